//! Point masses fixed to a body's section (docs/ancf.md §12.2): exact terms of the constant
//! mass matrix.
//!
//! A point mass at arclength `s` with offset `(x, y, z)` in the section frame has its centre at
//!
//! $$ r_p = r(s) + x\, r_x(s) + y\, r_y(s) + z\, r_z(s) = w_p^T e, $$
//!
//! linear in the element coordinates: the section offsets `y`, `z` ride on the section slopes
//! exactly as the section's own material points do, and the axial offset `x` rides on the
//! centreline tangent `r_x` (exact for a rigid motion and for an unstretched, unsheared axis;
//! the section normal `r_y × r_z` would be exact under shear too but is quadratic and would make
//! the mass matrix depend on q). Its rotary inertia is carried by the three directors at `s`,
//! `d = (r_x, r_y, r_z)`, orthonormal in the reference configuration (the body frame): for a
//! rigid rotation `ḋ_i = ω × d_i` and
//!
//! $$ \tfrac12 \sum_i D_{ii} |\dot d_i|^2 = \tfrac12\, \omega^T (\operatorname{tr} D\, 1 - D)\, \omega, $$
//!
//! which is the rigid body's `½ ωᵀ J ω` for the "director inertia" `D = ½ tr(J) 1 − J`:
//!
//! $$ D_{xx} = \tfrac12 (I_{yy} + I_{zz} - I_{xx}),\quad D_{yy} = \tfrac12 (I_{xx} - I_{yy} + I_{zz}),\quad D_{zz} = \tfrac12 (I_{xx} + I_{yy} - I_{zz}), $$
//!
//! all non-negative for a physical inertia (triangle inequality). The element mass factor gains
//! `m w_p w_pᵀ + D_xx w_x w_xᵀ + D_yy w_y w_yᵀ + D_zz w_z w_zᵀ` (`w_x`, `w_y`, `w_z` the weights
//! of the three directors at `s`) and the gravity force `m w_p ⊗ g`.

use crate::PointMass;
use crate::shape::{N_BLOCKS, hermite_dx, point_weights};

/// Weights of the point mass's centre on the eight blocks of its element (ξ in the element of
/// length `l`): `r_p = Σ w_b e_b`.
pub fn point_mass_weights(p: &PointMass, xi: f64, l: f64) -> [f64; N_BLOCKS] {
    let mut w = point_weights(xi, l, p.offset.y, p.offset.z);
    if p.offset.x != 0.0 {
        for (b, d) in [0, 1, 4, 5].into_iter().zip(hermite_dx(xi, l)) {
            w[b] += p.offset.x * d;
        }
    }
    w
}

/// The point mass's contribution to the scalar mass factor `m̄` of its element, kg.
pub fn point_mass_matrix(p: &PointMass, xi: f64, l: f64) -> [[f64; N_BLOCKS]; N_BLOCKS] {
    let w = point_mass_weights(p, xi, l);
    let i = p.inertia;
    let d =
        [(0.5 * (i.y + i.z - i.x)).max(0.0), (0.5 * (i.x - i.y + i.z)).max(0.0), (0.5 * (i.x + i.y - i.z)).max(0.0)];
    let mut m = [[0.0; N_BLOCKS]; N_BLOCKS];
    for a in 0..N_BLOCKS {
        for b in 0..N_BLOCKS {
            m[a][b] = p.mass * w[a] * w[b];
        }
    }
    for (dk, wk) in d.into_iter().zip(director_weights(xi, l)) {
        for a in 0..N_BLOCKS {
            for b in 0..N_BLOCKS {
                m[a][b] += dk * wk[a] * wk[b];
            }
        }
    }
    m
}

/// Weights of the three directors `r_x`, `r_y`, `r_z` at ξ on the eight blocks of the element.
pub fn director_weights(xi: f64, l: f64) -> [[f64; N_BLOCKS]; 3] {
    let h = hermite_dx(xi, l);
    [
        [h[0], h[1], 0.0, 0.0, h[2], h[3], 0.0, 0.0],
        [0.0, 0.0, 1.0 - xi, 0.0, 0.0, 0.0, xi, 0.0],
        [0.0, 0.0, 0.0, 1.0 - xi, 0.0, 0.0, 0.0, xi],
    ]
}

/// A point mass's share of the mass matrix, placed on its element.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PointInertia {
    /// Global element index (bodies in order), for the ODE path's reduced scatter.
    pub e_index: usize,
    /// First full coordinate of the element.
    pub first: usize,
    /// Non-zeros `(row block, column block, value)` of the scalar factor.
    pub mass_nz: Vec<(usize, usize, f64)>,
}

impl PointInertia {
    /// `out += c · M_p · x` for 24-vectors.
    pub(crate) fn add_mass_times(&self, c: f64, x: &[f64], out: &mut [f64]) {
        for &(a, b, m) in &self.mass_nz {
            let cm = c * m;
            for i in 0..3 {
                out[3 * a + i] += cm * x[3 * b + i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Vector3;

    #[test]
    fn the_centre_follows_a_rigid_rotation_of_the_section() {
        // element along x of length l with rigidly rotated slopes R·I: the point goes to R·offset
        let l = 0.3;
        let r = nalgebra::Rotation3::from_scaled_axis(Vector3::new(0.3, -0.5, 0.8)).into_inner();
        let mut e = [0.0; 24];
        for n in 0..2 {
            let pos = Vector3::new(1.0, 2.0, 3.0) + r * Vector3::x() * (n as f64 * l);
            e[12 * n..12 * n + 3].copy_from_slice(pos.as_slice());
            for k in 0..3 {
                e[12 * n + 3 * (k + 1)..12 * n + 3 * (k + 2)].copy_from_slice(r.column(k).as_slice());
            }
        }
        let p = PointMass { at: 0.0, offset: Vector3::new(0.05, -0.1, 0.2), mass: 1.0, inertia: Vector3::zeros() };
        let xi = 0.35;
        let w = point_mass_weights(&p, xi, l);
        let got: Vector3<f64> = (0..8).map(|b| Vector3::new(e[3 * b], e[3 * b + 1], e[3 * b + 2]) * w[b]).sum();
        let expected = Vector3::new(1.0, 2.0, 3.0) + r * (Vector3::x() * (xi * l) + p.offset);
        assert_relative_eq!(got, expected, epsilon = 1e-14);
    }

    #[test]
    fn translation_carries_the_mass_and_the_slopes_the_inertia() {
        let p =
            PointMass { at: 0.0, offset: Vector3::new(0.0, 0.1, 0.0), mass: 2.0, inertia: Vector3::new(0.5, 0.2, 0.3) };
        let m = point_mass_matrix(&p, 0.25, 0.4);
        let u = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let total: f64 = (0..8).flat_map(|a| (0..8).map(move |b| (a, b))).map(|(a, b)| u[a] * m[a][b] * u[b]).sum();
        assert_relative_eq!(total, 2.0, epsilon = 1e-14);
    }

    /// Kinetic energy `½ Σ m̄_ab ė_a·ė_b` of an element whose nodes and slopes move rigidly
    /// (orientation `r`, angular velocity `w`, origin velocity `v`) equals the rigid body's
    /// `½ m |v_p|² + ½ ωᵀ R J Rᵀ ω` for a general diagonal inertia (`I_xx ≠ I_yy + I_zz`) and
    /// an offset, for any orientation.
    #[test]
    fn kinetic_energy_of_rigid_motions_is_the_rigid_bodys() {
        let l = 0.3;
        let xi = 0.4;
        let p = PointMass {
            at: 0.0,
            offset: Vector3::new(0.04, -0.07, 0.11),
            mass: 0.8,
            inertia: Vector3::new(0.3e-2, 1.9e-2, 2.1e-2),
        };
        let m = point_mass_matrix(&p, xi, l);
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..20 {
            let mut v3 = |s: f64| Vector3::new(s * rnd(), s * rnd(), s * rnd());
            let r = nalgebra::Rotation3::from_scaled_axis(v3(3.0)).into_inner();
            let (c, v, w) = (v3(2.0), v3(1.5), v3(4.0));
            let mut e = [Vector3::zeros(); 8];
            let mut e_dot = [Vector3::zeros(); 8];
            for n in 0..2 {
                let pos = c + r * Vector3::x() * (n as f64 * l);
                e[4 * n] = pos;
                e_dot[4 * n] = v + w.cross(&(pos - c));
                for k in 0..3 {
                    let d: Vector3<f64> = r.column(k).into();
                    e[4 * n + k + 1] = d;
                    e_dot[4 * n + k + 1] = w.cross(&d);
                }
            }
            let mut ke = 0.0;
            for a in 0..8 {
                for b in 0..8 {
                    ke += 0.5 * m[a][b] * e_dot[a].dot(&e_dot[b]);
                }
            }
            let centre = c + r * (Vector3::x() * (xi * l) + p.offset);
            let v_p = v + w.cross(&(centre - c));
            let j = r * nalgebra::Matrix3::from_diagonal(&p.inertia) * r.transpose();
            let expected = 0.5 * p.mass * v_p.norm_squared() + 0.5 * w.dot(&(j * w));
            assert_relative_eq!(ke, expected, max_relative = 1e-13);
        }
    }
}
