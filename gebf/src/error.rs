//! Typed errors of the crate.

/// Errors of model construction, queries and the static solver.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The scene is not valid (checked once for both formulations).
    #[error(transparent)]
    Scene(#[from] scene::Error),
    /// A number that must be finite is not.
    #[error("{field}: {value} is not finite")]
    NonFinite {
        /// Path of the offending input field, e.g. `bodies[0].start`.
        field: String,
        /// The value.
        value: f64,
    },
    /// A count that must be at least one is zero.
    #[error("{field}: must be at least 1")]
    ZeroCount {
        /// Path of the offending input field.
        field: String,
    },
    /// A value outside its admissible interval.
    #[error("{field}: {value} is not in [{min}, {max}]")]
    OutOfRange {
        /// Path of the offending input field.
        field: String,
        /// The value.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A body frame whose columns are not orthonormal and right-handed.
    #[error("{field}: not an orthonormal right-handed frame (|FᵀF − I| = {deviation:.3e}, det = {det:.6})")]
    NotOrthonormal {
        /// Path of the offending input field.
        field: String,
        /// Largest entry of |FᵀF − I|.
        deviation: f64,
        /// Determinant.
        det: f64,
    },
    /// A joint refers to a body that does not exist.
    #[error("{field}: no body {body} (the model has {n_bodies})")]
    NoSuchBody {
        /// Path of the offending input field.
        field: String,
        /// The index given.
        body: usize,
        /// Number of bodies.
        n_bodies: usize,
    },
    /// A joint index out of range.
    #[error("no joint {joint} (the model has {n_joints})")]
    NoSuchJoint {
        /// The index given.
        joint: usize,
        /// Number of joints.
        n_joints: usize,
    },
    /// A query that needs a flared hinge was given another joint.
    #[error("joints[{joint}] is not a flared hinge")]
    NotAFlaredHinge {
        /// The joint.
        joint: usize,
    },
    /// A query that needs a free hinge (a ground hinge or a free flared hinge) was given
    /// another joint.
    #[error("joints[{joint}] is not a ground hinge or a free flared hinge")]
    NotAFreeHinge {
        /// The joint.
        joint: usize,
    },
    /// A node index out of range.
    #[error("body {body} has no node {node} (it has {n_nodes})")]
    NoSuchNode {
        /// The body.
        body: usize,
        /// The node given.
        node: usize,
        /// Number of nodes of the body.
        n_nodes: usize,
    },
    /// A vector of the wrong length.
    #[error("{what}: length {got}, expected {expected}")]
    WrongLength {
        /// What was passed.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The expected length.
        expected: usize,
    },
    /// The static Newton iteration failed.
    #[error(
        "static solve did not converge at load factor {load_factor:.4} after {iter} iterations \
         (residual {residual_norm:.3e}, increment {increment_norm:.3e})"
    )]
    StaticDiverged {
        /// Load factor reached, in (0, 1].
        load_factor: f64,
        /// Iterations done at that load.
        iter: usize,
        /// Infinity norm of the residual.
        residual_norm: f64,
        /// Infinity norm of the last increment.
        increment_norm: f64,
    },
    /// The eigenvalue problem could not be set up (singular mass matrix on the free dofs).
    #[error("modal analysis: the mass matrix restricted to the free motions is not positive definite")]
    SingularMass,
    /// An error of the time integrator.
    #[error(transparent)]
    Integrator(#[from] genalpha::Error),
}
