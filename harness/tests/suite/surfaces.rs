//! Several lifting surfaces from a case file (`aero.surfaces`, issue 34 item 3): two half-wings
//! meeting at the root against one surface across the plane of symmetry and against the mirror
//! image; a tail in a wing's downwash against the far-field estimate; a body on no surface
//! carries no aerodynamics; both formulations and the time march; bad surfaces named.

use harness::case::{Formulation, RunSpec};
use harness::statics::{StaticPoint, run_static};
use serde_json::{Value, json};

/// Write `v` to a fresh file in this test's folder and expand it.
fn spec(v: &Value, tag: &str) -> Result<RunSpec, String> {
    crate::common::json_spec(v, "surfaces", tag)
}

/// A clamped body `name` from `start` along `x_axis` (chord towards +Y), `length` long, with a
/// built-in incidence of `twist` degrees: the paper's wing section (Otsuka et al. 2024, Table 3)
/// with its stiffnesses times `stiff` (1e9 makes it all but rigid).
fn body(name: &str, start: [f64; 3], x_axis: [f64; 3], length: f64, twist: f64, stiff: f64) -> Value {
    let k = stiff;
    json!({ "name": name, "start": start, "length": length, "x_axis": x_axis, "y_axis": [0, 1, 0],
        "twist_deg": [twist, twist],
        "section": { "mass": 0.75, "rho_ixx": 0.1, "rho_iyy": 0.01, "rho_izz": 0.09, "ea": 1e7 * k, "ga_y": 5e6 * k,
          "ga_z": 5e6 * k, "gj": 1e4 * k, "ei_yy": 2e4 * k, "ei_zz": 5e6 * k } })
}

/// A case of `bodies` (each clamped at its root) with the `aero` block `aero`, a static point
/// at 10 m/s along −Y in air of density 1.
fn case(name: &str, bodies: Vec<Value>, aero: Value) -> Value {
    let joints: Vec<Value> = bodies
        .iter()
        .map(|b| json!({ "type": "clamp", "name": format!("root_{}", b["name"].as_str().unwrap()), "body": b["name"] }))
        .collect();
    let n = bodies.len();
    let mut a = json!({ "rho": 1.0, "airspeed": 10.0, "n_chordwise": 4, "n_wake_rows": 20 });
    for (k, v) in aero.as_object().unwrap() {
        a[k] = v.clone();
    }
    json!({
      "name": name,
      "bodies": bodies,
      "joints": joints,
      "gravity": [0, 0, 0],
      "t_end": 0.05,
      "ancf": { "elements_per_body": vec![4; n], "dt": 0.005 },
      "gebf": { "elements_per_body": vec![4; n], "dt": 0.005 },
      "aero": a,
      "static": { "airspeeds": [10.0] }
    })
}

/// The static point of formulation `f` of `spec`, checked to have converged.
fn solve(spec: &RunSpec, f: Formulation) -> StaticPoint {
    let r = run_static(&spec.case(f).problem(), f);
    let p = r.points.into_iter().next().unwrap();
    assert!(p.error.is_none(), "{}: {:?}", spec.name, p.error);
    p
}

/// Strip lift per span of `p` ordered from −X to +X: (x of the strip's middle, lift per span).
fn strips_by_x(p: &StaticPoint) -> Vec<(f64, f64)> {
    let mut v: Vec<(f64, f64)> = p.strips.iter().map(|s| (s.position[0], s.lift_per_span)).collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

/// Two half-wings meeting at the root (two surfaces) carry the loads of one surface across the
/// plane of symmetry and of today's mirror image, through the whole static solution (stiff
/// wings, 6° built-in incidence, AR 8): strip by strip within 1e-10 of the largest strip load.
/// The left half runs along −X with its chord towards +Y, so its section z axis points down and
/// its twist is about −X: the same incidence is −6° there.
#[test]
fn two_half_wings_equal_one_surface_across_and_the_mirror_image() {
    let panels = 16;
    let halves = case(
        "halves",
        vec![
            body("right", [0.0; 3], [1.0, 0.0, 0.0], 4.0, 6.0, 1e9),
            body("left", [0.0; 3], [-1.0, 0.0, 0.0], 4.0, -6.0, 1e9),
        ],
        json!({ "surfaces": [
            { "name": "right", "bodies": ["right"], "chord": 1.0, "le_offset": 0.25, "panels_per_body": [panels] },
            { "name": "left", "bodies": ["left"], "chord": 1.0, "le_offset": 0.25, "panels_per_body": [panels] } ] }),
    );
    let across = case(
        "across",
        vec![body("span", [-4.0, 0.0, 0.0], [1.0, 0.0, 0.0], 8.0, 6.0, 1e9)],
        json!({ "chord": 1.0, "le_offset": 0.25, "panels_per_body": [2 * panels] }),
    );
    let mirror = case(
        "mirror",
        vec![body("right", [0.0; 3], [1.0, 0.0, 0.0], 4.0, 6.0, 1e9)],
        json!({ "chord": 1.0, "le_offset": 0.25, "panels_per_body": [panels],
            "images": [{ "point": [0, 0, 0], "normal": [1, 0, 0] }] }),
    );
    let (h, a, m) =
        (spec(&halves, "halves").unwrap(), spec(&across, "across").unwrap(), spec(&mirror, "mirror").unwrap());
    let (ph, pa, pm) = (solve(&h, Formulation::Gebf), solve(&a, Formulation::Gebf), solve(&m, Formulation::Gebf));
    let (sh, sa, sm) = (strips_by_x(&ph), strips_by_x(&pa), strips_by_x(&pm));
    assert_eq!((sh.len(), sa.len(), sm.len()), (2 * panels, 2 * panels, panels));
    let scale = sa.iter().fold(0.0_f64, |m, s| m.max(s.1.abs()));
    let (mut d_across, mut d_mirror) = (0.0_f64, 0.0_f64);
    for (k, (x, l)) in sh.iter().enumerate() {
        assert!((x - sa[k].0).abs() < 1e-9, "strip {k} at x = {x} vs {}", sa[k].0);
        d_across = d_across.max((l - sa[k].1).abs() / scale);
        if k >= panels {
            d_mirror = d_mirror.max((l - sm[k - panels].1).abs() / scale);
        }
    }
    println!(
        "half-wings vs one surface across: {d_across:.2e}, vs mirror image: {d_mirror:.2e} of the largest strip lift \
         ({scale:.4} N/m); lift {:.6} / {:.6} / 2 × {:.6} N",
        ph.lift, pa.lift, pm.lift
    );
    assert!(d_across < 1e-10 && d_mirror < 1e-10);
    assert!((ph.lift - pa.lift).abs() < 1e-10 * pa.lift.abs(), "{} vs {}", ph.lift, pa.lift);
}

/// The wing + tail of [`tail_downwash`]: an AR-8 half-wing of taper 0.4 (root chord 10/7 m,
/// quarter-chord line straight, 4° built-in incidence, mirror plane at the root), and an AR-4
/// tail (chord 0.5 m, 2° incidence) whose leading edge is 16 root chords behind the wing's
/// quarter chord and 0.1 m above the wing's root; `with_wing`: whether the wing is a lifting
/// surface (otherwise its body is on no surface and carries no aerodynamics).
fn wing_and_tail(with_wing: bool, panels: usize) -> Value {
    let c0 = 10.0 / 7.0;
    let y_tail = -16.0 * c0 - 0.125;
    let wing = json!({ "name": "wing", "bodies": ["wing"], "chord": [[c0, 0.4 * c0]],
        "le_offset": [[0.25 * c0, 0.1 * c0]], "panels_per_body": [panels], "n_chordwise": 6 });
    let tail = json!({ "name": "tail", "bodies": ["tail"], "chord": 0.5, "le_offset": 0.125,
        "panels_per_body": [panels / 2] });
    let surfaces = if with_wing { vec![wing, tail] } else { vec![tail] };
    case(
        if with_wing { "wing_tail" } else { "tail_alone" },
        vec![
            body("wing", [0.0; 3], [1.0, 0.0, 0.0], 4.0, 4.0, 1e9),
            body("tail", [0.0, y_tail, 0.1], [1.0, 0.0, 0.0], 1.0, 2.0, 1e9),
        ],
        json!({ "surfaces": surfaces, "images": [{ "point": [0, 0, 0], "normal": [1, 0, 0] }] }),
    )
}

/// Lift of the strips with their middle behind `y` (the tail's), N.
fn lift_behind(p: &StaticPoint, y: f64, width: f64) -> f64 {
    p.strips.iter().filter(|s| s.position[1] < y).map(|s| s.lift_per_span * width).sum()
}

/// The tail's lift drops in the wing's downwash; the downwash angle from the drop,
/// ε = α_t (1 − L_t / L_t,alone), matches the classic far-field estimate ε = 2 C_L/(π A) of a
/// nearly elliptic load (Anderson, *Fundamentals of Aerodynamics*, §5.3) within 10 %. The wing's
/// C_L is its own lift over its area (both halves through the mirror plane).
#[test]
fn a_tail_in_the_wing_downwash_loses_the_far_field_estimate() {
    let panels = 32;
    let both = spec(&wing_and_tail(true, panels), "wing_tail").unwrap();
    let alone = spec(&wing_and_tail(false, panels), "tail_alone").unwrap();
    let (pb, pt) = (solve(&both, Formulation::Gebf), solve(&alone, Formulation::Gebf));
    let width = 1.0 / (panels / 2) as f64;
    let (lt, lt0) = (lift_behind(&pb, -10.0, width), lift_behind(&pt, -10.0, width));
    assert_eq!(pt.strips.len(), panels / 2, "the wing's body is on no surface: only the tail's strips");
    assert!((pt.lift - lt0).abs() < 1e-9 * lt0, "the tail alone carries all the lift");
    let c0 = 10.0 / 7.0;
    let wing_area = 4.0 * 0.5 * (c0 + 0.4 * c0);
    let lift_wing = pb.lift - lt;
    let cl = lift_wing / (0.5 * 100.0 * wing_area);
    let reference = 2.0 * cl / (std::f64::consts::PI * 8.0);
    let eps = 2f64.to_radians() * (1.0 - lt / lt0);
    println!(
        "tail lift {lt:.5} N in the downwash, {lt0:.5} N alone; wing C_L {cl:.4}; ε = {:.4}° against 2 C_L/(π A) = \
         {:.4}° ({:+.1} %)",
        eps.to_degrees(),
        reference.to_degrees(),
        100.0 * (eps / reference - 1.0)
    );
    assert!(lt < lt0, "the tail's lift drops in the downwash");
    assert!((eps / reference - 1.0).abs() < 0.10);
}

/// A flexible wing + tail (two surfaces, the paper's wing section) gives the same static
/// equilibrium in ANCF and GEBF.
#[test]
fn a_flexible_wing_and_tail_agree_in_both_formulations() {
    let mut v = wing_and_tail(true, 16);
    v["bodies"][0] = body("wing", [0.0; 3], [1.0, 0.0, 0.0], 4.0, 4.0, 1.0);
    v["bodies"][1]["section"] = v["bodies"][0]["section"].clone();
    v["aero"]["rho"] = json!(0.1);
    v["ancf"]["elements_per_body"] = json!([8, 2]);
    v["gebf"]["elements_per_body"] = json!([8, 2]);
    let s = spec(&v, "flexible").unwrap();
    let (pa, pg) = (solve(&s, Formulation::Ancf), solve(&s, Formulation::Gebf));
    println!(
        "flexible wing + tail: lift ANCF {:.6} N, GEBF {:.6} N; tail tip z {:.6} / {:.6} m",
        pa.lift, pg.lift, pa.tip[2], pg.tip[2]
    );
    assert!(pg.lift > 0.0 && ((pa.lift - pg.lift) / pg.lift).abs() < 2e-3, "lift {} vs {}", pa.lift, pg.lift);
}

/// The time march of two half-wings meeting at the root (two surfaces, two wakes) is the mirror
/// image's: an impulsive start of stiff wings (each half clamped at the root, so both deform
/// alike), the lift at every step within 1e-9 of twice the
/// mirrored half-wing's, in both formulations (the wake row as long as a panel, U·dt = c/4).
#[test]
fn two_half_wings_march_as_the_mirror_image() {
    let halves = case(
        "halves_march",
        vec![
            body("right", [0.0; 3], [1.0, 0.0, 0.0], 4.0, 6.0, 1e3),
            body("left", [0.0; 3], [-1.0, 0.0, 0.0], 4.0, -6.0, 1e3),
        ],
        json!({ "surfaces": [
            { "name": "right", "bodies": ["right"], "chord": 1.0, "le_offset": 0.25, "panels_per_body": [8] },
            { "name": "left", "bodies": ["left"], "chord": 1.0, "le_offset": 0.25, "panels_per_body": [8] } ] }),
    );
    let mirror = case(
        "mirror_march",
        vec![body("right", [0.0; 3], [1.0, 0.0, 0.0], 4.0, 6.0, 1e3)],
        json!({ "chord": 1.0, "le_offset": 0.25, "panels_per_body": [8],
            "images": [{ "point": [0, 0, 0], "normal": [1, 0, 0] }] }),
    );
    let set_dt = |mut v: Value| {
        v["t_end"] = json!(0.25);
        v["ancf"]["dt"] = json!(0.025);
        v["gebf"]["dt"] = json!(0.025);
        // The wake summed exactly: the two layouts agree to rounding, below the 1e-6 |V∞| of
        // the default mixed-precision far wake (docs/uvlm.md §14).
        v["aero"]["wake_aggregation"] = json!(false);
        v
    };
    let (h, m) = (spec(&set_dt(halves), "halves_march").unwrap(), spec(&set_dt(mirror), "mirror_march").unwrap());
    for f in [Formulation::Ancf, Formulation::Gebf] {
        let (oh, om) = (harness::scene::run_formulation(h.case(f), f), harness::scene::run_formulation(m.case(f), f));
        assert!(oh.error.is_none() && om.error.is_none(), "{f:?}: {:?} {:?}", oh.error, om.error);
        assert_eq!(oh.rows.len(), 11);
        let scale = om.rows.iter().fold(0.0_f64, |a, r| a.max(r.lift.abs()));
        let d = oh
            .rows
            .iter()
            .zip(&om.rows)
            .map(|(a, b)| (a.lift - 2.0 * b.lift).abs() / (2.0 * scale))
            .fold(0.0, f64::max);
        println!("{f:?}: two half-wings against the mirror image over 10 steps: lift within {d:.2e}");
        assert!(scale > 1.0 && d < 1e-9);
    }
}

/// Bad surfaces exit with the field named.
#[test]
fn bad_surfaces_are_named() {
    let base = wing_and_tail(true, 8);
    let bad = |edit: &dyn Fn(&mut Value), field: &str| {
        let mut v = base.clone();
        edit(&mut v);
        let e = spec(&v, "bad").err().unwrap_or_else(|| panic!("accepted: {field}"));
        assert!(e.contains(field), "`{e}` does not name `{field}`");
    };
    bad(&|v| v["aero"]["surfaces"][1]["bodies"] = json!(["fin"]), "aero.surfaces[1].bodies[0]");
    bad(&|v| v["aero"]["surfaces"][1]["bodies"] = json!(["wing"]), "aero.surfaces[1].bodies[0]");
    bad(&|v| v["aero"]["surfaces"][1]["name"] = json!("wing"), "aero.surfaces[1].name");
    bad(&|v| v["aero"]["surfaces"][0]["panels_per_body"] = json!([8, 2]), "aero.surfaces[0].panels_per_body");
    bad(&|v| v["aero"]["surfaces"][0]["chord"] = json!(-1.0), "aero.surfaces[0].chord");
    bad(&|v| v["aero"]["surfaces"][1]["n_chordwise"] = json!(0), "aero.surfaces[1].n_chordwise");
    bad(&|v| v["aero"]["chord"] = json!(1.0), "aero.chord");
    bad(
        &|v| {
            v["aero"]["surfaces"] = json!([{ "name": "wing", "bodies": ["wing", "tail"], "chord": 1.0, "le_offset": 0.25,
                "panels_per_body": [8, 4] }])
        },
        "aero.surfaces[0].bodies[1]",
    );
    bad(&|v| v["aero"]["surfaces"] = json!([]), "aero.chord");
    // Absurd sizes are refused before anything is laid out.
    bad(
        &|v| v["aero"]["surfaces"][1]["panels_per_body"] = json!([1_000_000_000]),
        "aero.surfaces[1].panels_per_body[0]",
    );
    bad(&|v| v["aero"]["surfaces"][1]["n_chordwise"] = json!(100_000_000), "aero.surfaces[1].n_chordwise");
    // A tail root 5 mm from the wing's root: closer than a panel, not shared.
    bad(&|v| v["bodies"][1]["start"] = json!([0.005, 0.0, 0.0]), "aero.surfaces[1].bodies[0]");
}

/// The flutter equation of two half-wings meeting at the root (two surfaces, the linearised
/// UVLM of both) holds the mirror image's roots: the symmetric motions of the pair are the
/// mirrored half-wing's. The half-wing with a mirror plane tracks 4 roots on 8 basis modes, the
/// pair 8 roots on 16 (the symmetric and antisymmetric combinations of the same shapes).
/// Untwisted, no gravity: the flexible paper's section, mid-chord axis, 20 m/s, ρ = 0.0889.
/// Every mirror root is among the pair's within 1e-8 of its magnitude, except where the pair's
/// search from a degenerate pair of structural modes landed twice on one root (its antisymmetric
/// one: the second landing is marked unconverged), which this test counts and prints.
#[test]
fn two_half_wings_have_the_mirror_images_flutter_roots() {
    let stab = |modes: usize| json!({ "airspeeds": [20.0], "modes": modes, "basis_modes": 2 * modes });
    let mut halves = case(
        "halves_flutter",
        vec![
            body("right", [0.0; 3], [1.0, 0.0, 0.0], 8.0, 0.0, 1.0),
            body("left", [0.0; 3], [-1.0, 0.0, 0.0], 8.0, 0.0, 1.0),
        ],
        json!({ "rho": 0.0889, "airspeed": 20.0, "surfaces": [
            { "name": "right", "bodies": ["right"], "chord": 1.0, "le_offset": 0.5, "panels_per_body": [12] },
            { "name": "left", "bodies": ["left"], "chord": 1.0, "le_offset": 0.5, "panels_per_body": [12] } ] }),
    );
    halves["stability"] = stab(8);
    let mut mirror = case(
        "mirror_flutter",
        vec![body("right", [0.0; 3], [1.0, 0.0, 0.0], 8.0, 0.0, 1.0)],
        json!({ "rho": 0.0889, "airspeed": 20.0, "chord": 1.0, "le_offset": 0.5, "panels_per_body": [12],
            "images": [{ "point": [0, 0, 0], "normal": [1, 0, 0] }] }),
    );
    mirror["stability"] = stab(4);
    let (h, m) = (spec(&halves, "halves_flutter").unwrap(), spec(&mirror, "mirror_flutter").unwrap());
    let f = Formulation::Gebf;
    let (oh, om) = (
        harness::stability::run_stability(&h.case(f).problem(), f),
        harness::stability::run_stability(&m.case(f).problem(), f),
    );
    let (ph, pm) = (&oh.points[0], &om.points[0]);
    assert!(ph.error.is_none() && pm.error.is_none(), "{:?} {:?}", ph.error, pm.error);
    // Roots of the pair found twice (the second landing unconverged).
    let twice = ph
        .roots
        .iter()
        .filter(|x| !x.converged)
        .filter(|x| {
            ph.roots.iter().any(|y| y.converged && (x.real - y.real).hypot(x.imag - y.imag) < 1e-6 * x.imag.abs())
        })
        .count();
    let mut matched = 0;
    for r in &pm.roots {
        let d = ph.roots.iter().map(|x| (x.real - r.real).hypot(x.imag - r.imag)).fold(f64::INFINITY, f64::min);
        let rel = d / r.real.hypot(r.imag);
        println!("mirror root {:+.6} {:+.6}i: nearest root of the pair {rel:.2e} relative", r.real, r.imag);
        assert!(r.converged);
        matched += usize::from(rel < 1e-8);
    }
    println!("{matched} of {} mirror roots matched; {twice} root(s) of the pair found twice", pm.roots.len());
    assert!(matched >= 2 && matched + twice >= pm.roots.len(), "{:?} vs {:?}", pm.roots, ph.roots);
}

/// The linear gust response (the linearised UVLM of every surface, its wake nodes following the
/// trailing edges and drifting with the gust) of two half-wings meeting at the root is twice the
/// mirror image's: the lift increment at every output time within 1e-6 of its peak. The wings
/// of [`two_half_wings_have_the_mirror_images_flutter_roots`] at 3° built-in incidence (so the
/// wake carries a steady circulation), a 1-cos gust of 20 m at 0.02 m/s; 16 against 8 basis modes.
#[test]
fn two_half_wings_have_twice_the_mirror_images_linear_gust_lift() {
    let gust = json!({ "kind": "one_minus_cosine", "gradient_m": 20.0, "velocity": 0.02, "x0": 0.0,
        "direction": [0, 0, 1] });
    let halves = case(
        "halves_gust",
        vec![
            body("right", [0.0; 3], [1.0, 0.0, 0.0], 8.0, 3.0, 1.0),
            body("left", [0.0; 3], [-1.0, 0.0, 0.0], 8.0, -3.0, 1.0),
        ],
        json!({ "rho": 0.0889, "airspeed": 20.0, "wake_closure": true, "gust": gust, "surfaces": [
            { "name": "right", "bodies": ["right"], "chord": 1.0, "le_offset": 0.5, "panels_per_body": [8] },
            { "name": "left", "bodies": ["left"], "chord": 1.0, "le_offset": 0.5, "panels_per_body": [8] } ] }),
    );
    let mirror = case(
        "mirror_gust",
        vec![body("right", [0.0; 3], [1.0, 0.0, 0.0], 8.0, 3.0, 1.0)],
        json!({ "rho": 0.0889, "airspeed": 20.0, "wake_closure": true, "gust": gust, "chord": 1.0, "le_offset": 0.5,
            "panels_per_body": [8], "images": [{ "point": [0, 0, 0], "normal": [1, 0, 0] }] }),
    );
    let set = |mut v: Value| {
        v["t_end"] = json!(1.0);
        v["gebf"]["dt"] = json!(0.0125);
        v["ancf"]["dt"] = json!(0.0125);
        v
    };
    let (h, m) = (spec(&set(halves), "halves_gust").unwrap(), spec(&set(mirror), "mirror_gust").unwrap());
    let f = Formulation::Gebf;
    let lh = harness::gust_linear::linear_gust_history(&h.case(f).problem(), f, Some(16), true).unwrap();
    let lm = harness::gust_linear::linear_gust_history(&m.case(f).problem(), f, Some(8), true).unwrap();
    let (a, b) = (&lh.increments.delta_lift, &lm.increments.delta_lift);
    assert_eq!(a.len(), b.len());
    let peak = b.iter().fold(0.0_f64, |p, x| p.max(x.abs()));
    let d = a.iter().zip(b).map(|(x, y)| (x - 2.0 * y).abs()).fold(0.0, f64::max) / (2.0 * peak);
    println!("linear gust: peak lift increment 2 × {peak:.6} N; half-wings against the mirror image within {d:.2e}");
    assert!(peak > 0.0 && d < 1e-6);
}
