//! Bad input is an error that names the field and the value, never a panic.

use gebf::{Error, JointSpec, Model, Options, samples};
use nalgebra::{Matrix3, Vector3};

fn msg(r: Result<Model, Error>) -> String {
    r.expect_err("must be rejected").to_string()
}

#[test]
fn invalid_models_name_the_field() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    let new = |b: &[gebf::BodySpec], j: &[JointSpec]| Model::new(b, j, g, Options::default());

    let mut bb = b.clone();
    bb[1].length = -0.5;
    assert_eq!(msg(new(&bb, &j)), "bodies[1].length: -0.5 is not positive");

    let mut bb = b.clone();
    bb[0].n_elements = 0;
    assert_eq!(msg(new(&bb, &j)), "bodies[0].n_elements: a body needs at least one element (got 0)");

    let mut bb = b.clone();
    bb[0].start.y = f64::NAN;
    assert_eq!(msg(new(&bb, &j)), "bodies[0].start[1]: NaN is not a finite number");

    let mut bb = b.clone();
    bb[0].frame = Matrix3::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert!(msg(new(&bb, &j)).starts_with("bodies[0].frame: not an orthonormal right-handed frame"));

    let mut bb = b.clone();
    bb[0].frame = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    assert!(msg(new(&bb, &j)).starts_with("bodies[0].frame: not an orthonormal right-handed frame"));

    let mut bb = b.clone();
    bb[1].section.gj = 0.0;
    assert_eq!(msg(new(&bb, &j)), "bodies[1].section.gj: 0 is not positive");

    let jj = vec![JointSpec::GroundHinge { body: 3, axis: Vector3::y() }, j[1].clone()];
    assert_eq!(msg(new(&b, &jj)), "joints[0].body: no body 3 (the scene has 2 bodies)");

    let jj = vec![JointSpec::GroundHinge { body: 0, axis: Vector3::zeros() }, j[1].clone()];
    assert_eq!(msg(new(&b, &jj)), "joints[0].axis: the axis has zero length");

    let jj = vec![j[0].clone(), JointSpec::FlaredHinge { parent: 0, child: 1, beta: 2.0 }];
    assert!(msg(new(&b, &jj)).starts_with("joints[1].beta: 2 is not in [-1.57"));

    let jj = vec![j[0].clone(), JointSpec::FlaredHinge { parent: 1, child: 0, beta: 0.3 }];
    assert!(msg(new(&b, &jj)).starts_with("joints[1].child: the child starts"));

    let jj = vec![j[0].clone(), j[1].clone(), JointSpec::Clamp { body: 1 }];
    assert_eq!(msg(new(&b, &jj)), "joints[2].body: body 1 is already attached at its start by joints[1]");

    let mut gg = g;
    gg.z = f64::INFINITY;
    assert_eq!(msg(Model::new(&b, &j, gg, Options::default())), "gravity[2]: inf is not a finite number");

    let bad = Options { n_gauss_stiffness: 4, ..Options::default() };
    assert_eq!(msg(Model::new(&b, &j, g, bad)), "options.n_gauss_stiffness: 4 is not in [1, 3]");
}

#[test]
fn queries_reject_bad_indices() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    let mut m = Model::new(&b, &j, g, Options::default()).unwrap();
    let q = m.reference_coordinates();
    assert_eq!(m.fold_angle(&q, 0).unwrap_err().to_string(), "joints[0] is not a flared hinge");
    assert_eq!(m.fold_angle(&q, 7).unwrap_err().to_string(), "no joint 7 (the model has 2)");
    assert_eq!(m.fold_angle(&q, 1).unwrap(), 0.0);
    assert!(m.node_position(&q, 1, 11).is_err());
    assert!(m.set_nodal_load(2, 0, Default::default()).is_err());
    assert_eq!(m.span(), 1.0);
    assert_eq!(m.tip_position(&q), Vector3::new(1.0, 0.0, 0.0));
    assert_eq!(m.constraint_residual(&q), 0.0);
}
