//! Throughput of the direct Biot–Savart kernel in point–segment evaluations per second on one
//! core, against the machine's fused-multiply-add roofline measured by a loop of independent
//! FMAs (AVX-512 or AVX2, whichever the CPU has; docs/uvlm.md §9).
//!
//! `kernel/segments` sums 4096 segments of a 64 × 32 ring grid at 512 points (2.1 million pairs
//! per iteration; criterion reports pairs/s). `fma_roofline` reports floating-point operations per
//! second (an FMA counts two). The ratio is in docs/uvlm.md §9: one pair costs about 30
//! operations and a division (the fill of `P − X` and `|P − X|` per node is shared by the
//! segments at the node).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use uvlm::*;

fn grid() -> Filaments {
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
    fil
}

fn bench_kernel(c: &mut Criterion) {
    let fil = grid();
    let pts: Vec<[f64; 3]> = (0..512).map(|i| [0.03 * i as f64, 0.25 * (i % 4) as f64, 0.05]).collect();
    let mut g = c.benchmark_group("kernel");
    g.throughput(Throughput::Elements((pts.len() * fil.n_segments()) as u64));
    g.bench_function("segments", |b| b.iter(|| black_box(induced_velocity(&[&fil], &pts))));
    g.finish();
}

/// `n` rounds of 12 independent 8-wide FMA chains; returns a sum so nothing is optimised away.
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

/// `n` rounds of 12 independent 4-wide FMA chains.
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
    let mut s = 0.0;
    for v in &x {
        let mut o = [0.0; 4];
        // SAFETY: storing 4 f64 into a [f64; 4].
        unsafe { _mm256_storeu_pd(o.as_mut_ptr(), *v) };
        s += o.iter().sum::<f64>();
    }
    s
}

fn bench_roofline(c: &mut Criterion) {
    let n = 100_000;
    let mut g = c.benchmark_group("fma_roofline");
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("fma") {
            g.throughput(Throughput::Elements((n * 12 * 8 * 2) as u64));
            // SAFETY: features detected above.
            g.bench_function("avx512", |b| b.iter(|| black_box(unsafe { fma_avx512(black_box(n)) })));
        }
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            g.throughput(Throughput::Elements((n * 12 * 4 * 2) as u64));
            // SAFETY: features detected above.
            g.bench_function("avx2", |b| b.iter(|| black_box(unsafe { fma_avx2(black_box(n)) })));
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench_kernel, bench_roofline
}
criterion_main!(benches);
