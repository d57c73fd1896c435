//! The one error type of the case files.

use crate::Formulation;

/// Errors of reading, expanding and validating a case file, of the reference files it names and
/// of building its models.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A case file is malformed or has an impossible value.
    #[error("{file}: {msg}")]
    Case {
        /// Case file.
        file: String,
        /// What is wrong, naming the field.
        msg: String,
    },
    /// A `--set` override is malformed or does not fit the case.
    #[error("--set: {0}")]
    Override(String),
    /// Reading a file failed.
    #[error("{0}")]
    Io(String),
    /// A reference CSV is malformed.
    #[error("reference {file}: {msg}")]
    Reference {
        /// The file.
        file: String,
        /// What is wrong.
        msg: String,
    },
    /// Building a model failed.
    #[error("{formulation} model: {msg}")]
    Model {
        /// Which formulation.
        formulation: Formulation,
        /// The library's message.
        msg: String,
    },
}

impl From<aeroelastic::Error> for Error {
    fn from(e: aeroelastic::Error) -> Self {
        match e {
            aeroelastic::Error::Model { formulation, msg } => Error::Model { formulation, msg },
        }
    }
}
