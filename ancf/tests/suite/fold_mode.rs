//! The fold mode of a free flared hinge (issue 38, point 5): a Healy-like 1 m wing at rest (no
//! gravity, no flow), a 0.75 m inner body clamped at the root and a 0.25 m tip on a flared hinge
//! with a soft spring `k`, whose lowest mode is the tip turning about the hinge axis at
//! `ω = √(k/J)`, `J` the tip's moment of inertia about that axis. The same wing is built in
//! `gebf/tests/suite/fold_mode.rs`.

use ancf::{BodySpec, ForceElement, JointSpec, Model, Options, PointMass, Scene, Section};
use nalgebra::{Matrix3, Vector3};

/// Length of the inner body and of the tip, m.
const INNER: f64 = 0.75;
const TIP: f64 = 0.25;

/// The section: Healy's aluminium spar (mass 0.2592 kg/m, EI_yy 12.9 N·m², EI_zz 224 N·m²,
/// J_xx = J_yy + J_zz so that ANCF's slope inertias are exact), with near-rigid shear.
fn section() -> Section {
    Section::centred(0.2592, 9.13766e-6, 4.97664e-7, 8.64e-6, 6.72e6, 1e9, 1e9, 18.2753, 12.9024, 224.0)
}

/// The tip's point mass: 0.061 kg, 12 mm behind the spar (−y), 0.1 m from the hinge.
fn tip_mass() -> PointMass {
    PointMass {
        at: 0.1,
        offset: Vector3::new(0.0, -0.0139, 0.0),
        mass: 0.061,
        inertia: Vector3::new(1.89e-5, 1.16e-4, 1.349e-4),
    }
}

/// The wing with flare `flare_deg` and hinge spring `k`, N·m/rad.
pub fn wing(flare_deg: f64, k: f64) -> Scene {
    let body = |name: &str, start: f64, length: f64, n_elements: usize, point_masses: Vec<PointMass>| BodySpec {
        name: name.into(),
        start: Vector3::new(start, 0.0, 0.0),
        length,
        frame: Matrix3::identity(),
        section: section(),
        n_elements,
        point_masses,
    };
    Scene {
        forces: vec![ForceElement::HingeSpring { joint: 1, stiffness: k, damping: 0.0, rest: 0.0 }],
        ..Scene::new(
            vec![body("inner", 0.0, INNER, 12, Vec::new()), body("tip", INNER, TIP, 4, vec![tip_mass()])],
            vec![
                JointSpec::Clamp { body: 0 },
                JointSpec::FlaredHinge { parent: 0, child: 1, beta: flare_deg.to_radians() },
            ],
            Vector3::zeros(),
        )
    }
}

/// The tip's moment of inertia about the hinge axis `a = sin β x + cos β y` through the hinge,
/// analytically: the line mass `μ` at `s x` (distance `s cos β` from the axis), the sections'
/// rotary inertias `aᵀ diag(ρI) a`, and the point mass at `r` (`|r|² − (r·a)²`) with its own
/// inertia.
pub fn tip_inertia(flare_deg: f64) -> f64 {
    let (sb, cb) = flare_deg.to_radians().sin_cos();
    let a = Vector3::new(sb, cb, 0.0);
    let s = section();
    let line = s.mass * TIP.powi(3) / 3.0 * cb * cb;
    let rotary = TIP * (s.rho_ixx * sb * sb + s.rho_iyy * cb * cb);
    let p = tip_mass();
    let r = Vector3::new(p.at, 0.0, 0.0) + p.offset;
    let point = p.mass * (r.norm_squared() - r.dot(&a).powi(2)) + a.dot(&p.inertia.component_mul(&a));
    line + rotary + point
}

/// The fold mode at flares 0°, 10°, 20° and 30° and springs of 1e-4 N·m/rad (Healy's; fold
/// frequency 0.035–0.039 Hz) and 1e-2 (0.35–0.39 Hz): within 2 % of `√(k/J)`. The rigid-tip
/// estimate holds because the fold frequency lies far below every elastic one (the first
/// bending is 5.6 Hz): the elastic motion the tip's inertia forces at the fold frequency lowers
/// `ω` by about `(ω/ω_bending)²`, 4e-5 at k = 1e-4 and 4e-3 at 1e-2. The second mode must lie
/// more than ten times above the fold's. Measured errors: ANCF −2.4e-5 … +6.5e-5 (k = 1e-4),
/// GEBF −6.6e-3 … +6.8e-3 (a floor that scales with the shear stiffness, see the GEBF test);
/// both −4.2e-3 … −5.7e-3 at k = 1e-2 (the elastic lowering).
#[test]
fn fold_mode_of_a_free_flared_hinge_is_sqrt_k_over_j() {
    for k in [1e-4, 1e-2] {
        for flare in [0.0, 10.0, 20.0, 30.0] {
            let model = Model::from_scene(&wing(flare, k), Options::default()).unwrap();
            let modes = model.linear_modes(model.reference_coordinates()).unwrap();
            let expected = (k / tip_inertia(flare)).sqrt();
            let fold = modes[0].omega;
            let err = fold / expected - 1.0;
            println!(
                "k {k:e}, flare {flare}: fold {:.6} Hz, sqrt(k/J) {:.6} Hz, error {err:+.2e}; next {:.3} Hz",
                fold / std::f64::consts::TAU,
                expected / std::f64::consts::TAU,
                modes[1].omega / std::f64::consts::TAU
            );
            assert!(err.abs() < 0.02, "k {k:e}, flare {flare}: fold {fold} rad/s against {expected}");
            assert!(modes[1].omega > 10.0 * expected, "k {k:e}, flare {flare}: second mode {}", modes[1].omega);
        }
    }
}
