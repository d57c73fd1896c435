//! Model-level derivative checks: the iteration matrix the integrator factorises equals central
//! differences of the residual (both solve paths, with a configuration-dependent moment load),
//! and the constraint Jacobian equals central differences of Φ; each also on twisted bodies
//! (a linear twist and a table with a breakpoint inside an element, docs/ancf.md §1).
use ancf::{BodySpec, ForceElement, JointSpec, Model, Options, PointLoad, Scene, SolvePath, Twist, samples};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::Vector3;

/// The paper's double pendulum, its bodies twisted when `twisted` (with a spring on the flared
/// hinge then, whose reference angle involves the twisted end and start sections).
fn pendulum(beta: f64, n_el: usize, twisted: bool, options: Options) -> Model {
    let (mut bodies, joints, g): (Vec<BodySpec>, Vec<JointSpec>, _) = samples::double_pendulum(1.0, beta, n_el);
    let mut scene = Scene::new(bodies.clone(), joints, g);
    if twisted {
        bodies[0].twist = Twist::linear(0.3, 1.1, 0.5);
        bodies[1].twist = Twist::table(vec![(0.0, -0.2), (0.2, 0.4), (0.5, 0.1)]);
        scene.bodies = bodies;
        scene.forces = vec![ForceElement::HingeSpring { joint: 1, stiffness: 0.7, damping: 0.0, rest: 0.2 }];
    }
    Model::from_scene(&scene, options).unwrap()
}

fn deformed_state(model: &Model) -> Vec<f64> {
    let q0 = model.initial_state().q;
    q0.iter().enumerate().map(|(i, x)| x + 0.05 * ((i * 37 % 101) as f64 / 101.0 - 0.5)).collect()
}

fn max_rel(a: &DenseMatrix, b: &DenseMatrix) -> f64 {
    let scale = b.as_slice().iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    a.as_slice().iter().zip(b.as_slice()).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn iteration_matrix_equals_finite_differences_of_the_residual() {
    for (path, twisted) in
        [(SolvePath::Dae, false), (SolvePath::Ode, false), (SolvePath::Dae, true), (SolvePath::Ode, true)]
    {
        let mut model = pendulum(45.0, 3, twisted, Options { path, ..Default::default() });
        model
            .set_point_loads(&[
                PointLoad::moment(1, 0.31, Vector3::new(0.4, -1.2, 0.7)),
                PointLoad {
                    body: 0,
                    s: 0.2,
                    y: 0.01,
                    z: -0.02,
                    force: Vector3::new(1.0, 2.0, -3.0),
                    moment: Vector3::zeros(),
                },
            ])
            .unwrap();
        let n = model.n_dof();
        let q = deformed_state(&model);
        let v = vec![0.0; n];
        let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin()).collect();
        for (c_m, c_k) in [(0.0, 1.0), (1.0, 0.0)] {
            let mut k = DenseMatrix::zeros(n, n);
            model.iteration_matrix_inplace(0.0, &q, &v, &a, c_m, 0.0, c_k, &mut k.view());
            let mut fd = DenseMatrix::zeros(n, n);
            // the residual is linear in v_dot: a unit step is exact and avoids cancellation
            let h = if c_k != 0.0 { 1e-6 } else { 1.0 };
            let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
            for j in 0..n {
                let (mut qp, mut qm, mut ap, mut am) = (q.clone(), q.clone(), a.clone(), a.clone());
                if c_k != 0.0 {
                    qp[j] += h;
                    qm[j] -= h;
                } else {
                    ap[j] += h;
                    am[j] -= h;
                }
                model.residual_inplace(0.0, &qp, &v, &ap, &mut rp);
                model.residual_inplace(0.0, &qm, &v, &am, &mut rm);
                for i in 0..n {
                    *fd.get_mut(i, j) = (rp[i] - rm[i]) / (2.0 * h);
                }
            }
            let err = max_rel(&k, &fd);
            println!("{path:?} twisted {twisted} c_m {c_m} c_k {c_k}: relative error {err:.2e}");
            assert!(err < 1e-6, "{path:?} twisted {twisted}: {err}");
        }
    }
}

#[test]
fn constraint_jacobian_equals_finite_differences() {
    for (beta, twisted) in [(0.0, false), (30.0, false), (90.0, false), (-60.0, false), (30.0, true), (90.0, true)] {
        let model = pendulum(beta, 2, twisted, Options::default());
        let (n, m) = (model.n_dof(), model.n_holonomic());
        let q = deformed_state(&model);
        let mut j = DenseMatrix::zeros(m, n);
        model.phi_q_inplace(0.0, &q, &mut j.view());
        let mut fd = DenseMatrix::zeros(m, n);
        let (mut pp, mut pm) = (vec![0.0; m], vec![0.0; m]);
        for c in 0..n {
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[c] += 1e-6;
            qm[c] -= 1e-6;
            model.phi_inplace(0.0, &qp, &mut pp);
            model.phi_inplace(0.0, &qm, &mut pm);
            for r in 0..m {
                *fd.get_mut(r, c) = (pp[r] - pm[r]) / 2e-6;
            }
        }
        let err = max_rel(&j, &fd);
        assert!(err < 1e-8, "beta {beta} twisted {twisted}: {err}");
        // rank 12 for every β, including 90° (no division by cos β anywhere)
        assert_eq!(model.n_reduced_coords(), n - 12, "beta {beta} twisted {twisted}");
    }
}

/// The exact section rates (`Structure::section_states`) equal central differences of the
/// section poses along the velocity, at a deformed state on both solve paths and on twisted
/// bodies: point velocities and frame angular velocities within 1e-8 of the largest (measured
/// 1.0e-10, the differences' own rounding error at a step of 1e-6).
#[test]
fn section_rates_equal_finite_differences_of_the_poses() {
    use formulation::Structure;
    for_section_cases(|path, twisted, model, q, v, at| {
        let mut exact = Vec::new();
        assert!(Structure::section_states(model, q, v, at, &mut exact));
        let eps = 1e-6;
        let probe = |sign: f64| {
            let dq: Vec<f64> = v.iter().map(|x| sign * eps * x).collect();
            let mut qp = vec![0.0; q.len()];
            model.retract_inplace(q, &dq, &mut qp);
            let mut poses = Vec::new();
            model.section_poses(&qp, at, &mut poses);
            poses
        };
        let (plus, minus) = (probe(1.0), probe(-1.0));
        let (mut scale, mut err) = (0.0_f64, 0.0_f64);
        for ((&(p, r, vel, omega), &(pp, rp)), &(pm, rm)) in exact.iter().zip(&plus).zip(&minus) {
            assert!((p - (pp + pm) * 0.5).norm() < 1e-9 && (r - (rp + rm) * 0.5).norm() < 1e-9);
            let fd_vel = (pp - pm) / (2.0 * eps);
            let w = (rp - rm) * r.transpose() / (2.0 * eps);
            let fd_omega = Vector3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) * 0.5;
            scale = scale.max(vel.norm()).max(omega.norm());
            err = err.max((vel - fd_vel).norm()).max((omega - fd_omega).norm());
        }
        println!("{path:?} twisted {twisted}: rates up to {scale:.3e}, exact - differences {err:.2e}");
        assert!(err <= 1e-8 * scale, "{path:?}: {err:e} against {scale:e}");
    });
}

/// `f` on the pendulum of both solve paths, plain and twisted, at a deformed state with
/// velocities, and six stations (both bodies' ends and interior points).
fn for_section_cases(mut f: impl FnMut(SolvePath, bool, &Model, &[f64], &[f64], &[(usize, f64)])) {
    for (path, twisted) in
        [(SolvePath::Dae, false), (SolvePath::Ode, false), (SolvePath::Dae, true), (SolvePath::Ode, true)]
    {
        let model = pendulum(45.0, 3, twisted, Options { path, ..Default::default() });
        let q = deformed_state(&model);
        let v: Vec<f64> = (0..model.n_dof()).map(|i| (i as f64 * 0.7).cos()).collect();
        let at = [(0, 0.0), (0, 0.13), (0, 0.5), (1, 0.0), (1, 0.31), (1, 0.5)];
        f(path, twisted, &model, &q, &v, &at);
    }
}

/// The exact section accelerations (`Structure::section_motions`) equal central differences of
/// the exact rates along the trajectory `q(t) = q ⊕ (t v + ½ t² a)`, `v(t) = v + t a`, on both
/// paths and on twisted bodies: accelerations and angular accelerations within 1e-8 of the
/// largest (measured 2.4e-10 to 5.7e-10, the differences' truncation at a step of 1e-5, which
/// falls a hundredfold from a step of 1e-4: second order).
#[test]
fn section_accelerations_equal_finite_differences_of_the_rates() {
    use formulation::Structure;
    for_section_cases(|path, twisted, model, q, v, at| {
        let a: Vec<f64> = (0..model.n_dof()).map(|i| (i as f64 * 1.3).sin() * 3.0).collect();
        let mut exact = Vec::new();
        assert!(Structure::section_motions(model, q, v, &a, at, &mut exact));
        let mut rates = Vec::new();
        assert!(Structure::section_states(model, q, v, at, &mut rates));
        let h = 1e-5;
        let probe = |t: f64| {
            let dq: Vec<f64> = v.iter().zip(&a).map(|(v, a)| t * v + 0.5 * t * t * a).collect();
            let mut qt = vec![0.0; q.len()];
            model.retract_inplace(q, &dq, &mut qt);
            let vt: Vec<f64> = v.iter().zip(&a).map(|(v, a)| v + t * a).collect();
            let mut out = Vec::new();
            assert!(Structure::section_states(model, &qt, &vt, at, &mut out));
            out
        };
        let (plus, minus) = (probe(h), probe(-h));
        let (mut scale, mut err) = (0.0_f64, 0.0_f64);
        for (((m, s0), p), q) in exact.iter().zip(&rates).zip(&plus).zip(&minus) {
            assert_eq!((m.p, m.r, m.vel, m.omega), *s0, "the motions' poses and rates are section_states'");
            let acc = (p.2 - q.2) / (2.0 * h);
            let alpha = (p.3 - q.3) / (2.0 * h);
            scale = scale.max(m.acc.norm()).max(m.alpha.norm());
            err = err.max((m.acc - acc).norm()).max((m.alpha - alpha).norm());
        }
        println!("{path:?} twisted {twisted}: accelerations up to {scale:.3e}, exact - differences {err:.2e}");
        assert!(err <= 1e-8 * scale, "{path:?}: {err:e} against {scale:e}");
    });
}
