//! Invariance properties (proptest): Biot–Savart equivariance and additivity, and objectivity of
//! the whole steady/unsteady solution under a rigid motion of wing + free stream.

use approx::assert_relative_eq;
use nalgebra::{Rotation3, Vector3};
use proptest::prelude::*;
use uvlm::samples::{FlaredWing, SpanSpacing, rectangular_wing};
use uvlm::*;

fn v3() -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-2.0..2.0f64)
}

fn rot(axis: [f64; 3], angle: f64) -> Rotation3<f64> {
    let a = Vector3::from(axis);
    if a.norm() < 1e-3 {
        Rotation3::identity()
    } else {
        Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(a), angle)
    }
}

proptest! {
    /// u(Q p + t; Q a + t, Q b + t) = Q u(p; a, b) for every rotation Q and translation t, all cores.
    #[test]
    fn segment_velocity_is_equivariant(p in v3(), a in v3(), b in v3(), axis in v3(), angle in -3.0..3.0f64, t in v3(),
                                        frac in 0.0..0.2f64) {
        prop_assume!((Vector3::from(b) - Vector3::from(a)).norm() > 0.1);
        let q = rot(axis, angle);
        let tr = |x: [f64; 3]| -> [f64; 3] { (q * Vector3::from(x) + Vector3::from(t)).into() };
        for core in [CoreModel::CutOff { radius: 1e-6 }, CoreModel::Scully { fraction: frac }] {
            let u = Vector3::from(segment_velocity(p, a, b, 1.3, core));
            let v = Vector3::from(segment_velocity(tr(p), tr(a), tr(b), 1.3, core));
            let qu = q * u;
            for k in 0..3 {
                assert_relative_eq!(v[k], qu[k], epsilon = 1e-10 * (1.0 + u.norm()));
            }
        }
    }

    /// Splitting a singular segment at an interior point does not change its induction.
    #[test]
    fn segment_velocity_is_additive(p in v3(), a in v3(), b in v3(), s in 0.05..0.95f64) {
        let (va, vb) = (Vector3::from(a), Vector3::from(b));
        prop_assume!((vb - va).norm() > 0.1);
        let d = (vb - va).normalize();
        let r = Vector3::from(p) - va;
        prop_assume!((r - d * r.dot(&d)).norm() > 0.05);
        let m: [f64; 3] = (va + s * (vb - va)).into();
        let core = CoreModel::CutOff { radius: 0.0 };
        let whole = segment_velocity(p, a, b, 0.7, core);
        let (u1, u2) = (segment_velocity(p, a, m, 0.7, core), segment_velocity(p, m, b, 0.7, core));
        for k in 0..3 {
            assert_relative_eq!(whole[k], u1[k] + u2[k], epsilon = 1e-9 * (1.0 + whole[k].abs()));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Rigidly moving the wing and the free stream together leaves the circulations unchanged and
    /// rotates the loads (steady solve, then two unsteady steps) and leaves the hinge moment
    /// unchanged, for the flared folded wing with a deflected part-span flap on the inner wing.
    #[test]
    fn solution_is_objective(axis in v3(), angle in -3.0..3.0f64, t in v3(), fold in -0.5..0.5f64, delta in -0.4..0.4f64) {
        let q = rot(axis, angle);
        let wing = FlaredWing { aoa: 4f64.to_radians(), n_inner: 6, n_outer: 2, inner_length: 3.0, outer_length: 1.0, ..FlaredWing::default() };
        let mut st = wing.stations(fold);
        for s in &mut st[2..=4] {
            s.flap = Some(StationFlap::new(0.3, delta));
        }
        let moved: Vec<SpanStation> = st
            .iter()
            .map(|s| SpanStation { origin: q * s.origin + Vector3::from(t), frame: q.matrix() * s.frame, ..*s })
            .collect();
        let v = Vector3::new(0.0, -25.0, 0.0);
        let run = |stations: &[SpanStation], v_inf: Vector3<f64>| {
            let lat = Lattice::from_stations(wing.spec(), stations).unwrap();
            let mut u = Uvlm::new(lat, UvlmParams::new(1.0, v_inf.into())).unwrap();
            let fs = u.solve_steady().unwrap().total_force();
            let h = u.hinge_moment(2..=4).unwrap();
            u.step(0.01).unwrap();
            let fu = u.step(0.01).unwrap().total_force();
            (u.gamma().to_vec(), Vector3::from(fs), Vector3::from(fu), h)
        };
        let (g0, fs0, fu0, h0) = run(&st, v);
        let (g1, fs1, fu1, h1) = run(&moved, q * v);
        prop_assert!((h0 - h1).abs() <= 1e-8 * (h0.abs() + 1e-3 * fs0.norm()));
        let gmax = g0.iter().fold(0.0f64, |a, g| a.max(g.abs()));
        for (a, b) in g0.iter().zip(&g1) {
            prop_assert!((a - b).abs() <= 1e-9 * gmax);
        }
        for (f0, f1) in [(fs0, fs1), (fu0, fu1)] {
            prop_assert!((q * f0 - f1).norm() <= 1e-8 * f0.norm());
        }
    }
}

/// Γ and the loads scale as U and U² (linearity of the potential flow, quadratic Joukowski load).
#[test]
fn scaling_with_free_stream_speed() {
    let st = rectangular_wing(0.0, 3.0, 1.0, 6, SpanSpacing::Uniform);
    let lat = Lattice::from_stations(LatticeSpec::new(3), &st).unwrap();
    let a = 5f64.to_radians();
    let solve = |u_inf: f64| {
        let mut u = Uvlm::new(lat.clone(), UvlmParams::new(1.0, [u_inf * a.cos(), 0.0, u_inf * a.sin()])).unwrap();
        let f = u.solve_steady().unwrap().total_force();
        (u.gamma()[0], f[2])
    };
    let (g1, f1) = solve(1.0);
    let (g3, f3) = solve(3.0);
    assert_relative_eq!(g3, 3.0 * g1, max_relative = 1e-12);
    assert_relative_eq!(f3, 9.0 * f1, max_relative = 1e-12);
}
