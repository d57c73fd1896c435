//! The energy study: where each formulation's energy error comes from, and what the integrator's
//! form does about it.
//!
//! The paper's pendulums without aerodynamics conserve their total energy exactly, so at
//! rho_inf = 1 (no numerical dissipation) the drift `max_t |E(t) − E(0)|` over the peak kinetic
//! energy is the scheme's own error. Every stiff-enough pendulum case (c = 1) is run with both
//! formulations in both generalized-α forms, recording every step (the β = 45° error is a
//! transient of ~20 steps while the tip whips through the fold), at the case's time step and at
//! half of it (the drift's observed order):
//!
//! * Arnold–Brüls (the default; the trapezoidal rule at rho_inf = 1): the frames' gyroscopic
//!   and Coriolis forces do O(h²) work in GEBF's floating frames;
//! * Chung–Hulbert (the implicit midpoint rule at rho_inf = 1): that work vanishes, but the
//!   midpoint evaluation of ANCF's stiff nonlinear elastic forces gains energy.

use std::fmt::Write as _;
use std::path::Path;

use rayon::prelude::*;
use serde::Serialize;

use crate::Error;
use crate::case::{Case, FormSetting, Formulation, RunSpec};
use crate::csv::write_file;
use crate::metrics::FormulationMetrics;
use crate::plot::{Dash, Marker, Panel, Series, Style, colors, panels_svg};
use crate::run::RunOutput;
use crate::scene::run_formulation;

/// Smallest relative energy error plotted (the start of every run is below it).
const ENERGY_FLOOR: f64 = 1e-8;

/// The two forms, in report order.
pub const FORMS: [FormSetting; 2] = [FormSetting::ArnoldBruls, FormSetting::ChungHulbert];

/// One run of the study.
#[derive(Debug, Clone, Serialize)]
pub struct EnergyRun {
    /// Case name.
    pub case: String,
    /// Formulation.
    pub formulation: Formulation,
    /// Generalized-α form.
    pub form: FormSetting,
    /// Metrics (drift, Newton work, wall time, failure).
    pub metrics: FormulationMetrics,
    /// The same run at half the time step (the drift's observed order in dt).
    pub half_step: FormulationMetrics,
    /// `(t, (E(t) − E(0)) / peak kinetic energy)` at every step.
    #[serde(skip)]
    pub history: Vec<(f64, f64)>,
}

/// The study's cases among `runs`: the pendulums (no aerodynamics) at c = 1.
pub fn select(runs: &[RunSpec]) -> Vec<RunSpec> {
    runs.iter()
        .filter(|r| {
            r.ancf.aero.is_none()
                && r.gebf.aero.is_none()
                && r.ancf.stiffness_scale == 1.0
                && r.gebf.stiffness_scale == 1.0
        })
        .cloned()
        .collect()
}

/// The case of formulation `f` at rho_inf = 1 in `form` with the time step divided by
/// `refine`, recording every step, without gate or references.
fn study_case(base: &Case, f: Formulation, form: FormSetting, refine: f64) -> Case {
    let mut k = base.clone();
    let block = k.block_mut(f);
    *block.rho_inf = 1.0;
    *block.form = form;
    *block.dt /= refine;
    k.output_dt = None;
    k.gate = None;
    k.references.clear();
    k
}

/// Run the study on `specs` (rayon over runs): each case, formulation and form at the case's
/// time step and at half of it.
pub fn run(specs: &[RunSpec]) -> Vec<EnergyRun> {
    let jobs: Vec<(usize, Formulation, FormSetting, f64)> = (0..specs.len())
        .flat_map(|i| {
            Formulation::ALL.into_iter().flat_map(move |f| {
                FORMS.into_iter().flat_map(move |m| [1.0, 2.0].into_iter().map(move |r| (i, f, m, r)))
            })
        })
        .collect();
    let outs: Vec<RunOutput> = jobs
        .par_iter()
        .map(|&(i, f, form, refine)| {
            let case = study_case(specs[i].case(f), f, form, refine);
            match case.validate() {
                Ok(()) => run_formulation(&case, f),
                Err(e) => RunOutput::failed(f, format!("{}: {e}", specs[i].name)),
            }
        })
        .collect();
    jobs.chunks(2)
        .zip(outs.chunks(2))
        .map(|(j, o)| {
            let (i, f, form, _) = j[0];
            let metrics = FormulationMetrics::of(&o[0]);
            let e0 = o[0].rows.first().map_or(0.0, |r| r.total);
            let peak = if metrics.peak_kinetic > 0.0 { metrics.peak_kinetic } else { 1.0 };
            // E + W_dissipated − W_thrust is what is conserved when the case has dampers and
            // thrusts.
            let d = |r: &crate::run::Row| if r.dissipated.is_finite() { r.dissipated } else { 0.0 };
            let th = |r: &crate::run::Row| if r.thrust_work.is_finite() { r.thrust_work } else { 0.0 };
            let history = o[0].rows.iter().map(|r| (r.t, (r.total + d(r) - e0 - th(r)) / peak)).collect();
            EnergyRun {
                case: specs[i].name.clone(),
                formulation: f,
                form,
                metrics,
                half_step: FormulationMetrics::of(&o[1]),
                history,
            }
        })
        .collect()
}

impl EnergyRun {
    /// Observed order of the drift in dt, `log2(drift(dt) / drift(dt/2))` (None when a run
    /// failed or a drift is zero).
    pub fn order(&self) -> Option<f64> {
        let (a, b) = (&self.metrics, &self.half_step);
        (a.error.is_none() && b.error.is_none() && a.energy_drift > 0.0 && b.energy_drift > 0.0)
            .then(|| (a.energy_drift / b.energy_drift).log2())
    }
}

/// Write `energy.csv`, `energy.md` and `energy.svg` (|E − E(0)| / peak kinetic energy against
/// time, one panel per case) into `dir`.
pub fn write(dir: &Path, runs: &[EnergyRun]) -> Result<(), Error> {
    let mut csv = String::from(
        "case,formulation,form,ok,t_reached,energy_drift,newton_per_step,factorizations,wall_s,\
         energy_drift_half_dt,order\n",
    );
    let mut md = String::from(
        "# Energy at rho_inf = 1\n\nmax |E(t) − E(0)| / peak kinetic energy over the run, every step recorded, at the \
         case's time step and at half of it (order = log2 of their ratio).\n\n\
         | case | formulation | form | energy drift | at dt / 2 | order | Newton / step | wall [ms] |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    let drift = |m: &FormulationMetrics| match &m.error {
        None => format!("{:.2e}", m.energy_drift),
        Some(_) => format!("failed after {:.3} s", m.t_reached),
    };
    for r in runs {
        let (m, h) = (&r.metrics, &r.half_step);
        let order = r.order();
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:e},{:.4},{},{:.6},{:e},{}",
            r.case,
            r.formulation,
            r.form.as_str(),
            m.error.is_none(),
            m.t_reached,
            m.energy_drift,
            m.newton_per_step,
            m.n_factorizations,
            m.wall_s,
            h.energy_drift,
            order.map_or(String::new(), |o| format!("{o:.3}"))
        );
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {:.2} | {:.1} |",
            r.case,
            r.formulation,
            r.form.label(),
            drift(m),
            drift(h),
            order.map_or("–".into(), |o| format!("{o:.2}")),
            m.newton_per_step,
            1e3 * m.wall_s
        );
    }
    write_file(&dir.join("energy.csv"), &csv)?;
    write_file(&dir.join("energy.md"), &md)?;
    let mut cases: Vec<&str> = runs.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    // Colour: the formulation; dash and marker: the form.
    let style = |f: Formulation, form: FormSetting| {
        let c = colors::of(f);
        match form {
            FormSetting::ArnoldBruls => Style::solid(c),
            FormSetting::ChungHulbert => Style::solid(c).dash(Dash::Dashed).marker(Marker::Circle),
        }
    };
    let panels: Vec<Panel> = cases
        .iter()
        .map(|c| Panel {
            title: format!("{c}, rho_inf = 1"),
            x_label: "t [s]".into(),
            y_label: "|E − E(0)| / max T (≥ 1e-8)".into(),
            log_y: true,
            series: runs
                .iter()
                .filter(|r| r.case == *c)
                .map(|r| {
                    Series::new(
                        format!("{} {}", r.formulation.as_str().to_uppercase(), r.form.label()),
                        style(r.formulation, r.form),
                        r.history.iter().map(|&(t, e)| (t, e.abs().max(ENERGY_FLOOR))).collect(),
                    )
                })
                .collect(),
            ..Panel::default()
        })
        .collect();
    panels_svg(&dir.join("energy.svg"), &panels, 1, (900, 320))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::CaseFile;

    /// The β = 90° pendulum for 0.1 s: four runs (two formulations × two forms) at rho_inf = 1,
    /// every step recorded, each form what was asked, the outputs written.
    #[test]
    fn study_runs_both_formulations_in_both_forms() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/double_pendulum_c1_beta90.json");
        let specs = CaseFile::read(&path).unwrap().expand(&["t_end=0.1".parse().unwrap()]).unwrap();
        let specs = select(&specs);
        assert_eq!(specs.len(), 1);
        for f in Formulation::ALL {
            for form in FORMS {
                let k = study_case(specs[0].case(f), f, form, 2.0);
                let p = crate::scene::settings(&k, f).params;
                assert_eq!((p.form, p.rho_inf, p.dt), (form.to_form(), 1.0, 0.001));
            }
        }
        let runs = run(&specs);
        assert_eq!(runs.len(), 4);
        for r in &runs {
            assert!(r.metrics.error.is_none(), "{:?}", r.metrics.error);
            assert_eq!(r.history.len(), 51, "every step of 0.002 s");
            assert_eq!(r.half_step.n_steps, 100, "half steps");
            assert!(r.metrics.energy_drift < 1e-3, "{} {:?}: {}", r.formulation, r.form, r.metrics.energy_drift);
        }
        let dir = std::env::temp_dir().join(format!("harness-energy-{}", std::process::id()));
        write(&dir, &runs).unwrap();
        let csv = std::fs::read_to_string(dir.join("energy.csv")).unwrap();
        assert_eq!(csv.lines().count(), 5);
        assert!(csv.contains("chung_hulbert") && csv.contains("arnold_bruls"));
        assert!(std::fs::read_to_string(dir.join("energy.svg")).unwrap().contains("Chung–Hulbert"));
        std::fs::remove_dir_all(dir).ok();
    }
}
