//! Thrust, a follower force (docs/ancf.md §14): its analytic tangent against finite differences
//! on twisted, deformed and rotated bodies, on both paths. The exact answers (small-load tip
//! deflection, the follower condition under a large load, the agreement with GEBF) and the
//! energy balance are in `aeroelastic/tests/suite/thrust.rs`.
use ancf::{BodySpec, ForceElement, Model, Options, RigidPose, Scene, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::{Rotation3, Unit, Vector3};

fn thrust(body: usize, at: f64, d: Vector3<f64>, magnitude: f64) -> ForceElement {
    ForceElement::Thrust { body, at, direction: d.normalize(), magnitude: scene::Schedule::constant(magnitude) }
}

/// The paper's pendulum (3 elements per body, both bodies twisted) with `forces`.
fn pendulum(forces: Vec<ForceElement>, path: SolvePath) -> Model {
    let (mut bodies, joints, g) = samples::double_pendulum(1.0, 45.0, 3);
    bodies[0].twist = ancf::Twist::linear(0.2, 0.9, bodies[0].length);
    bodies[1].twist = ancf::Twist::table(vec![(0.0, -0.3), (0.2, 0.4), (0.5, 0.1)]);
    let scene = Scene { forces, ..Scene::new(bodies, joints, g) };
    Model::from_scene(&scene, Options { path, ..Default::default() }).expect("valid scene")
}

/// Body 0 turned by 2.9 rad about the ground axis and body 1 folded by 1.7 rad, with noise on
/// every coordinate (bending, shear, stretch and section deformation).
fn state(model: &Model) -> Vec<f64> {
    let b: Vec<&BodySpec> = (0..2).map(|i| model.body_spec(i).unwrap()).collect();
    let r0 = Rotation3::from_axis_angle(&Vector3::y_axis(), 2.9).into_inner();
    let beta = 45f64.to_radians();
    let a = Vector3::new(beta.sin(), beta.cos(), 0.0);
    let fold = Rotation3::from_axis_angle(&Unit::new_normalize(-(r0 * a)), 1.7).into_inner();
    let poses = [
        RigidPose { rotation: r0, ..RigidPose::at_rest(b[0].start) },
        RigidPose { rotation: fold * r0, translation: r0 * b[1].start, ..RigidPose::at_rest(b[1].start) },
    ];
    let s = model.rigid_state(&poses).unwrap();
    s.q.iter().enumerate().map(|(i, x)| x + 0.04 * (((i * 37 + 11) % 101) as f64 / 101.0 - 0.5)).collect()
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// `∂r/∂q` of the thrusts alone (the model with thrusts minus the one without) equals central
/// differences of their residual (h = 1e-6), on both paths: thrusts inside an element, at a
/// node between elements, at a body's tip and at its start, in directions with axial and both
/// transverse parts, of some hundred newtons so that their residual stands well above the
/// rounding of the elastic forces it is the difference of. The thrusts' matrix is unsymmetric.
/// Measured: relative error 9.5e-9 (DAE), 2.3e-8 (ODE), the rounding of that difference (it
/// falls in proportion as the thrusts grow).
#[test]
fn thrust_tangent_equals_finite_differences() {
    let forces = || {
        vec![
            thrust(0, 0.1, Vector3::new(0.3, -0.4, 1.0), 300.0),
            thrust(0, 0.5 / 3.0, Vector3::new(0.0, 1.0, 0.0), 200.0),
            thrust(1, 0.5, Vector3::new(0.0, 0.0, 1.0), 150.0),
            thrust(1, 0.0, Vector3::new(1.0, 0.2, 0.1), 250.0),
        ]
    };
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let (with, without) = (pendulum(forces(), path), pendulum(Vec::new(), path));
        let n = with.n_dof();
        let q = state(&with);
        let (v, a) = (vec![0.0; n], vec![0.0; n]);
        let part = |q: &[f64]| {
            let (mut r1, mut r0) = (vec![0.0; n], vec![0.0; n]);
            with.residual_inplace(0.0, q, &v, &a, &mut r1);
            without.residual_inplace(0.0, q, &v, &a, &mut r0);
            r1.iter().zip(&r0).map(|(x, y)| x - y).collect::<Vec<f64>>()
        };
        let (mut k1, mut k0) = (DenseMatrix::zeros(n, n), DenseMatrix::zeros(n, n));
        with.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, 0.0, 1.0, &mut k1.view());
        without.iteration_matrix_inplace(0.0, &q, &v, &a, 0.0, 0.0, 1.0, &mut k0.view());
        let an: Vec<f64> = k1.as_slice().iter().zip(k0.as_slice()).map(|(x, y)| x - y).collect();
        let h = 1e-6;
        let mut fd = vec![0.0; n * n];
        for j in 0..n {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[j] += h;
            qm[j] -= h;
            let (rp, rm) = (part(&qp), part(&qm));
            for i in 0..n {
                fd[j * n + i] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let scale = max_abs(&fd);
        let diff: Vec<f64> = an.iter().zip(&fd).map(|(x, y)| x - y).collect();
        let err = max_abs(&diff) / scale;
        let asym = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).map(|(i, j)| (an[j * n + i] - an[i * n + j]).abs());
        let asym = asym.fold(0.0, f64::max) / scale;
        println!("{path:?}: |K_T| {scale:.3e}, relative error {err:.2e}, unsymmetric part {asym:.2e}");
        assert!(scale > 10.0, "the thrust part vanished");
        assert!(err < 1e-6, "{path:?}: {err:e}");
        assert!(asym > 1e-3, "{path:?}: a follower force's tangent is unsymmetric");
    }
}

/// In the reference configuration every thrust is `T R_ref(s) d`, and a rigid rotation of the
/// whole body rotates it exactly (to rounding), wherever it sits on the body.
#[test]
fn thrust_is_exact_in_the_reference_and_under_rigid_rotation() {
    for at in [0.0, 0.1, 0.5 / 3.0, 0.37, 0.5] {
        let d = Vector3::new(0.3, -0.4, 1.0).normalize();
        let path = SolvePath::Dae;
        let (with, without) = (pendulum(vec![thrust(1, at, d, 2.0)], path), pendulum(Vec::new(), path));
        let n = with.n_dof();
        let body = with.body_spec(1).unwrap().clone();
        let r = Rotation3::from_scaled_axis(Vector3::new(0.4, -1.1, 2.3)).into_inner();
        let poses = |rot| {
            [
                RigidPose::at_rest(with.body_spec(0).unwrap().start),
                RigidPose { rotation: rot, ..RigidPose::at_rest(body.start) },
            ]
        };
        for rot in [nalgebra::Matrix3::identity(), r] {
            let q = with.rigid_state(&poses(rot)).unwrap().q;
            let (mut r1, mut r0) = (vec![0.0; n], vec![0.0; n]);
            with.residual_inplace(0.0, &q, &q, &vec![0.0; n], &mut r1);
            without.residual_inplace(0.0, &q, &q, &vec![0.0; n], &mut r0);
            // Σ of the position rows of −(r1 − r0) is the force (the Hermite weights of the
            // positions sum to one; the slope rows carry its moment about the nodes)
            let mut f = Vector3::zeros();
            for node in 0..with.n_full_coords() / 12 {
                for i in 0..3 {
                    f[i] -= r1[12 * node + i] - r0[12 * node + i];
                }
            }
            let expected = rot * body.section_frame(at) * d * 2.0;
            assert!((f - expected).norm() < 1e-12, "at {at}: {f} against {expected}");
        }
    }
}
