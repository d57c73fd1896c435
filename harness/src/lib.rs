//! # harness — both formulations on every case, compared and reported
//!
//! Reads case files ([`case`]), builds the scene for ANCF and for GEBF ([`scene`]), integrates
//! each with the shared generalized-α integrator ([`run`]), compares them with each other and with
//! external references ([`metrics`]), writes CSV, `summary.json`, SVG plots and an HTML index
//! ([`report`], [`plot`]), a 3-D view ([`view3d`]) and ParaView files ([`vtk`]) and enforces the cross-formulation gate ([`gate`]). Studies: refinement
//! ladders ([`converge`]), the stress matrix ([`stress`]), energy by integrator form
//! ([`energy`]), speed ([`bench`](mod@bench), [`bench_aero`]). Sweeps split across processes or a SLURM job array
//! ([`shard`]) and are merged into one report ([`merge`]).
#![warn(missing_docs)]

pub mod atomic;
pub mod bench;
pub mod bench_aero;
pub mod console;
pub mod converge;
pub mod csv;
pub mod driver;
pub mod energy;
pub mod fuzz;
pub mod gate;
pub mod gust_out;
pub mod healy_readings;
pub mod merge;
pub mod metrics;
pub mod plot;
pub mod progress;
pub mod report;
pub mod shard;
pub mod signal;
pub mod stability_out;
pub mod static_out;
pub mod stress;
pub mod trim_out;
pub mod view3d;
pub mod vtk;

// The analyses live in the `aeroelastic` library, the case files in `casefile`; their modules keep
// their harness paths.
pub use aeroelastic::{aero, gust, gust_linear, lifting, loads, pencil, run, stability, static_hold, statics};
pub use casefile as case;
pub use casefile::{budget, scene};

/// Errors of the harness library (the binary adds context with anyhow).
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
    /// Reading or writing a file failed.
    #[error("{0}")]
    Io(String),
    /// A `--shard` is malformed, or the SLURM array it reads is unusable, or the shards to merge
    /// do not fit together.
    #[error("--shard: {0}")]
    Shard(String),
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
        formulation: case::Formulation,
        /// The library's message.
        msg: String,
    },
    /// Plotting failed.
    #[error("plot {file}: {msg}")]
    Plot {
        /// The file.
        file: String,
        /// What failed.
        msg: String,
    },
}

impl From<casefile::Error> for Error {
    fn from(e: casefile::Error) -> Self {
        match e {
            casefile::Error::Case { file, msg } => Error::Case { file, msg },
            casefile::Error::Override(msg) => Error::Override(msg),
            casefile::Error::Io(msg) => Error::Io(msg),
            casefile::Error::Reference { file, msg } => Error::Reference { file, msg },
            casefile::Error::Model { formulation, msg } => Error::Model { formulation, msg },
        }
    }
}

impl From<aeroelastic::Error> for Error {
    fn from(e: aeroelastic::Error) -> Self {
        match e {
            aeroelastic::Error::Model { formulation, msg } => Error::Model { formulation, msg },
        }
    }
}
