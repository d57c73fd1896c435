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
    /// Solves on the factorisation of an earlier matrix ([`crate::UvlmParams::aic_refinement`]).
    pub n_refined_solves: usize,
    /// Their corrections (each a product with the matrix and a solve with the factors).
    pub n_refinement_corrections: usize,
    /// Point–filament Biot–Savart pair evaluations (padded to whole blocks).
    pub n_pair_evaluations: u64,
    /// Wall time spent in solves and steps, s.
    pub wall_time: f64,
}
