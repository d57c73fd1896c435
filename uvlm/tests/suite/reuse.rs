//! Reuse of the far wake's induction within a step ([`WakeReuse::Frozen`], docs/uvlm.md §9)
//! against recomputing it at every solve ([`WakeReuse::Recompute`]).

use uvlm::samples::FlaredWing;
use uvlm::*;

/// The paper's wing at 5° folding harmonically (fold amplitude 0.2 rad, 1 Hz), 25 m/s, dt 0.01 s,
/// 20-row wake, closure legs, a mirror plane at the root (every filament family present).
fn solver(reuse: WakeReuse) -> (Uvlm, FlaredWing) {
    let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
    let lat = Lattice::from_stations(wing.spec(), &wing.stations(0.0)).unwrap();
    let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
    p.n_wake_rows = 20;
    p.wake_closure = true;
    p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
    p.wake_reuse = reuse;
    (Uvlm::new(lat, p).unwrap(), wing)
}

fn fold(k: usize) -> f64 {
    0.2 * (2.0 * std::f64::consts::PI * 0.01 * k as f64).sin()
}

/// Runs 30 steps; each step solves first at a lattice whose fold is off by `delta` (rad, the
/// coupling's predictor error), then at the true lattice (the last sub-iteration), and commits.
/// Returns the largest relative difference of the total force between the two modes over the
/// steps, and of Γ relative to max |Γ|.
fn frozen_against_recompute(delta: f64) -> (f64, f64) {
    let (mut a, wing) = solver(WakeReuse::Recompute);
    let (mut b, _) = solver(WakeReuse::Frozen);
    march_both(&mut a, &mut b, &wing, delta, 30)
}

/// March `a` and `b` side by side over `steps` steps of two solves (at the fold off by `delta`,
/// then at the true fold); the largest relative differences of the total force and of Γ
/// (relative to max |Γ|) over the steps.
fn march_both(a: &mut Uvlm, b: &mut Uvlm, wing: &FlaredWing, delta: f64, steps: usize) -> (f64, f64) {
    let (mut df, mut dg) = (0.0_f64, 0.0_f64);
    for k in 1..=steps {
        for u in [&mut *a, &mut *b] {
            u.advance_wake(0.01).unwrap();
            u.update_stations(&wing.stations(fold(k) + delta), None).unwrap();
            u.solve_step().unwrap();
            u.update_stations(&wing.stations(fold(k)), None).unwrap();
            u.solve_step().unwrap();
            u.commit_step().unwrap();
        }
        let (fa, fb) = (a.loads().total_force(), b.loads().total_force());
        let norm = (fa[0] * fa[0] + fa[1] * fa[1] + fa[2] * fa[2]).sqrt();
        let diff = ((fa[0] - fb[0]).powi(2) + (fa[1] - fb[1]).powi(2) + (fa[2] - fb[2]).powi(2)).sqrt();
        df = df.max(diff / norm);
        let gmax = a.gamma().iter().fold(0.0_f64, |m, g| m.max(g.abs()));
        let gd = a.gamma().iter().zip(b.gamma()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        dg = dg.max(gd / gmax);
    }
    (df, dg)
}

/// Without motion between the solves of a step the two modes are the same computation summed in
/// another order: equal to rounding.
#[test]
fn frozen_wake_equals_recompute_when_the_lattice_does_not_move_within_a_step() {
    let (df, dg) = frozen_against_recompute(0.0);
    assert!(df < 1e-12 && dg < 1e-12, "force {df:e}, gamma {dg:e}");
}

/// With the lattice moved between the first and the last solve of a step, the frozen far wake is
/// evaluated at the first solve's points: the error is first order in the motion (the far wake's
/// velocity gradient times the displacement). A fold error of 1e-4 rad (0.4 mm at the tip, far
/// more than the predictor error of a converged coupling) changes the force by 1.9e-6 of itself
/// and the circulations by 1.2e-5 of the largest (measured; bounds 5e-6 and 3e-5), and ten times
/// less motion gives ten times less error.
#[test]
fn frozen_wake_error_is_first_order_in_the_motion_within_a_step() {
    let (df1, dg1) = frozen_against_recompute(1e-4);
    let (df2, dg2) = frozen_against_recompute(1e-5);
    println!("fold error 1e-4: force {df1:.3e}, gamma {dg1:.3e}; 1e-5: force {df2:.3e}, gamma {dg2:.3e}");
    assert!(df1 < 5e-6 && dg1 < 3e-5, "force {df1:e}, gamma {dg1:e}");
    assert!(df1 > 0.0 && (5.0..20.0).contains(&(df1 / df2)), "ratio {}", df1 / df2);
}

/// The far wake through a treecode kept across steps (uniform stream: the wake translates, so
/// the tree is updated rather than rebuilt, uvlm/src/wake_tree.rs) against the direct sum, on
/// the folding wing of [`solver`] with a 20-row wake over 60 steps (the buffer full from step
/// 20: rows dropped, the last edge changing, rebuilds every 16 steps), leaves of 8 segments so
/// that the short wake aggregates. The tree is within 1e-6 |V∞| of the direct sum at every
/// point, so Γ stays within 1e-5 of its largest value; the tree summed fewer pairs.
#[test]
fn a_kept_wake_tree_matches_the_direct_sum() {
    let (mut a, wing) = solver(WakeReuse::Frozen);
    let lat = Lattice::from_stations(wing.spec(), &wing.stations(0.0)).unwrap();
    let mut p = a.params().clone();
    p.wake_aggregation = WakeAggregation { leaf_size: 8, ..WakeAggregation::treecode() };
    let mut b = Uvlm::new(lat, p).unwrap();
    let mut dg = 0.0_f64;
    for k in 1..=60 {
        for u in [&mut a, &mut b] {
            u.update_stations(&wing.stations(fold(k)), None).unwrap();
            u.step(0.01).unwrap();
        }
        let gmax = a.gamma().iter().fold(0.0_f64, |m, g| m.max(g.abs()));
        let gd = a.gamma().iter().zip(b.gamma()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        dg = dg.max(gd / gmax);
    }
    println!("kept tree: gamma {dg:.3e}");
    assert!(dg < 1e-5, "gamma {dg:e}");
    assert!(dg > 0.0, "the tree changed nothing: did it aggregate?");
    assert!(b.stats().n_pair_evaluations < a.stats().n_pair_evaluations);
}

/// A time step's load points with the aggregation's mixed precision (the bound rings and the
/// near wake in the f32 kernel, their axis extensions corrected only inside the cut-off
/// cylinders, the far wake summed directly in mixed precision) against f64 everywhere, on the
/// folding wing of [`solver`] with the coupling's two solves a step, over 40 steps (the 20-row
/// buffer full from step 20): the force, the moment about the root and Γ stay within 1e-6 of
/// themselves, the aggregation's tolerance (measured 8.7e-8, 1.1e-7 and 1.0e-7; Γ moves only
/// through the far wake at the collocation points, the influence matrix being f64).
#[test]
fn mixed_precision_loads_match_f64() {
    let (mut a, wing) = solver(WakeReuse::Frozen);
    let mut p = a.params().clone();
    p.wake_aggregation = WakeAggregation { min_segments: usize::MAX, ..WakeAggregation::treecode() };
    let mut b = Uvlm::new(a.lattice().clone(), p).unwrap();
    let (mut df, mut dm, mut dg) = (0.0_f64, 0.0_f64, 0.0_f64);
    let rel = |x: [f64; 3], y: [f64; 3]| {
        let n = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt() / n
    };
    for k in 1..=40 {
        for u in [&mut a, &mut b] {
            u.advance_wake(0.01).unwrap();
            u.update_stations(&wing.stations(fold(k) + 1e-4), None).unwrap();
            u.solve_step().unwrap();
            u.update_stations(&wing.stations(fold(k)), None).unwrap();
            u.solve_step().unwrap();
            u.commit_step().unwrap();
        }
        df = df.max(rel(a.loads().total_force(), b.loads().total_force()));
        dm = dm.max(rel(a.loads().moment_about([0.0; 3]), b.loads().moment_about([0.0; 3])));
        let gmax = a.gamma().iter().fold(0.0_f64, |m, g| m.max(g.abs()));
        let gd = a.gamma().iter().zip(b.gamma()).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        dg = dg.max(gd / gmax);
    }
    println!("mixed-precision loads: force {df:.3e}, moment {dm:.3e}, gamma {dg:.3e}");
    assert!(df < 1e-6 && dm < 1e-6 && dg < 1e-6, "force {df:e}, moment {dm:e}, gamma {dg:e}");
    assert!(df > 0.0, "the mixed path was not taken");
}

/// A solver as `u` was built, with the refined solves of the influence matrix.
fn refined(u: &Uvlm) -> Uvlm {
    let mut params = u.params().clone();
    params.aic_refinement = true;
    Uvlm::new(u.lattice().clone(), params).unwrap()
}

/// Γ solved on the factorisation of an earlier influence matrix and refined against the current
/// one (`aic_refinement`, uvlm/src/refine.rs) against a factorisation of every matrix, on the
/// folding wing of [`solver`] over 60 steps with two solves a step (the second at the step's
/// true fold). The refinement stops at a correction of 1e-12 of the largest Γ, the error then
/// about the contraction rate times that: Γ and the force agree to 1e-12 of themselves at every
/// step (measured 1.7e-15, with the differences carried through the wake), and the matrix was
/// factorised on far fewer solves than it changed (3 of 120).
#[test]
fn refined_solves_match_a_factorisation_of_every_matrix() {
    let (mut a, wing) = solver(WakeReuse::Frozen);
    let mut b = refined(&a);
    let (df, dg) = march_both(&mut a, &mut b, &wing, 1e-3, 60);
    let (sa, sb) = (a.stats(), b.stats());
    println!(
        "force {df:.2e}, gamma {dg:.2e}; factorisations {} against {}, refined solves {}, corrections {}",
        sb.n_factorizations, sa.n_factorizations, sb.n_refined_solves, sb.n_refinement_corrections
    );
    assert!(df < 1e-12 && dg < 1e-12, "force {df:e}, gamma {dg:e}");
    assert_eq!(sa.n_refined_solves, 0);
    assert_eq!(sa.n_factorizations, sa.n_aic_builds);
    assert!(sb.n_refined_solves > 0 && 5 * sb.n_factorizations < sb.n_aic_builds, "{sb:?}");
    assert_eq!(sb.n_refined_solves + sb.n_factorizations, sb.n_aic_builds);
}

/// Refined solves on a matrix that stops changing: the first eight solves on it refine on the
/// earlier factors, the ninth factorises it, and later ones use its own factors.
#[test]
fn a_matrix_that_stops_changing_is_factorised_after_eight_refined_solves() {
    let (u, wing) = solver(WakeReuse::Frozen);
    let mut u = refined(&u);
    for k in 1..=3 {
        u.advance_wake(0.01).unwrap();
        u.update_stations(&wing.stations(fold(k)), None).unwrap();
        u.solve_step().unwrap();
        u.commit_step().unwrap();
    }
    let before = *u.stats();
    assert_eq!(before.n_factorizations, 1, "{before:?}");
    u.advance_wake(0.01).unwrap();
    u.update_stations(&wing.stations(fold(4)), None).unwrap();
    for _ in 0..12 {
        u.solve_step().unwrap();
    }
    u.commit_step().unwrap();
    let after = *u.stats();
    assert_eq!(after.n_aic_builds - before.n_aic_builds, 1, "{after:?}");
    assert_eq!(after.n_refined_solves - before.n_refined_solves, 8, "{after:?}");
    assert_eq!(after.n_factorizations - before.n_factorizations, 1, "{after:?}");
}
