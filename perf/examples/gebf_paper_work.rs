//! Work counters and CPU time of the five paper double-pendulum cases at the benchmark's
//! settings (5 elements per body, dt = 0.002, 2 s, rho_inf = 0.8): steps, Newton iterations,
//! factorisations, residual evaluations, step halvings, and the thread CPU time of the run.
//!
//! `cargo run --release -p perf --example gebf_paper_work -- [repeats] [dump_dir]`
//!
//! With `dump_dir`, the tip trajectory of each case (t, x, y, z per step, full precision) is
//! written to `dump_dir/tip_c{c}_beta{beta}.txt`, to compare runs before and after a change.
use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;

/// CPU time of the calling thread, s (less sensitive to other processes than wall time).
fn thread_cpu() -> f64 {
    perf::thread_cpu_ns() as f64 * 1e-9
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let repeats: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let dump_dir = std::env::args().nth(2);
    for (c, beta) in samples::PAPER_CASES {
        let mut cpu = Vec::new();
        let mut wall = Vec::new();
        let mut stats = None;
        for _ in 0..repeats {
            let (b, j, g) = samples::double_pendulum(c, beta, 5);
            let (c0, t0) = (thread_cpu(), std::time::Instant::now());
            let mut m = Model::new(&b, &j, g, Options::default())?;
            let mut z = 0.0;
            let (_, st) =
                simulate::run(&mut m, IntegratorParams::new(0.8, 0.002), 2.0, |m, s, _| z += m.tip_position(&s.q).z)?;
            wall.push(t0.elapsed().as_secs_f64() * 1e3);
            cpu.push((thread_cpu() - c0) * 1e3);
            std::hint::black_box(z);
            stats = Some(st);
        }
        if let Some(dir) = &dump_dir {
            let (b, j, g) = samples::double_pendulum(c, beta, 5);
            let mut m = Model::new(&b, &j, g, Options::default())?;
            let mut out = String::new();
            simulate::run(&mut m, IntegratorParams::new(0.8, 0.002), 2.0, |m, s, _| {
                let p = m.tip_position(&s.q);
                out.push_str(&format!("{:.17e} {:.17e} {:.17e} {:.17e}\n", s.t, p.x, p.y, p.z));
            })?;
            std::fs::write(format!("{dir}/tip_c{c}_beta{beta}.txt"), out)?;
        }
        wall.sort_by(f64::total_cmp);
        cpu.sort_by(f64::total_cmp);
        let st = stats.expect("repeats ≥ 1");
        println!(
            "c {c:<5} beta {beta:>4}: wall median {:7.1} ms (min {:7.1}), cpu median {:7.1} ms | steps {} newton {} ({:.2}/step, max {}) factorisations {} residuals {} halvings {}",
            wall[wall.len() / 2],
            wall[0],
            cpu[cpu.len() / 2],
            st.n_steps,
            st.n_newton_iters,
            st.n_newton_iters as f64 / st.n_steps as f64,
            st.max_newton_iters,
            st.n_factorizations,
            st.n_residual_evals,
            st.n_step_halvings
        );
    }
    Ok(())
}
