//! Statics with exact answers (docs/cases.md §3.1–3.2), solved by the crate's Newton/load stepping.

use gebf::{Model, NodalLoad, Options, Section, StaticOptions, samples};
use nalgebra::Vector3;

/// A slender section with unit bending stiffness; axial and shear stiffness 1e7 times larger
/// so that the inextensible, unshearable analytic solutions apply (relative effect ~1e-7).
fn section() -> Section {
    Section {
        mass: 1.0,
        rho_ixx: 1e-3,
        rho_iyy: 5e-4,
        rho_izz: 5e-4,
        ea: 1e7,
        ga_y: 1e7,
        ga_z: 1e7,
        gj: 1.0,
        ei_yy: 1.0,
        ei_zz: 1.0,
        cg_offset: [0.0; 2],
    }
}

fn cantilever(n_el: usize) -> Model {
    let (b, j) = samples::cantilever(section(), 1.0, n_el);
    Model::new(&b, &j, Vector3::zeros(), Options::default()).unwrap()
}

/// Tip moment 2πEI/L about z rolls the cantilever into a full circle: the tip returns to the
/// root. Acceptance: within 1 % of L with at most 32 elements.
#[test]
fn tip_moment_rolls_a_full_circle() {
    let mut report = Vec::new();
    for n_el in [8, 16, 32] {
        let mut m = cantilever(n_el);
        let tip = m.n_nodes(0) - 1;
        let moment = 2.0 * std::f64::consts::PI; // EI/L = 1
        m.set_nodal_load(0, tip, NodalLoad { force: Vector3::zeros(), moment: Vector3::new(0.0, 0.0, moment) })
            .unwrap();
        let q0 = m.reference_coordinates();
        let sol = m.solve_static(&q0, &StaticOptions { n_load_steps: 16, ..StaticOptions::default() }).unwrap();
        let p = m.tip_position(&sol.q);
        report.push((n_el, p.norm()));
        assert!(p.z.abs() < 1e-12, "out of plane: {p:?}");
    }
    println!("tip distance from the root (fraction of L): {report:?}");
    // Reduced integration makes the uniform-curvature solution nodally exact (psi is linear
    // in s and γ vanishes at both Gauss points), so already 8 elements close the circle to
    // round-off. This needs the CRV rescaling: the tip rotation is 2π, where T(psi) is singular;
    // stored CRVs are rescaled past π and elements map their end nodes onto one branch.
    for (n_el, d) in report {
        assert!(d < 0.01, "{n_el} elements: tip {d} L from the root");
    }
}

/// Quarter of the circle moment: exact tip ((EI/M) sin θ, (EI/M)(1 − cos θ)) with θ = ML/EI.
#[test]
fn tip_moment_arc_matches_reissner_solution() {
    let mut m = cantilever(16);
    let tip = m.n_nodes(0) - 1;
    let th = 0.5 * std::f64::consts::PI;
    m.set_nodal_load(0, tip, NodalLoad { force: Vector3::zeros(), moment: Vector3::new(0.0, 0.0, th) }).unwrap();
    let q0 = m.reference_coordinates();
    let sol = m.solve_static(&q0, &StaticOptions::default()).unwrap();
    let p = m.tip_position(&sol.q);
    let exact = Vector3::new(th.sin() / th, (1.0 - th.cos()) / th, 0.0);
    println!("quarter circle tip {p:?}, exact {exact:?}");
    assert!((p - exact).norm() < 1e-4, "{p:?} vs {exact:?}");
    // The tip section is rotated by θ about z.
    let c = m.node_frame(&sol.q, 0, tip).unwrap();
    assert!((c[(1, 0)].atan2(c[(0, 0)]) - th).abs() < 1e-4);
}

/// Tip-load elastica (Mattiasson 1981, recomputed by shooting; docs/cases.md §3.2): dead load P along
/// −z at the tip. Acceptance: u/L, w/L and the tip rotation within 0.5 %.
#[test]
fn tip_load_elastica_table() {
    // (P L²/EI, u/L, w/L, rotation)
    let table = [
        (1.0, 0.05643, 0.30172, 0.46135),
        (2.0, 0.16064, 0.49346, 0.78175),
        (5.0, 0.38763, 0.71379, 1.21537),
        (10.0, 0.55500, 0.81061, 1.43029),
    ];
    let mut worst: f64 = 0.0;
    for (p, u_ref, w_ref, rot_ref) in table {
        let mut m = cantilever(16);
        let tip = m.n_nodes(0) - 1;
        m.set_nodal_load(0, tip, NodalLoad { force: Vector3::new(0.0, 0.0, -p), moment: Vector3::zeros() }).unwrap();
        let q0 = m.reference_coordinates();
        let sol = m.solve_static(&q0, &StaticOptions { n_load_steps: 10, ..StaticOptions::default() }).unwrap();
        let x = m.tip_position(&sol.q);
        let c = m.node_frame(&sol.q, 0, tip).unwrap();
        let (u, w) = (1.0 - x.x, -x.z);
        // Rotation of the tip section about −y (tip tangent dips below the x axis).
        let rot = (-c[(2, 0)]).atan2(c[(0, 0)]);
        let errs = [(u - u_ref) / u_ref, (w - w_ref) / w_ref, (rot - rot_ref) / rot_ref];
        println!(
            "PL²/EI = {p}: u/L {u:.5} ({u_ref}), w/L {w:.5} ({w_ref}), rot {rot:.5} ({rot_ref}); rel errors {:.2e} {:.2e} {:.2e}",
            errs[0], errs[1], errs[2]
        );
        for e in errs {
            worst = worst.max(e.abs());
        }
    }
    assert!(worst < 5e-3, "worst relative error {worst:.2e}");
}
