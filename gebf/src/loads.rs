//! External nodal loads (for the aerodynamic coupling and for statics).
//!
//! A [`NodalLoad`] is a force and a moment in *global* components applied at a node; it is
//! held fixed during a Newton iteration (a dead load for the current step; the coupling code
//! updates it between steps). Its virtual work is
//! `F·δr + M·δθ_G` with `δr = C^{GA}(δr_A + δR + δθ_A × R)` and
//! `δθ_G = C^{GA}(δθ_A + C^{AB} T(psi) δpsi)`, so with `F_A = C^{AG} F`, `M_A = C^{AG} M` and
//! `M_B = C^{BA} M_A` the generalised forces are `R: F_A`, `psi: Tᵀ M_B`, `v_A: F_A`,
//! `omega_A: R × F_A + M_A`. At node 0 (clamped to the frame) only the frame rows remain.
//! The tangent includes the dependence on the frame orientation and on `psi`.

use crate::body::Body;
use crate::crv::{Tangent, V3, rotation_matrix, skew};
use genalpha::MatView;
use nalgebra::Vector3;

/// A load applied at a node, global components.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NodalLoad {
    /// Force, N (global).
    pub force: Vector3<f64>,
    /// Moment, N·m (global).
    pub moment: Vector3<f64>,
}

impl NodalLoad {
    /// Whether both vectors are zero.
    pub fn is_zero(&self) -> bool {
        self.force == V3::zeros() && self.moment == V3::zeros()
    }
}

/// Subtract `scale ×` the generalised load of node `i` of `body` from the residual `r`.
pub(crate) fn add_load(body: &Body, i: usize, load: &NodalLoad, scale: f64, q: &[f64], r: &mut [f64]) {
    let (_, chi) = body.frame_state(q);
    let c_ag = chi.to_rotation_matrix().transpose();
    let fa = c_ag * load.force * scale;
    let ma = c_ag * load.moment * scale;
    let f = body.frame_dof();
    let (ri, psi) = body.node_state(q, i);
    let mut sub = |k: usize, x: &V3| {
        r[k] -= x.x;
        r[k + 1] -= x.y;
        r[k + 2] -= x.z;
    };
    sub(f, &fa);
    sub(f + 3, &(ri.cross(&fa) + ma));
    if let Some(d) = body.node_dof(i) {
        let mb = rotation_matrix(&psi).transpose() * ma;
        sub(d, &fa);
        sub(d + 3, &(Tangent::new(&psi).t.transpose() * mb));
    }
}

/// Add `c_k ∂/∂q` of the (negative) generalised load of node `i` to `k`.
pub(crate) fn add_load_tangent(
    body: &Body,
    i: usize,
    load: &NodalLoad,
    scale: f64,
    q: &[f64],
    c_k: f64,
    k: &mut MatView<'_>,
) {
    let (_, chi) = body.frame_state(q);
    let c_ag = chi.to_rotation_matrix().transpose();
    let fa = c_ag * load.force * scale;
    let ma = c_ag * load.moment * scale;
    let f = body.frame_dof();
    let (ri, psi) = body.node_state(q, i);
    let fat = skew(&fa);
    let mat = skew(&ma);
    let mut k = k.scaled(c_k);
    k.add_block::<3, 3>(f, f + 3, &(-fat));
    k.add_block::<3, 3>(f + 3, f + 3, &(-(skew(&ri) * fat) - mat));
    if let Some(d) = body.node_dof(i) {
        let tg = Tangent::new(&psi);
        let cba = tg.rotation().transpose();
        let mb = cba * ma;
        k.add_block::<3, 3>(d, f + 3, &(-fat));
        k.add_block::<3, 3>(f + 3, d, &fat);
        k.add_block::<3, 3>(d + 3, d + 3, &(-(tg.jac_t(&mb) + tg.t.transpose() * skew(&mb) * tg.t)));
        k.add_block::<3, 3>(d + 3, f + 3, &(-(tg.t.transpose() * cba * mat)));
    }
}
