//! Force elements: forces that act across joints (hinge springs and dampers) or on one body
//! (thrust, a follower force), with their own stiffness, damping or schedule.

use nalgebra::Vector3;

/// A piecewise-linear schedule of a value in time: points `(t, value)` with strictly increasing
/// `t`, linear in between and held constant outside; one point is a constant.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// The points `(t (s), value)`.
    pub points: Vec<(f64, f64)>,
}

impl Schedule {
    /// A constant value.
    pub fn constant(value: f64) -> Self {
        Self { points: vec![(0.0, value)] }
    }

    /// The value at time `t` (0 for an empty schedule, which validation refuses). Does not
    /// allocate.
    pub fn at(&self, t: f64) -> f64 {
        let p = &self.points;
        let (Some(first), Some(last)) = (p.first(), p.last()) else { return 0.0 };
        if t <= first.0 {
            return first.1;
        }
        if t >= last.0 {
            return last.1;
        }
        let i = p.partition_point(|x| x.0 <= t) - 1;
        let (a, b) = (p[i], p[i + 1]);
        a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
    }
}

/// A force element. A hinge spring acts across one joint of the scene; a thrust acts on one
/// body.
#[derive(Debug, Clone, PartialEq)]
pub enum ForceElement {
    /// A rotational spring and damper about a hinge's axis: the moment
    /// `M = −k (θ − θ₀) − c θ̇` about the hinge axis, on the child (and `−M` on the parent or
    /// ground), with θ the hinge's rotation (the fold angle of a flared hinge, the rotation about
    /// the axis of a ground hinge) measured from the reference configuration.
    HingeSpring {
        /// The joint (a ground or free flared hinge).
        joint: usize,
        /// Rotational stiffness k, N·m/rad (≥ 0).
        stiffness: f64,
        /// Rotational damping c, N·m·s/rad (≥ 0).
        damping: f64,
        /// Rest angle θ₀, rad.
        rest: f64,
    },
    /// A follower force `F = T(t) R(s) d` at the axis point at arclength `at` of a body: its
    /// direction `d` is fixed in the section at `at` and turns with it (case field `thrust`).
    Thrust {
        /// The body.
        body: usize,
        /// Arclength of the point of application, m, in `[0, length]`.
        at: f64,
        /// Unit direction in the body's twisted reference section frame at `at`
        /// ([`BodySpec::section_frame`](crate::BodySpec::section_frame): x along the axis, y
        /// towards the leading edge, z = x × y).
        direction: Vector3<f64>,
        /// Magnitude T(t), N.
        magnitude: Schedule,
    },
}

impl ForceElement {
    /// The joint the element acts across (`None`: an element on one body, a thrust).
    pub fn joint(&self) -> Option<usize> {
        match *self {
            ForceElement::HingeSpring { joint, .. } => Some(joint),
            ForceElement::Thrust { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Schedule;

    #[test]
    fn schedule_is_linear_between_points_and_held_outside() {
        let s = Schedule { points: vec![(1.0, 10.0), (3.0, 30.0), (4.0, 0.0)] };
        for (t, v) in [(-1.0, 10.0), (1.0, 10.0), (2.0, 20.0), (3.0, 30.0), (3.5, 15.0), (4.0, 0.0), (9.0, 0.0)] {
            approx::assert_relative_eq!(s.at(t), v, epsilon = 1e-12);
        }
        assert_eq!(Schedule::constant(5.0).at(-3.0), 5.0);
        assert_eq!(Schedule { points: Vec::new() }.at(1.0), 0.0);
    }
}
