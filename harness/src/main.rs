//! `harness`: run both formulations on the case files, compare, report, gate.
//!
//! One function per subcommand (`cmd_*`), each over the argument structs the subcommands share
//! (`CaseSource`, `OutOpt`, `SetOpt`, `ShardOpt`, `AnalysisArgs`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};

use harness::budget::Analysis;
use harness::case::{CaseFile, Formulation, Override, RunSpec, json_schema};
use harness::console::Lines;
use harness::driver::{
    any_interrupted, claim_outputs, discover, expand_all, finish_case, limit_steps, run_all, run_into, variant_name,
    write_index,
};
use harness::progress::Progress;
use harness::shard::{Plan, ShardArg, Unit, run_unit, runs_here};
use harness::{bench, converge, energy, gate, stress};

#[derive(Parser)]
#[command(
    name = "harness",
    version,
    about = "flexmb: nonlinear aeroelasticity of flared folding wingtips, two beam formulations (ANCF / GEBF) side by side"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
    /// Memory one run may take, GB (default: ¾ of the machine's memory, at most ½ of the
    /// address-space limit); a case estimated above it is refused (exit 2).
    #[arg(long, global = true, value_name = "GB")]
    max_memory: Option<f64>,
    /// Wall time one run may take, hours (default 48); a case estimated above it is refused.
    #[arg(long, global = true, value_name = "HOURS")]
    max_hours: Option<f64>,
}

/// `--shard` of the commands that expand sweeps (`#[command(flatten)] shard: ShardOpt`).
#[derive(Args, Clone, Copy)]
struct ShardOpt {
    /// Run only shard k of N of the command's runs (1-based; runs dealt by estimated cost, the
    /// same way in every shard), or `slurm` for the task's share of a job array
    /// (SLURM_ARRAY_TASK_ID/COUNT). Each shard writes its own runs; `harness merge` makes the report.
    #[arg(long, value_name = "k/N|slurm")]
    shard: Option<ShardArg>,
}

/// `--set` of every command that reads case files.
#[derive(Args, Clone)]
struct SetOpt {
    /// Override a case value: `[ancf:|gebf:]path=value`, e.g. `t_end=0.5`,
    /// `gebf:joints.1.flare_deg=40`, `pitch_deg=5` or `gust.gradients_m=[30]`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<Override>,
}

/// `--out` of the commands that write a report (default `reports`).
#[derive(Args, Clone)]
struct OutOpt {
    /// Output folder.
    #[arg(long, default_value = "reports")]
    out: PathBuf,
}

/// `--cases` of the commands that discover case files.
#[derive(Args, Clone)]
struct CaseSource {
    /// Folder of case files.
    #[arg(long, default_value = "cases")]
    cases: PathBuf,
}

/// `--formulation`: one formulation by name, or `both`.
#[derive(Clone, Debug)]
struct Which(Vec<Formulation>);

impl Which {
    /// The formulations this choice runs.
    fn formulations(&self) -> Vec<Formulation> {
        self.0.clone()
    }
    /// The parser of `--formulation`: the formulations' names or `both` (listed in the help and
    /// in the error of any other value).
    fn parser() -> impl clap::builder::TypedValueParser<Value = Which> {
        use clap::builder::TypedValueParser as _;
        let names = Formulation::ALL.map(Formulation::as_str).into_iter().chain(["both"]);
        clap::builder::PossibleValuesParser::new(names)
            .map(|s: String| Which(Formulation::from_name(&s).map_or_else(|| Formulation::ALL.to_vec(), |f| vec![f])))
    }
}

/// The arguments of the analyses (`static`, `stability`, `gust`).
#[derive(Args, Clone)]
struct AnalysisArgs {
    /// Case file (with the analysis' block: `static`, `stability` or `gust`).
    case: PathBuf,
    /// Formulation(s) to run.
    #[arg(long, value_parser = Which::parser(), default_value = "both")]
    formulation: Which,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
    #[command(flatten)]
    shard: ShardOpt,
}

/// `harness trim`.
#[derive(Args, Clone)]
struct TrimArgs {
    /// Case file (with a `trim` block, a free joint, `aero` and `thrust`).
    case: PathBuf,
    /// Formulation(s) to trim.
    #[arg(long, value_parser = Which::parser(), default_value = "both")]
    formulation: Which,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
}

/// `harness all`.
#[derive(Args)]
struct AllArgs {
    #[command(flatten)]
    cases: CaseSource,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
    /// Skip the refinement ladders, the stress matrix and the speed benchmark (cases only).
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    shard: ShardOpt,
}

/// `harness run`.
#[derive(Args)]
struct RunArgs {
    /// Case file.
    case: PathBuf,
    /// Formulation(s) to run.
    #[arg(long, value_parser = Which::parser(), default_value = "both")]
    formulation: Which,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
    /// Also write ParaView files (beams with section frames, chord ribbon, vortex lattice, wake;
    /// .vtp plus a .pvd time series per family) to `<out>/<case>/vtk/<formulation>/`; a case
    /// with a `vtk` block writes them without the flag.
    #[arg(long)]
    vtk: bool,
    /// With --vtk, write every N-th output step (default: the case's `vtk.stride`, else about
    /// 100 frames per run, max(1, output rows / 100)).
    #[arg(long, value_name = "N", requires = "vtk")]
    vtk_stride: Option<usize>,
    /// Stop each run after N steps (a smoke test; the folder name says so).
    #[arg(long, value_name = "N")]
    max_steps: Option<usize>,
}

/// `harness fuzz`.
#[derive(Args)]
struct FuzzArgs {
    /// Folder of seed case files (with their `reference/`).
    #[arg(long, default_value = "cases")]
    cases: PathBuf,
    /// Output folder.
    #[arg(long, default_value = "reports/fuzz")]
    out: PathBuf,
    /// Number of inputs.
    #[arg(long, default_value_t = 100_000)]
    inputs: usize,
    /// Index of the first input (to continue a campaign with the same seed).
    #[arg(long, default_value_t = 0)]
    first: usize,
    /// Seed of the mutations.
    #[arg(long, default_value_t = 19)]
    seed: u64,
    /// Inputs run at once.
    #[arg(long, default_value_t = 2)]
    jobs: usize,
    /// Time limit of one input, s of CPU time (and 6 × this of wall time).
    #[arg(long, default_value_t = 20)]
    timeout: u64,
    /// Address-space limit of one input, GB.
    #[arg(long, default_value_t = 4)]
    address_space_gb: u64,
    /// Steps each run of an input takes at most.
    #[arg(long, default_value_t = 3)]
    max_steps: usize,
    /// Children run `harness run` (every output file written) instead of `harness check`.
    #[arg(long)]
    run: bool,
    /// A new process per input (`harness check`) instead of long-lived worker processes
    /// (each still under the limits, restarted after any crash or hang).
    #[arg(long)]
    exec_each: bool,
}

/// `harness check`.
#[derive(Args)]
struct CheckArgs {
    /// Case file.
    case: PathBuf,
    /// Steps each run takes at most.
    #[arg(long, default_value_t = 3)]
    max_steps: usize,
}

/// `harness gate` and `harness bench`: explicit case files, else the ones discovered.
#[derive(Args)]
struct FilesArgs {
    /// Case files (default: the cases in --cases the command applies to).
    files: Vec<PathBuf>,
    #[command(flatten)]
    cases: CaseSource,
    #[command(flatten)]
    set: SetOpt,
}

/// `harness converge` and `harness stress`: one case file, sharded.
#[derive(Args)]
struct StudyArgs {
    /// Case file.
    case: PathBuf,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
    #[command(flatten)]
    shard: ShardOpt,
}

/// `harness stress`: as [`StudyArgs`], with the paper's pendulum as the default base case.
#[derive(Args)]
struct StressArgs {
    /// Base case file.
    #[arg(default_value = "cases/double_pendulum_c1_beta45.json")]
    case: PathBuf,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
    #[command(flatten)]
    shard: ShardOpt,
}

/// `harness energy`.
#[derive(Args)]
struct EnergyArgs {
    #[command(flatten)]
    cases: CaseSource,
    #[command(flatten)]
    out: OutOpt,
    #[command(flatten)]
    set: SetOpt,
}

/// `harness bench`.
#[derive(Args)]
struct BenchArgs {
    #[command(flatten)]
    files: FilesArgs,
    /// Timed runs per configuration.
    #[arg(long, default_value_t = 7)]
    repeats: usize,
    /// Time the aerodynamics instead: the coupled step of the paper's and Healy's wings against
    /// the wake's length (direct and treecode), a 20 s wing run, Healy's static and gust sweeps
    /// and a flutter sweep, from the case files in `--cases`; writes `<out>/bench/aero.*`.
    #[arg(long)]
    aero: bool,
    #[command(flatten)]
    out: OutOpt,
}

/// `harness healy-readings`.
#[derive(Args)]
struct ReadingsArgs {
    #[command(flatten)]
    cases: CaseSource,
    #[command(flatten)]
    out: OutOpt,
    /// Formulation (ANCF and GEBF agree on these equilibria to 1e-3°; one is enough).
    #[arg(long, value_parser = Which::parser(), default_value = "gebf")]
    formulation: Which,
}

/// `harness merge`.
#[derive(Args)]
struct MergeArgs {
    /// The shards' output folders (each holds `shards/*.json`; shards may share one).
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    #[command(flatten)]
    out: OutOpt,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run every case with both formulations; write reports/ (CSV, summary.json, SVG, index.html, summary.md).
    All(AllArgs),
    /// Run one case file.
    Run(RunArgs),
    /// Fuzz campaign: mutants of the case files, each run in its own process (`run --max-steps`)
    /// under a time and an address-space limit, classified by outcome; writes `<out>/fuzz.json`,
    /// `fuzz.md` and every crashing input under `crashes/`.
    Fuzz(FuzzArgs),
    /// The worker of `harness fuzz`: reads input paths from stdin, answers one line each.
    #[command(hide = true)]
    FuzzWorker {
        /// Steps each run takes at most.
        #[arg(long, default_value_t = 3)]
        max_steps: usize,
    },
    /// Check a case file: parse, validate, build both formulations and run each at most
    /// `--max-steps` steps, writing nothing; exit 0 (runs), 1 (a run failed), 2 (bad input).
    Check(CheckArgs),
    /// Run the gated cases and check their tolerances; exit 1 when any case fails.
    Gate(FilesArgs),
    /// Refinement ladders (time, space, both) for each formulation: error against wall time;
    /// writes `<out>/converge/<case>/`.
    Converge(StudyArgs),
    /// The stress matrix (c × β × dt × rho_inf) on a base case, for both formulations; writes
    /// `<out>/stress/`.
    Stress(StressArgs),
    /// Energy at rho_inf = 1 of the c = 1 pendulums, each formulation in both generalized-α forms
    /// (Arnold–Brüls, Chung–Hulbert), at dt and dt/2; writes `<out>/energy/` (energy.md, energy.csv,
    /// energy.svg).
    Energy(EnergyArgs),
    /// Time each formulation on each case (median thread CPU time of repeated serial runs, ANCF on
    /// both paths) with the work per step; writes `<out>/bench/` (bench.md, bench.json, bench.svg).
    Bench(BenchArgs),
    /// Static aeroelastic equilibria over the case's `static.airspeeds` (or, for a case without
    /// `aero`, the equilibria under its `static.point_loads` at `static.load_factors`); writes
    /// `<out>/<case>/static_{ancf,gebf}.csv`, `static_lift_*.csv`, `static_summary.json` and plots.
    Static(AnalysisArgs),
    /// Healy's experiment under every reading of issue 37 (lattice / strips / strips with tip
    /// loss × polars × geometry): RMS per curve, coast-angle change per 5° of pitch and the
    /// level-coast pitch; writes `<out>/healy_readings.csv` and the report's section.
    HealyReadings(ReadingsArgs),
    /// Merge the outputs of the shards of a sweep (`--shard`) into one report and summary; exits 1
    /// naming the runs no shard finished.
    Merge(MergeArgs),
    /// Linearised stability over the case's `stability.airspeeds` (flutter, divergence, modes);
    /// writes `<out>/<case>/stability_{ancf,gebf}.csv`, `.json`, plots and a report fragment.
    Stability(AnalysisArgs),
    /// Gust sweep over the case's `gust` block (gradients x hinge states) from the static
    /// equilibrium; writes `<out>/<case>/gust_{ancf,gebf}.csv`, `gust_history_*.csv`,
    /// `gust_summary.json` and plots (docs/gust.md).
    Gust(AnalysisArgs),
    /// Trim a free aircraft in steady level flight (the case's `trim` block): angle of attack,
    /// elevator deflection and thrust with no net force and pitching moment; writes
    /// `<out>/<case>/trim_{ancf,gebf}.json` (docs/trim.md).
    Trim(TrimArgs),
    /// List the runs the case files expand into.
    List(CaseSource),
    /// Print the JSON Schema of case files.
    Schema,
}

/// Repeats of each timed run of the benchmark in `harness all`.
const BENCH_REPEATS: usize = 7;

/// Run the benchmark on `runs` and write `dir` (`<out>/bench/`); the targets apply to the cases without
/// aerodynamics (the issues' figures are for the paper's pendulums).
fn run_bench(runs: &[RunSpec], repeats: usize, dir: &Path) -> Result<Vec<bench::BenchRow>> {
    let t = std::time::Instant::now();
    let rows = bench::run(runs, repeats, true);
    write_bench(runs, repeats, &rows, dir, t)?;
    Ok(rows)
}

/// Write the benchmark's `rows` of `runs` (begun at `t`) to `dir` and print its time.
fn write_bench(
    runs: &[RunSpec],
    repeats: usize,
    rows: &[bench::BenchRow],
    dir: &Path,
    t: std::time::Instant,
) -> Result<()> {
    let pendulums: Vec<&str> = runs.iter().filter(|r| r.ancf.aero.is_none()).map(|r| r.name.as_str()).collect();
    bench::write(dir, rows, |c| pendulums.contains(&c))?;
    println!("bench: {} configurations x {repeats} runs in {:.1} s", rows.len(), t.elapsed().as_secs_f64());
    Ok(())
}

/// Run the energy study on the c = 1 pendulums among `runs` (none when there are none); the
/// runs and the wall time, s.
fn energy_study(runs: &[RunSpec]) -> (Vec<energy::EnergyRun>, f64) {
    let t = std::time::Instant::now();
    let specs = energy::select(runs);
    let study = if specs.is_empty() { Vec::new() } else { energy::run(&specs) };
    (study, t.elapsed().as_secs_f64())
}

/// Write the energy study (`secs` s of wall time) to `dir` (`<out>/energy/`) and keep the drifts
/// in `lines`; returns whether every run reached its end (true when there was nothing to study).
fn energy_report(study: &[energy::EnergyRun], secs: f64, dir: &Path, lines: &mut Lines) -> Result<bool> {
    if study.is_empty() {
        lines.out("energy study: no c = 1 pendulum (no aerodynamics) among the cases; nothing written");
        return Ok(true);
    }
    energy::write(dir, study)?;
    for r in study {
        let m = &r.metrics;
        lines.out(format!(
            "energy {} {} {}: {}",
            r.case,
            r.formulation,
            r.form.label(),
            m.error.as_ref().map_or_else(
                || format!(
                    "drift {:.2e} of the peak kinetic energy, {:.2} Newton/step",
                    m.energy_drift, m.newton_per_step
                ),
                |e| format!("FAILED: {e}")
            )
        ));
    }
    lines.out(format!("energy study: {} runs in {secs:.1} s", study.len()));
    Ok(study.iter().all(|r| r.metrics.error.is_none()))
}

/// The extra hard runs of the stress study: a 20 s pendulum and the wing at AoA 15°.
fn stress_extras(dir: &Path, set: &[Override]) -> Result<Vec<(String, RunSpec)>> {
    let mut v = Vec::new();
    let pend = dir.join("double_pendulum_c1_beta45.json");
    if pend.exists() {
        let mut ov = set.to_vec();
        ov.push("t_end=20".parse()?);
        ov.push("output_dt=0.01".parse()?);
        v.push(("pendulum c=1 beta=45 deg, 20 s".to_string(), CaseFile::read(&pend)?.expand(&ov)?.remove(0)));
    }
    let wing = dir.join("wing_aoa10.json");
    if wing.exists() {
        let mut ov = set.to_vec();
        ov.push("pitch_deg=15".parse()?);
        v.push(("wing AoA 15 deg, 20 s".to_string(), CaseFile::read(&wing)?.expand(&ov)?.remove(0)));
    }
    Ok(v)
}

/// The stability sweeps of `spec` with the formulations `fs`, in parallel.
fn run_stability_case(spec: &RunSpec, fs: &[Formulation]) -> Vec<harness::stability::StabilityOutput> {
    use rayon::prelude::*;
    fs.par_iter().map(|&f| harness::stability::run_stability(&spec.case(f).problem(), f)).collect()
}

/// Keep a stability sweep's results in `lines`; true when a point failed.
fn report_stability(name: &str, outs: &[harness::stability::StabilityOutput], lines: &mut Lines) -> bool {
    let mut failed = false;
    for o in outs {
        if let Some(e) = &o.error {
            lines.err(format!("stability {name} {}: {e}", o.formulation));
            failed = true;
            continue;
        }
        let bad = o.points.iter().filter(|p| p.error.is_some()).count();
        let unconverged = harness::stability_out::unconverged_roots(o);
        if unconverged > 0 {
            lines.err(format!(
                "stability {name} {}: WARNING: {unconverged} root(s) did not converge; the flutter and divergence \
                 speeds may be wrong (stability_{}.json: \"roots_converged\": false)",
                o.formulation, o.formulation
            ));
        }
        for p in o.points.iter().filter(|p| p.error.is_some()) {
            lines.err(format!(
                "stability {name} {} at {} m/s: {}",
                o.formulation,
                p.airspeed,
                p.error.as_deref().unwrap_or("")
            ));
        }
        failed |= bad > 0;
        let f = |x: Option<f64>| x.map_or_else(|| "none".to_string(), |v| format!("{v:.3}"));
        lines.out(format!(
            "stability {name} {}: flutter {} m/s at {} rad/s, divergence {} m/s; {} points ({} failed, {} unconverged roots), basis {} of {} free motions, {} + {} rings, build {:.3} s, roots {:.3} s, {} D(s) evaluations",
            o.formulation,
            f(o.flutter_speed),
            f(o.flutter_frequency_rad_s),
            f(o.divergence_speed),
            o.points.len(),
            bad,
            unconverged,
            o.n_basis,
            o.n_free,
            o.n_rings,
            o.n_wake_rings,
            o.build_s,
            o.solve_s,
            o.n_evaluations
        ));
    }
    failed
}

/// The gust sweep of one run specification (of case file `file`) with the formulations `fs`.
fn gust_sweep(spec: &RunSpec, fs: &[Formulation], file: &str) -> Result<harness::gust_out::GustSummary> {
    let sweep = spec.gust_sweep(fs).map_err(|msg| harness::Error::Case { file: file.to_string(), msg })?;
    Ok(harness::gust_out::summarise(sweep))
}

/// Write a gust sweep of `spec` to `<out>/<case>/` and keep its lines; true when a run of the
/// sweep failed.
fn gust_report(
    spec: &RunSpec,
    fs: &[Formulation],
    summary: &harness::gust_out::GustSummary,
    out: &Path,
    lines: &mut Lines,
) -> Result<bool> {
    let mut failed = false;
    let dir = out.join(&spec.name);
    harness::gust_out::write(&dir, summary)?;
    for r in &summary.runs {
        match &r.error {
            Some(e) => {
                failed = true;
                lines.err(format!(
                    "gust {} {} {} H = {} m: FAILED: {e}",
                    spec.name,
                    r.formulation,
                    r.hinge.label(),
                    r.gradient_m
                ));
            }
            None => lines.out(format!(
                "gust {} {} {:<6} H = {:>8.3} m ({:.3} Hz, {:.3} m/s): peak dM_root {:>11.5} N m at {:.2} s, peak dfold {:>8.3} deg, {:.2} s CPU",
                spec.name,
                r.formulation,
                r.hinge.label(),
                r.gradient_m,
                r.frequency_hz,
                r.gust_velocity,
                r.peak_delta_root_bending_moment.0,
                r.peak_delta_root_bending_moment.1,
                r.peak_delta_fold_deg.0,
                r.cpu_s
            )),
        }
    }
    for a in &summary.alleviation {
        lines.out(format!(
            "  {} {} H = {:.3} m: alleviation {:.1} %",
            a.formulation,
            a.hinge.label(),
            a.gradient_m,
            a.root_bending_moment_percent
        ));
    }
    let pair = match (summary.max_peak_rbm_difference_percent, summary.max_peak_fold_difference_deg) {
        (Some(m), Some(f)) => format!("ANCF-GEBF peak dM_root within {m:.3} %, peak fold within {f:.3} deg"),
        _ if fs.len() == 2 => "ANCF-GEBF: no pair of runs both formulations finished".into(),
        _ => "one formulation".into(),
    };
    lines.out(format!(
        "gust {}: {pair}; {} run(s) failed; sweep {:.1} s wall",
        spec.name, summary.n_failed, summary.wall_s
    ));
    lines.out(format!("wrote {}", dir.display()));
    Ok(failed)
}

/// Rough multiples of one run's estimated cost for the studies of `harness all` (only the ratios
/// between units matter to [`harness::shard::assign`]): a refinement ladder set, the energy study
/// (both forms at dt and dt/2) and the benchmark (7 serial repeats, ANCF on two paths).
const LADDER_COST: f64 = 30.0;
const ENERGY_COST: f64 = 6.0;
const BENCH_COST: f64 = 10.0;

/// Every unit of work of `harness all`: each case run (with its static sweep), and unless
/// `quick` each refinement ladder, stress cell and extra run, the energy study and the benchmark.
fn all_units(
    runs: &[RunSpec],
    quick: bool,
    stress_base: Option<&RunSpec>,
    axes: &stress::Axes,
    extras: &[(String, RunSpec)],
) -> Vec<Unit> {
    use harness::shard::run_cost;
    let mut u: Vec<Unit> = runs.iter().map(|r| Unit { id: run_unit(&r.name), cost: run_cost(r) }).collect();
    if quick {
        return u;
    }
    for r in runs.iter().filter(|r| r.ancf.converge) {
        u.push(Unit { id: format!("converge:{}", r.name), cost: LADDER_COST * run_cost(r) });
    }
    if let Some(base) = stress_base {
        u.extend(stress_units(base, axes, extras));
    }
    let energy: f64 = energy::select(runs).iter().map(run_cost).sum();
    u.push(Unit { id: "energy".into(), cost: ENERGY_COST * energy });
    let bench: f64 = runs.iter().filter(|r| r.ancf.aero.is_none()).map(run_cost).sum();
    u.push(Unit { id: "bench".into(), cost: BENCH_COST * bench });
    u
}

/// The units of the stress study: every cell of the matrix, then each extra run.
fn stress_units(base: &RunSpec, axes: &stress::Axes, extras: &[(String, RunSpec)]) -> Vec<Unit> {
    let mut u: Vec<Unit> =
        stress::jobs(axes).iter().map(|j| Unit { id: stress::job_id(j), cost: stress::job_cost(base, j) }).collect();
    u.extend(extras.iter().map(|(l, r)| Unit { id: harness::merge::extra_unit(l), cost: harness::shard::run_cost(r) }));
    u
}

/// Run this shard's cells and extra runs of the stress study (all of them without a plan),
/// adding their units to `done`, with their progress on `progress`.
fn run_stress(
    base: &RunSpec,
    axes: &stress::Axes,
    extras: &[(String, RunSpec)],
    plan: Option<&Plan>,
    done: &mut Vec<String>,
    progress: &Progress,
) -> (Vec<stress::Cell>, Vec<stress::Extra>) {
    let jobs: Vec<stress::Job> =
        stress::jobs(axes).into_iter().filter(|j| runs_here(plan, &stress::job_id(j))).collect();
    let mine: Vec<_> =
        extras.iter().filter(|(l, _)| runs_here(plan, &harness::merge::extra_unit(l))).cloned().collect();
    // The extra runs are long (a 20 s run whose recovery with step control takes minutes): they
    // start at once beside the matrix, whose short cells fill the other threads meanwhile.
    let (ex, cells) = rayon::join(|| stress::run_extras(&mine, progress), || stress::run_jobs(base, &jobs, progress));
    done.extend(jobs.iter().map(stress::job_id));
    done.extend(mine.iter().map(|(l, _)| harness::merge::extra_unit(l)));
    (cells, ex)
}

/// The static sweeps of `spec` with the formulations `fs`, in parallel, summarised.
fn run_static_case(spec: &RunSpec, fs: &[Formulation]) -> harness::static_out::StaticSummary {
    use rayon::prelude::*;
    let outs: Vec<_> = fs.par_iter().map(|&f| harness::statics::run_static(&spec.case(f).problem(), f)).collect();
    let mut summary = harness::static_out::summarise(&spec.ancf, &spec.dir, outs);
    harness::static_out::hold_references(spec, &mut summary);
    summary
}

/// Keep a sweep's outcome in `lines`; true when a point (or a point of the model held at the
/// experiment) failed.
fn report_static(s: &harness::static_out::StaticSummary, lines: &mut Lines) -> bool {
    let structural = s.runs.iter().flat_map(|r| &r.points).any(|p| p.load_factor.is_some());
    for r in &s.runs {
        let ok = r.points.iter().filter(|p| p.error.is_none()).count();
        lines.out(format!(
            "static {} {}: {ok} of {} {} in {:.3} s ({} steady solves, {} aerodynamic tangents, {} unknowns)",
            s.name,
            r.formulation,
            r.points.len(),
            if structural { "load factors" } else { s.abscissa.plural() },
            r.wall_s,
            r.n_aero_solves,
            r.n_tangents,
            r.n_dof
        ));
        for p in &r.points {
            if let Some(lf) = p.load_factor {
                // A structural static case: tip positions at the load factors.
                match &p.error {
                    Some(e) => lines.err(format!("  load factor {lf}: FAILED: {e}")),
                    None => lines.out(format!(
                        "  load factor {lf:>6}  tip ({:.4}, {:.4}, {:.4})  ({} Newton)",
                        p.tip[0], p.tip[1], p.tip[2], p.newton_iterations
                    )),
                }
                continue;
            }
            let at = match s.abscissa {
                harness::static_out::Abscissa::Airspeed => format!("{:>5} m/s", p.airspeed),
                harness::static_out::Abscissa::Sideslip => format!("{:>5} deg sideslip", p.sideslip_deg),
            };
            match &p.error {
                Some(e) => lines.err(format!("  {at}: FAILED: {e}")),
                None => lines.out(format!(
                    "  {at}  fold {:>8.3} deg  RBM {:>9.5} N m  torque {:>9.5} N m  hinge {:>9.2e} N m  lift {:>8.4} N  ({} Newton)",
                    p.fold_deg,
                    p.loads.root_bending_moment,
                    p.loads.root_torque,
                    p.loads.hinge_moment,
                    p.lift,
                    p.newton_iterations
                )),
            }
        }
    }
    let band = s.abscissa.band_text();
    for r in &s.references {
        for (f, rms) in &r.rms_deg {
            match rms {
                Some(rms) => {
                    lines.out(format!("static {} {f}: RMS error against {} = {rms:.2} deg (over {band})", s.name, r.label))
                }
                None => lines.out(format!(
                    "static {} {f}: no RMS error against {}: no equilibrium at its points in {band} ({f} failed, see below)",
                    s.name, r.label
                )),
            }
        }
    }
    let mut held_failed = false;
    for h in &s.held {
        held_failed |= h.error.is_some();
        match &h.error {
            Some(e) => lines.err(format!(
                "static {} {}: held at {} deg at {} m/s: FAILED: {e}",
                s.name, h.formulation, h.coast_deg, h.airspeed
            )),
            None => lines.out(format!(
                "static {} {}: held at the measured {:.2} deg at {} m/s: hinge moment {:+.5} N m ({:+.3e} m^3 x q), equivalent pitch {:+.2} deg",
                s.name,
                h.formulation,
                h.coast_deg,
                h.airspeed,
                h.hinge_moment,
                h.per_dynamic_pressure,
                h.equivalent_pitch_deg
            )),
        }
    }
    for c in &s.history {
        lines.out(format!(
            "static {} {}: time history mean over {:.0}-{:.0} s: tip z {:.4} m, fold {:.3} deg; static {:.4} m ({:+.2} %), {:.3} deg ({:+.3} deg)",
            s.name,
            c.formulation,
            c.window.0,
            c.window.1,
            c.tip_z_mean,
            c.fold_mean_deg,
            c.static_tip_z,
            100.0 * c.tip_z_relative_difference,
            c.static_fold_deg,
            c.fold_difference_deg
        ));
        match &c.run_wake_error {
            Some(e) => lines.out(format!(
                "static {} {}: static with the run's wake ({}) failed: {e}",
                s.name,
                c.formulation,
                harness::static_out::wake_label(&c.run_wake)
            )),
            None => lines.out(format!(
                "static {} {}: static with the run's wake ({}): {:.4} m ({:+.2} %), {:.3} deg ({:+.3} deg)",
                s.name,
                c.formulation,
                harness::static_out::wake_label(&c.run_wake),
                c.run_wake_static_tip_z,
                100.0 * c.run_wake_tip_z_relative_difference,
                c.run_wake_static_fold_deg,
                c.run_wake_fold_difference_deg
            )),
        }
    }
    if let (true, [a, g]) = (structural, s.runs.as_slice()) {
        let d = a
            .points
            .iter()
            .zip(&g.points)
            .filter(|(pa, pg)| pa.error.is_none() && pg.error.is_none())
            .map(|(pa, pg)| (0..3).map(|i| (pa.tip[i] - pg.tip[i]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        lines.out(format!("static {}: ANCF-GEBF max tip distance {d:.4e} m", s.name));
    } else if s.runs.len() == 2 {
        match (s.max_fold_difference_deg, s.max_rbm_relative_difference) {
            (Some(d), Some(r)) => lines.out(format!(
                "static {}: ANCF-GEBF max fold difference {d:.4} deg, max root bending moment difference {:.3} % \
                 (over the points both solved)",
                s.name,
                100.0 * r
            )),
            _ => lines
                .out(format!("static {}: ANCF-GEBF: no comparison, no airspeed has an equilibrium in both", s.name)),
        }
    }
    for f in &s.failures {
        lines.err(format!("static {}: FAILED: {}", s.name, f.text()));
    }
    s.n_failed > 0 || held_failed || s.runs.iter().any(|r| r.error.is_some())
}

/// 2 when any input was bad (whatever else happened), else 1 when a run or a gate failed.
fn exit_code<E>(input_errors: &[E], ok: bool) -> ExitCode {
    if !input_errors.is_empty() {
        ExitCode::from(2)
    } else if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn main() -> ExitCode {
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            // A signal that ended a wait (a folder lock) is an interruption, not bad input.
            if harness::signal::interrupted() {
                return ExitCode::from(harness::signal::EXIT_INTERRUPTED);
            }
            ExitCode::from(2)
        }
    }
}

/// Claim the runs' output folders, run them streaming their CSVs, write their files; returns the
/// results and whether a signal stopped them.
fn run_and_write(
    runs: &[RunSpec],
    fs: &[Formulation],
    out: &Path,
    progress: &Progress,
    observer: &(dyn Fn(&RunSpec, Formulation) -> Box<dyn harness::run::Observer> + Sync),
) -> Result<(Vec<harness::report::CaseResult>, bool)> {
    let (_locks, dirs) = claim_outputs(out, runs)?;
    let results = run_into(runs, fs, Some(&dirs), progress, observer);
    for (r, dir) in results.iter().zip(&dirs) {
        finish_case(dir, r).with_context(|| format!("writing {}", dir.display()))?;
    }
    let interrupted = any_interrupted(&results);
    Ok((results, interrupted))
}

/// The runs renamed after their variant (`--set`, one formulation, `--max-steps`).
fn variants(mut runs: Vec<RunSpec>, set: &[Override], fs: &[Formulation], max_steps: Option<usize>) -> Vec<RunSpec> {
    for r in &mut runs {
        r.name = variant_name(&r.name, set, fs);
        if let Some(n) = max_steps {
            r.name.push_str(&format!("__max-steps-{n}"));
            limit_steps(r, n);
        }
    }
    runs
}

/// The runs of an analysis's case file, each checked for the analysis' block (`has_block`, else
/// exit 2 with `missing`) and against the budget with the analysis' estimate (exit 2 naming the
/// field to change), and the shard plan over them.
fn analysis_runs(
    a: &AnalysisArgs,
    analysis: Analysis,
    has_block: impl Fn(&RunSpec) -> bool,
    missing: &str,
) -> Result<(Vec<RunSpec>, Option<Plan>)> {
    let kind = analysis.name();
    let fs = a.formulation.formulations();
    let file = CaseFile::read(&a.case)?;
    // The block first: a case without it has nothing to estimate.
    let runs = file.expand_for(&a.set.set, &harness::budget::Limits::UNLIMITED, None, &fs)?;
    if runs.iter().all(&has_block) {
        file.expand_for_analysis(&a.set.set, &harness::budget::limits(), analysis, &fs)?;
    }
    if !runs.iter().all(has_block) {
        let file = a.case.display().to_string();
        return Err(harness::Error::Case { file, msg: format!("{kind}: {missing}") }.into());
    }
    let plan = harness::shard::plan(kind, a.shard.shard, || {
        runs.iter().map(|r| Unit { id: format!("{kind}:{}", r.name), cost: harness::shard::run_cost(r) }).collect()
    })?;
    Ok((runs, plan))
}

/// Run `each` on the runs of this shard (`<kind>:<name>` units), then write the shard's manifest;
/// exit 1 when `each` reports a failure for any run.
fn analysis_loop(
    analysis: Analysis,
    fs: &[Formulation],
    runs: &[RunSpec],
    plan: Option<&Plan>,
    out: &Path,
    mut each: impl FnMut(&RunSpec) -> Result<bool>,
) -> Result<ExitCode> {
    let kind = analysis.name();
    let mut failed = false;
    let mut done = Vec::new();
    for spec in runs.iter().filter(|r| runs_here(plan, &format!("{kind}:{}", r.name))) {
        let bound: f64 =
            fs.iter().map(|&f| harness::budget::estimate_analysis(spec.case(f), f, analysis).seconds).sum();
        eprintln!(
            "{kind} {}: estimate {}",
            spec.name,
            harness::budget::describe_analysis(spec.case(fs[0]), analysis, fs)
        );
        let beat = harness::progress::Heartbeat::start(format!("{kind} {}", spec.name), bound);
        failed |= each(spec)?;
        drop(beat);
        done.push(format!("{kind}:{}", spec.name));
        if harness::signal::interrupted() {
            eprintln!("interrupted: the sweeps finished so far are written");
            return Ok(ExitCode::from(harness::signal::EXIT_INTERRUPTED));
        }
    }
    if let Some(p) = plan {
        p.write_manifest(out, serde_json::json!({}), &done)?;
    }
    Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// `harness static`: every run of the case file through its static sweep; exit 2 without a
/// `static` block, 1 when a point failed.
fn cmd_static(a: &AnalysisArgs) -> Result<ExitCode> {
    let missing = "the case has no `static` block (airspeeds to sweep)";
    let (runs, plan) = analysis_runs(a, Analysis::Static, |r| r.ancf.statics.is_some(), missing)?;
    let fs = a.formulation.formulations();
    let out = &a.out.out;
    analysis_loop(Analysis::Static, &fs, &runs, plan.as_ref(), out, |spec| {
        let summary = run_static_case(spec, &fs);
        let dir = out.join(&spec.name);
        harness::static_out::write(&dir, &summary)?;
        let mut lines = Lines::new();
        let failed = report_static(&summary, &mut lines);
        lines.out(format!("wrote {}", dir.display()));
        lines.print(&Progress::Off);
        Ok(failed)
    })
}

/// `harness healy-readings`: the table of readings of Healy's experiment (exit 2 when a case
/// file or reference is unreadable, 1 when a point of a reading failed).
fn cmd_healy_readings(a: &ReadingsArgs) -> Result<ExitCode> {
    let Some(&f) = a.formulation.formulations().first().filter(|_| a.formulation.formulations().len() == 1) else {
        eprintln!("error: --formulation: give one formulation (ancf or gebf)");
        return Ok(ExitCode::from(2));
    };
    let mut lines = Lines::new();
    let failed = healy_readings(&a.cases.cases, &a.out.out, f, &mut lines);
    lines.print(&Progress::Off);
    Ok(if failed? { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// Compute and write the Healy readings; keep the table in `lines`; true when a point failed.
fn healy_readings(cases: &Path, out: &Path, f: Formulation, lines: &mut Lines) -> Result<bool> {
    use harness::healy_readings as hr;
    let t = std::time::Instant::now();
    let results = hr::run(cases, f)?;
    let healy = hr::healy_model(cases)?;
    hr::write(out, cases, &results, &healy, f)?;
    let mut failed = false;
    for r in &results {
        let rms: Vec<String> = r.curves.iter().map(|c| c.rms_deg.map_or("-".into(), |x| format!("{x:.2}"))).collect();
        lines.out(format!("healy reading {}: RMS {} deg", r.reading.label(), rms.join(" / ")));
        for e in r.curves.iter().flat_map(|c| &c.failures).chain(&r.level_failures) {
            failed = true;
            lines.out(format!("  FAILED: {e}"));
        }
    }
    lines.out(format!(
        "healy readings: {:.1} s; wrote {}",
        t.elapsed().as_secs_f64(),
        out.join("healy_readings.csv").display()
    ));
    Ok(failed)
}

/// `harness stability`: every run of the case file through its stability sweep; exit 2 without a
/// `stability` block, 1 when a point could not be analysed.
fn cmd_stability(a: &AnalysisArgs) -> Result<ExitCode> {
    let missing = "the case has no `stability` block (airspeeds to analyse)";
    let (runs, plan) = analysis_runs(a, Analysis::Stability, |r| r.ancf.stability.is_some(), missing)?;
    let fs = a.formulation.formulations();
    let out = &a.out.out;
    analysis_loop(Analysis::Stability, &fs, &runs, plan.as_ref(), out, |spec| {
        let outs = run_stability_case(spec, &fs);
        let dir = out.join(&spec.name);
        harness::stability_out::write_with_history(&dir, &spec.name, &outs, None)?;
        let mut lines = Lines::new();
        let failed = report_stability(&spec.name, &outs, &mut lines);
        lines.out(format!("wrote {}", dir.display()));
        lines.print(&Progress::Off);
        Ok(failed)
    })
}

/// `harness gust`: every run of the case file through its gust sweep; exit 2 without a `gust`
/// block, 1 when a run failed.
fn cmd_gust(a: &AnalysisArgs) -> Result<ExitCode> {
    let missing = "the case has no `gust` block (gradients and hinge states to sweep)";
    let (runs, plan) = analysis_runs(a, Analysis::Gust, |r| r.ancf.gust.is_some(), missing)?;
    let fs = a.formulation.formulations();
    let file = a.case.display().to_string();
    analysis_loop(Analysis::Gust, &fs, &runs, plan.as_ref(), &a.out.out, |spec| {
        let summary = gust_sweep(spec, &fs, &file)?;
        let mut lines = Lines::new();
        let failed = gust_report(spec, &fs, &summary, &a.out.out, &mut lines);
        lines.print(&Progress::Off);
        failed
    })
}

/// `harness trim`: every run of the case file trimmed; exit 2 without a `trim` block or on a bad
/// one (named by the case's validation), 1 when a trim failed.
fn cmd_trim(a: &TrimArgs) -> Result<ExitCode> {
    let fs = a.formulation.formulations();
    let file = CaseFile::read(&a.case)?;
    let runs = file.expand_for(&a.set.set, &harness::budget::limits(), None, &fs)?;
    let name = a.case.display().to_string();
    if let Some(r) = runs.iter().find(|r| fs.iter().any(|&f| r.case(f).trim.is_none())) {
        let msg = format!("trim: the case has no `trim` block ({})", r.name);
        return Err(harness::Error::Case { file: name, msg }.into());
    }
    let mut failed = false;
    for spec in &runs {
        let outs = harness::trim_out::run(spec, &fs).map_err(|msg| harness::Error::Case { file: name.clone(), msg })?;
        let dir = a.out.out.join(&spec.name);
        harness::trim_out::write(&dir, &spec.name, &outs)?;
        let mut lines = Lines::new();
        failed |= harness::trim_out::report(&spec.name, &outs, &mut lines);
        lines.out(format!("wrote {}", dir.display()));
        lines.print(&Progress::Off);
    }
    Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// `harness check`: exit 0 (runs), 1 (a run failed), 101 (a panic), 2 (bad input).
fn cmd_check(a: &CheckArgs) -> Result<ExitCode> {
    use harness::fuzz::Class;
    let (class, msg) = harness::fuzz::check_file(&a.case, a.max_steps, &harness::budget::limits());
    Ok(match class {
        Class::Ok => {
            println!("{}: ok", a.case.display());
            ExitCode::SUCCESS
        }
        Class::RunFailed => {
            eprintln!("{}: a run failed: {msg}", a.case.display());
            ExitCode::FAILURE
        }
        Class::Panic => {
            eprintln!("{}: panicked: {msg}", a.case.display());
            ExitCode::from(101)
        }
        _ => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
    })
}

/// `harness fuzz`: exit 1 when an input crashed (panic, abort, hang, escape).
fn cmd_fuzz(a: &FuzzArgs) -> Result<ExitCode> {
    let c = harness::fuzz::Campaign {
        cases: a.cases.clone(),
        out: a.out.clone(),
        inputs: a.inputs,
        first: a.first,
        seed: a.seed,
        jobs: a.jobs,
        timeout: std::time::Duration::from_secs(a.timeout),
        address_space: a.address_space_gb << 30,
        max_steps: a.max_steps,
        run: a.run,
        exec_each: a.exec_each,
    };
    let r = harness::fuzz::campaign(&c)?;
    println!("fuzz: {} inputs in {:.0} s, slowest {:.1} s", r.inputs, r.wall_s, r.slowest_s);
    for (k, n) in &r.classes {
        println!("  {k:?}: {n}");
    }
    println!("wrote {}", a.out.join("fuzz.md").display());
    let crashed = r.classes.iter().any(|(k, n)| k.is_crash() && *n > 0);
    Ok(if crashed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// `harness schema`.
fn cmd_schema() -> Result<ExitCode> {
    use std::io::Write as _;
    // A closed pipe (`| head`) is not an error worth a panic.
    let _ = writeln!(std::io::stdout(), "{}", serde_json::to_string_pretty(&json_schema())?);
    Ok(ExitCode::SUCCESS)
}

/// `harness list`: exit 2 when a case file does not load.
fn cmd_list(a: &CaseSource) -> Result<ExitCode> {
    let (runs, errors) = expand_all(&discover(&a.cases)?, &[]);
    for r in &runs {
        println!(
            "{:<48} ancf: {} el/body dt {}  gebf: {} el/body dt {}  t_end {}  gate: {}",
            r.name,
            r.ancf.ancf.elements_per_body,
            r.ancf.ancf.dt,
            r.gebf.gebf.elements_per_body,
            r.gebf.gebf.dt,
            r.ancf.t_end,
            if r.ancf.gate.is_some() { "yes" } else { "no" }
        );
    }
    for e in &errors {
        eprintln!("error: {e}");
    }
    Ok(if errors.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(2) })
}

/// The shared state of the phases of `harness all`.
struct AllPlan {
    /// Every run of the cases (this shard's and the others').
    all_runs: Vec<RunSpec>,
    /// This shard's runs.
    runs: Vec<RunSpec>,
    /// The stress study's base run (not with --quick).
    stress_base: Option<RunSpec>,
    axes: stress::Axes,
    extras: Vec<(String, RunSpec)>,
    plan: Option<Plan>,
}

impl AllPlan {
    fn here(&self, id: &str) -> bool {
        runs_here(self.plan.as_ref(), id)
    }
}

/// `harness all`: the cases, then (unless `--quick` or interrupted) the studies, the analyses and
/// the reports; exit 2 when a case file was bad, 1 when a run, a gate or an analysis failed, 130
/// when interrupted.
///
/// The phases go side by side in four lanes, threads that hand their runs to the one rayon pool,
/// so that both cores stay busy to the end (one lane's idle tail is filled with another's runs):
/// the cases, then their analyses' comparisons with the runs and the analyses' files
/// ([`all_cases`]); the static, stability and trim sweeps ([`all_sweeps`]); the stress matrix
/// and the energy study ([`all_studies`]); Healy's readings and the gust sweeps ([`all_gusts`]).
/// The phases whose figures are times meant to characterise speed run after them, alone
/// ([`all_timed`]). Each phase prints its lines whole when it ends.
fn cmd_all(a: &AllArgs) -> Result<ExitCode> {
    let out = &a.out.out;
    let progress = Progress::new(true);
    let (p, errors) = all_plan(a, &progress)?;
    // Every run keeps one thread while the phases go side by side (the UVLM threads a run only
    // while it is the one run registered): the pool's threads are the only ones computing.
    let _one_thread_each = harness::aero::register_runs(2);
    // The gust sweeps first, with the machine to themselves: each is one study whose user waits
    // for the whole of it, while the other lanes' many short units pack the cores after it as
    // well as beside it.
    let gusts = all_gusts(a, &p, &progress);
    if stopping() {
        // Nothing of the lanes has begun: the folders keep what an earlier run wrote.
        gusts?;
        eprintln!("interrupted during the gust sweeps: the cases, sweeps and studies were not begun");
        return Ok(ExitCode::from(harness::signal::EXIT_INTERRUPTED));
    }
    let (cases, studies, readings) = std::thread::scope(|s| {
        let studies = s.spawn(|| all_studies(a, &p, &progress));
        let readings = s.spawn(|| all_readings(a, &p, &progress));
        let sweeps = s.spawn(|| all_sweeps(&p, &progress));
        let cases = all_cases(a, &p, &progress, sweeps);
        (cases, joined(studies), joined(readings))
    });
    let (cases, studies, gusts) = (cases?, studies?, gusts?.and(readings?));
    let interrupted = cases.interrupted || harness::signal::interrupted();
    let (ladders, bench) = if a.quick || interrupted { Default::default() } else { all_timed(a, &p, &progress)? };
    // The manifest's units: the cases, the ladders, the stress matrix, the energy study, the benchmark.
    let done: Vec<String> = [cases.done, ladders, studies, bench].concat();
    let failures = cases.failures.and(gusts);
    match &p.plan {
        Some(plan) => {
            progress.phase("shard: the exact runs and the manifest for `harness merge`");
            for (spec, r) in p.runs.iter().zip(&cases.results) {
                harness::merge::save_case(&plan.data_dir(out), spec, r)?;
            }
            let stress_dir = variant_name("stress", &a.set.set, &Formulation::ALL);
            let args = serde_json::json!({ "report": true, "stress_dir": stress_dir, "axes": p.axes });
            plan.write_manifest(out, args, &done)?;
        }
        None => {
            progress.phase("reports: index.html, summary.md");
            write_index(out, &cases.results).context("writing reports")?;
        }
    }
    all_verdict(out, &cases.results, cases.wall, &failures, &errors, interrupted)
}

/// Read the case files and plan `harness all` (this shard's runs among all); the files that did
/// not load are printed and returned.
fn all_plan(a: &AllArgs, progress: &Progress) -> Result<(AllPlan, Vec<harness::Error>)> {
    let (cases, set) = (&a.cases.cases, &a.set.set);
    let files = discover(cases)?;
    progress.phase(&format!("reading {} case files in {}", files.len(), cases.display()));
    let (runs, errors) = expand_all(&files, set);
    for e in &errors {
        eprintln!("error: {e}");
    }
    let all_runs = variants(runs, set, &Formulation::ALL, None);
    // The stress matrix's base case and extra runs (read here: a shard plans every unit).
    let base = files.iter().find(|f| f.ends_with("double_pendulum_c1_beta45.json"));
    let axes = stress::Axes::default();
    let stress_base = match base {
        Some(b) if !a.quick => Some(CaseFile::read(b).and_then(|c| c.expand(set))?.remove(0)),
        _ => None,
    };
    let extras = if stress_base.is_some() { stress_extras(cases, set)? } else { Vec::new() };
    let plan = harness::shard::plan("all", a.shard.shard, || {
        all_units(&all_runs, a.quick, stress_base.as_ref(), &axes, &extras)
    })?;
    let runs: Vec<_> = all_runs.iter().filter(|r| runs_here(plan.as_ref(), &run_unit(&r.name))).cloned().collect();
    Ok((AllPlan { all_runs, runs, stress_base, axes, extras, plan }, errors))
}

/// The value a lane's thread returned; a panic there goes on here.
fn joined<T>(lane: std::thread::ScopedJoinHandle<'_, T>) -> T {
    lane.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))
}

/// Whether a signal stopped `harness all`: a phase not yet begun is skipped.
fn stopping() -> bool {
    harness::signal::interrupted()
}

/// Whether a signal came while `phase` ran (its time loops stopped early): then it writes
/// nothing, and says so.
fn cut_short(progress: &Progress, phase: &str) -> bool {
    let cut = harness::signal::interrupted();
    if cut {
        progress.phase(&format!("{phase}: interrupted, nothing written"));
    }
    cut
}

/// What the cases' lane of `harness all` hands back.
struct CasesOutcome {
    results: Vec<harness::report::CaseResult>,
    /// Wall time of the case runs, s.
    wall: f64,
    /// Whether a signal stopped the case runs.
    interrupted: bool,
    /// The units finished (for a shard's manifest).
    done: Vec<String>,
    failures: AnalysisFailures,
}

/// The cases' lane of `harness all`: this shard's case runs, then (unless a signal stopped them)
/// the files of their static, stability and trim sweeps (`sweeps`, computed meanwhile), compared
/// with the runs.
fn all_cases<'p>(
    a: &AllArgs,
    p: &'p AllPlan,
    progress: &Progress,
    sweeps: std::thread::ScopedJoinHandle<'_, Sweeps<'p>>,
) -> Result<CasesOutcome> {
    let out = &a.out.out;
    let t0 = std::time::Instant::now();
    progress.phase(&format!("cases: {} runs x 2 formulations", p.runs.len()));
    // Each run also records its 3-D view for the report (and writes VTK where the case asks).
    let (results, interrupted) = run_and_write(&p.runs, &Formulation::ALL, out, progress, &|spec, f| {
        harness::view3d::report_observer(out, spec, f)
    })?;
    let wall = t0.elapsed().as_secs_f64();
    if interrupted {
        let failures = AnalysisFailures::default();
        return Ok(CasesOutcome { results, wall, interrupted, done: Vec::new(), failures });
    }
    progress.phase(&format!("cases: done in {wall:.1} s"));
    let done = p.runs.iter().map(|r| run_unit(&r.name)).collect();
    let failures = all_analyses(a, &results, joined(sweeps), progress)?;
    Ok(CasesOutcome { results, wall, interrupted, done, failures })
}

/// The studies' lane of `harness all` (not with --quick): the stress matrix, then the energy
/// study, each where this shard runs it; the units finished.
fn all_studies(a: &AllArgs, p: &AllPlan, progress: &Progress) -> Result<Vec<String>> {
    let mut done = Vec::new();
    if a.quick {
        return Ok(done);
    }
    let (out, set) = (&a.out.out, &a.set.set);
    // Studies of a run with overrides go to folders that say so too.
    let study = |name: &str| out.join(variant_name(name, set, &Formulation::ALL));
    if let Some(spec) = p.stress_base.as_ref().filter(|_| !stopping()) {
        progress.phase("stress matrix (c x beta x dt x rho_inf, both formulations), then its two long runs");
        let t = std::time::Instant::now();
        let mut units = Vec::new();
        let (cells, ex) = run_stress(spec, &p.axes, &p.extras, p.plan.as_ref(), &mut units, progress);
        if cut_short(progress, "stress matrix") {
            return Ok(done);
        }
        match &p.plan {
            Some(plan) => harness::merge::save_stress(&plan.data_dir(out), &cells, &ex)?,
            None => {
                stress::write(&study("stress"), &p.axes, &cells)?;
                stress::write_extras(&study("stress"), &ex)?;
            }
        }
        let mut lines = Lines::new();
        for f in Formulation::ALL {
            let (ok, rec, n) = stress::survival(&cells, f);
            lines
                .out(format!("stress {f}: {ok} of {n} cells reach t_end at fixed steps, {rec} more with step control"));
        }
        lines.out(format!("stress matrix: {:.1} s", t.elapsed().as_secs_f64()));
        lines.print(progress);
        done.extend(units);
    }
    if p.here("energy") && !stopping() {
        progress.phase("energy study (rho_inf = 1, both forms, dt and dt/2)");
        let (runs, secs) = energy_study(&p.all_runs);
        if cut_short(progress, "energy study") {
            return Ok(done);
        }
        let mut lines = Lines::new();
        energy_report(&runs, secs, &study("energy"), &mut lines)?;
        lines.print(progress);
        done.push("energy".into());
    }
    Ok(done)
}

/// The lane of `harness all` with Healy's readings (where the three cases are): not with
/// --quick, and not on a shard.
fn all_readings(a: &AllArgs, p: &AllPlan, progress: &Progress) -> Result<AnalysisFailures> {
    let mut n = AnalysisFailures::default();
    if a.quick || p.plan.is_some() {
        return Ok(n);
    }
    let (cases, out) = (&a.cases.cases, &a.out.out);
    let healy_here = harness::healy_readings::CASES.iter().all(|c| cases.join(format!("{c}.json")).is_file());
    if healy_here && !stopping() {
        progress.phase("the readings of Healy's experiment");
        let mut lines = Lines::new();
        n.static_failed += usize::from(healy_readings(cases, out, Formulation::Gebf, &mut lines)?);
        lines.print(progress);
    }
    Ok(n)
}

/// The gust sweeps of `harness all`, several minutes of CPU: not with --quick, and not on a
/// shard (on a cluster the gust sweeps are their own array, `harness gust --shard`).
fn all_gusts(a: &AllArgs, p: &AllPlan, progress: &Progress) -> Result<AnalysisFailures> {
    let mut n = AnalysisFailures::default();
    if a.quick || p.plan.is_some() {
        return Ok(n);
    }
    let out = &a.out.out;
    for spec in p.runs.iter().filter(|r| r.ancf.gust.is_some()) {
        if stopping() {
            break;
        }
        progress.phase(&format!("gust sweep of {}", spec.name));
        let t = std::time::Instant::now();
        let file = spec.dir.join(format!("{}.json", spec.name)).display().to_string();
        let summary = gust_sweep(spec, &Formulation::ALL, &file)?;
        if cut_short(progress, &format!("gust sweep of {}", spec.name)) {
            break;
        }
        let mut lines = Lines::new();
        n.gust_failed += usize::from(gust_report(spec, &Formulation::ALL, &summary, out, &mut lines)?);
        lines.out(format!("gust {}: {:.1} s", spec.name, t.elapsed().as_secs_f64()));
        lines.print(progress);
    }
    Ok(n)
}

/// The studies of `harness all` whose figures are times meant to characterise speed, after every
/// other phase (not with --quick nor after a signal), each where this shard runs it; the units
/// finished, the ladders' and the benchmark's.
///
/// They run alone: the cost of a ladder's rung is its thread CPU time in the work-precision plot,
/// and the rungs go two at a time as `harness converge` runs them, so that each shares the
/// machine's memory and caches with another rung only, not with whatever runs of other phases
/// happen to go beside it; the benchmark is the median thread CPU time of serial runs, with the
/// other core idle.
fn all_timed(a: &AllArgs, p: &AllPlan, progress: &Progress) -> Result<(Vec<String>, Vec<String>)> {
    let (out, set) = (&a.out.out, &a.set.set);
    let study = |name: &str| out.join(variant_name(name, set, &Formulation::ALL));
    let mut ladders = Vec::new();
    for spec in p.all_runs.iter().filter(|r| r.ancf.converge && p.here(&format!("converge:{}", r.name))) {
        if stopping() {
            break;
        }
        progress.phase(&format!("refinement ladders of {}", spec.name));
        let t = std::time::Instant::now();
        let r = converge::converge(spec, progress)?;
        if cut_short(progress, &format!("refinement ladders of {}", spec.name)) {
            break;
        }
        converge::write(&study("converge").join(&spec.name), &r)?;
        let mut lines = Lines::new();
        lines.out(format!("converge {}: {:.1} s", spec.name, t.elapsed().as_secs_f64()));
        lines.print(progress);
        ladders.push(format!("converge:{}", spec.name));
    }
    let mut bench = Vec::new();
    if p.here("bench") && !stopping() {
        progress.phase("speed benchmark (serial repeated runs)");
        let t = std::time::Instant::now();
        let pendulums: Vec<_> = p.all_runs.iter().filter(|r| r.ancf.aero.is_none()).cloned().collect();
        let rows = bench::run(&pendulums, BENCH_REPEATS, true);
        if !cut_short(progress, "speed benchmark") {
            write_bench(&pendulums, BENCH_REPEATS, &rows, &study("bench"), t)?;
            bench.push("bench".into());
        }
    }
    Ok((ladders, bench))
}

/// How many sweeps of each analysis failed in `harness all`.
#[derive(Default)]
struct AnalysisFailures {
    static_failed: usize,
    stability_failed: usize,
    trim_failed: usize,
    gust_failed: usize,
}

impl AnalysisFailures {
    /// The failures of both.
    fn and(self, o: Self) -> Self {
        Self {
            static_failed: self.static_failed + o.static_failed,
            stability_failed: self.stability_failed + o.stability_failed,
            trim_failed: self.trim_failed + o.trim_failed,
            gust_failed: self.gust_failed + o.gust_failed,
        }
    }
}

/// The static, stability and trim sweeps of this shard's runs, each with both formulations and
/// its wall time, s (the sweeps of a kind side by side; a run's sweep not begun when a signal came
/// is left out).
struct Sweeps<'p> {
    statics: PerRun<'p, harness::static_out::StaticSummary>,
    stabilities: PerRun<'p, Vec<harness::stability::StabilityOutput>>,
    trims: PerRun<'p, Result<Vec<aeroelastic::trim::TrimOutput>, String>>,
}

/// Runs, each with a result and its wall time, s.
type PerRun<'p, T> = Vec<(&'p RunSpec, T, f64)>;

/// The sweeps' lane of `harness all`: the static, stability and trim sweeps of this shard's runs,
/// which need nothing of the runs until they are compared with them ([`all_analyses`]).
fn all_sweeps<'p>(p: &'p AllPlan, progress: &Progress) -> Sweeps<'p> {
    use rayon::prelude::*;
    /// `work` on every run with `has` (unless a signal came before it began), side by side, timed.
    fn each<'p, T: Send>(
        runs: &'p [RunSpec],
        has: impl Fn(&RunSpec) -> bool,
        work: impl Fn(&RunSpec) -> T + Sync,
    ) -> PerRun<'p, T> {
        let specs: Vec<&RunSpec> = runs.iter().filter(|r| has(r)).collect();
        let timed = |spec: &&'p RunSpec| {
            let t = std::time::Instant::now();
            (!stopping()).then(|| (*spec, work(spec), t.elapsed().as_secs_f64()))
        };
        specs.par_iter().filter_map(timed).collect()
    }
    let count = |has: fn(&RunSpec) -> bool| p.runs.iter().filter(|r| has(r)).count();
    let has_static: fn(&RunSpec) -> bool = |r| r.ancf.statics.is_some();
    let has_stability: fn(&RunSpec) -> bool = |r| r.ancf.stability.is_some();
    let has_trim: fn(&RunSpec) -> bool = |r| r.ancf.trim.is_some();
    progress.phase(&format!(
        "sweeps: static of {} runs, stability of {}, trim of {}",
        count(has_static),
        count(has_stability),
        count(has_trim)
    ));
    let fs = &Formulation::ALL;
    // The costliest kind first: its long sweeps start while there is other work to go beside them.
    let stabilities = each(&p.runs, has_stability, |spec| run_stability_case(spec, fs));
    let statics = each(&p.runs, has_static, |spec| run_static_case(spec, fs));
    let trims = each(&p.runs, has_trim, |spec| harness::trim_out::run(spec, fs));
    Sweeps { statics, stabilities, trims }
}

/// The files of the sweeps of this shard's runs in `harness all` and their lines, after the runs:
/// the static sweeps compared with the runs' time histories (side by side), the stability sweeps
/// beside them, and the trims; in the runs' order.
fn all_analyses(
    a: &AllArgs,
    results: &[harness::report::CaseResult],
    sweeps: Sweeps<'_>,
    progress: &Progress,
) -> Result<AnalysisFailures> {
    use rayon::prelude::*;
    let out = &a.out.out;
    let mut n = AnalysisFailures::default();
    let history = |spec: &RunSpec| results.iter().find(|r| r.name == spec.name);
    if !sweeps.statics.is_empty() {
        progress.phase("static sweeps: against the runs' time histories");
        let mut statics = sweeps.statics;
        statics.par_iter_mut().for_each(|(spec, summary, secs)| {
            let t = std::time::Instant::now();
            if let Some(r) = history(spec) {
                harness::static_out::compare_with_history(summary, spec, &r.runs);
            }
            *secs += t.elapsed().as_secs_f64();
        });
        let mut lines = Lines::new();
        for (spec, summary, secs) in &statics {
            harness::static_out::write(&out.join(&spec.name), summary)?;
            n.static_failed += usize::from(report_static(summary, &mut lines));
            lines.out(format!("static {}: {secs:.1} s", spec.name));
        }
        lines.print(progress);
    }
    let mut lines = Lines::new();
    for (spec, outs, secs) in &sweeps.stabilities {
        let metrics = history(spec).map(|r| r.metrics.clone());
        harness::stability_out::write_with_history(&out.join(&spec.name), &spec.name, outs, metrics.as_ref())?;
        n.stability_failed += usize::from(report_stability(&spec.name, outs, &mut lines));
        lines.out(format!("stability {}: {secs:.1} s", spec.name));
    }
    for (spec, outs, secs) in sweeps.trims {
        let outs = outs.map_err(|msg| harness::Error::Case { file: spec.name.clone(), msg })?;
        harness::trim_out::write(&out.join(&spec.name), &spec.name, &outs)?;
        n.trim_failed += usize::from(harness::trim_out::report(&spec.name, &outs, &mut lines));
        lines.out(format!("trim {}: {secs:.1} s", spec.name));
    }
    lines.print(progress);
    Ok(n)
}

/// The gate table, the totals and the exit code of `harness all`.
fn all_verdict(
    out: &Path,
    results: &[harness::report::CaseResult],
    wall: f64,
    n: &AnalysisFailures,
    errors: &[harness::Error],
    interrupted: bool,
) -> Result<ExitCode> {
    print!("{}", gate::table(results));
    let failed = results.iter().flat_map(|r| &r.runs).filter(|r| r.error.is_some()).count();
    println!(
        "{} runs ({} cases x 2 formulations) in {:.2} s wall; {} failed; reports in {}",
        2 * results.len(),
        results.len(),
        wall,
        failed,
        out.join("index.html").display()
    );
    let gate_failed = results.iter().filter(|r| r.status() == "FAIL").count();
    if gate_failed > 0 {
        eprintln!("gate: {gate_failed} case(s) fail their tolerances (see the table)");
    }
    if n.static_failed > 0 {
        eprintln!("static: {} sweep(s) have airspeeds without an equilibrium", n.static_failed);
    }
    if n.stability_failed > 0 {
        eprintln!("stability: {} sweep(s) have airspeeds that could not be analysed", n.stability_failed);
    }
    if n.trim_failed > 0 {
        eprintln!("trim: {} case(s) could not be trimmed", n.trim_failed);
    }
    if n.gust_failed > 0 {
        eprintln!("gust: {} sweep(s) have runs that failed", n.gust_failed);
    }
    if interrupted {
        eprintln!("interrupted: the rows computed so far are written; studies skipped");
        return Ok(ExitCode::from(harness::signal::EXIT_INTERRUPTED));
    }
    let analyses_ok = n.static_failed == 0 && n.stability_failed == 0 && n.trim_failed == 0 && n.gust_failed == 0;
    Ok(exit_code(errors, failed == 0 && gate_failed == 0 && analyses_ok))
}

/// `harness run`: exit 1 when a run failed, 130 when interrupted.
fn cmd_run(a: &RunArgs) -> Result<ExitCode> {
    let (out, set) = (&a.out.out, &a.set.set);
    let fs = a.formulation.formulations();
    let limits = harness::budget::limits();
    let file = CaseFile::read(&a.case)?;
    let runs = variants(file.expand_for(set, &limits, a.max_steps, &fs)?, set, &fs, a.max_steps);
    let progress = Progress::new(true);
    // VTK when --vtk asks for it or the case's `vtk` block does.
    let cli = a.vtk.then_some(a.vtk_stride);
    let vtk_out = out.clone();
    let observer = move |spec: &RunSpec, f: Formulation| -> Box<dyn harness::run::Observer> {
        match harness::vtk::writer_for(&vtk_out, spec, f, cli) {
            Some(w) => Box::new(w),
            None => Box::new(harness::run::NoObserver),
        }
    };
    let (results, interrupted) = run_and_write(&runs, &fs, out, &progress, &observer)?;
    let mut failed = false;
    for r in &results {
        failed |= print_run(out, r);
    }
    if interrupted {
        eprintln!("interrupted: the rows computed so far are written; summary.json says \"interrupted\"");
        return Ok(ExitCode::from(harness::signal::EXIT_INTERRUPTED));
    }
    Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}

/// Print one case's runs (metrics or failure), the ANCF-GEBF difference and its gate; true when
/// a run failed.
fn print_run(out: &Path, r: &harness::report::CaseResult) -> bool {
    let mut failed = false;
    let dir = out.join(&r.name);
    for run in &r.runs {
        let m = &r.metrics[&run.formulation];
        match &run.error {
            Some(e) => {
                failed = true;
                eprintln!("{} {}: FAILED: {e}", r.name, run.formulation);
            }
            None => println!(
                "{} {}: {} steps in {:.1} ms, {:.2} Newton/step{}, energy drift {:.2e}, max constraint {:.1e} -> {}",
                r.name,
                run.formulation,
                m.n_steps,
                1e3 * m.wall_s,
                m.newton_per_step,
                if m.aero_solves_per_step > 0.0 {
                    format!(", {:.2} aero solves/step", m.aero_solves_per_step)
                } else {
                    String::new()
                },
                m.energy_drift,
                m.max_constraint_residual,
                dir.join(format!("{}.csv", run.formulation)).display()
            ),
        }
    }
    if let Some(p) = &r.pair {
        println!("{}: max tip difference ANCF-GEBF {:.3} mm", r.name, 1e3 * p.all.max);
    }
    // The case's gate, for information (`harness gate` is the command that enforces it).
    if let Some(g) = &r.gate_outcome {
        let lines = g.failed_lines();
        println!(
            "{}: gate {} ({} failed check(s); `harness gate` enforces it)",
            r.name,
            if g.pass() { "pass" } else { "FAIL" },
            lines.len()
        );
        for l in lines {
            eprintln!("{}: gate: {l}", r.name);
        }
    }
    failed
}

/// `harness converge`: the refinement ladders of every run of the case file.
fn cmd_converge(a: &StudyArgs) -> Result<ExitCode> {
    let out = &a.out.out;
    let runs = CaseFile::read(&a.case).and_then(|c| c.expand(&a.set.set))?;
    let plan = harness::shard::plan("converge", a.shard.shard, || {
        runs.iter()
            .map(|r| Unit { id: format!("converge:{}", r.name), cost: LADDER_COST * harness::shard::run_cost(r) })
            .collect()
    })?;
    let mut done = Vec::new();
    let progress = Progress::new(true);
    for spec in runs.iter().filter(|r| runs_here(plan.as_ref(), &format!("converge:{}", r.name))) {
        let r = converge::converge(spec, &progress)?;
        let dir = out.join("converge").join(&spec.name);
        converge::write(&dir, &r)?;
        for o in &r.orders {
            let ord: Vec<String> = o.orders.iter().map(|x| format!("{x:.2}")).collect();
            println!(
                "{} {} {:<8} observed orders [{}], truth error estimate {:.2e} m",
                spec.name,
                o.formulation,
                format!("{:?}", o.ladder).to_lowercase(),
                ord.join(", "),
                o.truth_error_estimate_m
            );
        }
        println!("wrote {}", dir.display());
        done.push(format!("converge:{}", spec.name));
    }
    if let Some(p) = &plan {
        p.write_manifest(out, serde_json::json!({}), &done)?;
    }
    Ok(ExitCode::SUCCESS)
}

/// `harness merge`: exit 1 naming the runs no shard finished.
fn cmd_merge(a: &MergeArgs) -> Result<ExitCode> {
    let out = &a.out.out;
    let m = harness::merge::merge(&a.dirs, out)?;
    let shards: Vec<String> = m.shards.iter().map(|(c, k)| format!("{c} {k}")).collect();
    println!(
        "merge: {} shard(s) ({}); {} case run(s), {} stress cell(s); wrote {}",
        m.shards.len(),
        shards.join(", "),
        m.results.len(),
        m.stress_cells,
        out.display()
    );
    if !m.results.is_empty() {
        print!("{}", gate::table(&m.results));
    }
    if m.missing.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    eprintln!("merge: {} run(s) missing (no shard finished them):", m.missing.len());
    for (cmd, unit, k) in &m.missing {
        eprintln!("  {cmd} {unit} (shard {k})");
    }
    Ok(ExitCode::FAILURE)
}

/// `harness stress`: the stress matrix and its extra runs on the base case.
fn cmd_stress(a: &StressArgs) -> Result<ExitCode> {
    let (out, set) = (&a.out.out, &a.set.set);
    let runs = CaseFile::read(&a.case).and_then(|c| c.expand(set))?;
    let base = runs.first().context("the base case expands into no run")?;
    let axes = stress::Axes::default();
    let extras = stress_extras(&a.case.with_file_name(""), set)?;
    let plan = harness::shard::plan("stress", a.shard.shard, || stress_units(base, &axes, &extras))?;
    let t0 = std::time::Instant::now();
    let mut done = Vec::new();
    let (cells, ex) = run_stress(base, &axes, &extras, plan.as_ref(), &mut done, &Progress::new(true));
    let dir = out.join("stress");
    for f in Formulation::ALL {
        let (ok, rec, n) = stress::survival(&cells, f);
        println!("{f}: {ok} of {n} cells reach t_end at fixed steps, {rec} more with step control");
    }
    match &plan {
        Some(p) => {
            harness::merge::save_stress(&p.data_dir(out), &cells, &ex)?;
            let args = serde_json::json!({ "report": false, "stress_dir": "stress", "axes": axes });
            p.write_manifest(out, args, &done)?;
        }
        None => {
            stress::write(&dir, &axes, &cells)?;
            stress::write_extras(&dir, &ex)?;
        }
    }
    let line = |error: &Option<String>, newton: f64, drift: f64| {
        error.clone().unwrap_or_else(|| format!("ok, {newton:.2} Newton/step, drift {drift:.2e}"))
    };
    for e in &ex {
        let m = &e.metrics;
        println!("{} {}: {}", e.label, e.formulation, line(&m.error, m.newton_per_step, m.energy_drift));
        if let Some(r) = &e.recovery {
            println!("  with step control: {}", line(&r.error, r.newton_per_step, r.energy_drift));
        }
    }
    println!("stress matrix in {:.1} s; wrote {}", t0.elapsed().as_secs_f64(), dir.display());
    Ok(ExitCode::SUCCESS)
}

/// `harness energy`: exit 2 when a case file was bad, 1 when a run failed.
fn cmd_energy(a: &EnergyArgs) -> Result<ExitCode> {
    let (runs, errors) = expand_all(&discover(&a.cases.cases)?, &a.set.set);
    for e in &errors {
        eprintln!("error: {e}");
    }
    let (study, secs) = energy_study(&runs);
    let mut lines = Lines::new();
    let ok = energy_report(&study, secs, &a.out.out.join("energy"), &mut lines);
    lines.print(&Progress::Off);
    Ok(exit_code(&errors, ok?))
}

/// The case files of `harness gate` and `harness bench` (explicit, else discovered), expanded;
/// the bad ones printed and returned apart. The flag says whether the files were explicit.
fn files_runs(a: &FilesArgs) -> Result<(Vec<RunSpec>, Vec<harness::Error>, bool)> {
    let explicit = !a.files.is_empty();
    let files = if explicit { a.files.clone() } else { discover(&a.cases.cases)? };
    let (runs, errors) = expand_all(&files, &a.set.set);
    for e in &errors {
        eprintln!("error: {e}");
    }
    Ok((runs, errors, explicit))
}

/// `harness bench`: exit 2 when a case file was bad, 1 when a timed run failed.
fn cmd_bench(a: &BenchArgs) -> Result<ExitCode> {
    if a.aero {
        let t = std::time::Instant::now();
        let b = harness::bench_aero::run(&a.files.cases.cases, true)?;
        harness::bench_aero::write(&a.out.out.join("bench"), &b)?;
        println!("bench --aero: done in {:.1} s", t.elapsed().as_secs_f64());
        let failed = b.steps.iter().any(|r| r.error.is_some()) || b.analyses.iter().any(|r| r.error.is_some());
        return Ok(if failed { ExitCode::from(1) } else { ExitCode::SUCCESS });
    }
    let (runs, errors, explicit) = files_runs(&a.files)?;
    let runs: Vec<_> = runs.into_iter().filter(|r| explicit || r.ancf.aero.is_none()).collect();
    let rows = run_bench(&runs, a.repeats, &a.out.out.join("bench"))?;
    let failed = rows.iter().filter(|r| r.error.is_some()).count();
    Ok(exit_code(&errors, failed == 0))
}

/// `harness gate`: exit 2 when a case file was bad, 1 when a gated case fails.
fn cmd_gate(a: &FilesArgs) -> Result<ExitCode> {
    let (runs, errors, _) = files_runs(a)?;
    let gated: Vec<_> = runs.into_iter().filter(|r| r.ancf.gate.is_some()).collect();
    let results = run_all(&gated, &Formulation::ALL, true);
    print!("{}", gate::table(&results));
    let failing: Vec<_> = results.iter().filter(|r| r.status() != "pass").collect();
    for r in &failing {
        for l in r.gate_outcome.as_ref().map(|g| g.failed_lines()).unwrap_or_default() {
            eprintln!("gate FAILED: {}: {l}", r.name);
        }
    }
    println!("gate: {} of {} cases pass", results.len() - failing.len(), results.len());
    Ok(exit_code(&errors, failing.is_empty()))
}

fn real_main() -> Result<ExitCode> {
    let cli = Cli::parse();
    harness::budget::set_limits(cli.max_memory, cli.max_hours);
    harness::signal::install();
    match &cli.cmd {
        Cmd::All(a) => cmd_all(a),
        Cmd::Run(a) => cmd_run(a),
        Cmd::Fuzz(a) => cmd_fuzz(a),
        Cmd::FuzzWorker { max_steps } => {
            harness::fuzz::worker_main(*max_steps)?;
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Check(a) => cmd_check(a),
        Cmd::Gate(a) => cmd_gate(a),
        Cmd::Converge(a) => cmd_converge(a),
        Cmd::Stress(a) => cmd_stress(a),
        Cmd::Energy(a) => cmd_energy(a),
        Cmd::Bench(a) => cmd_bench(a),
        Cmd::Static(a) => cmd_static(a),
        Cmd::HealyReadings(a) => cmd_healy_readings(a),
        Cmd::Merge(a) => cmd_merge(a),
        Cmd::Stability(a) => cmd_stability(a),
        Cmd::Gust(a) => cmd_gust(a),
        Cmd::Trim(a) => cmd_trim(a),
        Cmd::List(a) => cmd_list(a),
        Cmd::Schema => cmd_schema(),
    }
}
