//! Typed errors of the integrator.

/// Errors of the generalized-α integrator and of the [`analysis`](crate::analysis) module. A
/// variant raised by a time step or a static solve carries the time it happened at.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// Newton did not converge within `max_iter` iterations.
    #[error(
        "Newton did not converge at t = {t:.6} s after {iter} iterations \
         (scaled residual {residual_norm:.3e}, increment {increment_norm:.3e}, \
         position constraint {phi_norm:.3e}, velocity constraint {psi_norm:.3e})"
    )]
    NewtonDiverged {
        /// Time of the failed step, s.
        t: f64,
        /// Iterations done.
        iter: usize,
        /// Infinity norm of the scaled dynamic residual.
        residual_norm: f64,
        /// Weighted norm of the last increment (converged when ≤ 1).
        increment_norm: f64,
        /// Infinity norm of the holonomic constraint residual.
        phi_norm: f64,
        /// Infinity norm of the velocity constraint residual.
        psi_norm: f64,
    },
    /// The residual or the increment stopped being finite.
    #[error("non-finite state at t = {t:.6} s, Newton iteration {iter}")]
    NonFinite {
        /// Time of the failed step, s.
        t: f64,
        /// Newton iteration.
        iter: usize,
    },
    /// The iteration matrix is singular (zero pivot).
    #[error("singular iteration matrix at t = {t:.6} s (zero pivot in row {pivot})")]
    SingularMatrix {
        /// Time, s.
        t: f64,
        /// Row of the first zero pivot.
        pivot: usize,
    },
    /// Invalid integrator parameters.
    #[error("invalid integrator parameter `{field}`: {reason}")]
    InvalidParameter {
        /// Name of the offending field.
        field: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The static Newton iteration did not converge.
    #[error(
        "static equilibrium not found at t = {t:.6} s after {iter} Newton iterations \
         (residual {residual_norm:.3e}, weighted increment {increment_norm:.3e})"
    )]
    StaticNotConverged {
        /// Time the forces were evaluated at, s.
        t: f64,
        /// Iterations done.
        iter: usize,
        /// Infinity norm of the last equilibrium residual `r + Φ_qᵀλ + Bᵀμ`.
        residual_norm: f64,
        /// Weighted infinity norm of the last increment.
        increment_norm: f64,
    },
    /// A step of a static continuation failed.
    #[error("continuation step {step} (parameter {parameter}) failed: {source}")]
    ContinuationFailed {
        /// Index of the failed step in the path.
        step: usize,
        /// The parameter value of that step.
        parameter: f64,
        /// What went wrong in its solve.
        source: Box<Error>,
    },
    /// The mass matrix restricted to the free motions is not positive definite (a free motion
    /// without inertia).
    #[error("the mass matrix on the {n_free} free motions is not positive definite")]
    MassNotPositiveDefinite {
        /// Number of free motions (null-space dimension).
        n_free: usize,
    },
    /// A dense SVD or eigenvalue iteration did not converge (or produced non-finite values).
    #[error("a dense decomposition of dimension {n} did not converge")]
    DecompositionNotConverged {
        /// Dimension of the decomposed matrix.
        n: usize,
    },
}
