//! Gust response of a rigid flat wing against thin-aerofoil theory (docs/gust.md §5): a
//! sharp-edged gust against the exact Küssner function, sinusoidal gusts against Sears' function,
//! and the lift of a 1-cos gust under lattice and time refinement.
//!
//! The wing is a high-aspect-ratio rectangle (chord 1, AR 200, a half wing with a symmetry
//! plane, as in the Theodorsen test), U = 1 along +x, the gust along +z. Lift of the strip next
//! to the symmetry plane (the mid-span of the full wing), normalised by the same strip's steady
//! lift in a uniform upwash of the gust's amplitude (so the finite span's lift slope drops out).

use uvlm::gust_theory::{Kussner, sears};
use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

const W0: f64 = 0.01;

fn wing(nc: usize, n_half: usize, ar: f64, spacing: SpanSpacing) -> (Lattice, UvlmParams) {
    let st = rectangular_wing(0.0, 0.5 * ar, 1.0, n_half, spacing);
    let lat = Lattice::from_stations(LatticeSpec::new(nc), &st).unwrap();
    let mut p = UvlmParams::new(1.0, [1.0, 0.0, 0.0]);
    p.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    // The harness's default: the treecode (1e-6 |V∞|) once the far wake reaches its size.
    p.wake_aggregation =
        WakeAggregation { min_segments: WakeAggregation::AUTO_MIN_SEGMENTS, ..WakeAggregation::treecode() };
    (lat, p)
}

fn strip_lift(l: &Loads) -> f64 {
    lift_drag_of(l.strip[0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).0
}

fn total_lift(l: &Loads) -> f64 {
    lift_drag_of(l.total_force(), [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).0
}

/// Steady lift (strip, total) in a uniform upwash W0.
fn steady(lat: &Lattice, p: &UvlmParams) -> (f64, f64) {
    let mut u = Uvlm::new(lat.clone(), p.clone()).unwrap();
    u.set_disturbance(Some(Box::new(Uniform([0.0, 0.0, W0]))));
    let l = u.solve_steady().unwrap();
    (strip_lift(l), total_lift(l))
}

/// Küssner: 16 and 32 chordwise panels, U·dt = panel length, the front at the leading edge at
/// t = 0, s = 2 U t / c from 2 to 24 semichords (the wake is never truncated). The sharp front
/// crossing the last collocation point near s = 2 gives a one-step spike of the ρ A n dΓ/dt term
/// whose size falls with the panel length (so the error falls with refinement); the finest
/// lattice is checked within 3 % of the final lift.
#[test]
fn sharp_edged_gust_follows_exact_kussner() {
    let psi = Kussner::default();
    let mut errors = Vec::new();
    for nc in [16, 32] {
        let (lat, mut p) = wing(nc, 16, 200.0, SpanSpacing::HalfCosine);
        let dt = 1.0 / nc as f64;
        let n_steps = 12 * nc;
        p.n_wake_rows = n_steps + 1;
        let (l_inf, _) = steady(&lat, &p);
        let conv = Convection::new([1.0, 0.0, 0.0], [0.0; 3], 0.0).unwrap();
        let gust = SharpEdged::new(conv, W0, [0.0, 0.0, 1.0]).unwrap();
        let mut u = Uvlm::new(lat, p).unwrap();
        u.set_disturbance(Some(Box::new(gust)));
        let (mut worst, mut at) = (0.0_f64, 0.0);
        for n in 1..=n_steps {
            let l = strip_lift(u.step(dt).unwrap()) / l_inf;
            let s = 2.0 * n as f64 * dt;
            if s >= 2.0 - 1e-12 {
                let e = (l - psi.psi(s)).abs();
                if e > worst {
                    (worst, at) = (e, s);
                }
            }
            if (s - s.round()).abs() < 1e-9 && (s.round() as usize).is_multiple_of(2) && s <= 24.0 {
                println!("Kussner nc = {nc}: s = {s:5.2}: L/L_inf = {l:.4}, exact psi = {:.4}", psi.psi(s));
            }
        }
        println!("Kussner nc = {nc}: max |L/L_inf - psi| = {worst:.4} (at s = {at:.3}) over s in [2, 24]");
        errors.push((worst, at));
    }
    assert!(errors[1].0 < errors[0].0, "no convergence to Küssner: {errors:?}");
    let (worst, at) = errors[1];
    assert!(worst < 0.03, "sharp-edged gust: {worst} of the final lift off Küssner at s = {at}");
}

/// Sears: the gust `w₀ sin(ω t − k_x (x − c/2))` over all space (phase zero at mid-chord), the
/// first harmonic of the lift over the third cycle, the wake never truncated, 8 spanwise panels on
/// the half wing, U·dt the chordwise panel length; normalised by the steady lift in the upwash w₀;
/// against S(k) within 3 % and 3° on the finer lattice of each k.
#[test]
fn sinusoidal_gust_follows_sears() {
    let mut last = (0.0, 0.0, 0.0);
    for (k, nc) in [(0.1, 8), (0.25, 16), (0.5, 16), (0.5, 32), (1.0, 32), (1.0, 64)] {
        let (lat, mut p) = wing(nc, 8, 200.0, SpanSpacing::HalfCosine);
        let (b, omega) = (0.5, 2.0 * k);
        let period = 2.0 * std::f64::consts::PI / omega;
        let n_per = (period * nc as f64).round() as usize;
        let dt = period / n_per as f64;
        let cycles = 3;
        p.n_wake_rows = cycles * n_per + 1;
        let (l_qs, _) = steady(&lat, &p);
        let conv = Convection::new([1.0, 0.0, 0.0], [b, 0.0, 0.0], 0.0).unwrap();
        let gust = Sinusoidal::new(conv, W0, period, None, true, [0.0, 0.0, 1.0]).unwrap();
        let mut u = Uvlm::new(lat, p).unwrap();
        u.set_disturbance(Some(Box::new(gust)));
        let mut fits = Vec::new();
        let (mut a, mut c) = (0.0, 0.0);
        for n in 1..=cycles * n_per {
            let t = n as f64 * dt;
            let l = strip_lift(u.step(dt).unwrap()) / l_qs;
            a += 2.0 * l * (omega * t).sin() / n_per as f64;
            c += 2.0 * l * (omega * t).cos() / n_per as f64;
            if n % n_per == 0 {
                fits.push((a, c));
                (a, c) = (0.0, 0.0);
            }
        }
        let s = sears(k);
        let (tamp, tph) = (s.norm(), s.im.atan2(s.re).to_degrees());
        // L/L_qs = Re S sin ωt + Im S cos ωt for an input sin ωt at the mid-chord.
        for (cy, &(a, c)) in fits.iter().enumerate() {
            let (amp, ph) = ((a * a + c * c).sqrt(), c.atan2(a).to_degrees());
            println!(
                "Sears k = {k}, {nc} chordwise, cycle {}: |L|/L_qs {amp:.4} vs |S| {tamp:.4} ({:+.2} %), phase {ph:.2} deg vs {tph:.2} deg ({:+.2} deg)",
                cy + 1,
                100.0 * (amp / tamp - 1.0),
                ph - tph
            );
        }
        let (a, c) = fits[cycles - 1];
        let (amp, ph) = ((a * a + c * c).sqrt(), c.atan2(a).to_degrees());
        if last.0 == k {
            // The finer lattice of this k: closer, and within the tolerance.
            assert!((amp / tamp - 1.0).abs() < (last.1 / tamp - 1.0).abs() + 1e-3, "k = {k}: no convergence");
            assert!((amp / tamp - 1.0).abs() < 0.03, "k = {k}: amplitude {amp} vs {tamp}");
            assert!((ph - tph).abs() < 3.0, "k = {k}: phase {ph} vs {tph}");
        } else if k < 0.4 {
            assert!((amp / tamp - 1.0).abs() < 0.03, "k = {k}: amplitude {amp} vs {tamp}");
            assert!((ph - tph).abs() < 3.0, "k = {k}: phase {ph} vs {tph}");
        }
        last = (k, amp, ph);
    }
}

/// A 1-cos gust (gradient 2 chords, peak w₀) on an AR-8 rectangular wing: the peak total lift
/// over the steady lift in the upwash w₀ on three lattices, chordwise × half-span panels
/// 4 × 8, 8 × 16, 16 × 32, each with U·dt = the chordwise panel length (lattice and time refined
/// together). The change between levels falls by more than half from one level to the next; the
/// printed Richardson estimate (first order) gives the remaining error of the finest level.
#[test]
fn one_minus_cosine_lift_converges_under_refinement() {
    let h = 2.0;
    let mut peaks = Vec::new();
    for (nc, n_half) in [(4, 8), (8, 16), (16, 32)] {
        let (lat, mut p) = wing(nc, n_half, 8.0, SpanSpacing::Uniform);
        let dt = 1.0 / nc as f64;
        let n_steps = (10.0 / dt) as usize;
        p.n_wake_rows = n_steps;
        let (_, l_qs) = steady(&lat, &p);
        let conv = Convection::new([1.0, 0.0, 0.0], [0.0; 3], 0.0).unwrap();
        let gust = OneMinusCosine::new(conv, h, W0, [0.0, 0.0, 1.0]).unwrap();
        let mut u = Uvlm::new(lat, p).unwrap();
        u.set_disturbance(Some(Box::new(gust)));
        let mut peak = (0.0_f64, 0.0);
        for n in 1..=n_steps {
            let l = total_lift(u.step(dt).unwrap()) / l_qs;
            if l > peak.0 {
                peak = (l, n as f64 * dt);
            }
        }
        println!("1-cos ladder: {nc} x {n_half} panels, dt = {dt}: peak L/L_qs = {:.5} at t = {:.3}", peak.0, peak.1);
        peaks.push(peak.0);
    }
    let (d1, d2) = ((peaks[1] - peaks[0]).abs(), (peaks[2] - peaks[1]).abs());
    let r = d2 / d1;
    let extrapolated = peaks[2] + (peaks[2] - peaks[1]) * r / (1.0 - r);
    println!(
        "1-cos ladder: changes {d1:.5}, {d2:.5} (ratio {r:.2}); extrapolated peak {extrapolated:.5}, finest level {:+.2} % off it",
        100.0 * (peaks[2] / extrapolated - 1.0)
    );
    assert!(d2 < 0.5 * d1, "no convergence: changes {d1}, {d2}");
    assert!((peaks[2] / extrapolated - 1.0).abs() < 0.03, "finest level more than 3 % off the extrapolation");
}
