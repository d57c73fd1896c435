//! The model held at an experiment's coast angles (docs/statics.md §7).
//!
//! Where a static sweep's coast angle misses a measured one, the equilibrium alone does not say
//! why. Holding the wingtip at the measured angle does: the air and gravity loads of the model's
//! tip there leave a moment about the hinge axis that the real tip, at rest at that angle, did
//! not have. How that moment scales with airspeed separates the causes — proportional to the
//! dynamic pressure it is aerodynamic (the tip's incidence or lift), constant it is gravity,
//! mass placement or friction — and the root pitch change that cancels it states an
//! aerodynamic discrepancy as an incidence.
//!
//! The hold is a stiff spring about the hinge axis with its rest angle at the measured coast
//! angle ([`HOLD_STIFFNESS`]: the held fold misses the measured one by the moment over the
//! stiffness, under 1e-3° here); the moment is the air and gravity moment about the axis at
//! that state plus the case's own hinge spring.

use crate::problem::{Formulation, Joint, Problem, Spring};

/// Stiffness of the holding spring, N·m/rad (a hinge moment of 0.1 N·m moves the held fold by
/// 6e-4°).
pub const HOLD_STIFFNESS: f64 = 1e4;

/// Root pitch step of the secant for the equivalent pitch, degrees.
pub const PITCH_STEP_DEG: f64 = 1.0;

/// The model held at one measured coast angle.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct HeldPoint {
    /// Formulation.
    pub formulation: Formulation,
    /// Airspeed, m/s.
    pub airspeed: f64,
    /// The measured coast angle, degrees.
    pub coast_deg: f64,
    /// The held model's fold angle, degrees (the measured angle within the hold's compliance).
    pub fold_deg: f64,
    /// Moment about the hinge axis of the tip's air and gravity loads and the case's hinge
    /// spring at the held state, N·m (fold-up positive): what the model's tip has there and the
    /// real tip did not.
    pub hinge_moment: f64,
    /// `hinge_moment` over the dynamic pressure ½ ρ V², m³: constant where the excess is
    /// aerodynamic.
    pub per_dynamic_pressure: f64,
    /// Change of `hinge_moment` per degree of root pitch at the held fold, N·m/deg.
    pub pitch_sensitivity: f64,
    /// Root pitch change that makes `hinge_moment` vanish at the measured angle, degrees
    /// (secant from a [`PITCH_STEP_DEG`] step): negative when the model's tip has more
    /// incidence than the experiment's.
    pub equivalent_pitch_deg: f64,
    /// Why the point has no result, if it has none.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub error: Option<String>,
}

/// `case` with its fold hinge held at `coast_deg` by the holding spring, at `airspeed` only,
/// and its root pitch changed by `dpitch_deg`; with the case's own spring `(k, θ₀)` of the fold
/// hinge. None when the case has no free fold hinge.
fn held_case(case: &Problem, airspeed: f64, coast_deg: f64, dpitch_deg: f64) -> Option<(Problem, (f64, f64))> {
    let j = case.fold_joint_index()?;
    let mut c = case.clone();
    let Joint::FlaredHinge { locked: false, spring, .. } = &mut c.joints[j] else { return None };
    let own = spring.map_or((0.0, 0.0), |s| (s.stiffness, s.rest_deg.to_radians()));
    *spring = Some(Spring { stiffness: HOLD_STIFFNESS, damping: 0.0, rest_deg: coast_deg });
    c.pitch_deg += dpitch_deg;
    let st = c.statics.as_mut()?;
    st.airspeeds = vec![airspeed];
    Some((c, own))
}

/// The fold (degrees) and the hinge moment with the case's own spring (N·m) of `case` held at
/// `coast_deg`, root pitch changed by `dpitch_deg`.
fn held_moment(
    case: &Problem,
    f: Formulation,
    airspeed: f64,
    coast_deg: f64,
    dpitch_deg: f64,
) -> Result<(f64, f64), String> {
    let (c, (k, rest)) = held_case(case, airspeed, coast_deg, dpitch_deg)
        .ok_or("the case has no free fold hinge or no `static` block")?;
    let out = crate::statics::run_static(&c, f);
    if let Some(e) = out.error {
        return Err(e);
    }
    let p = out.points.into_iter().next().ok_or("no point")?;
    if let Some(e) = p.error {
        return Err(e);
    }
    Ok((p.fold_deg, p.loads.hinge_moment - k * (p.fold_deg.to_radians() - rest)))
}

/// The model of `case` held at the measured coast angle `coast_deg` at `airspeed`.
pub fn hold(case: &Problem, f: Formulation, airspeed: f64, coast_deg: f64) -> HeldPoint {
    let rho = case.aero.as_ref().map_or(f64::NAN, |a| a.rho);
    let q = 0.5 * rho * airspeed * airspeed;
    let mut p = HeldPoint {
        formulation: f,
        airspeed,
        coast_deg,
        fold_deg: f64::NAN,
        hinge_moment: f64::NAN,
        per_dynamic_pressure: f64::NAN,
        pitch_sensitivity: f64::NAN,
        equivalent_pitch_deg: f64::NAN,
        error: None,
    };
    let base = held_moment(case, f, airspeed, coast_deg, 0.0);
    let stepped = held_moment(case, f, airspeed, coast_deg, -PITCH_STEP_DEG);
    match (base, stepped) {
        (Ok((fold, m)), Ok((_, m1))) => {
            let slope = (m - m1) / PITCH_STEP_DEG;
            p.fold_deg = fold;
            p.hinge_moment = m;
            p.per_dynamic_pressure = m / q;
            p.pitch_sensitivity = slope;
            p.equivalent_pitch_deg = -m / slope;
        }
        (Err(e), _) | (_, Err(e)) => p.error = Some(e),
    }
    p
}

/// Whether `case` can be held: it has a free fold hinge and a `static` block.
pub fn can_hold(case: &Problem) -> bool {
    held_case(case, 0.0, 0.0, 0.0).is_some()
}
