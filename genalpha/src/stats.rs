//! Work counters.

/// Statistics of one time step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepStats {
    /// Newton iterations of this step.
    pub n_newton_iters: usize,
    /// Factorisations of the iteration matrix in this step.
    pub n_factorizations: usize,
    /// Final infinity norm of the scaled dynamic residual.
    pub residual_norm: f64,
    /// Final infinity norm of the holonomic constraint residual Φ.
    pub phi_norm: f64,
    /// Final infinity norm of the velocity constraint residual B v + b.
    pub psi_norm: f64,
    /// Sub-steps the step was completed in (1 unless Newton failed and the step was halved).
    pub n_substeps: usize,
}

/// Accumulated statistics of a run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Accepted steps.
    pub n_steps: usize,
    /// Newton iterations, all steps.
    pub n_newton_iters: usize,
    /// Largest number of Newton iterations in one step.
    pub max_newton_iters: usize,
    /// Numeric factorisations of the iteration matrix.
    pub n_factorizations: usize,
    /// Residual evaluations.
    pub n_residual_evals: usize,
    /// Splits of a step into two halves, at any depth: after a Newton failure or too large a
    /// local error, and (with local error control) the splits of a step started at the depth
    /// the previous steps needed. A step done in `k` sub-steps counts `k − 1`.
    pub n_step_halvings: usize,
}

impl Stats {
    pub(crate) fn record(&mut self, s: &StepStats) {
        self.n_step_halvings += s.n_substeps.saturating_sub(1);
        self.n_steps += 1;
        self.n_newton_iters += s.n_newton_iters;
        self.max_newton_iters = self.max_newton_iters.max(s.n_newton_iters);
        self.n_factorizations += s.n_factorizations;
    }
}

/// One Newton iteration, recorded when tracing is on ([`GenAlpha::set_trace`](crate::GenAlpha::set_trace)):
/// what the iteration did and how far it still was from convergence. Attempts that failed and
/// were retried as half steps are recorded too (their `h` is the attempted step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationRecord {
    /// End time of the attempted step, s.
    pub t: f64,
    /// Attempted step size, s.
    pub h: f64,
    /// Iteration number within the attempt (1 = at the predictor).
    pub iter: usize,
    /// The iteration matrix was assembled and factorised at this iterate.
    pub factorized: bool,
    /// Scaled infinity norm of the dynamic residual before the update.
    pub residual_norm: f64,
    /// Infinity norm of Φ before the update.
    pub phi_norm: f64,
    /// Infinity norm of B v + b before the update.
    pub psi_norm: f64,
    /// Weighted increment against its tolerance (converged at ≤ 1).
    pub increment_norm: f64,
    /// The unknown (tangent index) with the largest weighted increment ratio.
    pub worst_unknown: usize,
}
