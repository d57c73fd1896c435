//! # genalpha — the one generalized-α integrator of the toolkit
//!
//! Integrates constrained second-order systems in the Arnold–Brüls form
//!
//! $$ M(q)\,\dot v + g(q, v, t) + \Phi_q^T \lambda + B^T \mu = 0,\qquad
//!    \Phi(q) = 0,\qquad B(q)\,v + b(q, t) = 0 $$
//!
//! with the Chung–Hulbert parameters derived from `rho_inf`:
//! `alpha_m = (2 rho_inf - 1)/(rho_inf + 1)`, `alpha_f = rho_inf/(rho_inf + 1)`,
//! `gamma = 1/2 - alpha_m + alpha_f`, `beta = (gamma + 1/2)^2 / 4`, and the update
//!
//! $$ q_{n+1} = q_n \circ \exp\big(h\,\Delta q_n\big),\quad
//!    \Delta q_n = v_n + h(\tfrac12 - \beta) a_n + h\beta a_{n+1},\quad
//!    v_{n+1} = v_n + h(1-\gamma) a_n + h\gamma a_{n+1},$$
//! $$ (1-\alpha_m) a_{n+1} + \alpha_m a_n = (1-\alpha_f)\dot v_{n+1} + \alpha_f \dot v_n .$$
//!
//! `q ∘ exp(·)` is the model's [`ConstrainedSystem::retract_inplace`]: plain addition for
//! vector coordinates (ANCF), an exponential-map update for quaternion frames (GEBF).
//! Newton iterates on the tangent increment with the scaled iteration matrix of docs/integrator.md §5.2
//! (dynamic rows × 1/β′, velocity rows × 1/γ′, multipliers λ/β′, μ/β′). The factorisation is
//! reused across iterations and steps while Newton contracts, refreshed at the predictor for a
//! while after a reused one failed; an update made with a reused factorisation that diverged is
//! taken back and the matrix factorised at the iterate before it; an iterate is accepted when the increment, or the
//! contraction estimate θ/(1 − θ)·|Δ| (`NewtonParams::estimate_convergence`), is below the
//! tolerance. A failed step is retried as two half steps (`NewtonParams::max_step_halvings`).
//! The default [`DenseLu`] switches to a bordered band LU (Schur complement on the border) when
//! the system declares a [`BandedBorder`] structure, on 6×6 node blocks when it declares nodes.
//! Newton starts from a predictor: constant or linearly extrapolated acceleration
//! (`NewtonParams::predictor`).
//!
//! [`Form::ChungHulbert`] keeps the Newmark relations and the end-of-step constraints but
//! evaluates the forces (and the constraint forces' Jacobians) at the weighted state
//! `q_α = q_n ∘ exp((1 − α_f) h Δq_n)`, `v_α = (1 − α_f) v_{n+1} + α_f v_n`,
//! `v̇_α = (1 − α_m) a_{n+1} + α_m a_n`: Chung & Hulbert's original form, the implicit midpoint
//! rule at `rho_inf = 1`. Every weighted quantity moves by `1 − α_f` times its end-of-step
//! increment, so the scaled iteration matrix is the same; only the constraint rows (Φ_q and B
//! at the end of the step) and the multiplier columns (Φ_qᵀ and Bᵀ at the weighted state)
//! differ.
//!
//! The crate knows no beams: a structural model implements [`ConstrainedSystem`]. The same trait
//! serves the [`analysis`] module: static equilibrium with continuation, linearisation about it,
//! natural and damped modes, written once for every model.
#![warn(missing_docs)]

pub mod analysis;
mod banded;
mod error;
mod integrator;
mod linear_solver;
mod matrix;
mod node_lu;
mod params;
mod stats;
mod system;
mod vecops;

pub use banded::BandedBorder;
pub use error::Error;
pub use integrator::{GenAlpha, State};
pub use linear_solver::{Assembled, DENSE_FALLBACK_MAX, DenseLu, Entries, LinearSolver};
pub use matrix::{AssemblyTarget, DenseMatrix, MatView};
pub use params::{Coefficients, Form, IntegratorParams, NewtonParams, Predictor};
pub use stats::{IterationRecord, Stats, StepStats};
pub use system::ConstrainedSystem;

#[cfg(test)]
mod tests;
