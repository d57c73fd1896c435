//! Sideslip (`aero.sideslip_deg`, `static.sideslips_deg`): the free stream's convention, the
//! symmetry of a symmetric wing, the sideslip sweep's continuation to large folds in both
//! formulations, and bad input named.

use std::process::{Command, Output};

use crate::common::{case, root};
use harness::case::Formulation;
use harness::statics::run_static;
use nalgebra::{Matrix3, Vector3};

/// Positive sideslip is wind from the right (starboard, +X): a stream along −Y becomes
/// −V (sin β, cos β, 0), to rounding; zero sideslip leaves the stream bit for bit.
#[test]
fn sideslip_turns_the_free_stream_about_the_vertical() {
    let spec = case("healy_sideslip_flare20_pitch0.json", &["aero.sideslip_deg=12"]);
    let aero = spec.ancf.aero.clone().unwrap();
    let v = aero.free_stream();
    let (s, c) = 12f64.to_radians().sin_cos();
    let expected = [-22.0 * s, -22.0 * c, 0.0];
    for k in 0..3 {
        assert!((v[k] - expected[k]).abs() < 1e-13, "{v:?} vs {expected:?}");
    }
    let mut zero = aero.clone();
    zero.sideslip_deg = 0.0;
    assert_eq!(zero.free_stream(), [0.0, -22.0, 0.0]);
    // With a `v_inf` that has a vertical component, only the horizontal part turns.
    zero.v_inf = Some([0.0, -3.0, 1.0]);
    zero.airspeed = None;
    zero.sideslip_deg = -30.0;
    let w = zero.free_stream();
    assert!((w[0] - 1.5).abs() < 1e-14 && (w[1] + 3.0 * 30f64.to_radians().cos()).abs() < 1e-14 && w[2] == 1.0);
}

/// A flat rectangular wing symmetric about x = 0 in sideslip ±β: the same lift and drag (to
/// rounding of the summation order, 1e-12 relative) and opposite side forces, and less lift than
/// without sideslip (the stream's component across the span carries no circulation).
#[test]
fn a_symmetric_wing_in_sideslip_has_even_lift_and_odd_side_force() {
    let span = 2.0;
    let n = 16;
    let frame = Matrix3::from_columns(&[
        Vector3::x(),
        Vector3::new(0.0, 5f64.to_radians().cos(), 5f64.to_radians().sin()),
        Vector3::new(0.0, -5f64.to_radians().sin(), 5f64.to_radians().cos()),
    ]);
    let stations: Vec<uvlm::SpanStation> = (0..=n)
        .map(|j| uvlm::SpanStation {
            origin: Vector3::new(-0.5 * span + span * j as f64 / n as f64, 0.0, 0.0),
            frame,
            chord: 0.25,
            le_offset: 0.0625,
            slant: 0.0,
            flap: None,
        })
        .collect();
    let spec = case("healy_sideslip_flare20_pitch0.json", &[]);
    let forces = |beta: f64| {
        let mut aero = spec.ancf.aero.clone().unwrap();
        aero.sideslip_deg = beta;
        let v = aero.free_stream();
        let lattice = uvlm::Lattice::from_stations(uvlm::LatticeSpec::new(4), &stations).unwrap();
        let mut u = uvlm::Uvlm::new(lattice, uvlm::UvlmParams::new(1.225, v)).unwrap();
        let f = Vector3::from(u.solve_steady().unwrap().total_force());
        let lift_dir = harness::statics::lift_direction(v);
        (f.dot(&lift_dir), f.dot(&Vector3::from(v).normalize()), f.x, f)
    };
    let (l0, _, _, _) = forces(0.0);
    let (lp, dp, _, fp) = forces(15.0);
    let (lm, dm, _, fm) = forces(-15.0);
    assert!((lp - lm).abs() < 1e-12 * lp.abs(), "lift {lp} vs {lm}");
    assert!((dp - dm).abs() < 1e-10 * lp.abs(), "drag {dp} vs {dm}");
    // Mirror x → −x: the force's x component changes sign, y and z stay.
    assert!((fp.x + fm.x).abs() < 1e-10 * lp.abs() && (fp.y - fm.y).abs() < 1e-10 * lp.abs(), "{fp} vs {fm}");
    assert!(lp < l0 && lp > 0.85 * l0, "lift at 15° sideslip {lp} against {l0} without");
}

/// The sideslip sweep of Healy's flare-20° wing at pitch 0° continues from 0° sideslip out to
/// 20°, where the tip folds past −80°: both formulations reach every point, agree within 0.01°,
/// and the tip folds further down as the wind turns towards its side (the trend of the
/// experiment, whose points lie at −15.2°, −25.5° and −107° at 2°, 10° and 20°).
#[test]
fn the_sideslip_sweep_reaches_large_folds_in_both_formulations() {
    let spec = case("healy_sideslip_flare20_pitch0.json", &["static.sideslips_deg=[20, -10, 0, 10]"]);
    let a = run_static(&spec.ancf.problem(), Formulation::Ancf);
    let g = run_static(&spec.gebf.problem(), Formulation::Gebf);
    for (pa, pg) in a.points.iter().zip(&g.points) {
        assert!(pa.error.is_none() && pg.error.is_none(), "{:?} {:?}", pa.error, pg.error);
        assert_eq!(pa.sideslip_deg, pg.sideslip_deg);
        assert!((pa.fold_deg - pg.fold_deg).abs() < 0.01, "{} vs {} at {}", pa.fold_deg, pg.fold_deg, pa.sideslip_deg);
        assert!((pa.airspeed - 22.0).abs() < 1e-12, "airspeed {}", pa.airspeed);
    }
    // Reported in the case's order.
    let betas: Vec<f64> = g.points.iter().map(|p| p.sideslip_deg).collect();
    assert_eq!(betas, [20.0, -10.0, 0.0, 10.0]);
    let fold = |b: f64| g.points.iter().find(|p| p.sideslip_deg == b).unwrap().fold_deg;
    assert!(fold(-10.0) > fold(0.0) && fold(0.0) > fold(10.0) && fold(10.0) > fold(20.0), "{betas:?}");
    assert!(fold(20.0) < -80.0, "fold at 20° sideslip {}", fold(20.0));
}

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

#[test]
fn bad_sideslip_input_exits_2_naming_the_field() {
    let c = "cases/healy_sideslip_flare20_pitch0.json";
    for (set, needle) in [
        ("aero.sideslip_deg=90", "aero.sideslip_deg"),
        ("aero.sideslip_deg=\"NaN\"", "aero.sideslip_deg"),
        ("static.sideslips_deg=[0,-95]", "static.sideslips_deg[1]"),
        ("static.sideslips_deg=[0,3,0]", "static.sideslips_deg[2]"),
        ("static.airspeeds=[20,22]", "static.airspeeds"),
    ] {
        let o = harness(&["static", c, "--set", set, "--out", std::env::temp_dir().to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{set}: {err}");
    }
}
