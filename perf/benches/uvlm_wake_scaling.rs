//! Per-step time of the paper's flared-hinge wing (128 bound rings, 25 m/s, dt 0.01 s, flexible
//! lattice: the AIC is rebuilt every step) against the wake's length, 40 to 320 rows, with the
//! wake summed directly (`direct`) and through the treecode at 1e-6 |V∞| (`treecode`,
//! docs/uvlm.md §14). The acceptance of issue 36: a wake 8× longer costs at most 2.5× per step.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use uvlm::samples::FlaredWing;
use uvlm::*;

/// A solver whose wake of `rows` rows is full, and its stations.
fn solver(rows: usize, aggregation: WakeAggregation) -> (Uvlm, Vec<SpanStation>) {
    let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
    let st = wing.stations(10f64.to_radians());
    let lat = Lattice::from_stations(wing.spec(), &st).unwrap();
    let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
    p.parallel = Parallel::Off;
    p.n_wake_rows = rows;
    // As the harness marches: the far wake frozen within a step, closure legs.
    p.wake_reuse = WakeReuse::Frozen;
    p.wake_closure = true;
    p.wake_aggregation = aggregation;
    let mut u = Uvlm::new(lat, p).unwrap();
    for _ in 0..rows + 2 {
        u.update_stations(&st, None).unwrap();
        u.step(0.01).unwrap();
    }
    (u, st)
}

fn bench_scaling(c: &mut Criterion) {
    let mut g = c.benchmark_group("uvlm_step_vs_wake_rows");
    let tree = WakeAggregation::treecode();
    for rows in [40usize, 80, 160, 320] {
        for (name, agg) in [("direct", WakeAggregation::off()), ("treecode", tree)] {
            let (mut u, st) = solver(rows, agg);
            g.bench_with_input(BenchmarkId::new(name, rows), &rows, |b, _| {
                b.iter(|| {
                    u.update_stations(&st, None).unwrap();
                    black_box(u.step(0.01).unwrap().total_force())
                })
            });
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench_scaling
}
criterion_main!(benches);
