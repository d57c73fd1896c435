//! The strip correction of a lattice's loads by a section polar (the scheme of SHARPy's
//! `PolarCorrection` with `correct_lift` on, written as a pure function; docs/section_aero.md).
//!
//! All vectors are in the strip frame: `x̂` along the span, `ŷ` in the chord plane towards the
//! leading edge, `ẑ = x̂ × ŷ` the surface normal (docs/conventions.md §2). For a strip with the
//! air velocity `u` relative to it (free stream, disturbance and the strip's own motion, at the
//! strip), chord `c`, span width `w` and density `ρ`:
//!
//! 1. The section plane sees `u_n = u − (u·x̂) x̂`, speed `V = |u_n|`; drag acts along
//!    `d̂ = u_n/V`, lift along `l̂ = d̂ × x̂`; `q S = ½ρV²·c w`, `Re = V c / ν`.
//! 2. The lattice's lift `L = F_inv·l̂` gives `cl_inv = L/(qS)` and the effective incidence
//!    $$ \alpha_e = \alpha_{0,lat} + \frac{cl_{inv}}{a_{lat}}, $$
//!    inverting the lattice section's own lift line ([`LatticeSection`]: `2π` and `0` for the flat
//!    lattice of this project). It holds the three-dimensional downwash and the unsteady lift
//!    that the lattice has computed.
//! 3. The polar gives `cl, cd, cm` at `(α_e, Re)`.
//! 4. The corrected loads keep the lattice's force apart from its lift, replace the lift by the
//!    polar's and add the profile drag; the lift change and the drag act at the quarter chord
//!    `r` (relative to the point about which the moments are taken), and the polar's moment is
//!    added about the span axis:
//!    $$ F = F_{inv} + (cl - cl_{inv})\,qS\,\hat l + cd\,qS\,\hat d, \qquad M = M_{inv} + r\times(F - F_{inv}) + cm\,qS\,c\,\hat x. $$
//!
//! The lattice's induced drag (its force along `d̂`) and side force stay as they are. A polar on
//! the lattice's own line (`cl = a_lat(α − α_0,lat)`, `cd = cm = 0`) returns `F_inv`, `M_inv`.

use crate::error::{AerofoilError, Result};
use crate::polar::{Coefficients, Polar};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// The lift line of the lattice's own section, which the strip correction inverts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatticeSection {
    /// Lift-curve slope `a_lat` of the lattice's section in two-dimensional flow, 1/rad
    /// (`2π` for a flat vortex lattice).
    pub lift_slope: f64,
    /// Zero-lift incidence `α_0,lat` of the lattice's section, rad (0 for a flat lattice; a
    /// cambered lattice's own, not the polar's).
    pub zero_lift_alpha: f64,
}

impl LatticeSection {
    /// The flat thin plate: `2π`, zero-lift incidence 0.
    pub const THIN_PLATE: Self = Self { lift_slope: 2.0 * PI, zero_lift_alpha: 0.0 };
}

/// One strip of the lattice, vectors in the strip frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strip {
    /// Velocity of the air relative to the strip at the strip, m/s (points from the leading
    /// edge aft in attached flow: about `−V ŷ`).
    pub flow: Vector3<f64>,
    /// Chord, m.
    pub chord: f64,
    /// Span width of the strip, m.
    pub width: f64,
    /// Air density, kg/m³.
    pub rho: f64,
    /// Kinematic viscosity of the air, m²/s (1.5e-5 for air near 20 °C).
    pub kinematic_viscosity: f64,
    /// A fixed Reynolds number to read the polar at (e.g. the free stream's, `V∞ c/ν`, per run);
    /// `None`: the strip's own `V c/ν` on its section-plane speed, at every evaluation.
    pub fixed_reynolds: Option<f64>,
    /// The quarter-chord point relative to the reference point about which moments are given,
    /// m: where the polar's `cm` refers and where the lift change and the profile drag act.
    pub quarter_chord: Vector3<f64>,
}

impl Strip {
    /// Speed in the section plane `V = |u − (u·x̂)x̂|`, m/s.
    pub fn section_speed(&self) -> f64 {
        self.flow.yz().norm()
    }

    /// The Reynolds number the polar is read at: `fixed_reynolds`, or `V c / ν` on the
    /// section-plane speed.
    pub fn reynolds(&self) -> f64 {
        self.fixed_reynolds.unwrap_or_else(|| self.section_speed() * self.chord / self.kinematic_viscosity)
    }

    fn validate(&self) -> Result<()> {
        let bad = |field, value| Err(AerofoilError::InvalidStrip { field, value });
        if !self.flow.iter().all(|v| v.is_finite()) {
            return bad("flow", self.flow.norm());
        }
        if !self.quarter_chord.iter().all(|v| v.is_finite()) {
            return bad("quarter_chord", self.quarter_chord.norm());
        }
        for (field, value) in [
            ("chord", self.chord),
            ("width", self.width),
            ("rho", self.rho),
            ("kinematic_viscosity", self.kinematic_viscosity),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return bad(field, value);
            }
        }
        if self.section_speed() <= 0.0 {
            return bad("flow", self.section_speed());
        }
        if let Some(re) = self.fixed_reynolds.filter(|re| !(re.is_finite() && *re > 0.0)) {
            return bad("fixed_reynolds", re);
        }
        Ok(())
    }
}

/// A strip's force (N) and moment about its reference point (N·m), strip frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripLoads {
    /// Force, N.
    pub force: Vector3<f64>,
    /// Moment about the strip's reference point, N·m.
    pub moment: Vector3<f64>,
}

/// The corrected loads of one strip, with what produced them and their derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correction {
    /// Corrected force and moment about the reference point, strip frame.
    pub loads: StripLoads,
    /// Effective incidence `α_e`, rad.
    pub alpha: f64,
    /// Geometric incidence of the local flow, `atan2(u·ẑ, −u·ŷ)`, rad (`α_geo − α_e` is the
    /// incidence the lattice's downwash and unsteadiness take away).
    pub alpha_geometric: f64,
    /// Reynolds number the polar was read at.
    pub reynolds: f64,
    /// Lift coefficient of the lattice's lift.
    pub cl_inviscid: f64,
    /// The polar's coefficients and slopes at `(α_e, Re)`.
    pub coefficients: Coefficients,
    /// Lift direction `l̂`.
    pub lift_dir: Vector3<f64>,
    /// Drag direction `d̂` (the local flow in the section plane).
    pub drag_dir: Vector3<f64>,
    /// `q S = ½ρV² c w`, N.
    pub q_area: f64,
    /// `∂F/∂L_inv` of the correction term: `(cl'/a_lat − 1) l̂ + (cd'/a_lat) d̂`.
    pub d_force_d_lift: Vector3<f64>,
    /// `∂M/∂L_inv` of the correction term: `r × ∂F/∂L_inv + (cm' c / a_lat) x̂`, m.
    pub d_moment_d_lift: Vector3<f64>,
    /// `dF/dα_e` at fixed flow of a strip whose lattice lift follows its own line:
    /// `qS (cl' l̂ + cd' d̂)`, N/rad.
    pub d_force_d_alpha: Vector3<f64>,
    /// `dM/dα_e` at fixed flow when the lattice's lift acts at the quarter chord (steady thin
    /// plate): `r × dF/dα + cm' qS c x̂`, N·m/rad.
    pub d_moment_d_alpha: Vector3<f64>,
    /// `∂F/∂u` at fixed lattice loads, N·s/m: how the corrected force follows the strip's flow
    /// vector through `d̂`, `l̂`, `q`, `α_e` (via `cl_inv = F_inv·l̂/(qS)`) and `Re`. The full
    /// tangent adds `force_jacobian() · ∂F_inv/∂u` of the lattice.
    pub d_force_d_flow: Matrix3<f64>,
    /// `∂M/∂u` at fixed lattice loads, N·s.
    pub d_moment_d_flow: Matrix3<f64>,
}

impl Correction {
    /// Profile drag `cd qS`, N.
    pub fn profile_drag(&self) -> f64 {
        self.coefficients.cd * self.q_area
    }

    /// `∂F/∂F_inv = I + (∂F/∂L_inv) l̂ᵀ` at fixed flow: the tangent of the corrected force with
    /// respect to the lattice's force.
    pub fn force_jacobian(&self) -> Matrix3<f64> {
        Matrix3::identity() + self.d_force_d_lift * self.lift_dir.transpose()
    }

    /// `∂M/∂F_inv = (∂M/∂L_inv) l̂ᵀ` at fixed flow (`∂M/∂M_inv` is the identity), m.
    pub fn moment_jacobian(&self) -> Matrix3<f64> {
        self.d_moment_d_lift * self.lift_dir.transpose()
    }
}

/// Correct a strip's inviscid loads by the polar (module docs). Errors: an impossible strip or
/// lattice section ([`AerofoilError::InvalidStrip`]), and the polar's range errors at the
/// effective incidence and the strip's Reynolds number.
pub fn correct_strip(
    polar: &Polar,
    lattice: &LatticeSection,
    strip: &Strip,
    inviscid: &StripLoads,
) -> Result<Correction> {
    strip.validate()?;
    if !(lattice.lift_slope.is_finite() && lattice.lift_slope > 0.0) {
        return Err(AerofoilError::InvalidStrip { field: "lift_slope", value: lattice.lift_slope });
    }
    if !lattice.zero_lift_alpha.is_finite() {
        return Err(AerofoilError::InvalidStrip { field: "zero_lift_alpha", value: lattice.zero_lift_alpha });
    }
    if !inviscid.force.iter().chain(inviscid.moment.iter()).all(|v| v.is_finite()) {
        return Err(AerofoilError::InvalidStrip { field: "inviscid", value: f64::NAN });
    }
    let span = Vector3::x();
    let u_n = Vector3::new(0.0, strip.flow.y, strip.flow.z);
    let speed = u_n.norm();
    let drag_dir = u_n / speed;
    let lift_dir = drag_dir.cross(&span);
    let q_area = 0.5 * strip.rho * speed * speed * strip.chord * strip.width;
    let reynolds = strip.reynolds();
    let cl_inviscid = inviscid.force.dot(&lift_dir) / q_area;
    let a = lattice.lift_slope;
    let alpha = lattice.zero_lift_alpha + cl_inviscid / a;
    let c = polar.coefficients(alpha, reynolds)?;
    let r = strip.quarter_chord;
    let delta_f = (c.cl - cl_inviscid) * q_area * lift_dir + c.cd * q_area * drag_dir;
    let loads = StripLoads {
        force: inviscid.force + delta_f,
        moment: inviscid.moment + r.cross(&delta_f) + c.cm * q_area * strip.chord * span,
    };
    let d_force_d_lift = (c.dcl / a - 1.0) * lift_dir + (c.dcd / a) * drag_dir;
    let d_force_d_alpha = q_area * (c.dcl * lift_dir + c.dcd * drag_dir);
    let frame = StripState { speed, drag_dir, lift_dir, q_area, reynolds, cl_inviscid, lift_slope: a };
    let (d_force_d_flow, d_moment_d_flow) = flow_jacobians(&frame, &c, strip, inviscid);
    Ok(Correction {
        loads,
        alpha,
        alpha_geometric: strip.flow.z.atan2(-strip.flow.y),
        reynolds,
        cl_inviscid,
        coefficients: c,
        lift_dir,
        drag_dir,
        q_area,
        d_force_d_lift,
        d_moment_d_lift: r.cross(&d_force_d_lift) + (c.dcm * strip.chord / a) * span,
        d_force_d_alpha,
        d_moment_d_alpha: r.cross(&d_force_d_alpha) + c.dcm * q_area * strip.chord * span,
        d_force_d_flow,
        d_moment_d_flow,
    })
}

/// The section-plane quantities of one evaluation.
struct StripState {
    speed: f64,
    drag_dir: Vector3<f64>,
    lift_dir: Vector3<f64>,
    q_area: f64,
    reynolds: f64,
    cl_inviscid: f64,
    lift_slope: f64,
}

/// `∂F/∂u` and `∂M/∂u` at fixed lattice loads. With `P = diag(0, 1, 1)` (the section plane):
///
/// $$ \partial\hat d = (I - \hat d\hat d^T)P/V, \quad \partial\hat l = -[\hat x]_\times\partial\hat d,
///    \quad \partial Q = 2Q/V\,\hat d^T, \quad \partial Re = Re/V\,\hat d^T, $$
/// $$ \partial\alpha_e = \big(F_{inv}^T\partial\hat l/Q - cl_{inv}\,\partial Q/Q\big)/a_{lat}, \quad
///    \partial c = c'\,\partial\alpha_e + c_{Re}\,\partial Re, $$
/// and the product rule on `ΔF = (cl Q − L) l̂ + cd Q d̂`, `ΔM = r × ΔF + cm Q c x̂`.
fn flow_jacobians(
    s: &StripState,
    c: &Coefficients,
    strip: &Strip,
    inviscid: &StripLoads,
) -> (Matrix3<f64>, Matrix3<f64>) {
    let (d, l, q) = (s.drag_dir, s.lift_dir, s.q_area);
    let plane = Matrix3::from_diagonal(&Vector3::new(0.0, 1.0, 1.0));
    let dd = (Matrix3::identity() - d * d.transpose()) * plane / s.speed;
    let dl = -Vector3::<f64>::x().cross_matrix() * dd;
    let dq = (2.0 * q / s.speed) * d.transpose();
    // A fixed Reynolds number does not follow the flow.
    let dre = if strip.fixed_reynolds.is_some() {
        Vector3::zeros().transpose()
    } else {
        (s.reynolds / s.speed) * d.transpose()
    };
    let dlift = inviscid.force.transpose() * dl;
    let dalpha = (dlift / q - s.cl_inviscid * dq / q) / s.lift_slope;
    let dcl = c.dcl * dalpha + c.dcl_dre * dre;
    let dcd = c.dcd * dalpha + c.dcd_dre * dre;
    let dcm = c.dcm * dalpha + c.dcm_dre * dre;
    let lift_excess = c.cl * q - s.cl_inviscid * q;
    let df = l * (q * dcl + c.cl * dq - dlift) + lift_excess * dl + d * (q * dcd + c.cd * dq) + (c.cd * q) * dd;
    let dm = strip.quarter_chord.cross_matrix() * df + (strip.chord * Vector3::x()) * (q * dcm + c.cm * dq);
    (df, dm)
}

#[cfg(test)]
#[path = "strip_tests.rs"]
mod tests;
