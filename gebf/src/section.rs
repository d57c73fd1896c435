//! The section constants as GEBF's element kernels use them.

pub use scene::Section;

/// The section's constitutive and inertia diagonals.
pub(crate) trait SectionDiagonals {
    /// Stiffness of the force strains (EA, GA_y, GA_z), N.
    fn force_stiffness(&self) -> crate::crv::V3;
    /// Stiffness of the curvatures (GJ, EI_yy, EI_zz), N·m².
    fn moment_stiffness(&self) -> crate::crv::V3;
    /// Rotary inertia per unit length diag(ρI_xx, ρI_yy, ρI_zz), kg·m.
    fn inertia(&self) -> crate::crv::V3;
}

impl SectionDiagonals for Section {
    fn force_stiffness(&self) -> crate::crv::V3 {
        crate::crv::V3::new(self.ea, self.ga_y, self.ga_z)
    }

    fn moment_stiffness(&self) -> crate::crv::V3 {
        crate::crv::V3::new(self.gj, self.ei_yy, self.ei_zz)
    }

    fn inertia(&self) -> crate::crv::V3 {
        crate::crv::V3::new(self.rho_ixx, self.rho_iyy, self.rho_izz)
    }
}
