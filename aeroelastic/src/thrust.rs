//! Thrust (case field `thrust`, issue 35 item 4): a follower force on a body, its magnitude a
//! number or a schedule in time. The structure carries it as the force element
//! `scene::ForceElement::Thrust` (its direction turns with the section it acts on); the trim
//! ([`crate::trim`]) scales every thrust's magnitude together.

use crate::control_surface::Deflection;

/// One thrust: a follower force at a point of a body's axis.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Thrust {
    /// Name (reports and `--set thrust.<name>.…`; default `thrust<k>`).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub name: Option<String>,
    /// The body it acts on (its name).
    pub body: String,
    /// Arclength of the point of application along the body's axis, m, in `[0, length]`.
    pub at: f64,
    /// Direction in the body's section frame at `at` (`x` along the axis, `y` towards the
    /// leading edge, `z = x × y`); normalised. The force turns with the section: a follower force.
    pub direction: [f64; 3],
    /// Magnitude, N: a number, or a schedule `[[t, N], …]` (linear in between, held outside).
    pub magnitude: Deflection,
}

impl Thrust {
    /// The magnitude at time `t`, N.
    pub fn magnitude_at(&self, t: f64) -> f64 {
        self.magnitude.at(t).0
    }

    /// The unit direction in the section frame (the zero vector stays zero; validation refuses it).
    pub fn unit_direction(&self) -> [f64; 3] {
        let d = self.direction;
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if n > 0.0 { [d[0] / n, d[1] / n, d[2] / n] } else { d }
    }

    /// The magnitude as the scene's schedule (a number: one point).
    pub fn schedule(&self) -> scene::Schedule {
        match &self.magnitude {
            Deflection::Fixed(m) => scene::Schedule::constant(*m),
            Deflection::Schedule(p) => scene::Schedule { points: p.iter().map(|x| (x[0], x[1])).collect() },
        }
    }

    /// Its display name: `name`, or `thrust<k>` for the k-th entry.
    pub fn label(&self, k: usize) -> String {
        self.name.clone().unwrap_or_else(|| format!("thrust{k}"))
    }
}
