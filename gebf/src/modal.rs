//! Linear modes about a configuration at rest.
//!
//! With `K = ∂r/∂q` and `M = ∂r/∂v_dot` at `(q, v = 0)` and the joint Jacobian `B(q)`, the
//! admissible motions are `δq = N y` with `N` an orthonormal basis of `ker B`; the modes solve
//! `Nᵀ K N y = ω² Nᵀ M N y` (K symmetrised; a configuration under load adds its geometric
//! stiffness). Solved by Cholesky of the reduced mass matrix and a symmetric eigensolver, in
//! [`genalpha::analysis`].

use crate::{Error, Model};
use genalpha::ConstrainedSystem;
use genalpha::analysis;
use nalgebra::DMatrix;

/// Natural frequencies and mode shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// Circular frequencies ω, rad/s, ascending (negative values: −√|ω²| for unstable modes).
    pub omega: Vec<f64>,
    /// Mode shapes in the tangent space (n_dof × n_modes), columns M-orthonormal.
    pub shapes: DMatrix<f64>,
}

impl Model {
    /// Linear modes about `q` at rest, with the joints' velocity constraints: the integrator
    /// crate's generic linearisation ([`genalpha::analysis::linearise`], zero joint multipliers)
    /// and its [`natural_modes`](genalpha::analysis::Linearisation::natural_modes).
    pub fn linear_modes(&self, q: &[f64]) -> Result<Modes, Error> {
        if q.len() != self.n_coords() {
            return Err(Error::WrongLength { what: "q", got: q.len(), expected: self.n_coords() });
        }
        let mu = vec![0.0; self.n_velocity_constraints()];
        let natural = analysis::linearise(self, 0.0, q, &[], &mu)?.natural_modes().map_err(|e| match e {
            genalpha::Error::MassNotPositiveDefinite { .. } => Error::SingularMass,
            other => Error::Integrator(other),
        })?;
        Ok(Modes { omega: natural.omega, shapes: natural.shapes })
    }
}
