//! All five paper cases at the paper's settings reach 2 s; β = 0 stays planar; β = 90° keeps
//! the fold below 1° (the hinge axis is the beam axis, and the section is symmetric).

use crate::common;
use common::*;

#[test]
fn all_five_paper_cases_reach_two_seconds() {
    for (c, beta) in gebf::samples::PAPER_CASES {
        let run = run_paper_case(c, beta, 0.8, false);
        let t_end = run.tip.last().unwrap().0;
        let max_y = run.tip.iter().map(|(_, p)| p.y.abs()).fold(0.0, f64::max);
        let max_fold = run.fold.iter().map(|f| f.abs()).fold(0.0, f64::max).to_degrees();
        let max_res = run.residual.iter().copied().fold(0.0, f64::max);
        println!(
            "c = {c}, beta = {beta}: t_end {t_end:.3}, max |Y| {max_y:.2e} m, max |fold| {max_fold:.3} deg, \
             max joint violation {max_res:.2e}, {:?}",
            run.stats
        );
        assert!((t_end - 2.0).abs() < 1e-9);
        if beta == 0.0 {
            assert!(max_y < 1e-9, "beta = 0 left the plane: {max_y}");
        }
        if beta == 90.0 {
            assert!(max_fold < 1.0, "beta = 90: fold {max_fold} deg");
        }
    }
}
