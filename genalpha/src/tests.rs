//! Integrator tests on small systems with known answers.

use crate::*;
use approx::assert_relative_eq;

/// Linear oscillator m ẍ + k x = 0 (one dof, no constraints).
pub(crate) struct Oscillator {
    pub(crate) m: f64,
    pub(crate) k: f64,
}

impl ConstrainedSystem for Oscillator {
    fn n_coords(&self) -> usize {
        1
    }
    fn n_dof(&self) -> usize {
        1
    }
    fn residual_inplace(&self, _t: f64, q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        r[0] = self.m * v_dot[0] + self.k * q[0];
    }
    fn iteration_matrix_inplace(
        &self,
        _t: f64,
        _q: &[f64],
        _v: &[f64],
        _a: &[f64],
        c_m: f64,
        _c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        k.add(0, 0, c_m * self.m + c_k * self.k);
    }
}

/// Planar pendulum in Cartesian coordinates (x, z), gravity −z, rod length `l`.
/// `velocity_level` selects Φ = ½(x² + z² − l²) (index 3) or B v = x ẋ + z ż = 0 (index 2).
struct Pendulum {
    m: f64,
    g: f64,
    l: f64,
    velocity_level: bool,
}

impl ConstrainedSystem for Pendulum {
    fn n_coords(&self) -> usize {
        2
    }
    fn n_dof(&self) -> usize {
        2
    }
    fn n_holonomic(&self) -> usize {
        usize::from(!self.velocity_level)
    }
    fn n_velocity_constraints(&self) -> usize {
        usize::from(self.velocity_level)
    }
    fn residual_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        r[0] = self.m * v_dot[0];
        r[1] = self.m * v_dot[1] + self.m * self.g;
    }
    fn iteration_matrix_inplace(
        &self,
        _t: f64,
        _q: &[f64],
        _v: &[f64],
        _a: &[f64],
        c_m: f64,
        _c_c: f64,
        _c_k: f64,
        k: &mut MatView<'_>,
    ) {
        k.add(0, 0, c_m * self.m);
        k.add(1, 1, c_m * self.m);
    }
    fn phi_inplace(&self, _t: f64, q: &[f64], phi: &mut [f64]) {
        if !self.velocity_level {
            phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - self.l * self.l);
        }
    }
    fn phi_q_inplace(&self, _t: f64, q: &[f64], j: &mut MatView<'_>) {
        if !self.velocity_level {
            j.add(0, 0, q[0]);
            j.add(0, 1, q[1]);
        }
    }
    fn phi_qq_vv_inplace(&self, _t: f64, _q: &[f64], v: &[f64], out: &mut [f64]) {
        if !self.velocity_level {
            out[0] = v[0] * v[0] + v[1] * v[1];
        }
    }
    fn psi_inplace(&self, _t: f64, q: &[f64], v: &[f64], psi: &mut [f64]) {
        if self.velocity_level {
            psi[0] = q[0] * v[0] + q[1] * v[1];
        }
    }
    fn psi_v_inplace(&self, _t: f64, q: &[f64], j: &mut MatView<'_>) {
        if self.velocity_level {
            j.add(0, 0, q[0]);
            j.add(0, 1, q[1]);
        }
    }
    fn psi_q_inplace(&self, _t: f64, _q: &[f64], v: &[f64], j: &mut MatView<'_>) {
        if self.velocity_level {
            j.add(0, 0, v[0]);
            j.add(0, 1, v[1]);
        }
    }
    fn constraint_force_tangent_inplace(
        &self,
        _t: f64,
        _q: &[f64],
        lambda: &[f64],
        mu: &[f64],
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        let m = if self.velocity_level { mu[0] } else { lambda[0] };
        if !self.velocity_level {
            k.add(0, 0, c_k * m);
            k.add(1, 1, c_k * m);
        }
    }
}

fn run_oscillator(rho_inf: f64, dt: f64, t_end: f64) -> (f64, Stats) {
    let sys = Oscillator { m: 2.0, k: 8.0 }; // ω = 2
    let mut ga = GenAlpha::new(IntegratorParams::new(rho_inf, dt), &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0]);
    let mut sys = sys;
    ga.initialize(&sys, &mut s).unwrap();
    let n = (t_end / dt).round() as usize;
    for _ in 0..n {
        ga.step(&mut sys, &mut s).unwrap();
    }
    ((s.q[0] - (2.0 * s.t).cos()).abs(), *ga.stats())
}

#[test]
fn chung_hulbert_coefficients() {
    let c = Coefficients::new(1.0, 0.1);
    assert_relative_eq!(c.alpha_m, 0.5, epsilon = 1e-15);
    assert_relative_eq!(c.alpha_f, 0.5, epsilon = 1e-15);
    assert_relative_eq!(c.gamma, 0.5, epsilon = 1e-15);
    assert_relative_eq!(c.beta, 0.25, epsilon = 1e-15);
    let c = Coefficients::new(0.0, 0.1);
    assert_relative_eq!(c.alpha_m, -1.0, epsilon = 1e-15);
    assert_relative_eq!(c.alpha_f, 0.0, epsilon = 1e-15);
}

#[test]
fn oscillator_second_order_in_time() {
    for rho in [1.0, 0.8, 0.5] {
        let (e1, _) = run_oscillator(rho, 0.02, 2.0);
        let (e2, _) = run_oscillator(rho, 0.01, 2.0);
        let order = (e1 / e2).log2();
        assert!((order - 2.0).abs() < 0.15, "rho_inf {rho}: observed order {order}");
    }
}

#[test]
fn oscillator_linear_problem_converges_in_two_iterations() {
    // One solve gives the exact answer of a linear problem; the second confirms the increment
    // criterion (its increment is round-off).
    let (_, st) = run_oscillator(0.9, 0.01, 1.0);
    assert_eq!(st.n_steps, 100);
    assert_eq!(st.max_newton_iters, 2);
    assert_eq!(st.n_factorizations, 1); // modified Newton reuses the constant matrix
}

fn run_pendulum(velocity_level: bool, rho_inf: f64, dt: f64) -> (State, Vec<f64>) {
    let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level };
    let mut ga = GenAlpha::new(IntegratorParams::new(rho_inf, dt), &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
    ga.initialize(&sys, &mut s).unwrap();
    let mut energy = Vec::new();
    for _ in 0..(1.0 / dt).round() as usize {
        ga.step(&mut sys, &mut s).unwrap();
        energy.push(0.5 * (s.v[0] * s.v[0] + s.v[1] * s.v[1]) + 9.81 * s.q[1]);
    }
    (s, energy)
}

#[test]
fn pendulum_index3_keeps_constraint_and_energy() {
    let (s, e) = run_pendulum(false, 1.0, 1e-3);
    let phi = 0.5 * (s.q[0] * s.q[0] + s.q[1] * s.q[1] - 1.0);
    assert!(phi.abs() < 1e-10, "phi = {phi}");
    let drift = e.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(drift < 1e-3 * 9.81, "energy drift {drift}");
}

#[test]
fn pendulum_velocity_level_matches_index3() {
    let (s3, _) = run_pendulum(false, 0.9, 5e-4);
    let (s2, _) = run_pendulum(true, 0.9, 5e-4);
    // Same motion to discretisation error; the velocity form drifts in length by O(h²).
    assert!((s3.q[0] - s2.q[0]).abs() < 2e-3 && (s3.q[1] - s2.q[1]).abs() < 2e-3, "{:?} vs {:?}", s3.q, s2.q);
    let len = (s2.q[0] * s2.q[0] + s2.q[1] * s2.q[1]).sqrt();
    assert!((len - 1.0).abs() < 1e-3);
}

#[test]
fn consistent_initial_multiplier() {
    // Pendulum horizontal at rest: rod force is zero, acceleration is −g in z.
    let sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false };
    let mut ga = GenAlpha::new(IntegratorParams::new(0.8, 1e-3), &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
    ga.initialize(&sys, &mut s).unwrap();
    assert_relative_eq!(s.v_dot[1], -9.81, epsilon = 1e-12);
    assert_relative_eq!(s.lambda[0], 0.0, epsilon = 1e-12);
}

/// The velocity-level pendulum released horizontally, `steps` steps with parameters `p`: the
/// final state and the integrator's statistics.
fn swing_pendulum(p: IntegratorParams, steps: usize) -> (State, Stats) {
    let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: true };
    let mut ga = GenAlpha::new(p, &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
    ga.initialize(&sys, &mut s).unwrap();
    for _ in 0..steps {
        ga.step(&mut sys, &mut s).unwrap();
    }
    (s, *ga.stats())
}

/// The contraction estimate saves the confirming iteration; accepting each step within the
/// Newton tolerance changes the answer after 500 steps far less than the time discretisation
/// error (~1e-3 here, see `pendulum_velocity_level_matches_index3`).
#[test]
fn convergence_estimate_saves_iterations() {
    let run = |estimate: bool| {
        let mut p = IntegratorParams::new(0.8, 1e-3);
        p.newton.estimate_convergence = estimate;
        swing_pendulum(p, 500)
    };
    let (a, sa) = run(false);
    let (b, sb) = run(true);
    assert!(sb.n_newton_iters < sa.n_newton_iters, "{sb:?} vs {sa:?}");
    for (x, y) in a.q.iter().zip(&b.q) {
        assert!((x - y).abs() < 1e-5, "{x} vs {y}");
    }
}

/// Broyden's corrections of the reused factorisation: fewer iterations (and no more
/// factorisations) on a pendulum swinging through large angles with a coarse step, and the
/// same answer to within the Newton tolerance's effect (the time discretisation error is ~1e-2
/// at this step).
#[test]
fn broyden_corrections_save_iterations() {
    let run = |broyden: bool| {
        let mut p = IntegratorParams::new(0.8, 1e-2);
        p.newton.broyden = broyden;
        swing_pendulum(p, 300)
    };
    let (a, sa) = run(false);
    let (b, sb) = run(true);
    println!("plain: {sa:?}\nbroyden: {sb:?}");
    assert!(sb.n_newton_iters < sa.n_newton_iters, "{sb:?} vs {sa:?}");
    assert!(sb.n_factorizations <= sa.n_factorizations, "{sb:?} vs {sa:?}");
    for (x, y) in a.q.iter().zip(&b.q) {
        assert!((x - y).abs() < 1e-6, "{x} vs {y}");
    }
}

/// The Newton trace holds one record per solve, numbered from 1 in every step, with the
/// factorisations marked, and nothing when tracing is off.
#[test]
fn newton_trace_records_every_iteration() {
    let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: true };
    let mut ga = GenAlpha::new(IntegratorParams::new(0.8, 1e-2), &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
    ga.initialize(&sys, &mut s).unwrap();
    ga.step(&mut sys, &mut s).unwrap();
    assert!(ga.take_trace().is_empty(), "off by default");
    ga.set_trace(true);
    let before = *ga.stats();
    for _ in 0..50 {
        ga.step(&mut sys, &mut s).unwrap();
    }
    let st = *ga.stats();
    let trace = ga.take_trace();
    assert_eq!(st.n_step_halvings, 0, "the count below assumes no failed attempt");
    assert_eq!(trace.len(), st.n_residual_evals - before.n_residual_evals);
    assert_eq!(trace.iter().filter(|r| r.factorized).count(), st.n_factorizations - before.n_factorizations);
    assert_eq!(trace.iter().filter(|r| r.iter == 1).count(), 50);
    assert!(trace.windows(2).all(|w| w[1].iter == 1 || (w[1].iter == w[0].iter + 1 && w[1].t == w[0].t)));
    assert!(trace.iter().all(|r| r.h == 1e-2 && r.worst_unknown < 2 && r.increment_norm.is_finite()));
    assert!(ga.take_trace().is_empty(), "taken");
}

#[test]
fn invalid_parameters_name_the_field() {
    let sys = Oscillator { m: 1.0, k: 1.0 };
    let e = GenAlpha::new(IntegratorParams::new(1.5, 1e-3), &sys).unwrap_err();
    assert!(e.to_string().contains("rho_inf"));
    let e = GenAlpha::new(IntegratorParams::new(0.9, -1.0), &sys).unwrap_err();
    assert!(e.to_string().contains("dt"));
}

/// A pendulum whose Newton iteration is made to fail at one step size: `max_iter` is too small
/// for some full steps but enough for half steps; those steps must be retried in halves, reach the
/// right time and keep the constraint; with retries off the same run fails.
#[test]
fn failed_step_is_retried_in_halves() {
    let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false };
    let mut p = IntegratorParams::new(0.9, 0.02);
    p.newton.max_iter = 2;
    p.newton.reuse_factorization = false;
    p.newton.estimate_convergence = false;
    let mut ga = GenAlpha::new(p, &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
    ga.initialize(&sys, &mut s).unwrap();
    let mut halved = 0;
    for _ in 0..10 {
        let st = ga.step(&mut sys, &mut s).unwrap();
        assert!(st.n_substeps >= 1);
        halved += st.n_substeps - 1;
    }
    assert_relative_eq!(s.t, 0.2, epsilon = 1e-12);
    assert!(halved > 0, "the test needs at least one halving");
    assert_eq!(ga.stats().n_step_halvings, halved);
    let phi = 0.5 * (s.q[0] * s.q[0] + s.q[1] * s.q[1] - 1.0);
    assert!(phi.abs() < 1e-9, "phi = {phi}");
    // Without retries the same run fails.
    let mut p0 = p;
    p0.newton.max_step_halvings = 0;
    let mut ga = GenAlpha::new(p0, &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
    ga.initialize(&sys, &mut s).unwrap();
    let failed = (0..10).any(|_| ga.step(&mut sys, &mut s).is_err());
    assert!(failed);
}

/// A hardening spring m ẍ + k x + k₃ x³ = F, with the force switched on after t = 0: the
/// predictor sits at rest where the tangent is k, the solution far into the stiff range.
struct SuddenlyLoadedSpring {
    m: f64,
    k: f64,
    k3: f64,
    force: f64,
}

impl ConstrainedSystem for SuddenlyLoadedSpring {
    fn n_coords(&self) -> usize {
        1
    }
    fn n_dof(&self) -> usize {
        1
    }
    fn residual_inplace(&self, t: f64, q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        let f = if t > 0.0 { self.force } else { 0.0 };
        r[0] = self.m * v_dot[0] + self.k * q[0] + self.k3 * q[0].powi(3) - f;
    }
    fn iteration_matrix_inplace(
        &self,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        _a: &[f64],
        c_m: f64,
        _c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        k.add(0, 0, c_m * self.m + c_k * (self.k + 3.0 * self.k3 * q[0] * q[0]));
    }
}

/// Modified Newton with the predictor's matrix overshoots on the sudden load (the tangent at
/// the solution is many times the one at rest) and would spoil the iterate; stepping back to the
/// iterate before the divergent update and factorising there converges the step at full size to
/// the answer of full Newton.
#[test]
fn divergent_modified_newton_update_is_taken_back() {
    let run = |reuse: bool| {
        let mut sys = SuddenlyLoadedSpring { m: 1.0, k: 1.0e2, k3: 1.0e6, force: 3.0e2 };
        let mut p = IntegratorParams::new(0.8, 0.05);
        p.newton.reuse_factorization = reuse;
        p.newton.max_step_halvings = 0;
        let mut ga = GenAlpha::new(p, &sys).unwrap();
        let mut s = State::at_rest(&sys, 0.0, vec![0.0]);
        ga.initialize(&sys, &mut s).unwrap();
        let st = ga.step(&mut sys, &mut s).expect("the step converges at full size");
        (s.q[0], st)
    };
    let (x_full, full) = run(false);
    let (x_mod, modified) = run(true);
    println!("full Newton {full:?}\nmodified Newton {modified:?}");
    assert_eq!(modified.n_substeps, 1);
    assert!(x_full > 0.05, "the load reaches the stiff range: x = {x_full}");
    assert_relative_eq!(x_mod, x_full, epsilon = 1e-12, max_relative = 1e-9);
}

/// Pendulum released horizontally, one coarse step size, with or without local error control:
/// (position error at t = 1 s against a fine fixed-step run, step halvings).
fn pendulum_with_error_control(tol: f64) -> (f64, usize) {
    let run = |dt: f64, tol: f64| {
        let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false };
        let mut p = IntegratorParams::new(0.9, dt);
        p.newton.local_error_tol = tol;
        p.newton.max_step_halvings = 6;
        let mut ga = GenAlpha::new(p, &sys).unwrap();
        let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
        ga.initialize(&sys, &mut s).unwrap();
        for _ in 0..(1.0 / dt).round() as usize {
            ga.step(&mut sys, &mut s).unwrap();
        }
        (s, ga.stats().n_step_halvings)
    };
    let (fine, _) = run(1e-4, 0.0);
    let (s, halvings) = run(0.02, tol);
    (((s.q[0] - fine.q[0]).powi(2) + (s.q[1] - fine.q[1]).powi(2)).sqrt(), halvings)
}

#[test]
fn local_error_control_halves_long_steps_and_reduces_the_error() {
    let (e_off, h_off) = pendulum_with_error_control(0.0);
    assert_eq!(h_off, 0, "no control: nominal steps only");
    let (e_on, h_on) = pendulum_with_error_control(1e-5);
    // The control sub-steps where the estimate h²|β − 1/6||Δa| exceeds 1e-5 m: the pendulum's
    // fast bottom swing; its error drops accordingly.
    assert!(h_on > 0, "the estimate must trigger halvings");
    assert!(e_on < 0.25 * e_off, "error with control {e_on:.3e} m, without {e_off:.3e} m");
}

/// The extrapolated-acceleration predictor starts Newton one order closer to the solution: on
/// the velocity-level pendulum (its residual is quadratic in the velocities through the
/// constraint) it needs fewer iterations, and the converged answer is the same to far below
/// the time discretisation error.
#[test]
fn extrapolated_predictor_saves_iterations() {
    let run = |predictor: Predictor| {
        let mut p = IntegratorParams::new(0.8, 1e-2);
        p.newton.predictor = predictor;
        swing_pendulum(p, 300)
    };
    let (a, sa) = run(Predictor::ConstantAcceleration);
    let (b, sb) = run(Predictor::ExtrapolatedAcceleration);
    println!("iterations: constant {}, extrapolated {}", sa.n_newton_iters, sb.n_newton_iters);
    assert!(sb.n_newton_iters < sa.n_newton_iters, "{sb:?} vs {sa:?}");
    for (x, y) in a.q.iter().zip(&b.q) {
        assert!((x - y).abs() < 1e-6, "{x} vs {y}");
    }
}
