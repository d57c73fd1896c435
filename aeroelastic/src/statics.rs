//! Static aeroelastic equilibrium: the structure (gravity, springs, point masses) under the steady
//! aerodynamic loads of its own deformed lattice, by Newton's method on the coupled residual, with
//! continuation in airspeed (docs/statics.md).
//!
//! The coupled system is the structure's `ConstrainedSystem` with the station loads of a steady
//! UVLM solve (semi-infinite wake legs along the free stream, [`uvlm::Uvlm::solve_steady`], or the
//! finite frozen wake of `static.wake`) at the current coordinates added to its residual
//! ([`AeroStatic`]). Its tangent is the structure's
//! (loads held) plus the aerodynamic stiffness `−∂Q_aero/∂q`, from the lattice's analytic load
//! derivative ([`uvlm::Uvlm::steady_load_derivative`]) composed with central differences of the
//! smooth maps without a lattice solve (stations, lumping, polar correction, the formulation's
//! load; docs/statics.md §2), or on request a forward difference of steady solves. It is still
//! a few hundred evaluations, so the aerodynamic part is kept between iterations and between
//! airspeeds (scaled by V², the exact scaling at fixed geometry) and refreshed only when Newton
//! stops contracting. The generic Newton iteration of `genalpha::analysis` does the rest
//! (constraints, multipliers, convergence tests).
//!
//! A sweep starts at the highest airspeed, from the reference configuration (ramping gravity in
//! if the direct solve fails), and walks down the list, each point from the previous equilibrium;
//! a point that fails is retried through intermediate airspeeds (bisection), and if it still
//! fails it is reported and the sweep goes on from the last equilibrium.

use std::sync::{Mutex, MutexGuard, PoisonError, RwLock, RwLockReadGuard, RwLockWriteGuard};
use std::time::Instant;

use genalpha::analysis::{StaticParams, StaticSolution, StaticSolver};
use genalpha::{ConstrainedSystem, MatView};
use nalgebra::Vector3;

use crate::Error;
use formulation::Structure;

use crate::aero::{AeroSettings, SectionLoad, StationMap, station_map, stations_at};
use crate::aero_settings::AeroModel;
use crate::factory::{BuildModel, ForModel, dispatch};
use crate::loads::{LoadModel, LoadScratch, WingLoads};
use crate::polar_correction::{StripPolars, StripReport};
use crate::problem::{Formulation, Problem};
use crate::strip_statics::StripStatics;

/// What turns a lattice solve into station loads besides the lattice: the section polars'
/// correction, or the static strips in its place, each with the factor on its Reynolds numbers.
type Sources<'a> = (Option<(&'a StripPolars, f64)>, Option<(&'a StripStatics, f64)>);

/// Ring nodes (stacked over the surfaces), the nodal forces on them and the strip forces.
type LatticeForces<'a> = (&'a [[f64; 3]], &'a [[f64; 3]], &'a [[f64; 3]]);

/// The steady aerodynamics of a lattice that follows the structure.
struct SteadyAero {
    uv: uvlm::Uvlm,
    /// The stations of each lifting surface.
    ranges: Vec<std::ops::Range<usize>>,
    stations: Vec<uvlm::SpanStation>,
    vel: Vec<uvlm::StationVelocity>,
    scratch: crate::aero::StationScratch,
    zeros: Vec<f64>,
    origins: Vec<[f64; 3]>,
    fbuf: Vec<[f64; 3]>,
    mbuf: Vec<[f64; 3]>,
    n_solves: usize,
    /// The section polars' correction of the last solve.
    report: StripReport,
}

impl SteadyAero {
    /// A steady UVLM on the lattice of `model` at `q`, with free stream `v_inf` and the steady
    /// wake `wake`.
    fn new<S: Structure>(
        model: &S,
        q: &[f64],
        map: &[StationMap],
        aero: &AeroSettings,
        v_inf: [f64; 3],
        wake: uvlm::SteadyWake,
        lattice: bool,
    ) -> Result<Self, String> {
        let mut s = Self {
            uv: placeholder_uvlm()?,
            ranges: Vec::new(),
            stations: Vec::new(),
            vel: Vec::new(),
            scratch: crate::aero::StationScratch::default(),
            zeros: vec![0.0; model.n_dof()],
            origins: Vec::with_capacity(map.len()),
            fbuf: vec![[0.0; 3]; map.len()],
            mbuf: vec![[0.0; 3]; map.len()],
            n_solves: 0,
            report: StripReport::default(),
        };
        stations_at(model, q, &s.zeros, map, aero, None, &mut s.scratch, &mut s.stations, &mut s.vel);
        s.ranges = crate::lifting::surface_ranges(map);
        if !lattice {
            // The static strips need the stations only (a folded tip is no lattice's concern).
            return Ok(s);
        }
        let mut params = aero.uvlm_params(v_inf);
        params.steady_wake = wake;
        s.uv = crate::lifting::new_uvlm(map, aero, &s.stations, params)
            .map_err(|e| format!("aerodynamic lattice: {e}"))?;
        Ok(s)
    }

    /// Station loads of the steady solution on the lattice of `model` at `q`, into `out`,
    /// corrected by the section polars `polars` (the structure at rest: each strip sees the free
    /// stream); or with `strips`, the static strips' loads instead of the lattice's (their
    /// Reynolds numbers scaled by the factor beside them).
    fn loads_at<S: Structure>(
        &mut self,
        model: &S,
        q: &[f64],
        map: &[StationMap],
        aero: &AeroSettings,
        (polars, strips): Sources<'_>,
        out: &mut [SectionLoad],
    ) -> Result<(), String> {
        stations_at(model, q, &self.zeros, map, aero, None, &mut self.scratch, &mut self.stations, &mut self.vel);
        if let Some((st, re_factor)) = strips {
            self.n_solves += 1;
            return st.loads(&self.stations, (map, aero), re_factor, out, &mut self.report);
        }
        crate::lifting::move_lattices(&mut self.uv, &self.ranges, &self.stations, None)
            .map_err(|e| format!("aerodynamic lattice: {e}"))?;
        self.uv.solve_steady().map_err(|e| format!("steady aerodynamics: {e}"))?;
        self.n_solves += 1;
        self.origins.clear();
        self.origins.extend(self.stations.iter().map(|x| [x.origin.x, x.origin.y, x.origin.z]));
        crate::lifting::lump_into(&self.uv, &self.ranges, &self.origins, &mut self.fbuf, &mut self.mbuf);
        for (j, t) in out.iter_mut().enumerate() {
            t.force = Vector3::from(self.fbuf[j]);
            t.moment = Vector3::from(self.mbuf[j]);
        }
        if let Some((p, re_factor)) = polars {
            let v = Vector3::from(self.uv.params().v_inf);
            p.correct(&self.stations, map, self.uv.loads(), |_, _| v, re_factor, out, &mut self.report)?;
        }
        Ok(())
    }
}

impl SteadyAero {
    /// Move the lattice to the stations of `model` at `q` (geometry only, no solve) and put its
    /// ring nodes, surface after surface, into `out`.
    fn geometry_at<S: Structure>(
        &mut self,
        model: &S,
        q: &[f64],
        map: &[StationMap],
        aero: &AeroSettings,
        out: &mut Vec<[f64; 3]>,
    ) -> Result<(), String> {
        stations_at(model, q, &self.zeros, map, aero, None, &mut self.scratch, &mut self.stations, &mut self.vel);
        crate::lifting::move_lattices(&mut self.uv, &self.ranges, &self.stations, None)
            .map_err(|e| format!("aerodynamic lattice: {e}"))?;
        out.clear();
        for s in self.uv.surfaces() {
            out.extend_from_slice(s.lattice().ring_nodes());
        }
        Ok(())
    }

    /// Station loads of the lattice forces `nodal` (on the ring nodes, stacked) and `strip` at
    /// the geometry of the last [`SteadyAero::geometry_at`] (ring nodes `nodes`): lumped to the
    /// stations and corrected by `polars` as [`SteadyAero::loads_at`] does.
    fn loads_of(
        &mut self,
        map: &[StationMap],
        (nodes, nodal, strip): LatticeForces<'_>,
        polars: Option<(&StripPolars, f64)>,
        out: &mut [SectionLoad],
    ) -> Result<(), String> {
        self.origins.clear();
        self.origins.extend(self.stations.iter().map(|x| [x.origin.x, x.origin.y, x.origin.z]));
        let mut v0 = 0;
        for (r, surf) in self.ranges.iter().zip(self.uv.surfaces()) {
            let nn = surf.lattice().n_nodes();
            uvlm::lump_columns(
                &nodes[v0..v0 + nn],
                &nodal[v0..v0 + nn],
                &self.origins[r.clone()],
                &mut self.fbuf[r.clone()],
                &mut self.mbuf[r.clone()],
            );
            v0 += nn;
        }
        for (j, t) in out.iter_mut().enumerate() {
            t.force = Vector3::from(self.fbuf[j]);
            t.moment = Vector3::from(self.mbuf[j]);
        }
        if let Some((p, re_factor)) = polars {
            let v = Vector3::from(self.uv.params().v_inf);
            let mut report = StripReport::default();
            p.correct_strips(&self.stations, map, strip, |_, _| v, re_factor, out, &mut report)?;
        }
        Ok(())
    }
}

/// A one-ring lattice that stands in until the real one is built (keeps `SteadyAero::new`
/// free of `Option`s).
fn placeholder_uvlm() -> Result<uvlm::Uvlm, String> {
    let st = |x: f64| uvlm::SpanStation {
        origin: Vector3::new(x, 0.0, 0.0),
        frame: nalgebra::Matrix3::identity(),
        chord: 1.0,
        le_offset: 0.5,
        slant: 0.0,
        flap: None,
    };
    uvlm::Lattice::from_stations(uvlm::LatticeSpec::new(1), &[st(0.0), st(1.0)])
        .and_then(|l| uvlm::Uvlm::new(l, uvlm::UvlmParams::new(1.0, [0.0, -1.0, 0.0])))
        .map_err(|e| e.to_string())
}

/// The shortest step (m in the increment weights) along which [`Secant`] corrects the kept
/// aerodynamic stiffness: the loads' difference must stand well above its round-off (1e-16 of
/// ANCF's 1e5 N axial terms against a stiffness of order 10 N/m times the step).
const SECANT_MIN_STEP: f64 = 1e-8;

/// Broyden's rank-one correction of the kept aerodynamic stiffness `K` along the static
/// solver's steps: with `s` the last step (tangent space) and `y` the change of the
/// generalised aerodynamic load along it, `K ← K + (y − K s) (W² s)ᵀ / (sᵀ W² s)` with `W` the
/// increment weights, so that the kept stiffness reproduces the load's change along the step
/// (the secant condition) and is unchanged across it. A kept stiffness then converges
/// superlinearly instead of linearly (Dennis & Moré 1977; Kelley, *Iterative Methods for
/// Linear and Nonlinear Equations*, SIAM 1995, ch. 7).
#[derive(Debug)]
struct Secant {
    /// Coordinates and generalised aerodynamic load of the last evaluation.
    q: Vec<f64>,
    g: Vec<f64>,
    has_g: bool,
    /// The solver's step since: its start and its tangent vector.
    from: Vec<f64>,
    step: Vec<f64>,
    has_step: bool,
    zeros: Vec<f64>,
    residual: Vec<f64>,
    /// The increment weights `W` of the coordinates (fixed by the model's coordinates).
    weights: Vec<f64>,
}

impl Secant {
    fn new(n_coords: usize, weights: Vec<f64>) -> Self {
        let n = weights.len();
        Self {
            q: vec![0.0; n_coords],
            g: vec![0.0; n],
            has_g: false,
            from: vec![0.0; n_coords],
            step: vec![0.0; n],
            has_step: false,
            zeros: vec![0.0; n],
            residual: vec![0.0; n],
            weights,
        }
    }

    /// Start afresh (a new solve, a new lattice or airspeed: the load is another function).
    fn forget(&mut self) {
        self.has_g = false;
        self.has_step = false;
    }

    fn note_step(&mut self, from: &[f64], step: &[f64]) {
        self.from.copy_from_slice(from);
        self.step.copy_from_slice(step);
        self.has_step = true;
    }

    /// The generalised load `g` at `q`, for the next update.
    fn remember(&mut self, q: &[f64], g: &[f64]) {
        self.q.copy_from_slice(q);
        self.g.copy_from_slice(g);
        self.has_g = true;
        self.has_step = false;
    }

    /// Correct `k` (row-major n × n, used times `scale`) with the load `g` at the end of the
    /// noted step, if that step left the remembered state and is long enough.
    fn update(&mut self, k: &mut [f64], scale: f64, g: &[f64]) {
        if !(self.has_g && self.has_step && self.from == self.q) {
            return;
        }
        let n = self.g.len();
        let w = &self.weights;
        let size = self.step.iter().zip(w).fold(0.0_f64, |m, (s, w)| m.max((s * w).abs()));
        if !(size > SECANT_MIN_STEP && scale.is_finite() && scale > 0.0) {
            return;
        }
        let denom: f64 = self.step.iter().zip(w).map(|(s, w)| (s * w).powi(2)).sum();
        for i in 0..n {
            let ks: f64 = k[i * n..(i + 1) * n].iter().zip(&self.step).map(|(a, s)| a * s).sum();
            self.residual[i] = (g[i] - self.g[i]) / scale - ks;
        }
        for i in 0..n {
            let c = self.residual[i] / denom;
            if c == 0.0 {
                continue;
            }
            for ((a, s), w) in k[i * n..(i + 1) * n].iter_mut().zip(&self.step).zip(w) {
                *a += c * s * w.powi(2);
            }
        }
    }
}

/// The aerodynamic stiffness and when to refresh it.
struct AeroTangent {
    /// `−∂Q_aero/∂q` (row-major, n × n) at airspeed² `speed2`.
    k: Vec<f64>,
    speed2: f64,
    valid: bool,
    /// Re-evaluate at the next assembly.
    refresh: bool,
    n_refresh: usize,
    /// The secant (Broyden) updates of `k` along the static solver's steps.
    secant: Secant,
    // work buffers
    dq: Vec<f64>,
    q_tmp: Vec<f64>,
    r0: Vec<f64>,
    r1: Vec<f64>,
    loads: Vec<SectionLoad>,
}

/// The structure with the steady aerodynamic loads of its own lattice: a [`ConstrainedSystem`]
/// whose static equilibria are the aeroelastic ones.
pub struct AeroStatic<'a, S: Structure> {
    model: RwLock<S>,
    aero_state: Mutex<SteadyAero>,
    tangent: Mutex<AeroTangent>,
    loads: Mutex<Vec<SectionLoad>>,
    zero_loads: Vec<SectionLoad>,
    error: Mutex<Option<String>>,
    map: &'a [StationMap],
    aero: AeroSettings,
    /// The steady wake (a fixed length: the V² scaling of the kept stiffness stays exact).
    wake: uvlm::SteadyWake,
    speed2: f64,
    /// Forward-difference step of the aerodynamic stiffness, in the increment weights' units.
    fd_step: f64,
    /// The section polars that correct the lattice's loads (none: uncorrected).
    polars: Option<StripPolars>,
    /// The airspeed whose Reynolds numbers the polars are read at (none: the current one).
    reynolds_airspeed: Option<f64>,
    /// The static strips that replace the lattice (`aero.model: "strip"`; none: the lattice).
    strips: Option<StripStatics>,
    /// Take the lattice's aerodynamic stiffness by forward differences of steady solves instead
    /// of the analytic load derivative (docs/statics.md §2).
    difference_tangent: bool,
}

impl<'a, S: Structure> AeroStatic<'a, S> {
    /// The coupled system of `model` with the aerodynamics `aero` (its free stream as given) on
    /// the stations `map`, with the steady wake `wake`; the lattice is built at `q`.
    pub fn new(
        model: S,
        q: &[f64],
        map: &'a [StationMap],
        aero: &AeroSettings,
        wake: uvlm::SteadyWake,
        span: f64,
    ) -> Result<Self, String> {
        let v = aero.free_stream();
        let st = SteadyAero::new(&model, q, map, aero, v, wake, true)?;
        let n = model.n_dof();
        let loads: Vec<SectionLoad> = map
            .iter()
            .map(|m| SectionLoad { body: m.body, s: m.s, force: Vector3::zeros(), moment: Vector3::zeros() })
            .collect();
        let tangent = AeroTangent {
            k: vec![0.0; n * n],
            speed2: 0.0,
            valid: false,
            refresh: false,
            n_refresh: 0,
            secant: Secant::new(model.n_coords(), (0..n).map(|j| model.increment_weight(j)).collect()),
            dq: vec![0.0; n],
            q_tmp: vec![0.0; model.n_coords()],
            r0: vec![0.0; n],
            r1: vec![0.0; n],
            loads: loads.clone(),
        };
        Ok(Self {
            model: RwLock::new(model),
            aero_state: Mutex::new(st),
            tangent: Mutex::new(tangent),
            zero_loads: loads.clone(),
            loads: Mutex::new(loads),
            error: Mutex::new(None),
            map,
            aero: aero.clone(),
            wake,
            speed2: v.iter().map(|x| x * x).sum(),
            fd_step: 1e-7 * span.max(1e-3),
            polars: None,
            reynolds_airspeed: None,
            strips: None,
            difference_tangent: false,
        })
    }

    /// Replace the lattice by the static strips `strips` from now on (none: the lattice). Their
    /// aerodynamic stiffness is a central difference of the strips' generalised load (cheap: no
    /// lattice solve), refreshed at every round of Newton iterations.
    pub fn set_strips(&mut self, strips: Option<StripStatics>) {
        self.strips = strips;
        self.tangent.get_mut().unwrap_or_else(PoisonError::into_inner).valid = false;
        self.begin_solve(true);
    }

    /// Take the lattice's aerodynamic stiffness by forward differences of steady solves (one per
    /// coordinate) when `on`, instead of the analytic load derivative (the default; for
    /// comparison).
    pub fn set_difference_tangent(&mut self, on: bool) {
        self.difference_tangent = on;
        self.tangent.get_mut().unwrap_or_else(PoisonError::into_inner).valid = false;
    }

    /// Whether the static strips replace the lattice.
    pub fn has_strips(&self) -> bool {
        self.strips.is_some()
    }

    /// Correct the lattice's loads by the section polars `polars` from now on (none: the
    /// lattice's own loads). The aerodynamic stiffness, a difference quotient of the corrected
    /// loads, then holds the correction's derivative (docs/section_aero.md §7).
    pub fn set_polars(&mut self, polars: Option<StripPolars>) {
        self.polars = polars;
        self.begin_solve(true);
    }

    /// Read the polars at the Reynolds numbers of `airspeed` whatever the current airspeed (none:
    /// at the current one). The load stepping of a sweep ramps the dynamic pressure through low
    /// airspeeds, which would otherwise leave a polar's Reynolds range.
    pub fn hold_reynolds_at(&mut self, airspeed: Option<f64>) {
        self.reynolds_airspeed = airspeed;
    }

    /// The section polars' correction at the last evaluation of the loads (empty without
    /// polars).
    pub fn strip_report(&self) -> StripReport {
        lock(&self.aero_state).report.clone()
    }

    /// Change the airspeed (the free stream keeps its direction): the lattice is rebuilt at `q`;
    /// the aerodynamic stiffness is kept, scaled by the square of the speed ratio.
    pub fn set_airspeed(&mut self, airspeed: f64, q: &[f64]) -> Result<(), String> {
        self.aero.airspeed = Some(airspeed);
        self.rebuild_lattice(q)
    }

    /// Replace the aerodynamic settings (a turned free stream, new control-surface deflections;
    /// the station map stays): the lattice is rebuilt at `q`, the aerodynamic stiffness kept (a
    /// Newton iteration refreshes it when it stops contracting). The trim's step.
    pub fn set_aero(&mut self, aero: &AeroSettings, q: &[f64]) -> Result<(), String> {
        self.aero = aero.clone();
        self.rebuild_lattice(q)
    }

    /// Rebuild the lattice of the current aerodynamic settings at `q`, keeping the solve count
    /// and the aerodynamic stiffness.
    fn rebuild_lattice(&mut self, q: &[f64]) -> Result<(), String> {
        let v = self.aero.free_stream();
        let solves = lock(&self.aero_state).n_solves;
        let lattice = self.strips.is_none();
        let mut st = SteadyAero::new(&*read(&self.model), q, self.map, &self.aero, v, self.wake, lattice)?;
        st.n_solves = solves;
        *lock(&self.aero_state) = st;
        self.speed2 = v.iter().map(|x| x * x).sum();
        self.begin_solve(false);
        Ok(())
    }

    /// Change the sideslip angle (the airspeed kept): the lattice is rebuilt at `q`; the
    /// aerodynamic stiffness is kept (a Newton iteration refreshes it when it stops contracting).
    pub fn set_sideslip(&mut self, sideslip_deg: f64, q: &[f64]) -> Result<(), String> {
        self.aero.sideslip_deg = sideslip_deg;
        let speed = self.aero.airspeed.unwrap_or_else(|| self.airspeed());
        self.set_airspeed(speed, q)
    }

    /// Drop the kept aerodynamic stiffness: the next assembly evaluates it afresh (a walk that
    /// goes back to an earlier equilibrium must not start from the stiffness of a far one).
    pub fn forget_tangent(&mut self) {
        let tg = self.tangent.get_mut().unwrap_or_else(PoisonError::into_inner);
        tg.valid = false;
        tg.secant.forget();
    }

    /// The sideslip angle, degrees.
    pub fn sideslip_deg(&self) -> f64 {
        self.aero.sideslip_deg
    }

    /// Replace the structural model (same coordinates; e.g. with scaled gravity).
    pub fn set_model(&mut self, model: S) {
        let tg = self.tangent.get_mut().unwrap_or_else(PoisonError::into_inner);
        for (j, w) in tg.secant.weights.iter_mut().enumerate() {
            *w = model.increment_weight(j);
        }
        *write(&self.model) = model;
        self.begin_solve(false);
    }

    /// Start a solve: re-evaluate the aerodynamic stiffness at the next assembly when `refresh`
    /// (it is evaluated at the first assembly in any case).
    pub fn begin_solve(&mut self, refresh: bool) {
        let tg = self.tangent.get_mut().unwrap_or_else(PoisonError::into_inner);
        tg.refresh = refresh;
        tg.secant.forget();
        *self.error.get_mut().unwrap_or_else(PoisonError::into_inner) = None;
    }

    /// The structural model.
    pub fn model(&self) -> RwLockReadGuard<'_, S> {
        read(&self.model)
    }

    /// The airspeed, m/s.
    pub fn airspeed(&self) -> f64 {
        self.speed2.sqrt()
    }

    /// Why the last residual could not be evaluated (the lattice folded, the solve failed).
    pub fn error(&self) -> Option<String> {
        lock(&self.error).clone()
    }

    /// Steady solves and aerodynamic-stiffness evaluations so far.
    pub fn counters(&self) -> (usize, usize) {
        // One lock at a time: `update_tangent` takes them in the other order.
        let solves = lock(&self.aero_state).n_solves;
        (solves, lock(&self.tangent).n_refresh)
    }

    /// Station loads and the UVLM's lattice loads at `q`.
    fn station_loads(&self, q: &[f64], out: &mut [SectionLoad]) -> bool {
        let model = read(&self.model);
        let re_factor = self.reynolds_airspeed.map_or(1.0, |u| u / self.speed2.sqrt());
        let polars = self.polars.as_ref().map(|p| (p, re_factor));
        let strips = self.strips.as_ref().map(|s| (s, re_factor));
        match lock(&self.aero_state).loads_at(&*model, q, self.map, &self.aero, (polars, strips), out) {
            Ok(()) => true,
            Err(e) => {
                *lock(&self.error) = Some(e);
                false
            }
        }
    }

    /// Loads at `q` applied to the model; false when the aerodynamics failed.
    fn apply_loads(&self, q: &[f64]) -> bool {
        let mut loads = lock(&self.loads);
        if !self.station_loads(q, &mut loads) {
            return false;
        }
        if let Err(e) = write(&self.model).set_section_loads(&loads) {
            *lock(&self.error) = Some(e.to_string());
            return false;
        }
        true
    }

    /// The station loads of the last residual evaluation.
    pub fn current_loads(&self) -> Vec<SectionLoad> {
        lock(&self.loads).clone()
    }

    /// Recompute the aerodynamics at `q` (e.g. at a converged equilibrium, after the difference
    /// quotients moved the lattice); returns the station loads and the UVLM's loads.
    pub fn evaluate_at(&self, q: &[f64]) -> Result<(Vec<SectionLoad>, uvlm::Loads, Vec<uvlm::SpanStation>), String> {
        if !self.apply_loads(q) {
            return Err(self.error().unwrap_or_default());
        }
        let st = lock(&self.aero_state);
        Ok((lock(&self.loads).clone(), st.uv.loads().clone(), st.stations.clone()))
    }

    /// The control surfaces' hinge moments (N·m, trailing edge down positive) of the last
    /// lattice solve (call after [`Self::evaluate_at`]); the lattice's loads, without the section
    /// polars' correction.
    pub fn control_hinge_moments(&self, map: &[StationMap]) -> Result<Vec<f64>, String> {
        let cols = crate::control_surface::columns(map, &self.aero.control_surfaces)?;
        let st = lock(&self.aero_state);
        let ranges = crate::lifting::surface_ranges(map);
        cols.into_iter()
            .map(|c| crate::lifting::hinge_moment(&st.uv, &ranges, c).map_err(|e| format!("hinge moment: {e}")))
            .collect()
    }

    /// Generalised aerodynamic load `r(q, L) − r(q, 0)` (the residual's load part, with the
    /// minus sign of an external force) of the station loads `loads` at `q`, into `out`.
    fn load_part(&self, t: f64, q: &[f64], loads: &[SectionLoad], zeros: &[f64], scratch: &mut [f64], out: &mut [f64]) {
        let mut m = write(&self.model);
        let applied = m
            .set_section_loads(loads)
            .map(|()| m.residual_inplace(t, q, zeros, zeros, out))
            .and_then(|()| m.set_section_loads(&self.zero_loads));
        if let Err(e) = applied {
            *lock(&self.error) = Some(e.to_string());
            out.fill(f64::NAN);
            return;
        }
        m.residual_inplace(t, q, zeros, zeros, scratch);
        for (o, s) in out.iter_mut().zip(scratch.iter()) {
            *o -= s;
        }
    }

    /// The residual with the loads of `q` into `r`, and `c_k` times the aerodynamic stiffness
    /// added to `k` (the structure's matrix is already there).
    #[allow(clippy::too_many_arguments)] // the state, the residual and the matrix with its weight
    fn add_aero(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64], c_k: f64, k: &mut MatView<'_>) {
        if !self.apply_loads(q) {
            r.iter_mut().for_each(|x| *x = f64::NAN);
            return;
        }
        read(&self.model).residual_inplace(t, q, v, v_dot, r);
        if c_k == 0.0 {
            return;
        }
        let refreshes = lock(&self.tangent).n_refresh;
        self.update_tangent(t, q);
        self.secant_update(t, q, r, refreshes);
        let tg = lock(&self.tangent);
        let n = self.n_dof();
        let scale = c_k * self.speed2 / tg.speed2;
        for i in 0..n {
            for j in 0..n {
                let v = tg.k[i * n + j];
                if v != 0.0 {
                    k.add(i, j, scale * v);
                }
            }
        }
    }

    /// Correct the kept aerodynamic stiffness along the solver's last step (Broyden's update in
    /// the increment weights' metric), from the generalised aerodynamic load at `q` (`r`, the
    /// residual with the loads of `q`, minus the residual without them) and at the state the
    /// step left. Not after a refresh at `q` (`refreshes` was the count before it), nor along a
    /// step too short for the difference of the loads to rise above their round-off.
    fn secant_update(&self, t: f64, q: &[f64], r: &[f64], refreshes: usize) {
        let mut tg = lock(&self.tangent);
        let tg = &mut *tg;
        if !tg.valid {
            return;
        }
        {
            let mut m = write(&self.model);
            let loads = lock(&self.loads);
            let unloaded = m
                .set_section_loads(&self.zero_loads)
                .map(|()| m.residual_inplace(t, q, &tg.secant.zeros, &tg.secant.zeros, &mut tg.r0))
                .and_then(|()| m.set_section_loads(&loads));
            if let Err(e) = unloaded {
                *lock(&self.error) = Some(e.to_string());
                tg.secant.forget();
                return;
            }
        }
        for ((g, a), b) in tg.r1.iter_mut().zip(r).zip(&tg.r0) {
            *g = a - b;
        }
        let scale = self.speed2 / tg.speed2;
        if tg.n_refresh == refreshes {
            tg.secant.update(&mut tg.k, scale, &tg.r1);
        }
        tg.secant.remember(q, &tg.r1);
    }

    /// The generalised aerodynamic load at `q` moved by `h` along coordinate `j`, into `tg.r1`;
    /// false when the aerodynamics failed there.
    #[allow(clippy::too_many_arguments)] // the point, the step and the work buffers
    fn load_part_at(
        &self,
        t: f64,
        q: &[f64],
        j: usize,
        h: f64,
        tg: &mut AeroTangent,
        zeros: &[f64],
        scratch: &mut [f64],
    ) -> bool {
        tg.dq.iter_mut().for_each(|x| *x = 0.0);
        tg.dq[j] = h;
        read(&self.model).retract_inplace(q, &tg.dq, &mut tg.q_tmp);
        if !self.station_loads(&tg.q_tmp, &mut tg.loads) {
            return false;
        }
        self.load_part(t, &tg.q_tmp, &tg.loads, zeros, scratch, &mut tg.r1);
        true
    }

    /// Decide whether to refresh the aerodynamic stiffness at `q`, and do it: the forward
    /// difference of the whole generalised aerodynamic load, so that both the lattice's
    /// response and the way a formulation applies a station load (ANCF's moments through the
    /// section slopes) are in it. The model's loads are those of `q` on return.
    fn update_tangent(&self, t: f64, q: &[f64]) {
        let mut tg = lock(&self.tangent);
        let tg = &mut *tg;
        if tg.valid && !tg.refresh {
            return;
        }
        tg.refresh = false;
        tg.n_refresh += 1;
        let n = self.n_dof();
        let zeros = vec![0.0; n];
        let mut scratch = vec![0.0; n];
        let loads_q = lock(&self.loads).clone();
        if self.strips.is_none() && !self.difference_tangent {
            // The analytic load derivative; the differences below where it does not apply (a
            // core sized by the panels, a lattice that folded at a side point).
            let done = self.analytic_tangent(t, q, tg, &zeros, &mut scratch);
            if done.is_ok() {
                tg.speed2 = self.speed2;
                tg.valid = true;
                if let Err(e) = write(&self.model).set_section_loads(&loads_q) {
                    *lock(&self.error) = Some(e.to_string());
                }
                return;
            }
        }
        self.load_part(t, q, &loads_q, &zeros, &mut scratch, &mut tg.r0);
        // The strips are cheap: a central difference (second order) instead of a forward one.
        let central = self.strips.is_some();
        // The backward loads of a central difference; the forward difference's base otherwise.
        let mut back = if central { vec![0.0; n] } else { tg.r0.clone() };
        for j in 0..n {
            let h = self.fd_step / read(&self.model).increment_weight(j).max(1e-12);
            let ok = self.load_part_at(t, q, j, h, tg, &zeros, &mut scratch)
                && (!central || {
                    std::mem::swap(&mut tg.r1, &mut back);
                    let ok = self.load_part_at(t, q, j, -h, tg, &zeros, &mut scratch);
                    std::mem::swap(&mut tg.r1, &mut back);
                    ok
                });
            let step = if central { 2.0 * h } else { h };
            for (i, (r1, b)) in tg.r1.iter().zip(&back).enumerate() {
                // A column that failed keeps the structural tangent alone.
                tg.k[i * n + j] = if ok { (r1 - b) / step } else { 0.0 };
            }
        }
        tg.speed2 = self.speed2;
        tg.valid = true;
        // Back to the loads of q (accepted before).
        if let Err(e) = write(&self.model).set_section_loads(&loads_q) {
            *lock(&self.error) = Some(e.to_string());
        }
    }
}

impl<S: Structure> AeroStatic<'_, S> {
    /// The aerodynamic stiffness at `q` from the lattice's analytic load derivative
    /// (docs/statics.md §2): with `D = ∂(nodal, strip forces)/∂X` of the steady solution at `q`
    /// and `E(q, F)` the generalised load of the lattice forces `F` placed on the geometry of
    /// `q` (lumped to the stations, corrected by the polars, applied by the formulation), column
    /// `j` is the central difference of `E(q ± h e_j, F₀ ± h D δX_j)` with `δX_j` the central
    /// difference of the ring nodes: every quotient is of a smooth map without a lattice solve.
    fn analytic_tangent(
        &self,
        t: f64,
        q: &[f64],
        tg: &mut AeroTangent,
        zeros: &[f64],
        scratch: &mut [f64],
    ) -> Result<(), String> {
        let n = self.n_dof();
        let re_factor = self.reynolds_airspeed.map_or(1.0, |u| u / self.speed2.sqrt());
        let polars = self.polars.as_ref().map(|p| (p, re_factor));
        let mut st = lock(&self.aero_state);
        let mut x0 = Vec::new();
        st.geometry_at(&*read(&self.model), q, self.map, &self.aero, &mut x0)?;
        let d = st.uv.steady_load_derivative().map_err(|e| format!("load derivative: {e}"))?;
        st.n_solves += 1;
        let nv = x0.len();
        let (mut xp, mut xm) = (Vec::with_capacity(nv), Vec::with_capacity(nv));
        let (mut qp, mut qm) = (tg.q_tmp.clone(), tg.q_tmp.clone());
        // Smooth maps only: a step of 1e-6 of the span in the increment weights.
        let steps: Vec<f64> =
            (0..n).map(|j| 10.0 * self.fd_step / read(&self.model).increment_weight(j).max(1e-12)).collect();
        let sides = |j: usize, dq: &mut [f64], qp: &mut [f64], qm: &mut [f64]| {
            dq.iter_mut().for_each(|x| *x = 0.0);
            dq[j] = steps[j];
            read(&self.model).retract_inplace(q, dq, qp);
            dq[j] = -steps[j];
            read(&self.model).retract_inplace(q, dq, qm);
        };
        // The ring nodes' derivative, one column per coordinate, then the forces' (two products).
        let mut dx = nalgebra::DMatrix::zeros(3 * nv, n);
        for j in 0..n {
            sides(j, &mut tg.dq, &mut qp, &mut qm);
            st.geometry_at(&*read(&self.model), &qp, self.map, &self.aero, &mut xp)?;
            st.geometry_at(&*read(&self.model), &qm, self.map, &self.aero, &mut xm)?;
            for v in 0..nv {
                for a in 0..3 {
                    dx[(3 * v + a, j)] = (xp[v][a] - xm[v][a]) / (2.0 * steps[j]);
                }
            }
        }
        let dn = &d.d_nodal * &dx;
        let ds = &d.d_strip * &dx;
        let (mut fp, mut fm) = (vec![[0.0; 3]; nv], vec![[0.0; 3]; nv]);
        let (mut sp, mut sm) = (vec![[0.0; 3]; d.strip.len()], vec![[0.0; 3]; d.strip.len()]);
        for j in 0..n {
            let h = steps[j];
            for v in 0..nv {
                for a in 0..3 {
                    fp[v][a] = d.nodal[v][a] + h * dn[(3 * v + a, j)];
                    fm[v][a] = d.nodal[v][a] - h * dn[(3 * v + a, j)];
                }
            }
            for k in 0..sp.len() {
                for a in 0..3 {
                    sp[k][a] = d.strip[k][a] + h * ds[(3 * k + a, j)];
                    sm[k][a] = d.strip[k][a] - h * ds[(3 * k + a, j)];
                }
            }
            sides(j, &mut tg.dq, &mut qp, &mut qm);
            st.geometry_at(&*read(&self.model), &qm, self.map, &self.aero, &mut xm)?;
            st.loads_of(self.map, (&xm, &fm, &sm), polars, &mut tg.loads)?;
            self.load_part(t, &qm, &tg.loads, zeros, scratch, &mut tg.r0);
            st.geometry_at(&*read(&self.model), &qp, self.map, &self.aero, &mut xp)?;
            st.loads_of(self.map, (&xp, &fp, &sp), polars, &mut tg.loads)?;
            self.load_part(t, &qp, &tg.loads, zeros, scratch, &mut tg.r1);
            for i in 0..n {
                tg.k[i * n + j] = (tg.r1[i] - tg.r0[i]) / (2.0 * h);
            }
        }
        // The lattice back at q.
        st.geometry_at(&*read(&self.model), q, self.map, &self.aero, &mut x0)?;
        if tg.k.iter().all(|v| v.is_finite()) { Ok(()) } else { Err("non-finite load derivative".into()) }
    }
}

impl<S: Structure> ConstrainedSystem for AeroStatic<'_, S> {
    fn note_static_step(&self, q_from: &[f64], dq: &[f64]) {
        lock(&self.tangent).secant.note_step(q_from, dq);
    }

    fn adjust_static_step(&self, q: &[f64], dq: &mut [f64]) {
        read(&self.model).adjust_static_step(q, dq);
    }

    fn n_coords(&self) -> usize {
        read(&self.model).n_coords()
    }
    fn n_dof(&self) -> usize {
        read(&self.model).n_dof()
    }
    fn n_holonomic(&self) -> usize {
        read(&self.model).n_holonomic()
    }
    fn n_velocity_constraints(&self) -> usize {
        read(&self.model).n_velocity_constraints()
    }
    fn retract_inplace(&self, q: &[f64], dq: &[f64], q_out: &mut [f64]) {
        read(&self.model).retract_inplace(q, dq, q_out);
    }
    fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        if !self.apply_loads(q) {
            r.iter_mut().for_each(|x| *x = f64::NAN);
            return;
        }
        read(&self.model).residual_inplace(t, q, v, v_dot, r);
    }
    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        let mut r = vec![0.0; self.n_dof()];
        self.residual_and_iteration_matrix_inplace(t, q, v, v_dot, &mut r, c_m, c_c, c_k, k);
    }
    fn residual_and_iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        r: &mut [f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        // The structure's matrix without loads (their tangent is in the difference quotients),
        // then the residual with the loads of q.
        if let Err(e) = write(&self.model).set_section_loads(&self.zero_loads) {
            *lock(&self.error) = Some(e.to_string());
            r.fill(f64::NAN);
            return;
        }
        read(&self.model).residual_and_iteration_matrix_inplace(t, q, v, v_dot, r, c_m, c_c, c_k, k);
        self.add_aero(t, q, v, v_dot, r, c_k, k);
    }
    fn residual_and_static_matrix_inplace(&self, t: f64, q: &[f64], zeros: &[f64], r: &mut [f64], k: &mut MatView<'_>) {
        // The structure's Newton matrix at rest without loads, then as above.
        if let Err(e) = write(&self.model).set_section_loads(&self.zero_loads) {
            *lock(&self.error) = Some(e.to_string());
            r.fill(f64::NAN);
            return;
        }
        read(&self.model).residual_and_static_matrix_inplace(t, q, zeros, r, k);
        self.add_aero(t, q, zeros, zeros, r, 1.0, k);
    }
    fn has_static_matrix(&self) -> bool {
        read(&self.model).has_static_matrix()
    }
    fn phi_inplace(&self, t: f64, q: &[f64], phi: &mut [f64]) {
        read(&self.model).phi_inplace(t, q, phi);
    }
    fn phi_q_inplace(&self, t: f64, q: &[f64], j: &mut MatView<'_>) {
        read(&self.model).phi_q_inplace(t, q, j);
    }
    fn phi_q_is_constant(&self) -> bool {
        read(&self.model).phi_q_is_constant()
    }
    fn psi_inplace(&self, t: f64, q: &[f64], v: &[f64], psi: &mut [f64]) {
        read(&self.model).psi_inplace(t, q, v, psi);
    }
    fn psi_v_inplace(&self, t: f64, q: &[f64], j: &mut MatView<'_>) {
        read(&self.model).psi_v_inplace(t, q, j);
    }
    fn psi_q_inplace(&self, t: f64, q: &[f64], v: &[f64], j: &mut MatView<'_>) {
        read(&self.model).psi_q_inplace(t, q, v, j);
    }
    fn constraint_force_tangent_inplace(
        &self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        mu: &[f64],
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        read(&self.model).constraint_force_tangent_inplace(t, q, lambda, mu, c_k, k);
    }
    fn increment_weight(&self, i: usize) -> f64 {
        read(&self.model).increment_weight(i)
    }
}

/// Lift per unit span of one lattice column at an equilibrium.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Strip {
    /// Arclength of the column's middle along the wing (bodies end to end), m.
    pub s: f64,
    /// The column's middle (mean of its two stations' axis points), global, m.
    pub position: [f64; 3],
    /// Lift per unit span (perpendicular to the free stream and the global X axis), N/m.
    pub lift_per_span: f64,
    /// Section lift coefficient `l / (½ ρ V² c)`.
    pub cl: f64,
    /// Effective incidence of the strip (from the lattice's lift, docs/section_aero.md §4), rad;
    /// NaN on a strip without a section polar.
    pub alpha: f64,
}

/// One airspeed of a static sweep.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StaticPoint {
    /// Airspeed, m/s.
    pub airspeed: f64,
    /// Sideslip angle, degrees (`aero.sideslip_deg`, or the point's of a sideslip sweep).
    pub sideslip_deg: f64,
    /// Fold angle of the fold hinge, degrees (tip up positive; NaN without one).
    pub fold_deg: f64,
    /// Tip position, m.
    pub tip: [f64; 3],
    /// Root and hinge loads.
    pub loads: WingLoads,
    /// Total lift, N.
    pub lift: f64,
    /// Total drag (along the free stream), N: the lattice's induced drag, plus the profile drag
    /// of the section polars when the case has them.
    pub drag: f64,
    /// The section polars' profile drag along the free stream, N (0 without polars): each
    /// strip's `cd qS` along its section-plane flow, projected. `drag − profile_drag` is the
    /// lattice's induced drag (the static strips': the drag of their lift along the free stream).
    pub profile_drag: f64,
    /// Hinge moment of each control surface (`aero.control_surfaces`, in order), N·m, trailing
    /// edge down positive: the lattice's loads (docs/uvlm.md §15); empty without surfaces.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Vec::is_empty"))]
    pub control_hinge_moments: Vec<f64>,
    /// Newton iterations spent on this point (its intermediate airspeeds included).
    pub newton_iterations: usize,
    /// Why the point has no equilibrium, if it has none.
    pub error: Option<String>,
    /// The load factor of a structural static case's point (`static.load_factors`; its
    /// airspeed is 0).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub load_factor: Option<f64>,
    /// Spanwise lift distribution.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub strips: Vec<Strip>,
    /// The equilibrium: coordinates and the multipliers of the holonomic and velocity
    /// constraints (for the linearisation about it).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub state: Option<(Vec<f64>, Vec<f64>, Vec<f64>)>,
}

/// A formulation's static sweep.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StaticOutput {
    /// Formulation.
    pub formulation: Formulation,
    /// One point per airspeed (or per sideslip angle of a sideslip sweep), in the case's order.
    pub points: Vec<StaticPoint>,
    /// Wall time of the sweep, s.
    pub wall_s: f64,
    /// Steady lattice solves (residuals and difference quotients).
    pub n_aero_solves: usize,
    /// Evaluations of the aerodynamic stiffness.
    pub n_tangents: usize,
    /// Tangent dimension of the structure.
    pub n_dof: usize,
    /// Why the sweep could not start, if it could not.
    pub error: Option<String>,
}

/// The static equilibrium of `case` at its own airspeed with the steady wake `wake`: the point
/// with its state.
///
/// # Errors
/// A case without `aero`, a failed sweep, or no equilibrium.
pub fn equilibrium_at(
    case: &Problem,
    f: Formulation,
    wake: crate::stability_settings::WakeSettings,
) -> Result<StaticPoint, String> {
    let aero = case.aero.as_ref().ok_or("the case has no `aero` block")?;
    let mut c = case.clone();
    c.statics = Some(crate::problem::StaticSettings::at(vec![aero.speed()], Some(wake)));
    // Stability and gust linearise about the lattice's equilibrium whatever `aero.model` says
    // (the static strips are the statics' diagnostic).
    if let Some(a) = c.aero.as_mut() {
        a.model = AeroModel::Uvlm;
    }
    let out = run_static(&c, f);
    if let Some(e) = out.error {
        return Err(e);
    }
    let p = out.points.into_iter().next().ok_or("no point")?;
    match (&p.error, &p.state) {
        (Some(e), _) => Err(e.clone()),
        (None, None) => Err("no state".into()),
        (None, Some(_)) => Ok(p),
    }
}

/// Run the static sweep of `case` (its `static.airspeeds`, or for a structural case its
/// `static.load_factors`) with formulation `f`.
pub fn run_static(case: &Problem, f: Formulation) -> StaticOutput {
    let t0 = Instant::now();
    struct Sweep<'a>(&'a Problem, Formulation);
    impl ForModel for Sweep<'_> {
        type Output = StaticOutput;
        fn run<M: BuildModel>(self) -> StaticOutput {
            sweep(self.0, self.1, M::build)
        }
    }
    let mut out = dispatch(f, Sweep(case, f));
    out.wall_s = t0.elapsed().as_secs_f64();
    out
}

fn failed_output(case: &Problem, f: Formulation, msg: String) -> StaticOutput {
    let beta = case.aero.as_ref().map_or(0.0, |a| a.sideslip_deg);
    let at = case.statics.as_ref().map(|s| s.points(beta)).unwrap_or_default();
    StaticOutput {
        formulation: f,
        points: at.iter().map(|&(u, b)| StaticPoint { sideslip_deg: b, ..failed_point(u, msg.clone()) }).collect(),
        wall_s: 0.0,
        n_aero_solves: 0,
        n_tangents: 0,
        n_dof: 0,
        error: Some(msg),
    }
}

fn failed_point(airspeed: f64, msg: String) -> StaticPoint {
    StaticPoint {
        airspeed,
        sideslip_deg: 0.0,
        fold_deg: f64::NAN,
        tip: [f64::NAN; 3],
        loads: WingLoads {
            root_force: [f64::NAN; 3],
            root_moment: [f64::NAN; 3],
            root_bending_moment: f64::NAN,
            root_torque: f64::NAN,
            hinge_moment: f64::NAN,
        },
        lift: f64::NAN,
        drag: f64::NAN,
        profile_drag: f64::NAN,
        control_hinge_moments: Vec::new(),
        newton_iterations: 0,
        error: Some(msg),
        load_factor: None,
        strips: Vec::new(),
        state: None,
    }
}

/// Newton settings of the static points: the generic defaults, with room for the linear
/// convergence of a kept aerodynamic stiffness.
pub(crate) fn static_params() -> StaticParams {
    StaticParams { max_iter: ROUND_ITERATIONS, tol: 1e-10, rel_residual_tol: 1e-10 }
}

/// Newton iterations per round of a static solve (one aerodynamic stiffness each): a kept
/// stiffness converges linearly but costs nothing, a fresh one costs a lattice solve per unknown.
const ROUND_ITERATIONS: usize = 25;
/// Rounds per static solve.
const ROUNDS: usize = 8;

/// Largest load step of a structural static case, as a fraction of the full load.
const MAX_LOAD_STEP: f64 = 0.05;

/// A structural static case (no `aero`): the dead point loads `static.point_loads` at each of
/// `static.load_factors`, each equilibrium reached from the previous one by equal load steps of
/// at most [`MAX_LOAD_STEP`]. A point that fails ends the sweep (the later ones are reported as
/// not reached).
fn structural_sweep<S: Structure>(
    case: &Problem,
    f: Formulation,
    build: fn(&Problem) -> Result<S, Error>,
) -> StaticOutput {
    let Some(st) = case.statics.as_ref() else {
        return failed_output(case, f, "the case has no `static` block".into());
    };
    let mut model = match build(case) {
        Ok(m) => m,
        Err(e) => return failed_output(case, f, e.to_string()),
    };
    let mut loads = Vec::with_capacity(st.point_loads.len());
    for (k, l) in st.point_loads.iter().enumerate() {
        let Some(body) = case.body_index(&l.body) else {
            return failed_output(case, f, format!("static.point_loads[{k}].body: no body `{}`", l.body));
        };
        let s = l.at.unwrap_or(case.bodies[body].length);
        loads.push(SectionLoad { body, s, force: Vector3::from(l.force), moment: Vector3::from(l.moment) });
    }
    let q_ref = model.initial_state().q;
    let n_dof = model.n_dof();
    let mut solver = StaticSolver::new(&model, StaticParams { max_iter: 30, tol: 1e-10, rel_residual_tol: 1e-12 });
    let mut x = StaticSolution::guess(&model, &q_ref);
    let mut scaled = loads.clone();
    let (mut lambda, mut failed) = (0.0_f64, None::<String>);
    let mut points = Vec::with_capacity(st.load_factors.len());
    for &target in &st.load_factors {
        let fail = |msg: String| StaticPoint { airspeed: 0.0, load_factor: Some(target), ..failed_point(0.0, msg) };
        if let Some(e) = &failed {
            points.push(fail(format!("not reached: {e}")));
            continue;
        }
        let n_steps = ((target - lambda) / MAX_LOAD_STEP).ceil().max(1.0) as usize;
        let it0 = x.n_iterations;
        for k in 1..=n_steps {
            let l = lambda + (target - lambda) * k as f64 / n_steps as f64;
            for (a, b) in scaled.iter_mut().zip(&loads) {
                a.force = l * b.force;
                a.moment = l * b.moment;
            }
            if let Err(e) = model.set_section_loads(&scaled) {
                failed = Some(format!("static.point_loads at load factor {l:.6}: {e}"));
                break;
            }
            let m = &model;
            if let Err(e) = solver.solve_normalised(m, 0.0, &mut x, |q| m.normalise(q)) {
                failed = Some(format!("no equilibrium at load factor {l:.6}: {e}"));
                break;
            }
        }
        match &failed {
            Some(e) => points.push(fail(e.clone())),
            None => {
                lambda = target;
                let fold = case.fold_joint_index().map_or(f64::NAN, |j| model.fold(&x.q, j).to_degrees());
                points.push(StaticPoint {
                    airspeed: 0.0,
                    fold_deg: fold,
                    tip: model.tip(&x.q),
                    newton_iterations: x.n_iterations - it0,
                    error: None,
                    load_factor: Some(target),
                    ..failed_point(0.0, String::new())
                });
            }
        }
    }
    StaticOutput { formulation: f, points, wall_s: 0.0, n_aero_solves: 0, n_tangents: 0, n_dof, error: None }
}

fn sweep<S: Structure>(case: &Problem, f: Formulation, build: fn(&Problem) -> Result<S, Error>) -> StaticOutput {
    if case.aero.is_none() && case.statics.as_ref().is_some_and(|s| !s.point_loads.is_empty()) {
        return structural_sweep(case, f, build);
    }
    let Some((aero, st)) = case.aero.as_ref().zip(case.statics.as_ref()) else {
        return failed_output(case, f, "the case has no `aero` and `static` blocks".into());
    };
    let map = match station_map(case, aero) {
        Ok(m) => m,
        Err(e) => return failed_output(case, f, e),
    };
    let model = match build(case) {
        Ok(m) => m,
        Err(e) => return failed_output(case, f, e.to_string()),
    };
    let q_ref = model.initial_state().q;
    let n_dof = model.n_dof();
    let at = st.points(aero.sideslip_deg);
    let (order, restart) = walk_order(st, &at);
    let axis = if st.is_sideslip_sweep() { Axis::Sideslip } else { Axis::Airspeed };
    let (top, beta0) = at[order[0]];
    let mut a0 = aero.clone();
    a0.airspeed = Some(top);
    a0.sideslip_deg = beta0;
    let wake = st.wake.as_ref().map_or(uvlm::SteadyWake::SemiInfinite, |w| w.steady_wake());
    let mut sys = match AeroStatic::new(model, &q_ref, &map, &a0, wake, case.span()) {
        Ok(s) => s,
        Err(e) => return failed_output(case, f, e),
    };
    let polars = match StripPolars::of(case) {
        Ok(p) => p,
        Err(e) => return failed_output(case, f, e),
    };
    if aero.model == AeroModel::Strip {
        // The strips read the polars themselves; the lattice's correction stays off.
        match StripStatics::new(&map, aero, polars) {
            Ok(s) => sys.set_strips(Some(s)),
            Err(e) => return failed_output(case, f, e),
        }
    } else {
        sys.set_polars(polars);
    }
    sys.set_difference_tangent(st.difference_tangent);
    let mut solver = StaticSolver::new(&sys, static_params());
    let mut x = StaticSolution::guess(&sys, &q_ref);
    let loads_model = LoadModel::new(case, f);
    let mut points: Vec<Option<StaticPoint>> = vec![None; at.len()];
    // 1. The first equilibrium (the highest airspeed, or the sideslip nearest zero), by load
    // stepping.
    sys.hold_reynolds_at(Some(top));
    let stepped = load_stepping(case, build, top, &mut sys, &mut solver, &mut x);
    sys.hold_reynolds_at(None);
    if let Err(e) = stepped {
        return failed_output(case, f, e);
    }
    let first = x.clone();
    let mut iters = x.n_iterations;
    // 2. Along the walk, bisecting a step that fails; a sideslip sweep walks its second branch
    // from the first equilibrium again.
    let mut current = axis.value(at[order[0]]);
    for (k, &i) in order.iter().enumerate() {
        if Some(k) == restart {
            x = first.clone();
            iters = x.n_iterations;
            current = axis.value(at[order[0]]);
            if let Err(e) = axis.set(&mut sys, current, &x.q) {
                return failed_output(case, f, e);
            }
            sys.forget_tangent();
        }
        let target = axis.value(at[i]);
        let good = x.clone();
        let last_err = bisect_to(axis, target, &mut current, &mut sys, &mut solver, &mut x);
        let n_it = x.n_iterations - iters;
        iters = x.n_iterations;
        points[i] = Some(match last_err {
            Some(e) => {
                x = good;
                let p = failed_point(at[i].0, format!("no equilibrium at {}: {e}", axis.describe(target)));
                StaticPoint { sideslip_deg: at[i].1, ..p }
            }
            None => {
                let mut p = point_at(&sys, &x.q, case, loads_model.as_ref(), &map, aero.rho);
                p.newton_iterations = n_it;
                p.state = Some((x.q.clone(), x.lambda.clone(), x.mu.clone()));
                p
            }
        });
    }
    let (n_aero_solves, n_tangents) = sys.counters();
    StaticOutput {
        formulation: f,
        points: points
            .into_iter()
            .zip(&at)
            .map(|(p, &(u, b))| {
                p.unwrap_or_else(|| StaticPoint { sideslip_deg: b, ..failed_point(u, "not reached".into()) })
            })
            .collect(),
        wall_s: 0.0,
        n_aero_solves,
        n_tangents,
        n_dof,
        error: None,
    }
}

/// The parameter a static sweep walks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Axis {
    /// The airspeed, m/s.
    Airspeed,
    /// The sideslip angle, degrees.
    Sideslip,
}

impl Axis {
    /// The walked value of a point `(airspeed, sideslip)`.
    fn value(self, at: (f64, f64)) -> f64 {
        match self {
            Axis::Airspeed => at.0,
            Axis::Sideslip => at.1,
        }
    }

    /// Move the system to `value` (the lattice rebuilt at `q`).
    fn set<S: Structure>(self, sys: &mut AeroStatic<'_, S>, value: f64, q: &[f64]) -> Result<(), String> {
        match self {
            Axis::Airspeed => sys.set_airspeed(value, q),
            Axis::Sideslip => sys.set_sideslip(value, q),
        }
    }

    /// `12 m/s` or `sideslip 4°`, for messages.
    fn describe(self, value: f64) -> String {
        match self {
            Axis::Airspeed => format!("{value} m/s"),
            Axis::Sideslip => format!("sideslip {value}°"),
        }
    }
}

/// The order in which a sweep visits its points `at` (indices), and the position in that order
/// where the walk restarts from the first equilibrium. An airspeed sweep walks down from the
/// highest airspeed. A sideslip sweep starts at the angle nearest zero (the least deformed
/// state), walks up through the larger angles, then restarts there and walks down through the
/// smaller ones, so that each branch follows its equilibrium continuously.
fn walk_order(st: &crate::problem::StaticSettings, at: &[(f64, f64)]) -> (Vec<usize>, Option<usize>) {
    let mut order: Vec<usize> = (0..at.len()).collect();
    if !st.is_sideslip_sweep() {
        order.sort_by(|&a, &b| at[b].0.total_cmp(&at[a].0));
        return (order, None);
    }
    let start = (0..at.len()).min_by(|&a, &b| at[a].1.abs().total_cmp(&at[b].1.abs())).unwrap_or(0);
    let b0 = at[start].1;
    let mut up: Vec<usize> = order.iter().copied().filter(|&i| i != start && at[i].1 >= b0).collect();
    up.sort_by(|&a, &b| at[a].1.total_cmp(&at[b].1));
    let mut down: Vec<usize> = order.iter().copied().filter(|&i| i != start && at[i].1 < b0).collect();
    down.sort_by(|&a, &b| at[b].1.total_cmp(&at[a].1));
    order = std::iter::once(start).chain(up.iter().copied()).collect();
    let restart = (!down.is_empty()).then_some(order.len());
    order.extend(down);
    (order, restart)
}

/// Newton on the aeroelastic system from `x`, in rounds of up to [`ROUND_ITERATIONS`]
/// iterations: the aerodynamic stiffness (the costly part of the tangent) is kept within a round
/// and from the previous point, and re-evaluated at the start of every further round.
pub(crate) fn solve_rounds<S: Structure>(
    sys: &mut AeroStatic<'_, S>,
    solver: &mut StaticSolver,
    x: &mut StaticSolution,
) -> Result<(), String> {
    let mut last = String::new();
    let x0 = x.clone();
    for round in 0..ROUNDS {
        sys.begin_solve(round > 0);
        let s: &AeroStatic<'_, S> = sys;
        // Borrowed only for the call: the system borrows the model mutably to apply its loads.
        match solver.solve_normalised(s, 0.0, x, |q| read(&s.model).normalise(q)) {
            // The residual at the converged state is evaluated once more; the lattice
            // must still be valid there.
            Ok(()) if !x.residual_norm.is_finite() => {
                return Err(sys.error().unwrap_or_else(|| "non-finite residual at the equilibrium".into()));
            }
            Ok(()) => return polish(sys, solver, x),
            Err(e @ genalpha::Error::StaticNotConverged { .. }) => last = e.to_string(),
            // A kept aerodynamic stiffness can send the first iterate past the lattice's
            // limits: start again from the same estimate with a fresh one.
            Err(e) if round == 0 => {
                last = sys.error().map_or_else(|| e.to_string(), |a| format!("{e} ({a})"));
                *x = x0.clone();
            }
            Err(e) => return Err(sys.error().map_or_else(|| e.to_string(), |a| format!("{e} ({a})"))),
        }
    }
    Err(format!("{last} ({ROUNDS} rounds of {ROUND_ITERATIONS} iterations)"))
}

/// Newton iterations of [`polish`] at most.
const POLISH_ITERATIONS: usize = 10;
/// The increment [`polish`] iterates down to (m in the increment weights): a few hundred ulp of
/// a structure of metres, a thousandth of [`static_params`]' `tol`.
const POLISH_TOL: f64 = 1e-13;

/// Iterate an equilibrium `x` that [`solve_rounds`] accepted (increment below `tol` = 1e-10 m)
/// on, with the aerodynamic stiffness it ended with, down to [`POLISH_TOL`], so that the last
/// iterate is the equilibrium to rounding rather than within `tol` of it along a path that
/// depends on the tangent. The equilibrium's derived quantities need it: the flutter equation's
/// geometric terms are central differences about it (a step of 1e-6, which turns 1e-11 of the
/// state into 1e-5 of a root), and a polar that reproduces the lattice must give the lattice's
/// equilibrium and roots to rounding although its tangent differs by its own differences. Where
/// the increment stalls at round-off above [`POLISH_TOL`], the better of the two iterates (by
/// the residual) is kept and finished once more with the usual settings.
fn polish<S: Structure>(
    sys: &mut AeroStatic<'_, S>,
    solver: &mut StaticSolver,
    x: &mut StaticSolution,
) -> Result<(), String> {
    let coarse = *solver.params();
    let mut y = x.clone();
    solver.set_params(StaticParams { max_iter: POLISH_ITERATIONS, tol: POLISH_TOL, rel_residual_tol: 0.0 });
    sys.begin_solve(false);
    let s: &AeroStatic<'_, S> = sys;
    let fine = solver.solve_normalised(s, 0.0, &mut y, |q| read(&s.model).normalise(q));
    solver.set_params(coarse);
    if fine.is_ok() && y.residual_norm.is_finite() {
        *x = y;
        return Ok(());
    }
    if y.residual_norm.is_finite() && y.residual_norm < x.residual_norm {
        *x = y;
    }
    sys.begin_solve(false);
    let s: &AeroStatic<'_, S> = sys;
    match solver.solve_normalised(s, 0.0, x, |q| read(&s.model).normalise(q)) {
        Ok(()) if x.residual_norm.is_finite() => Ok(()),
        Ok(()) => Err(sys.error().unwrap_or_else(|| "non-finite residual at the equilibrium".into())),
        Err(e) => Err(sys.error().map_or_else(|| e.to_string(), |a| format!("{e} ({a})"))),
    }
}

/// The first equilibrium, at airspeed `top`, by load stepping from the unloaded reference:
/// gravity λ g and dynamic pressure λ q (the airspeed √λ V), so that the ratio of weight to air
/// load, which sets the fold, is the final one at every step while the elastic deflection grows
/// from zero. A step that fails is halved. (Newton straight to the full load can land on a
/// spurious state of a folded-over lattice on a flexible wing.)
pub(crate) fn load_stepping<S: Structure>(
    case: &Problem,
    build: fn(&Problem) -> Result<S, Error>,
    top: f64,
    sys: &mut AeroStatic<'_, S>,
    solver: &mut StaticSolver,
    x: &mut StaticSolution,
) -> Result<(), String> {
    let g = case.gravity.unwrap_or([0.0; 3]);
    let (mut lambda, mut step) = (0.0_f64, 0.25_f64);
    let mut good = x.clone();
    while lambda < 1.0 {
        let next = (lambda + step).min(1.0);
        let mut c = case.clone();
        c.gravity = case.gravity.map(|_| [next * g[0], next * g[1], next * g[2]]);
        sys.set_model(build(&c).map_err(|e| e.to_string())?);
        let attempt = sys.set_airspeed(top * next.sqrt(), &x.q).and_then(|()| solve_rounds(sys, solver, x));
        match attempt {
            Ok(()) => {
                lambda = next;
                good = x.clone();
                step = (1.5 * step).min(0.25);
            }
            Err(e) => {
                *x = good.clone();
                step *= 0.5;
                if step < 1e-3 {
                    return Err(format!("at {top} m/s: load stepping stalled at {lambda:.4} of the load: {e}"));
                }
            }
        }
    }
    Ok(())
}

/// From the equilibrium `x` at the value `current` of `axis` (airspeed or sideslip) to the one
/// at `target`, restarting from the last equilibrium towards the midpoint of a step that fails,
/// at most 6 times; the last error when it does not get there (`x` and the system's value are
/// then the last equilibrium's).
fn bisect_to<S: Structure>(
    axis: Axis,
    target: f64,
    current: &mut f64,
    sys: &mut AeroStatic<'_, S>,
    solver: &mut StaticSolver,
    x: &mut StaticSolution,
) -> Option<String> {
    let good = x.clone();
    let mut path = vec![target];
    let mut halvings = 0;
    while let Some(&u) = path.last() {
        let attempt = axis.set(sys, u, &x.q).and_then(|()| solve_rounds(sys, solver, x));
        match attempt {
            Ok(()) => {
                *current = u;
                path.pop();
            }
            Err(e) => {
                *x = good.clone();
                let _ = axis.set(sys, *current, &x.q);
                if halvings >= 6 {
                    return Some(e);
                }
                halvings += 1;
                // Restart from the last equilibrium towards the midpoint.
                path.push(0.5 * (*current + u));
            }
        }
    }
    None
}

/// The outputs at the equilibrium `q` of `sys`.
pub(crate) fn point_at<S: Structure>(
    sys: &AeroStatic<'_, S>,
    q: &[f64],
    case: &Problem,
    loads_model: Option<&LoadModel>,
    map: &[StationMap],
    rho: f64,
) -> StaticPoint {
    let airspeed = sys.airspeed();
    let (station_loads, uv_loads, stations) = match sys.evaluate_at(q) {
        Ok(v) => v,
        Err(e) => return failed_point(airspeed, e),
    };
    let control_hinge_moments = match sys.control_hinge_moments(map) {
        Ok(v) => v,
        Err(e) => return failed_point(airspeed, e),
    };
    let model = sys.model();
    let fold = case.fold_joint_index().map_or(f64::NAN, |j| model.fold(q, j).to_degrees());
    let loads = loads_model.map_or(
        WingLoads {
            root_force: [f64::NAN; 3],
            root_moment: [f64::NAN; 3],
            root_bending_moment: f64::NAN,
            root_torque: f64::NAN,
            hinge_moment: f64::NAN,
        },
        |lm| lm.evaluate(&*model, q, None, &station_loads, &mut LoadScratch::default()),
    );
    let v_inf = sys.aero.free_stream();
    let lift_dir = lift_direction(v_inf);
    let report = sys.strip_report();
    let qdyn = 0.5 * rho * airspeed * airspeed;
    // The static strips have no lattice: their report holds each strip's whole force.
    let (total, strips) = if sys.has_strips() {
        (report.total_delta, crate::strip_statics::strip_rows(map, &stations, &report, lift_dir, qdyn))
    } else {
        let total = Vector3::from(uv_loads.total_force()) + report.total_delta;
        (total, strips_of(map, &stations, &uv_loads, &report, lift_dir, qdyn))
    };
    let lift = total.dot(&lift_dir);
    let stream = Vector3::from(v_inf).normalize();
    let drag = total.dot(&stream);
    let profile_drag = report.profile_drag.dot(&stream);
    StaticPoint {
        airspeed,
        sideslip_deg: sys.sideslip_deg(),
        fold_deg: fold,
        tip: model.tip(q),
        loads,
        lift,
        drag,
        profile_drag,
        control_hinge_moments,
        newton_iterations: 0,
        error: None,
        load_factor: None,
        strips,
        state: None,
    }
}
/// The strips (lattice columns) of the lattice solution `loads` on `stations` (driven as `map`
/// says), their forces changed by the section polars' correction `report` (empty: none): lift
/// per unit span along `lift_dir`, its coefficient at the dynamic pressure `qdyn` (Pa) on the
/// planform's chord, and the effective incidence. Shared by the statics and the time march.
pub(crate) fn strips_of(
    map: &[StationMap],
    stations: &[uvlm::SpanStation],
    loads: &uvlm::Loads,
    report: &StripReport,
    lift_dir: Vector3<f64>,
    qdyn: f64,
) -> Vec<Strip> {
    // Column j of the lattice lies between stations j and j + 1.
    let arc = |m: &StationMap| m.arc;
    // The planform's chord at the station (along the stream for streamwise sections, also at a
    // hinge column, whose slant is the flare's).
    let chord = |m: &StationMap| m.planform_chord;
    // The lattice's strips run surface after surface, one fewer than the surface's stations.
    (0..stations.len().saturating_sub(1))
        .filter(|&j| map[j].lifting == map[j + 1].lifting)
        .filter_map(|j| {
            let i = j - map[j].lifting;
            let f = Vector3::from(*loads.strip.get(i)?) + report.delta_force.get(j).copied().unwrap_or_default();
            let (a, b) = (stations[j].origin, stations[j + 1].origin);
            let width = (b - a).norm();
            let l = f.dot(&lift_dir) / width;
            let mid = 0.5 * (a + b);
            Some(Strip {
                s: 0.5 * (arc(&map[j]) + arc(&map[j + 1])),
                position: mid.into(),
                lift_per_span: l,
                cl: l / (qdyn * 0.5 * (chord(&map[j]) + chord(&map[j + 1]))),
                alpha: report.alpha.get(j).copied().unwrap_or(f64::NAN),
            })
        })
        .collect()
}

/// Unit lift direction: perpendicular to the free stream and to the global X axis (the span).
pub fn lift_direction(v_inf: [f64; 3]) -> Vector3<f64> {
    let v = Vector3::from(v_inf).normalize();
    let span = Vector3::x() - v * v.x;
    v.cross(&span).normalize()
}

// `AeroStatic` is a `ConstrainedSystem` (methods on `&self`) whose residual sets loads on the
// model and solves the lattice: its state sits behind locks, so it is `Send + Sync` like the
// models. The model behind a read-write lock (never taken twice by one thread: std's may deadlock), the rest behind mutexes; a lock
// is poisoned only by a panic elsewhere, after which the state is rewritten before it is read.
fn read<T>(l: &RwLock<T>) -> RwLockReadGuard<'_, T> {
    l.read().unwrap_or_else(PoisonError::into_inner)
}
fn write<T>(l: &RwLock<T>) -> RwLockWriteGuard<'_, T> {
    l.write().unwrap_or_else(PoisonError::into_inner)
}
fn lock<T>(l: &Mutex<T>) -> MutexGuard<'_, T> {
    l.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The analytic aerodynamic stiffness (docs/statics.md §2) at the first equilibrium of `case`'s
/// sweep, checked against central differences of the generalised aerodynamic load (each side a
/// steady solve, with the section polars' correction when the case has them): for every step of
/// `steps` (a fraction of the span, in the increment weights) the largest difference over the
/// largest entry.
///
/// # Errors
/// A case without an equilibrium at its first airspeed, or a failed lattice solve.
pub fn aero_stiffness_check(case: &Problem, f: Formulation, steps: &[f64]) -> Result<Vec<f64>, String> {
    let out = run_static(case, f);
    if let Some(e) = out.error {
        return Err(e);
    }
    let p = out.points.first().ok_or("no point")?;
    let (q, _, _) = p.state.clone().ok_or_else(|| p.error.clone().unwrap_or_default())?;
    struct Check<'a>(&'a Problem, f64, Vec<f64>, &'a [f64]);
    impl ForModel for Check<'_> {
        type Output = Result<Vec<f64>, String>;
        fn run<M: BuildModel>(self) -> Self::Output {
            stiffness_check(self.0, M::build, self.1, &self.2, self.3)
        }
    }
    dispatch(f, Check(case, p.airspeed, q, steps))
}

/// [`aero_stiffness_check`] of the model `build` makes, at airspeed `u` and coordinates `q`.
fn stiffness_check<S: Structure>(
    case: &Problem,
    build: fn(&Problem) -> Result<S, Error>,
    u: f64,
    q: &[f64],
    steps: &[f64],
) -> Result<Vec<f64>, String> {
    let (aero, st) = case.aero.as_ref().zip(case.statics.as_ref()).ok_or("no `aero` and `static` blocks")?;
    let map = station_map(case, aero)?;
    let model = build(case).map_err(|e| e.to_string())?;
    let mut a0 = aero.clone();
    a0.airspeed = Some(u);
    let wake = st.wake.as_ref().map_or(uvlm::SteadyWake::SemiInfinite, |w| w.steady_wake());
    let mut sys = AeroStatic::new(model, q, &map, &a0, wake, case.span())?;
    sys.set_polars(StripPolars::of(case)?);
    let n = sys.n_dof();
    if !sys.apply_loads(q) {
        return Err(sys.error().unwrap_or_default());
    }
    sys.update_tangent(0.0, q);
    let k = lock(&sys.tangent).k.clone();
    let zeros = vec![0.0; n];
    let (mut scratch, mut rp, mut rm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut dq = vec![0.0; n];
    let mut qs = q.to_vec();
    let mut loads = sys.zero_loads.clone();
    let mut worst = Vec::new();
    for &step in steps {
        let (mut diff, mut big) = (0.0f64, 0.0f64);
        for j in 0..n {
            let h = step * case.span() / sys.model().increment_weight(j).max(1e-12);
            for (r, sign) in [(&mut rp, 1.0), (&mut rm, -1.0)] {
                dq.fill(0.0);
                dq[j] = sign * h;
                sys.model().retract_inplace(q, &dq, &mut qs);
                if !sys.station_loads(&qs, &mut loads) {
                    return Err(sys.error().unwrap_or_default());
                }
                sys.load_part(0.0, &qs, &loads, &zeros, &mut scratch, r);
            }
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                diff = diff.max((k[i * n + j] - fd).abs());
                big = big.max(fd.abs());
            }
        }
        worst.push(diff / big);
    }
    Ok(worst)
}
