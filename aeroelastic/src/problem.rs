//! The typed description of an aeroelastic problem: the structure (bodies, sections, point
//! masses, joints with their springs, gravity, root pitch), each formulation's discretisation and
//! integrator settings, and the optional aerodynamic, static, stability and gust settings. Every
//! analysis of this crate takes a [`Problem`] (or parts of it) and a formulation; a front end
//! (the harness's case file) builds one. [`Problem::scene`] maps it onto the [`scene::Scene`]
//! both formulations build their models from.

use nalgebra::Vector3;

use crate::aero_settings::AeroSettings;
use crate::gust_settings::GustSweep;
use crate::stability_settings::{StabilitySettings, WakeSettings};

#[cfg(feature = "serde")]
fn default_rho_inf() -> f64 {
    0.8
}
#[cfg(feature = "serde")]
fn default_x_axis() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}
#[cfg(feature = "serde")]
fn default_y_axis() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// One problem: a structure, its discretisation per formulation and what acts on it.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Name (of the run).
    pub name: String,
    /// Bodies.
    pub bodies: Vec<Body>,
    /// Joints.
    pub joints: Vec<Joint>,
    /// Gravity, m/s² (global); none: zero.
    pub gravity: Option<[f64; 3]>,
    /// Nose-up root pitch of the whole structure about +X, degrees.
    pub pitch_deg: f64,
    /// Factor on every stiffness of every section.
    pub stiffness_scale: f64,
    /// End time of a time march, s.
    pub t_end: f64,
    /// Output interval of a time march, s (none: every step).
    pub output_dt: Option<f64>,
    /// Name of the joint whose fold angle is reported (none: the first flared hinge).
    pub fold_joint: Option<String>,
    /// Name of the ground hinge whose rate is the `roll_rate` column (none: no column).
    pub roll_joint: Option<String>,
    /// Name of the joint (a flared hinge or a clamp) at which the root loads are measured: the
    /// free body of its child (or clamped body) and everything outboard of it (none: the first
    /// clamp).
    pub root_joint: Option<String>,
    /// Hinge events of the time march: hinges locked or released at given times.
    pub events: Vec<crate::events::HingeEvent>,
    /// Thrusts: follower forces on bodies (`thrust`).
    pub thrust: Vec<crate::thrust::Thrust>,
    /// The level-flight trim (`trim`; none: the case cannot be trimmed).
    pub trim: Option<crate::trim::TrimSettings>,
    /// Where a time march starts: the reference configuration, or the trimmed state.
    pub initial: crate::trim::Initial,
    /// ANCF's discretisation and integrator settings.
    pub ancf: AncfSettings,
    /// GEBF's discretisation and integrator settings.
    pub gebf: GebfSettings,
    /// Aerodynamics (none: in vacuo).
    pub aero: Option<AeroSettings>,
    /// The static sweep.
    pub statics: Option<StaticSettings>,
    /// The stability sweep.
    pub stability: Option<StabilitySettings>,
    /// The gust sweep.
    pub gust: Option<GustSweep>,
    /// The section polars of `aero.polars`, loaded (none: the lattice's loads uncorrected).
    pub polars: Vec<crate::section_polars::BodyPolar>,
}

/// The static sweep of a problem: airspeeds with aerodynamics, or dead point loads scaled by
/// load factors without.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StaticSettings {
    /// Airspeeds of the sweep, m/s.
    pub airspeeds: Vec<f64>,
    /// Dead point loads of a structural static problem.
    pub point_loads: Vec<StaticPointLoad>,
    /// Load factors of a structural static problem (increasing).
    pub load_factors: Vec<f64>,
    /// The steady wake of the static solution (none: semi-infinite legs along the free stream).
    pub wake: Option<WakeSettings>,
    /// Sideslip angles of a sideslip sweep, degrees (at the one airspeed of `airspeeds`); empty:
    /// the sweep is over `airspeeds` at the aerodynamic settings' own sideslip.
    pub sideslips_deg: Vec<f64>,
    /// Take the lattice's aerodynamic stiffness by forward differences of steady solves instead
    /// of its analytic load derivative (docs/statics.md §2; for comparison, not a case field).
    pub difference_tangent: bool,
}

impl StaticSettings {
    /// An aeroelastic sweep over `airspeeds` with the steady wake `wake` (semi-infinite legs
    /// when `None`).
    pub fn at(airspeeds: Vec<f64>, wake: Option<WakeSettings>) -> Self {
        Self {
            airspeeds,
            point_loads: Vec::new(),
            load_factors: Vec::new(),
            wake,
            sideslips_deg: Vec::new(),
            difference_tangent: false,
        }
    }

    /// The points of the sweep in the case's order, `(airspeed m/s, sideslip degrees)`: each
    /// airspeed at the sideslip `sideslip_deg` of the aerodynamic settings, or each of
    /// `sideslips_deg` at the first airspeed.
    pub fn points(&self, sideslip_deg: f64) -> Vec<(f64, f64)> {
        if self.sideslips_deg.is_empty() {
            self.airspeeds.iter().map(|&u| (u, sideslip_deg)).collect()
        } else {
            let u = self.airspeeds.first().copied().unwrap_or(f64::NAN);
            self.sideslips_deg.iter().map(|&b| (u, b)).collect()
        }
    }

    /// Whether the sweep is over sideslip (`sideslips_deg`) rather than airspeed.
    pub fn is_sideslip_sweep(&self) -> bool {
        !self.sideslips_deg.is_empty()
    }
}

/// A dead point load of a structural static case (`static.point_loads`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct StaticPointLoad {
    /// Body name.
    pub body: String,
    /// Arclength of the loaded section from the body's start, m, in [0, length]. Default: the
    /// body's end.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub at: Option<f64>,
    /// Force, N, global components (held fixed: a dead load).
    pub force: [f64; 3],
    /// Moment, N·m, global components. Default zero.
    #[cfg_attr(feature = "serde", serde(default))]
    pub moment: [f64; 3],
}

/// Index of the body called `name` in `bodies`.
pub fn body_index(bodies: &[Body], name: &str) -> Option<usize> {
    bodies.iter().position(|b| b.name == name)
}

/// Index of the joint whose fold angle is reported: the joint called `fold_joint`, or the first
/// flared hinge.
pub fn fold_joint_index(joints: &[Joint], fold_joint: Option<&str>) -> Option<usize> {
    match fold_joint {
        Some(n) => joints.iter().position(|j| j.name() == Some(n)),
        None => joints.iter().position(|j| matches!(j, Joint::FlaredHinge { .. })),
    }
}

/// A straight beam body.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Body {
    /// Name joints refer to.
    pub name: String,
    /// Start point, m (global). Default: the end of its parent (the body a flared hinge hangs
    /// it from), or the origin for a body without one.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub start: Option<[f64; 3]>,
    /// Length, m.
    pub length: f64,
    /// Beam axis (section x) in global coordinates; normalised. Default +X.
    #[cfg_attr(feature = "serde", serde(default = "default_x_axis"))]
    pub x_axis: [f64; 3],
    /// Section y axis in global coordinates; must be perpendicular to `x_axis`. Default +Y.
    #[cfg_attr(feature = "serde", serde(default = "default_y_axis"))]
    pub y_axis: [f64; 3],
    /// Sweep Λ, degrees, positive aft: the beam axis turned about the reference frame's z axis
    /// from its x axis towards −y (the trailing edge). The reference frame is the parent's end
    /// section frame for the child of a flared hinge, else the frame of `x_axis`/`y_axis`.
    /// Default 0, within ±80°.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero"))]
    pub sweep_deg: f64,
    /// Dihedral Γ, degrees, positive up: the swept beam axis raised towards the reference
    /// frame's z axis. The body's frame is `F · R_z(−Λ) · R_y(−Γ)`, its beam axis
    /// `F (cos Γ cos Λ, −cos Γ sin Λ, sin Γ)`, its chord direction `F (sin Λ, cos Λ, 0)`.
    /// Default 0, within ±80°.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero"))]
    pub dihedral_deg: f64,
    /// Built-in twist of the section frame about the beam axis along the body, degrees,
    /// right-handed about the axis (for a body along +X: leading edge up, nose up), structural
    /// and aerodynamic (the lattice follows the sections): `[root, tip]`, linear along the
    /// body, or a table `[[s (m), deg], …]` increasing in s within the body, linear in between
    /// and held outside. Default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub twist_deg: Option<TwistSpec>,
    /// Section properties per unit length.
    pub section: Section,
    /// Point masses fixed to the body's sections (default none).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub point_masses: Vec<PointMass>,
}

/// A body's placement in the reference configuration before the root pitch: its start point
/// and its section axes x (the beam axis) and y, before its own twist.
pub type Placement = (Vector3<f64>, Vector3<f64>, Vector3<f64>);

/// A body's built-in twist (`twist_deg`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub enum TwistSpec {
    /// `[root, tip]`, degrees, linear along the body.
    Linear([f64; 2]),
    /// `[[s (m), degrees], …]`, increasing in s.
    Table(Vec<[f64; 2]>),
}

impl TwistSpec {
    /// The scene's twist of a body of `length` (radians).
    pub fn twist(&self, length: f64) -> scene::Twist {
        match self {
            TwistSpec::Linear([a, b]) => scene::Twist::linear(a.to_radians(), b.to_radians(), length),
            TwistSpec::Table(p) => scene::Twist::table(p.iter().map(|x| (x[0], x[1].to_radians())).collect()),
        }
    }

    /// Why the twist is not valid on a body of `length` (non-finite, beyond ±90°, a table not
    /// increasing in s or reaching outside the body), naming the entry below `field`.
    pub fn check(&self, field: &str, length: f64) -> Result<(), String> {
        let deg = |f: String, d: f64| {
            if d.is_finite() && d.abs() <= 90.0 {
                Ok(())
            } else {
                Err(format!("{f}: {d} is not a twist within ±90 degrees"))
            }
        };
        match self {
            TwistSpec::Linear([a, b]) => deg(format!("{field}[0]"), *a).and(deg(format!("{field}[1]"), *b)),
            TwistSpec::Table(p) => {
                if p.is_empty() {
                    return Err(format!("{field}: an empty table"));
                }
                for (k, x) in p.iter().enumerate() {
                    let inside = x[0].is_finite() && x[0] >= 0.0 && x[0] <= length * (1.0 + 1e-12);
                    if !inside || (k > 0 && x[0] <= p[k - 1][0]) {
                        return Err(format!(
                            "{field}[{k}]: s = {} does not increase within the body (0 to {length} m)",
                            x[0]
                        ));
                    }
                    deg(format!("{field}[{k}]"), x[1])?;
                }
                Ok(())
            }
        }
    }
}

/// A rigid point mass fixed to a body's section.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct PointMass {
    /// Arclength of the section it is fixed to, from the body's start, m.
    pub at: f64,
    /// Its centre relative to the section's axis point, `[x, y, z]` in the section frame, m
    /// (default `[0, 0, 0]`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub offset: [f64; 3],
    /// Mass, kg.
    pub mass: f64,
    /// Principal inertias about its own centre along the section axes `[I_xx, I_yy, I_zz]`,
    /// kg·m² (default `[0, 0, 0]`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub inertia: [f64; 3],
}

/// A rotational spring and damper about a hinge's axis: the moment `−k (θ − θ₀) − c θ̇`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
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
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
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
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero2"))]
    pub cg_offset: [f64; 2],
}

#[cfg(feature = "serde")]
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_zero2(v: &[f64; 2]) -> bool {
    *v == [0.0; 2]
}

/// A joint.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(tag = "type", rename_all = "snake_case", deny_unknown_fields))]
pub enum Joint {
    /// The body's start point pinned to ground; rotation only about a fixed global axis.
    GroundHinge {
        /// Optional joint name.
        #[cfg_attr(feature = "serde", serde(default))]
        name: Option<String>,
        /// Body name.
        body: String,
        /// Hinge axis, global (normalised).
        axis: [f64; 3],
        /// Rotational spring and damper about the axis (default none).
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        spring: Option<Spring>,
    },
    /// Flared hinge from the end of `parent` to the start of `child`, axis
    /// a = sin β·x + cos β·y in the parent's end section frame.
    FlaredHinge {
        /// Optional joint name.
        #[cfg_attr(feature = "serde", serde(default))]
        name: Option<String>,
        /// Parent body name.
        parent: String,
        /// Child body name.
        child: String,
        /// Flare angle β, degrees, in [−90, 90].
        flare_deg: f64,
        /// Lock the hinge (the child welded to the parent's end section) at the fold `lock_deg`:
        /// used for the rigid-wing check, and released or locked again by `events`. Default
        /// false.
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "std::ops::Not::not"))]
        locked: bool,
        /// Fold angle at which a locked hinge is welded, degrees (default 0: the reference
        /// configuration).
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero"))]
        lock_deg: f64,
        /// Rotational spring and damper about the hinge axis, on the fold angle (default none;
        /// inactive while the hinge is `locked`).
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        spring: Option<Spring>,
        /// Where the hinge line crosses the chord at the parent's end station (`length` from its
        /// start): the distance from the beam axis along the parent's end section's y axis
        /// (towards the leading edge), m. Default 0: the hinge line passes through the beam axis
        /// there. Otherwise the line through that point along the flare axis meets the beam axis
        /// `−y tan β` further outboard, and the joint sits there: the parent is lengthened and the
        /// child shortened by that much, the child's `start`, point masses and thrusts moved with
        /// it, so that its outer end and its masses stay in place (docs/statics.md §6). Healy's
        /// model code pivots the flare about mid-chord: `y = le_offset − chord/2`.
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero"))]
        hinge_line_y: f64,
    },
    /// The body's start section clamped to ground.
    Clamp {
        /// Optional joint name.
        #[cfg_attr(feature = "serde", serde(default))]
        name: Option<String>,
        /// Body name.
        body: String,
    },
    /// No constraint: the body (the root of a free-flying chain, which has no parent) moves
    /// with six rigid-body degrees of freedom relative to the ground.
    Free {
        /// Optional joint name.
        #[cfg_attr(feature = "serde", serde(default))]
        name: Option<String>,
        /// Body name.
        body: String,
    },
}

impl Joint {
    /// The joint's name, if any.
    pub fn name(&self) -> Option<&str> {
        match self {
            Joint::GroundHinge { name, .. }
            | Joint::FlaredHinge { name, .. }
            | Joint::Clamp { name, .. }
            | Joint::Free { name, .. } => name.as_deref(),
        }
    }
}

/// Newton settings (defaults as genalpha's, except `predictor`: see its field).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
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
    /// Turn a factorisation reused from an earlier step with the nodes' rotations (ANCF's DAE
    /// path; a no-op elsewhere).
    pub corotate: bool,
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
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
            corotate: d.corotate,
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
            corotate: self.corotate,
            max_step_halvings: self.max_step_halvings,
            local_error_tol: self.local_error_tol,
            ..Default::default()
        }
    }
}

/// Elements per body: one number for every body, or a list in body order.
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(untagged))]
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

    /// Every impossible value, naming `field`: one count per body (or one for all), each at
    /// least 1.
    ///
    /// # Errors
    /// A message naming the field.
    pub fn check(&self, field: &str, n_bodies: usize) -> Result<(), String> {
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AncfPath {
    /// Index-3 DAE with Lagrange multipliers.
    #[default]
    Dae,
    /// Constraints eliminated with the constant velocity transformation B (paper eq. 6–7).
    Ode,
}

/// ANCF settings.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AncfSettings {
    /// Two-node elements per body (a number, or a list in body order).
    pub elements_per_body: Elements,
    /// Time step, s.
    pub dt: f64,
    /// Spectral radius at infinite frequency. Default 0.8.
    #[cfg_attr(feature = "serde", serde(default = "default_rho_inf"))]
    pub rho_inf: f64,
    /// DAE (default) or ODE path.
    #[cfg_attr(feature = "serde", serde(default))]
    pub path: AncfPath,
    /// Where the generalized-α step enforces the equations of motion. Default `arnold_bruls`;
    /// `chung_hulbert` is not available with aerodynamics.
    #[cfg_attr(feature = "serde", serde(default))]
    pub form: FormSetting,
    /// Newton settings.
    #[cfg_attr(feature = "serde", serde(default))]
    pub newton: NewtonSettings,
}

/// GEBF settings.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct GebfSettings {
    /// Three-node elements per body (a number, or a list in body order).
    pub elements_per_body: Elements,
    /// Time step, s.
    pub dt: f64,
    /// Spectral radius at infinite frequency. Default 0.8.
    #[cfg_attr(feature = "serde", serde(default = "default_rho_inf"))]
    pub rho_inf: f64,
    /// Position-level projection of the joints after each step. Default off.
    #[cfg_attr(feature = "serde", serde(default))]
    pub stabilization: bool,
    /// After each step, restore the linear and angular momentum to their balance with the
    /// external loads by the smallest rigid velocity change (docs/gebf.md §15.1): free flight
    /// then keeps both momenta to round-off. Default off (they drift at second order).
    #[cfg_attr(feature = "serde", serde(default))]
    pub conserve_momentum: bool,
    /// Where the generalized-α step enforces the equations of motion. Default `arnold_bruls`;
    /// `chung_hulbert` keeps the floating frames' gyroscopic forces from doing discrete work
    /// (at rho_inf = 1, the implicit midpoint rule): use it for energy studies. Not available
    /// with aerodynamics (the coupled step holds the loads of the step's end).
    #[cfg_attr(feature = "serde", serde(default))]
    pub form: FormSetting,
    /// Newton settings.
    #[cfg_attr(feature = "serde", serde(default))]
    pub newton: NewtonSettings,
}

/// The settings every formulation's block (`ancf`, `gebf`) has, read from the block of one:
/// callers pick a block by [`Formulation`] ([`Problem::block`], [`blocks`]) instead of
/// matching on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block<'a> {
    /// Elements per body.
    pub elements_per_body: &'a Elements,
    /// Time step, s.
    pub dt: f64,
    /// Spectral radius at infinite frequency.
    pub rho_inf: f64,
    /// Where the generalized-α step enforces the equations of motion.
    pub form: FormSetting,
    /// Newton settings.
    pub newton: NewtonSettings,
    /// The solve path, for a formulation that has more than one (ANCF: with multipliers or by
    /// eliminating the joints); `None` for one with a single path.
    pub path: Option<AncfPath>,
}

/// The shared settings of one formulation's block, to change in place.
#[derive(Debug)]
pub struct BlockMut<'a> {
    /// Elements per body.
    pub elements_per_body: &'a mut Elements,
    /// Time step, s.
    pub dt: &'a mut f64,
    /// Spectral radius at infinite frequency.
    pub rho_inf: &'a mut f64,
    /// Where the generalized-α step enforces the equations of motion.
    pub form: &'a mut FormSetting,
    /// Newton settings.
    pub newton: &'a mut NewtonSettings,
    /// The solve path ([`Block::path`]).
    pub path: Option<&'a mut AncfPath>,
}

/// The block of formulation `f` of a pair of blocks (a problem's or a case file's).
pub fn blocks<'a>(f: Formulation, ancf: &'a AncfSettings, gebf: &'a GebfSettings) -> Block<'a> {
    f.pick(
        Block {
            elements_per_body: &ancf.elements_per_body,
            dt: ancf.dt,
            rho_inf: ancf.rho_inf,
            form: ancf.form,
            newton: ancf.newton,
            path: Some(ancf.path),
        },
        Block {
            elements_per_body: &gebf.elements_per_body,
            dt: gebf.dt,
            rho_inf: gebf.rho_inf,
            form: gebf.form,
            newton: gebf.newton,
            path: None,
        },
    )
}

/// [`blocks`], to change in place.
pub fn blocks_mut<'a>(f: Formulation, ancf: &'a mut AncfSettings, gebf: &'a mut GebfSettings) -> BlockMut<'a> {
    f.pick(
        BlockMut {
            elements_per_body: &mut ancf.elements_per_body,
            dt: &mut ancf.dt,
            rho_inf: &mut ancf.rho_inf,
            form: &mut ancf.form,
            newton: &mut ancf.newton,
            path: Some(&mut ancf.path),
        },
        BlockMut {
            elements_per_body: &mut gebf.elements_per_body,
            dt: &mut gebf.dt,
            rho_inf: &mut gebf.rho_inf,
            form: &mut gebf.form,
            newton: &mut gebf.newton,
            path: None,
        },
    )
}

/// The two structural formulations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Formulation {
    /// Absolute nodal coordinates.
    Ancf,
    /// Geometrically exact beam on floating frames.
    Gebf,
}

impl Formulation {
    /// Both, in report order.
    pub const ALL: [Formulation; 2] = [Formulation::Ancf, Formulation::Gebf];
    /// The formulation whose [`Formulation::as_str`] is `name`.
    pub fn from_name(name: &str) -> Option<Formulation> {
        Formulation::ALL.into_iter().find(|f| f.as_str() == name)
    }
    /// Lower-case name used in file names.
    pub fn as_str(self) -> &'static str {
        Self::NAMES[self.index()].0
    }
    /// Of a pair of values kept per formulation in the case file's order (`ancf`, `gebf`: the
    /// blocks of a problem, the cases of a run), this formulation's: the one place that matches
    /// on the variants for such pairs.
    pub fn pick<T>(self, ancf: T, gebf: T) -> T {
        match self {
            Formulation::Ancf => ancf,
            Formulation::Gebf => gebf,
        }
    }
    /// Upper-case name used in tables and legends.
    pub fn label(self) -> &'static str {
        Self::NAMES[self.index()].1
    }
    /// Position in [`Formulation::ALL`]: where tables indexed by formulation (plot styles, speed
    /// targets) keep this formulation's entry.
    pub fn index(self) -> usize {
        self as usize
    }
    /// File name and label of each formulation, in [`Formulation::ALL`] order.
    const NAMES: [(&'static str, &'static str); 2] = [("ancf", "ANCF"), ("gebf", "GEBF")];
}

impl std::fmt::Display for Formulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Problem {
    /// Index of the body called `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        body_index(&self.bodies, name)
    }

    /// Index of the joint whose fold angle is reported.
    pub fn fold_joint_index(&self) -> Option<usize> {
        fold_joint_index(&self.joints, self.fold_joint.as_deref())
    }

    /// The body at whose start the root loads are measured: the child of the `root_joint` (a
    /// flared hinge) or the body of a clamp (the `root_joint`, or the first clamp without one).
    pub fn root_body_index(&self) -> Option<usize> {
        let joint = match self.root_joint.as_deref() {
            Some(n) => self.joints.iter().find(|j| j.name() == Some(n))?,
            None => self.joints.iter().find(|j| matches!(j, Joint::Clamp { .. }))?,
        };
        match joint {
            Joint::FlaredHinge { child, .. } => self.body_index(child),
            Joint::Clamp { body, .. } => self.body_index(body),
            _ => None,
        }
    }

    /// Index of the `roll_joint`, if the problem names one.
    pub fn roll_joint_index(&self) -> Option<usize> {
        let name = self.roll_joint.as_deref()?;
        self.joints.iter().position(|j| j.name() == Some(name))
    }

    /// The settings of formulation `f`'s block.
    pub fn block(&self, f: Formulation) -> Block<'_> {
        blocks(f, &self.ancf, &self.gebf)
    }

    /// The settings of formulation `f`'s block, to change in place.
    pub fn block_mut(&mut self, f: Formulation) -> BlockMut<'_> {
        blocks_mut(f, &mut self.ancf, &mut self.gebf)
    }

    /// Total length of all bodies, m.
    pub fn span(&self) -> f64 {
        self.bodies.iter().map(|b| b.length).sum()
    }

    /// Each body's start point and section axes x (the beam axis) and y in the reference
    /// configuration before the root pitch and before its own twist: `start` or the parent's end
    /// (the origin without a parent); the axes of `x_axis`/`y_axis`, or with a sweep or dihedral
    /// those of the reference frame (the parent's end section frame, its twist included, or
    /// `x_axis`/`y_axis` for a body without a parent) turned by `R_z(−Λ) R_y(−Γ)`.
    pub fn placements(&self) -> Vec<Placement> {
        let n = self.bodies.len();
        let parent: Vec<Option<usize>> = (0..n)
            .map(|i| {
                self.joints.iter().find_map(|j| match j {
                    Joint::FlaredHinge { parent, child, .. } if self.body_index(child) == Some(i) => {
                        self.body_index(parent).filter(|&p| p != i)
                    }
                    _ => None,
                })
            })
            .collect();
        let mut placed: Vec<Option<Placement>> = vec![None; n];
        for i in 0..n {
            self.place(i, &parent, &mut placed, 0);
        }
        placed.into_iter().map(|p| p.unwrap_or((Vector3::zeros(), Vector3::x(), Vector3::y()))).collect()
    }

    /// [`Problem::placements`] of body `i`, its parents first (a chain longer than the body
    /// count is a loop, which the scene's validation names; it is cut here).
    fn place(
        &self,
        i: usize,
        parent: &[Option<usize>],
        placed: &mut Vec<Option<Placement>>,
        depth: usize,
    ) -> Placement {
        if let Some(p) = placed[i] {
            return p;
        }
        let b = &self.bodies[i];
        let unit = |v: [f64; 3]| Vector3::from(v).normalize();
        let up = parent[i].filter(|_| depth < self.bodies.len()).map(|p| {
            let (s, x, y) = self.place(p, parent, placed, depth + 1);
            let parent = &self.bodies[p];
            // The parent's end section frame: its axes turned by its twist at the end.
            let theta = parent.twist_deg.as_ref().map_or(0.0, |t| t.twist(parent.length).angle(parent.length));
            let (st, ct) = theta.sin_cos();
            (s + x * parent.length, x, y * ct + x.cross(&y) * st)
        });
        let start = b.start.map(Vector3::from).or(up.map(|u| u.0)).unwrap_or_else(Vector3::zeros);
        let (x, y) = if b.sweep_deg == 0.0 && b.dihedral_deg == 0.0 {
            (unit(b.x_axis), unit(b.y_axis))
        } else {
            let (x0, y0) = up.map_or_else(|| (unit(b.x_axis), unit(b.y_axis)), |u| (u.1, u.2));
            let z0 = x0.cross(&y0);
            let (sl, cl) = b.sweep_deg.to_radians().sin_cos();
            let (sg, cg) = b.dihedral_deg.to_radians().sin_cos();
            (x0 * (cg * cl) - y0 * (cg * sl) + z0 * sg, x0 * sl + y0 * cl)
        };
        placed[i] = Some((start, x, y));
        (start, x, y)
    }

    /// The scene of formulation `f`: bodies (stiffnesses scaled by `stiffness_scale`, element
    /// counts of `f`), joints, hinge springs as force elements, gravity. Body names that do not
    /// resolve become an index past the last body, which [`scene::Scene::validate`] rejects.
    pub fn scene(&self, f: Formulation) -> scene::Scene {
        let n_el = self.block(f).elements_per_body;
        // Nose-up pitch: a rotation about +X takes +Y (the leading edge) towards +Z.
        let pitch = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), self.pitch_deg.to_radians());
        let placed = self.placements();
        let bodies = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (start, x, y) = placed[i];
                let (x, y) = (pitch * x, pitch * y);
                let s = &b.section;
                let section = scene::Section {
                    cg_offset: s.cg_offset,
                    ..scene::Section::centred(
                        s.mass, s.rho_ixx, s.rho_iyy, s.rho_izz, s.ea, s.ga_y, s.ga_z, s.gj, s.ei_yy, s.ei_zz,
                    )
                };
                scene::BodySpec {
                    name: b.name.clone(),
                    start: pitch * start,
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
                    twist: b.twist_deg.as_ref().map_or_else(scene::Twist::none, |t| t.twist(b.length)),
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
                Joint::FlaredHinge { parent, child, flare_deg, locked, lock_deg, .. } => {
                    let (parent, child, beta) = (idx(parent), idx(child), flare_deg.to_radians());
                    if *locked {
                        scene::JointSpec::LockedHinge { parent, child, beta, fold: lock_deg.to_radians() }
                    } else {
                        scene::JointSpec::FlaredHinge { parent, child, beta }
                    }
                }
                Joint::Clamp { body, .. } => scene::JointSpec::Clamp { body: idx(body) },
                Joint::Free { body, .. } => scene::JointSpec::Free { body: idx(body) },
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
                Joint::Clamp { .. } | Joint::Free { .. } => None,
            })
            .chain(self.thrust.iter().map(|t| scene::ForceElement::Thrust {
                body: idx(&t.body),
                at: t.at,
                direction: t.unit_direction().into(),
                magnitude: t.schedule(),
            }))
            .collect();
        let gravity = self.gravity.map(nalgebra::Vector3::from).unwrap_or_else(nalgebra::Vector3::zeros);
        scene::Scene { bodies, joints, forces, gravity }
    }
}

#[cfg(test)]
mod tests {
    use super::Formulation;

    /// Tables indexed by [`Formulation::index`] rely on it being the position in `ALL`, and the
    /// command line's names on `from_name` inverting `as_str`.
    #[test]
    fn formulation_index_and_names_follow_all() {
        for (i, f) in Formulation::ALL.into_iter().enumerate() {
            assert_eq!(f.index(), i);
            assert_eq!(Formulation::from_name(f.as_str()), Some(f));
            assert_eq!(f.label(), f.as_str().to_uppercase());
        }
        assert_eq!(Formulation::from_name("both"), None);
    }
}
