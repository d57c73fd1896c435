//! The energies every formulation reports.

use serde::Serialize;

/// Energies in J. `potential = −∫ m g·(r − r_ref) ds − Σ m_p g·(r_p − r_p,ref)` (zero in the
/// reference configuration).
///
/// ```
/// let e = formulation::Energies { kinetic: 1.0, elastic: 2.0, potential: -0.5, spring: 0.25 };
/// assert_eq!(e.total(), 2.75);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Energies {
    /// Kinetic energy T = ½ q̇ᵀ M q̇ (point masses included), J.
    pub kinetic: f64,
    /// Elastic strain energy U (ANCF: with the cross-section penalty terms), J.
    pub elastic: f64,
    /// Gravitational potential V relative to the reference configuration, J.
    pub potential: f64,
    /// Energy of the hinge springs `Σ ½ k (θ − θ₀)²`, J.
    pub spring: f64,
}

impl Energies {
    /// T + U + V + spring energy, J.
    pub fn total(&self) -> f64 {
        self.kinetic + self.elastic + self.potential + self.spring
    }
}
