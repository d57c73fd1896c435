//! The generic analyses (statics, linearisation, modes) on small systems with exact answers:
//! a spring–mass chain, a hardening spring under load stepping, a pendulum in Cartesian
//! coordinates held by a holonomic and by a velocity-level constraint, a rotation stored as a
//! unit complex number (n_coords ≠ n_dof), and damped oscillators.

use approx::assert_relative_eq;
use genalpha::analysis::{
    StaticParams, StaticSolution, StaticSolver, linearise, load_steps, solve_static, solve_static_path,
};
use genalpha::{ConstrainedSystem, Error, MatView};
use std::f64::consts::PI;

/// Masses `m[i]` in a line, spring `k[i]` between mass `i − 1` (the ground for `i = 0`) and
/// mass `i`, dashpots `c[i]` alongside, forces `load · f[i]`. Optional hardening `k3 q₀³` of
/// the first spring.
struct Chain {
    m: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    k3: f64,
    f: Vec<f64>,
    load: f64,
}

impl Chain {
    fn uniform(n: usize, m: f64, k: f64) -> Self {
        Self { m: vec![m; n], k: vec![k; n], c: vec![0.0; n], k3: 0.0, f: vec![0.0; n], load: 1.0 }
    }
    /// `y_i − y_{i−1}` (with y_{−1} = 0) of spring `i`.
    fn stretch(y: &[f64], i: usize) -> f64 {
        y[i] - if i == 0 { 0.0 } else { y[i - 1] }
    }
    /// Add `c · k_i` on the stencil of spring `i`.
    fn add_spring(k: &mut MatView<'_>, i: usize, value: f64) {
        k.add(i, i, value);
        if i > 0 {
            k.add(i - 1, i - 1, value);
            k.add(i, i - 1, -value);
            k.add(i - 1, i, -value);
        }
    }
}

impl ConstrainedSystem for Chain {
    fn n_coords(&self) -> usize {
        self.m.len()
    }
    fn n_dof(&self) -> usize {
        self.m.len()
    }
    fn residual_inplace(&self, _t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        let n = self.m.len();
        for i in 0..n {
            r[i] = self.m[i] * v_dot[i] - self.load * self.f[i];
        }
        for i in 0..n {
            let hardening = if i == 0 { self.k3 * q[0].powi(3) } else { 0.0 };
            let force = self.k[i] * Self::stretch(q, i) + self.c[i] * Self::stretch(v, i) + hardening;
            r[i] += force;
            if i > 0 {
                r[i - 1] -= force;
            }
        }
    }
    fn iteration_matrix_inplace(
        &self,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        _v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        for i in 0..self.m.len() {
            k.add(i, i, c_m * self.m[i]);
            let stiffness = self.k[i] + if i == 0 { 3.0 * self.k3 * q[0] * q[0] } else { 0.0 };
            Self::add_spring(k, i, c_k * stiffness + c_c * self.c[i]);
        }
    }
}

/// A point mass in the (x, z) plane, gravity −z, held at distance `l` from the origin either by
/// Φ = ½(x² + z² − l²) = 0 or at velocity level by B v = x ẋ + z ż = 0.
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
        _v_dot: &[f64],
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
    /// `∂(Φ_qᵀλ)/∂q = λ I` (and the same for `Bᵀμ`).
    fn constraint_force_tangent_inplace(
        &self,
        _t: f64,
        _q: &[f64],
        lambda: &[f64],
        mu: &[f64],
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        let nu = lambda.first().or(mu.first()).copied().unwrap_or(0.0);
        k.add(0, 0, c_k * nu);
        k.add(1, 1, c_k * nu);
    }
}

/// A rigid pendulum (inertia `j` about the pivot, mass `m` at distance `l`) on a torsion spring
/// `k_t`, driven by a torque `tau`; its angle θ from the hanging position is stored as the unit
/// complex number (cos θ, sin θ): two coordinates, one tangent unknown, retraction = rotation.
struct Rotor {
    j: f64,
    m: f64,
    g: f64,
    l: f64,
    k_t: f64,
    tau: f64,
}

impl Rotor {
    fn angle(q: &[f64]) -> f64 {
        q[1].atan2(q[0])
    }
}

impl ConstrainedSystem for Rotor {
    fn n_coords(&self) -> usize {
        2
    }
    fn n_dof(&self) -> usize {
        1
    }
    fn retract_inplace(&self, q: &[f64], dq: &[f64], q_out: &mut [f64]) {
        let (c, s) = (dq[0].cos(), dq[0].sin());
        q_out[0] = q[0] * c - q[1] * s;
        q_out[1] = q[0] * s + q[1] * c;
    }
    fn residual_inplace(&self, _t: f64, q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        let th = Self::angle(q);
        r[0] = self.j * v_dot[0] + self.k_t * th + self.m * self.g * self.l * th.sin() - self.tau;
    }
    fn iteration_matrix_inplace(
        &self,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        _v_dot: &[f64],
        c_m: f64,
        _c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        let th = Self::angle(q);
        k.add(0, 0, c_m * self.j + c_k * (self.k_t + self.m * self.g * self.l * th.cos()));
    }
}

/// A fixed–free chain of n equal masses and springs: the static deflection under end and
/// distributed loads is exact after one Newton iteration (linear system), and the frequencies
/// are ω_j = 2√(k/m) sin((2j − 1)π / (2(2n + 1))).
#[test]
fn spring_mass_chain_deflection_and_frequencies() {
    let (n, m, k) = (6, 2.0, 300.0);
    let mut chain = Chain::uniform(n, m, k);
    chain.f = (0..n).map(|i| 1.0 + i as f64).collect();
    let sol = solve_static(&chain, 0.0, &vec![0.0; n], &StaticParams::default()).unwrap();
    // spring j carries the sum of the forces outboard of it
    let exact: Vec<f64> = (0..n)
        .scan(0.0, |y, j| {
            *y += chain.f[j..].iter().sum::<f64>() / k;
            Some(*y)
        })
        .collect();
    for (a, b) in sol.q.iter().zip(&exact) {
        assert_relative_eq!(*a, *b, max_relative = 1e-13);
    }
    // one solve; the residual after it is at round-off (converged by the residual test)
    assert_eq!(sol.n_iterations, 1);
    assert!(sol.residual_norm < 1e-12, "{}", sol.residual_norm);

    let lin = linearise(&chain, 0.0, &sol.q, &[], &[]).unwrap();
    assert_eq!(lin.n_free(), n);
    let modes = lin.natural_modes().unwrap();
    let mut worst: f64 = 0.0;
    for (j, w) in modes.omega.iter().enumerate() {
        let exact = 2.0 * (k / m).sqrt() * ((2 * j + 1) as f64 * PI / (2.0 * (2 * n + 1) as f64)).sin();
        worst = worst.max((w / exact - 1.0).abs());
    }
    println!("chain: worst relative frequency error {worst:.1e}");
    assert!(worst < 1e-13, "{worst}");
    // mass-orthonormal shapes
    let gram = modes.shapes.transpose() * &lin.mass * &modes.shapes;
    assert_relative_eq!(gram, nalgebra::DMatrix::identity(n, n), epsilon = 1e-12);
}

/// Load stepping on a hardening spring k u + k3 u³ = p F: each continuation step starts from
/// the last equilibrium, and every equilibrium is the real root of the cubic (Cardano).
#[test]
fn hardening_spring_load_path() {
    let (k, k3, f) = (100.0, 4e4, 50.0);
    let mut spring = Chain { m: vec![1.0], k: vec![k], c: vec![0.0], k3, f: vec![f], load: 0.0 };
    let path = load_steps(5);
    let sols = solve_static_path(&mut spring, 0.0, &[0.0], &StaticParams::default(), &path, |s, p| s.load = p).unwrap();
    for (p, sol) in path.iter().zip(&sols) {
        // u³ + a u = b: u = ∛(b/2 + √D) + ∛(b/2 − √D), D = (b/2)² + (a/3)³
        let (a, b) = (k / k3, p * f / k3);
        let d = (b / 2.0).powi(2) + (a / 3.0).powi(3);
        let exact = (b / 2.0 + d.sqrt()).cbrt() + (b / 2.0 - d.sqrt()).cbrt();
        println!("load {p:.1}: u = {:.12}, exact {exact:.12}, iterations so far {}", sol.q[0], sol.n_iterations);
        assert_relative_eq!(sol.q[0], exact, max_relative = 1e-12);
    }
    assert!(sols[4].n_iterations > 5, "the nonlinear path takes several iterations");
    // the stiffness at the end of the path: k + 3 k3 u²
    let u = sols[4].q[0];
    let lin = linearise(&spring, 0.0, &sols[4].q, &[], &[]).unwrap();
    assert_relative_eq!(lin.stiffness[(0, 0)], k + 3.0 * k3 * u * u, max_relative = 1e-14);

    // a path the spring cannot follow in one iteration fails as a continuation step
    let params = StaticParams { max_iter: 1, ..StaticParams::default() };
    let err = solve_static_path(&mut spring, 0.0, &[0.0], &params, &[1.0], |s, p| s.load = p).unwrap_err();
    match err {
        Error::ContinuationFailed { step: 0, parameter, source } => {
            assert_eq!(parameter, 1.0);
            assert!(matches!(*source, Error::StaticNotConverged { iter: 1, .. }), "{source:?}");
        }
        other => panic!("unexpected error {other:?}"),
    }
}

/// Pendulum in Cartesian coordinates with the holonomic constraint ½(x² + z² − l²) = 0: Newton
/// from an offset start finds the hanging equilibrium with λ = m g / l; the linearisation
/// (stiffness λ I from the constraint force alone) gives ω = √(g/l) on the one free motion.
/// The inverted equilibrium has λ = −m g / l and ω² = −g/l.
#[test]
fn pendulum_holonomic_linearised_frequency() {
    let p = Pendulum { m: 0.7, g: 9.81, l: 1.3, velocity_level: false };
    for (start, sign) in [([0.4, -1.1], 1.0), ([0.3, 1.2], -1.0)] {
        let mut solver = StaticSolver::new(&p, StaticParams::default());
        let mut x = StaticSolution::guess(&p, &start);
        // at λ = 0 the pendulum has no stiffness along the circle: start from a tension guess
        x.lambda[0] = sign * p.m * p.g / p.l * 0.5;
        solver.solve(&p, 0.0, &mut x).unwrap();
        assert!(x.q[0].abs() < 1e-12 && (x.q[1] + sign * p.l).abs() < 1e-12, "{:?}", x.q);
        assert_relative_eq!(x.lambda[0], sign * p.m * p.g / p.l, max_relative = 1e-12);
        assert!(x.constraint_norm < 1e-13 && x.residual_norm < 1e-12, "{x:?}");
        let lin = linearise(&p, 0.0, &x.q, &x.lambda, &x.mu).unwrap();
        assert_eq!(lin.n_free(), 1);
        let modes = lin.natural_modes().unwrap();
        assert_relative_eq!(modes.omega_squared[0], sign * p.g / p.l, max_relative = 1e-12);
        // the free motion is horizontal
        assert!(modes.shapes[(1, 0)].abs() < 1e-12 && modes.shapes[(0, 0)] > 0.0);
        // damped form: ±i√(g/l) hanging; a real pair ±√(g/l) inverted
        let damped = lin.damped_modes(0).unwrap();
        let w = (p.g / p.l).sqrt();
        if sign > 0.0 {
            assert_eq!(damped.len(), 1);
            assert_relative_eq!(damped[0].eigenvalue.im, w, max_relative = 1e-12);
            assert!(damped[0].eigenvalue.re.abs() < 1e-12 * w);
        } else {
            let mut re: Vec<f64> = damped.iter().map(|d| d.eigenvalue.re).collect();
            re.sort_by(f64::total_cmp);
            assert_relative_eq!(re.as_slice(), [-w, w].as_slice(), max_relative = 1e-12);
        }
    }
}

/// The same pendulum held by the velocity-level row B v = x ẋ + z ż = 0 (b = 0): each Newton
/// increment moves along the circle through the current point, so the iterates leave the
/// circle at second order and the equilibrium is straight below the pivot at a radius a little
/// above l, with μ = m g / |z|; the linearised frequency is √(g/|z|) exactly.
#[test]
fn pendulum_velocity_constraint_linearised_frequency() {
    let p = Pendulum { m: 0.7, g: 9.81, l: 1.3, velocity_level: true };
    let x0 = 0.2;
    let mut solver = StaticSolver::new(&p, StaticParams::default());
    let mut x = StaticSolution::guess(&p, &[x0, -(p.l * p.l - x0 * x0).sqrt()]);
    x.mu[0] = p.m * p.g / p.l;
    solver.solve(&p, 0.0, &mut x).unwrap();
    let radius = -x.q[1];
    println!("velocity-level pendulum: radius {radius:.6} (l = {}), {} iterations", p.l, x.n_iterations);
    assert!(x.q[0].abs() < 1e-12, "{:?}", x.q);
    assert!(radius > p.l && radius - p.l < x0 * x0 / p.l, "radius {radius}");
    assert_relative_eq!(x.mu[0], p.m * p.g / radius, max_relative = 1e-12);
    let lin = linearise(&p, 0.0, &x.q, &x.lambda, &x.mu).unwrap();
    assert_eq!((lin.n_holonomic, lin.n_free()), (0, 1));
    let modes = lin.natural_modes().unwrap();
    assert_relative_eq!(modes.omega[0], (p.g / radius).sqrt(), max_relative = 1e-12);
}

/// A rotation stored as a unit complex number (two coordinates, one tangent unknown): Newton
/// with the rotation retraction finds the angle where k_t θ + m g l sin θ = τ, and the
/// linearised frequency is √((k_t + m g l cos θ)/J).
#[test]
fn retraction_with_more_coordinates_than_unknowns() {
    let theta = 1.0;
    let mut rotor = Rotor { j: 0.3, m: 0.7, g: 9.81, l: 0.5, k_t: 2.0, tau: 0.0 };
    rotor.tau = rotor.k_t * theta + rotor.m * rotor.g * rotor.l * theta.sin();
    let mut solver = StaticSolver::new(&rotor, StaticParams::default());
    let mut x = StaticSolution::guess(&rotor, &[1.0, 0.0]);
    // the normalisation hook: keep the stored number on the unit circle
    solver
        .solve_normalised(&rotor, 0.0, &mut x, |q| {
            let r = q[0].hypot(q[1]);
            q.iter_mut().for_each(|c| *c /= r);
        })
        .unwrap();
    assert_relative_eq!(Rotor::angle(&x.q), theta, max_relative = 1e-12);
    let modes = linearise(&rotor, 0.0, &x.q, &[], &[]).unwrap().natural_modes().unwrap();
    let exact = ((rotor.k_t + rotor.m * rotor.g * rotor.l * theta.cos()) / rotor.j).sqrt();
    assert_relative_eq!(modes.omega[0], exact, max_relative = 1e-12);
}

/// A damped oscillator m ẍ + c ẋ + k x = 0 has s = −ζω ± iω√(1 − ζ²); a two-mass chain with
/// Rayleigh damping C = αM + βK has ζ_j = α/(2ω_j) + βω_j/2 on its undamped mode shapes.
#[test]
fn damped_oscillators_complex_eigenvalues() {
    let (m, k, zeta): (f64, f64, f64) = (1.5, 600.0, 0.05);
    let w = (k / m).sqrt();
    let mut one = Chain::uniform(1, m, k);
    one.c[0] = 2.0 * zeta * w * m;
    let lin = linearise(&one, 0.0, &[0.0], &[], &[]).unwrap();
    let modes = lin.damped_modes(1).unwrap();
    assert_eq!(modes.len(), 1);
    assert_relative_eq!(modes[0].eigenvalue.re, -zeta * w, max_relative = 1e-12);
    assert_relative_eq!(modes[0].eigenvalue.im, w * (1.0 - zeta * zeta).sqrt(), max_relative = 1e-12);
    assert_relative_eq!(modes[0].frequency(), w, max_relative = 1e-12);
    assert_relative_eq!(modes[0].damping_ratio(), zeta, max_relative = 1e-12);

    // two masses, Rayleigh damping: springs k, k; masses m, m/2
    let (alpha, beta) = (0.8, 2e-4);
    let mut two = Chain { m: vec![m, 0.5 * m], k: vec![k, k], c: vec![0.0; 2], k3: 0.0, f: vec![0.0; 2], load: 1.0 };
    let undamped = linearise(&two, 0.0, &[0.0, 0.0], &[], &[]).unwrap();
    let natural = undamped.natural_modes().unwrap();
    // C = α M + β K cannot be built from the dashpots alone (α M is not a dashpot): add it to
    // the linearisation directly, as a model with mass-proportional damping would
    let mut lin = undamped.clone();
    lin.damping = &lin.mass * alpha + &lin.stiffness * beta;
    lin.reduced_damping = lin.null_space.transpose() * &lin.damping * &lin.null_space;
    let damped = lin.damped_modes(2).unwrap();
    for (j, mode) in damped.iter().enumerate() {
        let wj = natural.omega[j];
        let zj = alpha / (2.0 * wj) + beta * wj / 2.0;
        println!("mode {j}: ω {wj:.4} rad/s, ζ {:.6} (Rayleigh {zj:.6})", mode.damping_ratio());
        assert_relative_eq!(mode.frequency(), wj, max_relative = 1e-12);
        assert_relative_eq!(mode.damping_ratio(), zj, max_relative = 1e-10);
        // proportional damping keeps the real undamped shapes
        let shape = mode.shape.as_ref().expect("shape requested");
        let phi = natural.shapes.column(j);
        let imax = phi.iamax();
        for i in 0..2 {
            assert_relative_eq!(shape[i].re, phi[i] / phi[imax], epsilon = 1e-9);
            assert!(shape[i].im.abs() < 1e-9, "{shape:?}");
        }
    }
    // the dashpot-only chain: damped eigenvalues against the undamped ones as c → 0
    two.c = vec![1e-9; 2];
    let tiny = linearise(&two, 0.0, &[0.0, 0.0], &[], &[]).unwrap().damped_modes(0).unwrap();
    for (mode, w) in tiny.iter().zip(&natural.omega) {
        assert_relative_eq!(mode.frequency(), *w, max_relative = 1e-12);
    }
}

/// A model that cannot evaluate its residual somewhere (NaN entries: an aerodynamic lattice that
/// folds over) is a non-finite state, not an equilibrium: a NaN must not pass for a zero
/// residual.
#[test]
fn a_residual_with_nan_entries_is_not_an_equilibrium() {
    struct Partial(Chain);
    impl ConstrainedSystem for Partial {
        fn n_coords(&self) -> usize {
            self.0.n_coords()
        }
        fn n_dof(&self) -> usize {
            self.0.n_dof()
        }
        fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
            self.0.residual_inplace(t, q, v, v_dot, r);
            if q[0] > 0.1 {
                r[1] = f64::NAN;
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
            self.0.iteration_matrix_inplace(t, q, v, v_dot, c_m, c_c, c_k, k);
        }
    }
    // Loaded to q₀ = 1, past the model's domain.
    let mut chain = Chain::uniform(2, 1.0, 1.0);
    chain.f = vec![1.0, 0.0];
    let err = solve_static(&Partial(chain), 0.0, &[0.0, 0.0], &StaticParams::default()).unwrap_err();
    assert!(matches!(err, Error::NonFinite { .. }), "{err:?}");
}
