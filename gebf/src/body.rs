//! Beam bodies: the input description and the internal layout of a body's unknowns.
//!
//! Each body carries its own floating frame of reference A, which coincides with the body's
//! section frame and start point in the reference configuration. The body is discretised into
//! `n_elements` three-node elements (nodes `0..=2 n_elements`, equally spaced); node 0 is
//! clamped to A (`R_0 = 0`, `psi_0 = 0`) and is not an unknown.
//!
//! Layout of the unknowns of one body:
//! * storage `q`: nodes 1..=N `(R, psi)` (6 each, R in m in A, psi the CRV of B relative to A),
//!   then `r_A` (3, global, m) and the quaternion `χ` (4, `[w, x, y, z]`);
//! * tangent (`v`, `v_dot`, residual rows): nodes 1..=N `(R_dot, psi_dot)`, then `v_A` (3) and
//!   `omega_A` (3), both in A components.

use crate::Section;
use crate::crv::{M3, V3};
use crate::quaternion::Quaternion;
use crate::rigid_slice::Slice;

pub use scene::BodySpec;

/// Internal description of one body: geometry, section and where its unknowns live.
#[derive(Debug, Clone)]
pub(crate) struct Body {
    pub n_elements: usize,
    /// Element length, m.
    pub le: f64,
    pub length: f64,
    pub section: Section,
    /// Reference frame origin (global), m.
    pub start: V3,
    /// Reference orientation C^{GA}_0.
    pub frame: M3,
    pub quat0: Quaternion,
    /// First tangent index of the body.
    pub dof0: usize,
    /// First storage index of the body.
    pub coord0: usize,
    /// The section's centre of mass relative to the axis, `(0, y_c, z_c)` in section
    /// components, m (zero: the axis kernel of `inertia.rs`).
    pub cg: V3,
    /// The point masses of each element, at their parametric positions.
    pub point_masses: Vec<Vec<Slice>>,
    /// A twisted body's reference twist of each node relative to A, φ_i = θ(s_i) − θ(0), rad
    /// (its reference CRV is `φ_i e_x`); empty for an untwisted body (docs/gebf.md §4).
    pub twist0: Vec<f64>,
}

impl Body {
    pub fn new(spec: &BodySpec, dof0: usize, coord0: usize) -> Self {
        // Orthonormalise the frame (it passed a 1e-9 check) so that the quaternion is exact.
        // A follows the start section: twisted by θ(0) for a twisted body.
        let quat0 = Quaternion::from_rotation_matrix(&spec.section_frame(0.0));
        let le = spec.length / spec.n_elements as f64;
        let twist0 = if spec.twist.is_none() {
            Vec::new()
        } else {
            let root = spec.twist.angle(0.0);
            (0..=2 * spec.n_elements).map(|i| spec.twist.angle(0.5 * le * i as f64) - root).collect()
        };
        let mut point_masses = vec![Vec::new(); spec.n_elements];
        for p in &spec.point_masses {
            // The element holding arclength `at` (the last one for the body's end).
            let e = ((p.at / le).floor().max(0.0) as usize).min(spec.n_elements - 1);
            let xi = (2.0 * (p.at - e as f64 * le) / le - 1.0).clamp(-1.0, 1.0);
            point_masses[e].push(Slice { xi, mass: p.mass, inertia: p.inertia, offset: p.offset });
        }
        Self {
            n_elements: spec.n_elements,
            le,
            length: spec.length,
            section: spec.section,
            start: spec.start,
            frame: quat0.to_rotation_matrix(),
            quat0,
            dof0,
            coord0,
            cg: V3::new(0.0, spec.section.cg_offset[0], spec.section.cg_offset[1]),
            point_masses,
            twist0,
        }
    }
    /// Reference CRV of node `i` relative to A (`None`: zero, an untwisted body).
    #[inline]
    pub fn node_psi0(&self, i: usize) -> Option<V3> {
        self.twist0.get(i).map(|&phi| V3::new(phi, 0.0, 0.0))
    }
    /// The nodal reference twists of element `e` (`None` for an untwisted body).
    #[inline]
    pub fn element_twist(&self, e: usize) -> Option<&[f64; 3]> {
        self.twist0.get(2 * e..2 * e + 3).map(|w| w.try_into().expect("three nodes"))
    }
    /// Reference orientation `C^{GB}_0` of node `i`'s section.
    pub fn section_frame0(&self, i: usize) -> M3 {
        match self.node_psi0(i) {
            None => self.frame,
            Some(psi0) => self.frame * crate::crv::rotation_matrix(&psi0),
        }
    }
    /// Number of nodes, including the clamped node 0.
    pub fn n_nodes(&self) -> usize {
        2 * self.n_elements + 1
    }
    /// Number of tangent unknowns.
    pub fn n_dof(&self) -> usize {
        12 * self.n_elements + 6
    }
    /// Number of storage coordinates.
    pub fn n_coords(&self) -> usize {
        12 * self.n_elements + 7
    }
    /// Tangent index of node `i`'s `(R, psi)` block (None for the clamped node 0).
    #[inline]
    pub fn node_dof(&self, i: usize) -> Option<usize> {
        if i == 0 { None } else { Some(self.dof0 + 6 * (i - 1)) }
    }
    /// Storage index of node `i`'s `(R, psi)`.
    #[inline]
    pub fn node_coord(&self, i: usize) -> Option<usize> {
        if i == 0 { None } else { Some(self.coord0 + 6 * (i - 1)) }
    }
    /// Tangent index of `(v_A, omega_A)`.
    #[inline]
    pub fn frame_dof(&self) -> usize {
        self.dof0 + 12 * self.n_elements
    }
    /// Storage index of `r_A`; the quaternion follows at `+3`.
    #[inline]
    pub fn frame_coord(&self) -> usize {
        self.coord0 + 12 * self.n_elements
    }
    /// Reference position of node `i` in A, m.
    pub fn node_ref(&self, i: usize) -> V3 {
        V3::new(0.5 * self.le * i as f64, 0.0, 0.0)
    }
    /// Nodal `(R, psi)` of node `i` from the storage vector.
    #[inline]
    pub fn node_state(&self, q: &[f64], i: usize) -> (V3, V3) {
        match self.node_coord(i) {
            None => (V3::zeros(), V3::zeros()),
            Some(k) => (V3::new(q[k], q[k + 1], q[k + 2]), V3::new(q[k + 3], q[k + 4], q[k + 5])),
        }
    }
    /// Nodal tangent-space pair (e.g. `(R_dot, psi_dot)`) of node `i`.
    #[inline]
    pub fn node_rates(&self, x: &[f64], i: usize) -> (V3, V3) {
        match self.node_dof(i) {
            None => (V3::zeros(), V3::zeros()),
            Some(k) => (V3::new(x[k], x[k + 1], x[k + 2]), V3::new(x[k + 3], x[k + 4], x[k + 5])),
        }
    }
    /// `(r_A, χ)` from the storage vector.
    #[inline]
    pub fn frame_state(&self, q: &[f64]) -> (V3, Quaternion) {
        let k = self.frame_coord();
        (V3::new(q[k], q[k + 1], q[k + 2]), Quaternion::from_slice(&q[k + 3..k + 7]))
    }
    /// `(v_A, omega_A)` (or their rates) from a tangent vector.
    #[inline]
    pub fn frame_rates(&self, x: &[f64]) -> (V3, V3) {
        let k = self.frame_dof();
        (V3::new(x[k], x[k + 1], x[k + 2]), V3::new(x[k + 3], x[k + 4], x[k + 5]))
    }
}
