//! Linear modes of the constrained model about a configuration: the generalized eigenproblem
//!
//! $$ N^T K_t N\, \phi = \omega^2\, N^T M N\, \phi,\qquad \Phi_q N = 0 $$
//!
//! on the free motions (joints eliminated exactly), each mode classified by the
//! strain kind that stores most of its linearised strain energy, so that the cross-section
//! penalty modes can be told apart from beam modes.

use crate::Error;
use crate::elastic_force::ElementVector;
use crate::model::Model;
use crate::shape::{ELEMENT_DOF, NODE_DOF};
use crate::statics::FullCoordinates;
use crate::strain::{N_STRAINS, StrainKind};
use genalpha::analysis;

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
    ///
    /// The eigenproblem is the integrator crate's generic one
    /// ([`genalpha::analysis::linearise`], then
    /// [`natural_modes`](genalpha::analysis::Linearisation::natural_modes)) on the full
    /// coordinates, with the joints eliminated by an orthonormal basis of `ker Φ_q` (the same
    /// subspace as the [`reduction`](crate::reduction)'s `B`); the classification is ANCF's.
    pub fn linear_modes(&self, q_full: &[f64]) -> Result<Vec<Mode>, Error> {
        let lambda = vec![0.0; self.n_constraint_rows()];
        let natural = analysis::linearise(&FullCoordinates(self), 0.0, q_full, &lambda, &[])
            .and_then(|lin| lin.natural_modes())
            .map_err(|_| Error::SingularMatrix { pivot: 0 })?;
        type Gradients = Vec<(StrainKind, f64, ElementVector)>;
        let grads: Vec<(usize, Gradients)> = self
            .bodies
            .iter()
            .flat_map(|body| {
                (0..body.n_elements()).map(move |el| {
                    let first = body.offset + NODE_DOF * el;
                    (first, body.kernel(el).strain_gradients(&q_full[first..first + ELEMENT_DOF]))
                })
            })
            .collect();
        let modes = natural
            .omega_squared
            .iter()
            .zip(natural.shapes.column_iter())
            .map(|(&lam, column)| {
                let shape: Vec<f64> = column.iter().copied().collect();
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
