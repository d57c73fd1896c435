//! The readings of Healy's experiment (issue 37, point 5): the static strips against their
//! closed form, the hinge line through mid-chord, ANCF against GEBF on every new reading, and
//! bad input of the new fields named.

use std::f64::consts::PI;
use std::process::Command;

use crate::common::root;
use harness::case::{CaseFile, Formulation, Override, RunSpec};
use harness::healy_readings::Reading;
use harness::statics::run_static;

fn healy(stem: &str, set: &[&str]) -> RunSpec {
    let ov: Vec<Override> = set.iter().map(|s| s.parse().unwrap()).collect();
    CaseFile::read(&root().join(format!("cases/{stem}.json"))).unwrap().expand(&ov).unwrap().remove(0)
}

/// The rigid, locked Healy wing without gravity at 4° pitch: every static strip lifts
/// `½ρV²c·2πα` per unit span (the flat lift slope; the spar at the quarter chord carries no
/// torque), and with the lifting-line tip loss `F(η)` times that, `F` the factor of the
/// 0.5 m × 78 mm planform mirrored at the root.
#[test]
fn static_strips_lift_a_rigid_wing_by_two_pi_alpha() {
    let base = [
        "aero.model=strip",
        "joints.1.locked=true",
        "gravity=[0,0,0]",
        "stiffness_scale=1e6",
        "pitch_deg=4",
        "static.airspeeds=[20]",
        "static.references=[]",
    ];
    let (q, c, alpha) = (0.5 * 1.225 * 20.0 * 20.0, 0.078, 4f64.to_radians());
    let ll = aeroelastic::strip_statics::LiftingLine::new(0.5, 2.0 * PI, |_| c).unwrap();
    for tip_loss in [false, true] {
        let mut set = base.to_vec();
        if tip_loss {
            set.push("aero.strip_tip_loss=lifting_line");
        }
        let spec = healy("healy_ffwt_flare10_aoa0", &set);
        for f in Formulation::ALL {
            let out = run_static(&spec.case(f).problem(), f);
            let p = &out.points[0];
            assert!(p.error.is_none(), "{f}: {:?}", p.error);
            let mut total = 0.0;
            for s in &p.strips {
                let factor = if tip_loss { ll.factor(s.s / 0.5, c) } else { 1.0 };
                let exact = q * c * 2.0 * PI * alpha * factor;
                assert!(
                    (s.lift_per_span - exact).abs() < 1e-6 * q * c,
                    "{f} at s = {}: {} against {exact}",
                    s.s,
                    s.lift_per_span
                );
                total += exact;
            }
            let mean = total / p.strips.len() as f64;
            assert!((p.lift / 0.5 - mean).abs() < 0.02 * mean, "{f}: lift {} against strips {}", p.lift, mean * 0.5);
            if !tip_loss {
                let exact = q * c * 0.5 * 2.0 * PI * alpha;
                assert!((p.lift - exact).abs() < 1e-6 * exact, "{f}: lift {} against {exact}", p.lift);
            }
        }
    }
}

/// The hinge line through mid-chord (`hinge_line_y = −0.02` at flare 10°): the joint moves
/// 0.02 tan 10° outboard along the spar, the tip keeps its outer end and its mass's station.
#[test]
fn the_hinge_line_places_the_joint_on_the_spar() {
    let spec = healy("healy_ffwt_flare10_aoa0", &["joints.1.hinge_line_y=-0.02"]);
    let p = spec.case(Formulation::Gebf).problem();
    let d = 0.02 * 10f64.to_radians().tan();
    assert!((p.bodies[0].length - (0.365 + d)).abs() < 1e-15);
    assert!((p.bodies[1].length - (0.135 - d)).abs() < 1e-15);
    let start = p.bodies[1].start.unwrap();
    assert!((start[0] - (0.365 + d)).abs() < 1e-15);
    assert!((start[0] + p.bodies[1].point_masses[0].at - 0.424).abs() < 1e-15);
    // The joint lies on the line through the mid-chord point at 365 mm along the flare axis.
    let (sb, cb) = 10f64.to_radians().sin_cos();
    let t = -0.02 / cb;
    assert!((start[0] + t * sb - 0.365).abs() < 1e-15);
}

/// ANCF and GEBF agree on every new reading (static strips with and without tip loss and
/// polars, geometry 2 on the lattice): coast angle within 0.01°, root bending moment within
/// 0.1 %, on the flare-10° pitch-5° curve at 15 and 27 m/s.
#[test]
fn ancf_and_gebf_agree_on_every_new_reading() {
    for r in Reading::all().into_iter().filter(|r| r.aero != harness::healy_readings::Aero::Lattice || r.geometry == 2)
    {
        let mut set: Vec<String> = r.overrides().unwrap().iter().map(|o| format!("{}={}", o.path, o.value)).collect();
        set.push("static.airspeeds=[15,27]".into());
        set.push("static.references=[]".into());
        let refs: Vec<&str> = set.iter().map(String::as_str).collect();
        let spec = healy("healy_ffwt_flare10_aoa5", &refs);
        let [a, g] = Formulation::ALL.map(|f| run_static(&spec.case(f).problem(), f));
        for (pa, pg) in a.points.iter().zip(&g.points) {
            assert!(pa.error.is_none() && pg.error.is_none(), "{}: {:?} {:?}", r.label(), pa.error, pg.error);
            let dfold = (pa.fold_deg - pg.fold_deg).abs();
            let (ra, rg) = (pa.loads.root_bending_moment, pg.loads.root_bending_moment);
            let drbm = (ra - rg).abs() / rg.abs();
            assert!(dfold < 0.01, "{} at {} m/s: fold {} / {}", r.label(), pa.airspeed, pa.fold_deg, pg.fold_deg);
            assert!(drbm < 1e-3, "{} at {} m/s: RBM {ra} / {rg}", r.label(), pa.airspeed);
        }
    }
}

fn harness(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

/// Bad values of the new fields exit 2 naming the field.
#[test]
fn bad_readings_input_exits_2_naming_the_field() {
    let out = std::env::temp_dir().join(format!("flexmb_readings_bad_{}", std::process::id()));
    let o = out.to_str().unwrap();
    let case = "cases/healy_ffwt_flare10_aoa0.json";
    for (set, field) in [
        ("joints.1.hinge_line_y=-1", "joints[1].hinge_line_y"),
        ("joints.1.hinge_line_y=0.01", ""),
        ("aero.strip_tip_loss=lifting_line", "aero.strip_tip_loss"),
        ("aero.strip_tip_loss=prandtl", "aero.strip_tip_loss"),
    ] {
        let r = harness(&[
            "static",
            case,
            "--formulation",
            "gebf",
            "--out",
            o,
            "--set",
            set,
            "--set",
            "static.airspeeds=[20]",
        ]);
        let err = String::from_utf8_lossy(&r.stderr);
        if field.is_empty() {
            assert_eq!(r.status.code(), Some(0), "{set}: {err}");
        } else {
            assert_eq!(r.status.code(), Some(2), "{set}: {err}");
            assert!(err.contains(field), "{set}: {err}");
        }
    }
    let flare = harness(&[
        "static",
        case,
        "--out",
        o,
        "--set",
        "joints.1.flare_deg=90",
        "--set",
        "joints.1.hinge_line_y=-0.02",
    ]);
    assert_eq!(flare.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&flare.stderr).contains("joints[1].hinge_line_y"));
    let both = harness(&["healy-readings", "--formulation", "both", "--out", o]);
    assert_eq!(both.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&both.stderr).contains("--formulation"));
    let _ = std::fs::remove_dir_all(&out);
}
