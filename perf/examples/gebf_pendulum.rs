//! Run one paper double-pendulum case and print the tip, fold angle, energy and joint drift
//! every 0.1 s; optionally write every step to a CSV file.
//!
//! `cargo run --release -p perf --example gebf_pendulum -- [c] [beta_deg] [n_el] [dt] [rho_inf] [stabilization 0/1] [out.csv]`
use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let get = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (c, beta, n_el, dt, rho) = (get(1, 1.0), get(2, 45.0), get(3, 5.0) as usize, get(4, 0.002), get(5, 0.8));
    let stabilization = get(6, 0.0) != 0.0;
    let (b, j, g) = samples::double_pendulum(c, beta, n_el);
    let mut m = Model::new(&b, &j, g, Options { stabilization, ..Options::default() })?;
    let t0 = std::time::Instant::now();
    let (rec, stats) = simulate::record(&mut m, IntegratorParams::new(rho, dt), 2.0)?;
    let wall = t0.elapsed();
    let every = ((0.1 / dt).round() as usize).max(1);
    for s in rec.iter().step_by(every) {
        println!(
            "t {:.3}  tip {:8.5} {:8.5} {:8.5}  fold {:8.3} deg  E {:+.3e} J  joint violation {:.2e}  Newton {}",
            s.t,
            s.tip.x,
            s.tip.y,
            s.tip.z,
            s.fold.to_degrees(),
            s.energies.total(),
            s.constraint_residual,
            s.newton_iterations
        );
    }
    println!("{stats:?}, wall {wall:.3?} (with energies every step)");
    if let Some(path) = a.get(7) {
        let mut out = String::from("t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,residual\n");
        for s in &rec {
            let e = &s.energies;
            out += &format!(
                "{},{},{},{},{},{},{},{},{},{}\n",
                s.t,
                s.tip.x,
                s.tip.y,
                s.tip.z,
                s.fold,
                e.kinetic,
                e.elastic,
                e.potential,
                e.total(),
                s.constraint_residual
            );
        }
        std::fs::write(path, out)?;
    }
    Ok(())
}
