//! # ancf — absolute nodal coordinate beams with linear joints
//!
//! Two-node beam elements with the nodal coordinates `e_k = [r, r_x, r_y, r_z]` (12 per node,
//! 24 per element; docs/ancf.md), a constant mass matrix, an elastic force from beam strains written
//! as quadratic forms of the coordinates (exact analytic tangent), and joints that are *linear*
//! in the coordinates (ground hinge, flared hinge of paper eq. 5, clamp). Equations of motion:
//!
//! $$ M \ddot q + f_{el}(q) - Q + \Phi_q^T \lambda = 0,\qquad \Phi(q) = \Phi_q q - c = 0 $$
//!
//! (index-3 DAE, constant `M` and `Φ_q`), or, eliminating the joints with the constant velocity
//! transformation `q = B z + q_p`, `Φ_q B = 0` (paper eq. 6–7),
//!
//! $$ B^T M B\, \ddot z + B^T\big(f_{el}(B z + q_p) - Q\big) = 0 . $$
//!
//! [`Model`] implements [`genalpha::ConstrainedSystem`] in either form ([`Options::path`]).
//! Elastic energy (docs/ancf.md §3), with reference values subtracted:
//!
//! $$ U = \tfrac12\int_0^L \big[EA\,\varepsilon^2 + GA_y\gamma_y^2 + GA_z\gamma_z^2 + GJ K_1^2
//!      + EI_{yy} K_2^2 + EI_{zz} K_3^2\big] dx + \text{section penalties}. $$
//!
//! **Element** ([`strain`], [`elastic_force`]): every strain is a quadratic form of the element
//! coordinates, so force and tangent are exact and trigonometry-free. Bending uses the
//! *hybrid* curvature ([`Curvature::Hybrid`]): element-mean curvature from the rotation of the
//! section slopes (so a joint that holds a section takes the moment directly) plus the zero-mean
//! variation of the cubic centreline (linearly varying curvature exact); shear and the
//! cross-section penalties are sampled at the nodes (no shear or curvature-thickness locking).
//! Joint loads on single nodal slopes (the flared hinge's `a = sin β r_x + cos β r_y`) would reach
//! the section only through node-local terms whose stiffness vanishes with the element length;
//! *section ties* at the hinge nodes (docs/ancf.md §3.5: the nodal triad held orthonormal with
//! a stiffness `∝ EI/l`) fix the joint's axis in the section, so the joint compliance vanishes
//! under refinement and the element converges to geometrically exact beam theory (§3.7).
//!
//! **Force elements and lumped masses** (docs/ancf.md §11–12): a hinge spring and damper
//! ([`ForceElement::HingeSpring`]) on a ground or free flared hinge adds
//! `(k(θ − θ₀) + c θ̇) θ_q` to the residual, with θ a smooth, unwrapped function of the section
//! slopes and analytic tangents; point masses ([`PointMass`]) and a section centre of mass off
//! the axis ([`Section::cg_offset`]) add constant terms to `M` and to the gravity force, since
//! every material point is linear in the coordinates.
//!
//! **Use**: build a [`Model`] from [`BodySpec`]s and [`JointSpec`]s (or a [`Scene`] with force
//! elements, [`Model::from_scene`]), take
//! [`Model::initial_state`], integrate with [`Model::integrator`] (generalized-α with the
//! [`SkylineLu`] solver) or `genalpha::GenAlpha::new` (the model declares its band structure),
//! read [`Model::tip_position`], [`Model::fold_angle`], [`Model::hinge_angle`],
//! [`Model::energies`], [`Model::dissipation_power`], [`Model::constraint_residual`]; apply aerodynamic or other loads with
//! [`Model::set_point_loads`]; statics with [`Model::solve_static`], linear modes with
//! [`Model::linear_modes`]. Reference scenes are in [`samples`].
//!
//! Units SI; global frame as in docs/conventions.md §1.
#![warn(missing_docs)]

mod carry;
pub mod elastic_force;
pub mod element;
mod error;
pub mod frame;
mod hinge_spring;
mod joint;
mod loads;
pub mod mass;
pub mod modal;
mod model;
mod node_tie;
pub mod point_mass;
pub mod reduction;
mod rigid;
pub use scene::samples;
pub mod shape;
pub mod skyline;
mod spec;
mod static_step;
pub mod statics;
pub mod strain;
mod structure;
mod thrust;

pub use error::Error;
pub use formulation::Energies;
pub use joint::ConstraintRow;
pub use loads::PointLoad;
pub use modal::{Mode, ModeKind};
pub use model::Model;
pub use rigid::RigidPose;
pub use skyline::SkylineLu;
pub use spec::{BodySpec, Curvature, ForceElement, JointSpec, Options, PointMass, Scene, Section, SolvePath, Twist};
pub use strain::StrainKind;
