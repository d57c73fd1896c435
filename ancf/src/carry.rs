//! A state carried across a change of the joints, as when a hinge locks or is released during a
//! march (docs/ancf.md §6): the two models share their bodies and full nodal coordinates, and
//! on the ODE path their independent coordinates `z` differ in number.

use crate::model::Model;
use crate::{Error, SolvePath};
use nalgebra::{DMatrix, DVector};

impl Model {
    /// The state `(q, v)` of `old` — a model of the same bodies whose joints differ — in this
    /// model's coordinates and velocities.
    ///
    /// The full nodal coordinates carry over, restricted to this model's independent ones on
    /// the ODE path (which moves them onto its joints' equations where they meet them only
    /// approximately, by the strain of the hinge's sections). The full velocities carry over on the DAE path, where
    /// the integrator's impact imposes the new joints; on the ODE path they are projected onto
    /// the admissible ones closest in kinetic energy,
    ///
    /// $$ \dot z = (B^T M B)^{-1} B^T M \dot q ,$$
    ///
    /// exact when `q̇` is admissible and otherwise a perfectly inelastic impact that removes
    /// `½ (q̇ − B ż)ᵀ M (q̇ − B ż)` of kinetic energy: a lock's, and a small one at a release,
    /// because the weld leaves the centreline slopes free and the hinge's axis equation reads
    /// them (the welded state meets it to the hinge sections' strain).
    ///
    /// # Errors
    /// [`Error::CarriedState`] when the two models do not share their full coordinates or
    /// `q`, `v` do not fit `old`; [`Error::SingularMatrix`] when `BᵀMB` has no Cholesky factor.
    pub fn carry_state(&self, old: &Model, q: &[f64], v: &[f64]) -> Result<(Vec<f64>, Vec<f64>), Error> {
        use genalpha::ConstrainedSystem;
        let n = self.n_full_coords();
        if old.n_full_coords() != n || q.len() != old.n_coords() || v.len() != old.n_dof() {
            return Err(Error::CarriedState { got: old.n_full_coords(), expected: n });
        }
        let mut qf = vec![0.0; n];
        let mut vf = vec![0.0; n];
        old.full_coordinates_inplace(q, &mut qf);
        old.full_velocities_inplace(v, &mut vf);
        if self.options().path == SolvePath::Dae {
            return Ok((qf, vf));
        }
        let r = &self.reduction;
        let nz = r.n_reduced();
        // BᵀMB column by column: B e_j, its mass product, projected (M is banded and B nearly an
        // identity, so the nz products cost O(nz · n); an event is rare).
        let (mut col, mut m_col, mut proj) = (vec![0.0; n], vec![0.0; n], vec![0.0; nz]);
        let mut reduced = DMatrix::zeros(nz, nz);
        let mut unit = vec![0.0; nz];
        for j in 0..nz {
            unit[j] = 1.0;
            r.expand_rate_inplace(&unit, &mut col);
            unit[j] = 0.0;
            self.mass_times_full(&col, &mut m_col);
            r.project_inplace(&m_col, &mut proj);
            reduced.column_mut(j).copy_from_slice(&proj);
        }
        let reduced = (&reduced + reduced.transpose()) * 0.5;
        let chol = reduced.cholesky().ok_or(Error::SingularMatrix { pivot: 0 })?;
        self.mass_times_full(&vf, &mut m_col);
        r.project_inplace(&m_col, &mut proj);
        let vz = chol.solve(&DVector::from_vec(proj));
        Ok((r.restrict(&qf), vz.as_slice().to_vec()))
    }
}
