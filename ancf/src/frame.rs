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

/// The rotation factor of the polar decomposition `F = R U` (the rotation closest to `F`).
pub fn polar_rotation(f: &Matrix3<f64>) -> Matrix3<f64> {
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
