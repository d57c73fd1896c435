//! Linear modes about a configuration at rest.
//!
//! With `K = ∂r/∂q` and `M = ∂r/∂v_dot` at `(q, v = 0)` and the joint Jacobian `B(q)`, the
//! admissible motions are `δq = N y` with `N` an orthonormal basis of `ker B`; the modes solve
//! `Nᵀ K N y = ω² Nᵀ M N y` (K symmetrised; a configuration under load adds its geometric
//! stiffness). Solved by Cholesky of the reduced mass matrix and a symmetric eigensolver.

use crate::{Error, Model};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::DMatrix;

/// Natural frequencies and mode shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// Circular frequencies ω, rad/s, ascending (negative values: −√|ω²| for unstable modes).
    pub omega: Vec<f64>,
    /// Mode shapes in the tangent space (n_dof × n_modes), columns M-orthonormal.
    pub shapes: DMatrix<f64>,
}

fn to_dmatrix(m: &DenseMatrix) -> DMatrix<f64> {
    DMatrix::from_column_slice(m.n_rows(), m.n_cols(), m.as_slice())
}

impl Model {
    /// Linear modes about `q` at rest, with the joints' velocity constraints.
    pub fn linear_modes(&self, q: &[f64]) -> Result<Modes, Error> {
        if q.len() != self.n_coords() {
            return Err(Error::WrongLength { what: "q", got: q.len(), expected: self.n_coords() });
        }
        let n = self.n_dof();
        let nc = self.n_velocity_constraints();
        let zeros = vec![0.0; n];
        let mut k = DenseMatrix::zeros(n, n);
        self.iteration_matrix_inplace(0.0, q, &zeros, &zeros, 0.0, 0.0, 1.0, &mut k.view());
        let mut m = DenseMatrix::zeros(n, n);
        self.iteration_matrix_inplace(0.0, q, &zeros, &zeros, 1.0, 0.0, 0.0, &mut m.view());
        let mut b = DenseMatrix::zeros(nc.max(1), n);
        if nc > 0 {
            self.psi_v_inplace(0.0, q, &mut b.view());
        }
        let (k, m, b) = (to_dmatrix(&k), to_dmatrix(&m), to_dmatrix(&b));
        let k = (&k + k.transpose()) * 0.5;
        // Null space of B from the SVD of Bᵀ B (n × n, symmetric): eigenvectors with zero
        // eigenvalue.
        let btb = b.transpose() * &b;
        let eig = btb.symmetric_eigen();
        let scale = eig.eigenvalues.amax().max(1e-300);
        let free: Vec<usize> = (0..n).filter(|&i| eig.eigenvalues[i] <= 1e-12 * scale).collect();
        let nf = free.len();
        let mut basis = DMatrix::zeros(n, nf);
        for (c, &i) in free.iter().enumerate() {
            basis.set_column(c, &eig.eigenvectors.column(i));
        }
        let mr = basis.transpose() * &m * &basis;
        let kr = basis.transpose() * &k * &basis;
        let mr = (&mr + mr.transpose()) * 0.5;
        let chol = mr.cholesky().ok_or(Error::SingularMass)?;
        let l = chol.l();
        let linv = l.clone().try_inverse().ok_or(Error::SingularMass)?;
        let a = &linv * kr * linv.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let e = a.symmetric_eigen();
        let mut order: Vec<usize> = (0..nf).collect();
        order.sort_by(|&i, &j| e.eigenvalues[i].total_cmp(&e.eigenvalues[j]));
        let omega = order.iter().map(|&i| e.eigenvalues[i].signum() * e.eigenvalues[i].abs().sqrt()).collect();
        let mut shapes = DMatrix::zeros(n, nf);
        let back = &basis * linv.transpose();
        for (c, &i) in order.iter().enumerate() {
            shapes.set_column(c, &(&back * e.eigenvectors.column(i)));
        }
        Ok(Modes { omega, shapes })
    }
}
