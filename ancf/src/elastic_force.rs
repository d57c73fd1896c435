//! Elastic energy, force and analytic tangent of the element (THEORY §A.3).
//!
//! With the sampled strains `s_k = ½ eᵀ A_k e` (see [`strain`](crate::strain)) and their
//! stiffness-weighted quadrature weights `C_k`:
//!
//! $$ U = \tfrac12 \sum_k C_k (s_k - s_k^0)^2,\qquad
//!    f = \sum_k C_k (s_k - s_k^0)\, A_k e,\qquad
//!    K = \sum_k C_k\big[(A_k e)(A_k e)^T + (s_k - s_k^0) A_k\big]. $$
//!
//! `A_k e` is formed from the fields: for a term `c f_a·f_b`, `∂s/∂f_a = c f_b` and
//! `∂s/∂f_b = c f_a`, scattered to the nodal blocks by the interpolation weights. No trigonometry,
//! no allocation.

use crate::element::Element;
use crate::shape::{ELEMENT_DOF, N_BLOCKS};
use crate::strain::{MAX_FIELDS, N_STRAINS, StrainKind, StrainPlan, strain_value};
use nalgebra::{SMatrix, SVector};

/// 24×24 element matrix.
pub type ElementMatrix = SMatrix<f64, ELEMENT_DOF, ELEMENT_DOF>;
/// 24-vector.
pub type ElementVector = SVector<f64, ELEMENT_DOF>;

type Fields = [[f64; 3]; MAX_FIELDS];

#[inline]
fn eval_fields(plan: &StrainPlan, e: &[f64]) -> Fields {
    let mut f = [[0.0; 3]; MAX_FIELDS];
    for (fi, w) in f.iter_mut().zip(&plan.fields) {
        *fi = w.eval(e);
    }
    f
}

/// `out[field] += scale ∂s/∂f` for every field of strain `s`.
#[inline]
fn add_field_gradient(s: &crate::strain::SampledStrain, f: &Fields, scale: f64, out: &mut Fields) {
    for &(c, a, b) in s.terms() {
        let cs = c * scale;
        for i in 0..3 {
            out[a][i] += cs * f[b][i];
            out[b][i] += cs * f[a][i];
        }
    }
}

/// `out[block] += Σ_f W_f[block] P_f` over the first `n` fields.
#[inline]
fn scatter(plan: &StrainPlan, pf: &Fields, out: &mut [f64]) {
    for (w, p) in plan.fields.iter().zip(pf) {
        for k in 0..w.n {
            let b = 3 * w.block[k];
            let x = w.weight[k];
            out[b] += x * p[0];
            out[b + 1] += x * p[1];
            out[b + 2] += x * p[2];
        }
    }
}

/// Copy the upper block triangle (3×3 blocks `(a, b)`, `a ≤ b`) onto the lower one.
pub fn mirror_upper_inplace(k: &mut ElementMatrix) {
    let data = k.as_mut_slice(); // column-major: (i, j) at 24 j + i
    for j in 0..ELEMENT_DOF {
        for i in 3 * (j / 3 + 1)..ELEMENT_DOF {
            data[ELEMENT_DOF * j + i] = data[ELEMENT_DOF * i + j];
        }
    }
}

/// `A_k e` of one strain as a 24-vector.
fn strain_gradient(plan: &StrainPlan, s: &crate::strain::SampledStrain, f: &Fields) -> ElementVector {
    let mut g = ElementVector::zeros();
    for &(c, a, b) in s.terms() {
        for (fi, other) in [(a, b), (b, a)] {
            let w = &plan.fields[fi];
            for k in 0..w.n {
                let base = 3 * w.block[k];
                let x = c * w.weight[k];
                g[base] += x * f[other][0];
                g[base + 1] += x * f[other][1];
                g[base + 2] += x * f[other][2];
            }
        }
    }
    g
}

impl Element {
    /// Elastic energy of one element with coordinates `e` (24 numbers), J.
    pub fn elastic_energy(&self, e: &[f64]) -> f64 {
        let f = eval_fields(&self.plan, e);
        self.plan
            .strains
            .iter()
            .map(|s| {
                let d = strain_value(s, &f) - s.reference;
                0.5 * s.stiffness * d * d
            })
            .sum()
    }

    /// Elastic energy split by [`StrainKind`], J.
    pub fn elastic_energy_by_kind(&self, e: &[f64]) -> [f64; N_STRAINS] {
        let f = eval_fields(&self.plan, e);
        let mut u = [0.0; N_STRAINS];
        for s in &self.plan.strains {
            let d = strain_value(s, &f) - s.reference;
            u[s.kind as usize] += 0.5 * s.stiffness * d * d;
        }
        u
    }

    /// `out += f_el(e)`, the elastic force of one element (24 numbers); returns its energy.
    pub fn add_elastic_force(&self, e: &[f64], out: &mut [f64]) -> f64 {
        let f = eval_fields(&self.plan, e);
        let mut pf = [[0.0; 3]; MAX_FIELDS];
        let mut u = 0.0;
        for s in &self.plan.strains {
            let d = strain_value(s, &f) - s.reference;
            u += 0.5 * s.stiffness * d * d;
            add_field_gradient(s, &f, s.stiffness * d, &mut pf);
        }
        scatter(&self.plan, &pf, out);
        u
    }

    /// `k += c · K_el(e)`, the analytic elastic tangent of one element.
    pub fn add_elastic_tangent(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        let mut upper = ElementMatrix::zeros();
        self.add_elastic_tangent_upper(e, c, &mut upper);
        mirror_upper_inplace(&mut upper);
        *k += upper;
    }

    /// `k += c · K_el(e)` on the upper block triangle only (3×3 blocks `(a, b)` with `a ≤ b`,
    /// diagonal blocks in full); [`mirror_upper_inplace`] completes the symmetric matrix, so that
    /// it is exactly symmetric.
    ///
    /// Each strain adds the rank-one term `C (A e)(A e)ᵀ` column by column as one contiguous
    /// update over the rows from its first to the column's block (the few zero rows of unused
    /// blocks in between cost less than the branching that would skip them).
    pub fn add_elastic_tangent_upper(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        let f = eval_fields(&self.plan, e);
        let mut geometric = [[0.0; N_BLOCKS]; N_BLOCKS];
        let data = k.as_mut_slice(); // column-major 24 × 24
        for s in &self.plan.strains {
            let d = strain_value(s, &f) - s.reference;
            let g = strain_gradient(&self.plan, s, &f);
            let g = g.as_slice();
            let cs = c * s.stiffness;
            let blocks = &s.blocks[..s.n_blocks];
            let Some(&first) = blocks.first() else { continue };
            let lo = 3 * first;
            for &bj in blocks {
                let hi = 3 * bj + 3;
                for j in 3 * bj..hi {
                    let x = cs * g[j];
                    if x == 0.0 {
                        continue;
                    }
                    let col = &mut data[ELEMENT_DOF * j + lo..ELEMENT_DOF * j + hi];
                    for (cij, gi) in col.iter_mut().zip(&g[lo..hi]) {
                        *cij += x * gi;
                    }
                }
            }
            let sd = c * s.stiffness * d;
            for (jb, &b) in blocks.iter().enumerate() {
                for &a in &blocks[..=jb] {
                    geometric[a][b] += sd * s.hessian[a][b];
                }
            }
        }
        for b in 0..N_BLOCKS {
            for a in 0..=b {
                let x = geometric[a][b];
                if x != 0.0 {
                    for i in 0..3 {
                        data[ELEMENT_DOF * (3 * b + i) + 3 * a + i] += x;
                    }
                }
            }
        }
    }

    /// Strain gradients `A_k e` at `e` with their stiffness weights — the rows of the
    /// linearised strain operator (used by the modal analysis to classify modes).
    pub fn strain_gradients(&self, e: &[f64]) -> Vec<(StrainKind, f64, ElementVector)> {
        let f = eval_fields(&self.plan, e);
        self.plan.strains.iter().map(|s| (s.kind, s.stiffness, strain_gradient(&self.plan, s, &f))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strain::reference_element;
    use crate::{Curvature, Section};
    use nalgebra::{Matrix3, Rotation3, Vector3};
    use proptest::prelude::*;

    const ALL_CURVATURES: [Curvature; 3] = [Curvature::Hybrid, Curvature::Kirchhoff, Curvature::Mixed];

    fn section() -> Section {
        Section {
            mass: 1.08,
            rho_ixx: 7.2e-5,
            rho_iyy: 3.6e-5,
            rho_izz: 3.6e-5,
            ea: 2.8e5,
            ga_y: 1.037e5,
            ga_z: 1.2e5,
            gj: 6.91,
            ei_yy: 9.33,
            ei_zz: 12.0,
        }
    }

    /// A deformed state: reference plus a perturbation of size `amp` (positions scaled by l).
    fn deformed(l: f64, seed: &[f64], amp: f64) -> [f64; 24] {
        let mut e = reference_element(l);
        for (i, x) in e.iter_mut().enumerate() {
            let scale = if (i / 3) % 4 == 0 { l } else { 1.0 };
            *x += amp * scale * seed[i % seed.len()];
        }
        e
    }

    fn apply_rigid(e: &[f64; 24], rot: &Matrix3<f64>, shift: &Vector3<f64>) -> [f64; 24] {
        let mut out = [0.0; 24];
        for b in 0..8 {
            let v = Vector3::new(e[3 * b], e[3 * b + 1], e[3 * b + 2]);
            let w = if b % 4 == 0 { rot * v + shift } else { rot * v };
            out[3 * b..3 * b + 3].copy_from_slice(w.as_slice());
        }
        out
    }

    /// max |K − K_fd| / max |K_fd| with K_fd the central difference of the force.
    fn tangent_error(curvature: Curvature, seed: &[f64], amp: f64) -> f64 {
        let l = 0.1;
        let el = Element::new(l, &section(), curvature, 1.0, 100.0);
        let e = deformed(l, seed, amp);
        let mut k = ElementMatrix::zeros();
        el.add_elastic_tangent(&e, 1.0, &mut k);
        let mut fd = ElementMatrix::zeros();
        let h = 1e-6;
        for j in 0..24 {
            let (mut ep, mut em) = (e, e);
            ep[j] += h;
            em[j] -= h;
            let (mut fp, mut fm) = ([0.0; 24], [0.0; 24]);
            el.add_elastic_force(&ep, &mut fp);
            el.add_elastic_force(&em, &mut fm);
            for i in 0..24 {
                fd[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
            }
        }
        (k - fd).amax() / fd.amax()
    }

    /// max |f − ∇U_fd| / max |f|.
    fn force_error(curvature: Curvature, seed: &[f64], amp: f64) -> f64 {
        let l = 0.1;
        let el = Element::new(l, &section(), curvature, 1.0, 100.0);
        let e = deformed(l, seed, amp);
        let mut f = [0.0; 24];
        el.add_elastic_force(&e, &mut f);
        let h = 1e-6;
        let fmax = f.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        (0..24)
            .map(|j| {
                let (mut ep, mut em) = (e, e);
                ep[j] += h;
                em[j] -= h;
                let d = (el.elastic_energy(&ep) - el.elastic_energy(&em)) / (2.0 * h);
                (d - f[j]).abs() / fmax
            })
            .fold(0.0, f64::max)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// The analytic tangent equals a central difference of the force (relative < 1e-6).
        #[test]
        fn tangent_matches_finite_difference(seed in proptest::collection::vec(-1.0..1.0f64, 24), amp in 0.01..0.3f64) {
            for c in ALL_CURVATURES {
                let err = tangent_error(c, &seed, amp);
                prop_assert!(err < 1e-6, "{c:?}: relative error {err:e}");
            }
        }

        /// The force is the gradient of the energy.
        #[test]
        fn force_matches_energy_gradient(seed in proptest::collection::vec(-1.0..1.0f64, 24), amp in 0.01..0.3f64) {
            for c in ALL_CURVATURES {
                let err = force_error(c, &seed, amp);
                prop_assert!(err < 1e-6, "{c:?}: relative error {err:e}");
            }
        }

        /// A random rigid motion of the reference element gives zero force and energy (relative
        /// to a 1 %-strain state, < 1e-9); of a deformed element it leaves the energy unchanged.
        #[test]
        fn rigid_motion_is_strain_free(axis in proptest::collection::vec(-1.0..1.0f64, 3), angle in -3.1..3.1f64,
                                        shift in proptest::collection::vec(-2.0..2.0f64, 3)) {
            let l = 0.1;
            let axis = Vector3::new(axis[0], axis[1], axis[2]);
            prop_assume!(axis.norm() > 1e-3);
            let rot = Rotation3::from_scaled_axis(axis.normalize() * angle).into_inner();
            let shift = Vector3::new(shift[0], shift[1], shift[2]);
            for c in ALL_CURVATURES {
                let el = Element::new(l, &section(), c, 1.0, 100.0);
                let e0 = apply_rigid(&reference_element(l), &rot, &shift);
                let mut f = [0.0; 24];
                let u = el.add_elastic_force(&e0, &mut f);
                let e1 = deformed(l, &[0.3, -0.2, 0.5, 0.1], 0.01);
                let mut f1 = [0.0; 24];
                let u1 = el.add_elastic_force(&e1, &mut f1);
                let fmax = f.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                let f1max = f1.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                prop_assert!(u.abs() < 1e-9 * u1, "{c:?}: U = {u:e} vs {u1:e}");
                prop_assert!(fmax < 1e-9 * f1max, "{c:?}: |f| = {fmax:e} vs {f1max:e}");
                let u2 = el.elastic_energy(&apply_rigid(&e1, &rot, &shift));
                prop_assert!((u2 - u1).abs() < 1e-9 * u1, "{c:?}: {u2} vs {u1}");
            }
        }
    }

    #[test]
    fn tangent_is_symmetric() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0, 100.0);
            let e = deformed(l, &[0.3, -0.7, 0.2, 0.9, -0.4], 0.2);
            let mut k = ElementMatrix::zeros();
            el.add_elastic_tangent(&e, 1.0, &mut k);
            assert!((k - k.transpose()).amax() < 1e-12 * k.amax());
        }
    }
}
