//! CPU time per unsteady step of one surface against the same panels as two surfaces
//! (docs/uvlm.md §16): an AR-16 rectangular wing of 32 × 4 rings meshed (a) as one surface,
//! (b) as two half-wings of 16 × 4 meeting at the root, (c) a wing of 24 × 4 and a tail of
//! 8 × 4 behind it; 40-row prescribed wake, the lattice moved every step (the AIC rebuilt and
//! refactorised each time, as in a flexible run), single thread. Thread CPU time of runs of 100
//! steps, the cases interleaved in nine rounds: minimum and median.
//! Run: `cargo run --release -p perf --example uvlm_multi_surface_timing`.
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

use perf::thread_cpu_ns as cpu_ns;

fn shifted(st: &[SpanStation], dx: f64, dz: f64) -> Vec<SpanStation> {
    st.iter().map(|s| SpanStation { origin: s.origin + nalgebra::Vector3::new(dx, 0.0, dz), ..*s }).collect()
}

fn main() {
    let alpha = 5f64.to_radians();
    let full = rectangular_wing(-8.0, 8.0, 1.0, 32, SpanSpacing::Uniform);
    let wing24 = rectangular_wing(-6.0, 6.0, 1.0, 24, SpanSpacing::Uniform);
    let tail8 = shifted(&rectangular_wing(-2.0, 2.0, 0.5, 8, SpanSpacing::Uniform), 5.0, 0.3);
    let cases: [(&str, Vec<Vec<SpanStation>>); 3] = [
        ("one surface 32x4", vec![full.clone()]),
        ("two half-wings 16x4 + 16x4", vec![full[..=16].to_vec(), full[16..].to_vec()]),
        ("wing 24x4 + tail 8x4", vec![wing24, tail8]),
    ];
    let mut solvers: Vec<(&str, Vec<Vec<SpanStation>>, Uvlm)> = cases
        .into_iter()
        .map(|(name, surfaces)| {
            let lats: Vec<Lattice> =
                surfaces.iter().map(|st| Lattice::from_stations(LatticeSpec::new(4), st).unwrap()).collect();
            let mut p = UvlmParams::new(1.0, [10.0 * alpha.cos(), 0.0, 10.0 * alpha.sin()]);
            p.parallel = Parallel::Off;
            p.n_wake_rows = 40;
            (name, surfaces, Uvlm::with_surfaces(lats, p).unwrap())
        })
        .collect();
    let step = |u: &mut Uvlm, surfaces: &[Vec<SpanStation>]| {
        for (k, st) in surfaces.iter().enumerate() {
            u.update_stations_of(k, st, None).unwrap();
        }
        u.step(0.025).unwrap();
    };
    for (_, surfaces, u) in &mut solvers {
        for _ in 0..45 {
            step(u, surfaces);
        }
    }
    // Rounds interleave the cases, so that the machine's other load falls on all alike.
    let (n, rounds) = (100, 9);
    let mut times = vec![Vec::new(); solvers.len()];
    let pairs0: Vec<u64> = solvers.iter().map(|(_, _, u)| u.stats().n_pair_evaluations).collect();
    for _ in 0..rounds {
        for (c, (_, surfaces, u)) in solvers.iter_mut().enumerate() {
            let t0 = cpu_ns();
            for _ in 0..n {
                step(u, surfaces);
            }
            times[c].push((cpu_ns() - t0) as f64 / n as f64 * 1e-6);
        }
    }
    for (c, (name, _, u)) in solvers.iter().enumerate() {
        times[c].sort_by(f64::total_cmp);
        let pairs = (u.stats().n_pair_evaluations - pairs0[c]) as f64 / (rounds * n) as f64;
        let rings: usize = u.surfaces().iter().map(|s| s.lattice().n_rings()).sum();
        println!(
            "{name}: {rings} rings, {:.3} ms CPU/step (min), {:.3} (median of {rounds}), {pairs:.0} pairs/step",
            times[c][0],
            times[c][rounds / 2]
        );
    }
}
