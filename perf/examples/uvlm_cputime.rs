//! CPU time of the calling thread (not wall time) per UVLM step of the paper's wing, useful on
//! shared machines where criterion's wall time is inflated by other load. With rayon the CPU
//! figure only counts the main thread: read the wall time there.
//! Run: `cargo run --release -p perf --example uvlm_cputime`.
use perf::thread_cpu_ns as cpu_ns;
use uvlm::samples::FlaredWing;
use uvlm::*;
fn main() {
    let cases = [
        ("flexible", false, true, Parallel::Off),
        ("static", false, false, Parallel::Off),
        ("flexible_mirror", true, true, Parallel::Off),
        ("flexible, rayon auto", false, true, Parallel::Auto),
        ("flexible_mirror, rayon auto", true, true, Parallel::Auto),
    ];
    for (name, mirror, moving, par) in cases {
        let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
        let st = wing.stations(10f64.to_radians());
        let lat = Lattice::from_stations(wing.spec(), &st).unwrap();
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.parallel = par;
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
        let wall = w0.elapsed().as_secs_f64() * 1e3 / n as f64;
        let pairs = (u.stats().n_pair_evaluations - pairs0) as f64 / n as f64;
        if par == Parallel::Off {
            println!(
                "{name}: {:.3} ms CPU/step ({:.3} ms wall), {:.0} pairs/step, {:.2} ns/pair",
                cpu * 1e-6,
                wall,
                pairs,
                cpu / pairs
            );
        } else {
            println!("{name}: {wall:.3} ms wall/step, {pairs:.0} pairs/step");
        }
    }
}
