//! Cross-section data per unit length.

use crate::Error;

/// Cross-section data per unit length (SI). Centre of mass and shear centre on the beam axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Mass per unit length m = ρA, kg/m.
    pub mass: f64,
    /// Torsional inertia per unit length ρI_xx, kg·m.
    pub rho_ixx: f64,
    /// Inertia per unit length about the section y axis ρI_yy, kg·m.
    pub rho_iyy: f64,
    /// Inertia per unit length about the section z axis ρI_zz, kg·m.
    pub rho_izz: f64,
    /// Axial stiffness EA, N.
    pub ea: f64,
    /// Shear stiffness along y, GA_y (shear correction included), N.
    pub ga_y: f64,
    /// Shear stiffness along z, GA_z, N.
    pub ga_z: f64,
    /// Torsional stiffness GJ, N·m².
    pub gj: f64,
    /// Bending stiffness about y (curvature κ_y), EI_yy, N·m².
    pub ei_yy: f64,
    /// Bending stiffness about z (curvature κ_z), EI_zz, N·m².
    pub ei_zz: f64,
}

impl Section {
    /// Every field must be finite and positive; the error names the field under `path`.
    pub fn validate(&self, path: &str) -> Result<(), Error> {
        for (name, v) in [
            ("mass", self.mass),
            ("rho_ixx", self.rho_ixx),
            ("rho_iyy", self.rho_iyy),
            ("rho_izz", self.rho_izz),
            ("ea", self.ea),
            ("ga_y", self.ga_y),
            ("ga_z", self.ga_z),
            ("gj", self.gj),
            ("ei_yy", self.ei_yy),
            ("ei_zz", self.ei_zz),
        ] {
            let field = format!("{path}.{name}");
            if !v.is_finite() {
                return Err(Error::NotFinite { field, value: v });
            }
            if v <= 0.0 {
                return Err(Error::NotPositive { field, value: v });
            }
        }
        Ok(())
    }

    /// Stiffness of the force strains (EA, GA_y, GA_z), N.
    pub(crate) fn force_stiffness(&self) -> crate::crv::V3 {
        crate::crv::V3::new(self.ea, self.ga_y, self.ga_z)
    }

    /// Stiffness of the curvatures (GJ, EI_yy, EI_zz), N·m².
    pub(crate) fn moment_stiffness(&self) -> crate::crv::V3 {
        crate::crv::V3::new(self.gj, self.ei_yy, self.ei_zz)
    }

    /// Rotary inertia per unit length diag(ρI_xx, ρI_yy, ρI_zz), kg·m.
    pub(crate) fn inertia(&self) -> crate::crv::V3 {
        crate::crv::V3::new(self.rho_ixx, self.rho_iyy, self.rho_izz)
    }
}
