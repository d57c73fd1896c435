//! One validation of the whole scene, with every limit a formulation imposes.

use nalgebra::{Matrix3, Vector3};

use crate::{BodySpec, Error, ForceElement, JointSpec, Scene, Section};

/// Largest entry of |FᵀF − I| accepted for a body frame.
const FRAME_TOLERANCE: f64 = 1e-9;

fn finite(field: impl FnOnce() -> String, value: f64) -> Result<(), Error> {
    if value.is_finite() { Ok(()) } else { Err(Error::NonFinite { field: field(), value }) }
}

fn positive(field: impl Fn() -> String, value: f64) -> Result<(), Error> {
    finite(&field, value)?;
    if value > 0.0 { Ok(()) } else { Err(Error::NotPositive { field: field(), value }) }
}

fn non_negative(field: impl Fn() -> String, value: f64) -> Result<(), Error> {
    finite(&field, value)?;
    if value >= 0.0 { Ok(()) } else { Err(Error::Negative { field: field(), value }) }
}

fn finite_vector(field: &str, v: &Vector3<f64>) -> Result<(), Error> {
    v.iter().enumerate().try_for_each(|(k, x)| finite(|| format!("{field}[{k}]"), *x))
}

impl Section {
    /// Every constant finite and positive (inertias and stiffnesses alike), ANCF's slope
    /// inertias positive, the centre-of-mass offset finite. Fields are named under `path`.
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
            positive(|| format!("{path}.{name}"), v)?;
        }
        for (k, v) in self.cg_offset.iter().enumerate() {
            finite(|| format!("{path}.cg_offset[{k}]"), *v)?;
        }
        let d_yy = 0.5 * (self.rho_ixx - self.rho_iyy + self.rho_izz);
        let d_zz = 0.5 * (self.rho_ixx + self.rho_iyy - self.rho_izz);
        if d_yy <= 0.0 || d_zz <= 0.0 {
            return Err(Error::MasslessSection { field: path.to_string(), d_yy, d_zz });
        }
        Ok(())
    }
}

impl BodySpec {
    /// Check every field of body `i`; errors name the field as `bodies[i].<field>`.
    pub fn validate(&self, i: usize) -> Result<(), Error> {
        let path = format!("bodies[{i}]");
        finite_vector(&format!("{path}.start"), &self.start)?;
        positive(|| format!("{path}.length"), self.length)?;
        for (k, v) in self.frame.iter().enumerate() {
            finite(|| format!("{path}.frame[{}][{}]", k % 3, k / 3), *v)?;
        }
        let deviation = (self.frame.transpose() * self.frame - Matrix3::identity()).amax();
        let det = self.frame.determinant();
        if deviation > FRAME_TOLERANCE || det <= 0.0 {
            return Err(Error::BadFrame { field: format!("{path}.frame"), deviation, det });
        }
        self.section.validate(&format!("{path}.section"))?;
        if self.n_elements == 0 {
            return Err(Error::ZeroElements { field: format!("{path}.n_elements") });
        }
        self.validate_twist(&path)?;
        for (k, p) in self.point_masses.iter().enumerate() {
            let pm = format!("{path}.point_masses[{k}]");
            finite(|| format!("{pm}.at"), p.at)?;
            if !(0.0..=self.length).contains(&p.at) {
                return Err(Error::OutOfRange { field: format!("{pm}.at"), value: p.at, min: 0.0, max: self.length });
            }
            finite_vector(&format!("{pm}.offset"), &p.offset)?;
            non_negative(|| format!("{pm}.mass"), p.mass)?;
            for (a, v) in p.inertia.iter().enumerate() {
                non_negative(|| format!("{pm}.inertia[{a}]"), *v)?;
            }
            let i = p.inertia;
            let slack = 1e-12 * i.amax();
            if i.x > i.y + i.z + slack || i.y > i.x + i.z + slack || i.z > i.x + i.y + slack {
                return Err(Error::ImpossibleInertia { field: format!("{pm}.inertia"), inertia: i.into() });
            }
        }
        Ok(())
    }
}

impl BodySpec {
    /// The twist table: every point finite, `s` strictly increasing and within `[0, length]`
    /// (1e-12 relative slack). Fields are named `bodies[i].twist[k].s` / `.angle`.
    fn validate_twist(&self, path: &str) -> Result<(), Error> {
        let slack = 1e-12 * self.length;
        let mut previous: Option<f64> = None;
        for (k, &(s, angle)) in self.twist.points().iter().enumerate() {
            let field = format!("{path}.twist[{k}]");
            finite(|| format!("{field}.s"), s)?;
            finite(|| format!("{field}.angle"), angle)?;
            if s < -slack || s > self.length + slack {
                return Err(Error::OutOfRange { field: format!("{field}.s"), value: s, min: 0.0, max: self.length });
            }
            if let Some(p) = previous
                && s <= p
            {
                return Err(Error::TwistNotIncreasing { field: format!("{field}.s"), value: s, previous: p });
            }
            previous = Some(s);
        }
        Ok(())
    }
}

impl Scene {
    /// Check everything both formulations rely on. A scene that passes builds in both.
    pub fn validate(&self) -> Result<(), Error> {
        if self.bodies.is_empty() {
            return Err(Error::NoBodies);
        }
        for (i, b) in self.bodies.iter().enumerate() {
            b.validate(i)?;
        }
        finite_vector("gravity", &self.gravity)?;
        self.validate_joints()?;
        self.validate_forces()
    }

    fn validate_joints(&self) -> Result<(), Error> {
        let nb = self.bodies.len();
        let body = |field: String, b: usize| {
            if b < nb { Ok(()) } else { Err(Error::NoSuchBody { field, body: b, n_bodies: nb }) }
        };
        let mut attached: Vec<Option<usize>> = vec![None; nb];
        let mut parent: Vec<Option<usize>> = vec![None; nb];
        for (j, spec) in self.joints.iter().enumerate() {
            let path = format!("joints[{j}]");
            match *spec {
                JointSpec::GroundHinge { body: b, ref axis } => {
                    body(format!("{path}.body"), b)?;
                    finite_vector(&format!("{path}.axis"), axis)?;
                    if axis.norm() == 0.0 {
                        return Err(Error::ZeroAxis { field: format!("{path}.axis") });
                    }
                }
                JointSpec::Clamp { body: b } | JointSpec::Free { body: b } => body(format!("{path}.body"), b)?,
                JointSpec::FlaredHinge { parent: p, child: c, beta }
                | JointSpec::LockedHinge { parent: p, child: c, beta, .. } => {
                    if let JointSpec::LockedHinge { fold, .. } = *spec {
                        finite(|| format!("{path}.lock_deg"), fold)?;
                    }
                    body(format!("{path}.parent"), p)?;
                    body(format!("{path}.child"), c)?;
                    if p == c {
                        return Err(Error::SelfJoint { field: format!("{path}.child"), body: c });
                    }
                    finite(|| format!("{path}.beta"), beta)?;
                    let half_pi = std::f64::consts::FRAC_PI_2;
                    if beta.abs() > half_pi * (1.0 + 1e-12) {
                        return Err(Error::OutOfRange {
                            field: format!("{path}.beta"),
                            value: beta,
                            min: -half_pi,
                            max: half_pi,
                        });
                    }
                    let (bp, bc) = (&self.bodies[p], &self.bodies[c]);
                    let gap = (bp.end() - bc.start).norm();
                    if gap > 1e-9 * bp.length.max(bc.length).max(1.0) {
                        return Err(Error::JointGap { field: format!("{path}.child"), gap });
                    }
                    parent[c] = Some(p);
                }
            }
            let b = spec.attached_body();
            if let Some(other) = attached[b] {
                // A free joint on a body that also hangs from another joint is named at the
                // free joint, whichever comes first.
                let (field, other) = match (&self.joints[other], spec) {
                    (JointSpec::Free { .. }, _) => (format!("joints[{other}].body"), j),
                    (_, JointSpec::FlaredHinge { .. } | JointSpec::LockedHinge { .. }) => {
                        (format!("{path}.child"), other)
                    }
                    _ => (format!("{path}.body"), other),
                };
                return Err(Error::DoublyAttached { field, body: b, other });
            }
            attached[b] = Some(j);
        }
        for (b, joint) in attached.iter().enumerate() {
            let (mut cur, mut n) = (b, 0);
            while let Some(p) = parent[cur] {
                n += 1;
                cur = p;
                if n > nb {
                    return Err(Error::JointLoop { joint: joint.unwrap_or(0) });
                }
            }
        }
        Ok(())
    }

    fn validate_forces(&self) -> Result<(), Error> {
        let nj = self.joints.len();
        let mut spring: Vec<Option<usize>> = vec![None; nj];
        let mut n_thrust = 0;
        for (k, f) in self.forces.iter().enumerate() {
            match *f {
                ForceElement::Thrust { body, at, ref direction, ref magnitude } => {
                    self.validate_thrust(n_thrust, body, at, direction, &magnitude.points)?;
                    n_thrust += 1;
                }
                ForceElement::HingeSpring { joint, stiffness, damping, rest } => {
                    if joint >= nj {
                        return Err(Error::NoSuchJoint { field: format!("forces[{k}].joint"), joint, n_joints: nj });
                    }
                    let path = format!("joints[{joint}].spring");
                    match self.joints[joint] {
                        JointSpec::GroundHinge { .. } | JointSpec::FlaredHinge { .. } => {}
                        ref other => return Err(Error::NotAHinge { field: path, kind: other.kind() }),
                    }
                    if let Some(other) = spring[joint] {
                        return Err(Error::DuplicateSpring { field: path, joint, other });
                    }
                    spring[joint] = Some(k);
                    non_negative(|| format!("{path}.stiffness"), stiffness)?;
                    non_negative(|| format!("{path}.damping"), damping)?;
                    finite(|| format!("{path}.rest_deg"), rest)?;
                }
            }
        }
        Ok(())
    }

    /// The `k`-th thrust (case field `thrust[k]`): an existing body, a point on it, a finite
    /// non-zero direction, a finite magnitude schedule with strictly increasing times.
    fn validate_thrust(
        &self,
        k: usize,
        body: usize,
        at: f64,
        direction: &Vector3<f64>,
        magnitude: &[(f64, f64)],
    ) -> Result<(), Error> {
        let path = format!("thrust[{k}]");
        let nb = self.bodies.len();
        if body >= nb {
            return Err(Error::NoSuchBody { field: format!("{path}.body"), body, n_bodies: nb });
        }
        finite(|| format!("{path}.at"), at)?;
        let len = self.bodies[body].length;
        if at < -1e-12 * len || at > len * (1.0 + 1e-12) {
            return Err(Error::OutOfRange { field: format!("{path}.at"), value: at, min: 0.0, max: len });
        }
        finite_vector(&format!("{path}.direction"), direction)?;
        if direction.norm() == 0.0 {
            return Err(Error::ZeroDirection { field: format!("{path}.direction") });
        }
        if magnitude.is_empty() {
            return Err(Error::EmptySchedule { field: format!("{path}.magnitude") });
        }
        // A one-point schedule is the case's plain number: no index in the field's name.
        let single = magnitude.len() == 1;
        let point = |i: usize, part: &str| {
            if single { format!("{path}.magnitude") } else { format!("{path}.magnitude[{i}]{part}") }
        };
        for (i, &(t, v)) in magnitude.iter().enumerate() {
            finite(|| point(i, "[0]"), t)?;
            finite(|| point(i, "[1]"), v)?;
            if i > 0 && t <= magnitude[i - 1].0 {
                return Err(Error::ScheduleNotIncreasing {
                    field: point(i, "[0]"),
                    value: t,
                    previous: magnitude[i - 1].0,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PointMass;

    fn pendulum() -> Scene {
        let section = Section::centred(1.08, 7.2e-5, 3.6e-5, 3.6e-5, 2.8e5, 1.037e5, 1.037e5, 6.91, 9.33, 9.33);
        let body = |name: &str, x0: f64| BodySpec {
            name: name.into(),
            start: Vector3::new(x0, 0.0, 0.0),
            length: 0.5,
            frame: Matrix3::identity(),
            section,
            n_elements: 2,
            point_masses: Vec::new(),
            twist: crate::Twist::none(),
        };
        Scene::new(
            vec![body("a", 0.0), body("b", 0.5)],
            vec![
                JointSpec::GroundHinge { body: 0, axis: Vector3::y() },
                JointSpec::FlaredHinge { parent: 0, child: 1, beta: 0.5 },
            ],
            Vector3::new(0.0, 0.0, -9.8),
        )
    }

    fn msg(s: &Scene) -> String {
        s.validate().expect_err("invalid").to_string()
    }

    #[test]
    fn the_pendulum_is_valid() {
        pendulum().validate().unwrap();
    }

    #[test]
    fn errors_name_the_field() {
        let mut s = pendulum();
        s.bodies[1].section.cg_offset[1] = f64::NAN;
        assert_eq!(msg(&s), "bodies[1].section.cg_offset[1]: NaN is not a finite number");
        let mut s = pendulum();
        s.bodies[0].section.rho_iyy = 1.0;
        assert!(msg(&s).starts_with("bodies[0].section: the section inertias give"));
        let mut s = pendulum();
        s.bodies[0].point_masses.push(PointMass {
            at: 0.6,
            offset: Vector3::zeros(),
            mass: 1.0,
            inertia: Vector3::zeros(),
        });
        assert_eq!(msg(&s), "bodies[0].point_masses[0].at: 0.6 is not in [0, 0.5]");
        s.bodies[0].point_masses[0].at = 0.5;
        s.bodies[0].point_masses[0].mass = -1.0;
        assert_eq!(msg(&s), "bodies[0].point_masses[0].mass: -1 is negative");
        s.bodies[0].point_masses[0].mass = 1.0;
        s.bodies[0].point_masses[0].inertia = Vector3::new(3.0, 1.0, 1.0);
        assert!(msg(&s).starts_with("bodies[0].point_masses[0].inertia: principal inertias"));
        let mut s = pendulum();
        s.forces.push(ForceElement::HingeSpring { joint: 1, stiffness: -2.0, damping: 0.0, rest: 0.0 });
        assert_eq!(msg(&s), "joints[1].spring.stiffness: -2 is negative");
        s.forces[0] = ForceElement::HingeSpring { joint: 4, stiffness: 2.0, damping: 0.0, rest: 0.0 };
        assert_eq!(msg(&s), "forces[0].joint: no joint 4 (the scene has 2 joints)");
        s.forces[0] = ForceElement::HingeSpring { joint: 1, stiffness: 2.0, damping: f64::INFINITY, rest: 0.0 };
        assert_eq!(msg(&s), "joints[1].spring.damping: inf is not a finite number");
        s.joints[1] = JointSpec::LockedHinge { parent: 0, child: 1, beta: 0.5, fold: 0.0 };
        s.forces[0] = ForceElement::HingeSpring { joint: 1, stiffness: 2.0, damping: 0.0, rest: 0.0 };
        assert_eq!(msg(&s), "joints[1].spring: a hinge spring needs a free ground or flared hinge, not a locked hinge");
        let mut s = pendulum();
        s.bodies[1].twist = crate::Twist::table(vec![(0.0, 0.1), (0.3, f64::NAN)]);
        assert_eq!(msg(&s), "bodies[1].twist[1].angle: NaN is not a finite number");
        s.bodies[1].twist = crate::Twist::table(vec![(0.0, 0.1), (0.6, 0.2)]);
        assert_eq!(msg(&s), "bodies[1].twist[1].s: 0.6 is not in [0, 0.5]");
        s.bodies[1].twist = crate::Twist::table(vec![(0.2, 0.1), (0.2, 0.2)]);
        assert_eq!(
            msg(&s),
            "bodies[1].twist[1].s: s = 0.2 does not exceed the previous point's s = 0.2 (the table must increase strictly)"
        );
        s.bodies[1].twist = crate::Twist::linear(0.1, 0.2, 0.5 * (1.0 + 1e-13));
        s.validate().unwrap();
        let mut s = pendulum();
        let thrust = |body, at, direction: Vector3<f64>, points: Vec<(f64, f64)>| ForceElement::Thrust {
            body,
            at,
            direction,
            magnitude: crate::Schedule { points },
        };
        s.forces.push(ForceElement::HingeSpring { joint: 1, stiffness: 2.0, damping: 0.0, rest: 0.0 });
        s.forces.push(thrust(1, 0.5, Vector3::y(), vec![(0.0, 3.0)]));
        s.validate().unwrap();
        s.forces.push(thrust(2, 0.5, Vector3::y(), vec![(0.0, 3.0)]));
        assert_eq!(msg(&s), "thrust[1].body: no body 2 (the scene has 2 bodies)");
        s.forces[2] = thrust(1, 0.6, Vector3::y(), vec![(0.0, 3.0)]);
        assert_eq!(msg(&s), "thrust[1].at: 0.6 is not in [0, 0.5]");
        s.forces[2] = thrust(1, 0.2, Vector3::zeros(), vec![(0.0, 3.0)]);
        assert_eq!(msg(&s), "thrust[1].direction: the direction has zero length");
        s.forces[2] = thrust(1, 0.2, Vector3::new(0.0, f64::NAN, 1.0), vec![(0.0, 3.0)]);
        assert_eq!(msg(&s), "thrust[1].direction[1]: NaN is not a finite number");
        s.forces[2] = thrust(1, 0.2, Vector3::y(), vec![(0.0, f64::INFINITY)]);
        assert_eq!(msg(&s), "thrust[1].magnitude: inf is not a finite number");
        s.forces[2] = thrust(1, 0.2, Vector3::y(), vec![(0.0, 1.0), (0.0, 2.0)]);
        assert_eq!(
            msg(&s),
            "thrust[1].magnitude[1][0]: t = 0 does not exceed the previous point's t = 0 (the schedule must increase strictly)"
        );
        s.forces[2] = thrust(1, 0.2, Vector3::y(), Vec::new());
        assert_eq!(msg(&s), "thrust[1].magnitude: the schedule has no point");
        let mut s = pendulum();
        s.joints.push(JointSpec::Clamp { body: 1 });
        assert_eq!(msg(&s), "joints[2].body: body 1 is already attached at its start by joints[1]");
    }
}
