//! Helpers shared by the integration tests.
#![allow(dead_code)] // each test binary uses a subset

use uvlm::samples::{SpanSpacing, rectangular_wing};
use uvlm::*;

/// Read a reference CSV from `cases/reference/uvlm/` (header skipped, `#` lines ignored).
pub fn reference_csv(name: &str) -> Vec<Vec<String>> {
    let path = format!("{}/../cases/reference/uvlm/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .skip(1)
        .map(|l| l.split(',').map(|s| s.trim().to_string()).collect())
        .collect()
}

/// Steady lift coefficient over sin α of a flat rectangular wing (chord 1, aspect ratio `ar`),
/// meshed as a half wing with a symmetry plane, `nc` chordwise × `ns_half` spanwise panels,
/// trailing legs along the free stream, singular bound vortices.
pub fn rect_cl_over_sin(ar: f64, nc: usize, ns_half: usize, alpha: f64) -> f64 {
    let st = rectangular_wing(0.0, 0.5 * ar, 1.0, ns_half, SpanSpacing::Uniform);
    let lat = Lattice::from_stations(LatticeSpec::new(nc), &st).unwrap();
    let mut p = UvlmParams::new(1.0, [alpha.cos(), 0.0, alpha.sin()]);
    p.bound_core = CoreModel::CutOff { radius: 0.0 };
    p.images = vec![ImagePlane::through_origin([0.0, 1.0, 0.0])];
    let mut u = Uvlm::new(lat, p.clone()).unwrap();
    let (lift, _) = u.solve_steady().unwrap().lift_drag(p.v_inf, [0.0, 1.0, 0.0]);
    lift / (0.5 * 0.5 * ar) / alpha.sin()
}
