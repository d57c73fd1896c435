//! `harness merge DIR… [--out DIR]`: one report from the outputs of the shards of a sweep
//! ([`crate::shard`]).
//!
//! Every shard leaves a manifest (`<out>/shards/<command>-k-of-N.json`: every unit of the
//! command, its shard, and the units this shard finished) and, under
//! `<out>/shards/<command>-k-of-N/`, the exact results of its units: each case run's
//! [`RunOutput`]s with its [`RunSpec`] (`runs/<run>.json`), and its stress-matrix cells and extra
//! runs (`stress.json`), every `f64` stored by its bits. The merge
//!
//! 1. reads the manifests in the folders given (several shards may share one folder), checks that
//!    they describe the same plan, and names every unit no shard finished;
//! 2. copies each folder's files (run folders, studies) into `--out`, the `shards/` folder
//!    excepted;
//! 3. rebuilds the case results ([`CaseResult::evaluate`] on the exact runs: the same metrics and
//!    gate as a single machine's) and writes `index.html` and `summary.md`, and the stress matrix's
//!    `stress.csv`, `stress.json`, heat maps and `extras.csv` from all shards' cells in the
//!    matrix's order.
//!
//! Apart from the measured times, the merged folder is what one machine running the unsharded
//! command writes: the same CSV files byte for byte and the same summaries.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::case::{Case, Formulation, RunSpec};
use crate::metrics::FormulationMetrics;
use crate::report::CaseResult;
use crate::run::{Row, RunOutput};
use crate::shard::{Manifest, Plan, SHARDS_DIR};
use crate::stress::{Axes, Cell, Extra};

fn io(p: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io(format!("{}: {e}", p.display()))
}

fn json_err(p: &Path) -> impl Fn(serde_json::Error) -> Error + '_ {
    move |e| Error::Io(format!("{}: {e}", p.display()))
}

/// A row with every `f64` as its bits (`newton_iterations` as itself): the 18 columns, then
/// the control surfaces' hinge moments (a record of 18 has none: NaN), then the roll rate, then
/// the thrusts' work (an older record without it: NaN).
type RowBits = Vec<u64>;

fn row_bits(r: &Row) -> RowBits {
    let b = f64::to_bits;
    let mut v = vec![
        b(r.t),
        b(r.tip[0]),
        b(r.tip[1]),
        b(r.tip[2]),
        b(r.fold),
        b(r.kinetic),
        b(r.elastic),
        b(r.potential),
        b(r.spring),
        b(r.dissipated),
        b(r.total),
        b(r.constraint_residual),
        r.newton_iterations as u64,
        b(r.aero_work),
        b(r.lift),
        b(r.root_bending_moment),
        b(r.root_torque),
        b(r.hinge_moment),
    ];
    v.extend(r.control_hinge_moments.iter().map(|&h| b(h)));
    v.push(b(r.roll_rate));
    v.push(b(r.thrust_work));
    v
}

fn row_of(x: &[u64]) -> Row {
    let f = f64::from_bits;
    let g = |i: usize| x.get(i).map_or(f64::NAN, |&v| f(v));
    Row {
        t: g(0),
        tip: [g(1), g(2), g(3)],
        fold: g(4),
        kinetic: g(5),
        elastic: g(6),
        potential: g(7),
        spring: g(8),
        dissipated: g(9),
        total: g(10),
        constraint_residual: g(11),
        newton_iterations: x.get(12).map_or(0, |&v| v as usize),
        aero_work: g(13),
        lift: g(14),
        root_bending_moment: g(15),
        root_torque: g(16),
        hinge_moment: g(17),
        control_hinge_moments: std::array::from_fn(|i| g(18 + i)),
        roll_rate: g(18 + aeroelastic::control_surface::MAX_CONTROL_SURFACES),
        thrust_work: g(19 + aeroelastic::control_surface::MAX_CONTROL_SURFACES),
    }
}

/// A [`RunOutput`] stored exactly.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RunRecord {
    formulation: Formulation,
    rows: Vec<RowBits>,
    wall_s: u64,
    stats: [usize; 6],
    n_dof: usize,
    error: Option<String>,
    aero_wall_s: u64,
    #[serde(default)]
    aero_solves: usize,
    #[serde(default)]
    aero_steps: usize,
}

impl RunRecord {
    fn of(r: &RunOutput) -> Self {
        let s = &r.stats;
        Self {
            formulation: r.formulation,
            rows: r.rows.iter().map(row_bits).collect(),
            wall_s: r.wall_s.to_bits(),
            stats: [
                s.n_steps,
                s.n_newton_iters,
                s.max_newton_iters,
                s.n_factorizations,
                s.n_residual_evals,
                s.n_step_halvings,
            ],
            n_dof: r.n_dof,
            error: r.error.clone(),
            aero_wall_s: r.aero_wall_s.to_bits(),
            aero_solves: r.aero_solves,
            aero_steps: r.aero_steps,
        }
    }

    fn output(&self) -> RunOutput {
        let [n_steps, n_newton_iters, max_newton_iters, n_factorizations, n_residual_evals, n_step_halvings] =
            self.stats;
        RunOutput {
            formulation: self.formulation,
            rows: self.rows.iter().map(|r| row_of(r)).collect(),
            wall_s: f64::from_bits(self.wall_s),
            stats: genalpha::Stats {
                n_steps,
                n_newton_iters,
                max_newton_iters,
                n_factorizations,
                n_residual_evals,
                n_step_halvings,
            },
            n_dof: self.n_dof,
            error: self.error.clone(),
            aero_wall_s: f64::from_bits(self.aero_wall_s),
            aero_solves: self.aero_solves,
            aero_steps: self.aero_steps,
            // The shards' exact results do not carry the hinge events' records (their effect is
            // in the rows; each shard's own folder has its events CSV).
            events: Vec::new(),
            // Nor the section polars' strips of the last solve (an in-memory diagnostic).
            strips: Vec::new(),
        }
    }
}

/// A case run: its spec and its runs.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct CaseRecord {
    name: String,
    dir: PathBuf,
    ancf: Case,
    gebf: Case,
    runs: Vec<RunRecord>,
}

/// Save the exact runs of a case result for the merge, in `data_dir/runs/<run>.json`.
pub fn save_case(data_dir: &Path, spec: &RunSpec, result: &CaseResult) -> Result<(), Error> {
    let rec = CaseRecord {
        name: spec.name.clone(),
        dir: spec.dir.clone(),
        ancf: spec.ancf.clone(),
        gebf: spec.gebf.clone(),
        runs: result.runs.iter().map(RunRecord::of).collect(),
    };
    let path = data_dir.join("runs").join(format!("{}.json", spec.name));
    let json = serde_json::to_string(&rec).map_err(json_err(&path))?;
    crate::atomic::write(&path, json.as_bytes())
}

fn load_case(path: &Path) -> Result<CaseResult, Error> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    let rec: CaseRecord = serde_json::from_str(&text).map_err(json_err(path))?;
    let spec = RunSpec { name: rec.name, dir: rec.dir, ancf: rec.ancf, gebf: rec.gebf };
    Ok(CaseResult::evaluate(&spec, rec.runs.iter().map(RunRecord::output).collect()))
}

/// [`FormulationMetrics`] stored exactly.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct MetricsRecord {
    f: [u64; 8],
    n: [usize; 5],
    error: Option<String>,
    /// Each oscillation's window start and end, frequency, growth rate, damping ratio, amplitude.
    oscillations: Vec<[u64; 6]>,
    oscillation_signal: String,
    #[serde(default)]
    aero_solves_per_step: u64,
}

impl MetricsRecord {
    fn of(m: &FormulationMetrics) -> Self {
        let b = f64::to_bits;
        Self {
            f: [
                b(m.wall_s),
                b(m.steps_per_s),
                b(m.newton_per_step),
                b(m.t_reached),
                b(m.energy_drift),
                b(m.peak_kinetic),
                b(m.max_constraint_residual),
                b(m.kinetic_resolution),
            ],
            n: [m.n_steps, m.n_newton_iters, m.max_newton_iters, m.n_factorizations, m.n_dof],
            error: m.error.clone(),
            oscillations: m
                .oscillations
                .iter()
                .map(|o| {
                    [o.t_start, o.t_end, o.frequency_hz, o.growth_rate, o.damping_ratio, o.amplitude].map(f64::to_bits)
                })
                .collect(),
            oscillation_signal: m.oscillation_signal.to_string(),
            aero_solves_per_step: m.aero_solves_per_step.to_bits(),
        }
    }

    fn metrics(&self, aero_wall_s: f64) -> FormulationMetrics {
        let f = |i: usize| f64::from_bits(self.f[i]);
        FormulationMetrics {
            wall_s: f(0),
            n_steps: self.n[0],
            steps_per_s: f(1),
            n_newton_iters: self.n[1],
            newton_per_step: f(2),
            max_newton_iters: self.n[2],
            n_factorizations: self.n[3],
            n_dof: self.n[4],
            t_reached: f(3),
            energy_drift: f(4),
            peak_kinetic: f(5),
            kinetic_resolution: f(7),
            max_constraint_residual: f(6),
            error: self.error.clone(),
            aero_wall_s,
            aero_solves_per_step: f64::from_bits(self.aero_solves_per_step),
            oscillations: self
                .oscillations
                .iter()
                .map(|o| {
                    let [t_start, t_end, frequency_hz, growth_rate, damping_ratio, amplitude] = o.map(f64::from_bits);
                    crate::pencil::Oscillation { t_start, t_end, frequency_hz, growth_rate, damping_ratio, amplitude }
                })
                .collect(),
            // The signals `FormulationMetrics::of` names.
            oscillation_signal: match self.oscillation_signal.as_str() {
                "fold" => "fold",
                "tip_z" => "tip_z",
                _ => "",
            },
            // The stress study's cells have no roll joint (a merged case's metrics are evaluated
            // afresh from its rows).
            roll: None,
        }
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct MetricsPair {
    metrics: MetricsRecord,
    aero_wall_s: u64,
}

impl MetricsPair {
    fn of(m: &FormulationMetrics) -> Self {
        Self { metrics: MetricsRecord::of(m), aero_wall_s: m.aero_wall_s.to_bits() }
    }
    fn get(&self) -> FormulationMetrics {
        self.metrics.metrics(f64::from_bits(self.aero_wall_s))
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct CellRecord {
    id: String,
    formulation: Formulation,
    axes: [u64; 4],
    metrics: MetricsPair,
    recovery: Option<MetricsPair>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct ExtraRecord {
    label: String,
    formulation: Formulation,
    metrics: MetricsPair,
    recovery: Option<MetricsPair>,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct StressRecord {
    cells: Vec<CellRecord>,
    extras: Vec<ExtraRecord>,
}

/// Save a shard's stress-matrix cells and extra runs for the merge (`data_dir/stress.json`).
pub fn save_stress(data_dir: &Path, cells: &[Cell], extras: &[Extra]) -> Result<(), Error> {
    let rec = StressRecord {
        cells: cells
            .iter()
            .map(|k| CellRecord {
                id: crate::stress::job_id(&(k.formulation, k.c, k.beta_deg, k.dt_factor, k.rho_inf)),
                formulation: k.formulation,
                axes: [k.c.to_bits(), k.beta_deg.to_bits(), k.dt_factor.to_bits(), k.rho_inf.to_bits()],
                metrics: MetricsPair::of(&k.metrics),
                recovery: k.recovery.as_ref().map(MetricsPair::of),
            })
            .collect(),
        extras: extras
            .iter()
            .map(|e| ExtraRecord {
                label: e.label.clone(),
                formulation: e.formulation,
                metrics: MetricsPair::of(&e.metrics),
                recovery: e.recovery.as_ref().map(MetricsPair::of),
            })
            .collect(),
    };
    let path = data_dir.join("stress.json");
    let json = serde_json::to_string(&rec).map_err(json_err(&path))?;
    crate::atomic::write(&path, json.as_bytes())
}

/// The unit name of an extra run of the stress study.
pub fn extra_unit(label: &str) -> String {
    format!("stress-extra:{label}")
}

/// What a merge found.
#[derive(Debug, Clone, Default)]
pub struct Merged {
    /// `(command, k/N)` of every manifest read.
    pub shards: Vec<(String, String)>,
    /// Units no shard finished: `(command, unit, the shard that owns it)`.
    pub missing: Vec<(String, String, usize)>,
    /// The case results rebuilt, in the plan's order.
    pub results: Vec<CaseResult>,
    /// Stress cells merged (both formulations).
    pub stress_cells: usize,
}

/// Every manifest in `dir/shards/`.
fn manifests(dir: &Path) -> Result<Vec<(PathBuf, Manifest)>, Error> {
    let sd = dir.join(SHARDS_DIR);
    let rd = match std::fs::read_dir(&sd) {
        Ok(rd) => rd,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io(&sd)(e)),
    };
    let mut paths: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json") && p.is_file())
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).map_err(io(&p))?;
            let m: Manifest = serde_json::from_str(&text).map_err(json_err(&p))?;
            Ok((p, m))
        })
        .collect()
}

/// Copy `src` into `dst` recursively (files overwritten), leaving out `shards/` at the top and
/// lock and temporary files.
fn copy_tree(src: &Path, dst: &Path, top: bool) -> Result<(), Error> {
    std::fs::create_dir_all(dst).map_err(io(dst))?;
    let mut entries: Vec<_> = std::fs::read_dir(src).map_err(io(src))?.filter_map(Result::ok).collect();
    entries.sort_by_key(|e| e.file_name());
    for e in entries {
        let name = e.file_name();
        let n = name.to_string_lossy();
        if (top && n == SHARDS_DIR) || n == ".lock" || n.contains(".tmp-") {
            continue;
        }
        let (from, to) = (e.path(), dst.join(&name));
        let ty = e.file_type().map_err(io(&from))?;
        if ty.is_dir() {
            copy_tree(&from, &to, false)?;
        } else if ty.is_file() {
            std::fs::copy(&from, &to).map_err(io(&from))?;
        }
    }
    Ok(())
}

/// Merge the shards' outputs in `dirs` into `out` (see the module docs). Returns what was found;
/// the caller reports [`Merged::missing`]. An error when no manifest is found or the shards'
/// plans differ.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Merged, Error> {
    // Manifests by command, each shard once (shards may share a folder, listed more than once).
    let mut by_cmd: BTreeMap<String, BTreeMap<usize, (PathBuf, Manifest)>> = BTreeMap::new();
    let mut seen_dirs = BTreeSet::new();
    for d in dirs {
        let canon = d.canonicalize().map_err(io(d))?;
        if !seen_dirs.insert(canon) {
            continue;
        }
        for (p, m) in manifests(d)? {
            let cmd = m.plan.command.clone();
            let k = m.plan.shard.k;
            let slot = by_cmd.entry(cmd.clone()).or_default();
            if let Some((other, _)) = slot.get(&k) {
                return Err(Error::Io(format!(
                    "merge: shard {k} of `{cmd}` appears twice ({} and {})",
                    other.display(),
                    p.display()
                )));
            }
            slot.insert(k, (d.clone(), m));
        }
    }
    if by_cmd.is_empty() {
        let list: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
        return Err(Error::Io(format!(
            "merge: no shard manifest (shards/*.json) in {}: were they written with --shard?",
            list.join(", ")
        )));
    }
    let mut merged = Merged::default();
    // Files first: every folder's run and study files.
    let out_canon = {
        std::fs::create_dir_all(out).map_err(io(out))?;
        out.canonicalize().map_err(io(out))?
    };
    for d in seen_dirs.iter().filter(|d| **d != out_canon) {
        copy_tree(d, out, true)?;
    }
    for (cmd, shards) in &by_cmd {
        let (_, first) = shards.values().next().expect("at least one shard");
        let plan: &Plan = &first.plan;
        for (dir, m) in shards.values() {
            if m.plan.units != plan.units || m.plan.owner != plan.owner || m.plan.shard.n != plan.shard.n {
                return Err(Error::Io(format!(
                    "merge: the shards of `{cmd}` in {} plan other runs than shard {}'s (a different sweep, \
                     overrides or N)",
                    dir.display(),
                    plan.shard.k
                )));
            }
            merged.shards.push((cmd.clone(), m.plan.shard.to_string()));
        }
        let done: BTreeSet<&str> = shards.values().flat_map(|(_, m)| m.done.iter().map(String::as_str)).collect();
        for (u, &o) in plan.units.iter().zip(&plan.owner) {
            if !done.contains(u.id.as_str()) {
                merged.missing.push((cmd.clone(), u.id.clone(), o));
            }
        }
        // Case runs, in the plan's order.
        let data = |m: &Manifest, dir: &Path| m.plan.data_dir(dir);
        let mut results = Vec::new();
        for u in &plan.units {
            let Some(name) = u.id.strip_prefix("run:") else { continue };
            for (dir, m) in shards.values() {
                let p = data(m, dir).join("runs").join(format!("{name}.json"));
                if m.done.contains(&u.id) && p.exists() {
                    results.push(load_case(&p)?);
                    break;
                }
            }
        }
        // The stress matrix.
        let mut cells: BTreeMap<String, Cell> = BTreeMap::new();
        let mut extras: Vec<Extra> = Vec::new();
        for (dir, m) in shards.values() {
            let p = data(m, dir).join("stress.json");
            if !p.exists() {
                continue;
            }
            let text = std::fs::read_to_string(&p).map_err(io(&p))?;
            let rec: StressRecord = serde_json::from_str(&text).map_err(json_err(&p))?;
            for c in rec.cells {
                let f = f64::from_bits;
                cells.insert(
                    c.id,
                    Cell {
                        formulation: c.formulation,
                        c: f(c.axes[0]),
                        beta_deg: f(c.axes[1]),
                        dt_factor: f(c.axes[2]),
                        rho_inf: f(c.axes[3]),
                        metrics: c.metrics.get(),
                        recovery: c.recovery.as_ref().map(MetricsPair::get),
                    },
                );
            }
            extras.extend(rec.extras.into_iter().map(|e| Extra {
                label: e.label,
                formulation: e.formulation,
                metrics: e.metrics.get(),
                recovery: e.recovery.as_ref().map(MetricsPair::get),
            }));
        }
        if let Some(stress_dir) = first.args.get("stress_dir").and_then(|v| v.as_str()) {
            let axes: Axes = first
                .args
                .get("axes")
                .and_then(|a| serde_json::from_value(a.clone()).ok())
                .ok_or_else(|| Error::Io(format!("merge: the `{cmd}` manifests have no stress-matrix axes")))?;
            let ordered: Vec<Cell> = plan.units.iter().filter_map(|u| cells.get(&u.id)).cloned().collect();
            if !ordered.is_empty() {
                crate::stress::write(&out.join(stress_dir), &axes, &ordered)?;
            }
            // Extras in the plan's order, ANCF before GEBF as one machine runs them.
            let mut ex = Vec::new();
            for u in plan.units.iter().filter(|u| u.id.starts_with("stress-extra:")) {
                for f in Formulation::ALL {
                    ex.extend(extras.iter().filter(|e| extra_unit(&e.label) == u.id && e.formulation == f).cloned());
                }
            }
            if !ex.is_empty() {
                crate::stress::write_extras(&out.join(stress_dir), &ex)?;
            }
            merged.stress_cells += ordered.len();
        }
        if first.args.get("report").and_then(serde_json::Value::as_bool) == Some(true) {
            crate::driver::write_index(out, &results)?;
        }
        merged.results.extend(results);
    }
    Ok(merged)
}
