//! Point masses (`BodySpec::point_masses`) and the section's centre-of-mass offset
//! (`Section::cg_offset`), docs/gebf.md §14:
//!
//! * the rigid-body mass, centre of mass and inertia tensor read off the model's kinetic energy
//!   under rigid velocity fields equal `BodySpec::reference_inertia()` (1e-12 relative), in the
//!   reference configuration and rigidly rotated;
//! * a clamped cantilever with an offset tip mass under gravity, and one whose sections' centre
//!   of mass is off the axis: static tip deflection (bending and shear) and twist against the
//!   linear analytic values (0.5 %);
//! * the first bending frequency of a cantilever with a tip mass, on the tip and on a rigid arm
//!   beyond it, against the Euler–Bernoulli frequency equation (1 %);
//! * the paper's pendulum carrying offset masses conserves E = T + U + V (gravity's potential
//!   including the offsets) to the integrator's energy error.

use gebf::{BodySpec, Model, Options, PointMass, RigidPose, Scene, Section, StaticOptions, samples, simulate};
use genalpha::{Form, IntegratorParams};
use nalgebra::{Matrix3, Matrix6, Rotation3, Vector3, Vector6};

fn point_mass(at: f64, offset: [f64; 3], mass: f64, inertia: [f64; 3]) -> PointMass {
    PointMass { at, offset: Vector3::from(offset), mass, inertia: Vector3::from(inertia) }
}

/// A body with everything: a rotated frame, a section centre of mass off the axis, point masses
/// at the start, inside an element, on a node and at the end, with offsets and inertias.
fn loaded_body() -> BodySpec {
    let mut section = Section::centred(1.3, 0.05, 0.02, 0.03, 1e5, 1e5, 1e5, 1e3, 1e3, 1e3);
    section.cg_offset = [0.04, -0.07];
    BodySpec {
        name: "loaded".into(),
        start: Vector3::new(0.3, -0.2, 0.5),
        length: 1.4,
        frame: Rotation3::from_scaled_axis(Vector3::new(0.3, -0.5, 0.8)).into_inner(),
        section,
        n_elements: 3,
        point_masses: vec![
            point_mass(0.0, [0.01, 0.1, -0.05], 0.4, [0.01, 0.02, 0.025]),
            point_mass(0.31, [0.0, -0.2, 0.12], 0.9, [0.03, 0.02, 0.04]),
            point_mass(1.4 / 3.0, [0.05, 0.0, 0.0], 0.2, [0.0, 0.0, 0.0]),
            point_mass(1.4, [-0.02, 0.15, 0.3], 1.5, [0.1, 0.06, 0.07]),
        ],
        twist: gebf::Twist::none(),
    }
}

/// `½ [v; ω]ᵀ M₆ [v; ω]` with `M₆ = [[m I, −m c̃], [m c̃, I_O]]` about the start point (global
/// components, c = centre − start): M₆ read off the model's kinetic energy by polarisation over
/// the 6 unit velocity fields and their 15 pairs.
fn rigid_mass_matrix(m: &Model, rotation: Matrix3<f64>, start: Vector3<f64>) -> Matrix6<f64> {
    let energy = |x: &Vector6<f64>| {
        let pose = RigidPose {
            rotation,
            translation: start,
            velocity: Vector3::new(x[0], x[1], x[2]),
            angular_velocity: Vector3::new(x[3], x[4], x[5]),
        };
        let s = m.rigid_state(&[pose]).unwrap();
        m.energies(&s.q, &s.v).kinetic
    };
    let mut m6 = Matrix6::zeros();
    for i in 0..6 {
        m6[(i, i)] = 2.0 * energy(&Vector6::ith(i, 1.0));
    }
    for i in 0..6 {
        for j in i + 1..6 {
            let e = energy(&(Vector6::ith(i, 1.0) + Vector6::ith(j, 1.0)));
            m6[(i, j)] = e - 0.5 * (m6[(i, i)] + m6[(j, j)]);
            m6[(j, i)] = m6[(i, j)];
        }
    }
    m6
}

/// Mass, centre (global) and inertia about the centre from `M₆`.
fn rigid_body_from(m6: &Matrix6<f64>, start: Vector3<f64>) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let mass = m6[(0, 0)];
    let mc: Matrix3<f64> = m6.fixed_view::<3, 3>(3, 0).into();
    let c = Vector3::new(mc[(2, 1)] - mc[(1, 2)], mc[(0, 2)] - mc[(2, 0)], mc[(1, 0)] - mc[(0, 1)]) * (0.5 / mass);
    let i_o: Matrix3<f64> = m6.fixed_view::<3, 3>(3, 3).into();
    let i_c = i_o - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * mass;
    (mass, start + c, i_c)
}

/// The kinetic energy of a rigidly moving body is exact (the 3-point rule integrates the
/// line's quadratic velocity field exactly; sections and point masses add constants), so the
/// model's mass, centre and inertia tensor equal the analytic `reference_inertia()` to
/// round-off: tolerance 1e-12 relative (measured ~1e-15). The same after a rigid rotation of
/// the body (the offsets turn with the sections).
#[test]
fn rigid_body_inertia_from_kinetic_energy_matches_the_reference() {
    let err = inertia_error(loaded_body());
    assert!(err < 1e-12, "{err:e}");
}

/// The same on the loaded body twisted (a table with a breakpoint on a node, −0.2 to 1.2 rad):
/// the rotated sections' inertia and centre-of-mass offset are integrated by the 3-point rule,
/// exact for the twisted sections up to its error on `cos 2θ` over an element (`O(Δ⁶)`):
/// measured 5.9e-10, 9.1e-12, 1.4e-13 at 6, 12 and 24 elements; tolerance 1e-10 from 12
/// elements on. (A breakpoint inside an element is interpolated quadratically, an `O(h²)` error
/// there: 7.0e-5, 8.7e-6, 6.5e-6 with the breakpoint at 0.5 m.)
#[test]
fn twisted_rigid_body_inertia_converges_to_the_reference() {
    let errors: Vec<f64> = [6, 12, 24]
        .into_iter()
        .map(|n_elements| {
            let body = BodySpec {
                n_elements,
                twist: gebf::Twist::table(vec![(0.0, 0.3), (0.7, 1.2), (1.4, -0.2)]),
                ..loaded_body()
            };
            inertia_error(body)
        })
        .collect();
    println!("twisted body: worst relative errors {errors:?}");
    assert!(errors[1] < 1e-10 && errors[2] < 1e-10, "{errors:?}");
}

/// The worst relative error of the model's mass, centre and inertia tensor against
/// `reference_inertia()`, in the reference and rigidly rotated.
fn inertia_error(body: BodySpec) -> f64 {
    let mut worst: f64 = 0.0;
    let reference = body.reference_inertia();
    let m = Model::from_scene(&Scene::new(vec![body.clone()], vec![], Vector3::zeros()), Options::default()).unwrap();
    let rot = Rotation3::from_scaled_axis(Vector3::new(-0.7, 0.4, 1.1)).into_inner();
    let moved = Vector3::new(2.0, -1.0, 0.5);
    for (rotation, start) in [(Matrix3::identity(), body.start), (rot, moved)] {
        let (mass, centre, inertia) = rigid_body_from(&rigid_mass_matrix(&m, rotation, start), start);
        let expected_centre = start + rotation * (reference.centre - body.start);
        let expected_inertia = rotation * reference.inertia * rotation.transpose();
        let e_mass = (mass / reference.mass - 1.0).abs();
        let e_centre = (centre - expected_centre).norm() / (expected_centre - start).norm();
        let e_inertia = (inertia - expected_inertia).amax() / expected_inertia.amax();
        println!(
            "mass {mass:.15} (reference {:.15}): rel err {e_mass:.1e}; centre rel err {e_centre:.1e}; \
             inertia rel err {e_inertia:.1e}",
            reference.mass
        );
        worst = worst.max(e_mass).max(e_centre).max(e_inertia);
    }
    worst
}

/// A 1 m cantilever (10 elements) clamped at the origin along +X with a 1 kg tip mass at
/// e = 0.1 m along the section's y axis, gravity 9.81 m/s² along −Z (P = 9.81 N), and a light
/// beam (w = 1e-3·g N/m). Linear analytic tip values (the load is small: δ/L ≈ 3e-4, so the
/// geometric nonlinearity is ~1e-7 relative):
/// `δ = PL³/3EI + PL/GA + wL⁴/8EI + wL²/2GA` (bending about y, shear along z) and
/// `φ = −P e L/GJ` (the weight at the offset twists the beam about −x). Tolerance 0.5 %.
#[test]
fn offset_tip_mass_deflects_and_twists_the_cantilever() {
    let (l, mass, e, g) = (1.0, 1.0, 0.1, 9.81);
    let (ei, ga, gj) = (1e4, 1e6, 1e3);
    let section = Section::centred(1e-3, 2e-9, 1e-9, 1e-9, 1e8, ga, ga, gj, ei, ei);
    let (mut bodies, joints) = samples::cantilever(section, l, 10);
    bodies[0].point_masses.push(point_mass(l, [0.0, e, 0.0], mass, [1e-3, 1e-3, 1e-3]));
    let mut m = Model::from_scene(&Scene::new(bodies, joints, Vector3::new(0.0, 0.0, -g)), Options::default()).unwrap();
    let sol = m.solve_static(&m.reference_coordinates(), &StaticOptions::default()).unwrap();
    let tip = m.n_nodes(0) - 1;
    let p = m.node_position(&sol.q, 0, tip).unwrap();
    let frame = m.node_frame(&sol.q, 0, tip).unwrap();
    let twist = frame[(2, 1)].atan2(frame[(1, 1)]);
    let (pw, w) = (mass * g, section.mass * g);
    let deflection = pw * l.powi(3) / (3.0 * ei) + pw * l / ga + w * l.powi(4) / (8.0 * ei) + w * l * l / (2.0 * ga);
    let expected_twist = -pw * e * l / gj;
    let (e_d, e_t) = (-p.z / deflection - 1.0, twist / expected_twist - 1.0);
    println!(
        "tip deflection {:.6e} m (analytic {deflection:.6e}, of which shear {:.2e}): rel err {e_d:.2e}; \
         twist {twist:.6e} rad (analytic {expected_twist:.6e}): rel err {e_t:.2e}; {} Newton iterations",
        -p.z,
        pw * l / ga,
        sol.n_iterations
    );
    assert!(e_d.abs() < 5e-3 && e_t.abs() < 5e-3);
}

/// The same cantilever carrying its own weight (m = 1 kg/m) with the section's centre of mass
/// 5 cm off the axis along y: the distributed torque `−m g e` twists the tip by
/// `φ = −m g e L²/2GJ`, and the tip deflects by `wL⁴/8EI + wL²/2GA`. Tolerance 0.5 %.
#[test]
fn section_cg_offset_twists_the_cantilever_under_gravity() {
    let (l, mu, e, g) = (1.0, 1.0, 0.05, 9.81);
    let (ei, ga, gj) = (1e4, 1e6, 100.0);
    let mut section = Section::centred(mu, 2e-4, 1e-4, 1e-4, 1e8, ga, ga, gj, ei, ei);
    section.cg_offset = [e, 0.0];
    let (bodies, joints) = samples::cantilever(section, l, 10);
    let mut m = Model::from_scene(&Scene::new(bodies, joints, Vector3::new(0.0, 0.0, -g)), Options::default()).unwrap();
    let sol = m.solve_static(&m.reference_coordinates(), &StaticOptions::default()).unwrap();
    let tip = m.n_nodes(0) - 1;
    let p = m.node_position(&sol.q, 0, tip).unwrap();
    let frame = m.node_frame(&sol.q, 0, tip).unwrap();
    let twist = frame[(2, 1)].atan2(frame[(1, 1)]);
    let w = mu * g;
    let deflection = w * l.powi(4) / (8.0 * ei) + w * l * l / (2.0 * ga);
    let expected_twist = -w * e * l * l / (2.0 * gj);
    let (e_d, e_t) = (-p.z / deflection - 1.0, twist / expected_twist - 1.0);
    println!(
        "tip deflection {:.6e} m (analytic {deflection:.6e}): rel err {e_d:.2e}; twist {twist:.6e} rad \
         (analytic {expected_twist:.6e}): rel err {e_t:.2e}",
        -p.z
    );
    assert!(e_d.abs() < 5e-3 && e_t.abs() < 5e-3);
}

/// Smallest root β of `1 + cos βL cosh βL + (Mβ/m)(cos βL sinh βL − sin βL cosh βL) = 0`
/// (Euler–Bernoulli cantilever with a tip mass M, no rotary inertia), by bisection below the
/// bare cantilever's 1.8751/L.
fn tip_mass_beta(l: f64, m: f64, tip: f64) -> f64 {
    bisect(1e-3 / l, 1.8752 / l, |b| {
        let x = b * l;
        1.0 + x.cos() * x.cosh() + tip * b / m * (x.cos() * x.sinh() - x.sin() * x.cosh())
    })
}

/// The same with the mass on a rigid massless arm of length `arm` beyond the tip, along the
/// beam: with `w = A (cos − cosh) + B (sin − sinh)` (clamped at 0), `u = w(L) + arm·w'(L)` the
/// mass's displacement and `λ = M ω²/EI = M β⁴/m`, stationarity of `∫ (T − U) dt` gives at the
/// tip `w'' − λ·arm·u = 0` (moment) and `w''' + λ u = 0` (shear); β is the smallest root of
/// their 2×2 determinant. With `arm = 0` it is the equation above (checked in the test).
fn tip_mass_on_arm_beta(l: f64, m: f64, tip: f64, arm: f64) -> f64 {
    bisect(1e-3 / l, 1.8752 / l, |b| {
        let x = b * l;
        let (c, s, ch, sh) = (x.cos(), x.sin(), x.cosh(), x.sinh());
        let lambda = tip * b.powi(4) / m;
        // [A, B] coefficients of w, w', w'', w''' at L
        let w = [c - ch, s - sh];
        let w1 = [b * (-s - sh), b * (c - ch)];
        let w2 = [b * b * (-c - ch), b * b * (-s - sh)];
        let w3 = [b.powi(3) * (s - sh), b.powi(3) * (-c - ch)];
        let u = [w[0] + arm * w1[0], w[1] + arm * w1[1]];
        let moment = [w2[0] - lambda * arm * u[0], w2[1] - lambda * arm * u[1]];
        let shear = [w3[0] + lambda * u[0], w3[1] + lambda * u[1]];
        (moment[0] * shear[1] - moment[1] * shear[0]) / b.powi(5)
    })
}

fn bisect(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    assert!(f(lo) * f(hi) < 0.0, "no sign change");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// A slender cantilever (L = 1 m, m = 1 kg/m, EI = 100 N·m² for flap, 400 in plane, shear and
/// rotary inertia negligible: GA = 1e9 N, ρI = 1e-6 kg·m) with a 0.5 kg tip mass: the first
/// flap frequency from the model's modal analysis (10 elements) against the Euler–Bernoulli
/// frequency equation; tolerance 1 %. A second run puts the mass 0.2 m beyond the tip along
/// the section's x (a rigid arm: the offset's lever on the tip rotation), against the same
/// equation with the arm.
#[test]
fn cantilever_with_tip_mass_first_bending_frequency() {
    let (l, mu, ei, tip, arm) = (1.0, 1.0, 100.0, 0.5, 0.2);
    assert!((tip_mass_on_arm_beta(l, mu, tip, 0.0) / tip_mass_beta(l, mu, tip) - 1.0).abs() < 1e-12);
    let section = Section::centred(mu, 2e-6, 1e-6, 1e-6, 1e9, 1e9, 1e9, 10.0, ei, 4.0 * ei);
    for (offset, beta) in [(0.0, tip_mass_beta(l, mu, tip)), (arm, tip_mass_on_arm_beta(l, mu, tip, arm))] {
        let (mut bodies, joints) = samples::cantilever(section, l, 10);
        bodies[0].point_masses.push(point_mass(l, [offset, 0.0, 0.0], tip, [0.0, 0.0, 0.0]));
        let m = Model::from_scene(&Scene::new(bodies, joints, Vector3::zeros()), Options::default()).unwrap();
        let first = m.linear_modes(&m.reference_coordinates()).unwrap().omega[0];
        let analytic = beta * beta * (ei / mu).sqrt();
        let err = first / analytic - 1.0;
        println!(
            "arm {offset} m: first bending frequency {first:.6} rad/s, analytic {analytic:.6} rad/s \
             (βL = {:.6}): rel err {err:.2e}",
            beta * l
        );
        assert!(err.abs() < 1e-2);
    }
}

/// The paper's c = 1, β = 45° pendulum with a 0.2 kg tip mass 5 cm off the second body's axis
/// (with inertia), a 0.1 kg mass inside the first body, and the second body's section centre of
/// mass 1 cm off its axis: the total energy (the gravitational potential including the offsets)
/// is conserved to the integrator's energy error, measured as in tests/suite/energy.rs (Chung–Hulbert
/// form, ρ∞ = 1, dt = 0.002, 2 s; relative to the peak kinetic energy). Bound: 1e-3, the
/// criterion of tests/suite/energy.rs.
#[test]
fn pendulum_with_offset_masses_conserves_energy() {
    let (mut b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    b[0].point_masses.push(point_mass(0.27, [0.0, 0.03, -0.02], 0.1, [1e-4, 1e-4, 1e-4]));
    b[1].point_masses.push(point_mass(0.5, [0.0, 0.05, 0.0], 0.2, [2e-4, 1e-4, 1.5e-4]));
    b[1].section.cg_offset = [0.01, 0.0];
    let mut m = Model::from_scene(&Scene::new(b, j, g), Options::default()).unwrap();
    let mut p = IntegratorParams::new(1.0, 0.002);
    p.form = Form::ChungHulbert;
    let mut e = Vec::new();
    simulate::run(&mut m, p, 2.0, |m, s, _| e.push(m.energies(&s.q, &s.v))).unwrap();
    let e0 = e[0].total();
    let peak = e.iter().map(|x| x.kinetic).fold(0.0, f64::max);
    let drift = e.iter().map(|x| (x.total() - e0).abs()).fold(0.0, f64::max) / peak;
    let v_min = e.iter().map(|x| x.potential).fold(f64::MAX, f64::min);
    println!("drift {drift:.3e} of the peak kinetic energy {peak:.3} J (lowest potential {v_min:.3} J)");
    assert!(drift < 1e-3, "drift {drift:.3e}");
}

/// A point mass at the clamped start of a cantilever adds nothing to its motion but its
/// reference inertia (it rides on the clamped node 0): the modes are those without it.
#[test]
fn a_point_mass_on_the_clamp_changes_no_mode() {
    let section = Section::centred(1.0, 2e-4, 1e-4, 1e-4, 1e7, 1e6, 1e6, 50.0, 100.0, 100.0);
    let (mut bodies, joints) = samples::cantilever(section, 1.0, 4);
    let plain =
        Model::from_scene(&Scene::new(bodies.clone(), joints.clone(), Vector3::zeros()), Options::default()).unwrap();
    bodies[0].point_masses.push(point_mass(0.0, [0.0, 0.0, 0.0], 3.0, [0.1, 0.1, 0.1]));
    let clamped = Model::from_scene(&Scene::new(bodies, joints, Vector3::zeros()), Options::default()).unwrap();
    let (a, b) = (
        plain.linear_modes(&plain.reference_coordinates()).unwrap().omega,
        clamped.linear_modes(&clamped.reference_coordinates()).unwrap().omega,
    );
    for (x, y) in a.iter().zip(&b).take(6) {
        assert!((x / y - 1.0).abs() < 1e-9, "{x} vs {y}");
    }
}
