//! Linearisation of a constrained system about a configuration at rest.

use super::{null_space, to_dmatrix};
use crate::{ConstrainedSystem, DenseMatrix, Error};
use nalgebra::DMatrix;

/// The linear equations of small motions `q = q_0 ∘ exp(δq)`, `v = δv` about `(q_0, v = 0)`:
///
/// $$ M\,\dot{\delta v} + C\,\delta v + K\,\delta q + G^T\delta\nu = 0,\qquad G\,\delta q = 0 ,$$
///
/// and their restriction to the admissible motions `δq = N y`. All matrices are in the tangent
/// space (`n_dof` columns). The velocity rows `B` enter `G` as the Jacobian of the joints they
/// differentiate: `B(q_0) δv = 0` integrates to `B(q_0) δq = 0` for motions starting in
/// `ker G` (this assumes `∂b/∂q = 0` at `q_0`, as for joints written at velocity level).
#[derive(Debug, Clone, PartialEq)]
pub struct Linearisation {
    /// Mass matrix `M = ∂r/∂v_dot` (n_dof × n_dof).
    pub mass: DMatrix<f64>,
    /// Damping matrix `C = ∂r/∂v` at `v = 0` (gyroscopic terms vanish at rest; aerodynamic
    /// damping does not).
    pub damping: DMatrix<f64>,
    /// Stiffness matrix `K = ∂r/∂q + ∂(Φ_qᵀλ_0 + Bᵀμ_0)/∂q`, including the geometric stiffness
    /// of the constraint forces; unsymmetric under follower loads.
    pub stiffness: DMatrix<f64>,
    /// Constraint Jacobian `G`: the `n_holonomic` rows of `Φ_q`, then the rows of `B`.
    pub constraint_jacobian: DMatrix<f64>,
    /// Number of holonomic rows at the top of [`constraint_jacobian`](Self::constraint_jacobian).
    pub n_holonomic: usize,
    /// Orthonormal basis `N` of `ker G` (n_dof × n_free), see [`null_space`](super::null_space).
    pub null_space: DMatrix<f64>,
    /// `Nᵀ M N`.
    pub reduced_mass: DMatrix<f64>,
    /// `Nᵀ C N`.
    pub reduced_damping: DMatrix<f64>,
    /// `Nᵀ K N`.
    pub reduced_stiffness: DMatrix<f64>,
}

impl Linearisation {
    /// Number of tangent unknowns `n_dof`.
    pub fn n_dof(&self) -> usize {
        self.mass.nrows()
    }
    /// Number of free motions (columns of the null-space basis).
    pub fn n_free(&self) -> usize {
        self.null_space.ncols()
    }
    /// Whether the reduced stiffness is symmetric to `rtol` of its largest entry (then the
    /// undamped modes of [`natural_modes`](Self::natural_modes) are exact).
    pub fn is_stiffness_symmetric(&self, rtol: f64) -> bool {
        let k = &self.reduced_stiffness;
        (k - k.transpose()).amax() <= rtol * k.amax()
    }
}

/// Linearise `system` at time `t` about `(q0, v = 0)` with the multipliers `(lambda, mu)` of
/// the equilibrium (from [`StaticSolution`](super::StaticSolution); zeros for an unloaded
/// reference configuration). `M`, `C` and `K` are the model's
/// [`iteration_matrix_inplace`](ConstrainedSystem::iteration_matrix_inplace) with one coefficient
/// set to one and the others to zero, `K` plus
/// [`constraint_force_tangent_inplace`](ConstrainedSystem::constraint_force_tangent_inplace).
///
/// # Errors
/// [`Error::DecompositionNotConverged`] when the null-space SVD does not converge.
///
/// # Panics
/// When a vector's length does not match the system.
pub fn linearise<S: ConstrainedSystem + ?Sized>(
    system: &S,
    t: f64,
    q0: &[f64],
    lambda: &[f64],
    mu: &[f64],
) -> Result<Linearisation, Error> {
    let (n, n_h, n_v) = (system.n_dof(), system.n_holonomic(), system.n_velocity_constraints());
    assert_eq!(q0.len(), system.n_coords(), "q0 has the wrong length");
    assert_eq!(lambda.len(), n_h, "lambda has the wrong length");
    assert_eq!(mu.len(), n_v, "mu has the wrong length");
    let zeros = vec![0.0; n];
    let part = |c_m: f64, c_c: f64, c_k: f64| {
        let mut d = DenseMatrix::zeros(n, n);
        system.iteration_matrix_inplace(t, q0, &zeros, &zeros, c_m, c_c, c_k, &mut d.view());
        d
    };
    let mass = to_dmatrix(&part(1.0, 0.0, 0.0));
    let damping = to_dmatrix(&part(0.0, 1.0, 0.0));
    let mut k = part(0.0, 0.0, 1.0);
    system.constraint_force_tangent_inplace(t, q0, lambda, mu, 1.0, &mut k.view());
    let stiffness = to_dmatrix(&k);
    let mut g = DenseMatrix::zeros(n_h + n_v, n);
    system.phi_q_inplace(t, q0, &mut g.block(0, 0, n_h, n));
    system.psi_v_inplace(t, q0, &mut g.block(n_h, 0, n_v, n));
    let constraint_jacobian = to_dmatrix(&g);
    let basis = null_space(&constraint_jacobian)?;
    let reduce = |a: &DMatrix<f64>| basis.transpose() * a * &basis;
    Ok(Linearisation {
        reduced_mass: reduce(&mass),
        reduced_damping: reduce(&damping),
        reduced_stiffness: reduce(&stiffness),
        mass,
        damping,
        stiffness,
        constraint_jacobian,
        n_holonomic: n_h,
        null_space: basis,
    })
}
