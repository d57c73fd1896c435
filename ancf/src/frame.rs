//! Section frames of the deformed beam and the angles the sensors report.
//!
//! The ANCF section slopes `r_y`, `r_z` are nearly, not exactly, orthonormal. The section frame
//! is the closest rotation (polar factor) to `[n, r_y, r_z]` with `n = r_y × r_z / |r_y × r_z|`:
//! it depends on the section slopes only, the way a geometrically exact beam's frame is the
//! section orientation rather than the centreline tangent.

use nalgebra::{Matrix3, Vector3};

/// The orthonormalised section frame (columns x, y, z) from the section slopes.
pub fn section_frame(r_y: &Vector3<f64>, r_z: &Vector3<f64>) -> Matrix3<f64> {
    let n = r_y.cross(r_z);
    let n = n / n.norm().max(f64::MIN_POSITIVE);
    polar_rotation(&Matrix3::from_columns(&[n, *r_y, *r_z]))
}

/// [`section_frame`] and its angular velocity (global, rad/s) while the slopes change at rates
/// `dr_y`, `dr_z`. With `F = [n, r_y, r_z] = R U` (polar) and the body rate `Ω = Rᵀ Ṙ = [w]×`,
/// `Rᵀ Ḟ = Ω U + U̇` with `U̇` symmetric, so `Rᵀ Ḟ − Ḟᵀ R = Ω U + U Ω = [(tr U − U) w]×`: `w`
/// solves a 3 × 3 system whose matrix is `2 I` for orthonormal slopes (symmetric positive
/// definite while `U` is), and the global rate is `R w`. A degenerate section gives NaN.
pub fn section_frame_rate(
    r_y: &Vector3<f64>,
    r_z: &Vector3<f64>,
    dr_y: &Vector3<f64>,
    dr_z: &Vector3<f64>,
) -> (Matrix3<f64>, Vector3<f64>) {
    let c = r_y.cross(r_z);
    let len = c.norm().max(f64::MIN_POSITIVE);
    let n = c / len;
    let dc = dr_y.cross(r_z) + r_y.cross(dr_z);
    let dn = (dc - n * n.dot(&dc)) / len;
    let p = PolarRate::new(&Matrix3::from_columns(&[n, *r_y, *r_z]), &Matrix3::from_columns(&[dn, *dr_y, *dr_z]));
    (p.r, p.r * p.body)
}

/// [`section_frame_rate`] one derivative further: the frame, its angular velocity `ω` and its
/// angular acceleration `α` (global) while the slopes move with rates `dr_*` and accelerations
/// `ddr_*`. Differentiating `A w = x` (`A = tr U − U`, `x` the axial vector of `W − Wᵀ`,
/// `W = Rᵀ Ḟ`): `A ẇ = ẋ − Ȧ w` with `U̇ = W − Ω U` and `Ẇ = Rᵀ F̈ − Ω W`; then `α = R ẇ`
/// (`Ṙ w = R (w × w) = 0`). `n̈` is that of the unit normal `n = c/|c|`, `c = r_y × r_z`.
pub fn section_frame_motion(
    r_y: &Vector3<f64>,
    r_z: &Vector3<f64>,
    dr_y: &Vector3<f64>,
    dr_z: &Vector3<f64>,
    ddr_y: &Vector3<f64>,
    ddr_z: &Vector3<f64>,
) -> (Matrix3<f64>, Vector3<f64>, Vector3<f64>) {
    let c = r_y.cross(r_z);
    let len = c.norm().max(f64::MIN_POSITIVE);
    let n = c / len;
    let dc = dr_y.cross(r_z) + r_y.cross(dr_z);
    let ddc = ddr_y.cross(r_z) + dr_y.cross(dr_z) * 2.0 + r_y.cross(ddr_z);
    let dn = (dc - n * n.dot(&dc)) / len;
    let ddn = (ddc - n * n.dot(&ddc) - n * dn.dot(&dc) - dn * (2.0 * n.dot(&dc))) / len;
    let p = PolarRate::new(&Matrix3::from_columns(&[n, *r_y, *r_z]), &Matrix3::from_columns(&[dn, *dr_y, *dr_z]));
    let Some(ch) = p.a.cholesky() else {
        return (p.r, Vector3::from_element(f64::NAN), Vector3::from_element(f64::NAN));
    };
    let omega_b = p.body.cross_matrix();
    let du = p.w - omega_b * p.u;
    let du = (du + du.transpose()) * 0.5;
    let dw = p.r.transpose() * Matrix3::from_columns(&[ddn, *ddr_y, *ddr_z]) - omega_b * p.w;
    let da = Matrix3::identity() * du.trace() - du;
    let body_acc = ch.solve(&(axial(&dw) - da * p.body));
    (p.r, p.r * p.body, p.r * body_acc)
}

/// The polar factor `R` of `F = R U` and the body rate `w` of `Ω = Rᵀ Ṙ = [w]×` while `F`
/// changes at `Ḟ`: `(tr U − U) w = axial(W − Wᵀ)`, `W = Rᵀ Ḟ` (NaN for a degenerate `F`).
struct PolarRate {
    r: Matrix3<f64>,
    /// `U`'s symmetric part, `W`, and `A = tr U − U`.
    u: Matrix3<f64>,
    w: Matrix3<f64>,
    a: Matrix3<f64>,
    body: Vector3<f64>,
}

impl PolarRate {
    fn new(f: &Matrix3<f64>, df: &Matrix3<f64>) -> Self {
        let r = polar_rotation(f);
        let u = r.transpose() * f;
        let u = (u + u.transpose()) * 0.5;
        let w = r.transpose() * df;
        let a = Matrix3::identity() * u.trace() - u;
        let body = a.cholesky().map_or(Vector3::from_element(f64::NAN), |ch| ch.solve(&axial(&w)));
        Self { r, u, w, a, body }
    }
}

/// `(m₂₁ − m₁₂, m₀₂ − m₂₀, m₁₀ − m₀₁)`: twice the axial vector of `m`'s skew part.
fn axial(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
}

/// The rotation factor of the polar decomposition `F = R U` (the rotation closest to `F`).
///
/// For `det F > 0` (every section frame: `det [n, r_y, r_z] = |r_y × r_z|`) by Higham's Newton
/// iteration `X ← (ζX + (ζX)⁻ᵀ/ζ)/2` with the determinant scaling `ζ = |det X|^(−1/3)` (1 once `det X` is within 1e-2 of 1), which
/// converges quadratically to the polar factor (Higham, *Functions of Matrices*, SIAM 2008,
/// §8.6): a section's slopes are orthonormal to their strain, so three or four iterations of
/// a 3 × 3 inverse reach rounding, against a general SVD that cost a fifth of the paper's wing
/// run. Otherwise (a reflection or a singular `F`) from the SVD, as the closest proper rotation.
pub fn polar_rotation(f: &Matrix3<f64>) -> Matrix3<f64> {
    let mut x = *f;
    let mut det = x.determinant();
    for _ in 0..POLAR_MAX_ITERATIONS {
        if !(det > 0.0 && det.is_finite()) {
            return polar_rotation_svd(f);
        }
        // Scaling pays only far from orthogonality (Higham §8.9 switches it off once the
        // iteration settles); near it, ζ is 1 to within |det X − 1| and the cube root costs more
        // than the iteration.
        let zeta = if (det - 1.0).abs() < 1e-2 { 1.0 } else { det.cbrt().recip() };
        // (ζX)⁻ᵀ from the cofactors: (X⁻¹)ᵀ = cof(X)/det X.
        let (c0, c1, c2) = (x.column(0), x.column(1), x.column(2));
        let cof = Matrix3::from_columns(&[c1.cross(&c2), c2.cross(&c0), c0.cross(&c1)]);
        let next = (x * zeta + cof * (1.0 / (det * zeta))) * 0.5;
        let change = (next - x).amax();
        x = next;
        if change <= POLAR_TOLERANCE {
            return x;
        }
        det = x.determinant();
    }
    polar_rotation_svd(f)
}

/// Iterations of [`polar_rotation`]'s Newton iteration before it falls back to the SVD (a
/// well-conditioned `F` takes 3–5; scaling bounds the count by about 9 for condition 1e16).
const POLAR_MAX_ITERATIONS: usize = 20;

/// Largest entry change of a Newton iterate at which [`polar_rotation`] stops: quadratic
/// convergence leaves the next change at about its square, below rounding.
const POLAR_TOLERANCE: f64 = 1e-12;

/// The closest proper rotation to `f` from its SVD (a reflection flips the last singular vector).
fn polar_rotation_svd(f: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = f.svd(true, true);
    let (u, vt) = match (svd.u, svd.v_t) {
        (Some(u), Some(vt)) => (u, vt),
        _ => return Matrix3::identity(),
    };
    let mut r = u * vt;
    if r.determinant() < 0.0 {
        let mut u2 = u;
        u2.column_mut(2).neg_mut();
        r = u2 * vt;
    }
    r
}

/// The rotation that turns a node from the slopes `from` to the slopes `to` (each
/// `[r_x, r_y, r_z]`, nine values column after column): the rotation factor of
/// `F_to F_from⁻¹`, identity when `F_from` is singular.
pub fn node_turn(from: &[f64], to: &[f64]) -> Matrix3<f64> {
    let (f0, f1) = (Matrix3::from_column_slice(&from[..9]), Matrix3::from_column_slice(&to[..9]));
    match f0.try_inverse() {
        Some(inv) => polar_rotation(&(f1 * inv)),
        None => Matrix3::identity(),
    }
}

/// Rotation angle of a rotation matrix, rad in [0, π] (accurate for small angles).
pub fn rotation_angle(r: &Matrix3<f64>) -> f64 {
    let s = Vector3::new(r[(2, 1)] - r[(1, 2)], r[(0, 2)] - r[(2, 0)], r[(1, 0)] - r[(0, 1)]).norm() * 0.5;
    let c = 0.5 * (r.trace() - 1.0);
    s.atan2(c)
}

/// Angle between two vectors, rad in [0, π] (accurate for small angles).
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Fold angle θ of `r = R_parentᵀ R_child R_ref⁻¹` about `−a` (`a` in the parent section frame):
/// `θ = atan2(n2·(r n1), n1·(r n1))` with `n1 ⟂ a` fixed and `n2 = (−a) × n1`.
pub fn fold_angle(r: &Matrix3<f64>, a: &Vector3<f64>) -> f64 {
    let (n1, n2) = rotation_basis(&-a.normalize());
    let rn1 = r * n1;
    n2.dot(&rn1).atan2(n1.dot(&rn1))
}

/// The fixed unit vectors that measure a rotation about the unit axis `axis`: `n1 ⟂ axis` (the
/// least aligned coordinate axis, made orthogonal to `axis`) and `n2 = axis × n1`. A rotation
/// `R` by θ about `axis` has `θ = atan2(n2·(R n1), n1·(R n1))`.
pub fn rotation_basis(axis: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let k = axis.iamin();
    let mut n1 = Vector3::zeros();
    n1[k] = 1.0;
    let n1 = (n1 - axis * axis.dot(&n1)).normalize();
    (n1, axis.cross(&n1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Rotation3;

    #[test]
    fn frame_of_a_rotated_orthonormal_section_is_that_rotation() {
        let rot = Rotation3::from_scaled_axis(Vector3::new(0.3, -1.1, 0.4)).into_inner();
        let f = section_frame(&(rot * Vector3::y()), &(rot * Vector3::z()));
        assert_relative_eq!(f, rot, epsilon = 1e-14);
    }

    #[test]
    fn newton_polar_factor_equals_the_svd_one() {
        // Near rotations (a section's slopes) and strongly distorted matrices with det > 0.
        let mut seed = 12345u64;
        let mut rand = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for k in 0..400 {
            let rot = Rotation3::from_scaled_axis(Vector3::new(6.0 * rand(), 6.0 * rand(), 6.0 * rand()));
            let size = if k % 2 == 0 { 1e-3 } else { 1.0 };
            let u = Matrix3::from_fn(|i, j| f64::from(u8::from(i == j)) + size * rand());
            let f = rot.into_inner() * u;
            if f.determinant() <= 1e-3 {
                continue;
            }
            let (newton, svd) = (polar_rotation(&f), polar_rotation_svd(&f));
            assert_relative_eq!(newton, svd, epsilon = 1e-13);
            assert_relative_eq!(newton.transpose() * newton, Matrix3::identity(), epsilon = 1e-14);
        }
        // A reflection takes the SVD's closest proper rotation.
        let m = Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, -0.5));
        assert_relative_eq!(polar_rotation(&m), polar_rotation_svd(&m), epsilon = 1e-15);
        assert!(polar_rotation(&m).determinant() > 0.0);
    }

    #[test]
    fn frame_of_a_stretched_section_is_orthonormal() {
        let f = section_frame(&Vector3::new(0.01, 1.02, 0.03), &Vector3::new(-0.02, 0.01, 0.97));
        assert_relative_eq!(f.transpose() * f, Matrix3::identity(), epsilon = 1e-13);
        assert!(f.determinant() > 0.0);
    }

    #[test]
    fn fold_angle_follows_the_right_hand_rule_about_minus_a() {
        for beta in [0.0, 0.4, 1.2, std::f64::consts::FRAC_PI_2, -0.7] {
            let a = Vector3::new(f64::sin(beta), f64::cos(beta), 0.0);
            for theta in [-2.5, -0.3, 0.0, 0.8, 3.0] {
                let r = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(-a), theta).into_inner();
                assert_relative_eq!(fold_angle(&r, &a), theta, epsilon = 1e-13);
            }
        }
        // β = 0, θ > 0 lifts the child's free end (+x) toward +z.
        let a = Vector3::y();
        let r = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(-a), 0.5).into_inner();
        assert!((r * Vector3::x()).z > 0.0);
    }

    #[test]
    fn small_angles_are_accurate() {
        let r = Rotation3::from_scaled_axis(Vector3::new(1e-9, 2e-9, -2e-9)).into_inner();
        assert_relative_eq!(rotation_angle(&r), 3e-9, max_relative = 1e-6);
        assert_relative_eq!(angle_between(&Vector3::x(), &Vector3::new(1.0, 1e-10, 0.0)), 1e-10, max_relative = 1e-6);
    }
}
