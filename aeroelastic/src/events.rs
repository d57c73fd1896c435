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
//! The event takes effect at the end of the step nearest its time (the nominal steps of
//! `dt` are kept: no step is shortened), recorded as [`EventRecord::time`].

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

/// A hinge event of a case: at `time`, `action` on the flared hinge named `joint`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct HingeEvent {
    /// Time, s, in (0, t_end]; the event acts at the end of the step nearest it.
    pub time: f64,
    /// Name of the flared hinge (`joints[k].name`).
    pub joint: String,
    /// `"lock"` or `"release"`.
    pub action: HingeAction,
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
    /// Time, s.
    pub time: f64,
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
    /// Pending events, latest first (popped from the end).
    pending: Vec<ScheduledEvent>,
    rebuild: Rebuild<'a, S>,
    /// The events that acted, in order.
    pub records: Vec<EventRecord>,
    /// Counters of the integrators the events replaced.
    replaced: genalpha::Stats,
}

impl<'a, S: Structure> Events<'a, S> {
    /// The schedule `events` (any order) with the model factory `rebuild`.
    pub fn new(mut events: Vec<ScheduledEvent>, rebuild: Rebuild<'a, S>) -> Self {
        events.sort_by(|a, b| b.time.total_cmp(&a.time));
        Self { pending: events, rebuild, records: Vec::new(), replaced: genalpha::Stats::default() }
    }

    /// No events at all.
    pub fn none() -> Self {
        Self::new(Vec::new(), Box::new(|_, _| Err("no events".into())))
    }

    /// Whether the run has any events (scheduled or done).
    pub fn any(&self) -> bool {
        !self.pending.is_empty() || !self.records.is_empty()
    }

    /// Apply every event due at the end of a step that reached `s.t` (steps of `dt`): rebuild
    /// the model, carry the state over (projecting the velocities on a lock), apply `loads` to
    /// the new model, and restart the integrator `ga`. Returns the energy the locks removed, or
    /// `None` when no event was due.
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
    ) -> Result<Option<f64>, String> {
        let mut loss = None;
        while self.pending.last().is_some_and(|e| e.time < s.t + 0.5 * params.dt) {
            let e = self.pending.pop().expect("checked above");
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
        if new.n_coords() != s.q.len() || new.n_dof() != s.v.len() {
            return Err(format!(
                "the new model has {} coordinates and {} velocities, not {} and {}",
                new.n_coords(),
                new.n_dof(),
                s.q.len(),
                s.v.len()
            ));
        }
        new.set_section_loads(loads).map_err(|err| err.to_string())?;
        let mut energy_loss = 0.0;
        if lock.is_some() {
            let hit = genalpha::analysis::impact(&new, s.t, &s.q, &s.v).map_err(|err| err.to_string())?;
            s.v.copy_from_slice(&hit.velocities);
            energy_loss = hit.energy_loss;
        }
        let fresh = new.initial_state();
        s.lambda = fresh.lambda;
        s.mu = fresh.mu;
        let mut restarted = new.integrator(params).map_err(|err| err.to_string())?;
        restarted.initialize(&new, s).map_err(|err| format!("accelerations after the event: {err}"))?;
        *model = new;
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
