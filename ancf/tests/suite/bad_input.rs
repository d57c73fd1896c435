//! Bad input gives an error naming the field, never a panic.
use ancf::{Error, JointSpec, Model, Options, PointLoad, samples};
use nalgebra::Vector3;

fn err(f: impl FnOnce(&mut Vec<ancf::BodySpec>, &mut Vec<JointSpec>) -> Option<Options>) -> Error {
    let (mut b, mut j, g) = samples::double_pendulum(1.0, 45.0, 2);
    let opts = f(&mut b, &mut j).unwrap_or_default();
    Model::new(&b, &j, g, opts).expect_err("the input is invalid")
}

#[test]
fn unknown_body_in_a_joint() {
    let e = err(|_, j| {
        j[1] = JointSpec::FlaredHinge { parent: 0, child: 3, beta: 0.1 };
        None
    });
    assert_eq!(e.to_string(), "joints[1].child: no body 3 (the scene has 2 bodies)");
    let e = err(|_, j| {
        j[0] = JointSpec::GroundHinge { body: 7, axis: Vector3::y() };
        None
    });
    assert!(e.to_string().starts_with("joints[0].body: no body 7"), "{e}");
}

#[test]
fn missing_body_in_a_joint() {
    // a flared hinge needs two distinct bodies; a model needs at least one body
    let e = err(|_, j| {
        j[1] = JointSpec::FlaredHinge { parent: 1, child: 1, beta: 0.1 };
        None
    });
    assert!(e.to_string().starts_with("joints[1].child:"), "{e}");
    let e = Model::new(&[], &[], Vector3::zeros(), Options::default()).unwrap_err();
    assert!(e.to_string().starts_with("bodies:"), "{e}");
}

#[test]
fn negative_length() {
    let e = err(|b, _| {
        b[1].length = -0.5;
        None
    });
    assert_eq!(e.to_string(), "bodies[1].length: -0.5 is not positive");
}

#[test]
fn zero_elements() {
    let e = err(|b, _| {
        b[0].n_elements = 0;
        None
    });
    assert!(e.to_string().starts_with("bodies[0].n_elements:"), "{e}");
}

#[test]
fn non_finite_numbers() {
    let e = err(|b, _| {
        b[0].section.ei_yy = f64::NAN;
        None
    });
    assert!(e.to_string().starts_with("bodies[0].section.ei_yy: NaN"), "{e}");
    let e = err(|b, _| {
        b[1].start.x = f64::INFINITY;
        None
    });
    assert!(e.to_string().starts_with("bodies[1].start[0]:"), "{e}");
    let e = err(|_, j| {
        j[1] = JointSpec::FlaredHinge { parent: 0, child: 1, beta: f64::NAN };
        None
    });
    assert!(e.to_string().starts_with("joints[1].beta:"), "{e}");
    let (b, j, _) = samples::double_pendulum(1.0, 45.0, 2);
    let e = Model::new(&b, &j, Vector3::new(0.0, f64::NAN, 0.0), Options::default()).unwrap_err();
    assert!(e.to_string().starts_with("gravity[1]:"), "{e}");
}

#[test]
fn other_impossible_values() {
    let e = err(|_, j| {
        j[1] = JointSpec::FlaredHinge { parent: 0, child: 1, beta: 2.0 };
        None
    });
    assert!(e.to_string().starts_with("joints[1].beta: 2 is not in [-1.57"), "{e}");
    let e = err(|b, _| {
        b[0].frame[(0, 0)] = 2.0;
        None
    });
    assert!(e.to_string().starts_with("bodies[0].frame:"), "{e}");
    let e = err(|b, _| {
        b[1].start.z = 0.1;
        None
    });
    assert!(e.to_string().starts_with("joints[1].child: the child starts"), "{e}");
    let e = err(|_, j| {
        j.push(JointSpec::Clamp { body: 0 });
        None
    });
    // the scene rejects a second joint at one body's start before ANCF's rank test sees it
    assert_eq!(e.to_string(), "joints[2].body: body 0 is already attached at its start by joints[0]");
    let e = err(|_, _| Some(Options { penalty_factor: -1.0, ..Default::default() }));
    assert!(e.to_string().starts_with("options.penalty_factor:"), "{e}");
}

#[test]
fn bad_loads_and_sensor_queries() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 2);
    let mut m = Model::new(&b, &j, g, Options::default()).unwrap();
    let e = m.set_point_loads(&[PointLoad::force(0, 0.7, Vector3::x())]).unwrap_err();
    assert!(e.to_string().starts_with("loads[0].s: arclength 0.7 m is outside"), "{e}");
    let e = m.set_point_loads(&[PointLoad::force(5, 0.1, Vector3::x())]).unwrap_err();
    assert!(e.to_string().starts_with("loads[0].body: no body 5"), "{e}");
    let e = m.set_point_loads(&[PointLoad::force(0, 0.1, Vector3::new(f64::NAN, 0.0, 0.0))]).unwrap_err();
    assert!(e.to_string().starts_with("loads[0].force[0]:"), "{e}");
    let q = m.initial_state().q;
    assert!(matches!(m.fold_angle(&q, 0), Err(Error::NotAFlaredHinge { joint: 0 })));
    assert!(matches!(m.fold_angle(&q, 9), Err(Error::NoSuchJoint { joint: 9, n_joints: 2 })));
    assert!(m.section_frame(&q, 1, -0.1).is_err());
}
