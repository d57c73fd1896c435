//! Analyses of a [`ConstrainedSystem`](crate::ConstrainedSystem) at rest, written once for every
//! model: static equilibrium, linearisation about it, and its modes.
//!
//! **Statics** ([`StaticSolver`], [`solve_static`], [`solve_static_path`]). At rest (`v = 0`,
//! `v_dot = 0`) the equations of motion reduce to
//!
//! $$ r(q, 0, 0, t) + \Phi_q^T\lambda + B^T\mu = 0,\qquad \Phi(q) = 0,\qquad B(q)\,0 + b = 0 ,$$
//!
//! solved by Newton's method on the bordered matrix built from the model's own derivatives
//! (`iteration_matrix_inplace` with `c_m = c_c = 0`, `c_k = 1`, plus
//! `constraint_force_tangent_inplace`) and updated with the model's retraction
//! `q ← q ∘ exp(δq)`. A continuation (load stepping, or any parameter the caller sets through a
//! closure, e.g. the airspeed) chains such solves, each starting from the last equilibrium.
//!
//! **Linearisation** ([`linearise`]). About `(q_0, v = 0)` with multipliers `(λ_0, μ_0)`, a small
//! motion `q = q_0 ∘ exp(δq)` obeys
//!
//! $$ M\,\ddot{\delta q} + C\,\dot{\delta q} + K\,\delta q + G^T \delta\nu = 0,\qquad
//!    G\,\delta q = 0,\qquad G = \begin{bmatrix}\Phi_q \\ B\end{bmatrix},$$
//!
//! with `M = ∂r/∂v_dot`, `C = ∂r/∂v`, `K = ∂r/∂q + ∂(Φ_qᵀλ_0 + Bᵀμ_0)/∂q`. The admissible
//! motions are `δq = N y`, `N` an orthonormal basis of `ker G`, and
//! `Nᵀ M N ÿ + Nᵀ C N ẏ + Nᵀ K N y = 0`.
//!
//! **Modes** ([`Linearisation::natural_modes`], [`Linearisation::damped_modes`]): the undamped
//! generalized symmetric eigenproblem `Nᵀ K N φ = ω² Nᵀ M N φ`, and the complex eigenvalues of
//! the first-order form when `C ≠ 0` or `K` is unsymmetric (follower or aerodynamic loads).
//!
//! Everything here is dense: nalgebra's SVD, Cholesky and eigen-solvers (O(n³)) at the sizes of
//! our models (n < 500 tangent unknowns) take well under a second; the static Newton iteration
//! factorises with the integrator's [`DenseLu`](crate::DenseLu).

mod impact;
mod linearise;
mod modes;
mod null_space;
mod statics;

pub use impact::{Impact, impact};
pub use linearise::{Linearisation, linearise};
pub use modes::{DampedMode, NaturalModes, SHIFT_RATIO};
pub use null_space::{NULL_SPACE_RTOL, null_space};
pub use statics::{
    MAX_BACKTRACKS, STALL_ITERATIONS, StaticParams, StaticSolution, StaticSolver, load_steps, solve_static,
    solve_static_path,
};

use nalgebra::DMatrix;

/// A copy of a [`DenseMatrix`](crate::DenseMatrix) as a nalgebra matrix.
fn to_dmatrix(m: &crate::DenseMatrix) -> DMatrix<f64> {
    DMatrix::from_column_slice(m.n_rows(), m.n_cols(), m.as_slice())
}

/// `(a + aᵀ) / 2`.
fn symmetrised(a: &DMatrix<f64>) -> DMatrix<f64> {
    (a + a.transpose()) * 0.5
}
