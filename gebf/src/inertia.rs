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
use crate::crv::{M3, Tangent, V3, col_mul, diag_mul, skew, skew_mul};
use crate::element::{ElementState, Mat24, V_OFF, Vec24, W_OFF, add3, add33, gauss_rule, interp, shape};
use crate::section::SectionDiagonals;

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
    mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { add_inertia_avx2(st, le, sec, res, mat) };
    }
    add_inertia_generic(st, le, sec, res, mat)
}

/// The same code compiled with AVX2 (wider vectors, no FMA: the same arithmetic, so the same
/// results bit for bit).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn add_inertia_avx2(
    st: &ElementState,
    le: f64,
    sec: &Section,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    add_inertia_generic(st, le, sec, res, mat)
}

#[inline(always)]
fn add_inertia_generic(
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
    // added once after the loop; so are the lever arms `R × (l_r δR)`, `R × (l_v δv_A)` of the
    // omega_A rows, through `∫ N_k R` and `∫ R`.
    let (mut n_kl, mut n_k, mut n_1) = ([[0.0; 3]; 3], [0.0; 3], 0.0);
    let (mut rn_k, mut r_1) = ([V3::zeros(); 3], V3::zeros());
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
        let tg = if mat.is_some() { Tangent::with_second_order(&psi) } else { Tangent::new(&psi) };
        let t = tg.t;
        let cab = tg.rotation(); // C^{AB}; C^{BA} x = cab.tr_mul(x)
        let om_r = t * psid;
        let cw = cab.tr_mul(&w);
        let cwd = cab.tr_mul(&wd);
        let om = om_r + cw;
        let jom = jd.component_mul(&om);
        let om_d = t * psidd + tg.dir_vec(&psid, &psid) + cw.cross(&om_r) + cwd;
        let h = jd.component_mul(&om_d) + om.cross(&jom);
        kinetic += 0.5 * wt * (m * vel.norm_squared() + om.dot(&jom));

        let tth = t.tr_mul(&h);
        for k in 0..3 {
            // The middle Gauss point lies on the middle node: the end nodes' weights are zero.
            if n[k] != 0.0 {
                add3(res, 6 * k, &(f * (wt * n[k])));
                add3(res, 6 * k + 3, &(tth * (wt * n[k])));
            }
        }
        add3(res, V_OFF, &(f * wt));
        add3(res, W_OFF, &((rf + cab * h) * wt));

        if let Some((mm, c)) = mat.as_mut() {
            let c = *c;
            // Linear part: columns of omega_A (rows × n_k), with w̃ R̃ = R wᵀ − (w·R) I.
            let l_w = skew(&(r * (-m * c.c_m) + (rd * 2.0 + w0) * (-m * c.c_c)))
                + (r * w.transpose() - i3 * w.dot(&r)) * (-m * c.c_c);
            // Angular part; J is diagonal, so J·X scales the rows of X and X·J its columns.
            let x = col_mul(&skew(&om), &jd) - skew(&jom);
            let cwt_t = skew_mul(&cw, &t);
            let d_psid = tg.jac(&psid);
            let dom_dpsi = d_psid + cwt_t;
            let domd_dpsi = tg.acceleration_jac(&psid, &psidd) + skew_mul(&cw, &d_psid) - skew_mul(&om_r, &cwt_t)
                + skew_mul(&cwd, &t);
            let domd_dpsid = tg.dir(&psid) + dom_dpsi;
            let h_psi = diag_mul(&jd, &(t * c.c_m + domd_dpsid * c.c_c + domd_dpsi * c.c_k))
                + x * (t * c.c_c + dom_dpsi * c.c_k);
            // ∂h/∂omega_A = (J c_m + (X − J om_r~) c_c) C^{BA}.
            let h_w = (M3::from_diagonal(&(jd * c.c_m)) + (x - diag_mul(&jd, &skew(&om_r))) * c.c_c) * cab.transpose();
            let geo_psi_row = tg.jac_t(&h) * c.c_k; // ∂(Tᵀh)/∂psi at fixed h
            let geo_rf = -skew(&f) * c.c_k; // ∂(R × f)/∂R at fixed f

            let a_pp = t.tr_mul(&h_psi) + geo_psi_row;
            // ∂(C^{AB} h)/∂psi = C^{AB} (∂h/∂psi − h̃ T) (the second term at fixed h).
            let a_wp = cab * (h_psi - skew_mul(&h, &t) * c.c_k);
            let a_pw = t.tr_mul(&h_w);
            for k in 0..3 {
                let nk = n[k] * wt;
                if nk == 0.0 {
                    continue;
                }
                n_k[k] += nk;
                rn_k[k] += r * nk;
                // The weights of (k, l) and (l, k) are equal: one scaled block for both.
                for l in k..3 {
                    let nkl = nk * n[l];
                    if nkl != 0.0 {
                        let blk = a_pp * nkl;
                        n_kl[k][l] += nkl;
                        add33(mm, 6 * k + 3, 6 * l + 3, &blk);
                        if l != k {
                            n_kl[l][k] += nkl;
                            add33(mm, 6 * l + 3, 6 * k + 3, &blk);
                        }
                    }
                }
                add33(mm, 6 * k, W_OFF, &(l_w * nk));
                add33(mm, 6 * k + 3, W_OFF, &(a_pw * nk));
                // Frame rows, node columns (the lever arm R̃ l_r is added after the loop).
                add33(mm, W_OFF, 6 * k, &(geo_rf * nk));
                add33(mm, W_OFF, 6 * k + 3, &(a_wp * nk));
            }
            n_1 += wt;
            r_1 += r * wt;
            add33(mm, V_OFF, W_OFF, &(l_w * wt));
            add33(mm, W_OFF, W_OFF, &((skew_mul(&r, &l_w) + cab * h_w) * wt));
        }
    }
    if let Some((mm, _)) = mat.as_mut() {
        for k in 0..3 {
            for l in 0..3 {
                if n_kl[k][l] != 0.0 {
                    add33(mm, 6 * k, 6 * l, &(l_r * n_kl[k][l]));
                }
            }
            add33(mm, 6 * k, V_OFF, &(l_v * n_k[k]));
            add33(mm, V_OFF, 6 * k, &(l_r * n_k[k]));
            add33(mm, W_OFF, 6 * k, &skew_mul(&rn_k[k], &l_r));
        }
        add33(mm, V_OFF, V_OFF, &(l_v * n_1));
        add33(mm, W_OFF, V_OFF, &skew_mul(&r_1, &l_v));
    }
    kinetic
}
