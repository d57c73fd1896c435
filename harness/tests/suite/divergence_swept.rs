//! Static aeroelastic divergence of a uniform swept cantilever wing under strip theory
//! (`cases/stability/divergence_swept.json`) against the exact solution of Diederich & Budiansky's
//! bending–torsion divergence equations (NACA TN 1680, 1948), as Hodges & Pierce set them out
//! ("Introduction to Structural Dynamics and Aeroelasticity", 2nd ed. 2011, §4.3: the straight
//! wing's Eq. 4.55, the swept wing's parameters τ and β of Eq. 4.103, their linear interaction
//! Eq. 4.113, numbered as AeroBeams.jl's tests cite them; docs/stability.md §4.1).
//!
//! With `y` along the elastic axis (length `l`), `θ` the torsion (nose up), `w` the bending
//! deflection (up), `c` the chord normal to the axis, `e` the distance of the axis behind the
//! aerodynamic centre, `a = 2π`, `Λ` the sweep (positive aft) and `q = ½ρU²`, strip theory gives
//! the lift per unit length `L′ = q c a cos²Λ (θ − w′ tan Λ)`, and
//!
//! `GJ θ″ + e L′ = 0`, `EI w⁗ = L′`, `θ(0) = w(0) = w′(0) = 0`, `θ′(l) = w″(l) = w‴(l) = 0`.
//!
//! Integrating the bending equation twice from the tip, `w″ = GJ/(e EI) (θ(l) − θ)`; with
//! `φ = θ − θ(l)` and `x = y/l` the derivative of the torsion equation is
//!
//! `φ‴ + τ φ′ + β φ = 0`, `τ = q a c e l² cos²Λ / GJ`, `β = q a c l³ sin Λ cos Λ / EI`,
//!
//! with `φ″(0) = 0` (the torsion equation at the clamped root), `φ(1) = 0` and `φ′(1) = 0`.
//! Divergence is the lowest `q` at which this has a solution other than zero: with `F = exp(A)`,
//! `A` the companion matrix of `(φ, φ′, φ″)`, the determinant `F₀₀F₁₁ − F₀₁F₁₀` of the two tip
//! conditions on the two root values left free vanishes. Its limits are Hodges & Pierce's exact
//! ones: `τ_D = π²/4` without bending coupling (β = 0, the straight wing's Eq. 4.55) and
//! `β_D = −6.3297` for a torsionally rigid wing (τ = 0).

use crate::common::root;
use harness::case::{CaseFile, Formulation, Override};
use harness::stability::{StabilityOutput, run_stability};

/// `exp(A)` of a 3 × 3 matrix: Taylor series (30 terms) after scaling to a norm ≤ ½, then
/// squaring back.
fn expm3(a: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mul = |x: &[[f64; 3]; 3], y: &[[f64; 3]; 3]| {
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = (0..3).map(|k| x[i][k] * y[k][j]).sum();
            }
        }
        r
    };
    let norm = a.iter().map(|r| r.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale *= 0.5;
        squarings += 1;
    }
    let a_s = a.map(|r| r.map(|x| x * scale));
    let mut e = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut term = e;
    for k in 1..30 {
        term = mul(&term, &a_s).map(|r| r.map(|x| x / k as f64));
        for i in 0..3 {
            for j in 0..3 {
                e[i][j] += term[i][j];
            }
        }
    }
    for _ in 0..squarings {
        e = mul(&e, &e);
    }
    e
}

/// The characteristic determinant of `φ‴ + τφ′ + βφ = 0`, `φ″(0) = φ(1) = φ′(1) = 0`: 1 at
/// `τ = β = 0`, zero at divergence.
fn characteristic(tau: f64, beta: f64) -> f64 {
    let f = expm3([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-beta, -tau, 0.0]]);
    f[0][0] * f[1][1] - f[0][1] * f[1][0]
}

/// The first zero of `f` on `(0, hi]`: scanned in `n` steps, then bisected to 1e-13.
fn first_zero(f: impl Fn(f64) -> f64, hi: f64, n: usize) -> Option<f64> {
    let mut a = 0.0;
    let mut fa = f(a);
    for i in 1..=n {
        let b = hi * i as f64 / n as f64;
        let fb = f(b);
        if fa.signum() != fb.signum() {
            let (mut lo, mut up) = (a, b);
            while up - lo > 1e-13 * hi {
                let m = 0.5 * (lo + up);
                if f(m).signum() == fa.signum() { lo = m } else { up = m }
            }
            return Some(0.5 * (lo + up));
        }
        (a, fa) = (b, fb);
    }
    None
}

/// The wing of the case file: (GJ, EI flap, chord, e, length, ρ).
fn wing() -> (f64, f64, f64, f64, f64, f64) {
    let text = std::fs::read_to_string(root().join("cases/stability/divergence_swept.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (body, aero) = (&v["bodies"][0], &v["aero"]);
    let num = |x: &serde_json::Value| x.as_f64().unwrap();
    let (chord, le) = (num(&aero["chord"]), num(&aero["le_offset"]));
    // The aerodynamic centre is the quarter chord: e = le_offset − c/4 behind it.
    let e = le - 0.25 * chord;
    (num(&body["section"]["gj"]), num(&body["section"]["ei_yy"]), chord, e, num(&body["length"]), num(&aero["rho"]))
}

/// Diederich & Budiansky's divergence speed of the case's wing at sweep `sweep_deg`, m/s.
fn reference_speed(sweep_deg: f64) -> f64 {
    let (gj, ei, c, e, l, rho) = wing();
    let a = 2.0 * std::f64::consts::PI;
    let (s, co) = sweep_deg.to_radians().sin_cos();
    let det = |q: f64| characteristic(q * a * c * e * l * l * co * co / gj, q * a * c * l.powi(3) * s * co / ei);
    let q = first_zero(det, 5e3, 5000).expect("the wing diverges below 5 kPa");
    (2.0 * q / rho).sqrt()
}

fn both(sweep_deg: f64) -> (StabilityOutput, StabilityOutput) {
    both_with(&format!("bodies.0.sweep_deg={sweep_deg}"))
}

fn both_with(set: &str) -> (StabilityOutput, StabilityOutput) {
    let ov: Vec<Override> = vec![set.parse().unwrap()];
    let spec =
        CaseFile::read(&root().join("cases/stability/divergence_swept.json")).unwrap().expand(&ov).unwrap().remove(0);
    let (a, g) = rayon::join(
        || run_stability(&spec.ancf.problem(), Formulation::Ancf),
        || run_stability(&spec.gebf.problem(), Formulation::Gebf),
    );
    for o in [&a, &g] {
        assert!(o.error.is_none(), "{set} {}: {:?}", o.formulation, o.error);
        assert!(o.points.iter().all(|p| p.error.is_none()), "{set} {}: a point failed", o.formulation);
    }
    (a, g)
}

/// The characteristic equation reproduces Hodges & Pierce's exact limits: `τ_D = π²/4` without
/// bending (1e-12) and `β_D = −6.3297` for a torsionally rigid wing (5e-5), and with them the
/// textbook straight wing `q_D = π² GJ / (4 e c a l²)` (1e-12).
#[test]
fn the_characteristic_equation_has_the_published_limits() {
    let pi = std::f64::consts::PI;
    let tau_d = first_zero(|t| characteristic(t, 0.0), 10.0, 1000).unwrap();
    assert!((tau_d / (pi * pi / 4.0) - 1.0).abs() < 1e-12, "τ_D = {tau_d}");
    let beta_d = -first_zero(|b| characteristic(0.0, -b), 20.0, 2000).unwrap();
    assert!((beta_d / -6.3297 - 1.0).abs() < 5e-5, "β_D = {beta_d}");
    let (gj, _, c, e, l, rho) = wing();
    let q0 = pi * pi * gj / (4.0 * e * c * 2.0 * pi * l * l);
    let u0 = reference_speed(0.0);
    assert!((0.5 * rho * u0 * u0 / q0 - 1.0).abs() < 1e-12, "q_D {} vs {q0}", 0.5 * rho * u0 * u0);
}

/// The swept wing's divergence speed with Theodorsen strips (`harness stability`, both
/// formulations) is within 2 % of Diederich & Budiansky's at −15°, 0° and +15° sweep (measured
/// within 0.02 %: 17.874 / 17.876 against 17.877 m/s, 20.016 / 20.018 against 20.018 m/s,
/// 25.818 / 25.822 against 25.819 m/s, ANCF / GEBF); forward sweep lowers it and aft sweep raises
/// it; ANCF and GEBF within 0.5 % of each other (measured ≤ 0.02 %).
#[test]
fn swept_wing_divergence_matches_diederich_budiansky() {
    let mut speeds = Vec::new();
    for sweep in [-15.0, 0.0, 15.0] {
        let reference = reference_speed(sweep);
        let (a, g) = both(sweep);
        let (da, dg) = (a.divergence_speed.unwrap(), g.divergence_speed.unwrap());
        println!("sweep {sweep:+}°: reference {reference:.4} m/s, ANCF {da:.4}, GEBF {dg:.4}");
        for (d, name) in [(da, "ANCF"), (dg, "GEBF")] {
            assert!((d / reference - 1.0).abs() < 0.02, "sweep {sweep}° {name}: {d} vs {reference} m/s");
        }
        assert!((da / dg - 1.0).abs() < 5e-3, "sweep {sweep}°: ANCF {da} GEBF {dg}");
        speeds.push(da);
    }
    assert!(speeds[0] < speeds[1] && speeds[1] < speeds[2], "{speeds:?}");
}

/// The strips take their sweep from the stream: the unswept wing in sideslip β (the relative wind
/// from the tip, `aero.sideslip_deg`) diverges as the wing swept by −β in a stream without
/// sideslip, the same scene turned about the vertical (1e-8; measured 1e-10 ANCF, bitwise GEBF).
#[test]
fn sideslip_is_sweep_to_the_strips() {
    for beta in [15.0, -15.0] {
        let (sa, sg) = both_with(&format!("aero.sideslip_deg={beta}"));
        let (wa, wg) = both(-beta);
        for (s, w) in [(&sa, &wa), (&sg, &wg)] {
            let (ds, dw) = (s.divergence_speed.unwrap(), w.divergence_speed.unwrap());
            assert!((ds / dw - 1.0).abs() < 1e-8, "β = {beta}° {}: {ds} vs swept {dw}", s.formulation);
        }
    }
}
