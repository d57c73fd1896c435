//! Linear modes of the constrained model about a configuration: the generalized eigenproblem
//!
//! $$ B^T K_t B\, \phi = \omega^2\, B^T M B\, \phi $$
//!
//! on the independent coordinates (joints eliminated exactly), each mode classified by the
//! strain kind that stores most of its linearised strain energy, so that the cross-section
//! penalty modes can be told apart from beam modes.

use crate::Error;
use crate::elastic_force::ElementVector;
use crate::model::Model;
use crate::shape::{ELEMENT_DOF, NODE_DOF};
use crate::strain::{N_STRAINS, StrainKind};
use genalpha::DenseMatrix;
use nalgebra::DMatrix;

/// Classification of a mode by where its strain energy sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeKind {
    /// Free motion (no strain energy), e.g. a pendulum mode.
    Rigid,
    /// Axial stretching.
    Axial,
    /// Bending about the section y axis (deflection along z): K2 and γ_z.
    BendingY,
    /// Bending about the section z axis (deflection along y): K3 and γ_y.
    BendingZ,
    /// Torsion: K1.
    Torsion,
    /// Cross-section deformation (penalty strains): not a beam mode.
    Penalty,
}

/// One linear mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// Circular frequency ω, rad/s.
    pub omega: f64,
    /// Dominant strain kind.
    pub kind: ModeKind,
    /// Fraction of the strain energy per [`StrainKind`].
    pub energy_fractions: [f64; N_STRAINS],
    /// Mode shape on the full coordinates, mass-normalised.
    pub shape: Vec<f64>,
}

impl Model {
    /// Linear modes about the full configuration `q_full` (usually
    /// [`reference_coordinates`](Model::reference_coordinates)), sorted by frequency. External
    /// loads are ignored; the tangent includes the stress stiffening of `q_full`.
    pub fn linear_modes(&self, q_full: &[f64]) -> Result<Vec<Mode>, Error> {
        let n = self.n_full_coords();
        let red = &self.reduction;
        let nz = red.n_reduced();
        let mut b = DMatrix::<f64>::zeros(n, nz);
        for i in 0..n {
            for &(z, c) in red.row(i) {
                b[(i, z)] = c;
            }
        }
        let full = |c_m: f64, c_k: f64| {
            let mut d = DenseMatrix::zeros(n, n);
            self.assemble_full_inplace(q_full, c_m, c_k, &mut d.view());
            DMatrix::from_column_slice(n, n, d.as_slice())
        };
        let k = b.transpose() * full(0.0, 1.0) * &b;
        let m = b.transpose() * full(1.0, 0.0) * &b;
        let k = 0.5 * (&k + k.transpose());
        let chol = m.cholesky().ok_or(Error::SingularMatrix { pivot: 0 })?;
        let l = chol.l();
        let l_inv = l.clone().try_inverse().ok_or(Error::SingularMatrix { pivot: 0 })?;
        let a = &l_inv * k * l_inv.transpose();
        let a = 0.5 * (&a + a.transpose());
        let eig = a.symmetric_eigen();
        let mut order: Vec<usize> = (0..nz).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        type Gradients = Vec<(StrainKind, f64, ElementVector)>;
        let grads: Vec<(usize, Gradients)> = self
            .bodies
            .iter()
            .flat_map(|body| {
                (0..body.n_elements()).map(move |el| {
                    let first = body.offset + NODE_DOF * el;
                    (first, body.element.strain_gradients(&q_full[first..first + ELEMENT_DOF]))
                })
            })
            .collect();
        let modes = order
            .into_iter()
            .map(|i| {
                let lam = eig.eigenvalues[i];
                let y = eig.eigenvectors.column(i);
                let phi_z = l_inv.transpose() * y;
                let shape: Vec<f64> = (&b * phi_z).iter().copied().collect();
                let mut energy = [0.0; N_STRAINS];
                for (first, list) in &grads {
                    let e = &shape[*first..*first + ELEMENT_DOF];
                    for (kind, stiffness, g) in list {
                        let s: f64 = g.iter().zip(e).map(|(a, b)| a * b).sum();
                        energy[*kind as usize] += 0.5 * stiffness * s * s;
                    }
                }
                let total: f64 = energy.iter().sum();
                let fractions = energy.map(|x| if total > 0.0 { x / total } else { 0.0 });
                Mode { omega: lam.max(0.0).sqrt(), kind: classify(&fractions, lam), energy_fractions: fractions, shape }
            })
            .collect();
        Ok(modes)
    }
}

fn classify(f: &[f64; N_STRAINS], lambda: f64) -> ModeKind {
    use StrainKind::*;
    if lambda.abs() < 1e-8 || f.iter().all(|x| *x == 0.0) {
        return ModeKind::Rigid;
    }
    let g = |k: StrainKind| f[k as usize];
    let _ = (SectionYY, SectionZZ, SectionYZ);
    let groups = [
        (ModeKind::Axial, g(Axial)),
        (ModeKind::BendingY, g(BendY) + g(ShearZ)),
        (ModeKind::BendingZ, g(BendZ) + g(ShearY)),
        (ModeKind::Torsion, g(Twist)),
        (ModeKind::Penalty, f.iter().zip(StrainKind::ALL).filter(|(_, k)| k.is_penalty()).map(|(x, _)| x).sum()),
    ];
    groups.iter().max_by(|a, b| a.1.total_cmp(&b.1)).map(|x| x.0).unwrap_or(ModeKind::Rigid)
}
