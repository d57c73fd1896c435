//! The model's per-step primitives do not allocate (STYLE rule 4): residual, iteration matrix,
//! constraints, sensors and load updates, on both solve paths, counted with a global allocator.
use ancf::{ForceElement, Model, Options, PointLoad, PointMass, Scene, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::Vector3;

#[test]
fn per_step_primitives_do_not_allocate() {
    // the counter works
    let (probe, n) = alloc_count::count(|| Vec::<u64>::with_capacity(16));
    assert!(n > 0 && probe.capacity() >= 16);
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let (b, j, g) = samples::double_pendulum(1.0, 45.0, 4);
        let mut model = Model::new(&b, &j, g, Options { path, ..Default::default() }).unwrap();
        let loads = [PointLoad::force(1, 0.3, Vector3::new(0.0, 0.0, 1.0)), PointLoad::moment(0, 0.2, Vector3::y())];
        model.set_point_loads(&loads).unwrap(); // sizes the moment list
        let s = model.initial_state();
        let (n, m) = (model.n_dof(), model.n_holonomic());
        let mut r = vec![0.0; n];
        let mut phi = vec![0.0; m];
        let mut k = DenseMatrix::zeros(n, n);
        let ((), allocations) = alloc_count::count(|| {
            for _ in 0..3 {
                model.set_point_loads(&loads).unwrap();
                model.residual_inplace(0.0, &s.q, &s.v, &s.a, &mut r);
                model.iteration_matrix_inplace(0.0, &s.q, &s.v, &s.a, 1.0, 0.0, 1e-6, &mut k.view());
                model.phi_inplace(0.0, &s.q, &mut phi);
                let _ = model.tip_position(&s.q);
                let _ = model.fold_angle(&s.q, 1).unwrap();
                let _ = model.energies(&s.q, &s.v);
                let _ = model.constraint_residual(&s.q);
                let _ = model.section_frame(&s.q, 1, 0.25).unwrap();
                let _ = model.material_velocity(&s.v, 1, 0.25, 0.1, 0.0).unwrap();
            }
        });
        assert_eq!(allocations, 0, "{path:?}: {allocations} allocations");
    }
    spring_and_point_mass_primitives_do_not_allocate();
}

/// The same with hinge springs and dampers on both hinges, point masses and an offset section:
/// the spring terms, the dampers' velocity expansion (ODE path), the hinge-angle bookkeeping of
/// `post_step` and the new sensors allocate nothing either. (Called from the test above.)
fn spring_and_point_mass_primitives_do_not_allocate() {
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let (mut b, j, g) = samples::double_pendulum(1.0, 45.0, 4);
        b[1].section.cg_offset = [0.01, 0.02];
        b[1].point_masses.push(PointMass {
            at: 0.1,
            offset: Vector3::new(0.01, 0.02, 0.0),
            mass: 0.2,
            inertia: Vector3::new(2e-4, 1e-4, 1e-4),
        });
        let forces = vec![
            ForceElement::HingeSpring { joint: 0, stiffness: 1.0, damping: 0.1, rest: 0.0 },
            ForceElement::HingeSpring { joint: 1, stiffness: 2.0, damping: 0.0, rest: 0.2 },
        ];
        let scene = Scene { forces, ..Scene::new(b, j, g) };
        let mut model = Model::from_scene(&scene, Options { path, ..Default::default() }).unwrap();
        let mut s = model.initial_state();
        s.v.iter_mut().enumerate().for_each(|(i, x)| *x = 0.01 * (i % 7) as f64);
        let n = model.n_dof();
        let mut r = vec![0.0; n];
        let mut k = DenseMatrix::zeros(n, n);
        let (mut q, mut v, mut vd, mut a) = (s.q.clone(), s.v.clone(), s.v_dot.clone(), s.a.clone());
        let ((), allocations) = alloc_count::count(|| {
            for _ in 0..3 {
                model.residual_inplace(0.0, &s.q, &s.v, &s.a, &mut r);
                model.iteration_matrix_inplace(0.0, &s.q, &s.v, &s.a, 1.0, 0.5, 1e-6, &mut k.view());
                let _ = model.energies(&s.q, &s.v);
                let _ = model.dissipation_power(&s.q, &s.v);
                let _ = model.hinge_angle(&s.q, 1).unwrap();
                q.copy_from_slice(&s.q);
                model.post_step(0.0, &mut q, &mut v, &mut vd, &mut a);
                model.reset_hinge_angles(&q);
            }
        });
        assert_eq!(allocations, 0, "{path:?}: {allocations} allocations");
    }
}

/// Time steps with thrusts (follower forces, docs/ancf.md §14), on both paths, with the skyline
/// LU that the thrusts' unsymmetric tangent switches to its unsymmetric storage, and the
/// thrusts' power of the energy balance: nothing allocates after the first step.
#[test]
fn time_steps_with_thrust_do_not_allocate() {
    for path in [SolvePath::Dae, SolvePath::Ode] {
        let (b, j, g) = samples::double_pendulum(1.0, 45.0, 4);
        let thrust = |body, at, direction: Vector3<f64>| ForceElement::Thrust {
            body,
            at,
            direction,
            magnitude: scene::Schedule { points: vec![(0.0, 0.0), (0.1, 2.0), (0.3, 1.0)] },
        };
        let forces = vec![thrust(1, 0.5, Vector3::z()), thrust(0, 0.3, Vector3::new(0.0, 0.6, 0.8))];
        let scene = Scene { forces, ..Scene::new(b, j, g) };
        let mut model = Model::from_scene(&scene, Options { path, ..Default::default() }).unwrap();
        let mut ga = model.integrator(genalpha::IntegratorParams::new(0.8, 0.002)).unwrap();
        let mut s = model.initial_state();
        ga.initialize(&model, &mut s).unwrap();
        ga.step(&mut model, &mut s).unwrap(); // first step: lazy set-up, if any
        let ((), allocations) = alloc_count::count(|| {
            for _ in 0..100 {
                ga.step(&mut model, &mut s).unwrap();
                std::hint::black_box(model.thrust_power(s.t, &s.q, &s.v));
                std::hint::black_box(model.energies(&s.q, &s.v));
            }
        });
        assert_eq!(allocations, 0, "{path:?}: {allocations} allocations in 100 steps");
    }
}
