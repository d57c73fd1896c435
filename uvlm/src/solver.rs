//! The UVLM solver: steady solve and unsteady time steps on one or several lattices (surfaces),
//! each with its wake, in one influence system.

use crate::aic::{AicLayout, BoundSystem, FarRows, SegmentKeys, TrailingEdge, WakePart, append_wake_rows};
use crate::axis_extension::{
    ExtensionLayout, SurfaceLayout, WakeColumns, correct_axis_extensions, correct_wake_columns,
};
use crate::biot_savart::{Filaments, NodeBlock};
use crate::dense_lu::DenseLu;
use crate::error::{Result, UvlmError};
use crate::flow::{Flow, FlowField};
use crate::images::append_images;
use crate::induce::{Points, induced_velocity_inplace};
use crate::lattice::Lattice;
use crate::loads::{Loads, compute_loads, concatenate_loads};
use crate::mixed::{MixedScratch, add_velocity_mixed};
use crate::params::{SteadyWake, UvlmParams, WakeConvection, WakeReuse};
use crate::refine;
use crate::scratch::ScratchPool;
use crate::station::{SpanStation, StationVelocity};
use crate::stats::Stats;
use crate::surface::Surface;
use crate::wake::Wake;
use crate::wake_tree::WakeTree;
use std::time::Instant;

/// Which trailing-edge model the current AIC was built for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Steady,
    Unsteady,
}

/// A UVLM solver owning its lattices (surfaces, [`Surface`]), their wakes, the circulations, work
/// buffers and loads. [`Uvlm::new`] makes a solver of one surface, [`Uvlm::with_surfaces`] of
/// several in one influence system (docs/uvlm.md §16).
///
/// The solver keeps the time `t` of its committed solution ([`Uvlm::time`], 0 at construction,
/// see [`Uvlm::set_time`]); the external flow `V_ext(x, t) = V∞ + u_dist(x, t)` ([`Flow`]) is
/// evaluated at the points and times below. Per unsteady step `t → t + dt` ([`Uvlm::step`]), with
/// the lattice already moved to the new time:
/// 1. convect the wake with `V_ext(x, t)` (plus the induced velocity for a free wake), forward
///    Euler over `dt`;
/// 2. shed a row (explicit Kutta condition): the previous trailing-edge ring row, convected,
///    becomes the downstream edge of the newest wake ring, which carries the trailing-edge
///    circulation of the previous step (the oldest row is dropped when the buffer is full);
/// 3. assemble and factorise the AIC of the bound rings unless the lattice is unchanged;
/// 4. right-hand side `−(V_ext(c, t + dt) − ẋ_c + u_wake(c))·n`, solve for Γ;
/// 5. loads: Joukowski per segment with `V_ext` at its midpoint at `t + dt`, + ρ·A·n·dΓ/dt
///    (backward differences, first order on the first step, second order after);
/// 6. on commit, `t ← t + dt`.
#[derive(Debug)]
pub struct Uvlm {
    params: UvlmParams,
    flow: Flow,
    time: f64,
    /// The surfaces; their rings are numbered surface after surface.
    pub(crate) surfaces: Vec<Surface>,
    gamma: Vec<f64>,
    gamma_prev: Vec<f64>,
    gamma_prev2: Vec<f64>,
    gamma_dot: Vec<f64>,
    n_history: usize,
    bound: BoundSystem,
    bound_mode: Option<Mode>,
    has_solution: bool,
    /// The known wake: all of it, or with [`WakeReuse::Frozen`] its part touching the trailing
    /// edge (the rest is `far`).
    known: Filaments,
    /// With [`WakeReuse::Frozen`]: the wake beyond the trailing-edge filaments, fixed within a
    /// step; empty otherwise.
    far: Filaments,
    /// Whether `far` and its induction `u_far_col` / `u_far_mid` belong to the pending step.
    far_ready: bool,
    u_far_col: Vec<[f64; 3]>,
    u_far_mid: Vec<[f64; 3]>,
    /// Treecodes over `known` and `far` (when the aggregation applies), valid while the flags are.
    known_tree: WakeTree,
    far_tree: WakeTree,
    /// The names of `far`'s segments, for the persistent tree (wake_tree.rs).
    far_keys: SegmentKeys,
    /// Whether `far` holds only the rows the kept tree needs ([`WakeTree::rows_needed`]); the
    /// tree holds the rest. Per surface: those rows, and the push numbers of the rows left out.
    far_partial: bool,
    far_rows: Vec<FarRows>,
    far_omitted: Vec<(u64, u64)>,
    lu: DenseLu,
    aic: Vec<f64>,
    rhs: Vec<f64>,
    /// The mode the current influence matrix was built for (with the lattice versions of
    /// [`Surface::aic_version`]); `None` when it must be rebuilt.
    aic_mode: Option<Mode>,
    /// The mode of the matrix `lu` factorised (`None`: no factorisation), and whether that matrix
    /// is an earlier one than `aic` ([`UvlmParams::aic_refinement`]: solves refine on it).
    lu_mode: Option<Mode>,
    lu_stale: bool,
    /// The last refined solve was slow: factorise at the next change of the matrix.
    refactor_next: bool,
    /// Solves refined on the current matrix (which has not changed since).
    stale_solves: usize,
    /// Scratch of the refined solves.
    refine_work: Vec<f64>,
    col: Points,
    nrm: Points,
    mid: Points,
    wpts: Points,
    u_col: Vec<[f64; 3]>,
    u_mid: Vec<[f64; 3]>,
    /// Where the load points and their collinear filaments sit (axis_extension.rs).
    ext_layout: ExtensionLayout,
    u_wake: Vec<[f64; 3]>,
    v_col: Vec<[f64; 3]>,
    v_mid: Vec<[f64; 3]>,
    v_wake: Vec<[f64; 3]>,
    /// The Biot–Savart loops' workspace (one entry per threaded chunk).
    blocks: ScratchPool<NodeBlock>,
    /// The mixed-precision loops' workspace for the load points of a time step
    /// ([`Uvlm::mixed_loads`]).
    mixed_mid: MixedScratch,
    /// The loads of all surfaces together (filled with several surfaces only; one surface's
    /// loads are its own).
    loads: Loads,
    stats: Stats,
    pending_dt: Option<f64>,
    solved_pending: bool,
}

impl Uvlm {
    /// A solver for one lifting surface, `lattice`, with an empty wake (impulsive start).
    pub fn new(lattice: Lattice, params: UvlmParams) -> Result<Self> {
        Self::from_lattices(vec![lattice], params)
    }

    /// A solver for the surfaces `lattices` (rings numbered surface after surface).
    pub(crate) fn from_lattices(lattices: Vec<Lattice>, params: UvlmParams) -> Result<Self> {
        params.validate()?;
        if lattices.is_empty() {
            return Err(UvlmError::NoSurfaces);
        }
        let mut surfaces = Vec::with_capacity(lattices.len());
        let mut nr = 0;
        for lattice in lattices {
            let n = lattice.n_rings();
            surfaces.push(Surface::new(lattice, nr, params.n_wake_rows));
            nr += n;
        }
        Ok(Self {
            flow: Flow::new(params.v_inf),
            time: 0.0,
            surfaces,
            gamma: vec![0.0; nr],
            gamma_prev: vec![0.0; nr],
            gamma_prev2: vec![0.0; nr],
            gamma_dot: vec![0.0; nr],
            n_history: 0,
            bound: BoundSystem::default(),
            bound_mode: None,
            has_solution: false,
            known: Filaments::default(),
            far: Filaments::default(),
            far_ready: false,
            u_far_col: vec![[0.0; 3]; nr],
            u_far_mid: Vec::new(),
            known_tree: WakeTree::new(&params.wake_aggregation),
            far_tree: WakeTree::far(&params.wake_aggregation),
            far_keys: SegmentKeys::default(),
            far_partial: false,
            far_rows: Vec::new(),
            far_omitted: Vec::new(),
            lu: DenseLu::new(nr),
            aic: vec![0.0; AicLayout::BlockRings.len(nr)],
            rhs: vec![0.0; nr],
            aic_mode: None,
            lu_mode: None,
            lu_stale: false,
            refactor_next: false,
            stale_solves: 0,
            refine_work: vec![0.0; nr],
            col: Points::default(),
            nrm: Points::default(),
            mid: Points::default(),
            wpts: Points::default(),
            u_col: vec![[0.0; 3]; nr],
            u_mid: Vec::new(),
            mixed_mid: MixedScratch::default(),
            ext_layout: ExtensionLayout::default(),
            u_wake: Vec::new(),
            v_col: vec![[0.0; 3]; nr],
            v_mid: Vec::new(),
            v_wake: Vec::new(),
            blocks: ScratchPool::default(),
            loads: Loads::default(),
            stats: Stats::default(),
            pending_dt: None,
            solved_pending: false,
            params,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &UvlmParams {
        &self.params
    }
    /// The lattice (current geometry) of the first surface: the only one of a solver built by
    /// [`Uvlm::new`]. See [`Uvlm::surface`] for the others.
    pub fn lattice(&self) -> &Lattice {
        &self.surfaces[0].lattice
    }
    /// The wake of the first surface (see [`Uvlm::lattice`]).
    pub fn wake(&self) -> &Wake {
        &self.surfaces[0].wake
    }
    /// Bound ring circulations Γ of all surfaces, m²/s: surface after surface
    /// ([`Surface::rings`]), index `i·N + j` within a surface.
    pub fn gamma(&self) -> &[f64] {
        &self.gamma
    }
    /// dΓ/dt of the last step (zero after a steady solve), m²/s².
    pub fn gamma_dot(&self) -> &[f64] {
        &self.gamma_dot
    }
    /// Loads of the last solve. With several surfaces: all of them, nodal forces, positions and
    /// strips concatenated in surface order, totals summed (lump each surface's own
    /// [`Surface::loads`] to its stations: its nodal loads follow its grid).
    pub fn loads(&self) -> &Loads {
        match self.surfaces.as_slice() {
            [s] => &s.loads,
            _ => &self.loads,
        }
    }
    /// Hinge moment of the control surface covering grid columns `columns` (each must carry a
    /// flap), from the loads of the last solve, N·m, positive trailing edge down: see
    /// [`crate::hinge_moment`]. Call it after the solve, before the stations move again. One
    /// surface only ([`UvlmError::SeveralSurfaces`] otherwise): see [`Uvlm::hinge_moment_of`].
    pub fn hinge_moment(&self, columns: std::ops::RangeInclusive<usize>) -> Result<f64> {
        let s = self.only_surface("hinge_moment")?;
        crate::flap::hinge_moment(&s.lattice, &s.loads, columns)
    }
    /// Work counters.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }
    /// The external flow (free stream `params().v_inf` and disturbance).
    pub fn flow(&self) -> &Flow {
        &self.flow
    }

    /// Set the wake of the steady solves ([`UvlmParams::steady_wake`]); the next
    /// [`Uvlm::solve_steady`] rebuilds its influence matrix.
    ///
    /// # Errors
    /// A finite wake whose length is not positive and finite.
    pub fn set_steady_wake(&mut self, wake: SteadyWake) -> Result<()> {
        let p = UvlmParams { steady_wake: wake, ..self.params.clone() };
        p.validate()?;
        if self.params.steady_wake != wake {
            self.params.steady_wake = wake;
            (self.aic_mode, self.lu_mode) = (None, None);
        }
        Ok(())
    }

    /// Attach a disturbance field (gust, turbulence) to the free stream, or remove it (`None`).
    /// It applies from the next evaluation on: the next wake convection and solve. See
    /// [`crate::flow`] for where it is evaluated and how to write one.
    pub fn set_disturbance(&mut self, disturbance: Option<Box<dyn FlowField>>) {
        self.flow.set_disturbance(disturbance);
    }

    /// Time of the committed solution, s: 0 at construction (or as set by [`Uvlm::set_time`]),
    /// advanced by `dt` on every [`Uvlm::commit_step`] ([`Uvlm::step`]). A steady solve is at
    /// this time; a pending step ([`Uvlm::advance_wake`] … [`Uvlm::solve_step`]) solves at
    /// `time() + dt`.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Set the time of the current solution, s (e.g. the structure's initial time). Only between
    /// steps; the disturbance is evaluated from this clock.
    pub fn set_time(&mut self, t: f64) -> Result<()> {
        if !t.is_finite() {
            return Err(UvlmError::InvalidParameter { field: "t", value: t });
        }
        if self.pending_dt.is_some() {
            return Err(UvlmError::StepOrder { call: "set_time", expected: "commit_step" });
        }
        self.time = t;
        Ok(())
    }

    /// Time of the last solve, s: `time() + dt` while a solved step is pending, else `time()`.
    fn solution_time(&self) -> f64 {
        match self.pending_dt {
            Some(dt) if self.solved_pending => self.time + dt,
            _ => self.time,
        }
    }

    /// Total velocity `V_ext + u_ind` at a point, m/s: external flow at the time of the last
    /// solve, bound rings and wake of the last solve (images included). The bound part is zero
    /// before the first solve.
    pub fn velocity_at(&self, p: [f64; 3]) -> [f64; 3] {
        let mut v = self.flow.velocity(p, self.solution_time());
        let mut add = |u: [f64; 3]| {
            for q in 0..3 {
                v[q] += u[q];
            }
        };
        if self.has_solution {
            add(self.bound.fil.velocity_at(p));
            if self.bound_mode == Some(Mode::Unsteady) {
                add(self.known.velocity_at(p));
                if self.far_partial {
                    // `far` holds part of the far wake (the kept tree the rest): build it whole.
                    let mut far = Filaments::default();
                    self.build_far_whole(&mut far);
                    add(far.velocity_at(p));
                } else {
                    add(self.far.velocity_at(p));
                }
            }
        }
        v
    }

    /// Move the lattice to new station frames and velocities (see [`Lattice::update_stations`]).
    /// One surface only ([`UvlmError::SeveralSurfaces`] otherwise): see
    /// [`Uvlm::update_stations_of`].
    pub fn update_stations(&mut self, stations: &[SpanStation], velocities: Option<&[StationVelocity]>) -> Result<()> {
        self.only_surface_mut("update_stations")?.lattice.update_stations(stations, velocities)
    }

    /// Set the grid nodes and velocities directly (see [`Lattice::set_grid`]). One surface only:
    /// see [`Uvlm::set_grid_of`].
    pub fn set_grid(&mut self, positions: &[[f64; 3]], velocities: &[[f64; 3]]) -> Result<()> {
        self.only_surface_mut("set_grid")?.lattice.set_grid(positions, velocities)
    }

    /// Unit free-stream direction (error if the free stream is zero). A direction, not a
    /// velocity: the steady trailing legs and the wake-closure legs follow the free stream `V∞`
    /// whatever the disturbance.
    fn stream_dir(&self) -> Result<[f64; 3]> {
        let v = self.flow.free_stream();
        let vn = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if vn > 0.0 {
            Ok([v[0] / vn, v[1] / vn, v[2] / vn])
        } else {
            Err(UvlmError::InvalidParameter { field: "v_inf", value: 0.0 })
        }
    }

    /// Whether a time step's load points take the bound rings and the near wake in mixed
    /// precision (docs/uvlm.md §14): with the aggregation and its mixed precision on and the far
    /// wake frozen within the step. The influence matrix and the steady solve's loads (whose
    /// difference quotients the static analyses take) stay in f64.
    fn mixed_loads(&self) -> bool {
        let agg = &self.params.wake_aggregation;
        agg.enabled && agg.mixed_precision && self.params.wake_reuse == WakeReuse::Frozen
    }

    /// Absolute tolerance of the wake aggregation, m/s: its relative tolerance × |V∞|.
    fn aggregation_tolerance(&self) -> f64 {
        let v = self.flow.free_stream();
        self.params.wake_aggregation.tolerance * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    /// Collocation points and normals of every surface (global ring order) into SoA buffers.
    fn load_collocation(&mut self) {
        self.col.clear();
        self.nrm.clear();
        for s in &self.surfaces {
            for (c, n) in s.lattice.collocation().iter().zip(s.lattice.normals()) {
                self.col.push(*c);
                self.nrm.push(*n);
            }
        }
    }

    /// Build (if needed) and factorise the AIC for `mode`.
    fn prepare_aic(&mut self, mode: Mode) -> Result<()> {
        let current = self.aic_mode == Some(mode)
            && self.bound_mode == Some(mode)
            && self.surfaces.iter().all(|s| s.aic_version == Some(s.lattice.version()));
        if current {
            return Ok(());
        }
        let te = match mode {
            Mode::Steady => match self.params.steady_wake {
                SteadyWake::SemiInfinite => TrailingEdge::Steady(self.stream_dir()?),
                SteadyWake::Finite { length } => TrailingEdge::SteadyFinite { dir: self.stream_dir()?, length },
            },
            Mode::Unsteady => TrailingEdge::Unsteady,
        };
        self.bound.build_surfaces(
            self.surfaces.iter().map(|s| &s.lattice),
            te,
            &self.params.bound_core,
            &self.params.images,
        );
        self.bound_mode = Some(mode);
        self.load_collocation();
        self.stats.n_pair_evaluations += self.bound.assemble_aic(
            &self.col,
            &self.nrm,
            &mut self.aic,
            AicLayout::BlockRings,
            self.params.parallel,
            &mut self.blocks,
        );
        self.stats.n_aic_builds += 1;
        self.aic_mode = None;
        if self.params.aic_refinement && self.lu_mode == Some(mode) && !self.refactor_next {
            // Solves refine on the factorisation in hand (refine.rs).
            (self.lu_stale, self.stale_solves) = (true, 0);
        } else {
            self.factorize_aic(mode)?;
        }
        self.aic_mode = Some(mode);
        for s in &mut self.surfaces {
            s.aic_version = Some(s.lattice.version());
        }
        Ok(())
    }

    /// Factorise the current influence matrix, built for `mode`.
    fn factorize_aic(&mut self, mode: Mode) -> Result<()> {
        self.lu_mode = None;
        self.lu
            .factorize_block_rings(&self.aic, crate::biot_savart::LANES)
            .map_err(|pivot| UvlmError::SingularAic { pivot })?;
        self.stats.n_factorizations += 1;
        (self.lu_mode, self.lu_stale, self.refactor_next) = (Some(mode), false, false);
        Ok(())
    }

    /// `gamma ← A⁻¹ rhs` with the current influence matrix: with its factors, or refined on the
    /// factors of an earlier one, factorising it when the refinement does not converge.
    fn solve_aic(&mut self) -> Result<()> {
        self.gamma.copy_from_slice(&self.rhs);
        // A stale factorisation is of the current matrix's mode (prepare_aic).
        if let (true, Some(mode)) = (self.lu_stale, self.lu_mode) {
            self.stale_solves += 1;
            let refined = if self.stale_solves > refine::MAX_STALE_SOLVES {
                None // the matrix stopped changing: its own factors pay
            } else {
                refine::solve_refined(&mut self.lu, &self.aic, &self.rhs, &mut self.gamma, &mut self.refine_work)
            };
            if let Some(k) = refined {
                self.stats.n_refined_solves += 1;
                self.stats.n_refinement_corrections += k;
                self.refactor_next = k > refine::REFACTOR_ABOVE;
                return Ok(());
            }
            self.factorize_aic(mode)?;
            self.gamma.copy_from_slice(&self.rhs);
        }
        self.lu.solve_in_place(&mut self.gamma);
        Ok(())
    }

    /// Solve for Γ with the current AIC at time `t`: rhs = −(V_ext(c, t) − ẋ_c + u_known(c))·n.
    fn solve_gamma(&mut self, with_known_wake: bool, t: f64) -> Result<()> {
        self.load_collocation();
        if with_known_wake {
            let tol = self.aggregation_tolerance();
            self.u_col.fill([0.0; 3]);
            self.stats.n_pair_evaluations += self.known_tree.add_velocity(
                &self.known,
                &self.col,
                tol,
                &mut self.u_col,
                self.params.parallel,
                &mut self.blocks,
            );
            if self.params.wake_reuse == WakeReuse::Frozen {
                if !self.far_ready {
                    self.u_far_col.fill([0.0; 3]);
                    self.stats.n_pair_evaluations += self.far_tree.add_velocity(
                        &self.far,
                        &self.col,
                        tol,
                        &mut self.u_far_col,
                        self.params.parallel,
                        &mut self.blocks,
                    );
                }
                add_to(&mut self.u_col, &self.u_far_col);
            }
        } else {
            self.u_col.fill([0.0; 3]);
        }
        self.flow.velocity_inplace(&self.col, t, &mut self.v_col);
        for surf in &self.surfaces {
            let cv = surf.lattice.collocation_velocities();
            let nrm = surf.lattice.normals();
            for (r, rg) in surf.rings.clone().enumerate() {
                let v = self.v_col[rg];
                let mut s = 0.0;
                for q in 0..3 {
                    s += (v[q] - cv[r][q] + self.u_col[rg][q]) * nrm[r][q];
                }
                self.rhs[rg] = -s;
            }
        }
        self.solve_aic()?;
        if !self.gamma.iter().all(|g| g.is_finite()) {
            return Err(UvlmError::NonFiniteSolution { step: self.stats.n_steps });
        }
        self.bound.set_strengths(&self.gamma);
        self.has_solution = true;
        Ok(())
    }

    /// Induced velocity and external flow (at time `t`) at the lattice segment midpoints (bound
    /// + known wake) and the loads.
    fn update_loads(&mut self, with_known_wake: bool, unsteady: bool, t: f64) {
        self.mid.clear();
        for k in 0..self.surfaces.len() {
            let range = self.bound.surface(k);
            for s in range.seg0..range.seg0 + self.n_load_segments(k) {
                let (a, b) = self.bound.fil.segment_nodes(s);
                let (pa, pb) = (self.bound.fil.node(a as usize), self.bound.fil.node(b as usize));
                self.mid.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])]);
            }
        }
        self.u_mid.resize(self.mid.len(), [0.0; 3]);
        let tol = self.aggregation_tolerance();
        let mixed = with_known_wake && unsteady && self.mixed_loads();
        let pairs = if mixed {
            self.u_mid.fill([0.0; 3]);
            let (parallel, scratch) = (self.params.parallel, &mut self.mixed_mid);
            add_velocity_mixed(&self.bound.fil, &self.mid, &mut self.u_mid, parallel, scratch)
                + add_velocity_mixed(&self.known, &self.mid, &mut self.u_mid, parallel, scratch)
        } else if with_known_wake && self.known_tree.applies(&self.known) {
            let bound = induced_velocity_inplace(
                &[&self.bound.fil],
                &self.mid,
                &mut self.u_mid,
                self.params.parallel,
                &mut self.blocks,
            );
            bound
                + self.known_tree.add_velocity(
                    &self.known,
                    &self.mid,
                    tol,
                    &mut self.u_mid,
                    self.params.parallel,
                    &mut self.blocks,
                )
        } else if with_known_wake {
            induced_velocity_inplace(
                &[&self.bound.fil, &self.known],
                &self.mid,
                &mut self.u_mid,
                self.params.parallel,
                &mut self.blocks,
            )
        } else {
            induced_velocity_inplace(
                &[&self.bound.fil],
                &self.mid,
                &mut self.u_mid,
                self.params.parallel,
                &mut self.blocks,
            )
        };
        self.stats.n_pair_evaluations += pairs;
        // The bound filaments' regular induction on their axis extensions (docs/uvlm.md §3):
        // where the mixed kernel summed them, only inside their cut-off cylinders.
        let mut layout = std::mem::take(&mut self.ext_layout);
        self.load_layout(&mut layout);
        correct_axis_extensions(&self.bound.fil, &layout, &self.mid, &mut self.u_mid, self.params.parallel, mixed);
        let frozen = self.params.wake_reuse == WakeReuse::Frozen;
        if with_known_wake {
            // The known wake's streamwise filaments on the same footing (as the steady legs).
            let part = if frozen { WakePart::Near } else { WakePart::All };
            self.correct_wake_at_midpoints(&layout, part, false, mixed);
        }
        if with_known_wake && frozen {
            if !self.far_ready {
                self.u_far_mid.clear();
                self.u_far_mid.resize(self.mid.len(), [0.0; 3]);
                self.stats.n_pair_evaluations += self.far_tree.add_velocity(
                    &self.far,
                    &self.mid,
                    tol,
                    &mut self.u_far_mid,
                    self.params.parallel,
                    &mut self.blocks,
                );
                let cutoff_only = !self.far_tree.kernel_exact(&self.far);
                self.correct_wake_at_midpoints(&layout, WakePart::Far, true, cutoff_only);
            }
            add_to(&mut self.u_mid, &self.u_far_mid);
        }
        self.ext_layout = layout;
        self.v_mid.resize(self.mid.len(), [0.0; 3]);
        self.flow.velocity_inplace(&self.mid, t, &mut self.v_mid);
        let gd = unsteady && self.params.unsteady_term;
        let mut m0 = 0;
        for k in 0..self.surfaces.len() {
            let m1 = m0 + self.n_load_segments(k);
            let surf = &mut self.surfaces[k];
            let shed = with_known_wake && self.params.te_segment_force && surf.wake.n_rows() > 0;
            if shed {
                for j in 0..surf.te_shed.len() {
                    surf.te_shed[j] = surf.wake.gamma(0, j);
                }
            }
            let te_shed = if shed { Some(&surf.te_shed[..]) } else { None };
            let gd = if gd { Some(&self.gamma_dot[surf.rings.clone()]) } else { None };
            let (v, u) = (&self.v_mid[m0..m1], &self.u_mid[m0..m1]);
            compute_loads(&mut surf.loads, &surf.lattice, &self.bound, k, v, u, gd, te_shed, &self.params);
            m0 = m1;
        }
        if self.surfaces.len() > 1 {
            concatenate_loads(&mut self.loads, self.surfaces.iter().map(|s| &s.loads));
        }
    }

    /// The regular form of the known wake's part `part` (its streamwise filaments, column by
    /// column) at the chordwise load points, in `u_far_mid` (`far`) or `u_mid`
    /// (axis_extension.rs, docs/uvlm.md §3): the time march's wake rows take the terms the steady
    /// solve's legs take, so that a steady solution is the march's equilibrium. `cutoff_only`
    /// where the part went through the treecode (its clusters are expansions of the singular
    /// law) or the mixed-precision kernel (regular forms outside the filaments).
    fn correct_wake_at_midpoints(&mut self, layout: &ExtensionLayout, part: WakePart, far: bool, cutoff_only: bool) {
        let closure = if self.params.wake_closure { self.stream_dir().ok() } else { None };
        let u = if far { &mut self.u_far_mid } else { &mut self.u_mid };
        let mut p0 = 0;
        for (sl, s) in layout.surfaces.iter().zip(&self.surfaces) {
            let (m, n) = (s.lattice.n_chordwise(), s.lattice.n_spanwise());
            let te = &s.lattice.ring_nodes()[m * (n + 1)..];
            let w = WakeColumns { te, wake: &s.wake, closure, core: &self.params.wake_core, part, cutoff_only };
            correct_wake_columns(sl, p0, &w, &self.mid, u);
            p0 += sl.n_load;
        }
    }

    /// Where every surface's load points and filaments sit in the bound system (the load points
    /// of [`Uvlm::update_loads`], surface after surface).
    fn load_layout(&self, out: &mut ExtensionLayout) {
        let n_copies = crate::images::copy_signs(self.params.images.len()).len();
        let surfaces = &mut out.surfaces;
        surfaces.clear();
        let mut leg0 = 0;
        for (k, s) in self.surfaces.iter().enumerate() {
            let r = self.bound.surface(k);
            let (m, n) = (s.lattice.n_chordwise(), s.lattice.n_spanwise());
            surfaces.push(SurfaceLayout {
                seg0: r.seg0,
                n_load: self.n_load_segments(k),
                n_lattice_seg: r.n_lattice_seg,
                m,
                n,
                leg0,
                finite: matches!(self.bound_mode, Some(Mode::Steady))
                    && matches!(self.params.steady_wake, SteadyWake::Finite { .. }),
            });
            if self.bound.fil.n_legs() > 0 {
                leg0 += n + 1;
            }
        }
        out.n_base_seg = self.bound.fil.n_segments() / n_copies;
        out.n_base_leg = self.bound.fil.n_legs() / n_copies;
        out.n_copies = n_copies;
    }

    /// Number of surface `k`'s lattice segments that carry loads: the trailing-edge segments are
    /// skipped unless asked for.
    fn n_load_segments(&self, k: usize) -> usize {
        let range = self.bound.surface(k);
        if self.params.te_segment_force { range.n_lattice_seg } else { range.n_lattice_seg - range.n_te_seg }
    }

    /// Steady solution with the wake of [`UvlmParams::steady_wake`] along the free stream:
    /// semi-infinite trailing legs (a ring VLM, the default) or a finite frozen wake. In the
    /// external flow at [`Uvlm::time`] (the wake follows `V∞`, not the disturbance).
    /// Does not touch the wake or the unsteady history.
    pub fn solve_steady(&mut self) -> Result<&Loads> {
        if self.pending_dt.is_some() {
            return Err(UvlmError::StepOrder { call: "solve_steady", expected: "commit_step" });
        }
        let t0 = Instant::now();
        self.prepare_aic(Mode::Steady)?;
        self.solve_gamma(false, self.time)?;
        self.gamma_dot.fill(0.0);
        self.update_loads(false, false, self.time);
        self.stats.n_steady_solves += 1;
        self.stats.wall_time += t0.elapsed().as_secs_f64();
        Ok(self.loads())
    }

    /// Replace the wake by the steady wake of the current Γ for time step `dt`: `n_wake_rows`
    /// straight rows convected with the free stream, every row carrying Γ_TE, and make the
    /// current Γ the unsteady history (dΓ/dt = 0). Call after [`Uvlm::solve_steady`] to start
    /// an unsteady run from a converged state instead of impulsively. The rows follow the free
    /// stream `V∞` (the steady wake's geometry, a direction), not the disturbance.
    pub fn prefill_wake(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(UvlmError::InvalidParameter { field: "dt", value: dt });
        }
        if self.pending_dt.is_some() {
            return Err(UvlmError::StepOrder { call: "prefill_wake", expected: "commit_step" });
        }
        let v = self.flow.free_stream();
        for s in &mut self.surfaces {
            let (lat, ring0) = (&s.lattice, s.rings.start);
            let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
            for j in 0..=n {
                s.prev_te[j] = lat.ring_nodes()[lat.node_index(m, j)];
            }
            for j in 0..n {
                s.gamma_row[j] = self.gamma[ring0 + lat.ring_index(m - 1, j)];
            }
            s.wake.clear();
            self.far_tree.break_persistence();
            for r in (0..s.wake.capacity()).rev() {
                let k = (r + 1) as f64 * dt;
                for j in 0..=n {
                    let p = s.prev_te[j];
                    s.row_buf[j] = [p[0] + k * v[0], p[1] + k * v[1], p[2] + k * v[2]];
                }
                s.wake.push_front(&s.row_buf, &s.gamma_row);
            }
        }
        self.gamma_prev.copy_from_slice(&self.gamma);
        self.gamma_prev2.copy_from_slice(&self.gamma);
        self.n_history = 2;
        self.bound_mode = None;
        self.aic_mode = None;
        Ok(())
    }

    /// Per surface: its wake nodes (row by row) then its previous trailing-edge row, into `wpts`.
    fn load_wake_points(&mut self) {
        self.wpts.clear();
        for s in &self.surfaces {
            let n = s.wake.n_spanwise();
            for r in 0..s.wake.n_rows() {
                for j in 0..=n {
                    self.wpts.push(s.wake.node(r, j));
                }
            }
            for p in &s.prev_te {
                self.wpts.push(*p);
            }
        }
    }

    /// Convect the wake and the previous trailing-edge row over `dt` with the velocity at the
    /// start of the step (time [`Uvlm::time`]): the external flow, plus the induced velocity for a
    /// free wake.
    fn convect(&mut self, dt: f64) {
        let t = self.time;
        let free = self.params.wake_convection == WakeConvection::Free
            && self.has_solution
            && self.bound_mode == Some(Mode::Unsteady);
        if !free && self.flow.is_uniform() {
            // The same displacement V∞·dt for every node.
            let v = self.flow.free_stream();
            let d = [v[0] * dt, v[1] * dt, v[2] * dt];
            // The images move with the wake when `d` lies in every plane.
            let along = self.params.images.iter().all(|p| {
                let n = p.unit_normal();
                (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]).abs()
                    <= 1e-12 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            });
            if along {
                self.far_tree.translate(d);
            } else {
                self.far_tree.break_persistence();
            }
            for s in &mut self.surfaces {
                s.wake.translate(d);
                for p in &mut s.prev_te {
                    for q in 0..3 {
                        p[q] += d[q];
                    }
                }
            }
            return;
        }
        self.far_tree.break_persistence();
        self.far_whole();
        self.load_wake_points();
        self.v_wake.resize(self.wpts.len(), [0.0; 3]);
        self.flow.velocity_inplace(&self.wpts, t, &mut self.v_wake);
        self.u_wake.resize(self.wpts.len(), [0.0; 3]);
        if free && (self.known_tree.applies(&self.known) || self.far_tree.applies(&self.far)) {
            let tol = self.aggregation_tolerance();
            self.stats.n_pair_evaluations += induced_velocity_inplace(
                &[&self.bound.fil],
                &self.wpts,
                &mut self.u_wake,
                self.params.parallel,
                &mut self.blocks,
            );
            for (tree, set) in [(&mut self.known_tree, &self.known), (&mut self.far_tree, &self.far)] {
                self.stats.n_pair_evaluations +=
                    tree.add_velocity(set, &self.wpts, tol, &mut self.u_wake, self.params.parallel, &mut self.blocks);
            }
        } else if free {
            self.stats.n_pair_evaluations += induced_velocity_inplace(
                &[&self.bound.fil, &self.known, &self.far],
                &self.wpts,
                &mut self.u_wake,
                self.params.parallel,
                &mut self.blocks,
            );
        } else {
            self.u_wake.fill([0.0; 3]);
        }
        let mut k = 0;
        for s in &mut self.surfaces {
            let n = s.wake.n_spanwise();
            for r in 0..s.wake.n_rows() {
                for j in 0..=n {
                    let (v, u) = (self.v_wake[k], self.u_wake[k]);
                    s.wake.displace(r, j, [(v[0] + u[0]) * dt, (v[1] + u[1]) * dt, (v[2] + u[2]) * dt]);
                    k += 1;
                }
            }
            for p in &mut s.prev_te {
                let (v, u) = (self.v_wake[k], self.u_wake[k]);
                for q in 0..3 {
                    p[q] += (v[q] + u[q]) * dt;
                }
                k += 1;
            }
        }
    }

    /// Advance one time step of length `dt` (s): [`Uvlm::advance_wake`], [`Uvlm::solve_step`],
    /// [`Uvlm::commit_step`]. The lattice must already be at the new time.
    pub fn step(&mut self, dt: f64) -> Result<&Loads> {
        self.advance_wake(dt)?;
        self.solve_step()?;
        self.commit_step()?;
        Ok(self.loads())
    }

    /// First phase of a step: convect the wake over `dt` (s) and shed the trailing-edge row of
    /// the last committed step. For strongly coupled (sub-iterated) runs call this once per time
    /// step, then [`Uvlm::update_stations`] + [`Uvlm::solve_step`] as often as needed, then
    /// [`Uvlm::commit_step`].
    pub fn advance_wake(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(UvlmError::InvalidParameter { field: "dt", value: dt });
        }
        if self.pending_dt.is_some() {
            return Err(UvlmError::StepOrder { call: "advance_wake", expected: "commit_step" });
        }
        let t0 = Instant::now();
        self.convect(dt);
        for s in &mut self.surfaces {
            let (lat, ring0) = (&s.lattice, s.rings.start);
            let m = lat.n_chordwise();
            // The trailing-edge circulations of the last committed solve.
            for j in 0..lat.n_spanwise() {
                s.gamma_row[j] = self.gamma[ring0 + lat.ring_index(m - 1, j)];
            }
            s.wake.push_front(&s.prev_te, &s.gamma_row);
        }
        self.far_ready = false;
        self.pending_dt = Some(dt);
        self.stats.wall_time += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Second phase: solve the current step for the lattice as it is now (AIC if it moved, known
    /// wake, circulations, dΓ/dt by backward differences against the committed history, loads).
    /// May be repeated within one step (sub-iterations).
    pub fn solve_step(&mut self) -> Result<&Loads> {
        let Some(dt) = self.pending_dt else {
            return Err(UvlmError::StepOrder { call: "solve_step", expected: "advance_wake" });
        };
        let t0 = Instant::now();
        self.prepare_aic(Mode::Unsteady)?;
        let closure = if self.params.wake_closure { Some(self.stream_dir()?) } else { None };
        let frozen = self.params.wake_reuse == WakeReuse::Frozen;
        let part = if frozen { WakePart::Near } else { WakePart::All };
        build_wakes(&mut self.known, &self.surfaces, closure, &self.params, part, None, None);
        self.known_tree.invalidate();
        if frozen && !self.far_ready {
            // The far wake's segments are named when a tree can be kept across steps.
            let named = self.params.wake_aggregation.enabled
                && SegmentKeys::representable(
                    self.surfaces.len(),
                    self.surfaces.iter().map(|s| s.wake.n_spanwise()).max().unwrap_or(0),
                );
            self.far_partial = named && self.sync_far_rows(closure);
            if !self.far_partial {
                let keys = if named { Some(&mut self.far_keys) } else { None };
                build_wakes(&mut self.far, &self.surfaces, closure, &self.params, WakePart::Far, keys, None);
                self.far_tree.sync(&self.far, named.then_some(&self.far_keys.keys[..]));
            }
        }
        let t = self.time + dt;
        self.solve_gamma(true, t)?;
        for r in 0..self.gamma.len() {
            self.gamma_dot[r] = if self.n_history >= 2 {
                (3.0 * self.gamma[r] - 4.0 * self.gamma_prev[r] + self.gamma_prev2[r]) / (2.0 * dt)
            } else {
                (self.gamma[r] - self.gamma_prev[r]) / dt
            };
        }
        self.update_loads(true, true, t);
        self.far_ready = frozen;
        self.solved_pending = true;
        self.stats.wall_time += t0.elapsed().as_secs_f64();
        Ok(self.loads())
    }

    /// Build `far` from the rows the kept far tree needs and update the tree from them
    /// (wake_tree.rs), when it can be: the rows between are the tree's, translated and
    /// unchanged, so they are neither built nor merged. Returns false (`far` to be built whole)
    /// otherwise.
    fn sync_far_rows(&mut self, closure: Option<[f64; 3]>) -> bool {
        self.far_rows.clear();
        self.far_omitted.clear();
        for s in &self.surfaces {
            let Some((head, tail)) = self.far_tree.rows_needed(s.wake.n_rows()) else {
                return false;
            };
            let n = s.wake.n_pushed();
            self.far_rows.push((head, tail));
            self.far_omitted.push((n - (tail - 1) as u64, n - (head + 1) as u64));
        }
        build_wakes(
            &mut self.far,
            &self.surfaces,
            closure,
            &self.params,
            WakePart::Far,
            Some(&mut self.far_keys),
            Some(&self.far_rows),
        );
        self.far_tree.sync_rows(&self.far, &self.far_keys.keys, &self.far_omitted)
    }

    /// Make `far` hold the whole far wake again where it holds part of it (the kept tree is then
    /// rebuilt from it at its next use).
    fn far_whole(&mut self) {
        if self.far_partial {
            let mut far = std::mem::take(&mut self.far);
            self.build_far_whole(&mut far);
            self.far = far;
            self.far_tree.invalidate();
            self.far_partial = false;
        }
    }

    /// The whole far wake of the last solve into `fil` (unnamed).
    fn build_far_whole(&self, fil: &mut Filaments) {
        // The stream's direction was checked by the solve that built the partial set.
        let closure = if self.params.wake_closure { self.stream_dir().ok() } else { None };
        build_wakes(fil, &self.surfaces, closure, &self.params, WakePart::Far, None, None);
    }

    /// Third phase: accept the last [`Uvlm::solve_step`] as the state at the new time (history
    /// for dΓ/dt, trailing-edge row to shed next).
    pub fn commit_step(&mut self) -> Result<()> {
        if self.pending_dt.is_none() || !self.solved_pending {
            return Err(UvlmError::StepOrder { call: "commit_step", expected: "solve_step" });
        }
        std::mem::swap(&mut self.gamma_prev2, &mut self.gamma_prev);
        self.gamma_prev.copy_from_slice(&self.gamma);
        self.n_history += 1;
        for s in &mut self.surfaces {
            let (lat, m) = (&s.lattice, s.lattice.n_chordwise());
            for j in 0..=lat.n_spanwise() {
                s.prev_te[j] = lat.ring_nodes()[lat.node_index(m, j)];
            }
        }
        if let Some(dt) = self.pending_dt.take() {
            self.time += dt;
        }
        self.solved_pending = false;
        self.stats.n_steps += 1;
        Ok(())
    }
}

/// The known wake of every surface into `fil` (surface after surface, each from its own trailing
/// edge; `part` as in [`WakePart`]), then the images of all. One surface gives exactly
/// [`crate::aic::build_known_wake`]'s set.
fn build_wakes(
    fil: &mut Filaments,
    surfaces: &[Surface],
    closure: Option<[f64; 3]>,
    p: &UvlmParams,
    part: WakePart,
    mut keys: Option<&mut SegmentKeys>,
    rows: Option<&[FarRows]>,
) {
    fil.clear();
    if let Some(k) = keys.as_deref_mut() {
        k.clear();
    }
    for (i, s) in surfaces.iter().enumerate() {
        let (m, n) = (s.lattice.n_chordwise(), s.lattice.n_spanwise());
        let te = &s.lattice.ring_nodes()[m * (n + 1)..];
        if let Some(k) = keys.as_deref_mut() {
            k.surface = i as u64;
        }
        let r = rows.and_then(|r| r.get(i)).copied();
        append_wake_rows(fil, te, &s.wake, closure, &p.wake_core, &p.bound_core, part, r, keys.as_deref_mut());
    }
    append_images(fil, &p.images);
    if let Some(k) = keys {
        k.append_images(p.images.len());
    }
}

/// `a[i] += b[i]` componentwise.
fn add_to(a: &mut [[f64; 3]], b: &[[f64; 3]]) {
    for (x, y) in a.iter_mut().zip(b) {
        for q in 0..3 {
            x[q] += y[q];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::LatticeSpec;
    use crate::samples::{SpanSpacing, rectangular_wing};

    fn solver(v_inf: [f64; 3]) -> Uvlm {
        let lat =
            Lattice::from_stations(LatticeSpec::new(2), &rectangular_wing(0.0, 2.0, 1.0, 2, SpanSpacing::Uniform))
                .unwrap();
        Uvlm::new(lat, UvlmParams::new(1.0, v_inf)).unwrap()
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let mut u = solver([1.0, 0.0, 0.1]);
        assert!(matches!(u.step(0.0), Err(UvlmError::InvalidParameter { field: "dt", .. })));
        assert!(matches!(u.step(f64::NAN), Err(UvlmError::InvalidParameter { field: "dt", .. })));
        assert!(matches!(u.prefill_wake(-1.0), Err(UvlmError::InvalidParameter { field: "dt", .. })));
        let mut still = solver([0.0, 0.0, 0.0]);
        assert!(matches!(still.solve_steady(), Err(UvlmError::InvalidParameter { field: "v_inf", .. })));
        let lat = still.lattice().clone();
        let bad = UvlmParams { n_wake_rows: 0, ..UvlmParams::new(1.0, [1.0, 0.0, 0.0]) };
        assert!(matches!(Uvlm::new(lat, bad), Err(UvlmError::InvalidParameter { field: "n_wake_rows", .. })));
        assert!(matches!(u.set_grid(&[[0.0; 3]; 3], &[[0.0; 3]; 3]), Err(UvlmError::LengthMismatch { .. })));
    }

    /// Sub-iterations: the result of a step depends only on the committed state and the final
    /// lattice, so intermediate solves with other geometries leave no trace; phases out of order
    /// are errors.
    #[test]
    fn sub_iterations_and_step_order() {
        use crate::station::StationVelocity;
        let st = rectangular_wing(0.0, 2.0, 1.0, 4, SpanSpacing::Uniform);
        let lat = Lattice::from_stations(LatticeSpec::new(2), &st).unwrap();
        let p = UvlmParams::new(1.0, [1.0, 0.0, 0.1]);
        let (mut a, mut b) = (Uvlm::new(lat.clone(), p.clone()).unwrap(), Uvlm::new(lat, p).unwrap());
        let heave = |z: f64| -> Vec<SpanStation> {
            st.iter().map(|s| SpanStation { origin: s.origin + nalgebra::Vector3::new(0.0, 0.0, z), ..*s }).collect()
        };
        let vel = vec![StationVelocity { linear: [0.0, 0.0, 0.2].into(), ..Default::default() }; st.len()];
        for k in 1..=4 {
            let z = 0.02 * k as f64;
            a.update_stations(&heave(z), Some(&vel)).unwrap();
            a.step(0.1).unwrap();
            b.advance_wake(0.1).unwrap();
            for guess in [z + 0.05, z - 0.03] {
                b.update_stations(&heave(guess), None).unwrap();
                b.solve_step().unwrap();
            }
            b.update_stations(&heave(z), Some(&vel)).unwrap();
            b.solve_step().unwrap();
            b.commit_step().unwrap();
            assert_eq!(a.gamma(), b.gamma());
            assert_eq!(a.loads().total_force(), b.loads().total_force());
        }
        assert!(matches!(b.solve_step(), Err(UvlmError::StepOrder { call: "solve_step", .. })));
        assert!(matches!(b.commit_step(), Err(UvlmError::StepOrder { call: "commit_step", .. })));
        b.advance_wake(0.1).unwrap();
        assert!(matches!(b.advance_wake(0.1), Err(UvlmError::StepOrder { call: "advance_wake", .. })));
        assert!(matches!(b.commit_step(), Err(UvlmError::StepOrder { .. })));
        assert!(matches!(b.solve_steady(), Err(UvlmError::StepOrder { .. })));
    }

    /// A wing at zero incidence at rest in the stream carries no circulation and no load.
    #[test]
    fn zero_incidence_zero_load() {
        let mut u = solver([1.0, 0.0, 0.0]);
        u.step(0.1).unwrap();
        assert!(u.gamma().iter().all(|g| g.abs() < 1e-15));
        assert!(u.loads().total_force().iter().all(|f| f.abs() < 1e-15));
    }
}
