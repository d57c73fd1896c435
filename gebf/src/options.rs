//! Model options.

use crate::Error;

/// Options of the GEBF model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Position-level projection after every step (re-anchor each child frame at its parent's
    /// end node and rotate it minimally to realign the hinge axes; ground hinges and clamps are
    /// re-anchored too). Off by default: the velocity-level joints then drift, and the drift is
    /// measured by `Model::constraint_residual`.
    pub stabilization: bool,
    /// Gauss points per element for the elastic forces: 2 (default) is the reduced integration
    /// of SHARPy/xbeam; 3 is full integration (stiffer in shear).
    pub n_gauss_stiffness: usize,
    /// After every step, restore the linear and angular momentum to their balance with the
    /// external loads over the step by the smallest rigid velocity change (docs/gebf.md §15.1).
    /// Off by default: both momenta then drift at the integrator's second order.
    pub conserve_momentum: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self { stabilization: false, n_gauss_stiffness: 2, conserve_momentum: false }
    }
}

impl Options {
    /// Check ranges; errors name the field.
    pub fn validate(&self) -> Result<(), Error> {
        if !(1..=3).contains(&self.n_gauss_stiffness) {
            return Err(Error::OutOfRange {
                field: "options.n_gauss_stiffness".into(),
                value: self.n_gauss_stiffness as f64,
                min: 1.0,
                max: 3.0,
            });
        }
        Ok(())
    }
}
