//! Dense LU with partial pivoting for the aerodynamic influence matrix (faer, sequential, in
//! place, no allocation after set-up). faer types never leave this file.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::{PartialPivLuParams, lu_in_place, lu_in_place_scratch};
use faer::linalg::lu::partial_pivoting::solve::{solve_in_place, solve_in_place_scratch};
use faer::perm::PermRef;
use faer::{Mat, MatMut, MatRef, Par, Spec};

/// Factorisation of an `n × n` matrix given row-major.
pub(crate) struct DenseLu {
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

impl DenseLu {
    /// Workspace for dimension `n`.
    pub(crate) fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Spec::<PartialPivLuParams, f64>::default()),
            solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        Self { n, lu: Mat::zeros(n, n), perm: vec![0; n], perm_inv: vec![0; n], buf: MemBuffer::new(req) }
    }

    /// Factorise the row-major matrix `a`. Returns the first (numerically) zero pivot row on failure.
    pub(crate) fn factorize_row_major(&mut self, a: &[f64]) -> Result<(), usize> {
        let n = self.n;
        assert_eq!(a.len(), n * n, "factorize: dimension mismatch");
        self.lu.copy_from(MatRef::from_row_major_slice(a, n, n));
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

    /// Overwrite `b` with `A⁻¹ b`.
    pub(crate) fn solve_in_place(&mut self, b: &mut [f64]) {
        assert_eq!(b.len(), self.n, "solve: dimension mismatch");
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, self.n);
        let rhs = MatMut::from_column_major_slice_mut(b, self.n, 1);
        let stack = MemStack::new(&mut self.buf);
        solve_in_place(self.lu.as_ref(), self.lu.as_ref(), perm, rhs, Par::Seq, stack);
    }
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
}
