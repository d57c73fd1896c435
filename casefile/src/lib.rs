//! # casefile — flexmb's case files
//!
//! The case-file schema (the scene: bodies, joints, gravity; solver settings per formulation;
//! external references and gate tolerances; the analyses' blocks), read from JSON ([`CaseFile`]),
//! expanded over its sweep and `--set` overrides into [`RunSpec`]s, validated ([`Case::validate`]
//! names the offending field of every impossible value; unknown fields are errors), checked
//! against the cost limits ([`budget`]) and converted in one place to the library's
//! [`aeroelastic::Problem`] ([`Case::problem`]). [`scene`] runs a case's formulation through
//! [`aeroelastic::factory`]; [`csv`] and [`curve`] are the file formats the `harness` command
//! line and the Python package share (the time-history columns, the static sweep's header, the
//! reference curves a case names).
//!
//! This crate is what a front end needs between a case file and the analyses, without the
//! command line, plots or progress bars. The JSON-schema derives sit behind the `schema` feature
//! (`json_schema`).
#![warn(missing_docs)]

use std::path::{Path, PathBuf};

#[cfg(feature = "schema")]
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

pub mod budget;
pub mod csv;
pub mod curve;
mod error;
mod json;
mod polars;
pub mod scene;
mod to_lib;
mod validate;

pub use error::Error;
pub use json::parse_unique_keys;

pub use aeroelastic::problem::{
    AncfPath, AncfSettings, Block, BlockMut, Body, Elements, FormSetting, Formulation, GebfSettings, Joint,
    NewtonSettings, PointMass, PredictorSetting, Section, Spring, StaticPointLoad,
};

fn one() -> f64 {
    1.0
}

/// One simulation scene, run with both formulations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Unique name; outputs go to `reports/<name>/`.
    pub name: String,
    /// Free text shown in the reports.
    #[serde(default)]
    pub description: String,
    /// Beam bodies, straight in the reference configuration.
    pub bodies: Vec<Body>,
    /// Joints between bodies and to ground.
    pub joints: Vec<Joint>,
    /// Gravity vector, m/s² (omit for none).
    #[serde(default)]
    pub gravity: Option<[f64; 3]>,
    /// Nose-up pitch of the whole scene, degrees, in [−90, 90]: every body's start point and
    /// section axes are rotated about the global X axis through the origin (Y towards Z) before
    /// anything else, so that a wing whose leading edge points along +Y (free stream along −Y)
    /// meets the flow at this incidence. Gravity and the free stream are not rotated. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub pitch_deg: f64,
    /// Multiplies every stiffness (EA, GA_y, GA_z, GJ, EI_yy, EI_zz): the paper's `c`. Default 1.
    #[serde(default = "one")]
    pub stiffness_scale: f64,
    /// End time, s.
    pub t_end: f64,
    /// Output interval, s (default: every step of the formulation).
    #[serde(default)]
    pub output_dt: Option<f64>,
    /// Name of the flared hinge whose fold angle is the `fold` sensor (default: the first one).
    #[serde(default)]
    pub fold_joint: Option<String>,
    /// Name of the ground hinge whose rate is the `roll_rate` column (a roll rig's shaft).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_joint: Option<String>,
    /// Name of the joint at which the `root_bending_moment` and `root_torque` columns are
    /// measured: a flared hinge (its child and everything outboard, in the child's root section
    /// frame; a wing's root on a free aircraft) or a clamp (default: the first clamp).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub root_joint: Option<String>,
    /// Hinge events of the time march: `[{ "time", "joint", "action": "lock" | "release" }]`
    /// (docs/case-file.md §2.1).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<aeroelastic::events::HingeEvent>,
    /// Thrusts, follower forces on bodies: `{ "body", "at", "direction", "magnitude" }` or a list
    /// of them (docs/case-file.md §2.2).
    #[serde(default, skip_serializing_if = "Vec::is_empty", deserialize_with = "one_or_many")]
    #[cfg_attr(feature = "schema", schemars(with = "OneOrMany<aeroelastic::thrust::Thrust>"))]
    pub thrust: Vec<aeroelastic::thrust::Thrust>,
    /// ANCF settings.
    pub ancf: AncfSettings,
    /// GEBF settings.
    pub gebf: GebfSettings,
    /// External reference curves drawn as a third curve and included in the metrics.
    #[serde(default)]
    pub references: Vec<Reference>,
    /// Gate tolerances (omit: the case is reported but not gated).
    #[serde(default)]
    pub gate: Option<Gate>,
    /// Aerodynamics (UVLM) — omit for a purely structural case.
    #[serde(default)]
    pub aero: Option<aeroelastic::aero::AeroSettings>,
    /// `harness all` also runs the refinement ladders of this case (`harness converge`).
    #[serde(default)]
    pub converge: bool,
    /// End time of the refinement study, s (default `t_end`). An aeroelastic case's finest rungs
    /// take 8× the steps with 8× the wake rows, so a shorter window keeps the study in minutes.
    #[serde(default)]
    pub converge_t_end: Option<f64>,
    /// ParaView files for every run of this case (`harness run` and `harness all`), as `--vtk`
    /// writes them (docs/outputs.md §7); omit for none.
    #[serde(default)]
    pub vtk: Option<VtkOutput>,
    /// Parameter sweep: each entry maps a `--set`-style path (e.g. `stiffness_scale`,
    /// `joints.1.flare_deg`, `ancf.dt`) to a list of values; the Cartesian product expands into
    /// named runs `<name>__<key>=<value>…`.
    #[serde(default)]
    pub sweep: Vec<SweepAxis>,
    /// Static aeroelastic equilibria (`harness static`): the airspeeds of the sweep and the
    /// experiment or model curves to compare with. Needs `aero`.
    #[serde(default, rename = "static", skip_serializing_if = "Option::is_none")]
    pub statics: Option<StaticSettings>,
    /// Trim in steady level flight (`harness trim`): the control surfaces that act as the
    /// elevator and the solver's settings. Needs a free joint, `aero` and `thrust`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trim: Option<aeroelastic::trim::TrimSettings>,
    /// Where a time march starts: `"reference"` (default: the reference configuration at rest,
    /// an impulsively started lattice), `"trim"` (the trimmed state of `trim`, in level flight
    /// with the steady wake; docs/trim.md §5) or `"trim_held"` (the same state with the aircraft
    /// held at its free body throughout; docs/trim.md §6).
    #[serde(default, skip_serializing_if = "aeroelastic::trim::Initial::is_reference")]
    pub initial: aeroelastic::trim::Initial,
    /// Linearised stability (`harness stability`): airspeeds, modes to track, the state to
    /// linearise about. Needs `aero`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stability: Option<aeroelastic::stability::StabilitySettings>,
    /// Gust sweep (`harness gust`): the gradients (or gust frequencies) of the case's 1-cos
    /// `aero.gust` and the hinge states to fly through them (docs/gust.md). Needs `aero.gust`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<aeroelastic::gust::GustSweep>,
    /// The polars of `aero.polars`, read by [`Case::load_polars`] when the case is expanded (not
    /// a case-file field).
    #[serde(skip)]
    #[cfg_attr(feature = "schema", schemars(skip))]
    pub polars: Vec<aeroelastic::section_polars::BodyPolar>,
}

/// One entry or a list of them (the case field `thrust`).
#[derive(Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(untagged)]
#[allow(dead_code)] // only its schema and its deserialisation are used
enum OneOrMany<T> {
    One(T),
    Many(Vec<T>),
}

fn one_or_many<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    Ok(match OneOrMany::deserialize(d)? {
        OneOrMany::One(t) => vec![t],
        OneOrMany::Many(v) => v,
    })
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// The case file's `vtk` block: write ParaView files for every run of the case, as `--vtk`
/// does (`harness run` and `harness all`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct VtkOutput {
    /// Write every N-th output step (≥ 1; default: about 100 frames per run,
    /// max(1, output rows / 100)). `--vtk-stride` overrides it.
    #[serde(default)]
    pub stride: Option<usize>,
}

/// The static aeroelastic sweep of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct StaticSettings {
    /// Airspeeds of the sweep, m/s (positive; the free stream keeps the direction of
    /// `aero.v_inf`, or −Y). Reported in the order given. Required with `aero`; must be absent
    /// or empty without it.
    #[serde(default)]
    pub airspeeds: Vec<f64>,
    /// Dead point loads of a structural static case (a case without `aero`): forces and moments
    /// in global components at body sections, applied by `harness static` only (the time
    /// domain ignores them), scaled by each of `load_factors`. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub point_loads: Vec<StaticPointLoad>,
    /// Load factors of a structural static case: one equilibrium per factor, each reached by
    /// load steps of at most 0.05 of the full load from the previous one (increasing order).
    /// Required with `point_loads`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub load_factors: Vec<f64>,
    /// Measured or computed coast angles to compare with: CSV files of two columns, airspeed
    /// (m/s) — or sideslip (degrees) for a sweep in `sideslips_deg` — and fold angle (degrees),
    /// relative to the case file's folder.
    #[serde(default)]
    pub references: Vec<StaticReference>,
    /// The steady wake of the static solution: `rows` straight rows of `row_length` (m) along
    /// the free stream behind the trailing edge, without closure a finite frozen wake (each
    /// strip's wake one ring of length `rows·row_length` carrying its trailing-edge circulation,
    /// the steady state of a time march with `aero.n_wake_rows` rows of `airspeed·dt`), with
    /// `closure` the semi-infinite legs. Default (absent): semi-infinite legs along the free
    /// stream. Needs `aero`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wake: Option<aeroelastic::stability::WakeSettings>,
    /// A sweep in sideslip instead of airspeed: sideslip angles, degrees (the convention of
    /// `aero.sideslip_deg`), each solved at the one airspeed of `airspeeds`, continued from the
    /// angle nearest zero outwards in both directions. The references then give the fold angle
    /// against sideslip (degrees). Default none (a sweep in airspeed at `aero.sideslip_deg`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sideslips_deg: Vec<f64>,
}

/// A curve of equilibrium fold (coast) angle against airspeed (or sideslip).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct StaticReference {
    /// Legend label.
    pub label: String,
    /// CSV file (`airspeed_m_s,coast_angle_deg`), relative to the case file's folder.
    pub file: String,
    /// An experiment (drawn as points and used for the error metrics) rather than a model
    /// (drawn as a line, compared for information). Default false.
    #[serde(default)]
    pub experiment: bool,
}

/// One sweep dimension.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct SweepAxis {
    /// Dotted path into the case (as for `--set`).
    pub path: String,
    /// Values to take.
    pub values: Vec<Value>,
}

/// An external reference curve (CSV with a header; `#` lines are comments).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Legend label.
    pub label: String,
    /// CSV path relative to the case file's folder; needs columns `t, tip_x, tip_y, tip_z`.
    pub file: String,
    /// The reference at time t + `time_shift` is compared with the run at time t, s (SHARPy's
    /// zero-acceleration start lags by dt/2: use dt/2).
    #[serde(default)]
    pub time_shift: f64,
    /// Gate: maximum tip distance from this reference, m, per formulation (omit: not gated).
    #[serde(default)]
    pub tip_max_m: Option<f64>,
    /// The reference is converged (its own error far below the formulations' at the case's
    /// settings): convergence studies measure the diagonal ladder against it.
    #[serde(default)]
    pub converged: bool,
}

/// Gate tolerances of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct Gate {
    /// Why these numbers (refinement study); shown in the reports.
    #[serde(default)]
    pub justification: String,
    /// Windows of the ANCF–GEBF tip difference.
    pub windows: Vec<GateWindow>,
    /// Maximum energy drift (max |E − E0 − W_aero| / peak kinetic energy), each formulation.
    pub energy_drift: f64,
    /// Maximum position-level constraint residual, each formulation.
    pub constraint_residual: f64,
}

/// Tip-difference limits over a time window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct GateWindow {
    /// Window start, s.
    pub t_start: f64,
    /// Window end, s.
    pub t_end: f64,
    /// Maximum tip difference |p_ANCF − p_GEBF|, m.
    pub tip_max_m: f64,
    /// RMS tip difference, m.
    pub tip_rms_m: f64,
}

/// An override `path=value`, optionally for one formulation only (`gebf:path=value`).
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// Only for this formulation, or for both.
    pub only: Option<Formulation>,
    /// Dotted path (`joints.1.flare_deg`).
    pub path: String,
    /// JSON value (a bare word that is not JSON is taken as a string).
    pub value: Value,
}

impl std::str::FromStr for Override {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        let bad = || Error::Override(format!("`{s}` is not of the form [ancf:|gebf:]path=value"));
        let (lhs, rhs) = s.split_once('=').ok_or_else(bad)?;
        let (only, path) = match lhs.split_once(':') {
            Some((name, p)) => (Some(Formulation::from_name(name).ok_or_else(bad)?), p),
            None => (None, lhs),
        };
        if path.is_empty() {
            return Err(bad());
        }
        let value = serde_json::from_str(rhs).unwrap_or_else(|_| Value::String(rhs.to_string()));
        Ok(Override { only, path: path.to_string(), value })
    }
}

/// Set `path` (dotted; numbers index arrays) in a JSON value. The path must exist except for
/// its last key in an object. A key that is not a number selects, in an array of objects, the
/// element whose `"name"` equals it (`aero.control_surfaces.aileron.deflection_deg`).
pub fn set_path(root: &mut Value, path: &str, value: Value) -> Result<(), Error> {
    let keys: Vec<&str> = path.split('.').collect();
    let mut cur = root;
    for (i, key) in keys.iter().enumerate() {
        let last = i + 1 == keys.len();
        let here = keys[..=i].join(".");
        cur = match cur {
            Value::Object(map) => {
                if last {
                    map.insert((*key).to_string(), value);
                    return Ok(());
                }
                // Missing intermediate objects are created (e.g. `ancf.newton.rtol`); a misspelt
                // key is then rejected by the schema, naming the field.
                map.entry((*key).to_string()).or_insert_with(|| Value::Object(Default::default()))
            }
            Value::Array(arr) => {
                let idx = match key.parse::<usize>() {
                    Ok(i) => i,
                    Err(_) => arr.iter().position(|x| x.get("name").and_then(Value::as_str) == Some(*key)).ok_or_else(
                        || Error::Override(format!("`{here}`: no element named `{key}` (nor an array index)")),
                    )?,
                };
                let len = arr.len();
                let slot = arr
                    .get_mut(idx)
                    .ok_or_else(|| Error::Override(format!("`{here}`: index {idx} out of range (length {len})")))?;
                if last {
                    *slot = value;
                    return Ok(());
                }
                slot
            }
            _ => return Err(Error::Override(format!("`{here}`: cannot index into a number or string"))),
        };
    }
    Ok(())
}

/// A case file read from disk, before sweeps and overrides are applied.
#[derive(Debug, Clone)]
pub struct CaseFile {
    /// Path of the file.
    pub path: PathBuf,
    /// Raw JSON.
    pub raw: Value,
}

impl CaseFile {
    /// Read and parse JSON (syntax only; the schema is checked per run). The file must be a
    /// regular file of at most [`crate::budget::MAX_CASE_BYTES`].
    pub fn read(path: &Path) -> Result<Self, Error> {
        let io = |e: std::io::Error| Error::Io(format!("{}: {e}", path.display()));
        let meta = std::fs::metadata(path).map_err(io)?;
        let bad = |msg: String| Error::Case { file: path.display().to_string(), msg };
        if !meta.is_file() {
            return Err(bad("not a regular file".into()));
        }
        if meta.len() > crate::budget::MAX_CASE_BYTES {
            return Err(bad(format!(
                "{} bytes, more than the limit of {} for a case file",
                meta.len(),
                crate::budget::MAX_CASE_BYTES
            )));
        }
        let mut bytes = Vec::new();
        use std::io::Read as _;
        std::fs::File::open(path)
            .and_then(|f| f.take(crate::budget::MAX_CASE_BYTES + 1).read_to_end(&mut bytes))
            .map_err(io)?;
        Self::from_bytes(path, &bytes)
    }

    /// Parse the bytes of a case file read from `path` (references are resolved against its
    /// folder). Invalid UTF-8 is reported with its line and column.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Self, Error> {
        let bad = |msg: String| Error::Case { file: path.display().to_string(), msg: clip(&msg) };
        if bytes.len() as u64 > crate::budget::MAX_CASE_BYTES {
            return Err(bad(format!("more than the limit of {} bytes for a case file", crate::budget::MAX_CASE_BYTES)));
        }
        let text = std::str::from_utf8(bytes).map_err(|e| {
            let ok = &bytes[..e.valid_up_to()];
            let line = ok.iter().filter(|&&b| b == b'\n').count() + 1;
            let col = ok.len() - ok.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1) + 1;
            bad(format!("invalid UTF-8 at line {line} column {col} (byte {})", e.valid_up_to()))
        })?;
        let raw = parse_unique_keys(text).map_err(|e| bad(e.to_string()))?;
        Ok(Self { path: path.to_path_buf(), raw })
    }

    /// Folder references are resolved against.
    pub fn dir(&self) -> PathBuf {
        self.path.parent().map(Path::to_path_buf).unwrap_or_default()
    }

    /// Expand the sweep and apply overrides; returns one [`RunSpec`] per sweep point.
    pub fn expand(&self, overrides: &[Override]) -> Result<Vec<RunSpec>, Error> {
        self.expand_within(overrides, &crate::budget::limits(), None)
    }

    /// As [`expand`](Self::expand), each run checked against `limits` as a run of at most
    /// `max_steps` steps when given (`harness run --max-steps`, `harness check`).
    pub fn expand_within(
        &self,
        overrides: &[Override],
        limits: &crate::budget::Limits,
        max_steps: Option<usize>,
    ) -> Result<Vec<RunSpec>, Error> {
        self.expand_for(overrides, limits, max_steps, &Formulation::ALL)
    }

    /// As [`expand_within`](Self::expand_within) for a run of the formulations `fs` only
    /// (`--formulation`): the case of a formulation outside `fs` is parsed but neither validated
    /// ([`Case::validate_for`]) nor checked against the limits, so that its settings cannot
    /// refuse a run that does not use them.
    pub fn expand_for(
        &self,
        overrides: &[Override],
        limits: &crate::budget::Limits,
        max_steps: Option<usize>,
        fs: &[Formulation],
    ) -> Result<Vec<RunSpec>, Error> {
        self.expand_checked(overrides, fs, &|case, f| crate::budget::check_formulations(case, limits, max_steps, &[f]))
    }

    /// As [`expand_for`](Self::expand_for) for analysis `a`: each run is checked against
    /// `limits` with the analysis' estimate ([`crate::budget::check_analysis`]) instead of a time
    /// march's (a static or stability sweep never marches to `t_end`).
    pub fn expand_for_analysis(
        &self,
        overrides: &[Override],
        limits: &crate::budget::Limits,
        a: crate::budget::Analysis,
        fs: &[Formulation],
    ) -> Result<Vec<RunSpec>, Error> {
        self.expand_checked(overrides, fs, &|case, f| crate::budget::check_analysis(case, a, &[f], limits))
    }

    /// Expand the sweep and apply overrides; each point's case of a formulation in `fs` is
    /// validated for `fs` and then checked by `check(case, formulation)` (the budget), the others
    /// only parsed.
    fn expand_checked(
        &self,
        overrides: &[Override],
        fs: &[Formulation],
        check: &dyn Fn(&Case, Formulation) -> Result<(), String>,
    ) -> Result<Vec<RunSpec>, Error> {
        let file = self.path.display().to_string();
        let err = |msg: String| Error::Case { file: file.clone(), msg: clip(&msg) };
        // Global overrides first (they may change the sweep itself).
        let mut base = self.raw.clone();
        for o in overrides.iter().filter(|o| o.only.is_none()) {
            set_path(&mut base, &o.path, o.value.clone()).map_err(|e| err(e.to_string()))?;
        }
        let sweep: Vec<SweepAxis> = match base.get("sweep") {
            Some(v) => serde_json::from_value(v.clone()).map_err(|e| err(format!("sweep: {e}")))?,
            None => Vec::new(),
        };
        if let Value::Object(m) = &mut base {
            m.remove("sweep");
        }
        let mut n_points: usize = 1;
        for (k, axis) in sweep.iter().enumerate() {
            if axis.values.is_empty() {
                return Err(err(format!("sweep[{k}].values: empty list")));
            }
            // Two points of one name would write (and lock) one folder: an input error.
            let mut seen: std::collections::HashMap<String, usize> = Default::default();
            for (i, v) in axis.values.iter().enumerate() {
                if let Some(j) = seen.insert(sweep_label(v), i) {
                    return Err(err(format!(
                        "sweep[{k}].values: values {j} and {i} are both {} (duplicate sweep points; give each point once)",
                        sweep_label(v)
                    )));
                }
            }
            n_points = n_points.saturating_mul(axis.values.len());
            if n_points > crate::budget::MAX_SWEEP_POINTS {
                return Err(err(format!(
                    "sweep[{k}].values: the sweep expands into more than {} runs",
                    crate::budget::MAX_SWEEP_POINTS
                )));
            }
        }
        // Every point holds a copy of the case: bound their total size too.
        let size = serde_json::to_string(&base).map_or(0, |t| t.len());
        if n_points.saturating_mul(size) > crate::budget::MAX_SWEEP_BYTES {
            return Err(err(format!(
                "sweep: {n_points} runs of a {size}-byte case are more than {} bytes of cases",
                crate::budget::MAX_SWEEP_BYTES
            )));
        }
        let mut points: Vec<Vec<(String, Value)>> = vec![Vec::new()];
        for axis in &sweep {
            points = points
                .into_iter()
                .flat_map(|p| {
                    axis.values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.push((axis.path.clone(), v.clone()));
                        q
                    })
                })
                .collect();
        }
        let mut runs = Vec::new();
        let mut checked: std::collections::HashSet<String> = Default::default();
        for point in points {
            let mut raw = base.clone();
            let mut suffix = String::new();
            for (path, v) in &point {
                set_path(&mut raw, path, v.clone()).map_err(|e| err(format!("sweep: {e}")))?;
                let key = path.rsplit('.').next().unwrap_or(path);
                suffix.push_str(&format!("__{key}={}", sweep_label(v)));
            }
            let mut per = Vec::new();
            for f in Formulation::ALL {
                let mut r = raw.clone();
                for o in overrides.iter().filter(|o| o.only == Some(f)) {
                    set_path(&mut r, &o.path, o.value.clone()).map_err(|e| err(format!("{f}: {e}")))?;
                }
                let mut case = parse_case(&r).map_err(&err)?;
                case.name.push_str(&suffix);
                case.load_polars(&self.dir()).map_err(&err)?;
                if !fs.contains(&f) {
                    per.push(case);
                    continue;
                }
                case.validate_for(fs).map_err(&err)?;
                check(&case, f).map_err(&err)?;
                for (k, r) in case.references.iter().enumerate() {
                    if checked.contains(&r.file) {
                        continue;
                    }
                    check_reference(&self.dir(), &r.file).map_err(|e| err(format!("references[{k}].file: {e}")))?;
                    checked.insert(r.file.clone());
                }
                for (k, r) in case.statics.iter().flat_map(|s| s.references.iter()).enumerate() {
                    check_static_reference(&self.dir(), &r.file)
                        .map_err(|e| err(format!("static.references[{k}].file: {e}")))?;
                }
                per.push(case);
            }
            let gebf = per.pop().expect("two formulations");
            let ancf = per.pop().expect("two formulations");
            if let Some(same) = runs.iter().find(|r: &&RunSpec| r.name == ancf.name) {
                return Err(err(format!("sweep: two points give the run name {} (duplicate sweep points)", same.name)));
            }
            runs.push(RunSpec { name: ancf.name.clone(), dir: self.dir(), ancf, gebf });
        }
        Ok(runs)
    }
}

/// A sweep value as it appears in the run's name (`__key=label`).
fn sweep_label(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        // `[0,1,0]` → `0,1,0`: brackets are not among a name's characters.
        Value::Array(a) => a.iter().map(Value::to_string).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

/// Most airspeeds in one static sweep.
pub const MAX_STATIC_POINTS: usize = 10_000;

/// Shorten a message that echoes a long value: at most 400 characters, the cut marked.
pub fn clip(msg: &str) -> String {
    const MAX: usize = 400;
    if msg.chars().count() <= MAX {
        return msg.to_string();
    }
    let head: String = msg.chars().take(MAX).collect();
    format!("{head}… ({} characters in all)", msg.chars().count())
}

/// Largest reference file read, bytes.
pub const MAX_REFERENCE_BYTES: u64 = 64 << 20;

/// Check that reference `file` (relative to the case folder `dir`) is a readable regular file
/// of at most [`MAX_REFERENCE_BYTES`] inside `dir`, holding a curve; the message names the file.
pub fn check_reference(dir: &Path, file: &str) -> Result<(), String> {
    let full = checked_file(dir, file)?;
    // A file read once (same path, size and modification time) is not parsed again.
    type Key = (PathBuf, u64, Option<std::time::SystemTime>);
    static READ: std::sync::Mutex<Vec<Key>> = std::sync::Mutex::new(Vec::new());
    let meta = std::fs::metadata(&full).map_err(|e| format!("{}: {e}", full.display()))?;
    let key = (full.clone(), meta.len(), meta.modified().ok());
    if READ.lock().is_ok_and(|v| v.contains(&key)) {
        return Ok(());
    }
    crate::curve::read_curve(&full).map_err(|e| e.to_string())?;
    if let Ok(mut v) = READ.lock()
        && v.len() < 1024
    {
        v.push(key);
    }
    Ok(())
}

/// Check a static reference as [`check_reference`] does, holding an airspeed–angle curve.
pub fn check_static_reference(dir: &Path, file: &str) -> Result<(), String> {
    let full = checked_file(dir, file)?;
    crate::curve::read_xy(&full).map(|_| ()).map_err(|e| e.to_string())
}

/// `dir/file`, canonical, when it is a regular file of at most [`MAX_REFERENCE_BYTES`] under `dir`.
fn checked_file(dir: &Path, file: &str) -> Result<PathBuf, String> {
    let path = dir.join(file);
    let shown = path.display();
    let canon = |p: &Path| p.canonicalize().map_err(|e| format!("{}: {e}", p.display()));
    let base = canon(if dir.as_os_str().is_empty() { Path::new(".") } else { dir })?;
    let full = canon(&path)?;
    if !full.starts_with(&base) {
        return Err(format!("{shown}: not under the case file's folder {}", base.display()));
    }
    let meta = std::fs::metadata(&full).map_err(|e| format!("{shown}: {e}"))?;
    if !meta.is_file() {
        return Err(format!("{shown}: not a regular file"));
    }
    if meta.len() > MAX_REFERENCE_BYTES {
        return Err(format!("{shown}: {} bytes, more than the limit of {MAX_REFERENCE_BYTES}", meta.len()));
    }
    Ok(full)
}

/// Deserialize with the path of the offending field in the message.
pub fn parse_case(raw: &Value) -> Result<Case, String> {
    serde_path_to_error::deserialize(raw).map_err(|e| {
        let path = e.path().to_string();
        if path == "." { e.inner().to_string() } else { format!("{path}: {}", e.inner()) }
    })
}

/// One expanded run: the case as each formulation sees it (they differ only under
/// formulation-specific overrides).
#[derive(Debug, Clone)]
pub struct RunSpec {
    /// Run name (case name plus sweep suffix).
    pub name: String,
    /// Folder of the case file (references are relative to it).
    pub dir: PathBuf,
    /// The case for ANCF.
    pub ancf: Case,
    /// The case for GEBF.
    pub gebf: Case,
}

impl RunSpec {
    /// The case seen by formulation `f`.
    pub fn case(&self, f: Formulation) -> &Case {
        f.pick(&self.ancf, &self.gebf)
    }

    /// The case seen by formulation `f`, to change in place.
    pub fn case_mut(&mut self, f: Formulation) -> &mut Case {
        f.pick(&mut self.ancf, &mut self.gebf)
    }
}

/// The number of steps of `dt` in `t` when `t` is a whole multiple of it (within a relative
/// 1e-9) and at least one step.
pub fn whole_steps(t: f64, dt: f64) -> Option<usize> {
    let r = t / dt;
    let n = r.round();
    (r.is_finite() && n >= 1.0 && (r - n).abs() <= 1e-9 * r).then_some(n as usize)
}

/// The step nearest `dt` that divides `t` into a whole number (at least one) of steps: studies
/// that scale a case's step use it so that their runs still end at `t`.
pub fn commensurate_dt(t: f64, dt: f64) -> f64 {
    t / (t / dt).round().max(1.0)
}

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn norm3(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

impl Case {
    /// The settings of formulation `f`'s block (`ancf` or `gebf`).
    pub fn block(&self, f: Formulation) -> Block<'_> {
        aeroelastic::problem::blocks(f, &self.ancf, &self.gebf)
    }

    /// The settings of formulation `f`'s block, to change in place.
    pub fn block_mut(&mut self, f: Formulation) -> BlockMut<'_> {
        aeroelastic::problem::blocks_mut(f, &mut self.ancf, &mut self.gebf)
    }

    /// Index of the body called `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        aeroelastic::problem::body_index(&self.bodies, name)
    }

    /// Index of the joint whose fold angle is reported.
    pub fn fold_joint_index(&self) -> Option<usize> {
        aeroelastic::problem::fold_joint_index(&self.joints, self.fold_joint.as_deref())
    }

    /// Total length of all bodies, m.
    pub fn span(&self) -> f64 {
        self.bodies.iter().map(|b| b.length).sum()
    }

    /// The scene of formulation `f` ([`aeroelastic::Problem::scene`]).
    pub fn scene(&self, f: Formulation) -> ::scene::Scene {
        self.problem().scene(f)
    }
}

/// The JSON Schema of a case file, generated from these types.
#[cfg(feature = "schema")]
pub fn json_schema() -> Value {
    serde_json::to_value(schemars::schema_for!(Case)).unwrap_or(Value::Null)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn raw() -> Value {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/double_pendulum_c1_beta45.json");
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    }

    #[test]
    fn paper_case_parses_and_validates() {
        let c = parse_case(&raw()).unwrap();
        c.validate().unwrap();
        assert_eq!(c.fold_joint_index(), Some(1));
        assert_eq!(c.span(), 1.0);
    }

    #[test]
    fn override_syntax() {
        let o: Override = "gebf:joints.1.flare_deg=40".parse().unwrap();
        assert_eq!(o.only, Some(Formulation::Gebf));
        assert_eq!(o.value, json!(40));
        let o: Override = "ancf.path=ode".parse().unwrap();
        assert_eq!((o.only, o.value), (None, json!("ode")));
        assert!("nonsense".parse::<Override>().is_err());
        assert!("foo:x=1".parse::<Override>().is_err());
    }

    #[test]
    fn set_path_reports_missing_keys_and_indices() {
        let mut v = raw();
        set_path(&mut v, "joints.1.flare_deg", json!(10)).unwrap();
        assert_eq!(v["joints"][1]["flare_deg"], json!(10));
        assert!(set_path(&mut v, "joints.9.flare_deg", json!(1)).unwrap_err().to_string().contains("joints.9"));
        set_path(&mut v, "ancf.newton.rtol", json!(1e-6)).unwrap();
        assert_eq!(parse_case(&v).unwrap().ancf.newton.rtol, 1e-6);
        set_path(&mut v, "bodies.outer.length", json!(0.5)).unwrap();
        assert_eq!(v["bodies"][1]["length"], json!(0.5));
        let e = set_path(&mut v, "bodies.nose.length", json!(1)).unwrap_err().to_string();
        assert!(e.contains("bodies.nose") && e.contains("no element named"), "{e}");
        set_path(&mut v, "nope.x", json!(1)).unwrap();
        assert!(parse_case(&v).unwrap_err().contains("nope"));
    }

    #[test]
    fn sweep_expands_with_formulation_overrides() {
        let mut v = raw();
        v["sweep"] = json!([{"path": "stiffness_scale", "values": [1, 0.1]}, {"path": "joints.1.flare_deg", "values": [0, 45, 90]}]);
        let cf = CaseFile { path: Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/x.json"), raw: v };
        let ov: Override = "gebf:t_end=1".parse().unwrap();
        let runs = cf.expand(&[ov]).unwrap();
        assert_eq!(runs.len(), 6);
        assert_eq!(runs[1].name, "double_pendulum_c1_beta45__stiffness_scale=1__flare_deg=45");
        assert_eq!(runs[5].ancf.stiffness_scale, 0.1);
        assert_eq!((runs[0].ancf.t_end, runs[0].gebf.t_end), (2.0, 1.0));
    }

    /// Issue 38: `"values": [1, 1]` expanded into two runs of one name, and `harness run` then
    /// waited for ever on the folder lock the first of them held. Duplicate points (also `1`
    /// and `"1"`, which name a run alike) are an input error naming the axis.
    #[test]
    fn duplicate_sweep_points_are_an_input_error_issue_38() {
        for values in [json!([1, 1]), json!([0.5, 1, "1"])] {
            let mut v = raw();
            v["sweep"] = json!([{"path": "t_end", "values": [1, 2]}, {"path": "stiffness_scale", "values": values}]);
            let cf = CaseFile { path: Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/x.json"), raw: v };
            let e = cf.expand(&[]).unwrap_err().to_string();
            assert!(e.contains("sweep[1].values") && e.contains("duplicate"), "{e}");
        }
    }

    #[test]
    fn validation_names_fields() {
        let cases: [(&str, Value, &str); 6] = [
            ("bodies.0.length", json!(-1.0), "bodies[0].length"),
            ("joints.0.body", json!("ghost"), "joints[0].body"),
            ("joints.1.flare_deg", json!(120.0), "joints[1].flare_deg"),
            ("ancf.dt", json!(0.0), "ancf.dt"),
            ("gebf.rho_inf", json!(1.5), "gebf.rho_inf"),
            ("bodies.1.y_axis", json!([1.0, 0.0, 0.0]), "bodies[1].y_axis"),
        ];
        for (path, value, needle) in cases {
            let mut v = raw();
            set_path(&mut v, path, value).unwrap();
            let c = parse_case(&v).unwrap();
            let e = c.validate().unwrap_err();
            assert!(e.contains(needle), "{path}: {e}");
        }
        // The Chung–Hulbert form with aerodynamics.
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/wing_aoa5.json");
        let mut v: Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        set_path(&mut v, "gebf.form", json!("chung_hulbert")).unwrap();
        let e = parse_case(&v).unwrap().validate().unwrap_err();
        assert!(e.contains("gebf.form"), "{e}");
        // Non-finite numbers cannot even be written in JSON; a string where a number belongs:
        let mut v = raw();
        set_path(&mut v, "bodies.0.section.mass", json!("NaN")).unwrap();
        assert!(parse_case(&v).unwrap_err().contains("bodies[0].section.mass"));
    }

    /// `run CASE --formulation ancf` refused the case over GEBF's `dt` (issue 33, item 9): a
    /// run validates only the settings of the formulations it runs.
    #[test]
    fn a_run_of_one_formulation_ignores_the_others_settings_issue_33() {
        let cf = CaseFile { path: Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/x.json"), raw: raw() };
        let limits = crate::budget::limits();
        // 2 s is not a whole number of GEBF steps of 0.0003 s, and the step is no positive number.
        for value in ["0.0003", "-1"] {
            let ov: Override = format!("gebf:gebf.dt={value}").parse().unwrap();
            let both = cf.expand_within(std::slice::from_ref(&ov), &limits, None).unwrap_err().to_string();
            assert!(both.contains("gebf.dt"), "{both}");
            let ancf = cf.expand_for(std::slice::from_ref(&ov), &limits, None, &[Formulation::Ancf]).unwrap();
            assert_eq!(ancf[0].ancf.gebf.dt, 0.002, "the ANCF run's case keeps the file's GEBF step");
            let e = cf.expand_for(&[ov], &limits, None, &[Formulation::Gebf]).unwrap_err().to_string();
            assert!(e.contains("gebf.dt"), "{e}");
        }
        // The same with the settings in the file itself, and with a run of ANCF alone refused
        // over ANCF's own.
        let mut v = raw();
        set_path(&mut v, "gebf.newton.max_iter", json!(10_000)).unwrap();
        let c = parse_case(&v).unwrap();
        assert!(c.validate().unwrap_err().contains("gebf.newton.max_iter"));
        c.validate_for(&[Formulation::Ancf]).unwrap();
        set_path(&mut v, "ancf.rho_inf", json!(2.0)).unwrap();
        let e = parse_case(&v).unwrap().validate_for(&[Formulation::Ancf]).unwrap_err();
        assert!(e.starts_with("ancf.rho_inf"), "{e}");
    }

    /// A start from the trim (and stability about it) holds the free body, which changes the
    /// coordinates of ANCF's ODE path: refused naming `ancf.path` when ANCF runs, and only then.
    #[test]
    fn a_trim_start_refuses_ancfs_ode_path_only_when_ancf_runs() {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/horten_flying_wing.json");
        let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
        set_path(&mut v, "initial", json!("trim")).unwrap();
        parse_case(&v).unwrap().validate().unwrap();
        set_path(&mut v, "ancf.path", json!("ode")).unwrap();
        let c = parse_case(&v).unwrap();
        let e = c.validate().unwrap_err();
        assert!(e.starts_with("initial") && e.contains("ancf.path \"dae\""), "{e}");
        c.validate_for(&[Formulation::Gebf]).unwrap();
    }
}
