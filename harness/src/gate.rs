//! The cross-formulation gate: each case's declared tolerances against its measured metrics.

use serde::Serialize;

use crate::case::Formulation;
use crate::metrics::window_stats;
use crate::report::CaseResult;

/// One checked metric.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// What was checked, e.g. `tip_max[0,1]` or `gebf.energy_drift`.
    pub metric: String,
    /// Measured value.
    pub value: f64,
    /// Limit.
    pub limit: f64,
    /// value ≤ limit (NaN fails).
    pub pass: bool,
}

/// Gate outcome of one case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GateOutcome {
    /// All checks.
    pub checks: Vec<Check>,
    /// Run failures (each fails the gate).
    pub failures: Vec<String>,
}

impl GateOutcome {
    /// Whether every check passed and no run failed.
    pub fn pass(&self) -> bool {
        self.failures.is_empty() && self.checks.iter().all(|c| c.pass)
    }
    /// The failed checks and failures, one line each.
    pub fn failed_lines(&self) -> Vec<String> {
        let mut v: Vec<String> = self.failures.clone();
        v.extend(
            self.checks.iter().filter(|c| !c.pass).map(|c| format!("{} = {:.4e} > {:.4e}", c.metric, c.value, c.limit)),
        );
        v
    }
}

fn check(metric: String, value: f64, limit: f64) -> Check {
    Check { metric, value, limit, pass: value <= limit }
}

/// Evaluate the case's gate (None when the case declares none).
pub fn evaluate(r: &CaseResult) -> Option<GateOutcome> {
    let gate = r.gate.as_ref()?;
    let mut out = GateOutcome { checks: Vec::new(), failures: Vec::new() };
    for run in &r.runs {
        if let Some(e) = &run.error {
            out.failures.push(format!("{} run failed: {e}", run.formulation));
        }
    }
    // The time every formulation reached: a window past it was never simulated, and its
    // statistics over the rows that exist would pass vacuously.
    let reached = if r.runs.is_empty() {
        0.0
    } else {
        r.runs.iter().map(|run| run.rows.last().map_or(f64::NEG_INFINITY, |row| row.t)).fold(f64::INFINITY, f64::min)
    };
    for w in &gate.windows {
        if w.t_end > reached + 1e-9 * w.t_end.abs().max(1.0) || reached.is_nan() {
            out.failures.push(format!(
                "gate window [{}, {}] s not covered: the run reached t = {} s",
                w.t_start,
                w.t_end,
                if reached.is_finite() { reached } else { 0.0 }
            ));
        }
        let s = window_stats(&r.pair_diff, w.t_start, w.t_end);
        out.checks.push(check(format!("tip_max[{},{}]", w.t_start, w.t_end), s.max, w.tip_max_m));
        out.checks.push(check(format!("tip_rms[{},{}]", w.t_start, w.t_end), s.rms, w.tip_rms_m));
    }
    for f in Formulation::ALL {
        if let Some(m) = r.metrics.get(&f) {
            out.checks.push(check(format!("{f}.energy_drift"), m.energy_drift, gate.energy_drift));
            out.checks.push(check(
                format!("{f}.constraint_residual"),
                m.max_constraint_residual,
                gate.constraint_residual,
            ));
        }
    }
    for rm in &r.references {
        if let Some(lim) = rm.tip_max_m {
            out.checks.push(check(format!("{}.tip_vs[{}]", rm.formulation, rm.label), rm.diff.max, lim));
        }
    }
    out.failures.extend(r.reference_errors.iter().cloned());
    Some(out)
}

/// A plain-text table of gate outcomes.
pub fn table(results: &[CaseResult]) -> String {
    let mut s = format!("{:<44} {:<36} {:>12} {:>12}  {}\n", "case", "metric", "value", "limit", "result");
    for r in results {
        match &r.gate_outcome {
            None => s.push_str(&format!("{:<44} {:<36} {:>12} {:>12}  {}\n", r.name, "(no gate)", "", "", "-")),
            Some(g) => {
                for f in &g.failures {
                    s.push_str(&format!("{:<44} {:<36} {:>12} {:>12}  FAIL\n", r.name, f, "", ""));
                }
                for c in &g.checks {
                    s.push_str(&format!(
                        "{:<44} {:<36} {:>12.4e} {:>12.4e}  {}\n",
                        r.name,
                        c.metric,
                        c.value,
                        c.limit,
                        if c.pass { "pass" } else { "FAIL" }
                    ));
                }
            }
        }
    }
    s
}
