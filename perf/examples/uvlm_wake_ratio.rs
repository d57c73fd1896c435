//! The performance issue's "a wake 8× longer costs at most 2.5× per step": CPU time of one
//! thread per UVLM step of the paper's wing (the far wake frozen within the step, closure legs,
//! as the harness marches) at 40 rows, direct and through the treecode, and at 320 rows, both,
//! interleaved, medians of seven runs of 64 steps; the ratio is the 320-row treecode's step over
//! the faster 40-row one (docs/uvlm.md §14).
//! Run: `cargo run --release -p perf --example uvlm_wake_ratio [order]`.
use uvlm::samples::FlaredWing;
use uvlm::*;
fn cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(0)
}
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
fn solver(rows: usize, agg: WakeAggregation) -> (Uvlm, Vec<SpanStation>) {
    let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
    let st = wing.stations(10f64.to_radians());
    let lat = Lattice::from_stations(wing.spec(), &st).unwrap();
    let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
    p.parallel = Parallel::Off;
    p.n_wake_rows = rows;
    p.wake_closure = true;
    p.wake_reuse = WakeReuse::Frozen;

    p.wake_aggregation = agg;
    let mut u = Uvlm::new(lat, p).unwrap();
    for _ in 0..rows + 2 {
        u.update_stations(&st, None).unwrap();
        u.step(0.01).unwrap();
    }
    (u, st)
}
fn time(u: &mut Uvlm, st: &[SpanStation]) -> f64 {
    let t0 = cpu_ns();
    for _ in 0..64 {
        u.update_stations(st, None).unwrap();
        std::hint::black_box(u.step(0.01).unwrap().total_force());
    }
    (cpu_ns() - t0) as f64 * 1e-6 / 64.0
}
fn main() {
    let order: usize = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(4);
    let tree = WakeAggregation { order, min_segments: 0, ..WakeAggregation::treecode() };
    let (mut a, st) = solver(40, WakeAggregation::off());
    let (mut b, _) = solver(320, tree);
    let (mut c, _) = solver(320, WakeAggregation::off());
    let (mut d, _) = solver(40, tree);
    let (mut ta, mut tb, mut tc, mut td) = (vec![], vec![], vec![], vec![]);
    for _ in 0..7 {
        ta.push(time(&mut a, &st));
        tb.push(time(&mut b, &st));
        tc.push(time(&mut c, &st));
        td.push(time(&mut d, &st));
    }
    let (ma, mb, mc, md) = (median(ta), median(tb), median(tc), median(td));
    println!(
        "p={order} direct40 {ma:.3} tree40 {md:.3} direct320 {mc:.3} tree320 {mb:.3} ratio {:.3}",
        mb / ma.min(md)
    );
}
