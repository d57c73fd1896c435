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
//! **Strains and elastic forces** (reduced 2-point integration, [`Options::n_gauss_stiffness`]):
//! $$ \gamma = C^{BA}(\psi) R' - e_x,\quad \kappa = T(\psi)\psi',\quad
//!    U = \tfrac12\int \gamma^T S_\gamma \gamma + \kappa^T S_\kappa \kappa \, ds .$$
//!
//! **Inertia** (3-point integration): with `W = v_A + R_dot + omega_A × R` and
//! `Omega = T(psi) psi_dot + C^{BA} omega_A`, `T_kin = ½ ∫ m|W|² + Omegaᵀ J Omega ds` (plus the
//! rigid slices of point masses and of offset centres of mass, docs/gebf.md §14); the
//! equations of motion are
//!
//! $$ M(q)\dot v + g_{gyr}(q, v) + g_{el}(q) - f_{grav}(q) - f_{ext}(q) + B(q)^T \mu = 0,
//!    \qquad B(q)\,v = 0 ,$$
//!
//! with the joint rows `B v = 0` at velocity level ([`JointSpec`]: ground hinge, flared hinge,
//! clamp; the flared hinge's angular rows are projected on a fixed pair perpendicular to the
//! axis, valid for every β) and exact tangents of every term, including `∂(B v)/∂q` and
//! `∂(Bᵀ mu)/∂q` (finite-difference checked in the unit tests).
//!
//! **Time integration** by [`genalpha::GenAlpha`] with the Lie update of [`Model`]'s
//! `retract_inplace` (additive on nodes; `χ ← χ ⊗ exp(δθ/2)` and the frame position advanced
//! with the midpoint orientation on frames, second order). The model declares its block-banded
//! matrix structure, so the integrator's LU works on a Schur complement of the frame and joint
//! unknowns. Stored nodal CRVs are rescaled past π after every step (rates transformed), and
//! elements map their end nodes onto the middle node's branch with the exact chain rule, so
//! rotations of more than π relative to a body frame are handled.
//!
//! ## API used by the harness
//! * [`Model::new`] (validates, errors name the field), [`Model::initial_state`],
//!   [`Model::tip_position`], [`Model::fold_angle`], [`Model::energies`],
//!   [`Model::constraint_residual`], [`Model::span`]; [`Options`] (`stabilization`: position
//!   projection after each step, off by default).
//! * Aerodynamic coupling: [`Model::set_nodal_load`] / [`Model::clear_nodal_loads`] apply a force
//!   and a moment in global components at a node (held fixed during a step); the geometry comes
//!   from [`Model::node_position`], [`Model::node_frame`], [`Model::node_velocity`],
//!   [`Model::node_angular_velocity`] and [`Model::node_arc_length`].
//! * Force elements and mass distribution from the [`Scene`] ([`Model::from_scene`]): hinge
//!   springs and dampers on ground and free flared hinges ([`ForceElement::HingeSpring`];
//!   [`Model::hinge_angle`], [`Model::dissipation_power`], [`Energies::spring`],
//!   [`Model::reset_hinge_angles`]; docs/gebf.md §13), point masses ([`PointMass`]) and the
//!   section's centre-of-mass offset (`Section::cg_offset`), exact in the inertial forces,
//!   gravity and the potential (docs/gebf.md §14).
//! * Extras: [`Model::solve_static`] (Newton with load stepping), [`Model::linear_modes`],
//!   [`samples`] (the paper's cases, SHARPy's regression, cantilevers), [`simulate`] (a plain
//!   time loop).
//!
//! ## Known limitations
//! * The velocity-level joints drift in position (measured by `constraint_residual`; ~2e-4 in
//!   2 s for the paper's c = 1, β = 45° case); `Options::stabilization` projects it away.
//! * CRV interpolation is not objective for deformed elements (Crisfield & Jelenić); the effect
//!   is ~1e-6 of the element energy for moderate curvature.
//! * The flexible paper cases (c = 0.1, 0.01, β = 45°) need 5–6 Newton iterations per step and
//!   some step halvings. The slow direction is almost always the child frame's rotation about
//!   its own x axis with the nodal CRVs counter-rotating (node 0 is clamped to the frame, so this
//!   is the twist of the first half element: inertia ~1e-6 kg·m², the smallest singular value
//!   of the scaled iteration matrix, ~3e-7 of the largest at c = 0.01). The tangent is exact
//!   there (finite differences agree to 1e-9), but the hinge moment makes that direction
//!   strongly nonlinear, and a diverging iterate can end in a singular matrix; the integrator
//!   then halves the step, which is counted in its statistics.
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
mod hinge_spring;
mod inertia;
mod joint;
mod loads;
mod modal;
mod model;
mod momentum;
mod momentum_hold;
mod options;
pub mod quaternion;
mod rigid;
mod rigid_slice;
pub use scene::samples;
mod section;
pub mod simulate;
mod statics;
mod stiffness;
mod structure;
mod thrust;

pub use body::BodySpec;
pub use error::Error;
pub use formulation::Energies;
pub use joint::JointSpec;
pub use loads::NodalLoad;
pub use modal::Modes;
pub use model::Model;
pub use options::Options;
pub use rigid::RigidPose;
pub use scene::{ForceElement, PointMass, Scene, Twist};
pub use section::Section;
pub use statics::{StaticOptions, StaticSolution};

#[cfg(test)]
mod tangent_tests;
