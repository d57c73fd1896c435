//! Joint drift: the velocity-level joints let the hinge gap grow (reported every step by
//! `Model::constraint_residual`); with the optional position projection it stays below 1e-8.

use crate::common;
use common::*;

#[test]
fn hinge_gap_with_and_without_projection() {
    let free = run_paper_case(1.0, 45.0, 0.8, false);
    let proj = run_paper_case(1.0, 45.0, 0.8, true);
    let max_free = free.residual.iter().copied().fold(0.0, f64::max);
    let max_proj = proj.residual.iter().copied().fold(0.0, f64::max);
    let (dmax, _) = tip_difference(&proj.tip, &free.tip, 0.0);
    println!(
        "max joint violation: {max_free:.3e} without projection, {max_proj:.3e} with; \
         tip difference between the two runs {:.2} mm",
        dmax * 1e3
    );
    assert_eq!(proj.residual.len(), 1001, "reported every step");
    assert!(max_proj < 1e-8, "{max_proj}");
    assert!(max_free > 1e-6, "the unprojected run should drift measurably");
    // The projection only removes the drift: the motion stays within the method's accuracy.
    let exudyn = load_tip("exudyn/flex_c1_beta45_gebf_n80_dt0.0005.csv");
    let (e_max, _) = tip_difference(&proj.tip, &exudyn, 0.0);
    println!("projected run against Exudyn n80: max {:.2} mm", e_max * 1e3);
    assert!(e_max < 0.015);
}
