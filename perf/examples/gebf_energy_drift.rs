//! Energy drift of the c = 1 paper double pendulum against the time step and the number of
//! elements: max over 2 s of |E(t) − E(0)| divided by the run's peak kinetic energy
//! (docs/outputs.md §3), with the largest joint violation of the run.
//!
//! `cargo run --release -p perf --example gebf_energy_drift -- [c] [rho_inf] [stabilization 0/1]`
use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let get = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (c, rho) = (get(1, 1.0), get(2, 1.0));
    let stabilization = get(3, 0.0) != 0.0;
    println!("c = {c}, rho_inf = {rho}, stabilization = {stabilization}");
    println!("beta  n_el  dt       drift/T_max  max joint violation  Newton/step");
    for beta in [0.0, 45.0, 90.0] {
        for n_el in [5, 10] {
            for dt in [0.002, 0.001, 0.0005] {
                let (b, j, g) = samples::double_pendulum(c, beta, n_el);
                let mut m = Model::new(&b, &j, g, Options { stabilization, ..Options::default() })?;
                let (rec, st) = simulate::record(&mut m, IntegratorParams::new(rho, dt), 2.0)?;
                let e0 = rec[0].energies.total();
                let t_max = rec.iter().map(|s| s.energies.kinetic).fold(0.0, f64::max);
                let drift = rec.iter().map(|s| (s.energies.total() - e0).abs()).fold(0.0, f64::max) / t_max;
                let viol = rec.iter().map(|s| s.constraint_residual).fold(0.0, f64::max);
                println!(
                    "{beta:4}  {n_el:4}  {dt:.4}   {drift:.3e}    {viol:.3e}            {:.2}",
                    st.n_newton_iters as f64 / st.n_steps as f64
                );
            }
        }
    }
    Ok(())
}
