//! # gebf — a SHARPy-style geometrically exact beam with floating frames
//!
//! The second structural formulation of the harness: displacement-based geometrically exact
//! beams in the style of SHARPy's structural core (xbeam), with one floating frame of reference
//! A per body and velocity-level joints, integrated by the shared [`genalpha`] integrator.
//!
//! **Kinematics.** Each body is discretised into three-node quadratic elements. Node `i` carries
//! its position `R_i` in A and the CRV `psi_i` of its section frame B relative to A (node 0 is
//! clamped to A). The frame has position `r_A` (global), orientation quaternion `χ`
//! (`C^{GA}`), and velocities `v_A`, `omega_A` in A components.
//!
//! **Strains and elastic forces** (reduced 2-point integration):
//! $$ \gamma = C^{BA}(\psi) R' - e_x,\quad \kappa = T(\psi)\psi',\quad
//!    U = \tfrac12\int \gamma^T S_\gamma \gamma + \kappa^T S_\kappa \kappa \, ds .$$
//!
//! **Inertia** (3-point integration): with `W = v_A + R_dot + omega_A × R` and
//! `Omega = T(psi) psi_dot + C^{BA} omega_A`, `T_kin = ½ ∫ m|W|² + Omegaᵀ J Omega ds`; the
//! equations of motion are
//!
//! $$ M(q)\dot v + g_{gyr}(q, v) + g_{el}(q) - f_{grav}(q) - f_{ext}(q) + B(q)^T \mu = 0,
//!    \qquad B(q)\,v = 0 ,$$
//!
//! with the joint rows `B v = 0` at velocity level (ground hinge, flared hinge, clamp) and
//! exact tangents of every term (including `∂(B v)/∂q` and `∂(Bᵀ mu)/∂q`).
//!
//! **Time integration**: [`genalpha::GenAlpha`] with the Lie update of [`Model`]'s
//! `retract_inplace` (additive on nodes, `χ ← χ ⊗ exp(δθ/2)` on frames).
//!
//! Start with [`samples::double_pendulum`], [`Model::new`] and [`simulate::run`].
#![warn(missing_docs)]
// The element math indexes nodes k, l and their shape functions explicitly, as the equations do.
#![allow(clippy::needless_range_loop)]

mod body;
mod clamp;
pub mod crv;
mod element;
mod error;
mod flared_hinge;
mod gravity;
mod ground_hinge;
mod inertia;
mod joint;
mod loads;
mod modal;
mod model;
mod options;
pub mod quaternion;
pub mod samples;
mod section;
pub mod simulate;
mod statics;
mod stiffness;

pub use body::BodySpec;
pub use error::Error;
pub use joint::JointSpec;
pub use loads::NodalLoad;
pub use modal::Modes;
pub use model::{Energies, Model};
pub use options::Options;
pub use section::Section;
pub use statics::{StaticOptions, StaticSolution};

#[cfg(test)]
mod tangent_tests;
