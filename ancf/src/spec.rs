//! The scene description the harness hands over: sections, bodies, joints and solver options,
//! with their validation.

use crate::Error;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Cross-section data per unit length (SI). Centre of mass and shear centre on the beam axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Mass per unit length m = ρA, kg/m.
    pub mass: f64,
    /// Torsional inertia ρI_xx, kg·m.
    pub rho_ixx: f64,
    /// Inertia about the section y axis ρI_yy = ∫ρz² dA, kg·m.
    pub rho_iyy: f64,
    /// Inertia about the section z axis ρI_zz = ∫ρy² dA, kg·m.
    pub rho_izz: f64,
    /// Axial stiffness EA, N.
    pub ea: f64,
    /// Shear stiffness along y, GA_y, N.
    pub ga_y: f64,
    /// Shear stiffness along z, GA_z, N.
    pub ga_z: f64,
    /// Torsional stiffness GJ, N·m².
    pub gj: f64,
    /// Bending stiffness about y (out-of-plane flap for a wing), EI_yy, N·m².
    pub ei_yy: f64,
    /// Bending stiffness about z, EI_zz, N·m².
    pub ei_zz: f64,
}

impl Section {
    /// Slope inertias of the ANCF mass matrix (docs/ancf.md §2):
    /// `D_yy = (J_xx − J_yy + J_zz)/2`, `D_zz = (J_xx + J_yy − J_zz)/2`, kg·m. Exact when
    /// `J_xx = J_yy + J_zz`; otherwise the torsional inertia `J_xx = D_yy + D_zz` is kept.
    pub fn slope_inertias(&self) -> (f64, f64) {
        let d_yy = 0.5 * (self.rho_ixx - self.rho_iyy + self.rho_izz);
        let d_zz = 0.5 * (self.rho_ixx + self.rho_iyy - self.rho_izz);
        (d_yy.max(0.0), d_zz.max(0.0))
    }

    fn validate(&self, field: &str) -> Result<(), Error> {
        let positive = [("mass", self.mass), ("ea", self.ea), ("ga_y", self.ga_y), ("ga_z", self.ga_z)];
        let positive2 = [("gj", self.gj), ("ei_yy", self.ei_yy), ("ei_zz", self.ei_zz)];
        let non_negative = [("rho_ixx", self.rho_ixx), ("rho_iyy", self.rho_iyy), ("rho_izz", self.rho_izz)];
        for (name, v) in positive.iter().chain(&positive2).chain(&non_negative) {
            finite(&format!("{field}.{name}"), *v)?;
        }
        for (name, v) in positive.iter().chain(&positive2) {
            if *v <= 0.0 {
                return Err(Error::NotPositive { field: format!("{field}.{name}"), value: *v });
            }
        }
        for (name, v) in non_negative {
            if v < 0.0 {
                return Err(Error::Negative { field: format!("{field}.{name}"), value: v });
            }
        }
        let (d_yy, d_zz) = self.slope_inertias();
        if d_yy <= 0.0 || d_zz <= 0.0 {
            return Err(Error::MasslessSection { field: field.to_string(), d_yy, d_zz });
        }
        Ok(())
    }
}

/// A straight beam body in its reference configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct BodySpec {
    /// Name, for reports.
    pub name: String,
    /// Start point, global, m.
    pub start: Vector3<f64>,
    /// Length, m.
    pub length: f64,
    /// Columns = section frame x (beam axis), y, z in global coordinates (orthonormal,
    /// right-handed).
    pub frame: Matrix3<f64>,
    /// Section data.
    pub section: Section,
    /// Number of two-node elements.
    pub n_elements: usize,
}

impl BodySpec {
    /// End point of the reference axis, global, m.
    pub fn end(&self) -> Vector3<f64> {
        self.start + self.frame.column(0) * self.length
    }

    pub(crate) fn validate(&self, i: usize) -> Result<(), Error> {
        let field = format!("bodies[{i}]");
        for (k, v) in self.start.iter().enumerate() {
            finite(&format!("{field}.start[{k}]"), *v)?;
        }
        finite(&format!("{field}.length"), self.length)?;
        if self.length <= 0.0 {
            return Err(Error::NotPositive { field: format!("{field}.length"), value: self.length });
        }
        for (k, v) in self.frame.iter().enumerate() {
            finite(&format!("{field}.frame[{}][{}]", k % 3, k / 3), *v)?;
        }
        let deviation = (self.frame.transpose() * self.frame - Matrix3::identity()).amax();
        let det = self.frame.determinant();
        if deviation > 1e-6 || det <= 0.0 {
            return Err(Error::BadFrame { field: format!("{field}.frame"), deviation, det });
        }
        self.section.validate(&format!("{field}.section"))?;
        if self.n_elements == 0 {
            return Err(Error::ZeroElements { field: format!("{field}.n_elements") });
        }
        Ok(())
    }
}

/// Joints; bodies are referred to by index into the body list.
#[derive(Debug, Clone, PartialEq)]
pub enum JointSpec {
    /// Body's start point pinned; rotation only about a fixed global axis.
    GroundHinge {
        /// The body.
        body: usize,
        /// Hinge axis, global (normalised internally).
        axis: Vector3<f64>,
    },
    /// End of `parent` to start of `child`; axis `a = sin β x + cos β y` in the section frame
    /// of the parent's end (β in rad, [−π/2, π/2]).
    FlaredHinge {
        /// Parent body (its end section).
        parent: usize,
        /// Child body (its start section).
        child: usize,
        /// Flare angle β, rad.
        beta: f64,
    },
    /// Body's start section fully clamped to ground.
    Clamp {
        /// The body.
        body: usize,
    },
    /// A flared hinge locked at its reference fold: the child's start section is welded to the
    /// parent's end section (`r`, `r_y`, `r_z` continuous, as a clamp to the parent).
    /// The fold angle is still measured about `a = sin β x + cos β y`.
    LockedHinge {
        /// Parent body (its end section).
        parent: usize,
        /// Child body (its start section).
        child: usize,
        /// Flare angle β of the locked hinge, rad.
        beta: f64,
    },
}

impl JointSpec {
    pub(crate) fn validate(&self, j: usize, bodies: &[BodySpec]) -> Result<(), Error> {
        let field = format!("joints[{j}]");
        let check = |name: &str, body: usize| {
            if body >= bodies.len() {
                Err(Error::NoSuchBody { field: format!("{field}.{name}"), body, n_bodies: bodies.len() })
            } else {
                Ok(())
            }
        };
        match *self {
            JointSpec::GroundHinge { body, axis } => {
                check("body", body)?;
                for (k, v) in axis.iter().enumerate() {
                    finite(&format!("{field}.axis[{k}]"), *v)?;
                }
                if axis.norm() == 0.0 {
                    return Err(Error::ZeroAxis { field: format!("{field}.axis") });
                }
            }
            JointSpec::FlaredHinge { parent, child, beta } | JointSpec::LockedHinge { parent, child, beta } => {
                check("parent", parent)?;
                check("child", child)?;
                if parent == child {
                    return Err(Error::SelfJoint { field: format!("{field}.child"), body: child });
                }
                finite(&format!("{field}.beta"), beta)?;
                if beta.abs() > std::f64::consts::FRAC_PI_2 * (1.0 + 1e-12) {
                    return Err(Error::BetaOutOfRange { field: format!("{field}.beta"), beta });
                }
                let gap = (bodies[parent].end() - bodies[child].start).norm();
                let scale = bodies[parent].length.max(bodies[child].length);
                if gap > 1e-9 * scale.max(1.0) {
                    return Err(Error::JointGap { field: format!("{field}.child"), gap });
                }
            }
            JointSpec::Clamp { body } => check("body", body)?,
        }
        Ok(())
    }
}

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
    /// Factor κ of the shear-gradient stabilisation `½κ∫[EI_zz γ_y'² + EI_yy γ_z'² + GJ γ_yz'²]dx`
    /// (see [`strain`](crate::strain)); default 100, 0 switches it off. The node-local joint
    /// compliance it leaves is about `l/(κ L)` of the physical one. Its stiffness `κ·EI` is not
    /// bounded by the axial and shear stiffnesses: on thick sections (`EI ≈ EA·l²`, the paper's
    /// wing chordwise) κ = 1000 made it ~500× EA on quadratic strain measures, and Newton's
    /// convergence radius collapsed (7–11 iterations, step halvings, failure at AoA 10°).
    pub shear_gradient_factor: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self { path: SolvePath::Dae, curvature: Curvature::Hybrid, penalty_factor: 1.0, shear_gradient_factor: 100.0 }
    }
}

impl Options {
    pub(crate) fn validate(&self) -> Result<(), Error> {
        finite("options.penalty_factor", self.penalty_factor)?;
        if self.penalty_factor <= 0.0 {
            return Err(Error::NotPositive { field: "options.penalty_factor".into(), value: self.penalty_factor });
        }
        finite("options.shear_gradient_factor", self.shear_gradient_factor)?;
        if self.shear_gradient_factor < 0.0 {
            return Err(Error::Negative {
                field: "options.shear_gradient_factor".into(),
                value: self.shear_gradient_factor,
            });
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

    #[test]
    fn slope_inertias_preserve_the_torsional_inertia() {
        let s = crate::samples::pendulum_section(1.0);
        let (d_yy, d_zz) = s.slope_inertias();
        approx::assert_relative_eq!(d_yy + d_zz, s.rho_ixx, max_relative = 1e-14);
        // exact when J_xx = J_yy + J_zz: J_yy = D_zz, J_zz = D_yy
        approx::assert_relative_eq!(d_zz, s.rho_iyy, max_relative = 1e-14);
        approx::assert_relative_eq!(d_yy, s.rho_izz, max_relative = 1e-14);
    }
}
