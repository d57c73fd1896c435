//! A catalogue of reference scenes, shared by both formulations' tests and benchmarks and by the
//! harness (re-exported as `ancf::samples` and `gebf::samples`).

use crate::{BodySpec, ForceElement, JointSpec, PointMass, Scene, Section, Twist};
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
        twist: Twist::none(),
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
        twist: Twist::none(),
    };
    (vec![body], vec![JointSpec::Clamp { body: 0 }])
}

/// Length of the inner body of [`free_hinge_wing`], m.
pub const FREE_HINGE_INNER: f64 = 0.75;
/// Length of the tip of [`free_hinge_wing`], m.
pub const FREE_HINGE_TIP: f64 = 0.25;

/// The section: Healy's aluminium spar (mass 0.2592 kg/m, EI_yy 12.9 N·m², EI_zz 224 N·m²,
/// J_xx = J_yy + J_zz so that ANCF's slope inertias are exact), with near-rigid shear.
pub fn free_hinge_section() -> Section {
    Section::centred(0.2592, 9.13766e-6, 4.97664e-7, 8.64e-6, 6.72e6, 1e9, 1e9, 18.2753, 12.9024, 224.0)
}

/// The tip's point mass: 0.061 kg, 12 mm behind the spar (−y), 0.1 m from the hinge.
pub fn free_hinge_tip_mass() -> PointMass {
    PointMass {
        at: 0.1,
        offset: Vector3::new(0.0, -0.0139, 0.0),
        mass: 0.061,
        inertia: Vector3::new(1.89e-5, 1.16e-4, 1.349e-4),
    }
}

/// A Healy-like 1 m wing with a free flared hinge (no gravity): a 0.75 m inner body clamped at
/// the root (12 elements) and a 0.25 m tip (4 elements, a point mass) on a flared hinge of flare
/// `flare_deg` with a soft spring `k`, N·m/rad (joint 1). Its lowest mode is the tip turning
/// about the hinge axis at `ω = √(k/J)`, `J` = [`free_hinge_tip_inertia`], while `ω` lies far
/// below the first bending (5.6 Hz).
pub fn free_hinge_wing(flare_deg: f64, k: f64) -> Scene {
    let body = |name: &str, start: f64, length: f64, n_elements: usize, point_masses: Vec<PointMass>| BodySpec {
        name: name.into(),
        start: Vector3::new(start, 0.0, 0.0),
        length,
        frame: Matrix3::identity(),
        section: free_hinge_section(),
        n_elements,
        point_masses,
        twist: Twist::none(),
    };
    Scene {
        forces: vec![ForceElement::HingeSpring { joint: 1, stiffness: k, damping: 0.0, rest: 0.0 }],
        ..Scene::new(
            vec![
                body("inner", 0.0, FREE_HINGE_INNER, 12, Vec::new()),
                body("tip", FREE_HINGE_INNER, FREE_HINGE_TIP, 4, vec![free_hinge_tip_mass()]),
            ],
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
pub fn free_hinge_tip_inertia(flare_deg: f64) -> f64 {
    let (sb, cb) = flare_deg.to_radians().sin_cos();
    let a = Vector3::new(sb, cb, 0.0);
    let s = free_hinge_section();
    let line = s.mass * FREE_HINGE_TIP.powi(3) / 3.0 * cb * cb;
    let rotary = FREE_HINGE_TIP * (s.rho_ixx * sb * sb + s.rho_iyy * cb * cb);
    let p = free_hinge_tip_mass();
    let r = Vector3::new(p.at, 0.0, 0.0) + p.offset;
    let point = p.mass * (r.norm_squared() - r.dot(&a).powi(2)) + a.dot(&p.inertia.component_mul(&a));
    line + rotary + point
}

/// The section of the pretwisted cantilever ([`pretwisted_cantilever`]): EI_zz = 10 EI_yy
/// (1 and 10 N·m²), GJ = 2 N·m², near-rigid axial and shear stiffness (EA = GA = 1e7 N), and
/// J_xx = J_yy + J_zz so that ANCF's slope inertias are exact.
pub fn pretwisted_section() -> Section {
    Section::centred(1.0, 4e-4, 1e-4, 3e-4, 1e7, 1e7, 1e7, 2.0, 1.0, 10.0)
}

/// A cantilever of `length` along +X from the origin, clamped at the origin, with a linear
/// built-in twist from `root` to `tip` (rad) and `n_el` elements.
pub fn pretwisted_cantilever(
    section: Section,
    length: f64,
    n_el: usize,
    root: f64,
    tip: f64,
) -> (Vec<BodySpec>, Vec<JointSpec>) {
    let (mut bodies, joints) = cantilever(section, length, n_el);
    bodies[0].twist = Twist::linear(root, tip, length);
    (bodies, joints)
}

/// The exact linear tip compliance of a body clamped at its start, loaded by a force `F` on the
/// axis of its end section: tip displacement `u = G F`, m/N (global components),
///
/// $$ G = \int_0^L \big[(L-s)^2\,X^T R\,C^{-1} R^T X + R\,S^{-1} R^T\big]\,ds, $$
///
/// with `X = [x]×` the skew matrix of the body's axis, `R(s)` its section frame (twisted),
/// `C = diag(GJ, EI_yy, EI_zz)` and `S = diag(EA, GA_y, GA_z)`: the moment `(L − s) x × F` bends
/// the section about its own (rotating) principal axes, the curvature integrates to the
/// rotation and the rotation (with the shear and axial strain) to the tip displacement. It is
/// Timoshenko's cantilever with the principal axes turning along the span; untwisted it gives
/// `L³/(3EI) + L/GA` across and `L/EA` along. Integrated by [`Twist::quadrature`], exact to
/// rounding for a piecewise-linear twist.
pub fn cantilever_tip_compliance(body: &BodySpec) -> Matrix3<f64> {
    let sec = &body.section;
    let c_inv = Matrix3::from_diagonal(&Vector3::new(1.0 / sec.gj, 1.0 / sec.ei_yy, 1.0 / sec.ei_zz));
    let s_inv = Matrix3::from_diagonal(&Vector3::new(1.0 / sec.ea, 1.0 / sec.ga_y, 1.0 / sec.ga_z));
    let x = body.frame.column(0).cross_matrix();
    let l = body.length;
    body.twist.quadrature(l).into_iter().fold(Matrix3::zeros(), |g, (s, w)| {
        let r = body.section_frame(s);
        let arm = (l - s) * (l - s);
        g + (x.transpose() * r * c_inv * r.transpose() * x * arm + r * s_inv * r.transpose()) * w
    })
}

/// The section of [`flying_spaghetti`]: EA = GA = 10⁴ N, GJ = EI = 500 N·m², ρA = 1 kg/m,
/// ρI = 10 kg·m (polar 20).
pub fn spaghetti_section() -> Section {
    Section {
        mass: 1.0,
        rho_ixx: 20.0,
        rho_iyy: 10.0,
        rho_izz: 10.0,
        ea: 1e4,
        ga_y: 1e4,
        ga_z: 1e4,
        gj: 500.0,
        ei_yy: 500.0,
        ei_zz: 500.0,
        cg_offset: [0.0; 2],
    }
}

/// The free-flying "spaghetti" of Simo & Vu-Quoc (*On the dynamics in space of rods undergoing
/// large motions — a geometrically exact approach*, CMAME 66, 1988, §7), a classic check of
/// free-floating flexible multibody codes: a 10 m rod of [`spaghetti_section`] in the X–Z plane,
/// its axis (0.6, 0, 0.8) (53.13° above X), free in space (a [`JointSpec::Free`] root), no
/// gravity. `tip` splits it into a root rod and a tip rod of that length joined by a flared
/// hinge of flare `flare_deg` (`tip = 0`: one rod), the free-floating multibody variant. The
/// loads that set it tumbling are [`spaghetti_loads`].
pub fn flying_spaghetti(n_el: usize, tip: f64, flare_deg: f64) -> Scene {
    let axis = Vector3::new(0.6, 0.0, 0.8);
    let frame = Matrix3::from_columns(&[axis, Vector3::y(), axis.cross(&Vector3::y())]);
    let body = |name: &str, start: Vector3<f64>, length: f64, n_elements: usize| BodySpec {
        name: name.into(),
        start,
        length,
        frame,
        section: spaghetti_section(),
        n_elements,
        point_masses: Vec::new(),
        twist: Twist::none(),
    };
    let mut joints = vec![JointSpec::Free { body: 0 }];
    let bodies = if tip > 0.0 {
        let root = 10.0 - tip;
        let n_tip = ((n_el as f64 * tip / 10.0).round() as usize).max(1);
        joints.push(JointSpec::FlaredHinge { parent: 0, child: 1, beta: flare_deg.to_radians() });
        vec![body("root", Vector3::zeros(), root, n_el - n_tip), body("tip", axis * root, tip, n_tip)]
    } else {
        vec![body("rod", Vector3::zeros(), 10.0, n_el)]
    };
    Scene { bodies, joints, forces: Vec::new(), gravity: Vector3::zeros() }
}

/// The loads of [`flying_spaghetti`] at time `t`: two dead forces, at the root's start and at
/// the tip's end (global components), each a hat of 2.5 s up and 2.5 s down, `(20, 0, 0) p(t)`
/// and `(0, 20, −10) p(t)` N with `p` rising from 0 to 1 and back, zero from 5 s on: impulses of
/// 50 and (0, 50, −25) N·s. (Simo & Vu-Quoc push with a force and a couple at one end; two
/// forces make the couple here because a force's virtual work is linear in every formulation's
/// coordinates, so the loads' angular impulse is exactly `∫ Σ r × F dt`.)
pub fn spaghetti_loads(t: f64) -> [Vector3<f64>; 2] {
    let p = if t <= 2.5 {
        t / 2.5
    } else if t <= 5.0 {
        2.0 - t / 2.5
    } else {
        0.0
    };
    [Vector3::new(20.0, 0.0, 0.0) * p, Vector3::new(0.0, 20.0, -10.0) * p]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Untwisted: Timoshenko's cantilever (1e-14). A quarter turn of twist, θ = k s with
    /// `kL = π/2`, weighs the two bending compliances with `∫ (L−s)² cos²θ`, `∫ (L−s)² sin²θ`
    /// and couples y and z through `∫ (L−s)² sin θ cos θ`, integrated by parts in closed form
    /// below (1e-13).
    #[test]
    fn the_tip_compliance_has_its_closed_forms() {
        let sec = pretwisted_section();
        let l = 1.3;
        let (b, _) = cantilever(sec, l, 1);
        let g = cantilever_tip_compliance(&b[0]);
        assert_relative_eq!(g[(2, 2)], l.powi(3) / (3.0 * sec.ei_yy) + l / sec.ga_z, max_relative = 1e-14);
        assert_relative_eq!(g[(1, 1)], l.powi(3) / (3.0 * sec.ei_zz) + l / sec.ga_y, max_relative = 1e-14);
        assert_relative_eq!(g[(0, 0)], l / sec.ea, max_relative = 1e-14);
        let (b, _) = pretwisted_cantilever(sec, l, 1, 0.0, std::f64::consts::FRAC_PI_2);
        let g = cantilever_tip_compliance(&b[0]);
        // ∫ (L−s)² cos²(ks) ds, ∫ (L−s)² sin²(ks) ds, ∫ (L−s)² sin(ks) cos(ks) ds with kL = π/2:
        // ∫ (L−s)² cos(2ks) ds = [(L−s)² sin 2ks/(2k)] + ∫ (L−s) sin(2ks)/k ds = L/(2k²) − sin(2kL)/(4k³) = L/(2k²)
        // ∫ (L−s)² sin(2ks) ds = L²/(2k) − ∫ (L−s) cos(2ks)/k ds = L²/(2k) − (1 − cos 2kL)/(4k³) = L²/(2k) − 1/(2k³)
        let k = std::f64::consts::FRAC_PI_2 / l;
        let (i0, ic2, is2) = (l.powi(3) / 3.0, l / (2.0 * k * k), l * l / (2.0 * k) - 1.0 / (2.0 * k.powi(3)));
        let (cc, ss, sc) = (0.5 * (i0 + ic2), 0.5 * (i0 - ic2), 0.5 * is2);
        // force along z bends about the section's y (EI_yy) where θ = 0, about its z where θ = 90°
        let gzz = cc / sec.ei_yy + ss / sec.ei_zz + l / sec.ga_z;
        let gyy = ss / sec.ei_yy + cc / sec.ei_zz + l / sec.ga_y;
        let gyz = -sc * (1.0 / sec.ei_yy - 1.0 / sec.ei_zz);
        assert_relative_eq!(g[(2, 2)], gzz, max_relative = 1e-13);
        assert_relative_eq!(g[(1, 1)], gyy, max_relative = 1e-13);
        assert_relative_eq!(g[(1, 2)], gyz, max_relative = 1e-13);
        assert_relative_eq!(g[(2, 1)], gyz, max_relative = 1e-13);
    }
}
