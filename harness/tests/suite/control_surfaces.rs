//! Control surfaces from the case file (`aero.control_surfaces`, issue 34 item 4): a flap on the
//! paper's wing raises the static lift in both formulations, its hinge moment is the lattice's
//! (`Uvlm::hinge_moment` on the equilibrium's lattice), a deflection schedule reaches the time
//! march and its CSV, and bad input exits 2 naming the field.

use std::process::{Command, Output};

use crate::common::root;
use harness::case::{CaseFile, Formulation, Override, RunSpec};
use harness::statics::{StaticPoint, run_static};

/// The paper's wing with `set` applied.
fn wing(set: &[&str]) -> RunSpec {
    let ov: Vec<Override> = set.iter().map(|s| s.parse().unwrap()).collect();
    CaseFile::read(&root().join("cases/wing_aoa5.json")).unwrap().expand(&ov).unwrap().remove(0)
}

/// A full-span trailing-edge flap on the inner body, 25 % chord, at `deflection` (JSON).
fn flap(deflection: &str) -> String {
    format!(
        r#"aero.control_surfaces=[{{"name":"flap","body":"inner","span":[0,12],"chord_fraction":0.25,"deflection_deg":{deflection}}}]"#
    )
}

fn static_point(spec: &RunSpec, f: Formulation) -> StaticPoint {
    let out = run_static(&spec.case(f).problem(), f);
    let p = out.points.into_iter().next().unwrap();
    assert!(p.error.is_none(), "{f}: {:?}", p.error);
    p
}

/// The hinge moment of `p` recomputed from scratch: the lattice of the GEBF model at the
/// equilibrium's coordinates with the case's flap, solved steadily by the UVLM, and
/// `Uvlm::hinge_moment` over the flap's columns.
fn hinge_moment_on_the_lattice(spec: &RunSpec, p: &StaticPoint) -> f64 {
    let case = spec.case(Formulation::Gebf);
    let problem = case.problem();
    let aero = case.aero.clone().unwrap();
    let model = aeroelastic::factory::build_gebf(&problem).unwrap();
    let q = &p.state.as_ref().unwrap().0;
    let map = harness::aero::station_map(&problem, &aero).unwrap();
    let zeros = vec![0.0; q.len()];
    let mut scratch = harness::aero::StationScratch::default();
    let stations: Vec<uvlm::SpanStation> = map
        .iter()
        .map(|m| {
            let (origin, frame, _, _) = harness::aero::section_state(&model, q, &zeros, m, &mut scratch);
            uvlm::SpanStation {
                origin,
                frame,
                chord: m.chord,
                le_offset: m.le_offset,
                slant: m.slant,
                flap: m.control.map(|i| aero.control_surfaces[i].flap_at(None)),
            }
        })
        .collect();
    let first = map.iter().position(|m| m.control == Some(0)).unwrap();
    let last = map.iter().rposition(|m| m.control == Some(0)).unwrap();
    // The inner body's 24 strips: stations 0..=24, the hinge column (24) included.
    assert_eq!((first, last), (0, 24));
    let lattice = uvlm::Lattice::from_stations(harness::lifting::lattice_spec(&map, &aero, 0), &stations).unwrap();
    let mut params = aero.uvlm_params(aero.free_stream());
    params.steady_wake = uvlm::SteadyWake::SemiInfinite;
    let mut u = uvlm::Uvlm::new(lattice, params).unwrap();
    u.solve_steady().unwrap();
    u.hinge_moment(first..=last).unwrap()
}

/// The paper's wing at 25 m/s with a full-span 25 %-chord flap at 2° on the inner body: more lift
/// than without it (both formulations), ANCF and GEBF agree (fold within 0.01°, lift and hinge
/// moment within 1e-4 relative: the case's own static agreement), and the hinge moment is
/// negative (lift on the flap) and equals `Uvlm::hinge_moment` on the equilibrium's lattice.
#[test]
fn a_flap_raises_the_static_lift_and_reports_its_hinge_moment() {
    let plain = wing(&[]);
    let flapped = wing(&[&flap("2")]);
    let mut lifts = Vec::new();
    for f in Formulation::ALL {
        let (p0, p1) = (static_point(&plain, f), static_point(&flapped, f));
        assert!(p0.control_hinge_moments.is_empty());
        assert_eq!(p1.control_hinge_moments.len(), 1);
        let h = p1.control_hinge_moments[0];
        eprintln!(
            "{f}: lift {:.4} → {:.4} N, fold {:.4} → {:.4}°, flap hinge moment {h:.5} N·m",
            p0.lift, p1.lift, p0.fold_deg, p1.fold_deg
        );
        // 2° of a 25 % flap is about 1.2° of incidence (τ ≈ 0.61) on the inner 12 m of 16 m.
        assert!(p1.lift > 1.05 * p0.lift, "{f}: lift {} with the flap, {} without", p1.lift, p0.lift);
        assert!(h < 0.0, "{f}: hinge moment {h}");
        lifts.push((p1.lift, p1.fold_deg, h));
        if f == Formulation::Gebf {
            let h_lattice = hinge_moment_on_the_lattice(&flapped, &p1);
            assert!((h - h_lattice).abs() <= 1e-9 * h.abs(), "hinge moment {h} vs the lattice's {h_lattice}");
        }
    }
    let ((la, fa, ha), (lg, fg, hg)) = (lifts[0], lifts[1]);
    assert!((fa - fg).abs() < 0.01, "fold ANCF {fa}° vs GEBF {fg}°");
    assert!((la - lg).abs() < 1e-4 * lg.abs(), "lift ANCF {la} vs GEBF {lg}");
    assert!((ha - hg).abs() < 1e-4 * hg.abs(), "hinge moment ANCF {ha} vs GEBF {hg}");
}

/// The stations a surface covers: its range's panel edges; the flared hinge's column (station
/// 24, the inner body's end) belongs to a surface ending at the inner body's tip and to one of
/// the tip body starting at its root.
#[test]
fn surfaces_cover_their_panel_edges_and_the_hinge_column() {
    let columns = |surfaces: &str| {
        let spec = wing(&[&format!("aero.control_surfaces=[{surfaces}]")]);
        let case = spec.case(Formulation::Ancf);
        let aero = case.aero.clone().unwrap();
        let map = harness::aero::station_map(&case.problem(), &aero).unwrap();
        assert_eq!(map.len(), 33);
        assert!(map[24].hinge);
        (0..aero.control_surfaces.len())
            .map(|i| {
                let j: Vec<usize> = (0..map.len()).filter(|&j| map[j].control == Some(i)).collect();
                (j[0], *j.last().unwrap(), j.len())
            })
            .collect::<Vec<_>>()
    };
    let s = |name: &str, body: &str, span: &str| {
        format!(r#"{{"name":"{name}","body":"{body}","span":{span},"chord_fraction":0.3,"deflection_deg":1}}"#)
    };
    // 0.5 m strips on the inner body, 0.5 m on the tip.
    assert_eq!(columns(&s("a", "inner", "[1,3]")), [(2, 6, 5)]);
    assert_eq!(columns(&s("a", "inner", "[6,12]")), [(12, 24, 13)]);
    assert_eq!(columns(&s("a", "outer", "[0,4]")), [(24, 32, 9)]);
    assert_eq!(columns(&s("a", "outer", "[1,2]")), [(26, 28, 3)]);
    assert_eq!(
        columns(&format!("{},{}", s("a", "inner", "[0,11.5]"), s("b", "outer", "[0,4]"))),
        [(0, 23, 24), (24, 32, 9)]
    );
}

fn harness(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_harness")).args(args).current_dir(root()).output().expect("binary runs")
}

/// Columns of a CSV text: header names and rows of numbers.
fn read_csv(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    (head, rows)
}

/// A deflection ramp 0 → 2° over the first 0.1 s of an impulsively started march: the CSV has a
/// `flap_hinge_moment` column after `hinge_moment`, finite and negative at the end; the lift
/// equals the plain wing's at t = 0 and is above it at the end (0.3 s, the wake 7.5 chords long:
/// measured +19.7 N on 177.9 N, against the static equilibrium's +34 N).
#[test]
fn a_deflection_schedule_reaches_the_march_and_its_csv() {
    let out = std::env::temp_dir().join(format!("flexmb_cs_{}", std::process::id()));
    let run = |set: &[&str]| {
        let mut args = vec!["run", "cases/wing_aoa5.json", "--formulation", "gebf", "--out", out.to_str().unwrap()];
        args.extend(["--set", "t_end=0.3"]);
        for s in set {
            args.extend(["--set", s]);
        }
        let o = harness(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let dir = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .max_by_key(|p| std::fs::metadata(p).unwrap().modified().unwrap())
            .unwrap();
        read_csv(&std::fs::read_to_string(dir.join("gebf.csv")).unwrap())
    };
    let (h0, plain) = run(&[]);
    let (h1, ramp) = run(&[&flap("[[0, 0], [0.1, 2]]")]);
    let _ = std::fs::remove_dir_all(&out);
    assert!(!h0.iter().any(|c| c.ends_with("_hinge_moment") && c != "hinge_moment"), "{h0:?}");
    assert_eq!(h1.len(), h0.len() + 1);
    assert_eq!(h1.last().unwrap(), "flap_hinge_moment");
    assert_eq!(h1[..h0.len()], h0[..]);
    let col = |h: &[String], name: &str| h.iter().position(|c| c == name).unwrap();
    let (lift, hm) = (col(&h1, "lift"), col(&h1, "flap_hinge_moment"));
    assert!(ramp.iter().all(|r| r[hm].is_finite()));
    let (a, b) = (&plain[plain.len() - 1], &ramp[ramp.len() - 1]);
    let d_lift = b[lift] - a[lift];
    eprintln!("lift at 0.3 s: {:.3} N plain, {:.3} N with the ramp; hinge moment {:.4} N·m", a[lift], b[lift], b[hm]);
    assert!(d_lift > 0.03 * a[lift], "lift {} with the flap, {} without", b[lift], a[lift]);
    assert!(b[hm] < 0.0, "hinge moment {}", b[hm]);
    // Before the flap moves (the first rows) the two runs agree.
    assert_eq!(ramp[0][lift], plain[0][lift]);
}

/// Bad control surfaces and an unknown name in `--set` exit 2 naming the field.
#[test]
fn bad_control_surfaces_exit_2_naming_the_field() {
    let one = |body: &str, span: &str, e: &str, d: &str| {
        format!(r#"{{"name":"a","body":"{body}","span":{span},"chord_fraction":{e},"deflection_deg":{d}}}"#)
    };
    let list = |items: &[String]| format!("aero.control_surfaces=[{}]", items.join(","));
    let ok = one("inner", "[0,6]", "0.25", "2");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec![list(&[one("nose", "[0,6]", "0.25", "2")])], "aero.control_surfaces[0].body"),
        (vec![list(&[one("inner", "[6,6]", "0.25", "2")])], "aero.control_surfaces[0].span"),
        (vec![list(&[one("inner", "[0,13]", "0.25", "2")])], "aero.control_surfaces[0].span"),
        (vec![list(&[one("inner", "[0,6.1]", "0.25", "2")])], "panel edge"),
        (vec![list(&[one("inner", "[0,6]", "1", "2")])], "aero.control_surfaces[0].chord_fraction"),
        (vec![list(&[one("inner", "[0,6]", "0.25", "85")])], "aero.control_surfaces[0].deflection_deg"),
        (vec![list(&[one("inner", "[0,6]", "0.25", "[[0,0],[0,1]]")])], "aero.control_surfaces[0].deflection_deg"),
        (vec![list(&[one("inner", "[0,6]", "0.25", "[]")])], "aero.control_surfaces[0].deflection_deg"),
        (vec![list(&[ok.clone(), ok.replace("[0,6]", "[9,12]")])], "aero.control_surfaces[1].name"),
        // Two surfaces meeting at a station are refused unless they are alike (one chord
        // fraction, one deflection: one flap continued across a station).
        (
            vec![list(&[ok.clone(), one("inner", "[6,12]", "0.25", "3").replace("\"a\"", "\"b\"")])],
            "aero.control_surfaces[1]",
        ),
        (
            vec![list(&[
                one("inner", "[6,12]", "0.25", "2"),
                one("outer", "[0,2]", "0.25", "1").replace("\"a\"", "\"b\""),
            ])],
            "aero.control_surfaces[1]",
        ),
        (vec![list(std::slice::from_ref(&ok)), "aero.n_chordwise=1".into()], "aero.n_chordwise"),
        (
            vec![list(std::slice::from_ref(&ok)), "aero.control_surfaces.b.deflection_deg=3".into()],
            "aero.control_surfaces.b",
        ),
    ];
    // Nothing is written: every case here is refused before a run.
    let tmp = std::env::temp_dir().join("flexmb_cs_bad").to_string_lossy().into_owned();
    for (set, needle) in cases {
        let mut args = vec!["run", "cases/wing_aoa5.json", "--max-steps", "1", "--out", tmp.as_str()];
        for s in &set {
            args.extend(["--set", s.as_str()]);
        }
        let o = harness(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{set:?}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{set:?}: {err}");
    }
    // By name, the deflection is set (and checked).
    let o = harness(&[
        "run",
        "cases/wing_aoa5.json",
        "--max-steps",
        "1",
        "--out",
        tmp.as_str(),
        "--set",
        &list(std::slice::from_ref(&ok)),
        "--set",
        "aero.control_surfaces.a.deflection_deg=95",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("aero.control_surfaces[0].deflection_deg"));
}
