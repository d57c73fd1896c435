//! Body orientation (`sweep_deg`, `dihedral_deg`, a start defaulting to the parent's end): the
//! frames it builds, the swept cantilever as the straight one rotated in both formulations, and
//! bad input named.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common::root;
use harness::case::{CaseFile, Formulation};
use harness::statics::run_static;
use nalgebra::{Rotation3, Vector3};
use serde_json::{Value, json};

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Write `v` to a fresh file in this test's folder and expand it.
fn spec(v: &Value, tag: &str) -> (harness::case::RunSpec, PathBuf) {
    let dir = std::env::temp_dir().join(format!("harness-geometry-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{tag}.json"));
    std::fs::write(&p, v.to_string()).unwrap();
    (CaseFile::read(&p).unwrap().expand(&[]).unwrap().remove(0), p)
}

/// The Bathe–Bolourchi bend, written with explicit starts and axes per body, is the chain of
/// its root body with each further body swept forward by 45°/8 relative to its parent's end
/// (no starts, no axes): the same scene to 1e-12 of the radius.
#[test]
fn sweep_builds_the_bend_chain_from_the_parents_end() {
    let written = read(&root().join("cases/statics/bathe_bolourchi_bend.json"));
    let mut swept = written.clone();
    for b in swept["bodies"].as_array_mut().unwrap().iter_mut().skip(1) {
        let o = b.as_object_mut().unwrap();
        o.remove("start");
        o.remove("x_axis");
        o.remove("y_axis");
        o.insert("sweep_deg".into(), json!(-45.0 / 8.0));
    }
    let (a, _) = spec(&written, "written");
    let (b, _) = spec(&swept, "swept");
    for f in Formulation::ALL {
        let (sa, sb) = (a.case(f).scene(f), b.case(f).scene(f));
        for (x, y) in sa.bodies.iter().zip(&sb.bodies) {
            assert!((x.start - y.start).norm() < 1e-12 * 100.0, "{}: {} vs {}", x.name, x.start, y.start);
            assert!((x.frame - y.frame).norm() < 1e-12, "{}: {} vs {}", x.name, x.frame, y.frame);
        }
    }
}

/// A cantilever swept 30° aft with 10° dihedral under a dead tip load is the straight
/// cantilever along X under the load turned back by the same rotation, rotated: the tip agrees
/// to 1e-6 of its displacement in both formulations (objectivity of the static solution and the
/// frame `R_z(−Λ) R_y(−Γ)` of docs/case-file.md).
#[test]
fn a_swept_cantilever_is_the_straight_one_rotated() {
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), -30f64.to_radians())
        * Rotation3::from_axis_angle(&Vector3::y_axis(), -10f64.to_radians());
    let force = Vector3::new(0.3, -0.8, 2.0);
    let case = |sweep: f64, dihedral: f64, f: Vector3<f64>| {
        json!({
            "name": "swept_cantilever",
            "bodies": [{
                "name": "beam", "length": 1.0, "sweep_deg": sweep, "dihedral_deg": dihedral,
                "section": { "mass": 1.0, "rho_ixx": 2e-4, "rho_iyy": 1e-4, "rho_izz": 1e-4, "ea": 1e6,
                    "ga_y": 4e5, "ga_z": 4e5, "gj": 8.0, "ei_yy": 10.0, "ei_zz": 40.0 }
            }],
            "joints": [{ "type": "clamp", "body": "beam" }],
            "t_end": 0.01,
            "ancf": { "elements_per_body": [16], "dt": 0.001 },
            "gebf": { "elements_per_body": [16], "dt": 0.001 },
            "static": { "point_loads": [{ "body": "beam", "force": [f.x, f.y, f.z] }], "load_factors": [1.0] }
        })
    };
    let (straight, _) = spec(&case(0.0, 0.0, force), "straight");
    let (swept, _) = spec(&case(30.0, 10.0, rot * force), "swept");
    // The swept body's axis is the rotated X axis.
    let axis = swept.ancf.scene(Formulation::Ancf).bodies[0].frame.column(0).into_owned();
    assert!((axis - rot * Vector3::x()).norm() < 1e-15, "{axis}");
    for f in Formulation::ALL {
        let a = run_static(&straight.case(f).problem(), f);
        let b = run_static(&swept.case(f).problem(), f);
        let (pa, pb) = (&a.points[0], &b.points[0]);
        assert!(pa.error.is_none() && pb.error.is_none(), "{f}: {:?} {:?}", pa.error, pb.error);
        let (ta, tb) = (Vector3::from(pa.tip), Vector3::from(pb.tip));
        let u = ta - Vector3::x();
        assert!(u.norm() > 0.05, "{f}: a load that deflects: {u}");
        assert!((tb - rot * ta).norm() < 1e-6 * u.norm(), "{f}: {tb} vs {}", rot * ta);
    }
}

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

#[test]
fn bad_orientation_exits_2_naming_the_field() {
    let c = "cases/healy_ffwt_flare10_aoa5.json";
    for (set, needle) in [
        ("bodies.1.sweep_deg=85", "bodies[1].sweep_deg"),
        ("bodies.0.dihedral_deg=-80.5", "bodies[0].dihedral_deg"),
        ("bodies.1.dihedral_deg=\"NaN\"", "bodies[1].dihedral_deg"),
        ("bodies.1.twist_deg=[0,95]", "bodies[1].twist_deg[1]"),
        ("bodies.1.twist_deg=[[0,0],[0.2,1]]", "bodies[1].twist_deg[1]"),
        ("bodies.1.twist_deg=[[0.05,0],[0.05,1]]", "bodies[1].twist_deg[1]"),
    ] {
        let o = harness(&["static", c, "--set", set, "--out", std::env::temp_dir().to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{set}: {err}");
    }
    let out = std::env::temp_dir();
    let o = harness(&[
        "static",
        c,
        "--set",
        "bodies.1.sweep_deg=10",
        "--set",
        "bodies.1.x_axis=[0,0,1]",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("bodies[1].x_axis"), "{err}");
}

/// Healy's wingtip with the thesis' built-in twist ramp (zero up to 0.425 m from the root, 3°
/// nose up from 0.45 m): ANCF and GEBF reach one equilibrium (0.01°, with the case's 12 tip
/// elements), and the washed-in tip rests higher than the untwisted one, by several degrees
/// (the fold's own incidence change, sin 20° per degree of fold, must make up for the twist).
#[test]
fn a_twisted_wingtip_coasts_higher_in_both_formulations() {
    let path = root().join("cases/healy_sideslip_flare20_pitch0.json");
    let set = |twist: &str| -> harness::case::RunSpec {
        let ov: Vec<harness::case::Override> =
            ["static.sideslips_deg=[0]".to_string(), format!("bodies.1.twist_deg={twist}")]
                .iter()
                .map(|s| s.parse().unwrap())
                .collect();
        CaseFile::read(&path).unwrap().expand(&ov).unwrap().remove(0)
    };
    let fold = |spec: &harness::case::RunSpec, f: Formulation| {
        let p = run_static(&spec.case(f).problem(), f).points.remove(0);
        assert!(p.error.is_none(), "{f}: {:?}", p.error);
        p.fold_deg
    };
    let flat = set("[0,0]");
    let twisted = set("[[0,0],[0.06,0],[0.085,3],[0.135,3]]");
    let (a, g) = (fold(&twisted, Formulation::Ancf), fold(&twisted, Formulation::Gebf));
    assert!((a - g).abs() < 0.01, "twisted tip: ANCF {a}° GEBF {g}°");
    let g0 = fold(&flat, Formulation::Gebf);
    assert!(g > g0 + 2.0 && g < g0 + 3.0 / 20f64.to_radians().sin(), "twisted {g}° against untwisted {g0}°");
}
