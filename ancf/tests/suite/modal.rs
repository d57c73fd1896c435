//! Linear dynamics of a clamped cantilever (16 elements) against Euler–Bernoulli, rod and shaft
//! theory: first two bending frequencies about each axis, first torsion, first axial mode
//! within 1 %. Penalty (cross-section) modes are told apart by their strain energy.
use ancf::{ModeKind, Model, Options, Section, samples};
use nalgebra::Vector3;
use std::f64::consts::PI;

fn section() -> Section {
    // slender (L/r ≈ 300) so that rotary inertia and shear change the bending frequencies by
    // < 0.1 %; torsion and axial frequencies do not depend on them
    Section {
        mass: 2.0,
        rho_ixx: 4e-5,
        rho_iyy: 1e-5,
        rho_izz: 3e-5,
        ea: 4e7,
        ga_y: 1.5e7,
        ga_z: 1.5e7,
        gj: 300.0,
        ei_yy: 800.0,
        ei_zz: 2000.0,
        cg_offset: [0.0; 2],
    }
}

#[test]
fn cantilever_frequencies_within_one_percent_at_16_elements() {
    let (l, sec) = (2.0, section());
    let (b, j) = samples::cantilever(sec, l, 16);
    let model = Model::new(&b, &j, Vector3::zeros(), Options::default()).unwrap();
    let modes = model.linear_modes(model.reference_coordinates()).unwrap();
    let of = |kind: ModeKind| -> Vec<f64> { modes.iter().filter(|m| m.kind == kind).map(|m| m.omega).collect() };
    let bend = |ei: f64, k: usize| [3.516_015, 22.034_49][k] / (l * l) * (ei / sec.mass).sqrt();
    let (by, bz) = (of(ModeKind::BendingY), of(ModeKind::BendingZ));
    let checks = [
        ("bending about y, 1st", by[0], bend(sec.ei_yy, 0)),
        ("bending about y, 2nd", by[1], bend(sec.ei_yy, 1)),
        ("bending about z, 1st", bz[0], bend(sec.ei_zz, 0)),
        ("bending about z, 2nd", bz[1], bend(sec.ei_zz, 1)),
        ("torsion, 1st", of(ModeKind::Torsion)[0], PI / (2.0 * l) * (sec.gj / sec.rho_ixx).sqrt()),
        ("axial, 1st", of(ModeKind::Axial)[0], PI / (2.0 * l) * (sec.ea / sec.mass).sqrt()),
    ];
    for (name, got, exact) in checks {
        let rel = got / exact - 1.0;
        println!("{name}: {got:.4} rad/s, analytic {exact:.4}, relative error {rel:.2e}");
        assert!(rel.abs() < 0.01, "{name}: {got} vs {exact}");
    }
    // no spurious soft mode: every mode below the first axial one is a beam mode
    let axial = of(ModeKind::Axial)[0];
    assert!(modes.iter().filter(|m| m.omega < axial).all(|m| m.kind != ModeKind::Penalty && m.kind != ModeKind::Rigid));
    let first_penalty = modes.iter().find(|m| m.kind == ModeKind::Penalty).map(|m| m.omega).unwrap_or(f64::INFINITY);
    println!("lowest penalty mode {first_penalty:.1} rad/s");
}
