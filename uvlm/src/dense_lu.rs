//! Dense LU with partial pivoting for the aerodynamic influence matrix (faer, sequential, in
//! place, no allocation after set-up). faer types never leave this file.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::{PartialPivLuParams, lu_in_place, lu_in_place_scratch};
use faer::linalg::lu::partial_pivoting::solve::{solve_in_place, solve_in_place_scratch};
use faer::perm::PermRef;
use faer::{Mat, MatMut, Par, Spec};

/// Factorisation of an `n × n` matrix given row-major.
pub(crate) struct DenseLu {
    n: usize,
    lu: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    buf: MemBuffer,
    /// Scratch of [`DenseLu::solve_vector`].
    work: Vec<f64>,
}

impl std::fmt::Debug for DenseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLu").field("n", &self.n).finish_non_exhaustive()
    }
}

impl DenseLu {
    /// Workspace for dimension `n`.
    pub(crate) fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Spec::<PartialPivLuParams, f64>::default()),
            solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        let (lu, perm, perm_inv, buf) = (Mat::zeros(n, n), vec![0; n], vec![0; n], MemBuffer::new(req));
        Self { n, lu, perm, perm_inv, buf, work: vec![0.0; n] }
    }

    /// Factorise the row-major matrix `a`. Returns the first (numerically) zero pivot row on failure.
    pub(crate) fn factorize_row_major(&mut self, a: &[f64]) -> Result<(), usize> {
        let n = self.n;
        assert_eq!(a.len(), n * n, "factorize: dimension mismatch");
        transpose_into(a, n, &mut self.lu);
        self.factorize_in_place()
    }

    /// LU of `self.lu` in place, with the pivot check.
    fn factorize_in_place(&mut self) -> Result<(), usize> {
        let n = self.n;
        let stack = MemStack::new(&mut self.buf);
        lu_in_place(self.lu.as_mut(), &mut self.perm, &mut self.perm_inv, Par::Seq, stack, Default::default());
        let scale = (0..n).map(|i| self.lu[(i, i)].abs()).fold(0.0_f64, f64::max);
        for i in 0..n {
            let d = self.lu[(i, i)];
            if !d.is_finite() || d.abs() <= 1e-13 * scale {
                return Err(i);
            }
        }
        Ok(())
    }

    /// Factorise the matrix given in [`crate::aic::AicLayout::BlockRings`]
    /// layout (blocks of `lanes` rows, each ring's lanes contiguous): each column gathers one
    /// contiguous run per block. Returns the first (numerically) zero pivot row on failure.
    pub(crate) fn factorize_block_rings(&mut self, a: &[f64], lanes: usize) -> Result<(), usize> {
        let n = self.n;
        assert_eq!(a.len(), n.div_ceil(lanes) * n * lanes, "factorize: dimension mismatch");
        for j in 0..n {
            let col = self.lu.col_as_slice_mut(j);
            for (b, rows) in col.chunks_mut(lanes).enumerate() {
                let at = (b * n + j) * lanes;
                rows.copy_from_slice(&a[at..at + rows.len()]);
            }
        }
        self.factorize_in_place()
    }

    /// Overwrite `b` with `A⁻¹ b`.
    pub(crate) fn solve_in_place(&mut self, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "solve: dimension mismatch");
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, self.n);
        let rhs = MatMut::from_column_major_slice_mut(b, self.n, 1);
        let stack = MemStack::new(&mut self.buf);
        solve_in_place(self.lu.as_ref(), self.lu.as_ref(), perm, rhs, Par::Seq, stack);
    }
}

impl DenseLu {
    /// Overwrite `b` with `A⁻¹ b` by substitution column by column (the solves of a refinement,
    /// refine.rs): faer's solve, made for many right-hand sides, took twice as long
    /// for one at the lattices' sizes. Within rounding of [`DenseLu::solve_in_place`], not bit for
    /// bit; one instruction set's sums are every other's (no fused products).
    pub(crate) fn solve_vector(&mut self, b: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if crate::biot_savart::isa() != crate::biot_savart::Isa::Generic {
            // SAFETY: AVX2 was detected at run time.
            unsafe { self.solve_vector_avx2(b) };
            return;
        }
        self.solve_vector_generic(b);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_vector_avx2(&mut self, b: &mut [f64]) {
        self.solve_vector_generic(b);
    }

    #[inline(always)]
    fn solve_vector_generic(&mut self, b: &mut [f64]) {
        let (n, work) = (self.n, &mut self.work[..]);
        assert_eq!(b.len(), n, "solve_vector: dimension mismatch");
        // P A = L U with row i of P A row perm[i] of A.
        for (w, &p) in work.iter_mut().zip(&self.perm) {
            *w = b[p];
        }
        // L y = P b, L unit lower: column j eliminates y_j below the diagonal.
        for j in 0..n {
            let (yj, col) = (work[j], &self.lu.col_as_slice(j)[j + 1..]);
            for (y, l) in work[j + 1..].iter_mut().zip(col) {
                *y -= l * yj;
            }
        }
        // U x = y: column j, from the last, after its own division.
        for j in (0..n).rev() {
            let col = self.lu.col_as_slice(j);
            let xj = work[j] / col[j];
            work[j] = xj;
            for (x, u) in work[..j].iter_mut().zip(&col[..j]) {
                *x -= u * xj;
            }
        }
        b.copy_from_slice(work);
    }
}

/// Copy the row-major `n × n` matrix `a` into the column-major `m` in tiles of [`TILE`] × [`TILE`]
/// (each tile's rows and columns stay in the first-level cache; faer's general strided copy
/// took a third of the factorisation at the lattice's sizes).
fn transpose_into(a: &[f64], n: usize, m: &mut Mat<f64>) {
    for j0 in (0..n).step_by(TILE) {
        let j1 = (j0 + TILE).min(n);
        for i0 in (0..n).step_by(TILE) {
            let i1 = (i0 + TILE).min(n);
            for j in j0..j1 {
                let col = &mut m.col_as_slice_mut(j)[i0..i1];
                for (x, i) in col.iter_mut().zip(i0..i1) {
                    *x = a[i * n + j];
                }
            }
        }
    }
}

/// Tile size of [`transpose_into`].
const TILE: usize = 8;

/// `A⁻¹ B` for a complex square `A` (the frequency-domain influence matrix with its wake,
/// [`crate::with_wake`]) by faer's blocked LU with partial pivoting, sequential: nalgebra's
/// unblocked LU took about a quarter of a stability analysis on a 16 × 32 lattice. `None` when
/// a pivot is zero or the solution is not finite.
///
/// # Panics
/// If `a` is not square or `b` has another number of rows.
pub fn solve_complex(
    a: &nalgebra::DMatrix<nalgebra::Complex<f64>>,
    b: &nalgebra::DMatrix<nalgebra::Complex<f64>>,
) -> Option<nalgebra::DMatrix<nalgebra::Complex<f64>>> {
    type C = faer::c64;
    let n = a.nrows();
    assert!(a.ncols() == n && b.nrows() == n, "solve_complex: dimension mismatch");
    let k = b.ncols();
    let req = StackReq::any_of(&[
        lu_in_place_scratch::<usize, C>(n, n, Par::Seq, Spec::<PartialPivLuParams, C>::default()),
        solve_in_place_scratch::<usize, C>(n, k, Par::Seq),
    ]);
    let mut buf = MemBuffer::new(req);
    // Both are column-major: nalgebra's storage is faer's.
    let mut lu = Mat::<C>::from_fn(n, n, |i, j| a[(i, j)]);
    let (mut perm, mut perm_inv) = (vec![0usize; n], vec![0usize; n]);
    lu_in_place(lu.as_mut(), &mut perm, &mut perm_inv, Par::Seq, MemStack::new(&mut buf), Default::default());
    if (0..n).any(|i| lu[(i, i)] == C::new(0.0, 0.0)) {
        return None;
    }
    let mut x = Mat::<C>::from_fn(n, k, |i, j| b[(i, j)]);
    let perm = PermRef::new_checked(&perm, &perm_inv, n);
    solve_in_place(lu.as_ref(), lu.as_ref(), perm, x.as_mut(), Par::Seq, MemStack::new(&mut buf));
    let out = nalgebra::DMatrix::from_fn(n, k, |i, j| x[(i, j)]);
    out.iter().all(|z| z.re.is_finite() && z.im.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn solves_and_detects_singular() {
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.2, 0.1, 2.0];
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum()).collect();
        let mut lu = DenseLu::new(3);
        lu.factorize_row_major(&a).unwrap();
        lu.solve_in_place(&mut b);
        for k in 0..3 {
            assert_relative_eq!(b[k], x[k], max_relative = 1e-14);
        }
        assert!(lu.factorize_row_major(&[1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0]).is_err());
    }

    /// The substitution of one right-hand side agrees with faer's solve to rounding.
    #[test]
    fn the_vector_solve_matches_the_solve() {
        let n = 45;
        let a: Vec<f64> = (0..n * n)
            .map(|k| ((k * 37 % 101) as f64 / 101.0 - 0.5) + if k % (n + 1) == 0 { 0.3 } else { 0.0 })
            .collect();
        let mut lu = DenseLu::new(n);
        lu.factorize_row_major(&a).unwrap();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.9).sin()).collect();
        let (mut x, mut y) = (b.clone(), b.clone());
        lu.solve_in_place(&mut x);
        lu.solve_vector(&mut y);
        let size = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (p, q) in x.iter().zip(&y) {
            assert!((p - q).abs() <= 1e-12 * size, "{p} vs {q}");
        }
    }

    /// A complex 40 × 40 system with three right-hand sides: the residual `A X − B` at round-off
    /// and the same solution as nalgebra's LU; a singular matrix gives `None`.
    #[test]
    fn complex_solve_matches_nalgebra_and_detects_singular() {
        use nalgebra::{Complex, DMatrix};
        let n = 40;
        let z = |i: usize, j: usize, k: f64| {
            Complex::new(((i * 7 + j * 3) as f64 * k).sin(), ((i + 2 * j) as f64 * k).cos())
        };
        let a = DMatrix::from_fn(n, n, |i, j| {
            z(i, j, 0.37) + if i == j { Complex::new(4.0, 1.0) } else { Complex::new(0.0, 0.0) }
        });
        let b = DMatrix::from_fn(n, 3, |i, j| z(i, j, 1.3));
        let x = solve_complex(&a, &b).unwrap();
        let scale = b.iter().map(|v| v.norm()).fold(0.0, f64::max);
        assert!((&a * &x - &b).iter().all(|v| v.norm() < 1e-13 * scale));
        let y = a.clone().lu().solve(&b).unwrap();
        assert!((&x - &y).iter().all(|v| v.norm() < 1e-12 * scale));
        let mut s = a.clone();
        let row = s.row(3).clone_owned();
        s.row_mut(5).copy_from(&row);
        s.row_mut(5).scale_mut(0.0);
        assert!(solve_complex(&s, &b).is_none());
    }
}
