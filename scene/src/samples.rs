//! A catalogue of reference scenes, shared by both formulations' tests and benchmarks and by the
//! harness (re-exported as `ancf::samples` and `gebf::samples`).

use crate::{BodySpec, JointSpec, Section};
use nalgebra::{Matrix3, Vector3};

/// The paper's double-pendulum section (Otsuka, Cheng & Palacios, ICAS 2024, Tables 1–2):
/// m = 1.08 kg/m, ρI_xx = 7.2e-5, ρI_yy = ρI_zz = 3.6e-5 kg·m, stiffnesses scaled by `c`:
/// EA = c·2.80e5 N, GA_y = GA_z = c·1.037e5 N, GJ = c·6.91 N·m², EI = c·9.33 N·m².
pub fn paper_section(c: f64) -> Section {
    Section {
        mass: 1.08,
        rho_ixx: 7.2e-5,
        rho_iyy: 3.6e-5,
        rho_izz: 3.6e-5,
        ea: c * 2.80e5,
        ga_y: c * 1.037e5,
        ga_z: c * 1.037e5,
        gj: c * 6.91,
        ei_yy: c * 9.33,
        ei_zz: c * 9.33,
        cg_offset: [0.0; 2],
    }
}

/// The paper's five double-pendulum runs `(c, β in degrees)`.
pub const PAPER_CASES: [(f64, f64); 5] = [(1.0, 0.0), (1.0, 90.0), (1.0, 45.0), (0.1, 45.0), (0.01, 45.0)];

fn two_bodies(section: Section, n_el: usize, beta: f64) -> (Vec<BodySpec>, Vec<JointSpec>) {
    let body = |name: &str, x0: f64| BodySpec {
        name: name.into(),
        start: Vector3::new(x0, 0.0, 0.0),
        length: 0.5,
        frame: Matrix3::identity(),
        section,
        n_elements: n_el,
        point_masses: Vec::new(),
    };
    let bodies = vec![body("body1", 0.0), body("body2", 0.5)];
    let joints = vec![
        JointSpec::GroundHinge { body: 0, axis: Vector3::y() },
        JointSpec::FlaredHinge { parent: 0, child: 1, beta },
    ];
    (bodies, joints)
}

/// The paper's flared double pendulum (docs/cases.md §1): two 0.5 m bodies along +X, ground hinge
/// about +Y at the origin, flared hinge at X = 0.5 with flare angle `beta_deg`, `n_el`
/// three-node elements per body, gravity 9.8 m/s² along −Z. Joint 1 is the flared hinge.
pub fn double_pendulum(c: f64, beta_deg: f64, n_el: usize) -> (Vec<BodySpec>, Vec<JointSpec>, Vector3<f64>) {
    let (b, j) = two_bodies(paper_section(c), n_el, beta_deg.to_radians());
    (b, j, Vector3::new(0.0, 0.0, -9.8))
}

/// SHARPy's own regression `tests/coupled/multibody/double_slanted_pendulum` (docs/cases.md §5):
/// aluminium 0.02 m square bars (m = 1.08 kg/m, J_xx = 7.2e-5, J_yy = J_zz = 3.6e-5 kg·m,
/// EA = 2.8e7, GA = 1.037e7, GJ = 691.4, EI = 933.3), 11 nodes (5 three-node elements) per
/// body, flare 45°, g = 9.81 m/s² along −Z. SHARPy's tip at t = 0.3 s (Newmark γ = ½,
/// β = ¼, dt = 0.01): (0.80955, 0.10248, −0.48184).
pub fn sharpy_slanted_pendulum() -> (Vec<BodySpec>, Vec<JointSpec>, Vector3<f64>) {
    let section = Section {
        mass: 2700.0 * 0.02 * 0.02,
        rho_ixx: 2700.0 * 0.02 * 0.02 * (2.0 * 0.02 * 0.02) / 12.0,
        rho_iyy: 2700.0 * 0.02 * 0.02 * (2.0 * 0.02 * 0.02) / 24.0,
        rho_izz: 2700.0 * 0.02 * 0.02 * (2.0 * 0.02 * 0.02) / 24.0,
        ea: 2.8e7,
        ga_y: 1.037e7,
        ga_z: 1.037e7,
        gj: 6.914e2,
        ei_yy: 9.333e2,
        ei_zz: 9.333e2,
        cg_offset: [0.0; 2],
    };
    let (b, j) = two_bodies(section, 5, 45f64.to_radians());
    (b, j, Vector3::new(0.0, 0.0, -9.81))
}

/// SHARPy's tip position at t = 0.3 s in its regression test, m.
pub const SHARPY_SLANTED_TIP_AT_0_3: [f64; 3] = [0.80954978, 0.1024842, -0.48183994];

/// A straight cantilever of `length` along +X from the origin, clamped at the origin.
pub fn cantilever(section: Section, length: f64, n_el: usize) -> (Vec<BodySpec>, Vec<JointSpec>) {
    let body = BodySpec {
        name: "cantilever".into(),
        start: Vector3::zeros(),
        length,
        frame: Matrix3::identity(),
        section,
        n_elements: n_el,
        point_masses: Vec::new(),
    };
    (vec![body], vec![JointSpec::Clamp { body: 0 }])
}
