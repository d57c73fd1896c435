//! Metrics of docs/outputs.md §3: tip difference between formulations and against references, energy
//! drift, constraint residual, speed.

use serde::Serialize;

use crate::run::{Row, RunOutput};

pub use casefile::curve::{tip_curve, tip_difference};

/// Max and RMS of a sampled difference over a window.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct DiffStats {
    /// Maximum, m.
    pub max: f64,
    /// Root mean square, m.
    pub rms: f64,
    /// Time of the maximum, s.
    pub t_max: f64,
    /// Samples used.
    pub n: usize,
}

/// Statistics of `d` restricted to `t_start ≤ t ≤ t_end`.
pub fn window_stats(d: &[(f64, f64)], t_start: f64, t_end: f64) -> DiffStats {
    let mut s = DiffStats::default();
    let mut sum = 0.0;
    for &(t, x) in d.iter().filter(|(t, _)| *t >= t_start - 1e-12 && *t <= t_end + 1e-12) {
        if x > s.max || s.n == 0 {
            s.max = x;
            s.t_max = t;
        }
        sum += x * x;
        s.n += 1;
    }
    s.rms = if s.n > 0 { (sum / s.n as f64).sqrt() } else { f64::NAN };
    if s.n == 0 {
        s.max = f64::NAN;
    }
    s
}

/// The roll response of a run with a `roll_joint` (the `roll_rate` column): its steady rate,
/// the mean over the last quarter of the run; how much it still moves there; and the rise time,
/// the first time the rate reaches 90 % of the steady one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RollResponse {
    /// Mean roll rate over the last quarter of the run, rad/s.
    pub steady_rate: f64,
    /// Largest minus smallest rate over that quarter, relative to |steady_rate|.
    pub spread: f64,
    /// First time |rate| ≥ 0.9 |steady_rate|, s (NaN if never).
    pub rise_time_s: f64,
}

impl RollResponse {
    /// The response of `rows` (None without a finite `roll_rate`).
    pub fn of(rows: &[Row]) -> Option<Self> {
        let (t0, t1) = (rows.first()?.t, rows.last()?.t);
        if !rows.iter().all(|r| r.roll_rate.is_finite()) || t1 <= t0 {
            return None;
        }
        let tail: Vec<f64> =
            rows.iter().filter(|r| r.t >= t1 - 0.25 * (t1 - t0) - 1e-12).map(|r| r.roll_rate).collect();
        let steady = tail.iter().sum::<f64>() / tail.len() as f64;
        let (lo, hi) = tail.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        let rise = rows.iter().find(|r| r.roll_rate.abs() >= 0.9 * steady.abs()).map_or(f64::NAN, |r| r.t);
        Some(Self { steady_rate: steady, spread: (hi - lo) / steady.abs(), rise_time_s: rise })
    }
}

/// Per-formulation metrics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormulationMetrics {
    /// Wall time, s.
    pub wall_s: f64,
    /// Steps taken.
    pub n_steps: usize,
    /// Steps per second.
    pub steps_per_s: f64,
    /// Newton iterations in total.
    pub n_newton_iters: usize,
    /// Mean Newton iterations per step.
    pub newton_per_step: f64,
    /// Most Newton iterations in one step.
    pub max_newton_iters: usize,
    /// Factorisations of the iteration matrix.
    pub n_factorizations: usize,
    /// Tangent dimension.
    pub n_dof: usize,
    /// Last time reached, s.
    pub t_reached: f64,
    /// max |E(t) − E(0) − W_aero(t)| / max kinetic energy.
    pub energy_drift: f64,
    /// Peak kinetic energy, J.
    pub peak_kinetic: f64,
    /// The kinetic energy below which the run's motion is not resolved, J (NaN when not known):
    /// see [`kinetic_resolution`]. A `peak_kinetic` at or below it makes
    /// `energy_drift` a ratio of two residues of the solve
    /// ([`resolved_energy_drift`](Self::resolved_energy_drift)).
    pub kinetic_resolution: f64,
    /// Largest position-level constraint residual.
    pub max_constraint_residual: f64,
    /// Error that stopped the run.
    pub error: Option<String>,
    /// Wall time in the aerodynamics, s.
    pub aero_wall_s: f64,
    /// Aerodynamic solves per time step of the march (0 without aerodynamics).
    pub aero_solves_per_step: f64,
    /// Dominant oscillation of the fold angle (the tip's vertical position without a fold
    /// hinge) in four equal windows of the run, by the matrix pencil method
    /// ([`crate::pencil`]): frequency and growth rate to compare with the stability analysis.
    pub oscillations: Vec<crate::pencil::Oscillation>,
    /// The signal of `oscillations`: `fold` or `tip_z`.
    pub oscillation_signal: &'static str,
    /// The roll response (a case with a `roll_joint`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roll: Option<RollResponse>,
}

impl FormulationMetrics {
    /// Metrics of one run.
    pub fn of(run: &RunOutput) -> Self {
        let e0 = run.rows.first().map_or(0.0, |r| r.total);
        let peak = run.rows.iter().map(|r| r.kinetic).fold(0.0, f64::max);
        let w = |r: &Row| if r.aero_work.is_finite() { r.aero_work } else { 0.0 };
        // E(t) + W_dissipated(t) − W_aero(t) − W_thrust(t) = E(0)
        let d = |r: &Row| if r.dissipated.is_finite() { r.dissipated } else { 0.0 };
        let th = |r: &Row| if r.thrust_work.is_finite() { r.thrust_work } else { 0.0 };
        let drift = run.rows.iter().map(|r| (r.total + d(r) - e0 - w(r) - th(r)).abs()).fold(0.0, f64::max);
        Self {
            wall_s: run.wall_s,
            n_steps: run.stats.n_steps,
            steps_per_s: if run.wall_s > 0.0 { run.stats.n_steps as f64 / run.wall_s } else { 0.0 },
            n_newton_iters: run.stats.n_newton_iters,
            newton_per_step: run.stats.n_newton_iters as f64 / run.stats.n_steps.max(1) as f64,
            max_newton_iters: run.stats.max_newton_iters,
            n_factorizations: run.stats.n_factorizations,
            n_dof: run.n_dof,
            t_reached: run.rows.last().map_or(0.0, |r| r.t),
            energy_drift: if peak > 0.0 { drift / peak } else { drift },
            peak_kinetic: peak,
            kinetic_resolution: f64::NAN,
            max_constraint_residual: run.rows.iter().map(|r| r.constraint_residual).fold(0.0, f64::max),
            error: run.error.clone(),
            aero_wall_s: run.aero_wall_s,
            aero_solves_per_step: run.aero_solves as f64 / run.aero_steps.max(1) as f64,
            oscillations: Vec::new(),
            oscillation_signal: "",
            roll: RollResponse::of(&run.rows),
        }
        .with_oscillations(run)
    }

    /// The energy drift, or None when the peak kinetic energy it is divided by is at or below
    /// the run's [`kinetic_resolution`](Self::kinetic_resolution): nothing moved that the solve
    /// resolves, drift and peak are both its residues, and their ratio (about 1) measures
    /// nothing. A run whose resolution is not known keeps its drift.
    pub fn resolved_energy_drift(&self) -> Option<f64> {
        if self.peak_kinetic <= self.kinetic_resolution { None } else { Some(self.energy_drift) }
    }

    fn with_oscillations(mut self, run: &RunOutput) -> Self {
        let fold = run.rows.iter().all(|r| r.fold.is_finite());
        let samples: Vec<(f64, f64)> =
            run.rows.iter().map(|r| (r.t, if fold { r.fold.to_degrees() } else { r.tip[2] })).collect();
        let span = samples.last().map_or(0.0, |l| l.0) - samples.first().map_or(0.0, |f| f.0);
        let window = span / 4.0;
        // At least two periods in a window.
        self.oscillations = crate::pencil::windows(&samples, window, 2.0 / window.max(1e-9));
        self.oscillation_signal = if fold { "fold" } else { "tip_z" };
        self
    }
}

/// The kinetic energy below which a run of `case` by formulation `f` does not resolve motion, J:
/// the structure's whole mass M (beams and point masses) moving by Newton's absolute tolerance
/// `atol` in one step `dt`,
///
/// $$T_{\text{res}} = \tfrac12\,M\,(\text{atol}/dt)^2 .$$
///
/// Newton accepts a step once its increments are below `atol` (m), so velocities below
/// `atol/dt` are what the solve leaves, not motion; a run whose peak kinetic energy stays at or
/// below this (a wing at zero incidence without gravity: 1e-18 J against 4e-14 J for the Goland
/// wing) has no energy to measure its drift against.
pub fn kinetic_resolution(case: &crate::case::Case, f: crate::case::Formulation) -> f64 {
    let mass: f64 = case
        .bodies
        .iter()
        .map(|b| b.section.mass * b.length + b.point_masses.iter().map(|p| p.mass).sum::<f64>())
        .sum();
    let b = case.block(f);
    let (atol, dt) = (b.newton.atol, b.dt);
    0.5 * mass * (atol / dt).powi(2)
}

/// ANCF–GEBF tip difference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairMetrics {
    /// Over the whole common time range.
    pub all: DiffStats,
    /// Over t ≤ 1 s.
    pub first_second: DiffStats,
    /// `all.max` divided by the span.
    pub max_over_span: f64,
    /// `all.rms` divided by the span.
    pub rms_over_span: f64,
}

impl PairMetrics {
    /// Compare two runs.
    pub fn of(a: &RunOutput, b: &RunOutput, span: f64) -> (Self, Vec<(f64, f64)>) {
        let d = tip_difference(&tip_curve(&a.rows), &tip_curve(&b.rows), 0.0);
        let all = window_stats(&d, f64::NEG_INFINITY, f64::INFINITY);
        let m = Self {
            all,
            first_second: window_stats(&d, f64::NEG_INFINITY, 1.0),
            max_over_span: all.max / span,
            rms_over_span: all.rms / span,
        };
        (m, d)
    }
}

/// A formulation against an external reference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceMetrics {
    /// Reference label.
    pub label: String,
    /// Formulation compared.
    pub formulation: crate::case::Formulation,
    /// Tip distance statistics.
    pub diff: DiffStats,
    /// Gate limit if any, m.
    pub tip_max_m: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::RollResponse;
    use crate::run::Row;

    /// A first-order roll response `p(t) = p_ss (1 − e^(−t/τ))`: the steady rate is the last
    /// quarter's mean, the rise time τ ln 10 to within the sampling, and no roll column gives
    /// no response.
    #[test]
    fn roll_response_of_a_first_order_lag() {
        let (p_ss, tau) = (-3.0, 0.1);
        let rows: Vec<Row> = (0..=2000)
            .map(|k| {
                let t = k as f64 * 1e-3;
                Row { t, roll_rate: p_ss * (1.0 - (-t / tau).exp()), ..nan_row() }
            })
            .collect();
        let x = RollResponse::of(&rows).unwrap();
        // Over 1.5–2 s the lag has decayed to e^−15: the mean is p_ss within 1e-6.
        assert!((x.steady_rate - p_ss).abs() < 1e-6 * p_ss.abs(), "{x:?}");
        assert!(x.spread < 1e-6, "{x:?}");
        assert!((x.rise_time_s - tau * 10f64.ln()).abs() <= 1e-3, "{x:?}");
        let none: Vec<Row> = rows.iter().map(|r| Row { roll_rate: f64::NAN, ..*r }).collect();
        assert!(RollResponse::of(&none).is_none());
    }

    /// A row with every value NaN.
    fn nan_row() -> Row {
        let nan = f64::NAN;
        Row {
            t: nan,
            tip: [nan; 3],
            fold: nan,
            roll_rate: nan,
            kinetic: nan,
            elastic: nan,
            potential: nan,
            spring: nan,
            dissipated: nan,
            total: nan,
            thrust_work: nan,
            constraint_residual: nan,
            newton_iterations: 0,
            aero_work: nan,
            lift: nan,
            root_bending_moment: nan,
            root_torque: nan,
            hinge_moment: nan,
            control_hinge_moments: [nan; aeroelastic::control_surface::MAX_CONTROL_SURFACES],
        }
    }
}
