//! Built-in twist (docs/gebf.md §4): the twisted reference is free of stress and stays at rest,
//! a constant twist is a rotated frame, and a linearly pretwisted cantilever meets the exact
//! compliance of rotating principal axes (`scene::samples::cantilever_tip_compliance`); its
//! natural frequencies agree between ANCF and GEBF.
use formulation::Structure;
use gebf::{
    BodySpec, ForceElement, JointSpec, Model, NodalLoad, Options, PointMass, RigidPose, Scene, StaticOptions, Twist,
    samples,
};
use genalpha::{ConstrainedSystem, IntegratorParams};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Two twisted bodies in a general orientation: a clamped inner body (a twist table with a
/// breakpoint inside an element, a centre-of-mass offset, a point mass) and a tip on a flared
/// hinge with a spring (or a locked hinge), whose start section is turned against the inner
/// body's end section; the inner body clamped or (`ground`) on a ground hinge with a spring.
fn twisted_wing(ground: bool, locked: bool) -> Scene {
    let frame = Rotation3::from_euler_angles(0.2, -0.3, 0.5).into_inner();
    let mut section = samples::pretwisted_section();
    section.cg_offset = [0.02, -0.01];
    let body = |name: &str, start: Vector3<f64>, length: f64, twist: Twist| BodySpec {
        name: name.into(),
        start,
        length,
        frame,
        section,
        n_elements: 6,
        point_masses: vec![PointMass {
            at: 0.5 * length,
            offset: Vector3::new(0.0, -0.03, 0.01),
            mass: 0.2,
            inertia: Vector3::new(1e-4, 6e-5, 8e-5),
        }],
        twist,
    };
    let inner =
        body("inner", Vector3::new(0.1, 0.2, 0.3), 0.6, Twist::table(vec![(0.0, 0.2), (0.25, 0.9), (0.6, 0.5)]));
    let tip = body("tip", inner.end(), 0.4, Twist::linear(-0.3, 0.6, 0.4));
    let root = if ground {
        JointSpec::GroundHinge { body: 0, axis: Vector3::new(0.3, 1.0, -0.2) }
    } else {
        JointSpec::Clamp { body: 0 }
    };
    let hinge = if locked {
        JointSpec::LockedHinge { parent: 0, child: 1, beta: 0.4, fold: 0.0 }
    } else {
        JointSpec::FlaredHinge { parent: 0, child: 1, beta: 0.4 }
    };
    let mut forces = Vec::new();
    if ground {
        forces.push(ForceElement::HingeSpring { joint: 0, stiffness: 5.0, damping: 0.2, rest: 0.0 });
    }
    if !locked {
        forces.push(ForceElement::HingeSpring { joint: 1, stiffness: 2.0, damping: 0.1, rest: 0.0 });
    }
    Scene { forces, ..Scene::new(vec![inner, tip], vec![root, hinge], Vector3::zeros()) }
}

/// At rest in its twisted reference with no load, the residual vanishes (below 1e-12 EA, a
/// strain of 1e-12; measured 2.4e-8 N against EA = 1e7 N), so do the joints' violation and the fold angle, the section frames at the
/// nodes are the twisted ones (1e-14), and 20 time steps leave every coordinate within 1e-12.
/// Every combination of a clamped or ground-hinged root and a free or locked flared hinge.
#[test]
fn a_twisted_body_at_rest_stays_at_rest() {
    for (ground, locked) in [(false, false), (true, false), (false, true), (true, true)] {
        println!("ground hinge {ground}, locked hinge {locked}:");
        at_rest(&twisted_wing(ground, locked));
    }
}

fn at_rest(scene: &Scene) {
    let ea = scene.bodies[0].section.ea;
    let mut model = Model::from_scene(scene, Options::default()).unwrap();
    let s0 = model.initial_state();
    let n = model.n_dof();
    let mut r = vec![0.0; n];
    model.residual_inplace(0.0, &s0.q, &s0.v, &vec![0.0; n], &mut r);
    let worst = r.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    println!("twisted reference: max |r| = {worst:.2e} N (EA = {ea:.1e} N)");
    assert!(worst < 1e-12 * ea, "residual {worst}");
    assert!(model.fold_angle(&s0.q, 1).unwrap().abs() < 1e-14);
    assert!(model.constraint_residual(&s0.q) < 1e-14);
    for (b, spec) in scene.bodies.iter().enumerate() {
        for k in 0..=spec.n_elements {
            let s = spec.length * k as f64 / spec.n_elements as f64;
            let (_, frame) = Structure::section_pose(&model, &s0.q, b, s);
            let err = (frame - spec.section_frame(s)).amax();
            assert!(err < 1e-14, "body {b} s {s}: frame off by {err}");
        }
    }
    let mut ga = Structure::integrator(&model, IntegratorParams::new(0.8, 1e-3)).unwrap();
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).unwrap();
    for _ in 0..20 {
        ga.step(&mut model, &mut s).unwrap();
    }
    let drift = s.q.iter().zip(&s0.q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    println!("after 20 steps: max |q − q_ref| = {drift:.2e}");
    assert!(drift < 1e-12, "drift {drift}");
}

/// The flared hinge's axis is fixed in the parent's twisted end section: the tip turned rigidly
/// by φ about `−a`, `a = F_P(L) (sin β, cos β, 0)` with `F_P(L)` the inner body's twisted end
/// section frame, keeps every joint (violation below 1e-12) and reads a fold angle of φ
/// (1e-12), for φ up to ±2 rad.
#[test]
fn the_hinge_axis_is_fixed_in_the_parents_twisted_end_section() {
    let scene = twisted_wing(false, false);
    let model = Model::from_scene(&scene, Options::default()).unwrap();
    let (inner, tip) = (&scene.bodies[0], &scene.bodies[1]);
    let beta: f64 = 0.4;
    let a = inner.section_frame(inner.length) * Vector3::new(beta.sin(), beta.cos(), 0.0);
    for phi in [-2.0, -0.3, 0.5, 2.0] {
        let rotation = Rotation3::from_scaled_axis(-a * phi).into_inner();
        let pose = RigidPose { rotation, ..RigidPose::at_rest(tip.start) };
        let q = model.rigid_state(&[RigidPose::at_rest(scene.bodies[0].start), pose]).unwrap().q;
        let (violation, fold) = (model.constraint_residual(&q), model.fold_angle(&q, 1).unwrap());
        println!("φ = {phi}: joint violation {violation:.1e}, fold {fold}");
        assert!(violation < 1e-12 && (fold - phi).abs() < 1e-12, "φ = {phi}: {violation:e}, fold {fold}");
    }
}

/// Tip position of a clamped body of `n_el` elements under a tip force, solved statically.
fn tip_under_load(bodies: &[BodySpec], joints: &[JointSpec], force: Vector3<f64>, n_steps: usize) -> Vector3<f64> {
    let mut m = Model::new(bodies, joints, Vector3::zeros(), Options::default()).unwrap();
    let tip = m.n_nodes(0) - 1;
    m.set_nodal_load(0, tip, NodalLoad { force, moment: Vector3::zeros() }).unwrap();
    let q0 = m.reference_coordinates();
    let sol = m.solve_static(&q0, &StaticOptions { n_load_steps: n_steps, ..Default::default() }).unwrap();
    m.tip_position(&sol.q)
}

/// A constant twist θ is the untwisted body with its frame turned by θ: the same large
/// deflection under a tip force (tip displacement of 2 % of L, in all three directions) within
/// 1e-10 of the displacement (measured: bitwise equal; a constant twist has no reference curvature).
#[test]
fn a_constant_twist_is_a_rotated_frame() {
    let frame = Rotation3::from_euler_angles(0.1, 0.4, -0.2).into_inner();
    let theta = 0.7;
    let (mut twisted, joints) = samples::cantilever(samples::pretwisted_section(), 1.0, 8);
    twisted[0].frame = frame;
    twisted[0].twist = Twist::linear(theta, theta, 1.0);
    let mut rotated = twisted.clone();
    rotated[0].twist = Twist::none();
    rotated[0].frame = frame * scene::twist::rotation_x(theta);
    let force = Vector3::new(0.05, 0.1, 0.2);
    let (a, b) = (tip_under_load(&twisted, &joints, force, 4), tip_under_load(&rotated, &joints, force, 4));
    let u = a - twisted[0].end();
    let err = (a - b).norm() / u.norm();
    println!("constant twist vs rotated frame: |u| = {:.3e} m, difference {err:.2e} of it", u.norm());
    assert!(u.norm() > 0.02, "the load must deflect the tip: {u:?}");
    assert!(err < 1e-10, "{err}");
}

/// A linearly pretwisted cantilever (L = 1 m, EI_zz = 10 EI_yy, twist 0 → 90°) under a small
/// tip force meets the exact linear compliance of its rotating principal axes (shear and axial
/// compliance included) within 1e-4 from 16 elements on (the odd part of the response to ±F,
/// so that the axial shortening cancels). The quadratic CRV interpolation holds a linear twist
/// exactly; measured 3.19e-7, 2.01e-8, 1.56e-9, 6.3e-10 at 16, 32, 64 and 128 elements (the
/// last at the static solver's tolerance).
#[test]
fn a_pretwisted_cantilever_meets_the_exact_compliance() {
    let force = Vector3::new(0.0, 3e-5, 1e-4);
    let mut errors = Vec::new();
    for n_el in [16, 32, 64, 128] {
        let (b, j) =
            samples::pretwisted_cantilever(samples::pretwisted_section(), 1.0, n_el, 0.0, 0.5 * std::f64::consts::PI);
        let exact = samples::cantilever_tip_compliance(&b[0]) * force;
        // the odd part of the response: the axial shortening (u²/L, 1.5e-5 of u here) cancels
        let u = 0.5 * (tip_under_load(&b, &j, force, 1) - tip_under_load(&b, &j, -force, 1));
        let err = (u - exact).norm() / exact.norm();
        println!("{n_el} elements: u = {u:?}, exact {exact:?}, relative error {err:.3e}");
        errors.push(err);
    }
    assert!(errors[3] < 1e-4, "{errors:?}");
    assert!(errors.iter().all(|e| *e < 1e-4), "{errors:?}");
    assert!(errors[1] < 0.1 * errors[0], "not converging: {errors:?}");
    // the y–z coupling is there: a force along z moves the tip along y
    let (b, _) = samples::pretwisted_cantilever(samples::pretwisted_section(), 1.0, 1, 0.0, 0.5 * std::f64::consts::PI);
    let g: Matrix3<f64> = samples::cantilever_tip_compliance(&b[0]);
    assert!(g[(1, 2)].abs() > 0.1 * g[(2, 2)].abs(), "{g}");
}

/// ANCF's first six circular frequencies (rad/s) of the pretwisted cantilever below, Richardson's
/// extrapolation of its 32 and 64 elements (`ancf/tests/suite/twist.rs`, second order).
const ANCF_EXTRAPOLATED: [f64; 6] = [3.603510411, 8.870751510, 28.221906188, 45.120585786, 93.540280075, 107.785676209];

/// The pretwisted cantilever's natural frequencies (L = 1 m, twist 0 → 90°, EI_zz = 10 EI_yy):
/// GEBF's change from 32 to 64 elements stays below 2e-5 (measured ≤ 1.9e-5, the sixth mode),
/// and its 64-element frequencies meet ANCF's extrapolated ones within 2e-5 (measured ≤ 7.0e-6).
#[test]
fn pretwisted_cantilever_frequencies_agree_with_ancf() {
    let omegas = |n_el: usize| {
        let (b, j) =
            samples::pretwisted_cantilever(samples::pretwisted_section(), 1.0, n_el, 0.0, 0.5 * std::f64::consts::PI);
        let m = Model::new(&b, &j, Vector3::zeros(), Options::default()).unwrap();
        m.linear_modes(&m.reference_coordinates()).unwrap().omega[..6].to_vec()
    };
    let (w32, w64) = (omegas(32), omegas(64));
    for k in 0..6 {
        let (change, e) = (w32[k] / w64[k] - 1.0, w64[k] / ANCF_EXTRAPOLATED[k] - 1.0);
        println!(
            "mode {k}: GEBF 32 {:.8}, 64 {:.8}, ANCF {:.8}: change {change:.1e}, vs ANCF {e:.1e}",
            w32[k], w64[k], ANCF_EXTRAPOLATED[k]
        );
        assert!(change.abs() < 2e-5 && e.abs() < 2e-5, "mode {k}: {change:e}, {e:e}");
    }
}
