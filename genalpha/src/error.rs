//! Typed errors of the integrator.

/// Errors of the generalized-α integrator. Every variant carries the time it happened at.
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
}
