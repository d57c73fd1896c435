//! Section polars in the trim, the march from a trim and the strip-theory march (issue 37,
//! docs/section_aero.md §7.5–7.6): a linear polar reproduces the unpolared trim and strip march,
//! a drag polar raises the trimmed thrust by the profile drag, the strip march follows a
//! stalling table and keeps its energy balance with the drag's work, ANCF and GEBF agree.

use std::f64::consts::PI;
use std::path::Path;

use crate::common::root;
use crate::polars::{AR20_CASE, expand, polars_set, rel, scratch, stalling, worst_of, write_polar};
use aeroelastic::trim::{TrimOutput, run_trim};
use harness::case::{Formulation, RunSpec};
use harness::metrics::FormulationMetrics;
use harness::run::{Row, RunOutput};
use harness::scene::run_formulation;

/// The Horten half model (`cases/horten_flying_wing.json`, 12 bodies) with overrides `set`.
fn horten(set: &[String]) -> RunSpec {
    expand(&root().join("cases/horten_flying_wing.json"), set).unwrap()
}

/// The polar `file` on all 12 bodies of the Horten half model.
fn horten_polar(file: &Path) -> String {
    polars_set(file, &format!("{:?}", (0..12).collect::<Vec<_>>()))
}

fn trim(spec: &RunSpec, f: Formulation) -> TrimOutput {
    let out = run_trim(&spec.case(f).problem(), f, spec.case(f).trim.as_ref().unwrap());
    assert!(out.converged, "{f}: {:?}", out.error);
    out
}

/// cl = 2πα, cd = cm = 0 on every body of the Horten wing: the trim's α, elevator and thrust
/// equal the unpolared trim's within 1e-9 relative, both formulations.
#[test]
fn a_linear_polar_reproduces_the_trim() {
    let dir = scratch("flight_linear_trim");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    let (plain, corrected) = (horten(&[]), horten(&[horten_polar(&file)]));
    for f in Formulation::ALL {
        let (a, b) = (trim(&plain, f), trim(&corrected, f));
        for (what, x, y) in [("alpha", a.alpha_deg, b.alpha_deg), ("elevator", a.elevator_deg, b.elevator_deg)]
            .into_iter()
            .chain([("thrust", a.thrust, b.thrust), ("lift", a.lift, b.lift), ("drag", a.drag, b.drag)])
        {
            println!("{f} {what}: {x:.12e} vs {y:.12e} ({:.1e})", rel(y, x));
            assert!(rel(y, x) < 1e-9, "{f} {what}: {x} vs {y}");
        }
        assert_eq!(a.iterations, b.iterations, "{f}");
    }
}

/// Profile drag along the stream of the Horten half model at incidence `alpha` (rad) with a
/// constant `cd`, in closed form: each strip sees the section-plane dynamic pressure
/// `q (1 − cos²α sin²Λ)` on its area (docs/section_aero.md §4: the polar's chord is the one
/// normal to the beam, its width the beam-wise one, so `c w` is the planform area), and its
/// drag along the section-plane flow has `(1 − cos²α sin²Λ)^{1/2}` of its size along the stream:
/// `D = cd q Σ A (1 − cos²α sin²Λ)^{3/2}` over the unswept centre section (1.0 × 0.4125 m) and
/// the wing (sweep Λ = 20°, 11 bodies of 0.92753 m along the beam, chord 1.0 → 0.25 m along the
/// stream).
fn horten_profile_drag(cd: f64, alpha: f64) -> f64 {
    let q = 0.5 * 1.02 * 28.0 * 28.0;
    let sweep = 20f64.to_radians();
    let wing = 11.0 * 0.927_527_672_146_618_8 * sweep.cos() * 0.5 * (1.0 + 0.25);
    let factor = (1.0 - (alpha.cos() * sweep.sin()).powi(2)).powf(1.5);
    cd * q * (1.0 * 0.4125 + wing * factor)
}

/// cl = 2πα, cd = 0.01, cm = 0: the trimmed thrust rises by the profile drag. In level flight
/// with the thrust along the body axis `T cos α = D` (the forward and vertical balances of body
/// axes), so `ΔT cos α` is the change of drag: the closed-form profile drag of
/// [`horten_profile_drag`] within 0.5 % (measured −0.18 %: the trim's own profile drag is the
/// closed form's within 0.2 % (measured −0.08 %; the closed form leaves out the strips' widths
/// along the tapered quarter-chord line and the wing's bending and twist), and the induced drag
/// falls by 0.1 % of the profile drag with the lift the thrust takes over). ANCF and GEBF agree
/// within 0.01° (α, elevator) and 0.5 % (thrust), as without polars.
#[test]
fn a_drag_polar_raises_the_trimmed_thrust_by_the_profile_drag() {
    let dir = scratch("flight_drag_trim");
    let file = dir.join("drag.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.01, 0.0));
    let (plain, corrected) = (horten(&[]), horten(&[horten_polar(&file)]));
    let mut outs = Vec::new();
    for f in Formulation::ALL {
        let (a, b) = (trim(&plain, f), trim(&corrected, f));
        let alpha = b.alpha_deg.to_radians();
        let want = horten_profile_drag(0.01, alpha);
        let got = b.thrust * alpha.cos() - a.thrust * a.alpha_deg.to_radians().cos();
        println!(
            "{f}: thrust {:.4} -> {:.4} N, α {:.4}° -> {:.4}°, elevator {:.4}° -> {:.4}°; ΔT cos α {got:.4} N, \
             closed form {want:.4} N ({:+.3} %); drag {:.4} -> {:.4} N",
            a.thrust,
            b.thrust,
            a.alpha_deg,
            b.alpha_deg,
            a.elevator_deg,
            b.elevator_deg,
            100.0 * (got - want) / want,
            a.drag,
            b.drag,
        );
        println!(
            "{f}: profile drag {:.4} N against the closed form's {want:.4} N ({:+.3} %); induced {:.4} -> {:.4} N",
            b.profile_drag,
            100.0 * (b.profile_drag - want) / want,
            a.drag - a.profile_drag,
            b.drag - b.profile_drag
        );
        assert!(rel(got, want) < 5e-3, "{f}: ΔT cos α {got} N vs {want} N");
        assert!(rel(b.profile_drag, want) < 2e-3, "{f}: profile drag {} N vs {want} N", b.profile_drag);
        // The trim's own drag output holds the profile drag: T cos α = D.
        assert!(rel(b.thrust * alpha.cos(), b.drag) < 1e-3, "{f}: {} vs {}", b.thrust, b.drag);
        outs.push(b);
    }
    let (a, g) = (&outs[0], &outs[1]);
    assert!((a.alpha_deg - g.alpha_deg).abs() < 0.01, "α {} vs {}", a.alpha_deg, g.alpha_deg);
    assert!((a.elevator_deg - g.elevator_deg).abs() < 0.01, "δ {} vs {}", a.elevator_deg, g.elevator_deg);
    assert!(rel(a.thrust, g.thrust) < 5e-3, "T {} vs {}", a.thrust, g.thrust);
}

/// The march from a trim with the drag polar (`initial: "trim_held"`, the Horten half model,
/// its 6 steps): the march's loads are corrected as the trim's were, so it starts in
/// equilibrium: the tip stays within 1e-6 m of its start and the lift within 1e-6 of the
/// weight's share it carried at the trim (measured without polars: the same order).
#[test]
fn the_march_from_a_trim_holds_the_polars_trim() {
    let dir = scratch("flight_trim_march");
    let file = dir.join("drag.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.01, 0.0));
    for set in [vec![], vec![horten_polar(&file)]] {
        let spec = horten(&[set.clone(), vec![r#"initial="trim_held""#.to_string()]].concat());
        for f in Formulation::ALL {
            let out = run_formulation(spec.case(f), f);
            assert!(out.error.is_none(), "{f}: {:?}", out.error);
            let r0 = &out.rows[0];
            let tip = out.rows.iter().map(|r| (0..3).map(|k| (r.tip[k] - r0.tip[k]).abs()).fold(0.0, f64::max));
            let tip = tip.fold(0.0, f64::max);
            let lift = out.rows.iter().map(|r| rel(r.lift, r0.lift)).fold(0.0, f64::max);
            println!("{f} polars {}: tip moves {tip:.2e} m, lift {lift:.2e} (lift {:.3} N)", !set.is_empty(), r0.lift);
            assert!(tip < 1e-6 && lift < 1e-6, "{f}: tip {tip} m, lift {lift}");
        }
    }
}

/// The roll rig with strip aerodynamics at 20 m/s, 0.16 s, with overrides `set`.
fn roll_rig_strips(set: &[String]) -> RunSpec {
    let base = [r#"aero.model="strip""#.to_string(), "t_end=0.16".to_string(), "aero.v_inf=[0,-20,0]".to_string()];
    expand(&root().join("cases/healy_roll_rig.json"), &[base.to_vec(), set.to_vec()].concat()).unwrap()
}

/// The strip march's columns compared here.
fn strip_columns(r: &Row) -> [(&'static str, f64); 8] {
    [
        ("tip x", r.tip[0]),
        ("tip y", r.tip[1]),
        ("tip z", r.tip[2]),
        ("fold", r.fold),
        ("roll rate", r.roll_rate),
        ("kinetic", r.kinetic),
        ("aero_work", r.aero_work),
        ("lift", r.lift),
    ]
}

/// The largest difference of every column of [`strip_columns`] of `b` from `a`, relative to the
/// column's peak in `a`.
fn worst(a: &RunOutput, b: &RunOutput) -> Vec<(&'static str, f64)> {
    worst_of(a, b, strip_columns)
}

/// cl = 2πα, cd = cm = 0 on the four wing bodies of the roll rig in the strip march (ailerons
/// at ±5°, so the polar is read at `α + τ δ` on the flapped strips): tip, fold, roll rate,
/// kinetic energy, aerodynamic work and lift equal the unpolared march's within 1e-9 of each
/// column's peak, both formulations.
#[test]
fn a_linear_polar_reproduces_the_strip_march() {
    let dir = scratch("flight_linear_strip");
    let file = dir.join("thin_plate.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.0, 0.0));
    let plain = roll_rig_strips(&[]);
    let corrected = roll_rig_strips(&[polars_set(&file, "[1,2,3,4]")]);
    for f in Formulation::ALL {
        let a = run_formulation(plain.case(f), f);
        let b = run_formulation(corrected.case(f), f);
        assert!(a.error.is_none() && b.error.is_none(), "{f}: {:?} {:?}", a.error, b.error);
        assert!(a.strips.is_empty() && !b.strips.is_empty());
        for (what, d) in worst(&a, &b) {
            println!("{f} {what}: {d:.1e}");
            assert!(d < 1e-9, "{f} {what}: {d:e}");
        }
    }
}

/// The AR-20 wing of the polars' tests (stiff, clamped, 40 strips) in the strip march at 2°, 8°
/// and 14° root pitch with the table that stalls at 10° (0.1 s from an impulsive start): the
/// mid-span strip's lift coefficient of the applied loads equals the table's at its incidence
/// within 0.1 % (the stiff wing's vibration changes its local flow), and the incidence is the
/// geometric one within 1 % (strips have no downwash; what is left is the wing's vibration after
/// the start: a plunge velocity of 1 cm/s is 0.03° at 20 m/s). ANCF and GEBF agree on the lift
/// within 0.1 %.
#[test]
fn the_strip_march_follows_a_stalling_table() {
    let dir = scratch("flight_stall_strip");
    let polar = dir.join("stall10.csv");
    write_polar(&polar, stalling);
    let table = aerofoil::read_polar(&polar).unwrap();
    let case = dir.join("ar20.json");
    std::fs::write(&case, AR20_CASE).unwrap();
    for pitch in [2.0, 8.0, 14.0] {
        let set = [format!("pitch_deg={pitch}"), polars_set(&polar, "[0]"), r#"aero.model="strip""#.into()];
        let spec = expand(&case, &set).unwrap();
        let mut lifts = Vec::new();
        for f in Formulation::ALL {
            let out = run_formulation(spec.case(f), f);
            assert!(out.error.is_none(), "{f} {pitch}°: {:?}", out.error);
            let mid = out.strips.iter().min_by(|a, b| (a.s - 1.0).abs().total_cmp(&(b.s - 1.0).abs())).unwrap();
            let want = table.coefficients(mid.alpha, 20.0 * 0.1 / 1.5e-5).unwrap().cl;
            println!(
                "{f} {pitch}°: mid-span α {:.5}°, cl {:.6}, table {want:.6} ({:+.4} %), lift {:.4} N",
                mid.alpha.to_degrees(),
                mid.cl,
                100.0 * (mid.cl - want) / want,
                out.rows.last().unwrap().lift
            );
            assert!(rel(mid.cl, want) < 1e-3, "{f} {pitch}°: cl {} vs the table's {want}", mid.cl);
            assert!(rel(mid.alpha.to_degrees(), pitch) < 0.01, "{f} {pitch}°: α {}", mid.alpha.to_degrees());
            lifts.push(out.rows.last().unwrap().lift);
        }
        assert!(rel(lifts[0], lifts[1]) < 1e-3, "{pitch}°: lift {} vs {}", lifts[0], lifts[1]);
    }
}

/// The roll rig's strip march with a drag polar (cl = 2πα, cd = 0.05, cm = −0.05): the energy
/// balance `E + W_damp − E0 − W_aero` holds with the drag's work counted in `W_aero` (drift
/// relative to the peak kinetic energy within 1.5 times the unpolared march's, which is the
/// loose coupling's own), while the polar changes `W_aero` by more than 5 times the drift (left
/// out of the work, the drag would show in the balance). ANCF and GEBF agree on the roll rate
/// within 1 % of its peak.
#[test]
fn the_strip_march_counts_the_drag_work() {
    let dir = scratch("flight_energy_strip");
    let file = dir.join("drag.csv");
    write_polar(&file, |a| (2.0 * PI * a, 0.05, -0.05));
    let plain = roll_rig_strips(&[]);
    let corrected = roll_rig_strips(&[polars_set(&file, "[1,2,3,4]")]);
    let mut rates = Vec::new();
    for f in Formulation::ALL {
        let a = run_formulation(plain.case(f), f);
        let b = run_formulation(corrected.case(f), f);
        assert!(a.error.is_none() && b.error.is_none(), "{f}: {:?} {:?}", a.error, b.error);
        let (ma, mb) = (FormulationMetrics::of(&a), FormulationMetrics::of(&b));
        let (da, db) = (ma.energy_drift, mb.energy_drift);
        let (wa, wb) = (a.rows.last().unwrap().aero_work, b.rows.last().unwrap().aero_work);
        let drift_j = db * mb.peak_kinetic;
        println!(
            "{f}: energy drift {da:.3e} without, {db:.3e} with the drag polar ({drift_j:.2e} J); W_aero {wa:.5} J vs \
             {wb:.5} J"
        );
        assert!(db < 1.5 * da, "{f}: drift {db} vs {da}");
        assert!((wa - wb).abs() > 5.0 * drift_j, "{f}: W_aero {wb} vs {wa}, drift {drift_j} J");
        rates.push(b.rows.iter().map(|r| r.roll_rate).collect::<Vec<_>>());
    }
    let peak = rates[1].iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let diff = rates[0].iter().zip(&rates[1]).map(|(a, g)| (a - g).abs()).fold(0.0, f64::max);
    println!("roll rate: ANCF-GEBF {diff:.3e} of peak {peak:.4} rad/s");
    assert!(diff < 0.01 * peak, "roll rate {diff} of {peak}");
}
