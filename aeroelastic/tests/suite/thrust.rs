//! Thrust, a follower force (docs/ancf.md §14, docs/gebf.md §16), in both formulations: the
//! small-load tip deflection of a cantilever, the follower condition under a large load, the
//! two formulations' agreement there, and the energy balance with the thrusts' work.

use aeroelastic::factory::{BuildModel, ForModel, dispatch};
use aeroelastic::problem::Formulation;
use aeroelastic::run::{NoObserver, Row, RunSettings, simulate};
use genalpha::ConstrainedSystem;
use nalgebra::{Matrix3, Vector3};
use scene::{ForceElement, JointSpec, Scene, Schedule, samples};

/// EI of [`samples::paper_section`] at c = 1, N·m².
const EI: f64 = 9.33;

/// A 1 m cantilever along +X of the paper's section, no gravity, with a thrust `f` N at its
/// tip along the section's z (perpendicular to the axis).
fn cantilever(f: f64, n_el: usize) -> Scene {
    let (bodies, joints) = samples::cantilever(samples::paper_section(1.0), 1.0, n_el);
    let thrust = ForceElement::Thrust { body: 0, at: 1.0, direction: Vector3::z(), magnitude: Schedule::constant(f) };
    Scene { forces: vec![thrust], ..Scene::new(bodies, joints, Vector3::zeros()) }
}

/// The static tip of `scene` under ANCF with the force on the tip and the section's axis
/// direction `r_y × r_z` and centreline tangent `r_x` there (global).
fn ancf_tip(scene: &Scene) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let mut model = ancf::Model::from_scene(scene, ancf::Options::default()).unwrap();
    let params = ancf::statics::StaticsParams { n_load_steps: 20, ..Default::default() };
    let q = model.solve_static(params).unwrap().q;
    let bare = Scene { forces: Vec::new(), ..scene.clone() };
    let without = ancf::Model::from_scene(&bare, ancf::Options::default()).unwrap();
    let n = model.n_dof();
    let (mut r1, mut r0, z) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    model.residual_inplace(0.0, &q, &z, &z, &mut r1);
    without.residual_inplace(0.0, &q, &z, &z, &mut r0);
    let tip = n - 12; // the last node: r, r_x, r_y, r_z
    let v = |k: usize| Vector3::new(q[tip + 3 * k], q[tip + 3 * k + 1], q[tip + 3 * k + 2]);
    // −(r1 − r0) on the tip node's position rows is the force (its Hermite weight is 1 at s = L)
    let force = -Vector3::new(r1[tip] - r0[tip], r1[tip + 1] - r0[tip + 1], r1[tip + 2] - r0[tip + 2]);
    (v(0), force, v(2).cross(&v(3)), v(1))
}

/// The same under GEBF: the tip, the force (from the residual's tip-node rows, `F = C^{GA} F_A`),
/// the tip section's x axis and the centreline tangent of the quadratic interpolation.
fn gebf_tip(scene: &Scene) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let mut model = gebf::Model::from_scene(scene, gebf::Options::default()).unwrap();
    let q0 = model.reference_coordinates();
    let opts = gebf::StaticOptions { n_load_steps: 20, ..Default::default() };
    let q = model.solve_static(&q0, &opts).unwrap().q;
    let bare = Scene { forces: Vec::new(), ..scene.clone() };
    let without = gebf::Model::from_scene(&bare, gebf::Options::default()).unwrap();
    let n = model.n_dof();
    let (mut r1, mut r0, z) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    model.residual_inplace(0.0, &q, &z, &z, &mut r1);
    without.residual_inplace(0.0, &q, &z, &z, &mut r0);
    let last = model.n_nodes(0) - 1;
    let d = 6 * (last - 1); // the tip node's R rows (node 0 is not an unknown)
    let fa = -Vector3::new(r1[d] - r0[d], r1[d + 1] - r0[d + 1], r1[d + 2] - r0[d + 2]);
    let (_, c_ga) = model.body_frame(&q, 0);
    let p = |k: usize| model.node_position(&q, 0, k).unwrap();
    let le = 1.0 / ((last / 2) as f64);
    let tangent = (p(last - 2) - p(last - 1) * 4.0 + p(last) * 3.0) / le;
    let frame: Matrix3<f64> = model.node_frame(&q, 0, last).unwrap();
    (p(last), c_ga * fa, frame.column(0).into(), tangent)
}

fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a.dot(b) / (a.norm() * b.norm())).clamp(-1.0, 1.0).acos().to_degrees()
}

/// A small follower load, `F L²/EI = 1e-3`: the tip deflects by `F L³/(3 EI)` in both
/// formulations (the follower's rotation is a second-order effect there). Tolerance 1 %; the
/// shear flexibility adds `3 EI/(GA L²) = 2.7e-4`. Measured: +2.70e-4 in both
/// (ANCF 8 elements, GEBF 4), the shear.
#[test]
fn a_small_tip_thrust_deflects_the_cantilever_by_fl3_over_3ei() {
    let f = 1e-3 * EI;
    let expected = f / (3.0 * EI);
    for (name, tip) in [("ANCF", ancf_tip(&cantilever(f, 8)).0), ("GEBF", gebf_tip(&cantilever(f, 4)).0)] {
        let err = tip.z / expected - 1.0;
        println!("{name}: tip deflection {:.6e} m, F L³/(3 EI) = {expected:.6e} m, error {err:+.2e}", tip.z);
        assert!(err.abs() < 0.01, "{name}: {err:e}");
    }
}

/// The classic follower-load check under a large load, `F L²/EI = 2`: the force stays
/// perpendicular to the deformed tip section's axis (90° to 1e-8°, the follower condition),
/// where a dead load would not; the angle to the centreline's tangent differs from 90° by the
/// tip's shear angle (printed). The two formulations' tips agree to 0.5 % of the tip
/// displacement. Measured: both 90° to rounding (printed 90.000000000000°); the centreline
/// 89.9897° (ANCF: the shear angle `F/GA`, 1.8e-4 rad) and 89.84° (GEBF: the quadratic
/// interpolation's end slope on 8 elements); tips (0.76679, 0, 0.57440) and (0.76724, 0,
/// 0.57396) m, 1.0e-3 of the tip displacement apart (ANCF 16 elements, GEBF 8).
#[test]
fn a_large_tip_thrust_follows_the_tip_and_both_formulations_agree() {
    let f = 2.0 * EI;
    let (a, g) = (ancf_tip(&cantilever(f, 16)), gebf_tip(&cantilever(f, 8)));
    for (name, (tip, force, axis, tangent)) in [("ANCF", a), ("GEBF", g)] {
        let (to_axis, to_tangent) = (angle_deg(&force, &axis), angle_deg(&force, &tangent));
        println!(
            "{name}: tip {tip:.6?}, |F| {:.6} N, angle to the section's axis {to_axis:.12}°, to the centreline {to_tangent:.6}°",
            force.norm()
        );
        assert!((to_axis - 90.0).abs() < 1e-8, "{name}: {to_axis}°");
        assert!((force.norm() / f - 1.0).abs() < 1e-12, "{name}: |F| = {}", force.norm());
        assert!(tip.x < 0.9, "{name}: the load must be large: tip {tip}");
    }
    let displacement = (g.0 - Vector3::x()).norm();
    let diff = (a.0 - g.0).norm() / displacement;
    println!("ANCF − GEBF tip: {:.3e} m, {diff:.2e} of the tip displacement {displacement:.4} m", (a.0 - g.0).norm());
    assert!(diff < 5e-3, "tips differ by {diff:e} of the displacement");
}

/// A time march of `scene` through the run loop, its rows.
struct March<'a>(&'a Scene, genalpha::IntegratorParams, f64);

impl ForModel for March<'_> {
    type Output = Vec<Row>;
    fn run<M: BuildModel>(self) -> Vec<Row> {
        let mut model = M::from_scene(self.0).unwrap();
        let settings = RunSettings {
            params: self.1,
            t_end: self.2,
            output_dt: None,
            fold_joint: None,
            roll_joint: None,
            loads: None,
            polars: None,
        };
        let out = simulate(M::FORMULATION, &mut model, &settings, &mut NoObserver);
        assert!(out.error.is_none(), "{:?}", out.error);
        out.rows
    }
}

/// A pinned beam (the paper's section at c = 1, 1 m, ground hinge about +Y at its start, no
/// gravity) pushed at its tip by a thrust perpendicular to its axis that ramps from 0 to 2 N in
/// 0.2 s and then holds: it spins up about the hinge, bending, while the thrust's work goes into
/// its kinetic and elastic energy. With `thrust_work` (the trapezoidal integral of
/// `Structure::external_power`) the balance `E − E(0) − W_thrust` closes to the integrator's
/// accuracy: 1 s at dt = 1 ms and 0.5 ms, ρ∞ = 1. Bound 1e-3 of the thrust's work (4.5 J;
/// without it the balance is off by all of it); measured: ANCF 9.7e-6 and 2.4e-6, GEBF 3.4e-7
/// and 8.4e-8, second order (halving dt divides the error by 4.0).
#[test]
fn thrust_work_closes_the_energy_balance() {
    let (bodies, _) = samples::cantilever(samples::paper_section(1.0), 1.0, 6);
    let joints = vec![JointSpec::GroundHinge { body: 0, axis: Vector3::y() }];
    let thrust = ForceElement::Thrust {
        body: 0,
        at: 1.0,
        direction: Vector3::z(),
        magnitude: Schedule { points: vec![(0.0, 0.0), (0.2, 2.0)] },
    };
    let scene = Scene { forces: vec![thrust], ..Scene::new(bodies, joints, Vector3::zeros()) };
    for f in Formulation::ALL {
        let mut errors = Vec::new();
        for dt in [1e-3, 5e-4] {
            let rows = dispatch(f, March(&scene, genalpha::IntegratorParams::new(1.0, dt), 1.0));
            let e0 = rows[0].total;
            let w_end = rows.last().unwrap().thrust_work;
            let err =
                rows.iter().map(|r| (r.total + r.dissipated - e0 - r.thrust_work).abs()).fold(0.0, f64::max) / w_end;
            let without = rows.iter().map(|r| (r.total - e0).abs()).fold(0.0, f64::max) / w_end;
            println!(
                "{f} dt {dt:e}: thrust work {w_end:.6} J, max |E + W_d − E(0) − W_T| = {err:.2e} of it (without W_T: {without:.2})"
            );
            assert!(rows.iter().all(|r| r.thrust_work.is_finite() && r.dissipated.is_finite()));
            assert!(w_end > 0.1, "{f}: the thrust must do work: {w_end} J");
            assert!(err < 1e-3, "{f} dt {dt}: balance error {err:e}");
            errors.push(err);
        }
        println!("{f}: error ratio at dt/2: {:.2}", errors[0] / errors[1]);
        assert!(errors[0] / errors[1] > 3.0, "{f}: the balance error must fall as dt²");
    }
}
