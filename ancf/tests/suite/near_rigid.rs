//! Near-rigid shear and axial stiffness (issue 38).

use ancf::{BodySpec, ForceElement, JointSpec, Model, Options, PointMass, Scene, Section};
use nalgebra::{Matrix3, Vector3};

/// Healy's wind-tunnel wing (cases/healy_ffwt_flare10_aoa5.json): an aluminium spar 0.365 m
/// inboard and a 0.135 m tip on a flared hinge with a 1e-4 N·m/rad spring, its tip mass 12 mm
/// behind the spar, with the shear stiffness `ga` and every other stiffness as in the case.
pub fn healy_wing(ga: f64, ea: f64, flare_deg: f64, gravity: Vector3<f64>) -> Scene {
    let section = |scale: f64| Section {
        ea,
        ga_y: ga,
        ga_z: ga,
        ..Section::centred(
            0.2592 * scale,
            9.13766e-6 * scale,
            4.97664e-7 * scale,
            8.64e-6 * scale,
            ea,
            ga,
            ga,
            18.2753,
            12.9024,
            224.0,
        )
    };
    let inner = BodySpec {
        name: "inner".into(),
        start: Vector3::zeros(),
        length: 0.365,
        frame: Matrix3::identity(),
        section: section(1.0),
        n_elements: 8,
        point_masses: Vec::new(),
        twist: ancf::Twist::none(),
    };
    let tip = BodySpec {
        name: "tip".into(),
        start: Vector3::new(0.365, 0.0, 0.0),
        length: 0.135,
        frame: Matrix3::identity(),
        section: section(0.1),
        n_elements: 3,
        point_masses: vec![PointMass {
            at: 0.059,
            offset: Vector3::new(0.0, -0.0139, 0.0),
            mass: 0.061,
            inertia: Vector3::new(1.89e-5, 1.16e-4, 1.349e-4),
        }],
        twist: ancf::Twist::none(),
    };
    Scene {
        forces: vec![ForceElement::HingeSpring { joint: 1, stiffness: 1e-4, damping: 0.0, rest: 0.0 }],
        ..Scene::new(
            vec![inner, tip],
            vec![
                JointSpec::Clamp { body: 0 },
                JointSpec::FlaredHinge { parent: 0, child: 1, beta: flare_deg.to_radians() },
            ],
            gravity,
        )
    }
}

/// ANCF statics with near-rigid shear stiffness, issue 38: the Healy wing's free flared hinge
/// (spring 1e-4 N·m/rad) under gravity, hanging (−89.49°) and, with gravity reversed and
/// weakened, folded up (+82.93°), solved by the generic Newton iteration at rest from the
/// reference configuration in one load step. With the exact tangent alone Newton wandered from
/// GA = 1e8 N up (a turned body's transient stretch `θ²/2` times the shear stiffness outweighed
/// the bending and hinge stiffness) and never converged; the solver now falls back, when the
/// exact iteration stalls, on Newton's matrix at rest without the geometric terms of the shears
/// and of compressed axial strain (docs/ancf.md §9), which converges from the case's
/// GA = 2.16e6 N up to 1e11 N (GA/EI_yy = 7.8e9 1/m²; at 1e12 N the matrix is singular to
/// rounding) to the same fold angle: measured within 4e-8° of GA = 2.16e6's, in 57–94
/// iterations of both attempts. The static steps now turn the nodes rather than push them along
/// their tangents (docs/ancf.md §9, `static_step.rs`), so no transient stretch arises: 8–11
/// iterations, the same folds. Accepted: within 1e-6°, at most 20 iterations.
#[test]
fn near_rigid_shear_statics_converge_issue_38() {
    for g in [Vector3::new(0.0, 0.0, -9.8), Vector3::new(0.0, 0.0, 0.3)] {
        let mut reference = None;
        for ga in [2.16e6, 1e8, 1e9, 1e10, 1e11] {
            let model = Model::from_scene(&healy_wing(ga, 6.72e6, 10.0, g), Options::default()).unwrap();
            let q0 = model.reference_coordinates().to_vec();
            let p = genalpha::analysis::StaticParams { max_iter: 100, tol: 1e-11, rel_residual_tol: 0.0 };
            let s = genalpha::analysis::solve_static(&model, 0.0, &q0, &p)
                .unwrap_or_else(|e| panic!("GA {ga:e}, gravity {}: {e}", g.z));
            let fold = model.fold_angle(&s.q, 1).unwrap().to_degrees();
            println!("GA {ga:e}, gravity {}: fold {fold:.9} deg, {} iterations", g.z, s.n_iterations);
            assert!(s.n_iterations <= 20, "GA {ga:e}: {} iterations", s.n_iterations);
            let f0 = *reference.get_or_insert(fold);
            assert!((fold - f0).abs() < 1e-6, "GA {ga:e}: fold {fold} against {f0}");
            assert!(fold.abs() > 80.0, "a large fold expected: {fold}");
        }
    }
}
