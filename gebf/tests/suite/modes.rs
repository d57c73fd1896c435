//! Linear cantilever frequencies against the analytic (Euler–Bernoulli, Saint-Venant torsion,
//! bar) values at 16 elements; acceptance within 1 %. The beam is slender (L = 5 m with the
//! paper's section: radius of gyration / L ≈ 1.2e-3), so shear and rotary-inertia corrections
//! to the first two bending frequencies are below 1e-4.

use gebf::{Model, Options, samples};
use nalgebra::Vector3;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    BendingZ,
    BendingY,
    Torsion,
    Axial,
}

/// Classify a mode by where its M-weighted kinetic energy sits: R_x (axial), R_y, R_z
/// (bending), psi_x (torsion); bending rotations count with their displacements.
fn classify(shape: &[f64]) -> Kind {
    let mut e = [0.0; 4];
    for node in shape.chunks(6).take(shape.len() / 6) {
        if node.len() < 6 {
            break;
        }
        e[0] += node[0] * node[0];
        e[1] += node[1] * node[1];
        e[2] += node[2] * node[2];
        e[3] += node[3] * node[3] * 1e-4; // rotations weighted by a small length²
    }
    let imax = (0..4).max_by(|&a, &b| e[a].total_cmp(&e[b])).unwrap();
    match imax {
        0 => Kind::Axial,
        1 => Kind::BendingZ, // in-plane y displacement: bending about z
        2 => Kind::BendingY,
        _ => Kind::Torsion,
    }
}

#[test]
fn cantilever_frequencies_at_16_elements() {
    let sec = samples::paper_section(1.0);
    let l = 5.0;
    let (b, j) = samples::cantilever(sec, l, 16);
    let m = Model::new(&b, &j, Vector3::zeros(), Options::default()).unwrap();
    let modes = m.linear_modes(&m.reference_coordinates()).unwrap();
    let n = modes.omega.len();
    let kinds: Vec<Kind> = (0..n)
        .map(|c| {
            let col: Vec<f64> = modes.shapes.column(c).iter().copied().collect();
            // Torsion modes have no displacement; weigh rotations so that they win there.
            let disp: f64 = col.chunks(6).map(|x| x[..3].iter().map(|v| v * v).sum::<f64>()).sum();
            let rot_x: f64 = col.chunks(6).map(|x| if x.len() == 6 { x[3] * x[3] } else { 0.0 }).sum();
            if rot_x * 1e-4 > disp { Kind::Torsion } else { classify(&col) }
        })
        .collect();
    let first =
        |k: Kind, nth: usize| (0..n).filter(|&i| kinds[i] == k).nth(nth).map(|i| modes.omega[i]).expect("mode found");
    let eb = (sec.ei_yy / (sec.mass * l.powi(4))).sqrt();
    let checks = [
        ("bending 1 (y)", first(Kind::BendingY, 0), 3.516_015 * eb),
        ("bending 1 (z)", first(Kind::BendingZ, 0), 3.516_015 * eb),
        ("bending 2 (y)", first(Kind::BendingY, 1), 22.034_49 * eb),
        ("bending 2 (z)", first(Kind::BendingZ, 1), 22.034_49 * eb),
        ("torsion 1", first(Kind::Torsion, 0), std::f64::consts::PI / (2.0 * l) * (sec.gj / sec.rho_ixx).sqrt()),
        ("axial 1", first(Kind::Axial, 0), std::f64::consts::PI / (2.0 * l) * (sec.ea / sec.mass).sqrt()),
    ];
    for (name, num, exact) in checks {
        let e = (num - exact) / exact;
        println!("{name}: {num:.5} rad/s, analytic {exact:.5}, rel error {e:+.2e}");
        assert!(e.abs() < 0.01, "{name}: {num} vs {exact}");
    }
}
