//! Thrust, a follower force (docs/gebf.md §16): `F = T(t) C^{GB}(s) d_B` at the axis point at
//! arclength `s` of a body, `d_B` the case's direction in the section.
//!
//! The force is shared among the three nodes of the element holding `s` with the quadratic
//! Lagrange weights `w_k` of `s` (the consistent nodal load of a point force, as
//! `apply_section_loads` distributes the aerodynamic loads), each share turning with its own
//! node's section: `F_k = w_k T C^{GA} C(ψ_k) d_k` with `d_k = (C^{GB}_{0,k})ᵀ R_ref(s) d`, so
//! that `Σ F_k = T R_ref(s) d` in the reference configuration. At a node (the common case)
//! the whole force sits on that node and follows its section exactly.
//!
//! In the body frame A a share is `F_A = w T C(ψ) d`: it does not depend on the frame's
//! orientation. Its virtual work `F_A·(δr_A + δR + δθ_A × R)` gives the generalised forces
//! `R: F_A`, `v_A: F_A`, `ω_A: R × F_A`, and with `δC = C (T(ψ) δψ)~`,
//! `∂F_A/∂ψ = −w T C d̃ T(ψ)`; the residual's tangent (`r −= Q`) is
//!
//! * rows `R` and `v_A`, columns `ψ`: `w T C d̃ T(ψ)`;
//! * rows `ω_A`, columns `R`: `F̃_A`; columns `ψ`: `R̃ w T C d̃ T(ψ)`.
//!
//! It is unsymmetric. The power is `F_A · (v_A + Ṙ + ω_A × R)`. At node 0 (clamped to A) only
//! the frame rows remain, with constant `F_A`.

use crate::body::Body;
use crate::crv::{Tangent, V3, skew};
use genalpha::MatView;
use nalgebra::Vector3;
use scene::Schedule;

/// A thrust on one body.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Thrust {
    /// The body.
    pub body: usize,
    /// `(node, w_k, d_k)` of each share.
    shares: [(usize, f64, V3); 3],
    /// T(t), N.
    magnitude: Schedule,
}

impl Thrust {
    /// The thrust at arclength `at` of `b` (body index `body`) with the unit direction
    /// `direction` in its reference section frame at `at` (`frame_at`, global columns).
    pub(crate) fn new(
        body: usize,
        b: &Body,
        at: f64,
        frame_at: &nalgebra::Matrix3<f64>,
        direction: &Vector3<f64>,
        magnitude: Schedule,
    ) -> Self {
        let e = ((at / b.le).floor().max(0.0) as usize).min(b.n_elements - 1);
        let target = frame_at * direction;
        let shares = std::array::from_fn(|k| {
            let node = 2 * e + k;
            let s = |j: usize| b.node_ref(2 * e + j).x;
            let (o1, o2) = ((k + 1) % 3, (k + 2) % 3);
            let w = (at - s(o1)) * (at - s(o2)) / ((s(k) - s(o1)) * (s(k) - s(o2)));
            (node, w, b.section_frame0(node).transpose() * target)
        });
        Self { body, shares, magnitude }
    }

    /// T(t), N.
    pub(crate) fn magnitude(&self, t: f64) -> f64 {
        self.magnitude.at(t)
    }

    /// `r −= Q` for magnitude `p`.
    pub(crate) fn add_residual(&self, b: &Body, p: f64, q: &[f64], r: &mut [f64]) {
        let f = b.frame_dof();
        for &(i, w, d) in &self.shares {
            let (ri, psi) = b.node_state(q, i);
            let fa = crate::crv::rotation_matrix(&psi) * d * (w * p);
            let mut sub = |k: usize, x: &V3| {
                r[k] -= x.x;
                r[k + 1] -= x.y;
                r[k + 2] -= x.z;
            };
            sub(f, &fa);
            sub(f + 3, &ri.cross(&fa));
            if let Some(nd) = b.node_dof(i) {
                sub(nd, &fa);
            }
        }
    }

    /// `k += c_k ∂(−Q)/∂q` for magnitude `p`.
    pub(crate) fn add_tangent(&self, b: &Body, p: f64, q: &[f64], c_k: f64, k: &mut MatView<'_>) {
        if p == 0.0 || c_k == 0.0 {
            return;
        }
        let f = b.frame_dof();
        let mut k = k.scaled(c_k);
        for &(i, w, d) in &self.shares {
            let Some(nd) = b.node_dof(i) else { continue };
            let (ri, psi) = b.node_state(q, i);
            let tg = Tangent::new(&psi);
            let c = tg.rotation();
            let fa = c * d * (w * p);
            let dpsi = c * skew(&d) * tg.t * (w * p);
            k.add_block::<3, 3>(nd, nd + 3, &dpsi);
            k.add_block::<3, 3>(f, nd + 3, &dpsi);
            k.add_block::<3, 3>(f + 3, nd, &skew(&fa));
            k.add_block::<3, 3>(f + 3, nd + 3, &(skew(&ri) * dpsi));
        }
    }

    /// The power `Σ F_A · (v_A + Ṙ + ω_A × R)` for magnitude `p`, W.
    pub(crate) fn power(&self, b: &Body, p: f64, q: &[f64], v: &[f64]) -> f64 {
        let (va, wa) = b.frame_rates(v);
        self.shares
            .iter()
            .map(|&(i, w, d)| {
                let (ri, psi) = b.node_state(q, i);
                let (rd, _) = b.node_rates(v, i);
                let fa = crate::crv::rotation_matrix(&psi) * d * (w * p);
                fa.dot(&(va + rd + wa.cross(&ri)))
            })
            .sum()
    }
}
