//! One UVLM time step of the paper's flared-hinge wing: 24 + 8 spanwise × 4 chordwise = 128 bound
//! rings, a full 40-row wake (40 × 32 rings), prescribed wake, single thread. The lattice is
//! updated before every step (as in a flexible run), so the AIC is rebuilt and refactorised each
//! time; variants: static lattice (AIC reused) and with a symmetry plane (mirror image).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use uvlm::samples::FlaredWing;
use uvlm::*;

fn solver(mirror: bool) -> (Uvlm, Vec<SpanStation>) {
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
    assert_eq!(u.wake().n_rows(), 40);
    (u, st)
}

fn bench_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("uvlm_step_paper_wing");
    for (name, mirror, moving) in [("flexible", false, true), ("static", false, false), ("flexible_mirror", true, true)]
    {
        let (mut u, st) = solver(mirror);
        // Pair evaluations of one step, for the ns/pair figure.
        let before = u.stats().n_pair_evaluations;
        if moving {
            u.update_stations(&st, None).unwrap();
        }
        u.step(0.01).unwrap();
        let pairs = u.stats().n_pair_evaluations - before;
        println!("{name}: {pairs} point-filament pairs per step");
        g.bench_function(name, |b| {
            b.iter(|| {
                if moving {
                    u.update_stations(&st, None).unwrap();
                }
                black_box(u.step(0.01).unwrap().total_force())
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(60).measurement_time(std::time::Duration::from_secs(4));
    targets = bench_step
}
criterion_main!(benches);
