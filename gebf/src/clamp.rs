//! Clamp: a body's frame is fixed to ground.
//!
//! Velocity-level rows (6): `v_A = 0`, `omega_A = 0`. `B` is constant.

use crate::body::Body;
use crate::crv::from_rotation_matrix;
use genalpha::MatView;

/// Internal clamp.
#[derive(Debug, Clone)]
pub(crate) struct Clamp {
    pub body: usize,
}

impl Clamp {
    pub const N_ROWS: usize = 6;

    pub fn psi(&self, b: &Body, v: &[f64], out: &mut [f64]) {
        let f = b.frame_dof();
        out[..6].copy_from_slice(&v[f..f + 6]);
    }

    pub fn add_b(&self, b: &Body, j: &mut MatView<'_>, row0: usize) {
        let f = b.frame_dof();
        for k in 0..6 {
            j.add(row0 + k, f + k, 1.0);
        }
    }

    /// (gap of the start point, m; angle of the full relative rotation to the reference, rad).
    pub fn violation(&self, b: &Body, q: &[f64]) -> (f64, f64) {
        let (r, chi) = b.frame_state(q);
        let rel = b.frame.transpose() * chi.to_rotation_matrix();
        ((r - b.start).norm(), from_rotation_matrix(&rel).norm())
    }
}
