//! Force elements: forces that act across joints, with their own stiffness and damping.

/// A force element. Each acts across one joint of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
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
}

impl ForceElement {
    /// The joint the element acts across.
    pub fn joint(&self) -> usize {
        match *self {
            ForceElement::HingeSpring { joint, .. } => joint,
        }
    }
}
