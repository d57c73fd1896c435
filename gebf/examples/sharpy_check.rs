//! Development: SHARPy regression tip vs time and step.
use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;
fn main() {
    for dt in [0.01, 0.005, 0.001] {
        let (b, j, g) = samples::sharpy_slanted_pendulum();
        let mut m = Model::new(&b, &j, g, Options::default()).unwrap();
        let mut tips = Vec::new();
        simulate::run(&mut m, IntegratorParams::new(1.0, dt), 0.3, |m, s, _| tips.push((s.t, m.tip_position(&s.q)))).unwrap();
        let r = samples::SHARPY_SLANTED_TIP_AT_0_3;
        for &(t, tip) in tips.iter().rev().take(((0.011 / dt) as usize).max(2)) {
            let d = ((tip.x - r[0]).powi(2) + (tip.y - r[1]).powi(2) + (tip.z - r[2]).powi(2)).sqrt();
            println!("dt {dt} t {t:.4} tip {:.5} {:.5} {:.5} d {:.2} mm", tip.x, tip.y, tip.z, d * 1e3);
        }
    }
}
