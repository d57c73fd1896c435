//! Aero-structure coupling: the UVLM driven by either structural formulation.
//!
//! Written once against [`Structure`]: the section pose (axis point and section frame) of a
//! body at an arclength, and a way to apply point forces and moments there. Station velocities
//! are the derivative of the pose along the model's own retraction `q ∘ exp(ε v)` (central
//! difference), so they are consistent with each formulation's kinematics without a second code
//! path. Lattice column `j` is a span station; the flared hinge column is driven by the inner
//! body's end section and carries the slant β, so the shared edge never opens.
//!
//! Scheme per step `n → n+1` (dt of the structure):
//! 1. predict the structure at `t_{n+1}` (`q_n ∘ exp(h v_n + ½h² a_n)`), move the lattice there;
//! 2. convect and shed the wake, solve the UVLM, lump loads to the stations and, with section
//!    polars, correct them strip by strip (`polar_correction.rs`, docs/section_aero.md §7);
//! 3. apply them and solve the structural step;
//! 4. strong coupling (optional): move the lattice to the new structure, re-solve the same UVLM
//!    step, relax the loads and redo the structural step from `n` until the relative load change
//!    is below the tolerance. Strongly coupled, steps 1–2 are by default only the wake's
//!    convection, and step 3 takes the last two steps' loads extrapolated to `t_{n+1}`
//!    ([`LoadPredictor`]; docs/coupling.md §4);
//! 5. commit the UVLM step and add the aerodynamic work `∫ Σ (F·v + M·ω) dt` (trapezoidal).

use nalgebra::{Matrix3, Vector3};

use crate::polar_correction::{StripPolars, StripReport};
use crate::problem::{Joint, Problem};

pub use crate::aero_settings::{AeroSettings, Coupling, LoadPredictor, MirrorPlane, RunsGuard, register_runs};
use formulation::Structure;

pub use formulation::SectionLoad;

use crate::planform::{Sections, SurfacePlan};

/// Largest angle between a streamwise section and the normal to the beam axis, degrees.
pub const MAX_STREAMWISE_SLANT_DEG: f64 = 70.0;

/// One span station of the lattice: which body section drives it, and its column slant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationMap {
    /// Body index.
    pub body: usize,
    /// Arclength, m.
    pub s: f64,
    /// Slant of the grid column, rad (β at a flared hinge, blended next to it, 0 elsewhere).
    pub slant: f64,
    /// Whether this is a flared hinge's column.
    pub hinge: bool,
    /// The control surface on this station (index into `aero.control_surfaces`), if any.
    pub control: Option<usize>,
    /// The lifting surface this station belongs to (0 with one surface).
    pub lifting: usize,
    /// Arclength of the station along its lifting surface from the surface's root, the
    /// surface's bodies laid end to end, m.
    pub arc: f64,
    /// Chord measured along the section's y axis, m (`aero.chord` at this station, times the
    /// cosine of the streamwise slant for streamwise sections).
    pub chord: f64,
    /// Distance from the beam axis to the leading edge along the section's y axis, m.
    pub le_offset: f64,
    /// Chord as the planform gives it (measured along the stream for streamwise sections), m.
    pub planform_chord: f64,
}

/// Span stations of every lifting surface (`aero.surfaces`, or the one-surface shorthand of
/// every body), surface after surface: each a chain of bodies joined end to start by flared
/// hinges, each body's panels, the hinge column shared (driven by the inner body's end).
pub fn station_map(case: &Problem, aero: &AeroSettings) -> Result<Vec<StationMap>, String> {
    let plans = aero.surface_plans(case)?;
    let frames = reference_frames(case);
    let stream = -Vector3::from(aero.stream_without_sideslip()).normalize();
    let mut out = Vec::new();
    for (k, plan) in plans.iter().enumerate() {
        let start = out.len();
        surface_stations(case, plan, k, &frames, &stream, &mut out)?;
        grade_slants(&mut out[start..]);
    }
    if plans.len() > 1 {
        check_roots(case, &plans)?;
    }
    place_control_surfaces(case, aero, &plans, &mut out)?;
    Ok(out)
}

/// The stations of lifting surface `k` (`plan`) appended to `out`.
fn surface_stations(
    case: &Problem,
    plan: &SurfacePlan,
    k: usize,
    frames: &[Matrix3<f64>],
    stream: &Vector3<f64>,
    out: &mut Vec<StationMap>,
) -> Result<(), String> {
    let field = &plan.field;
    let mut before = 0.0;
    for (i, &b) in plan.bodies.iter().enumerate() {
        let body = &case.bodies[b];
        let n = plan.panels[i];
        if i > 0 {
            // The previous body's end column is the hinge column: find the flared hinge.
            let inner = plan.bodies[i - 1];
            let hinge = case.joints.iter().find_map(|j| match j {
                Joint::FlaredHinge { parent, child, flare_deg, .. }
                    if case.body_index(parent) == Some(inner) && case.body_index(child) == Some(b) =>
                {
                    Some(flare_deg.to_radians())
                }
                _ => None,
            });
            let Some(beta) = hinge else {
                return Err(format!(
                    "{}: bodies `{}` and `{}` are not joined by a flared hinge (parent then child)",
                    if plan.field == "aero" { "aero".to_string() } else { format!("{field}.bodies[{i}]") },
                    case.bodies[inner].name,
                    body.name
                ));
            };
            check_shared_column(plan, i)?;
            if let Some(last) = out.last_mut() {
                let last: &mut StationMap = last;
                last.slant = beta;
                last.hinge = true;
            }
        }
        let twist = body.twist_deg.as_ref().map(|t| t.twist(body.length));
        for j in usize::from(i > 0)..=n {
            let frac = j as f64 / n as f64;
            let s = body.length * frac;
            let (planform_chord, mut le_offset) = (plan.chord.at(i, frac), plan.le_offset.at(i, frac));
            let mut chord = planform_chord;
            let mut slant = 0.0;
            if plan.sections == Sections::Streamwise {
                let frame = frames[b] * twist.as_ref().map_or_else(Matrix3::identity, |t| t.rotation(s));
                let (along, ahead) = (frame.column(0).dot(stream), frame.column(1).dot(stream));
                if ahead <= 0.0 {
                    return Err(format!(
                        "{field}.sections: the stream comes from behind bodies[{b}]'s leading edge at s = {s} m"
                    ));
                }
                slant = along.atan2(ahead);
                if slant.abs() >= MAX_STREAMWISE_SLANT_DEG.to_radians() {
                    return Err(format!(
                        "{field}.sections: bodies[{b}] at s = {s} m lies {:.1}° off the normal to the stream (at \
                         most {MAX_STREAMWISE_SLANT_DEG}° for streamwise sections)",
                        slant.to_degrees()
                    ));
                }
                chord *= slant.cos();
                le_offset *= slant.cos();
            }
            let arc = before + s;
            out.push(StationMap {
                body: b,
                s,
                slant,
                hinge: false,
                control: None,
                lifting: k,
                arc,
                chord,
                le_offset,
                planform_chord,
            });
        }
        before += body.length;
    }
    Ok(())
}

/// Surfaces that meet must share their root station exactly (two half-wings at the plane of
/// symmetry): a gap smaller than a panel between two trailing legs makes their induced velocity
/// blow up (docs/uvlm.md §16). Roots closer than 1e-9 m count as shared; farther apart they
/// must be at least a panel width apart (the smaller root strip of the two).
fn check_roots(case: &Problem, plans: &[SurfacePlan]) -> Result<(), String> {
    let placements = case.placements();
    // Root point and root panel width of each surface.
    let roots: Vec<(Vector3<f64>, f64)> = plans
        .iter()
        .map(|p| (placements[p.bodies[0]].0, case.bodies[p.bodies[0]].length / p.panels[0] as f64))
        .collect();
    for (k, &(rk, wk)) in roots.iter().enumerate() {
        for (i, &(ri, wi)) in roots[..k].iter().enumerate() {
            let d = (rk - ri).norm();
            if d > 1e-9 && d < wk.min(wi) {
                return Err(format!(
                    "aero.surfaces[{k}].bodies[0]: its root is {d:.3e} m from aero.surfaces[{i}]'s root; surfaces \
                     that meet must share their root point exactly, others keep at least a root panel ({:.3e} m) \
                     apart",
                    wk.min(wi)
                ));
            }
        }
    }
    Ok(())
}

/// Check `aero.control_surfaces` and put each on the stations it covers (the hinge column
/// belongs to the inner body's end; a surface of the outer body from `s0 = 0` covers it).
fn place_control_surfaces(
    case: &Problem,
    aero: &AeroSettings,
    plans: &[SurfacePlan],
    map: &mut [StationMap],
) -> Result<(), String> {
    let cs = &aero.control_surfaces;
    if cs.is_empty() {
        return Ok(());
    }
    // Each body's lattice: spanwise and chordwise panels of its surface.
    let mut lattice = vec![None; case.bodies.len()];
    for p in plans {
        for (i, &b) in p.bodies.iter().enumerate() {
            lattice[b] = Some((p.panels[i], p.n_chordwise));
        }
    }
    crate::control_surface::check(case, cs, &lattice)?;
    for j in 0..map.len() {
        // A hinge column also belongs to the root of the surface's next body.
        let next = map[j].hinge.then(|| map.get(j + 1).map(|m| m.body)).flatten();
        map[j].control = crate::control_surface::surface_at(case, cs, map[j].body, map[j].s, next)?;
    }
    crate::control_surface::columns(map, cs).map(|_| ())
}

/// Blend the columns next to a slanted hinge column towards its slant, so that no panel folds
/// when the hinge column's ends reach past a neighbouring station (a large flare, a long chord
/// or narrow panels): a column of own slant `γ₀` (0 for normal sections) at arclength distance
/// `d` from the hinge gets `tan γ = tan γ₀ + w (tan β − tan γ₀)`, `w = max(0, 1 − d/D)` with
/// `D = 2 max(le, c − le) |tan β − tan γ₀|`, which keeps the leading- and trailing-edge nodes in
/// spanwise order. Only the panel layout changes, not the planform; columns farther than `D`
/// keep `γ₀` exactly.
fn grade_slants(map: &mut [StationMap]) {
    let arc = |m: &StationMap| m.arc;
    let hinges: Vec<(f64, f64)> = map.iter().filter(|m| m.hinge).map(|m| (arc(m), m.slant)).collect();
    let reach = map.iter().map(|m| m.le_offset.abs().max((m.chord - m.le_offset).abs())).fold(0.0, f64::max);
    for m in map.iter_mut().filter(|m| !m.hinge) {
        let x = arc(m);
        let own = m.slant.tan();
        let (mut t, mut near) = (0.0, false);
        for &(xh, beta) in &hinges {
            let d_max = 2.0 * reach * (beta.tan() - own).abs();
            let w = if d_max > 0.0 { (1.0 - (x - xh).abs() / d_max).max(0.0) } else { 0.0 };
            near |= w > 0.0;
            t += w * (beta.tan() - own);
        }
        if near {
            m.slant = (own + t).atan();
        }
    }
}

/// A hinge column is shared by the inner body's end and the outer body's root: their chords
/// and leading-edge offsets must meet there.
fn check_shared_column(plan: &SurfacePlan, b: usize) -> Result<(), String> {
    for (name, taper) in [("chord", &plan.chord), ("le_offset", &plan.le_offset)] {
        let field = format!("{}.{name}", plan.field);
        let (tip, root) = (taper.at(b - 1, 1.0), taper.at(b, 0.0));
        if (tip - root).abs() > 1e-9 * tip.abs().max(root.abs()).max(1e-3) {
            return Err(format!(
                "{field}[{b}][0]: {root} m differs from {field}[{}][1] = {tip} m; the bodies share their hinge column",
                b - 1
            ));
        }
    }
    Ok(())
}

/// Each body's section frame in the reference configuration before its own twist, the root
/// pitch included (the frame the scene builds).
fn reference_frames(case: &Problem) -> Vec<Matrix3<f64>> {
    let pitch = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), case.pitch_deg.to_radians());
    case.placements()
        .into_iter()
        .map(|(_, x, y)| {
            let (x, y) = (pitch * x, pitch * y);
            Matrix3::from_columns(&[x, y, x.cross(&y)])
        })
        .collect()
}

/// Reused buffers of the stations' poses and velocities: the exact states where the
/// formulation gives them, else the probe states `q ⊕ ±ε v` and the poses at `q` and at both
/// probes.
#[derive(Debug, Clone, Default)]
pub struct StationScratch {
    dq: Vec<f64>,
    qp: Vec<f64>,
    qm: Vec<f64>,
    at: Vec<(usize, f64)>,
    poses: [Vec<(Vector3<f64>, Matrix3<f64>)>; 3],
    states: Vec<SectionKinematics>,
}

/// A section's pose and velocity: point, frame, linear and angular velocity.
pub type SectionKinematics = formulation::SectionState;

/// Pose and velocity of a section: exact where the formulation gives them
/// ([`Structure::section_states`]), else by central differences along the retraction.
pub fn section_state<S: Structure + ?Sized>(
    model: &S,
    q: &[f64],
    v: &[f64],
    st: &StationMap,
    scratch: &mut StationScratch,
) -> SectionKinematics {
    let mut out = None;
    station_states(model, q, v, std::slice::from_ref(st), scratch, |_, k| out = Some(k));
    out.unwrap_or_else(|| unreachable!("one station in, one out"))
}

/// [`section_state`] of every station of `map`, handed to `each` with its index. Without exact
/// rates the probe states `q ⊕ ±ε v` depend on the state only, so one pair serves every station
/// (a retraction costs the whole structure), and the poses go through
/// [`Structure::section_poses`].
pub fn station_states<S: Structure + ?Sized>(
    model: &S,
    q: &[f64],
    v: &[f64],
    map: &[StationMap],
    scratch: &mut StationScratch,
    mut each: impl FnMut(usize, SectionKinematics),
) {
    let StationScratch { dq, qp, qm, at, poses, states } = scratch;
    at.clear();
    at.extend(map.iter().map(|st| (st.body, st.s)));
    if model.section_states(q, v, at, states) {
        for (i, &k) in states.iter().enumerate() {
            each(i, k);
        }
        return;
    }
    let vmax = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let eps = (vmax != 0.0).then(|| 1e-6 / vmax.max(1.0));
    model.section_poses(q, at, &mut poses[0]);
    let Some(eps) = eps else {
        for (i, &(p, r)) in poses[0].iter().enumerate() {
            each(i, (p, r, Vector3::zeros(), Vector3::zeros()));
        }
        return;
    };
    dq.clear();
    dq.extend(v.iter().map(|x| eps * x));
    qp.resize(q.len(), 0.0);
    qm.resize(q.len(), 0.0);
    model.retract_inplace(q, dq, qp);
    dq.iter_mut().for_each(|x| *x = -*x);
    model.retract_inplace(q, dq, qm);
    let [p0, pp, pm] = poses;
    model.section_poses(qp, at, pp);
    model.section_poses(qm, at, pm);
    for (i, ((&(p, r), &(pp, rp)), &(pm, rm))) in p0.iter().zip(pp.iter()).zip(pm.iter()).enumerate() {
        let vel = (pp - pm) / (2.0 * eps);
        let w = (rp - rm) * r.transpose() / (2.0 * eps);
        let omega = Vector3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) * 0.5;
        each(i, (p, r, vel, omega));
    }
}

/// Build the lattice stations (and their velocities) of the current structural state, with the
/// control surfaces' flaps at time `t` (`None`: steady, the deflection at t = 0 and no rate, as
/// statics, stability and the linear gust use).
#[allow(clippy::too_many_arguments)] // model, state, map, settings, time and three reused buffers
pub(crate) fn stations_at<S: Structure + ?Sized>(
    model: &S,
    q: &[f64],
    v: &[f64],
    map: &[StationMap],
    aero: &AeroSettings,
    t: Option<f64>,
    scratch: &mut StationScratch,
    stations: &mut Vec<uvlm::SpanStation>,
    velocities: &mut Vec<uvlm::StationVelocity>,
) {
    stations.clear();
    velocities.clear();
    station_states(model, q, v, map, scratch, |i, (p, r, vel, omega)| {
        let st = &map[i];
        stations.push(uvlm::SpanStation {
            origin: p,
            frame: r,
            chord: st.chord,
            le_offset: st.le_offset,
            slant: st.slant,
            flap: st.control.map(|i| aero.control_surfaces[i].flap_at(t)),
        });
        velocities.push(uvlm::StationVelocity { linear: vel, angular: omega });
    });
}

/// Aerodynamic power Σ F·v + M·ω of station loads with station velocities, W.
fn power(loads: &[SectionLoad], vel: &[uvlm::StationVelocity]) -> f64 {
    loads.iter().zip(vel).map(|(l, v)| l.force.dot(&v.linear) + l.moment.dot(&v.angular)).sum()
}

/// Integrate an aeroelastic case (see the module docs for the scheme), from the model's initial
/// state with an empty wake (an impulsive start).
pub fn simulate_aero<S: Structure>(
    formulation: crate::problem::Formulation,
    model: &mut S,
    settings: &crate::run::RunSettings,
    aero: &AeroSettings,
    map: &[StationMap],
    observer: &mut dyn crate::run::Observer,
) -> crate::run::RunOutput {
    simulate_aero_from(formulation, model, settings, aero, map, observer, None)
}

/// [`simulate_aero`], optionally from `equilibrium`: the coordinates of a static aeroelastic
/// equilibrium (docs/statics.md), at rest, with the steady solution of the lattice there, its wake
/// prefilled along the free stream ([`uvlm::Uvlm::prefill_wake`]) and its loads applied before the
/// initial accelerations, so that without a disturbance the run stays at the equilibrium
/// (docs/gust.md §3). A gust (`aero.gust`) is attached in both cases, its front placed relative to
/// the initial lattice's most upstream leading-edge point.
pub fn simulate_aero_from<S: Structure>(
    formulation: crate::problem::Formulation,
    model: &mut S,
    settings: &crate::run::RunSettings,
    aero: &AeroSettings,
    map: &[StationMap],
    observer: &mut dyn crate::run::Observer,
    equilibrium: Option<&[f64]>,
) -> crate::run::RunOutput {
    let mut none = crate::events::Events::none();
    simulate_aero_with_events(formulation, model, settings, aero, map, observer, equilibrium, &mut none)
}

/// [`simulate_aero_from`] with hinge events ([`crate::events`]): each one rebuilds `model`, with
/// the aerodynamic loads of the step applied, and restarts the integrator at the end of the step
/// nearest its time; the lattice and its wake go on.
#[allow(clippy::too_many_arguments)]
pub fn simulate_aero_with_events<S: Structure>(
    formulation: crate::problem::Formulation,
    model: &mut S,
    settings: &crate::run::RunSettings,
    aero: &AeroSettings,
    map: &[StationMap],
    observer: &mut dyn crate::run::Observer,
    equilibrium: Option<&[f64]>,
    events: &mut crate::events::Events<'_, S>,
) -> crate::run::RunOutput {
    let start = equilibrium.map_or(MarchStart::Rest, MarchStart::Equilibrium);
    march_aero(formulation, model, settings, (aero, map), observer, start, events, None).0
}

/// Where a coupled march starts.
pub enum MarchStart<'q> {
    /// The model's initial state at rest, the lattice started impulsively.
    Rest,
    /// A static aeroelastic equilibrium's coordinates (see [`simulate_aero_from`]).
    Equilibrium(&'q [f64]),
    /// Where another march stopped ([`march_aero`]'s checkpoint): its coordinates, velocities
    /// and time, its lattice with its wake, clock and disturbance, and its last loads, on the
    /// model given (which may differ from the stopped march's in its joints' states, as after a
    /// hinge event: the same coordinates and velocities, consistent accelerations).
    Resume(Box<MarchCheckpoint>),
}

/// The state of a coupled march at the end of a step, to resume it from ([`MarchStart::Resume`]).
pub struct MarchCheckpoint {
    /// The structure's state (time, coordinates, velocities; the rest is recomputed).
    pub state: genalpha::State,
    /// The step it ended.
    pub step: usize,
    uv: uvlm::Uvlm,
    loads: Vec<SectionLoad>,
    lift: f64,
    hinge: [f64; crate::control_surface::MAX_CONTROL_SURFACES],
}

/// The coupled march of `model` from `start` to the settings' end, or, with `stop_after`, to the
/// end of that step, returning the checkpoint to resume from (docs/coupling.md §8).
#[allow(clippy::too_many_arguments)]
pub fn march_aero<S: Structure>(
    formulation: crate::problem::Formulation,
    model: &mut S,
    settings: &crate::run::RunSettings,
    (aero, map): (&AeroSettings, &[StationMap]),
    observer: &mut dyn crate::run::Observer,
    start: MarchStart<'_>,
    events: &mut crate::events::Events<'_, S>,
    stop_after: Option<usize>,
) -> (crate::run::RunOutput, Option<MarchCheckpoint>) {
    use crate::run::{Dissipation, RunOutput, SnapshotFeed, row};
    let wall = std::time::Instant::now();
    let mut out = RunOutput::failed(formulation, String::new());
    out.error = None;
    out.n_dof = model.n_dof();
    let dt = settings.params.dt;
    let n_steps = settings.n_steps();
    let every = settings.output_every();
    let fail = |mut out: RunOutput, e: String| {
        out.error = Some(e);
        out.wall_s = wall.elapsed().as_secs_f64();
        (out, None)
    };
    let mut ga = match model.integrator(settings.params) {
        Ok(g) => g,
        Err(e) => return fail(out, e.to_string()),
    };
    let (mut s, mut c, first) = match march_start(model, settings, (aero, map), start) {
        Ok(x) => x,
        Err(e) => return fail(out, e),
    };
    if let Err(e) = ga.initialize(model, &mut s) {
        return fail(out, format!("initial accelerations: {e}"));
    }
    model.start_march(s.t, &s.q, &s.v);
    let mut work = 0.0;
    let mut stopped = None;
    let fold = (settings.fold_joint, settings.roll_joint);
    let mut feed = SnapshotFeed::new(observer);
    let mut dissipation = Dissipation::new(model, &s, events.any());
    // Wing loads from the free body of each output state (docs/statics.md §4).
    let load_model = settings.loads.as_ref();
    let mut load_scratch = crate::loads::LoadScratch::default();
    let mut trigger_scratch = crate::loads::LoadScratch::default();
    let mut with_loads = |model: &S, r: &mut crate::run::Row, s: &genalpha::State, loads: &[SectionLoad]| {
        if let Some(lm) = load_model {
            let w = lm.evaluate(model, &s.q, Some((&s.v, &s.v_dot)), loads, &mut load_scratch);
            r.root_bending_moment = w.root_bending_moment;
            r.root_torque = w.root_torque;
            r.hinge_moment = w.hinge_moment;
        }
    };
    let mut r0 = dissipation.record(row(model, fold, &s, 0));
    r0.aero_work = 0.0;
    r0.lift = c.lift;
    r0.control_hinge_moments = c.hinge;
    with_loads(model, &mut r0, &s, &c.loads);
    events.set_root_bending_moment_start(r0.root_bending_moment);
    out.rows.push(r0);
    if let Err(e) = feed.feed(model, &r0, &s.q, Some(&c.uv)) {
        return fail(out, format!("output at t = {}: {e}", s.t));
    }
    for k in first..=n_steps {
        if crate::interrupt::interrupted() {
            out.error = Some(crate::run::interrupted_message(s.t));
            break;
        }
        let st = match c.step(model, &mut ga, &mut s, k) {
            Ok(st) => st,
            Err(e) => return fail(out, e),
        };
        // 5. Work of the aerodynamic loads over the step (trapezoidal in the station velocities).
        c.move_to(model, &s.q, &s.v, s.t);
        work += 0.5 * dt * (power(&c.loads, &c.vel_n) + power(&c.loads, &c.vel));
        dissipation.step(model, &s);
        let rbm = match load_model {
            Some(lm) if events.watches_root_bending_moment() => {
                lm.evaluate(model, &s.q, Some((&s.v, &s.v_dot)), &c.loads, &mut trigger_scratch).root_bending_moment
            }
            _ => f64::NAN,
        };
        match events.apply_due(model, &mut ga, &mut s, settings.params, &c.loads, rbm) {
            Ok(Some(loss)) => {
                dissipation.add_loss(loss);
                dissipation.restart(model, &s);
                // The stations' velocities after the event (a lock changes them).
                c.move_to(model, &s.q, &s.v, s.t);
                c.restart_loads();
            }
            Ok(None) => {}
            Err(e) => return fail(out, format!("step {k}: {e}")),
        }
        if k % every == 0 || k == n_steps {
            let mut r = dissipation.record(row(model, fold, &s, st.n_newton_iters));
            r.aero_work = work;
            r.lift = c.lift;
            r.control_hinge_moments = c.hinge;
            with_loads(model, &mut r, &s, &c.loads);
            out.rows.push(r);
            if let Err(e) = feed.feed(model, &r, &s.q, Some(&c.uv)) {
                return fail(out, format!("step {k}: output: {e}"));
            }
        }
        if stop_after == Some(k) {
            stopped = Some(k);
            break;
        }
    }
    out.stats = events.total_stats(ga.stats());
    out.events = events.records.clone();
    out.wall_s = wall.elapsed().as_secs_f64();
    out.aero_wall_s = c.uv.stats().wall_time;
    out.aero_solves = c.n_solves;
    out.aero_steps = c.n_steps;
    out.strips = c.strips();
    let checkpoint =
        stopped.map(|step| MarchCheckpoint { state: s, step, uv: c.uv, loads: c.loads, lift: c.lift, hinge: c.hinge });
    (out, checkpoint)
}

/// The structure's state, the lattice side and the first step of a march from `start`, with the
/// start's loads applied to `model` (the integrator's consistent start follows). A rest or
/// equilibrium start attaches the case's gust; a resumed march keeps its lattice's.
fn march_start<'a, S: Structure>(
    model: &mut S,
    settings: &'a crate::run::RunSettings,
    (aero, map): (&'a AeroSettings, &'a [StationMap]),
    start: MarchStart<'_>,
) -> Result<(genalpha::State, MarchAero<'a>, usize), String> {
    let dt = settings.params.dt;
    let mut s = model.initial_state();
    let polars = settings.polars.as_ref();
    let equilibrium = match start {
        MarchStart::Resume(ck) => {
            let (q, v) = (&ck.state.q, &ck.state.v);
            if q.len() != s.q.len() || v.len() != s.v.len() {
                return Err(format!(
                    "resume: {} coordinates and {} velocities for a model of {} and {}",
                    q.len(),
                    v.len(),
                    s.q.len(),
                    s.v.len()
                ));
            }
            s.t = ck.state.t;
            s.q.copy_from_slice(q);
            s.v.copy_from_slice(v);
            model.set_section_loads(&ck.loads).map_err(|e| format!("resume: loads: {e}"))?;
            let first = ck.step + 1;
            let c = MarchAero::resume(model, &s, (map, aero, dt), polars, *ck)?;
            return Ok((s, c, first));
        }
        MarchStart::Equilibrium(q) => Some(q),
        MarchStart::Rest => None,
    };
    if let Some(q) = equilibrium {
        if q.len() != s.q.len() {
            return Err(format!("equilibrium: {} coordinates for a model of {}", q.len(), s.q.len()));
        }
        s.q.copy_from_slice(q);
        s.v.iter_mut().for_each(|x| *x = 0.0);
    }
    let mut c = MarchAero::start(model, &s, map, aero, dt, equilibrium.is_some(), polars)?;
    if let Some(g) = &aero.gust {
        let d = crate::gust_field::disturbance(g, aero, &c.stations, settings.t_end, s.t)
            .map_err(|e| format!("aero.gust: {e}"))?;
        c.uv.set_disturbance(Some(d));
    }
    Ok((s, c, 1))
}

/// The stations placed on a structure: the scratch of [`stations_at`], the stations and their
/// velocities.
type Placed = (StationScratch, Vec<uvlm::SpanStation>, Vec<uvlm::StationVelocity>);

/// The span direction of the lift (the global X axis).
const SPAN_DIR: [f64; 3] = [1.0, 0.0, 0.0];

/// The lattice side of the time march and its reused buffers: the UVLM, the stations and their
/// velocities (now and at the start of the step), the station loads applied to the structure
/// and the last solve's, the lift, and the buffers of the lumping and of the predictor.
struct MarchAero<'a> {
    uv: uvlm::Uvlm,
    map: &'a [StationMap],
    aero: &'a AeroSettings,
    dt: f64,
    scratch: StationScratch,
    stations: Vec<uvlm::SpanStation>,
    vel: Vec<uvlm::StationVelocity>,
    vel_n: Vec<uvlm::StationVelocity>,
    /// The loads applied to the structure.
    loads: Vec<SectionLoad>,
    /// The loads of a sub-iteration's solve, before relaxation.
    new_loads: Vec<SectionLoad>,
    /// Lift of the last solve, N.
    lift: f64,
    lumping: Lumping,
    /// The stations of each lifting surface.
    ranges: Vec<std::ops::Range<usize>>,
    /// Predictor: coordinates, increment and velocity at `t_{n+1}`.
    qp: Vec<f64>,
    dq: Vec<f64>,
    vp: Vec<f64>,
    /// The grid columns of each control surface.
    surface_columns: Vec<std::ops::RangeInclusive<usize>>,
    /// Hinge moment of each control surface at the last solve, N·m (NaN past the surfaces).
    hinge: [f64; crate::control_surface::MAX_CONTROL_SURFACES],
    /// The section polars that correct the lumped loads (none: the lattice's as they are).
    polars: Option<&'a StripPolars>,
    /// The polars' correction of the last solve.
    report: StripReport,
    /// The loads of the step before the last ([`LoadPredictor::Extrapolate`]), valid when
    /// `has_previous_loads` (false after a (re)start of the march).
    loads_previous: Vec<SectionLoad>,
    has_previous_loads: bool,
    /// Aerodynamic solves and time steps of the march.
    n_solves: usize,
    n_steps: usize,
}

/// Buffers of the lumping of the lattice's nodal loads to the stations: the stations' origins,
/// and the forces and moments about them.
struct Lumping {
    origins: Vec<[f64; 3]>,
    force: Vec<[f64; 3]>,
    moment: Vec<[f64; 3]>,
}

impl Lumping {
    /// Buffers for `n` stations.
    fn new(n: usize) -> Self {
        Self { origins: Vec::with_capacity(n), force: vec![[0.0; 3]; n], moment: vec![[0.0; 3]; n] }
    }

    /// Lump the last solve's nodal loads of `uv` (surfaces on `ranges` of the stations) to
    /// `stations` (about their origins) into `target`; return the lift, ⊥ the free stream `v_inf`
    /// (a direction: a disturbance would not turn it).
    fn apply(
        &mut self,
        uv: &uvlm::Uvlm,
        ranges: &[std::ops::Range<usize>],
        stations: &[uvlm::SpanStation],
        v_inf: [f64; 3],
        target: &mut [SectionLoad],
    ) -> f64 {
        let l = uv.loads();
        self.origins.clear();
        self.origins.extend(stations.iter().map(|x| [x.origin.x, x.origin.y, x.origin.z]));
        crate::lifting::lump_into(uv, ranges, &self.origins, &mut self.force, &mut self.moment);
        for (j, t) in target.iter_mut().enumerate() {
            t.force = Vector3::from(self.force[j]);
            t.moment = Vector3::from(self.moment[j]);
        }
        uvlm::lift_drag_of(l.total_force(), v_inf, SPAN_DIR).0
    }
}

impl<'a> MarchAero<'a> {
    /// The lattice of `model` at `s` with an empty wake or, `at_equilibrium`, the steady solution
    /// there with its wake prefilled and its loads applied to `model`; the UVLM's clock, at which
    /// a disturbance is evaluated, starts at the structure's and advances with each commit.
    /// `polars` correct every solve's lumped loads.
    fn start<S: Structure>(
        model: &mut S,
        s: &genalpha::State,
        map: &'a [StationMap],
        aero: &'a AeroSettings,
        dt: f64,
        at_equilibrium: bool,
        polars: Option<&'a StripPolars>,
    ) -> Result<Self, String> {
        let mut scratch = StationScratch::default();
        let (mut stations, mut vel) = (Vec::new(), Vec::new());
        stations_at(model, &s.q, &s.v, map, aero, Some(s.t), &mut scratch, &mut stations, &mut vel);
        let mut params = aero.uvlm_params(aero.free_stream());
        if at_equilibrium && !aero.wake_closure {
            // The equilibrium's steady solution with the march's own unclosed wake (its rows
            // prefilled below), so that without a disturbance the run stays there.
            params.steady_wake = uvlm::SteadyWake::Finite { length: aero.n_wake_rows as f64 * aero.speed() * dt };
        }
        let uv =
            crate::lifting::new_uvlm(map, aero, &stations, params).map_err(|e| format!("aerodynamic lattice: {e}"))?;
        let loads: Vec<SectionLoad> = map
            .iter()
            .map(|m| SectionLoad { body: m.body, s: m.s, force: Vector3::zeros(), moment: Vector3::zeros() })
            .collect();
        let mut c = Self::with_lattice(uv, (scratch, stations, vel), s, (map, aero, dt), loads, polars)?;
        c.uv.set_time(s.t).map_err(|e| format!("aerodynamic clock: {e}"))?;
        if at_equilibrium {
            c.steady_start(model)?;
        }
        Ok(c)
    }

    /// The lattice side of a march resumed from `ck` ([`MarchCheckpoint`]): its lattice, wake and
    /// clock as they were, its stations moved to `model` at `s`, its last loads (already applied
    /// to `model` by the caller).
    fn resume<S: Structure>(
        model: &S,
        s: &genalpha::State,
        (map, aero, dt): (&'a [StationMap], &'a AeroSettings, f64),
        polars: Option<&'a StripPolars>,
        ck: MarchCheckpoint,
    ) -> Result<Self, String> {
        let mut scratch = StationScratch::default();
        let (mut stations, mut vel) = (Vec::new(), Vec::new());
        stations_at(model, &s.q, &s.v, map, aero, Some(s.t), &mut scratch, &mut stations, &mut vel);
        if ck.loads.len() != map.len() {
            return Err(format!("resume: {} station loads for {} stations", ck.loads.len(), map.len()));
        }
        let mut c = Self::with_lattice(ck.uv, (scratch, stations, vel), s, (map, aero, dt), ck.loads, polars)?;
        c.lift = ck.lift;
        c.hinge = ck.hinge;
        Ok(c)
    }

    /// The lattice side around the lattice `uv` with the stations and velocities `at` of `s`,
    /// the applied `loads`.
    fn with_lattice(
        uv: uvlm::Uvlm,
        (scratch, stations, vel): Placed,
        s: &genalpha::State,
        (map, aero, dt): (&'a [StationMap], &'a AeroSettings, f64),
        loads: Vec<SectionLoad>,
        polars: Option<&'a StripPolars>,
    ) -> Result<Self, String> {
        let surface_columns = crate::control_surface::columns(map, &aero.control_surfaces)?;
        let mut hinge = [f64::NAN; crate::control_surface::MAX_CONTROL_SURFACES];
        hinge.iter_mut().take(surface_columns.len()).for_each(|h| *h = 0.0);
        Ok(MarchAero {
            uv,
            map,
            aero,
            dt,
            scratch,
            stations,
            vel,
            vel_n: Vec::with_capacity(map.len()),
            new_loads: loads.clone(),
            loads,
            lift: 0.0,
            lumping: Lumping::new(map.len()),
            ranges: crate::lifting::surface_ranges(map),
            qp: vec![0.0; s.q.len()],
            dq: vec![0.0; s.v.len()],
            vp: vec![0.0; s.v.len()],
            surface_columns,
            hinge,
            polars,
            report: StripReport::default(),
            loads_previous: Vec::new(),
            has_previous_loads: false,
            n_solves: 0,
            n_steps: 0,
        })
    }

    /// The steady solution on the equilibrium's lattice, its wake laid out as the unsteady solver
    /// would have shed it, its loads applied to `model` before the initial accelerations.
    fn steady_start<S: Structure>(&mut self, model: &mut S) -> Result<(), String> {
        self.uv.solve_steady().map_err(|e| format!("steady aerodynamics at the equilibrium: {e}"))?;
        self.lift =
            self.lumping.apply(&self.uv, &self.ranges, &self.stations, self.aero.free_stream(), &mut self.loads);
        self.lift += self.correct(false, self.uv.time()).map_err(|e| format!("at the equilibrium: {e}"))?;
        self.hinge_moments()?;
        self.uv.prefill_wake(self.dt).map_err(|e| format!("steady wake at the equilibrium: {e}"))?;
        model.set_section_loads(&self.loads).map_err(|e| format!("loads at the equilibrium: {e}"))
    }

    /// Move the stations (and their velocities) to the structure at `(q, v)`, the control
    /// surfaces to their deflections at time `t`.
    fn move_to<S: Structure>(&mut self, model: &S, q: &[f64], v: &[f64], t: f64) {
        stations_at(model, q, v, self.map, self.aero, Some(t), &mut self.scratch, &mut self.stations, &mut self.vel);
    }

    /// The control surfaces' hinge moments of the last solve into `hinge`.
    fn hinge_moments(&mut self) -> Result<(), String> {
        for (h, cols) in self.hinge.iter_mut().zip(&self.surface_columns) {
            *h = crate::lifting::hinge_moment(&self.uv, &self.ranges, cols.clone())
                .map_err(|e| format!("hinge moment: {e}"))?;
        }
        Ok(())
    }

    /// Move the lattice to the stations, solve the pending UVLM step (at time `t`) and lump its
    /// loads into `loads` (`into_new`: `new_loads`), corrected by the section polars; the lift of
    /// the solve.
    fn solve(&mut self, into_new: bool, t: f64) -> Result<f64, String> {
        self.n_solves += 1;
        crate::lifting::move_lattices(&mut self.uv, &self.ranges, &self.stations, Some(&self.vel))
            .map_err(|e| e.to_string())?;
        self.uv.solve_step().map_err(|e| e.to_string())?;
        let target = if into_new { &mut self.new_loads } else { &mut self.loads };
        let lift = self.lumping.apply(&self.uv, &self.ranges, &self.stations, self.aero.free_stream(), target);
        let delta = self.correct(into_new, t)?;
        self.hinge_moments()?;
        Ok(lift + delta)
    }

    /// Correct the last solve's lumped loads (`into_new`: `new_loads`, else `loads`) by the
    /// section polars, with the statics' [`StripPolars::correct`]; the change of lift, N (0
    /// without polars). A strip's flow is the air's velocity relative to its quarter-chord
    /// midpoint `p` without the lattice's induction: the free stream plus the disturbance at `p`
    /// at time `t`, less the mean of its two stations' rigid-arm velocities `v + ω × (p − o)`.
    /// The control surfaces' hinge moments stay the lattice's.
    fn correct(&mut self, into_new: bool, t: f64) -> Result<f64, String> {
        let Some(polars) = self.polars else { return Ok(0.0) };
        let flow = self.uv.flow();
        let v_inf = Vector3::from(flow.free_stream());
        let (stations, vel) = (&self.stations, &self.vel);
        let air = |j: usize, p: Vector3<f64>| {
            let gust = flow.disturbance().map_or_else(Vector3::zeros, |d| Vector3::from(d.velocity(p.into(), t)));
            let motion = |k: usize| {
                let (st, v): (&uvlm::SpanStation, &uvlm::StationVelocity) = (&stations[k], &vel[k]);
                v.linear + v.angular.cross(&(p - st.origin))
            };
            v_inf + gust - 0.5 * (motion(j) + motion(j + 1))
        };
        let target = if into_new { &mut self.new_loads } else { &mut self.loads };
        polars.correct(stations, self.map, self.uv.loads(), air, 1.0, target, &mut self.report)?;
        Ok(uvlm::lift_drag_of(self.report.total_delta.into(), self.aero.free_stream(), SPAN_DIR).0)
    }

    /// The strips of the last solve with the polars' correction (empty without polars), their
    /// lift coefficients at the free stream's dynamic pressure.
    fn strips(&self) -> Vec<crate::statics::Strip> {
        if self.polars.is_none() {
            return Vec::new();
        }
        let v_inf = self.aero.free_stream();
        let speed2 = v_inf.iter().map(|x| x * x).sum::<f64>();
        let lift_dir = crate::statics::lift_direction(v_inf);
        let qdyn = 0.5 * self.aero.rho * speed2;
        crate::statics::strips_of(self.map, &self.stations, self.uv.loads(), &self.report, lift_dir, qdyn)
    }

    /// [`LoadPredictor::Extrapolate`]: the applied loads `L_n` become `2 L_n − L_{n−1}` (kept as
    /// they are on the first step after a (re)start, which knows no `L_{n−1}`), and `L_n` is kept
    /// as the next step's previous loads.
    fn extrapolate_loads(&mut self) {
        if self.has_previous_loads {
            for (l, p) in self.loads.iter_mut().zip(&mut self.loads_previous) {
                let (f, m) = (l.force, l.moment);
                l.force = 2.0 * f - p.force;
                l.moment = 2.0 * m - p.moment;
                p.force = f;
                p.moment = m;
            }
        } else {
            self.loads_previous.clone_from(&self.loads);
            self.has_previous_loads = true;
        }
    }

    /// Forget the loads of earlier steps (after a hinge event, whose jump they do not predict).
    fn restart_loads(&mut self) {
        self.has_previous_loads = false;
    }

    /// Relax the applied loads towards the sub-iteration's; whether the relative change was
    /// within the coupling's tolerance.
    fn relax(&mut self) -> bool {
        let (mut num, mut den) = (0.0, 0.0);
        let w = self.aero.coupling.relaxation;
        for (a, b) in self.loads.iter_mut().zip(&self.new_loads) {
            num += (b.force - a.force).norm_squared() + (b.moment - a.moment).norm_squared();
            den += b.force.norm_squared() + b.moment.norm_squared();
            a.force = w * b.force + (1.0 - w) * a.force;
            a.moment = w * b.moment + (1.0 - w) * a.moment;
        }
        num.sqrt() <= self.aero.coupling.tolerance * den.sqrt().max(1e-12)
    }

    /// Step `k` of the march, steps 1–4 of the scheme (module docs) and the commit of the UVLM
    /// step; `vel_n` keeps the stations' velocities at the start of the step.
    fn step<S: Structure>(
        &mut self,
        model: &mut S,
        ga: &mut genalpha::GenAlpha<S::Solver>,
        s: &mut genalpha::State,
        k: usize,
    ) -> Result<genalpha::StepStats, String> {
        let dt = self.dt;
        let t1 = s.t + dt;
        // (A hinge event on ANCF's ODE path changes the number of coordinates.)
        self.dq.resize(s.v.len(), 0.0);
        self.vp.resize(s.v.len(), 0.0);
        self.qp.resize(s.q.len(), 0.0);
        self.vel_n.clear();
        self.vel_n.extend_from_slice(&self.vel);
        let aero_err = |e: String| format!("step {k} (t = {t1:.4} s): aerodynamics: {e}");
        let coupling = &self.aero.coupling;
        if coupling.max_sub_iterations > 0 && coupling.predictor == LoadPredictor::Extrapolate {
            // 1–2. Convect and shed the wake; the last two steps' loads extrapolated to t_{n+1}.
            self.uv.advance_wake(dt).map_err(|e| aero_err(e.to_string()))?;
            self.extrapolate_loads();
        } else {
            // 1. Predict the structure at t_{n+1} and move the lattice there.
            for i in 0..self.dq.len() {
                self.dq[i] = dt * s.v[i] + 0.5 * dt * dt * s.v_dot[i];
                self.vp[i] = s.v[i] + dt * s.v_dot[i];
            }
            model.retract_inplace(&s.q, &self.dq, &mut self.qp);
            stations_at(
                model,
                &self.qp,
                &self.vp,
                self.map,
                self.aero,
                Some(t1),
                &mut self.scratch,
                &mut self.stations,
                &mut self.vel,
            );
            // 2. Wake and aerodynamic solve at the predicted lattice.
            self.uv.advance_wake(dt).map_err(|e| aero_err(e.to_string()))?;
            self.lift = self.solve(false, t1).map_err(aero_err)?;
        }
        // 3. Structural step with these loads.
        let s_n: genalpha::State = s.clone();
        model.set_section_loads(&self.loads).map_err(|e| format!("step {k} (t = {t1:.4} s): {e}"))?;
        let mut st = ga.step(model, s).map_err(|e| format!("step {k}: {e}"))?;
        // 4. Strong coupling.
        for _ in 0..self.aero.coupling.max_sub_iterations {
            self.move_to(model, &s.q, &s.v, t1);
            self.lift = self.solve(true, t1).map_err(aero_err)?;
            if self.relax() {
                break;
            }
            *s = s_n.clone();
            model
                .set_section_loads(&self.loads)
                .map_err(|e| format!("step {k} (t = {t1:.4} s, sub-iteration): {e}"))?;
            st = ga.step(model, s).map_err(|e| format!("step {k} (sub-iteration): {e}"))?;
        }
        self.uv.commit_step().map_err(|e| format!("step {k}: aerodynamics: {e}"))?;
        self.n_steps += 1;
        debug_assert!(
            (self.uv.time() - s.t).abs() <= 1e-9 * s.t.abs().max(1.0),
            "the UVLM's clock follows the structure's"
        );
        Ok(st)
    }
}
