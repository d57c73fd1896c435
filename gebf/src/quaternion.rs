//! Unit quaternions for the orientation of the floating frames.
//!
//! `χ = (w, x, y, z)` with `w = cos(φ/2)`, `(x, y, z) = sin(φ/2) n`: the rotation by `φ` about
//! `n`. Its matrix `C(χ) = C^{GA}` maps frame (A) components to global (G) components, and
//! the Hamilton product composes like the matrices: `C(χ₁ ⊗ χ₂) = C(χ₁) C(χ₂)`.
//! The Lie update of the integrator is `χ ← χ ⊗ exp(δθ/2)` with `δθ` in A components, i.e.
//! `C^{GA} ← C^{GA} exp(δθ̃)`; it keeps `|χ| = 1` exactly (up to round-off).

use crate::crv::{M3, V3};

/// A quaternion `w + x i + y j + z k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quaternion {
    /// Scalar part.
    pub w: f64,
    /// Vector part.
    pub v: V3,
}

impl Quaternion {
    /// The identity rotation.
    pub fn identity() -> Self {
        Self { w: 1.0, v: V3::zeros() }
    }

    /// From the storage order `[w, x, y, z]`.
    ///
    /// # Panics
    /// When `s` has fewer than four entries.
    pub fn from_slice(s: &[f64]) -> Self {
        Self { w: s[0], v: V3::new(s[1], s[2], s[3]) }
    }

    /// Write in storage order `[w, x, y, z]`.
    ///
    /// # Panics
    /// When `s` has fewer than four entries.
    pub fn write_to(&self, s: &mut [f64]) {
        s[0] = self.w;
        s[1] = self.v.x;
        s[2] = self.v.y;
        s[3] = self.v.z;
    }

    /// Hamilton product `self ⊗ o`.
    pub fn mul(&self, o: &Self) -> Self {
        Self { w: self.w * o.w - self.v.dot(&o.v), v: o.v * self.w + self.v * o.w + self.v.cross(&o.v) }
    }

    /// Conjugate (the inverse of a unit quaternion).
    pub fn conjugate(&self) -> Self {
        Self { w: self.w, v: -self.v }
    }

    /// Euclidean norm.
    pub fn norm(&self) -> f64 {
        (self.w * self.w + self.v.norm_squared()).sqrt()
    }

    /// Scaled to unit norm.
    pub fn normalized(&self) -> Self {
        let n = self.norm();
        Self { w: self.w / n, v: self.v / n }
    }

    /// The unit quaternion of the rotation vector `theta` (rotation by |theta| about its
    /// direction): `exp(theta/2)` in quaternion terms.
    pub fn from_rotation_vector(theta: &V3) -> Self {
        let phi = theta.norm();
        let h = 0.5 * phi;
        // sin(φ/2)/φ with its series near zero.
        let s = if phi < 1e-4 { 0.5 - phi * phi / 48.0 } else { h.sin() / phi };
        Self { w: h.cos(), v: theta * s }
    }

    /// The rotation vector (CRV) with norm in [0, π] of this unit quaternion (the logarithm).
    pub fn to_crv(&self) -> V3 {
        // Choose the hemisphere w ≥ 0 so that the angle is in [0, π].
        let (w, v) = if self.w < 0.0 { (-self.w, -self.v) } else { (self.w, self.v) };
        let sv = v.norm();
        if sv < 1e-12 {
            // φ ≈ 2 sv; first-order with the cubic correction.
            return v * (2.0 / w.max(f64::MIN_POSITIVE)) * (1.0 - sv * sv / (3.0 * w * w));
        }
        let phi = 2.0 * sv.atan2(w);
        v * (phi / sv)
    }

    /// The rotation matrix `C(χ)`.
    pub fn to_rotation_matrix(&self) -> M3 {
        let (w, x, y, z) = (self.w, self.v.x, self.v.y, self.v.z);
        M3::new(
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        )
    }

    /// The unit quaternion (with w ≥ 0) of a rotation matrix (Shepperd's method: the largest
    /// diagonal combination is used, so it is accurate at every angle).
    pub fn from_rotation_matrix(c: &M3) -> Self {
        let tr = c.trace();
        let d = [tr, c[(0, 0)], c[(1, 1)], c[(2, 2)]];
        let i = (0..4).fold(0, |best, k| if d[k] > d[best] { k } else { best });
        let q = match i {
            0 => {
                let r = (1.0 + tr).sqrt();
                let s = 0.5 / r;
                Self {
                    w: 0.5 * r,
                    v: V3::new((c[(2, 1)] - c[(1, 2)]) * s, (c[(0, 2)] - c[(2, 0)]) * s, (c[(1, 0)] - c[(0, 1)]) * s),
                }
            }
            1 => {
                let r = (1.0 + 2.0 * c[(0, 0)] - tr).sqrt();
                let s = 0.5 / r;
                Self {
                    w: (c[(2, 1)] - c[(1, 2)]) * s,
                    v: V3::new(0.5 * r, (c[(0, 1)] + c[(1, 0)]) * s, (c[(0, 2)] + c[(2, 0)]) * s),
                }
            }
            2 => {
                let r = (1.0 + 2.0 * c[(1, 1)] - tr).sqrt();
                let s = 0.5 / r;
                Self {
                    w: (c[(0, 2)] - c[(2, 0)]) * s,
                    v: V3::new((c[(0, 1)] + c[(1, 0)]) * s, 0.5 * r, (c[(1, 2)] + c[(2, 1)]) * s),
                }
            }
            _ => {
                let r = (1.0 + 2.0 * c[(2, 2)] - tr).sqrt();
                let s = 0.5 / r;
                Self {
                    w: (c[(1, 0)] - c[(0, 1)]) * s,
                    v: V3::new((c[(0, 2)] + c[(2, 0)]) * s, (c[(1, 2)] + c[(2, 1)]) * s, 0.5 * r),
                }
            }
        };
        let q = q.normalized();
        if q.w < 0.0 { Self { w: -q.w, v: -q.v } } else { q }
    }

    /// The Lie update `self ⊗ exp(δθ/2)`, renormalised against round-off.
    pub fn retract(&self, dtheta: &V3) -> Self {
        self.mul(&Self::from_rotation_vector(dtheta)).normalized()
    }

    /// Rotate a vector: `C(χ) a`.
    pub fn rotate(&self, a: &V3) -> V3 {
        // a + 2w (v × a) + 2 v × (v × a)
        let t = self.v.cross(a) * 2.0;
        a + t * self.w + self.v.cross(&t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::crv::{rotation_matrix, skew};
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn vectors() -> Vec<V3> {
        vec![
            V3::zeros(),
            V3::new(1e-10, 0.0, -3e-10),
            V3::new(0.2, -0.1, 0.3),
            V3::new(1.0, 2.0, -1.5),
            V3::new(0.0, PI - 1e-9, 0.0),
            V3::new(1.0, 1.0, 1.0).normalize() * (PI - 1e-7),
            V3::new(PI, 0.0, 0.0),
        ]
    }

    #[test]
    fn crv_quaternion_matrix_round_trips() {
        for th in vectors() {
            let q = Quaternion::from_rotation_vector(&th);
            assert_relative_eq!(q.norm(), 1.0, epsilon = 1e-15);
            let c = q.to_rotation_matrix();
            assert_relative_eq!(c, rotation_matrix(&th), epsilon = 1e-14);
            let q2 = Quaternion::from_rotation_matrix(&c);
            // Same rotation (q and −q are equal rotations).
            assert_relative_eq!(q2.to_rotation_matrix(), c, epsilon = 1e-14);
            let back = q2.to_crv();
            if th.norm() < PI - 1e-6 {
                assert_relative_eq!(back, th, epsilon = 1e-12);
            } else {
                // At π the direction sign is ambiguous; the rotation must agree.
                assert_relative_eq!(rotation_matrix(&back), c, epsilon = 1e-12);
                assert_relative_eq!(back.norm(), th.norm(), epsilon = 1e-6);
            }
            assert_relative_eq!(q.rotate(&V3::new(0.3, -0.4, 1.2)), c * V3::new(0.3, -0.4, 1.2), epsilon = 1e-14);
        }
    }

    #[test]
    fn product_composes_like_matrices() {
        let a = Quaternion::from_rotation_vector(&V3::new(0.3, -1.2, 0.5));
        let b = Quaternion::from_rotation_vector(&V3::new(-2.0, 0.1, 0.4));
        assert_relative_eq!(
            a.mul(&b).to_rotation_matrix(),
            a.to_rotation_matrix() * b.to_rotation_matrix(),
            epsilon = 1e-14
        );
        assert_relative_eq!(a.mul(&a.conjugate()).w, 1.0, epsilon = 1e-15);
    }

    #[test]
    fn retract_is_right_multiplication_by_exp() {
        let q = Quaternion::from_rotation_vector(&V3::new(0.7, 0.2, -0.4));
        let d = V3::new(1e-3, -2e-3, 5e-4);
        let c = q.retract(&d).to_rotation_matrix();
        assert_relative_eq!(c, q.to_rotation_matrix() * rotation_matrix(&d), epsilon = 1e-15);
        // Small-increment derivative: C ← C (I + δθ̃).
        let e = 1e-7;
        let dc = (q.retract(&(d * e)).to_rotation_matrix() - q.retract(&(-d * e)).to_rotation_matrix()) / (2.0 * e);
        assert_relative_eq!(dc, q.to_rotation_matrix() * skew(&d), epsilon = 1e-8);
    }
}
