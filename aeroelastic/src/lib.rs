//! # aeroelastic — the analyses of flexmb over any beam formulation
//!
//! A [`Problem`] (the structure, each formulation's discretisation and settings, and what acts
//! on it) and a formulation's model ([`factory`]) go into the analyses:
//! the time march with observers ([`run`]), coupled with the UVLM ([`aero`]); the static
//! aeroelastic equilibria ([`statics`]) and the model held at measured angles
//! ([`static_hold`]); the linear stability about them ([`stability`]); the gust response, marched
//! ([`gust`]) and linear ([`gust_linear`]); the wing's root and hinge loads ([`loads`]); and the
//! matrix pencil that reads oscillations off a time history ([`pencil`]). Every analysis is
//! written once, generic over [`formulation::Structure`]; none reads a file.
#![warn(missing_docs)]

pub mod aero;
pub mod aero_settings;
pub mod clock;
pub mod control_surface;
pub mod events;
pub mod factory;
pub mod flight_modes;
pub mod gust;
pub mod gust_field;
pub mod gust_linear;
pub mod gust_settings;
pub mod hinge_line;
pub mod interrupt;
pub mod level_coast;
pub mod lifting;
pub mod loads;
pub mod pencil;
pub mod planform;
pub mod polar_correction;
pub mod problem;
pub mod run;
pub mod section_polars;
pub mod stability;
pub mod stability_settings;
pub mod static_hold;
pub mod statics;
pub mod strip_march;
pub mod strip_statics;
pub mod thrust;
pub mod trim;

pub use problem::{Formulation, Problem};

/// Errors of the analyses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// Building a model failed.
    #[error("{formulation} model: {msg}")]
    Model {
        /// Which formulation.
        formulation: Formulation,
        /// The model crate's message.
        msg: String,
    },
}
