//! The cross-formulation gate on the paper's cases: this is what CI enforces.

use std::path::PathBuf;
use std::process::Command;

use harness::case::{Formulation, Override};
use harness::driver::{discover, expand_all, run_all};
use harness::gate::table;

fn cases_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases")
}

/// Every gated case passes its declared tolerances with both formulations.
#[test]
fn paper_cases_pass_the_gate() {
    let (runs, errors) = expand_all(&discover(&cases_dir()).unwrap(), &[]);
    assert!(errors.is_empty(), "{errors:?}");
    let gated: Vec<_> = runs.into_iter().filter(|r| r.ancf.gate.is_some()).collect();
    assert!(gated.len() >= 5, "the five double-pendulum cases must be gated");
    let results = run_all(&gated, &Formulation::ALL, false);
    let t = table(&results);
    for r in &results {
        assert_eq!(r.status(), "pass", "{}\n{t}", r.name);
    }
}

/// Negative control: giving GEBF a different flare angle must fail the gate, naming the case and
/// the metric, through the binary's exit code.
#[test]
fn gate_fails_when_one_formulation_gets_another_flare_angle() {
    let o = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["gate", "cases/double_pendulum_c1_beta45.json", "--set", "gebf:joints.1.flare_deg=40"])
        .current_dir(cases_dir().join(".."))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("double_pendulum_c1_beta45") && err.contains("tip_max"), "{err}");
    // The library path agrees.
    let ov: Override = "gebf:joints.1.flare_deg=40".parse().unwrap();
    let (runs, _) = expand_all(&[cases_dir().join("double_pendulum_c1_beta45.json")], &[ov]);
    let r = run_all(&runs, &Formulation::ALL, false);
    assert_eq!(r[0].status(), "FAIL");
}

/// A locked flared hinge welds the outer body to the inner one in both formulations: the fold
/// angle stays at zero and the two formulations' tips agree as closely as for the free hinge.
#[test]
fn locked_hinge_keeps_the_fold_at_zero_in_both_formulations() {
    let p = cases_dir().join("double_pendulum_c1_beta45.json");
    let ov: Vec<Override> =
        ["joints.1.locked=true", "t_end=1", "output_dt=0.01"].iter().map(|s| s.parse().unwrap()).collect();
    let spec = harness::case::CaseFile::read(&p).unwrap().expand(&ov).unwrap().remove(0);
    let outs: Vec<_> = Formulation::ALL
        .iter()
        .map(|&f| {
            let out = harness::scene::run_formulation(spec.case(f), f);
            assert!(out.error.is_none(), "{f}: {:?}", out.error);
            let fold = out.rows.iter().map(|r| r.fold.abs()).fold(0.0, f64::max);
            assert!(fold < 1e-6, "{f}: locked hinge folded by {fold:.3e} rad");
            out
        })
        .collect();
    let diff = outs[0]
        .rows
        .iter()
        .zip(&outs[1].rows)
        .map(|(a, b)| (0..3).map(|i| (a.tip[i] - b.tip[i]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    eprintln!("locked c1 β45: ANCF–GEBF max tip difference over 1 s {:.3e} m", diff);
    assert!(diff < 1e-3, "ANCF–GEBF tip difference {diff:.3e} m");
}
