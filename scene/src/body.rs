//! Beam bodies, the point masses they carry, and their analytic rigid-body inertia.

use nalgebra::{Matrix3, Vector3};

use crate::{Section, Twist};

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
    /// Built-in twist of the section frame about the beam axis: the section frame at arclength
    /// `s` is [`section_frame(s)`](Self::section_frame) `= frame · R_x(θ(s))`; section data,
    /// centre-of-mass offsets and point-mass offsets are in that twisted frame.
    pub twist: Twist,
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

    /// The section frame at arclength `s` in the reference configuration (columns x, y, z,
    /// global): `frame · R_x(θ(s))`, `frame` itself for an untwisted body.
    pub fn section_frame(&self, s: f64) -> Matrix3<f64> {
        if self.twist.is_none() { self.frame } else { self.frame * self.twist.rotation(s) }
    }

    /// Global position of the point `offset` (section frame at `s`, twisted) of the section at
    /// arclength `s` in the reference configuration.
    pub fn reference_point(&self, s: f64, offset: &Vector3<f64>) -> Vector3<f64> {
        if self.twist.is_none() {
            self.start + self.frame * (Vector3::x() * s + offset)
        } else {
            self.start + self.frame.column(0) * s + self.section_frame(s) * offset
        }
    }

    /// The body's mass, centre of mass and inertia tensor in the reference configuration,
    /// exactly: the uniform beam (section inertias about the section's centre of mass, plus
    /// `m L³/12` of the line mass about the two transverse axes) and every point mass. A twisted
    /// body's beam part is integrated over its rotated sections ([`crate::twist`]'s quadrature,
    /// exact to rounding).
    pub fn reference_inertia(&self) -> RigidBodyInertia {
        let beam = if self.twist.is_none() { self.straight_beam_inertia() } else { self.twisted_beam_inertia() };
        self.point_masses.iter().fold(beam, |acc, p| {
            let f = self.section_frame(p.at);
            let point = RigidBodyInertia {
                mass: p.mass,
                centre: self.reference_point(p.at, &p.offset),
                inertia: f * Matrix3::from_diagonal(&p.inertia) * f.transpose(),
            };
            acc.combine(&point)
        })
    }

    /// The beam part of [`reference_inertia`](Self::reference_inertia) without twist, in closed
    /// form.
    fn straight_beam_inertia(&self) -> RigidBodyInertia {
        let s = &self.section;
        let l = self.length;
        let line_mass = s.mass * l;
        let cg = Vector3::new(0.5 * l, s.cg_offset[0], s.cg_offset[1]);
        let local = Matrix3::from_diagonal(&Vector3::new(
            s.rho_ixx * l,
            s.rho_iyy * l + line_mass * l * l / 12.0,
            s.rho_izz * l + line_mass * l * l / 12.0,
        ));
        RigidBodyInertia {
            mass: line_mass,
            centre: self.start + self.frame * cg,
            inertia: self.frame * local * self.frame.transpose(),
        }
    }

    /// The beam part of a twisted body: `∫ [R J Rᵀ + m (|p|² I − p pᵀ)] ds` about the start
    /// with `p(s)` the section's centre of mass and `R(s)` its frame, by [`Twist::quadrature`]
    /// (the integrand is a polynomial of degree ≤ 2 in `s` times `cos`, `sin` of `θ` or `2θ`:
    /// exact to rounding).
    fn twisted_beam_inertia(&self) -> RigidBodyInertia {
        let sec = &self.section;
        let j_local = Matrix3::from_diagonal(&Vector3::new(sec.rho_ixx, sec.rho_iyy, sec.rho_izz));
        let cg = Vector3::new(0.0, sec.cg_offset[0], sec.cg_offset[1]);
        let (mut first, mut about_start) = (Vector3::zeros(), Matrix3::zeros());
        for (s, wt) in self.twist.quadrature(self.length) {
            let r = self.frame * self.twist.rotation(s);
            let p = self.frame.column(0) * s + r * cg;
            first += p * (sec.mass * wt);
            about_start += (r * j_local * r.transpose()
                + (Matrix3::identity() * p.norm_squared() - p * p.transpose()) * sec.mass)
                * wt;
        }
        let mass = sec.mass * self.length;
        let c = first / mass;
        let inertia = about_start - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * mass;
        RigidBodyInertia { mass, centre: self.start + c, inertia }
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
            twist: Twist::none(),
        };
        let r = body.reference_inertia();
        assert_relative_eq!(r.mass, 11.0, max_relative = 1e-15);
        assert_relative_eq!(r.centre, Vector3::new(1.0, 0.0, 0.0), epsilon = 1e-15);
        let beam_transverse = 0.1 * 2.0 + 6.0 * 4.0 / 12.0;
        let expected = Matrix3::from_diagonal(&Vector3::new(0.4 + 1.0, beam_transverse + 2.0, beam_transverse + 2.5));
        assert_relative_eq!(r.inertia, expected, max_relative = 1e-14);
    }

    fn twisted_body(twist: Twist, frame: Matrix3<f64>) -> BodySpec {
        let mut section = Section::centred(3.0, 0.2, 0.05, 0.15, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0);
        section.cg_offset = [0.03, -0.02];
        BodySpec {
            name: "b".into(),
            start: Vector3::new(0.1, 0.2, 0.3),
            length: 2.0,
            frame,
            section,
            n_elements: 1,
            point_masses: vec![PointMass {
                at: 1.5,
                offset: Vector3::new(0.0, 0.1, 0.05),
                mass: 5.0,
                inertia: Vector3::new(1.0, 0.4, 0.8),
            }],
            twist,
        }
    }

    /// A constant twist θ is the untwisted body with its frame turned by θ about its axis
    /// (tolerance 1e-14: the quadrature against the closed form, rounding only).
    #[test]
    fn a_constant_twist_is_a_rotated_frame() {
        let frame = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.7).into_inner();
        let theta = 0.8;
        let twisted = twisted_body(Twist::table(vec![(0.5, theta)]), frame).reference_inertia();
        let rotated = twisted_body(Twist::none(), frame * crate::twist::rotation_x(theta)).reference_inertia();
        assert_relative_eq!(twisted.mass, rotated.mass, max_relative = 1e-15);
        assert_relative_eq!(twisted.centre, rotated.centre, max_relative = 1e-14);
        assert_relative_eq!(twisted.inertia, rotated.inertia, max_relative = 1e-14, epsilon = 1e-14);
    }

    /// A linear twist 0 → π/2 over the body: closed form of the rotated section inertias and of
    /// the centre-of-mass offset's path (tolerance 1e-13).
    #[test]
    fn a_linear_twist_integrates_the_rotated_sections_exactly() {
        let half_pi = std::f64::consts::FRAC_PI_2;
        let mut body = twisted_body(Twist::linear(0.0, half_pi, 2.0), Matrix3::identity());
        body.point_masses.clear();
        body.start = Vector3::zeros();
        let r = body.reference_inertia();
        let (l, m, k) = (2.0, 3.0, half_pi / 2.0);
        let (yc, zc) = (0.03, -0.02);
        // ∫ cos θ ds = sin(kL)/k = 1/k, ∫ sin θ ds = (1 − cos kL)/k = 1/k over θ = k s, kL = π/2
        let (ic, is) = (1.0 / k, 1.0 / k);
        let cy = m * (yc * ic - zc * is) / (m * l);
        let cz = m * (yc * is + zc * ic) / (m * l);
        assert_relative_eq!(r.centre, Vector3::new(1.0, cy, cz), max_relative = 1e-13);
        // ∫ R J Rᵀ: the y, z diagonal averages J_yy and J_zz over a quarter turn; off-diagonal
        // (J_yy − J_zz) ∫ sin θ cos θ = (J_yy − J_zz)/(2k)
        let (jyy, jzz) = (0.05, 0.15);
        let sections = Matrix3::new(
            0.2 * l,
            0.0,
            0.0,
            0.0,
            0.5 * (jyy + jzz) * l,
            (jyy - jzz) / (2.0 * k),
            0.0,
            (jyy - jzz) / (2.0 * k),
            0.5 * (jyy + jzz) * l,
        );
        // the line mass's own part about its centre: p = (s, R c); ∫|p|²I − ppᵀ minus the
        // centre's parallel-axis term
        let c2 = yc * yc + zc * zc;
        let ss = l * l * l / 3.0;
        // ∫ (R c)(R c)ᵀ: c rotated by θ: y = yc cos − zc sin, z = yc sin + zc cos
        let iyy = 0.5 * (yc * yc + zc * zc) * l + 0.5 * (yc * yc - zc * zc) * 0.0 - yc * zc * (1.0 / k);
        let izz = c2 * l - iyy;
        let iyz = 0.5 * (yc * yc - zc * zc) / k + yc * zc * 0.0;
        // ∫ s R c ds: ∫ s cos θ = (L sin kL)/k + (cos kL − 1)/k² = L/k − 1/k², ∫ s sin θ = (−L cos kL)/k + sin kL/k² = 1/k²
        let (sc, ssn) = (l / k - 1.0 / (k * k), 1.0 / (k * k));
        let sy = yc * sc - zc * ssn;
        let sz = yc * ssn + zc * sc;
        let about_start =
            Matrix3::new(c2 * l, -sy, -sz, -sy, ss + c2 * l - iyy, -iyz, -sz, -iyz, ss + c2 * l - izz) * m + sections;
        let c = r.centre;
        let expected = about_start - (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * (m * l);
        assert_relative_eq!(r.inertia, expected, max_relative = 1e-13, epsilon = 1e-13);
    }
}
