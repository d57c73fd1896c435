//! Integrating one formulation of one case and recording the sensors of docs/conventions.md §5.

use std::time::Instant;

use genalpha::{IntegratorParams, State, Stats};

use crate::events::Events;
use crate::problem::Formulation;

pub use formulation::{BeamGeometry, Energies, Structure};

/// What a run hands its [`Observer`] at every output step: the time, every body's nodes with their
/// section frames, and the aerodynamic state (lattice, bound circulation, wake) when the case has
/// one. Borrowed: an observer copies what it keeps.
pub struct Snapshot<'a> {
    /// Output row index (0 at the initial state).
    pub index: usize,
    /// Time, s.
    pub t: f64,
    /// One entry per body.
    pub beams: &'a [BeamGeometry],
    /// The UVLM after the step (lattice, `gamma()`, `wake()`, `loads()`), if any.
    pub aero: Option<&'a uvlm::Uvlm>,
    /// Where the run's axes are in the earth frame at this step, when they move (a flight from
    /// its trim runs in body axes, docs/trim.md §5); none: the run's axes are the earth's.
    pub placement: Option<Placement>,
}

/// The earth placement of a run's axes at one step: `x_earth = rotation · x + shift`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Rotation from the run's axes to the earth's.
    pub rotation: nalgebra::Matrix3<f64>,
    /// The run's origin in the earth frame, m.
    pub shift: nalgebra::Vector3<f64>,
}

impl Placement {
    /// A point of the run's axes in the earth frame.
    pub fn point(&self, p: &nalgebra::Vector3<f64>) -> nalgebra::Vector3<f64> {
        self.rotation * p + self.shift
    }

    /// A frame (columns in the run's axes) in the earth frame.
    pub fn frame(&self, r: &nalgebra::Matrix3<f64>) -> nalgebra::Matrix3<f64> {
        self.rotation * r
    }
}

/// Receives each output step's geometry (3-D output, animation, probes): the output seam. The time
/// loops call it; a new output format implements it and touches no loop.
pub trait Observer {
    /// Whether the run should assemble snapshots at all (false: no geometry is computed).
    fn wants_snapshots(&self) -> bool {
        true
    }
    /// One output step. An error stops the run with the message.
    fn observe(&mut self, snapshot: &Snapshot<'_>) -> Result<(), String>;
    /// The row of an output step, as it is recorded (before [`observe`](Self::observe) of the same
    /// step; called whether or not the observer wants snapshots). Default: nothing. An error
    /// stops the run with the message.
    fn row(&mut self, _row: &Row) -> Result<(), String> {
        Ok(())
    }
}

/// The observer of a run that records only its rows.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;

impl Observer for NoObserver {
    fn wants_snapshots(&self) -> bool {
        false
    }
    fn observe(&mut self, _: &Snapshot<'_>) -> Result<(), String> {
        Ok(())
    }
}

/// Builds snapshots with reused storage and hands them to an observer.
pub(crate) struct SnapshotFeed<'o> {
    observer: &'o mut dyn Observer,
    beams: Vec<BeamGeometry>,
    index: usize,
}

impl<'o> SnapshotFeed<'o> {
    pub(crate) fn new(observer: &'o mut dyn Observer) -> Self {
        Self { observer, beams: Vec::new(), index: 0 }
    }

    /// Hand the output step's row, and its state `q` (and the UVLM, if any), to the observer.
    pub(crate) fn feed<S: Structure + ?Sized>(
        &mut self,
        model: &S,
        row: &Row,
        q: &[f64],
        aero: Option<&uvlm::Uvlm>,
    ) -> Result<(), String> {
        let index = self.index;
        let t = row.t;
        self.index += 1;
        self.observer.row(row)?;
        if !self.observer.wants_snapshots() {
            return Ok(());
        }
        self.beams.resize_with(model.n_bodies(), BeamGeometry::default);
        for (b, g) in self.beams.iter_mut().enumerate() {
            model.body_geometry(q, b, g);
        }
        self.observer.observe(&Snapshot { index, t, beams: &self.beams, aero, placement: None })
    }
}

/// One output row (the CSV columns).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Row {
    /// Time, s.
    pub t: f64,
    /// Tip position, m.
    pub tip: [f64; 3],
    /// Fold angle, rad.
    pub fold: f64,
    /// Rate of the `roll_joint`'s angle, rad/s (NaN without one).
    pub roll_rate: f64,
    /// Kinetic energy, J.
    pub kinetic: f64,
    /// Elastic energy, J.
    pub elastic: f64,
    /// Gravitational potential, J.
    pub potential: f64,
    /// Hinge spring potential, J (NaN without force elements).
    pub spring: f64,
    /// Work dissipated by the dampers since t = 0, J (NaN without force elements).
    pub dissipated: f64,
    /// Total energy T + U + V (+ spring potential), J.
    pub total: f64,
    /// Work done by the thrusts since t = 0, J (NaN without thrust).
    pub thrust_work: f64,
    /// Position-level constraint residual.
    pub constraint_residual: f64,
    /// Newton iterations of the step that reached this row.
    pub newton_iterations: usize,
    /// Work done by the aerodynamic loads since t = 0, J (NaN without aerodynamics).
    pub aero_work: f64,
    /// Aerodynamic lift, N (NaN without aerodynamics).
    pub lift: f64,
    /// Root bending moment at the clamp, N·m (positive when lift bends the wing up; NaN
    /// without a clamp or without aerodynamics; see [`crate::loads`]).
    pub root_bending_moment: f64,
    /// Root torque at the clamp, N·m (nose-up positive; NaN as `root_bending_moment`).
    pub root_torque: f64,
    /// Moment about the fold hinge's axis, N·m (fold-up positive; NaN without one or without
    /// aerodynamics).
    pub hinge_moment: f64,
    /// Hinge moment of each control surface (`aero.control_surfaces`, in order), N·m, trailing
    /// edge down positive (docs/uvlm.md §15); NaN past the case's surfaces.
    pub control_hinge_moments: [f64; crate::control_surface::MAX_CONTROL_SURFACES],
}

/// Solver settings of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSettings {
    /// Integrator parameters.
    pub params: IntegratorParams,
    /// End time, s.
    pub t_end: f64,
    /// Output interval, s (None: every step).
    pub output_dt: Option<f64>,
    /// The flared hinge whose fold angle is the `fold` column (None: NaN).
    pub fold_joint: Option<usize>,
    /// The ground hinge whose rate is the `roll_rate` column (None: NaN, no column).
    pub roll_joint: Option<usize>,
    /// The free bodies of the wing loads columns (None: NaN).
    pub loads: Option<crate::loads::LoadModel>,
    /// The section polars that correct the lattice's strip loads in the time march
    /// (docs/section_aero.md §7; none: uncorrected). [`crate::factory::settings`] leaves them
    /// unset: the analyses that apply them set them from the problem
    /// ([`crate::polar_correction::StripPolars::of`]).
    pub polars: Option<crate::polar_correction::StripPolars>,
}

impl RunSettings {
    /// Steps of the march over `[0, t_end]` (validated cases hold a whole number of steps within
    /// a relative 1e-9: rounded), at least one.
    pub fn n_steps(&self) -> usize {
        (self.t_end / self.params.dt).round().max(1.0) as usize
    }

    /// Steps between output rows (every step without `output_dt`), at least one.
    pub fn output_every(&self) -> usize {
        self.output_dt.map_or(1, |o| ((o / self.params.dt).round() as usize).max(1))
    }
}

/// Outcome of one run: what was computed, even when it failed part-way.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// Formulation.
    pub formulation: Formulation,
    /// Recorded rows.
    pub rows: Vec<Row>,
    /// Wall time of model set-up plus the time loop, s.
    pub wall_s: f64,
    /// Integrator counters.
    pub stats: Stats,
    /// Tangent dimension of the model.
    pub n_dof: usize,
    /// Why the run stopped early, if it did.
    pub error: Option<String>,
    /// Wall time spent in the aerodynamics, s (0 without).
    pub aero_wall_s: f64,
    /// Aerodynamic solves of the time march (0 without aerodynamics): one per step loosely
    /// coupled, one per sub-iteration (and the predictor's, docs/coupling.md §4) strongly.
    pub aero_solves: usize,
    /// Time steps marched with the aerodynamics (the structure's steps, `stats.n_steps`, also
    /// count the sub-iterations' repeats).
    pub aero_steps: usize,
    /// The hinge events that acted, in order.
    pub events: Vec<crate::events::EventRecord>,
    /// The lattice's strips at the last solve with the section polars' correction (lift per span
    /// and its coefficient at the free stream's dynamic pressure, effective incidence); empty
    /// without `aero.polars`.
    pub strips: Vec<crate::statics::Strip>,
}

impl RunOutput {
    /// A run that could not even start.
    pub fn failed(formulation: Formulation, error: String) -> Self {
        Self {
            formulation,
            rows: Vec::new(),
            wall_s: 0.0,
            stats: Stats::default(),
            n_dof: 0,
            error: Some(error),
            aero_wall_s: 0.0,
            aero_solves: 0,
            aero_steps: 0,
            events: Vec::new(),
            strips: Vec::new(),
        }
    }
}

/// The sensors of `model` at state `s` (aerodynamic columns NaN).
pub fn row<S: Structure + ?Sized>(
    model: &S,
    (fold_joint, roll_joint): (Option<usize>, Option<usize>),
    s: &State,
    newton_iterations: usize,
) -> Row {
    let e = model.energies(&s.q, &s.v);
    let springs = model.has_force_elements();
    Row {
        t: s.t,
        tip: model.tip(&s.q),
        fold: fold_joint.map_or(f64::NAN, |j| model.fold(&s.q, j)),
        roll_rate: roll_joint.map_or(f64::NAN, |j| model.hinge_rate(&s.q, &s.v, j)),
        kinetic: e.kinetic,
        elastic: e.elastic,
        potential: e.potential,
        spring: if springs { e.spring } else { f64::NAN },
        dissipated: if springs { 0.0 } else { f64::NAN },
        total: if springs {
            e.kinetic + e.elastic + e.potential + e.spring
        } else {
            e.kinetic + e.elastic + e.potential
        },
        thrust_work: if model.has_external_power() { 0.0 } else { f64::NAN },
        constraint_residual: model.constraint_residual(&s.q),
        newton_iterations,
        aero_work: f64::NAN,
        lift: f64::NAN,
        root_bending_moment: f64::NAN,
        root_torque: f64::NAN,
        hinge_moment: f64::NAN,
        control_hinge_moments: [f64::NAN; crate::control_surface::MAX_CONTROL_SURFACES],
    }
}

/// Work dissipated by the dampers and work done by the thrusts: the trapezoidal rule on each
/// power over every accepted step (the rule the generalized-α energy balance follows at
/// rho_inf = 1).
pub(crate) struct Dissipation {
    on: bool,
    t: f64,
    power: f64,
    work: f64,
    /// Whether the model has thrusts.
    thrust: bool,
    /// Their power at `t`, W.
    thrust_power: f64,
    /// Their work since t = 0, J.
    thrust_work: f64,
}

impl Dissipation {
    /// The dampers of `model` from state `s`; `events`: the run has hinge events, whose locks'
    /// losses join the dissipated work (and put the spring and dissipated columns on).
    pub(crate) fn new<S: Structure + ?Sized>(model: &S, s: &State, events: bool) -> Self {
        let on = model.has_force_elements() || events;
        let thrust = model.has_external_power();
        Self {
            on,
            t: s.t,
            power: if on { model.dissipation_power(&s.q, &s.v) } else { 0.0 },
            work: 0.0,
            thrust,
            thrust_power: if thrust { model.external_power(s.t, &s.q, &s.v) } else { 0.0 },
            thrust_work: 0.0,
        }
    }

    /// Account for energy an event removed (a hinge lock's impact), J.
    pub(crate) fn add_loss(&mut self, loss: f64) {
        self.work += loss;
    }

    /// Restart the power's trapezoid at state `s` of `model` (after a model change).
    pub(crate) fn restart<S: Structure + ?Sized>(&mut self, model: &S, s: &State) {
        if self.on {
            self.power = model.dissipation_power(&s.q, &s.v);
        }
        if self.thrust {
            self.thrust_power = model.external_power(s.t, &s.q, &s.v);
        }
        self.t = s.t;
    }

    /// Account for the step that ended at state `s`.
    pub(crate) fn step<S: Structure + ?Sized>(&mut self, model: &S, s: &State) {
        if self.on {
            let p = model.dissipation_power(&s.q, &s.v);
            self.work += 0.5 * (s.t - self.t) * (self.power + p);
            self.power = p;
        }
        if self.thrust {
            let p = model.external_power(s.t, &s.q, &s.v);
            self.thrust_work += 0.5 * (s.t - self.t) * (self.thrust_power + p);
            self.thrust_power = p;
        }
        self.t = s.t;
    }

    /// The row with the work dissipated and the thrusts' work so far.
    pub(crate) fn record(&self, mut r: Row) -> Row {
        if self.thrust {
            r.thrust_work = self.thrust_work;
        }
        if self.on {
            r.dissipated = self.work;
            if r.spring.is_nan() {
                // A model without springs in a run with events: no spring energy.
                r.spring = 0.0;
            }
        }
        r
    }
}

/// The error of a run stopped by SIGINT or SIGTERM after the step that reached `t`.
pub fn interrupted_message(t: f64) -> String {
    format!("{INTERRUPTED} at t = {t} s (SIGINT or SIGTERM)")
}

/// How the error of a run stopped by a signal starts.
pub const INTERRUPTED: &str = "interrupted";

/// Integrate `model` from its reference state to `t_end`, recording rows and handing each output
/// step to `observer`. A Newton failure ends the run with `error` set and the rows computed so far.
pub fn simulate<S: Structure>(
    formulation: Formulation,
    model: &mut S,
    settings: &RunSettings,
    observer: &mut dyn Observer,
) -> RunOutput {
    simulate_with_events(formulation, model, settings, observer, &mut Events::none())
}

/// [`simulate`] with hinge events ([`crate::events`]): each one rebuilds `model` and restarts
/// the integrator at the end of the step nearest its time; what happened is in
/// `RunOutput::events`.
pub fn simulate_with_events<S: Structure>(
    formulation: Formulation,
    model: &mut S,
    settings: &RunSettings,
    observer: &mut dyn Observer,
    events: &mut Events<'_, S>,
) -> RunOutput {
    let start = Instant::now();
    let mut out = RunOutput {
        formulation,
        rows: Vec::new(),
        wall_s: 0.0,
        stats: Stats::default(),
        n_dof: model.n_dof(),
        error: None,
        aero_wall_s: 0.0,
        aero_solves: 0,
        aero_steps: 0,
        events: Vec::new(),
        strips: Vec::new(),
    };
    let n_steps = settings.n_steps();
    let every = settings.output_every();
    // Reserve for the expected rows, but never more than a bounded guess up front: the count
    // comes from user input (`dt`, `t_end`) and the vector grows as rows arrive anyway.
    out.rows.reserve((n_steps / every + 2).min(1 << 16));
    let mut ga = match model.integrator(settings.params) {
        Ok(g) => g,
        Err(e) => {
            out.error = Some(e.to_string());
            return out;
        }
    };
    let mut s = model.initial_state();
    if let Err(e) = ga.initialize(model, &mut s) {
        out.error = Some(format!("initial accelerations: {e}"));
        return out;
    }
    model.start_march(s.t, &s.q, &s.v);
    let fold = (settings.fold_joint, settings.roll_joint);
    let mut feed = SnapshotFeed::new(observer);
    let mut dissipation = Dissipation::new(model, &s, events.any());
    let r0 = dissipation.record(row(model, fold, &s, 0));
    out.rows.push(r0);
    if let Err(e) = feed.feed(model, &r0, &s.q, None) {
        out.error = Some(format!("output at t = {}: {e}", s.t));
        return out;
    }
    for k in 1..=n_steps {
        if crate::interrupt::interrupted() {
            out.error = Some(interrupted_message(s.t));
            break;
        }
        match ga.step(model, &mut s) {
            Ok(st) => {
                dissipation.step(model, &s);
                match events.apply_due(model, &mut ga, &mut s, settings.params, &[], f64::NAN) {
                    Ok(Some(loss)) => {
                        dissipation.add_loss(loss);
                        dissipation.restart(model, &s);
                    }
                    Ok(None) => {}
                    Err(e) => {
                        out.error = Some(format!("step {k}: {e}"));
                        break;
                    }
                }
                if k % every == 0 || k == n_steps {
                    let r = dissipation.record(row(model, fold, &s, st.n_newton_iters));
                    out.rows.push(r);
                    if let Err(e) = feed.feed(model, &r, &s.q, None) {
                        out.error = Some(format!("step {k}: output: {e}"));
                        break;
                    }
                }
            }
            Err(e) => {
                out.error = Some(format!("step {k}: {e}"));
                break;
            }
        }
    }
    out.stats = events.total_stats(ga.stats());
    out.events = events.records.clone();
    out.wall_s = start.elapsed().as_secs_f64();
    out
}
