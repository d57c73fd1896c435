//! Frame handling: a rigidly rotated and shifted scene (bodies, frames, hinge axis, gravity)
//! gives the rotated and shifted motion, on both solve paths; and a scene whose child body has
//! a different (but equivalent) section frame orientation is handled by the general flared-hinge
//! axis `α_C = F_Cᵀ F_P (sin β, cos β, 0)`.
use crate::common;

use ancf::{JointSpec, Model, Options, SolvePath, samples};
use nalgebra::{Rotation3, Vector3};

/// The tip after `n_steps` paper-size steps, each solved far below the default Newton tolerance:
/// the invariance holds for the converged steps, while the default tolerance (1e-8 of a step's
/// motion, with the convergence estimate accepting iterates anywhere below it) would let the
/// two scenes differ by ~1e-8 m.
fn tip_after(model: &mut Model, n_steps: usize) -> Vector3<f64> {
    let mut params = common::params(0.8, 0.002);
    params.newton.rtol = 1e-12;
    params.newton.atol = 1e-14;
    let mut ga = model.integrator(params).unwrap();
    let mut s = model.initial_state();
    ga.initialize(model, &mut s).unwrap();
    for _ in 0..n_steps {
        ga.step(model, &mut s).unwrap();
    }
    model.tip_position(&s.q)
}

#[test]
fn rotated_scene_gives_the_rotated_motion() {
    let rot = Rotation3::from_scaled_axis(Vector3::new(0.4, -0.9, 1.3));
    let shift = Vector3::new(1.0, -2.0, 0.5);
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let (b, j, g) = samples::double_pendulum(1.0, 30.0, 4);
        let mut m0 = Model::new(&b, &j, g, Options { path, ..Default::default() }).unwrap();
        let tip0 = tip_after(&mut m0, 150);
        let b1: Vec<_> = b
            .iter()
            .map(|x| {
                let mut y = x.clone();
                y.start = rot * x.start + shift;
                y.frame = rot.matrix() * x.frame;
                y
            })
            .collect();
        let j1 = vec![JointSpec::GroundHinge { body: 0, axis: rot * Vector3::y() }, j[1].clone()];
        let mut m1 = Model::new(&b1, &j1, rot * g, Options { path, ..Default::default() }).unwrap();
        let tip1 = tip_after(&mut m1, 150);
        let err = (tip1 - (rot * tip0 + shift)).norm();
        assert!(err < 1e-9, "{path:?}: {err:e}");
        assert!((tip0 - Vector3::new(1.0, 0.0, 0.0)).norm() > 0.1, "the pendulum must have moved");
    }
}

#[test]
fn child_with_a_rolled_section_frame_is_the_same_hinge() {
    // Body 2's section frame rolled by 90° about its axis: (x, z, −y). Same physics for a
    // section with equal bending stiffness and inertia about y and z.
    let (b, j, g) = samples::double_pendulum(1.0, 30.0, 4);
    let mut m0 = Model::new(&b, &j, g, Options::default()).unwrap();
    let tip0 = tip_after(&mut m0, 150);
    let mut b1 = b.clone();
    b1[1].frame = Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2).into_inner();
    let mut m1 = Model::new(&b1, &j, g, Options::default()).unwrap();
    let tip1 = tip_after(&mut m1, 150);
    assert!((tip1 - tip0).norm() < 1e-8, "{:e}", (tip1 - tip0).norm());
    // the fold angle is measured relative to the reference relative rotation: zero at start
    let q = m1.initial_state().q;
    assert!(m1.fold_angle(&q, 1).unwrap().abs() < 1e-14);
}
