//! What a run will cost, estimated from the case before anything is allocated, and the limits a
//! case must stay within.
//!
//! The estimate counts what grows with the input: the unknowns `n` of each formulation (ANCF:
//! 12 per node plus at most 12 constraint rows per joint; GEBF: 12 per element plus 6 per body
//! and at most 6 rows per joint), the fallback factorisation of a matrix the band storage cannot
//! take (up to [`genalpha::DENSE_FALLBACK_MAX`] unknowns a dense matrix and
//! its LU, `16 n²` bytes; above it a sparse LU, `n²` bytes), the band storage,
//! the Broyden history (`n × (max_iter + 1)`), the recorded rows, and with aerodynamics the
//! influence matrix and its LU (`2 × 8 N_b²` for `N_b` bound rings) and the wake. The time is
//! a per-step cost (a few Newton iterations over a band, linear in `n`, the influence matrix, its
//! LU and the wake's induced velocities) times the steps, with the coupling sub-iterations, plus
//! a sparse consistent start.
//! Constants are deliberately generous: the estimate refuses what cannot fit, it does not
//! predict a run's wall time.
//!
//! Limits: memory — the smaller of ¾ of the machine's memory and ½ of the process's
//! address-space limit (`ulimit -v`), or `--max-memory`; time — 48 hours, or `--max-hours`.

use std::sync::OnceLock;

use aeroelastic::run::Row;

use crate::{Block, Case, Formulation};

/// Largest `newton.max_iter`.
pub const MAX_NEWTON_ITER: usize = 200;
/// Largest `newton.max_step_halvings` (a step may be cut into up to 2^this pieces).
pub const MAX_STEP_HALVINGS: usize = 12;
/// Largest `aero.coupling.max_sub_iterations`.
pub const MAX_SUB_ITERATIONS: usize = 100;
/// Largest element count of one body.
pub const MAX_ELEMENTS_PER_BODY: usize = 1_000_000;
/// Largest `aero.panels_per_body` entry.
pub const MAX_PANELS_PER_BODY: usize = 100_000;
/// Largest `aero.n_chordwise`.
pub const MAX_CHORDWISE: usize = 10_000;
/// Largest `aero.n_wake_rows`.
pub const MAX_WAKE_ROWS: usize = 1_000_000;
/// Most runs one case file may expand into (the product of its sweep's lists).
pub const MAX_SWEEP_POINTS: usize = 1_000;
/// Most bytes of case text a sweep may expand into (points × case size).
pub const MAX_SWEEP_BYTES: usize = 256 << 20;
/// Most bodies (and joints) in a case.
pub const MAX_BODIES: usize = 1_000;
/// Most entries of a case's other lists (references, gate windows, a body's point masses).
pub const MAX_LIST: usize = 10_000;
/// Largest case file, bytes.
pub const MAX_CASE_BYTES: u64 = 16 << 20;

/// The limits runs are checked against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Memory one run may take, bytes.
    pub memory_bytes: f64,
    /// Wall time one run may take, s.
    pub seconds: f64,
}

impl Limits {
    /// No limit (for an expansion whose budget is checked another way).
    pub const UNLIMITED: Limits = Limits { memory_bytes: f64::INFINITY, seconds: f64::INFINITY };
}

static LIMITS: OnceLock<Limits> = OnceLock::new();

/// Set the limits for this process (the binary's `--max-memory` and `--max-hours`); the first
/// call wins. `None` keeps the default of that limit.
pub fn set_limits(memory_gb: Option<f64>, hours: Option<f64>) {
    let d = default_limits();
    let _ = LIMITS.set(Limits {
        memory_bytes: memory_gb.map_or(d.memory_bytes, |g| g * 1e9),
        seconds: hours.map_or(d.seconds, |h| h * 3600.0),
    });
}

/// The limits in force.
pub fn limits() -> Limits {
    *LIMITS.get_or_init(default_limits)
}

fn default_limits() -> Limits {
    Limits { memory_bytes: machine_memory(), seconds: 48.0 * 3600.0 }
}

/// ¾ of the physical memory, and at most ½ of the address-space limit (heap, code, thread
/// stacks and the allocator's slack share it).
fn machine_memory() -> f64 {
    let mut m: f64 = 8e9;
    #[cfg(target_os = "linux")]
    {
        if let Ok(s) = std::fs::read_to_string("/proc/meminfo")
            && let Some(kb) = s
                .lines()
                .find(|l| l.starts_with("MemTotal:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|x| x.parse::<f64>().ok())
        {
            m = 0.75 * kb * 1024.0;
        }
        let mut r = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // SAFETY: getrlimit writes into the struct it is given.
        if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut r) } == 0 && r.rlim_cur != libc::RLIM_INFINITY {
            m = m.min(0.5 * r.rlim_cur as f64);
        }
    }
    m
}

/// The estimated cost of one formulation of a case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Unknowns of the iteration matrix.
    pub unknowns: f64,
    /// Time steps.
    pub steps: f64,
    /// Bound vortex rings (0 without aerodynamics).
    pub bound_rings: f64,
    /// Wake rings kept (0 without aerodynamics).
    pub wake_rings: f64,
    /// Memory, bytes.
    pub bytes: f64,
    /// Wall time, s.
    pub seconds: f64,
    /// Memory of the structure alone, bytes (what `elements_per_body` drives).
    pub structure_bytes: f64,
    /// Memory of the aerodynamics alone, bytes.
    pub aero_bytes: f64,
    /// Wall time of the structure alone, s.
    pub structure_seconds: f64,
}

/// The unknowns of formulation `f` of `case` (coordinates plus constraint rows).
fn unknowns(case: &Case, f: Formulation) -> f64 {
    let elements = case.block(f).elements_per_body;
    let nb = case.bodies.len();
    let nj = case.joints.len() as f64;
    let el: f64 = (0..nb).map(|i| elements.for_body(i) as f64).sum();
    aeroelastic::factory::unknowns_bound(f, el, nb as f64, nj)
}

/// Estimate formulation `f` of `case` (validated counts; every product in f64, so nothing
/// overflows), run for at most `max_steps` steps when given.
pub fn estimate(case: &Case, f: Formulation, max_steps: Option<usize>) -> Estimate {
    let Block { dt, newton, .. } = case.block(f);
    let n = unknowns(case, f);
    let mut steps = (case.t_end / dt).round().max(1.0);
    if let Some(m) = max_steps {
        steps = steps.min(m as f64);
    }
    let every = case.output_dt.map_or(1.0, |o| (o / dt).round().max(1.0));
    let rows = steps / every + 2.0;
    let structure_bytes = fallback_bytes(n)
        + 8.0 * n * 600.0
        + 8.0 * n * (newton.max_iter as f64 + 1.0)
        + rows * std::mem::size_of::<Row>() as f64;
    let (mut bound, mut wake, mut aero_bytes, mut aero_step, mut sub) = (0.0, 0.0, 0.0, 0.0, 1.0);
    if let Some(a) = &case.aero {
        let (span, rings) = a.lattice_size();
        bound = rings;
        wake = span * a.n_wake_rows as f64;
        aero_bytes = 16.0 * bound * bound + 100.0 * (bound + wake);
        aero_step = 2e-8 * bound * bound + 1e-9 * bound * bound * bound / 3.0 + 3e-8 * bound * wake;
        sub = 1.0 + a.coupling.max_sub_iterations as f64;
    }
    // A band solve and the element loops per Newton iteration, linear in n (measured on the
    // paper's pendulum with 1,000 and 2,000 elements per body: ANCF 1.3e-6 n s a step, GEBF
    // 0.6e-6 n). The consistent start costs about two steps more, and a sparse fallback's time
    // can grow as n³ (GEBF's pendulum start through faer's sparse LU: 1.7 s at 48,000
    // unknowns, 15 s at 96,000, 1.7e-14 n³ s).
    let structure_step = 5.0 * 2e-6 * n;
    let start = 4e-14 * n * n * n;
    let seconds = start + (steps + 2.0) * sub * (structure_step + aero_step);
    let structure_seconds = start + (steps + 2.0) * sub * structure_step;
    Estimate {
        unknowns: n,
        steps,
        bound_rings: bound,
        wake_rings: wake,
        bytes: structure_bytes + aero_bytes + 50e6,
        seconds,
        structure_bytes,
        aero_bytes,
        structure_seconds,
    }
}

/// Bytes of the fallback factorisation of an `n`-unknown matrix that the band storage cannot
/// take (a tiny band pivot, or an entry outside the declared structure): up to
/// [`genalpha::DENSE_FALLBACK_MAX`] unknowns the dense matrix and its LU (`2 × 8 n²`), above it
/// entries and faer's sparse LU, whose fill is counted as `n²` bytes (GEBF's pendulum start
/// through it: 0.45–0.5 n² at 24,000 to 96,000 unknowns).
fn fallback_bytes(n: f64) -> f64 {
    if n <= genalpha::DENSE_FALLBACK_MAX as f64 { 16.0 * n * n } else { n * n }
}

fn gb(x: f64) -> String {
    if x >= 1e15 {
        format!("{:.3e} GB", x / 1e9)
    } else if x >= 1e9 {
        format!("{:.3} GB", x / 1e9)
    } else {
        format!("{:.1} MB", x / 1e6)
    }
}

fn duration(s: f64) -> String {
    if s >= 3.6e9 {
        format!("{:.3e} h", s / 3600.0)
    } else if s >= 3600.0 {
        format!("{:.3} h", s / 3600.0)
    } else {
        format!("{s:.1} s")
    }
}

/// Refuse a case whose run would not fit the [`limits`]: the message names the field that drives
/// the excess and the estimate.
pub fn check(case: &Case) -> Result<(), String> {
    check_within(case, &limits(), None)
}

/// As [`check`], against `lim`, for runs of at most `max_steps` steps when given.
pub fn check_within(case: &Case, lim: &Limits, max_steps: Option<usize>) -> Result<(), String> {
    check_formulations(case, lim, max_steps, &Formulation::ALL)
}

/// As [`check_within`] for a run of the formulations `fs` only.
pub fn check_formulations(
    case: &Case,
    lim: &Limits,
    max_steps: Option<usize>,
    fs: &[Formulation],
) -> Result<(), String> {
    for &f in fs {
        let e = estimate(case, f, max_steps);
        if e.bytes > lim.memory_bytes {
            let field = if e.aero_bytes > e.structure_bytes {
                "aero.panels_per_body / aero.n_chordwise / aero.n_wake_rows".to_string()
            } else if fallback_bytes(e.unknowns) > 0.5 * e.structure_bytes {
                format!("{f}.elements_per_body")
            } else {
                format!("t_end / {f}.dt / output_dt ({:.3e} steps)", e.steps)
            };
            return Err(format!(
                "{field}: the {f} run needs an estimated {} ({:.0} unknowns, {:.0} bound and {:.0} wake rings, \
                 {:.3e} steps), more than the limit of {} (--max-memory)",
                gb(e.bytes),
                e.unknowns,
                e.bound_rings,
                e.wake_rings,
                e.steps,
                gb(lim.memory_bytes)
            ));
        }
        if e.seconds > lim.seconds {
            // The field that makes each step dear, or the step count when steps are cheap.
            let field = if e.steps > 1e4 {
                format!("t_end / {f}.dt")
            } else if 2.0 * e.structure_seconds >= e.seconds {
                format!("{f}.elements_per_body")
            } else {
                "aero.panels_per_body / aero.n_chordwise / aero.n_wake_rows".to_string()
            };
            return Err(format!(
                "{field}: the {f} run takes {:.3e} steps, an estimated {} ({:.0} unknowns, {:.0} bound \
                 rings), more than the limit of {} (--max-hours)",
                e.steps,
                duration(e.seconds),
                e.unknowns,
                e.bound_rings,
                duration(lim.seconds)
            ));
        }
    }
    Ok(())
}

/// The analyses whose cost [`estimate_analysis`] bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Analysis {
    /// `harness static`: equilibria over `static.airspeeds` (or `static.load_factors`).
    Static,
    /// `harness stability`: linearised roots over `stability.airspeeds`.
    Stability,
    /// `harness gust`: a static equilibrium, then a time march per gradient and hinge state.
    Gust,
}

impl Analysis {
    /// The command's name.
    pub fn name(self) -> &'static str {
        match self {
            Analysis::Static => "static",
            Analysis::Stability => "stability",
            Analysis::Gust => "gust",
        }
    }
}

/// Newton iterations a static point is charged (with its continuation and retries).
pub const STATIC_ITERATIONS: f64 = 40.0;
/// Evaluations of the flutter determinant charged per stability airspeed.
pub const STABILITY_EVALUATIONS: f64 = 200.0;

/// The cost of one steady lattice solve with `bound` rings and `legs` wake legs (influence
/// matrix, its LU), s, and its memory, bytes.
fn steady_solve(bound: f64, legs: f64) -> (f64, f64) {
    (2e-8 * bound * bound + 1e-9 * bound * bound * bound / 3.0 + 3e-8 * bound * legs, 16.0 * bound * bound)
}

/// Estimate analysis `a` of formulation `f` of `case` (a validated case with the analysis'
/// block), like [`estimate`] for a run: generous constants, an upper bound rather than a
/// prediction.
///
/// * static: per point [`STATIC_ITERATIONS`] residuals (a steady lattice solve each) and one
///   aerodynamic tangent (a steady solve per unknown), plus the structure's dense tangent and
///   LU; a structural case (no `aero`) 20 load steps per load factor;
/// * stability: per airspeed the static equilibrium above, the linearised lattice with its
///   frozen wake, and [`STABILITY_EVALUATIONS`] evaluations of the flutter determinant over the
///   modal basis;
/// * gust: the static equilibrium, then every run of the sweep (gradients × hinge states) as
///   a time march of `gust.t_end` ([`estimate`]).
pub fn estimate_analysis(case: &Case, f: Formulation, a: Analysis) -> Estimate {
    let n = unknowns(case, f);
    let structure_iter = 5.0 * (2e-6 * n + 4e-9 * n * n) + 2e-9 * n * n * n / 3.0;
    let structure_bytes = 3.0 * 8.0 * n * n + 8.0 * n * 600.0;
    let (mut bound, mut span) = (0.0, 0.0);
    if let Some(a) = &case.aero {
        (span, bound) = a.lattice_size();
    }
    let (solve_s, solve_bytes) = steady_solve(bound, 2.0 * span);
    let static_point = if case.aero.is_some() {
        STATIC_ITERATIONS * (solve_s + structure_iter) + n * solve_s
    } else {
        20.0 * STATIC_ITERATIONS * structure_iter
    };
    let mut e = Estimate {
        unknowns: n,
        steps: 0.0,
        bound_rings: bound,
        wake_rings: 0.0,
        bytes: structure_bytes + solve_bytes + 8.0 * n * bound + 50e6,
        seconds: 0.0,
        structure_bytes,
        aero_bytes: solve_bytes + 8.0 * n * bound,
        structure_seconds: 0.0,
    };
    match a {
        Analysis::Static => {
            let st = case.statics.as_ref();
            let points =
                st.map_or(0, |s| s.airspeeds.len().max(s.load_factors.len()).max(s.sideslips_deg.len())) as f64;
            e.seconds = points * static_point;
            e.structure_seconds = points * STATIC_ITERATIONS * structure_iter;
        }
        Analysis::Stability => {
            let Some(st) = case.stability.as_ref() else { return e };
            let points = st.airspeeds.len() as f64;
            let rows = st.wake.as_ref().map_or_else(|| case.aero.as_ref().map_or(0, |a| a.n_wake_rows), |w| w.rows);
            let wake = span * rows as f64;
            let basis = st.basis_modes.unwrap_or((2 * st.modes).max(20)) as f64;
            let lattice = 16.0 * bound * (bound + wake) + 16.0 * (bound + wake) * basis;
            let determinant = 1e-9 * (bound * bound * bound / 3.0 + bound * bound * basis + basis * basis * basis);
            let linearise = 1e-8 * (bound + wake) * (bound + wake);
            // The modal basis: once about the undeformed state, at each equilibrium otherwise.
            let modes = 2e-9 * n * n * n;
            let (per_point, once) = match st.about {
                aeroelastic::stability::About::Equilibrium => (static_point + modes, 0.0),
                aeroelastic::stability::About::Undeformed => (0.0, modes),
                // A trim is about twenty static solves (three unknowns, difference quotients).
                aeroelastic::stability::About::Trim => (20.0 * static_point + modes, 0.0),
            };
            e.wake_rings = wake;
            e.bytes += lattice + 16.0 * n * n;
            e.aero_bytes += lattice;
            e.seconds = once + points * (per_point + linearise + STABILITY_EVALUATIONS * determinant);
            e.structure_seconds = once + points * per_point;
        }
        Analysis::Gust => {
            let Some(g) = case.gust.as_ref() else { return e };
            let runs = (g.gradients_m.len().max(g.frequencies_hz.len()) * g.hinges.len()) as f64;
            let mut march = case.clone();
            if let Some(t) = g.t_end {
                march.t_end = t;
            }
            let r = estimate(&march, f, None);
            e.steps = runs * r.steps;
            e.wake_rings = r.wake_rings;
            e.bytes = e.bytes.max(r.bytes);
            e.aero_bytes = e.aero_bytes.max(r.aero_bytes);
            e.structure_bytes = e.structure_bytes.max(r.structure_bytes);
            e.seconds = static_point + runs * r.seconds;
            e.structure_seconds = runs * r.structure_seconds;
        }
    }
    e
}

/// Refuse analysis `a` of `case` when its estimate ([`estimate_analysis`]) for either
/// formulation exceeds `lim`: the message names the field to change and gives the estimate.
pub fn check_analysis(case: &Case, a: Analysis, fs: &[Formulation], lim: &Limits) -> Result<(), String> {
    for &f in fs {
        let e = estimate_analysis(case, f, a);
        let over_memory = e.bytes > lim.memory_bytes;
        if !over_memory && e.seconds <= lim.seconds {
            continue;
        }
        let field = if e.aero_bytes > e.structure_bytes && over_memory
            || !over_memory && 2.0 * e.structure_seconds < e.seconds
        {
            match a {
                Analysis::Stability => "aero.panels_per_body / aero.n_chordwise / stability.wake (or aero.n_wake_rows)",
                _ => "aero.panels_per_body / aero.n_chordwise",
            }
            .to_string()
        } else if a == Analysis::Gust && e.steps > 1e4 {
            format!("gust.t_end (or t_end) / {f}.dt / gust.gradients_m / gust.hinges")
        } else {
            format!("{f}.elements_per_body")
        };
        let points = match a {
            Analysis::Static => "static.airspeeds / static.load_factors",
            Analysis::Stability => "stability.airspeeds",
            Analysis::Gust => "gust.gradients_m / gust.hinges",
        };
        let (what, limit, flag) = if over_memory {
            (gb(e.bytes), gb(lim.memory_bytes), "--max-memory")
        } else {
            (duration(e.seconds), duration(lim.seconds), "--max-hours")
        };
        return Err(format!(
            "{field} (or fewer {points}): the {f} {} analysis needs an estimated {what} ({:.0} unknowns, {:.0} bound \
             and {:.0} wake rings), more than the limit of {limit} ({flag})",
            a.name(),
            e.unknowns,
            e.bound_rings,
            e.wake_rings
        ));
    }
    Ok(())
}

/// A short account of analysis `a`'s estimate for the formulations `fs`, for the line the
/// commands print before they start.
pub fn describe_analysis(case: &Case, a: Analysis, fs: &[Formulation]) -> String {
    let parts: Vec<String> = fs
        .iter()
        .map(|&f| {
            let e = estimate_analysis(case, f, a);
            format!("{f} at most ~{}, {}", duration(e.seconds), gb(e.bytes))
        })
        .collect();
    parts.join("; ")
}

#[cfg(test)]
mod tests {
    use super::unknowns;
    use crate::{CaseFile, Formulation};
    use aeroelastic::factory::{BuildModel, ForModel, dispatch};

    /// The built model's unknowns.
    struct Count(aeroelastic::Problem);
    impl ForModel for Count {
        type Output = usize;
        fn run<M: BuildModel>(self) -> usize {
            M::build(&self.0).map_or(0, |m| m.n_unknowns())
        }
    }

    /// The budget's count bounds every shipped case's model from above and within 25 %, so that
    /// it neither lets an oversized case through nor refuses a fitting one.
    #[test]
    fn unknowns_bound_every_case_model_closely() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases");
        let mut checked = 0;
        for e in std::fs::read_dir(&dir).unwrap() {
            let path = e.unwrap().path();
            if path.extension().is_none_or(|x| x != "json") || path.ends_with("case.schema.json") {
                continue;
            }
            let spec = CaseFile::read(&path).unwrap().expand(&[]).unwrap().remove(0);
            for f in Formulation::ALL {
                let case = spec.case(f);
                let (built, bound) = (dispatch(f, Count(case.problem())), unknowns(case, f));
                assert!(built > 0, "{}: {f} does not build", path.display());
                let ratio = bound / built as f64;
                assert!((1.0..=1.25).contains(&ratio), "{} {f}: bound {bound} for {built} unknowns", path.display());
                checked += 1;
            }
        }
        assert!(checked >= 30, "only {checked} models checked");
    }
}
