//! The roll rig with strip aerodynamics on a rigid wing (issue 35's acceptance, docs/validation.md
//! §7): the steady roll rate and the roll time constant of strip theory.

use aeroelastic::Formulation;
use harness::case::{CaseFile, Override};

/// `cases/healy_roll_rig.json` at 20 m/s with `aero.model: "strip"`, its tips locked and every
/// stiffness ×100 (a rigid wing): the steady roll rate is within 1 % of strip theory's
/// `p = (3/2)(V/s) τ (η₂² − η₁²) δ` (ailerons from η₁ = 0.364 to η₂ = 0.728 of the semi-span
/// s = 0.5 m, τ the thin-aerofoil effectiveness of a 25 % flap, δ = 5°), and the time constant of
/// an exponential fitted to the first 2.5 of them within 2 % of `3 I / (ρ V c a s³)`, I the rig's
/// roll inertia from the case (wings and tips; the hub's is 1e-6 of it).
#[test]
fn the_strip_roll_rig_rolls_as_strip_theory_says() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let sets = ["aero.model=strip", "stiffness_scale=100", "joints.3.locked=true", "joints.4.locked=true"];
    let ov: Vec<Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
    let runs = CaseFile::read(&root.join("cases/healy_roll_rig.json")).unwrap().expand(&ov).unwrap();
    let spec = runs.into_iter().find(|r| r.name.contains("v_inf=0,-20,0")).expect("the 20 m/s run");
    let (v, s, c, rho, delta) = (20.0_f64, 0.5_f64, 0.067_f64, 1.225_f64, 5.0_f64.to_radians());
    let theta = (2.0_f64 * 0.25 - 1.0).acos();
    let tau_flap = 1.0 - (theta - theta.sin()) / std::f64::consts::PI;
    let p_ss = 1.5 * v / s * tau_flap * (0.728_f64.powi(2) - 0.364_f64.powi(2)) * delta;
    let case = spec.case(Formulation::Gebf);
    let inertia: f64 = case.bodies[1..]
        .iter()
        .map(|b| {
            let x0 = b.start.map_or(0.0, |p| p[0].abs());
            b.section.mass * ((x0 + b.length).powi(3) - x0.powi(3)) / 3.0
        })
        .sum();
    let tau = 3.0 * inertia / (rho * v * c * 2.0 * std::f64::consts::PI * s.powi(3));
    for f in Formulation::ALL {
        let out = harness::scene::run_formulation(spec.case(f), f);
        assert!(out.error.is_none(), "{f}: {:?}", out.error);
        let rows = &out.rows;
        let tail = &rows[3 * rows.len() / 4..];
        let steady = tail.iter().map(|r| r.roll_rate).sum::<f64>() / tail.len() as f64;
        assert!((steady.abs() / p_ss - 1.0).abs() < 0.01, "{f}: steady rate {steady} against {p_ss}");
        // ln(1 − p/p_ss) = −t/τ: least squares through the first 2.5 τ.
        let pts: Vec<(f64, f64)> =
            rows.iter().skip(1).filter(|r| r.t < 2.5 * tau).map(|r| (r.t, (1.0 - r.roll_rate / steady).ln())).collect();
        let n = pts.len() as f64;
        let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
        let (sxx, sxy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0 * p.0, a.1 + p.0 * p.1));
        let fitted = -(n * sxx - sx * sx) / (n * sxy - sx * sy);
        assert!((fitted / tau - 1.0).abs() < 0.02, "{f}: time constant {fitted} against {tau}");
        eprintln!("{f}: p_ss {steady:.5} against {p_ss:.5}, tau {fitted:.5} against {tau:.5}");
    }
}
