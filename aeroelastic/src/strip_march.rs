//! Quasi-steady strip theory in the time march (`aero.model: "strip"`, docs/coupling.md §9): each
//! span station of the lifting surfaces carries the lift of a two-dimensional thin aerofoil at
//! the incidence its own motion and the free stream give, with no wake and no induction. It is
//! the classic reference of roll and flight-mechanics estimates (the roll rig's steady rate
//! `p = (3/2)(V/s) τ (η₂² − η₁²) δ` and time constant `3 I / (ρ V c a s³)` are its results) and the
//! cheap model to set against the lattice.
//!
//! At each strip (pose `R = [x y z]`, axis point `p`, velocity `v`, angular velocity `ω`):
//! * the air's velocity relative to the three-quarter-chord point `r₃ = p + y (e − ¾c)` (`e` the
//!   leading-edge offset, `c` the chord along `y`): `u = V∞ − v − ω × (r₃ − p)`, and its part in
//!   the section plane `u⊥ = u − x (x·u)`;
//! * the incidence `α = atan2(u·z, −u·y)`, and with a control surface of chord fraction `E`
//!   deflected by `δ` (trailing edge down positive) the thin-aerofoil flap effectiveness
//!   `τ = 1 − (θ − sin θ)/π`, `cos θ = 2E − 1`;
//! * the lift per span `l = ½ ρ |u⊥|² c a (α + τ δ)` (lift slope `a`, `aero.strip_lift_slope`),
//!   along `u⊥ × x / |u⊥|`, at the quarter chord `r₁ = p + y (e − ¼c)`;
//! * per strip, the column between two neighbouring stations of a surface: at its middle (the
//!   mean of the two stations' points, velocities and angular velocities, the frame `x` along the
//!   column and `y` the stations' mean made normal to it), over its width, flapped when both its
//!   stations carry the control surface, and lumped half to each station (force, and its moment
//!   about the station's axis point).
//!
//! With section polars (`aero.polars`) a strip's thin-aerofoil lift goes through the lattice's
//! strip correction ([`StripPolars::correct_one`]) with the strip's own lift line: the polar's
//! `cl(α + τ δ, Re)` replaces it, its profile drag `cd q c w` acts along `u⊥` and its moment
//! `cm q c² w` about the span, quasi-steadily on the three-quarter-chord incidence
//! (docs/section_aero.md §7.6). With `aero.polars[i].dynamic_stall` the strips of those bodies
//! carry the dynamic-stall model's states ([`aerofoil::DynamicStall`]; docs/section_aero.md §8),
//! started at their steady state at the first evaluation and advanced from one evaluation to the
//! next with the strip's incidence, pitch rate, speed and Reynolds number varying linearly over
//! the interval; its `cl`, `cd`, `cm` replace the static polar's.
//!
//! The loads of a step are those of the state at its start (a loosely coupled march, as the
//! lattice's); their power `Σ F·v + M·ω` is integrated into the aerodynamic work with the
//! trapezoidal rule, so the energy balance `E + W_damp − W_aero` holds as with the lattice.

use std::time::Instant;

use nalgebra::{Matrix3, Vector3};

use formulation::{SectionLoad, Structure};
use genalpha::State;

use crate::aero::{AeroSettings, SectionKinematics as Kinematics, StationMap, station_states};
use crate::polar_correction::{StripGeometry, StripPolars};
use crate::problem::Formulation;
use crate::run::{Dissipation, Observer, RunOutput, RunSettings, SnapshotFeed, row};

/// The lift of every strip (the column between two neighbouring stations of a surface) at a
/// state, lumped to the two stations.
pub struct StripAero<'a> {
    map: &'a [StationMap],
    aero: &'a AeroSettings,
    /// The section polars that replace the strips' thin-aerofoil lift (none: `a (α + τ δ)`).
    polars: Option<&'a StripPolars>,
    /// The columns: their first station (the second is the next one).
    columns: Vec<usize>,
    /// Each station's pose and velocity: axis point, frame, velocity, angular velocity.
    kin: Vec<Kinematics>,
    loads: Vec<SectionLoad>,
    /// Each column's last loads (in the order of `columns`).
    last: Vec<ColumnLoad>,
    /// Each column's dynamic-stall model and state (in the order of `columns`; `None` before
    /// its first evaluation and on bodies without the model).
    stall: Vec<Option<StallSlot>>,
    scratch: crate::aero::StationScratch,
}

/// One column's loads at a state.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ColumnLoad {
    /// Force, N (global).
    force: Vector3<f64>,
    /// Moment about `at` (the polar's `cm`; zero without a polar), N·m.
    moment: Vector3<f64>,
    /// The point of action: the quarter chord at the column's middle.
    at: Vector3<f64>,
    /// The incidence the polar was read at, `α + τ δ`, rad (NaN without a polar).
    alpha: f64,
}

/// A column's dynamic-stall model and its state at time `t`.
#[derive(Debug, Clone, Copy)]
struct StallSlot {
    model: aerofoil::DynamicStall,
    state: aerofoil::DynamicStallState,
    /// Time of `state`, s.
    t: f64,
}

/// What the dynamic-stall model of a column needs from its quasi-steady evaluation.
#[derive(Debug, Clone, Copy)]
struct StallInput {
    body: usize,
    flow: aerofoil::SectionFlow,
    /// The static polar's coefficients already applied.
    coefficients: aerofoil::Coefficients,
    /// `q c w`, N.
    qcw: f64,
    /// Lift, drag and span directions (global, unit).
    lift: Vector3<f64>,
    drag: Vector3<f64>,
    span: Vector3<f64>,
}

/// Thin-aerofoil flap effectiveness `dα/dδ` of a trailing-edge flap of chord fraction `e`.
pub fn flap_effectiveness(e: f64) -> f64 {
    let theta = (2.0 * e - 1.0).clamp(-1.0, 1.0).acos();
    1.0 - (theta - theta.sin()) / std::f64::consts::PI
}

impl<'a> StripAero<'a> {
    /// The strips of the stations `map` (the aerodynamic settings `aero`), their lift read from
    /// the section polars `polars` where a body has one (docs/section_aero.md §7.6).
    pub fn new(map: &'a [StationMap], aero: &'a AeroSettings, polars: Option<&'a StripPolars>) -> Self {
        let columns: Vec<usize> =
            crate::lifting::surface_ranges(map).into_iter().flat_map(|r| r.start..r.end.saturating_sub(1)).collect();
        let loads = map
            .iter()
            .map(|m| SectionLoad { body: m.body, s: m.s, force: Vector3::zeros(), moment: Vector3::zeros() })
            .collect();
        let kin = vec![(Vector3::zeros(), Matrix3::identity(), Vector3::zeros(), Vector3::zeros()); map.len()];
        let none =
            ColumnLoad { force: Vector3::zeros(), moment: Vector3::zeros(), at: Vector3::zeros(), alpha: f64::NAN };
        let last = vec![none; columns.len()];
        let stall = vec![None; columns.len()];
        Self { map, aero, polars, columns, kin, loads, last, stall, scratch: crate::aero::StationScratch::default() }
    }

    /// The station loads at time `t` and state `(q, v)`, replacing the loads held so far; and the
    /// power `Σ F·v + M·ω` at this state of the loads held so far and of the new ones, W.
    ///
    /// # Errors
    /// A polar's range error, naming the strip and its body.
    pub fn evaluate<S: Structure + ?Sized>(
        &mut self,
        model: &S,
        t: f64,
        q: &[f64],
        v: &[f64],
    ) -> Result<(&[SectionLoad], f64, f64), String> {
        let kin = &mut self.kin;
        station_states(model, q, v, self.map, &mut self.scratch, |i, k| kin[i] = k);
        let power_of = |loads: &[SectionLoad], kin: &[Kinematics]| -> f64 {
            loads.iter().zip(kin).map(|(l, k)| l.force.dot(&k.2) + l.moment.dot(&k.3)).sum()
        };
        let held = power_of(&self.loads, &self.kin);
        for l in &mut self.loads {
            l.force = Vector3::zeros();
            l.moment = Vector3::zeros();
        }
        for (n, &j) in self.columns.iter().enumerate() {
            let (mut c, stall) = self.column_load(j, t)?;
            if let (Some(input), Some(polars)) = (stall, self.polars) {
                dynamic_stall(&mut self.stall[n], polars, t, &input, &mut c)
                    .map_err(|e| format!("dynamic stall of strip {j} (body {}): {e}", input.body))?;
            }
            for i in [j, j + 1] {
                let half = c.force * 0.5;
                self.loads[i].force += half;
                self.loads[i].moment += (c.at - self.kin[i].0).cross(&half) + 0.5 * c.moment;
            }
            self.last[n] = c;
        }
        let power = power_of(&self.loads, &self.kin);
        Ok((&self.loads, held, power))
    }

    /// The loads of column `j` (stations `j`, `j + 1`) at time `t`, acting at the quarter chord
    /// at the column's middle, quasi-steady; and, when its body's polar has the dynamic-stall
    /// model, that model's inputs.
    fn column_load(&self, j: usize, t: f64) -> Result<(ColumnLoad, Option<StallInput>), String> {
        let (a, b) = (&self.kin[j], &self.kin[j + 1]);
        let (ma, mb) = (&self.map[j], &self.map[j + 1]);
        let p = 0.5 * (a.0 + b.0);
        let (vel, omega) = (0.5 * (a.2 + b.2), 0.5 * (a.3 + b.3));
        // The column's frame: x along it, y the stations' mean y made normal to x.
        let x = (b.0 - a.0).try_normalize(1e-300).unwrap_or_else(|| a.1.column(0).into_owned());
        let y_mean = 0.5 * (a.1.column(1) + b.1.column(1));
        let y = (y_mean - x * x.dot(&y_mean)).normalize();
        let z = x.cross(&y);
        let (chord, le) = (0.5 * (ma.chord + mb.chord), 0.5 * (ma.le_offset + mb.le_offset));
        let arm3 = y * (le - 0.75 * chord);
        let r1 = p + y * (le - 0.25 * chord);
        let u = Vector3::from(self.aero.free_stream()) - vel - omega.cross(&arm3);
        let u_perp = u - x * x.dot(&u);
        let speed2 = u_perp.norm_squared();
        let alpha = u.dot(&z).atan2(-u.dot(&y));
        // A column is flapped when both its stations carry the same control surface.
        let flap = match (ma.control, mb.control) {
            (Some(i), Some(k)) if i == k => {
                let c = &self.aero.control_surfaces[i];
                flap_effectiveness(c.chord_fraction) * c.deflection_deg.at(t).0.to_radians()
            }
            _ => 0.0,
        };
        let mut out = ColumnLoad { force: Vector3::zeros(), moment: Vector3::zeros(), at: r1, alpha: f64::NAN };
        if speed2 == 0.0 {
            return Ok((out, None));
        }
        let width = (b.0 - a.0).norm();
        let lift = 0.5 * self.aero.rho * speed2 * chord * self.aero.strip_lift_slope * (alpha + flap) * width;
        out.force = u_perp.cross(&x) / speed2.sqrt() * lift;
        let Some((polars, polar)) = self.polars.and_then(|p| Some((p, p.polar_of(mb.body)?))) else {
            return Ok((out, None));
        };
        if width == 0.0 {
            // Two stations at one point: no strip (and no lift above).
            return Ok((out, None));
        }
        // The polar replaces the thin-aerofoil lift: the correction inverts the strip's own lift
        // line (slope `a`, no zero-lift incidence), so it reads the polar at `α + τ δ` exactly,
        // and adds the profile drag along `u⊥` and the moment `cm q c² w` about the span.
        let line = aerofoil::LatticeSection { lift_slope: self.aero.strip_lift_slope, zero_lift_alpha: 0.0 };
        let g = StripGeometry { frame: Matrix3::from_columns(&[x, y, z]), chord, width };
        let (df, dm, c) = polars
            .correct_one(polar, &line, &g, u, 1.0, out.force)
            .map_err(|e| format!("polar of strip {j} (body {}): {e}", mb.body))?;
        out.force += df;
        out.moment = dm;
        out.alpha = c.alpha;
        if polars.dynamic_stall_of(mb.body).is_none() {
            return Ok((out, None));
        }
        let speed = speed2.sqrt();
        let flow = aerofoil::SectionFlow {
            alpha: c.alpha,
            // Nose up is about +x (it turns y, towards the leading edge, to z).
            pitch_rate: omega.dot(&x),
            speed,
            chord,
            re: speed * chord / polars.kinematic_viscosity(),
        };
        let drag = u_perp / speed;
        let stall = StallInput {
            body: mb.body,
            flow,
            coefficients: c.coefficients,
            qcw: 0.5 * polars.rho() * speed2 * chord * width,
            lift: drag.cross(&x),
            drag,
            span: x,
        };
        Ok((out, Some(stall)))
    }

    /// The strips at the last evaluation with a section polar (empty without polars): lift per
    /// span along `lift_dir`, its coefficient at the dynamic pressure `qdyn` (Pa) on the
    /// planform's chord, and the incidence the polar was read at.
    fn strips(&self, lift_dir: &Vector3<f64>, qdyn: f64) -> Vec<crate::statics::Strip> {
        if self.polars.is_none() {
            return Vec::new();
        }
        self.columns
            .iter()
            .zip(&self.last)
            .map(|(&j, c)| {
                let (a, b) = (self.kin[j].0, self.kin[j + 1].0);
                let l = c.force.dot(lift_dir) / (b - a).norm();
                let chord = 0.5 * (self.map[j].planform_chord + self.map[j + 1].planform_chord);
                crate::statics::Strip {
                    s: 0.5 * (self.map[j].arc + self.map[j + 1].arc),
                    position: (0.5 * (a + b)).into(),
                    lift_per_span: l,
                    cl: l / (qdyn * chord),
                    alpha: c.alpha,
                }
            })
            .collect()
    }
}

/// Advance the dynamic-stall state of a column in `slot` to time `t` (started at its steady state
/// at the first call; a call at the time of the state changes its inputs only) and replace the
/// static coefficients in the column's loads `out` by the model's.
fn dynamic_stall(
    slot: &mut Option<StallSlot>,
    polars: &StripPolars,
    t: f64,
    input: &StallInput,
    out: &mut ColumnLoad,
) -> Result<(), aerofoil::AerofoilError> {
    let (Some(polar), Some(constants)) = (polars.polar_of(input.body), polars.dynamic_stall_of(input.body)) else {
        return Ok(());
    };
    let s = match slot {
        None => {
            let model = aerofoil::DynamicStall::new(polar, input.flow.re, *constants)?;
            let state = model.steady_state(polar, &input.flow)?;
            slot.insert(StallSlot { model, state, t })
        }
        Some(s) if t > s.t => {
            s.state = s.model.step(polar, &s.state, t - s.t, &input.flow)?;
            s.t = t;
            s
        }
        Some(s) => {
            s.state = s.model.jump(polar, &s.state, &input.flow)?;
            s
        }
    };
    let c = s.model.coefficients(polar, &s.state)?;
    let st = &input.coefficients;
    out.force += ((c.cl - st.cl) * input.lift + (c.cd - st.cd) * input.drag) * input.qcw;
    out.moment += (c.cm - st.cm) * input.qcw * input.flow.chord * input.span;
    Ok(())
}

/// Integrate `model` with strip aerodynamics `aero` on the stations `map` (see the module docs).
pub fn simulate_strip<S: Structure>(
    formulation: Formulation,
    model: &mut S,
    settings: &RunSettings,
    aero: &AeroSettings,
    map: &[StationMap],
    observer: &mut dyn Observer,
) -> RunOutput {
    let start = Instant::now();
    let mut out = RunOutput::failed(formulation, String::new());
    out.error = None;
    out.n_dof = model.n_dof();
    let dt = settings.params.dt;
    let n_steps = settings.n_steps();
    let every = settings.output_every();
    let mut ga = match model.integrator(settings.params) {
        Ok(g) => g,
        Err(e) => return finish(out, start, Some(e.to_string())),
    };
    let mut s: State = model.initial_state();
    let mut strips = StripAero::new(map, aero, settings.polars.as_ref());
    let lift_dir = crate::statics::lift_direction(aero.free_stream());
    let (mut power, mut lift) = match apply(&mut strips, model, &s, &lift_dir) {
        Ok((_, p, l)) => (p, l),
        Err(e) => return finish(out, start, Some(format!("loads at t = {}: {e}", s.t))),
    };
    if let Err(e) = ga.initialize(model, &mut s) {
        return finish(out, start, Some(format!("initial accelerations: {e}")));
    }
    model.start_march(s.t, &s.q, &s.v);
    let fold = (settings.fold_joint, settings.roll_joint);
    let mut feed = SnapshotFeed::new(observer);
    let mut dissipation = Dissipation::new(model, &s, false);
    let mut work = 0.0;
    let record = |d: &Dissipation, r: crate::run::Row, work: f64, lift: f64| {
        let mut r = d.record(r);
        r.aero_work = work;
        r.lift = lift;
        r
    };
    let r0 = record(&dissipation, row(model, fold, &s, 0), work, lift);
    out.rows.push(r0);
    if let Err(e) = feed.feed(model, &r0, &s.q, None) {
        return finish(out, start, Some(format!("output at t = {}: {e}", s.t)));
    }
    for k in 1..=n_steps {
        if crate::interrupt::interrupted() {
            out.error = Some(crate::run::interrupted_message(s.t));
            break;
        }
        let step = ga.step(model, &mut s);
        let st = match step {
            Ok(st) => st,
            Err(e) => {
                out.error = Some(format!("step {k}: {e}"));
                break;
            }
        };
        dissipation.step(model, &s);
        // The loads held over the step did the work of their power at its start and its end
        // (trapezoid); the next step's loads come from this state.
        match apply(&mut strips, model, &s, &lift_dir) {
            Ok((held, p, l)) => {
                work += 0.5 * dt * (power + held);
                (power, lift) = (p, l);
            }
            Err(e) => {
                out.error = Some(format!("step {k} (t = {}): {e}", s.t));
                break;
            }
        }
        if k % every == 0 || k == n_steps {
            let r = record(&dissipation, row(model, fold, &s, st.n_newton_iters), work, lift);
            out.rows.push(r);
            if let Err(e) = feed.feed(model, &r, &s.q, None) {
                out.error = Some(format!("step {k}: output: {e}"));
                break;
            }
        }
    }
    out.stats = *ga.stats();
    let speed = aero.speed();
    out.strips = strips.strips(&lift_dir, 0.5 * aero.rho * speed * speed);
    let err = out.error.take();
    finish(out, start, err)
}

/// The strips' loads at state `s` applied to `model`: the power of the loads held until now and
/// of the new ones at `s`, and the new loads' lift (along `lift_dir`).
fn apply<S: Structure>(
    strips: &mut StripAero<'_>,
    model: &mut S,
    s: &State,
    lift_dir: &Vector3<f64>,
) -> Result<(f64, f64, f64), String> {
    let (loads, held, power) = strips.evaluate(&*model, s.t, &s.q, &s.v)?;
    let lift = loads.iter().map(|l| l.force.dot(lift_dir)).sum();
    model.set_section_loads(loads).map_err(|e| e.to_string())?;
    Ok((held, power, lift))
}

fn finish(mut out: RunOutput, start: Instant, error: Option<String>) -> RunOutput {
    out.error = error;
    out.wall_s = start.elapsed().as_secs_f64();
    out
}
