//! The linear-solver seam: symbolic set-up once, numeric factorisation per Newton matrix,
//! solve in place. faer types never leave this file.

use crate::DenseMatrix;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::{PartialPivLuParams, lu_in_place, lu_in_place_scratch};
use faer::linalg::lu::partial_pivoting::solve::{solve_in_place, solve_in_place_scratch};
use faer::perm::PermRef;
use faer::{Mat, MatMut, MatRef, Par, Spec};

/// A linear solver with the three phases of diffsol's `LinearSolver`.
pub trait LinearSolver {
    /// Prepare for matrices of dimension `n` (symbolic analysis; called once per topology).
    fn set_dimension(&mut self, n: usize);
    /// Factorise `a`. Returns the first zero pivot row if `a` is singular.
    fn factorize(&mut self, a: &DenseMatrix) -> Result<(), usize>;
    /// Overwrite `b` with `A⁻¹ b` for the last factorised `A`.
    fn solve_in_place(&mut self, b: &mut [f64]);
}

/// Dense LU with partial pivoting (faer, sequential, in place, no allocation after set-up).
pub struct DenseLu {
    n: usize,
    lu: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    buf: MemBuffer,
}

impl std::fmt::Debug for DenseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLu").field("n", &self.n).finish_non_exhaustive()
    }
}

impl Default for DenseLu {
    fn default() -> Self {
        Self {
            n: 0,
            lu: Mat::zeros(0, 0),
            perm: Vec::new(),
            perm_inv: Vec::new(),
            buf: MemBuffer::new(StackReq::EMPTY),
        }
    }
}

impl LinearSolver for DenseLu {
    fn set_dimension(&mut self, n: usize) {
        self.n = n;
        self.lu = Mat::zeros(n, n);
        self.perm = vec![0; n];
        self.perm_inv = vec![0; n];
        let req = StackReq::any_of(&[
            lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Spec::<PartialPivLuParams, f64>::default()),
            solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        self.buf = MemBuffer::new(req);
    }

    fn factorize(&mut self, a: &DenseMatrix) -> Result<(), usize> {
        assert!(a.n_rows() == self.n && a.n_cols() == self.n, "factorize: dimension mismatch");
        let src = MatRef::from_column_major_slice(a.as_slice(), self.n, self.n);
        self.lu.copy_from(src);
        let stack = MemStack::new(&mut self.buf);
        lu_in_place(self.lu.as_mut(), &mut self.perm, &mut self.perm_inv, Par::Seq, stack, Default::default());
        let scale = (0..self.n).map(|i| self.lu[(i, i)].abs()).fold(0.0_f64, f64::max);
        for i in 0..self.n {
            let d = self.lu[(i, i)];
            if !d.is_finite() || d.abs() <= 1e-14 * scale {
                return Err(i);
            }
        }
        Ok(())
    }

    fn solve_in_place(&mut self, b: &mut [f64]) {
        assert!(b.len() == self.n, "solve: dimension mismatch");
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, self.n);
        let rhs = MatMut::from_column_major_slice_mut(b, self.n, 1);
        let stack = MemStack::new(&mut self.buf);
        solve_in_place(self.lu.as_ref(), self.lu.as_ref(), perm, rhs, Par::Seq, stack);
    }
}
