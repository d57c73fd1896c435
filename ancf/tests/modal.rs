//! Linear dynamics of a clamped cantilever against Euler–Bernoulli / rod / shaft theory.
use ancf::{Curvature, Model, ModeKind, Options, Section, samples};
use nalgebra::Vector3;

fn section() -> Section {
    Section {
        mass: 2.0,
        rho_ixx: 4e-4,
        rho_iyy: 1e-4,
        rho_izz: 3e-4,
        ea: 4e7,
        ga_y: 1.5e7,
        ga_z: 1.5e7,
        gj: 300.0,
        ei_yy: 800.0,
        ei_zz: 2000.0,
    }
}

fn report(curvature: Curvature, n: usize) {
    let (b, j) = samples::cantilever(section(), 2.0, n);
    let model = Model::new(&b, &j, Vector3::zeros(), Options { curvature, ..Default::default() }).unwrap();
    let modes = model.linear_modes(model.reference_coordinates()).unwrap();
    for m in modes.iter().take(40) {
        println!("{:?} {:10.4} {:?}", m.kind, m.omega, m.energy_fractions.map(|x| (x * 100.0).round() / 100.0));
    }
}

#[test]
fn print_modes() {
    report(Curvature::Hybrid, 16);
}
