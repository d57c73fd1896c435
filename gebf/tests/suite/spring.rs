//! Hinge springs and dampers (`scene::ForceElement::HingeSpring`, docs/gebf.md §13): the
//! moment `−k(θ − θ₀) − c θ̇` about a ground or flared hinge.
//!
//! * the spring's own generalised force and its position and velocity tangents against finite
//!   differences along the retraction, at random states of the paper's pendulum;
//! * a stiff body on a ground hinge with a spring oscillates at `√(k/J)`, J about the hinge axis
//!   from `BodySpec::reference_inertia()`, and about the rest angle;
//! * (the paper's pendulum with a damper, `E(t) + ∫ c θ̇² dt` constant: for every formulation
//!   in `aeroelastic/tests/suite/cross_formulation.rs`);
//! * springs through ±180° (ground and flared hinge): the angle and the force are continuous,
//!   the energy conserved.

use gebf::{BodySpec, ForceElement, JointSpec, Model, Options, RigidPose, Scene, Section, samples, simulate};
use genalpha::{ConstrainedSystem, DenseMatrix, GenAlpha, IntegratorParams};
use nalgebra::{Matrix3, Rotation3, Vector3};
use std::f64::consts::PI;

/// A stiff section: its bending modes are thousands of times faster than the spring's.
fn stiff_section() -> Section {
    Section::centred(2.0, 0.02, 0.01, 0.01, 1e9, 1e9, 1e9, 1e7, 1e7, 1e7)
}

fn body(name: &str, start: Vector3<f64>, frame: Matrix3<f64>, length: f64, n_elements: usize) -> BodySpec {
    BodySpec {
        name: name.into(),
        start,
        length,
        frame,
        section: stiff_section(),
        n_elements,
        point_masses: Vec::new(),
        twist: gebf::Twist::none(),
    }
}

fn spring(joint: usize, stiffness: f64, damping: f64, rest: f64) -> ForceElement {
    ForceElement::HingeSpring { joint, stiffness, damping, rest }
}

/// A deterministic pseudo-random generator in [−1, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// The spring's own forces and tangents (the difference of the pendulum with and without the
/// springs at the same state) against central differences (h = 1e-6) along the retraction, at
/// random states whose fold angles reach past ±90°. Tolerance: 1e-6 relative (max-norm), as in
/// the crate's other tangent checks; measured ≤ 2e-9.
#[test]
fn spring_force_jacobians_match_finite_differences() {
    // Soft sections (c = 1e-3): the elastic forces at the random states stay of order 100 N, so
    // the differences' cancellation error (~1e-16 · |r| / h) stays far below the tolerance.
    let (b, j, g) = samples::double_pendulum(1e-3, 30.0, 3);
    let plain = Scene::new(b, j, g);
    let mut sprung = plain.clone();
    sprung.forces = vec![spring(0, 4.0, 0.3, 0.2), spring(1, 2.5, 0.8, -0.5)];
    let with = Model::from_scene(&sprung, Options::default()).unwrap();
    let without = Model::from_scene(&plain, Options::default()).unwrap();
    let n = with.n_dof();
    let mut rng = Lcg(17);
    for trial in 0..4 {
        let q0 = with.reference_coordinates();
        let dq: Vec<f64> = (0..n).map(|_| rng.next() * (0.3 + 0.6 * trial as f64)).collect();
        let mut q = q0.clone();
        with.retract_inplace(&q0, &dq, &mut q);
        let v: Vec<f64> = (0..n).map(|_| rng.next()).collect();
        let a = vec![0.0; n];
        let force = |q: &[f64], v: &[f64]| {
            let (mut r1, mut r0) = (vec![0.0; n], vec![0.0; n]);
            with.residual_inplace(0.0, q, v, &a, &mut r1);
            without.residual_inplace(0.0, q, v, &a, &mut r0);
            r1.iter().zip(&r0).map(|(x, y)| x - y).collect::<Vec<f64>>()
        };
        let h = 1e-6;
        for (part, c_c, c_k) in [("velocity", 1.0, 0.0), ("position", 0.0, 1.0)] {
            let (mut k1, mut k0) = (DenseMatrix::zeros(n, n), DenseMatrix::zeros(n, n));
            with.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, c_c, c_k, &mut k1.view());
            without.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, c_c, c_k, &mut k0.view());
            let (mut diff, mut scale) = (0.0_f64, 0.0_f64);
            for col in 0..n {
                let (fp, fm) = if c_c == 1.0 {
                    let (mut vp, mut vm) = (v.clone(), v.clone());
                    vp[col] += h;
                    vm[col] -= h;
                    (force(&q, &vp), force(&q, &vm))
                } else {
                    let (mut d, mut qp, mut qm) = (vec![0.0; n], q.clone(), q.clone());
                    d[col] = h;
                    with.retract_inplace(&q, &d, &mut qp);
                    d[col] = -h;
                    with.retract_inplace(&q, &d, &mut qm);
                    (force(&qp, &v), force(&qm, &v))
                };
                for row in 0..n {
                    let an = k1.get(row, col) - k0.get(row, col);
                    let fd = (fp[row] - fm[row]) / (2.0 * h);
                    diff = diff.max((an - fd).abs());
                    scale = scale.max(an.abs());
                }
            }
            let folds = (with.hinge_angle(&q, 0).unwrap(), with.hinge_angle(&q, 1).unwrap());
            println!(
                "trial {trial} (angles {:.4}°, {:.4}°): {part} tangent rel err {:.2e} (max entry {scale:.2e})",
                folds.0.to_degrees(),
                folds.1.to_degrees(),
                diff / scale
            );
            assert!(scale > 0.1, "the spring must contribute");
            assert!(diff / scale < 1e-6, "{part} tangent: rel err {:.2e}", diff / scale);
        }
    }
}

/// Time of the `k`-th crossing of `x` through `level` (linear interpolation between steps).
fn crossings(t: &[f64], x: &[f64], level: f64) -> Vec<f64> {
    (1..x.len())
        .filter(|&i| (x[i - 1] - level) * (x[i] - level) < 0.0)
        .map(|i| {
            let (a, b) = (x[i - 1] - level, x[i] - level);
            t[i - 1] + (t[i] - t[i - 1]) * a / (a - b)
        })
        .collect()
}

/// One stiff 1 m body on a ground hinge about a skew axis, spring k = 10 N·m/rad, no gravity:
/// θ̈ J = −k(θ − θ₀) for a rigid body turning about a fixed axis, so ω = √(k/J) with J the
/// moment of inertia about the hinge axis through the start point (from the analytic
/// `reference_inertia()`, parallel-axis theorem). Started at rest at θ = 0 with θ₀ = 0.01 rad,
/// θ(t) = θ₀ (1 − cos ωt). The period from the crossings of θ₀ over three periods (ρ∞ = 1,
/// dt = 1e-3: the trapezoidal rule's period error (ωh)²/12 ≈ 1.3e-6); tolerance 0.1 %.
#[test]
fn ground_hinge_spring_oscillates_at_sqrt_k_over_j() {
    let frame = Rotation3::from_scaled_axis(Vector3::new(0.1, -0.2, 0.15)).into_inner();
    let b = body("bar", Vector3::new(0.1, 0.2, 0.3), frame, 1.0, 4);
    let axis = Vector3::new(0.2, 1.0, 0.3).normalize();
    let inertia = b.reference_inertia();
    let d = inertia.centre - b.start;
    let j_axis = axis
        .dot(&((inertia.inertia + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * inertia.mass) * axis));
    let (k, rest) = (10.0, 0.01);
    let mut scene = Scene::new(vec![b], vec![JointSpec::GroundHinge { body: 0, axis }], Vector3::zeros());
    scene.forces.push(spring(0, k, 0.0, rest));
    let mut m = Model::from_scene(&scene, Options::default()).unwrap();
    let dt = 1e-3;
    let omega = (k / j_axis).sqrt();
    let period = 2.0 * PI / omega;
    let (mut t, mut theta, mut energy) = (Vec::new(), Vec::new(), Vec::new());
    simulate::run(&mut m, IntegratorParams::new(1.0, dt), 3.2 * period, |m, s, _| {
        t.push(s.t);
        theta.push(m.hinge_angle(&s.q, 0).unwrap());
        energy.push(m.energies(&s.q, &s.v));
    })
    .unwrap();
    let c = crossings(&t, &theta, rest);
    let measured = (c[c.len() - 1] - c[0]) / ((c.len() - 1) as f64 / 2.0);
    let err = measured / period - 1.0;
    let max = theta.iter().copied().fold(f64::MIN, f64::max);
    println!(
        "J = {j_axis:.6} kg·m², period {period:.6} s, measured {measured:.6} s ({} crossings): rel err {err:.2e}; \
         max θ {max:.6} (2θ₀ = {})",
        c.len(),
        2.0 * rest
    );
    assert!(c.len() >= 6);
    assert!(err.abs() < 1e-3, "period rel err {err:.2e}");
    // Started at rest at θ = 0: it swings to 2θ₀ (energy ½k θ₀² all in the spring at both ends).
    assert!((max / (2.0 * rest) - 1.0).abs() < 1e-3, "max θ {max}");
    assert!((energy[0].spring - 0.5 * k * rest * rest).abs() < 1e-12);
}

/// Spin a stiff body on a ground hinge so that its spring stops it at 270° (through 180°) and
/// brings it back: the angle never jumps (largest change per step ≤ 1.01 ω_max dt), it peaks
/// at the energy's prediction `θ_max = ω₀ √(J/k)`, and `E = T + ½kθ²` stays constant.
/// Tolerances: θ_max 1e-3 relative; energy 1e-6 of E(0) (measured ~1e-9: a rigid rotation about
/// a fixed axis is a linear oscillator, which the trapezoidal rule conserves).
#[test]
fn ground_hinge_spring_through_180_degrees() {
    let b = body("bar", Vector3::zeros(), Matrix3::identity(), 1.0, 3);
    let inertia = b.reference_inertia();
    let j_axis = inertia.inertia[(1, 1)] + inertia.mass * inertia.centre.x.powi(2);
    let k = 5.0;
    let theta_max = 1.5 * PI;
    let omega0 = theta_max * (k / j_axis).sqrt();
    let mut scene = Scene::new(vec![b], vec![JointSpec::GroundHinge { body: 0, axis: Vector3::y() }], Vector3::zeros());
    scene.forces.push(spring(0, k, 0.0, 0.0));
    run_through_180(&scene, 0, vec![pose_spinning(Vector3::zeros(), Vector3::y() * omega0)], omega0, theta_max, 1e-6);
}

/// The same through a flared hinge (β = 30°, to 234°): the parent clamped, the child spun about
/// the hinge axis. The fold angle θ is measured about −a, so ω = −ω₀ a gives θ̇ = ω₀. The child
/// spins at up to 22 rad/s and its centrifugal load stretches and bends both stiff bodies: the
/// energy error, 1.5e-6 of E(0), is the integrator's on that flexible motion (1.6e-6 when the
/// same child spins freely without the spring; it does not fall with dt: 1.3e-6 at dt/2,
/// 1.2e-6 at dt/4, being carried by vibrations with ω dt ≫ 1); tolerance 1e-5.
#[test]
fn flared_hinge_spring_through_180_degrees() {
    let beta = 30f64.to_radians();
    let parent = body("parent", Vector3::zeros(), Matrix3::identity(), 0.5, 2);
    let child = body("child", Vector3::new(0.5, 0.0, 0.0), Matrix3::identity(), 0.5, 2);
    let inertia = child.reference_inertia();
    let a = Vector3::new(beta.sin(), beta.cos(), 0.0);
    let d = inertia.centre - child.start;
    let j_axis =
        a.dot(&((inertia.inertia + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * inertia.mass) * a));
    let k = 2.0;
    let theta_max = 1.3 * PI;
    let omega0 = theta_max * (k / j_axis).sqrt();
    let mut scene = Scene::new(
        vec![parent, child],
        vec![JointSpec::Clamp { body: 0 }, JointSpec::FlaredHinge { parent: 0, child: 1, beta }],
        Vector3::zeros(),
    );
    scene.forces.push(spring(1, k, 0.0, 0.0));
    let poses = vec![RigidPose::at_rest(Vector3::zeros()), pose_spinning(Vector3::new(0.5, 0.0, 0.0), -a * omega0)];
    run_through_180(&scene, 1, poses, omega0, theta_max, 1e-5);
}

fn pose_spinning(start: Vector3<f64>, angular_velocity: Vector3<f64>) -> RigidPose {
    RigidPose { angular_velocity, ..RigidPose::at_rest(start) }
}

/// Integrate (ρ∞ = 1, dt = 1e-3) for ¾ of a period from the spinning poses; check the angle's
/// continuity, its peak and the energy (`energy_tol` relative to E(0)).
fn run_through_180(scene: &Scene, joint: usize, poses: Vec<RigidPose>, omega0: f64, theta_max: f64, energy_tol: f64) {
    let mut m = Model::from_scene(scene, Options::default()).unwrap();
    let dt = 1e-3;
    let mut ga = GenAlpha::new(IntegratorParams::new(1.0, dt), &m).unwrap();
    let mut s = m.rigid_state(&poses).unwrap();
    m.reset_hinge_angles(&s.q);
    ga.initialize(&m, &mut s).unwrap();
    let e0 = m.energies(&s.q, &s.v).total();
    let period = 2.0 * PI * theta_max / omega0;
    let (mut theta, mut max_jump, mut max_de, mut max_spring_jump) = (vec![0.0], 0.0_f64, 0.0_f64, 0.0_f64);
    let mut spring_prev = 0.0;
    while s.t < 0.75 * period {
        ga.step(&mut m, &mut s).unwrap();
        let th = m.hinge_angle(&s.q, joint).unwrap();
        let e = m.energies(&s.q, &s.v);
        max_jump = max_jump.max((th - theta.last().unwrap()).abs());
        max_spring_jump = max_spring_jump.max((e.spring - spring_prev).abs());
        spring_prev = e.spring;
        max_de = max_de.max((e.total() - e0).abs());
        theta.push(th);
    }
    let peak = theta.iter().copied().fold(f64::MIN, f64::max);
    println!(
        "peak θ {:.4}° (expected {:.4}°), largest step in θ {max_jump:.3e} rad (ω₀ dt = {:.3e}), \
         largest step in the spring energy {max_spring_jump:.3e} J, max |E − E(0)| {:.2e} of E(0), final θ {:.2}°",
        peak.to_degrees(),
        theta_max.to_degrees(),
        omega0 * dt,
        max_de / e0,
        theta.last().unwrap().to_degrees()
    );
    assert!(peak > PI + 0.5, "it must pass 180°");
    assert!((peak / theta_max - 1.0).abs() < 1e-3, "peak {peak}");
    assert!(max_jump <= 1.01 * omega0 * dt, "the angle jumped by {max_jump}");
    // the spring energy changes by at most its power over a step, k θ_max ω₀ dt
    assert!(max_spring_jump <= 1.01 * theta_max * omega0 * dt * scene_stiffness(scene));
    assert!(max_de < energy_tol * e0, "energy error {:.2e} of E(0)", max_de / e0);
    // on the way back, past 180° again
    assert!(*theta.last().unwrap() < PI);
}

fn scene_stiffness(scene: &Scene) -> f64 {
    match scene.forces[0] {
        ForceElement::HingeSpring { stiffness, .. } => stiffness,
        ForceElement::Thrust { .. } => 0.0,
    }
}

/// The declared matrix structure (node-banded blocks per body, frames and joint rows in the
/// border) holds every non-zero of the iteration matrix with springs and dampers on both
/// hinges, point masses and an offset section centre of mass, at a random state: the spring
/// couples the parent's end node with the two frames, which the joint rows already couple, so
/// the integrator's direct assembly never meets an entry outside its storage.
#[test]
fn declared_structure_holds_springs_and_point_masses() {
    let (mut b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    b[1].section.cg_offset = [0.02, -0.01];
    b[0].point_masses.push(gebf::PointMass {
        at: 0.5,
        offset: Vector3::new(0.0, 0.05, 0.02),
        mass: 0.3,
        inertia: Vector3::new(1e-4, 1e-4, 1e-4),
    });
    let mut scene = Scene::new(b, j, g);
    scene.forces = vec![spring(0, 3.0, 0.2, 0.1), spring(1, 1.0, 0.05, -0.2)];
    let m = Model::from_scene(&scene, Options::default()).unwrap();
    let n = m.n_dof();
    let mut rng = Lcg(3);
    let q0 = m.reference_coordinates();
    let dq: Vec<f64> = (0..n).map(|_| rng.next() * 0.2).collect();
    let mut q = q0.clone();
    m.retract_inplace(&q0, &dq, &mut q);
    let v: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let a: Vec<f64> = (0..n).map(|_| rng.next()).collect();
    let mut k = DenseMatrix::zeros(n, n);
    m.iteration_matrix_inplace(0.0, &q, &v, &a, 1.0, 0.5, 0.25, &mut k.view());
    let structure = m.matrix_structure().expect("GEBF declares its structure");
    let node_band = structure.node_bandwidth.expect("node-banded");
    let block_of = |i: usize| structure.blocks.iter().position(|&(first, len, _)| (first..first + len).contains(&i));
    let mut outside = Vec::new();
    for col in 0..n {
        for row in 0..n {
            if k.get(row, col) == 0.0 {
                continue;
            }
            let fits = match (block_of(row), block_of(col)) {
                (Some(x), Some(y)) if x == y => {
                    let first = structure.blocks[x].0;
                    ((row - first) / 6).abs_diff((col - first) / 6) <= node_band
                }
                (Some(_), Some(_)) => false,
                _ => true, // a border row or column
            };
            if !fits {
                outside.push((row, col));
            }
        }
    }
    assert!(outside.is_empty(), "non-zeros outside the declared structure: {outside:?}");
}
