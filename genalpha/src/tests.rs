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
        // Φ_qᵀλ = q λ and Bᵀμ = q μ: ∂/∂q = λ I or μ I.
        let m = if self.velocity_level { mu[0] } else { lambda[0] };
        k.add(0, 0, c_k * m);
        k.add(1, 1, c_k * m);
    }
}

fn run_oscillator(rho_inf: f64, dt: f64, t_end: f64) -> (f64, Stats) {
    run_oscillator_in(Form::ArnoldBruls, rho_inf, dt, t_end)
}

/// (|x(t_end) − exact|, statistics) of the oscillator released from x = 1, in form `form`.
fn run_oscillator_in(form: Form, rho_inf: f64, dt: f64, t_end: f64) -> (f64, Stats) {
    let mut sys = Oscillator { m: 2.0, k: 8.0 }; // ω = 2
    let mut p = IntegratorParams::new(rho_inf, dt);
    p.form = form;
    let mut ga = GenAlpha::new(p, &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![1.0]);
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
    for form in [Form::ArnoldBruls, Form::ChungHulbert] {
        for rho in [1.0, 0.8, 0.5] {
            let (e1, _) = run_oscillator_in(form, rho, 0.02, 2.0);
            let (e2, _) = run_oscillator_in(form, rho, 0.01, 2.0);
            let order = (e1 / e2).log2();
            assert!((order - 2.0).abs() < 0.15, "{form:?}, rho_inf {rho}: observed order {order}");
        }
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
fn pendulum_with_error_control(tol: f64, form: Form, rho_inf: f64) -> (f64, usize) {
    let run = |dt: f64, tol: f64| {
        let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false };
        let mut p = IntegratorParams::new(rho_inf, dt);
        p.form = form;
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
    for form in [Form::ArnoldBruls, Form::ChungHulbert] {
        let (e_off, h_off) = pendulum_with_error_control(0.0, form, 0.9);
        assert_eq!(h_off, 0, "no control: nominal steps only");
        let (e_on, h_on) = pendulum_with_error_control(1e-5, form, 0.9);
        println!("{form:?}: error {e_off:.3e} m, with control {e_on:.3e} m after {h_on} halvings");
        // The control sub-steps where the estimate h²|β − 1/6||Δa| (Δv̇_α in the Chung–Hulbert
        // form) exceeds 1e-5 m: the pendulum's fast bottom swing; its error drops accordingly,
        // to about 2e-4 m in both forms (measured: by 13× from the Arnold–Brüls form's 2.4e-3 m,
        // by 4.7× from the Chung–Hulbert form's smaller 1.1e-3 m).
        assert!(h_on > 0, "the estimate must trigger halvings");
        let gain = if form == Form::ArnoldBruls { 4.0 } else { 3.0 };
        assert!(e_on * gain < e_off, "{form:?}: error with control {e_on:.3e} m, without {e_off:.3e} m");
    }
}

/// At rho_inf = 1 the Chung–Hulbert form's `a` alternates about the acceleration, so the
/// estimator measures the change of the smooth v̇_α instead: the control then halves 57 steps
/// and cuts the error 3.8 times (1.0e-3 → 2.7e-4 m). Measuring `a` would halve 2667 steps,
/// nearly every step down to the limit. (The Arnold–Brüls form at rho_inf = 1 does that: the
/// trapezoidal rule lets the index-3 pendulum's accelerations alternate, in `a` and `v̇` alike.)
#[test]
fn local_error_control_at_rho_inf_one_in_the_chung_hulbert_form() {
    let (e_off, _) = pendulum_with_error_control(0.0, Form::ChungHulbert, 1.0);
    let (e_on, h_on) = pendulum_with_error_control(1e-5, Form::ChungHulbert, 1.0);
    println!("Chung–Hulbert, rho_inf 1: error {e_off:.3e} m, with control {e_on:.3e} m after {h_on} halvings");
    assert!((1..200).contains(&h_on), "{h_on} halvings");
    assert!(e_on * 3.0 < e_off, "error with control {e_on:.3e} m, without {e_off:.3e} m");
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

/// A free rigid body in body-frame angular velocities (Euler's equations
/// `J ω̇ + ω × J ω = 0`; `q` integrates ω and enters nothing). Its kinetic energy `½ ωᵀJω` and
/// the squared angular momentum `|Jω|²` are quadratic invariants.
struct FreeRigidBody {
    j: [f64; 3],
}

impl FreeRigidBody {
    fn energy_and_momentum(&self, w: &[f64]) -> (f64, f64) {
        let [a, b, c] = self.j;
        (
            0.5 * (a * w[0] * w[0] + b * w[1] * w[1] + c * w[2] * w[2]),
            (a * w[0]).powi(2) + (b * w[1]).powi(2) + (c * w[2]).powi(2),
        )
    }
}

impl ConstrainedSystem for FreeRigidBody {
    fn n_coords(&self) -> usize {
        3
    }
    fn n_dof(&self) -> usize {
        3
    }
    fn residual_inplace(&self, _t: f64, _q: &[f64], w: &[f64], w_dot: &[f64], r: &mut [f64]) {
        let [a, b, c] = self.j;
        let h = [a * w[0], b * w[1], c * w[2]];
        r[0] = a * w_dot[0] + w[1] * h[2] - w[2] * h[1];
        r[1] = b * w_dot[1] + w[2] * h[0] - w[0] * h[2];
        r[2] = c * w_dot[2] + w[0] * h[1] - w[1] * h[0];
    }
    fn iteration_matrix_inplace(
        &self,
        _t: f64,
        _q: &[f64],
        w: &[f64],
        _a: &[f64],
        c_m: f64,
        c_c: f64,
        _c_k: f64,
        k: &mut MatView<'_>,
    ) {
        let [a, b, c] = self.j;
        for (i, ji) in self.j.iter().enumerate() {
            k.add(i, i, c_m * ji);
        }
        // ∂(ω × Jω)/∂ω = ω̃ J − (Jω)~.
        k.add(0, 1, c_c * (c - b) * w[2]);
        k.add(0, 2, c_c * (c - b) * w[1]);
        k.add(1, 0, c_c * (a - c) * w[2]);
        k.add(1, 2, c_c * (a - c) * w[0]);
        k.add(2, 0, c_c * (b - a) * w[1]);
        k.add(2, 1, c_c * (b - a) * w[0]);
    }
}

/// (max relative kinetic energy error, max relative |Jω|² error) of a free body tumbling near
/// its unstable middle axis for 4 s at step 0.02 s, with `rho_inf = 1` in form `form`.
fn tumble(form: Form) -> (f64, f64) {
    let mut sys = FreeRigidBody { j: [1.0, 2.0, 3.0] };
    let mut p = IntegratorParams::new(1.0, 0.02);
    p.form = form;
    p.newton.rtol = 1e-12;
    p.newton.atol = 1e-14;
    let mut ga = GenAlpha::new(p, &sys).unwrap();
    let mut s = State::at_rest(&sys, 0.0, vec![0.0; 3]);
    s.v.copy_from_slice(&[0.05, 4.0, 0.05]);
    ga.initialize(&sys, &mut s).unwrap();
    let (e0, h0) = sys.energy_and_momentum(&s.v);
    let (mut de, mut dh) = (0.0_f64, 0.0_f64);
    for _ in 0..200 {
        ga.step(&mut sys, &mut s).unwrap();
        let (e, h) = sys.energy_and_momentum(&s.v);
        de = de.max((e / e0 - 1.0).abs());
        dh = dh.max((h / h0 - 1.0).abs());
    }
    (de, dh)
}

/// At `rho_inf = 1` the Chung–Hulbert form is the implicit midpoint rule, which conserves
/// quadratic invariants: the tumbling body's kinetic energy and squared angular momentum stay
/// constant to the Newton tolerance, where the Arnold–Brüls form (the trapezoidal rule) lets
/// the gyroscopic term do work at O(h²): 5.3e-4 of the energy as the body flips.
#[test]
fn chung_hulbert_midpoint_conserves_a_tumbling_body_s_invariants() {
    let (de, dh) = tumble(Form::ChungHulbert);
    let (de_ab, dh_ab) = tumble(Form::ArnoldBruls);
    println!("Chung–Hulbert: energy {de:.2e}, momentum {dh:.2e}; Arnold–Brüls: {de_ab:.2e}, {dh_ab:.2e}");
    assert!(de < 1e-10 && dh < 1e-10, "Chung–Hulbert: energy {de:.2e}, momentum {dh:.2e}");
    assert!(de_ab > 1e-4, "the trapezoidal rule's gyroscopic work is visible: {de_ab:.2e}");
}

/// The pendulum with a holonomic (index 3) or velocity-level constraint in the Chung–Hulbert
/// form: the constraint holds at the end of each step, the energy is kept as in the
/// Arnold–Brüls form, and both forms converge at second order to the same motion (errors at
/// t = 1 s against a run 50 times finer, with Newton tolerances far below them; measured: the
/// ratios are 4.00, and the Chung–Hulbert errors are 2.5–4.5 times smaller).
#[test]
fn chung_hulbert_pendulum_keeps_constraints_and_is_second_order() {
    let run = |velocity_level: bool, form: Form, rho_inf: f64, dt: f64, tight: bool| {
        let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level };
        let mut p = IntegratorParams::new(rho_inf, dt);
        p.form = form;
        if tight {
            (p.newton.rtol, p.newton.atol, p.newton.phi_tol, p.newton.psi_tol) = (1e-12, 1e-14, 1e-13, 1e-12);
        }
        let mut ga = GenAlpha::new(p, &sys).unwrap();
        let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
        ga.initialize(&sys, &mut s).unwrap();
        let mut drift = 0.0_f64;
        for _ in 0..(1.0 / dt).round() as usize {
            ga.step(&mut sys, &mut s).unwrap();
            drift = drift.max((0.5 * (s.v[0] * s.v[0] + s.v[1] * s.v[1]) + 9.81 * s.q[1]).abs());
        }
        (s, drift)
    };
    let (s, drift) = run(false, Form::ChungHulbert, 1.0, 1e-3, false);
    let phi = 0.5 * (s.q[0] * s.q[0] + s.q[1] * s.q[1] - 1.0);
    assert!(phi.abs() < 1e-10, "phi = {phi}");
    assert!(drift < 1e-3 * 9.81, "energy drift {drift}");
    let (s, _) = run(true, Form::ChungHulbert, 0.9, 1e-3, false);
    let len = (s.q[0] * s.q[0] + s.q[1] * s.q[1]).sqrt();
    assert!((len - 1.0).abs() < 1e-3, "velocity-level length drift {}", len - 1.0);
    for velocity_level in [false, true] {
        let (fine, _) = run(velocity_level, Form::ArnoldBruls, 1.0, 2e-5, true);
        for rho_inf in [1.0, 0.9] {
            for form in [Form::ArnoldBruls, Form::ChungHulbert] {
                let err = |dt: f64| {
                    let (s, _) = run(velocity_level, form, rho_inf, dt, true);
                    ((s.q[0] - fine.q[0]).powi(2) + (s.q[1] - fine.q[1]).powi(2)).sqrt()
                };
                let (e1, e2) = (err(2e-3), err(1e-3));
                println!("velocity level {velocity_level}, rho_inf {rho_inf}, {form:?}: {e1:.3e}, {e2:.3e}");
                assert!((3.7..4.3).contains(&(e1 / e2)), "{form:?}: ratio {}", e1 / e2);
                assert!(e1 < 1e-4, "{form:?}: error {e1:.3e} m");
            }
        }
    }
}

/// The index-3 pendulum with a coupling spring `k_c x z` switched on after `t_on`, optionally
/// declaring its two coordinates one diagonal block (half-bandwidth 0) of a bordered band
/// structure: once the spring is on, its off-diagonal stiffness lies outside that structure.
struct CoupledPendulum {
    p: Pendulum,
    k_c: f64,
    t_on: f64,
    structured: bool,
    /// A mass coupling `m_c (ẍ z̈)`-type term, present from the start (outside the structure).
    m_c: f64,
}

impl ConstrainedSystem for CoupledPendulum {
    fn n_coords(&self) -> usize {
        2
    }
    fn n_dof(&self) -> usize {
        2
    }
    fn n_holonomic(&self) -> usize {
        1
    }
    fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        self.p.residual_inplace(t, q, v, v_dot, r);
        r[0] += self.m_c * v_dot[1];
        r[1] += self.m_c * v_dot[0];
        if t > self.t_on {
            r[0] += self.k_c * q[1];
            r[1] += self.k_c * q[0];
        }
    }
    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.p.iteration_matrix_inplace(t, q, v, v_dot, c_m, c_c, c_k, k);
        if self.m_c != 0.0 {
            k.add(0, 1, c_m * self.m_c);
            k.add(1, 0, c_m * self.m_c);
        }
        if t > self.t_on {
            k.add(0, 1, c_k * self.k_c);
            k.add(1, 0, c_k * self.k_c);
        }
    }
    fn phi_inplace(&self, t: f64, q: &[f64], phi: &mut [f64]) {
        self.p.phi_inplace(t, q, phi);
    }
    fn phi_q_inplace(&self, t: f64, q: &[f64], j: &mut MatView<'_>) {
        self.p.phi_q_inplace(t, q, j);
    }
    fn phi_qq_vv_inplace(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.p.phi_qq_vv_inplace(t, q, v, out);
    }
    fn constraint_force_tangent_inplace(
        &self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        mu: &[f64],
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.p.constraint_force_tangent_inplace(t, q, lambda, mu, c_k, k);
    }
    fn matrix_structure(&self) -> Option<BandedBorder> {
        self.structured.then(|| BandedBorder { blocks: vec![(0, 2, 0)], node_bandwidth: None })
    }
}

/// When the solver's own storage meets an entry outside the declared structure, the integrator
/// assembles the same matrix densely in the middle of an iteration; the residual recomputed on
/// the way must carry the constraint forces again (it once did not: that iteration's increment
/// was 1e5 times too large, and Newton needed extra iterations to recover). With and without a
/// declared structure the runs take the same iterations to the same states, in both forms.
#[test]
fn dense_hand_over_keeps_the_constraint_forces() {
    for form in [Form::ArnoldBruls, Form::ChungHulbert] {
        let run = |structured: bool| {
            let mut sys = CoupledPendulum {
                p: Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false },
                k_c: 50.0,
                t_on: 0.1,
                structured,
                m_c: 0.0,
            };
            let mut p = IntegratorParams::new(0.8, 1e-2);
            p.form = form;
            p.newton.reuse_factorization = false;
            let mut ga = GenAlpha::new(p, &sys).unwrap();
            let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
            ga.initialize(&sys, &mut s).unwrap();
            ga.set_trace(true);
            for _ in 0..30 {
                ga.step(&mut sys, &mut s).unwrap();
            }
            (s, *ga.stats(), ga.take_trace())
        };
        let (a, sa, ta) = run(false);
        let (b, sb, tb) = run(true);
        println!("{form:?}: dense {sa:?}\nstructured {sb:?}");
        assert_eq!(sa.n_newton_iters, sb.n_newton_iters, "{form:?}");
        // Iteration by iteration (the multipliers' error would show in the next residual).
        for (x, y) in ta.iter().zip(&tb) {
            let close = |u: f64, w: f64| (u - w).abs() <= 1e-6 * u.abs().max(w.abs()) + 1e-12;
            assert!(
                close(x.residual_norm, y.residual_norm) && close(x.increment_norm, y.increment_norm),
                "{form:?} at t = {}, iteration {}: {x:?} vs {y:?}",
                x.t,
                x.iter
            );
        }
        for (x, y) in a.q.iter().chain(&a.lambda).zip(b.q.iter().chain(&b.lambda)) {
            assert!((x - y).abs() < 1e-9 * (1.0 + x.abs()), "{form:?}: {x} vs {y}");
        }
    }
}

/// `m ẍ + k x = F sin(Ω t)` from rest: a force that depends on time.
struct ForcedOscillator {
    m: f64,
    k: f64,
    f: f64,
    omega: f64,
}

impl ForcedOscillator {
    /// The exact displacement.
    fn exact(&self, t: f64) -> f64 {
        let w = (self.k / self.m).sqrt();
        let a = self.f / (self.m * (w * w - self.omega * self.omega));
        a * ((self.omega * t).sin() - self.omega / w * (w * t).sin())
    }
}

impl ConstrainedSystem for ForcedOscillator {
    fn n_coords(&self) -> usize {
        1
    }
    fn n_dof(&self) -> usize {
        1
    }
    fn residual_inplace(&self, t: f64, q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        r[0] = self.m * v_dot[0] + self.k * q[0] - self.f * (self.omega * t).sin();
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

/// The forces are evaluated at the weighted instant t_α too: a time-dependent force keeps the
/// Chung–Hulbert form second order (measured ratio 4.0; at t_{n+1} it would be first order).
#[test]
fn chung_hulbert_forced_oscillator_second_order() {
    let sys0 = ForcedOscillator { m: 1.0, k: 4.0, f: 1.0, omega: 3.0 };
    for rho in [1.0, 0.8] {
        let err = |dt: f64| {
            let mut sys = ForcedOscillator { ..sys0 };
            let mut p = IntegratorParams::new(rho, dt);
            p.form = Form::ChungHulbert;
            p.newton.rtol = 1e-12;
            let mut ga = GenAlpha::new(p, &sys).unwrap();
            let mut s = State::at_rest(&sys, 0.0, vec![0.0]);
            ga.initialize(&sys, &mut s).unwrap();
            for _ in 0..(2.0 / dt).round() as usize {
                ga.step(&mut sys, &mut s).unwrap();
            }
            (s.q[0] - sys0.exact(s.t)).abs()
        };
        let (e1, e2) = (err(0.02), err(0.01));
        println!("rho_inf {rho}: {e1:.3e}, {e2:.3e}");
        assert!((3.7..4.3).contains(&(e1 / e2)), "rho_inf {rho}: ratio {}", e1 / e2);
    }
}

/// Full Newton (a fresh matrix at every iteration, no Broyden correction, no contraction
/// estimate) converges quadratically in both forms, so the iteration matrix is the exact
/// Jacobian: multiplier columns and constraint-force tangent at the state the forces see,
/// constraint rows at the step's end, the (1 − α_f) weights. Pendulum swinging through large
/// angles, index 3 and velocity level: every step in 3 solves (the third confirms; multiplier
/// columns taken at the step's end instead of the weighted state need 4). And the converged
/// step satisfies the equations of motion at the form's state with its multipliers (which the
/// increment test, on the coordinates only, would not see if the multipliers moved by the wrong
/// scale).
#[test]
fn full_newton_converges_quadratically_in_both_forms() {
    for velocity_level in [false, true] {
        for form in [Form::ArnoldBruls, Form::ChungHulbert] {
            for rho in [1.0, 0.8] {
                let mut sys = Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level };
                let mut p = IntegratorParams::new(rho, 1e-2);
                p.form = form;
                p.newton.reuse_factorization = false;
                p.newton.broyden = false;
                p.newton.estimate_convergence = false;
                (p.newton.rtol, p.newton.atol) = (1e-10, 1e-12);
                let mut ga = GenAlpha::new(p, &sys).unwrap();
                let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
                ga.initialize(&sys, &mut s).unwrap();
                // The equations of motion at the state the form evaluates them at, with the
                // step's multipliers: r + Φ_qᵀλ + Bᵀμ = 0 (all pendulum forces are O(m g)).
                let w = if form == Form::ChungHulbert { 1.0 - ga.coefficients().alpha_f } else { 1.0 };
                let mut worst = 0.0_f64;
                for _ in 0..100 {
                    let s0 = s.clone();
                    ga.step(&mut sys, &mut s).unwrap();
                    let at = |x0: f64, x1: f64| (1.0 - w) * x0 + w * x1;
                    let q = [at(s0.q[0], s.q[0]), at(s0.q[1], s.q[1])];
                    let v = [at(s0.v[0], s.v[0]), at(s0.v[1], s.v[1])];
                    let mut r = [0.0; 2];
                    sys.residual_inplace(at(s0.t, s.t), &q, &v, &s.v_dot, &mut r);
                    let m = if velocity_level { s.mu[0] } else { s.lambda[0] };
                    worst = worst.max((r[0] + q[0] * m).abs().max((r[1] + q[1] * m).abs()) / 9.81);
                }
                let st = *ga.stats();
                let per_step = st.n_newton_iters as f64 / st.n_steps as f64;
                println!(
                    "velocity level {velocity_level}, {form:?}, rho_inf {rho}: {per_step:.2} per step, max {}, \
                     equations of motion to {worst:.1e} m g",
                    st.max_newton_iters
                );
                assert!(st.max_newton_iters <= 3, "{st:?}");
                assert!(worst < 1e-8, "{form:?}: equations of motion hold to {worst:.2e} m g");
            }
        }
    }
}

/// A model that writes outside its declared structure from the first matrix on: the dense LU
/// drops the structure at once and never offers its own storage, so every matrix is assembled
/// densely. Those entries must be cleared before each assembly, not added up (they once were:
/// Newton diverged at t = 0.08 s). Same iterations and states as without a declared structure.
#[test]
fn entries_outside_a_declared_structure_do_not_pile_up() {
    for form in [Form::ArnoldBruls, Form::ChungHulbert] {
        let run = |structured: bool| {
            let mut sys = CoupledPendulum {
                p: Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false },
                k_c: 0.0,
                t_on: f64::INFINITY,
                structured,
                m_c: 0.3,
            };
            let mut p = IntegratorParams::new(0.8, 1e-2);
            p.form = form;
            p.newton.reuse_factorization = false;
            let mut ga = GenAlpha::new(p, &sys).unwrap();
            let mut s = State::at_rest(&sys, 0.0, vec![1.0, 0.0]);
            ga.initialize(&sys, &mut s).unwrap();
            for _ in 0..100 {
                ga.step(&mut sys, &mut s).unwrap();
            }
            (s, *ga.stats())
        };
        let (a, sa) = run(false);
        let (b, sb) = run(true);
        assert_eq!(sa.n_newton_iters, sb.n_newton_iters, "{form:?}");
        for (x, y) in a.q.iter().chain(&a.lambda).zip(b.q.iter().chain(&b.lambda)) {
            assert!((x - y).abs() < 1e-9 * (1.0 + x.abs()), "{form:?}: {x} vs {y}");
        }
    }
}

/// [`CoupledPendulum`] beside `extra` uncoupled oscillators `ẍ + 4 x = 0` (at rest), so that the
/// matrix is larger than [`DENSE_FALLBACK_MAX`]; the structure declares every coordinate its own
/// diagonal block.
struct PaddedPendulum {
    inner: CoupledPendulum,
    extra: usize,
}

impl ConstrainedSystem for PaddedPendulum {
    fn n_coords(&self) -> usize {
        2 + self.extra
    }
    fn n_dof(&self) -> usize {
        2 + self.extra
    }
    fn n_holonomic(&self) -> usize {
        1
    }
    fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        self.inner.residual_inplace(t, &q[..2], &v[..2], &v_dot[..2], &mut r[..2]);
        for i in 2..r.len() {
            r[i] = v_dot[i] + 4.0 * q[i];
        }
    }
    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.inner.iteration_matrix_inplace(t, &q[..2], &v[..2], &v_dot[..2], c_m, c_c, c_k, k);
        for i in 2..self.n_coords() {
            k.add(i, i, c_m + 4.0 * c_k);
        }
    }
    fn phi_inplace(&self, t: f64, q: &[f64], phi: &mut [f64]) {
        self.inner.phi_inplace(t, &q[..2], phi);
    }
    fn phi_q_inplace(&self, t: f64, q: &[f64], j: &mut MatView<'_>) {
        self.inner.phi_q_inplace(t, &q[..2], j);
    }
    fn phi_qq_vv_inplace(&self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) {
        self.inner.phi_qq_vv_inplace(t, &q[..2], &v[..2], out);
    }
    fn constraint_force_tangent_inplace(
        &self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        mu: &[f64],
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.inner.constraint_force_tangent_inplace(t, &q[..2], lambda, mu, c_k, k);
    }
    fn matrix_structure(&self) -> Option<BandedBorder> {
        Some(BandedBorder { blocks: vec![(0, self.n_coords(), 0)], node_bandwidth: None })
    }
}

/// Above [`DENSE_FALLBACK_MAX`] unknowns, a matrix the structured storage cannot take (here the
/// coupling spring, outside the declared structure, from t = 0.1 s on) goes to the sparse LU as
/// entries: no `n × n` matrix is ever allocated, and the pendulum takes the same iterations to
/// the same states as the small system's dense fallback.
#[test]
fn large_fallback_goes_to_the_sparse_lu_without_a_dense_matrix() {
    let run = |extra: usize| {
        let inner = CoupledPendulum {
            p: Pendulum { m: 1.0, g: 9.81, l: 1.0, velocity_level: false },
            k_c: 50.0,
            t_on: 0.1,
            structured: true,
            m_c: 0.0,
        };
        let mut sys = PaddedPendulum { inner, extra };
        let mut p = IntegratorParams::new(0.8, 1e-2);
        p.newton.reuse_factorization = false;
        let mut ga = GenAlpha::new(p, &sys).unwrap();
        let mut q0 = vec![0.0; 2 + extra];
        q0[0] = 1.0;
        let mut s = State::at_rest(&sys, 0.0, q0);
        ga.initialize(&sys, &mut s).unwrap();
        for _ in 0..30 {
            ga.step(&mut sys, &mut s).unwrap();
        }
        (s, *ga.stats(), ga.holds_dense_matrix(), ga.sparse_fallbacks(), ga.dense_assemblies())
    };
    let (small, s_small, dense_small, sparse_small, _) = run(0);
    let (large, s_large, dense_large, sparse_large, assemblies_large) = run(DENSE_FALLBACK_MAX);
    assert!(dense_small && sparse_small == 0, "the small system falls back densely");
    assert!(!dense_large && assemblies_large == 0, "no dense matrix above the fallback's size");
    assert!(sparse_large >= 20, "{sparse_large} sparse fallbacks");
    assert_eq!(s_small.n_newton_iters, s_large.n_newton_iters);
    for (x, y) in small.q.iter().chain(&small.lambda).zip(large.q[..2].iter().chain(&large.lambda)) {
        assert!((x - y).abs() < 1e-12 * (1.0 + x.abs()), "{x} vs {y}");
    }
    assert!(large.q[2..].iter().all(|&x| x == 0.0));
}

/// Two point masses joined by a stiff spring, spinning in the plane about their centre of mass,
/// which two linear constraint rows hold at the origin: absolute coordinates whose stiffness
/// turns with the body. The co-rotation is the turn of the spring's direction.
struct SpinningDumbbell {
    m: f64,
    k: f64,
    l: f64,
}

impl SpinningDumbbell {
    fn axis(q: &[f64]) -> [f64; 2] {
        [q[2] - q[0], q[3] - q[1]]
    }
}

impl ConstrainedSystem for SpinningDumbbell {
    fn n_coords(&self) -> usize {
        4
    }
    fn n_dof(&self) -> usize {
        4
    }
    fn n_holonomic(&self) -> usize {
        2
    }
    fn residual_inplace(&self, _t: f64, q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        let d = Self::axis(q);
        let len = d[0].hypot(d[1]);
        let g = [self.k * (len - self.l) * d[0] / len, self.k * (len - self.l) * d[1] / len];
        for i in 0..2 {
            r[i] = self.m * v_dot[i] - g[i];
            r[2 + i] = self.m * v_dot[2 + i] + g[i];
        }
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
        let d = Self::axis(q);
        let len = d[0].hypot(d[1]);
        let u = [d[0] / len, d[1] / len];
        let s = (len - self.l) / len;
        for i in 0..2 {
            for j in 0..2 {
                let eye = if i == j { 1.0 } else { 0.0 };
                let kg = c_k * self.k * (u[i] * u[j] + s * (eye - u[i] * u[j]));
                k.add(i, j, kg);
                k.add(2 + i, 2 + j, kg);
                k.add(i, 2 + j, -kg);
                k.add(2 + i, j, -kg);
            }
            k.add(i, i, c_m * self.m);
            k.add(2 + i, 2 + i, c_m * self.m);
        }
    }
    fn phi_inplace(&self, _t: f64, q: &[f64], phi: &mut [f64]) {
        phi[0] = q[0] + q[2];
        phi[1] = q[1] + q[3];
    }
    fn phi_q_inplace(&self, _t: f64, _q: &[f64], j: &mut MatView<'_>) {
        for i in 0..2 {
            j.add(i, i, 1.0);
            j.add(i, 2 + i, 1.0);
        }
    }
    fn phi_q_is_constant(&self) -> bool {
        true
    }
    fn corotation_inplace(&self, q_ref: &[f64], q: &[f64], rotations: &mut Vec<f64>) -> bool {
        let (a, b) = (Self::axis(q_ref), Self::axis(q));
        let turn = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
        rotations.clear();
        rotations.extend_from_slice(&[turn.cos(), turn.sin()]);
        true
    }
    fn corotate_inplace(&self, rotations: &[f64], x: &mut [f64], transpose: bool) {
        let (c, s) = (rotations[0], if transpose { -rotations[1] } else { rotations[1] });
        for p in x.chunks_exact_mut(2) {
            let (x0, y0) = (p[0], p[1]);
            p[0] = c * x0 - s * y0;
            p[1] = s * x0 + c * y0;
        }
    }
}

/// A stiff spinning body in absolute coordinates: its matrix turns by ω h = 0.05 rad a step,
/// which stalls a reused factorisation; co-rotated, the factorisation is kept. The answer is as
/// close to a tightly converged run as without co-rotation (2.1e-6 and 2.3e-6 m after 1.6
/// turns; 2.8e-4 m when a co-rotated iterate was accepted on the contraction of its first two
/// increments), and the linear constraints hold to round-off (the co-rotated increments are
/// projected back onto them).
#[test]
fn co_rotated_reuse_keeps_a_turning_matrix_and_its_answer() {
    let run = |corotate: bool, tight: bool| {
        let mut sys = SpinningDumbbell { m: 1.0, k: 1e7, l: 1.0 };
        let mut p = IntegratorParams::new(0.8, 1e-3);
        p.newton.corotate = corotate;
        if tight {
            (p.newton.reuse_factorization, p.newton.rtol, p.newton.atol) = (false, 1e-12, 1e-14);
        }
        let mut ga = GenAlpha::new(p, &sys).unwrap();
        let mut s = State::at_rest(&sys, 0.0, vec![-0.5, 0.0, 0.5, 0.0]);
        // ω = 50 rad/s about the centre (the spring then stretches to carry the centripetal
        // force, and its stiff mode rings, damped)
        s.v.copy_from_slice(&[0.0, -25.0, 0.0, 25.0]);
        ga.initialize(&sys, &mut s).unwrap();
        let mut worst_phi = 0.0_f64;
        for _ in 0..200 {
            ga.step(&mut sys, &mut s).unwrap();
            worst_phi = worst_phi.max((s.q[0] + s.q[2]).abs()).max((s.q[1] + s.q[3]).abs());
        }
        (s.q.clone(), ga.stats().n_factorizations, worst_phi)
    };
    let (q_ref, _, _) = run(false, true);
    let (q_plain, f_plain, _) = run(false, false);
    let (q_co, f_co, phi_co) = run(true, false);
    let error = |q: &[f64]| q.iter().zip(&q_ref).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let (e_plain, e_co) = (error(&q_plain), error(&q_co));
    println!("factorisations {f_plain} → {f_co}; error {e_plain:e} → {e_co:e}; |Φ| {phi_co:e}");
    assert!(f_co * 10 <= f_plain, "co-rotation should keep the matrix: {f_co} against {f_plain}");
    assert!(e_co <= 3e-6 && e_plain <= 3e-6, "errors {e_co:e} (co-rotated), {e_plain:e} (plain)");
    assert!(phi_co < 1e-14, "the constraints should hold to round-off: {phi_co:e}");
}
