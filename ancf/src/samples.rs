//! A catalogue of reference scenes, shared by tests, benchmarks and the harness.

use crate::{BodySpec, JointSpec, Section};
use nalgebra::{Matrix3, Vector3};

/// Section of the paper's double pendulum (Table 1–2) with stiffness factor `c`:
/// m = 1.08 kg/m, ρI_xx = 7.2e-5, ρI_yy = ρI_zz = 3.6e-5 kg·m, EA = c·2.80e5 N,
/// GA_y = GA_z = c·1.037e5 N, GJ = c·6.91 N·m², EI_yy = EI_zz = c·9.33 N·m².
pub fn pendulum_section(c: f64) -> Section {
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

/// The paper's flared double pendulum (docs/cases.md §1): two 0.5 m bodies along +X, ground hinge
/// about +Y at the origin, flared hinge (β in degrees) at X = 0.5, gravity 9.8 m/s² along −Z.
/// Returns (bodies, joints, gravity).
pub fn double_pendulum(c: f64, beta_deg: f64, n_elements: usize) -> (Vec<BodySpec>, Vec<JointSpec>, Vector3<f64>) {
    let body = |name: &str, x0: f64| BodySpec {
        name: name.to_string(),
        start: Vector3::new(x0, 0.0, 0.0),
        length: 0.5,
        frame: Matrix3::identity(),
        section: pendulum_section(c),
        n_elements,
        point_masses: Vec::new(),
    };
    (
        vec![body("body1", 0.0), body("body2", 0.5)],
        vec![
            JointSpec::GroundHinge { body: 0, axis: Vector3::y() },
            JointSpec::FlaredHinge { parent: 0, child: 1, beta: beta_deg.to_radians() },
        ],
        Vector3::new(0.0, 0.0, -9.8),
    )
}

/// A clamped straight cantilever of length `length` along +X with `section`.
pub fn cantilever(section: Section, length: f64, n_elements: usize) -> (Vec<BodySpec>, Vec<JointSpec>) {
    (
        vec![BodySpec {
            name: "cantilever".into(),
            start: Vector3::zeros(),
            length,
            frame: Matrix3::identity(),
            section,
            n_elements,
            point_masses: Vec::new(),
        }],
        vec![JointSpec::Clamp { body: 0 }],
    )
}

/// The paper's five double-pendulum runs (c, β in degrees).
pub const PAPER_PENDULUM_CASES: [(f64, f64); 5] = [(1.0, 0.0), (1.0, 90.0), (1.0, 45.0), (0.1, 45.0), (0.01, 45.0)];
