//! No heap allocation inside the time loop: a counting global allocator around 200 steps of
//! the c = 1, β = 45° pendulum (assembly, structured factorisation, solves, CRV rescaling,
//! projection) after the set-up.

use gebf::{ForceElement, Model, Options, PointMass, Scene, samples};
use genalpha::{GenAlpha, IntegratorParams};
use nalgebra::Vector3;

#[test]
fn time_steps_do_not_allocate() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    steps_do_not_allocate(Model::new(&b, &j, g, Options { stabilization: true, ..Options::default() }).unwrap());
}

/// The same with springs and dampers on both hinges, point masses and an offset section centre
/// of mass (the slice kernels, the spring's tangents and the angle unwrapping in `post_step`).
/// The springs start at their rest angles: a preloaded spring is a step moment on the root
/// sections, whose first steps need halvings (docs/gebf.md §13).
#[test]
fn time_steps_with_springs_and_point_masses_do_not_allocate() {
    let (mut b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    b[1].section.cg_offset = [0.01, -0.005];
    b[1].point_masses.push(PointMass {
        at: 0.5,
        offset: Vector3::new(0.0, 0.05, 0.0),
        mass: 0.2,
        inertia: Vector3::new(2e-4, 1e-4, 1.5e-4),
    });
    let mut scene = Scene::new(b, j, g);
    scene.forces.push(ForceElement::HingeSpring { joint: 0, stiffness: 2.0, damping: 0.01, rest: 0.0 });
    scene.forces.push(ForceElement::HingeSpring { joint: 1, stiffness: 1.0, damping: 0.05, rest: 0.0 });
    steps_do_not_allocate(Model::from_scene(&scene, Options { stabilization: true, ..Options::default() }).unwrap());
}

/// The same with thrusts (follower forces, docs/gebf.md §16): one inside an element, one at the
/// tip, on a schedule, with their power.
#[test]
fn time_steps_with_thrust_do_not_allocate() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    let mut scene = Scene::new(b, j, g);
    for (body, at, direction) in [(1, 0.5, Vector3::z()), (0, 0.27, Vector3::new(0.0, 0.6, 0.8))] {
        let magnitude = scene::Schedule { points: vec![(0.0, 0.0), (0.1, 2.0), (0.3, 1.0)] };
        scene.forces.push(ForceElement::Thrust { body, at, direction, magnitude });
    }
    steps_do_not_allocate(Model::from_scene(&scene, Options { stabilization: true, ..Options::default() }).unwrap());
}

fn steps_do_not_allocate(mut m: Model) {
    let mut ga = GenAlpha::new(IntegratorParams::new(0.8, 0.002), &m).unwrap();
    let mut s = m.initial_state();
    ga.initialize(&m, &mut s).unwrap();
    ga.step(&mut m, &mut s).unwrap(); // first step: lazy set-up, if any
    let ((), allocations) = alloc_count::count(|| {
        for _ in 0..200 {
            ga.step(&mut m, &mut s).unwrap();
            std::hint::black_box(m.tip_position(&s.q));
            std::hint::black_box(m.constraint_residual(&s.q));
            std::hint::black_box(m.energies(&s.q, &s.v));
            std::hint::black_box(m.dissipation_power(&s.q, &s.v));
            std::hint::black_box(m.thrust_power(s.t, &s.q, &s.v));
        }
    });
    assert_eq!(allocations, 0, "{allocations} allocations in 200 steps");
}
