//! The formulation factory: building each formulation's model from a [`Problem`]. Both models
//! implement [`formulation::Structure`] in their own crates; the time loops and analyses are
//! generic over it. [`dispatch`] is the one place that picks a formulation's model type.

use formulation::Structure;
use genalpha::Predictor;

use crate::Error;
use crate::aero::{simulate_aero_with_events, station_map};
use crate::events::{Events, ScheduledEvent, When};
use crate::polar_correction::StripPolars;
use crate::problem::{AncfPath, Block, Formulation, Problem};
use crate::run::{NoObserver, Observer, RunOutput, RunSettings, simulate_with_events};

/// A formulation's model as a problem builds it: [`Structure`] plus its construction and its
/// Newton predictor. A third formulation implements this and adds one line to [`dispatch`].
pub trait BuildModel: Structure + Send + Sync + Sized {
    /// The formulation this model is.
    const FORMULATION: Formulation;
    /// Newton's predictor for this formulation's time steps.
    const PREDICTOR: Predictor;
    /// Build the model of `problem` (its scene and this formulation's options).
    ///
    /// # Errors
    /// [`Error::Model`] when the scene does not validate or the model cannot be built.
    fn build(problem: &Problem) -> Result<Self, Error>;
    /// Build the model of a bare `scene` with this formulation's default options: for work on
    /// a structure alone (modes, statics, a user's own analysis), without a problem's flow and
    /// solver settings.
    ///
    /// # Errors
    /// [`Error::Model`] when the scene does not validate or the model cannot be built.
    fn from_scene(scene: &scene::Scene) -> Result<Self, Error>;
    /// An upper bound of [`Structure::n_unknowns`] for `elements` beam elements on `bodies`
    /// bodies and `joints` joints, before the model is built: what a size budget checks. In
    /// f64, so that a count that cannot fit in memory overflows nothing.
    fn unknowns_bound(elements: f64, bodies: f64, joints: f64) -> f64;
}

impl BuildModel for ancf::Model {
    const FORMULATION: Formulation = Formulation::Ancf;
    /// ANCF's inertia is linear: constant accelerations.
    const PREDICTOR: Predictor = Predictor::ConstantAcceleration;
    fn build(problem: &Problem) -> Result<Self, Error> {
        build_ancf(problem)
    }
    fn from_scene(scene: &scene::Scene) -> Result<Self, Error> {
        ancf::Model::from_scene(scene, ancf::Options::default())
            .map_err(|e| Error::Model { formulation: Self::FORMULATION, msg: e.to_string() })
    }
    /// 12 coordinates per node, one node more than elements per body; at most 12 constraint
    /// rows per joint (a clamp: 12, a hinge: fewer).
    fn unknowns_bound(elements: f64, bodies: f64, joints: f64) -> f64 {
        12.0 * (elements + bodies) + 12.0 * joints
    }
}

impl BuildModel for gebf::Model {
    const FORMULATION: Formulation = Formulation::Gebf;
    /// GEBF starts Newton from extrapolated accelerations: its residual is quadratic in the
    /// floating frames' angular velocities (Coriolis and centrifugal terms of the beam in a
    /// frame spinning at up to 30 rad/s in the c = 0.01 case).
    const PREDICTOR: Predictor = Predictor::ExtrapolatedAcceleration;
    fn build(problem: &Problem) -> Result<Self, Error> {
        build_gebf(problem)
    }
    fn from_scene(scene: &scene::Scene) -> Result<Self, Error> {
        gebf::Model::from_scene(scene, gebf::Options::default())
            .map_err(|e| Error::Model { formulation: Self::FORMULATION, msg: e.to_string() })
    }
    /// Three-node elements: 6 unknowns (R, ψ) on each of the 2 nodes an element adds after a
    /// body's first node, 6 for the body's floating frame, at most 6 constraint rows per joint.
    fn unknowns_bound(elements: f64, bodies: f64, joints: f64) -> f64 {
        12.0 * elements + 6.0 * bodies + 6.0 * joints
    }
}

/// Work generic over a formulation's model type, run by [`dispatch`].
///
/// # Example: a user's own analysis, written once and run for every formulation
///
/// The lowest natural frequency of a clamped cantilever at rest, by the integrator crate's
/// generic linearisation, against Euler–Bernoulli's `1.8751² √(EI / (m L⁴))`:
///
/// ```
/// use aeroelastic::factory::{BuildModel, ForModel, dispatch};
/// use aeroelastic::problem::Formulation;
/// use genalpha::ConstrainedSystem;
///
/// /// The lowest natural frequency (rad/s) of a scene at rest in its reference configuration.
/// struct LowestFrequency<'a>(&'a scene::Scene);
///
/// impl ForModel for LowestFrequency<'_> {
///     type Output = f64;
///     fn run<M: BuildModel>(self) -> f64 {
///         let model = M::from_scene(self.0).expect("a valid scene");
///         let q = model.initial_state().q;
///         let (lambda, mu) = (vec![0.0; model.n_holonomic()], vec![0.0; model.n_velocity_constraints()]);
///         let lin = genalpha::analysis::linearise(&model, 0.0, &q, &lambda, &mu).expect("linearisable");
///         lin.natural_modes().expect("positive mass").omega[0]
///     }
/// }
///
/// // The paper's section (m = 1.08 kg/m, EI = 9.33 N·m²) on a 1 m cantilever, 8 elements.
/// let section = scene::samples::paper_section(1.0);
/// let (bodies, joints) = scene::samples::cantilever(section, 1.0, 8);
/// let cantilever = scene::Scene::new(bodies, joints, nalgebra::Vector3::zeros());
/// let exact = 1.8751_f64.powi(2) * (section.ei_yy / section.mass).sqrt();
/// for f in Formulation::ALL {
///     let omega = dispatch(f, LowestFrequency(&cantilever));
///     assert!((omega / exact - 1.0).abs() < 1e-2, "{f}: {omega} rad/s against {exact}");
/// }
/// ```
pub trait ForModel {
    /// What the work returns.
    type Output;
    /// Do the work with model type `M`.
    fn run<M: BuildModel>(self) -> Self::Output;
}

/// The formulation factory: run `work` with the model type of formulation `f`.
pub fn dispatch<W: ForModel>(f: Formulation, work: W) -> W::Output {
    match f {
        Formulation::Ancf => work.run::<ancf::Model>(),
        Formulation::Gebf => work.run::<gebf::Model>(),
    }
}

/// The Newton predictor of formulation `f` ([`BuildModel::PREDICTOR`]).
pub fn predictor(f: Formulation) -> Predictor {
    struct Of;
    impl ForModel for Of {
        type Output = Predictor;
        fn run<M: BuildModel>(self) -> Predictor {
            M::PREDICTOR
        }
    }
    dispatch(f, Of)
}

/// [`BuildModel::unknowns_bound`] of formulation `f`.
pub fn unknowns_bound(f: Formulation, elements: f64, bodies: f64, joints: f64) -> f64 {
    struct Bound(f64, f64, f64);
    impl ForModel for Bound {
        type Output = f64;
        fn run<M: BuildModel>(self) -> f64 {
            M::unknowns_bound(self.0, self.1, self.2)
        }
    }
    dispatch(f, Bound(elements, bodies, joints))
}

/// The integrator parameters, end time and output interval of formulation `f` of a problem.
pub fn settings(problem: &Problem, f: Formulation) -> RunSettings {
    let Block { dt, rho_inf: rho, newton, form, .. } = problem.block(f);
    let predictor = predictor(f);
    let mut params = genalpha::IntegratorParams::new(rho, dt);
    params.newton = newton.to_params(predictor);
    // Both formulations default to the Arnold–Brüls form. GEBF's energy at rho_inf = 1 is better
    // in the Chung–Hulbert form (the implicit midpoint rule: the β = 45° pendulum's energy error
    // is 1.6e-4 of the peak kinetic energy instead of 1.35e-3), which costs 2 % more work on the
    // c = 1 pendulums and 8–13 % on the soft ones (more Newton iterations where the tip twists,
    // and B at two states), so a case opts in with `gebf.form`. Not even at rho_inf = 1, where
    // it needs fewer Newton iterations on the paper cases: over the stress matrix's 72 GEBF
    // cells at rho_inf = 1 (c × β × dt) it reaches the end at fixed steps in 46 against 51 (it
    // fails on soft tips at 2–5 × dt, where step control then recovers them), although its
    // energy error is 2–100 times smaller in most cells.
    params.form = form.to_form();
    // Wing loads are recorded with aerodynamics (the pendulums' outputs stay as they were).
    let loads = if problem.aero.is_some() { crate::loads::LoadModel::new(problem, f) } else { None };
    RunSettings {
        params,
        t_end: problem.t_end,
        output_dt: problem.output_dt,
        fold_joint: problem.fold_joint_index(),
        roll_joint: problem.roll_joint_index(),
        loads,
        polars: None,
    }
}

/// Build the ANCF model of a problem (DAE or ODE path as the case says).
pub fn build_ancf(problem: &Problem) -> Result<ancf::Model, Error> {
    let path = match problem.ancf.path {
        AncfPath::Dae => ancf::SolvePath::Dae,
        AncfPath::Ode => ancf::SolvePath::Ode,
    };
    let f = <ancf::Model as BuildModel>::FORMULATION;
    ancf::Model::from_scene(&problem.scene(f), ancf::Options { path, ..Default::default() })
        .map_err(|e| Error::Model { formulation: f, msg: e.to_string() })
}

/// Build the GEBF model of a problem.
pub fn build_gebf(problem: &Problem) -> Result<gebf::Model, Error> {
    let options = gebf::Options {
        stabilization: problem.gebf.stabilization,
        conserve_momentum: problem.gebf.conserve_momentum,
        ..Default::default()
    };
    let f = <gebf::Model as BuildModel>::FORMULATION;
    gebf::Model::from_scene(&problem.scene(f), options).map_err(|e| Error::Model { formulation: f, msg: e.to_string() })
}

/// The hinge events of `problem` (resolved to joint indices; names the case validation has
/// checked) with a factory that rebuilds the model of formulation `M` with each hinge's new
/// state, keeping the earlier ones.
pub fn hinge_events<M: BuildModel>(problem: &Problem) -> Events<'static, M> {
    let index = |name: &str| problem.joints.iter().position(|j| j.name() == Some(name));
    let schedule = problem
        .events
        .iter()
        .filter_map(|e| {
            let joint = index(&e.joint)?;
            let when = match (e.time, &e.when) {
                (Some(t), _) => When::Time(t),
                (None, Some(w)) => match (w.root_bending_moment_above, w.root_bending_moment_increment_above) {
                    (Some(m), _) => When::RootBendingMoment(m),
                    (None, Some(m)) => When::RootBendingMomentIncrement(m),
                    (None, None) => When::Fold {
                        joint: w.joint.as_deref().map_or(Some(joint), index)?,
                        above: w.fold_deg_above.map_or(f64::INFINITY, f64::to_radians),
                        below: w.fold_deg_below.map_or(f64::NEG_INFINITY, f64::to_radians),
                    },
                },
                (None, None) => return None,
            };
            Some(ScheduledEvent { when, joint, action: e.action })
        })
        .collect();
    let mut current = problem.clone();
    let rebuild = move |joint: usize, lock: Option<f64>| {
        let Some(crate::problem::Joint::FlaredHinge { locked, lock_deg, .. }) = current.joints.get_mut(joint) else {
            return Err(format!("joint {joint} is not a flared hinge"));
        };
        match (*locked, lock.is_some()) {
            (true, true) => return Err("the hinge is already locked".into()),
            (false, false) => return Err("the hinge is not locked".into()),
            _ => {}
        }
        *locked = lock.is_some();
        *lock_deg = lock.map_or(0.0, f64::to_degrees);
        M::build(&current).map_err(|e| e.to_string())
    };
    Events::new(schedule, Box::new(rebuild))
}

/// A time march from the trimmed state (`initial: "trim"`, docs/trim.md §5): the trim with the
/// march's own wake, then the march of the free aircraft in body axes from the trimmed
/// coordinates, at rest, with the steady wake prefilled and its loads applied. With
/// `initial: "trim_held"` the aircraft stays held at its free body (docs/trim.md §6): the
/// trim's held equilibrium marched, its earth frame the wind tunnel's (turned by α, at rest).
fn from_trim<M: BuildModel>(
    problem: &Problem,
    f: Formulation,
    observer: &mut dyn Observer,
) -> Result<RunOutput, Error> {
    let model_error = |msg: String| Error::Model { formulation: f, msg };
    let (flight, trim) = crate::trim::trim_for_march::<M>(problem, f).map_err(model_error)?;
    let (Some(aero), Some(aero0)) = (flight.aero.as_ref(), problem.aero.as_ref()) else {
        return Err(model_error(format!("initial: \"{}\" needs `aero`", problem.initial.name())));
    };
    // The lattice's layout of the reference flow, as the trim has it.
    let map = station_map(problem, aero0).map_err(model_error)?;
    let mut s = settings(&flight, f);
    // The trim's polars correct the march's loads too, so the trimmed state is its equilibrium.
    s.polars = StripPolars::of(&flight).map_err(model_error)?;
    let mut events = hinge_events::<M>(&flight);
    let mut model = M::build(&flight)?;
    // Body axes turned back by α, moving against the reference flow: the earth frame.
    let rotation =
        *nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), trim.alpha_deg.to_radians()).matrix();
    let velocity = if problem.initial == crate::trim::Initial::TrimHeld {
        nalgebra::Vector3::zeros()
    } else {
        -nalgebra::Vector3::from(aero0.stream_without_sideslip())
    };
    let mut earth = EarthAxes { inner: observer, rotation, velocity };
    Ok(simulate_aero_with_events(f, &mut model, &s, aero, &map, &mut earth, Some(&trim.q), &mut events))
}

/// Hands the snapshots of a run in body axes on with their earth placement: the axes turned by
/// `rotation` and moving at `velocity` from the origin at t = 0.
struct EarthAxes<'o> {
    inner: &'o mut dyn Observer,
    rotation: nalgebra::Matrix3<f64>,
    velocity: nalgebra::Vector3<f64>,
}

impl Observer for EarthAxes<'_> {
    fn wants_snapshots(&self) -> bool {
        self.inner.wants_snapshots()
    }

    fn observe(&mut self, s: &crate::run::Snapshot<'_>) -> Result<(), String> {
        let placement = crate::run::Placement { rotation: self.rotation, shift: self.velocity * s.t };
        let moved =
            crate::run::Snapshot { index: s.index, t: s.t, beams: s.beams, aero: s.aero, placement: Some(placement) };
        self.inner.observe(&moved)
    }

    fn row(&mut self, row: &crate::run::Row) -> Result<(), String> {
        self.inner.row(row)
    }
}

/// Build and integrate formulation `f` of `case`. Never panics on bad input: a model that cannot
/// be built gives a failed [`RunOutput`] with the reason.
pub fn run_formulation(problem: &Problem, f: Formulation) -> RunOutput {
    run_formulation_observed(problem, f, &mut NoObserver)
}

/// As [`run_formulation`], handing every output step's geometry to `observer`.
pub fn run_formulation_observed(problem: &Problem, f: Formulation, observer: &mut dyn Observer) -> RunOutput {
    struct Run<'a, 'o> {
        problem: &'a Problem,
        f: Formulation,
        observer: &'o mut dyn Observer,
    }
    impl ForModel for Run<'_, '_> {
        type Output = Result<RunOutput, Error>;
        fn run<M: BuildModel>(self) -> Self::Output {
            let Run { problem, f, observer } = self;
            let model_error = |msg: String| Error::Model { formulation: f, msg };
            crate::section_polars::refuse_tip_loss(problem, "time march").map_err(model_error)?;
            if problem.initial.is_trim() {
                return from_trim::<M>(problem, f, observer);
            }
            let mut s = settings(problem, f);
            let mut events = hinge_events::<M>(problem);
            match &problem.aero {
                None => {
                    M::build(problem).map(|mut model| simulate_with_events(f, &mut model, &s, observer, &mut events))
                }
                Some(aero) if aero.model == crate::aero_settings::AeroModel::Strip => {
                    if events.any() {
                        let msg = "events: hinge events with `aero.model: \"strip\"` are not implemented".into();
                        return Err(Error::Model { formulation: f, msg });
                    }
                    let map = station_map(problem, aero).map_err(model_error)?;
                    s.polars = StripPolars::of(problem).map_err(model_error)?;
                    M::build(problem)
                        .map(|mut model| crate::strip_march::simulate_strip(f, &mut model, &s, aero, &map, observer))
                }
                Some(aero) => {
                    let map = station_map(problem, aero).map_err(model_error)?;
                    s.polars = StripPolars::of(problem).map_err(model_error)?;
                    M::build(problem).map(|mut model| {
                        simulate_aero_with_events(f, &mut model, &s, aero, &map, observer, None, &mut events)
                    })
                }
            }
        }
    }
    dispatch(f, Run { problem, f, observer }).unwrap_or_else(|e| RunOutput::failed(f, e.to_string()))
}
