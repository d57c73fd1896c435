//! # formulation — what every beam formulation offers the analyses
//!
//! One trait, [`Structure`], sits between the structural models (`ancf`, `gebf`) and the
//! analyses built on them (the coupled time march, statics, stability, gust response, loads).
//! A model implements it in its own crate; an analysis is generic over it and never names a
//! formulation. A third formulation implements [`Structure`] and adds one line to the factory
//! that builds a model from a case.
//!
//! The trait extends [`genalpha::ConstrainedSystem`] — the residual
//! $r(q, \dot q, \ddot q, \lambda, t)$, its iteration matrix and the constraint rows the
//! integrator needs — with
//!
//! * the integrator the formulation runs best with ([`Structure::integrator`]) and its state at
//!   rest ([`Structure::initial_state`]);
//! * the sensors of a time history: tip, fold angle, [`Energies`], the dampers' dissipation power
//!   $\sum c\,\dot\theta^2$, the position-level constraint residual and the [`Momentum`] of a
//!   free-flying model;
//! * the aerodynamic seam: the pose of a section at (body, arclength `s`) and the section loads
//!   ([`SectionLoad`]), set through [`Structure::set_section_loads`], which checks every load
//!   the same way for every formulation and returns a [`LoadError`] naming the station;
//! * the body geometry an output draws ([`BeamGeometry`]);
//! * the statics hook [`Structure::normalise`] and the unknown count
//!   [`Structure::n_unknowns`].
#![warn(missing_docs)]

mod energies;
mod geometry;
mod load;
mod momentum;
mod structure;

pub use energies::Energies;
pub use geometry::BeamGeometry;
pub use load::{LoadError, SectionLoad, check_section_loads};
pub use momentum::Momentum;
pub use structure::{SectionMotion, SectionState, Structure};
