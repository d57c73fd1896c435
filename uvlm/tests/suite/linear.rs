//! The linearised UVLM in the Laplace domain (docs/uvlm.md §13) against Theodorsen's theory:
//! harmonic pitch about the quarter chord and plunge of a 2D-like wing, lift and quarter-chord
//! moment. About the quarter chord both moments are pure apparent-mass (non-circulatory) terms,
//! so they test the ρ·A·n·dΓ/dt load term on their own; the lifts test the wake.

use crate::common;

use common::reference_csv;
use nalgebra::{Complex, DMatrix, DVector, Rotation3, Vector3};
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

type C = Complex<f64>;
/// Residual and nodal-force derivatives of one motion.
type Pair = (DVector<f64>, DVector<f64>);

/// Theodorsen's C(k) by linear interpolation of the reference table (k in the table only).
fn theodorsen_c(table: &[Vec<f64>], k: f64) -> C {
    let row = table.iter().find(|r| (r[0] - k).abs() < 1e-12).expect("k in theodorsen.csv");
    C::new(row[1], row[2])
}

struct Wing {
    lin: LinearUvlm,
    base: Vec<SpanStation>,
    span: f64,
}

/// AR-`ar` half wing with a symmetry plane, chord 1 (b = 0.5), ρ = U = 1, stream along +x,
/// `nc` chordwise panels, a frozen wake of `rows` rows of length `dx` closed by legs.
fn wing(ar: f64, n_half: usize, nc: usize, rows: usize, dx: f64) -> Wing {
    let base = rectangular_wing(0.0, 0.5 * ar, 1.0, n_half, SpanSpacing::HalfCosine);
    let lat = Lattice::from_stations(LatticeSpec::new(nc), &base).unwrap();
    let mut p = UvlmParams::new(1.0, [1.0, 0.0, 0.0]);
    p.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    let mut u = Uvlm::new(lat, p).unwrap();
    let lin = u.linearise(&LinearWake::uniform(rows, dx, true)).unwrap();
    Wing { lin, base, span: 0.5 * ar }
}

/// Stations moved by pitch `al` about the quarter chord and plunge `h` (up), with velocities
/// `(al_dot, h_dot)`.
fn moved(base: &[SpanStation], al: f64, h: f64, al_dot: f64, h_dot: f64) -> (Vec<SpanStation>, Vec<StationVelocity>) {
    let r = Rotation3::from_axis_angle(&Vector3::y_axis(), al);
    let st: Vec<SpanStation> = base
        .iter()
        .map(|s| {
            let qc = Vector3::new(0.25, s.origin.y, 0.0);
            SpanStation {
                origin: qc + r * (s.origin - qc) + Vector3::new(0.0, 0.0, h),
                frame: r.matrix() * s.frame,
                ..*s
            }
        })
        .collect();
    let om = Vector3::new(0.0, al_dot, 0.0);
    let vel = st
        .iter()
        .map(|s| StationVelocity {
            linear: om.cross(&(s.origin - Vector3::new(0.25, s.origin.y, 0.0))) + Vector3::new(0.0, 0.0, h_dot),
            angular: om,
        })
        .collect();
    (st, vel)
}

/// Residual and nodal forces of the lattice moved as `moved` says.
fn eval(w: &Wing, al: f64, h: f64, ad: f64, hd: f64) -> (DVector<f64>, DVector<f64>) {
    let (st, vel) = moved(&w.base, al, h, ad, hd);
    let mut lat = w.lin.lattice().clone();
    lat.update_stations(&st, Some(&vel)).unwrap();
    let (r, f) = w.lin.evaluate(&lat).unwrap();
    (DVector::from_vec(r), DVector::from_vec(f))
}

/// Lift (z) and quarter-chord pitching moment (about +y, nose up) per unit span of stacked
/// nodal forces `f` on the reference lattice.
fn lift_moment(w: &Wing, f: &DVector<C>) -> (C, C) {
    let nodes = w.lin.lattice().ring_nodes();
    let (mut l, mut m) = (C::new(0.0, 0.0), C::new(0.0, 0.0));
    for (k, x) in nodes.iter().enumerate() {
        let (fx, fz) = (f[3 * k], f[3 * k + 2]);
        l += fz;
        // (r × F)_y = r_z F_x − r_x F_z, r from the quarter-chord line.
        m += fx * x[2] - fz * (x[0] - 0.25);
    }
    (l / w.span, m / w.span)
}

/// Lift and moment per unit amplitude of a motion with geometric terms (R_x, F_x) and rate
/// terms (R_ẋ, F_ẋ), at s = i k / b.
fn response(w: &Wing, s: C, geo: &Pair, rate: &Pair) -> (C, C) {
    let rhs: DVector<C> = geo.0.map(C::from) + rate.0.map(|x| s * x);
    let dgamma = -w.lin.normalwash_matrix(s).lu().solve(&rhs).unwrap();
    let f: DVector<C> = w.lin.force_matrix(s) * dgamma + geo.1.map(C::from) + rate.1.map(|x| s * x);
    lift_moment(w, &f)
}

/// Derivatives of (residual, forces) along pitch or plunge: central difference in position, and
/// the exact (linear) velocity part.
fn derivatives(w: &Wing, pitch: bool) -> (Pair, Pair) {
    let e = 1e-6;
    let (a, h) = if pitch { (e, 0.0) } else { (0.0, e) };
    let (rp, fp) = eval(w, a, h, 0.0, 0.0);
    let (rm, fm) = eval(w, -a, -h, 0.0, 0.0);
    let geo = ((rp - rm) / (2.0 * e), (fp - fm) / (2.0 * e));
    let (ad, hd) = if pitch { (1.0, 0.0) } else { (0.0, 1.0) };
    let (rp, fp) = eval(w, 0.0, 0.0, ad, hd);
    let (rm, fm) = eval(w, 0.0, 0.0, -ad, -hd);
    let rate = ((rp - rm) / 2.0, (fp - fm) / 2.0);
    (geo, rate)
}

/// Theodorsen (a = −½, ρ = U = 1, b = ½) per unit pitch and per unit plunge (up):
/// pitch: L = πb²(U α̇ + b/2 α̈) + 2πUb C (U α + b α̇), M_c/4 = −πb³(U α̇ + 3/8 b α̈);
/// plunge up h = −h_down: L = −πb² ḧ − 2πUb C ḣ, M_c/4 = +πb³/2 ḧ (moment nose-up).
fn theory(s: C, c: C) -> [(C, C); 2] {
    let (b, pi) = (0.5, std::f64::consts::PI);
    let pitch_l = pi * b * b * (s + 0.5 * b * s * s) + 2.0 * pi * b * c * (1.0 + b * s);
    let pitch_m = -pi * b.powi(3) * (s + 0.375 * b * s * s);
    let plunge_l = -pi * b * b * s * s - 2.0 * pi * b * c * s;
    let plunge_m = 0.5 * pi * b.powi(3) * s * s;
    [(pitch_l, pitch_m), (plunge_l, plunge_m)]
}

/// Errors of the linear model against Theodorsen at `nc` chordwise panels (wake rows of one
/// panel length over 30 chords), per k in `KS`: (pitch lift, plunge lift) as complex ratios to
/// theory, the lifts normalised by the wing's own steady lift slope (which takes out the 3D
/// lift-slope loss of AR 200), and (pitch moment, plunge moment) about the quarter chord per
/// unit span, not normalised.
fn theodorsen_errors(nc: usize) -> Vec<[C; 4]> {
    let table: Vec<Vec<f64>> =
        reference_csv("theodorsen.csv").iter().map(|r| r.iter().map(|x| x.parse().unwrap()).collect()).collect();
    let w = wing(200.0, 12, nc, 30 * nc, 1.0 / nc as f64);
    let pitch = derivatives(&w, true);
    let plunge = derivatives(&w, false);
    let l_alpha = response(&w, C::new(0.0, 0.0), &pitch.0, &pitch.1).0.re;
    let scale = std::f64::consts::PI / l_alpha;
    KS.iter()
        .map(|&k| {
            let s = C::new(0.0, k / 0.5);
            let th = theory(s, theodorsen_c(&table, k));
            let (lp, mp) = response(&w, s, &pitch.0, &pitch.1);
            let (lh, mh) = response(&w, s, &plunge.0, &plunge.1);
            let e = [lp * scale / th[0].0, lh * scale / th[1].0, mp / th[0].1, mh / th[1].1];
            println!(
                "nc = {nc}, k = {k}: lift pitch {:+.2} % {:+.2}°, plunge {:+.2} % {:+.2}°; c/4 moment pitch {:+.2} % {:+.2}°, plunge {:+.2} % {:+.2}°",
                100.0 * (e[0].norm() - 1.0),
                e[0].arg().to_degrees(),
                100.0 * (e[1].norm() - 1.0),
                e[1].arg().to_degrees(),
                100.0 * (e[2].norm() - 1.0),
                e[2].arg().to_degrees(),
                100.0 * (e[3].norm() - 1.0),
                e[3].arg().to_degrees()
            );
            e
        })
        .collect()
}

const KS: [f64; 5] = [0.1, 0.3, 0.5, 1.0, 2.0];

/// Harmonic pitch about the quarter chord and plunge, k = 0.1 … 2, at 8 and 16 chordwise panels.
/// Lifts: phase within 3° at 16 panels; amplitude error smaller than at 8 panels and below 6 % for
/// k ≥ 0.3, and within 3 % at k = 0.1. Part of the lift error is a 3-D offset of about 2 % that
/// does not refine away (2.26 / 2.17 / 2.13 % at 8 / 16 / 32 panels at k = 0.1); the rest
/// halves with the panel size. Moments about the quarter chord, which are
/// Theodorsen's apparent-mass terms alone (πρb²-terms; the circulatory lift acts at the quarter
/// chord): error at 16 panels at most 0.6 × that at 8, at every k and for both motions, and within
/// 12 % and 3° at k ≥ 0.5 in pitch. Measured (release), pitch at k = 0.5 / 1 / 2: lift +4.9 /
/// +6.7 / +8.8 % at 8 panels, +3.4 / +4.1 / +5.5 % at 16, +2.6 / +2.7 / +3.7 % at 32; moment
/// +20.4 / +17.7 / +17.4 %, +10.3 / +8.9 / +9.0 %, +5.2 / +4.3 / +4.6 %.
#[test]
fn linear_uvlm_converges_to_theodorsen_pitch_and_plunge() {
    let coarse = theodorsen_errors(8);
    let fine = theodorsen_errors(16);
    for (i, &k) in KS.iter().enumerate() {
        for m in 0..2 {
            let (ec, ef) = (coarse[i][m], fine[i][m]);
            assert!(ef.arg().to_degrees().abs() < 3.0, "k = {k} lift {m}: phase {ef}");
            let (ac, af) = ((ec.norm() - 1.0).abs(), (ef.norm() - 1.0).abs());
            if k >= 0.3 {
                assert!(af < ac && af < 0.06, "k = {k} lift {m}: {af} at 16 panels vs {ac} at 8");
            } else {
                assert!(af < 0.03, "k = {k} lift {m}: {ef}");
            }
        }
        for m in 2..4 {
            let (ec, ef) = ((coarse[i][m] - 1.0).norm(), (fine[i][m] - 1.0).norm());
            assert!(ef <= 0.6 * ec, "k = {k} moment {m}: error {ef} at 16 panels vs {ec} at 8");
        }
        if k >= 0.5 {
            let e = fine[i][2];
            assert!((e.norm() - 1.0).abs() < 0.12 && e.arg().to_degrees().abs() < 3.0, "k = {k} pitch moment: {e}");
        }
    }
}

/// The steady limit: at s = 0 with a closed wake the linear model's lift derivative equals the
/// difference quotient of the nonlinear steady solver.
#[test]
fn linear_uvlm_steady_limit() {
    let w = wing(8.0, 8, 4, 200, 0.25);
    let pitch = derivatives(&w, true);
    let l = response(&w, C::new(0.0, 0.0), &pitch.0, &pitch.1).0.re * w.span;
    let lat = w.lin.lattice().clone();
    let steady = |al: f64| {
        let mut u = Uvlm::new(lat.clone(), w.lin.params().clone()).unwrap();
        u.update_stations(&moved(&w.base, al, 0.0, 0.0, 0.0).0, None).unwrap();
        u.solve_steady().unwrap().total_force()[2]
    };
    let fd = (steady(1e-5) - steady(-1e-5)) / 2e-5;
    println!("steady lift slope: linear {l:.6}, nonlinear {fd:.6}");
    assert!((l / fd - 1.0).abs() < 2e-3, "{l} vs {fd}");
    let _ = DMatrix::<f64>::zeros(1, 1);
}
/// The linear model is the time-marching scheme's linearisation: harmonic pitch of the
/// AR-200 wing (8 chordwise panels, 96 rows of U·dt = panel length) marched for six cycles
/// against the Laplace-domain transfer at s = iω, first harmonic of the lift within 0.5 % (complex
/// ratio) at k = 0.1, 0.3, 0.5, without and with the trailing-edge segment's force (its net
/// circulation Γ_w0 − Γ_TE, shed one step ago). (Measured: 0.01 %, 0.12 %, 0.28 % without it.)
#[test]
fn linear_matches_time_marching() {
    // The two variants are independent: run them in parallel.
    rayon::join(|| linear_matches_time_marching_with(false), || linear_matches_time_marching_with(true));
}

fn linear_matches_time_marching_with(te_segment_force: bool) {
    let (ar, n_half, nc) = (200.0, 16, 8);
    let base = rectangular_wing(0.0, 0.5 * ar, 1.0, n_half, SpanSpacing::HalfCosine);
    let lat = Lattice::from_stations(LatticeSpec::new(nc), &base).unwrap();
    let mut p = UvlmParams::new(1.0, [1.0, 0.0, 0.0]);
    p.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    p.n_wake_rows = 96;
    p.te_segment_force = te_segment_force;
    let mut u0 = Uvlm::new(lat.clone(), p.clone()).unwrap();
    let lin = u0.linearise(&LinearWake::uniform(96, 1.0 / nc as f64, false)).unwrap();
    let w = Wing { lin, base: base.clone(), span: 0.5 * ar };
    let pitch = derivatives(&w, true);
    for k in [0.1, 0.3, 0.5] {
        let (b, da) = (0.5, 1e-3);
        let om = k / b;
        let (lt, _) = response(&w, C::new(0.0, om), &pitch.0, &pitch.1);
        let period = 2.0 * std::f64::consts::PI / om;
        let n_per = (period * nc as f64).round() as usize;
        let dt = period / n_per as f64;
        let mut u = Uvlm::new(lat.clone(), p.clone()).unwrap();
        let (mut c, mut s) = (0.0, 0.0);
        for n in 1..=6 * n_per {
            let t = n as f64 * dt;
            let (al, ad) = (da * (om * t).sin(), da * om * (om * t).cos());
            let (st, vel) = moved(&base, al, 0.0, ad, 0.0);
            u.update_stations(&st, Some(&vel)).unwrap();
            let l = u.step(dt).unwrap().total_force()[2] / w.span;
            if n > 5 * n_per {
                c += 2.0 * l * (om * t).cos() / n_per as f64;
                s += 2.0 * l * (om * t).sin() / n_per as f64;
            }
        }
        let lm = C::new(s, c) / da;
        println!("TE force {te_segment_force}, k = {k}: linear {lt:.4} marching {lm:.4} ratio {:.4}", lt / lm);
        assert!((lt / lm - 1.0).norm() < 5e-3, "TE force {te_segment_force}, k = {k}: {lt} vs {lm}");
    }
}
