//! Work counters of the solver.

/// Counters accumulated over the solver's life (tests assert exact values for fixed set-ups).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    /// Unsteady steps taken.
    pub n_steps: usize,
    /// Steady solves.
    pub n_steady_solves: usize,
    /// AIC assemblies.
    pub n_aic_builds: usize,
    /// LU factorisations.
    pub n_factorizations: usize,
    /// Point–filament Biot–Savart pair evaluations (padded to whole blocks).
    pub n_pair_evaluations: u64,
    /// Wall time spent in solves and steps, s.
    pub wall_time: f64,
}
