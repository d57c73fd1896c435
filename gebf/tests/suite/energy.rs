//! Energy conservation of the c = 1 paper cases at the paper's settings (no aerodynamics, so the
//! exact total energy is constant): with rho_inf = 1 the drift max_t |E(t) − E(0)| stays within
//! 1e-3 of the run's peak kinetic energy in the Chung–Hulbert form of the integrator (the
//! implicit midpoint rule at rho_inf = 1; below). In the default Arnold–Brüls form (the
//! trapezoidal rule at rho_inf = 1) β = 45° is the hardest case (the hinge moment twists
//! and bends body 1 violently near t = 1.5 s): without the position projection its drift is
//! 1.35e-3, with it 0.93e-3; both are O(dt²) (halving dt divides them by ~4). The projection
//! does not remove an error of the hinge's position drift (55 µm and 1.7e-4 rad at the peak):
//! by t = 1.418 s it has added +3.9e-4 of the peak kinetic energy (+4.6e-4 since 1.400 s, mostly
//! kinetic: it rotates the child frame under fixed nodal coordinates), which happens to offset
//! part of the trapezoidal loss analysed below (the same −1.03e-3 + −2.6e-4 as without it).
//! rho_inf = 0.8 dissipates a little; the drift is reported, not hidden.
//!
//! Diagnosis of the β = 45° drift: the energy error is a transient of ~20 steps
//! while the tip whips through the fold at ~27 rad/s (t ≈ 1.42 s), not a growth: E − E(0) goes
//! from −1e-4 (t = 1.402 s) to −1.35e-3 (1.418 s) and back to −2e-5 (1.428 s) of the peak
//! kinetic energy. It is the same for 5 and 10 elements per body and for 2- or 3-point
//! integration of the elastic forces (1.35e-3 / 1.38e-3), falls by 3.85–3.95 per halving of
//! dt for β = 0, 45, 90 (with or without the projection), and ANCF shows the same transient
//! (6.9e-4 at dt 0.002, 1.8e-4 at dt 0.001, drifting without the return); the kinetic energy
//! equals ½ vᵀ M(q) v of the assembled mass matrix to 12 digits. So it is the trapezoidal
//! rule's (rho_inf = 1) O(dt²) error on the floating-frame form, and dt = 0.001 meets the 1e-3
//! criterion; an energy-conserving scheme would be needed to meet it at dt = 0.002.
//!
//! The discrete energy balance split by force group (exact for the trapezoidal rule: each
//! group's energy change minus the trapezoidal work of its tangent-space forces)
//! puts
//! the −1.345e-3 at t = 1.418 s on: body 2's translational inertia −1.032e-3 (kinetic energy
//! change against the trapezoidal work of its inertial forces in its floating frame), the flared
//! hinge's constraint forces −2.57e-4 (angular rows −2.80e-4, linear rows +2.3e-5: B depends on
//! q, so Bᵀμ at t_n does work on the step), gravity −3.7e-5, elastic forces −1.9e-5; body 1's
//! inertia (frame rotating about a fixed axis, v_A = 0) −8e-7, rotary inertia < 2e-7, Newton
//! residual 2e-9. All scale with dt² (dt 0.001: −2.69e-4, −7.3e-5). During the whip itself
//! (1.396 → 1.418 s) the inertia term contributes −1.06e-3 and the constraint term −1.0e-4.
//! Without the constraint term the peak would still be 1.09e-3; without the inertia term
//! 6.6e-4. Writing the frames' translational velocity in global instead of A components (the
//! R³ × SO(3) group instead of the SE(3)-like one) makes the drift worse: 1.78e-3.
//!
//! The cure is where the forces are evaluated. The Chung–Hulbert form enforces the equations at
//! the step's weighted state; at rho_inf = 1 that is the midpoint, where the frame's inertial
//! force `m(Δv/h + ω_mid × W_mid + …)` does exactly the work `Δ(½m|W|²)` up to a term in
//! `Δω × ΔR` (the elastic motion in the frame, small), instead of the trapezoidal rule's
//! `h(ω_{n+1} − ω_n) × …`. Measured at dt 0.002: β = 45° drift 1.6e-4 (2.7e-4 with the
//! projection), β = 0 1.8e-4, β = 90° 1.3e-6; 4.4e-5 for β = 45° at dt 0.001. It is GEBF's
//! choice for energy studies, not its default: at the paper cases' rho_inf = 0.8 it costs 2 %
//! more work on the c = 1 pendulums and 8–13 % on the soft ones. ANCF stays in the Arnold–Brüls
//! form: with its stiff nonlinear elastic forces the midpoint evaluation gains energy (β = 45°:
//! 7.9e-3 at rho_inf = 1, with 8.4 Newton iterations per step; 6.4e-3 at 0.8), the midpoint
//! rule's known weakness in nonlinear elastodynamics (Simo & Tarnow 1992).

use crate::common;
use common::*;
use genalpha::{Form, IntegratorParams};

fn drift(run: &Run) -> (f64, f64) {
    let e0 = run.energy[0].total();
    let t_max = run.energy.iter().map(|e| e.kinetic).fold(0.0, f64::max);
    let d = run.energy.iter().map(|e| (e.total() - e0).abs()).fold(0.0, f64::max);
    (d / t_max, t_max)
}

/// The criterion, in the Chung–Hulbert form (at rho_inf = 1 the implicit midpoint rule, whose
/// gyroscopic and Coriolis forces do no discrete work): measured 1.8e-4 (β = 0), 1.6e-4 (45°;
/// 2.7e-4 with the projection), 1.3e-6 (90°) of the peak kinetic energy.
#[test]
fn energy_drift_with_rho_inf_one() {
    for (beta, stab) in [(0.0, false), (45.0, false), (45.0, true), (90.0, false)] {
        let mut p = IntegratorParams::new(1.0, 0.002);
        p.form = Form::ChungHulbert;
        let run = run_paper_case_with(1.0, beta, stab, p);
        let (d, t_max) = drift(&run);
        println!(
            "rho_inf 1, Chung–Hulbert, beta {beta}, stabilization {stab}: drift {d:.3e} of peak kinetic {t_max:.3} J"
        );
        assert!(d < 1e-3, "beta {beta}: drift {d:.3e}");
    }
}

/// The Arnold–Brüls form (the default; at rho_inf = 1 the trapezoidal rule) meets it for β = 0
/// and 90° but not for 45°: 1.35e-3 without the projection (analysed above), 0.93e-3 with it.
#[test]
fn energy_drift_with_rho_inf_one_arnold_bruls_is_reported() {
    for (beta, stab, bound) in [(0.0, false, 1e-3), (90.0, false, 1e-3), (45.0, true, 1e-3), (45.0, false, 1.5e-3)] {
        let run = run_paper_case(1.0, beta, 1.0, stab);
        let (d, t_max) = drift(&run);
        println!(
            "rho_inf 1, Arnold–Brüls, beta {beta}, stabilization {stab}: drift {d:.3e} of peak kinetic {t_max:.3} J"
        );
        assert!(d < bound, "beta {beta}: drift {d:.3e}");
    }
}

#[test]
fn energy_drift_with_rho_inf_08_is_reported() {
    for beta in [0.0, 45.0, 90.0] {
        let run = run_paper_case(1.0, beta, 0.8, false);
        let (d, t_max) = drift(&run);
        println!("rho_inf 0.8, beta {beta}: drift {d:.3e} of peak kinetic {t_max:.3} J");
        // Numerical dissipation only removes energy: E(t) ≤ E(0) up to the O(dt²) error.
        let e0 = run.energy[0].total();
        let gain = run.energy.iter().map(|e| e.total() - e0).fold(f64::MIN, f64::max) / t_max;
        assert!(gain < 1e-3, "energy gain {gain:.2e}");
        assert!(d < 1e-2);
    }
}

/// The β = 45° drift at rho_inf = 1 is the scheme's O(dt²) error: halving dt divides it by
/// about 4 (measured 3.85: 1.345e-3 → 3.50e-4), so dt = 0.001 meets the 1e-3 criterion.
#[test]
fn beta45_energy_drift_is_second_order_in_dt() {
    let coarse = drift(&run_paper_case_dt(1.0, 45.0, 1.0, false, 0.002)).0;
    let fine = drift(&run_paper_case_dt(1.0, 45.0, 1.0, false, 0.001)).0;
    let ratio = coarse / fine;
    println!("beta 45, rho_inf 1: drift {coarse:.3e} (dt 0.002), {fine:.3e} (dt 0.001), ratio {ratio:.2}");
    assert!(fine < 1e-3, "dt 0.001: drift {fine:.3e}");
    assert!((3.4..4.6).contains(&ratio), "drift ratio {ratio:.2} is not second order");
}
