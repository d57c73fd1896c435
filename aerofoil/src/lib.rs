//! # aerofoil — section aerodynamics on top of a lattice
//!
//! A thin lifting surface knows no Reynolds number, no profile drag, no lift curve that bends and
//! no stall. This crate holds what a section adds (issue 37, docs/section_aero.md):
//!
//! * [`Polar`]: lift, drag and quarter-chord moment coefficients against incidence, at one or
//!   more Reynolds numbers, read from a CSV file ([`read_polar`]: `alpha_deg, cl, cd, cm`, plus
//!   `re`) and validated with errors that name the file, line and column. Interpolation is
//!   monotone cubic in incidence (C¹, no overshoot; the local slope `dcl/dα` is continuous) and
//!   linear in `ln Re`; outside the ranges an error, a clamp or, in incidence, the
//!   flat-plate extrapolation to ±90° ([`Bounds`]).
//! * [`correct_strip`]: the strip correction of a lattice's loads, as SHARPy's polar correction
//!   does it, with its derivatives in the incidence and in the lattice's force, for Newton
//!   tangents and the linear stability model. From a strip's inviscid lift `L`, with
//!   `q S = ½ρV² c w`:
//!
//! $$ \alpha_e = \alpha_{0,lat} + \frac{L}{a_{lat}\,qS}, \qquad
//!    F = F_{inv} + \big(cl(\alpha_e, Re) - \tfrac{L}{qS}\big)\,qS\,\hat l + cd\,qS\,\hat d,
//!    \qquad M = M_{inv} + r_{c/4}\times(F - F_{inv}) + cm\,qS\,c\,\hat x. $$
//!
//! * [`DynamicStall`]: a dynamic-stall model (Hansen, Gaunaa & Madsen's four-state form of
//!   Beddoes–Leishman) driven by a polar, stepped per section and time step.
//!
//! The crate knows no lattice and no beam: its inputs are plain numbers and vectors in a strip's
//! frame (`x̂` span, `ŷ` towards the leading edge, `ẑ` normal; docs/conventions.md §2), so the
//! time march, statics, stability and gust can all call the same function.
//!
//! ```
//! use aerofoil::{LatticeSection, Polar, Strip, StripLoads, correct_strip};
//! use nalgebra::Vector3;
//! # fn main() -> Result<(), aerofoil::AerofoilError> {
//! let polar = aerofoil::parse_polar(
//!     "alpha_deg, cl, cd, cm\n-10, -0.9, 0.02, 0.0\n0, 0.0, 0.01, 0.0\n10, 0.9, 0.02, 0.0\n",
//!     std::path::Path::new("example.csv"),
//! )?;
//! let strip = Strip {
//!     flow: Vector3::new(0.0, -20.0, 1.0), // air relative to the strip, strip frame, m/s
//!     chord: 0.078,
//!     width: 0.02,
//!     rho: 1.225,
//!     kinematic_viscosity: 1.5e-5,
//!     fixed_reynolds: None,
//!     quarter_chord: Vector3::new(0.0, 0.0195, 0.0), // from the reference point, m
//! };
//! let inviscid = StripLoads { force: Vector3::new(0.0, 0.005, 0.2), moment: Vector3::zeros() };
//! let c = correct_strip(&polar, &LatticeSection::THIN_PLATE, &strip, &inviscid)?;
//! assert!(c.profile_drag() > 0.0 && c.loads.force.z < inviscid.force.z);
//! # Ok(()) }
//! ```
#![warn(missing_docs)]

mod dynamic_stall;
mod error;
mod extrapolation;
mod monotone_cubic;
mod polar;
mod polar_file;
mod strip;

pub use dynamic_stall::{DynamicCoefficients, DynamicStall, DynamicStallConstants, DynamicStallState, SectionFlow};
pub use error::{AerofoilError, Result};
pub use polar::{AlphaOutOfRange, Bounds, Coefficients, OutOfRange, Polar, Table};
pub use polar_file::{parse_polar, read_polar};
pub use strip::{Correction, LatticeSection, Strip, StripLoads, correct_strip};
