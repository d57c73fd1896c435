//! Joints between bodies and to ground.

use nalgebra::Vector3;

/// Joints; bodies are referred to by index into the body list.
#[derive(Debug, Clone, PartialEq)]
pub enum JointSpec {
    /// The body's start point pinned to ground; rotation only about a fixed global axis.
    GroundHinge {
        /// The body.
        body: usize,
        /// Hinge axis, global (any non-zero length; normalised by the formulations).
        axis: Vector3<f64>,
    },
    /// End of `parent` to start of `child`; axis `a = sin β x + cos β y` in the section frame of
    /// the parent's end (β in rad, [−π/2, π/2]).
    FlaredHinge {
        /// Parent body (its end section).
        parent: usize,
        /// Child body (its start section).
        child: usize,
        /// Flare angle β, rad.
        beta: f64,
    },
    /// The body's start section fully clamped to ground.
    Clamp {
        /// The body.
        body: usize,
    },
    /// No constraint: the body's start is free in space, with six rigid-body degrees of freedom
    /// relative to the ground (the root of a free-flying chain). A body without any joint is
    /// free too; the joint states it and refuses a parent.
    Free {
        /// The body.
        body: usize,
    },
    /// A flared hinge locked at fold `fold`: the child's start section is welded to the parent's
    /// end section, turned from their reference relative pose by `fold` about `−a`. The fold
    /// angle is still measured about `a = sin β x + cos β y`.
    LockedHinge {
        /// Parent body (its end section).
        parent: usize,
        /// Child body (its start section).
        child: usize,
        /// Flare angle β of the locked hinge, rad.
        beta: f64,
        /// Fold angle at which the hinge is welded, rad (0: the reference configuration).
        fold: f64,
    },
}

impl JointSpec {
    /// The body the joint attaches at its start (the child of a hinge).
    pub fn attached_body(&self) -> usize {
        match *self {
            JointSpec::GroundHinge { body, .. } | JointSpec::Clamp { body } | JointSpec::Free { body } => body,
            JointSpec::FlaredHinge { child, .. } | JointSpec::LockedHinge { child, .. } => child,
        }
    }

    /// A short name of the joint's kind, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            JointSpec::GroundHinge { .. } => "ground hinge",
            JointSpec::FlaredHinge { .. } => "flared hinge",
            JointSpec::Clamp { .. } => "clamp",
            JointSpec::Free { .. } => "free joint",
            JointSpec::LockedHinge { .. } => "locked hinge",
        }
    }
}
