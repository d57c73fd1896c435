//! Elastic energy, force and analytic tangent of the element (docs/ancf.md §3.6).
//!
//! With the sampled strains `s_k = ½ eᵀ A_k e` (see [`strain`](crate::strain)) and their
//! stiffness-weighted quadrature weights `C_k`:
//!
//! $$ U = \tfrac12 \sum_k C_k (s_k - s_k^0)^2,\qquad
//!    f = \sum_k C_k (s_k - s_k^0)\, A_k e,\qquad
//!    K = \sum_k C_k\big[(A_k e)(A_k e)^T + (s_k - s_k^0) A_k\big]. $$
//!
//! With `A_k = a_k ⊗ I₃` (`a_k` the 8×8 scalar Hessian, a few non-zeros) everything follows from
//! the Gram products `e_a·e_b` of the eight nodal 3-vectors: `s_k = ½ Σ_ab a_k[a][b] e_a·e_b`,
//! `f = (Σ_k C_k (s_k − s_k^0) a_k ⊗ I₃) e`, `A_k e = (a_k ⊗ I₃) e`. The positions are taken
//! relative to the first node (every strain is translation invariant), which keeps the Gram
//! products of the order of the element and the strains accurate far from the origin.
//! No trigonometry, no allocation.
//!
//! The force and tangent kernels are compiled twice, for the baseline x86-64 target and with
//! AVX2 enabled, and the AVX2 copy is chosen at run time when the CPU has it. No FMA is enabled,
//! so both copies do the same IEEE operations in the same order: the results are identical,
//! only the vector width differs.

use crate::element::Element;
use crate::shape::{ELEMENT_DOF, N_BLOCKS};
use crate::strain::{
    MAX_FIELDS, MAX_GROUP, N_STRAINS, SampledStrain, StrainGroup, StrainKind, StrainPlan, dot, strain_value,
};
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

/// The eight nodal 3-vectors of `e` with the first node's position subtracted from both
/// positions (blocks 0 and 4).
#[inline(always)]
fn relative_blocks(e: &[f64]) -> [[f64; 3]; N_BLOCKS] {
    let e = &e[..ELEMENT_DOF];
    let mut b = [[0.0; 3]; N_BLOCKS];
    for (k, bk) in b.iter_mut().enumerate() {
        *bk = [e[3 * k], e[3 * k + 1], e[3 * k + 2]];
    }
    let origin = std::mem::take(&mut b[0]);
    for (x, o) in b[4].iter_mut().zip(origin) {
        *x -= o;
    }
    b
}

/// A quantity of `L` elements evaluated together (one lane per element).
type Lanes<const L: usize> = [f64; L];
/// 8×8 block-level matrix of `L` elements.
type BlockMatrix<const L: usize> = [[Lanes<L>; N_BLOCKS]; N_BLOCKS];
/// 24×24 element matrices of `L` elements, column-major (`m[j][i][l]` is entry (i, j) of
/// element `l`).
pub type LaneMatrix<const L: usize> = [[Lanes<L>; ELEMENT_DOF]; ELEMENT_DOF];

/// Upper triangle of the Gram matrix `e_a·e_b` of the nodal 3-vectors of `L` elements, with the
/// diagonal halved (`½ e_a·e_a`), so that every strain is `s = Σ_{a≤b} h g[a][b]` over its
/// Hessian pairs.
#[inline(always)]
fn gram<const L: usize>(x: &[[[f64; 3]; N_BLOCKS]; L]) -> BlockMatrix<L> {
    let mut g = [[[0.0; L]; N_BLOCKS]; N_BLOCKS];
    for a in 1..N_BLOCKS {
        for l in 0..L {
            g[a][a][l] = 0.5 * dot(&x[l][a], &x[l][a]);
        }
        for c in a + 1..N_BLOCKS {
            for l in 0..L {
                g[a][c][l] = dot(&x[l][a], &x[l][c]);
            }
        }
    }
    g // row and column 0 stay zero: block 0 is the origin of the relative positions
}

/// `s = Σ_{a<b} h e_a·e_b + ½ Σ_a h e_a·e_a` from the Gram products (diagonal halved).
#[inline(always)]
fn strain_from_gram<const L: usize>(s: &SampledStrain, g: &BlockMatrix<L>) -> Lanes<L> {
    let mut v = [0.0; L];
    for &(a, b, h) in &s.pairs[..s.n_pairs] {
        for (vl, gl) in v.iter_mut().zip(&g[a][b]) {
            *vl += h * gl;
        }
    }
    v
}

/// `out = (m ⊗ I₃) x` for symmetric 8×8 `m` given by their upper triangles (the lower ones are
/// overwritten with the mirror image), lane by lane.
#[inline(always)]
fn symmetric_times<const L: usize>(
    m: &mut BlockMatrix<L>,
    x: &[[[f64; 3]; N_BLOCKS]; L],
    out: &mut [[f64; ELEMENT_DOF]; L],
) {
    for (a, c) in (1..N_BLOCKS).flat_map(|a| (0..a).map(move |c| (a, c))) {
        m[a][c] = m[c][a];
    }
    for (l, (xl, ol)) in x.iter().zip(out.iter_mut()).enumerate() {
        for (row, oa) in m.iter().zip(ol.chunks_exact_mut(3)) {
            let mut acc = [0.0; 3];
            for (h, xc) in row.iter().zip(xl) {
                acc[0] += h[l] * xc[0];
                acc[1] += h[l] * xc[1];
                acc[2] += h[l] * xc[2];
            }
            oa.copy_from_slice(&acc);
        }
    }
}

/// The tangent terms of the `M` strains of one group on its `NB` (compact, padded) blocks, for
/// `L` elements in the lanes of every quantity (each lane gets the operations of one element, in
/// the same order whatever `L`):
///
/// 1. the gradients `u_m = (a_m ⊗ I₃) x` on the group's blocks, from the compact Hessians
///    (register accumulators, no scatter), and the strains `s_m = ½ x·u_m`;
/// 2. the geometric weights `c C_m (s_m − s⁰_m)` on the Hessian pairs into `geometric`;
/// 3. the rank-one terms `K_ab += Σ_m c C_m u_m[a] u_m[b]ᵀ`, one 3×3 block `(a, b)` (`a < b`;
///    diagonal blocks `a = b` on and above their diagonal only) at a time with fixed-size loops.
#[inline(always)]
fn add_group_tangent<const M: usize, const NB: usize, const MODE: u8, const L: usize>(
    plan: &StrainPlan,
    group: &StrainGroup,
    x: &[[[f64; 3]; N_BLOCKS]; L],
    c: f64,
    geometric: &mut BlockMatrix<L>,
    cols: &mut LaneMatrix<L>,
) {
    let blocks: [usize; NB] = std::array::from_fn(|i| group.blocks[i]);
    // positions component by component, so that the gradient loops run over the blocks
    let xt: [[Lanes<L>; NB]; 3] = std::array::from_fn(|k| blocks.map(|b| std::array::from_fn(|l| x[l][b][k])));
    let hessians = &plan.group_hessians[group.hessian_start..][..M * NB * NB];
    let mut u = [[[[0.0; L]; 3]; NB]; M]; // ∂s_m/∂x on the group's blocks
    let mut wu = [[[[0.0; L]; 3]; NB]; M]; // c C_m ∂s_m/∂x
    for (m, h) in hessians.chunks_exact(NB * NB).enumerate() {
        let s = &plan.strains[group.members[m]];
        // u_k = a x_k for each component k (a symmetric: row j is column j)
        let mut ut = [[[0.0; L]; NB]; 3];
        for (j, col) in h.chunks_exact(NB).enumerate() {
            for (uk, xk) in ut.iter_mut().zip(&xt) {
                for (ui, aij) in uk.iter_mut().zip(col) {
                    for l in 0..L {
                        ui[l] += aij * xk[j][l];
                    }
                }
            }
        }
        let mut value = [0.0; L]; // s = ½ x·u
        for (i, um) in u[m].iter_mut().enumerate() {
            *um = [ut[0][i], ut[1][i], ut[2][i]];
            for l in 0..L {
                value[l] += 0.5 * (xt[0][i][l] * um[0][l] + xt[1][i][l] * um[1][l] + xt[2][i][l] * um[2][l]);
            }
        }
        let w = c * s.stiffness;
        let mut wd = [0.0; L];
        for l in 0..L {
            let mut d = value[l] - s.reference;
            if MODE != EXACT && newton_drops_geometric(s.kind, d, MODE) {
                d = 0.0;
            }
            wd[l] = w * d;
        }
        for &(a, b, h) in &s.pairs[..s.n_pairs] {
            for l in 0..L {
                geometric[a][b][l] += wd[l] * h;
            }
        }
        for (wv, v) in wu[m].iter_mut().zip(&u[m]) {
            for (wx, x) in wv.iter_mut().zip(v) {
                for l in 0..L {
                    wx[l] = w * x[l];
                }
            }
        }
    }
    for (j, &b) in blocks.iter().enumerate() {
        for (i, &a) in blocks[..j].iter().enumerate() {
            for (jj, col) in cols[3 * b..3 * b + 3].iter_mut().enumerate() {
                let mut acc = [[0.0; L]; 3];
                for m in 0..M {
                    for (ac, ua) in acc.iter_mut().zip(&u[m][i]) {
                        for l in 0..L {
                            ac[l] += wu[m][j][jj][l] * ua[l];
                        }
                    }
                }
                for (k, ac) in col[3 * a..3 * a + 3].iter_mut().zip(acc) {
                    for l in 0..L {
                        k[l] += ac[l];
                    }
                }
            }
        }
        // the diagonal block on and above its diagonal
        for (jj, col) in cols[3 * b..3 * b + 3].iter_mut().enumerate() {
            let mut acc = [[0.0; L]; 3];
            for m in 0..M {
                for (ac, ua) in acc[..=jj].iter_mut().zip(&u[m][j]) {
                    for l in 0..L {
                        ac[l] += wu[m][j][jj][l] * ua[l];
                    }
                }
            }
            for (k, ac) in col[3 * b..=3 * b + jj].iter_mut().zip(acc) {
                for l in 0..L {
                    k[l] += ac[l];
                }
            }
        }
    }
}

/// The exact tangent.
const EXACT: u8 = 0;
/// Newton's matrix of a time step ([`Element::add_newton_tangent_upper`]).
const TIME_STEP: u8 = 1;
/// Newton's matrix at rest ([`Element::add_rest_tangent_upper`]).
const AT_REST: u8 = 2;

/// Whether a tangent of kind `mode` leaves out the geometric term of a strain of this kind at
/// `s − s⁰ = d`. Time step: a section stretch penalty under compression, and the section shear
/// penalty (`r_y·r_z`, whose geometric term is indefinite) always. At rest also the transverse
/// shears (indefinite) always and the axial strain under compression.
#[inline(always)]
fn newton_drops_geometric(kind: StrainKind, d: f64, mode: u8) -> bool {
    match kind {
        StrainKind::SectionYY | StrainKind::SectionZZ => d < 0.0,
        StrainKind::SectionYZ => true,
        StrainKind::ShearY | StrainKind::ShearZ => mode == AT_REST,
        StrainKind::Axial => mode == AT_REST && d < 0.0,
        _ => false,
    }
}

/// Copy the upper triangle onto the strictly lower one.
pub fn mirror_upper_inplace(k: &mut ElementMatrix) {
    let data = k.as_mut_slice(); // column-major: (i, j) at 24 j + i
    for j in 0..ELEMENT_DOF {
        for i in j + 1..ELEMENT_DOF {
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
        let g = gram(&[relative_blocks(e)]);
        self.plan
            .strains
            .iter()
            .map(|s| {
                let d = strain_from_gram(s, &g)[0] - s.reference;
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
        let mut f = [[0.0; ELEMENT_DOF]; 1];
        let [u] = self.elastic_forces([e], &mut f);
        for (o, x) in out[..ELEMENT_DOF].iter_mut().zip(&f[0]) {
            *o += x;
        }
        u
    }

    /// `out[l] = f_el(e[l])`: the elastic forces of `L` elements sharing this kernel, evaluated
    /// together (every loop over the strain plan serves all lanes); returns their energies.
    pub fn elastic_forces<const L: usize>(&self, e: [&[f64]; L], out: &mut [[f64; ELEMENT_DOF]; L]) -> Lanes<L> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.forces_avx2(e, out) };
        }
        self.forces_generic(e, out)
    }

    /// [`Self::elastic_forces`] compiled with AVX2 (see the module documentation).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn forces_avx2<const L: usize>(&self, e: [&[f64]; L], out: &mut [[f64; ELEMENT_DOF]; L]) -> Lanes<L> {
        self.forces_generic(e, out)
    }

    #[inline(always)]
    fn forces_generic<const L: usize>(&self, e: [&[f64]; L], out: &mut [[f64; ELEMENT_DOF]; L]) -> Lanes<L> {
        let x = e.map(relative_blocks);
        let g = gram(&x);
        let mut m = [[[0.0; L]; N_BLOCKS]; N_BLOCKS]; // Σ C (s − s⁰) a, upper triangle
        let mut u = [0.0; L];
        for s in &self.plan.strains {
            let mut cd = strain_from_gram(s, &g);
            for (ul, c) in u.iter_mut().zip(&mut cd) {
                let d = *c - s.reference;
                *ul += 0.5 * s.stiffness * d * d;
                *c = s.stiffness * d;
            }
            for &(a, b, h) in &s.pairs[..s.n_pairs] {
                for (ml, c) in m[a][b].iter_mut().zip(&cd) {
                    *ml += c * h;
                }
            }
        }
        symmetric_times(&mut m, &x, out);
        u
    }

    /// `k += c · K_el(e)`, the analytic elastic tangent of one element.
    pub fn add_elastic_tangent(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        let mut upper = ElementMatrix::zeros();
        self.add_elastic_tangent_upper(e, c, &mut upper);
        mirror_upper_inplace(&mut upper);
        *k += upper;
    }

    /// `k += c · K_el(e)` on the upper triangle (the strictly lower entries are not meaningful
    /// afterwards); [`mirror_upper_inplace`] completes the symmetric matrix, so that it is
    /// exactly symmetric.
    ///
    /// The strains are taken a [`StrainGroup`] (equal block sets) at a time, see
    /// `add_group_tangent`; the geometric terms `C (s − s⁰) a ⊗ I₃` are gathered on the 8×8
    /// block level and added last.
    ///
    /// [`StrainGroup`]: crate::strain::StrainGroup
    pub fn add_elastic_tangent_upper(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        self.add_tangent_upper::<EXACT>(e, c, k)
    }

    /// [`Self::add_elastic_tangent_upper`] for Newton's iteration matrix of a time step
    /// (`c > 0`): the cross-section penalties (docs/ancf.md §3.4) contribute only the positive
    /// semidefinite part of their tangent. The geometric term `c C (s − s⁰) a` of a section
    /// stretch (`ε_yy`, `ε_zz`) is left out where the section is compressed (`s < s⁰`, where it
    /// is negative definite on the slope), and that of the section shear `γ_yz` (indefinite)
    /// always: on the light section slopes such terms can outweigh the inertia in the iteration
    /// matrix and make it near-singular. Every other term is the exact tangent's; the residual is
    /// unchanged, so Newton converges to the same solution.
    pub fn add_newton_tangent_upper(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        self.add_tangent_upper::<TIME_STEP>(e, c, k)
    }

    /// [`Self::add_elastic_tangent_upper`] for Newton's matrix at rest (statics, docs/ancf.md §9):
    /// as [`Self::add_newton_tangent_upper`], and also without the geometric terms of the
    /// transverse shears (indefinite) and of a compressed axial strain. With near-rigid shear and
    /// axial stiffnesses (GA of 1e8–1e9 N) the transient strains of an iterate that turns a body
    /// linearly (a stretch `θ²/2`) make these terms outweigh the bending and hinge stiffness by
    /// orders of magnitude, and Newton's steps wander; at the equilibrium they are the stress
    /// stiffening of the section forces, which are small against the elastic terms kept, so the
    /// iteration still converges, to the same solution.
    pub fn add_rest_tangent_upper(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        self.add_tangent_upper::<AT_REST>(e, c, k)
    }

    #[inline]
    fn add_tangent_upper<const MODE: u8>(&self, e: &[f64], c: f64, k: &mut ElementMatrix) {
        // SAFETY: an `ElementMatrix` stores its 24 × 24 entries column-major in one array,
        // `[[f64; 24]; 24]`, which has the layout of `LaneMatrix<1>`.
        let k = unsafe { &mut *(k.data.0.as_mut_ptr().cast::<LaneMatrix<1>>()) };
        self.add_tangent_upper_lanes::<MODE, 1>([e], c, k)
    }

    /// `k[l] += c · K_el(e[l])` on and above the diagonal (Newton's matrix of a time step, as
    /// [`Self::add_newton_tangent_upper`]) for `L` elements sharing this kernel, evaluated
    /// together: every loop over the strain plan serves all lanes, and each lane gets the same
    /// operations as the single element.
    pub fn add_newton_tangent_upper_lanes<const L: usize>(&self, e: [&[f64]; L], c: f64, k: &mut LaneMatrix<L>) {
        self.add_tangent_upper_lanes::<TIME_STEP, L>(e, c, k)
    }

    #[inline]
    fn add_tangent_upper_lanes<const MODE: u8, const L: usize>(&self, e: [&[f64]; L], c: f64, k: &mut LaneMatrix<L>) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { self.tangent_avx2::<MODE, L>(e, c, k) };
            return;
        }
        self.tangent_generic::<MODE, L>(e, c, k)
    }

    /// [`Self::add_elastic_tangent_upper`] compiled with AVX2 (see the module documentation).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn tangent_avx2<const MODE: u8, const L: usize>(&self, e: [&[f64]; L], c: f64, k: &mut LaneMatrix<L>) {
        self.tangent_generic::<MODE, L>(e, c, k)
    }

    #[inline(always)]
    fn tangent_generic<const MODE: u8, const L: usize>(&self, e: [&[f64]; L], c: f64, cols: &mut LaneMatrix<L>) {
        let x = e.map(relative_blocks);
        let mut geometric = [[[0.0; L]; N_BLOCKS]; N_BLOCKS]; // Σ c C (s − s⁰) a, upper triangle
        for group in &self.plan.groups {
            let (plan, g) = (&self.plan, &mut geometric);
            macro_rules! members {
                ($nb:literal) => {
                    match group.n_members {
                        1 => add_group_tangent::<1, $nb, MODE, L>(plan, group, &x, c, g, cols),
                        2 => add_group_tangent::<2, $nb, MODE, L>(plan, group, &x, c, g, cols),
                        3 => add_group_tangent::<3, $nb, MODE, L>(plan, group, &x, c, g, cols),
                        _ => add_group_tangent::<MAX_GROUP, $nb, MODE, L>(plan, group, &x, c, g, cols),
                    }
                };
            }
            match group.n_blocks {
                1 => members!(1),
                2 => members!(2),
                4 => members!(4),
                6 => members!(6),
                _ => members!(8),
            }
        }
        for b in 0..N_BLOCKS {
            for a in 0..=b {
                let x = geometric[a][b];
                for i in 0..3 {
                    let k = &mut cols[3 * b + i][3 * a + i];
                    for l in 0..L {
                        // a zero weight adds nothing (not even to the sign of a zero entry)
                        if x[l] != 0.0 {
                            k[l] += x[l];
                        }
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
            cg_offset: [0.0; 2],
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
        let el = Element::new(l, &section(), curvature, 1.0);
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
        let el = Element::new(l, &section(), curvature, 1.0);
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
                let el = Element::new(l, &section(), c, 1.0);
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

    /// The Gram-product strains equal the field-product definition (`elastic_energy_by_kind`
    /// evaluates the fields), and a far translation changes neither energy nor force.
    #[test]
    fn gram_strains_match_fields_and_translation() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0);
            let e = deformed(l, &[0.3, -0.7, 0.2, 0.9, -0.4], 0.05);
            let u = el.elastic_energy(&e);
            let by_kind: f64 = el.elastic_energy_by_kind(&e).iter().sum();
            approx::assert_relative_eq!(u, by_kind, max_relative = 1e-11);
            let far = apply_rigid(&e, &Matrix3::identity(), &Vector3::new(1.0e3, -2.0e3, 5.0e2));
            approx::assert_relative_eq!(el.elastic_energy(&far), u, max_relative = 1e-11);
            let (mut f, mut f_far) = ([0.0; 24], [0.0; 24]);
            el.add_elastic_force(&e, &mut f);
            el.add_elastic_force(&far, &mut f_far);
            let fmax = f.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            for (a, b) in f.iter().zip(&f_far) {
                assert!((a - b).abs() <= 1e-10 * fmax, "{c:?}: {a} vs {b}");
            }
        }
    }

    /// Four elements evaluated together give each element's force and energy exactly.
    #[test]
    fn lanes_equal_single_elements() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0);
            let es: Vec<[f64; 24]> =
                (0..4).map(|k| deformed(l, &[0.3, -0.7, 0.2 * k as f64, 0.9, -0.4 + 0.1 * k as f64], 0.1)).collect();
            let mut f = [[0.0; 24]; 4];
            let u = el.elastic_forces([&es[0][..], &es[1], &es[2], &es[3]], &mut f);
            for (k, e) in es.iter().enumerate() {
                let mut single = [0.0; 24];
                let u1 = el.add_elastic_force(e, &mut single);
                assert_eq!(u[k], u1, "{c:?} lane {k}");
                assert_eq!(f[k], single, "{c:?} lane {k}");
            }
        }
    }

    /// The run-time-dispatched kernels (AVX2 where the CPU has it) equal the baseline-compiled
    /// ones bit for bit.
    #[test]
    fn dispatched_kernels_equal_baseline_kernels() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0);
            let es: Vec<[f64; 24]> =
                (0..4).map(|k| deformed(l, &[0.3, -0.7, 0.2 * k as f64, 0.9, -0.4 + 0.1 * k as f64], 0.1)).collect();
            let e: [&[f64]; 4] = std::array::from_fn(|k| &es[k][..]);
            let (mut f, mut f_base) = ([[0.0; 24]; 4], [[0.0; 24]; 4]);
            assert_eq!(el.elastic_forces(e, &mut f), el.forces_generic(e, &mut f_base), "{c:?}");
            assert_eq!(f, f_base, "{c:?}");
            let as_lanes = |k: &ElementMatrix| -> LaneMatrix<1> { k.data.0.map(|col| col.map(|x| [x])) };
            let (mut k, mut k_base) = (ElementMatrix::zeros(), [[[0.0; 1]; 24]; 24]);
            el.add_elastic_tangent_upper(&es[1], 0.7, &mut k);
            el.tangent_generic::<EXACT, 1>([&es[1]], 0.7, &mut k_base);
            assert_eq!(as_lanes(&k), k_base, "{c:?}");
            let (mut k, mut k_base) = (ElementMatrix::zeros(), [[[0.0; 1]; 24]; 24]);
            el.add_newton_tangent_upper(&es[1], 0.7, &mut k);
            el.tangent_generic::<TIME_STEP, 1>([&es[1]], 0.7, &mut k_base);
            assert_eq!(as_lanes(&k), k_base, "{c:?}");
        }
    }

    /// Newton's tangent of four elements in lanes equals the four single-element tangents bit
    /// for bit, added to what the matrices held.
    #[test]
    fn tangent_lanes_equal_single_elements() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0);
            let es: Vec<[f64; 24]> =
                (0..4).map(|k| deformed(l, &[0.3, -0.7, 0.2 * k as f64, 0.9, -0.4 + 0.1 * k as f64], 0.1)).collect();
            let e: [&[f64]; 4] = std::array::from_fn(|k| &es[k][..]);
            let start = |l: usize, i: usize, j: usize| if i == j { 1.5 + l as f64 } else { 0.0 };
            let mut lanes: LaneMatrix<4> =
                std::array::from_fn(|j| std::array::from_fn(|i| std::array::from_fn(|l| start(l, i, j))));
            el.add_newton_tangent_upper_lanes(e, 0.7, &mut lanes);
            for (l, el_e) in es.iter().enumerate() {
                let mut k = ElementMatrix::from_fn(|i, j| start(l, i, j));
                el.add_newton_tangent_upper(el_e, 0.7, &mut k);
                for j in 0..24 {
                    for i in 0..24 {
                        assert_eq!(lanes[j][i][l].to_bits(), k[(i, j)].to_bits(), "{c:?} lane {l} ({i}, {j})");
                    }
                }
            }
        }
    }

    #[test]
    fn tangent_is_symmetric() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0);
            let e = deformed(l, &[0.3, -0.7, 0.2, 0.9, -0.4], 0.2);
            let mut k = ElementMatrix::zeros();
            el.add_elastic_tangent(&e, 1.0, &mut k);
            assert!((k - k.transpose()).amax() < 1e-12 * k.amax());
        }
    }

    /// Newton's tangent leaves out only geometric terms of the section penalties: it differs
    /// from the exact tangent on the `r_y`, `r_z` blocks of a node only, by the section shear's
    /// coupling of `r_y` and `r_z` component by component, and, on compressed sections only, by
    /// a non-negative diagonal.
    #[test]
    fn newton_tangent_drops_only_section_penalty_geometric_terms() {
        let l = 0.1;
        for curvature in ALL_CURVATURES {
            let el = Element::new(l, &section(), curvature, 1.0);
            for (scale, compressed) in [(1.01, false), (0.99, true)] {
                let mut e = deformed(l, &[0.3, -0.7, 0.2, 0.5, -0.1], 1e-3);
                for node in 0..2 {
                    for x in &mut e[12 * node + 6..12 * node + 12] {
                        *x *= scale; // r_y, r_z
                    }
                }
                let (mut exact, mut newton) = (ElementMatrix::zeros(), ElementMatrix::zeros());
                el.add_elastic_tangent_upper(&e, 0.7, &mut exact);
                el.add_newton_tangent_upper(&e, 0.7, &mut newton);
                let d = newton - exact;
                let (mut diagonal, mut shear) = (0.0_f64, 0.0_f64);
                for j in 0..ELEMENT_DOF {
                    for i in 0..=j {
                        let x = d[(i, j)];
                        let section = i / 12 == j / 12 && i % 12 >= 6 && j % 12 >= 6;
                        if section && i == j {
                            assert!(x >= 0.0, "{curvature:?} ({i}, {j}): {x}");
                            diagonal = diagonal.max(x);
                        } else if section && j - i == 3 {
                            shear = shear.max(x.abs());
                        } else {
                            assert_eq!(x, 0.0, "{curvature:?} ({i}, {j})");
                        }
                    }
                }
                assert!(shear > 0.0, "{curvature:?}: the section shear term must be left out");
                assert_eq!(diagonal > 0.0, compressed, "{curvature:?}: stretch terms left out iff compressed");
            }
        }
    }

    /// The upper-triangle kernel leaves the strictly lower triangle alone (the padding blocks
    /// of a group add exact zeros there), and the mirrored tangent is symmetric bit for bit.
    #[test]
    fn upper_kernel_fills_only_the_upper_triangle() {
        let l = 0.2;
        for c in ALL_CURVATURES {
            let el = Element::new(l, &section(), c, 1.0);
            let e = deformed(l, &[0.3, -0.7, 0.2, 0.9, -0.4], 0.2);
            let mut full = ElementMatrix::zeros();
            el.add_elastic_tangent(&e, 1.0, &mut full);
            assert_eq!(full, full.transpose(), "{c:?}");
            let mut k = ElementMatrix::from_fn(|i, j| if i > j { f64::NAN } else { 0.0 });
            el.add_elastic_tangent_upper(&e, 1.0, &mut k);
            for j in 0..ELEMENT_DOF {
                for i in 0..ELEMENT_DOF {
                    if i > j {
                        assert!(k[(i, j)].is_nan(), "{c:?} ({i}, {j})");
                    } else {
                        assert_eq!(k[(i, j)], full[(i, j)], "{c:?} ({i}, {j})");
                    }
                }
            }
        }
    }
}
