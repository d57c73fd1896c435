//! The precomputed two-node element of one body: length, constant mass, integration points.
//!
//! All elements of a body share length and section, so one [`Element`] serves them all;
//! it is built once at model construction. Forces and tangents are in
//! [`elastic_force`](crate::elastic_force).

use crate::elastic_force::ElementMatrix;
use crate::mass::{cg_offset_mass, element_mass, nonzeros};
use crate::shape::N_BLOCKS;
use crate::strain::{StrainPlan, strain_plan};
use crate::{Curvature, Section};

/// The element kernel shared by all elements of one body.
#[derive(Debug, Clone, PartialEq)]
pub struct Element {
    /// Element length l, m.
    pub l: f64,
    /// Scalar mass factor `m̄` (`M_e = m̄ ⊗ I₃`), kg.
    pub mass: [[f64; N_BLOCKS]; N_BLOCKS],
    /// Non-zeros of `mass`.
    pub mass_nz: Vec<(usize, usize, f64)>,
    /// The full 24×24 mass matrix `m̄ ⊗ I₃`, kg (the start of every element's iteration matrix).
    pub mass_matrix: ElementMatrix,
    /// Fields and sampled strains.
    pub plan: StrainPlan,
    /// Mass per unit length, kg/m (for gravity and point loads).
    pub mass_per_length: f64,
    /// Centre of mass of the section `[y_c, z_c]`, section frame, m.
    pub cg_offset: [f64; 2],
}

impl Element {
    /// Build the kernel for elements of length `l`.
    /// `penalty_factor` scales the section penalties (see [`strain`](crate::strain)).
    pub fn new(l: f64, section: &Section, curvature: Curvature, penalty_factor: f64) -> Self {
        let (d_yy, d_zz) = section.slope_inertias();
        let mut mass = element_mass(section.mass, d_yy, d_zz, l);
        if section.cg_offset != [0.0; 2] {
            let extra = cg_offset_mass(section.mass, section.cg_offset, l);
            for (row, extra_row) in mass.iter_mut().zip(&extra) {
                for (m, x) in row.iter_mut().zip(extra_row) {
                    *m += x;
                }
            }
        }
        let mut mass_matrix = ElementMatrix::zeros();
        for (a, row) in mass.iter().enumerate() {
            for (b, m) in row.iter().enumerate() {
                for i in 0..3 {
                    mass_matrix[(3 * a + i, 3 * b + i)] = *m;
                }
            }
        }
        Self {
            l,
            mass_nz: nonzeros(&mass),
            mass_matrix,
            mass,
            plan: strain_plan(l, section, curvature, penalty_factor),
            mass_per_length: section.mass,
            cg_offset: section.cg_offset,
        }
    }

    /// The same kernel with the strains' reference values taken from the element coordinates
    /// `e0` (one element of a twisted body, docs/ancf.md §1): mass, stiffnesses and sampling are
    /// unchanged.
    pub fn with_reference(&self, e0: &[f64]) -> Self {
        Self { plan: self.plan.with_reference(e0), ..self.clone() }
    }

    /// `out += c · M_e · x` for 24-vectors.
    #[inline]
    pub fn add_mass_times(&self, c: f64, x: &[f64], out: &mut [f64]) {
        for &(a, b, m) in &self.mass_nz {
            let cm = c * m;
            out[3 * a] += cm * x[3 * b];
            out[3 * a + 1] += cm * x[3 * b + 1];
            out[3 * a + 2] += cm * x[3 * b + 2];
        }
    }

    /// Generalized gravity force of one element, `∫ m S(x, y_c, z_c)ᵀ g dx` (24 numbers): the
    /// weight acts at the section's centre of mass.
    pub fn gravity_force(&self, g: [f64; 3]) -> [f64; 24] {
        let (m, l) = (self.mass_per_length, self.l);
        // ∫ h dx = (l/2, l²/12, l/2, −l²/12)
        let w = [(0, 0.5 * l), (1, l * l / 12.0), (4, 0.5 * l), (5, -l * l / 12.0)];
        let mut f = [0.0; 24];
        for (b, x) in w {
            for i in 0..3 {
                f[3 * b + i] = m * x * g[i];
            }
        }
        if self.cg_offset != [0.0; 2] {
            // ∫ (1 − ξ) dx = ∫ ξ dx = l/2 on the slopes r_y (blocks 2, 6) and r_z (3, 7)
            let [yc, zc] = self.cg_offset;
            for (b, c) in [(2, yc), (6, yc), (3, zc), (7, zc)] {
                for i in 0..3 {
                    f[3 * b + i] = m * c * 0.5 * l * g[i];
                }
            }
        }
        f
    }
}
