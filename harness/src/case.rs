//! Case files: the scene (bodies, joints, gravity), solver settings per formulation, external
//! references and gate tolerances. JSON deserialises straight into these types; unknown fields
//! are errors, and [`Case::validate`] names the offending field of every impossible value.

use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::Error;

mod validate;

fn one() -> f64 {
    1.0
}
fn default_rho_inf() -> f64 {
    0.8
}
fn default_x_axis() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
fn default_y_axis() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// One simulation scene, run with both formulations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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
    pub aero: Option<crate::aero::AeroSettings>,
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
    pub vtk: Option<crate::vtk::VtkOutput>,
    /// Parameter sweep: each entry maps a `--set`-style path (e.g. `stiffness_scale`,
    /// `joints.1.flare_deg`, `ancf.dt`) to a list of values; the Cartesian product expands into
    /// named runs `<name>__<key>=<value>…`.
    #[serde(default)]
    pub sweep: Vec<SweepAxis>,
    /// Static aeroelastic equilibria (`harness static`): the airspeeds of the sweep and the
    /// experiment or model curves to compare with. Needs `aero`.
    #[serde(default, rename = "static", skip_serializing_if = "Option::is_none")]
    pub statics: Option<StaticSettings>,
    /// Linearised stability (`harness stability`): airspeeds, modes to track, the state to
    /// linearise about. Needs `aero`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stability: Option<crate::stability::StabilitySettings>,
    /// Gust sweep (`harness gust`): the gradients (or gust frequencies) of the case's 1-cos
    /// `aero.gust` and the hinge states to fly through them (docs/gust.md). Needs `aero.gust`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gust: Option<crate::gust::GustSweep>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// The static aeroelastic sweep of a case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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
    /// (m/s) and fold angle (degrees), relative to the case file's folder.
    #[serde(default)]
    pub references: Vec<StaticReference>,
    /// The steady wake of the static solution: `rows` straight rows of `row_length` (m) along
    /// the free stream behind the trailing edge, without closure a finite frozen wake (each
    /// strip's wake one ring of length `rows·row_length` carrying its trailing-edge circulation,
    /// the steady state of a time march with `aero.n_wake_rows` rows of `airspeed·dt`), with
    /// `closure` the semi-infinite legs. Default (absent): semi-infinite legs along the free
    /// stream. Needs `aero`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wake: Option<crate::stability::WakeSettings>,
}

impl StaticSettings {
    /// An aeroelastic sweep over `airspeeds` with the steady wake `wake` (semi-infinite legs
    /// when `None`), no references.
    pub fn at(airspeeds: Vec<f64>, wake: Option<crate::stability::WakeSettings>) -> Self {
        Self { airspeeds, references: Vec::new(), point_loads: Vec::new(), load_factors: Vec::new(), wake }
    }
}

impl crate::stability::WakeSettings {
    /// Every impossible value, naming its field under `prefix` (e.g. `static.wake`).
    ///
    /// # Errors
    /// A message naming the field.
    pub fn validate(&self, prefix: &str) -> Result<(), String> {
        if !(self.row_length.is_finite() && self.row_length > 0.0 && self.row_length <= 1e6) {
            return Err(format!("{prefix}.row_length: {} is not in (0, 1e6] m", self.row_length));
        }
        if self.rows == 0 || self.rows > 4000 {
            return Err(format!("{prefix}.rows: {} is not in 1..=4000", self.rows));
        }
        Ok(())
    }

    /// The steady UVLM wake of these settings: the rows' total length without closure, the
    /// semi-infinite legs with it.
    pub fn steady_wake(&self) -> uvlm::SteadyWake {
        if self.closure {
            uvlm::SteadyWake::SemiInfinite
        } else {
            uvlm::SteadyWake::Finite { length: self.rows as f64 * self.row_length }
        }
    }
}

/// A dead point load of a structural static case (`static.point_loads`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StaticPointLoad {
    /// Body name.
    pub body: String,
    /// Arclength of the loaded section from the body's start, m, in [0, length]. Default: the
    /// body's end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<f64>,
    /// Force, N, global components (held fixed: a dead load).
    pub force: [f64; 3],
    /// Moment, N·m, global components. Default zero.
    #[serde(default)]
    pub moment: [f64; 3],
}

/// A curve of equilibrium fold (coast) angle against airspeed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepAxis {
    /// Dotted path into the case (as for `--set`).
    pub path: String,
    /// Values to take.
    pub values: Vec<Value>,
}

/// A straight beam body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Name joints refer to.
    pub name: String,
    /// Start point, m (global).
    pub start: [f64; 3],
    /// Length, m.
    pub length: f64,
    /// Beam axis (section x) in global coordinates; normalised. Default +X.
    #[serde(default = "default_x_axis")]
    pub x_axis: [f64; 3],
    /// Section y axis in global coordinates; must be perpendicular to `x_axis`. Default +Y.
    #[serde(default = "default_y_axis")]
    pub y_axis: [f64; 3],
    /// Section properties per unit length.
    pub section: Section,
    /// Point masses fixed to the body's sections (default none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub point_masses: Vec<PointMass>,
}

/// A rigid point mass fixed to a body's section.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointMass {
    /// Arclength of the section it is fixed to, from the body's start, m.
    pub at: f64,
    /// Its centre relative to the section's axis point, `[x, y, z]` in the section frame, m
    /// (default `[0, 0, 0]`).
    #[serde(default)]
    pub offset: [f64; 3],
    /// Mass, kg.
    pub mass: f64,
    /// Principal inertias about its own centre along the section axes `[I_xx, I_yy, I_zz]`,
    /// kg·m² (default `[0, 0, 0]`).
    #[serde(default)]
    pub inertia: [f64; 3],
}

/// A rotational spring and damper about a hinge's axis: the moment `−k (θ − θ₀) − c θ̇`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Spring {
    /// Stiffness k, N·m/rad (default 0).
    pub stiffness: f64,
    /// Damping c, N·m·s/rad (default 0).
    pub damping: f64,
    /// Rest angle θ₀, degrees, from the reference configuration (default 0).
    pub rest_deg: f64,
}

/// Cross-section data per unit length (SI). The shear centre lies on the beam axis; the centre of
/// mass may be offset by `cg_offset`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Section {
    /// Mass per length m = ρA, kg/m.
    pub mass: f64,
    /// Torsional mass moment of inertia per length ρI_xx, kg·m.
    pub rho_ixx: f64,
    /// ρI_yy, kg·m.
    pub rho_iyy: f64,
    /// ρI_zz, kg·m.
    pub rho_izz: f64,
    /// Axial stiffness EA, N.
    pub ea: f64,
    /// Shear stiffness GA_y, N.
    pub ga_y: f64,
    /// Shear stiffness GA_z, N.
    pub ga_z: f64,
    /// Torsional stiffness GJ, N·m².
    pub gj: f64,
    /// Bending stiffness EI_yy, N·m².
    pub ei_yy: f64,
    /// Bending stiffness EI_zz, N·m².
    pub ei_zz: f64,
    /// Centre of mass in the section plane, `[y, z]` in the section frame, m (default `[0, 0]`).
    /// The rotary inertias are about it.
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub cg_offset: [f64; 2],
}

fn is_zero2(v: &[f64; 2]) -> bool {
    *v == [0.0; 2]
}

/// A joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Joint {
    /// The body's start point pinned to ground; rotation only about a fixed global axis.
    GroundHinge {
        /// Optional joint name.
        #[serde(default)]
        name: Option<String>,
        /// Body name.
        body: String,
        /// Hinge axis, global (normalised).
        axis: [f64; 3],
        /// Rotational spring and damper about the axis (default none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        spring: Option<Spring>,
    },
    /// Flared hinge from the end of `parent` to the start of `child`, axis
    /// a = sin β·x + cos β·y in the parent's end section frame.
    FlaredHinge {
        /// Optional joint name.
        #[serde(default)]
        name: Option<String>,
        /// Parent body name.
        parent: String,
        /// Child body name.
        child: String,
        /// Flare angle β, degrees, in [−90, 90].
        flare_deg: f64,
        /// Lock the hinge at its reference fold (the child welded to the parent's end section):
        /// used for the rigid-wing check. Default false.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        locked: bool,
        /// Rotational spring and damper about the hinge axis, on the fold angle (default none;
        /// inactive while the hinge is `locked`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        spring: Option<Spring>,
    },
    /// The body's start section clamped to ground.
    Clamp {
        /// Optional joint name.
        #[serde(default)]
        name: Option<String>,
        /// Body name.
        body: String,
    },
}

impl Joint {
    /// The joint's name, if any.
    pub fn name(&self) -> Option<&str> {
        match self {
            Joint::GroundHinge { name, .. } | Joint::FlaredHinge { name, .. } | Joint::Clamp { name, .. } => {
                name.as_deref()
            }
        }
    }
}

/// Newton settings (defaults as genalpha's, except `predictor`: see its field).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSettings {
    /// Maximum iterations per step.
    pub max_iter: usize,
    /// Relative increment tolerance.
    pub rtol: f64,
    /// Absolute increment tolerance (m).
    pub atol: f64,
    /// Holonomic constraint tolerance.
    pub phi_tol: f64,
    /// Velocity constraint tolerance (m/s).
    pub psi_tol: f64,
    /// Reuse factorisations while Newton contracts fast.
    pub reuse_factorization: bool,
    /// Stop Newton when the RADAU5-style convergence estimate θ/(1−θ)·|Δ| is below tolerance
    /// (saves an iteration per step).
    pub estimate_convergence: bool,
    /// Broyden rank-one corrections of the steps made with a reused factorisation.
    pub broyden: bool,
    /// Retry a failed step as two half steps, at most this deep.
    pub max_step_halvings: usize,
    /// Local error control: halve a converged step whose error estimate
    /// h²|β − 1/6|·max|Δa| (m; rotations weighted by the body length) exceeds this, within
    /// `max_step_halvings`. 0 = off (default).
    pub local_error_tol: f64,
    /// Newton's starting point in each step. Default: `extrapolated_acceleration` for GEBF
    /// (its floating frames' gyroscopic terms make Newton sensitive to the predicted
    /// velocities), `constant_acceleration` for ANCF.
    pub predictor: Option<PredictorSetting>,
}

/// Where the generalized-α step enforces the equations of motion (the constraints are
/// enforced at the end of the step in both).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FormSetting {
    /// At the end of the step (Arnold & Brüls 2007); the trapezoidal rule at rho_inf = 1.
    #[default]
    ArnoldBruls,
    /// At the α-weighted state inside the step (Chung & Hulbert 1993); the implicit midpoint
    /// rule at rho_inf = 1, whose gyroscopic terms do no discrete work.
    ChungHulbert,
}

impl FormSetting {
    /// The name in case files.
    pub fn as_str(self) -> &'static str {
        match self {
            FormSetting::ArnoldBruls => "arnold_bruls",
            FormSetting::ChungHulbert => "chung_hulbert",
        }
    }

    /// The name in tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            FormSetting::ArnoldBruls => "Arnold–Brüls",
            FormSetting::ChungHulbert => "Chung–Hulbert",
        }
    }

    /// The genalpha form.
    pub fn to_form(self) -> genalpha::Form {
        match self {
            FormSetting::ArnoldBruls => genalpha::Form::ArnoldBruls,
            FormSetting::ChungHulbert => genalpha::Form::ChungHulbert,
        }
    }
}

/// Newton's starting point in each step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PredictorSetting {
    /// The acceleration of the last step.
    ConstantAcceleration,
    /// The acceleration extrapolated linearly from the last two steps.
    ExtrapolatedAcceleration,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        let d = genalpha::NewtonParams::default();
        Self {
            max_iter: d.max_iter,
            rtol: d.rtol,
            atol: d.atol,
            phi_tol: d.phi_tol,
            psi_tol: d.psi_tol,
            reuse_factorization: d.reuse_factorization,
            estimate_convergence: d.estimate_convergence,
            broyden: d.broyden,
            max_step_halvings: d.max_step_halvings,
            local_error_tol: d.local_error_tol,
            predictor: None,
        }
    }
}

impl NewtonSettings {
    /// As genalpha parameters, with `default_predictor` where the case sets none.
    pub fn to_params(self, default_predictor: genalpha::Predictor) -> genalpha::NewtonParams {
        genalpha::NewtonParams {
            predictor: match self.predictor {
                None => default_predictor,
                Some(PredictorSetting::ConstantAcceleration) => genalpha::Predictor::ConstantAcceleration,
                Some(PredictorSetting::ExtrapolatedAcceleration) => genalpha::Predictor::ExtrapolatedAcceleration,
            },
            max_iter: self.max_iter,
            rtol: self.rtol,
            atol: self.atol,
            phi_tol: self.phi_tol,
            psi_tol: self.psi_tol,
            reuse_factorization: self.reuse_factorization,
            estimate_convergence: self.estimate_convergence,
            broyden: self.broyden,
            max_step_halvings: self.max_step_halvings,
            local_error_tol: self.local_error_tol,
            ..Default::default()
        }
    }
}

/// Elements per body: one number for every body, or a list in body order.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum Elements {
    /// The same count for every body.
    Uniform(usize),
    /// One count per body, in body order.
    PerBody(Vec<usize>),
}

impl Elements {
    /// Count for body `i` (the last entry repeats if the list is short; validation rejects that).
    pub fn for_body(&self, i: usize) -> usize {
        match self {
            Elements::Uniform(n) => *n,
            Elements::PerBody(v) => v.get(i).or(v.last()).copied().unwrap_or(0),
        }
    }
    /// Every count multiplied by `k` (rounded, at least 1).
    pub fn scaled(&self, k: f64) -> Elements {
        let f = |n: usize| ((n as f64 * k).round() as usize).max(1);
        match self {
            Elements::Uniform(n) => Elements::Uniform(f(*n)),
            Elements::PerBody(v) => Elements::PerBody(v.iter().map(|&n| f(n)).collect()),
        }
    }
    fn check(&self, field: &str, n_bodies: usize) -> Result<(), String> {
        match self {
            Elements::Uniform(0) => Err(format!("{field}: must be at least 1")),
            Elements::Uniform(_) => Ok(()),
            Elements::PerBody(v) if v.len() != n_bodies => {
                Err(format!("{field}: {} entries for {n_bodies} bodies", v.len()))
            }
            Elements::PerBody(v) => match v.iter().position(|&n| n == 0) {
                Some(i) => Err(format!("{field}[{i}]: must be at least 1")),
                None => Ok(()),
            },
        }
    }
}

impl std::fmt::Display for Elements {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Elements::Uniform(n) => write!(f, "{n}"),
            Elements::PerBody(v) => {
                let s: Vec<String> = v.iter().map(|n| n.to_string()).collect();
                write!(f, "{}", s.join("+"))
            }
        }
    }
}

/// ANCF solve path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AncfPath {
    /// Index-3 DAE with Lagrange multipliers.
    #[default]
    Dae,
    /// Constraints eliminated with the constant velocity transformation B (paper eq. 6–7).
    Ode,
}

/// ANCF settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AncfSettings {
    /// Two-node elements per body (a number, or a list in body order).
    pub elements_per_body: Elements,
    /// Time step, s.
    pub dt: f64,
    /// Spectral radius at infinite frequency. Default 0.8.
    #[serde(default = "default_rho_inf")]
    pub rho_inf: f64,
    /// DAE (default) or ODE path.
    #[serde(default)]
    pub path: AncfPath,
    /// Where the generalized-α step enforces the equations of motion. Default `arnold_bruls`;
    /// `chung_hulbert` is not available with aerodynamics.
    #[serde(default)]
    pub form: FormSetting,
    /// Newton settings.
    #[serde(default)]
    pub newton: NewtonSettings,
}

/// GEBF settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GebfSettings {
    /// Three-node elements per body (a number, or a list in body order).
    pub elements_per_body: Elements,
    /// Time step, s.
    pub dt: f64,
    /// Spectral radius at infinite frequency. Default 0.8.
    #[serde(default = "default_rho_inf")]
    pub rho_inf: f64,
    /// Position-level projection of the joints after each step. Default off.
    #[serde(default)]
    pub stabilization: bool,
    /// Where the generalized-α step enforces the equations of motion. Default `arnold_bruls`;
    /// `chung_hulbert` keeps the floating frames' gyroscopic forces from doing discrete work
    /// (at rho_inf = 1, the implicit midpoint rule): use it for energy studies. Not available
    /// with aerodynamics (the coupled step holds the loads of the step's end).
    #[serde(default)]
    pub form: FormSetting,
    /// Newton settings.
    #[serde(default)]
    pub newton: NewtonSettings,
}

/// An external reference curve (CSV with a header; `#` lines are comments).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
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

/// The two structural formulations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Absolute nodal coordinates.
    Ancf,
    /// Geometrically exact beam on floating frames.
    Gebf,
}

impl Formulation {
    /// Both, in report order.
    pub const ALL: [Formulation; 2] = [Formulation::Ancf, Formulation::Gebf];
    /// Lower-case name used in file names.
    pub fn as_str(self) -> &'static str {
        match self {
            Formulation::Ancf => "ancf",
            Formulation::Gebf => "gebf",
        }
    }
}

impl std::fmt::Display for Formulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
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
            Some(("ancf", p)) => (Some(Formulation::Ancf), p),
            Some(("gebf", p)) => (Some(Formulation::Gebf), p),
            Some(_) => return Err(bad()),
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
/// its last key in an object.
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
                let idx: usize =
                    key.parse().map_err(|_| Error::Override(format!("`{here}`: `{key}` is not an array index")))?;
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
    crate::csv::read_curve(&full).map_err(|e| e.to_string())?;
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
    crate::statics::read_xy(&full).map(|_| ()).map_err(|e| e.to_string())
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

/// Parse JSON text into a [`Value`], refusing a key repeated within one object anywhere in the
/// document (`bodies[0]: duplicate key "length"`).
pub fn parse_unique_keys(text: &str) -> Result<Value, serde_json::Error> {
    use serde::de::DeserializeSeed;
    let mut de = serde_json::Deserializer::from_str(text);
    let v = UniqueKeys(String::new()).deserialize(&mut de)?;
    de.end()?;
    Ok(v)
}

/// Builds a [`Value`] like serde_json's own deserializer but errors on a repeated object key.
/// Hand-written because serde_json silently keeps the last of repeated keys and has no option to
/// refuse them (and `Value`'s own `Deserialize` builds its map the same way). The field is the
/// path of the value being read, in the messages' `bodies[0].section` style.
struct UniqueKeys(String);

impl<'de> serde::de::DeserializeSeed<'de> for UniqueKeys {
    type Value = Value;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for UniqueKeys {
    type Value = Value;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_some<D: serde::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        serde::de::DeserializeSeed::deserialize(self, d)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut v = Vec::new();
        while let Some(x) = seq.next_element_seed(UniqueKeys(format!("{}[{}]", self.0, v.len())))? {
            v.push(x);
        }
        Ok(Value::Array(v))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut m = serde_json::Map::new();
        while let Some(k) = map.next_key::<String>()? {
            if m.contains_key(&k) {
                let at = if self.0.is_empty() { String::new() } else { format!("{}: ", self.0) };
                return Err(serde::de::Error::custom(format!("{at}duplicate key \"{k}\"")));
            }
            let path = if self.0.is_empty() { k.clone() } else { format!("{}.{k}", self.0) };
            let v = map.next_value_seed(UniqueKeys(path))?;
            m.insert(k, v);
        }
        Ok(Value::Object(m))
    }
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
        match f {
            Formulation::Ancf => &self.ancf,
            Formulation::Gebf => &self.gebf,
        }
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
    /// Index of the body called `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Index of the joint whose fold angle is reported.
    pub fn fold_joint_index(&self) -> Option<usize> {
        match &self.fold_joint {
            Some(n) => self.joints.iter().position(|j| j.name() == Some(n.as_str())),
            None => self.joints.iter().position(|j| matches!(j, Joint::FlaredHinge { .. })),
        }
    }

    /// Total length of all bodies, m.
    pub fn span(&self) -> f64 {
        self.bodies.iter().map(|b| b.length).sum()
    }

    /// The scene of formulation `f`: bodies (stiffnesses scaled by `stiffness_scale`, element
    /// counts of `f`), joints, hinge springs as force elements, gravity. Body names that do not
    /// resolve become an index past the last body, which [`scene::Scene::validate`] rejects.
    pub fn scene(&self, f: Formulation) -> scene::Scene {
        let n_el = match f {
            Formulation::Ancf => &self.ancf.elements_per_body,
            Formulation::Gebf => &self.gebf.elements_per_body,
        };
        let unit = |v: [f64; 3]| nalgebra::Vector3::from(v).normalize();
        // Nose-up pitch: a rotation about +X takes +Y (the leading edge) towards +Z.
        let pitch = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), self.pitch_deg.to_radians());
        let bodies = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (x, y) = (pitch * unit(b.x_axis), pitch * unit(b.y_axis));
                let s = &b.section;
                let section = scene::Section {
                    cg_offset: s.cg_offset,
                    ..scene::Section::centred(
                        s.mass, s.rho_ixx, s.rho_iyy, s.rho_izz, s.ea, s.ga_y, s.ga_z, s.gj, s.ei_yy, s.ei_zz,
                    )
                };
                scene::BodySpec {
                    name: b.name.clone(),
                    start: pitch * nalgebra::Vector3::from(b.start),
                    length: b.length,
                    frame: nalgebra::Matrix3::from_columns(&[x, y, x.cross(&y)]),
                    section: section.with_stiffness_scale(self.stiffness_scale),
                    n_elements: n_el.for_body(i),
                    point_masses: b
                        .point_masses
                        .iter()
                        .map(|p| scene::PointMass {
                            at: p.at,
                            offset: p.offset.into(),
                            mass: p.mass,
                            inertia: p.inertia.into(),
                        })
                        .collect(),
                }
            })
            .collect();
        let idx = |n: &str| self.body_index(n).unwrap_or(usize::MAX);
        let joints = self
            .joints
            .iter()
            .map(|j| match j {
                Joint::GroundHinge { body, axis, .. } => {
                    // Normalised here as the case promises (a zero axis stays zero for the
                    // scene's validation to name).
                    let a = nalgebra::Vector3::from(*axis);
                    let axis = if a.norm() > 0.0 { a.normalize() } else { a };
                    scene::JointSpec::GroundHinge { body: idx(body), axis }
                }
                Joint::FlaredHinge { parent, child, flare_deg, locked, .. } => {
                    let (parent, child, beta) = (idx(parent), idx(child), flare_deg.to_radians());
                    if *locked {
                        scene::JointSpec::LockedHinge { parent, child, beta }
                    } else {
                        scene::JointSpec::FlaredHinge { parent, child, beta }
                    }
                }
                Joint::Clamp { body, .. } => scene::JointSpec::Clamp { body: idx(body) },
            })
            .collect();
        let forces = self
            .joints
            .iter()
            .enumerate()
            .filter_map(|(joint, j)| match j {
                // A locked hinge carries no spring: locking a sprung hinge (`--set
                // joints.<i>.locked=true`) welds it and its spring does nothing.
                Joint::FlaredHinge { locked: true, .. } => None,
                Joint::GroundHinge { spring, .. } | Joint::FlaredHinge { spring, .. } => {
                    spring.map(|s| scene::ForceElement::HingeSpring {
                        joint,
                        stiffness: s.stiffness,
                        damping: s.damping,
                        rest: s.rest_deg.to_radians(),
                    })
                }
                Joint::Clamp { .. } => None,
            })
            .collect();
        let gravity = self.gravity.map(nalgebra::Vector3::from).unwrap_or_else(nalgebra::Vector3::zeros);
        scene::Scene { bodies, joints, forces, gravity }
    }
}

/// The JSON Schema of a case file, generated from these types.
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
}
