//! Beam bodies, the point masses they carry, and their analytic rigid-body inertia.

use nalgebra::{Matrix3, Vector3};

use crate::Section;

/// A rigid point mass (a lumped mass with rotary inertia) fixed to a body's section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMass {
    /// Arclength of the section it is fixed to, from the body's start, m (in `[0, length]`).
    pub at: f64,
    /// Centre of the mass relative to the section's axis point, in the section frame `[x, y, z]`, m.
    pub offset: Vector3<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// Principal inertias about its own centre along the section axes `[I_xx, I_yy, I_zz]`, kg·m².
    pub inertia: Vector3<f64>,
}

/// A straight beam body in its reference configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct BodySpec {
    /// Name, for reports.
    pub name: String,
    /// Start point, global, m.
    pub start: Vector3<f64>,
    /// Length, m.
    pub length: f64,
    /// Columns = section frame x (beam axis), y, z in global coordinates (orthonormal,
    /// right-handed).
    pub frame: Matrix3<f64>,
    /// Section data.
    pub section: Section,
    /// Number of elements (each formulation's own kind).
    pub n_elements: usize,
    /// Point masses fixed to the body's sections.
    pub point_masses: Vec<PointMass>,
}

/// Mass, centre of mass and inertia tensor (about the centre of mass) of a rigid body, global.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidBodyInertia {
    /// Total mass, kg.
    pub mass: f64,
    /// Centre of mass, global, m.
    pub centre: Vector3<f64>,
    /// Inertia tensor about the centre of mass, global axes, kg·m².
    pub inertia: Matrix3<f64>,
}

impl RigidBodyInertia {
    /// Nothing.
    pub fn zero() -> Self {
        Self { mass: 0.0, centre: Vector3::zeros(), inertia: Matrix3::zeros() }
    }

    /// Inertia tensor about the origin: `J_c + m (|c|² I − c cᵀ)`.
    pub fn inertia_about_origin(&self) -> Matrix3<f64> {
        let c = self.centre;
        self.inertia + self.mass * (Matrix3::identity() * c.norm_squared() - c * c.transpose())
    }

    /// Two bodies as one: masses add, the centre is the weighted mean, inertias move by the
    /// parallel-axis theorem.
    pub fn combine(&self, other: &Self) -> Self {
        let mass = self.mass + other.mass;
        if mass == 0.0 {
            return Self::zero();
        }
        let centre = (self.centre * self.mass + other.centre * other.mass) / mass;
        let shift = |b: &Self| {
            let d = b.centre - centre;
            b.inertia + b.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose())
        };
        Self { mass, centre, inertia: shift(self) + shift(other) }
    }
}

impl BodySpec {
    /// End point of the reference axis, global, m.
    pub fn end(&self) -> Vector3<f64> {
        self.start + self.frame.column(0) * self.length
    }

    /// Global position of the point `offset` (section frame) of the section at arclength `s` in
    /// the reference configuration.
    pub fn reference_point(&self, s: f64, offset: &Vector3<f64>) -> Vector3<f64> {
        self.start + self.frame * (Vector3::x() * s + offset)
    }

    /// The body's mass, centre of mass and inertia tensor in the reference configuration,
    /// exactly: the uniform beam (section inertias about the section's centre of mass, plus
    /// `m L³/12` of the line mass about the two transverse axes) and every point mass.
    pub fn reference_inertia(&self) -> RigidBodyInertia {
        let s = &self.section;
        let l = self.length;
        let line_mass = s.mass * l;
        let cg = Vector3::new(0.5 * l, s.cg_offset[0], s.cg_offset[1]);
        let local = Matrix3::from_diagonal(&Vector3::new(
            s.rho_ixx * l,
            s.rho_iyy * l + line_mass * l * l / 12.0,
            s.rho_izz * l + line_mass * l * l / 12.0,
        ));
        let beam = RigidBodyInertia {
            mass: line_mass,
            centre: self.reference_point(0.0, &cg),
            inertia: self.frame * local * self.frame.transpose(),
        };
        self.point_masses.iter().fold(beam, |acc, p| {
            let point = RigidBodyInertia {
                mass: p.mass,
                centre: self.reference_point(p.at, &p.offset),
                inertia: self.frame * Matrix3::from_diagonal(&p.inertia) * self.frame.transpose(),
            };
            acc.combine(&point)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn a_point_mass_at_the_centre_adds_mass_and_its_own_inertia_only() {
        let body = BodySpec {
            name: "b".into(),
            start: Vector3::zeros(),
            length: 2.0,
            frame: Matrix3::identity(),
            section: Section::centred(3.0, 0.2, 0.1, 0.1, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0),
            n_elements: 1,
            point_masses: vec![PointMass {
                at: 1.0,
                offset: Vector3::zeros(),
                mass: 5.0,
                inertia: Vector3::new(1.0, 2.0, 2.5),
            }],
        };
        let r = body.reference_inertia();
        assert_relative_eq!(r.mass, 11.0, max_relative = 1e-15);
        assert_relative_eq!(r.centre, Vector3::new(1.0, 0.0, 0.0), epsilon = 1e-15);
        let beam_transverse = 0.1 * 2.0 + 6.0 * 4.0 / 12.0;
        let expected = Matrix3::from_diagonal(&Vector3::new(0.4 + 1.0, beam_transverse + 2.0, beam_transverse + 2.5));
        assert_relative_eq!(r.inertia, expected, max_relative = 1e-14);
    }
}
