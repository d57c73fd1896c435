//! CPU time (not wall time) per UVLM step of the paper's wing, for shared machines.
use uvlm::samples::FlaredWing;
use uvlm::*;
fn cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(0)
}
fn main() {
    for (name, mirror, moving) in [("flexible", false, true), ("static", false, false), ("flexible_mirror", true, true)]
    {
        let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
        let st = wing.stations(10f64.to_radians());
        let lat = Lattice::from_stations(wing.spec(), &st).unwrap();
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.parallel = Parallel::Off;
        if mirror {
            p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
        }
        let mut u = Uvlm::new(lat, p).unwrap();
        for _ in 0..45 {
            u.update_stations(&st, None).unwrap();
            u.step(0.01).unwrap();
        }
        let n = 400;
        let pairs0 = u.stats().n_pair_evaluations;
        let t0 = cpu_ns();
        let w0 = std::time::Instant::now();
        for _ in 0..n {
            if moving {
                u.update_stations(&st, None).unwrap();
            }
            u.step(0.01).unwrap();
        }
        let cpu = (cpu_ns() - t0) as f64 / n as f64;
        let pairs = (u.stats().n_pair_evaluations - pairs0) as f64 / n as f64;
        println!(
            "{name}: {:.3} ms CPU/step ({:.3} ms wall), {:.0} pairs/step, {:.2} ns/pair",
            cpu * 1e-6,
            w0.elapsed().as_secs_f64() * 1e3 / n as f64,
            pairs,
            cpu / pairs
        );
    }
}
