//! Cartesian rotation vectors (CRV): rotation matrix, tangential operator and its derivatives.
//!
//! A CRV `psi = phi·n` (|n| = 1) describes the rotation by `phi` about `n`:
//!
//! $$ C(\psi) = \exp(\tilde\psi) = I + \frac{\sin\phi}{\phi}\tilde\psi + \frac{1-\cos\phi}{\phi^2}\tilde\psi^2 .$$
//!
//! In the beam, `C(psi) = C^{AB}` maps section (B) components to body-frame (A) components.
//! The tangential operator gives the angular velocity in B, `Omega = T(psi) psi_dot`:
//!
//! $$ T(\psi) = I + \alpha(s)\,\tilde\psi + \beta(s)\,\tilde\psi^2,\quad
//!    \alpha = \frac{\cos\phi - 1}{\phi^2},\quad \beta = \frac{\phi - \sin\phi}{\phi^3},\quad s = \phi^2 .$$
//!
//! The beam tangents need the first and second derivatives of `T(psi) a` with respect to `psi`;
//! they are written in terms of the s-derivatives of `alpha` and `beta`, which are evaluated by
//! their Taylor series for `phi < 1` (no cancellation near `psi = 0`) and in closed form above.
//! `T` is singular at `|psi| = 2πk`, k ≥ 1; [`rescale`] maps a CRV past π back to the
//! equivalent one of norm below π, and [`rescale_rates`] transforms its rate consistently.

use nalgebra::{Matrix3, Vector3};

/// 3-vector of f64.
pub type V3 = Vector3<f64>;
/// 3×3 matrix of f64.
pub type M3 = Matrix3<f64>;

/// The skew-symmetric (cross-product) matrix: `skew(a) b = a × b`.
#[inline]
pub fn skew(a: &V3) -> M3 {
    M3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// `diag(d) · a`: scales row i of `a` by `d_i` (a diagonal stiffness or inertia times a matrix,
/// without the full product).
#[inline]
pub(crate) fn diag_mul(d: &V3, a: &M3) -> M3 {
    M3::from_fn(|i, k| d[i] * a[(i, k)])
}

/// `a · diag(d)`: scales column k of `a` by `d_k`.
#[inline]
pub(crate) fn col_mul(a: &M3, d: &V3) -> M3 {
    M3::from_fn(|i, k| a[(i, k)] * d[k])
}

/// The axial vector of the skew-symmetric part of `m`: `axial(skew(a)) = a`.
#[inline]
pub fn axial(m: &M3) -> V3 {
    V3::new(0.5 * (m[(2, 1)] - m[(1, 2)]), 0.5 * (m[(0, 2)] - m[(2, 0)]), 0.5 * (m[(1, 0)] - m[(0, 1)]))
}

/// Below this angle (rad) the series expansions are used.
const SERIES_LIMIT: f64 = 1.0;
/// Number of Taylor terms: the remainder at `phi = 1` is below 1e-20.
const N_TERMS: usize = 10;

/// Taylor coefficients of α(s) = Σ (−1)^{k+1} s^k/(2k+2)! (`sign = -1`, `offset = 2`) and
/// β(s) = Σ (−1)^k s^k/(2k+3)! (`sign = 1`, `offset = 3`), differentiated `deriv` times in s.
const fn series(sign: f64, offset: usize, deriv: usize) -> [f64; N_TERMS] {
    let mut out = [0.0; N_TERMS];
    let mut k = 0;
    while k < N_TERMS {
        let n = k + deriv; // index of the original term
        let mut f = 1.0;
        let mut i = 2;
        while i <= 2 * n + offset {
            f *= i as f64;
            i += 1;
        }
        let mut c = if n & 1 == 0 { sign / f } else { -sign / f };
        let mut d = 0;
        while d < deriv {
            c *= (n - d) as f64;
            d += 1;
        }
        out[k] = c;
        k += 1;
    }
    out
}

const SERIES_A: [f64; N_TERMS] = series(-1.0, 2, 0);
const SERIES_DA: [f64; N_TERMS] = series(-1.0, 2, 1);
const SERIES_DDA: [f64; N_TERMS] = series(-1.0, 2, 2);
const SERIES_B: [f64; N_TERMS] = series(1.0, 3, 0);
const SERIES_DB: [f64; N_TERMS] = series(1.0, 3, 1);
const SERIES_DDB: [f64; N_TERMS] = series(1.0, 3, 2);

/// Number of Taylor terms needed at `s = φ²` for a remainder below 1e-17 (φ < 1).
#[inline]
fn n_terms(s: f64) -> usize {
    if s < 0.04 {
        5
    } else if s < 0.36 {
        7
    } else {
        N_TERMS
    }
}

#[inline]
fn horner(c: &[f64; N_TERMS], s: f64) -> f64 {
    c[..n_terms(s)].iter().rev().fold(0.0, |acc, ck| acc * s + ck)
}

/// Several series at the same `s` in one Horner loop (the same operations as [`horner`] each).
#[inline]
fn horner_all<const M: usize>(c: [&[f64; N_TERMS]; M], s: f64) -> [f64; M] {
    let mut acc = [0.0; M];
    for i in (0..n_terms(s)).rev() {
        for (a, ck) in acc.iter_mut().zip(&c) {
            *a = *a * s + ck[i];
        }
    }
    acc
}

/// Scalar coefficients of `T(psi) = I + a·psĩ + b·psĩ²` and their first and second derivatives
/// with respect to `s = |psi|²`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentCoefficients {
    /// α(s) = (cos φ − 1)/φ².
    pub a: f64,
    /// β(s) = (φ − sin φ)/φ³.
    pub b: f64,
    /// dα/ds.
    pub da: f64,
    /// dβ/ds.
    pub db: f64,
    /// d²α/ds².
    pub dda: f64,
    /// d²β/ds².
    pub ddb: f64,
}

impl TangentCoefficients {
    /// Coefficients at the CRV `psi` (all derivatives, one `sin_cos`).
    pub fn new(psi: &V3) -> Self {
        Self::evaluate(psi.norm_squared(), true)
    }

    /// α, β and their first derivatives; the second derivatives are left at zero.
    pub fn first_order(psi: &V3) -> Self {
        Self::evaluate(psi.norm_squared(), false)
    }

    /// The coefficients at `s = |psi|²`, the second derivatives only if `second` (else zero).
    #[inline(always)]
    fn evaluate(s: f64, second: bool) -> Self {
        let phi = s.sqrt();
        if phi < SERIES_LIMIT {
            if second {
                let [a, b, da, db, dda, ddb] =
                    horner_all([&SERIES_A, &SERIES_B, &SERIES_DA, &SERIES_DB, &SERIES_DDA, &SERIES_DDB], s);
                Self { a, b, da, db, dda, ddb }
            } else {
                let [a, b, da, db] = horner_all([&SERIES_A, &SERIES_B, &SERIES_DA, &SERIES_DB], s);
                Self { a, b, da, db, dda: 0.0, ddb: 0.0 }
            }
        } else {
            let (sn, c) = phi.sin_cos();
            let p3 = s * phi;
            let p4 = s * s;
            let p5 = p4 * phi;
            let (dda, ddb) = if second { Self::closed_second(s, phi, sn, c) } else { (0.0, 0.0) };
            Self {
                a: (c - 1.0) / s,
                b: (phi - sn) / p3,
                da: -sn / (2.0 * p3) - (c - 1.0) / p4,
                db: -1.0 / p4 - c / (2.0 * p4) + 1.5 * sn / p5,
                dda,
                ddb,
            }
        }
    }

    /// Closed-form (d²α/ds², d²β/ds²) from `s`, `phi = √s`, `sin phi`, `cos phi`.
    #[inline]
    fn closed_second(s: f64, phi: f64, sn: f64, c: f64) -> (f64, f64) {
        let p4 = s * s;
        let p5 = p4 * phi;
        let p6 = p4 * s;
        let p7 = p6 * phi;
        (
            -c / (4.0 * p4) + 1.25 * sn / p5 + 2.0 * (c - 1.0) / p6,
            2.0 / p6 + sn / (4.0 * p5) + 1.75 * c / p6 - 3.75 * sn / p7,
        )
    }

    /// (d²α/ds², d²β/ds²) at `s = |psi|²`.
    pub fn second_order(s: f64) -> (f64, f64) {
        let phi = s.sqrt();
        if phi < SERIES_LIMIT {
            (horner(&SERIES_DDA, s), horner(&SERIES_DDB, s))
        } else {
            let (sn, c) = phi.sin_cos();
            Self::closed_second(s, phi, sn, c)
        }
    }

    /// The rotation matrix `C(psi) = I + (1 − s β) psĩ − α psĩ²` from the same coefficients.
    #[inline]
    pub fn rotation(&self, psi: &V3) -> M3 {
        let p = skew(psi);
        M3::identity() + p * (1.0 - psi.norm_squared() * self.b) - p * p * self.a
    }
}

/// Rotation matrix `C(psi) = exp(psĩ)` (C^{AB} for a nodal CRV).
pub fn rotation_matrix(psi: &V3) -> M3 {
    let s = psi.norm_squared();
    let phi = s.sqrt();
    // sin φ/φ and (1 − cos φ)/φ² with series near zero.
    let (c1, c2) = if phi < 1e-4 {
        (1.0 - s / 6.0 + s * s / 120.0, 0.5 - s / 24.0 + s * s / 720.0)
    } else {
        (phi.sin() / phi, (1.0 - phi.cos()) / s)
    };
    let k = skew(psi);
    M3::identity() + k * c1 + k * k * c2
}

/// The CRV of a rotation matrix, with norm in [0, π] (logarithm of SO(3)).
///
/// Goes through the unit quaternion so that it stays accurate near π.
pub fn from_rotation_matrix(c: &M3) -> V3 {
    crate::quaternion::Quaternion::from_rotation_matrix(c).to_crv()
}

/// Tangential operator `T(psi)`: `Omega_B = T(psi) psi_dot`.
pub fn tangent(psi: &V3) -> M3 {
    let k = TangentCoefficients::new(psi);
    tangent_with(psi, &k, 1.0)
}

/// `T_σ = I + σ α psĩ + β psĩ²` (σ = 1: T, σ = −1: Tᵀ).
fn tangent_with(psi: &V3, k: &TangentCoefficients, sigma: f64) -> M3 {
    let p = skew(psi);
    M3::identity() + p * (sigma * k.a) + p * p * k.b
}

/// Inverse of the tangential operator, `T(psi)⁻¹ = I + ½ psĩ + c(φ) psĩ²` with
/// `c = (1 − (φ/2) cot(φ/2))/φ²` (singular at φ = 2π).
pub fn tangent_inverse(psi: &V3) -> M3 {
    let s = psi.norm_squared();
    let phi = s.sqrt();
    let c = if phi < 1e-2 {
        1.0 / 12.0 + s / 720.0 + s * s / 30240.0
    } else {
        let h = 0.5 * phi;
        (1.0 - h * h.cos() / h.sin()) / s
    };
    let p = skew(psi);
    M3::identity() + p * 0.5 + p * p * c
}

/// `∂/∂psi [ (Σ_j b_j ∂T_σ/∂psi_j) a ]`: second derivative of `T_σ a` contracted with `b` on one
/// derivative index.
fn tangent_second_with(psi: &V3, k: &TangentCoefficients, sigma: f64, a: &V3, b: &V3) -> M3 {
    let i3 = M3::identity();
    let pa = psi.cross(a);
    let ppa = psi.cross(&pa);
    let psa = psi.dot(a);
    let psb = psi.dot(b);
    let ab = a.dot(b);
    let pt = psi.transpose();
    let t1 = a.cross(b) * pt * (-2.0 * sigma * k.da);
    let t2 = (pa * pt * (2.0 * k.dda * psb) + (skew(a) * (-psb) + pa * b.transpose()) * k.da) * (2.0 * sigma);
    let lin = b * psa + psi * ab - a * (2.0 * psb);
    let t3 = lin * pt * (2.0 * k.db) + (b * a.transpose() + i3 * ab - a * b.transpose() * 2.0) * k.b;
    let t4 = (ppa * pt * (2.0 * k.ddb * psb)
        + ((i3 * psa + psi * a.transpose() - a * pt * 2.0) * psb + ppa * b.transpose()) * k.db)
        * 2.0;
    t1 + t2 + t3 + t4
}

/// `skew(a) · m` from the cross products of the columns (cheaper than the matrix product).
#[inline]
pub(crate) fn skew_mul(a: &V3, m: &M3) -> M3 {
    M3::from_fn(|i, j| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        a[i1] * m[(i2, j)] - a[i2] * m[(i1, j)]
    })
}

/// The outer product `u vᵀ`.
#[inline]
fn outer(u: &V3, v: &V3) -> M3 {
    u * v.transpose()
}

/// `d I + skew(w)`.
#[inline]
fn diag_skew(d: f64, w: &V3) -> M3 {
    M3::new(d, -w.z, w.y, w.z, d, -w.x, -w.y, w.x, d)
}

/// The tangential operator and its derivatives at one CRV, sharing the scalar coefficients.
///
/// Every derivative is written as `d I + skew(w) + Σ u vᵀ` with few outer products (the
/// identities `ã b̃ = b aᵀ − (a·b) I` and `psĩ² = psi psiᵀ − s I` turn the products of skew
/// matrices into outer products).
#[derive(Debug, Clone, Copy)]
pub struct Tangent {
    /// The CRV.
    pub psi: V3,
    /// Scalar coefficients (the second derivatives only if built by [`Tangent::with_second_order`]).
    pub k: TangentCoefficients,
    /// `T(psi)`.
    pub t: M3,
    /// `psĩ²`.
    pp: M3,
    /// Whether `k` holds the second derivatives.
    second: bool,
}

impl Tangent {
    /// Evaluate at `psi` (first-order coefficients; [`Tangent::second`] and
    /// [`Tangent::hessian`] then evaluate the second-order ones on demand).
    #[inline]
    pub fn new(psi: &V3) -> Self {
        Self::build(psi, TangentCoefficients::first_order(psi), false)
    }
    /// Evaluate at `psi` with all coefficients (one `sin_cos`), for the tangent matrices.
    #[inline]
    pub fn with_second_order(psi: &V3) -> Self {
        Self::build(psi, TangentCoefficients::new(psi), true)
    }
    #[inline]
    fn build(psi: &V3, k: TangentCoefficients, second: bool) -> Self {
        // psĩ² = psi psiᵀ − s I
        let pp = outer(psi, psi) - M3::identity() * psi.norm_squared();
        Self { psi: *psi, k, t: diag_skew(1.0, &(psi * k.a)) + pp * k.b, pp, second }
    }
    /// The rotation matrix `C(psi)` (C^{AB}), from the same coefficients.
    #[inline]
    pub fn rotation(&self) -> M3 {
        let s = self.psi.norm_squared();
        diag_skew(1.0, &(self.psi * (1.0 - s * self.k.b))) - self.pp * self.k.a
    }
    /// `dT[b] = Σ_j b_j ∂T/∂psi_j`, so that `dT[b] a = ∂(T a)/∂psi · b`.
    #[inline]
    pub fn dir(&self, b: &V3) -> M3 {
        let (k, p) = (&self.k, &self.psi);
        let pb = p.dot(b);
        diag_skew(-2.0 * k.b * pb, &(b * k.a + p * (2.0 * k.da * pb)))
            + (outer(b, p) + outer(p, b)) * k.b
            + self.pp * (2.0 * k.db * pb)
    }
    /// The vector `dT[b] a` (cheaper than `dir(b) * a`).
    #[inline]
    pub fn dir_vec(&self, b: &V3, a: &V3) -> V3 {
        let (k, p) = (&self.k, &self.psi);
        let pb = p.dot(b);
        let pa = p.cross(a);
        b.cross(a) * k.a
            + pa * (2.0 * k.da * pb)
            + (b.cross(&pa) + p.cross(&b.cross(a))) * k.b
            + p.cross(&pa) * (2.0 * k.db * pb)
    }
    /// `∂(T_σ a)/∂psi` (σ = 1: T, σ = −1: Tᵀ).
    #[inline]
    fn jac_with(&self, sigma: f64, a: &V3) -> M3 {
        let (k, p) = (&self.k, &self.psi);
        let pa = p.cross(a);
        let u = pa * (2.0 * sigma * k.da) + p.cross(&pa) * (2.0 * k.db) - a * (2.0 * k.b);
        diag_skew(k.b * p.dot(a), &(a * (-sigma * k.a))) + outer(&u, p) + outer(p, a) * k.b
    }
    /// The vector `(∂(T a)/∂psi)ᵀ m` (without the matrix).
    #[inline]
    pub fn jac_tr_vec(&self, a: &V3, m: &V3) -> V3 {
        let (k, p) = (&self.k, &self.psi);
        let pa = p.cross(a);
        let u = pa * (2.0 * k.da) + p.cross(&pa) * (2.0 * k.db) - a * (2.0 * k.b);
        a.cross(m) * k.a + p * u.dot(m) + a * (k.b * p.dot(m)) + m * (k.b * p.dot(a))
    }
    /// `∂(T a)/∂psi`.
    #[inline]
    pub fn jac(&self, a: &V3) -> M3 {
        self.jac_with(1.0, a)
    }
    /// `∂(Tᵀ b)/∂psi`.
    #[inline]
    pub fn jac_t(&self, b: &V3) -> M3 {
        self.jac_with(-1.0, b)
    }
    #[inline]
    fn full(&self) -> TangentCoefficients {
        let mut k = self.k;
        if !self.second {
            (k.dda, k.ddb) = TangentCoefficients::second_order(self.psi.norm_squared());
        }
        k
    }
    /// `∂/∂psi [dT[b] a]` (a, b fixed).
    pub fn second(&self, a: &V3, b: &V3) -> M3 {
        tangent_second_with(&self.psi, &self.full(), 1.0, a, b)
    }
    /// `∂/∂psi [T c + dT[a] a]`: the Jacobian of the rotational acceleration
    /// `T psi_ddot + dT[psi_dot] psi_dot` for `a = psi_dot`, `c = psi_ddot` (equal to
    /// `jac(c) + second(a, a)`, collected into three outer products).
    #[inline(always)]
    pub fn acceleration_jac(&self, a: &V3, c: &V3) -> M3 {
        let k = self.full();
        let p = &self.psi;
        let (pa, pc) = (p.cross(a), p.cross(c));
        let ppa = p.cross(&pa);
        let (psa, aa) = (p.dot(a), a.dot(a));
        let u = pc * (2.0 * k.da) + p.cross(&pc) * (2.0 * k.db) - c * (2.0 * k.b)
            + pa * (4.0 * k.dda * psa)
            + p * (2.0 * k.db * aa)
            - a * (6.0 * k.db * psa)
            + ppa * (4.0 * k.ddb * psa);
        let v = pa * (2.0 * k.da) - a * k.b + p * (2.0 * k.db * psa) + ppa * (2.0 * k.db);
        let d = k.b * (p.dot(c) + aa) + 2.0 * k.db * psa * psa;
        let w = c * (-k.a) - a * (2.0 * k.da * psa);
        diag_skew(d, &w) + outer(&u, p) + outer(p, c) * k.b + outer(&v, a)
    }
    /// `∂/∂psi [ (∂(T a)/∂psi)ᵀ m ]`: the Hessian of the scalar
    /// `f = mᵀ T a = mᵀa + α L + β Q` with `L = psi·(a × m)` and
    /// `Q = (m·psi)(psi·a) − s (m·a)` (symmetric).
    #[inline(always)]
    pub fn hessian(&self, a: &V3, m: &V3) -> M3 {
        let k = self.full();
        let p = &self.psi;
        let axm = a.cross(m);
        let (ma, mp, pa) = (m.dot(a), m.dot(p), p.dot(a));
        let l = p.dot(&axm);
        let q = mp * pa - p.norm_squared() * ma;
        let grad_q = m * pa + a * mp - p * (2.0 * ma);
        // 2α'(L I + psi axmᵀ + axm psiᵀ) + 4α'' L psi psiᵀ + (the same in β, Q, grad Q)
        //   + β (m aᵀ + a mᵀ − 2 (m·a) I), the psi psiᵀ terms split between the two outer products.
        let z = axm * (2.0 * k.da) + grad_q * (2.0 * k.db) + p * (2.0 * (k.dda * l + k.ddb * q));
        let d = 2.0 * k.da * l + 2.0 * k.db * q - 2.0 * k.b * ma;
        M3::identity() * d + outer(p, &z) + outer(&z, p) + (outer(m, a) + outer(a, m)) * k.b
    }
}

/// `∂(T(psi) a)/∂psi`.
pub fn tangent_jacobian(psi: &V3, a: &V3) -> M3 {
    Tangent::new(psi).jac(a)
}

/// `∂(T(psi)ᵀ b)/∂psi`.
pub fn tangent_transpose_jacobian(psi: &V3, b: &V3) -> M3 {
    Tangent::new(psi).jac_t(b)
}

/// If `|psi| > π`, the equivalent CRV `psi (1 − 2πk/|psi|)` with norm in [0, π] (same rotation);
/// otherwise `None`.
pub fn rescale(psi: &V3) -> Option<V3> {
    let phi = psi.norm();
    if phi <= std::f64::consts::PI || !phi.is_finite() {
        return None;
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    let k = ((phi + std::f64::consts::PI) / two_pi).floor();
    Some(psi * (1.0 - two_pi * k / phi))
}

/// Rate of a rescaled CRV: the same angular velocity `T(psi_new) psi_dot_new = T(psi_old) psi_dot_old`.
pub fn rescale_rates(psi_old: &V3, psi_new: &V3, psi_dot_old: &V3) -> V3 {
    tangent_inverse(psi_new) * (tangent(psi_old) * psi_dot_old)
}

/// Second rate of a rescaled CRV: the same angular acceleration
/// `T psi_ddot + dT[psi_dot] psi_dot` in both parametrisations.
pub fn rescale_accelerations(psi_old: &V3, psi_new: &V3, psi_dot_old: &V3, psi_dot_new: &V3, psi_ddot_old: &V3) -> V3 {
    let to = Tangent::new(psi_old);
    let tn = Tangent::new(psi_new);
    let omega_dot = to.t * psi_ddot_old + to.dir(psi_dot_old) * psi_dot_old;
    tangent_inverse(psi_new) * (omega_dot - tn.dir(psi_dot_new) * psi_dot_new)
}

/// The branch change `u_j(psi) = psi (1 + 2πj/|psi|)` of a CRV (the same rotation, norm
/// shifted by 2πj) and its derivatives, used to bring the nodes of an element onto one branch
/// when their stored CRVs were rescaled separately. With `c(s) = 1 + 2πj s^{-1/2}`,
/// `J = ∂u/∂psi = c I + 2c' psi psiᵀ` (symmetric), `dJ[a] b = ∂(J b)/∂psi · a` (symmetric in
/// a, b), and `H(a, b) = ∂/∂psi (dJ[a] b)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchMap {
    /// The stored CRV.
    pub psi: V3,
    /// Number of turns added.
    pub j: i32,
    c: f64,
    c1: f64,
    c2: f64,
    c3: f64,
}

impl BranchMap {
    /// The map for `j` turns at `psi` (`psi ≠ 0`).
    pub fn new(psi: &V3, j: i32) -> Self {
        let s = psi.norm_squared();
        let pj = std::f64::consts::PI * j as f64;
        let r = 1.0 / s.sqrt(); // s^{-1/2}
        Self {
            psi: *psi,
            j,
            c: 1.0 + 2.0 * pj * r,
            c1: -pj * r / s,
            c2: 1.5 * pj * r / (s * s),
            c3: -3.75 * pj * r / (s * s * s),
        }
    }

    /// The number of turns that brings `psi` closest to `target`, if it is not zero.
    pub fn toward(psi: &V3, target: &V3) -> Option<Self> {
        let phi = psi.norm();
        let reach = phi + target.norm();
        // Non-finite or absurd values (a diverging Newton iterate) are left alone.
        if phi == 0.0 || !(reach > std::f64::consts::PI && reach < 1e6) {
            return None;
        }
        let two_pi = 2.0 * std::f64::consts::PI;
        let n = psi / phi;
        // The branch points are (phi + 2πj) n; pick j minimising the distance to target.
        let along = target.dot(&n);
        let j = ((along - phi) / two_pi).round() as i32;
        let dist = |j: i32| ((phi + two_pi * j as f64) * n - target).norm();
        let best = (j - 1..=j + 1).min_by(|a, b| dist(*a).total_cmp(&dist(*b))).unwrap_or(0);
        (best != 0).then(|| Self::new(psi, best))
    }

    /// `u(psi)`.
    pub fn apply(&self) -> V3 {
        self.psi * self.c
    }

    /// `J = ∂u/∂psi`.
    pub fn jac(&self) -> M3 {
        M3::identity() * self.c + self.psi * self.psi.transpose() * (2.0 * self.c1)
    }

    /// The matrix `b ↦ dJ[a] b`.
    pub fn djac(&self, a: &V3) -> M3 {
        let p = &self.psi;
        let pa = p.dot(a);
        (M3::identity() * pa + a * p.transpose() + p * a.transpose()) * (2.0 * self.c1)
            + p * p.transpose() * (4.0 * self.c2 * pa)
    }

    /// `H(a, b) = ∂/∂psi (dJ[a] b)`.
    pub fn hess(&self, a: &V3, b: &V3) -> M3 {
        let p = &self.psi;
        let (pa, pb, ab) = (p.dot(a), p.dot(b), a.dot(b));
        let pt = p.transpose();
        (b * a.transpose() + a * b.transpose() + M3::identity() * ab) * (2.0 * self.c1)
            + (b * pa + a * pb + p * ab) * pt * (4.0 * self.c2)
            + (p * a.transpose() * pb + p * b.transpose() * pa + M3::identity() * (pa * pb)) * (4.0 * self.c2)
            + p * pt * (8.0 * self.c3 * pa * pb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn samples() -> Vec<V3> {
        vec![
            V3::zeros(),
            V3::new(1e-9, -2e-9, 0.5e-9),
            V3::new(1e-3, 2e-3, -1e-3),
            V3::new(0.3, -0.2, 0.4),
            V3::new(0.6, 0.7, -0.2),  // φ ≈ 0.94 (series side)
            V3::new(0.6, 0.7, -0.45), // φ ≈ 1.03 (closed-form side)
            V3::new(1.2, -0.8, 2.0),
            V3::new(0.0, 0.0, PI - 1e-6),
            V3::new(1.5, 1.5, 2.0).normalize() * (PI - 1e-3),
            V3::new(-1.0, 2.0, 0.5).normalize() * 4.5,
        ]
    }

    fn fd_jac(f: impl Fn(&V3) -> V3, psi: &V3) -> M3 {
        let h = 1e-6;
        let mut j = M3::zeros();
        for c in 0..3 {
            let d = V3::ith(c, h);
            j.set_column(c, &((f(&(psi + d)) - f(&(psi - d))) / (2.0 * h)));
        }
        j
    }

    #[test]
    fn coefficients_continuous_at_series_limit() {
        let lo = TangentCoefficients::new(&V3::new(SERIES_LIMIT * (1.0 - 1e-12), 0.0, 0.0));
        let hi = TangentCoefficients::new(&V3::new(SERIES_LIMIT * (1.0 + 1e-12), 0.0, 0.0));
        assert_relative_eq!(lo.a, hi.a, max_relative = 1e-11);
        assert_relative_eq!(lo.b, hi.b, max_relative = 1e-11);
        assert_relative_eq!(lo.da, hi.da, max_relative = 1e-10);
        assert_relative_eq!(lo.db, hi.db, max_relative = 1e-10);
        assert_relative_eq!(lo.dda, hi.dda, max_relative = 1e-9);
        assert_relative_eq!(lo.ddb, hi.ddb, max_relative = 1e-9);
    }

    #[test]
    fn coefficient_derivatives_match_finite_differences() {
        for phi in [0.3, 0.9, 1.1, 2.5, 3.1, 5.0] {
            let s = phi * phi;
            let at = |s: f64| TangentCoefficients::new(&V3::new(s.sqrt(), 0.0, 0.0));
            let h = 1e-6;
            let (p, m, c) = (at(s + h), at(s - h), at(s));
            assert_relative_eq!(c.da, (p.a - m.a) / (2.0 * h), max_relative = 1e-7);
            assert_relative_eq!(c.db, (p.b - m.b) / (2.0 * h), max_relative = 1e-7);
            assert_relative_eq!(c.dda, (p.da - m.da) / (2.0 * h), max_relative = 1e-6);
            assert_relative_eq!(c.ddb, (p.db - m.db) / (2.0 * h), max_relative = 1e-6);
        }
    }

    #[test]
    fn rotation_matrix_is_orthonormal_and_round_trips() {
        for psi in samples() {
            let c = rotation_matrix(&psi);
            assert_relative_eq!(c.transpose() * c, M3::identity(), epsilon = 1e-14);
            assert_relative_eq!(c.determinant(), 1.0, epsilon = 1e-14);
            if psi.norm() <= PI {
                assert_relative_eq!(from_rotation_matrix(&c), psi, epsilon = 1e-9);
            } else {
                let r = rescale(&psi).unwrap();
                assert!(r.norm() <= PI);
                assert_relative_eq!(rotation_matrix(&r), c, epsilon = 1e-13);
                assert_relative_eq!(from_rotation_matrix(&c), r, epsilon = 1e-9);
            }
        }
    }

    #[test]
    fn tangent_gives_body_angular_velocity() {
        // Cᵀ dC/dt = (T psi_dot)~ along psi(t) = psi + t psi_dot.
        let dpsi = V3::new(0.3, -0.7, 0.2);
        for psi in samples() {
            let h = 1e-6;
            let dc = (rotation_matrix(&(psi + dpsi * h)) - rotation_matrix(&(psi - dpsi * h))) / (2.0 * h);
            let w = rotation_matrix(&psi).transpose() * dc;
            assert_relative_eq!(axial(&w), tangent(&psi) * dpsi, epsilon = 1e-8);
        }
    }

    #[test]
    fn tangent_inverse_inverts() {
        for psi in samples() {
            let t = tangent(&psi);
            assert_relative_eq!(tangent_inverse(&psi) * t, M3::identity(), epsilon = 1e-10);
        }
    }

    #[test]
    fn tangent_jacobians_match_finite_differences() {
        let a = V3::new(0.4, -1.3, 0.8);
        let b = V3::new(-0.6, 0.2, 1.1);
        for psi in samples() {
            let t = Tangent::new(&psi);
            let scale = 1.0 + t.jac(&a).norm();
            let fd = fd_jac(|p| tangent(p) * a, &psi);
            assert!((t.jac(&a) - fd).norm() < 1e-8 * scale, "jac at {psi:?}");
            let fd = fd_jac(|p| tangent(p).transpose() * b, &psi);
            assert!((t.jac_t(&b) - fd).norm() < 1e-8 * scale, "jac_t at {psi:?}");
            assert_relative_eq!(t.jac_tr_vec(&a, &b), t.jac(&a).transpose() * b, epsilon = 1e-13 * scale);
            // dT[b] a = jac(a) b
            assert_relative_eq!(t.dir(&b) * a, t.jac(&a) * b, epsilon = 1e-13 * scale);
            assert_relative_eq!(t.dir_vec(&b, &a), t.dir(&b) * a, epsilon = 1e-13 * scale);
            // Second derivative: ∂/∂psi [dT[b] a].
            let fd = fd_jac(|p| Tangent::new(p).dir(&b) * a, &psi);
            let an = t.second(&a, &b);
            assert!((an - fd).norm() < 1e-7 * (1.0 + an.norm()), "second at {psi:?}: {an} vs {fd}");
            // Hessian of bᵀ T a.
            let fd = fd_jac(|p| Tangent::new(p).jac(&a).transpose() * b, &psi);
            let an = t.hessian(&a, &b);
            assert!((an - fd).norm() < 1e-7 * (1.0 + an.norm()), "hessian at {psi:?}");
            assert_relative_eq!(an, an.transpose(), epsilon = 1e-12 * (1.0 + an.norm()));
        }
    }

    #[test]
    fn acceleration_jacobian_matches_finite_differences() {
        let a = V3::new(0.4, -1.3, 0.8);
        let c = V3::new(-0.6, 0.2, 1.1);
        for psi in samples() {
            let t = Tangent::with_second_order(&psi);
            let an = t.acceleration_jac(&a, &c);
            let fd = fd_jac(|p| tangent(p) * c + Tangent::new(p).dir_vec(&a, &a), &psi);
            assert!((an - fd).norm() < 1e-7 * (1.0 + an.norm()), "acceleration_jac at {psi:?}: {an} vs {fd}");
            let sum = t.jac(&c) + t.second(&a, &a);
            assert_relative_eq!(an, sum, epsilon = 1e-13 * (1.0 + an.norm()));
            // Both constructors give the same operators.
            let t1 = Tangent::new(&psi);
            assert_relative_eq!(t1.hessian(&a, &c), t.hessian(&a, &c), epsilon = 1e-14 * (1.0 + an.norm()));
            assert_relative_eq!(t1.rotation(), rotation_matrix(&psi), epsilon = 1e-14);
        }
    }

    #[test]
    fn branch_map_derivatives_match_finite_differences() {
        let a = V3::new(0.4, -1.3, 0.8);
        let b = V3::new(-0.6, 0.2, 1.1);
        for (psi, j) in [(V3::new(1.0, 2.0, -1.5), 1), (V3::new(-2.0, 0.5, 1.0), -1), (V3::new(0.3, 0.1, 3.0), 2)] {
            let m = BranchMap::new(&psi, j);
            // Same rotation.
            assert_relative_eq!(rotation_matrix(&m.apply()), rotation_matrix(&psi), epsilon = 1e-12);
            let fd = fd_jac(|p| BranchMap::new(p, j).apply(), &psi);
            assert_relative_eq!(m.jac(), fd, epsilon = 1e-7);
            let fd = fd_jac(|p| BranchMap::new(p, j).jac() * b, &psi);
            assert_relative_eq!(m.djac(&b), fd, epsilon = 1e-7);
            assert_relative_eq!(m.djac(&a) * b, m.djac(&b) * a, epsilon = 1e-12);
            let fd = fd_jac(|p| BranchMap::new(p, j).djac(&a) * b, &psi);
            assert_relative_eq!(m.hess(&a, &b), fd, epsilon = 1e-6);
            // T u̇ is the same angular velocity: T(u) J = T(psi).
            assert_relative_eq!(tangent(&m.apply()) * m.jac(), tangent(&psi), epsilon = 1e-10);
        }
        // Nearest branch.
        let psi = V3::new(0.0, 0.0, -PI + 0.1);
        let m = BranchMap::toward(&psi, &V3::new(0.0, 0.0, PI - 0.2)).unwrap();
        assert_eq!(m.j, -1);
        assert_relative_eq!(m.apply(), V3::new(0.0, 0.0, PI + 0.1), epsilon = 1e-12);
        assert!(BranchMap::toward(&V3::new(0.1, 0.0, 0.0), &V3::new(0.2, 0.0, 0.0)).is_none());
    }

    #[test]
    fn rescale_keeps_rotation_rate_and_acceleration() {
        let psi = V3::new(1.0, -2.0, 2.5).normalize() * (PI + 0.2);
        let psi_dot = V3::new(0.3, 0.1, -0.5);
        let psi_ddot = V3::new(-0.2, 0.4, 0.7);
        let new = rescale(&psi).unwrap();
        assert_relative_eq!(new.norm(), PI - 0.2, epsilon = 1e-12);
        let new_dot = rescale_rates(&psi, &new, &psi_dot);
        // Same path of rotations: C(psi(t)) = C(psi_new(t)) to first order.
        let h = 1e-6;
        let c_old = rotation_matrix(&(psi + psi_dot * h));
        let c_new = rotation_matrix(&(new + new_dot * h));
        assert_relative_eq!(c_old, c_new, epsilon = 1e-11);
        // Second order: compare the angular accelerations.
        let new_ddot = rescale_accelerations(&psi, &new, &psi_dot, &new_dot, &psi_ddot);
        let om = |p: &V3, d: &V3, dd: &V3, t: f64| {
            let pt = p + d * t + dd * (0.5 * t * t);
            tangent(&pt) * (d + dd * t)
        };
        let a_old = (om(&psi, &psi_dot, &psi_ddot, h) - om(&psi, &psi_dot, &psi_ddot, -h)) / (2.0 * h);
        let a_new = (om(&new, &new_dot, &new_ddot, h) - om(&new, &new_dot, &new_ddot, -h)) / (2.0 * h);
        assert_relative_eq!(a_old, a_new, epsilon = 1e-7);
        assert!(rescale(&V3::new(0.0, 3.0, 0.0)).is_none());
        // Multiples of 2π fold back too.
        let far = V3::new(0.0, 0.0, 4.0 * PI + 0.5);
        assert_relative_eq!(rescale(&far).unwrap(), V3::new(0.0, 0.0, 0.5), epsilon = 1e-12);
    }
}
