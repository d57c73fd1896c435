//! Strain measures of the element and where they are sampled (THEORY §A.3).
//!
//! Every strain is a quadratic form of the element coordinates, a sum of dot products of the
//! [`Field`]s: `s_k = Σ_t c_t f_{t1}·f_{t2}`, i.e. `s_k = ½ eᵀ A_k e` with the constant
//! `A_k = a_k ⊗ I₃`. Reference values (straight, unstrained body) are subtracted.
//!
//! | kind | measure | stiffness |
//! |---|---|---|
//! | axial ε | ½ r_x·r_x | EA |
//! | shear γ_y, γ_z | r_x·r_y, r_x·r_z | GA_y, GA_z |
//! | twist K1 | ½(r_z·r_y,x − r_y·r_z,x) | GJ |
//! | bending K2 | −r_z·r_xx (Kirchhoff) or ½(r_x·r_z,x − r_z·r_xx) (mixed) | EI_yy |
//! | bending K3 | r_y·r_xx (Kirchhoff) or ½(r_y·r_xx − r_x·r_y,x) (mixed) | EI_zz |
//! | section ε_yy, ε_zz | ½ r_y·r_y, ½ r_z·r_z | p·EA |
//! | section γ_yz | r_y·r_z | p·(GA_y + GA_z) |
//!
//! **Locking.** Axial strain and curvatures use 3-point Gauss quadrature. The section penalties
//! are sampled at the nodes only (trapezoidal rule): the linearly interpolated section slopes
//! shorten between rotated nodes, and penalising that would lock (curvature-thickness locking).
//! The transverse shear is sampled at the nodes (Kirchhoff curvature: the sections follow the
//! nodal tangents, the centreline alone carries bending) or at the midpoint (mixed curvature);
//! either way there is one shear sample per new nodal tilt, so the cubic centreline and the
//! linear sections do not fight (no shear locking).

use crate::shape::{Field, FieldWeights, N_BLOCKS, N_FIELDS, field_weights};
use crate::{Curvature, Section};

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

    /// Whether this is one of the cross-section penalty strains (no beam-theory counterpart).
    pub fn is_penalty(self) -> bool {
        matches!(self, StrainKind::SectionYY | StrainKind::SectionZZ | StrainKind::SectionYZ)
    }

    /// The terms `(c, f1, f2)` with `s = Σ c f1·f2`.
    pub fn terms(self, curvature: Curvature) -> &'static [(f64, Field, Field)] {
        use Field::*;
        match (self, curvature) {
            (StrainKind::Axial, _) => &[(0.5, X, X)],
            (StrainKind::ShearY, _) => &[(1.0, X, Y)],
            (StrainKind::ShearZ, _) => &[(1.0, X, Z)],
            (StrainKind::Twist, _) => &[(0.5, Z, YX), (-0.5, Y, ZX)],
            (StrainKind::BendY, Curvature::Kirchhoff) => &[(-1.0, Z, XX)],
            (StrainKind::BendY, Curvature::Mixed) => &[(0.5, X, ZX), (-0.5, Z, XX)],
            (StrainKind::BendZ, Curvature::Kirchhoff) => &[(1.0, Y, XX)],
            (StrainKind::BendZ, Curvature::Mixed) => &[(0.5, Y, XX), (-0.5, X, YX)],
            (StrainKind::SectionYY, _) => &[(0.5, Y, Y)],
            (StrainKind::SectionZZ, _) => &[(0.5, Z, Z)],
            (StrainKind::SectionYZ, _) => &[(1.0, Y, Z)],
        }
    }

    fn stiffness(self, s: &Section, penalty_factor: f64) -> f64 {
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

/// One strain sampled at one integration point.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledStrain {
    /// Which strain.
    pub kind: StrainKind,
    /// Its terms `(c, f1, f2)`.
    pub terms: &'static [(f64, Field, Field)],
    /// Stiffness × quadrature weight × l (so that `U = ½ Σ stiffness (s − reference)²`).
    pub stiffness: f64,
    /// Value in the reference configuration.
    pub reference: f64,
    /// The 8×8 scalar Hessian `a_k` (`∂²s/∂e∂e = a_k ⊗ I₃`).
    pub hessian: [[f64; N_BLOCKS]; N_BLOCKS],
}

/// An integration point with its interpolation weights and the strains sampled there.
#[derive(Debug, Clone, PartialEq)]
pub struct IntegrationPoint {
    /// ξ = x/l.
    pub xi: f64,
    /// Field interpolation weights, indexed by `Field as usize`.
    pub fields: [FieldWeights; N_FIELDS],
    /// Which fields the sampled strains need.
    pub used: [bool; N_FIELDS],
    /// Strains sampled at this point.
    pub strains: Vec<SampledStrain>,
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

/// Value of a strain from evaluated fields.
#[inline]
pub fn strain_value(terms: &[(f64, Field, Field)], f: &[[f64; 3]; N_FIELDS]) -> f64 {
    terms.iter().map(|&(c, a, b)| c * dot(&f[a as usize], &f[b as usize])).sum()
}

#[inline]
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The integration points of an element of length `l` with section `section`.
pub fn integration_points(l: f64, section: &Section, curvature: Curvature, penalty_factor: f64) -> Vec<IntegrationPoint> {
    use StrainKind::*;
    let g = 0.5 * (0.6f64).sqrt();
    let gauss = [(0.5 - g, 5.0 / 18.0), (0.5, 8.0 / 18.0), (0.5 + g, 5.0 / 18.0)];
    let continuum = [Axial, Twist, BendY, BendZ];
    let penalties = [SectionYY, SectionZZ, SectionYZ];
    // (ξ, [(kind, weight)])
    let mut plan: Vec<(f64, Vec<(StrainKind, f64)>)> = Vec::new();
    for xi in [0.0, 1.0] {
        let mut list: Vec<(StrainKind, f64)> = penalties.iter().map(|&k| (k, 0.5)).collect();
        if curvature == Curvature::Kirchhoff {
            list.push((ShearY, 0.5));
            list.push((ShearZ, 0.5));
        }
        plan.push((xi, list));
    }
    for (xi, w) in gauss {
        let mut list: Vec<(StrainKind, f64)> = continuum.iter().map(|&k| (k, w)).collect();
        if curvature == Curvature::Mixed && xi == 0.5 {
            list.push((ShearY, 1.0));
            list.push((ShearZ, 1.0));
        }
        plan.push((xi, list));
    }
    plan.sort_by(|a, b| a.0.total_cmp(&b.0));
    let e0 = reference_element(l);
    plan.into_iter()
        .map(|(xi, list)| {
            let fields = field_weights(xi, l);
            let f0: [[f64; 3]; N_FIELDS] = std::array::from_fn(|i| fields[i].eval(&e0));
            let dense: [[f64; N_BLOCKS]; N_FIELDS] = std::array::from_fn(|i| fields[i].dense());
            let mut used = [false; N_FIELDS];
            let strains = list
                .into_iter()
                .map(|(kind, w)| {
                    let terms = kind.terms(curvature);
                    let mut hessian = [[0.0; N_BLOCKS]; N_BLOCKS];
                    for &(c, f1, f2) in terms {
                        used[f1 as usize] = true;
                        used[f2 as usize] = true;
                        let (w1, w2) = (&dense[f1 as usize], &dense[f2 as usize]);
                        for a in 0..N_BLOCKS {
                            for b in 0..N_BLOCKS {
                                hessian[a][b] += c * (w1[a] * w2[b] + w2[a] * w1[b]);
                            }
                        }
                    }
                    SampledStrain {
                        kind,
                        terms,
                        stiffness: kind.stiffness(section, penalty_factor) * w * l,
                        reference: strain_value(terms, &f0),
                        hessian,
                    }
                })
                .collect();
            IntegrationPoint { xi, fields, used, strains }
        })
        .collect()
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
        }
    }

    #[test]
    fn quadrature_weights_sum_to_the_length() {
        let l = 0.3;
        for curvature in [Curvature::Kirchhoff, Curvature::Mixed] {
            let pts = integration_points(l, &section(), curvature, 1.0);
            let mut sum = [0.0; N_STRAINS];
            for p in &pts {
                for s in &p.strains {
                    sum[s.kind as usize] += s.stiffness / s.kind.stiffness(&section(), 1.0);
                }
            }
            for (k, v) in sum.iter().enumerate() {
                assert_relative_eq!(*v, l, epsilon = 1e-14);
                let _ = k;
            }
        }
    }

    #[test]
    fn reference_values_are_those_of_unit_orthonormal_slopes() {
        let pts = integration_points(0.4, &section(), Curvature::Mixed, 1.0);
        for p in &pts {
            for s in &p.strains {
                let expect = match s.kind {
                    StrainKind::Axial | StrainKind::SectionYY | StrainKind::SectionZZ => 0.5,
                    _ => 0.0,
                };
                assert_relative_eq!(s.reference, expect, epsilon = 1e-14);
            }
        }
    }

    #[test]
    fn hessian_reproduces_the_quadratic_form() {
        // s(e) = ½ eᵀ (a ⊗ I₃) e for every sampled strain, at an arbitrary e.
        let e: [f64; 24] = std::array::from_fn(|i| ((i * 7 + 3) % 11) as f64 * 0.1 - 0.4);
        for curvature in [Curvature::Kirchhoff, Curvature::Mixed] {
            for p in integration_points(0.7, &section(), curvature, 1.0) {
                let f: [[f64; 3]; N_FIELDS] = std::array::from_fn(|i| p.fields[i].eval(&e));
                for s in &p.strains {
                    let mut q = 0.0;
                    for a in 0..8 {
                        for b in 0..8 {
                            for i in 0..3 {
                                q += 0.5 * e[3 * a + i] * s.hessian[a][b] * e[3 * b + i];
                            }
                        }
                    }
                    assert_relative_eq!(q, strain_value(s.terms, &f), epsilon = 1e-12, max_relative = 1e-12);
                }
            }
        }
    }
}
