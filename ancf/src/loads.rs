//! External loads: gravity and point loads (docs/ancf.md §4).
//!
//! * Gravity: the constant generalized force `Q_g = Σ_e ∫ m S_cᵀ g dx`.
//! * A point force `F` at the material point (s, y, z) of a body (arclength s along the
//!   reference axis, section coordinates y, z): `Q = S(x, y, z)ᵀ F` — a dead load, constant in q.
//! * A point moment `M` (fixed global vector) at the section at s:
//!   `Q = ½ Σ_i (∂d_i/∂e)ᵀ (M × d_i)` with `d = (r_y × r_z, r_y, r_z)` (from
//!   `δθ = ½ Σ d_i × δd_i`); it depends on q and contributes `−∂Q/∂q` to the tangent.

use crate::model::Body;
use crate::shape::{NODE_DOF, point_weights};
use nalgebra::{Matrix3, Vector3};

/// A point load on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// Body index.
    pub body: usize,
    /// Arclength along the body's reference axis, m, in [0, length].
    pub s: f64,
    /// Section coordinate y of the loaded material point, m (0 = on the axis).
    pub y: f64,
    /// Section coordinate z of the loaded material point, m.
    pub z: f64,
    /// Force, global, N (dead load).
    pub force: Vector3<f64>,
    /// Moment on the section, global, N·m (fixed direction).
    pub moment: Vector3<f64>,
}

impl PointLoad {
    /// A force on the beam axis.
    pub fn force(body: usize, s: f64, force: Vector3<f64>) -> Self {
        Self { body, s, y: 0.0, z: 0.0, force, moment: Vector3::zeros() }
    }
    /// A moment on the section at `s`.
    pub fn moment(body: usize, s: f64, moment: Vector3<f64>) -> Self {
        Self { body, s, y: 0.0, z: 0.0, force: Vector3::zeros(), moment }
    }
}

/// A station on a body: the element's first coordinate and ξ within it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Station {
    pub first: usize,
    pub xi: f64,
    pub l: f64,
}

/// The element and ξ of arclength `s` (assumed within [0, L] up to round-off).
pub(crate) fn locate(body: &Body, s: f64) -> Station {
    let l = body.element.l;
    let n_el = body.n_nodes - 1;
    let x = (s / l).clamp(0.0, n_el as f64);
    let k = (x.floor() as usize).min(n_el - 1);
    Station { first: body.offset + NODE_DOF * k, xi: x - k as f64, l }
}

/// `out += S(x, y, z)ᵀ F` (full coordinate vector).
pub(crate) fn add_point_force(st: Station, y: f64, z: f64, force: &Vector3<f64>, out: &mut [f64]) {
    let w = point_weights(st.xi, st.l, y, z);
    for (b, wb) in w.iter().enumerate() {
        for i in 0..3 {
            out[st.first + 3 * b + i] += wb * force[i];
        }
    }
}

pub(crate) fn slopes(st: Station, q: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let v = |b: usize| Vector3::new(q[st.first + 3 * b], q[st.first + 3 * b + 1], q[st.first + 3 * b + 2]);
    let (w1, w2) = (1.0 - st.xi, st.xi);
    (v(2) * w1 + v(6) * w2, v(3) * w1 + v(7) * w2)
}

/// `out += Q_M(q)` for a moment `m` at the station.
pub(crate) fn add_moment_force(st: Station, m: &Vector3<f64>, q: &[f64], out: &mut [f64]) {
    let (ry, rz) = slopes(st, q);
    let w1 = 0.5 * m.cross(&ry.cross(&rz));
    let q_ry = 0.5 * m.cross(&ry) + rz.cross(&w1);
    let q_rz = 0.5 * m.cross(&rz) + w1.cross(&ry);
    for (node_block, weight) in [(0, 1.0 - st.xi), (4, st.xi)] {
        for i in 0..3 {
            out[st.first + 3 * (node_block + 2) + i] += weight * q_ry[i];
            out[st.first + 3 * (node_block + 3) + i] += weight * q_rz[i];
        }
    }
}

/// `∂Q_M/∂(r_y, r_z)` of the interpolated slopes: `[[∂Q_ry/∂r_y, ∂Q_ry/∂r_z], [∂Q_rz/∂r_y, ∂Q_rz/∂r_z]]`.
fn moment_jacobian(st: Station, m: &Vector3<f64>, q: &[f64]) -> [[Matrix3<f64>; 2]; 2] {
    let (ry, rz) = slopes(st, q);
    let s = m.cross_matrix();
    let (cy, cz) = (ry.cross_matrix(), rz.cross_matrix());
    let w1 = (0.5 * m.cross(&ry.cross(&rz))).cross_matrix();
    [[0.5 * s - 0.5 * cz * s * cz, -w1 + 0.5 * cz * s * cy], [w1 + 0.5 * cy * s * cz, 0.5 * s - 0.5 * cy * s * cy]]
}

/// Calls `add(row, col, block)` with the 3×3 blocks of `−c ∂Q_M/∂q` (full coordinates).
pub(crate) fn moment_tangent(
    st: Station,
    m: &Vector3<f64>,
    q: &[f64],
    c: f64,
    mut add: impl FnMut(usize, usize, &Matrix3<f64>),
) {
    let jac = moment_jacobian(st, m, q);
    let nodes = [(0usize, 1.0 - st.xi), (4usize, st.xi)];
    for &(na, wa) in &nodes {
        for &(nb, wb) in &nodes {
            for (fa, row) in jac.iter().enumerate() {
                for (fb, j) in row.iter().enumerate() {
                    let blk = -c * wa * wb * j;
                    add(st.first + 3 * (na + 2 + fa), st.first + 3 * (nb + 2 + fb), &blk);
                }
            }
        }
    }
}
