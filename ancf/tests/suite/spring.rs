//! Hinge springs and dampers (docs/ancf.md §11): analytic tangents against finite differences,
//! the small-oscillation frequency √(k/J) of a stiff body, and springs wound past ±180°. The
//! energy balance with a damper is checked for every formulation in
//! `aeroelastic/tests/suite/cross_formulation.rs`.
use ancf::{BodySpec, ForceElement, JointSpec, Model, Options, RigidPose, Scene, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseMatrix, IntegratorParams, State};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

fn spring(joint: usize, stiffness: f64, damping: f64, rest: f64) -> ForceElement {
    ForceElement::HingeSpring { joint, stiffness, damping, rest }
}

/// The paper's pendulum (3 elements per body) with `forces`.
fn pendulum(beta_deg: f64, forces: Vec<ForceElement>, path: SolvePath) -> Model {
    let (bodies, joints, g) = samples::double_pendulum(1.0, beta_deg, 3);
    let scene = Scene { forces, ..Scene::new(bodies, joints, g) };
    Model::from_scene(&scene, Options { path, ..Default::default() }).expect("valid scene")
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// States of the form `model` integrates: (a) the reference with noise on every coordinate,
/// (b) body 0 turned by 2.9 rad about the ground axis and body 1 folded by 2.7 rad about the
/// flared axis (near ±180°), with noise.
fn states(model: &Model, beta: f64) -> Vec<(Vec<f64>, Vec<f64>)> {
    let b: Vec<&BodySpec> = (0..2).map(|i| model.body_spec(i).unwrap()).collect();
    let r0 = Rotation3::from_axis_angle(&Vector3::y_axis(), 2.9).into_inner();
    let a = Vector3::new(beta.sin(), beta.cos(), 0.0);
    let fold = Rotation3::from_axis_angle(&Unit::new_normalize(-(r0 * a)), 2.7).into_inner();
    let poses = [
        [RigidPose::at_rest(b[0].start), RigidPose::at_rest(b[1].start)],
        [
            RigidPose { rotation: r0, ..RigidPose::at_rest(b[0].start) },
            RigidPose { rotation: fold * r0, translation: r0 * b[1].start, ..RigidPose::at_rest(b[1].start) },
        ],
    ];
    poses
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let s = model.rigid_state(p).unwrap();
            let noise = |i: usize, amp: f64| amp * (((i * 37 + 11 * k) % 101) as f64 / 101.0 - 0.5);
            let q = s.q.iter().enumerate().map(|(i, x)| x + noise(i, 0.04)).collect();
            let v = (0..s.q.len()).map(|i| noise(i + 5, 3.0)).collect();
            (q, v)
        })
        .collect()
}

/// The spring's own residual and iteration matrix: the model with springs minus the model
/// without, so that the elastic forces cannot hide an error in the spring terms.
struct SpringPart {
    with: Model,
    without: Model,
}

impl SpringPart {
    fn residual(&self, q: &[f64], v: &[f64]) -> Vec<f64> {
        let n = self.with.n_dof();
        let a = vec![0.0; n];
        let (mut r1, mut r0) = (vec![0.0; n], vec![0.0; n]);
        self.with.residual_inplace(0.0, q, v, &a, &mut r1);
        self.without.residual_inplace(0.0, q, v, &a, &mut r0);
        r1.iter().zip(&r0).map(|(x, y)| x - y).collect()
    }
    fn matrix(&self, q: &[f64], v: &[f64], c_c: f64, c_k: f64) -> DenseMatrix {
        let n = self.with.n_dof();
        let a = vec![0.0; n];
        let (mut k1, mut k0) = (DenseMatrix::zeros(n, n), DenseMatrix::zeros(n, n));
        self.with.iteration_matrix_inplace(0.0, q, v, &a, 0.0, c_c, c_k, &mut k1.view());
        self.without.iteration_matrix_inplace(0.0, q, v, &a, 0.0, c_c, c_k, &mut k0.view());
        for (x, y) in k1.as_mut_slice().iter_mut().zip(k0.as_slice()) {
            *x -= y;
        }
        k1
    }
}

/// ∂r/∂q (with c_k) and ∂r/∂v (with c_c) of the springs and dampers on both hinges of the paper's
/// pendulum equal central differences of their residual, on both paths, at a deformed moving
/// state and at one folded near ±180°. Measured: ≤ 1.4e-7 relative (h = 1e-6).
#[test]
fn spring_and_damper_tangents_equal_finite_differences() {
    let beta = 45f64.to_radians();
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let forces = vec![spring(0, 3.0, 0.7, 0.2), spring(1, 2.0, 0.4, -0.3)];
        let part = SpringPart { with: pendulum(45.0, forces, path), without: pendulum(45.0, Vec::new(), path) };
        let n = part.with.n_dof();
        for (s, (q, v)) in states(&part.with, beta).into_iter().enumerate() {
            for (c_c, c_k) in [(0.0, 1.0), (1.0, 0.0)] {
                let k = part.matrix(&q, &v, c_c, c_k);
                let h = 1e-6;
                let mut fd = DenseMatrix::zeros(n, n);
                for j in 0..n {
                    let (mut qp, mut qm, mut vp, mut vm) = (q.clone(), q.clone(), v.clone(), v.clone());
                    if c_k != 0.0 {
                        qp[j] += h;
                        qm[j] -= h;
                    } else {
                        vp[j] += h;
                        vm[j] -= h;
                    }
                    let (rp, rm) = (part.residual(&qp, &vp), part.residual(&qm, &vm));
                    for i in 0..n {
                        *fd.get_mut(i, j) = (rp[i] - rm[i]) / (2.0 * h);
                    }
                }
                let scale = max_abs(fd.as_slice());
                let diff: Vec<f64> = k.as_slice().iter().zip(fd.as_slice()).map(|(a, b)| a - b).collect();
                let err = max_abs(&diff) / scale;
                println!("{path:?} state {s} c_c {c_c} c_k {c_k}: |K| {scale:.3e}, relative error {err:.2e}");
                assert!(scale > 0.1, "the spring part vanished");
                assert!(err < 1e-6, "{path:?} state {s} (c_c {c_c}, c_k {c_k}): {err:e}");
            }
        }
    }
}

/// One stiff body (the pendulum's body at c = 100) on a ground hinge about +Y, no gravity.
fn stiff_body(length: f64) -> BodySpec {
    BodySpec {
        name: "stiff".into(),
        start: Vector3::zeros(),
        length,
        frame: Matrix3::identity(),
        section: samples::paper_section(100.0),
        n_elements: 4,
        point_masses: Vec::new(),
        twist: ancf::Twist::none(),
    }
}

fn run(model: &mut Model, state: &mut State, params: IntegratorParams, n: usize, mut f: impl FnMut(&Model, &State)) {
    let mut ga = model.integrator(params).expect("valid parameters");
    ga.initialize(model, state).expect("consistent start");
    f(model, state);
    for _ in 0..n {
        ga.step(model, state).unwrap_or_else(|e| panic!("{e}"));
        f(model, state);
    }
}

/// Small oscillations of a stiff body on a sprung ground hinge: the period measured from the
/// zero crossings of θ over three periods equals 2π √(J/k), J the body's moment of inertia about
/// the hinge axis (`BodySpec::reference_inertia`, exact for this section since
/// ρI_xx = ρI_yy + ρI_zz). Tolerance 0.1 %; measured: period +6.5e-5 (DAE), +6.2e-5 (ODE). The
/// linearised model (`Model::linear_modes`, the spring's stiffness included) has the same
/// frequency error, −6.05e-5, so this is the residual flexibility of the body at c = 100
/// (−2.0e-5 at c = 1000), not the integrator (dt = 1 ms, rho_inf = 0.9: (ωh)²/12 ≈ 2e-6).
#[test]
fn small_oscillation_frequency_is_sqrt_k_over_j() {
    let body = stiff_body(0.5);
    let axis = Vector3::y();
    let j: f64 = axis.dot(&(body.reference_inertia().inertia_about_origin() * axis));
    let k = 1.0;
    let omega = (k / j).sqrt();
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let scene = Scene {
            forces: vec![spring(0, k, 0.0, 0.0)],
            ..Scene::new(vec![body.clone()], vec![JointSpec::GroundHinge { body: 0, axis }], Vector3::zeros())
        };
        let mut model = Model::from_scene(&scene, Options { path, ..Default::default() }).unwrap();
        let modal = model.linear_modes(model.reference_coordinates()).unwrap()[0].omega / omega - 1.0;
        assert!(modal.abs() < 1e-3, "linearised frequency error {modal:e}");
        let pose = RigidPose { angular_velocity: axis * 0.01, ..RigidPose::at_rest(body.start) };
        let mut state = model.rigid_state(&[pose]).unwrap();
        let dt = 1e-3;
        let n_steps = (3.2 * std::f64::consts::TAU / omega / dt) as usize;
        let mut samples: Vec<(f64, f64)> = Vec::new();
        run(&mut model, &mut state, IntegratorParams::new(0.9, dt), n_steps, |m, s| {
            samples.push((s.t, m.hinge_angle(&s.q, 0).unwrap()));
        });
        // downward and upward zero crossings after t = 0, linearly interpolated
        let crossings: Vec<f64> = samples
            .windows(2)
            .filter(|w| w[0].0 > 0.0 && w[0].1.signum() != w[1].1.signum())
            .map(|w| w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1))
            .collect();
        assert!(crossings.len() >= 6, "{} crossings", crossings.len());
        let period = 2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
        let expected = std::f64::consts::TAU / omega;
        let err = period / expected - 1.0;
        println!(
            "{path:?}: J = {j:.6e} kg m², period {period:.6} s, 2π√(J/k) = {expected:.6} s, error {err:.2e} \
             (linear modes: frequency error {modal:.2e})"
        );
        assert!(err.abs() < 1e-3, "{path:?}: period error {err:e}");
    }
}

/// The pendulum with springs and dampers on both hinges: the DAE path (unsymmetric iteration
/// matrix through the skyline LU's unsymmetric storage) follows the ODE path to solver
/// tolerance (rho_inf = 0.8, 2 s), and so does the DAE path with the integrator's default
/// solver (the bordered band LU on the declared structure, where the flared hinge's spring
/// merges the two bodies' blocks). Measured: 9.6e-12 m, 9.6e-12 m. (The springs are at rest at t = 0. A spring preloaded at t = 0, θ₀ ≠ 0, is a step
/// moment on the hinge nodes' slopes: Newton then needs step halvings at the start, 13 for
/// 0.6 N·m here, and the two paths halve at different steps and differ by 2e-5 m.)
#[test]
fn damped_pendulum_dae_matches_ode() {
    let tips: Vec<Vec<Vector3<f64>>> = [(SolvePath::Dae, true), (SolvePath::Ode, true), (SolvePath::Dae, false)]
        .into_iter()
        .map(|(path, skyline)| {
            let (bodies, joints, g) = samples::double_pendulum(1.0, 45.0, 5);
            let forces = vec![spring(0, 0.5, 0.02, 0.0), spring(1, 2.0, 0.05, 0.0)];
            let scene = Scene { forces, ..Scene::new(bodies, joints, g) };
            let mut model = Model::from_scene(&scene, Options { path, ..Default::default() }).unwrap();
            let mut state = model.initial_state();
            let params = IntegratorParams::new(0.8, 0.002);
            let mut tips = Vec::new();
            if skyline {
                run(&mut model, &mut state, params, 1000, |m, s| tips.push(m.tip_position(&s.q)));
            } else {
                let mut ga = genalpha::GenAlpha::new(params, &model).unwrap();
                ga.initialize(&model, &mut state).unwrap();
                tips.push(model.tip_position(&state.q));
                for _ in 0..1000 {
                    ga.step(&mut model, &mut state).unwrap();
                    tips.push(model.tip_position(&state.q));
                }
            }
            tips
        })
        .collect();
    let diff =
        |a: &[Vector3<f64>], b: &[Vector3<f64>]| a.iter().zip(b).map(|(x, y)| (x - y).norm()).fold(0.0, f64::max);
    let (ode, banded) = (diff(&tips[0], &tips[1]), diff(&tips[2], &tips[1]));
    println!(
        "damped pendulum: max tip difference to the ODE path {ode:.2e} m (DAE, skyline), {banded:.2e} m (DAE, band LU)"
    );
    assert!(ode < 1e-6 && banded < 1e-6, "{ode}, {banded}");
}

/// The band structure the model declares to the integrator holds every non-zero of the
/// iteration matrix with springs on both hinges (the flared hinge's spring couples the last
/// node of body 0 to the first node of body 1): inside a block only within its half-bandwidth,
/// between blocks nothing (the border, all joint rows, is free). Both paths.
#[test]
fn declared_structure_covers_the_spring_couplings() {
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let forces = vec![spring(0, 3.0, 0.7, 0.2), spring(1, 2.0, 0.4, -0.3)];
        let model = pendulum(45.0, forces, path);
        let structure = model.matrix_structure().expect("declared");
        let n = model.n_dof();
        let block_of = |i: usize| structure.blocks.iter().position(|&(f, len, _)| (f..f + len).contains(&i));
        for (q, v) in states(&model, 45f64.to_radians()) {
            let mut k = DenseMatrix::zeros(n, n);
            model.iteration_matrix_inplace(0.0, &q, &v, &vec![0.0; n], 1.0, 1.0, 1.0, &mut k.view());
            for j in 0..n {
                for i in 0..n {
                    if k.get(i, j) == 0.0 {
                        continue;
                    }
                    match (block_of(i), block_of(j)) {
                        (Some(a), Some(b)) if a == b => {
                            let w = structure.blocks[a].2;
                            assert!(i.abs_diff(j) <= w, "{path:?}: ({i}, {j}) outside the half-bandwidth {w}");
                        }
                        (Some(a), Some(b)) => panic!("{path:?}: ({i}, {j}) couples blocks {a} and {b}"),
                        _ => {}
                    }
                }
            }
        }
        println!("{path:?}: blocks {:?}", structure.blocks);
    }
}

/// The static solver sees the spring: a stiff body on a sprung ground hinge about +Y, drooping
/// under gravity, settles where `k θ = m g (L/2) cos θ` (the rigid-body balance). Tolerance
/// 1e-4 relative; measured: −5.6e-5, the stiff body's residual compliance at its root (the
/// same order as the frequency test's −6e-5).
#[test]
fn static_equilibrium_balances_spring_and_gravity() {
    let body = stiff_body(0.5);
    let (k, g) = (2.0, 9.8);
    let scene = Scene {
        forces: vec![spring(0, k, 0.0, 0.0)],
        ..Scene::new(
            vec![body.clone()],
            vec![JointSpec::GroundHinge { body: 0, axis: Vector3::y() }],
            Vector3::new(0.0, 0.0, -g),
        )
    };
    let mut model = Model::from_scene(&scene, Options::default()).unwrap();
    let sol = model.solve_static(ancf::statics::StaticsParams::default()).unwrap();
    let theta = model.hinge_angle(&sol.q, 0).unwrap();
    // k θ = W cos θ by Newton's method
    let w = body.section.mass * body.length * g * 0.5 * body.length;
    let mut exact = 0.5;
    for _ in 0..50 {
        exact -= (k * exact - w * f64::cos(exact)) / (k + w * f64::sin(exact));
    }
    let err = theta / exact - 1.0;
    println!("static droop {theta:.8} rad, rigid-body balance {exact:.8} rad, error {err:.2e}");
    assert!(err.abs() < 1e-4, "{err:e}");
}

/// Records of a spin: (t, θ, total energy, spring energy).
type Spin = Vec<(f64, f64, f64, f64)>;

/// A weak spring wound past ±180°: a stiff body is spun by an initial angular velocity ω₀ about
/// its hinge axis so that the rigid-body answer θ_max = ω₀ √(J/k) = 1.5π. Ground hinge (the
/// single body of the frequency test) and flared hinge (β = 30°, the child of a clamped stiff
/// parent). The angle passes π continuously (no step changes it by more than 1.01 ω₀ dt), the
/// spring energy has no jump, θ_max is the rigid-body value within 0.1 %, and T + U + spring
/// energy is conserved within 1e-4 of the initial kinetic energy (rho_inf = 1, dt = 1 ms, ODE
/// path). Measured: θ_max error −7.5e-7 (ground), −8.2e-5 (flared: the clamped parent bends
/// under the spinning child); energy error 5.0e-6, 5.8e-6. (At
/// dt = 2 ms the flared case's energy error is 3.3e-4, and 4.2e-4 with no spring at all: the
/// integrator on the spinning elastic bodies, not the spring.)
#[test]
fn springs_wind_past_half_a_turn_without_a_jump() {
    let k = 0.01;
    let dt = 1e-3;
    let beta = 30f64.to_radians();
    // ground hinge
    let ground = {
        let body = stiff_body(0.5);
        let j = body.reference_inertia().inertia_about_origin()[(1, 1)];
        let scene = Scene {
            forces: vec![spring(0, k, 0.0, 0.0)],
            ..Scene::new(
                vec![body.clone()],
                vec![JointSpec::GroundHinge { body: 0, axis: Vector3::y() }],
                Vector3::zeros(),
            )
        };
        (scene, j, Vector3::y(), 0usize)
    };
    // flared hinge on a clamped parent: the child turns about a = sin β X + cos β Y
    let flared = {
        let (parent, mut child) = (stiff_body(0.5), stiff_body(0.5));
        child.start = parent.end();
        let a = Vector3::new(beta.sin(), beta.cos(), 0.0);
        let inertia = child.reference_inertia();
        let d = inertia.centre - child.start;
        let about_start = inertia.inertia + inertia.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose());
        let j: f64 = a.dot(&(about_start * a));
        let scene = Scene {
            forces: vec![spring(1, k, 0.0, 0.0)],
            ..Scene::new(
                vec![parent, child],
                vec![JointSpec::Clamp { body: 0 }, JointSpec::FlaredHinge { parent: 0, child: 1, beta }],
                Vector3::zeros(),
            )
        };
        (scene, j, a, 1usize)
    };
    for (name, (scene, j, axis, joint)) in [("ground", ground), ("flared", flared)] {
        let theta_max = 1.5 * std::f64::consts::PI;
        let omega0 = theta_max * (k / j).sqrt();
        let mut model = Model::from_scene(&scene, Options { path: SolvePath::Ode, ..Default::default() }).unwrap();
        let poses: Vec<RigidPose> = scene
            .bodies
            .iter()
            .enumerate()
            .map(|(b, spec)| {
                let w = if b == scene.bodies.len() - 1 { axis * omega0 } else { Vector3::zeros() };
                RigidPose { angular_velocity: w, ..RigidPose::at_rest(spec.start) }
            })
            .collect();
        let mut state = model.rigid_state(&poses).unwrap();
        // a quarter period reaches θ_max; run on to 1.3 quarter periods
        let quarter = 0.25 * std::f64::consts::TAU * (j / k).sqrt();
        let mut spin: Spin = Vec::new();
        run(&mut model, &mut state, IntegratorParams::new(1.0, dt), (1.3 * quarter / dt) as usize, |m, s| {
            let e = m.energies(&s.q, &s.v);
            spin.push((s.t, m.hinge_angle(&s.q, joint).unwrap(), e.total(), e.spring));
        });
        let peak = spin.iter().map(|r| r.1.abs()).fold(0.0, f64::max);
        let max_step = spin.windows(2).map(|w| (w[1].1 - w[0].1).abs()).fold(0.0, f64::max);
        let max_spring_jump = spin.windows(2).map(|w| (w[1].3 - w[0].3).abs()).fold(0.0, f64::max);
        let e0 = spin[0].2;
        let energy = spin.iter().map(|r| (r.2 - e0).abs()).fold(0.0, f64::max) / e0;
        let peak_err = peak / theta_max - 1.0;
        println!(
            "{name}: omega0 {omega0:.4} rad/s, peak |theta| {peak:.6} (rigid {theta_max:.6}, error {peak_err:.2e}), \
             largest step in theta {max_step:.3e} (omega0 dt = {:.3e}), largest spring-energy step {max_spring_jump:.3e} J, \
             energy error {energy:.2e} of E0",
            omega0 * dt
        );
        assert!(peak > std::f64::consts::PI * 1.4, "{name}: did not wind past 180°: {peak}");
        assert!(max_step < 1.01 * omega0 * dt, "{name}: θ jumps by {max_step}");
        // the spring energy changes per step by at most k θ_max ω₀ dt (its largest rate)
        assert!(
            max_spring_jump < 1.01 * k * theta_max * omega0 * dt,
            "{name}: spring energy jumps by {max_spring_jump}"
        );
        assert!(peak_err.abs() < 1e-3, "{name}: θ_max {peak} vs {theta_max}");
        assert!(energy < 1e-4, "{name}: energy error {energy:e}");
    }
}
