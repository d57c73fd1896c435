//! Dynamic stall: the four-state Beddoes–Leishman-type model of Hansen, Gaunaa & Madsen
//! (Risø-R-1354, 2004), driven only by a section's static polar (docs/section_aero.md §8).
//!
//! With `T_u = c/(2U)` (the time the flow takes over half a chord), `α` the incidence at the
//! three-quarter chord, `ω` the section's pitch rate and `cl_α`, `α₀` the attached-flow lift line:
//!
//! $$ \dot x_i = \frac{b_i}{T_u}\,(A_i\,\alpha - x_i)\ (i = 1, 2),\qquad
//!    \alpha_E = (1 - A_1 - A_2)\,\alpha + x_1 + x_2, $$
//! $$ cl_p = cl_\alpha(\alpha_E - \alpha_0) + \pi T_u\,\omega,\qquad
//!    \dot x_3 = \frac{cl_p - x_3}{T_p T_u},\qquad \alpha_F = \alpha_0 + x_3/cl_\alpha,\qquad
//!    \dot x_4 = \frac{f_{st}(\alpha_F) - x_4}{T_f T_u}. $$
//!
//! `x₁, x₂` are the attached-flow (Wagner) lag, `x₃` the lagged lift that sets the pressure
//! gradient (`α_F` its incidence), `x₄` the separation point. The static separation point comes
//! from the polar through Kirchhoff's relation `cl_st = cl_α(α − α₀)((1 + √f)/2)²`, and the
//! fully separated lift from the static polar's decomposition `cl_st = cl_α(α − α₀) f + cl_fs (1 − f)`.
//! The lift is HGM's `cl_α(α_E − α₀) x₄ + cl_fs(α_E)(1 − x₄) + π T_u ω`, written as
//!
//! $$ cl = cl_{st}(\alpha_E) + \big(cl_\alpha(\alpha_E - \alpha_0) - cl_{fs}(\alpha_E)\big)
//!    \big(x_4 - f_{st}(\alpha_E)\big) + \pi T_u\,\omega, $$
//!
//! the same wherever Kirchhoff's `f` lies in `(0, 1)`, and the static polar exactly at rest
//! where `f` is clipped (a polar above its own lift line, or far past stall).
//!
//! Drag and moment follow HGM as OpenFAST's `UAMod = 4` reads it: the lift's tilt by the lag and
//! the separation drag,
//! `cd = cd_st(α_E) + (α − α_E) cl + (cd_st(α_E) − cd_st(α₀)) ((√f_st − √x₄)/2 − (f_st − x₄)/4)`,
//! and `cm = cm_st(α_E) − (π/2) T_u ω` (no shift of the centre of pressure with `x₄`).
//!
//! Time integration: each state obeys `ẋ = (u − x)/T`, integrated exactly over a step with its
//! forcing `u` linear in time between its values at the step's two ends (first-order hold): exact
//! for `x₁, x₂` when `α` varies linearly, second order for `x₃, x₄`, unconditionally stable, and a
//! constant input holds the steady state. The speed's own rate (HGM's `U̇` terms) is left out:
//! `T_u` is the mean of its values at the step's ends.

use crate::error::{AerofoilError, Result};
use crate::polar::Polar;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The model's dimensionless constants (docs/section_aero.md §8.2 gives their sources).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DynamicStallConstants {
    /// Wagner-function amplitude of the slow pole, `A₁` (Jones' flat plate: 0.165).
    pub a1: f64,
    /// Slow pole, `b₁`, per semichord travelled (Jones: 0.0455).
    pub b1: f64,
    /// Wagner-function amplitude of the fast pole, `A₂` (Jones: 0.335).
    pub a2: f64,
    /// Fast pole, `b₂`, per semichord travelled (Jones: 0.3).
    pub b2: f64,
    /// Pressure-lag time constant `T_p`, semichords (Leishman & Beddoes 1989, NACA 0012: 1.7).
    pub t_p: f64,
    /// Separation-point time constant `T_f`, semichords (Leishman & Beddoes 1989, NACA 0012: 3.0).
    pub t_f: f64,
    /// Attached-flow lift slope `cl_α`, 1/rad. `None`: the largest secant slope
    /// `cl(α)/(α − α₀)` over the polar's incidence knots at the reference Reynolds number, so
    /// that the polar lies on or under its lift line (Kirchhoff's `f ≤ 1`).
    pub lift_slope: Option<f64>,
}

impl Default for DynamicStallConstants {
    fn default() -> Self {
        Self { a1: 0.165, b1: 0.0455, a2: 0.335, b2: 0.3, t_p: 1.7, t_f: 3.0, lift_slope: None }
    }
}

impl DynamicStallConstants {
    /// Every constant finite and in range: `A₁, A₂ ≥ 0` with `A₁ + A₂ < 1`, `b₁, b₂, T_p, T_f > 0`,
    /// `cl_α > 0` when given. The error names the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |field: &'static str, value: f64| Err(AerofoilError::InvalidDynamicStall { field, value });
        for (field, v) in [("a1", self.a1), ("a2", self.a2)] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, v);
            }
        }
        if self.a1 + self.a2 >= 1.0 {
            return bad("a1 + a2", self.a1 + self.a2);
        }
        let positive = [("b1", self.b1), ("b2", self.b2), ("t_p", self.t_p), ("t_f", self.t_f)];
        for (field, v) in positive.into_iter().chain(self.lift_slope.map(|s| ("lift_slope", s))) {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, v);
            }
        }
        Ok(())
    }
}

/// The flow a section sees at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SectionFlow {
    /// Incidence at the three-quarter-chord point, rad.
    pub alpha: f64,
    /// Pitch rate of the section, nose up, rad/s.
    pub pitch_rate: f64,
    /// Speed of the flow in the section plane, m/s (> 0).
    pub speed: f64,
    /// Chord, m (> 0).
    pub chord: f64,
    /// Reynolds number at which the polar is read (> 0).
    pub re: f64,
}

impl SectionFlow {
    /// `T_u = c/(2U)`, s.
    fn half_chord_time(&self) -> f64 {
        0.5 * self.chord / self.speed
    }

    fn validate(&self) -> Result<()> {
        let bad = |field: &'static str, value: f64| Err(AerofoilError::InvalidDynamicStall { field, value });
        if !self.alpha.is_finite() {
            return bad("alpha", self.alpha);
        }
        if !self.pitch_rate.is_finite() {
            return bad("pitch_rate", self.pitch_rate);
        }
        for (field, v) in [("speed", self.speed), ("chord", self.chord), ("re", self.re)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, v);
            }
        }
        Ok(())
    }
}

/// The model's state at one instant: the four states and the inputs they were reached with.
///
/// `Copy` and never mutated by the model: [`DynamicStall::step`] returns the next state, so an
/// iterative solver can redo a step from the same start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicStallState {
    /// `x₁, x₂`: the attached-flow lag states, rad.
    pub lag: [f64; 2],
    /// `x₃`: the lagged lift coefficient that sets the pressure gradient.
    pub lagged_lift: f64,
    /// `x₄`: the separation point, 0 (fully separated) to 1 (attached).
    pub separation: f64,
    /// The inputs at this instant.
    pub flow: SectionFlow,
    /// `cl_p` at this instant (the forcing of `x₃`).
    cl_p: f64,
    /// `f_st(α_F)` at this instant (the forcing of `x₄`).
    f_target: f64,
}

/// The coefficients of a state.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DynamicCoefficients {
    /// Lift coefficient (normal to the section-plane flow).
    pub cl: f64,
    /// Drag coefficient (along the flow).
    pub cd: f64,
    /// Moment coefficient about the quarter chord, nose up.
    pub cm: f64,
    /// Effective incidence `α_E` of the attached-flow lag, rad.
    pub alpha_e: f64,
    /// The separation point `x₄`.
    pub separation: f64,
    /// The static separation point `f_st(α_E)` at the effective incidence.
    pub static_separation: f64,
}

/// The model of one section: its constants and the attached-flow lift line of its polar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicStall {
    constants: DynamicStallConstants,
    /// `cl_α`, 1/rad.
    lift_slope: f64,
    /// `α₀`, rad.
    alpha0: f64,
}

impl DynamicStall {
    /// The model for `polar`, its lift line taken at Reynolds number `re_ref`: `α₀` the polar's
    /// zero-lift incidence there ([`Polar::zero_lift_alpha`]), `cl_α` the given
    /// [`DynamicStallConstants::lift_slope`] or the largest secant slope over the knots.
    ///
    /// The lift line is held at other Reynolds numbers; the static coefficients are read at each
    /// step's own Reynolds number, so the steady limit is the polar's there too.
    pub fn new(polar: &Polar, re_ref: f64, constants: DynamicStallConstants) -> Result<Self> {
        constants.validate()?;
        if !(re_ref.is_finite() && re_ref > 0.0) {
            return Err(AerofoilError::InvalidDynamicStall { field: "re", value: re_ref });
        }
        let alpha0 = polar.zero_lift_alpha(re_ref).ok_or(AerofoilError::NoZeroLift { re: re_ref })?;
        let lift_slope = match constants.lift_slope {
            Some(s) => s,
            None => largest_secant(polar, re_ref, alpha0)?,
        };
        Ok(Self { constants, lift_slope, alpha0 })
    }

    /// The constants.
    pub fn constants(&self) -> &DynamicStallConstants {
        &self.constants
    }

    /// `cl_α`, 1/rad.
    pub fn lift_slope(&self) -> f64 {
        self.lift_slope
    }

    /// `α₀`, rad.
    pub fn zero_lift_alpha(&self) -> f64 {
        self.alpha0
    }

    /// Kirchhoff's static separation point `f_st` and the fully separated lift `cl_fs` at
    /// incidence `alpha` where the polar's lift is `cl_st` and its slope `dcl_st`.
    ///
    /// With `r = cl_st/(cl_α(α − α₀))` and `g = √r`: `f = (2g − 1)²` and
    /// `cl_fs = cl_α(α − α₀)(3g − 1)/(4g)` for `1/4 < r ≤ 1` (the decomposition
    /// `cl_st = cl_α(α − α₀) f + cl_fs (1 − f)` without its 0/0 at `f = 1`); `f = 0`,
    /// `cl_fs = cl_st` for `r ≤ 1/4` (fully separated, or lift against the incidence);
    /// `f = 1`, `cl_fs = cl_α(α − α₀)/2` for `r > 1`. Within 1e-6 rad of `α₀`, where `r` is
    /// 0/0, its limit `r = dcl_st/cl_α`.
    pub fn separation(&self, alpha: f64, cl_st: f64, dcl_st: f64) -> (f64, f64) {
        let line = self.lift_slope * (alpha - self.alpha0);
        let r = if (alpha - self.alpha0).abs() < 1e-6 { dcl_st / self.lift_slope } else { cl_st / line };
        if r <= 0.25 {
            return (0.0, cl_st);
        }
        let g = r.sqrt().min(1.0);
        ((2.0 * g - 1.0).powi(2), line * (3.0 * g - 1.0) / (4.0 * g))
    }

    /// `f_st(α_F)` at the lagged lift `x₃`.
    fn target(&self, polar: &Polar, lagged_lift: f64, re: f64) -> Result<f64> {
        let alpha_f = self.alpha0 + lagged_lift / self.lift_slope;
        let c = polar.coefficients(alpha_f, re)?;
        Ok(self.separation(alpha_f, c.cl, c.dcl).0)
    }

    fn effective_alpha(&self, lag: [f64; 2], alpha: f64) -> f64 {
        let k = &self.constants;
        (1.0 - k.a1 - k.a2) * alpha + lag[0] + lag[1]
    }

    fn pressure_lift(&self, alpha_e: f64, flow: &SectionFlow) -> f64 {
        self.lift_slope * (alpha_e - self.alpha0) + PI * flow.half_chord_time() * flow.pitch_rate
    }

    /// The steady state at constant `flow` (its pitch rate included as a constant rate): every
    /// state at its equilibrium, `α_E = α`.
    pub fn steady_state(&self, polar: &Polar, flow: &SectionFlow) -> Result<DynamicStallState> {
        flow.validate()?;
        let k = &self.constants;
        let lag = [k.a1 * flow.alpha, k.a2 * flow.alpha];
        let cl_p = self.pressure_lift(self.effective_alpha(lag, flow.alpha), flow);
        let f_target = self.target(polar, cl_p, flow.re)?;
        Ok(DynamicStallState { lag, lagged_lift: cl_p, separation: f_target, flow: *flow, cl_p, f_target })
    }

    /// The state after an instantaneous change of the inputs to `flow` (a step in incidence):
    /// the states keep their values, `α_E` and the forcings follow the new inputs.
    pub fn jump(&self, polar: &Polar, state: &DynamicStallState, flow: &SectionFlow) -> Result<DynamicStallState> {
        flow.validate()?;
        let cl_p = self.pressure_lift(self.effective_alpha(state.lag, flow.alpha), flow);
        let f_target = self.target(polar, state.lagged_lift, flow.re)?;
        Ok(DynamicStallState { flow: *flow, cl_p, f_target, ..*state })
    }

    /// The state `dt` seconds after `start`, the inputs varying linearly from `start.flow` to
    /// `flow` over the step. Two polar evaluations, no allocation.
    pub fn step(
        &self,
        polar: &Polar,
        start: &DynamicStallState,
        dt: f64,
        flow: &SectionFlow,
    ) -> Result<DynamicStallState> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(AerofoilError::InvalidDynamicStall { field: "dt", value: dt });
        }
        flow.validate()?;
        let k = &self.constants;
        let tu = 0.5 * (start.flow.half_chord_time() + flow.half_chord_time());
        let (a_start, a_end) = (start.flow.alpha, flow.alpha);
        let lag = [
            hold(start.lag[0], k.a1 * a_start, k.a1 * a_end, dt * k.b1 / tu),
            hold(start.lag[1], k.a2 * a_start, k.a2 * a_end, dt * k.b2 / tu),
        ];
        let cl_p = self.pressure_lift(self.effective_alpha(lag, a_end), flow);
        let lagged_lift = hold(start.lagged_lift, start.cl_p, cl_p, dt / (k.t_p * tu));
        let f_target = self.target(polar, lagged_lift, flow.re)?;
        let separation = hold(start.separation, start.f_target, f_target, dt / (k.t_f * tu)).clamp(0.0, 1.0);
        Ok(DynamicStallState { lag, lagged_lift, separation, flow: *flow, cl_p, f_target })
    }

    /// The coefficients of `state` (three polar evaluations: at `α_E` and `α₀`).
    pub fn coefficients(&self, polar: &Polar, state: &DynamicStallState) -> Result<DynamicCoefficients> {
        let flow = &state.flow;
        let alpha_e = self.effective_alpha(state.lag, flow.alpha);
        let st = polar.coefficients(alpha_e, flow.re)?;
        let (f_st, cl_fs) = self.separation(alpha_e, st.cl, st.dcl);
        let x4 = state.separation;
        let rate = flow.half_chord_time() * flow.pitch_rate;
        let line = self.lift_slope * (alpha_e - self.alpha0);
        let cl = st.cl + (line - cl_fs) * (x4 - f_st) + PI * rate;
        let cd0 = polar.coefficients(self.alpha0, flow.re)?.cd;
        let separation_drag = 0.5 * (f_st.sqrt() - x4.sqrt()) - 0.25 * (f_st - x4);
        let cd = st.cd + (flow.alpha - alpha_e) * cl + (st.cd - cd0) * separation_drag;
        let cm = st.cm - 0.5 * PI * rate;
        Ok(DynamicCoefficients { cl, cd, cm, alpha_e, separation: x4, static_separation: f_st })
    }
}

/// `x(h)` of `ẋ = (u − x)/T` from `x(0) = x0`, `u` linear from `u0` to `u1`, with `z = h/T`:
/// `x0 E + u0 (1 − E) + (u1 − u0)(1 − (1 − E)/z)`, `E = e^{−z}` (series for small `z`).
fn hold(x0: f64, u0: f64, u1: f64, z: f64) -> f64 {
    let e = (-z).exp();
    let one_minus_e = -(-z).exp_m1();
    let ramp = if z < 1e-4 { z / 2.0 - z * z / 6.0 + z * z * z / 24.0 } else { 1.0 - one_minus_e / z };
    x0 * e + u0 * one_minus_e + (u1 - u0) * ramp
}

/// The largest `cl(α)/(α − α₀)` over every table's knots that the polar accepts at `re`, at
/// least 0.1° from `α₀`.
fn largest_secant(polar: &Polar, re: f64, alpha0: f64) -> Result<f64> {
    let mut best = f64::NEG_INFINITY;
    for table in polar.tables() {
        for &a in &table.alpha {
            if (a - alpha0).abs() < 0.1f64.to_radians() {
                continue;
            }
            if let Ok(c) = polar.coefficients(a, re) {
                best = best.max(c.cl / (a - alpha0));
            }
        }
    }
    if best.is_finite() && best > 0.0 {
        Ok(best)
    } else {
        Err(AerofoilError::InvalidDynamicStall { field: "lift_slope", value: best })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hold integrator against the closed form for a ramp (large steps) and its Taylor
    /// series (small steps, where the closed form itself cancels).
    #[test]
    fn hold_is_exact_for_a_ramp() {
        let (x0, u0, u1): (f64, f64, f64) = (0.3, -0.2, 0.7);
        for z in [1e-3f64, 0.1, 1.0, 30.0] {
            let s = (u1 - u0) / z; // slope per unit of t/T
            let exact = u1 - s + (x0 - u0 + s) * (-z).exp();
            assert!((hold(x0, u0, u1, z) - exact).abs() <= 1e-15 * (1.0 + s.abs()), "z = {z}");
        }
        for z in [1e-9f64, 1e-6] {
            let taylor = x0 + z * (u0 - x0) + 0.5 * z * (u1 - u0);
            assert!((hold(x0, u0, u1, z) - taylor).abs() <= 1e-15 + z * z, "z = {z}");
        }
        assert_eq!(hold(0.25, 0.25, 0.25, 0.3), 0.25);
    }

    #[test]
    fn separation_is_continuous_and_reconstructs_the_polar() {
        let polar = Polar::linear(2.0 * PI, 0.0, -0.5, 0.5).unwrap();
        let m = DynamicStall::new(&polar, 1e6, DynamicStallConstants::default()).unwrap();
        let a = 0.2;
        let line = m.lift_slope() * (a - m.zero_lift_alpha());
        for r in [-0.3, 0.1, 0.25, 0.2500001, 0.4, 0.7, 0.99, 1.0, 1.3] {
            let cl = r * line;
            let (f, cl_fs) = m.separation(a, cl, 0.0);
            assert!((0.0..=1.0).contains(&f));
            if r <= 1.0 {
                // The decomposition holds wherever f is not clipped at 1.
                assert!((line * f + cl_fs * (1.0 - f) - cl).abs() < 1e-12, "r = {r}");
            }
        }
    }

    #[test]
    fn bad_constants_and_inputs_name_the_field() {
        let polar = Polar::linear(2.0 * PI, 0.0, -0.5, 0.5).unwrap();
        let bad = DynamicStallConstants { t_f: 0.0, ..Default::default() };
        let err = DynamicStall::new(&polar, 1e6, bad).unwrap_err();
        assert!(matches!(err, AerofoilError::InvalidDynamicStall { field: "t_f", .. }), "{err}");
        let m = DynamicStall::new(&polar, 1e6, DynamicStallConstants::default()).unwrap();
        let flow = SectionFlow { alpha: 0.1, pitch_rate: 0.0, speed: 0.0, chord: 1.0, re: 1e6 };
        let err = m.steady_state(&polar, &flow).unwrap_err();
        assert!(matches!(err, AerofoilError::InvalidDynamicStall { field: "speed", .. }), "{err}");
    }
}
