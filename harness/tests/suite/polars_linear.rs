//! Section polars in the linear analyses (issue 37, docs/section_aero.md §7.7): a linear polar
//! reproduces the lattice's stability roots and linear gust response, the polar's slope in the
//! linear model matches differences of the statics' corrected loads on a stalling table, and
//! ANCF and GEBF agree on the roots with the NACA 0015 polar.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use crate::common::root;
use aeroelastic::Problem;
use aeroelastic::factory::BuildModel;
use aeroelastic::polar_correction::StripPolars;
use harness::aero::station_map;
use harness::case::{CaseFile, Formulation, Override, RunSpec};
use harness::stability::{StabilityOutput, linear_wake, reduce, run_stability, static_stiffness_check, wake_settings};
use harness::statics::equilibrium_at;

fn expand(path: &Path, set: &[String]) -> RunSpec {
    let ov: Vec<Override> = set.iter().map(|s| s.parse().unwrap()).collect();
    CaseFile::read(path).unwrap().expand(&ov).map(|mut v| v.remove(0)).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb_polars_linear_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A polar CSV of `f(α) → (cl, cd, cm)` at whole degrees over [−30°, 30°].
fn write_polar(path: &Path, f: impl Fn(f64) -> (f64, f64, f64)) {
    let mut s = String::from("alpha_deg,cl,cd,cm\n");
    for d in -30..=30 {
        let (cl, cd, cm) = f(f64::from(d).to_radians());
        s.push_str(&format!("{d},{cl:.17e},{cd:.17e},{cm:.17e}\n"));
    }
    std::fs::write(path, s).unwrap();
}

fn polars_set(file: &Path, bodies: &str, bounds: &str) -> String {
    format!(r#"aero.polars=[{{"bodies":{bodies},"file":"{}"{bounds}}}]"#, file.display())
}

/// The Healy flare-10° wing with 16 + 6 panels and a stability block at 16.5 and 24 m/s.
fn healy_stability(extra: &[String]) -> RunSpec {
    let mut set = vec![
        "aero.panels_per_body=[16,6]".to_string(),
        r#"stability={"airspeeds":[16.5,24],"modes":4,"basis_modes":12}"#.to_string(),
    ];
    set.extend_from_slice(extra);
    expand(&root().join("cases/healy_ffwt_flare10_aoa5.json"), &set)
}

/// The density changes of the rounding controls, in units of `ε` (ulp-sized steps of 1.225).
/// Each control is one sample of how far rounding moves the analysis; the tests take the largest
/// of five, since one sample can fall several times under the others.
const NUDGES: [f64; 5] = [-4.0, -2.0, 2.0, 4.0, 8.0];

/// The override setting the density to 1.225 moved by `k ε`.
fn nudged_rho(k: f64) -> String {
    format!("aero.rho={:.17e}", 1.225 * (1.0 + k * f64::EPSILON))
}

/// Largest `|s_a − s_b| / |s_b|` over the tracked roots of every point (both converged).
fn root_difference(a: &StabilityOutput, b: &StabilityOutput) -> f64 {
    assert!(a.error.is_none() && b.error.is_none(), "{:?} {:?}", a.error, b.error);
    assert_eq!(a.points.len(), b.points.len());
    let mut worst = 0.0f64;
    for (p, q) in a.points.iter().zip(&b.points) {
        assert!(p.error.is_none() && q.error.is_none(), "{:?} {:?}", p.error, q.error);
        assert_eq!(p.roots.len(), q.roots.len());
        println!("{} m/s: fold {:.15}° vs {:.15}°", p.airspeed, p.fold_deg, q.fold_deg);
        for (x, y) in p.roots.iter().zip(&q.roots) {
            if !(x.converged && y.converged) {
                println!(
                    "{} m/s mode {}: not converged ({} {:+.6} {:+.6}i, {} {:+.6} {:+.6}i)",
                    p.airspeed, x.mode, x.converged, x.real, x.imag, y.converged, y.real, y.imag
                );
                continue;
            }
            let d = ((x.real - y.real).powi(2) + (x.imag - y.imag).powi(2)).sqrt();
            let rel = d / y.real.hypot(y.imag);
            println!(
                "{} m/s mode {}: {:+.9} {:+.9}i vs {:+.9} {:+.9}i 1/s ({rel:.1e})",
                p.airspeed, x.mode, x.real, x.imag, y.real, y.imag
            );
            worst = worst.max(rel);
        }
    }
    worst
}

/// The reduced models with and without `polars` about one equilibrium (the plain case's, at its
/// airspeed): each of the first four roots from the same start by Newton's method on both; the
/// largest relative difference.
fn same_equilibrium<M: BuildModel>(plain: &Problem, corrected: &Problem) -> f64 {
    let f = M::FORMULATION;
    let aero = plain.aero.as_ref().unwrap();
    let u = aero.speed();
    let map = station_map(plain, aero).unwrap();
    let p = equilibrium_at(plain, f, wake_settings(plain, f, u)).unwrap();
    let (q, lambda, mu) = p.state.unwrap();
    let wake = linear_wake(plain, f, u);
    let polars = StripPolars::of(corrected).unwrap();
    assert!(polars.is_some());
    let red = |pol: Option<&StripPolars>| {
        let model = M::build(plain).unwrap();
        reduce(model, &q, &lambda, &mu, (&map, aero, pol), &wake, (12, 0), None, None).unwrap()
    };
    let (a, b) = (red(None), red(polars.as_ref()));
    let mut worst = 0.0f64;
    for (s0, e0) in a.starts(4) {
        let mut n = 0;
        let (sa, _, oka) = a.newton(s0, e0.clone(), &mut n);
        let (sb, _, okb) = b.newton(s0, e0, &mut n);
        assert!(oka && okb);
        let rel = (sa - sb).norm() / sa.norm();
        println!("{f} about one equilibrium: {sa:.9} vs {sb:.9} 1/s ({rel:.1e})");
        worst = worst.max(rel);
    }
    worst
}

/// cl = 2πα, cd = cm = 0 on both bodies (Healy flare 10°, 16 + 6 panels):
/// * about one equilibrium (the plain case's at 20 m/s), the flutter equation with the polar's
///   correction gives the lattice's roots within 1e-9 relative;
/// * through the whole analysis (each its own statics, 16.5 and 24 m/s), the roots differ by as
///   much as the lattice's own when its density is changed by a few ulp (the control): GEBF's
///   under 1e-9, ANCF's fold root by a few 1e-9 (its equilibria differ by rounding, and its
///   soft fold mode sits on stiff axial and shear terms). The test holds them to 1e-9 or twice
///   the largest control, whichever is larger.
#[test]
fn a_linear_polar_reproduces_the_lattice_stability() {
    let dir = scratch("stab");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    let plain = healy_stability(&[]);
    let corrected = healy_stability(&[polars_set(&file, "[0,1]", "")]);
    let controls: Vec<RunSpec> = NUDGES.iter().map(|k| healy_stability(&[nudged_rho(*k)])).collect();
    for f in Formulation::ALL {
        let (p0, p1) = (plain.case(f).problem(), corrected.case(f).problem());
        let one = match f {
            Formulation::Ancf => same_equilibrium::<ancf::Model>(&p0, &p1),
            Formulation::Gebf => same_equilibrium::<gebf::Model>(&p0, &p1),
        };
        println!("{f}: about one equilibrium, largest relative root difference {one:.1e}");
        assert!(one < 1e-9, "{f}: {one:.2e}");
        let a = run_stability(&p0, f);
        let b = run_stability(&p1, f);
        let worst = root_difference(&b, &a);
        let worst_control = controls
            .iter()
            .map(|c| root_difference(&run_stability(&c.case(f).problem(), f), &a))
            .fold(0.0f64, f64::max);
        println!("{f}: whole analysis {worst:.1e}, control (ρ by −4, −2, 2, 4, 8 ulp) {worst_control:.1e}");
        assert!(worst < 1e-9_f64.max(2.0 * worst_control), "{f}: {worst:.2e} (control {worst_control:.2e})");
    }
}

/// Largest difference of the peak of each increment over that peak.
fn peak_difference(a: &harness::gust::Increments, b: &harness::gust::Increments) -> f64 {
    let series = |x: &harness::gust::Increments| {
        [
            x.delta_root_bending_moment.clone(),
            x.delta_root_torque.clone(),
            x.delta_hinge_moment.clone(),
            x.delta_fold_deg.clone(),
            x.delta_lift.clone(),
        ]
    };
    let peak = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (k, (x, y)) in series(a).iter().zip(series(b).iter()).enumerate() {
        let (px, py) = (peak(x), peak(y));
        let d = x.iter().zip(y).fold(0.0f64, |m, (p, q)| m.max((p - q).abs())) / py;
        println!("series {k}: peak {px:.9e} vs {py:.9e}, largest difference over the peak {d:.1e}");
        worst = worst.max(d);
    }
    worst
}

/// The linear polar in the linear gust model (Healy gust case, 16 + 6 panels, 0.15 s, the wake's
/// motion on): every increment equals the uncorrected lattice's within 1e-9 of its peak, or
/// within twice the lattice's own change when its density moves by 2 ulp (the control, as in the
/// stability test: the hinge moment, a small difference of large terms, moves by 1e-6 of its
/// 1e-5 N·m peak in both).
#[test]
fn a_linear_polar_reproduces_the_lattice_linear_gust() {
    let dir = scratch("gust");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    let base = ["aero.panels_per_body=[16,6]".to_string(), "t_end=0.15".to_string()];
    let case = root().join("cases/healy_ffwt_gust.json");
    let plain = expand(&case, &base);
    let mut set = base.to_vec();
    set.push(polars_set(&file, "[0,1]", ""));
    let corrected = expand(&case, &set);
    let f = Formulation::Gebf;
    let history = |spec: &RunSpec| {
        harness::gust_linear::linear_gust_history(&spec.case(f).problem(), f, Some(12), true).unwrap().increments
    };
    let a = history(&plain);
    let worst = peak_difference(&history(&corrected), &a);
    let mut worst_control = 0.0f64;
    for k in [-2.0, 2.0] {
        let mut set = base.to_vec();
        set.push(format!("aero.rho={:.17e}", 1.225 * (1.0 + k * f64::EPSILON)));
        worst_control = worst_control.max(peak_difference(&history(&expand(&case, &set)), &a));
    }
    println!("{f}: largest difference over the peak {worst:.1e}, control (ρ by ±2 ulp) {worst_control:.1e}");
    assert!(worst < 1e-9_f64.max(2.0 * worst_control), "{worst:.2e} (control {worst_control:.2e})");
}

/// A table of slope 5.9 that stalls at 10° (then −0.04 per degree), cd = 0.01 + α²/2, cm = −0.02.
fn stalling(a: f64) -> (f64, f64, f64) {
    let stall = 10f64.to_radians();
    let cl =
        if a.abs() <= stall { 5.9 * a } else { a.signum() * (5.9 * stall - 0.04 * (a.abs() - stall).to_degrees()) };
    (cl, 0.01 + 0.5 * a * a, -0.02)
}

const AR20_CASE: &str = r#"{
  "name": "ar20_polar",
  "bodies": [{ "name": "wing", "start": [0, 0, 0], "length": 2.0,
    "section": { "mass": 0.5, "rho_ixx": 1e-4, "rho_iyy": 1e-5, "rho_izz": 1e-4, "ea": 1e9, "ga_y": 1e9,
      "ga_z": 1e9, "gj": 50, "ei_yy": 2000, "ei_zz": 1e5 } }],
  "joints": [{ "type": "clamp", "name": "root", "body": "wing" }],
  "t_end": 0.1,
  "ancf": { "elements_per_body": [6], "dt": 0.001 },
  "gebf": { "elements_per_body": [6], "dt": 0.001 },
  "aero": { "rho": 1.225, "airspeed": 20.0, "chord": 0.1, "le_offset": 0.04, "panels_per_body": [20],
    "n_chordwise": 4, "n_wake_rows": 20, "wake_closure": true },
  "static": { "airspeeds": [20] }
}"#;

/// Largest entry of `a − b` over the largest of `b`.
fn matrix_difference(a: &nalgebra::DMatrix<f64>, b: &nalgebra::DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

/// The polar's slope in the linear model: on an AR-20 wing with the stalling table at 8° (slope
/// 5.9) and 14° (the strips past the stall, slope −2.3 /rad), the static aerodynamic stiffness of
/// the flutter equation (`D(0) − K` in 4 modes) equals central differences along each mode of
/// the generalised steady loads as the statics correct them (`StripPolars::correct`), and so
/// does the lattice's own without the polar (the control): within 1e-5 of the largest entry
/// (measured 1.9e-9 and 6.2e-7 with the polar; the polar changes the stiffness by 5 % and 131 %).
#[test]
fn the_polar_slope_in_the_linear_model_matches_differences() {
    let dir = scratch("slope");
    let polar = dir.join("stall10.csv");
    write_polar(&polar, stalling);
    let case = dir.join("ar20.json");
    std::fs::write(&case, AR20_CASE).unwrap();
    let f = Formulation::Gebf;
    for pitch in [8.0, 14.0] {
        let plain = expand(&case, &[format!("pitch_deg={pitch}")]);
        let corrected = expand(&case, &[format!("pitch_deg={pitch}"), polars_set(&polar, "[0]", "")]);
        let [l0, d0] = static_stiffness_check(&plain.case(f).problem(), f, 4).unwrap();
        let [l1, d1] = static_stiffness_check(&corrected.case(f).problem(), f, 4).unwrap();
        let (e0, e1) = (matrix_difference(&l0, &d0), matrix_difference(&l1, &d1));
        println!("{pitch}°: lattice D(0)−K\n{l0:.5}differences\n{d0:.5}");
        println!("{pitch}°: with the polar D(0)−K\n{l1:.5}differences\n{d1:.5}");
        println!(
            "{pitch}°: linear vs differences {e0:.1e} (lattice), {e1:.1e} (polar); the polar changes the \
             stiffness by {:.1} %",
            100.0 * matrix_difference(&l1, &l0)
        );
        assert!(e0 < 1e-5 && e1 < 1e-5, "{pitch}°: {e0:.2e} {e1:.2e}");
    }
}

/// ANCF and GEBF with the NACA 0015 polar on the Healy wing at 16.5 and 24 m/s: every tracked
/// root converges in both, with and without the polar, and they agree within 1 % of |s|
/// (measured 3.2e-4 either way; the fold root 4.4e-6 and 7.0e-6). GEBF's fold root was lost
/// when its real start kept Newton's method on the real axis (docs/section_aero.md §7.7).
#[test]
fn both_formulations_agree_on_the_roots_with_the_naca0015_polar() {
    let file = root().join("cases/polars/naca0015_neuralfoil.csv");
    let spec = healy_stability(&[polars_set(&file, "[0,1]", "")]);
    let run = |s: &RunSpec, f: Formulation| run_stability(&s.case(f).problem(), f);
    let all_converged = |o: &StabilityOutput| o.points.iter().all(|p| p.roots.iter().all(|r| r.converged));
    let (ancf, gebf) = (run(&spec, Formulation::Ancf), run(&spec, Formulation::Gebf));
    assert!(all_converged(&ancf) && all_converged(&gebf), "a tracked root did not converge");
    let worst = root_difference(&ancf, &gebf);
    let plain = healy_stability(&[]);
    let (ancf0, gebf0) = (run(&plain, Formulation::Ancf), run(&plain, Formulation::Gebf));
    assert!(all_converged(&ancf0) && all_converged(&gebf0), "a tracked root did not converge without the polar");
    let worst0 = root_difference(&ancf0, &gebf0);
    println!("ANCF vs GEBF: largest relative root difference {worst:.2e} with the polar, {worst0:.2e} without");
    assert!(worst < 0.01, "{worst:.2e}");
}

/// The Healy wing's stability with Theodorsen strips (16 + 6 stations, 12 basis modes, four
/// roots at 16.5 and 24 m/s) and `extra` overrides.
fn healy_strip_stability(extra: &[String]) -> RunSpec {
    let mut set = vec![
        "aero.panels_per_body=[16,6]".to_string(),
        r#"stability={"airspeeds":[16.5,24],"modes":4,"basis_modes":12,"aerodynamics":"strip"}"#.to_string(),
    ];
    set.extend_from_slice(extra);
    expand(&root().join("cases/healy_ffwt_flare10_aoa5.json"), &set)
}

/// Theodorsen strips with section polars (docs/stability.md §4.2): with cl = 2πα every strip's
/// slope is 2π, so the roots equal the uncorrected strips' within 1e-9 relative (or twice their
/// own largest change when the density moves by a few ulp, as for the lattice); with the NACA 0015 polar
/// every root converges in both formulations and they agree within 1 % of |s|.
#[test]
fn strip_stability_takes_the_polars_slope() {
    let dir = scratch("strip_stab");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    let plain = healy_strip_stability(&[]);
    let linear = healy_strip_stability(&[polars_set(&file, "[0,1]", "")]);
    let controls: Vec<RunSpec> = NUDGES.iter().map(|k| healy_strip_stability(&[nudged_rho(*k)])).collect();
    let run = |s: &RunSpec, f: Formulation| run_stability(&s.case(f).problem(), f);
    let all_converged = |o: &StabilityOutput| o.points.iter().all(|p| p.roots.iter().all(|r| r.converged));
    for f in Formulation::ALL {
        let a = run(&plain, f);
        assert!(all_converged(&a), "{f}: a strip root did not converge");
        let worst = root_difference(&run(&linear, f), &a);
        let worst_control = controls.iter().map(|c| root_difference(&run(c, f), &a)).fold(0.0f64, f64::max);
        println!("{f}: strips with cl = 2πα {worst:.1e} (control {worst_control:.1e})");
        assert!(worst < 1e-9_f64.max(2.0 * worst_control), "{f}: {worst:.2e} (control {worst_control:.2e})");
    }
    let naca = healy_strip_stability(&[polars_set(&root().join("cases/polars/naca0015_neuralfoil.csv"), "[0,1]", "")]);
    let (ancf, gebf) = (run(&naca, Formulation::Ancf), run(&naca, Formulation::Gebf));
    assert!(all_converged(&ancf) && all_converged(&gebf), "a strip root did not converge with the polar");
    let worst = root_difference(&ancf, &gebf);
    println!("strips with the NACA 0015 polar, ANCF vs GEBF: {worst:.2e}");
    assert!(worst < 0.01, "{worst:.2e}");
}
