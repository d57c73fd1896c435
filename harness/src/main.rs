//! `harness`: run both formulations on the case files, compare, report, gate.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use harness::case::{CaseFile, Formulation, Override, json_schema};
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
    about = "Dual-formulation (ANCF / GEBF) verification harness for flared-hinged wings"
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

#[derive(Clone, Copy, ValueEnum)]
enum Which {
    Ancf,
    Gebf,
    Both,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run every case with both formulations; write reports/ (CSV, summary.json, SVG, index.html, summary.md).
    All {
        /// Folder of case files.
        #[arg(long, default_value = "cases")]
        cases: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value: `[ancf:|gebf:]path=value`, e.g. `t_end=0.5` or `gebf:joints.1.flare_deg=40`.
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
        /// Skip the refinement ladders, the stress matrix and the speed benchmark (cases only).
        #[arg(long)]
        quick: bool,
        #[command(flatten)]
        shard: ShardOpt,
    },
    /// Run one case file.
    Run {
        /// Case file.
        case: PathBuf,
        /// Formulation(s) to run.
        #[arg(long, value_enum, default_value = "both")]
        formulation: Which,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
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
    },
    /// Fuzz campaign: mutants of the case files, each run in its own process (`run --max-steps`)
    /// under a time and an address-space limit, classified by outcome; writes `<out>/fuzz.json`,
    /// `fuzz.md` and every crashing input under `crashes/`.
    Fuzz {
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
    },
    /// The worker of `harness fuzz`: reads input paths from stdin, answers one line each.
    #[command(hide = true)]
    FuzzWorker {
        /// Steps each run takes at most.
        #[arg(long, default_value_t = 3)]
        max_steps: usize,
    },
    /// Check a case file: parse, validate, build both formulations and run each at most
    /// `--max-steps` steps, writing nothing; exit 0 (runs), 1 (a run failed), 2 (bad input).
    Check {
        /// Case file.
        case: PathBuf,
        /// Steps each run takes at most.
        #[arg(long, default_value_t = 3)]
        max_steps: usize,
    },
    /// Run the gated cases and check their tolerances; exit 1 when any case fails.
    Gate {
        /// Case files (default: every case in --cases that declares a gate).
        files: Vec<PathBuf>,
        /// Folder of case files.
        #[arg(long, default_value = "cases")]
        cases: PathBuf,
        /// Override a case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
    },
    /// Refinement ladders (time, space, both) for each formulation: error against wall time.
    Converge {
        /// Case file.
        case: PathBuf,
        /// Output folder (writes `<out>/converge/<case>/`).
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
        #[command(flatten)]
        shard: ShardOpt,
    },
    /// The stress matrix (c × β × dt × rho_inf) on a base case, for both formulations.
    Stress {
        /// Base case file.
        #[arg(default_value = "cases/double_pendulum_c1_beta45.json")]
        case: PathBuf,
        /// Output folder (writes `<out>/stress/`).
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a base-case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
        #[command(flatten)]
        shard: ShardOpt,
    },
    /// Energy at rho_inf = 1 of the c = 1 pendulums, each formulation in both generalized-α forms
    /// (Arnold–Brüls, Chung–Hulbert), at dt and dt/2; writes `<out>/energy/` (energy.md, energy.csv,
    /// energy.svg).
    Energy {
        /// Folder of case files.
        #[arg(long, default_value = "cases")]
        cases: PathBuf,
        /// Output folder (writes `<out>/energy/`).
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
    },
    /// Time each formulation on each case (median thread CPU time of repeated serial runs, ANCF on
    /// both paths) with the work per step; writes `<out>/bench/` (bench.md, bench.json, bench.svg).
    Bench {
        /// Case files (default: every case in --cases without aerodynamics).
        files: Vec<PathBuf>,
        /// Folder of case files.
        #[arg(long, default_value = "cases")]
        cases: PathBuf,
        /// Timed runs per configuration.
        #[arg(long, default_value_t = 7)]
        repeats: usize,
        /// Output folder (writes `<out>/bench/`).
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
    },
    /// Static aeroelastic equilibria over the case's `static.airspeeds` (or, for a case without
    /// `aero`, the equilibria under its `static.point_loads` at `static.load_factors`); writes
    /// `<out>/<case>/static_{ancf,gebf}.csv`, `static_lift_*.csv`, `static_summary.json` and plots.
    Static {
        /// Case file (with `aero` and `static` blocks).
        case: PathBuf,
        /// Formulation(s) to run.
        #[arg(long, value_enum, default_value = "both")]
        formulation: Which,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`), e.g. `pitch_deg=5` or `joints.1.locked=true`.
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
        #[command(flatten)]
        shard: ShardOpt,
    },
    /// Merge the outputs of the shards of a sweep (`--shard`) into one report and summary; exits 1
    /// naming the runs no shard finished.
    Merge {
        /// The shards' output folders (each holds `shards/*.json`; shards may share one).
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output folder of the merged report.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Linearised stability over the case's `stability.airspeeds` (flutter, divergence, modes);
    /// writes `<out>/<case>/stability_{ancf,gebf}.csv`, `.json`, plots and a report fragment.
    Stability {
        /// Case file (with `aero` and `stability` blocks).
        case: PathBuf,
        /// Formulation(s) to run.
        #[arg(long, value_enum, default_value = "both")]
        formulation: Which,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
        #[command(flatten)]
        shard: ShardOpt,
    },
    /// Gust sweep over the case's `gust` block (gradients x hinge states) from the static
    /// equilibrium; writes `<out>/<case>/gust_{ancf,gebf}.csv`, `gust_history_*.csv`,
    /// `gust_summary.json` and plots (docs/gust.md).
    Gust {
        /// Case file (with `aero.gust` and a `gust` block).
        case: PathBuf,
        /// Formulation(s) to run.
        #[arg(long, value_enum, default_value = "both")]
        formulation: Which,
        /// Output folder.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Override a case value (see `all`), e.g. `gust.gradients_m=[30]`.
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<Override>,
        #[command(flatten)]
        shard: ShardOpt,
    },
    /// List the runs the case files expand into.
    List {
        /// Folder of case files.
        #[arg(long, default_value = "cases")]
        cases: PathBuf,
    },
    /// Print the JSON Schema of case files.
    Schema,
}

/// Run the benchmark on `runs` and write `dir` (`<out>/bench/`); the targets apply to the cases without
/// aerodynamics (the issues' figures are for the paper's pendulums).
fn run_bench(runs: &[harness::case::RunSpec], repeats: usize, dir: &std::path::Path) -> Result<Vec<bench::BenchRow>> {
    let t = std::time::Instant::now();
    let rows = bench::run(runs, repeats, true);
    let pendulums: Vec<&str> = runs.iter().filter(|r| r.ancf.aero.is_none()).map(|r| r.name.as_str()).collect();
    bench::write(dir, &rows, |c| pendulums.contains(&c))?;
    println!("bench: {} configurations x {repeats} runs in {:.1} s", rows.len(), t.elapsed().as_secs_f64());
    Ok(rows)
}

/// Run the energy study on the c = 1 pendulums among `runs`, write `dir` (`<out>/energy/`) and print the
/// drifts; returns whether every run reached its end (true when there is nothing to study).
fn run_energy(runs: &[harness::case::RunSpec], dir: &std::path::Path) -> Result<bool> {
    let t = std::time::Instant::now();
    let specs = energy::select(runs);
    if specs.is_empty() {
        println!("energy study: no c = 1 pendulum (no aerodynamics) among the cases; nothing written");
        return Ok(true);
    }
    let study = energy::run(&specs);
    energy::write(dir, &study)?;
    for r in &study {
        let m = &r.metrics;
        println!(
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
        );
    }
    println!("energy study: {} runs in {:.1} s", study.len(), t.elapsed().as_secs_f64());
    Ok(study.iter().all(|r| r.metrics.error.is_none()))
}

/// The extra hard runs of the stress study: a 20 s pendulum and the wing at AoA 15°.
fn stress_extras(dir: &std::path::Path, set: &[Override]) -> Result<Vec<(String, harness::case::RunSpec)>> {
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
fn run_stability_case(spec: &harness::case::RunSpec, fs: &[Formulation]) -> Vec<harness::stability::StabilityOutput> {
    use rayon::prelude::*;
    fs.par_iter().map(|&f| harness::stability::run_stability(spec.case(f), f)).collect()
}

/// Print a stability sweep's results; true when a point failed.
fn report_stability(name: &str, outs: &[harness::stability::StabilityOutput]) -> bool {
    let mut failed = false;
    for o in outs {
        if let Some(e) = &o.error {
            eprintln!("stability {name} {}: {e}", o.formulation);
            failed = true;
            continue;
        }
        let bad = o.points.iter().filter(|p| p.error.is_some()).count();
        let unconverged = o.points.iter().flat_map(|p| &p.roots).filter(|r| !r.converged).count();
        for p in o.points.iter().filter(|p| p.error.is_some()) {
            eprintln!("stability {name} {} at {} m/s: {}", o.formulation, p.airspeed, p.error.as_deref().unwrap_or(""));
        }
        failed |= bad > 0;
        let f = |x: Option<f64>| x.map_or_else(|| "none".to_string(), |v| format!("{v:.3}"));
        println!(
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
        );
    }
    failed
}

/// The gust sweep of one run specification with the formulations `fs`, written to
/// `<out>/<case>/` and printed; true when a run of the sweep failed.
fn gust_case(spec: &harness::case::RunSpec, fs: &[Formulation], out: &std::path::Path, file: &str) -> Result<bool> {
    let mut failed = false;
    let sweep =
        harness::gust::run_sweep(spec, fs).map_err(|msg| harness::Error::Case { file: file.to_string(), msg })?;
    let summary = harness::gust_out::summarise(sweep);
    let dir = out.join(&spec.name);
    harness::gust_out::write(&dir, &summary)?;
    for r in &summary.runs {
        match &r.error {
            Some(e) => {
                failed = true;
                eprintln!(
                    "gust {} {} {} H = {} m: FAILED: {e}",
                    spec.name,
                    r.formulation,
                    r.hinge.label(),
                    r.gradient_m
                );
            }
            None => println!(
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
            ),
        }
    }
    for a in &summary.alleviation {
        println!(
            "  {} {} H = {:.3} m: alleviation {:.1} %",
            a.formulation,
            a.hinge.label(),
            a.gradient_m,
            a.root_bending_moment_percent
        );
    }
    println!(
        "gust {}: ANCF-GEBF peak dM_root within {:.3} %, peak fold within {:.3} deg; sweep {:.1} s wall",
        spec.name, summary.max_peak_rbm_difference_percent, summary.max_peak_fold_difference_deg, summary.wall_s
    );
    println!("wrote {}", dir.display());
    Ok(failed)
}

/// `harness gust`: every run of the case file through its gust sweep; exit 2 without a `gust`
/// block, 1 when a run failed.
fn run_gust(
    case: &std::path::Path,
    which: Which,
    out: &std::path::Path,
    set: &[Override],
    shard: Option<ShardArg>,
) -> Result<ExitCode> {
    let fs: Vec<Formulation> = match which {
        Which::Ancf => vec![Formulation::Ancf],
        Which::Gebf => vec![Formulation::Gebf],
        Which::Both => Formulation::ALL.to_vec(),
    };
    let runs = CaseFile::read(case)?.expand_for(set, &harness::budget::limits(), None, &fs)?;
    let file = case.display().to_string();
    for spec in &runs {
        if spec.ancf.gust.is_none() {
            let msg = "gust: the case has no `gust` block (gradients and hinge states to sweep)".into();
            return Err(harness::Error::Case { file, msg }.into());
        }
    }
    let plan = harness::shard::plan("gust", shard, || {
        runs.iter().map(|r| Unit { id: format!("gust:{}", r.name), cost: harness::shard::run_cost(r) }).collect()
    })?;
    let mut done = Vec::new();
    let mut failed = false;
    for spec in runs.iter().filter(|r| runs_here(plan.as_ref(), &format!("gust:{}", r.name))) {
        done.push(format!("gust:{}", spec.name));
        failed |= gust_case(spec, &fs, out, &file)?;
    }
    if let Some(p) = &plan {
        p.write_manifest(out, serde_json::json!({}), &done)?;
    }
    Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
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
    runs: &[harness::case::RunSpec],
    quick: bool,
    stress_base: Option<&harness::case::RunSpec>,
    axes: &stress::Axes,
    extras: &[(String, harness::case::RunSpec)],
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
fn stress_units(
    base: &harness::case::RunSpec,
    axes: &stress::Axes,
    extras: &[(String, harness::case::RunSpec)],
) -> Vec<Unit> {
    let mut u: Vec<Unit> =
        stress::jobs(axes).iter().map(|j| Unit { id: stress::job_id(j), cost: stress::job_cost(base, j) }).collect();
    u.extend(extras.iter().map(|(l, r)| Unit { id: harness::merge::extra_unit(l), cost: harness::shard::run_cost(r) }));
    u
}

/// Run this shard's cells and extra runs of the stress study (all of them without a plan),
/// adding their units to `done`.
fn run_stress(
    base: &harness::case::RunSpec,
    axes: &stress::Axes,
    extras: &[(String, harness::case::RunSpec)],
    plan: Option<&Plan>,
    done: &mut Vec<String>,
) -> (Vec<stress::Cell>, Vec<stress::Extra>) {
    let jobs: Vec<stress::Job> =
        stress::jobs(axes).into_iter().filter(|j| runs_here(plan, &stress::job_id(j))).collect();
    let cells = stress::run_jobs(base, &jobs, true);
    done.extend(jobs.iter().map(stress::job_id));
    let mine: Vec<_> =
        extras.iter().filter(|(l, _)| runs_here(plan, &harness::merge::extra_unit(l))).cloned().collect();
    let ex = stress::run_extras(&mine);
    done.extend(mine.iter().map(|(l, _)| harness::merge::extra_unit(l)));
    (cells, ex)
}

/// The static sweeps of `spec` with the formulations `fs`, in parallel, summarised.
fn run_static_case(spec: &harness::case::RunSpec, fs: &[Formulation]) -> harness::static_out::StaticSummary {
    use rayon::prelude::*;
    let outs: Vec<_> = fs.par_iter().map(|&f| harness::statics::run_static(spec.case(f), f)).collect();
    let mut summary = harness::static_out::summarise(&spec.ancf, &spec.dir, outs);
    harness::static_hold::hold_references(spec, &mut summary);
    summary
}

/// Print a sweep's outcome; true when a point (or a point of the model held at the experiment) failed.
fn report_static(s: &harness::static_out::StaticSummary) -> bool {
    let structural = s.runs.iter().flat_map(|r| &r.points).any(|p| p.load_factor.is_some());
    for r in &s.runs {
        let ok = r.points.iter().filter(|p| p.error.is_none()).count();
        println!(
            "static {} {}: {ok} of {} {} in {:.3} s ({} steady solves, {} aerodynamic tangents, {} unknowns)",
            s.name,
            r.formulation,
            r.points.len(),
            if structural { "load factors" } else { "airspeeds" },
            r.wall_s,
            r.n_aero_solves,
            r.n_tangents,
            r.n_dof
        );
        for p in &r.points {
            if let Some(lf) = p.load_factor {
                // A structural static case: tip positions at the load factors.
                match &p.error {
                    Some(e) => eprintln!("  load factor {lf}: FAILED: {e}"),
                    None => println!(
                        "  load factor {lf:>6}  tip ({:.4}, {:.4}, {:.4})  ({} Newton)",
                        p.tip[0], p.tip[1], p.tip[2], p.newton_iterations
                    ),
                }
                continue;
            }
            match &p.error {
                Some(e) => eprintln!("  {} m/s: FAILED: {e}", p.airspeed),
                None => println!(
                    "  {:>5} m/s  fold {:>8.3} deg  RBM {:>9.5} N m  torque {:>9.5} N m  hinge {:>9.2e} N m  lift {:>8.4} N  ({} Newton)",
                    p.airspeed,
                    p.fold_deg,
                    p.loads.root_bending_moment,
                    p.loads.root_torque,
                    p.loads.hinge_moment,
                    p.lift,
                    p.newton_iterations
                ),
            }
        }
    }
    for r in &s.references {
        for (f, rms) in &r.rms_deg {
            println!("static {} {f}: RMS error against {} = {rms:.2} deg (12-33 m/s)", s.name, r.label);
        }
    }
    let mut held_failed = false;
    for h in &s.held {
        held_failed |= h.error.is_some();
        match &h.error {
            Some(e) => eprintln!(
                "static {} {}: held at {} deg at {} m/s: FAILED: {e}",
                s.name, h.formulation, h.coast_deg, h.airspeed
            ),
            None => println!(
                "static {} {}: held at the measured {:.2} deg at {} m/s: hinge moment {:+.5} N m ({:+.3e} m^3 x q), equivalent pitch {:+.2} deg",
                s.name,
                h.formulation,
                h.coast_deg,
                h.airspeed,
                h.hinge_moment,
                h.per_dynamic_pressure,
                h.equivalent_pitch_deg
            ),
        }
    }
    for c in &s.history {
        println!(
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
        );
        match &c.run_wake_error {
            Some(e) => println!(
                "static {} {}: static with the run's wake ({}) failed: {e}",
                s.name,
                c.formulation,
                harness::static_out::wake_label(&c.run_wake)
            ),
            None => println!(
                "static {} {}: static with the run's wake ({}): {:.4} m ({:+.2} %), {:.3} deg ({:+.3} deg)",
                s.name,
                c.formulation,
                harness::static_out::wake_label(&c.run_wake),
                c.run_wake_static_tip_z,
                100.0 * c.run_wake_tip_z_relative_difference,
                c.run_wake_static_fold_deg,
                c.run_wake_fold_difference_deg
            ),
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
        println!("static {}: ANCF-GEBF max tip distance {d:.4e} m", s.name);
    } else if s.runs.len() == 2 {
        println!(
            "static {}: ANCF-GEBF max fold difference {:.4} deg, max root bending moment difference {:.3} %",
            s.name,
            s.max_fold_difference_deg,
            100.0 * s.max_rbm_relative_difference
        );
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
            ExitCode::from(2)
        }
    }
}

/// Claim the runs' output folders, run them streaming their CSVs, write their files; returns the
/// results and whether a signal stopped them.
fn run_and_write(
    runs: &[harness::case::RunSpec],
    fs: &[Formulation],
    out: &std::path::Path,
    progress: &Progress,
    observer: &(dyn Fn(&harness::case::RunSpec, Formulation) -> Box<dyn harness::run::Observer> + Sync),
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
fn variants(
    mut runs: Vec<harness::case::RunSpec>,
    set: &[Override],
    fs: &[Formulation],
    max_steps: Option<usize>,
) -> Vec<harness::case::RunSpec> {
    for r in &mut runs {
        r.name = variant_name(&r.name, set, fs);
        if let Some(n) = max_steps {
            r.name.push_str(&format!("__max-steps-{n}"));
            limit_steps(r, n);
        }
    }
    runs
}

fn real_main() -> Result<ExitCode> {
    let cli = Cli::parse();
    harness::budget::set_limits(cli.max_memory, cli.max_hours);
    harness::signal::install();
    match cli.cmd {
        Cmd::Check { case, max_steps } => {
            use harness::fuzz::Class;
            let (class, msg) = harness::fuzz::check_file(&case, max_steps, &harness::budget::limits());
            match class {
                Class::Ok => {
                    println!("{}: ok", case.display());
                    Ok(ExitCode::SUCCESS)
                }
                Class::RunFailed => {
                    eprintln!("{}: a run failed: {msg}", case.display());
                    Ok(ExitCode::FAILURE)
                }
                Class::Panic => {
                    eprintln!("{}: panicked: {msg}", case.display());
                    Ok(ExitCode::from(101))
                }
                _ => {
                    eprintln!("error: {msg}");
                    Ok(ExitCode::from(2))
                }
            }
        }
        Cmd::FuzzWorker { max_steps } => {
            harness::fuzz::worker_main(max_steps)?;
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Fuzz { cases, out, inputs, first, seed, jobs, timeout, address_space_gb, max_steps, run, exec_each } => {
            let c = harness::fuzz::Campaign {
                cases,
                out: out.clone(),
                inputs,
                first,
                seed,
                jobs,
                timeout: std::time::Duration::from_secs(timeout),
                address_space: address_space_gb << 30,
                max_steps,
                run,
                exec_each,
            };
            let r = harness::fuzz::campaign(&c)?;
            println!("fuzz: {} inputs in {:.0} s, slowest {:.1} s", r.inputs, r.wall_s, r.slowest_s);
            for (k, n) in &r.classes {
                println!("  {k:?}: {n}");
            }
            println!("wrote {}", out.join("fuzz.md").display());
            let crashed = r.classes.iter().any(|(k, n)| k.is_crash() && *n > 0);
            Ok(if crashed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
        }
        Cmd::Schema => {
            use std::io::Write as _;
            // A closed pipe (`| head`) is not an error worth a panic.
            let _ = writeln!(std::io::stdout(), "{}", serde_json::to_string_pretty(&json_schema())?);
            Ok(ExitCode::SUCCESS)
        }
        Cmd::List { cases } => {
            let (runs, errors) = expand_all(&discover(&cases)?, &[]);
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
        Cmd::All { cases, out, set, quick, shard } => {
            let files = discover(&cases)?;
            let progress = Progress::new(true);
            progress.phase(&format!("reading {} case files in {}", files.len(), cases.display()));
            let (runs, errors) = expand_all(&files, &set);
            for e in &errors {
                eprintln!("error: {e}");
            }
            let all_runs = variants(runs, &set, &Formulation::ALL, None);
            // Studies of a run with overrides go to folders that say so too.
            let study = |name: &str| out.join(variant_name(name, &set, &Formulation::ALL));
            // The stress matrix's base case and extra runs (read here: a shard plans every unit).
            let base = files.iter().find(|f| f.ends_with("double_pendulum_c1_beta45.json"));
            let axes = stress::Axes::default();
            let stress_base = match base {
                Some(b) if !quick => Some(CaseFile::read(b).and_then(|c| c.expand(&set))?.remove(0)),
                _ => None,
            };
            let extras = if stress_base.is_some() { stress_extras(&cases, &set)? } else { Vec::new() };
            let plan = harness::shard::plan("all", shard.shard, || {
                all_units(&all_runs, quick, stress_base.as_ref(), &axes, &extras)
            })?;
            let here = |id: &str| runs_here(plan.as_ref(), id);
            let mut done: Vec<String> = Vec::new();
            let runs: Vec<_> = all_runs.iter().filter(|r| here(&run_unit(&r.name))).cloned().collect();
            let t0 = std::time::Instant::now();
            progress.phase(&format!("cases: {} runs x 2 formulations", runs.len()));
            // Each run also records its 3-D view for the report (and writes VTK where the case asks).
            let (results, interrupted) = run_and_write(&runs, &Formulation::ALL, &out, &progress, &|spec, f| {
                harness::view3d::report_observer(&out, spec, f)
            })?;
            let wall = t0.elapsed().as_secs_f64();
            if !interrupted {
                done.extend(runs.iter().map(|r| run_unit(&r.name)));
            }
            if !quick && !interrupted {
                for spec in all_runs.iter().filter(|r| r.ancf.converge && here(&format!("converge:{}", r.name))) {
                    progress.phase(&format!("refinement ladders of {}", spec.name));
                    let t = std::time::Instant::now();
                    let r = converge::converge(spec, true)?;
                    converge::write(&study("converge").join(&spec.name), &r)?;
                    println!("converge {}: {:.1} s", spec.name, t.elapsed().as_secs_f64());
                    done.push(format!("converge:{}", spec.name));
                }
                if let Some(spec) = &stress_base {
                    progress
                        .phase("stress matrix (c x beta x dt x rho_inf, both formulations), then its two long runs");
                    let t = std::time::Instant::now();
                    let (cells, ex) = run_stress(spec, &axes, &extras, plan.as_ref(), &mut done);
                    match &plan {
                        Some(p) => harness::merge::save_stress(&p.data_dir(&out), &cells, &ex)?,
                        None => {
                            stress::write(&study("stress"), &axes, &cells)?;
                            stress::write_extras(&study("stress"), &ex)?;
                        }
                    }
                    for f in Formulation::ALL {
                        let (ok, rec, n) = stress::survival(&cells, f);
                        println!(
                            "stress {f}: {ok} of {n} cells reach t_end at fixed steps, {rec} more with step control"
                        );
                    }
                    println!("stress matrix: {:.1} s", t.elapsed().as_secs_f64());
                }
                if here("energy") {
                    progress.phase("energy study (rho_inf = 1, both forms, dt and dt/2)");
                    run_energy(&all_runs, &study("energy"))?;
                    done.push("energy".into());
                }
                if here("bench") {
                    progress.phase("speed benchmark (serial repeated runs)");
                    let pendulums: Vec<_> = all_runs.iter().filter(|r| r.ancf.aero.is_none()).cloned().collect();
                    run_bench(&pendulums, 7, &study("bench"))?;
                    done.push("bench".into());
                }
            }
            let mut static_failed = 0;
            for spec in runs.iter().filter(|r| r.ancf.statics.is_some() && !interrupted) {
                progress.phase(&format!("static sweep of {}", spec.name));
                let t = std::time::Instant::now();
                let mut summary = run_static_case(spec, &Formulation::ALL);
                if let Some(r) = results.iter().find(|r| r.name == spec.name) {
                    harness::static_out::compare_with_history(&mut summary, spec, &r.runs);
                }
                harness::static_out::write(&out.join(&spec.name), &summary)?;
                static_failed += usize::from(report_static(&summary));
                println!("static {}: {:.1} s", spec.name, t.elapsed().as_secs_f64());
            }
            let mut stability_failed = 0;
            for spec in runs.iter().filter(|r| r.ancf.stability.is_some() && !interrupted) {
                progress.phase(&format!("stability sweep of {}", spec.name));
                let t = std::time::Instant::now();
                let outs = run_stability_case(spec, &Formulation::ALL);
                let history = results.iter().find(|r| r.name == spec.name).map(|r| r.metrics.clone());
                harness::stability_out::write_with_history(&out.join(&spec.name), &spec.name, &outs, history.as_ref())?;
                stability_failed += usize::from(report_stability(&spec.name, &outs));
                println!("stability {}: {:.1} s", spec.name, t.elapsed().as_secs_f64());
            }
            // The gust sweeps (several minutes of CPU): not with --quick, and on a cluster as
            // their own array (`harness gust --shard`).
            let mut gust_failed = 0;
            if !quick && plan.is_none() {
                for spec in runs.iter().filter(|r| r.ancf.gust.is_some() && !interrupted) {
                    progress.phase(&format!("gust sweep of {}", spec.name));
                    let t = std::time::Instant::now();
                    let file = spec.dir.join(format!("{}.json", spec.name)).display().to_string();
                    gust_failed += usize::from(gust_case(spec, &Formulation::ALL, &out, &file)?);
                    println!("gust {}: {:.1} s", spec.name, t.elapsed().as_secs_f64());
                }
            }
            match &plan {
                Some(p) => {
                    progress.phase("shard: the exact runs and the manifest for `harness merge`");
                    for (spec, r) in runs.iter().zip(&results) {
                        harness::merge::save_case(&p.data_dir(&out), spec, r)?;
                    }
                    let stress_dir = variant_name("stress", &set, &Formulation::ALL);
                    let args = serde_json::json!({ "report": true, "stress_dir": stress_dir, "axes": axes });
                    p.write_manifest(&out, args, &done)?;
                }
                None => {
                    progress.phase("reports: index.html, summary.md");
                    write_index(&out, &results).context("writing reports")?;
                }
            }
            print!("{}", gate::table(&results));
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
            if static_failed > 0 {
                eprintln!("static: {static_failed} sweep(s) have airspeeds without an equilibrium");
            }
            if stability_failed > 0 {
                eprintln!("stability: {stability_failed} sweep(s) have airspeeds that could not be analysed");
            }
            if gust_failed > 0 {
                eprintln!("gust: {gust_failed} sweep(s) have runs that failed");
            }
            if interrupted {
                eprintln!("interrupted: the rows computed so far are written; studies skipped");
                return Ok(ExitCode::from(harness::signal::EXIT_INTERRUPTED));
            }
            Ok(exit_code(
                &errors,
                failed == 0 && gate_failed == 0 && static_failed == 0 && stability_failed == 0 && gust_failed == 0,
            ))
        }
        Cmd::Run { case, formulation, out, set, vtk, vtk_stride, max_steps } => {
            let fs: Vec<Formulation> = match formulation {
                Which::Ancf => vec![Formulation::Ancf],
                Which::Gebf => vec![Formulation::Gebf],
                Which::Both => Formulation::ALL.to_vec(),
            };
            let limits = harness::budget::limits();
            let file = CaseFile::read(&case)?;
            let runs = variants(file.expand_for(&set, &limits, max_steps, &fs)?, &set, &fs, max_steps);
            let progress = Progress::new(true);
            // VTK when --vtk asks for it or the case's `vtk` block does.
            let cli = vtk.then_some(vtk_stride);
            let vtk_out = out.clone();
            let observer = move |spec: &harness::case::RunSpec, f: Formulation| -> Box<dyn harness::run::Observer> {
                match harness::vtk::writer_for(&vtk_out, spec, f, cli) {
                    Some(w) => Box::new(w),
                    None => Box::new(harness::run::NoObserver),
                }
            };
            let (results, interrupted) = run_and_write(&runs, &fs, &out, &progress, &observer)?;
            let mut failed = false;
            for r in &results {
                let dir = out.join(&r.name);
                for run in &r.runs {
                    let m = &r.metrics[&run.formulation];
                    match &run.error {
                        Some(e) => {
                            failed = true;
                            eprintln!("{} {}: FAILED: {e}", r.name, run.formulation);
                        }
                        None => println!(
                            "{} {}: {} steps in {:.1} ms, {:.2} Newton/step, energy drift {:.2e}, max constraint {:.1e} -> {}",
                            r.name,
                            run.formulation,
                            m.n_steps,
                            1e3 * m.wall_s,
                            m.newton_per_step,
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
            }
            if interrupted {
                eprintln!("interrupted: the rows computed so far are written; summary.json says \"interrupted\"");
                return Ok(ExitCode::from(harness::signal::EXIT_INTERRUPTED));
            }
            Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
        }
        Cmd::Static { case, formulation, out, set, shard } => {
            let file = CaseFile::read(&case)?;
            let fs: Vec<Formulation> = match formulation {
                Which::Ancf => vec![Formulation::Ancf],
                Which::Gebf => vec![Formulation::Gebf],
                Which::Both => Formulation::ALL.to_vec(),
            };
            let runs = file.expand_for(&set, &harness::budget::limits(), None, &fs)?;
            let plan = harness::shard::plan("static", shard.shard, || {
                runs.iter()
                    .map(|r| Unit { id: format!("static:{}", r.name), cost: harness::shard::run_cost(r) })
                    .collect()
            })?;
            for spec in &runs {
                if spec.ancf.statics.is_none() {
                    return Err(harness::Error::Case {
                        file: case.display().to_string(),
                        msg: "static: the case has no `static` block (airspeeds to sweep)".into(),
                    }
                    .into());
                }
            }
            let mut failed = false;
            let mut done = Vec::new();
            for spec in runs.iter().filter(|r| runs_here(plan.as_ref(), &format!("static:{}", r.name))) {
                let summary = run_static_case(spec, &fs);
                let dir = out.join(&spec.name);
                harness::static_out::write(&dir, &summary)?;
                failed |= report_static(&summary);
                println!("wrote {}", dir.display());
                done.push(format!("static:{}", spec.name));
            }
            if let Some(p) = &plan {
                p.write_manifest(&out, serde_json::json!({}), &done)?;
            }
            Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
        }
        Cmd::Stability { case, formulation, out, set, shard } => {
            let file = CaseFile::read(&case)?;
            let fs: Vec<Formulation> = match formulation {
                Which::Ancf => vec![Formulation::Ancf],
                Which::Gebf => vec![Formulation::Gebf],
                Which::Both => Formulation::ALL.to_vec(),
            };
            let runs = file.expand_for(&set, &harness::budget::limits(), None, &fs)?;
            for spec in &runs {
                if spec.ancf.stability.is_none() {
                    return Err(harness::Error::Case {
                        file: case.display().to_string(),
                        msg: "stability: the case has no `stability` block (airspeeds to analyse)".into(),
                    }
                    .into());
                }
            }
            let plan = harness::shard::plan("stability", shard.shard, || {
                runs.iter()
                    .map(|r| Unit { id: format!("stability:{}", r.name), cost: harness::shard::run_cost(r) })
                    .collect()
            })?;
            let mut failed = false;
            let mut done = Vec::new();
            for spec in runs.iter().filter(|r| runs_here(plan.as_ref(), &format!("stability:{}", r.name))) {
                let outs = run_stability_case(spec, &fs);
                let dir = out.join(&spec.name);
                harness::stability_out::write_with_history(&dir, &spec.name, &outs, None)?;
                failed |= report_stability(&spec.name, &outs);
                println!("wrote {}", dir.display());
                done.push(format!("stability:{}", spec.name));
            }
            if let Some(p) = &plan {
                p.write_manifest(&out, serde_json::json!({}), &done)?;
            }
            Ok(if failed { ExitCode::FAILURE } else { ExitCode::SUCCESS })
        }
        Cmd::Gust { case, formulation, out, set, shard } => run_gust(&case, formulation, &out, &set, shard.shard),
        Cmd::Converge { case, out, set, shard } => {
            let runs = CaseFile::read(&case).and_then(|c| c.expand(&set))?;
            let plan = harness::shard::plan("converge", shard.shard, || {
                runs.iter()
                    .map(|r| Unit {
                        id: format!("converge:{}", r.name),
                        cost: LADDER_COST * harness::shard::run_cost(r),
                    })
                    .collect()
            })?;
            let mut done = Vec::new();
            for spec in runs.iter().filter(|r| runs_here(plan.as_ref(), &format!("converge:{}", r.name))) {
                let r = converge::converge(spec, true)?;
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
                p.write_manifest(&out, serde_json::json!({}), &done)?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Merge { dirs, out } => {
            let m = harness::merge::merge(&dirs, &out)?;
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
        Cmd::Stress { case, out, set, shard } => {
            let runs = CaseFile::read(&case).and_then(|c| c.expand(&set))?;
            let base = runs.first().context("the base case expands into no run")?;
            let axes = stress::Axes::default();
            let extras = stress_extras(&case.with_file_name(""), &set)?;
            let plan = harness::shard::plan("stress", shard.shard, || stress_units(base, &axes, &extras))?;
            let t0 = std::time::Instant::now();
            let mut done = Vec::new();
            let (cells, ex) = run_stress(base, &axes, &extras, plan.as_ref(), &mut done);
            let dir = out.join("stress");
            for f in Formulation::ALL {
                let (ok, rec, n) = stress::survival(&cells, f);
                println!("{f}: {ok} of {n} cells reach t_end at fixed steps, {rec} more with step control");
            }
            match &plan {
                Some(p) => {
                    harness::merge::save_stress(&p.data_dir(&out), &cells, &ex)?;
                    let args = serde_json::json!({ "report": false, "stress_dir": "stress", "axes": axes });
                    p.write_manifest(&out, args, &done)?;
                }
                None => {
                    stress::write(&dir, &axes, &cells)?;
                    stress::write_extras(&dir, &ex)?;
                }
            }
            for e in &ex {
                let m = &e.metrics;
                println!(
                    "{} {}: {}",
                    e.label,
                    e.formulation,
                    m.error.clone().unwrap_or_else(|| format!(
                        "ok, {:.2} Newton/step, drift {:.2e}",
                        m.newton_per_step, m.energy_drift
                    ))
                );
                if let Some(r) = &e.recovery {
                    println!(
                        "  with step control: {}",
                        r.error.clone().unwrap_or_else(|| format!(
                            "ok, {:.2} Newton/step, drift {:.2e}",
                            r.newton_per_step, r.energy_drift
                        ))
                    );
                }
            }
            println!("stress matrix in {:.1} s; wrote {}", t0.elapsed().as_secs_f64(), dir.display());
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Energy { cases, out, set } => {
            let (runs, errors) = expand_all(&discover(&cases)?, &set);
            for e in &errors {
                eprintln!("error: {e}");
            }
            let ok = run_energy(&runs, &out.join("energy"))?;
            Ok(if !errors.is_empty() {
                ExitCode::from(2)
            } else if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Cmd::Bench { files, cases, repeats, out, set } => {
            let explicit = !files.is_empty();
            let files = if explicit { files } else { discover(&cases)? };
            let (runs, errors) = expand_all(&files, &set);
            for e in &errors {
                eprintln!("error: {e}");
            }
            let runs: Vec<_> = runs.into_iter().filter(|r| explicit || r.ancf.aero.is_none()).collect();
            let rows = run_bench(&runs, repeats, &out.join("bench"))?;
            let failed = rows.iter().filter(|r| r.error.is_some()).count();
            Ok(exit_code(&errors, failed == 0))
        }
        Cmd::Gate { files, cases, set } => {
            let files = if files.is_empty() { discover(&cases)? } else { files };
            let (runs, errors) = expand_all(&files, &set);
            for e in &errors {
                eprintln!("error: {e}");
            }
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
    }
}
