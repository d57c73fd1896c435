//! Linear and angular momentum of the model (docs/gebf.md §15).
//!
//! With the kinetic energy of `inertia.rs` and `rigid_slice.rs`, a slice of mass `m` and
//! principal inertias `J` (section axes) whose centre sits at `ρ` (section components) from the
//! axis point `R` moves with `W_c = v_A + ω_A × R + Ṙ + C (Ω × ρ)` (A components, `C = C^{AB}`,
//! `Ω = T ψ̇ + C^{BA} ω_A`), so its momenta in A about A's origin are
//!
//! * `p_A = m W_c = ∂T/∂v_A`,
//! * `L_A = (R + C ρ) × m W_c + C J Ω = ∂T/∂ω_A`,
//!
//! summed with the same quadrature as the kinetic energy (3 Gauss points of the axis kernel or
//! of the offset section's slices, and the point masses). In global components and about the
//! global origin, `p = C^{GA} p_A` and `L = r_A × p + C^{GA} L_A`.

use formulation::Momentum;

use crate::Model;
use crate::body::Body;
use crate::crv::{Tangent, V3};
use crate::element::{ElementState, gauss_rule, interp, shape};
use crate::rigid_slice::Slice;

impl Model {
    /// Linear momentum and angular momentum about the global origin at `q`, `v` (global
    /// components): `∂T/∂v_A` and `∂T/∂ω_A` of every body's frame, turned to the ground frame.
    pub fn momentum(&self, q: &[f64], v: &[f64]) -> Momentum {
        let mut out = Momentum::default();
        for b in &self.bodies {
            let (p_a, l_a) = body_momentum(b, q, v);
            let (r_a, chi) = b.frame_state(q);
            let c_ga = chi.to_rotation_matrix();
            let p = c_ga * p_a;
            out.linear += p;
            out.angular += r_a.cross(&p) + c_ga * l_a;
        }
        out
    }
}

/// `(p_A, L_A)` of one body in its frame A, about A's origin.
fn body_momentum(b: &Body, q: &[f64], v: &[f64]) -> (V3, V3) {
    let (mut p, mut l) = (V3::zeros(), V3::zeros());
    let axis = Slice {
        xi: 0.0,
        mass: b.section.mass,
        inertia: V3::new(b.section.rho_ixx, b.section.rho_iyy, b.section.rho_izz),
        offset: b.cg,
    };
    let mut st = ElementState::default();
    for e in 0..b.n_elements {
        st.gather_into(b, e, q, Some(v), None);
        for &(xi, w) in gauss_rule(3) {
            slice_momentum(&st, b.le, 0.5 * b.le * w, &Slice { xi, ..axis }, &mut p, &mut l);
        }
        for s in &b.point_masses[e] {
            slice_momentum(&st, b.le, 1.0, s, &mut p, &mut l);
        }
    }
    (p, l)
}

/// Add weight `wt` times the momenta of slice `s` of an element to `p`, `l` (A, about A's origin).
fn slice_momentum(st: &ElementState, le: f64, wt: f64, s: &Slice, p: &mut V3, l: &mut V3) {
    let (n, _) = shape(s.xi, le);
    let r = interp(&n, &st.r);
    let rd = interp(&n, &st.rd);
    let psi = interp(&n, &st.psi);
    let psid = interp(&n, &st.psid);
    let tg = Tangent::new(&psi);
    let cab = tg.rotation();
    let om = tg.t * psid + cab.tr_mul(&st.w);
    let arm = cab * s.offset;
    let mw = (st.v + st.w.cross(&r) + rd + cab * om.cross(&s.offset)) * s.mass;
    *p += mw * wt;
    *l += ((r + arm).cross(&mw) + cab * s.inertia.component_mul(&om)) * wt;
}
