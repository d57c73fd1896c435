//! Model options, and the scene types of the [`scene`] crate re-exported (the scene is validated
//! there, once for both formulations).

use crate::Error;
use serde::{Deserialize, Serialize};

pub use scene::{BodySpec, ForceElement, JointSpec, PointMass, Scene, Section, Twist};

/// Which form of the equations of motion the model presents to the integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolvePath {
    /// Index-3 DAE: all nodal coordinates, joints as holonomic constraints with multipliers.
    #[default]
    Dae,
    /// ODE: independent coordinates `z` with `q = B z + q_p`, `Φ_q B = 0` (paper eq. 6–7); no
    /// multipliers, constant reduced mass `BᵀMB`.
    Ode,
}

/// Bending-curvature measure of the element (docs/ancf.md §3.2; details in [`strain`](crate::strain)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Curvature {
    /// Element-mean curvature from the rotation of the section slopes plus the zero-mean
    /// variation of the cubic centreline; transverse shear at the two Gauss points. Joints that
    /// hold a section take the bending moment directly; linearly varying curvature is exact.
    #[default]
    Hybrid,
    /// `K2 = −r_z·r_xx`, `K3 = r_y·r_xx` from the centreline alone; transverse shear at the
    /// nodes. Accurate inside a body, but a joint holding the section reaches the centreline only
    /// through the nodal shear (spurious joint compliance ∝ 1/(GA·l)). For comparison.
    Kirchhoff,
    /// `K2 = ½(r_x·r_z,x − r_z·r_xx)`, `K3 = ½(r_y·r_xx − r_x·r_y,x)` (skew part of `FᵀF_x`);
    /// transverse shear at the midpoint. Half the moment in the centreline, half in the sections;
    /// for comparison.
    Mixed,
}

/// Model options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Options {
    /// DAE (default) or ODE form.
    pub path: SolvePath,
    /// Curvature measure (default Hybrid).
    pub curvature: Curvature,
    /// Factor on the cross-section penalty stiffnesses (EA, EA, GA_y + GA_z); default 1.
    pub penalty_factor: f64,
    /// Factor `c_t` of the section ties at the hinges' nodes (docs/ancf.md §3.5): stiffness
    /// `c_t EI/l` on the metric strains of the node's slopes, with the EI (or GJ) of the
    /// rotation each one resists; default 1000. 0 switches them off, and a hinge's moment then reaches the section
    /// through the node's shear and penalty stiffness alone (∝ l): a joint compliance that grows
    /// as the mesh is refined.
    pub joint_tie_factor: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self { path: SolvePath::Dae, curvature: Curvature::Hybrid, penalty_factor: 1.0, joint_tie_factor: 1000.0 }
    }
}

impl Options {
    pub(crate) fn validate(&self) -> Result<(), Error> {
        finite("options.penalty_factor", self.penalty_factor)?;
        if self.penalty_factor <= 0.0 {
            return Err(Error::NotPositive { field: "options.penalty_factor".into(), value: self.penalty_factor });
        }
        finite("options.joint_tie_factor", self.joint_tie_factor)?;
        if self.joint_tie_factor < 0.0 {
            return Err(Error::Negative { field: "options.joint_tie_factor".into(), value: self.joint_tie_factor });
        }
        Ok(())
    }
}

pub(crate) fn finite(field: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() { Ok(()) } else { Err(Error::NonFinite { field: field.to_string(), value }) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_deserialise_with_defaults_and_reject_unknown_fields() {
        let o: Options = serde_json::from_str(r#"{"path": "ode"}"#).unwrap();
        assert_eq!(o, Options { path: SolvePath::Ode, ..Options::default() });
        let o: Options = serde_json::from_str(r#"{"curvature": "kirchhoff", "penalty_factor": 10}"#).unwrap();
        assert_eq!(o.curvature, Curvature::Kirchhoff);
        assert_eq!(o.penalty_factor, 10.0);
        let e = serde_json::from_str::<Options>(r#"{"pth": "ode"}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `pth`"), "{e}");
    }
}
