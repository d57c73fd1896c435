//! Rigid limit (docs/cases.md §6, rung 7): with c = 1000 the flexible model approaches the rigid two-body
//! solution `cases/reference/exudyn/rigid_beta*_ode.csv` (2-DOF Lagrangian model, DOP853 at
//! tolerance 1e-12). Bound: 1 cm over 2 s at the paper's settings; measured 0.75 mm (β = 0),
//! 1.8 mm (β = 45°), 0.15 mm (β = 90°).
use crate::common;

use ancf::{Options, SolvePath};
use common::*;

#[test]
fn stiff_pendulum_matches_the_rigid_solution() {
    for beta in [0.0, 45.0, 90.0] {
        let run = run_pendulum(1000.0, beta, 5, 0.002, 0.8, Options { path: SolvePath::Ode, ..Default::default() });
        let (err, t) = max_tip_error(&run, &reference(&format!("exudyn/rigid_beta{beta}_ode.csv")), 0.0);
        println!("c = 1000, beta = {beta}: max tip error {err:.3e} m at t = {t:.3} s");
        assert!(err < 0.01, "beta {beta}: {err} m at t = {t}");
    }
}
