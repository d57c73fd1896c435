//! Gravity on a beam element, expressed in the body frame A.
//!
//! With `g_A = C^{AG} g`, the distributed load `m g_A` does the virtual work
//! `∫ m g_A · (δr_A + δR + δθ_A × R) ds`; it depends on the frame orientation through
//! `∂g_A/∂θ_A = g̃_A` (for the update `C^{GA} ← C^{GA} exp(δθ̃_A)`). The potential energy is
//! `V = −∫ m g·(r − r_ref) ds`, zero in the reference configuration.

use crate::body::Body;
use crate::crv::{M3, V3, skew};
use crate::element::{ElementState, Mat24, V_OFF, Vec24, W_OFF, add3, add33, gauss_rule, interp, shape};

/// Subtract the gravity load of one element from `res` and add `c_k ×` its (negative) tangent
/// to `mat`. `g_a` is the gravity vector in A components, m/s².
pub(crate) fn add_gravity(
    st: &ElementState,
    le: f64,
    mass: f64,
    g_a: &V3,
    res: &mut Vec24,
    mat: Option<(&mut Mat24, f64)>,
) {
    let fg = g_a * mass;
    let fgt = skew(&fg);
    // The load is linear in the shape functions: integrate them (and R) once, then add.
    let (mut n_int, mut r_int, mut len) = ([0.0; 3], V3::zeros(), 0.0);
    for &(xi, w) in gauss_rule(3) {
        let (n, _) = shape(xi, le);
        let wt = 0.5 * le * w;
        for (a, nk) in n_int.iter_mut().zip(n) {
            *a += wt * nk;
        }
        r_int += interp(&n, &st.r) * wt;
        len += wt;
    }
    for (k, nk) in n_int.iter().enumerate() {
        add3(res, 6 * k, &(-fg * *nk));
    }
    add3(res, V_OFF, &(-fg * len));
    add3(res, W_OFF, &(-r_int.cross(&fg)));
    if let Some((m, c_k)) = mat {
        let a: M3 = -fgt * c_k;
        for (k, nk) in n_int.iter().enumerate() {
            add33(m, 6 * k, W_OFF, &(a * *nk));
            add33(m, W_OFF, 6 * k, &(fgt * (c_k * nk)));
        }
        add33(m, V_OFF, W_OFF, &(a * len));
        add33(m, W_OFF, W_OFF, &(skew(&r_int) * a));
    }
}

/// Gravitational potential of element `e` of `body`, J: `−∫ m g·(r − r_ref) ds` with
/// `r = r_A + C^{GA} R` and `(r_A, C^{GA})` the frame's current position and orientation.
pub(crate) fn potential(st: &ElementState, body: &Body, e: usize, g: &V3, r_a: &V3, c_ga: &M3) -> f64 {
    let ref_r = [body.node_ref(2 * e), body.node_ref(2 * e + 1), body.node_ref(2 * e + 2)];
    let mut v = 0.0;
    for &(xi, w) in gauss_rule(3) {
        let (n, _) = shape(xi, body.le);
        let wt = 0.5 * body.le * w;
        let r = r_a + c_ga * interp(&n, &st.r);
        let r0 = body.start + body.frame * interp(&n, &ref_r);
        v -= wt * body.section.mass * g.dot(&(r - r0));
    }
    v
}
