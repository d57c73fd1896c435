//! Linear and angular momentum of a model, for free-flying checks.

use nalgebra::Vector3;

/// Linear momentum `p = ∫ ṙ dm` (kg·m/s) and angular momentum about the global origin
/// `L = ∫ r × ṙ dm + Σ R J Ω` (kg·m²/s), global components, of every body with its point
/// masses and the sections' rotary inertia — the momenta whose rates are the external forces
/// and moments, so without external loads both are constant in the continuous system.
///
/// The momentum about another point `o` is `L − o × p`:
///
/// ```
/// use nalgebra::Vector3;
/// let m = formulation::Momentum { linear: Vector3::new(1.0, 0.0, 0.0), angular: Vector3::zeros() };
/// let about = m.angular_about(&Vector3::new(0.0, 2.0, 0.0));
/// assert_eq!(about, Vector3::new(0.0, 0.0, 2.0));
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Momentum {
    /// Linear momentum, global components, kg·m/s.
    pub linear: Vector3<f64>,
    /// Angular momentum about the global origin, global components, kg·m²/s.
    pub angular: Vector3<f64>,
}

impl Momentum {
    /// Angular momentum about point `o` (global), kg·m²/s.
    pub fn angular_about(&self, o: &Vector3<f64>) -> Vector3<f64> {
        self.angular - o.cross(&self.linear)
    }
}
