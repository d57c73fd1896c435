//! Elastic forces of the geometrically exact beam and their analytic tangent.
//!
//! Strains at a Gauss point (reference straight along the A-frame x axis, `psi_0 = 0`):
//!
//! $$ \gamma = C^{BA}(\psi)\,R' - e_x,\qquad \kappa = T(\psi)\,\psi' ,$$
//!
//! energy `U = ½ ∫ (γᵀ diag(EA, GA_y, GA_z) γ + κᵀ diag(GJ, EI_yy, EI_zz) κ) ds`, integrated
//! with `n_gauss` points (2 = reduced integration, as SHARPy/xbeam do, which avoids shear
//! locking of the quadratic element). With `N = S_γ γ`, `M = S_κ κ`, `e = C^{BA} R'` and
//! `D = ∂(T psi')/∂psi`, the virtual work is
//!
//! $$ \delta U = \int \big[ (C^{AB} N)\cdot\delta R' + (T^T (N\times e) + D^T M)\cdot\delta\psi
//!     + (T^T M)\cdot\delta\psi' \big]\,ds .$$
//!
//! The tangent is the material part `BᵀSB` plus the geometric part from differentiating
//! `C^{AB}`, `T`, `D` at fixed `N`, `M` (which needs the Hessian of `Mᵀ T(psi) psi'`).

use crate::Section;
use crate::crv::{M3, Tangent, V3, skew};
use crate::element::{ElementState, Mat24, Vec24, add3, add33, gauss_rule, interp, shape};

/// Add the elastic forces of one element to `res` (and `c_k ×` their tangent to `mat`);
/// returns the element's elastic energy, J.
pub(crate) fn add_elastic(
    st: &ElementState,
    le: f64,
    sec: &Section,
    n_gauss: usize,
    res: &mut Vec24,
    mut mat: Option<(&mut Mat24, f64)>,
) -> f64 {
    let sg = sec.force_stiffness();
    let sk = sec.moment_stiffness();
    let sg_m = M3::from_diagonal(&sg);
    let sk_m = M3::from_diagonal(&sk);
    let ex = V3::x();
    let mut energy = 0.0;
    for &(xi, w) in gauss_rule(n_gauss) {
        let (n, dn) = shape(xi, le);
        let wt = 0.5 * le * w;
        let r_p = interp(&dn, &st.r);
        let psi = interp(&n, &st.psi);
        let psi_p = interp(&dn, &st.psi);
        let tg = Tangent::new(&psi);
        let t = tg.t;
        let c = tg.rotation().transpose(); // C^{BA}
        let e = c * r_p;
        let gamma = e - ex;
        let kappa = t * psi_p;
        let nf = sg.component_mul(&gamma);
        let mo = sk.component_mul(&kappa);
        energy += 0.5 * wt * (gamma.dot(&nf) + kappa.dot(&mo));

        let d = tg.jac(&psi_p);
        let f_r = c.transpose() * nf; // × dn_k
        let f_psi_n = t.transpose() * nf.cross(&e) + d.transpose() * mo; // × n_k
        let f_psi_dn = t.transpose() * mo; // × dn_k
        for k in 0..3 {
            add3(res, 6 * k, &(f_r * (wt * dn[k])));
            add3(res, 6 * k + 3, &((f_psi_n * n[k] + f_psi_dn * dn[k]) * wt));
        }

        if let Some((m, c_k)) = mat.as_mut() {
            let f = wt * *c_k;
            let et = skew(&e) * t; // ∂γ/∂psi
            let nt = skew(&nf);
            // Material blocks.
            let a1 = c.transpose() * sg_m * c;
            let a2 = c.transpose() * sg_m * et;
            let a3 = et.transpose() * sg_m * et;
            let p = t.transpose() * sk_m * t;
            let qm = t.transpose() * sk_m * d;
            let rm = d.transpose() * sk_m * d;
            // Geometric blocks.
            let g1 = -(c.transpose() * nt * t); // (R_k, psi_l) × dn_k n_l
            let g2 = tg.jac_t(&nf.cross(&e)) + t.transpose() * nt * skew(&e) * t + tg.hessian(&psi_p, &mo);
            let g3 = tg.jac_t(&mo); // (psi_k, psi_l) × dn_k n_l
            let rp_blk = a2 + g1; // (R_k, psi_l) × dn_k n_l
            for k in 0..3 {
                for l in 0..3 {
                    let (nk, nl, dk, dl) = (n[k], n[l], dn[k], dn[l]);
                    add33(m, 6 * k, 6 * l, &(a1 * (f * dk * dl)));
                    add33(m, 6 * k, 6 * l + 3, &(rp_blk * (f * dk * nl)));
                    add33(m, 6 * k + 3, 6 * l, &(rp_blk.transpose() * (f * nk * dl)));
                    let pp = (a3 + rm + g2) * (nk * nl)
                        + p * (dk * dl)
                        + (qm + g3).transpose() * (nk * dl)
                        + (qm + g3) * (dk * nl);
                    add33(m, 6 * k + 3, 6 * l + 3, &(pp * f));
                }
            }
        }
    }
    energy
}
