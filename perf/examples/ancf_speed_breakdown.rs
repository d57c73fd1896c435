//! Work counts and wall time of the paper's five double-pendulum cases at the paper's settings
//! (5 elements per body, dt = 0.002 s, 2 s, rho_inf = 0.8), DAE and ODE paths.
//!
//! Usage: `speed_breakdown [repeats]` (release build; the fastest of `repeats` runs is shown).
//!
//! Environment: `SOLVER=banded` uses genalpha's `DenseLu` with the declared band structure
//! instead of `SkylineLu`; `RTOL`, `ATOL` override the Newton increment tolerances;
//! `NOEST=1` switches the convergence estimate off; `MAXC` sets the contraction rate above which a
//! reused factorisation is refreshed; `PRED=ext` extrapolates the acceleration in the predictor; `FULL=1` refactorises at every Newton iteration; `OUT=dir` writes every step's tip as
//! `dir/<case>.csv`; `REF=dir` compares the tip with such files and prints the largest
//! distance relative to the largest tip excursion from its start; `ONLY=<name>` (e.g.
//! `c1_beta45_Dae`) runs one case on one path, for a profile.
use ancf::{Model, Options, SolvePath, samples};
use genalpha::{GenAlpha, IntegratorParams, LinearSolver, State, Stats};
use nalgebra::Vector3;
use std::time::{Duration, Instant};

fn run_with<L: LinearSolver>(
    model: &mut Model,
    mut ga: GenAlpha<L>,
    tips: &mut Vec<Vector3<f64>>,
) -> Result<(Duration, Stats), genalpha::Error> {
    let mut s: State = model.initial_state();
    tips.clear();
    tips.push(model.tip_position(&s.q));
    let t0 = Instant::now();
    ga.initialize(model, &mut s)?;
    for _ in 0..1000 {
        ga.step(model, &mut s)?;
        tips.push(model.tip_position(&s.q));
    }
    Ok((t0.elapsed(), *ga.stats()))
}

fn main() {
    let repeats: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(3);
    let env = |k: &str| std::env::var(k).ok();
    let banded = env("SOLVER").as_deref() == Some("banded");
    println!("case                  wall_ms  newton/step  fact/step  resid/step  halvings  tip_z       dev/excursion");
    let mut tips = Vec::new();
    for (c, beta) in samples::PAPER_CASES {
        for path in [SolvePath::Dae, SolvePath::Ode] {
            let name = format!("c{c}_beta{beta}_{path:?}");
            if env("ONLY").is_some_and(|only| only != name) {
                continue;
            }
            let (bodies, joints, g) = samples::double_pendulum(c, beta, 5);
            let mut model =
                Model::new(&bodies, &joints, g, Options { path, ..Default::default() }).expect("valid case");
            let mut params = IntegratorParams::new(0.8, 0.002);
            params.newton.estimate_convergence = env("NOEST").is_none();
            if let Some(x) = env("RTOL") {
                params.newton.rtol = x.parse().expect("a number");
            }
            if env("PRED").as_deref() == Some("ext") {
                params.newton.predictor = genalpha::Predictor::ExtrapolatedAcceleration;
            }
            if let Some(x) = env("MAXC") {
                params.newton.max_contraction = x.parse().expect("a number");
            }
            if let Some(x) = env("ATOL") {
                params.newton.atol = x.parse().expect("a number");
            }
            params.newton.reuse_factorization = env("FULL").is_none();
            let mut best: Option<(Duration, Stats)> = None;
            for _ in 0..repeats {
                let out = if banded {
                    let ga = GenAlpha::new(params, &model).expect("valid parameters");
                    run_with(&mut model, ga, &mut tips)
                } else {
                    let ga = model.integrator(params).expect("valid parameters");
                    run_with(&mut model, ga, &mut tips)
                };
                match out {
                    Ok(r) => {
                        if best.as_ref().is_none_or(|b| r.0 < b.0) {
                            best = Some(r);
                        }
                    }
                    Err(e) => {
                        println!("{name}: {e}");
                        break;
                    }
                }
            }
            let Some((wall, st)) = best else { continue };
            let per = |x: usize| x as f64 / st.n_steps as f64;
            let mut dev = String::new();
            if let Some(dir) = env("REF") {
                let text = std::fs::read_to_string(format!("{dir}/{name}.csv")).expect("reference file");
                let reference: Vec<Vector3<f64>> = text
                    .lines()
                    .map(|l| {
                        let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("a number")).collect();
                        Vector3::new(v[0], v[1], v[2])
                    })
                    .collect();
                let excursion = reference.iter().map(|p| (p - reference[0]).norm()).fold(0.0, f64::max);
                let d = tips.iter().zip(&reference).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
                dev = format!("{:.2e}", d / excursion);
            }
            if let Some(dir) = env("OUT") {
                let text: String = tips.iter().map(|p| format!("{:e},{:e},{:e}\n", p.x, p.y, p.z)).collect();
                std::fs::write(format!("{dir}/{name}.csv"), text).expect("writable output");
            }
            println!(
                "{name:<22}{:>8.1}{:>13.2}{:>11.2}{:>12.2}{:>10}  {:<+.6e}  {dev}",
                wall.as_secs_f64() * 1e3,
                per(st.n_newton_iters),
                per(st.n_factorizations),
                per(st.n_residual_evals),
                st.n_step_halvings,
                tips.last().map_or(f64::NAN, |p| p.z),
            );
        }
    }
}
