//! Inertia and gravity of a rigid slice whose centre of mass is offset from the beam axis
//! (docs/gebf.md §14): a point mass, or a section whose centre of mass is not on the axis.
//!
//! A slice sits at a point of the axis (position `R`, section frame `C = C^{AB}(psi)`, both
//! interpolated at its parametric position ξ exactly as at the element's Gauss points) and has a
//! mass `m`, principal inertias `J` about its own centre along the section axes, and its centre
//! at `ρ` (section components) from the axis point. With the section's angular velocity `Ω` (in
//! B) and the axis point's velocity `W` (in A), its centre moves with `W + C (Ω × ρ)`, so
//!
//! $$ T = \tfrac12 m |W + C(\Omega\times\rho)|^2 + \tfrac12 \Omega^T J \Omega .$$
//!
//! d'Alembert: the centre's acceleration in A components is
//! `a_c = a + C (Ω̇ × ρ + Ω × (Ω × ρ))`, `a` the axis point's (docs/gebf.md §5), and its
//! virtual displacement `δr_A + δR + δθ_A × R + C (δθ_B × ρ)` with `δθ_B = T δpsi + C^{BA} δθ_A`.
//! So with `f = m a_c` and `h = J Ω̇ + Ω × J Ω + ρ × (C^{BA} f)` the rows are those of the axis
//! kernel: `R_k: N_k f`, `psi_k: N_k Tᵀ h`, `v_A: f`, `omega_A: R × f + C h`. Gravity
//! `f_g = m g_A` acts at the centre: `R_k: N_k f_g`, `v_A: f_g`, `omega_A: (R + Cρ) × f_g`,
//! `psi_k: N_k Tᵀ (ρ × C^{BA} f_g)`.
//!
//! The tangents follow by the chain rule through `a`, `Ω`, `Ω̇` (whose derivatives are those of
//! the axis kernel in `inertia.rs`) and through the explicit `C` in `f` and `h`
//! (`∂(C x)/∂psi = −C x̃ T`, `∂(C^{BA} x)/∂psi = (C^{BA} x)~ T`). With `ρ = 0` everything
//! reduces to the axis kernel, which stays the code path of sections without an offset.

use crate::body::Body;
use crate::crv::{M3, Tangent, V3, col_mul, diag_mul, skew, skew_mul};
use crate::element::{ElementState, Mat24, V_OFF, Vec24, W_OFF, add3, add33, gauss_rule, interp, shape};
use crate::gravity::{add_gravity, potential};
use crate::inertia::{MatrixCoefficients, add_inertia};

/// A rigid slice: mass, inertia about its own centre and the centre's offset from the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Slice {
    /// Parametric position in the element, ξ ∈ [−1, 1].
    pub xi: f64,
    /// Mass, kg (per unit length when integrated along the element).
    pub mass: f64,
    /// Principal inertias about the centre along the section axes, kg·m² (per unit length:
    /// kg·m).
    pub inertia: V3,
    /// Centre of mass relative to the axis point, section components, m.
    pub offset: V3,
}

/// Add the inertial forces of a slice (weight `wt`: `½ L_e w_g` at a Gauss point, 1 for a point
/// mass) to `res` and their weighted tangent to `mat`; returns its kinetic energy, J.
pub(crate) fn add_slice_inertia(
    st: &ElementState,
    le: f64,
    wt: f64,
    s: &Slice,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { add_slice_inertia_avx2(st, le, wt, s, res, mat) };
    }
    add_slice_inertia_generic(st, le, wt, s, res, mat)
}

/// The same code compiled with AVX2 (no FMA: the same results bit for bit).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn add_slice_inertia_avx2(
    st: &ElementState,
    le: f64,
    wt: f64,
    s: &Slice,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    add_slice_inertia_generic(st, le, wt, s, res, mat)
}

#[inline(always)]
fn add_slice_inertia_generic(
    st: &ElementState,
    le: f64,
    wt: f64,
    s: &Slice,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    let (m, jd, rho) = (s.mass, s.inertia, s.offset);
    let (n, _) = shape(s.xi, le);
    let r = interp(&n, &st.r);
    let rd = interp(&n, &st.rd);
    let rdd = interp(&n, &st.rdd);
    let psi = interp(&n, &st.psi);
    let psid = interp(&n, &st.psid);
    let psidd = interp(&n, &st.psidd);
    let (v, w, vd, wd) = (st.v, st.w, st.vd, st.wd);

    // The axis point: velocity and acceleration in A.
    let w0 = v + w.cross(&r);
    let vel = w0 + rd;
    let acc = vd + rdd + wd.cross(&r) + w.cross(&rd) * 2.0 + w.cross(&w0);
    // The section: angular velocity and acceleration in B.
    let tg = if mat.is_some() { Tangent::with_second_order(&psi) } else { Tangent::new(&psi) };
    let t = tg.t;
    let cab = tg.rotation();
    let om_r = t * psid;
    let cw = cab.tr_mul(&w);
    let cwd = cab.tr_mul(&wd);
    let om = om_r + cw;
    let om_d = t * psidd + tg.dir_vec(&psid, &psid) + cw.cross(&om_r) + cwd;
    let jom = jd.component_mul(&om);
    // The centre: relative acceleration e (B), force f (A), moment h about the axis point (B).
    let om_rho = om.cross(&rho);
    let e = om_d.cross(&rho) + om.cross(&om_rho);
    let ca = cab.tr_mul(&acc);
    let f = (acc + cab * e) * m;
    let h = jd.component_mul(&om_d) + om.cross(&jom) + rho.cross(&(ca + e)) * m;
    let kinetic = 0.5 * wt * (m * (vel + cab * om_rho).norm_squared() + om.dot(&jom));

    let tth = t.tr_mul(&h);
    for k in 0..3 {
        if n[k] != 0.0 {
            add3(res, 6 * k, &(f * (wt * n[k])));
            add3(res, 6 * k + 3, &(tth * (wt * n[k])));
        }
    }
    add3(res, V_OFF, &(f * wt));
    add3(res, W_OFF, &((r.cross(&f) + cab * h) * wt));

    let Some((mm, c)) = mat else { return kinetic };
    let i3 = M3::identity();
    let cba = cab.transpose();
    let wt3 = skew(&w);
    // ∂a: combined columns of R, v_A, omega_A (c_m ∂/∂acc + c_c ∂/∂vel + c_k ∂/∂pos).
    let a_r = i3 * c.c_m + wt3 * (2.0 * c.c_c) + (skew(&wd) + wt3 * wt3) * c.c_k;
    let a_v = i3 * c.c_m + wt3 * c.c_c;
    let a_w = skew(&(r * (-c.c_m) + (rd * 2.0 + w0) * (-c.c_c))) + (r * w.transpose() - i3 * w.dot(&r)) * (-c.c_c);
    // ∂Ω, ∂Ω̇: columns of psi and omega_A.
    let d_psid = tg.jac(&psid);
    let cwt_t = skew_mul(&cw, &t);
    let dom_dpsi = d_psid + cwt_t;
    let domd_dpsi =
        tg.acceleration_jac(&psid, &psidd) + skew_mul(&cw, &d_psid) - skew_mul(&om_r, &cwt_t) + skew_mul(&cwd, &t);
    let domd_dpsid = tg.dir(&psid) + dom_dpsi;
    let om_psi = t * c.c_c + dom_dpsi * c.c_k;
    let omd_psi = t * c.c_m + domd_dpsid * c.c_c + domd_dpsi * c.c_k;
    let om_w = cba * c.c_c;
    let omd_w = cba * c.c_m - skew(&om_r) * cba * c.c_c;
    // ∂e = −ρ̃ ∂Ω̇ + (−(Ω × ρ)~ − Ω̃ ρ̃) ∂Ω.
    let rho_t = skew(&rho);
    let e_om = -skew(&om_rho) - skew(&om) * rho_t;
    let e_psi = -rho_t * omd_psi + e_om * om_psi;
    let e_w = -rho_t * omd_w + e_om * om_w;
    // ∂f (A) and ∂h (B) per column group.
    let f_r = a_r * m;
    let f_v = a_v * m;
    let f_psi = cab * (e_psi - skew(&e) * t * c.c_k) * m;
    let f_w = (a_w + cab * e_w) * m;
    let x = col_mul(&skew(&om), &jd) - skew(&jom);
    let rm = rho_t * m;
    let h_r = rm * cba * a_r;
    let h_v = rm * cba * a_v;
    let h_psi = diag_mul(&jd, &omd_psi) + x * om_psi + rm * (skew(&ca) * t * c.c_k + e_psi);
    let h_w = diag_mul(&jd, &omd_w) + x * om_w + rm * (cba * a_w + e_w);
    // Rows: R_k: f; psi_k: Tᵀ h (+ ∂Tᵀ/∂psi h); v_A: f; omega_A: R × f + C h (+ the explicit
    // R and C at fixed f, h).
    let rt = skew(&r);
    let psi_row = |hx: &M3| t.tr_mul(hx);
    let pp = psi_row(&h_psi) + tg.jac_t(&h) * c.c_k;
    let w_r = rt * f_r + cab * h_r - skew(&f) * c.c_k;
    let w_psi = rt * f_psi + cab * (h_psi - skew_mul(&h, &t) * c.c_k);
    let w_v = rt * f_v + cab * h_v;
    let w_w = rt * f_w + cab * h_w;
    let (p_r, p_v, p_w) = (psi_row(&h_r), psi_row(&h_v), psi_row(&h_w));
    for k in 0..3 {
        let nk = n[k] * wt;
        if nk == 0.0 {
            continue;
        }
        for l in 0..3 {
            let nkl = nk * n[l];
            if nkl != 0.0 {
                add33(mm, 6 * k, 6 * l, &(f_r * nkl));
                add33(mm, 6 * k, 6 * l + 3, &(f_psi * nkl));
                add33(mm, 6 * k + 3, 6 * l, &(p_r * nkl));
                add33(mm, 6 * k + 3, 6 * l + 3, &(pp * nkl));
            }
        }
        add33(mm, 6 * k, V_OFF, &(f_v * nk));
        add33(mm, 6 * k, W_OFF, &(f_w * nk));
        add33(mm, 6 * k + 3, V_OFF, &(p_v * nk));
        add33(mm, 6 * k + 3, W_OFF, &(p_w * nk));
        add33(mm, V_OFF, 6 * k, &(f_r * nk));
        add33(mm, V_OFF, 6 * k + 3, &(f_psi * nk));
        add33(mm, W_OFF, 6 * k, &(w_r * nk));
        add33(mm, W_OFF, 6 * k + 3, &(w_psi * nk));
    }
    add33(mm, V_OFF, V_OFF, &(f_v * wt));
    add33(mm, V_OFF, W_OFF, &(f_w * wt));
    add33(mm, W_OFF, V_OFF, &(w_v * wt));
    add33(mm, W_OFF, W_OFF, &(w_w * wt));
    kinetic
}

/// Subtract the gravity load of a slice from `res` and add `c_k ×` its (negative) tangent to
/// `mat`. `axis_part`: include the load as if the mass sat on the axis (a point mass); without
/// it only the offset's part (a section whose axis part is in `gravity.rs`).
#[allow(clippy::too_many_arguments)] // the slice, its weight, the load and the two outputs
pub(crate) fn add_slice_gravity(
    st: &ElementState,
    le: f64,
    wt: f64,
    s: &Slice,
    g_a: &V3,
    axis_part: bool,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, f64)>,
) {
    let (n, _) = shape(s.xi, le);
    let r = interp(&n, &st.r);
    let psi = interp(&n, &st.psi);
    let tg = Tangent::new(&psi);
    let (t, cab) = (tg.t, tg.rotation());
    let fg = g_a * (s.mass * wt);
    let fgb = cab.tr_mul(&fg);
    let hg = s.offset.cross(&fgb);
    let arm = cab * s.offset;
    let tth = t.tr_mul(&hg);
    for k in 0..3 {
        if n[k] != 0.0 {
            add3(res, 6 * k + 3, &(-tth * n[k]));
            if axis_part {
                add3(res, 6 * k, &(-fg * n[k]));
            }
        }
    }
    let lever = if axis_part { r + arm } else { arm };
    add3(res, W_OFF, &(-lever.cross(&fg)));
    if axis_part {
        add3(res, V_OFF, &(-fg));
    }
    let Some((mm, c_k)) = mat else { return };
    let fgt = skew(&fg);
    let rho_t = skew(&s.offset);
    // psi_k rows −N_k Tᵀ (ρ × C^{BA} f_g): columns psi_l and θ_A.
    let pp = -(tg.jac_t(&hg) + t.tr_mul(&(rho_t * skew(&fgb) * t))) * c_k;
    let pw = -t.tr_mul(&(rho_t * cba_mul(&cab, &fgt))) * c_k;
    // omega_A row −(lever × f_g): columns psi_l (through C ρ), R_l and θ_A.
    let wp = -(fgt * cab * rho_t * t) * c_k;
    let ww = -(skew(&lever) * fgt) * c_k;
    for k in 0..3 {
        if n[k] == 0.0 {
            continue;
        }
        for l in 0..3 {
            if n[l] != 0.0 {
                add33(mm, 6 * k + 3, 6 * l + 3, &(pp * (n[k] * n[l])));
            }
        }
        add33(mm, 6 * k + 3, W_OFF, &(pw * n[k]));
        add33(mm, W_OFF, 6 * k + 3, &(wp * n[k]));
        if axis_part {
            add33(mm, 6 * k, W_OFF, &(-fgt * (c_k * n[k])));
            add33(mm, W_OFF, 6 * k, &(fgt * (c_k * n[k])));
        }
    }
    add33(mm, W_OFF, W_OFF, &ww);
    if axis_part {
        add33(mm, V_OFF, W_OFF, &(-fgt * c_k));
    }
}

/// `C^{BA} x̃` for a skew matrix `x̃`, as `Cᵀ x̃`.
#[inline]
fn cba_mul(cab: &M3, xt: &M3) -> M3 {
    cab.tr_mul(xt)
}

/// Gravitational potential of a slice, J: `−m g·(r_c − r_c,ref)` with the centre
/// `r_c = r_A + C^{GA} (R + axis·C ρ)`; `axis_part` as in [`add_slice_gravity`] (without it,
/// only the offset's part `−m g·(C^{GA} C ρ − C^{GA}_0 ρ)`).
#[allow(clippy::too_many_arguments)] // the slice, its body and element, the frame pose
pub(crate) fn slice_potential(
    st: &ElementState,
    body: &Body,
    e: usize,
    wt: f64,
    s: &Slice,
    g: &V3,
    axis_part: bool,
    r_a: &V3,
    c_ga: &M3,
) -> f64 {
    let (n, _) = shape(s.xi, body.le);
    let psi = interp(&n, &st.psi);
    let cab = Tangent::new(&psi).rotation();
    let ref_offset = match body.element_twist(e) {
        None => body.frame * s.offset,
        Some(phi) => {
            let psi0 = V3::new(n[0] * phi[0] + n[1] * phi[1] + n[2] * phi[2], 0.0, 0.0);
            body.frame * (Tangent::new(&psi0).rotation() * s.offset)
        }
    };
    let mut dr = c_ga * (cab * s.offset) - ref_offset;
    if axis_part {
        let ref_r = [body.node_ref(2 * e), body.node_ref(2 * e + 1), body.node_ref(2 * e + 2)];
        dr += r_a + c_ga * interp(&n, &st.r) - (body.start + body.frame * interp(&n, &ref_r));
    }
    -wt * s.mass * g.dot(&dr)
}

/// The inertial forces of element `e` of `body` (docs/gebf.md §5, §14): the axis kernel
/// ([`add_inertia`]) when the section's centre of mass is on the axis, otherwise one offset
/// slice per Gauss point (3 points); then the element's point masses. Returns the kinetic
/// energy, J.
pub(crate) fn add_element_inertia(
    st: &ElementState,
    body: &Body,
    e: usize,
    res: &mut Vec24,
    mut mat: Option<(&mut Mat24, MatrixCoefficients)>,
) -> f64 {
    let mut kinetic = if body.cg == V3::zeros() {
        add_inertia(st, body.le, &body.section, res, mat.as_mut().map(|(m, c)| (&mut **m, *c)))
    } else {
        gauss_slices(body)
            .map(|(wt, s)| add_slice_inertia(st, body.le, wt, &s, res, mat.as_mut().map(|(m, c)| (&mut **m, *c))))
            .sum()
    };
    for s in &body.point_masses[e] {
        kinetic += add_slice_inertia(st, body.le, 1.0, s, res, mat.as_mut().map(|(m, c)| (&mut **m, *c)));
    }
    kinetic
}

/// Gravity on element `e` of `body`: the axis part ([`add_gravity`]), the offset of the
/// section's centre of mass at the Gauss points, and the element's point masses.
pub(crate) fn add_element_gravity(
    st: &ElementState,
    body: &Body,
    e: usize,
    g_a: &V3,
    res: &mut Vec24,
    mut mat: Option<(&mut Mat24, f64)>,
) {
    add_gravity(st, body.le, body.section.mass, g_a, res, mat.as_mut().map(|(m, c)| (&mut **m, *c)));
    if body.cg != V3::zeros() {
        for (wt, s) in gauss_slices(body) {
            add_slice_gravity(st, body.le, wt, &s, g_a, false, res, mat.as_mut().map(|(m, c)| (&mut **m, *c)));
        }
    }
    for s in &body.point_masses[e] {
        add_slice_gravity(st, body.le, 1.0, s, g_a, true, res, mat.as_mut().map(|(m, c)| (&mut **m, *c)));
    }
}

/// Gravitational potential of element `e` of `body` with its offsets and point masses, J.
pub(crate) fn element_potential(st: &ElementState, body: &Body, e: usize, g: &V3, r_a: &V3, c_ga: &M3) -> f64 {
    let mut v = potential(st, body, e, g, r_a, c_ga);
    if body.cg != V3::zeros() {
        v += gauss_slices(body).map(|(wt, s)| slice_potential(st, body, e, wt, &s, g, false, r_a, c_ga)).sum::<f64>();
    }
    for s in &body.point_masses[e] {
        v += slice_potential(st, body, e, 1.0, s, g, true, r_a, c_ga);
    }
    v
}

/// The section as slices at the element's 3 inertia Gauss points: (weight `½ L_e w_g`, slice).
fn gauss_slices(body: &Body) -> impl Iterator<Item = (f64, Slice)> + '_ {
    let sec = &body.section;
    gauss_rule(3).iter().map(move |&(xi, w)| {
        let slice =
            Slice { xi, mass: sec.mass, inertia: V3::new(sec.rho_ixx, sec.rho_iyy, sec.rho_izz), offset: body.cg };
        (0.5 * body.le * w, slice)
    })
}
