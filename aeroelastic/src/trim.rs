//! Trim of a free aircraft in steady level flight (issue 35 item 5, docs/trim.md): the angle of
//! attack, the elevator deflection and the thrust for which the flexible aircraft's static
//! aeroelastic equilibrium carries no net force and pitching moment.
//!
//! The aircraft is held at its free body's root (the `free` joint becomes a clamp, as SHARPy's
//! `StaticTrim` holds its reference node) and its flexible static equilibrium is solved with the
//! steady lattice, gravity and the thrusts ([`crate::statics::AeroStatic`]). The load the aircraft
//! then puts on the clamp is the net external wrench: aerodynamic loads, weight and thrust,
//! measured by the one free-body rule of [`crate::loads`]. Trim drives its forward and vertical
//! components and its pitching moment to zero. A held aircraft carrying no load is a free one
//! in equilibrium.
//!
//! The angle of attack turns the flow, not the aircraft: the structure keeps its reference
//! geometry (body axes: span +X, nose +Y, up +Z) and the free stream and gravity are turned about
//! +X by −α, so every equilibrium of the iteration starts from the previous one's coordinates.
//! The lattice's columns keep the layout of the reference flow. The unknowns are found by
//! Newton's method with a difference-quotient Jacobian (one static solve per unknown), updated by
//! Broyden's rule between steps.

use nalgebra::{Matrix3, Rotation3, Vector3};

use genalpha::analysis::{StaticSolution, StaticSolver};

use crate::aero::{AeroSettings, StationMap, station_map};
use crate::control_surface::Deflection;
use crate::factory::{BuildModel, ForModel, dispatch};
use crate::loads::{LoadModel, LoadScratch};
use crate::polar_correction::StripPolars;
use crate::problem::{Formulation, Joint, Problem};
use crate::stability_settings::WakeSettings;
use crate::statics::{AeroStatic, load_stepping, point_at, solve_rounds, static_params};

/// The case's `trim` block.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TrimSettings {
    /// The control surfaces (names in `aero.control_surfaces`) deflected together as the
    /// elevator: a name, or `{ "name", "gain" }` for a surface deflected by `gain` times the
    /// elevator's deflection (−1 on a wing whose section z axis points down, where trailing edge
    /// down is the other way). The first surface's deflection in the case over its gain is the
    /// first guess.
    pub elevator: Vec<ElevatorSurface>,
    /// First guess of the angle of attack, degrees. Default 2.
    #[cfg_attr(feature = "serde", serde(default = "default_alpha"))]
    pub alpha_deg: f64,
    /// The steady wake of the equilibria (default: semi-infinite legs along the free stream).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub wake: Option<WakeSettings>,
    /// Largest net force left, N. Default 1e-3.
    #[cfg_attr(feature = "serde", serde(default = "default_tolerance"))]
    pub force_tolerance: f64,
    /// Largest net pitching moment left, N·m. Default 1e-3.
    #[cfg_attr(feature = "serde", serde(default = "default_tolerance"))]
    pub moment_tolerance: f64,
    /// Most trim iterations. Default 30.
    #[cfg_attr(feature = "serde", serde(default = "default_iterations"))]
    pub max_iterations: usize,
}

/// One surface of the elevator.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub enum ElevatorSurface {
    /// A surface deflected as the elevator.
    Name(String),
    /// A surface deflected by `gain` times the elevator's deflection.
    Geared {
        /// Its name in `aero.control_surfaces`.
        name: String,
        /// Its deflection per unit of the elevator's (non-zero).
        gain: f64,
    },
}

impl ElevatorSurface {
    /// Its name.
    pub fn name(&self) -> &str {
        match self {
            ElevatorSurface::Name(n) | ElevatorSurface::Geared { name: n, .. } => n,
        }
    }

    /// Its gain.
    pub fn gain(&self) -> f64 {
        match self {
            ElevatorSurface::Name(_) => 1.0,
            ElevatorSurface::Geared { gain, .. } => *gain,
        }
    }
}

impl TrimSettings {
    /// The gain of control surface `name` in the elevator (none: not in it).
    fn gain_of(&self, name: &str) -> Option<f64> {
        self.elevator.iter().find(|e| e.name() == name).map(ElevatorSurface::gain)
    }
}

#[cfg(feature = "serde")]
fn default_alpha() -> f64 {
    2.0
}
#[cfg(feature = "serde")]
fn default_tolerance() -> f64 {
    1e-3
}
#[cfg(feature = "serde")]
fn default_iterations() -> usize {
    30
}

impl TrimSettings {
    /// Every impossible value against the problem, naming its field: a free body to trim, the
    /// elevator among the control surfaces, a thrust, finite tolerances.
    ///
    /// # Errors
    /// A message naming the field.
    pub fn validate(&self, p: &Problem) -> Result<(), String> {
        if free_body(p).is_none() {
            return Err("trim: the case has no free body (a joint of type \"free\") to trim".into());
        }
        if let Some(k) = p.joints.iter().position(|j| matches!(j, Joint::Clamp { .. } | Joint::GroundHinge { .. })) {
            return Err(format!("joints[{k}]: a trimmed aircraft is held by nothing but its free joint"));
        }
        let Some(aero) = p.aero.as_ref() else {
            return Err("trim: the case has no `aero` block".into());
        };
        if self.elevator.is_empty() {
            return Err("trim.elevator: name at least one control surface".into());
        }
        for (k, e) in self.elevator.iter().enumerate() {
            let name = e.name();
            if !aero.control_surfaces.iter().any(|c| c.name == name) {
                return Err(format!("trim.elevator[{k}]: no control surface named {name:?} in aero.control_surfaces"));
            }
            if !(e.gain().is_finite() && e.gain() != 0.0) {
                return Err(format!("trim.elevator[{k}].gain: {} is not a finite non-zero number", e.gain()));
            }
        }
        if p.thrust.is_empty() {
            return Err("thrust: a trim needs a thrust (the field `thrust`)".into());
        }
        if aero.sideslip_deg != 0.0 {
            return Err("aero.sideslip_deg: the trim is for symmetric level flight (sideslip 0)".into());
        }
        if !(self.alpha_deg.is_finite() && self.alpha_deg.abs() < 30.0) {
            return Err(format!("trim.alpha_deg: {} is not within ±30°", self.alpha_deg));
        }
        for (field, v) in [("force_tolerance", self.force_tolerance), ("moment_tolerance", self.moment_tolerance)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("trim.{field}: {v} is not a positive number"));
            }
        }
        if self.max_iterations == 0 || self.max_iterations > 1000 {
            return Err(format!("trim.max_iterations: {} is not in 1..=1000", self.max_iterations));
        }
        Ok(())
    }
}

/// Where a time march starts (case field `initial`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Initial {
    /// The reference configuration at rest, the lattice started impulsively.
    #[default]
    Reference,
    /// The trimmed state of the case's `trim`: the deformed aircraft in level flight, at rest in
    /// body axes, with the steady wake (docs/trim.md §5).
    Trim,
    /// The trimmed state of `Trim`, with the aircraft held at its free body for the whole march
    /// (the free joint a clamp, as the trim holds it): the clamped wing of a comparison with the
    /// free flight (docs/trim.md §6).
    TrimHeld,
}

impl Initial {
    /// Whether this is the default.
    pub fn is_reference(&self) -> bool {
        *self == Initial::Reference
    }

    /// Whether the march starts from the trim (free or held).
    pub fn is_trim(&self) -> bool {
        matches!(self, Initial::Trim | Initial::TrimHeld)
    }

    /// The case file's spelling.
    pub fn name(&self) -> &'static str {
        match self {
            Initial::Reference => "reference",
            Initial::Trim => "trim",
            Initial::TrimHeld => "trim_held",
        }
    }
}

/// The index of the body on a `free` joint.
fn free_body(p: &Problem) -> Option<usize> {
    p.joints.iter().find_map(|j| match j {
        Joint::Free { body, .. } => p.body_index(body),
        _ => None,
    })
}

/// The unknowns of a trim: angle of attack (deg), elevator deflection (deg), thrust (N, each
/// thrust element's magnitude).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Unknowns([f64; 3]);

/// The net load on the held aircraft, in body axes, that trim zeroes: forward force (+Y), upward
/// force (+Z), nose-up pitching moment (about +X through the free body's root).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TrimResiduals {
    /// Net forward force, N.
    pub force_forward: f64,
    /// Net upward force, N.
    pub force_up: f64,
    /// Net nose-up pitching moment about the free body's root, N·m.
    pub pitch_moment: f64,
}

impl TrimResiduals {
    fn vector(&self) -> Vector3<f64> {
        Vector3::new(self.force_forward, self.force_up, self.pitch_moment)
    }
}

/// A formulation's trim.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TrimOutput {
    /// Formulation.
    pub formulation: Formulation,
    /// Airspeed, m/s.
    pub airspeed: f64,
    /// Angle of attack of the free body (the flow's incidence on the reference geometry), deg.
    pub alpha_deg: f64,
    /// The elevator's deflection, deg (each surface's over its gain).
    pub elevator_deg: f64,
    /// The elevator's control surfaces and their deflection, deg (trailing edge down positive in
    /// each surface's section frame).
    pub controls: Vec<(String, f64)>,
    /// Each thrust element's magnitude, N.
    pub thrust: f64,
    /// The net load left.
    pub residuals: TrimResiduals,
    /// Whether the residuals are within the tolerances.
    pub converged: bool,
    /// Trim iterations (Newton steps on the three unknowns).
    pub iterations: usize,
    /// Static aeroelastic solves (the difference quotients included).
    pub static_solves: usize,
    /// Lift (perpendicular to the flow, in the plane of symmetry), N, of the lattice as modelled
    /// (a half model's half).
    pub lift: f64,
    /// Drag (along the flow), N, as `lift`.
    pub drag: f64,
    /// The section polars' part of `drag` (their profile drag along the flow), N; 0 without
    /// polars.
    pub profile_drag: f64,
    /// Tip position (body axes), m.
    pub tip: [f64; 3],
    /// Wall time, s.
    pub wall_s: f64,
    /// Why the trim failed, if it did.
    pub error: Option<String>,
    /// The deformed state: the structure's coordinates (body axes, the free body held).
    pub q: Vec<f64>,
}

/// Trim `p` with formulation `f` and the settings `t`.
pub fn run_trim(p: &Problem, f: Formulation, t: &TrimSettings) -> TrimOutput {
    let t0 = std::time::Instant::now();
    struct Work<'a>(&'a Problem, Formulation, &'a TrimSettings);
    impl ForModel for Work<'_> {
        type Output = TrimOutput;
        fn run<M: BuildModel>(self) -> TrimOutput {
            trim_with::<M>(self.0, self.1, self.2)
        }
    }
    let mut out = dispatch(f, Work(p, f, t));
    out.wall_s = t0.elapsed().as_secs_f64();
    out
}

fn failed(p: &Problem, f: Formulation, msg: String) -> TrimOutput {
    TrimOutput {
        formulation: f,
        airspeed: p.aero.as_ref().map_or(f64::NAN, AeroSettings::speed),
        alpha_deg: f64::NAN,
        elevator_deg: f64::NAN,
        controls: Vec::new(),
        thrust: f64::NAN,
        residuals: TrimResiduals { force_forward: f64::NAN, force_up: f64::NAN, pitch_moment: f64::NAN },
        converged: false,
        iterations: 0,
        static_solves: 0,
        lift: f64::NAN,
        drag: f64::NAN,
        profile_drag: f64::NAN,
        tip: [f64::NAN; 3],
        wall_s: 0.0,
        error: Some(msg),
        q: Vec::new(),
    }
}

/// Body axes at angle of attack `alpha_deg`: the free stream and gravity of `p` turned about +X
/// by −α (the structure keeps its reference geometry). A gust's direction, given in the earth
/// frame, turns with them.
fn turn_flow(p: &mut Problem, alpha_deg: f64) {
    let turn = Rotation3::from_axis_angle(&Vector3::x_axis(), -alpha_deg.to_radians());
    p.gravity = p.gravity.map(|g| (turn * Vector3::from(g)).into());
    if let Some(a) = p.aero.as_mut() {
        a.v_inf = Some((turn * Vector3::from(a.stream_without_sideslip())).into());
        a.airspeed = None;
        if let Some(g) = a.gust.as_mut() {
            let d = g.direction_mut();
            *d = (turn * Vector3::from(*d)).into();
        }
    }
}

/// Hold the aircraft of `p` at its free body: every `free` joint becomes a clamp.
pub fn hold(p: &mut Problem) {
    for j in &mut p.joints {
        if let Joint::Free { name, body } = j {
            *j = Joint::Clamp { name: name.clone(), body: body.clone() };
        }
    }
}

/// The problem the trim solves at `x`: the free body clamped, the flow and gravity turned by −α
/// about +X, the elevator at δ, every thrust at T.
fn held_problem(base: &Problem, t: &TrimSettings, x: Unknowns) -> Problem {
    let mut p = base.clone();
    hold(&mut p);
    // The net load is measured at the clamp, over the whole aircraft, whatever joint the case
    // measures its root loads at.
    p.root_joint = None;
    turn_flow(&mut p, x.0[0]);
    if let Some(a) = p.aero.as_mut() {
        for c in &mut a.control_surfaces {
            if let Some(g) = t.gain_of(&c.name) {
                c.deflection_deg = Deflection::Fixed(g * x.0[1]);
            }
        }
    }
    for th in &mut p.thrust {
        th.magnitude = Deflection::Fixed(x.0[2]);
    }
    p
}

/// A schedule moved so that it starts at `start`: the fixed value becomes `start`, a schedule
/// keeps its changes from its value at t = 0.
fn offset_to(d: &Deflection, start: f64) -> Deflection {
    match d {
        Deflection::Fixed(_) => Deflection::Fixed(start),
        Deflection::Schedule(p) => {
            let d0 = d.at(0.0).0;
            Deflection::Schedule(p.iter().map(|&[t, v]| [t, v - d0 + start]).collect())
        }
    }
}

/// The problem of a time march from the trim `out` (docs/trim.md §5): in body axes, the flow and
/// gravity turned by −α as in the trim, the free joint free; the elevator's surfaces and the
/// thrusts at their trimmed values plus their schedules' changes from t = 0 (an elevator doublet
/// or a thrust step on top of the trim). With `initial: "trim_held"` the free joint is a clamp,
/// as in the trim's held problem.
pub fn flight_problem(base: &Problem, out: &TrimOutput) -> Problem {
    let mut p = base.clone();
    if p.initial == Initial::TrimHeld {
        hold(&mut p);
    }
    turn_flow(&mut p, out.alpha_deg);
    if let Some(a) = p.aero.as_mut() {
        for c in a.control_surfaces.iter_mut() {
            if let Some((_, d)) = out.controls.iter().find(|(n, _)| n == &c.name) {
                c.deflection_deg = offset_to(&c.deflection_deg, *d);
            }
        }
    }
    for th in &mut p.thrust {
        th.magnitude = offset_to(&th.magnitude, out.thrust);
    }
    p.initial = Initial::Reference;
    p
}

/// The trim a time march of `p` with formulation `M` starts from: the case's `trim` with the
/// march's own frozen wake (`aero.n_wake_rows` rows of `V dt`), so that the march, whose wake is
/// prefilled with that steady wake, starts in equilibrium. Returns the march's problem and the
/// trim.
///
/// # Errors
/// No `trim` block, or the trim failed.
pub(crate) fn trim_for_march<M: BuildModel>(p: &Problem, f: Formulation) -> Result<(Problem, TrimOutput), String> {
    let initial = p.initial.name();
    let t = p.trim.as_ref().ok_or_else(|| format!("initial: \"{initial}\" needs a `trim` block"))?;
    let aero = p.aero.as_ref().ok_or_else(|| format!("initial: \"{initial}\" needs `aero`"))?;
    let mut t = t.clone();
    t.wake = Some(crate::stability::march_wake(p, f, aero.speed()));
    let out = trim_with::<M>(p, f, &t);
    if let Some(e) = &out.error {
        return Err(format!("the trim the run starts from failed: {e}"));
    }
    Ok((flight_problem(p, &out), out))
}

/// The first guess: α from the settings, δ the first elevator surface's deflection at t = 0, T the
/// first thrust's magnitude at t = 0.
fn first_guess(p: &Problem, t: &TrimSettings) -> Unknowns {
    let first = t.elevator.first();
    let delta = p
        .aero
        .as_ref()
        .zip(first)
        .and_then(|(a, e)| a.control_surfaces.iter().find(|c| c.name == e.name()).map(|c| (c, e.gain())))
        .map_or(0.0, |(c, g)| c.deflection_deg.at(0.0).0 / g);
    let thrust = p.thrust.first().map_or(0.0, |th| th.magnitude_at(0.0));
    Unknowns([t.alpha_deg, delta, thrust])
}

/// The held aircraft's equilibria at successive unknowns, each from the previous one.
struct Held<'a, M: BuildModel> {
    base: &'a Problem,
    f: Formulation,
    t: &'a TrimSettings,
    sys: AeroStatic<'a, M>,
    solver: StaticSolver,
    x: StaticSolution,
    map: &'a [StationMap],
    root: usize,
    solves: usize,
}

impl<'a, M: BuildModel> Held<'a, M> {
    /// The equilibrium at `x` (from the last one) and its net load.
    fn residual(&mut self, x: Unknowns) -> Result<TrimResiduals, String> {
        let p = held_problem(self.base, self.t, x);
        let aero = p.aero.as_ref().ok_or("no aero")?;
        self.sys.set_model(M::build(&p).map_err(|e| e.to_string())?);
        self.sys.set_aero(aero, &self.x.q)?;
        let good = self.x.clone();
        self.solves += 1;
        if let Err(e) = solve_rounds(&mut self.sys, &mut self.solver, &mut self.x) {
            self.x = good;
            return Err(format!("no equilibrium at α {:.4}°, δ {:.4}°, T {:.4} N: {e}", x.0[0], x.0[1], x.0[2]));
        }
        self.net_load(&p)
    }

    /// The net load on the held aircraft at the current equilibrium of problem `p`.
    fn net_load(&self, p: &Problem) -> Result<TrimResiduals, String> {
        let q = &self.x.q;
        let (station_loads, _, _) = self.sys.evaluate_at(q)?;
        let lm = LoadModel::new(p, self.f).ok_or("no clamp to measure the load at")?;
        let model = self.sys.model();
        let w = lm.evaluate(&*model, q, None, &station_loads, &mut LoadScratch::default());
        let (p0, r0): (Vector3<f64>, Matrix3<f64>) = model.section_pose(q, self.root, 0.0);
        let mut force = r0 * Vector3::from(w.root_force);
        let mut moment = r0 * Vector3::from(w.root_moment);
        for th in &p.thrust {
            let b = p.body_index(&th.body).ok_or_else(|| format!("thrust body {:?}", th.body))?;
            let (pt, rt) = model.section_pose(q, b, th.at);
            let ft = rt * Vector3::from(th.unit_direction()) * th.magnitude_at(0.0);
            force += ft;
            moment += (pt - p0).cross(&ft);
        }
        Ok(TrimResiduals { force_forward: force.y, force_up: force.z, pitch_moment: moment.x })
    }
}

/// Difference steps of the unknowns: α and δ in degrees, T in newtons.
const STEPS: [f64; 3] = [0.05, 0.1, 0.5];
/// Largest Newton step of α and δ, degrees.
const MAX_ANGLE_STEP: f64 = 3.0;

pub(crate) fn trim_with<M: BuildModel>(base: &Problem, f: Formulation, t: &TrimSettings) -> TrimOutput {
    if let Err(e) = t.validate(base) {
        return failed(base, f, e);
    }
    if let Err(e) = crate::section_polars::refuse_tip_loss(base, "trim") {
        return failed(base, f, e);
    }
    let Some(root) = free_body(base) else { return failed(base, f, "no free body".into()) };
    let x0 = first_guess(base, t);
    let p0 = held_problem(base, t, x0);
    let Some(aero0) = p0.aero.clone() else { return failed(base, f, "no aero".into()) };
    // The lattice's layout of the reference flow (α = 0), kept for every α.
    let reference = held_problem(base, t, Unknowns([0.0, x0.0[1], x0.0[2]]));
    let map = match reference.aero.as_ref().map(|a| station_map(&reference, a)) {
        Some(Ok(m)) => m,
        Some(Err(e)) => return failed(base, f, e),
        None => return failed(base, f, "no aero".into()),
    };
    let model = match M::build(&p0) {
        Ok(m) => m,
        Err(e) => return failed(base, f, e.to_string()),
    };
    let q_ref = model.initial_state().q;
    let wake = t.wake.as_ref().map_or(uvlm::SteadyWake::SemiInfinite, WakeSettings::steady_wake);
    let mut sys = match AeroStatic::new(model, &q_ref, &map, &aero0, wake, base.span()) {
        Ok(s) => s,
        Err(e) => return failed(base, f, e),
    };
    // The section polars correct every equilibrium's loads, so the net load (and the thrust that
    // balances the profile drag) is of the corrected loads; docs/trim.md §2.
    match StripPolars::of(base) {
        Ok(p) => sys.set_polars(p),
        Err(e) => return failed(base, f, e),
    }
    let solver = StaticSolver::new(&sys, static_params());
    let x = StaticSolution::guess(&sys, &q_ref);
    let mut held = Held { base, f, t, sys, solver, x, map: &map, root, solves: 1 };
    // The first equilibrium by load stepping from the reference configuration, the polars read
    // at the trim airspeed's Reynolds numbers while the dynamic pressure is ramped (as a static
    // sweep's first point); every later equilibrium at the strips' own `V c/ν`.
    held.sys.hold_reynolds_at(Some(aero0.speed()));
    let stepped = load_stepping(&p0, M::build, aero0.speed(), &mut held.sys, &mut held.solver, &mut held.x);
    held.sys.hold_reynolds_at(None);
    if let Err(e) = stepped {
        return failed(base, f, e);
    }
    let out = iterate(&mut held, x0);
    finish(&held, base, f, t, out)
}

/// Newton–Broyden on the unknowns from `x`: the final unknowns, residuals and iterations.
fn iterate<M: BuildModel>(
    held: &mut Held<'_, M>,
    mut x: Unknowns,
) -> Result<(Unknowns, TrimResiduals, usize), (Unknowns, String)> {
    let t = held.t;
    let mut r = held.residual(x).map_err(|e| (x, e))?;
    let done = |r: &TrimResiduals| {
        r.force_forward.abs().max(r.force_up.abs()) <= t.force_tolerance && r.pitch_moment.abs() <= t.moment_tolerance
    };
    let mut jac: Option<Matrix3<f64>> = None;
    for it in 0..t.max_iterations {
        if done(&r) {
            return Ok((x, r, it));
        }
        // A fresh difference-quotient Jacobian at the start and whenever Broyden's stalls.
        let j = match jac {
            Some(j) => j,
            None => {
                let mut j = Matrix3::zeros();
                for (k, h) in STEPS.into_iter().enumerate() {
                    let mut xk = x;
                    xk.0[k] += h;
                    let rk = held.residual(xk).map_err(|e| (x, e))?;
                    j.set_column(k, &((rk.vector() - r.vector()) / h));
                }
                // Back to the equilibrium at x for the next step's warm start.
                r = held.residual(x).map_err(|e| (x, e))?;
                j
            }
        };
        let Some(inv) = j.try_inverse() else {
            return Err((x, "the trim Jacobian is singular: the elevator or the thrust does not act".into()));
        };
        let mut dx = -(inv * r.vector());
        let scale = (MAX_ANGLE_STEP / dx.x.abs().max(dx.y.abs()).max(MAX_ANGLE_STEP)).min(1.0);
        dx *= scale;
        let x_new = Unknowns([x.0[0] + dx.x, x.0[1] + dx.y, x.0[2] + dx.z]);
        let r_new = held.residual(x_new).map_err(|e| (x, e))?;
        let dr = r_new.vector() - r.vector();
        let stalled = r_new.vector().norm() > 0.5 * r.vector().norm();
        jac = if stalled { None } else { Some(j + (dr - j * dx) * dx.transpose() / dx.norm_squared()) };
        x = x_new;
        r = r_new;
    }
    if done(&r) {
        return Ok((x, r, t.max_iterations));
    }
    Err((x, format!("not trimmed in {} iterations: net load {:?}", t.max_iterations, r)))
}

fn finish<M: BuildModel>(
    held: &Held<'_, M>,
    base: &Problem,
    f: Formulation,
    t: &TrimSettings,
    out: Result<(Unknowns, TrimResiduals, usize), (Unknowns, String)>,
) -> TrimOutput {
    let (x, residuals, iterations, error) = match out {
        Ok((x, r, it)) => (x, r, it, None),
        Err((x, e)) => {
            (x, TrimResiduals { force_forward: f64::NAN, force_up: f64::NAN, pitch_moment: f64::NAN }, 0, Some(e))
        }
    };
    let p = held_problem(base, t, x);
    let rho = p.aero.as_ref().map_or(0.0, |a| a.rho);
    let point = point_at(&held.sys, &held.x.q, &p, None, held.map, rho);
    let model = held.sys.model();
    TrimOutput {
        formulation: f,
        airspeed: held.sys.airspeed(),
        alpha_deg: x.0[0],
        elevator_deg: x.0[1],
        controls: t.elevator.iter().map(|e| (e.name().to_string(), e.gain() * x.0[1])).collect(),
        thrust: x.0[2],
        residuals,
        converged: error.is_none(),
        iterations,
        static_solves: held.solves,
        lift: point.lift,
        drag: point.drag,
        profile_drag: point.profile_drag,
        tip: model.tip(&held.x.q),
        wall_s: 0.0,
        error,
        q: held.x.q.clone(),
    }
}
