//! Typed validation errors; each names the field the way a case file spells it.

/// Why a scene is not valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
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
    /// A value outside its admissible interval.
    #[error("{field}: {value} is not in [{min}, {max}]")]
    OutOfRange {
        /// Field path.
        field: String,
        /// The value.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A body needs at least one element.
    #[error("{field}: a body needs at least one element (got 0)")]
    ZeroElements {
        /// Field path, e.g. `bodies[2].n_elements`.
        field: String,
    },
    /// A scene needs at least one body.
    #[error("bodies: the scene has no body")]
    NoBodies,
    /// A joint or point mass refers to a body that does not exist.
    #[error("{field}: no body {body} (the scene has {n_bodies} bodies)")]
    NoSuchBody {
        /// Field path, e.g. `joints[0].child`.
        field: String,
        /// The index given.
        body: usize,
        /// Number of bodies.
        n_bodies: usize,
    },
    /// A force element refers to a joint that does not exist.
    #[error("{field}: no joint {joint} (the scene has {n_joints} joints)")]
    NoSuchJoint {
        /// Field path, e.g. `forces[0].joint`.
        field: String,
        /// The index given.
        joint: usize,
        /// Number of joints.
        n_joints: usize,
    },
    /// A force element on a joint that has no free rotation to act on.
    #[error("{field}: a hinge spring needs a free ground or flared hinge, not a {kind}")]
    NotAHinge {
        /// Field path.
        field: String,
        /// The joint's kind.
        kind: &'static str,
    },
    /// Two force elements on one joint.
    #[error("{field}: joint {joint} already has a spring (forces[{other}])")]
    DuplicateSpring {
        /// Field path.
        field: String,
        /// The joint.
        joint: usize,
        /// The earlier force element.
        other: usize,
    },
    /// A hinge connects a body to itself.
    #[error("{field}: body {body} cannot be hinged to itself")]
    SelfJoint {
        /// Field path.
        field: String,
        /// The body index.
        body: usize,
    },
    /// A body frame whose columns are not orthonormal and right-handed.
    #[error("{field}: not an orthonormal right-handed frame (max |FᵀF − I| = {deviation:.3e}, det = {det:.6})")]
    BadFrame {
        /// Field path, e.g. `bodies[0].frame`.
        field: String,
        /// Largest entry of |FᵀF − I|.
        deviation: f64,
        /// Determinant of the frame.
        det: f64,
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
    /// A body attached at its start by more than one joint.
    #[error("{field}: body {body} is already attached at its start by joints[{other}]")]
    DoublyAttached {
        /// Field path.
        field: String,
        /// The body.
        body: usize,
        /// The earlier joint.
        other: usize,
    },
    /// Flared hinges that form a closed loop.
    #[error("joints[{joint}]: the flared hinges form a closed loop")]
    JointLoop {
        /// A joint on the loop.
        joint: usize,
    },
    /// The section inertias leave ANCF's section slopes without mass.
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
    /// A point mass whose inertia is not a physical (triangle-inequality) rigid-body inertia.
    #[error("{field}: principal inertias {inertia:?} kg·m² violate the triangle inequality (I_a ≤ I_b + I_c)")]
    ImpossibleInertia {
        /// Field path, e.g. `bodies[0].point_masses[1].inertia`.
        field: String,
        /// The inertias given.
        inertia: [f64; 3],
    },
    /// A twist table whose arclengths do not increase strictly.
    #[error(
        "{field}: s = {value} does not exceed the previous point's s = {previous} (the table must increase strictly)"
    )]
    TwistNotIncreasing {
        /// Field path, e.g. `bodies[1].twist[2].s`.
        field: String,
        /// The offending arclength, m.
        value: f64,
        /// The previous point's arclength, m.
        previous: f64,
    },
    /// A direction vector of zero length.
    #[error("{field}: the direction has zero length")]
    ZeroDirection {
        /// Field path, e.g. `thrust[0].direction`.
        field: String,
    },
    /// A schedule without points.
    #[error("{field}: the schedule has no point")]
    EmptySchedule {
        /// Field path, e.g. `thrust[0].magnitude`.
        field: String,
    },
    /// A schedule whose times do not increase strictly.
    #[error(
        "{field}: t = {value} does not exceed the previous point's t = {previous} (the schedule must increase strictly)"
    )]
    ScheduleNotIncreasing {
        /// Field path, e.g. `thrust[0].magnitude[2].t`.
        field: String,
        /// The offending time, s.
        value: f64,
        /// The previous point's time, s.
        previous: f64,
    },
}
