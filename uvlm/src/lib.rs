//! # uvlm — unsteady vortex-lattice aerodynamics for the flared-hinge wing harness
//!
//! The crate knows nothing of beams: it takes a lattice geometry (and its motion) and returns
//! circulations and loads.
//!
//! ## Model
//! A lifting surface is a structured lattice of vortex rings (see [`lattice`]; a solver may hold
//! several, [`Surface`], in one influence system): grid column `j`
//! is generated from a [`SpanStation`] (section frame + chord), the rings are the grid panels
//! shifted a quarter panel downstream along the grid lines, collocation points sit at the ring
//! centroids. The non-penetration condition at every collocation point `c` with normal `n`,
//!
//! $$ \big(V_{ext}(c, t) + u_{ind}(c) - \dot x_c\big)\cdot n = 0, \qquad
//!    V_{ext}(x, t) = V_\infty + u_{dist}(x, t), $$
//!
//! gives the linear system `A Γ = −(V_ext − ẋ_c + u_wake)·n` for the ring circulations (the
//! external flow [`Flow`] is the free stream plus an optional disturbance field such as a gust,
//! evaluated at each point and at the solver's time; see [`flow`]), with
//! the Biot–Savart law of straight segments ([`biot_savart`]) evaluated once per shared edge with
//! its net circulation. The Kutta condition is explicit (as SHARPy): every step the trailing-edge
//! circulation is shed into a new wake row; steady solves close the rings by semi-infinite legs
//! along the free stream.
//! The wake ([`Wake`]) is a ring buffer of rows shed every step, convected with the external flow
//! (prescribed) or the local velocity (free), truncated after `n_wake_rows` rows, optionally
//! closed by semi-infinite legs. Loads ([`Loads`]) are Joukowski forces per segment plus
//! ρ·A·n·dΓ/dt per ring (eq. 16 of Otsuka, Cheng & Palacios 2024), as nodal forces on the ring
//! nodes. Symmetry and ground planes are modelled by image vortices ([`ImagePlane`]).
//!
//! ## Coupling API
//! ```
//! use uvlm::{Lattice, Uvlm, UvlmParams, samples::FlaredWing};
//! # fn main() -> Result<(), uvlm::UvlmError> {
//! let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
//! // 1. Build a lattice from span stations (origin, section frame, chord, le_offset) + hinge column.
//! let lattice = Lattice::from_stations(wing.spec(), &wing.stations(0.0))?;
//! let mut uvlm = Uvlm::new(lattice, UvlmParams::new(0.0889, [0.0, -25.0, 0.0]))?;
//! for step in 1..=3 {
//!     // 2. Each step: move the stations (positions, frames, optionally velocities) ...
//!     let fold = 0.01 * step as f64;
//!     uvlm.update_stations(&wing.stations(fold), None)?;
//!     // 3. ... advance one unsteady step ...
//!     let loads = uvlm.step(0.01)?;
//!     // 4. ... and lump the nodal forces to the stations: force + moment about each origin.
//!     let origins: Vec<[f64; 3]> = wing.stations(fold).iter().map(|s| s.origin.into()).collect();
//!     let (mut f, mut m) = (vec![[0.0; 3]; origins.len()], vec![[0.0; 3]; origins.len()]);
//!     loads.column_loads_inplace(&origins, &mut f, &mut m);
//!     assert!(f.iter().all(|v| v.iter().all(|x| x.is_finite())));
//! }
//! # Ok(()) }
//! ```
//! [`Uvlm::solve_steady`] gives the steady solution (a ring VLM); [`Uvlm::prefill_wake`] then
//! starts an unsteady run from it instead of impulsively.
//!
//! ## Public API at a glance
//! * Geometry: [`SpanStation`] `{ origin, frame, chord, le_offset, slant, flap }` (section frame
//!   columns `x_s` span, `y_s` towards the leading edge, `z_s` normal; `flap`: an optional
//!   control surface [`StationFlap`] `{ chord_fraction, deflection, rate }`, placed on the
//!   lattice as in docs/uvlm.md §15 and reported by [`Lattice::column_flaps`]), [`StationVelocity`]
//!   `{ linear, angular }`, [`LatticeSpec`] `{ n_chordwise, spacing, hinge: Option<HingeColumn
//!   { column, flare }>, min_corner_angle_deg }`; [`Lattice::from_stations`],
//!   [`Lattice::update_stations`], [`Lattice::set_grid`] (arbitrary node motion). The mesher
//!   returns [`UvlmError`] for non-finite input, non-monotone or folded grids, zero-area or
//!   over-skewed panels, a non-interior hinge column.
//! * Solver: [`Uvlm::new`]`(lattice, `[`UvlmParams`]`)`, [`Uvlm::update_stations`] /
//!   [`Uvlm::set_grid`], [`Uvlm::solve_steady`], [`Uvlm::step`]`(dt)` — or, for sub-iterated
//!   (strongly coupled) steps, [`Uvlm::advance_wake`]`(dt)` once, then [`Uvlm::solve_step`] as
//!   often as needed, then [`Uvlm::commit_step`] — [`Uvlm::prefill_wake`],
//!   accessors [`Uvlm::gamma`], [`Uvlm::gamma_dot`], [`Uvlm::wake`], [`Uvlm::loads`],
//!   [`Uvlm::stats`], [`Uvlm::velocity_at`]; the clock [`Uvlm::time`] / [`Uvlm::set_time`].
//! * Several lifting surfaces in one influence system (docs/uvlm.md §16):
//!   [`Uvlm::with_surfaces`]`(Vec<Lattice>, params)`, each [`Surface`] with its own lattice and
//!   wake ([`Surface::lattice`], [`Surface::wake`], [`Surface::loads`], [`Surface::rings`]: its
//!   unknowns in the global numbering); [`Uvlm::n_surfaces`], [`Uvlm::surface`],
//!   [`Uvlm::surfaces`], [`Uvlm::update_stations_of`], [`Uvlm::set_grid_of`],
//!   [`Uvlm::hinge_moment_of`]. [`Uvlm::loads`] is then all surfaces' loads concatenated; the
//!   one-surface calls (`update_stations`, `set_grid`, `hinge_moment`) return
//!   [`UvlmError::SeveralSurfaces`].
//! * The linearised UVLM (docs/uvlm.md §13): [`Uvlm::linearise`]`(&`[`LinearWake`]`)` →
//!   [`LinearUvlm`], of one or several surfaces over the stacked numbering ([`SurfaceBlock`]:
//!   each surface's rings, ring nodes, trailing-edge columns and nodes, load midpoints);
//!   [`LinearUvlm::evaluate_surfaces`] (moved lattices, circulations held), the transfer
//!   matrices [`LinearUvlm::normalwash_matrix`] / [`LinearUvlm::force_matrix`], the gust input
//!   [`LinearUvlm::gust`] → [`LinearGust`], [`LinearUvlm::wake_node_derivatives`].
//! * External flow ([`flow`]): [`FlowField`] (`velocity(x, t)`, batch `add_velocity_inplace`),
//!   [`Uniform`], [`Flow`] (free stream + optional disturbance); attach a gust with
//!   [`Uvlm::set_disturbance`]. Gusts ([`gust`]): [`OneMinusCosine`], [`SharpEdged`],
//!   [`Sinusoidal`], [`VonKarman`], frozen and convected ([`Convection`]); thin-aerofoil theory
//!   to check them against ([`gust_theory`]: Sears, exact Küssner).
//! * Loads: [`Loads::nodal`] (per ring node, N), [`Loads::strip`] (per panel column),
//!   [`Loads::total_force`], [`Loads::moment_about`], [`Loads::lift_drag`],
//!   [`Loads::column_loads_inplace`] (force + moment about each station origin);
//!   [`Uvlm::hinge_moment`] / [`hinge_moment`] (a control surface's moment about its hinge line).
//! * Parameters ([`UvlmParams`], serde, unknown fields rejected): `rho`, `v_inf`, `n_wake_rows`,
//!   `wake_convection` (prescribed / free), `wake_closure`, `bound_core` / `wake_core`
//!   ([`CoreModel`]: SHARPy cut-off or Scully core sized from the local panel), `images`
//!   ([`ImagePlane`]: symmetry and/or ground), `te_segment_force`, `unsteady_term`, `parallel`,
//!   `steady_wake` ([`SteadyWake`]: semi-infinite legs, or a finite frozen wake of a given length),
//!   `wake_reuse` ([`WakeReuse`]: sub-iterations of a step recompute the wake or reuse its far part),
//!   `wake_aggregation` ([`WakeAggregation`]: a treecode for long wakes, with an error bound).
//!
//! ## Performance
//! Filaments are stored once per shared edge in structure-of-arrays form; the kernels evaluate
//! blocks of 8 points, compute `P − X` and `|P − X|` once per (point, node), and are compiled for
//! AVX-512 and AVX2 + FMA with run-time dispatch (portable fallback otherwise). The AIC is rebuilt
//! and refactorised only when the lattice moved. Evaluations with enough work use rayon
//! ([`Parallel::Auto`]): their blocks of points are split into chunks, each with its own entry of
//! a scratch workspace the solver owns (no thread-local or shared mutable state; a threaded
//! evaluation is bit-identical to the serial one). [`Uvlm`], [`LinearUvlm`] and
//! [`treecode::Treecode`] are `Send + Sync`. No heap allocation happens in a step once the wake
//! buffer is full.
#![warn(missing_docs)]
// Index loops over x/y/z components and lattice indices mirror the equations they implement.
#![allow(clippy::needless_range_loop)]

mod aic;
mod axis_extension;
pub mod biot_savart;
mod dense_lu;
mod error;
mod flap;
pub mod flow;
pub mod gust;
pub mod gust_theory;
pub mod images;
mod induce;
pub mod lattice;
mod linear;
mod linear_gust;
mod linear_stack;
mod linearise;
mod load_derivative;
mod loads;
mod mixed;
mod params;
mod refine;
pub mod samples;
mod scratch;
mod solver;
mod station;
mod stats;
mod surface;
pub mod treecode;
mod wake;
mod wake_nodes;
mod wake_tree;

pub use biot_savart::{CoreModel, Filaments, segment_velocity, semi_infinite_velocity};
pub use dense_lu::solve_complex;
pub use error::{Result, UvlmError};
pub use flap::{ColumnFlap, hinge_moment, hinge_row};
pub use flow::{Flow, FlowField, Uniform};
pub use gust::{Convection, OneMinusCosine, SharpEdged, Sinusoidal, VonKarman, VonKarmanParams};
pub use images::ImagePlane;
pub use induce::{Points, induced_velocity};
pub use lattice::{ChordwiseSpacing, HingeColumn, Lattice, LatticeSpec};
pub use linear::{LinearUvlm, LinearWake, with_wake};
pub use linear_gust::LinearGust;
pub use linear_stack::SurfaceBlock;
pub use load_derivative::SteadyLoadDerivative;
pub use loads::{Loads, lift_drag_of, lump_columns};
pub use mixed::induced_velocity_mixed;
pub use params::{PARALLEL_MIN_PAIRS, Parallel, SteadyWake, UvlmParams, WakeAggregation, WakeConvection, WakeReuse};
pub use solver::Uvlm;
pub use station::{MAX_FLAP_DEFLECTION_DEG, SpanStation, StationFlap, StationVelocity};
pub use stats::Stats;
pub use surface::Surface;
pub use treecode::{TreeStats, Treecode};
pub use wake::Wake;
pub use wake_nodes::WakeNodeDerivatives;
