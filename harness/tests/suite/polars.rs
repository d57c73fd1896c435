//! Section polars in the static analysis and the time march (issue 37): a linear polar
//! reproduces the lattice, a high-aspect-ratio wing follows a stalling table, ANCF and GEBF agree
//! with the NACA 0015 polar, and bad `aero.polars` input is named.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use crate::common::root;
use harness::case::{CaseFile, Formulation, Override, RunSpec};
use harness::run::{Row, RunOutput};
use harness::scene::run_formulation;
use harness::statics::{aero_stiffness_check, run_static};

pub(crate) fn expand(path: &Path, set: &[String]) -> Result<RunSpec, String> {
    let ov: Vec<Override> = set.iter().map(|s| s.parse().unwrap()).collect();
    CaseFile::read(path).map_err(|e| e.to_string())?.expand(&ov).map(|mut v| v.remove(0)).map_err(|e| e.to_string())
}

fn healy(set: &[String]) -> Result<RunSpec, String> {
    expand(&root().join("cases/healy_ffwt_flare10_aoa5.json"), set)
}

/// A scratch folder for this test's files.
pub(crate) fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb_polars_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A polar CSV of `f(α) → (cl, cd, cm)` at whole degrees over [−30°, 30°].
pub(crate) fn write_polar(path: &Path, f: impl Fn(f64) -> (f64, f64, f64)) {
    let mut s = String::from("alpha_deg,cl,cd,cm\n");
    for d in -30..=30 {
        let (cl, cd, cm) = f(f64::from(d).to_radians());
        s.push_str(&format!("{d},{cl:.17e},{cd:.17e},{cm:.17e}\n"));
    }
    std::fs::write(path, s).unwrap();
}

pub(crate) fn polars_set(file: &Path, bodies: &str) -> String {
    format!(r#"aero.polars=[{{"bodies":{bodies},"file":"{}"}}]"#, file.display())
}

pub(crate) fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// cl = 2πα, cd = cm = 0 on every body: the static outputs equal the uncorrected lattice's
/// within 1e-9 relative (fold angle, tip, root and hinge loads, lift; drag is the lattice's
/// induced drag in both).
#[test]
fn a_linear_polar_reproduces_the_lattice_statics() {
    let dir = scratch("linear");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    let base = ["static.airspeeds=[16.5,27]".to_string(), "aero.panels_per_body=[16,6]".to_string()];
    let plain = healy(&base).unwrap();
    let mut set = base.to_vec();
    set.push(polars_set(&file, "[0,1]"));
    let corrected = healy(&set).unwrap();
    for f in Formulation::ALL {
        let a = run_static(&plain.case(f).problem(), f);
        let b = run_static(&corrected.case(f).problem(), f);
        for (p, q) in a.points.iter().zip(&b.points) {
            assert!(p.error.is_none() && q.error.is_none(), "{f}: {:?} {:?}", p.error, q.error);
            let pairs = [
                ("fold", p.fold_deg, q.fold_deg),
                ("tip z", p.tip[2], q.tip[2]),
                ("RBM", p.loads.root_bending_moment, q.loads.root_bending_moment),
                ("torque", p.loads.root_torque, q.loads.root_torque),
                ("hinge moment", p.loads.hinge_moment, q.loads.hinge_moment),
                ("lift", p.lift, q.lift),
                ("drag", p.drag, q.drag),
            ];
            for (what, x, y) in pairs {
                println!("{f} {} m/s {what}: {x:.12e} vs {y:.12e} ({:.1e})", p.airspeed, rel(y, x));
                assert!(rel(y, x) < 1e-9, "{f} {} m/s {what}: {x} vs {y}", p.airspeed);
            }
        }
    }
}

/// The stalling table: slope 5.9/rad up to 10°, then the lift falls by 0.04 per degree; cd
/// grows with α², cm −0.02.
pub(crate) fn stalling(a: f64) -> (f64, f64, f64) {
    let stall = 10f64.to_radians();
    let cl =
        if a.abs() <= stall { 5.9 * a } else { a.signum() * (5.9 * stall - 0.04 * (a.abs() - stall).to_degrees()) };
    (cl, 0.01 + 0.5 * a * a, -0.02)
}

/// A stiff clamped wing of aspect ratio 20 (2 m span, 0.1 m chord, 40 × 6 panels) at 2°, 8° and
/// 14° root pitch with a table that stalls at 10°: the mid-span strip's lift coefficient (of the
/// corrected loads) is within 2 % of the table's at the strip's effective incidence.
#[test]
fn a_high_aspect_ratio_wing_follows_its_polar() {
    let dir = scratch("ar20");
    let polar = dir.join("stall10.csv");
    write_polar(&polar, stalling);
    let table = aerofoil::read_polar(&polar).unwrap();
    let case = dir.join("ar20.json");
    std::fs::write(&case, AR20_CASE).unwrap();
    for pitch in [2.0, 8.0, 14.0] {
        let set = [format!("pitch_deg={pitch}"), polars_set(&polar, "[0]")];
        let spec = expand(&case, &set).unwrap();
        let out = run_static(&spec.gebf.problem(), Formulation::Gebf);
        let p = &out.points[0];
        assert!(p.error.is_none(), "{pitch}°: {:?}", p.error);
        let mid = p.strips.iter().min_by(|a, b| (a.s - 1.0).abs().total_cmp(&(b.s - 1.0).abs())).unwrap();
        let want = table.coefficients(mid.alpha, 20.0 * 0.1 / 1.5e-5).unwrap().cl;
        println!(
            "{pitch}°: mid-span α_e {:.4}°, cl {:.5}, table {want:.5} ({:+.3} %)",
            mid.alpha.to_degrees(),
            mid.cl,
            100.0 * (mid.cl - want) / want
        );
        assert!(rel(mid.cl, want) < 0.02, "{pitch}°: cl {} vs the table's {want}", mid.cl);
        // The effective incidence is below the geometric one (the wake's downwash), and at 14°
        // past the table's stall.
        assert!(mid.alpha.to_degrees() < pitch && mid.alpha.to_degrees() > 0.9 * pitch, "{pitch}°: {}", mid.alpha);
    }
}

/// The static outputs split the drag: on the stiff AR-20 wing (stiffer still in its plane) at 2°
/// with cl = 2πα, cd = 0.012 and cm = 0, `profile_drag` is `cd q c b` (the strips' section-plane
/// flow is the free stream on an unswept wing) and `induced_drag` is the uncorrected lattice's
/// drag, both within 1e-9 relative (measured 7.1e-12 and 4.7e-11); without polars
/// `profile_drag` is zero.
#[test]
fn the_static_drag_splits_into_profile_and_induced() {
    let dir = scratch("drag_split");
    let polar = dir.join("drag.csv");
    write_polar(&polar, |a| (2.0 * PI * a, 0.012, 0.0));
    let case = dir.join("ar20.json");
    std::fs::write(&case, AR20_CASE).unwrap();
    let solve = |set: &[String]| {
        let spec = expand(&case, set).unwrap();
        let out = run_static(&spec.gebf.problem(), Formulation::Gebf);
        let p = out.points[0].clone();
        assert!(p.error.is_none(), "{:?}", p.error);
        p
    };
    // The drag bends the wing in its plane, which moves its lattice and so its induced drag: by
    // 1.4e-9 of it with the case's EI_zz of 1e7 N·m², by 4.7e-11 with 1e9.
    let mut a = vec!["pitch_deg=2".to_string(), "bodies.0.section.ei_zz=1e9".to_string()];
    let plain = solve(&a);
    a.push(polars_set(&polar, "[0]"));
    let drag = solve(&a);
    let want = 0.012 * 0.5 * 1.225 * 20.0 * 20.0 * 0.1 * 2.0;
    println!(
        "profile {:.12e} N (cd q c b {want:.12e}, {:.1e}); induced {:.12e} vs the lattice's {:.12e} ({:.1e}); without polars {:e}",
        drag.profile_drag,
        rel(drag.profile_drag, want),
        drag.drag - drag.profile_drag,
        plain.drag,
        rel(drag.drag - drag.profile_drag, plain.drag),
        plain.profile_drag
    );
    assert!(rel(drag.profile_drag, want) < 1e-9, "profile drag {} vs {want}", drag.profile_drag);
    assert!(rel(drag.drag - drag.profile_drag, plain.drag) < 1e-9, "induced {} vs {}", drag.drag, plain.drag);
    assert_eq!(plain.profile_drag, 0.0);
}

pub(crate) const AR20_CASE: &str = r#"{
  "name": "ar20_polar",
  "bodies": [{ "name": "wing", "start": [0, 0, 0], "length": 2.0,
    "section": { "mass": 0.5, "rho_ixx": 1e-4, "rho_iyy": 1e-5, "rho_izz": 1e-4, "ea": 1e9, "ga_y": 1e9,
      "ga_z": 1e9, "gj": 1e6, "ei_yy": 1e6, "ei_zz": 1e7 } }],
  "joints": [{ "type": "clamp", "name": "root", "body": "wing" }],
  "t_end": 0.1,
  "ancf": { "elements_per_body": [6], "dt": 0.001 },
  "gebf": { "elements_per_body": [6], "dt": 0.001 },
  "aero": { "rho": 1.225, "airspeed": 20.0, "chord": 0.1, "le_offset": 0.025, "panels_per_body": [40],
    "n_chordwise": 6, "n_wake_rows": 20 },
  "static": { "airspeeds": [20] }
}"#;

/// ANCF and GEBF reach one equilibrium on the Healy flare-10° wing with the NACA 0015 polar:
/// coast angle within 0.01°, root bending moment within 0.1 %.
#[test]
fn both_formulations_agree_with_the_naca0015_polar() {
    let file = root().join("cases/polars/naca0015_neuralfoil.csv");
    let set = ["static.airspeeds=[16.5,24,30]".to_string(), polars_set(&file, "[0,1]")];
    let spec = healy(&set).unwrap();
    let a = run_static(&spec.ancf.problem(), Formulation::Ancf);
    let g = run_static(&spec.gebf.problem(), Formulation::Gebf);
    for (pa, pg) in a.points.iter().zip(&g.points) {
        assert!(pa.error.is_none() && pg.error.is_none(), "{:?} {:?}", pa.error, pg.error);
        let (ra, rg) = (pa.loads.root_bending_moment, pg.loads.root_bending_moment);
        println!(
            "{} m/s: fold {:.5}° vs {:.5}°, RBM {ra:.6} vs {rg:.6} ({:+.4} %)",
            pa.airspeed,
            pa.fold_deg,
            pg.fold_deg,
            100.0 * (ra - rg) / rg
        );
        assert!(
            (pa.fold_deg - pg.fold_deg).abs() < 0.01,
            "{} m/s: fold {} vs {}",
            pa.airspeed,
            pa.fold_deg,
            pg.fold_deg
        );
        assert!(rel(ra, rg) < 1e-3, "{} m/s: RBM {ra} vs {rg}", pa.airspeed);
    }
}

/// The static solver's tangent with polars (issue 37, docs/statics.md §2): the analytic
/// aerodynamic stiffness at the equilibrium equals central differences of the generalised
/// aerodynamic load (a steady solve and the polar correction on each side) at steps of 1e-5 and
/// 1e-6 of the span within 1e-7 of its largest entry (measured 1.3e-9 – 2.6e-8), and at 1e-4
/// within 3e-5 (measured 1.6e-6 – 8.8e-6: the differences' truncation) — on the AR-20 wing at
/// 14° with the table stalling at 10° (GEBF), and on the Healy wing (flare 10°, pitch 5°) at
/// 24 m/s with the NACA 0015 polar (both formulations).
#[test]
fn the_static_tangent_with_polars_matches_differences() {
    let steps = [1e-4, 1e-5, 1e-6];
    let dir = scratch("tangent");
    let polar = dir.join("stall10.csv");
    write_polar(&polar, stalling);
    let case = dir.join("ar20.json");
    std::fs::write(&case, AR20_CASE).unwrap();
    let ar20 = expand(&case, &["pitch_deg=14".to_string(), polars_set(&polar, "[0]")]).unwrap();
    let file = root().join("cases/polars/naca0015_neuralfoil.csv");
    let healy24 = healy(&["static.airspeeds=[24]".to_string(), polars_set(&file, "[0,1]")]).unwrap();
    let runs = [
        ("AR 20, 14°", ar20.gebf.problem(), Formulation::Gebf),
        ("Healy 24 m/s", healy24.gebf.problem(), Formulation::Gebf),
        ("Healy 24 m/s", healy24.ancf.problem(), Formulation::Ancf),
    ];
    for (name, problem, f) in runs {
        let worst = aero_stiffness_check(&problem, f, &steps).unwrap();
        println!("{name} {f}: worst difference over largest entry {worst:?} at steps {steps:?}");
        for (h, w) in steps.iter().zip(&worst) {
            let tol = if *h > 5e-5 { 3e-5 } else { 1e-7 };
            assert!(*w < tol, "{name} {f}: step {h:.0e}: {w:.2e}");
        }
    }
}

/// The analytic aerodynamic stiffness leads Newton to the difference tangent's equilibria:
/// Healy flare 10°, pitch 5°, 12 airspeeds, without and with the NACA 0015 polar, both
/// formulations: fold within 1e-9°, tip height and root bending moment within 1e-10 relative
/// (measured ≤ 4.9e-13°, 5.6e-14, 5.4e-14: Newton's tolerance), with 1.6–3.1 times fewer steady
/// solves (one derivative in place of one solve per unknown).
#[test]
fn the_analytic_static_tangent_keeps_the_equilibria() {
    let file = root().join("cases/polars/naca0015_neuralfoil.csv");
    for set in [vec![], vec![polars_set(&file, "[0,1]")]] {
        let spec = healy(&set).unwrap();
        for f in Formulation::ALL {
            let analytic = spec.case(f).problem();
            let mut difference = analytic.clone();
            if let Some(st) = difference.statics.as_mut() {
                st.difference_tangent = true;
            }
            let (a, d) = (run_static(&analytic, f), run_static(&difference, f));
            let (mut fold, mut tip, mut rbm) = (0.0f64, 0.0f64, 0.0f64);
            for (p, q) in a.points.iter().zip(&d.points) {
                assert!(p.error.is_none() && q.error.is_none(), "{f}: {:?} {:?}", p.error, q.error);
                fold = fold.max((p.fold_deg - q.fold_deg).abs());
                tip = tip.max(rel(p.tip[2], q.tip[2]));
                rbm = rbm.max(rel(p.loads.root_bending_moment, q.loads.root_bending_moment));
            }
            println!(
                "{f} {}: fold {fold:.1e}°, tip z {tip:.1e}, RBM {rbm:.1e}; solves {} vs {}, tangents {} vs {}",
                if set.is_empty() { "lattice" } else { "NACA 0015" },
                a.n_aero_solves,
                d.n_aero_solves,
                a.n_tangents,
                d.n_tangents
            );
            assert!(fold < 1e-9 && tip < 1e-10 && rbm < 1e-10, "{f}: fold {fold}, tip {tip}, RBM {rbm}");
        }
    }
}

/// Bad `aero.polars` input is refused at expansion (exit 2 in the CLI), naming the field.
#[test]
fn bad_polar_input_names_the_field() {
    let dir = scratch("bad");
    let good = root().join("cases/polars/naca0015_neuralfoil.csv");
    let unsorted = dir.join("unsorted.csv");
    std::fs::write(&unsorted, "alpha_deg,cl,cd,cm\n0,0,0.01,0\n2,0.2,0.01,0\n1,0.1,0.01,0\n").unwrap();
    let nonfinite = dir.join("nonfinite.csv");
    std::fs::write(&nonfinite, "alpha_deg,cl,cd,cm\n0,0,0.01,0\n1,NaN,0.01,0\n").unwrap();
    let short = dir.join("short.csv");
    std::fs::write(&short, "alpha_deg,cl,cd,cm\n0,0,0.01,0\n").unwrap();
    let cases = [
        (polars_set(&dir.join("missing.csv"), "[0]"), "aero.polars[0].file"),
        (polars_set(&unsorted, "[0]"), "aero.polars[0].file"),
        (polars_set(&nonfinite, "[0]"), "aero.polars[0].file"),
        (polars_set(&short, "[0]"), "aero.polars[0].file"),
        (polars_set(&good, "[0,2]"), "aero.polars[0].bodies[1]"),
        (polars_set(&good, "[0,0]"), "aero.polars[0].bodies[1]"),
    ];
    for (set, field) in cases {
        let e = healy(std::slice::from_ref(&set)).expect_err(&set);
        println!("{e}");
        assert!(e.contains(field), "{set}: {e}");
    }
    // 12 m/s is Re 6.2e4, inside; 40 m/s is Re 2.1e5, above the table's 2e5.
    let e = healy(&["static.airspeeds=[12,40]".into(), polars_set(&good, "[0,1]")]).unwrap_err();
    assert!(e.contains("aero.polars[0].file") && e.contains("40 m/s") && e.contains("bounds.re"), "{e}");
    let clamp = format!(r#"aero.polars=[{{"bodies":[0,1],"file":"{}","bounds":{{"re":"clamp"}}}}]"#, good.display());
    assert!(healy(&["static.airspeeds=[12,40]".into(), clamp]).is_ok());
}

/// The columns of a time-history row that the march's comparisons check.
fn columns(r: &Row) -> [(&'static str, f64); 12] {
    [
        ("tip x", r.tip[0]),
        ("tip y", r.tip[1]),
        ("tip z", r.tip[2]),
        ("fold", r.fold),
        ("kinetic", r.kinetic),
        ("elastic", r.elastic),
        ("total", r.total),
        ("aero_work", r.aero_work),
        ("lift", r.lift),
        ("RBM", r.root_bending_moment),
        ("torque", r.root_torque),
        ("hinge moment", r.hinge_moment),
    ]
}

/// The largest difference of every column of [`columns`] of `b` from `a` over the run.
fn worst_columns(a: &RunOutput, b: &RunOutput) -> Vec<(&'static str, f64)> {
    worst_of(a, b, columns)
}

/// The largest difference of every column that `columns` picks from a row of `b` from `a` over
/// the run, relative to the column's largest magnitude in `a`.
pub(crate) fn worst_of<const N: usize>(
    a: &RunOutput,
    b: &RunOutput,
    columns: fn(&Row) -> [(&'static str, f64); N],
) -> Vec<(&'static str, f64)> {
    assert_eq!(a.rows.len(), b.rows.len());
    (0..N)
        .map(|k| {
            let scale = a.rows.iter().map(|r| columns(r)[k].1.abs()).fold(0.0, f64::max).max(1e-300);
            let diff =
                a.rows.iter().zip(&b.rows).map(|(x, y)| (columns(x)[k].1 - columns(y)[k].1).abs()).fold(0.0, f64::max);
            (columns(&a.rows[0])[k].0, diff / scale)
        })
        .collect()
}

/// cl = 2πα, cd = cm = 0 on both Healy bodies in the time march (impulsive start, 0.2 s, 4
/// coupling sub-iterations): every output column (tip, fold, energies, aerodynamic work, lift,
/// root and hinge loads) equals the uncorrected lattice's within 1e-9 of its largest magnitude,
/// with both formulations. The hinge moment of the free hinge is the spring's k θ, about 1e-4 of
/// the aerodynamic, gravity and inertial moments that cancel to it, so rounding alone moves it
/// by more: control runs without polars whose density differs by −2, 2 and 4 units in the last
/// place move it by up to 1e-7 of its peak, and it is held within twice the largest control
/// difference. Newton's tolerances are tightened (rtol 1e-13, atol 1e-15) so that its stopping
/// point does not add to that floor.
#[test]
fn a_linear_polar_reproduces_the_lattice_time_march() {
    let dir = scratch("linear_march");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    // The wake summed exactly: the comparison is at the rounding floor, below the 1e-6 |V∞|
    // of the default mixed-precision far wake (docs/uvlm.md §14).
    let mut base = vec![
        "t_end=0.2".to_string(),
        "aero.panels_per_body=[16,6]".to_string(),
        "aero.wake_aggregation=false".to_string(),
    ];
    for f in ["ancf", "gebf"] {
        base.push(format!("{f}.newton.rtol=1e-13"));
        base.push(format!("{f}.newton.atol=1e-15"));
    }
    let plain = healy(&base).unwrap();
    let mut set = base.to_vec();
    set.push(polars_set(&file, "[0,1]"));
    let corrected = healy(&set).unwrap();
    for f in Formulation::ALL {
        let a = run_formulation(plain.case(f), f);
        let b = run_formulation(corrected.case(f), f);
        assert!(a.error.is_none() && b.error.is_none(), "{f}: {:?} {:?}", a.error, b.error);
        assert!(a.strips.is_empty() && !b.strips.is_empty());
        // The control: the uncorrected march with the density changed by −2, 2 and 4 units in
        // the last place, each column's largest difference of the three (one sample of the
        // rounding floor can fall well under the others).
        let rho = plain.case(f).problem().aero.as_ref().map(|x| x.rho).unwrap();
        let mut control = vec![0.0; worst_columns(&a, &a).len()];
        for k in [-2.0, 2.0, 4.0] {
            let set = format!("aero.rho={:.17e}", rho * (1.0 + k * f64::EPSILON));
            let nudged = healy(&[base.clone(), vec![set]].concat()).unwrap();
            for (c, (_, d)) in control.iter_mut().zip(worst_columns(&a, &run_formulation(nudged.case(f), f))) {
                *c = f64::max(*c, d);
            }
        }
        for ((what, d), floor) in worst_columns(&a, &b).into_iter().zip(control) {
            println!("{f} {what}: {d:.1e} (control {floor:.1e})");
            let limit = if what == "hinge moment" { 1e-9_f64.max(2.0 * floor) } else { 1e-9 };
            assert!(d < limit, "{f} {what}: {d:e} (control {floor:e})");
        }
    }
}
/// The AR-20 wing of the statics' test in the time march (impulsive start, 0.3 s = 60 chords
/// travelled, 200 wake rows): after the start has settled, the mid-span strip's lift coefficient
/// of the loads applied to the structure is within 2 % of the table's at its effective incidence
/// (the same check as the statics'), the effective incidence lies between 0.9 and 1 times the
/// geometric one, and the lift has stopped changing.
#[test]
fn a_high_aspect_ratio_wing_follows_its_polar_time_march() {
    let dir = scratch("ar20_march");
    let polar = dir.join("stall10.csv");
    write_polar(&polar, stalling);
    let table = aerofoil::read_polar(&polar).unwrap();
    let case = dir.join("ar20.json");
    std::fs::write(&case, AR20_CASE).unwrap();
    for pitch in [2.0, 8.0, 14.0] {
        let set = [
            format!("pitch_deg={pitch}"),
            polars_set(&polar, "[0]"),
            "t_end=0.3".into(),
            "aero.n_wake_rows=200".into(),
        ];
        let spec = expand(&case, &set).unwrap();
        let out = run_formulation(&spec.gebf, Formulation::Gebf);
        assert!(out.error.is_none(), "{pitch}°: {:?}", out.error);
        let mid = out.strips.iter().min_by(|a, b| (a.s - 1.0).abs().total_cmp(&(b.s - 1.0).abs())).unwrap();
        let want = table.coefficients(mid.alpha, 20.0 * 0.1 / 1.5e-5).unwrap().cl;
        // The lift's spread over the last 0.05 s, relative to its mean.
        let last = &out.rows[out.rows.len() - 50..];
        let (lo, hi) = last.iter().fold((f64::MAX, f64::MIN), |(a, b), r| (a.min(r.lift), b.max(r.lift)));
        let spread = (hi - lo) / (0.5 * (hi + lo));
        println!(
            "{pitch}°: mid-span α_e {:.4}°, cl {:.5}, table {want:.5} ({:+.3} %), lift {hi:.4} N (spread {spread:.1e})",
            mid.alpha.to_degrees(),
            mid.cl,
            100.0 * (mid.cl - want) / want,
        );
        assert!(rel(mid.cl, want) < 0.02, "{pitch}°: cl {} vs the table's {want}", mid.cl);
        assert!(mid.alpha.to_degrees() < pitch && mid.alpha.to_degrees() > 0.9 * pitch, "{pitch}°: {}", mid.alpha);
        assert!(spread < 1e-2, "{pitch}°: the lift still moves: {lo} – {hi} N");
    }
}

/// ANCF and GEBF march the Healy flare-10° wing with the NACA 0015 polar (impulsive start at
/// 20 m/s, 0.5 s, where the tip folds up by some 20°): tips within 1 mm and fold angles within
/// 0.05° at every output step (measured: 1.2 µm and 5e-4°).
#[test]
fn both_formulations_agree_with_the_naca0015_polar_time_march() {
    let file = root().join("cases/polars/naca0015_neuralfoil.csv");
    let set = ["t_end=0.5".to_string(), polars_set(&file, "[0,1]")];
    let spec = healy(&set).unwrap();
    let a = run_formulation(&spec.ancf, Formulation::Ancf);
    let g = run_formulation(&spec.gebf, Formulation::Gebf);
    assert!(a.error.is_none() && g.error.is_none(), "{:?} {:?}", a.error, g.error);
    let (mut tip, mut fold) = (0.0_f64, 0.0_f64);
    for (ra, rg) in a.rows.iter().zip(&g.rows) {
        let d = (0..3).map(|k| (ra.tip[k] - rg.tip[k]).powi(2)).sum::<f64>().sqrt();
        tip = tip.max(d);
        fold = fold.max((ra.fold - rg.fold).abs().to_degrees());
    }
    let last = a.rows.last().unwrap();
    println!("tip difference {:.3e} m, fold {fold:.3e}°; fold at the end {:.3}°", tip, last.fold.to_degrees());
    assert!(tip < 1e-3 && fold < 0.05, "tip {tip} m, fold {fold}°");
}

/// The marched gust starts from the statics' equilibrium with the polars: with a vanishing gust
/// (1e-9 m/s) on the Healy gust case with the NACA 0015 polar, the march stays there (its
/// steady start and every later solve are corrected as the statics' loads were): fold within
/// 1e-6° and root bending moment within 1e-5 of its static value over 0.2 s.
#[test]
fn the_marched_gust_holds_the_polars_equilibrium() {
    let file = root().join("cases/polars/naca0015_neuralfoil.csv");
    let set = ["t_end=0.2".to_string(), "aero.gust.velocity=1e-9".to_string(), polars_set(&file, "[0,1]")];
    let spec = expand(&root().join("cases/healy_ffwt_gust.json"), &set).unwrap();
    for f in Formulation::ALL {
        let h = harness::gust::gust_history(&spec.case(f).problem(), f, None).unwrap();
        assert!(h.error.is_none(), "{f}: {:?}", h.error);
        let inc = &h.increments;
        let fold = inc.delta_fold_deg.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let rbm = inc.delta_root_bending_moment.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let eq = &h.equilibrium;
        println!("{f}: fold {:.3}° (Δ {fold:.1e}°), RBM {:.4} N m (Δ {rbm:.1e})", eq.fold_deg, eq.root_bending_moment);
        assert!(fold < 1e-6 && rbm < 1e-5 * eq.root_bending_moment.abs(), "{f}: Δfold {fold}°, ΔRBM {rbm}");
        // The polar's equilibrium, not the lattice's (8.1° without polars).
        assert!(eq.fold_deg > 15.0, "{f}: {}", eq.fold_deg);
    }
}
