//! Gust response and load alleviation (docs/gust.md): the case field `aero.gust` (a frozen gust
//! or turbulence field convected with the free stream), the top-level `gust` sweep block (gust
//! gradients × hinge states), a gust run from the static aeroelastic equilibrium
//! ([`gust_history`]) and the sweep ([`run_sweep`]). The harness writes the outputs (`harness::gust_out`).
//!
//! A gust run starts at rest at the static equilibrium of its hinge state (docs/statics.md),
//! with the steady wake of that lattice laid out behind it, so that without a gust it stays
//! there and every load it records, minus its value at t = 0, is the gust's alone.

use std::time::Instant;

use crate::aero::{simulate_aero_with_events, station_map};
use crate::factory::{BuildModel, ForModel, dispatch};
use crate::problem::{Formulation, Joint, Problem, Spring};

pub use crate::gust_field::{disturbance, gust_front};
pub use crate::gust_settings::{Certification, GustSpec, GustSweep, HingeState, MAX_GUST_RUNS, RHO_SEA_LEVEL};

impl HingeState {
    /// `case` with its fold hinge in this state.
    pub fn apply(&self, case: &Problem) -> Result<Problem, String> {
        let mut c = case.clone();
        let j = c.fold_joint_index().ok_or("gust.hinges: the case has no flared hinge to free, lock or spring")?;
        if let Joint::FlaredHinge { locked, spring, name, .. } = &mut c.joints[j] {
            match self {
                HingeState::Free => *locked = false,
                HingeState::Locked => *locked = true,
                HingeState::Release { root_bending_moment_increment_above } => {
                    *locked = true;
                    let joint = name.get_or_insert_with(|| format!("joints[{j}]")).clone();
                    let when = crate::events::Trigger {
                        root_bending_moment_increment_above: Some(*root_bending_moment_increment_above),
                        ..Default::default()
                    };
                    let action = crate::events::HingeAction::Release;
                    c.events.push(crate::events::HingeEvent { time: None, when: Some(when), joint, action });
                }
                HingeState::Spring { stiffness, damping } => {
                    *locked = false;
                    let rest_deg = spring.map_or(0.0, |s| s.rest_deg);
                    *spring = Some(Spring { stiffness: *stiffness, damping: *damping, rest_deg });
                }
            }
        } else {
            return Err(format!("fold_joint: joints[{j}] is not a flared hinge"));
        }
        Ok(c)
    }
}

impl GustSweep {
    /// Check the block against its case (which must have `aero` with a 1-cos `aero.gust` and a
    /// flared hinge), naming the field.
    pub fn validate(&self, case: &Problem) -> Result<(), String> {
        let Some(aero) = &case.aero else {
            return Err("gust: a gust sweep needs aerodynamics (`aero`)".into());
        };
        match &aero.gust {
            Some(GustSpec::OneMinusCosine { .. }) => {}
            Some(g) => {
                return Err(format!(
                    "aero.gust.kind: the sweep varies the gradient of a one_minus_cosine gust, not a {}",
                    g.kind()
                ));
            }
            None => return Err("aero.gust: a gust sweep needs the gust it varies (`aero.gust`)".into()),
        }
        let (name, list) = match (self.gradients_m.is_empty(), self.frequencies_hz.is_empty()) {
            (false, true) => ("gust.gradients_m", &self.gradients_m),
            (true, false) => ("gust.frequencies_hz", &self.frequencies_hz),
            _ => return Err("gust.gradients_m: give exactly one of `gradients_m` and `frequencies_hz`".into()),
        };
        for (k, &v) in list.iter().enumerate() {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name}[{k}]: {v} is not a positive, finite number"));
            }
        }
        if self.hinges.is_empty() {
            return Err("gust.hinges: empty list".into());
        }
        for (k, h) in self.hinges.iter().enumerate() {
            if let HingeState::Release { root_bending_moment_increment_above: m } = h {
                if !m.is_finite() {
                    return Err(format!("gust.hinges[{k}].root_bending_moment_increment_above: {m} is not finite"));
                }
                if !case.joints.iter().any(|j| matches!(j, Joint::Clamp { .. })) {
                    return Err(format!(
                        "gust.hinges[{k}]: a release on the root bending moment needs a clamp (where it is measured)"
                    ));
                }
            }
            if let HingeState::Spring { stiffness, damping } = h {
                if !(stiffness.is_finite() && *stiffness >= 0.0) {
                    return Err(format!("gust.hinges[{k}].stiffness: {stiffness} is not a non-negative number"));
                }
                if !(damping.is_finite() && *damping >= 0.0) {
                    return Err(format!("gust.hinges[{k}].damping: {damping} is not a non-negative number"));
                }
            }
        }
        if case.fold_joint_index().is_none() {
            return Err("gust.hinges: the case has no flared hinge".into());
        }
        if let Some(t) = self.t_end
            && !(t.is_finite() && t > 0.0)
        {
            return Err(format!("gust.t_end: {t} is not a positive number"));
        }
        if list.len() * self.hinges.len() > MAX_GUST_RUNS {
            return Err(format!(
                "gust: {} gradients x {} hinge states is more than {MAX_GUST_RUNS} runs",
                list.len(),
                self.hinges.len()
            ));
        }
        Ok(())
    }
}

/// The values of the loads at the equilibrium a gust run starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Equilibrium {
    /// Root bending moment, N·m.
    pub root_bending_moment: f64,
    /// Root torque, N·m.
    pub root_torque: f64,
    /// Hinge moment, N·m.
    pub hinge_moment: f64,
    /// Fold angle, degrees.
    pub fold_deg: f64,
    /// Lift, N.
    pub lift: f64,
}

/// The increments of a gust run's outputs over their equilibrium values at the output times: the
/// time march's ([`GustHistory`]) and the linearised model's
/// ([`crate::gust_linear::LinearGustHistory`]).
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Increments {
    /// Times, s (0 at the equilibrium; the gust's front starts `x0` upstream of the wing).
    pub t: Vec<f64>,
    /// Root bending moment minus its equilibrium value, N·m.
    pub delta_root_bending_moment: Vec<f64>,
    /// Root torque minus its equilibrium value, N·m.
    pub delta_root_torque: Vec<f64>,
    /// Hinge moment minus its equilibrium value, N·m (NaN without a flared hinge).
    pub delta_hinge_moment: Vec<f64>,
    /// Fold angle minus its equilibrium value, degrees (NaN without a fold hinge).
    pub delta_fold_deg: Vec<f64>,
    /// Lift minus its equilibrium value, N.
    pub delta_lift: Vec<f64>,
}

/// One gust run: the incremental loads over their equilibrium values, at the output times.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GustHistory {
    /// The increments.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub increments: Increments,
    /// The equilibrium.
    pub equilibrium: Equilibrium,
    /// CPU time of the time march, s (thread CPU time; wall time off Linux).
    pub cpu_s: f64,
    /// CPU time of the static equilibrium, s.
    pub static_cpu_s: f64,
    /// Why the run stopped before `t_end`, if it did (the rows up to there are kept).
    pub error: Option<String>,
}

fn cpu_now() -> (Instant, Option<f64>) {
    (Instant::now(), crate::clock::thread_cpu_s())
}

fn cpu_since(t: (Instant, Option<f64>)) -> f64 {
    match (t.1, crate::clock::thread_cpu_s()) {
        (Some(a), Some(b)) => b - a,
        _ => t.0.elapsed().as_secs_f64(),
    }
}

/// The static aeroelastic equilibrium of `case` at its airspeed: its coordinates.
pub fn equilibrium_q(case: &Problem, f: Formulation) -> Result<Vec<f64>, String> {
    let aero = case.aero.as_ref().ok_or("the case has no `aero` block")?;
    // The steady state of the march's own wake, so that without a gust the run stays there.
    let wake = crate::stability::march_wake(case, f, aero.speed());
    let p = crate::statics::equilibrium_at(case, f, wake).map_err(|e| format!("static equilibrium: {e}"))?;
    p.state.map(|s| s.0).ok_or_else(|| "static equilibrium: no state".into())
}

/// Run `case` (with its `aero.gust`, its hinge state applied) with formulation `f` from the
/// static equilibrium `q_eq` (from [`equilibrium_q`]; computed when `None`) to `case.t_end`, and
/// return the incremental loads. The function to call for one gust time history, e.g. to
/// compare with a linearised model: `delta_root_bending_moment` against `t`.
pub fn gust_history(case: &Problem, f: Formulation, q_eq: Option<&[f64]>) -> Result<GustHistory, String> {
    let t0 = cpu_now();
    let owned;
    let q = match q_eq {
        Some(q) => q,
        None => {
            owned = equilibrium_q(case, f)?;
            &owned
        }
    };
    let static_cpu_s = cpu_since(t0);
    let t1 = cpu_now();
    struct March<'a>(&'a Problem, Formulation, &'a [f64]);
    impl ForModel for March<'_> {
        type Output = Result<crate::run::RunOutput, String>;
        fn run<M: BuildModel>(self) -> Self::Output {
            let mut m = M::build(self.0).map_err(|e| e.to_string())?;
            march::<M>(self.0, self.1, &mut m, self.2)
        }
    }
    let out = dispatch(f, March(case, f, q))?;
    let cpu_s = cpu_since(t1);
    let r0 = out.rows.first().ok_or_else(|| out.error.clone().unwrap_or_else(|| "no output".into()))?;
    let eq = Equilibrium {
        root_bending_moment: r0.root_bending_moment,
        root_torque: r0.root_torque,
        hinge_moment: r0.hinge_moment,
        fold_deg: r0.fold.to_degrees(),
        lift: r0.lift,
    };
    let col = |g: &dyn Fn(&crate::run::Row) -> f64, v0: f64| out.rows.iter().map(|r| g(r) - v0).collect::<Vec<f64>>();
    Ok(GustHistory {
        increments: Increments {
            t: out.rows.iter().map(|r| r.t).collect(),
            delta_root_bending_moment: col(&|r| r.root_bending_moment, eq.root_bending_moment),
            delta_root_torque: col(&|r| r.root_torque, eq.root_torque),
            delta_hinge_moment: col(&|r| r.hinge_moment, eq.hinge_moment),
            delta_fold_deg: col(&|r| r.fold.to_degrees(), eq.fold_deg),
            delta_lift: col(&|r| r.lift, eq.lift),
        },
        equilibrium: eq,
        cpu_s,
        static_cpu_s,
        error: out.error,
    })
}

/// The march of a gust run, with the case's hinge events (a [`HingeState::Release`]).
fn march<M: BuildModel>(
    case: &Problem,
    f: Formulation,
    model: &mut M,
    q: &[f64],
) -> Result<crate::run::RunOutput, String> {
    let aero = case.aero.as_ref().ok_or("the case has no `aero` block")?;
    let map = station_map(case, aero)?;
    let mut settings = crate::factory::settings(case, f);
    settings.polars = crate::polar_correction::StripPolars::of(case)?;
    let mut events = crate::factory::hinge_events::<M>(case);
    let observer = &mut crate::run::NoObserver;
    Ok(simulate_aero_with_events(f, model, &settings, aero, &map, observer, Some(q), &mut events))
}

/// The largest value of `v` and its time; (NaN, NaN) when empty.
pub fn maximum(t: &[f64], v: &[f64]) -> (f64, f64) {
    t.iter()
        .zip(v)
        .fold((f64::NAN, f64::NAN), |best, (&ti, &x)| if best.0.is_nan() || x > best.0 { (x, ti) } else { best })
}

/// The largest-magnitude value of `v` (signed) and its time; (NaN, NaN) when empty.
pub fn peak(t: &[f64], v: &[f64]) -> (f64, f64) {
    let mut best = (f64::NAN, f64::NAN);
    for (&ti, &x) in t.iter().zip(v) {
        if x.is_finite() && (best.0.is_nan() || x.abs() > best.0.abs()) {
            best = (x, ti);
        }
    }
    best
}

/// One run of a gust sweep.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GustRun {
    /// Formulation.
    pub formulation: Formulation,
    /// Hinge state.
    pub hinge: HingeState,
    /// Gust gradient H, m.
    pub gradient_m: f64,
    /// Gust frequency `V/(2H)`, Hz.
    pub frequency_hz: f64,
    /// Peak gust velocity U_ds, m/s.
    pub gust_velocity: f64,
    /// Peak incremental root bending moment (largest magnitude, signed), N·m, and its time, s.
    pub peak_delta_root_bending_moment: (f64, f64),
    /// Largest upward increment of the root bending moment, N·m, and its time, s: the gust load
    /// a release relieves (whose largest-magnitude increment can be the relief itself).
    pub max_delta_root_bending_moment: (f64, f64),
    /// Peak incremental root torque, N·m, and its time.
    pub peak_delta_root_torque: (f64, f64),
    /// Peak incremental hinge moment, N·m, and its time.
    pub peak_delta_hinge_moment: (f64, f64),
    /// Peak incremental fold angle, degrees, and its time.
    pub peak_delta_fold_deg: (f64, f64),
    /// Peak incremental lift, N, and its time.
    pub peak_delta_lift: (f64, f64),
    /// The history (skipped in the JSON summary; in `gust_history_<f>.csv`).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub history: Option<GustHistory>,
    /// The equilibrium.
    pub equilibrium: Option<Equilibrium>,
    /// CPU time of the time march, s.
    pub cpu_s: f64,
    /// Why the run failed or stopped early.
    pub error: Option<String>,
}

/// A formulation's sweep or a failure to start it.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GustSweepOutput {
    /// Problem (run) name.
    pub name: String,
    /// Airspeed, m/s.
    pub airspeed: f64,
    /// The gust of the case (its gradient replaced by each run's).
    pub gust: GustSpec,
    /// Every run, in the order formulation, hinge state, gradient.
    pub runs: Vec<GustRun>,
    /// Wall time of the sweep, s.
    pub wall_s: f64,
}

/// Run the gust sweep of `base` (its `gust` block) with each formulation of `cases` on its own problem: first the static
/// equilibria of every (formulation, hinge state), then every gust run, each set in parallel
/// (rayon).
pub fn run_sweep(base: &Problem, cases: &[(Formulation, &Problem)]) -> Result<GustSweepOutput, String> {
    use rayon::prelude::*;
    let t0 = Instant::now();
    let case = base;
    let sweep = case.gust.as_ref().ok_or("the case has no `gust` block")?;
    for &(_, c) in cases {
        c.gust.as_ref().ok_or("the case has no `gust` block")?.validate(c)?;
    }
    let aero = case.aero.as_ref().ok_or("gust: needs `aero`")?;
    let gust = aero.gust.clone().ok_or("aero.gust: missing")?;
    let v = aero.free_stream();
    let airspeed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let gradients = sweep.gradients(airspeed);
    // 1. Equilibria per (formulation, hinge state).
    let pairs: Vec<(Formulation, &Problem, HingeState)> =
        cases.iter().flat_map(|&(f, c)| sweep.hinges.iter().map(move |&h| (f, c, h))).collect();
    let equilibria: Vec<Result<(Problem, Vec<f64>), String>> = pairs
        .par_iter()
        .map(|&(f, c, h)| {
            let mut base = c.clone();
            if let Some(t) = sweep.t_end {
                base.t_end = t;
            }
            let c = h.apply(&base)?;
            let q = equilibrium_q(&c, f)?;
            Ok((c, q))
        })
        .collect();
    // 2. Gust runs.
    let jobs: Vec<(usize, f64)> = (0..pairs.len()).flat_map(|p| gradients.iter().map(move |&h| (p, h))).collect();
    let runs: Vec<GustRun> = jobs
        .par_iter()
        .map(|&(p, h)| {
            let (f, _, hinge) = pairs[p];
            let g = gust.with_gradient(h);
            let mut run = GustRun {
                formulation: f,
                hinge,
                gradient_m: h,
                frequency_hz: airspeed / (2.0 * h),
                gust_velocity: g.velocity(aero.rho),
                peak_delta_root_bending_moment: (f64::NAN, f64::NAN),
                max_delta_root_bending_moment: (f64::NAN, f64::NAN),
                peak_delta_root_torque: (f64::NAN, f64::NAN),
                peak_delta_hinge_moment: (f64::NAN, f64::NAN),
                peak_delta_fold_deg: (f64::NAN, f64::NAN),
                peak_delta_lift: (f64::NAN, f64::NAN),
                history: None,
                equilibrium: None,
                cpu_s: f64::NAN,
                error: None,
            };
            let (c, q) = match &equilibria[p] {
                Ok(x) => x,
                Err(e) => {
                    run.error = Some(e.clone());
                    return run;
                }
            };
            let mut c = c.clone();
            if let Some(a) = c.aero.as_mut() {
                a.gust = Some(g);
            }
            match gust_history(&c, f, Some(q)) {
                Ok(hist) => {
                    let inc = &hist.increments;
                    run.peak_delta_root_bending_moment = peak(&inc.t, &inc.delta_root_bending_moment);
                    run.max_delta_root_bending_moment = maximum(&inc.t, &inc.delta_root_bending_moment);
                    run.peak_delta_root_torque = peak(&inc.t, &inc.delta_root_torque);
                    run.peak_delta_hinge_moment = peak(&inc.t, &inc.delta_hinge_moment);
                    run.peak_delta_fold_deg = peak(&inc.t, &inc.delta_fold_deg);
                    run.peak_delta_lift = peak(&inc.t, &inc.delta_lift);
                    run.equilibrium = Some(hist.equilibrium);
                    run.cpu_s = hist.cpu_s;
                    run.error = hist.error.clone();
                    run.history = Some(hist);
                }
                Err(e) => run.error = Some(e),
            }
            run
        })
        .collect();
    Ok(GustSweepOutput { name: case.name.clone(), airspeed, gust, runs, wall_s: t0.elapsed().as_secs_f64() })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<GustSpec, String> {
        serde_json::from_str::<GustSpec>(s).map_err(|e| e.to_string())
    }

    #[test]
    fn spec_parses_and_validates() {
        let g = parse(
            r#"{"kind": "one_minus_cosine", "gradient_m": 30, "velocity": 1.2, "x0": 0, "direction": [0, 0, 1]}"#,
        )
        .unwrap();
        g.validate().unwrap();
        assert_eq!(g.gradient(), 30.0);
        let bad = parse(r#"{"kind": "one_minus_cosine", "gradient_m": -3, "velocity": 1.2}"#).unwrap();
        assert!(bad.validate().unwrap_err().starts_with("aero.gust.gradient_m"));
        let bad = parse(r#"{"kind": "von_karman", "intensity": 1, "length_scale_m": 100}"#).unwrap();
        assert!(bad.validate().unwrap_err().starts_with("aero.gust.seed"));
        let bad = parse(r#"{"kind": "sinusoidal", "velocity": 1, "wavelength_m": 1e400}"#);
        assert!(bad.is_err() || bad.unwrap().validate().is_err());
        assert!(parse(r#"{"kind": "sharp_edged", "velocity": 1, "typo": 2}"#).is_err());
        let bad = parse(r#"{"kind": "sharp_edged", "velocity": 1, "x0": -2}"#).unwrap();
        assert!(bad.validate().unwrap_err().starts_with("aero.gust.x0"));
    }

    #[test]
    fn peak_is_signed_largest_magnitude() {
        assert_eq!(peak(&[0.0, 1.0, 2.0], &[0.5, -2.0, 1.5]), (-2.0, 1.0));
        assert!(peak(&[], &[]).0.is_nan());
    }
}
