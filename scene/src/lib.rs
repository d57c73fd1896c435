//! The scene both beam formulations build from.
//!
//! A [`Scene`] is a list of straight beam [`BodySpec`]s in their reference configuration (each
//! with a cross-[`Section`], optional [`PointMass`]es and an optional built-in [`Twist`] of its
//! sections), the [`JointSpec`]s that connect them to
//! each other and to ground, the [`ForceElement`]s (hinge springs and dampers across joints,
//! thrusts on bodies), and gravity. Bodies are referred to by index into the body list, joints by index into
//! the joint list.
//!
//! [`Scene::validate`] checks everything any later stage would reject (ANCF's slope inertias,
//! GEBF's single attachment per body start, a force element on a joint that cannot carry it), so
//! a scene that validates builds in both formulations. Every error names the field the way a case
//! file spells it: `bodies[1].section.mass`, `joints[0].spring.stiffness`.
//!
//! The crate holds data and validation only: no formulation depends on another through it.

mod body;
mod error;
mod force;
mod joint;
pub mod samples;
mod section;
pub mod twist;
mod validate;

pub use body::{BodySpec, PointMass, RigidBodyInertia};
pub use error::Error;
pub use force::{ForceElement, Schedule};
pub use joint::JointSpec;
pub use section::Section;
pub use twist::Twist;

use nalgebra::Vector3;

/// Bodies, joints, force elements and gravity.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Beam bodies.
    pub bodies: Vec<BodySpec>,
    /// Joints between bodies and to ground.
    pub joints: Vec<JointSpec>,
    /// Force elements: hinge springs across joints, thrusts on bodies.
    pub forces: Vec<ForceElement>,
    /// Gravity, m/s².
    pub gravity: Vector3<f64>,
}

impl Scene {
    /// A scene without force elements.
    pub fn new(bodies: Vec<BodySpec>, joints: Vec<JointSpec>, gravity: Vector3<f64>) -> Self {
        Self { bodies, joints, forces: Vec::new(), gravity }
    }

    /// The hinge spring acting on joint `joint`, if any (the first one listed).
    pub fn spring_on(&self, joint: usize) -> Option<&ForceElement> {
        self.forces.iter().find(|f| f.joint() == Some(joint))
    }
}
