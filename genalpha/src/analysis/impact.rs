//! An inelastic change of the constraint set: the velocities after a joint locks.

use super::{null_space, to_dmatrix};
use crate::{ConstrainedSystem, DenseMatrix, Error};
use nalgebra::{DMatrix, DVector};

/// The velocities of a system right after its constraints `G v = 0` (the holonomic rows'
/// `Φ_q` and the velocity rows' `B`, at `q`) are imposed impulsively, as when a hinge locks or a
/// body hits a stop: the impulse `Gᵀν` is the one that makes the motion admissible with the
/// least change of kinetic energy,
///
/// $$ v^+ = \arg\min \tfrac12 (v^+ - v)^T M (v^+ - v) \quad\text{with}\quad G v^+ = 0
///   \;\Longrightarrow\; v^+ = N (N^T M N)^{-1} N^T M v ,$$
///
/// `N` an orthonormal basis of `ker G` ([`null_space`]). The impact is perfectly inelastic: the
/// kinetic energy falls by exactly `½ (v − v⁺)ᵀ M (v − v⁺)` (the M-orthogonal projection), which
/// is [`Impact::energy_loss`]. Velocities that already satisfy the constraints pass unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct Impact {
    /// Velocities after the impact (`n_dof` entries).
    pub velocities: Vec<f64>,
    /// Kinetic energy lost, `½ (v − v⁺)ᵀ M (v − v⁺)` ≥ 0, J.
    pub energy_loss: f64,
}

/// The impact of [`Impact`] on `system` at time `t`, coordinates `q`, velocities `v`.
///
/// # Errors
/// [`Error::DecompositionNotConverged`] when the null space cannot be computed;
/// [`Error::MassNotPositiveDefinite`] when `NᵀMN` has no Cholesky factor.
///
/// # Example: two unit masses on a line, the second moving, then coupled
///
/// ```
/// use genalpha::{ConstrainedSystem, MatView};
/// use genalpha::analysis::impact;
///
/// /// Two unit masses, `q₁ − q₂ = 0` imposed as a velocity row.
/// struct Pair;
/// impl ConstrainedSystem for Pair {
///     fn n_coords(&self) -> usize { 2 }
///     fn n_dof(&self) -> usize { 2 }
///     fn n_velocity_constraints(&self) -> usize { 1 }
///     fn residual_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], a: &[f64], r: &mut [f64]) {
///         r.copy_from_slice(a);
///     }
///     fn iteration_matrix_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], _a: &[f64],
///                                 c_m: f64, _c_c: f64, _c_k: f64, k: &mut MatView<'_>) {
///         k.add(0, 0, c_m);
///         k.add(1, 1, c_m);
///     }
///     fn psi_v_inplace(&self, _t: f64, _q: &[f64], j: &mut MatView<'_>) {
///         j.add(0, 0, 1.0);
///         j.add(0, 1, -1.0);
///     }
/// }
/// let hit = impact(&Pair, 0.0, &[0.0, 0.0], &[0.0, 2.0]).unwrap();
/// // Momentum 2 shared: both move at 1; the kinetic energy falls from 2 to 1.
/// assert!((hit.velocities[0] - 1.0).abs() < 1e-12 && (hit.velocities[1] - 1.0).abs() < 1e-12);
/// assert!((hit.energy_loss - 1.0).abs() < 1e-12);
/// ```
pub fn impact<S: ConstrainedSystem + ?Sized>(system: &S, t: f64, q: &[f64], v: &[f64]) -> Result<Impact, Error> {
    let (n, n_h, n_v) = (system.n_dof(), system.n_holonomic(), system.n_velocity_constraints());
    let zeros = vec![0.0; n];
    let mut m = DenseMatrix::zeros(n, n);
    system.iteration_matrix_inplace(t, q, &zeros, &zeros, 1.0, 0.0, 0.0, &mut m.view());
    let mass = to_dmatrix(&m);
    let mut g = DenseMatrix::zeros(n_h + n_v, n);
    system.phi_q_inplace(t, q, &mut g.block(0, 0, n_h, n));
    system.psi_v_inplace(t, q, &mut g.block(n_h, 0, n_v, n));
    let basis = null_space(&to_dmatrix(&g))?;
    let mass = (&mass + mass.transpose()) * 0.5;
    let reduced: DMatrix<f64> = basis.transpose() * &mass * &basis;
    let chol = reduced.cholesky().ok_or(Error::MassNotPositiveDefinite { n_free: basis.ncols() })?;
    let v_minus = DVector::from_column_slice(v);
    let y = chol.solve(&(basis.transpose() * (&mass * &v_minus)));
    let v_plus = &basis * y;
    let jump = &v_minus - &v_plus;
    let energy_loss = 0.5 * jump.dot(&(&mass * &jump));
    Ok(Impact { velocities: v_plus.as_slice().to_vec(), energy_loss })
}
