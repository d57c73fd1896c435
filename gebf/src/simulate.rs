//! A plain time loop over the generalized-α integrator, with an observer called after every
//! step (the harness has its own; tests and benchmarks use this one).

use crate::{Energies, Error, Model};
use genalpha::{GenAlpha, IntegratorParams, State, Stats, StepStats};
use nalgebra::Vector3;

/// Initialise consistently and integrate `model` from its reference state to `t_end`.
/// `observe(model, state, step_stats)` is called at t = 0 (with default stats) and after every
/// step. Returns the final state and the integrator's statistics.
pub fn run(
    model: &mut Model,
    params: IntegratorParams,
    t_end: f64,
    mut observe: impl FnMut(&Model, &State, &StepStats),
) -> Result<(State, Stats), Error> {
    let mut ga = GenAlpha::new(params, model)?;
    let mut s = model.initial_state();
    model.reset_hinge_angles(&s.q);
    ga.initialize(model, &mut s)?;
    observe(model, &s, &StepStats::default());
    let n_steps = (t_end / params.dt).round() as usize;
    for _ in 0..n_steps {
        let st = ga.step(model, &mut s)?;
        observe(model, &s, &st);
    }
    Ok((s, *ga.stats()))
}

/// One recorded output row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Tip position (global), m.
    pub tip: Vector3<f64>,
    /// Fold angle of the first flared hinge, rad (0 without one).
    pub fold: f64,
    /// Energies, J.
    pub energies: Energies,
    /// Position-level joint violation (`Model::constraint_residual`).
    pub constraint_residual: f64,
    /// Newton iterations of the step.
    pub newton_iterations: usize,
}

/// Run and record every step.
pub fn record(model: &mut Model, params: IntegratorParams, t_end: f64) -> Result<(Vec<Sample>, Stats), Error> {
    let fold_joint = model.flared_hinges().first().copied();
    let mut out = Vec::with_capacity((t_end / params.dt).round() as usize + 1);
    let (_, stats) = run(model, params, t_end, |m, s, st| {
        out.push(Sample {
            t: s.t,
            tip: m.tip_position(&s.q),
            fold: fold_joint.and_then(|j| m.fold_angle(&s.q, j).ok()).unwrap_or(0.0),
            energies: m.energies(&s.q, &s.v),
            constraint_residual: m.constraint_residual(&s.q),
            newton_iterations: st.n_newton_iters,
        });
    })?;
    Ok((out, stats))
}
