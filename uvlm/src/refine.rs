//! Solves with the influence matrix of a moving lattice on the factorisation of an earlier one,
//! by iterative refinement (docs/uvlm.md §9).
//!
//! A lattice that moves with the structure changes its AIC `A` at every step (and at every
//! sub-iteration of a strongly coupled step), but by little: the deflection of a step is a small
//! fraction of the distances between rings. The LU of an earlier matrix `A₀` then solves
//! `A x = b` by the classical refinement `x ← x + A₀⁻¹ (b − A x)`, which contracts by
//! `ρ ≈ ‖A₀⁻¹ (A − A₀)‖` per correction. Each correction costs a product with `A` and a solve with
//! the LU (`4n²` flops, [`DenseLu::solve_vector`]), the factorisation `⅔n³` at a lower rate than
//! its flop count says: on 128 rings a factorisation took as long as about fourteen corrections.
//!
//! The iteration stops when a correction is at most [`TOLERANCE`] of the solution's largest
//! entry (the residual left is then about `ρ` times that); it gives up, so that the caller
//! factorises the current matrix, when a correction does not shrink to [`MAX_CONTRACTION`] of the
//! one before or after [`MAX_CORRECTIONS`].

use crate::biot_savart::LANES;
use crate::dense_lu::DenseLu;

/// A correction at most this fraction of the solution's largest entry ends the iteration.
pub(crate) const TOLERANCE: f64 = 1e-12;

/// Corrections per solve before the refinement gives up.
pub(crate) const MAX_CORRECTIONS: usize = 8;

/// A correction larger than this fraction of the one before ends the refinement as failed.
pub(crate) const MAX_CONTRACTION: f64 = 0.25;

/// Refined solves on one unchanged matrix after which the caller factorises it: a lattice that
/// stopped moving then solves with its own factors.
pub(crate) const MAX_STALE_SOLVES: usize = 8;

/// Corrections above which the caller refactorises at its next change of the matrix. On the
/// paper's wing (128 rings, 2000 steps) the solves took 3.9 corrections on average and the
/// matrix was factorised 16 times; on Healy's (176 rings, 1000 steps of a gust) 3.7 and 14.
pub(crate) const REFACTOR_ABOVE: usize = 4;

/// `y = A x` for the `n × n` matrix `a` in [`crate::aic::AicLayout::BlockRings`] layout (blocks
/// of [`LANES`] rows, each column's lanes contiguous; rows past `n` are padding). Four partial
/// sums per row, over the columns in turn, so that the additions do not wait on each other.
pub(crate) fn block_rings_mul(a: &[f64], n: usize, x: &[f64], y: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if crate::biot_savart::isa() != crate::biot_savart::Isa::Generic {
        // SAFETY: AVX2 was detected at run time.
        unsafe { block_rings_mul_avx2(a, n, x, y) };
        return;
    }
    block_rings_mul_generic(a, n, x, y);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_rings_mul_avx2(a: &[f64], n: usize, x: &[f64], y: &mut [f64]) {
    block_rings_mul_generic(a, n, x, y);
}

#[inline(always)]
fn block_rings_mul_generic(a: &[f64], n: usize, x: &[f64], y: &mut [f64]) {
    debug_assert_eq!(a.len(), n.div_ceil(LANES) * n * LANES);
    for (b, out) in y.chunks_mut(LANES).enumerate() {
        let block = &a[b * n * LANES..(b + 1) * n * LANES];
        let mut acc = [[0.0; LANES]; 4];
        let (cols, rest) = block.as_chunks::<LANES>();
        debug_assert!(rest.is_empty());
        let (quads, tail) = cols.as_chunks::<4>();
        for (quad, xs) in quads.iter().zip(x.chunks_exact(4)) {
            for k in 0..4 {
                for l in 0..LANES {
                    acc[k][l] += quad[k][l] * xs[k];
                }
            }
        }
        for (col, &xj) in tail.iter().zip(&x[4 * quads.len()..]) {
            for l in 0..LANES {
                acc[0][l] += col[l] * xj;
            }
        }
        for (l, o) in out.iter_mut().enumerate() {
            *o = (acc[0][l] + acc[1][l]) + (acc[2][l] + acc[3][l]);
        }
    }
}

/// Solve `A x = b` with the LU of an earlier matrix: `x` holds `b` on entry and the solution on
/// a successful return, which gives the corrections made. `work` is scratch of length `n`.
/// `None` when the refinement does not converge (`x` is then spoiled: the caller factorises `A`
/// and solves again from `b`).
pub(crate) fn solve_refined(lu: &mut DenseLu, a: &[f64], b: &[f64], x: &mut [f64], work: &mut [f64]) -> Option<usize> {
    let n = b.len();
    lu.solve_vector(x);
    let mut last = f64::INFINITY;
    for k in 1..=MAX_CORRECTIONS {
        block_rings_mul(a, n, x, work);
        for (r, bi) in work.iter_mut().zip(b) {
            *r = bi - *r;
        }
        lu.solve_vector(work);
        let (mut step, mut size) = (0.0_f64, 0.0_f64);
        for (xi, d) in x.iter_mut().zip(work.iter()) {
            *xi += d;
            step = step.max(d.abs());
            size = size.max(xi.abs());
        }
        if !(step.is_finite() && size.is_finite()) || step > MAX_CONTRACTION * last {
            return None;
        }
        if step <= TOLERANCE * size {
            return Some(k);
        }
        last = step;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diagonally dominant `n × n` matrix in block-ring layout and row-major, and `A + εE`.
    fn matrices(n: usize, eps: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let entry = |i: usize, j: usize| {
            let v = ((i * 31 + j * 17) % 23) as f64 / 23.0 - 0.5;
            if i == j { v + n as f64 * 0.6 } else { v }
        };
        let pert = |i: usize, j: usize| ((i * 7 + j * 13) % 11) as f64 / 11.0 - 0.5;
        let nb = n.div_ceil(LANES);
        let mut a0 = vec![0.0; nb * n * LANES];
        let mut a1 = a0.clone();
        let mut row_major = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let at = ((i / LANES) * n + j) * LANES + i % LANES;
                a0[at] = entry(i, j);
                a1[at] = entry(i, j) + eps * pert(i, j) * n as f64;
                row_major[i * n + j] = a1[at];
            }
        }
        (a0, a1, row_major)
    }

    #[test]
    fn the_block_ring_product_matches_the_row_major_one() {
        let n = 21; // a padded last block
        let (_, a, row_major) = matrices(n, 1e-3);
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin()).collect();
        let mut y = vec![0.0; n];
        block_rings_mul(&a, n, &x, &mut y);
        for i in 0..n {
            let want: f64 = (0..n).map(|j| row_major[i * n + j] * x[j]).sum();
            assert!((y[i] - want).abs() <= 1e-13 * want.abs().max(1.0), "row {i}: {} vs {want}", y[i]);
        }
    }

    /// On a slightly changed matrix the refinement reaches the direct solution of the new
    /// matrix to the tolerance in a few corrections; on a very different one it gives up.
    #[test]
    fn refinement_on_an_earlier_factorisation_reaches_the_direct_solution() {
        let n = 37;
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.7).cos()).collect();
        for (eps, converges) in [(1e-5, true), (1e-3, true), (2.0, false)] {
            let (a0, a1, _) = matrices(n, eps);
            let mut old = DenseLu::new(n);
            old.factorize_block_rings(&a0, LANES).unwrap();
            let mut fresh = DenseLu::new(n);
            fresh.factorize_block_rings(&a1, LANES).unwrap();
            let mut direct = b.clone();
            fresh.solve_in_place(&mut direct);
            let (mut x, mut work) = (b.clone(), vec![0.0; n]);
            let k = solve_refined(&mut old, &a1, &b, &mut x, &mut work);
            assert_eq!(k.is_some(), converges, "eps {eps}: {k:?}");
            if let Some(k) = k {
                let size = direct.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                let err = x.iter().zip(&direct).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(err <= 10.0 * TOLERANCE * size, "eps {eps}: error {err:e} after {k} corrections");
                // Each correction gains about −log₁₀ ε digits of the 12 asked for.
                assert!(k <= if eps < 1e-4 { 4 } else { 7 }, "eps {eps}: {k} corrections");
            }
        }
    }
}
