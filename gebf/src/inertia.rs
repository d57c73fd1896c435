//! Inertial forces of a beam element in its moving frame A, with the configuration-dependent
//! mass matrix, the gyroscopic matrix and the inertial stiffness.
//!
//! At a point of the beam axis, with `W = v_A + R_dot + omega_A × R` (velocity in A) and the
//! section angular velocity in B `Omega = T(psi) psi_dot + C^{BA} omega_A`, the kinetic energy is
//! `½ ∫ (m |W|² + Omegaᵀ J Omega) ds`. The inertial forces follow from d'Alembert's principle:
//!
//! * linear: `f = m (v_A_dot + R_ddot + omega_A_dot × R + 2 omega_A × R_dot + omega_A × (v_A + omega_A × R))`
//!   (the acceleration of the point in A components), virtual displacement
//!   `δr = δr_A + δR + δθ_A × R` → rows `R_k: N_k f`, `v_A: f`, `omega_A: R × f`;
//! * angular: `h = J Omega_dot + Omega × J Omega` with
//!   `Omega_dot = T psi_ddot + dT[psi_dot] psi_dot + (C^{BA} omega_A) × (T psi_dot) + C^{BA} omega_A_dot`,
//!   virtual rotation `δθ_B = T δpsi + C^{BA} δθ_A` → rows `psi_k: N_k Tᵀ h`, `omega_A: C^{AB} h`.
//!
//! Nothing here depends on the frame's position or orientation (gravity is in `gravity.rs`).
//! Integrated with 3 Gauss points (exact for the translational mass of the quadratic element).

use crate::Section;
use crate::crv::{M3, Tangent, col_mul, diag_mul, skew};
use crate::element::{ElementState, Mat24, V_OFF, Vec24, W_OFF, add3, add33, gauss_rule, interp, shape};

/// Coefficients of the iteration matrix: `c_m ∂/∂v_dot + c_c ∂/∂v + c_k ∂/∂q`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MatrixCoefficients {
    pub c_m: f64,
    pub c_c: f64,
    pub c_k: f64,
}

/// Add the inertial forces of one element to `res` (and their weighted tangent to `mat`);
/// returns the kinetic energy of the element, J.
pub(crate) fn add_inertia(
    st: &ElementState,
    le: f64,
    sec: &Section,
    res: &mut Vec24,
    mut mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    let m = sec.mass;
    let jd = sec.inertia();
    let i3 = M3::identity();
    let mut kinetic = 0.0;
    let (v, w, vd, wd) = (st.v, st.w, st.vd, st.wd);
    let wt3 = skew(&w);
    // The translational blocks of the rows and columns of R and v_A do not depend on the
    // point: `l_r`, `l_v` times the consistent-mass integrals `∫ N_k N_l`, `∫ N_k`, `∫ 1`,
    // added once after the loop.
    let (mut n_kl, mut n_k, mut n_1) = ([[0.0; 3]; 3], [0.0; 3], 0.0);
    let (l_r, l_v) = mat.as_ref().map_or((M3::zeros(), M3::zeros()), |(_, c)| {
        let l_r = i3 * (c.c_m * m) + wt3 * (2.0 * m * c.c_c) + (skew(&wd) + wt3 * wt3) * (m * c.c_k);
        (l_r, i3 * (c.c_m * m) + wt3 * (m * c.c_c))
    });
    for &(xi, wgt) in gauss_rule(3) {
        let (n, _) = shape(xi, le);
        let wt = 0.5 * le * wgt;
        let r = interp(&n, &st.r);
        let rd = interp(&n, &st.rd);
        let rdd = interp(&n, &st.rdd);
        let psi = interp(&n, &st.psi);
        let psid = interp(&n, &st.psid);
        let psidd = interp(&n, &st.psidd);

        // Translation.
        let w0 = v + w.cross(&r);
        let vel = w0 + rd;
        let f = (vd + rdd + wd.cross(&r) + w.cross(&rd) * 2.0 + w.cross(&w0)) * m;
        let rf = r.cross(&f);
        // Rotation.
        let tg = Tangent::new(&psi);
        let t = tg.t;
        let cba = tg.rotation().transpose();
        let om_r = t * psid;
        let cw = cba * w;
        let om = om_r + cw;
        let jom = jd.component_mul(&om);
        let om_d = t * psidd + tg.dir_vec(&psid, &psid) + cw.cross(&om_r) + cba * wd;
        let h = jd.component_mul(&om_d) + om.cross(&jom);
        kinetic += 0.5 * wt * (m * vel.norm_squared() + om.dot(&jom));

        let tth = t.transpose() * h;
        for k in 0..3 {
            add3(res, 6 * k, &(f * (wt * n[k])));
            add3(res, 6 * k + 3, &(tth * (wt * n[k])));
        }
        add3(res, V_OFF, &(f * wt));
        add3(res, W_OFF, &((rf + cba.transpose() * h) * wt));

        if let Some((mm, c)) = mat.as_mut() {
            let c = *c;
            let rt = skew(&r);
            // Linear part: columns (per node: × n_l).
            let l_w = rt * (-m * c.c_m) + (skew(&rd) * 2.0 + skew(&w0) + wt3 * rt) * (-m * c.c_c);
            // Angular part; J is diagonal, so J·X scales the rows of X and X·J its columns.
            let x = col_mul(&skew(&om), &jd) - skew(&jom);
            let cwt = skew(&cw);
            let cwt_t = cwt * t;
            let omr_t = skew(&om_r);
            let d_psid = tg.jac(&psid);
            let dom_dpsi = d_psid + cwt_t;
            let domd_dpsi =
                tg.jac(&psidd) + tg.second(&psid, &psid) + cwt * d_psid - omr_t * cwt_t + skew(&(cba * wd)) * t;
            let domd_dpsid = tg.dir(&psid) + d_psid + cwt_t;
            let h_psi = diag_mul(&jd, &(t * c.c_m + domd_dpsid * c.c_c + domd_dpsi * c.c_k))
                + x * (t * c.c_c + dom_dpsi * c.c_k);
            let h_w = diag_mul(&jd, &((cba * c.c_m) - omr_t * cba * c.c_c)) + x * cba * c.c_c;
            let tt = t.transpose();
            let ct = cba.transpose();
            let geo_psi_row = tg.jac_t(&h) * c.c_k; // ∂(Tᵀh)/∂psi at fixed h
            let geo_w_row = -(ct * skew(&h) * t) * c.c_k; // ∂(C^{AB} h)/∂psi at fixed h
            let geo_rf = -skew(&f) * c.c_k; // ∂(R × f)/∂R at fixed f

            let a_pp = tt * h_psi + geo_psi_row;
            let a_wp = ct * h_psi + geo_w_row;
            let a_pw = tt * h_w;
            let a_wr = rt * l_r + geo_rf;
            for k in 0..3 {
                let nk = n[k] * wt;
                n_k[k] += nk;
                for l in 0..3 {
                    let nkl = nk * n[l];
                    n_kl[k][l] += nkl;
                    add33(mm, 6 * k + 3, 6 * l + 3, &(a_pp * nkl));
                }
                add33(mm, 6 * k, W_OFF, &(l_w * nk));
                add33(mm, 6 * k + 3, W_OFF, &(a_pw * nk));
                // Frame rows, node columns.
                add33(mm, W_OFF, 6 * k, &(a_wr * nk));
                add33(mm, W_OFF, 6 * k + 3, &(a_wp * nk));
            }
            n_1 += wt;
            add33(mm, V_OFF, W_OFF, &(l_w * wt));
            add33(mm, W_OFF, V_OFF, &(rt * l_v * wt));
            add33(mm, W_OFF, W_OFF, &((rt * l_w + ct * h_w) * wt));
        }
    }
    if let Some((mm, _)) = mat.as_mut() {
        for k in 0..3 {
            for l in 0..3 {
                add33(mm, 6 * k, 6 * l, &(l_r * n_kl[k][l]));
            }
            add33(mm, 6 * k, V_OFF, &(l_v * n_k[k]));
            add33(mm, V_OFF, 6 * k, &(l_r * n_k[k]));
        }
        add33(mm, V_OFF, V_OFF, &(l_v * n_1));
    }
    kinetic
}
