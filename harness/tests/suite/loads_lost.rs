//! Section loads cannot be lost (issue 33): a non-finite or out-of-range section load fails the
//! analysis with the station named, identically in both formulations.
//!
//! Before the fix, `set_section_loads` discarded the models' errors (`let _ =` in the harness's
//! `structure!` glue): ANCF kept the previous loads and GEBF dropped the bad node's share, and
//! both static sweeps below reported converged equilibria under loads they had never applied.

use std::path::PathBuf;

use harness::case::{CaseFile, Formulation};
use harness::statics::run_static;

fn bend() -> harness::case::RunSpec {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/statics/bathe_bolourchi_bend.json");
    CaseFile::read(&p).unwrap().expand(&[]).unwrap().remove(0)
}

/// A NaN component of a dead load (set through the library, past the case file's validation)
/// fails the first load step in both formulations, naming station 0 and the component; no point
/// is reported as converged.
#[test]
fn non_finite_section_load_fails_the_sweep_issue_33() {
    let spec = bend();
    let mut messages = Vec::new();
    for f in Formulation::ALL {
        let mut case = spec.case(f).clone();
        case.statics.as_mut().unwrap().point_loads[0].force[1] = f64::NAN;
        let out = run_static(&case.problem(), f);
        assert!(!out.points.is_empty(), "{f}");
        for p in &out.points {
            let e = p.error.as_deref().unwrap_or_else(|| panic!("{f}: a point converged under a NaN load: {p:?}"));
            assert!(e.contains("station 0") && e.contains("force[1] is NaN"), "{f}: {e}");
        }
        messages.push(out.points[0].error.clone().unwrap());
    }
    assert_eq!(messages[0], messages[1], "the two formulations report the same error");
}

/// A load beyond its body's end fails the same way, naming the station and the body's length.
#[test]
fn out_of_range_section_load_fails_the_sweep_issue_33() {
    let spec = bend();
    let mut messages = Vec::new();
    for f in Formulation::ALL {
        let mut case = spec.case(f).clone();
        let length = case.bodies.last().unwrap().length;
        case.statics.as_mut().unwrap().point_loads[0].at = Some(1.5 * length);
        let out = run_static(&case.problem(), f);
        let e = out.points[0].error.clone().unwrap_or_else(|| panic!("{f}: converged with a load off the body"));
        assert!(e.contains("station 0") && e.contains("outside"), "{f}: {e}");
        messages.push(e);
    }
    assert_eq!(messages[0], messages[1]);
}
