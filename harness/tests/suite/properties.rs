//! Cross-formulation property tests (proptest): the flared hinge written as a linear holonomic
//! constraint on ANCF gradients and as velocity-level constraints on GEBF floating frames must
//! say the same thing about the same physical motion.
//!
//! A random rigid motion of a two-body assembly (body 1 posed by a random rotation and
//! translation with a random velocity and angular velocity; body 2 turned about the hinge line by
//! a random fold angle θ at a random fold rate θ̇) is mapped into ANCF coordinates (both the DAE
//! and the ODE path) and into GEBF coordinates with each crate's `Model::rigid_state`. Both
//! must satisfy their joint equations (position and velocity level), and both must report the
//! fold angle θ, the tip position and the kinetic energy of the closed-form rigid-body motion.
//!
//! The negative controls give one formulation the flare angle −β and show that the same checker
//! then reports a violation for nearly every random case, and that proptest fails the property
//! with a shrunk counterexample.
//!
//! Inputs are plain numbers and angles (a rotation is its rotation vector `[x, y, z]`, rad) so
//! that a shrunk counterexample reads directly.

use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestCaseError, TestError, TestRunner};
use std::f64::consts::FRAC_PI_2;

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

fn config() -> ProptestConfig {
    ProptestConfig { cases: 256, ..ProptestConfig::default() }
}

fn rot(v: [f64; 3]) -> M3 {
    Rotation3::from_scaled_axis(V3::from(v)).into_inner()
}

fn axis_angle(axis: &V3, angle: f64) -> M3 {
    Rotation3::from_axis_angle(&Unit::new_normalize(*axis), angle).into_inner()
}

/// Section data per unit length shared by both formulations. `ρI_xx = ρI_yy + ρI_zz` (a thin
/// section), for which the ANCF slope inertias reproduce the rigid-body rotary inertia exactly.
#[derive(Debug, Clone, Copy)]
struct Sec {
    mass: f64,
    rho_iyy: f64,
    rho_izz: f64,
    c: f64,
}

impl Sec {
    fn rho_ixx(&self) -> f64 {
        self.rho_iyy + self.rho_izz
    }
    fn ancf(&self) -> ancf::Section {
        let mut s = ancf::samples::paper_section(self.c);
        (s.mass, s.rho_ixx, s.rho_iyy, s.rho_izz) = (self.mass, self.rho_ixx(), self.rho_iyy, self.rho_izz);
        s
    }
    fn gebf(&self) -> gebf::Section {
        let mut s = gebf::samples::paper_section(self.c);
        (s.mass, s.rho_ixx, s.rho_iyy, s.rho_izz) = (self.mass, self.rho_ixx(), self.rho_iyy, self.rho_izz);
        s
    }
}

/// One straight body in its reference configuration.
#[derive(Debug, Clone, Copy)]
struct Body {
    start: V3,
    length: f64,
    frame: M3,
    n_ancf: usize,
    n_gebf: usize,
}

/// A two-body scene: body 1 (parent) and body 2 (child) joined by a flared hinge, optionally
/// body 1 attached to ground at its start by `root` (then the flared hinge is joint 1).
#[derive(Debug, Clone)]
struct Scene {
    beta: f64,
    bodies: [Body; 2],
    section: Sec,
    root: Root,
    gravity: V3,
}

/// How body 1 is attached to ground.
#[derive(Debug, Clone, Copy)]
enum Root {
    Free,
    /// Ground hinge about this global axis.
    Hinge(V3),
    Clamp,
}

/// Which formulation gets the flare angle −β (the negative controls).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Broken {
    Neither,
    Ancf,
    Gebf,
}

impl Scene {
    fn fold_joint(&self) -> usize {
        usize::from(!matches!(self.root, Root::Free))
    }
    /// Hinge axis a = F_P (sin β, cos β, 0), global, reference.
    fn axis0(&self) -> V3 {
        self.bodies[0].frame * V3::new(self.beta.sin(), self.beta.cos(), 0.0)
    }
    fn beta_for(&self, which: Broken, broken: Broken) -> f64 {
        if which == broken { -self.beta } else { self.beta }
    }

    fn ancf_model(&self, path: ancf::SolvePath, broken: Broken) -> ancf::Model {
        let bodies: Vec<_> = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| ancf::BodySpec {
                name: format!("body{i}"),
                start: b.start,
                length: b.length,
                frame: b.frame,
                section: self.section.ancf(),
                n_elements: b.n_ancf,
                point_masses: Vec::new(),
                twist: scene::Twist::none(),
            })
            .collect();
        let mut joints = Vec::new();
        match self.root {
            Root::Free => {}
            Root::Hinge(axis) => joints.push(ancf::JointSpec::GroundHinge { body: 0, axis }),
            Root::Clamp => joints.push(ancf::JointSpec::Clamp { body: 0 }),
        }
        joints.push(ancf::JointSpec::FlaredHinge { parent: 0, child: 1, beta: self.beta_for(Broken::Ancf, broken) });
        let options = ancf::Options { path, ..Default::default() };
        ancf::Model::new(&bodies, &joints, self.gravity, options).expect("valid ANCF scene")
    }

    fn gebf_model(&self, broken: Broken) -> gebf::Model {
        let bodies: Vec<_> = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| gebf::BodySpec {
                name: format!("body{i}"),
                start: b.start,
                length: b.length,
                frame: b.frame,
                section: self.section.gebf(),
                n_elements: b.n_gebf,
                point_masses: Vec::new(),
                twist: scene::Twist::none(),
            })
            .collect();
        let mut joints = Vec::new();
        match self.root {
            Root::Free => {}
            Root::Hinge(axis) => joints.push(gebf::JointSpec::GroundHinge { body: 0, axis }),
            Root::Clamp => joints.push(gebf::JointSpec::Clamp { body: 0 }),
        }
        joints.push(gebf::JointSpec::FlaredHinge { parent: 0, child: 1, beta: self.beta_for(Broken::Gebf, broken) });
        gebf::Model::new(&bodies, &joints, self.gravity, gebf::Options::default()).expect("valid GEBF scene")
    }
}

/// A rigid pose of one body: rotation from the reference, position of its start, angular
/// velocity and start-point velocity (global).
#[derive(Debug, Clone, Copy)]
struct Pose {
    rotation: M3,
    translation: V3,
    angular_velocity: V3,
    velocity: V3,
}

impl Pose {
    fn ancf(&self) -> ancf::RigidPose {
        ancf::RigidPose {
            rotation: self.rotation,
            translation: self.translation,
            angular_velocity: self.angular_velocity,
            velocity: self.velocity,
        }
    }
    fn gebf(&self) -> gebf::RigidPose {
        gebf::RigidPose {
            rotation: self.rotation,
            translation: self.translation,
            angular_velocity: self.angular_velocity,
            velocity: self.velocity,
        }
    }
}

/// The physical motion: body 1 rotated by `r1` about its start, which moves to `t1` with
/// velocity `v1`, angular velocity `w1`; body 2 in addition turned by θ about the hinge line
/// (right-hand rule about −a) at the rate θ̇.
#[derive(Debug, Clone, Copy)]
struct Motion {
    r1: M3,
    t1: V3,
    w1: V3,
    v1: V3,
    theta: f64,
    theta_dot: f64,
}

fn poses(s: &Scene, m: &Motion) -> [Pose; 2] {
    let [b1, _] = s.bodies;
    let hinge = m.t1 + m.r1 * b1.frame.column(0) * b1.length;
    let axis = m.r1 * s.axis0();
    [
        Pose { rotation: m.r1, translation: m.t1, angular_velocity: m.w1, velocity: m.v1 },
        Pose {
            rotation: m.r1 * axis_angle(&(-s.axis0()), m.theta),
            translation: hinge,
            angular_velocity: m.w1 - axis * m.theta_dot,
            velocity: m.v1 + m.w1.cross(&(hinge - m.t1)),
        },
    ]
}

/// Closed-form rigid-body values: tip (free end of body 2), kinetic energy and gravitational
/// potential relative to the reference of a straight uniform beam body.
fn rigid_values(s: &Scene, p: &[Pose; 2]) -> (V3, f64, f64) {
    let sec = s.section;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    for (b, pose) in s.bodies.iter().zip(p) {
        let (m, l) = (sec.mass * b.length, b.length);
        let f = pose.rotation * b.frame;
        let centroid = pose.translation + f.column(0) * (0.5 * l);
        let centroid0 = b.start + b.frame.column(0) * (0.5 * l);
        let vc = pose.velocity + pose.angular_velocity.cross(&(centroid - pose.translation));
        let bending = m * l * l / 12.0;
        let inertia =
            M3::from_diagonal(&V3::new(sec.rho_ixx() * l, sec.rho_iyy * l + bending, sec.rho_izz * l + bending));
        let w_body = f.transpose() * pose.angular_velocity;
        kinetic += 0.5 * m * vc.norm_squared() + 0.5 * w_body.dot(&(inertia * w_body));
        potential -= m * s.gravity.dot(&(centroid - centroid0));
    }
    let last = s.bodies[1];
    let tip = p[1].translation + p[1].rotation * last.frame.column(0) * last.length;
    (tip, kinetic, potential)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// The three models of one scene: ANCF on both paths, GEBF.
struct Models {
    dae: ancf::Model,
    ode: ancf::Model,
    gebf: gebf::Model,
}

/// Everything the two formulations must agree on for one physical motion; returns the list of
/// violations (empty: consistent).
fn violations(s: &Scene, m: &Motion, broken: Broken) -> Vec<String> {
    let models = Models {
        dae: s.ancf_model(ancf::SolvePath::Dae, broken),
        ode: s.ancf_model(ancf::SolvePath::Ode, broken),
        gebf: s.gebf_model(broken),
    };
    violations_of(s, &models, m)
}

/// The checks of [`violations`] on given models of the scene `s`.
fn violations_of(s: &Scene, models: &Models, m: &Motion) -> Vec<String> {
    let Models { dae, ode, gebf: g } = models;
    let p = poses(s, m);
    let (tip, kinetic, potential) = rigid_values(s, &p);
    let theta = m.theta;
    let mut out = Vec::new();
    let mut check = |ok: bool, what: String| {
        if !ok {
            out.push(what);
        }
    };
    let jf = s.fold_joint();

    // ANCF, DAE path: Φ(q) = 0, Φ_q q̇ = 0.
    let sd = dae.rigid_state(&p.map(|x| x.ancf())).expect("valid poses");
    let mut phi = vec![0.0; dae.n_holonomic()];
    dae.phi_inplace(0.0, &sd.q, &mut phi);
    let mut jac = DenseMatrix::zeros(dae.n_holonomic(), dae.n_dof());
    dae.phi_q_inplace(0.0, &sd.q, &mut jac.view());
    let mut phi_dot = vec![0.0; dae.n_holonomic()];
    jac.mul_vec_inplace(&sd.v, &mut phi_dot);
    let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
    check(amax(&phi) < 1e-13, format!("ANCF Φ = {:e}", amax(&phi)));
    check(amax(&phi_dot) < 1e-13, format!("ANCF Φ_q v = {:e}", amax(&phi_dot)));
    check(dae.constraint_residual(&sd.q) < 1e-13, format!("ANCF residual {:e}", dae.constraint_residual(&sd.q)));

    // ANCF, ODE path: B z + q_p and B ż reproduce the DAE coordinates and velocities.
    let so = ode.rigid_state(&p.map(|x| x.ancf())).expect("valid poses");
    let q_full = ode.full_coordinates(&so.q);
    let mut v_full = vec![0.0; q_full.len()];
    ode.full_velocities_inplace(&so.v, &mut v_full);
    let gap = q_full.iter().zip(&sd.q).chain(v_full.iter().zip(&sd.v)).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    check(gap < 1e-13, format!("ANCF ODE state differs from the poses by {gap:e}"));

    // GEBF: Ψ = B(q) v = 0 and the position-level residual.
    let sg = g.rigid_state(&p.map(|x| x.gebf())).expect("valid poses");
    let mut psi = vec![0.0; g.n_velocity_constraints()];
    g.psi_inplace(0.0, &sg.q, &sg.v, &mut psi);
    check(amax(&psi) < 1e-13, format!("GEBF Ψ = {:e}", amax(&psi)));
    check(g.constraint_residual(&sg.q) < 1e-13, format!("GEBF residual {:e}", g.constraint_residual(&sg.q)));

    // Same fold angle, tip and energies, equal to the closed form.
    let folds = [
        ("ANCF DAE", dae.fold_angle(&sd.q, jf).expect("flared hinge")),
        ("ANCF ODE", ode.fold_angle(&so.q, jf).expect("flared hinge")),
        ("GEBF", g.fold_angle(&sg.q, jf).expect("flared hinge")),
    ];
    for (name, f) in folds {
        check((f - theta).abs() < 1e-13, format!("{name} fold {f} vs θ {theta}"));
    }
    let tips =
        [("ANCF DAE", dae.tip_position(&sd.q)), ("ANCF ODE", ode.tip_position(&so.q)), ("GEBF", g.tip_position(&sg.q))];
    for (name, t) in tips {
        check((t - tip).norm() < 1e-13 * (1.0 + tip.norm()), format!("{name} tip {t:?} vs {tip:?}"));
    }
    let energies = [
        ("ANCF DAE", dae.energies(&sd.q, &sd.v).kinetic, dae.energies(&sd.q, &sd.v).potential),
        ("ANCF ODE", ode.energies(&so.q, &so.v).kinetic, ode.energies(&so.q, &so.v).potential),
        ("GEBF", g.energies(&sg.q, &sg.v).kinetic, g.energies(&sg.q, &sg.v).potential),
    ];
    for (name, t, v) in energies {
        check(close(t, kinetic, 1e-13), format!("{name} kinetic {t} vs rigid {kinetic}"));
        check(close(v, potential, 2e-13), format!("{name} potential {v} vs rigid {potential}"));
    }
    out
}

/// β in [−π/2, π/2], with the special values 0 and ±π/2 drawn often.
fn beta() -> impl Strategy<Value = f64> {
    prop_oneof![1 => Just(0.0), 1 => Just(FRAC_PI_2), 1 => Just(-FRAC_PI_2), 7 => -FRAC_PI_2..=FRAC_PI_2]
}

/// A rotation vector (rad) with components in [−2, 2].
fn rotvec() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-2.0..2.0f64)
}

/// A vector with components in [−1, 1].
fn vec3() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-1.0..1.0f64)
}

/// Plain-number description of a free pair (no ground hinge) and its motion.
type FreeInput = (
    (f64, [f64; 3], [f64; 3], [f64; 3]),        // β, parent frame, child kink, start
    ((f64, f64), (usize, usize, usize, usize)), // lengths, element counts (ANCF, GEBF)
    (f64, f64, f64),                            // m, ρI_yy, ρI_zz
    ([f64; 3], [f64; 3], [f64; 3], [f64; 3], f64, f64), // r1, t1, ω1, v1, θ, θ̇
);

fn free_input(beta: impl Strategy<Value = f64>) -> impl Strategy<Value = FreeInput> {
    (
        (beta, rotvec(), prop::array::uniform3(-0.8..0.8f64), vec3()),
        ((0.2..2.0f64, 0.2..2.0f64), (1..=3usize, 1..=3usize, 1..=3usize, 1..=3usize)),
        (0.1..10.0f64, 1e-5..1e-2f64, 1e-5..1e-2f64),
        (rotvec(), vec3(), prop::array::uniform3(-5.0..5.0f64), vec3(), -3.0..3.0f64, -5.0..5.0f64),
    )
}

/// Body 1 from `start` with frame `fp`, body 2 from its end with the frame turned further by
/// `rot(kink)`; element counts (ANCF body 1, ANCF body 2, GEBF body 1, GEBF body 2).
fn two_bodies(fp: M3, kink: [f64; 3], start: V3, (l1, l2): (f64, f64), n: (usize, usize, usize, usize)) -> [Body; 2] {
    [
        Body { start, length: l1, frame: fp, n_ancf: n.0, n_gebf: n.2 },
        Body { start: start + fp.column(0) * l1, length: l2, frame: fp * rot(kink), n_ancf: n.1, n_gebf: n.3 },
    ]
}

fn free_case(input: &FreeInput) -> (Scene, Motion) {
    let ((beta, frame, kink, start), (lengths, n_el), (mass, rho_iyy, rho_izz), motion) = *input;
    let scene = Scene {
        beta,
        bodies: two_bodies(rot(frame), kink, V3::from(start), lengths, n_el),
        section: Sec { mass, rho_iyy, rho_izz, c: 1.0 },
        root: Root::Free,
        gravity: V3::new(0.0, 0.0, -9.8),
    };
    let (r1, t1, w1, v1, theta, theta_dot) = motion;
    let m = Motion { r1: rot(r1), t1: V3::from(t1), w1: V3::from(w1), v1: V3::from(v1), theta, theta_dot };
    (scene, m)
}

proptest! {
    #![proptest_config(config())]

    /// A free pair (random geometry, sections, element counts) in any rigid motion with any fold
    /// angle and fold rate: both formulations satisfy their joints and agree with each other
    /// and with the closed-form fold angle, tip, kinetic and potential energy.
    #[test]
    fn both_formulations_agree_on_a_folded_free_pair(input in free_input(beta())) {
        let (scene, motion) = free_case(&input);
        let v = violations(&scene, &motion, Broken::Neither);
        prop_assert!(v.is_empty(), "{}", v.join("\n"));
    }

    /// The paper's double pendulum (ground hinge about +Y at the origin, bodies along +X, the
    /// paper's section) at a random swing angle φ and fold angle θ with random rates: both
    /// formulations satisfy both joints and agree with the closed form.
    #[test]
    fn both_formulations_agree_on_the_paper_pendulum(
        beta in beta(), phi in -3.0..3.0f64, theta in -3.0..3.0f64, phi_dot in -5.0..5.0f64,
        theta_dot in -5.0..5.0f64, n_ancf in 1..=5usize, n_gebf in 1..=5usize,
    ) {
        let body = |x0: f64| Body {
            start: V3::new(x0, 0.0, 0.0), length: 0.5, frame: M3::identity(), n_ancf, n_gebf,
        };
        let scene = Scene {
            beta,
            bodies: [body(0.0), body(0.5)],
            section: Sec { mass: 1.08, rho_iyy: 3.6e-5, rho_izz: 3.6e-5, c: 1.0 },
            root: Root::Hinge(V3::y()),
            gravity: V3::new(0.0, 0.0, -9.8),
        };
        let motion = Motion {
            r1: axis_angle(&V3::y(), phi), t1: V3::zeros(), w1: V3::y() * phi_dot, v1: V3::zeros(), theta, theta_dot,
        };
        let v = violations(&scene, &motion, Broken::Neither);
        prop_assert!(v.is_empty(), "{}", v.join("\n"));
    }
}

proptest! {
    #![proptest_config(config())]

    /// Both formulations measure a joint violation the same way (`constraint_residual`: the
    /// hinge gap and the axis misalignment angle): body 2 of a folded free pair is moved off the
    /// hinge by `gap` and turned by ε about a random axis, and both report
    /// `√(|gap|² + angle(a_parent, a_child)²)`, and the same fold angle (except at β = 0, ±90°,
    /// where the sensors' fixed vectors ⟂ a differ and so do their readings, at second order in ε).
    #[test]
    fn both_formulations_measure_a_joint_violation_alike(
        input in free_input(beta()), gap in vec3(), tilt_axis in vec3(), tilt in 0.0..0.5f64,
    ) {
        prop_assume!(V3::from(tilt_axis).norm() > 0.1);
        let (scene, motion) = free_case(&input);
        let mut p = poses(&scene, &motion);
        let tilt_rot = axis_angle(&V3::from(tilt_axis), tilt);
        p[1].rotation = tilt_rot * p[1].rotation;
        p[1].translation += V3::from(gap) * 0.1;
        let a_parent = motion.r1 * scene.axis0();
        let a_child = tilt_rot * a_parent;
        let angle = a_parent.cross(&a_child).norm().atan2(a_parent.dot(&a_child));
        let expected = (0.01 * V3::from(gap).norm_squared() + angle * angle).sqrt();
        let dae = scene.ancf_model(ancf::SolvePath::Dae, Broken::Neither);
        let g = scene.gebf_model(Broken::Neither);
        let qa = dae.rigid_full_state(&p.map(|x| x.ancf())).unwrap().0;
        let qg = g.rigid_state(&p.map(|x| x.gebf())).unwrap().q;
        let (ra, rg) = (dae.constraint_residual(&qa), g.constraint_residual(&qg));
        prop_assert!((ra - expected).abs() < 1e-13, "ANCF residual {ra} vs {expected}");
        prop_assert!((rg - expected).abs() < 1e-13, "GEBF residual {rg} vs {expected}");
        // The fold sensors use different fixed vectors ⟂ a only at β = 0 and ±90° (ANCF: the
        // least aligned coordinate axis, GEBF: z); elsewhere they coincide.
        let (fa, fg) = (dae.fold_angle(&qa, 0).unwrap(), g.fold_angle(&qg, 0).unwrap());
        if scene.beta.abs() > 1e-6 && (scene.beta.abs() - FRAC_PI_2).abs() > 1e-6 {
            prop_assert!((fa - fg).abs() < 1e-12, "fold ANCF {fa} vs GEBF {fg}");
        }
    }
}

/// The case file a scene corresponds to (harness JSON schema, β in degrees).
fn case_json(s: &Scene, flare_deg: f64, path: &str) -> serde_json::Value {
    let sec = s.section;
    let section = serde_json::json!({
        "mass": sec.mass, "rho_ixx": sec.rho_ixx(), "rho_iyy": sec.rho_iyy, "rho_izz": sec.rho_izz,
        "ea": 2.8e5, "ga_y": 1.037e5, "ga_z": 1.037e5, "gj": 6.91, "ei_yy": 9.33, "ei_zz": 9.33
    });
    let body = |i: usize| {
        let b = s.bodies[i];
        let (x, y) = (b.frame.column(0), b.frame.column(1));
        serde_json::json!({
            "name": format!("body{i}"), "start": [b.start.x, b.start.y, b.start.z], "length": b.length,
            "x_axis": [x.x, x.y, x.z], "y_axis": [y.x, y.y, y.z], "section": section
        })
    };
    let mut joints = Vec::new();
    match s.root {
        Root::Free => {}
        Root::Hinge(a) => joints.push(
            serde_json::json!({"type": "ground_hinge", "name": "root", "body": "body0", "axis": [a.x, a.y, a.z]}),
        ),
        Root::Clamp => joints.push(serde_json::json!({"type": "clamp", "name": "root", "body": "body0"})),
    }
    joints.push(serde_json::json!({
        "type": "flared_hinge", "name": "fold", "parent": "body0", "child": "body1", "flare_deg": flare_deg
    }));
    let n = |f: fn(&Body) -> usize| serde_json::json!([f(&s.bodies[0]), f(&s.bodies[1])]);
    serde_json::json!({
        "name": "property", "bodies": [body(0), body(1)], "joints": joints,
        "gravity": [s.gravity.x, s.gravity.y, s.gravity.z], "t_end": 1.0,
        "ancf": {"elements_per_body": n(|b| b.n_ancf), "dt": 0.01, "path": path},
        "gebf": {"elements_per_body": n(|b| b.n_gebf), "dt": 0.01}
    })
}

/// The models the harness builds from the case of `s` (what the gate runs).
fn case_models(s: &Scene, flare_deg: f64) -> Models {
    let case = |path| {
        let c = harness::case::parse_case(&case_json(s, flare_deg, path)).expect("schema-valid case");
        c.validate().expect("valid case");
        assert_eq!(c.fold_joint_index(), Some(s.fold_joint()));
        c
    };
    Models {
        dae: harness::scene::build_ancf(&case("dae")).expect("ANCF model"),
        ode: harness::scene::build_ancf(&case("ode")).expect("ANCF model"),
        gebf: harness::scene::build_gebf(&case("dae")).expect("GEBF model"),
    }
}

proptest! {
    #![proptest_config(config())]

    /// The same through the harness: a case file (β in degrees, body axes, a ground hinge about
    /// a random axis) built into both formulations by `harness::scene` gives models that agree
    /// on a random swing about the ground axis with a random fold.
    #[test]
    fn harness_scenes_agree_on_a_grounded_pair(
        flare_deg in prop_oneof![1 => Just(0.0), 1 => Just(90.0), 1 => Just(-90.0), 7 => -90.0..=90.0f64],
        frame in rotvec(), kink in prop::array::uniform3(-0.8..0.8f64), start in vec3(), ground in vec3(),
        lengths in (0.2..2.0f64, 0.2..2.0f64), n_el in (1..=3usize, 1..=3usize, 1..=3usize, 1..=3usize),
        phi in -3.0..3.0f64, theta in -3.0..3.0f64, phi_dot in -5.0..5.0f64, theta_dot in -5.0..5.0f64,
    ) {
        prop_assume!(V3::from(ground).norm() > 0.1);
        let start = V3::from(start);
        let scene = Scene {
            beta: flare_deg.to_radians(),
            bodies: two_bodies(rot(frame), kink, start, lengths, n_el),
            section: Sec { mass: 1.08, rho_iyy: 3.6e-5, rho_izz: 3.6e-5, c: 1.0 },
            root: Root::Hinge(V3::from(ground).normalize()),
            gravity: V3::new(0.0, 0.0, -9.8),
        };
        let axis = V3::from(ground).normalize();
        let r1 = axis_angle(&axis, phi);
        let motion = Motion { r1, t1: start, w1: axis * phi_dot, v1: V3::zeros(), theta, theta_dot };
        let v = violations_of(&scene, &case_models(&scene, flare_deg), &motion);
        prop_assert!(v.is_empty(), "{}", v.join("\n"));
    }
}

proptest! {
    #![proptest_config(config())]

    /// The paper's flared-hinge wing (docs/cases.md §2: inner body 12 m clamped at the root, outer
    /// body 4 m, the wing section, any flare angle) with the wingtip folded by θ at the rate θ̇:
    /// both formulations satisfy the clamp and the hinge and agree with the closed form.
    #[test]
    fn both_formulations_agree_on_the_clamped_wing(
        beta in beta(), theta in -3.0..3.0f64, theta_dot in -2.0..2.0f64,
        n_el in (1..=12usize, 1..=4usize, 1..=6usize, 1..=2usize),
    ) {
        let scene = Scene {
            beta,
            bodies: two_bodies(M3::identity(), [0.0; 3], V3::zeros(), (12.0, 4.0), n_el),
            section: Sec { mass: 0.75, rho_iyy: 0.01, rho_izz: 0.09, c: 1.0 },
            root: Root::Clamp,
            gravity: V3::new(0.0, 0.0, -9.8),
        };
        let motion = Motion { r1: M3::identity(), t1: V3::zeros(), w1: V3::zeros(), v1: V3::zeros(), theta, theta_dot };
        let v = violations(&scene, &motion, Broken::Neither);
        prop_assert!(v.is_empty(), "{}", v.join("\n"));
    }
}

/// Flip β in one formulation and run the checker on `n` random cases (deterministic RNG) with
/// |β| ≥ 0.1 (at β = 0 the flip changes nothing); returns the number of cases it flags.
fn detections(broken: Broken, n: u32) -> u32 {
    let mut runner = TestRunner::deterministic();
    let strategy = free_input(prop_oneof![0.1..=FRAC_PI_2, -FRAC_PI_2..=-0.1]);
    let mut flagged = 0;
    for _ in 0..n {
        let input = strategy.new_tree(&mut runner).expect("strategy generates").current();
        let (scene, motion) = free_case(&input);
        assert!(violations(&scene, &motion, Broken::Neither).is_empty(), "the unbroken checker must pass: {input:?}");
        if !violations(&scene, &motion, broken).is_empty() {
            flagged += 1;
        }
    }
    flagged
}

/// Negative control: GEBF built with −β. The checker flags nearly every random case (it can
/// only miss motions with θ and θ̇ both near zero, where the two axes cannot be told apart).
#[test]
fn flipped_beta_in_gebf_is_detected() {
    let n = 256;
    let flagged = detections(Broken::Gebf, n);
    println!("GEBF with −β: {flagged}/{n} random cases flagged");
    assert!(flagged >= n - 3, "only {flagged}/{n} cases flagged");
}

/// Negative control: ANCF built with −β (both paths).
#[test]
fn flipped_beta_in_ancf_is_detected() {
    let n = 256;
    let flagged = detections(Broken::Ancf, n);
    println!("ANCF with −β: {flagged}/{n} random cases flagged");
    assert!(flagged >= n - 3, "only {flagged}/{n} cases flagged");
}

/// Negative control through proptest itself: the cross-formulation property with GEBF given
/// −β fails, and shrinking yields a readable minimal counterexample.
#[test]
fn the_cross_property_fails_when_one_side_is_broken() {
    let config = Config { cases: 256, failure_persistence: None, ..Config::default() };
    let mut runner = TestRunner::new(config);
    let result = runner.run(&free_input(prop_oneof![0.1..=FRAC_PI_2, -FRAC_PI_2..=-0.1]), |input| {
        let (scene, motion) = free_case(&input);
        let v = violations(&scene, &motion, Broken::Gebf);
        if v.is_empty() { Ok(()) } else { Err(TestCaseError::fail(v.join("; "))) }
    });
    match result {
        Err(TestError::Fail(reason, minimal)) => {
            println!("minimal counterexample: {minimal:?}\nreason: {reason}");
            // shrinking drives the fold angle to a simple value while the violation remains
            let (_, _, _, (_, _, _, _, theta, theta_dot)) = minimal;
            assert!(theta != 0.0 || theta_dot != 0.0, "a motion without fold cannot expose the flip");
        }
        other => panic!("the broken property must fail, got {other:?}"),
    }
}
