//! The finite frozen steady wake (`UvlmParams::steady_wake`): it tends to the
//! semi-infinite legs as it grows, it is the converged state of a time march with the same
//! unclosed wake rows, and mirror planes treat it as any other filament.

use approx::assert_relative_eq;
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

const ALPHA_DEG: f64 = 5.0;

/// A flat rectangular wing, chord 1, from `y0` to `y1` (`n_span` strips, 4 chordwise panels),
/// at 5° incidence in a unit free stream (x downstream, z up, lift along +z).
fn wing(y0: f64, y1: f64, n_span: usize, images: Vec<ImagePlane>, steady_wake: SteadyWake) -> Uvlm {
    let st = rectangular_wing(y0, y1, 1.0, n_span, SpanSpacing::Uniform);
    let lat = Lattice::from_stations(LatticeSpec::new(4), &st).unwrap();
    let a = ALPHA_DEG.to_radians();
    let mut p = UvlmParams::new(1.0, [a.cos(), 0.0, a.sin()]);
    p.images = images;
    p.steady_wake = steady_wake;
    Uvlm::new(lat, p).unwrap()
}

fn lift(u: &mut Uvlm) -> f64 {
    let v = u.params().v_inf;
    u.solve_steady().unwrap().lift_drag(v, [0.0, 1.0, 0.0]).0
}

/// A wake 1e4 chords long carries the lift of the semi-infinite legs within 1e-6 (the far
/// closing segment's downwash on an AR-4 wing is of order (b/L)² ≈ 2e-7 of the wing's own); a
/// 10-chord wake carries 0.29 % less (measured; the closing segment's share grows with the span
/// over the wake length: the paper wing's 16-chord lattice loses 1.32 % to its 10-chord wake).
#[test]
fn a_very_long_finite_wake_is_the_semi_infinite_one() {
    let infinite = lift(&mut wing(-2.0, 2.0, 8, Vec::new(), SteadyWake::SemiInfinite));
    let long = lift(&mut wing(-2.0, 2.0, 8, Vec::new(), SteadyWake::Finite { length: 1e4 }));
    assert_relative_eq!(long, infinite, max_relative = 1e-6);
    let short = lift(&mut wing(-2.0, 2.0, 8, Vec::new(), SteadyWake::Finite { length: 10.0 }));
    let ratio = short / infinite;
    println!("L(10 c) / L(∞) = {ratio:.6}");
    assert!(ratio < 0.998 && ratio > 0.995, "ratio {ratio}");
}

/// The finite steady solution is the converged state of the time-marching solver whose wake
/// has the same rows: 10 rows of U·dt = 0.25 chord, no closure (L = 2.5 chords, short enough for
/// the truncation to move the lift by several per cent), marched impulsively for 400 steps.
/// Total lift within 1e-6, circulations within 1e-6 of the largest.
#[test]
fn the_finite_steady_wake_is_the_converged_time_march() {
    let (rows, dt) = (10, 0.25);
    let mut steady = wing(-2.0, 2.0, 8, Vec::new(), SteadyWake::Finite { length: rows as f64 * dt });
    let l_steady = lift(&mut steady);
    let l_infinite = lift(&mut wing(-2.0, 2.0, 8, Vec::new(), SteadyWake::SemiInfinite));
    let st = rectangular_wing(-2.0, 2.0, 1.0, 8, SpanSpacing::Uniform);
    let lat = Lattice::from_stations(LatticeSpec::new(4), &st).unwrap();
    let mut p = steady.params().clone();
    p.n_wake_rows = rows;
    p.wake_closure = false;
    let mut march = Uvlm::new(lat, p.clone()).unwrap();
    let mut l_march = 0.0;
    for _ in 0..400 {
        l_march = march.step(dt).unwrap().lift_drag(p.v_inf, [0.0, 1.0, 0.0]).0;
    }
    println!("march {l_march:.12}, finite steady {l_steady:.12}, semi-infinite {l_infinite:.12}");
    assert!(l_infinite / l_steady > 1.02, "the short wake must matter: {l_infinite} vs {l_steady}");
    assert_relative_eq!(l_march, l_steady, max_relative = 1e-6);
    let gmax = steady.gamma().iter().fold(0.0f64, |a, g| a.max(g.abs()));
    for (gm, gs) in march.gamma().iter().zip(steady.gamma()) {
        assert!((gm - gs).abs() <= 1e-6 * gmax, "{gm} vs {gs}");
    }
}

/// Images: a half wing with a symmetry plane equals the full wing (circulations and forces),
/// and a ground plane raises the lift of the finite wake as of the semi-infinite one.
#[test]
fn mirror_planes_reflect_the_finite_wake() {
    let w = SteadyWake::Finite { length: 3.0 };
    let mut full = wing(-2.0, 2.0, 8, Vec::new(), w);
    let mut half = wing(0.0, 2.0, 4, vec![ImagePlane::through_origin([0.0, 1.0, 0.0])], w);
    full.solve_steady().unwrap();
    half.solve_steady().unwrap();
    let (n, nh) = (8, 4);
    let gmax = full.gamma().iter().fold(0.0f64, |a, g| a.max(g.abs()));
    for i in 0..4 {
        for j in 0..nh {
            let (gf, gh) = (full.gamma()[i * n + nh + j], half.gamma()[i * nh + j]);
            assert!((gf - gh).abs() <= 1e-10 * gmax, "ring ({i},{j}): {gf} vs {gh}");
        }
    }
    let (ff, fh) = (full.loads().total_force(), half.loads().total_force());
    assert_relative_eq!(ff[2], 2.0 * fh[2], max_relative = 1e-10);
    assert_relative_eq!(ff[0], 2.0 * fh[0], max_relative = 1e-10);
    let sym = ImagePlane::through_origin([0.0, 1.0, 0.0]);
    let ground = ImagePlane { point: [0.0, 0.0, -0.5], normal: [0.0, 0.0, 1.0] };
    let free = lift(&mut wing(0.0, 2.0, 4, vec![sym], w));
    let near = lift(&mut wing(0.0, 2.0, 4, vec![sym, ground], w));
    assert!(near > 1.05 * free, "ground effect: {near} vs {free}");
}
