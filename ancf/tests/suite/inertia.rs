//! Point masses and section centre-of-mass offsets in the constant mass matrix (docs/ancf.md
//! §12): rigid-body mass properties read off the mass matrix against the scene's analytic
//! `BodySpec::reference_inertia`, gravity, the reduced (ODE) mass matrix, and a cantilever with
//! an offset tip mass against beam theory (static deflection and twist, first bending frequency).
use ancf::statics::StaticsParams;
use ancf::{BodySpec, JointSpec, ModeKind, Model, Options, PointMass, RigidPose, Scene, Section, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseMatrix};
use nalgebra::{Matrix3, Matrix6, Rotation3, Vector3};

/// A section whose slope mapping is exact (ρI_xx = ρI_yy + ρI_zz, docs/ancf.md §2), with its
/// centre of mass off the axis.
fn offset_section() -> Section {
    Section {
        mass: 2.3,
        rho_ixx: 5e-3,
        rho_iyy: 2e-3,
        rho_izz: 3e-3,
        ea: 1e6,
        ga_y: 4e5,
        ga_z: 4e5,
        gj: 50.0,
        ei_yy: 80.0,
        ei_zz: 120.0,
        cg_offset: [0.04, -0.025],
    }
}

/// A body off the origin with a rotated frame, an offset section and two point masses with
/// general rotary inertias (I_xx ≠ I_yy + I_zz), one inside an element and one at the tip.
fn loaded_body() -> BodySpec {
    BodySpec {
        name: "loaded".into(),
        start: Vector3::new(0.3, -0.2, 0.5),
        length: 1.2,
        frame: Rotation3::from_scaled_axis(Vector3::new(0.3, -0.4, 0.7)).into_inner(),
        section: offset_section(),
        n_elements: 3,
        point_masses: vec![
            PointMass {
                at: 0.7,
                offset: Vector3::new(0.05, 0.1, -0.04),
                mass: 0.8,
                inertia: Vector3::new(0.01, 0.03, 0.025),
            },
            PointMass {
                at: 1.2,
                offset: Vector3::new(0.0, 0.0, 0.1),
                mass: 0.3,
                inertia: Vector3::new(0.002, 0.004, 0.005),
            },
        ],
        twist: ancf::Twist::none(),
    }
}

fn mass_matrix(model: &Model, path_q: &[f64]) -> DenseMatrix {
    let n = model.n_dof();
    let mut m = DenseMatrix::zeros(n, n);
    let zero = vec![0.0; n];
    model.iteration_matrix_inplace(0.0, path_q, &zero, &zero, 1.0, 0.0, 0.0, &mut m.view());
    m
}

/// The 6×6 rigid-body mass matrix `Vᵀ M V` of the free body, with V the nodal velocities of the
/// rigid motions `v = v₀ + ω × x` (unit v₀ and ω, about the global origin): `[[m I, −m[c]×],
/// [m[c]×, J_O]]`. Equal to the same matrix from `reference_inertia()` (the beam's line mass and
/// section inertias about the centre of mass, plus every point mass) to 1e-12 of its largest
/// entry: the section's slope mapping is exact for ρI_xx = ρI_yy + ρI_zz, the point masses'
/// director mapping for any inertia. Measured: 1.8e-16.
#[test]
fn rigid_body_mass_properties_equal_the_reference_inertia() {
    let err = mass_properties_error(loaded_body());
    assert!(err < 1e-12, "rigid-body mass matrix error {err:e}");
}

/// The same on the loaded body twisted (a table with a breakpoint on a node, −0.2 to 1.2 rad):
/// the centre-of-mass offset and the point masses ride on the linearly interpolated twisted
/// slopes, shorter than unit between the nodes by `Δ²/8` (docs/ancf.md §1), so
/// `reference_inertia()` (the exact twisted sections) is met at second order in the element's
/// twist Δ: measured 8.7e-4, 5.7e-5, 1.4e-5 at 6, 12 and 24 elements; tolerance 2e-4 at 24
/// elements and a ratio below 0.3 per halving.
#[test]
fn twisted_rigid_body_mass_properties_converge_to_the_reference_inertia() {
    let errors: Vec<f64> = [6, 12, 24]
        .into_iter()
        .map(|n_elements| {
            let body = BodySpec {
                n_elements,
                twist: ancf::Twist::table(vec![(0.0, 0.3), (0.6, 1.2), (1.2, -0.2)]),
                ..loaded_body()
            };
            mass_properties_error(body)
        })
        .collect();
    println!("twisted body: 6x6 relative errors {errors:?}");
    assert!(errors[2] < 2e-4 && errors[2] < 0.3 * errors[1] && errors[1] < 0.3 * errors[0], "{errors:?}");
}

/// The largest entry of the difference of the model's rigid-body mass matrix and the one from
/// `reference_inertia()`, relative to the latter's largest entry.
fn mass_properties_error(body: BodySpec) -> f64 {
    let scene = Scene::new(vec![body.clone()], Vec::new(), Vector3::zeros());
    let model = Model::from_scene(&scene, Options::default()).unwrap();
    let m = mass_matrix(&model, model.reference_coordinates());
    let n = model.n_dof();
    let fields: Vec<Vec<f64>> = (0..6)
        .map(|k| {
            let mut unit = Vector3::zeros();
            unit[k % 3] = 1.0;
            let (v0, w) = if k < 3 { (unit, Vector3::zeros()) } else { (Vector3::zeros(), unit) };
            let pose = RigidPose {
                angular_velocity: w,
                velocity: v0 + w.cross(&body.start),
                ..RigidPose::at_rest(body.start)
            };
            model.rigid_full_state(&[pose]).unwrap().1
        })
        .collect();
    let mut g = Matrix6::zeros();
    let mut mv = vec![0.0; n];
    for (b, vb) in fields.iter().enumerate() {
        m.mul_vec_inplace(vb, &mut mv);
        for (a, va) in fields.iter().enumerate() {
            g[(a, b)] = va.iter().zip(&mv).map(|(x, y)| x * y).sum();
        }
    }
    let r = body.reference_inertia();
    let mc = (r.centre * r.mass).cross_matrix();
    let mut expected = Matrix6::zeros();
    expected.fixed_view_mut::<3, 3>(0, 0).copy_from(&(Matrix3::identity() * r.mass));
    expected.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-mc));
    expected.fixed_view_mut::<3, 3>(3, 0).copy_from(&mc);
    expected.fixed_view_mut::<3, 3>(3, 3).copy_from(&r.inertia_about_origin());
    let err = (g - expected).amax() / expected.amax();
    let mass = g[(0, 0)];
    let centre = Vector3::new(g[(5, 1)], g[(3, 2)], g[(4, 0)]) / mass;
    println!(
        "mass {mass:.15} (exact {:.15}), centre {centre:?} (exact {:?}), 6x6 relative error {err:.2e}",
        r.mass, r.centre
    );
    err
}

/// Gravity acts at every mass's centre: for rigid motions of the free body the potential is
/// `−m g·(c' − c)` (the centre of mass moved by the rotation and translation), exactly, since
/// the potential is linear in q and rigid motions are exact. Measured: 5.7e-16 relative.
#[test]
fn gravity_potential_of_rigid_motions_moves_the_centre_of_mass() {
    let body = loaded_body();
    let g = Vector3::new(0.3, -1.1, -9.81);
    let model = Model::from_scene(&Scene::new(vec![body.clone()], Vec::new(), g), Options::default()).unwrap();
    let r = body.reference_inertia();
    let mut worst: f64 = 0.0;
    for (axis, t) in
        [(Vector3::new(0.2, 0.9, -0.4), Vector3::new(0.1, 0.5, -2.0)), (Vector3::new(-2.0, 0.3, 1.0), Vector3::zeros())]
    {
        let rot = Rotation3::from_scaled_axis(axis).into_inner();
        let pose = RigidPose { rotation: rot, translation: body.start + t, ..RigidPose::at_rest(body.start) };
        let (q, v) = model.rigid_full_state(&[pose]).unwrap();
        let moved = body.start + t + rot * (r.centre - body.start);
        let exact = -r.mass * g.dot(&(moved - r.centre));
        let got = model.energies(&q, &v).potential;
        worst = worst.max((got - exact).abs() / exact.abs());
    }
    println!("gravity potential of rigid motions: relative error {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// The inertia terms of the residual and the iteration matrix agree (the `c_m` part equals the
/// residual's derivative in v̇, which is linear: a unit step is exact), and on the ODE path the
/// reduced mass matrix is `Bᵀ M B` of the full one (point masses on elements whose coordinates
/// the flared hinge makes dependent go through the reduction). Pendulum with an offset section
/// and point masses next to the hinge. Measured: 2.1e-15 kg (entries up to ~1 kg) and 7e-18
/// relative.
#[test]
fn point_masses_enter_residual_and_reduced_mass_consistently() {
    let (mut bodies, joints, g) = samples::double_pendulum(1.0, 45.0, 3);
    for b in &mut bodies {
        b.section.cg_offset = [0.01, -0.02];
    }
    bodies[0].point_masses.push(PointMass {
        at: 0.5,
        offset: Vector3::new(-0.02, 0.05, 0.01),
        mass: 0.4,
        inertia: Vector3::new(2e-3, 1e-3, 1.5e-3),
    });
    bodies[1].point_masses.push(PointMass {
        at: 0.05,
        offset: Vector3::new(0.03, -0.04, 0.02),
        mass: 0.7,
        inertia: Vector3::new(1e-3, 1e-3, 1e-3),
    });
    let models: Vec<Model> = [SolvePath::Dae, SolvePath::Ode]
        .into_iter()
        .map(|path| {
            Model::from_scene(&Scene::new(bodies.clone(), joints.clone(), g), Options { path, ..Default::default() })
                .unwrap()
        })
        .collect();
    let mut worst_fd: f64 = 0.0;
    for model in &models {
        let n = model.n_dof();
        let q = model.initial_state().q;
        let m = mass_matrix(model, &q);
        let zero = vec![0.0; n];
        let (mut rp, mut r0) = (vec![0.0; n], vec![0.0; n]);
        model.residual_inplace(0.0, &q, &zero, &zero, &mut r0);
        for j in 0..n {
            let mut a = zero.clone();
            a[j] = 1.0;
            model.residual_inplace(0.0, &q, &zero, &a, &mut rp);
            for i in 0..n {
                worst_fd = worst_fd.max((rp[i] - r0[i] - m.get(i, j)).abs());
            }
        }
    }
    // Bᵀ M B from the full matrix, B column by column from the ODE model's velocity expansion
    let (dae, ode) = (&models[0], &models[1]);
    let m_full = mass_matrix(dae, dae.reference_coordinates());
    let m_red = mass_matrix(ode, &ode.initial_state().q);
    let (nf, nz) = (dae.n_dof(), ode.n_dof());
    let columns: Vec<Vec<f64>> = (0..nz)
        .map(|z| {
            let mut e = vec![0.0; nz];
            e[z] = 1.0;
            let mut out = vec![0.0; nf];
            ode.full_velocities_inplace(&e, &mut out);
            out
        })
        .collect();
    let mut mb = vec![0.0; nf];
    let mut worst_red: f64 = 0.0;
    for (b, cb) in columns.iter().enumerate() {
        m_full.mul_vec_inplace(cb, &mut mb);
        for (a, ca) in columns.iter().enumerate() {
            let x: f64 = ca.iter().zip(&mb).map(|(x, y)| x * y).sum();
            worst_red = worst_red.max((x - m_red.get(a, b)).abs());
        }
    }
    let scale = m_full.as_slice().iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    println!("residual vs matrix (v_dot): {worst_fd:.2e}; reduced mass vs BᵀMB: {:.2e} relative", worst_red / scale);
    assert!(worst_fd <= 1e-14 * scale && worst_red <= 1e-13 * scale, "{worst_fd:e}, {worst_red:e}");
}

/// A clamped cantilever of nearly massless, slender section carrying a tip mass.
fn cantilever_with_tip_mass(tip: PointMass, n: usize) -> (Vec<BodySpec>, Vec<JointSpec>, Section) {
    let section = Section {
        mass: 1e-6,
        rho_ixx: 2e-12,
        rho_iyy: 1e-12,
        rho_izz: 1e-12,
        ea: 1e8,
        ga_y: 1e6,
        ga_z: 1e6,
        gj: 1000.0,
        ei_yy: 3000.0,
        ei_zz: 3000.0,
        cg_offset: [0.0; 2],
    };
    let (mut bodies, joints) = samples::cantilever(section, 1.0, n);
    bodies[0].point_masses.push(tip);
    (bodies, joints, section)
}

/// A 1 kg tip mass 0.1 m to the side (section y) and 0.05 m beyond the tip along the axis (x,
/// on the centreline tangent), under gravity −Z (P = 9.81 N; the beam's own weight is 1e-6 of
/// it): the static tip deflection is `PL³/3EI + PL/GA + P x (L²/2EI + 1/GA)` and the twist
/// `−P y L/GJ`, within 0.5 %; Clapeyron's U = −V/2 within 0.5 % (small load: δ/L ≈ 1.2e-3,
/// twist 1e-3 rad). The axial offset puts the load `P x` on the tip's centreline slope `r_x`,
/// which turns by the bending slope and the shear angle alike (by Maxwell–Betti, the tip
/// force's slope `L²/2EI + 1/GA`); a section-normal attachment would lack the `P x/GA` term,
/// here 4e-4 of δ (docs/ancf.md §12.2). Measured: deflection −1.3e-6, twist −3.1e-6, energy
/// −9.1e-7 relative, the same with 5 to 40 elements.
#[test]
fn tip_mass_at_an_offset_deflects_and_twists_the_cantilever() {
    let tip = PointMass { at: 1.0, offset: Vector3::new(0.05, 0.1, 0.0), mass: 1.0, inertia: Vector3::zeros() };
    let (bodies, joints, sec) = cantilever_with_tip_mass(tip, 10);
    let g = Vector3::new(0.0, 0.0, -9.81);
    let mut model = Model::from_scene(&Scene::new(bodies, joints, g), Options::default()).unwrap();
    let sol = model.solve_static(StaticsParams::default()).unwrap();
    let l: f64 = 1.0;
    let p = 9.81 * tip.mass;
    let deflection = -model.tip_position(&sol.q).z;
    let exact_deflection = p * l.powi(3) / (3.0 * sec.ei_yy)
        + p * l / sec.ga_z
        + p * tip.offset.x * (l * l / (2.0 * sec.ei_yy) + 1.0 / sec.ga_z);
    let (_, frame) = model.section_frame(&sol.q, 0, l).unwrap();
    let twist = frame[(2, 1)].atan2(frame[(1, 1)]); // section y turning toward +Z
    let exact_twist = -p * tip.offset.y * l / sec.gj;
    let e = model.energies(&sol.q, &vec![0.0; sol.q.len()]);
    let (d_err, t_err) = (deflection / exact_deflection - 1.0, twist / exact_twist - 1.0);
    let clapeyron = e.elastic / (-0.5 * e.potential) - 1.0;
    println!(
        "tip deflection {deflection:.6e} m (exact {exact_deflection:.6e}, error {d_err:.2e}); twist {twist:.6e} rad \
         (exact {exact_twist:.6e}, error {t_err:.2e}); U/(-V/2) - 1 = {clapeyron:.2e}"
    );
    assert!(d_err.abs() < 5e-3, "deflection error {d_err:e}");
    assert!(t_err.abs() < 5e-3, "twist error {t_err:e}");
    assert!(clapeyron.abs() < 5e-3, "U = {} vs -V/2 = {}", e.elastic, -0.5 * e.potential);
}

/// Smallest root β of the cantilever-with-tip-mass frequency equation
/// `1 + cos βL cosh βL + (M β / m)(cos βL sinh βL − sin βL cosh βL) = 0`.
fn tip_mass_beta(l: f64, m: f64, tip: f64) -> f64 {
    let f = |b: f64| {
        let x = b * l;
        1.0 + x.cos() * x.cosh() + tip * b / m * (x.cos() * x.sinh() - x.sin() * x.cosh())
    };
    let mut lo = 1e-3 / l;
    while f(lo) * f(lo + 1e-3 / l) > 0.0 {
        lo += 1e-3 / l;
    }
    let mut hi = lo + 1e-3 / l;
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// First bending frequency of a slender cantilever (m = 1 kg/m, EI = 100 N·m², L = 1 m,
/// 16 elements) with a 0.5 kg tip mass (no rotary inertia) from `Model::linear_modes`, against
/// the Euler–Bernoulli frequency equation with a tip mass, within 1 % (without the tip mass the
/// same beam gives 3.516·√(EI/m)/L²). Measured: −1.8e-5 relative.
#[test]
fn first_bending_frequency_with_a_tip_mass() {
    let section = Section {
        mass: 1.0,
        rho_ixx: 2e-6,
        rho_iyy: 1e-6,
        rho_izz: 1e-6,
        ea: 1e8,
        ga_y: 1e7,
        ga_z: 1e7,
        gj: 100.0,
        ei_yy: 100.0,
        ei_zz: 100.0,
        cg_offset: [0.0; 2],
    };
    let tip = PointMass { at: 1.0, offset: Vector3::zeros(), mass: 0.5, inertia: Vector3::zeros() };
    let (mut bodies, joints) = samples::cantilever(section, 1.0, 16);
    bodies[0].point_masses.push(tip);
    let model = Model::from_scene(&Scene::new(bodies, joints, Vector3::zeros()), Options::default()).unwrap();
    let modes = model.linear_modes(model.reference_coordinates()).unwrap();
    let first = &modes[0];
    let beta = tip_mass_beta(1.0, section.mass, tip.mass);
    let exact = beta * beta * (section.ei_yy / section.mass).sqrt();
    let err = first.omega / exact - 1.0;
    println!(
        "first mode {:?} {:.6} rad/s; frequency equation β = {beta:.6}, ω = {exact:.6} rad/s (no tip mass: {:.6}); error {err:.2e}",
        first.kind,
        first.omega,
        3.516_015 * 10.0
    );
    assert!(matches!(first.kind, ModeKind::BendingY | ModeKind::BendingZ), "{:?}", first.kind);
    assert!(err.abs() < 0.01, "frequency error {err:e}");
}
