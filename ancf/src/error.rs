//! Typed errors of the ANCF crate.

/// Errors of model construction, sensors, loads and the static solver.
///
/// Every input error names the offending field the way a case file spells it, e.g.
/// `bodies[1].length: -0.5 is not positive`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The scene is not valid (checked once for both formulations).
    #[error(transparent)]
    Scene(#[from] scene::Error),
    /// A number that must be finite is NaN or infinite.
    #[error("{field}: {value} is not a finite number")]
    NonFinite {
        /// Field path, e.g. `bodies[0].section.ea`.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A number that must be strictly positive is not.
    #[error("{field}: {value} is not positive")]
    NotPositive {
        /// Field path.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A number that must be non-negative is negative.
    #[error("{field}: {value} is negative")]
    Negative {
        /// Field path.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A joint refers to a body that does not exist.
    #[error("{field}: no body {body} (the model has {n_bodies} bodies)")]
    NoSuchBody {
        /// Field path, e.g. `joints[0].child`.
        field: String,
        /// The index given.
        body: usize,
        /// Number of bodies in the model.
        n_bodies: usize,
    },
    /// The section frame is not orthonormal and right-handed.
    #[error("{field}: not an orthonormal right-handed frame (max |FᵀF − I| = {deviation:.3e}, det = {det:.6})")]
    BadFrame {
        /// Field path, e.g. `bodies[0].frame`.
        field: String,
        /// Largest entry of |FᵀF − I|.
        deviation: f64,
        /// Determinant of the frame.
        det: f64,
    },
    /// A joint's equations repeat equations of earlier joints (over-constrained node).
    #[error("joints[{joint}]: its equations are redundant with earlier joints (over-constrained node)")]
    RedundantJoint {
        /// Index of the joint.
        joint: usize,
    },
    /// A joint index out of range.
    #[error("joint {joint}: no such joint (the model has {n_joints} joints)")]
    NoSuchJoint {
        /// Index asked for.
        joint: usize,
        /// Number of joints.
        n_joints: usize,
    },
    /// A sensor that needs a ground hinge or a free flared hinge was asked about another joint
    /// type.
    #[error("joint {joint}: not a ground hinge or free flared hinge")]
    NotAFreeHinge {
        /// Index asked for.
        joint: usize,
    },
    /// A sensor that needs a flared hinge was asked about another joint type.
    #[error("joint {joint}: not a flared hinge")]
    NotAFlaredHinge {
        /// Index asked for.
        joint: usize,
    },
    /// A station outside the body.
    #[error("{field}: arclength {s} m is outside [0, {length}] m")]
    ArclengthOutOfRange {
        /// Field path, e.g. `loads[3].s`.
        field: String,
        /// Arclength given, m.
        s: f64,
        /// Body length, m.
        length: f64,
    },
    /// The static Newton iteration failed.
    #[error(
        "statics did not converge at load factor {load_factor:.4} after {iter} iterations (residual {residual_norm:.3e})"
    )]
    StaticsDiverged {
        /// Load factor of the failed load step.
        load_factor: f64,
        /// Newton iterations done in that load step.
        iter: usize,
        /// Infinity norm of the last residual.
        residual_norm: f64,
    },
    /// A list of rigid poses whose length is not the number of bodies.
    #[error("poses: {got} poses given, the model has {expected} bodies")]
    PoseCount {
        /// Number of poses given.
        got: usize,
        /// Number of bodies.
        expected: usize,
    },
    /// A state carried from a model that does not share this one's full coordinates (or a
    /// state that does not fit the model it came from).
    #[error("carried state: the previous model has {got} full coordinates, this one {expected}")]
    CarriedState {
        /// Full coordinates of the previous model.
        got: usize,
        /// Full coordinates of this one.
        expected: usize,
    },
    /// A singular matrix in the static solver or the modal analysis.
    #[error("singular matrix (zero pivot in row {pivot})")]
    SingularMatrix {
        /// Row of the first zero pivot.
        pivot: usize,
    },
}
