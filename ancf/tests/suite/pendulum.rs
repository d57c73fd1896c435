//! The paper's flared double pendulum (docs/cases.md §1) against the external references in
//! `cases/reference/` (Exudyn geometrically exact beam, converged; see its README).
use crate::common;

use ancf::{Model, Options, SolvePath, samples};
use common::*;

/// c = 1, β = 45°, 10 elements per body, dt = 0.0005, rho_inf = 0.8 (the reference's settings):
/// the tip stays within 1 cm of the converged Exudyn solution (80 elements per body) over 2 s.
/// The hinge moment twists and bends body 1 and changes the motion after ~0.5 s, so this
/// checks the flexible dynamics, not just the pendulum. Measured: 2.9 mm.
#[test]
fn beta45_fine_matches_converged_reference_within_1cm() {
    let run = run_pendulum(1.0, 45.0, 10, 0.0005, 0.8, Options::default());
    let (err, t) = max_tip_error(&run, &reference("exudyn/flex_c1_beta45_gebf_n80_dt0.0005.csv"), 0.0);
    println!("c=1 beta=45, 10 el, dt 5e-4: max tip error {err:.3e} m at t = {t:.3} s");
    assert!(err < 0.01, "max tip error {err} m at t = {t} s");
    let worst = run.iter().map(|r| r.residual).fold(0.0, f64::max);
    assert!(worst <= 1e-9, "constraint residual {worst:e}");
}

/// The paper's settings (5 elements, dt = 0.002): the same figure is reported; the bound is the
/// same 1 cm. Measured: 7.3 mm (SHARPy at these settings: 6.9 mm).
#[test]
fn beta45_paper_settings_against_converged_reference() {
    let run = run_pendulum(1.0, 45.0, 5, 0.002, 0.8, Options::default());
    let (err, t) = max_tip_error(&run, &reference("exudyn/flex_c1_beta45_gebf_n80_dt0.0005.csv"), 0.0);
    println!("c=1 beta=45, 5 el, dt 2e-3: max tip error {err:.3e} m at t = {t:.3} s");
    assert!(err < 0.01, "max tip error {err} m at t = {t} s");
    // Every step keeps the joints closed to round-off (DAE path, linear constraints).
    let worst = run.iter().map(|r| r.residual).fold(0.0, f64::max);
    assert!(worst <= 1e-9, "constraint residual {worst:e}");
}

/// β = 0 and β = 90° at the paper's settings against the Exudyn references (40 elements per
/// body), plus the symmetry checks: β = 0 stays in the X–Z plane, β = 90° does not fold.
#[test]
fn beta0_planar_and_beta90_unfolded() {
    let run0 = run_pendulum(1.0, 0.0, 5, 0.002, 0.8, Options::default());
    let max_y = run0.iter().map(|r| r.tip.y.abs()).fold(0.0, f64::max);
    assert!(max_y < 1e-9, "beta = 0 leaves the X-Z plane: |Y| = {max_y:e}");
    let (err0, _) = max_tip_error(&run0, &reference("exudyn/flex_c1_beta0_gebf_n40_dt0.0005.csv"), 0.0);

    let run90 = run_pendulum(1.0, 90.0, 5, 0.002, 0.8, Options::default());
    let max_fold = run90.iter().map(|r| r.fold.abs()).fold(0.0, f64::max).to_degrees();
    assert!(max_fold < 1.0, "beta = 90 folds by {max_fold} deg");
    let (err90, _) = max_tip_error(&run90, &reference("exudyn/flex_c1_beta90_gebf_n40_dt0.0005.csv"), 0.0);
    println!(
        "beta 0: max|Y| {max_y:e} m, tip error {err0:.3e} m; beta 90: max|fold| {max_fold:e} deg, tip error {err90:.3e} m"
    );
    assert!(err0 < 0.01 && err90 < 0.01, "tip errors {err0}, {err90}");
    for run in [&run0, &run90] {
        let worst = run.iter().map(|r| r.residual).fold(0.0, f64::max);
        assert!(worst <= 1e-9, "constraint residual {worst:e}");
    }
}

/// The ODE path (joints eliminated with the constant B) reproduces the DAE path to solver
/// tolerance on the hardest case.
#[test]
fn ode_path_matches_dae_path() {
    let dae = run_pendulum(1.0, 45.0, 5, 0.002, 0.8, Options::default());
    let ode = run_pendulum(1.0, 45.0, 5, 0.002, 0.8, Options { path: SolvePath::Ode, ..Default::default() });
    let diff = dae.iter().zip(&ode).map(|(a, b)| (a.tip - b.tip).norm()).fold(0.0, f64::max);
    println!("DAE vs ODE max tip difference {diff:e} m");
    assert!(diff < 1e-6, "DAE and ODE differ by {diff} m");
    let worst = ode.iter().map(|r| r.residual).fold(0.0, f64::max);
    assert!(worst < 1e-12, "ODE path constraint residual {worst:e}");
}

/// Compared with SHARPy at the paper's settings (SHARPy lags by ≈ dt/2, compared at t − dt/2):
/// reported, bounded loosely (SHARPy itself is 6.9 mm from the converged reference).
#[test]
fn beta45_against_sharpy() {
    let run = run_pendulum(1.0, 45.0, 5, 0.002, 0.8, Options::default());
    let sharpy = reference("sharpy/double_pendulum_c1_beta45_dt0.002.csv");
    // our run at t − dt/2 against SHARPy at t: shift SHARPy's time axis back by dt/2
    let shifted: Vec<_> = sharpy.iter().map(|(t, p)| (t - 0.001, *p)).collect();
    let (err, t) = max_tip_error(&run, &shifted, 0.0);
    println!("c=1 beta=45 vs SHARPy (paper settings): max tip difference {err:.3e} m at t = {t:.3}");
    assert!(err < 0.02, "{err}");
}

/// The diagonal refinement ladder (elements per body, dt) = (5, 2 ms), (10, 1 ms), (20, 0.5 ms),
/// (40, 0.25 ms) on c = 1, β = 45° against the converged Exudyn beam (80 elements per body; its
/// own error ≈ 0.5 mm): the element converges to geometrically exact beam theory, so the error
/// shrinks at every rung and is within 3.5 mm at the finest. Measured: 7.31, 3.81, 2.86,
/// 2.70 mm (GEBF: 7.10, 3.68, 2.71, 2.46 mm).
#[test]
fn beta45_diagonal_ladder_converges_to_the_reference() {
    let reference = reference("exudyn/flex_c1_beta45_gebf_n80_dt0.0005.csv");
    let errors: Vec<f64> = [5, 10, 20, 40]
        .iter()
        .map(|&n| {
            let run = run_pendulum(1.0, 45.0, n, 0.01 / n as f64, 0.8, Options::default());
            max_tip_error(&run, &reference, 0.0).0
        })
        .collect();
    println!("c=1 beta=45 diagonal ladder: max tip errors {:?} mm", errors.iter().map(|e| e * 1e3).collect::<Vec<_>>());
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "the error must shrink at every rung: {errors:?}");
    assert!(errors[3] < 3.5e-3, "40 el/body, dt 0.25 ms: {} m", errors[3]);
}

/// A hinge locked and released on the ODE path, whose independent coordinates change with the
/// joints: `Model::carry_state` passes the state through the full coordinates. Taken 0.2 s into
/// the free pendulum: carried to the ODE path and back to full coordinates it is unchanged (1e-12 m,
/// 1e-9 of the largest rate); locked at its fold, its velocities are
/// those of the DAE path's impact (`genalpha::analysis::impact`, the M-orthogonal projection
/// onto the new null space) and the kinetic energy it loses is the impact's; released again,
/// the kinetic energy it loses is the M-norm of its velocity jump (a projection).
#[test]
fn ode_path_carries_the_state_through_a_lock_and_a_release() {
    use ancf::JointSpec;
    use genalpha::ConstrainedSystem;
    let (bodies, joints, g) = samples::double_pendulum(1.0, 45.0, 5);
    let ode = Options { path: SolvePath::Ode, ..Default::default() };
    let mut model = Model::new(&bodies, &joints, g, Options::default()).expect("valid scene");
    let mut ga = model.integrator(params(0.8, 0.002)).expect("valid parameters");
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).expect("consistent start");
    for _ in 0..100 {
        ga.step(&mut model, &mut s).expect("step");
    }
    let fold = model.fold_angle(&s.q, 1).expect("flared hinge");
    let mut locked_joints = joints.clone();
    locked_joints[1] = JointSpec::LockedHinge { parent: 0, child: 1, beta: 45f64.to_radians(), fold };
    let free_ode = Model::new(&bodies, &joints, g, ode).expect("valid scene");
    let locked_ode = Model::new(&bodies, &locked_joints, g, ode).expect("valid scene");
    let locked_dae = Model::new(&bodies, &locked_joints, g, Options::default()).expect("valid scene");
    assert!(free_ode.n_dof() > locked_ode.n_dof(), "a lock removes independent coordinates");
    let gap = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    let full = |m: &Model, q: &[f64], v: &[f64]| {
        let mut vf = vec![0.0; m.n_full_coords()];
        m.full_velocities_inplace(v, &mut vf);
        (m.full_coordinates(q), vf)
    };

    // (The DAE path's velocities meet the hinge's velocity equations to its Newton tolerance:
    // the projection removes that residue, 4e-12 m/s.)
    let scale = s.v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let (zq, zv) = free_ode.carry_state(&model, &s.q, &s.v).expect("carried");
    let (qf, vf) = full(&free_ode, &zq, &zv);
    println!("DAE → ODE: {:e} m, {:e} of {scale:e} m/s", gap(&qf, &s.q), gap(&vf, &s.v));
    assert!(gap(&qf, &s.q) < 1e-12 && gap(&vf, &s.v) < 1e-9 * scale);

    let (lq, lv) = locked_ode.carry_state(&free_ode, &zq, &zv).expect("locked");
    let hit = genalpha::analysis::impact(&locked_dae, s.t, &s.q, &s.v).expect("impact");
    let (lqf, lvf) = full(&locked_ode, &lq, &lv);
    println!("lock at {fold:.4} rad: velocity gap to the DAE impact {:e} of {scale:e} m/s", gap(&lvf, &hit.velocities));
    // The weld's linear equations at the measured fold hold on the deformed hinge sections only
    // to their strain: the restriction moves the configuration onto them, by the locked model's
    // residual of the free state (the DAE path's first Newton step after the lock does the same).
    let before = locked_dae.constraint_residual(&s.q);
    println!("lock: configuration moved {:e} m; weld residual {before:e}", gap(&lqf, &s.q));
    assert!(gap(&lqf, &s.q) < 2.0 * before);
    assert!(gap(&lvf, &hit.velocities) < 1e-9 * scale, "velocities differ from the impact's");
    let loss = free_ode.energies(&zq, &zv).kinetic - locked_ode.energies(&lq, &lv).kinetic;
    println!("kinetic energy lost {loss:e} J, impact {:e} J", hit.energy_loss);
    assert!(hit.energy_loss > 0.0 && (loss - hit.energy_loss).abs() < 1e-6 * hit.energy_loss);

    let (rq, rv) = free_ode.carry_state(&locked_ode, &lq, &lv).expect("released");
    // The weld leaves the centreline slopes free and the free hinge's axis equation reads them,
    // so the welded state meets the hinge's equations only to the sections' strain too: the
    // release moves it back by as much as the lock moved it, and its velocities lose the part
    // that the hinge's equations forbid — an impact on the hinge sections' slope rates, whose
    // loss is again the M-norm of the jump (the DAE path takes it in its first step).
    let (rqf, rvf) = full(&free_ode, &rq, &rv);
    let loss = locked_ode.energies(&lq, &lv).kinetic - free_ode.energies(&rq, &rv).kinetic;
    let jump: Vec<f64> = lvf.iter().zip(&rvf).map(|(a, b)| a - b).collect();
    let norm = model.energies(&lqf, &jump).kinetic;
    println!(
        "release: configuration moved {:e} m; kinetic energy lost {loss:e} J, ½|Δv|²_M {norm:e} J",
        gap(&rqf, &lqf)
    );
    assert!(gap(&rqf, &lqf) < 2.0 * before);
    assert!(loss >= 0.0 && (loss - norm).abs() < 1e-6 * norm + 1e-14);
}
