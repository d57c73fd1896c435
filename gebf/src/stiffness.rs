//! Elastic forces of the geometrically exact beam and their analytic tangent.
//!
//! Strains at a Gauss point (reference straight along the A-frame x axis, `psi_0 = 0`):
//!
//! $$ \gamma = C^{BA}(\psi)\,R' - e_x,\qquad \kappa = T(\psi)\,\psi' - \kappa_0 ,$$
//!
//! with `κ₀ = 0` for an untwisted body. A twisted body's reference has `psi_0(s) = φ(s) e_x`
//! (`φ = θ − θ(0)`, the twist relative to the start section, which the frame A follows) and
//! `κ₀ = T(psi_0) psi_0' = φ' e_x`, evaluated from the nodal twists exactly as `κ` is from the
//! nodal CRVs, so the reference is free of stress to rounding (docs/gebf.md §4).
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
use crate::crv::{M3, Tangent, V3, diag_mul, skew_mul};
use crate::element::{ElementState, Mat24, Vec24, add3, add33, gauss_rule, interp, shape};
use crate::section::SectionDiagonals;

/// Add the elastic forces of one element to `res` (and `c_k ×` their tangent to `mat`);
/// returns the element's elastic energy, J.
/// `twist` holds the element's nodal reference twists φ (rad, relative to the body frame A),
/// `None` for an untwisted body.
pub(crate) fn add_elastic(
    st: &ElementState,
    le: f64,
    sec: &Section,
    n_gauss: usize,
    twist: Option<&[f64; 3]>,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, f64)>,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { add_elastic_avx2(st, le, sec, n_gauss, twist, res, mat) };
    }
    add_elastic_generic(st, le, sec, n_gauss, twist, res, mat)
}

/// The reference curvature `κ₀ = T(psi_0) psi_0'` at shape values `n`, `dn` of the nodal
/// reference twists `phi` (`psi_0 = φ e_x`).
#[inline]
fn reference_curvature(phi: &[f64; 3], n: &[f64; 3], dn: &[f64; 3]) -> V3 {
    let at = |w: &[f64; 3]| V3::new(w[0] * phi[0] + w[1] * phi[1] + w[2] * phi[2], 0.0, 0.0);
    Tangent::new(&at(n)).t * at(dn)
}

/// The same code compiled with AVX2 (wider vectors, no FMA: the same arithmetic, so the same
/// results bit for bit).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn add_elastic_avx2(
    st: &ElementState,
    le: f64,
    sec: &Section,
    n_gauss: usize,
    twist: Option<&[f64; 3]>,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, f64)>,
) -> f64 {
    add_elastic_generic(st, le, sec, n_gauss, twist, res, mat)
}

#[inline(always)]
fn add_elastic_generic(
    st: &ElementState,
    le: f64,
    sec: &Section,
    n_gauss: usize,
    twist: Option<&[f64; 3]>,
    res: &mut Vec24,
    mut mat: Option<(&mut Mat24, f64)>,
) -> f64 {
    let sg = sec.force_stiffness();
    let sk = sec.moment_stiffness();
    let ex = V3::x();
    let mut energy = 0.0;
    // The tangent is the Hessian of U in the nodal unknowns, so symmetric: only the node pairs
    // k ≤ l are accumulated, as (R_k, R_l), (R_k, psi_l), (psi_k, R_l), (psi_k, psi_l) blocks,
    // and mirrored after the loop.
    // (Only when the matrix is wanted: the residual path does not clear the 2.6 kB.)
    let mut kb = mat.as_ref().map(|_| [[[M3::zeros(); 4]; 3]; 3]);
    for &(xi, w) in gauss_rule(n_gauss) {
        let (n, dn) = shape(xi, le);
        let wt = 0.5 * le * w;
        let r_p = interp(&dn, &st.r);
        let psi = interp(&n, &st.psi);
        let psi_p = interp(&dn, &st.psi);
        let tg = if mat.is_some() { Tangent::with_second_order(&psi) } else { Tangent::new(&psi) };
        let t = tg.t;
        let cab = tg.rotation(); // C^{AB}
        let e = cab.tr_mul(&r_p);
        let gamma = e - ex;
        let kappa = match twist {
            None => t * psi_p,
            Some(phi) => t * psi_p - reference_curvature(phi, &n, &dn),
        };
        let nf = sg.component_mul(&gamma);
        let mo = sk.component_mul(&kappa);
        energy += 0.5 * wt * (gamma.dot(&nf) + kappa.dot(&mo));

        let nxe = nf.cross(&e);
        let f_r = cab * nf; // × dn_k
        let f_psi_n = t.tr_mul(&nxe) + tg.jac_tr_vec(&psi_p, &mo); // × n_k
        let f_psi_dn = t.tr_mul(&mo); // × dn_k
        for k in 0..3 {
            add3(res, 6 * k, &(f_r * (wt * dn[k])));
            add3(res, 6 * k + 3, &((f_psi_n * n[k] + f_psi_dn * dn[k]) * wt));
        }

        if let (Some((_, c_k)), Some(kb)) = (mat.as_ref(), kb.as_mut()) {
            let f = wt * *c_k;
            let d = tg.jac(&psi_p); // ∂κ/∂psi
            let et = skew_mul(&e, &t); // ∂γ/∂psi
            // S_γ ∂γ/∂psi − Ñ T: with it, the (R, psi) block is C^{AB} y (material + geometric)
            // and yᵀ ẽT = (ẽT)ᵀ S_γ ẽT + Tᵀ Ñ ẽ T.
            let y = diag_mul(&sg, &et) - skew_mul(&nf, &t);
            let sk_d = diag_mul(&sk, &d);
            let a1 = cab * diag_mul(&sg, &cab.transpose()); // (R_k, R_l) × dn_k dn_l
            let rp = cab * y; // (R_k, psi_l) × dn_k n_l
            let p = t.tr_mul(&diag_mul(&sk, &t)); // (psi_k, psi_l) × dn_k dn_l
            let z = t.tr_mul(&sk_d) + tg.jac_t(&mo); // (psi_k, psi_l) × dn_k n_l
            // (psi_k, psi_l) × n_k n_l
            let x = y.tr_mul(&et) + d.tr_mul(&sk_d) + tg.jac_t(&nxe) + tg.hessian(&psi_p, &mo);
            let (rpt, zt) = (rp.transpose(), z.transpose());
            // Column factors of node l, then each block is a combination over n_k, dn_k.
            // (Filled in a loop of this function: `std::array::from_fn` or a closure here is an
            // out-of-line call, compiled without AVX2.)
            let mut cols = [[M3::zeros(); 5]; 3];
            for (l, c) in cols.iter_mut().enumerate() {
                let (nl, dl) = (f * n[l], f * dn[l]);
                *c = [a1 * dl, rp * nl, rpt * dl, x * nl + zt * dl, z * nl + p * dl];
            }
            for k in 0..3 {
                let (nk, dk) = (n[k], dn[k]);
                for (l, c) in cols.iter().enumerate().skip(k) {
                    let b = &mut kb[k][l];
                    b[0] += c[0] * dk;
                    b[1] += c[1] * dk;
                    b[2] += c[2] * nk;
                    b[3] += c[3] * nk + c[4] * dk;
                }
            }
        }
    }
    if let (Some((m, _)), Some(kb)) = (mat.as_mut(), kb.as_ref()) {
        for k in 0..3 {
            for l in k..3 {
                let b = &kb[k][l];
                add33(m, 6 * k, 6 * l, &b[0]);
                add33(m, 6 * k, 6 * l + 3, &b[1]);
                add33(m, 6 * k + 3, 6 * l, &b[2]);
                add33(m, 6 * k + 3, 6 * l + 3, &b[3]);
                if l > k {
                    add33(m, 6 * l, 6 * k, &b[0].transpose());
                    add33(m, 6 * l, 6 * k + 3, &b[2].transpose());
                    add33(m, 6 * l + 3, 6 * k, &b[1].transpose());
                    add33(m, 6 * l + 3, 6 * k + 3, &b[3].transpose());
                }
            }
        }
    }
    energy
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::crv::{from_rotation_matrix, rotation_matrix};
    use crate::element::ElementState;

    fn section() -> Section {
        Section {
            mass: 1.0,
            rho_ixx: 1.0,
            rho_iyy: 1.0,
            rho_izz: 1.0,
            ea: 2.8e5,
            ga_y: 1.0e5,
            ga_z: 1.2e5,
            gj: 7.0,
            ei_yy: 9.0,
            ei_zz: 11.0,
            cg_offset: [0.0; 2],
        }
    }

    /// An element in its reference shape, moved rigidly: every node translated by `c` and
    /// rotated by `Q` (positions and section frames).
    fn rigidly_moved(le: f64, c: V3, q: &M3) -> ElementState {
        let mut s = ElementState::default();
        let psi = from_rotation_matrix(q);
        for k in 0..3 {
            s.r[k] = c + q * V3::new(0.5 * le * k as f64, 0.0, 0.0);
            s.psi[k] = psi;
        }
        s
    }

    /// Objectivity: a rigid motion produces zero strain, so zero elastic energy and force
    /// (relative to EA·L_e and EA respectively).
    #[test]
    fn rigid_motion_gives_zero_elastic_force_and_energy() {
        let le = 0.3;
        let sec = section();
        for (c, rot) in [
            (V3::new(0.1, -2.0, 0.5), V3::new(0.3, -0.4, 1.1)),
            (V3::new(5.0, 1.0, -1.0), V3::new(0.0, 0.0, 3.0)),
            (V3::zeros(), V3::new(-1.2, 2.0, 0.4)),
        ] {
            let q = rotation_matrix(&rot);
            let st = rigidly_moved(le, c, &q);
            let mut res = Vec24::zeros();
            let u = add_elastic(&st, le, &sec, 2, None, &mut res, None);
            assert!(u.abs() < 1e-9 * sec.ea * le, "energy {u}");
            assert!(res.amax() < 1e-9 * sec.ea, "force {}", res.amax());
            // Full integration as well.
            let mut res = Vec24::zeros();
            let u = add_elastic(&st, le, &sec, 3, None, &mut res, None);
            assert!(u.abs() < 1e-9 * sec.ea * le && res.amax() < 1e-9 * sec.ea);
        }
    }

    /// CRV interpolation is not objective for a *deformed* element (Crisfield & Jelenić 1999):
    /// superposing a rigid rotation changes the energy slightly. Pin the size of the effect for
    /// a moderately bent element (a known weakness, docs/gebf.md §11).
    #[test]
    fn superposed_rotation_on_a_bent_element_changes_energy_only_slightly() {
        let le = 0.3;
        let sec = section();
        let mut st = ElementState::default();
        let kappa = 0.8; // rad/m, bending about z
        for k in 0..3 {
            let s = 0.5 * le * k as f64;
            st.r[k] = V3::new((kappa * s).sin() / kappa, (1.0 - (kappa * s).cos()) / kappa, 0.0);
            st.psi[k] = V3::new(0.0, 0.0, kappa * s);
        }
        let mut res = Vec24::zeros();
        let u0 = add_elastic(&st, le, &sec, 2, None, &mut res, None);
        let q = rotation_matrix(&V3::new(0.7, -0.5, 0.9));
        let mut moved = st;
        for k in 0..3 {
            moved.r[k] = q * st.r[k];
            moved.psi[k] = from_rotation_matrix(&(q * rotation_matrix(&st.psi[k])));
        }
        let u1 = add_elastic(&moved, le, &sec, 2, None, &mut res, None);
        let rel = (u1 - u0).abs() / u0;
        println!("bent element: energy {u0:.6e}, after a rigid rotation {u1:.6e} (rel change {rel:.2e})");
        assert!(rel < 1e-5, "{rel}");
    }
}
