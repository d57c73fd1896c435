//! Cross-section data per unit length.

/// Cross-section data per unit length (SI). The shear centre lies on the beam axis; the centre
/// of mass may be offset from it by [`cg_offset`](Self::cg_offset).
///
/// The rotary inertias are about the section's centre of mass. The stiffnesses are about the
/// beam axis (the elastic axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Mass per unit length m = ρA, kg/m.
    pub mass: f64,
    /// Torsional inertia per unit length ρI_xx about the section's centre of mass, kg·m.
    pub rho_ixx: f64,
    /// Inertia per unit length about the section y axis ρI_yy = ∫ρz² dA, kg·m.
    pub rho_iyy: f64,
    /// Inertia per unit length about the section z axis ρI_zz = ∫ρy² dA, kg·m.
    pub rho_izz: f64,
    /// Axial stiffness EA, N.
    pub ea: f64,
    /// Shear stiffness along y, GA_y (shear correction included), N.
    pub ga_y: f64,
    /// Shear stiffness along z, GA_z, N.
    pub ga_z: f64,
    /// Torsional stiffness GJ, N·m².
    pub gj: f64,
    /// Bending stiffness about y (out-of-plane flap for a wing), EI_yy, N·m².
    pub ei_yy: f64,
    /// Bending stiffness about z, EI_zz, N·m².
    pub ei_zz: f64,
    /// Centre of mass in the section plane, `[y, z]` in the section frame, m (default `[0, 0]`).
    pub cg_offset: [f64; 2],
}

impl Section {
    /// A section with its centre of mass on the beam axis.
    #[allow(clippy::too_many_arguments)] // the ten section constants, in the order a table gives them
    pub fn centred(
        mass: f64,
        rho_ixx: f64,
        rho_iyy: f64,
        rho_izz: f64,
        ea: f64,
        ga_y: f64,
        ga_z: f64,
        gj: f64,
        ei_yy: f64,
        ei_zz: f64,
    ) -> Self {
        Self { mass, rho_ixx, rho_iyy, rho_izz, ea, ga_y, ga_z, gj, ei_yy, ei_zz, cg_offset: [0.0; 2] }
    }

    /// Slope inertias of ANCF's constant mass matrix (docs/ancf.md §2):
    /// `D_yy = (J_xx − J_yy + J_zz)/2`, `D_zz = (J_xx + J_yy − J_zz)/2`, kg·m, with the `J` about
    /// the centre of mass. Exact when `J_xx = J_yy + J_zz`; otherwise the torsional inertia
    /// `J_xx = D_yy + D_zz` is kept. Clamped at zero (validation rejects non-positive values).
    pub fn slope_inertias(&self) -> (f64, f64) {
        let d_yy = 0.5 * (self.rho_ixx - self.rho_iyy + self.rho_izz);
        let d_zz = 0.5 * (self.rho_ixx + self.rho_iyy - self.rho_izz);
        (d_yy.max(0.0), d_zz.max(0.0))
    }

    /// The same section with every stiffness multiplied by `c` (the paper's stiffness factor).
    pub fn with_stiffness_scale(&self, c: f64) -> Self {
        Self {
            ea: c * self.ea,
            ga_y: c * self.ga_y,
            ga_z: c * self.ga_z,
            gj: c * self.gj,
            ei_yy: c * self.ei_yy,
            ei_zz: c * self.ei_zz,
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_inertias_preserve_the_torsional_inertia() {
        let s = Section::centred(1.08, 7.2e-5, 3.6e-5, 3.6e-5, 2.8e5, 1.037e5, 1.037e5, 6.91, 9.33, 9.33);
        let (d_yy, d_zz) = s.slope_inertias();
        approx::assert_relative_eq!(d_yy + d_zz, s.rho_ixx, max_relative = 1e-14);
        // exact when J_xx = J_yy + J_zz: J_yy = D_zz, J_zz = D_yy
        approx::assert_relative_eq!(d_zz, s.rho_iyy, max_relative = 1e-14);
        approx::assert_relative_eq!(d_yy, s.rho_izz, max_relative = 1e-14);
    }
}
