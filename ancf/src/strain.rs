//! Strain measures of the element and where they are sampled (docs/ancf.md §3).
//!
//! Every strain is a quadratic form of the element coordinates: a sum of dot products of
//! interpolated *fields* (axis tangent `r_x`, `r_xx`, section slopes `r_y`, `r_z`, their
//! x-derivatives, the chord `(r² − r¹)/l`, each at some ξ), `s = Σ_t c_t f_{t1}·f_{t2}`, i.e.
//! `s = ½ eᵀ A e` with a constant `A = a ⊗ I₃`. Reference values (straight, unstrained body)
//! are subtracted.
//!
//! | kind | measure | stiffness |
//! |---|---|---|
//! | axial ε | ½ r_x·r_x | EA |
//! | shear γ_y, γ_z | r_x·r_y, r_x·r_z | GA_y, GA_z |
//! | twist K1 | ½(r_z·r_y,x − r_y·r_z,x) | GJ |
//! | bending K2, K3 | see [`Curvature`] | EI_yy, EI_zz |
//! | section ε_yy, ε_zz | ½ r_y·r_y, ½ r_z·r_z | p·EA |
//! | section γ_yz | r_y·r_z | p·(GA_y + GA_z) |
//!
//! **Bending** ([`Curvature::Hybrid`], the default):
//!
//! $$ K_2(\xi) = \bar r_x\cdot r_{z,x} - r_z\cdot r_{xx}(\xi) + \langle r_z\cdot r_{xx}\rangle,\qquad
//!    K_3(\xi) = -\bar r_x\cdot r_{y,x} + r_y\cdot r_{xx}(\xi) - \langle r_y\cdot r_{xx}\rangle $$
//!
//! with the chord `r̄_x = (r² − r¹)/l` (the element mean of `r_x`) and `⟨·⟩` the element mean
//! (2-point Gauss, exact). The element-mean curvature comes from the rotation of the sections,
//! so a joint that holds a section (clamp, hinge axis on `r_y`) takes the bending moment
//! directly; the zero-mean linear variation comes from the cubic centreline, so states of
//! linearly varying curvature (tip loads) are represented exactly. When `F = [r_x r_y r_z]` is a
//! rotation the two parts agree and `K` is the exact curvature of the skew part of `FᵀF_x`.
//! Transverse shear at the nodes ties the sections to the centreline: for a cubic centreline
//! with linearly varying curvature the linear section field that matches the centreline slope at
//! the nodes is continuous from element to element, so there is no shear locking.
//!
//! The alternatives [`Curvature::Kirchhoff`] (`K2 = −r_z·r_xx`, `K3 = r_y·r_xx`, shear at the
//! nodes) and [`Curvature::Mixed`] (`½(r_x·r_z,x − r_z·r_xx)`, … , shear at the midpoint)
//! carry the bending moment wholly or half in the centreline, which reaches a joint holding the
//! section only through shear over half an element: a spurious joint compliance `∝ 1/(GA l)`
//! that grows as the mesh is refined. They are kept for comparison.
//!
//! **Locking.** Axial strain and curvature use 3-point Gauss quadrature, the twist (linear in ξ)
//! 2-point Gauss, both exact or nearly so. The section
//! penalties are sampled at the nodes only (trapezoidal rule): linearly interpolated rotated
//! unit slopes shorten between the nodes, and penalising that would lock
//! (curvature-thickness locking).

use crate::Curvature;
use crate::Section;
use crate::shape::{Field, FieldWeights, N_BLOCKS, field_weights};

/// The nine strain kinds, in the order of [`StrainKind::ALL`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrainKind {
    /// Axial strain ε.
    Axial = 0,
    /// Transverse shear γ_y.
    ShearY = 1,
    /// Transverse shear γ_z.
    ShearZ = 2,
    /// Twist K1.
    Twist = 3,
    /// Bending curvature about y, K2.
    BendY = 4,
    /// Bending curvature about z, K3.
    BendZ = 5,
    /// Section stretch along y (penalty).
    SectionYY = 6,
    /// Section stretch along z (penalty).
    SectionZZ = 7,
    /// Section in-plane shear (penalty).
    SectionYZ = 8,
}

/// Number of strain kinds.
pub const N_STRAINS: usize = 9;

/// Upper bound of distinct fields per element.
pub const MAX_FIELDS: usize = 32;
/// Upper bound of terms per strain.
pub const MAX_TERMS: usize = 4;
/// Entries of the upper triangle of an 8×8 block Hessian.
pub const MAX_PAIRS: usize = N_BLOCKS * (N_BLOCKS + 1) / 2;
/// Upper bound of strains per [`StrainGroup`].
pub const MAX_GROUP: usize = 4;

impl StrainKind {
    /// All kinds in index order.
    pub const ALL: [StrainKind; N_STRAINS] = [
        StrainKind::Axial,
        StrainKind::ShearY,
        StrainKind::ShearZ,
        StrainKind::Twist,
        StrainKind::BendY,
        StrainKind::BendZ,
        StrainKind::SectionYY,
        StrainKind::SectionZZ,
        StrainKind::SectionYZ,
    ];

    /// Whether this is an artificial term (the cross-section penalties), with no beam-theory
    /// counterpart.
    pub fn is_penalty(self) -> bool {
        matches!(self, StrainKind::SectionYY | StrainKind::SectionZZ | StrainKind::SectionYZ)
    }

    /// The stiffness of this strain for a section, with the penalty factor `penalty_factor`
    /// (section penalties) applied.
    pub fn stiffness(self, s: &Section, penalty_factor: f64) -> f64 {
        match self {
            StrainKind::Axial => s.ea,
            StrainKind::ShearY => s.ga_y,
            StrainKind::ShearZ => s.ga_z,
            StrainKind::Twist => s.gj,
            StrainKind::BendY => s.ei_yy,
            StrainKind::BendZ => s.ei_zz,
            StrainKind::SectionYY | StrainKind::SectionZZ => penalty_factor * s.ea,
            StrainKind::SectionYZ => penalty_factor * (s.ga_y + s.ga_z),
        }
    }
}

/// One strain sampled at one integration point: `s = Σ c f_a·f_b` over its terms.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledStrain {
    /// Which strain.
    pub kind: StrainKind,
    /// ξ of the integration point.
    pub xi: f64,
    /// Number of used terms.
    pub n_terms: usize,
    /// Terms `(c, field a, field b)` (indices into [`StrainPlan::fields`]).
    pub terms: [(f64, usize, usize); MAX_TERMS],
    /// Stiffness × quadrature weight × l, so that `U = ½ Σ stiffness (s − reference)²`.
    pub stiffness: f64,
    /// Value in the reference configuration.
    pub reference: f64,
    /// The 8×8 scalar Hessian `a` (`∂²s/∂e∂e = a ⊗ I₃`).
    pub hessian: [[f64; N_BLOCKS]; N_BLOCKS],
    /// Number of blocks the strain depends on.
    pub n_blocks: usize,
    /// The blocks the strain depends on (first `n_blocks` entries).
    pub blocks: [usize; N_BLOCKS],
    /// Number of non-zero entries of the upper triangle of `hessian`.
    pub n_pairs: usize,
    /// The non-zero upper-triangle entries `(a, b, hessian[a][b])`, `a ≤ b` (first `n_pairs`):
    /// `s = Σ_{a<b} h (e_a·e_b) + ½ Σ_a h (e_a·e_a)` and `∂s/∂e_a = Σ_b hessian[a][b] e_b`.
    pub pairs: [(usize, usize, f64); MAX_PAIRS],
}

impl SampledStrain {
    /// The used terms.
    #[inline]
    pub fn terms(&self) -> &[(f64, usize, usize)] {
        &self.terms[..self.n_terms]
    }
}

/// Strains that depend on the same blocks (e.g. the axial strain at its three Gauss points):
/// the tangent adds their rank-one terms `C (A e)(A e)ᵀ` in one pass over the element matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StrainGroup {
    /// Number of members.
    pub n_members: usize,
    /// Indices into [`StrainPlan::strains`] (first `n_members`).
    pub members: [usize; MAX_GROUP],
    /// Number of blocks of the compact block set, padded to one of 1, 2, 4, 6, 8 (the sizes the
    /// tangent kernel is compiled for).
    pub n_blocks: usize,
    /// The compact block set: the members' blocks ascending, then the last one repeated as
    /// padding (first `n_blocks` entries).
    pub blocks: [usize; N_BLOCKS],
    /// Start of the members' compact Hessians in [`StrainPlan::group_hessians`]: member `m`'s
    /// `n_blocks × n_blocks` row-major block `hessian[blocks[i]][blocks[j]]` (zero on padding).
    pub hessian_start: usize,
}

impl StrainGroup {
    /// The member strain indices.
    #[inline]
    pub fn members(&self) -> &[usize] {
        &self.members[..self.n_members]
    }
}

/// The fields an element needs and the strains sampled from them.
#[derive(Debug, Clone, PartialEq)]
pub struct StrainPlan {
    /// Distinct interpolated fields.
    pub fields: Vec<FieldWeights>,
    /// Sampled strains.
    pub strains: Vec<SampledStrain>,
    /// The strains partitioned into groups with equal block sets (at most [`MAX_GROUP`] each),
    /// in the order of their first member.
    pub groups: Vec<StrainGroup>,
    /// The compact Hessians of the groups' members (see [`StrainGroup::hessian_start`]).
    pub group_hessians: Vec<f64>,
}

/// Partition strains into groups with equal block sets, at most [`MAX_GROUP`] per group, and
/// lay out their compact Hessians.
fn group_strains(strains: &[SampledStrain]) -> (Vec<StrainGroup>, Vec<f64>) {
    let mut groups: Vec<StrainGroup> = Vec::new();
    for (i, s) in strains.iter().enumerate() {
        let same = |g: &&mut StrainGroup| {
            let t = &strains[g.members[0]];
            g.n_members < MAX_GROUP && t.blocks[..t.n_blocks] == s.blocks[..s.n_blocks]
        };
        match groups.iter_mut().find(same) {
            Some(g) => {
                g.members[g.n_members] = i;
                g.n_members += 1;
            }
            None => {
                let n = s.n_blocks.max(1);
                let n_blocks = if matches!(n, 1 | 2 | 4 | 6 | 8) { n } else { n + 1 };
                let mut blocks = s.blocks;
                for k in n..n_blocks {
                    blocks[k] = blocks[n - 1];
                }
                groups.push(StrainGroup { n_members: 1, members: [i, 0, 0, 0], n_blocks, blocks, hessian_start: 0 })
            }
        }
    }
    let mut hessians = Vec::new();
    for g in &mut groups {
        g.hessian_start = hessians.len();
        let real = strains[g.members[0]].n_blocks;
        for &m in g.members() {
            let h = &strains[m].hessian;
            for i in 0..g.n_blocks {
                for j in 0..g.n_blocks {
                    let inside = i < real && j < real;
                    hessians.push(if inside { h[g.blocks[i]][g.blocks[j]] } else { 0.0 });
                }
            }
        }
    }
    (groups, hessians)
}

/// Element coordinates of a straight, unstrained element of length `l` along the x axis whose
/// sections are twisted about it by `theta0` at its first node and `theta1` at its second, rad
/// (the twisted reference of docs/ancf.md §1; slopes `r_y = R_x(θ) e_y`, `r_z = R_x(θ) e_z`).
pub fn twisted_reference_element(l: f64, theta0: f64, theta1: f64) -> [f64; 24] {
    let mut e = reference_element(l);
    for (n, theta) in [theta0, theta1].into_iter().enumerate() {
        let (s, c) = theta.sin_cos();
        e[12 * n + 6..12 * n + 12].copy_from_slice(&[0.0, c, s, 0.0, -s, c]);
    }
    e
}

impl StrainPlan {
    /// The same plan with every strain's reference value taken from the element coordinates
    /// `e0` (a twisted reference, [`twisted_reference_element`]): the element is then free of
    /// stress in the configuration `e0`.
    pub fn with_reference(&self, e0: &[f64]) -> StrainPlan {
        let f0: Vec<[f64; 3]> = self.fields.iter().map(|f| f.eval(e0)).collect();
        let mut plan = self.clone();
        for s in &mut plan.strains {
            s.reference = strain_value(s, &f0);
        }
        plan
    }
}

/// Element coordinates of a straight, unstrained element of length `l` along the global x axis.
pub fn reference_element(l: f64) -> [f64; 24] {
    let mut e = [0.0; 24];
    e[12] = l;
    for n in 0..2 {
        e[12 * n + 3] = 1.0;
        e[12 * n + 7] = 1.0;
        e[12 * n + 11] = 1.0;
    }
    e
}

#[inline]
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Value of a strain from evaluated fields.
#[inline]
pub fn strain_value(s: &SampledStrain, f: &[[f64; 3]]) -> f64 {
    s.terms().iter().map(|&(c, a, b)| c * dot(&f[a], &f[b])).sum()
}

struct Builder {
    l: f64,
    fields: Vec<FieldWeights>,
    strains: Vec<SampledStrain>,
}

impl Builder {
    fn intern(&mut self, w: FieldWeights) -> usize {
        if let Some(i) = self.fields.iter().position(|f| f.dense() == w.dense()) {
            return i;
        }
        self.fields.push(w);
        assert!(self.fields.len() <= MAX_FIELDS, "too many fields per element");
        self.fields.len() - 1
    }
    fn at(&mut self, f: Field, xi: f64) -> usize {
        let w = field_weights(xi, self.l)[f as usize];
        self.intern(w)
    }
    /// `2 (r² − r¹)/l − ½ (r¹_x + r²_x)`: the element-mean axis tangent, corrected so that
    /// its product with the linearly interpolated section gradient measures the curvature of a
    /// circular arc to O(Δ⁴) (Δ = rotation across the element) instead of O(Δ²).
    fn mean_tangent(&mut self) -> usize {
        let l = self.l;
        self.intern(FieldWeights::new(&[(0, -2.0 / l), (1, -0.5), (4, 2.0 / l), (5, -0.5)]))
    }
    fn push(
        &mut self,
        kind: StrainKind,
        xi: f64,
        weight: f64,
        terms: &[(f64, usize, usize)],
        section: &Section,
        pf: f64,
    ) {
        assert!(terms.len() <= MAX_TERMS);
        let mut t = [(0.0, 0, 0); MAX_TERMS];
        t[..terms.len()].copy_from_slice(terms);
        let mut hessian = [[0.0; N_BLOCKS]; N_BLOCKS];
        for &(c, fa, fb) in terms {
            let (wa, wb) = (self.fields[fa].dense(), self.fields[fb].dense());
            for a in 0..N_BLOCKS {
                for b in 0..N_BLOCKS {
                    hessian[a][b] += c * (wa[a] * wb[b] + wb[a] * wa[b]);
                }
            }
        }
        let mut used = [false; N_BLOCKS];
        for &(_, fa, fb) in terms {
            for f in [fa, fb] {
                let w = &self.fields[f];
                for k in 0..w.n {
                    used[w.block[k]] = true;
                }
            }
        }
        let mut blocks = [0; N_BLOCKS];
        let mut n_blocks = 0;
        for (b, u) in used.iter().enumerate() {
            if *u {
                blocks[n_blocks] = b;
                n_blocks += 1;
            }
        }
        let mut pairs = [(0, 0, 0.0); MAX_PAIRS];
        let mut n_pairs = 0;
        for (a, row) in hessian.iter().enumerate() {
            for (b, &h) in row.iter().enumerate().skip(a) {
                if h != 0.0 {
                    pairs[n_pairs] = (a, b, h);
                    n_pairs += 1;
                }
            }
        }
        self.strains.push(SampledStrain {
            kind,
            xi,
            n_terms: terms.len(),
            terms: t,
            stiffness: kind.stiffness(section, pf) * weight * self.l,
            reference: 0.0,
            hessian,
            n_blocks,
            blocks,
            n_pairs,
            pairs,
        });
    }
}

/// The strain plan of an element of length `l` (docs/ancf.md §3, see the module documentation).
pub fn strain_plan(l: f64, section: &Section, curvature: Curvature, penalty_factor: f64) -> StrainPlan {
    use Field::*;
    use StrainKind::*;
    let pf = penalty_factor;
    let mut bld = Builder { l, fields: Vec::new(), strains: Vec::new() };
    let g3 = 0.5 * (0.6f64).sqrt();
    let gauss3 = [(0.5 - g3, 5.0 / 18.0), (0.5, 8.0 / 18.0), (0.5 + g3, 5.0 / 18.0)];
    let g2 = 0.5 / 3f64.sqrt();
    let gauss2 = [0.5 - g2, 0.5 + g2];
    let (yx, zx) = (bld.at(YX, 0.5), bld.at(ZX, 0.5));
    let chord = bld.mean_tangent();
    // element means ⟨r_z·r_xx⟩, ⟨r_y·r_xx⟩ by 2-point Gauss: (½, z, xx) pairs.
    let mean_terms: Vec<(usize, usize, usize)> =
        gauss2.iter().map(|&xi| (bld.at(Z, xi), bld.at(Y, xi), bld.at(XX, xi))).collect();

    for (xi, w) in gauss3 {
        let (x, xx, y, z) = (bld.at(X, xi), bld.at(XX, xi), bld.at(Y, xi), bld.at(Z, xi));
        bld.push(Axial, xi, w, &[(0.5, x, x)], section, pf);
        match curvature {
            Curvature::Hybrid => {
                let (m0, m1) = (mean_terms[0], mean_terms[1]);
                bld.push(
                    BendY,
                    xi,
                    w,
                    &[(1.0, chord, zx), (-1.0, z, xx), (0.5, m0.0, m0.2), (0.5, m1.0, m1.2)],
                    section,
                    pf,
                );
                bld.push(
                    BendZ,
                    xi,
                    w,
                    &[(-1.0, chord, yx), (1.0, y, xx), (-0.5, m0.1, m0.2), (-0.5, m1.1, m1.2)],
                    section,
                    pf,
                );
            }
            Curvature::Kirchhoff => {
                bld.push(BendY, xi, w, &[(-1.0, z, xx)], section, pf);
                bld.push(BendZ, xi, w, &[(1.0, y, xx)], section, pf);
            }
            Curvature::Mixed => {
                bld.push(BendY, xi, w, &[(0.5, x, zx), (-0.5, z, xx)], section, pf);
                bld.push(BendZ, xi, w, &[(0.5, y, xx), (-0.5, x, yx)], section, pf);
            }
        }
    }
    // K1 is linear in ξ (linear sections, constant derivatives): 2-point Gauss is exact.
    for xi in gauss2 {
        let (y, z) = (bld.at(Y, xi), bld.at(Z, xi));
        bld.push(Twist, xi, 0.5, &[(0.5, z, yx), (-0.5, y, zx)], section, pf);
    }
    let shear_points: Vec<(f64, f64)> = match curvature {
        Curvature::Hybrid | Curvature::Kirchhoff => vec![(0.0, 0.5), (1.0, 0.5)],
        Curvature::Mixed => vec![(0.5, 1.0)],
    };
    for (xi, w) in shear_points {
        let (x, y, z) = (bld.at(X, xi), bld.at(Y, xi), bld.at(Z, xi));
        bld.push(ShearY, xi, w, &[(1.0, x, y)], section, pf);
        bld.push(ShearZ, xi, w, &[(1.0, x, z)], section, pf);
    }
    for xi in [0.0, 1.0] {
        let (y, z) = (bld.at(Y, xi), bld.at(Z, xi));
        bld.push(SectionYY, xi, 0.5, &[(0.5, y, y)], section, pf);
        bld.push(SectionZZ, xi, 0.5, &[(0.5, z, z)], section, pf);
        bld.push(SectionYZ, xi, 0.5, &[(1.0, y, z)], section, pf);
    }
    let e0 = reference_element(l);
    let f0: Vec<[f64; 3]> = bld.fields.iter().map(|f| f.eval(&e0)).collect();
    for s in &mut bld.strains {
        s.reference = strain_value(s, &f0);
    }
    let (groups, group_hessians) = group_strains(&bld.strains);
    StrainPlan { fields: bld.fields, strains: bld.strains, groups, group_hessians }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn section() -> Section {
        Section {
            mass: 1.0,
            rho_ixx: 2e-3,
            rho_iyy: 1e-3,
            rho_izz: 1e-3,
            ea: 1e6,
            ga_y: 4e5,
            ga_z: 3e5,
            gj: 50.0,
            ei_yy: 80.0,
            ei_zz: 120.0,
            cg_offset: [0.0; 2],
        }
    }

    const ALL_CURVATURES: [Curvature; 3] = [Curvature::Hybrid, Curvature::Kirchhoff, Curvature::Mixed];

    #[test]
    fn quadrature_weights_sum_to_the_length() {
        let l = 0.3;
        for curvature in ALL_CURVATURES {
            let plan = strain_plan(l, &section(), curvature, 1.0);
            let mut sum = [0.0; N_STRAINS];
            for s in &plan.strains {
                sum[s.kind as usize] += s.stiffness / s.kind.stiffness(&section(), 1.0);
            }
            for v in sum {
                assert_relative_eq!(v, l, epsilon = 1e-14);
            }
        }
    }

    #[test]
    fn reference_values_are_those_of_unit_orthonormal_slopes() {
        for curvature in ALL_CURVATURES {
            for s in &strain_plan(0.4, &section(), curvature, 1.0).strains {
                let expect = match s.kind {
                    StrainKind::Axial | StrainKind::SectionYY | StrainKind::SectionZZ => 0.5,
                    _ => 0.0,
                };
                assert_relative_eq!(s.reference, expect, epsilon = 1e-13);
            }
        }
    }

    #[test]
    fn groups_partition_the_strains_by_block_set() {
        for curvature in ALL_CURVATURES {
            let plan = strain_plan(0.4, &section(), curvature, 1.0);
            let mut seen = vec![0; plan.strains.len()];
            for g in &plan.groups {
                assert!((1..=MAX_GROUP).contains(&g.n_members));
                let first = &plan.strains[g.members[0]];
                for &m in g.members() {
                    seen[m] += 1;
                    let s = &plan.strains[m];
                    assert_eq!(s.blocks[..s.n_blocks], first.blocks[..first.n_blocks]);
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{curvature:?}: {seen:?}");
        }
        // Hybrid: the three axial Gauss points share blocks {0, 1, 4, 5}.
        let plan = strain_plan(0.4, &section(), Curvature::Hybrid, 1.0);
        let axial: Vec<usize> =
            (0..plan.strains.len()).filter(|&i| plan.strains[i].kind == StrainKind::Axial).collect();
        assert!(plan.groups.iter().any(|g| g.members() == axial.as_slice()));
    }

    #[test]
    fn group_hessians_are_the_members_hessians_on_the_compact_blocks() {
        for curvature in ALL_CURVATURES {
            let plan = strain_plan(0.4, &section(), curvature, 1.0);
            for g in &plan.groups {
                let nb = g.n_blocks;
                assert!(matches!(nb, 1 | 2 | 4 | 6 | 8), "{curvature:?}: {nb} blocks");
                let real = plan.strains[g.members[0]].n_blocks;
                assert_eq!(g.blocks[..real], plan.strains[g.members[0]].blocks[..real]);
                assert!(g.blocks[real..nb].iter().all(|&b| b == g.blocks[real - 1]));
                for (m, &member) in g.members().iter().enumerate() {
                    let h = &plan.group_hessians[g.hessian_start + m * nb * nb..][..nb * nb];
                    for i in 0..nb {
                        for j in 0..nb {
                            let expect = if i < real && j < real {
                                plan.strains[member].hessian[g.blocks[i]][g.blocks[j]]
                            } else {
                                0.0
                            };
                            assert_eq!(h[i * nb + j], expect, "{curvature:?} member {member} ({i}, {j})");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn hessian_reproduces_the_quadratic_form() {
        // s(e) = ½ eᵀ (a ⊗ I₃) e for every sampled strain, at an arbitrary e.
        let e: [f64; 24] = std::array::from_fn(|i| ((i * 7 + 3) % 11) as f64 * 0.1 - 0.4);
        for curvature in ALL_CURVATURES {
            let plan = strain_plan(0.7, &section(), curvature, 1.0);
            let f: Vec<[f64; 3]> = plan.fields.iter().map(|w| w.eval(&e)).collect();
            for s in &plan.strains {
                let mut q = 0.0;
                for a in 0..8 {
                    for b in 0..8 {
                        for i in 0..3 {
                            q += 0.5 * e[3 * a + i] * s.hessian[a][b] * e[3 * b + i];
                        }
                    }
                }
                assert_relative_eq!(q, strain_value(s, &f), epsilon = 1e-12, max_relative = 1e-12);
            }
        }
    }

    #[test]
    fn hybrid_curvature_is_exact_for_a_cubic_deflection() {
        // Small deflection w(x) = a x³ along z with the sections following the nodal slopes
        // (zero nodal shear): K2 = −w'' = −6 a x at every Gauss point, although the linear
        // sections cannot follow the quadratic slope in between.
        let (l, a) = (0.5, 1e-3);
        let plan = strain_plan(l, &section(), Curvature::Hybrid, 1.0);
        let w1 = |x: f64| 3.0 * a * x * x;
        let mut e = reference_element(l);
        e[3 + 2] = w1(0.0);
        e[9] = -w1(0.0); // r_z tilts toward −x when the axis slopes up
        e[12 + 2] = a * l * l * l;
        e[15 + 2] = w1(l);
        e[21] = -w1(l);
        let f: Vec<[f64; 3]> = plan.fields.iter().map(|w| w.eval(&e)).collect();
        let bend: Vec<_> = plan.strains.iter().filter(|s| s.kind == StrainKind::BendY).collect();
        assert_eq!(bend.len(), 3);
        for s in bend {
            assert_relative_eq!(strain_value(s, &f) - s.reference, -6.0 * a * s.xi * l, epsilon = 1e-12);
        }
        for s in plan.strains.iter().filter(|s| s.kind == StrainKind::ShearZ) {
            assert_relative_eq!(strain_value(s, &f), 0.0, epsilon = 1e-12);
        }
    }
}
