//! CPU time of the calling thread per UVLM step of the paper's wing against the wake's length
//! (40 to 320 rows), direct (f64, and mixed precision) and through the treecode at 1e-6 |V∞|
//! (orders 4, 5, 6), and the direct kernels' throughput against an FMA loop: the figures of docs/uvlm.md §9 and §14 on a
//! shared machine, where the wall time of `cargo bench -p perf --bench uvlm_wake_scaling` / `--bench
//! uvlm_kernel` is inflated by other load. Medians of three runs of 100 steps after the wake is full;
//! the last line is the 8×-wake ratio at p = 5 (interleaved medians of seven runs of 400 steps).
//! Run: `cargo run --release -p perf --example uvlm_wake_scaling [-- kernel]` (with `kernel`, the
//! throughputs only).
use uvlm::samples::FlaredWing;
use uvlm::*;

use perf::thread_cpu_ns as cpu_ns;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The paper's wing marched until its wake of `rows` rows is full, as the harness marches: the
/// far wake frozen within a step, closure legs.
fn solver(rows: usize, agg: WakeAggregation) -> (Uvlm, Vec<SpanStation>) {
    let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
    let st = wing.stations(10f64.to_radians());
    let lat = Lattice::from_stations(wing.spec(), &st).unwrap();
    let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
    p.parallel = Parallel::Off;
    p.n_wake_rows = rows;
    p.wake_reuse = WakeReuse::Frozen;
    p.wake_closure = true;
    p.wake_aggregation = agg;
    let mut u = Uvlm::new(lat, p).unwrap();
    for _ in 0..rows + 2 {
        u.update_stations(&st, None).unwrap();
        u.step(0.01).unwrap();
    }
    (u, st)
}

/// Thread CPU time per step over `n` steps at once (the clock ticks coarsely on some kernels), ms.
fn steps_ms(u: &mut Uvlm, st: &[SpanStation], n: usize) -> f64 {
    let t0 = cpu_ns();
    for _ in 0..n {
        u.update_stations(st, None).unwrap();
        std::hint::black_box(u.step(0.01).unwrap().total_force());
    }
    (cpu_ns() - t0) as f64 * 1e-6 / n as f64
}

fn step_ms(rows: usize, agg: WakeAggregation) -> f64 {
    let (mut u, st) = solver(rows, agg);
    median((0..3).map(|_| steps_ms(&mut u, &st, 100)).collect())
}

/// The performance issue's "a wake 8× longer costs at most 2.5× per step": the treecode's step
/// at 320 rows over the faster of the direct and the treecode's at 40 rows, interleaved, medians
/// of seven runs of 400 steps (the thread clock ticks every few milliseconds).
fn ratio(order: usize) {
    let tree = WakeAggregation { order, min_segments: 0, ..WakeAggregation::treecode() };
    let mut runs = [solver(40, WakeAggregation::off()), solver(40, mixed()), solver(40, tree), solver(320, tree)];
    let mut times = [vec![], vec![], vec![], vec![]];
    for _ in 0..7 {
        for ((u, st), t) in runs.iter_mut().zip(&mut times) {
            t.push(steps_ms(u, st, 400));
        }
    }
    let [d40, m40, t40, t320] = times.map(median);
    println!(
        "p = {order}: 40 rows direct {d40:.3} / mixed {m40:.3} / treecode {t40:.3} ms, 320 rows treecode {t320:.3} ms: {:.2}x",
        t320 / d40.min(m40).min(t40)
    );
}

/// The far wake summed directly in mixed precision (the treecode never applies).
fn mixed() -> WakeAggregation {
    WakeAggregation { min_segments: usize::MAX, ..WakeAggregation::treecode() }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
fn fma_avx512(n: usize) -> f64 {
    use std::arch::x86_64::*;
    let a = _mm512_set1_pd(0.999_999);
    let b = _mm512_set1_pd(1e-7);
    let mut x = [_mm512_set1_pd(1.0); 12];
    for _ in 0..n {
        for v in &mut x {
            *v = _mm512_fmadd_pd(*v, a, b);
        }
    }
    x.iter().map(|v| _mm512_reduce_add_pd(*v)).sum()
}

/// [`fma_avx512`] on AVX2: twelve independent chains of four-lane f64 fused multiply-adds.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn fma_avx2(n: usize) -> f64 {
    use std::arch::x86_64::*;
    let a = _mm256_set1_pd(0.999_999);
    let b = _mm256_set1_pd(1e-7);
    let mut x = [_mm256_set1_pd(1.0); 12];
    for _ in 0..n {
        for v in &mut x {
            *v = _mm256_fmadd_pd(*v, a, b);
        }
    }
    let mut lanes = [0.0; 4];
    x.iter().fold(0.0, |s, v| {
        // SAFETY: `lanes` holds the four f64 stored.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), *v) };
        s + lanes.iter().sum::<f64>()
    })
}

/// The machine's FMA roofline, f64 flop/s per core, and the instruction set it was measured
/// with (the widest the kernels use here).
fn roofline() -> Option<(f64, &'static str)> {
    #[cfg(target_arch = "x86_64")]
    {
        let n = 20_000_000;
        let fma = std::is_x86_feature_detected!("fma");
        let (lanes, isa): (usize, &str) = if fma && std::is_x86_feature_detected!("avx512f") {
            (8, "AVX-512")
        } else if fma && std::is_x86_feature_detected!("avx2") {
            (4, "AVX2")
        } else {
            return None;
        };
        let flops = median(
            (0..9)
                .map(|_| {
                    let t0 = cpu_ns();
                    // SAFETY: the features were detected above.
                    let s = unsafe {
                        if lanes == 8 { fma_avx512(std::hint::black_box(n)) } else { fma_avx2(std::hint::black_box(n)) }
                    };
                    std::hint::black_box(s);
                    (n * 12 * lanes * 2) as f64 / ((cpu_ns() - t0) as f64 * 1e-9)
                })
                .collect(),
        );
        Some((flops, isa))
    }
    #[cfg(not(target_arch = "x86_64"))]
    None
}

fn kernel() {
    let mut fil = Filaments::default();
    let core = CoreModel::CutOff { radius: 1e-6 };
    let (nr, nc) = (64u32, 33u32);
    for r in 0..nr {
        for j in 0..nc {
            fil.push_node([0.5 * j as f64, 2.0 + 0.25 * r as f64, 0.01 * (0.3 * j as f64).sin()]);
        }
    }
    for r in 0..nr {
        for j in 0..nc {
            let k = r * nc + j;
            if j + 1 < nc && fil.n_segments() < 4096 {
                fil.push_segment(k, k + 1, 0.1 + 0.001 * k as f64, &core);
            }
            if r + 1 < nr && fil.n_segments() < 4096 {
                fil.push_segment(k, k + nc, -0.2 + 0.001 * j as f64, &core);
            }
        }
    }
    let pts: Vec<[f64; 3]> = (0..512).map(|i| [0.03 * i as f64, 0.25 * (i % 4) as f64, 0.05]).collect();
    let pairs = (pts.len() * fil.n_segments()) as f64;
    let rate = median(
        (0..5)
            .map(|_| {
                let t0 = cpu_ns();
                for _ in 0..20 {
                    std::hint::black_box(induced_velocity(&[&fil], &pts));
                }
                20.0 * pairs / ((cpu_ns() - t0) as f64 * 1e-9)
            })
            .collect(),
    );
    println!("direct kernel: {:.3e} point-segment pairs/s per core", rate);
    let rate32 = median(
        (0..5)
            .map(|_| {
                let t0 = cpu_ns();
                for _ in 0..20 {
                    std::hint::black_box(induced_velocity_mixed(&fil, &pts));
                }
                20.0 * pairs / ((cpu_ns() - t0) as f64 * 1e-9)
            })
            .collect(),
    );
    println!("mixed-precision kernel: {:.3e} point-segment pairs/s per core", rate32);
    if let Some((flops, isa)) = roofline() {
        println!("FMA roofline ({isa}): {:.3e} flop/s per core", flops);
        println!("pairs per roofline flop: {:.4} (a pair is ~30 flops and one division)", rate / flops);
        println!("mixed: pairs per f32 roofline flop (twice the f64 lanes): {:.4}", rate32 / (2.0 * flops));
    }
}

fn main() {
    kernel();
    if std::env::args().nth(1).as_deref() == Some("kernel") {
        return;
    }
    println!("rows  direct_ms  mixed_ms  tree4_ms  tree5_ms  tree6_ms   (CPU time per step, median of 3 × 100 steps)");
    let tree = |order| WakeAggregation { order, ..WakeAggregation::treecode() };
    for rows in [40usize, 80, 160, 320] {
        let d = step_ms(rows, WakeAggregation::off());
        let m = step_ms(rows, mixed());
        let t4 = step_ms(rows, tree(4));
        let t5 = step_ms(rows, tree(5));
        let t6 = step_ms(rows, tree(6));
        println!("{rows:4}  {d:9.3}  {m:8.3}  {t4:8.3}  {t5:8.3}  {t6:8.3}");
    }
    ratio(5);
}
