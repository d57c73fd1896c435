//! Static aeroelastic equilibria and the wing loads: the two formulations agree, a damped time
//! march settles on the static answer, the free body balances, and bad static input is named.

use std::process::{Command, Output};

use crate::common::{case, root};
use harness::case::Formulation;
use harness::scene::run_formulation;
use harness::statics::run_static;

/// ANCF and GEBF reach one equilibrium: coast angle within 0.2°, root bending moment within
/// 0.5 % (of the larger of the point's value and 5 % of the sweep's largest, so that a moment
/// crossing zero is compared on the sweep's scale), at every airspeed of every Healy case.
#[test]
fn both_formulations_reach_one_equilibrium_on_every_healy_case() {
    for name in ["healy_ffwt_flare10_aoa0.json", "healy_ffwt_flare10_aoa5.json", "healy_ffwt_flare30_aoa10.json"] {
        let spec = case(name, &[]);
        let a = run_static(&spec.ancf.problem(), Formulation::Ancf);
        let g = run_static(&spec.gebf.problem(), Formulation::Gebf);
        let scale = g.points.iter().map(|p| p.loads.root_bending_moment.abs()).fold(0.0, f64::max);
        for (pa, pg) in a.points.iter().zip(&g.points) {
            assert!(
                pa.error.is_none() && pg.error.is_none(),
                "{name} {} m/s: {:?} {:?}",
                pa.airspeed,
                pa.error,
                pg.error
            );
            let df = (pa.fold_deg - pg.fold_deg).abs();
            assert!(df < 0.2, "{name} {} m/s: fold {} vs {}", pa.airspeed, pa.fold_deg, pg.fold_deg);
            let (ra, rg) = (pa.loads.root_bending_moment, pg.loads.root_bending_moment);
            assert!(
                (ra - rg).abs() < 5e-3 * rg.abs().max(0.05 * scale),
                "{name} {} m/s: RBM {ra} vs {rg}",
                pa.airspeed
            );
        }
    }
}

/// A damped time march (4 coupling sub-iterations, rho_inf 0.5) of the flare 10°, pitch 5°
/// case at 20 m/s settles within 0.1° (coast angle) and 0.2 % (root bending moment) of the
/// static solution, with both formulations.
#[test]
fn a_damped_time_march_settles_on_the_static_equilibrium() {
    // The coarser lattice of the refinement study keeps the 3 s march short; both analyses use it.
    let spec = case(
        "healy_ffwt_flare10_aoa5.json",
        &["static.airspeeds=[20]", "aero.airspeed=20", "t_end=3", "aero.panels_per_body=[16,6]"],
    );
    for f in Formulation::ALL {
        let st = run_static(&spec.case(f).problem(), f);
        let p = &st.points[0];
        assert!(p.error.is_none(), "{f}: {:?}", p.error);
        let run = run_formulation(spec.case(f), f);
        assert!(run.error.is_none(), "{f}: {:?}", run.error);
        let last = run.rows.last().unwrap();
        let fold = last.fold.to_degrees();
        assert!((fold - p.fold_deg).abs() < 0.1, "{f}: march {fold}°, static {}°", p.fold_deg);
        let rbm = p.loads.root_bending_moment;
        println!(
            "{f}: fold march {fold:.4}° static {:.4}°; RBM march {:.6} static {rbm:.6} N·m ({:+.4} %)",
            p.fold_deg,
            last.root_bending_moment,
            100.0 * (last.root_bending_moment - rbm) / rbm.abs()
        );
        assert!(
            (last.root_bending_moment - rbm).abs() < 2e-3 * rbm.abs(),
            "{f}: march {} N·m, static {rbm} N·m",
            last.root_bending_moment
        );
    }
}

/// The free body balances: with a free hinge the moment about its axis is the spring's,
/// `−k θ` seen from the tip (k = 1e-4 N·m/rad), at every airspeed.
#[test]
fn the_hinge_moment_of_a_free_hinge_is_its_spring_moment() {
    let spec = case("healy_ffwt_flare30_aoa10.json", &["static.airspeeds=[14,24,33]"]);
    for f in Formulation::ALL {
        for p in &run_static(&spec.case(f).problem(), f).points {
            let spring = 1e-4 * p.fold_deg.to_radians();
            assert!(
                (p.loads.hinge_moment - spring).abs() < 2e-6,
                "{f} {} m/s: {} vs {spring}",
                p.airspeed,
                p.loads.hinge_moment
            );
        }
    }
}

/// Gravity alone (a locked hinge at a negligible airspeed): the root bending moment and the
/// lock's moment are the weights' moments, `Σ m g x` over the spar and the point masses.
#[test]
fn gravity_alone_gives_the_weights_moments() {
    let spec = case("healy_ffwt_flare10_aoa0.json", &["static.airspeeds=[0.001]", "joints.1.locked=true"]);
    let g = 9.80665;
    let masses = [(20.3e-3, 0.017), (29.6e-3, 0.155), (29.6e-3, 0.255), (23.0e-3, 0.328), (61.0e-3, 0.424)];
    let rbm = -masses.iter().map(|(m, x)| m * g * x).sum::<f64>()
        - 0.2592 * g * 0.365f64.powi(2) / 2.0
        - 0.02592 * g * (0.5f64.powi(2) - 0.365f64.powi(2)) / 2.0;
    for f in Formulation::ALL {
        let p = &run_static(&spec.case(f).problem(), f).points[0];
        // The spar sags by a few millimetres: its moment arms shorten by less than 1e-4.
        assert!(
            (p.loads.root_bending_moment - rbm).abs() < 1e-4 * rbm.abs(),
            "{f}: {} vs {rbm}",
            p.loads.root_bending_moment
        );
        assert!(p.loads.root_torque > 0.0, "{f}: masses behind the spar pitch the wing nose-up");
    }
}

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

#[test]
fn bad_static_input_exits_2_naming_the_field() {
    let c = "cases/healy_ffwt_flare10_aoa5.json";
    for (set, needle) in [
        ("static.airspeeds=[]", "static.airspeeds"),
        ("static.airspeeds=[12,-3]", "static.airspeeds[1]"),
        ("static.airspeeds=[12,\"NaN\"]", "static.airspeeds[1]"),
        ("pitch_deg=95", "pitch_deg"),
        ("aero.airspeed=-1", "aero.airspeed"),
        (r#"static.wake={"row_length":0.25,"rows":0}"#, "static.wake.rows"),
        (r#"static.wake={"row_length":-1,"rows":40}"#, "static.wake.row_length"),
        (r#"static.wake={"row_length":"NaN","rows":40}"#, "static.wake.row_length"),
    ] {
        let o = harness(&["static", c, "--set", set, "--out", std::env::temp_dir().to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{set}: {err}");
    }
    // A static sweep without aerodynamics.
    let dir = std::env::temp_dir().join(format!("harness-static-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("cases/double_pendulum_c1_beta45.json")).unwrap())
            .unwrap();
    v["static"] = serde_json::json!({"airspeeds": [10]});
    let p = dir.join("no_aero.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let o = harness(&["static", p.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("static") && err.contains("aero"), "{err}");
    // A case without a static block.
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("cases/wing_aoa5.json")).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("static");
    let p = dir.join("no_static.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let o = harness(&["static", p.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("static"));
}

/// `pitch_deg` is the rotation the hand-written section axes used to encode: the paper's wing
/// at 5° written both ways gives one scene.
#[test]
fn pitch_rotates_the_scene_nose_up() {
    let a = case("wing_aoa5.json", &[]);
    let b = case("wing_aoa5.json", &["bodies.0.y_axis=[0,1,0]", "bodies.1.y_axis=[0,1,0]", "pitch_deg=5"]);
    let (sa, sb) = (a.ancf.scene(Formulation::Ancf), b.ancf.scene(Formulation::Ancf));
    for (x, y) in sa.bodies.iter().zip(&sb.bodies) {
        assert!((x.frame - y.frame).norm() < 1e-12 && (x.start - y.start).norm() < 1e-12);
    }
    // Leading edge (+y) up.
    assert!(sb.bodies[0].frame[(2, 1)] > 0.08);
}

/// Issue 20: the steady-wake static solution of the paper wing sits 0.8–1.7 % above the mean tip
/// height of its time histories, whose 40-row unclosed wake carries about 1.3 % less lift. With
/// the run's own wake as the static wake (`static.wake`: 40 rows of 25 m/s × 0.01 s, unclosed),
/// the static solution meets the mean of the 20 s GEBF run at AoA 5° over its second half within
/// 0.2 % in tip height and 0.1° in fold (the whole run: about 6 s release on one core).
#[test]
fn static_with_the_runs_wake_meets_the_time_history_mean() {
    let spec = case("wing_aoa5.json", &[]);
    let f = Formulation::Gebf;
    let run = run_formulation(spec.case(f), f);
    assert!(run.error.is_none(), "{:?}", run.error);
    let mut summary = harness::static_out::summarise(
        spec.case(f),
        &root().join("cases"),
        vec![run_static(&spec.case(f).problem(), f)],
    );
    harness::static_out::compare_with_history(&mut summary, &spec, std::slice::from_ref(&run));
    let c = &summary.history[0];
    println!("{c:#?}");
    assert_eq!((c.run_wake.rows, c.run_wake.closure), (40, false));
    assert!((c.run_wake.row_length - 0.25).abs() < 1e-12);
    assert!(c.run_wake_error.is_none(), "{:?}", c.run_wake_error);
    assert!(
        c.run_wake_tip_z_relative_difference.abs() <= 2e-3,
        "tip {:+.4} %",
        100.0 * c.run_wake_tip_z_relative_difference
    );
    assert!(c.run_wake_fold_difference_deg.abs() <= 0.1, "fold {:+.4}°", c.run_wake_fold_difference_deg);
    // The steady-wake solution stays where it was, further from the mean.
    assert!(c.tip_z_relative_difference.abs() > 2.0 * c.run_wake_tip_z_relative_difference.abs());
}

/// The model held at a measured coast angle (docs/statics.md §7) reads a known difference back.
/// The "measurement" is the flare 10° case's own equilibrium at 27 m/s with the root pitched
/// 2° lower: held there, the 5° model's tip has a fold-up moment that a root pitch change of
/// −2° cancels (within 0.05°: the secant's error); held at its own equilibrium, none (below
/// 1e-5 N·m, its spring's 1e-4 N·m/rad included), nor with a 0.05 N·m/rad spring. Both
/// formulations.
#[test]
fn holding_the_tip_at_a_measured_angle_recovers_a_pitch_difference() {
    let spec = case("healy_ffwt_flare10_aoa5.json", &["static.airspeeds=[27]"]);
    let lower = case("healy_ffwt_flare10_aoa5.json", &["static.airspeeds=[27]", "pitch_deg=3"]);
    for f in Formulation::ALL {
        let own = run_static(&spec.case(f).problem(), f).points[0].fold_deg;
        let measured = run_static(&lower.case(f).problem(), f).points[0].fold_deg;
        assert!(own - measured > 5.0, "{f}: {own} vs {measured}");
        let at_own = harness::static_hold::hold(&spec.case(f).problem(), f, 27.0, own);
        assert!(at_own.error.is_none(), "{:?}", at_own.error);
        assert!(at_own.hinge_moment.abs() < 1e-5, "{f}: {at_own:?}");
        let held = harness::static_hold::hold(&spec.case(f).problem(), f, 27.0, measured);
        println!("{held:?}");
        assert!(held.error.is_none(), "{:?}", held.error);
        assert!((held.fold_deg - measured).abs() < 1e-3, "{f}: held at {} for {measured}", held.fold_deg);
        assert!(held.hinge_moment > 0.0 && held.pitch_sensitivity > 0.0, "{f}: {held:?}");
        assert!((held.equivalent_pitch_deg + 2.0).abs() < 0.05, "{f}: {held:?}");
    }
    // A sprung hinge (its spring carries 0.011 N·m here): held at its own equilibrium, still none.
    let sprung = case(
        "healy_ffwt_flare10_aoa5.json",
        &["static.airspeeds=[27]", "joints.1.spring.stiffness=0.05", "joints.1.spring.rest_deg=3"],
    );
    for f in Formulation::ALL {
        let own = run_static(&sprung.case(f).problem(), f).points[0].fold_deg;
        let at_own = harness::static_hold::hold(&sprung.case(f).problem(), f, 27.0, own);
        assert!(at_own.hinge_moment.abs() < 1e-5, "{f}: {own} {at_own:?}");
    }
}

/// `harness static` holds the model at the experiment's coast angles inside the sweep's range:
/// `held` in `static_summary.json` (one entry per experiment airspeed from 24 to 33 m/s) and
/// its table in the report section.
#[test]
fn harness_static_reports_the_model_held_at_the_experiment() {
    let dir = std::env::temp_dir().join(format!("flexmb-held-{}", std::process::id()));
    let o = harness(&[
        "static",
        "cases/healy_ffwt_flare30_aoa10.json",
        "--formulation",
        "gebf",
        "--set",
        "static.airspeeds=[24,33]",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let run = dir.join("healy_ffwt_flare30_aoa10");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("static_summary.json")).unwrap()).unwrap();
    let held = v["held"].as_array().unwrap();
    let speeds: Vec<f64> = held.iter().map(|h| h["airspeed"].as_f64().unwrap()).collect();
    assert_eq!(speeds, [24.0, 27.0, 30.0, 33.0]);
    for h in held {
        assert!(h.get("error").is_none(), "{h}");
        let (coast, fold) = (h["coast_deg"].as_f64().unwrap(), h["fold_deg"].as_f64().unwrap());
        assert!((coast - fold).abs() < 1e-3, "{h}");
        assert!(h["equivalent_pitch_deg"].as_f64().unwrap().is_finite(), "{h}");
    }
    let section = std::fs::read_to_string(run.join("static_section.html")).unwrap();
    assert!(section.contains("equivalent pitch"), "{section}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 38: after ANCF failed at every airspeed the summary printed "RMS error against
/// Experiment … = NaN deg" and "ANCF-GEBF max fold difference NaN deg". With ANCF's wing made
/// a millionth as stiff (`ancf:stiffness_scale`), its lattice folds over and no airspeed has an
/// equilibrium: the sweep exits 1, and stdout, stderr, `static_summary.json` and the report's
/// section name the formulation, its airspeeds and the reason, never NaN.
#[test]
fn a_failed_formulation_is_named_never_nan_issue_38() {
    let dir = std::env::temp_dir().join(format!("harness-static-nan-{}", std::process::id()));
    let o = harness(&[
        "static",
        "cases/healy_ffwt_flare10_aoa5.json",
        "--set",
        "ancf:stiffness_scale=1e-6",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(1), "{out}\n{err}");
    let case_dir = std::fs::read_dir(&dir).unwrap().next().unwrap().unwrap().path();
    let json = std::fs::read_to_string(case_dir.join("static_summary.json")).unwrap();
    let html = std::fs::read_to_string(case_dir.join("static_section.html")).unwrap();
    for (what, text) in [("stdout", &*out), ("stderr", &*err), ("static_summary.json", &json), ("section", &html)] {
        assert!(!text.contains("NaN"), "{what} shows NaN:\n{text}");
    }
    assert!(err.contains("ANCF failed at 12 of 12 airspeeds (12, 13, 14,"), "{err}");
    assert!(out.contains("ancf: no RMS error against Experiment"), "{out}");
    assert!(out.contains("ANCF-GEBF: no comparison"), "{out}");
    assert!(html.contains("FAILED: ANCF failed at 12 of 12 airspeeds"), "{html}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["failures"][0]["formulation"], "ancf");
    assert_eq!(v["failures"][0]["at"].as_array().unwrap().len(), 12);
    assert!(v["failures"].as_array().unwrap().len() == 1, "GEBF converges: {}", v["failures"]);
    assert!(v["max_fold_difference_deg"].is_null());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Near-rigid shear in ANCF statics, issue 38: Healy's flare 10°, pitch 5° wing with
/// GA = 1e8 and 1e9 N (the case has 2.16e6; EI_yy = 12.9 N·m², so GA/EI_yy up to 7.8e7 1/m²)
/// converges at all 12 airspeeds with the fold within 0.01° of GEBF's; the Goland wing with its
/// 1e9 N shear (GA/EI_yy = 102 1/m²) at 3° incidence, 100 and 150 m/s, within 0.5 % of GEBF's
/// tip deflection. Newton starts with the exact tangent and falls back on the matrix at rest
/// only where that fails (docs/ancf.md §9).
#[test]
fn near_rigid_shear_statics_converge_issue_38() {
    for ga in ["1e8", "1e9"] {
        let set: Vec<String> =
            (0..2).flat_map(|b| ["ga_y", "ga_z"].map(|g| format!("bodies.{b}.section.{g}={ga}"))).collect();
        let set: Vec<&str> = set.iter().map(|s| s.as_str()).collect();
        let spec = case("healy_ffwt_flare10_aoa5.json", &set);
        let a = run_static(&spec.ancf.problem(), Formulation::Ancf);
        let g = run_static(&spec.gebf.problem(), Formulation::Gebf);
        assert_eq!(a.points.len(), 12);
        for (pa, pg) in a.points.iter().zip(&g.points) {
            assert!(
                pa.error.is_none() && pg.error.is_none(),
                "GA {ga}, {} m/s: {:?} {:?}",
                pa.airspeed,
                pa.error,
                pg.error
            );
            let df = (pa.fold_deg - pg.fold_deg).abs();
            println!(
                "Healy GA {ga}, {} m/s: fold ANCF {:.5} GEBF {:.5} deg, {df:.1e}",
                pa.airspeed, pa.fold_deg, pg.fold_deg
            );
            assert!(df < 0.01, "GA {ga}, {} m/s: fold {} vs {}", pa.airspeed, pa.fold_deg, pg.fold_deg);
        }
    }
    let spec = case("goland_flutter.json", &["pitch_deg=3", "static={\"airspeeds\":[100,150]}"]);
    let a = run_static(&spec.ancf.problem(), Formulation::Ancf);
    let g = run_static(&spec.gebf.problem(), Formulation::Gebf);
    for (pa, pg) in a.points.iter().zip(&g.points) {
        assert!(pa.error.is_none() && pg.error.is_none(), "Goland {} m/s: {:?} {:?}", pa.airspeed, pa.error, pg.error);
        let (za, zg) = (pa.tip[2], pg.tip[2]);
        println!("Goland {} m/s: tip z ANCF {za:.5} GEBF {zg:.5} m", pa.airspeed);
        assert!(zg.abs() > 1e-3 && (za - zg).abs() < 5e-3 * zg.abs(), "Goland {} m/s: tip z {za} vs {zg}", pa.airspeed);
    }
}

/// The time march with near-rigid shear, issue 38: the paper's wing at AoA 5° (impulsive start,
/// 25 m/s, gravity), GA = 1e9 N instead of 5e6, 1 s. ANCF's tip stays within 1 % of the peak
/// tip excursion of GEBF's at the same shear and of its own at the case's shear (measured over
/// 2 s: 0.69 mm and 0.33 mm of a 3.69 m peak; 5.2 Newton iterations per step).
#[test]
fn near_rigid_shear_time_march_issue_38() {
    let stiff: Vec<String> =
        (0..2).flat_map(|b| ["ga_y", "ga_z"].map(|g| format!("bodies.{b}.section.{g}=1e9"))).collect();
    let mut set: Vec<&str> = stiff.iter().map(|s| s.as_str()).collect();
    set.push("t_end=1");
    let spec = case("wing_aoa5.json", &set);
    let a = run_formulation(&spec.ancf, Formulation::Ancf);
    let g = run_formulation(&spec.gebf, Formulation::Gebf);
    let a0 = run_formulation(&case("wing_aoa5.json", &["t_end=1"]).ancf, Formulation::Ancf);
    for r in [&a, &g, &a0] {
        assert!(r.error.is_none(), "{}: {:?}", r.formulation, r.error);
    }
    assert!(a.rows.len() == g.rows.len() && a.rows.len() == a0.rows.len() && a.rows.len() > 50);
    let peak = g.rows.iter().map(|r| r.tip[2].abs()).fold(0.0, f64::max);
    let diff = |x: &[harness::run::Row], y: &[harness::run::Row]| {
        x.iter().zip(y).map(|(p, q)| (p.tip[2] - q.tip[2]).abs()).fold(0.0, f64::max)
    };
    let (dg, d0) = (diff(&a.rows, &g.rows), diff(&a.rows, &a0.rows));
    println!("GA 1e9 march: peak tip z {peak:.3} m; ANCF-GEBF {dg:.2e} m; ANCF GA 1e9 - 5e6 {d0:.2e} m");
    assert!(peak > 0.5 && dg < 0.01 * peak && d0 < 0.01 * peak, "peak {peak}, {dg}, {d0}");
}
