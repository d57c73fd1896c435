//! Hinge events: a flared hinge locked or released during a time march (docs/coupling.md §8).
//!
//! An event changes the constraint set, so the model is rebuilt with the hinge's new state and
//! the march restarts from the current coordinates and velocities, as a run started there would:
//!
//! * **release**: the locked hinge becomes free; positions and velocities carry over unchanged
//!   (the weld's reaction simply stops), and the integrator starts afresh with consistent
//!   accelerations ([`genalpha::GenAlpha::initialize`]);
//! * **lock**: the free hinge is welded at its current fold angle. The relative rotation rate
//!   about the hinge axis cannot survive, so the velocities jump to the admissible ones closest
//!   in kinetic energy ([`genalpha::analysis::impact`], a perfectly inelastic impact), and the
//!   kinetic energy lost, `½ Δvᵀ M Δv`, is reported in [`EventRecord::energy_loss`] and joins the
//!   dissipated work of the energy balance.
//!
//! A timed event takes effect at the end of the step nearest its time (the nominal steps of
//! `dt` are kept: no step is shortened); a triggered one ([`Trigger`]: a fold angle or the root
//! bending moment past a threshold) at the end of the first step where its condition holds, as
//! a gust-triggered release or a lock at a fold stop. Either is recorded with the time it acted,
//! [`EventRecord::time`].

use formulation::{SectionLoad, Structure};
use genalpha::{GenAlpha, IntegratorParams, State};

/// What an event does to its hinge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum HingeAction {
    /// Weld the hinge at its current fold angle (an inelastic event: its energy loss is
    /// reported).
    Lock,
    /// Free a locked hinge.
    Release,
}

impl HingeAction {
    /// The case file's word for it.
    pub fn as_str(self) -> &'static str {
        match self {
            HingeAction::Lock => "lock",
            HingeAction::Release => "release",
        }
    }
}

/// A hinge event of a case: `action` on the flared hinge named `joint`, at `time` or when the
/// condition `when` first holds (exactly one of the two).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct HingeEvent {
    /// Time, s, in (0, t_end]; the event acts at the end of the step nearest it.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub time: Option<f64>,
    /// The condition that triggers the event, checked at the end of every step; it acts once,
    /// at the first step where it holds.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub when: Option<Trigger>,
    /// Name of the flared hinge (`joints[k].name`).
    pub joint: String,
    /// `"lock"` or `"release"`.
    pub action: HingeAction,
}

/// The condition of a triggered event: exactly one threshold.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Trigger {
    /// The flared hinge whose fold angle is watched (default: the event's own `joint`).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub joint: Option<String>,
    /// Fires when that fold angle exceeds this, degrees (fold up positive).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub fold_deg_above: Option<f64>,
    /// Fires when that fold angle falls below this, degrees.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub fold_deg_below: Option<f64>,
    /// Fires when the root bending moment at the clamp exceeds this, N·m (lift bending the wing
    /// up positive; needs `aero` and a clamp or a `root_joint`: the `root_bending_moment` column).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub root_bending_moment_above: Option<f64>,
    /// Fires when the root bending moment exceeds its value at the start of the run by this,
    /// N·m (a gust's increment over the equilibrium it starts from; needs `aero` and a clamp or a
    /// `root_joint`).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub root_bending_moment_increment_above: Option<f64>,
}

/// When a scheduled event acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum When {
    /// At the end of the step nearest this time, s.
    Time(f64),
    /// When the fold of flared hinge `joint` (index) exceeds `above` or falls below `below`
    /// (rad).
    Fold {
        /// The watched hinge's index.
        joint: usize,
        /// Upper threshold, rad.
        above: f64,
        /// Lower threshold, rad.
        below: f64,
    },
    /// When the root bending moment exceeds this, N·m.
    RootBendingMoment(f64),
    /// When the root bending moment exceeds its value at the start by this, N·m.
    RootBendingMomentIncrement(f64),
}

/// An event as it happened in a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventRecord {
    /// Time the event acted (the end of a step), s.
    pub time: f64,
    /// Index of the hinge in the case's joints.
    pub joint: usize,
    /// What it did.
    pub action: HingeAction,
    /// Fold angle of the hinge when it acted, rad.
    pub fold: f64,
    /// Kinetic energy the lock removed, J (0 for a release).
    pub energy_loss: f64,
}

/// An event of the schedule, resolved to a joint index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduledEvent {
    /// When it acts.
    pub when: When,
    /// Index of the hinge in the problem's joints.
    pub joint: usize,
    /// What it does.
    pub action: HingeAction,
}

/// Builds the model with one hinge changed: `(joint, Some(fold))` welds it at `fold` (rad),
/// `(joint, None)` frees it. Earlier changes persist.
pub type Rebuild<'a, S> = Box<dyn FnMut(usize, Option<f64>) -> Result<S, String> + 'a>;

/// The events of a run still to come, how to rebuild the model for each, and what happened.
pub struct Events<'a, S> {
    /// Pending timed events, latest first (popped from the end).
    pending: Vec<ScheduledEvent>,
    /// Pending triggered events, in the case's order.
    triggered: Vec<ScheduledEvent>,
    rebuild: Rebuild<'a, S>,
    /// The events that acted, in order.
    pub records: Vec<EventRecord>,
    /// Counters of the integrators the events replaced.
    replaced: genalpha::Stats,
    /// The root bending moment at the start of the run, N·m (NaN until set).
    rbm_start: f64,
}

impl<'a, S: Structure> Events<'a, S> {
    /// The schedule `events` (any order) with the model factory `rebuild`.
    pub fn new(events: Vec<ScheduledEvent>, rebuild: Rebuild<'a, S>) -> Self {
        let time = |e: &ScheduledEvent| match e.when {
            When::Time(t) => t,
            _ => f64::NAN,
        };
        let (mut pending, triggered): (Vec<_>, Vec<_>) =
            events.into_iter().partition(|e| matches!(e.when, When::Time(_)));
        pending.sort_by(|a, b| time(b).total_cmp(&time(a)));
        Self {
            pending,
            triggered,
            rebuild,
            records: Vec::new(),
            replaced: genalpha::Stats::default(),
            rbm_start: f64::NAN,
        }
    }

    /// The root bending moment at the start of the run, the reference of
    /// [`When::RootBendingMomentIncrement`], N·m.
    pub fn set_root_bending_moment_start(&mut self, m: f64) {
        self.rbm_start = m;
    }

    /// Whether a pending event watches the root bending moment (which the march then evaluates
    /// at every step).
    pub fn watches_root_bending_moment(&self) -> bool {
        self.triggered
            .iter()
            .any(|e| matches!(e.when, When::RootBendingMoment(_) | When::RootBendingMomentIncrement(_)))
    }

    /// Whether `e`'s condition holds at `s` (`rbm`: the root bending moment there, NaN unknown).
    fn holds(&self, e: &ScheduledEvent, model: &S, s: &State, dt: f64, rbm: f64) -> bool {
        match e.when {
            When::Time(t) => t < s.t + 0.5 * dt,
            When::Fold { joint, above, below } => {
                let fold = model.fold(&s.q, joint);
                fold > above || fold < below
            }
            When::RootBendingMoment(m) => rbm > m,
            When::RootBendingMomentIncrement(m) => rbm - self.rbm_start > m,
        }
    }

    /// No events at all.
    pub fn none() -> Self {
        Self::new(Vec::new(), Box::new(|_, _| Err("no events".into())))
    }

    /// Whether the run has any events (scheduled or done).
    pub fn any(&self) -> bool {
        !self.pending.is_empty() || !self.triggered.is_empty() || !self.records.is_empty()
    }

    /// Apply every event due at the end of a step that reached `s.t` (steps of `dt`; `rbm` the
    /// root bending moment there, NaN when unknown): rebuild the model, carry the state over
    /// (projecting the velocities on a lock), apply `loads` to the new model, and restart the
    /// integrator `ga`. Returns the energy the locks removed, or `None` when no event was due.
    ///
    /// # Errors
    /// The event, its time and the reason, when the new model cannot be built, has other
    /// coordinates, or cannot start.
    pub fn apply_due(
        &mut self,
        model: &mut S,
        ga: &mut GenAlpha<S::Solver>,
        s: &mut State,
        params: IntegratorParams,
        loads: &[SectionLoad],
        rbm: f64,
    ) -> Result<Option<f64>, String> {
        let mut loss = None;
        loop {
            // The timed events due, in time order, then the triggered ones whose condition holds
            // (checked on the state as the earlier events of this step left it).
            let e = if self.pending.last().is_some_and(|e| self.holds(e, model, s, params.dt, rbm)) {
                self.pending.pop().expect("checked above")
            } else if let Some(k) = self.triggered.iter().position(|e| self.holds(e, model, s, params.dt, rbm)) {
                self.triggered.remove(k)
            } else {
                break;
            };
            let what = format!("event {} of joint {} at t = {} s", e.action.as_str(), e.joint, s.t);
            let rec = self.apply(e, model, ga, s, params, loads).map_err(|m| format!("{what}: {m}"))?;
            *loss.get_or_insert(0.0) += rec.energy_loss;
            self.records.push(rec);
        }
        Ok(loss)
    }

    /// The counters of the whole run: those of the integrators the events replaced plus `last`'s.
    pub fn total_stats(&self, last: &genalpha::Stats) -> genalpha::Stats {
        let mut s = self.replaced;
        add_stats(&mut s, last);
        s
    }

    fn apply(
        &mut self,
        e: ScheduledEvent,
        model: &mut S,
        ga: &mut GenAlpha<S::Solver>,
        s: &mut State,
        params: IntegratorParams,
        loads: &[SectionLoad],
    ) -> Result<EventRecord, String> {
        let fold = model.fold(&s.q, e.joint);
        if !fold.is_finite() {
            return Err("the joint is not a flared hinge".into());
        }
        let lock = matches!(e.action, HingeAction::Lock).then_some(fold);
        let mut new = (self.rebuild)(e.joint, lock)?;
        let (q, v) = new.carry_state(model, &s.q, &s.v)?;
        // Carried into other coordinates (ANCF's ODE path), the velocities are projected onto the
        // new model's admissible ones: the kinetic energy that removed is an impact's (a lock's,
        // and a release's small one where a weld's state does not meet the hinge's equations).
        let mut energy_loss = if q.len() != s.q.len() || v.len() != s.v.len() {
            (model.energies(&s.q, &s.v).kinetic - new.energies(&q, &v).kinetic).max(0.0)
        } else {
            0.0
        };
        (s.q, s.v) = (q, v);
        s.v_dot.resize(s.v.len(), 0.0);
        s.a.resize(s.v.len(), 0.0);
        new.set_section_loads(loads).map_err(|err| err.to_string())?;
        if lock.is_some() {
            let hit = genalpha::analysis::impact(&new, s.t, &s.q, &s.v).map_err(|err| err.to_string())?;
            s.v.copy_from_slice(&hit.velocities);
            energy_loss += hit.energy_loss;
        }
        let fresh = new.initial_state();
        s.lambda = fresh.lambda;
        s.mu = fresh.mu;
        let mut restarted = new.integrator(params).map_err(|err| err.to_string())?;
        restarted.initialize(&new, s).map_err(|err| format!("accelerations after the event: {err}"))?;
        *model = new;
        model.start_march(s.t, &s.q, &s.v);
        add_stats(&mut self.replaced, ga.stats());
        *ga = restarted;
        Ok(EventRecord { time: s.t, joint: e.joint, action: e.action, fold, energy_loss })
    }
}

/// `a += b`, counter by counter (the largest Newton count is the larger of the two).
fn add_stats(a: &mut genalpha::Stats, b: &genalpha::Stats) {
    a.n_steps += b.n_steps;
    a.n_newton_iters += b.n_newton_iters;
    a.max_newton_iters = a.max_newton_iters.max(b.max_newton_iters);
    a.n_factorizations += b.n_factorizations;
    a.n_residual_evals += b.n_residual_evals;
    a.n_step_halvings += b.n_step_halvings;
}
