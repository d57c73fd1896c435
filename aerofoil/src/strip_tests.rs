//! Tests of the strip correction (a separate file to keep `strip.rs` to the method).

use super::*;
use crate::polar::{Polar, Table};
use approx::assert_relative_eq;
use proptest::prelude::*;

/// A stalling section at two Reynolds numbers: slope `k`, peak at 10°, then a drop;
/// `cd = cd0 + 0.8 α²`; `cm = −0.03 − 0.05 α` about the quarter chord.
fn stall_polar() -> Polar {
    let table = |re: f64, k: f64, cd0: f64| {
        let alpha: Vec<f64> = (-40..=40).map(|i| (0.5 * i as f64).to_radians()).collect();
        let stall = 10f64.to_radians();
        let cl = alpha
            .iter()
            .map(|&a: &f64| if a.abs() <= stall { k * a } else { a.signum() * k * (stall - 0.5 * (a.abs() - stall)) })
            .collect();
        Table {
            re: Some(re),
            cd: alpha.iter().map(|a| cd0 + 0.8 * a * a).collect(),
            cm: alpha.iter().map(|a| -0.03 - 0.05 * a).collect(),
            cl,
            alpha,
        }
    };
    Polar::new(vec![table(1e5, 5.2, 0.02), table(3e5, 5.9, 0.012)]).unwrap()
}

/// A strip at geometric incidence `alpha` with a spanwise flow component `spanwise`, V = 20 m/s.
fn strip(alpha: f64, spanwise: f64) -> Strip {
    Strip {
        flow: 20.0 * Vector3::new(spanwise, -alpha.cos(), alpha.sin()),
        chord: 0.078,
        width: 0.04,
        rho: 1.225,
        kinematic_viscosity: 1.5e-5,
        fixed_reynolds: None,
        quarter_chord: Vector3::new(0.003, 0.0195 - 0.02, 0.001),
    }
}

/// Inviscid loads of a strip whose lattice lift is `cl_inv` (on `l̂`), with an induced drag and a
/// side force, acting at the quarter chord plus an extra moment `extra`.
fn inviscid(s: &Strip, cl_inv: f64, extra: Vector3<f64>) -> StripLoads {
    let u = Vector3::new(0.0, s.flow.y, s.flow.z);
    let (d, v) = (u.normalize(), u.norm());
    let l = d.cross(&Vector3::x());
    let q_area = 0.5 * s.rho * v * v * s.chord * s.width;
    let force = q_area * (cl_inv * l + 0.004 * d + 0.01 * Vector3::x());
    StripLoads { force, moment: s.quarter_chord.cross(&force) + extra }
}

#[test]
fn thin_plate_polar_returns_the_lattice_loads() {
    let polar = Polar::linear(2.0 * PI, 0.0, -0.5, 0.5).unwrap();
    for (alpha, spanwise, cl) in [(0.05, 0.0, 0.4), (0.2, 0.3, -0.9), (-0.1, -0.15, 1.7)] {
        let s = strip(alpha, spanwise);
        let inv = inviscid(&s, cl, Vector3::new(0.02, -0.03, 0.005));
        let c = correct_strip(&polar, &LatticeSection::THIN_PLATE, &s, &inv).unwrap();
        for k in 0..3 {
            assert_relative_eq!(c.loads.force[k], inv.force[k], epsilon = 1e-12 * inv.force.norm());
            assert_relative_eq!(c.loads.moment[k], inv.moment[k], epsilon = 1e-12 * inv.moment.norm());
        }
        assert_relative_eq!(c.alpha, cl / (2.0 * PI), max_relative = 1e-14);
        assert_eq!(c.profile_drag(), 0.0);
    }
}

#[test]
fn a_lattice_with_its_own_slope_and_offset_is_reproduced_by_its_line() {
    // A lattice section of slope 5.9 and zero-lift incidence −2°, and the polar of that line.
    let lat = LatticeSection { lift_slope: 5.9, zero_lift_alpha: -2f64.to_radians() };
    let polar = Polar::linear(5.9, -2f64.to_radians(), -0.4, 0.4).unwrap();
    let s = strip(0.1, 0.1);
    let inv = inviscid(&s, 0.75, Vector3::zeros());
    let c = correct_strip(&polar, &lat, &s, &inv).unwrap();
    assert_relative_eq!((c.loads.force - inv.force).norm(), 0.0, epsilon = 1e-12 * inv.force.norm());
    assert_relative_eq!(c.alpha, 0.75 / 5.9 - 2f64.to_radians(), max_relative = 1e-14);
}

#[test]
fn drag_acts_along_the_local_flow() {
    let polar = Polar::new(vec![Table {
        re: None,
        alpha: vec![-0.5, 0.5],
        cl: vec![-PI, PI],
        cd: vec![0.013, 0.013],
        cm: vec![0.0, 0.0],
    }])
    .unwrap();
    for spanwise in [0.0, 0.4] {
        let s = strip(0.08, spanwise);
        let inv = inviscid(&s, 0.5, Vector3::zeros());
        let c = correct_strip(&polar, &LatticeSection::THIN_PLATE, &s, &inv).unwrap();
        let added = c.loads.force - inv.force;
        let u_n = Vector3::new(0.0, s.flow.y, s.flow.z);
        assert_relative_eq!(added.cross(&u_n).norm(), 0.0, epsilon = 1e-12 * added.norm() * u_n.norm());
        assert!(added.dot(&u_n) > 0.0, "drag points downstream");
        let q_area = 0.5 * s.rho * u_n.norm_squared() * s.chord * s.width;
        assert_relative_eq!(added.norm(), 0.013 * q_area, max_relative = 1e-13);
        assert_relative_eq!(c.profile_drag(), 0.013 * q_area, max_relative = 1e-13);
        if spanwise == 0.0 {
            assert_relative_eq!((c.drag_dir - s.flow.normalize()).norm(), 0.0, epsilon = 1e-15);
        }
        // The drag acts at the quarter chord.
        assert_relative_eq!((c.loads.moment - inv.moment - s.quarter_chord.cross(&added)).norm(), 0.0, epsilon = 1e-15);
    }
}

#[test]
fn moment_is_the_polar_cm_about_the_quarter_chord_and_transfers_as_a_rigid_arm() {
    let polar = stall_polar();
    let quarter_chord = Vector3::new(0.01, -0.005, 0.002);
    let (a, b) = (Vector3::zeros(), Vector3::new(-0.02, 0.03, 0.004));
    let s_a = Strip { quarter_chord: quarter_chord - a, ..strip(0.1, 0.05) };
    let s_b = Strip { quarter_chord: quarter_chord - b, ..s_a };
    let inv_a = inviscid(&s_a, 0.6, Vector3::new(0.0, 0.0, 0.0));
    let inv_b = StripLoads { force: inv_a.force, moment: inv_a.moment + (a - b).cross(&inv_a.force) };
    let ca = correct_strip(&polar, &LatticeSection::THIN_PLATE, &s_a, &inv_a).unwrap();
    let cb = correct_strip(&polar, &LatticeSection::THIN_PLATE, &s_b, &inv_b).unwrap();
    let transferred = ca.loads.moment + (a - b).cross(&ca.loads.force);
    assert_relative_eq!((cb.loads.moment - transferred).norm(), 0.0, epsilon = 1e-13 * ca.loads.moment.norm());
    // About the quarter chord the lattice's lift has no moment (it acts there), so the corrected
    // moment is the polar's cm alone, about the span axis and nose up for cm > 0.
    let m_qc = ca.loads.moment - s_a.quarter_chord.cross(&ca.loads.force);
    let cm = ca.coefficients.cm;
    assert!(cm < 0.0);
    assert_relative_eq!(m_qc.x, cm * ca.q_area * s_a.chord, max_relative = 1e-12);
    assert_relative_eq!(m_qc.yz().norm(), 0.0, epsilon = 1e-14);
}

#[test]
fn the_effective_incidence_reads_the_table_past_stall() {
    let polar = stall_polar();
    let s = strip(14f64.to_radians(), 0.0);
    // A two-dimensional thin plate at 14°: the lattice's lift is 2π·14° and nothing is induced.
    let inv = inviscid(&s, 2.0 * PI * 14f64.to_radians(), Vector3::zeros());
    let c = correct_strip(&polar, &LatticeSection::THIN_PLATE, &s, &inv).unwrap();
    assert_relative_eq!(c.alpha, 14f64.to_radians(), max_relative = 1e-13);
    assert_relative_eq!(c.alpha_geometric, 14f64.to_radians(), max_relative = 1e-13);
    let table = polar.coefficients(c.alpha, s.reynolds()).unwrap();
    assert_relative_eq!(c.loads.force.dot(&c.lift_dir), table.cl * c.q_area, max_relative = 1e-12);
    assert!(table.dcl < 0.0, "past the peak the local slope is negative");
    assert_relative_eq!(s.reynolds(), 20.0 * 0.078 / 1.5e-5, max_relative = 1e-14);
}

#[test]
fn errors_name_the_field_and_the_incidence() {
    let polar = stall_polar();
    let s = strip(0.1, 0.0);
    let inv = inviscid(&s, 0.5, Vector3::zeros());
    let lat = LatticeSection::THIN_PLATE;
    for (field, bad) in [
        ("chord", Strip { chord: 0.0, ..s }),
        ("width", Strip { width: -1.0, ..s }),
        ("rho", Strip { rho: f64::NAN, ..s }),
        ("kinematic_viscosity", Strip { kinematic_viscosity: 0.0, ..s }),
        ("fixed_reynolds", Strip { fixed_reynolds: Some(-1.0), ..s }),
        ("flow", Strip { flow: Vector3::new(3.0, 0.0, 0.0), ..s }),
    ] {
        let e = correct_strip(&polar, &lat, &bad, &inv).unwrap_err();
        assert!(matches!(e, AerofoilError::InvalidStrip { field: f, .. } if f == field), "{e}");
    }
    let far = inviscid(&s, 2.0 * PI * 25f64.to_radians(), Vector3::zeros());
    let e = correct_strip(&polar, &lat, &s, &far).unwrap_err();
    assert!(matches!(e, AerofoilError::IncidenceOutOfRange { alpha_deg, .. } if (alpha_deg - 25.0).abs() < 1e-9));
}

proptest! {
    /// `d_force_d_alpha` and `d_moment_d_alpha` against central differences of the corrected
    /// loads of a strip whose lattice lift follows its own line and acts at the quarter chord.
    #[test]
    fn jacobian_in_incidence_matches_finite_differences(
        alpha_deg in -18.0f64..18.0, spanwise in -0.3f64..0.3, v in 20.0f64..55.0,
    ) {
        let polar = stall_polar();
        let lat = LatticeSection { lift_slope: 6.1, zero_lift_alpha: 0.01 };
        let s = Strip { flow: strip(0.1, spanwise).flow * (v / 20.0), ..strip(0.1, spanwise) };
        let loads = |alpha: f64| {
            let inv = inviscid(&s, lat.lift_slope * (alpha - lat.zero_lift_alpha), Vector3::new(0.01, 0.0, 0.0));
            correct_strip(&polar, &lat, &s, &inv).unwrap()
        };
        let (alpha, h) = (alpha_deg.to_radians(), 1e-6);
        let c = loads(alpha);
        prop_assert!((c.alpha - alpha).abs() < 1e-12);
        let (p, m) = (loads(alpha + h).loads, loads(alpha - h).loads);
        let fd_f = (p.force - m.force) / (2.0 * h);
        let fd_m = (p.moment - m.moment) / (2.0 * h);
        let scale_f = c.q_area * 6.0;
        prop_assert!((fd_f - c.d_force_d_alpha).norm() <= 1e-6 * scale_f, "{fd_f} vs {}", c.d_force_d_alpha);
        prop_assert!((fd_m - c.d_moment_d_alpha).norm() <= 1e-6 * scale_f * 0.1, "{fd_m} vs {}", c.d_moment_d_alpha);
    }

    /// `force_jacobian` and `moment_jacobian` against central differences in every component of
    /// the lattice's force.
    #[test]
    fn jacobian_in_the_lattice_force_matches_finite_differences(cl in -1.5f64..1.5, spanwise in -0.3f64..0.3) {
        let polar = stall_polar();
        let lat = LatticeSection::THIN_PLATE;
        let s = strip(0.05, spanwise);
        let inv = inviscid(&s, cl, Vector3::new(0.0, 0.01, 0.0));
        let c = correct_strip(&polar, &lat, &s, &inv).unwrap();
        let (jf, jm) = (c.force_jacobian(), c.moment_jacobian());
        let h = 1e-6 * inv.force.norm();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = h;
            let at = |df: Vector3<f64>| {
                correct_strip(&polar, &lat, &s, &StripLoads { force: inv.force + df, ..inv }).unwrap().loads
            };
            let (p, m) = (at(e), at(-e));
            let fd_f = (p.force - m.force) / (2.0 * h);
            let fd_m = (p.moment - m.moment) / (2.0 * h);
            prop_assert!((fd_f - jf.column(k)).norm() <= 1e-6, "column {k}: {fd_f} vs {}", jf.column(k));
            prop_assert!((fd_m - jm.column(k)).norm() <= 1e-7, "column {k}: {fd_m} vs {}", jm.column(k));
        }
    }
}

proptest! {
    /// `d_force_d_flow` and `d_moment_d_flow` against central differences in every component of
    /// the flow vector, at fixed lattice loads, between two Reynolds tables.
    #[test]
    fn jacobian_in_the_flow_matches_finite_differences(
        alpha_deg in -15.0f64..15.0, spanwise in -0.3f64..0.3, v in 21.0f64..55.0, cl in -1.0f64..1.0,
    ) {
        let polar = stall_polar();
        let lat = LatticeSection { lift_slope: 6.0, zero_lift_alpha: -0.01 };
        let base = strip(alpha_deg.to_radians(), spanwise);
        let fixed = (v > 40.0).then_some(1.7e5);
        let s = Strip { flow: base.flow * (v / 20.0), fixed_reynolds: fixed, ..base };
        let inv = inviscid(&s, cl, Vector3::new(0.01, -0.02, 0.0));
        let Ok(c) = correct_strip(&polar, &lat, &s, &inv) else { return Ok(()) };
        let h = 1e-6 * s.flow.norm();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = h;
            let at = |du: Vector3<f64>| correct_strip(&polar, &lat, &Strip { flow: s.flow + du, ..s }, &inv);
            let (Ok(p), Ok(m)) = (at(e), at(-e)) else { return Ok(()) };
            let fd_f = (p.loads.force - m.loads.force) / (2.0 * h);
            let fd_m = (p.loads.moment - m.loads.moment) / (2.0 * h);
            let scale = c.q_area / s.flow.norm();
            let (jf, jm) = (c.d_force_d_flow.column(k), c.d_moment_d_flow.column(k));
            prop_assert!((fd_f - jf).norm() <= 1e-6 * scale, "column {k}: {fd_f} vs {jf}");
            prop_assert!((fd_m - jm).norm() <= 1e-7 * scale, "column {k}: {fd_m} vs {jm}");
        }
    }
}
