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
    /// A scene feature this formulation does not model.
    #[error("{field}: not supported by the ANCF formulation")]
    Unsupported {
        /// Field path.
        field: String,
    },
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
    /// A body needs at least one element.
    #[error("{field}: a body needs at least one element (got 0)")]
    ZeroElements {
        /// Field path, e.g. `bodies[2].n_elements`.
        field: String,
    },
    /// A model needs at least one body.
    #[error("bodies: the model has no body")]
    NoBodies,
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
    /// A flared hinge connects a body to itself.
    #[error("{field}: body {body} cannot be hinged to itself")]
    SelfJoint {
        /// Field path.
        field: String,
        /// The body index.
        body: usize,
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
    /// A flare angle outside [−π/2, π/2].
    #[error("{field}: {beta} rad is outside [-pi/2, pi/2]")]
    BetaOutOfRange {
        /// Field path.
        field: String,
        /// The flare angle given, rad.
        beta: f64,
    },
    /// A zero hinge axis.
    #[error("{field}: the axis has zero length")]
    ZeroAxis {
        /// Field path.
        field: String,
    },
    /// The child body of a flared hinge does not start where its parent ends.
    #[error("{field}: the child starts {gap:.3e} m away from the parent's end")]
    JointGap {
        /// Field path.
        field: String,
        /// Distance between the parent's end and the child's start, m.
        gap: f64,
    },
    /// The section inertias leave the section slopes without mass.
    #[error(
        "{field}: the section inertias give D_yy = {d_yy:.3e}, D_zz = {d_zz:.3e} kg·m; both must be positive \
         (D_yy = (rho_ixx - rho_iyy + rho_izz)/2, D_zz = (rho_ixx + rho_iyy - rho_izz)/2)"
    )]
    MasslessSection {
        /// Field path, e.g. `bodies[0].section`.
        field: String,
        /// Mapped inertia on the y-slope, kg·m.
        d_yy: f64,
        /// Mapped inertia on the z-slope, kg·m.
        d_zz: f64,
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
    /// A singular matrix in the static solver or the modal analysis.
    #[error("singular matrix (zero pivot in row {pivot})")]
    SingularMatrix {
        /// Row of the first zero pivot.
        pivot: usize,
    },
}
