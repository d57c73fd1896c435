//! Run one paper double-pendulum case and print tip, fold, energy and joint drift.
//! `cargo run --release -p gebf --example pendulum -- <c> <beta_deg> [n_el] [dt] [rho_inf] [stab]`
use gebf::{Model, Options, samples, simulate};
use genalpha::IntegratorParams;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let get = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (c, beta, n_el, dt, rho) = (get(1, 1.0), get(2, 45.0), get(3, 5.0) as usize, get(4, 0.002), get(5, 0.8));
    let stab = get(6, 0.0) != 0.0;
    let (b, j, g) = samples::double_pendulum(c, beta, n_el);
    let mut m = Model::new(&b, &j, g, Options { stabilization: stab, ..Options::default() })?;
    if std::env::var("TRACE").is_ok() {
        let mut p = IntegratorParams::new(rho, dt);
        p.newton.reuse_factorization = std::env::var("NOREUSE").is_err();
        let mut ga = genalpha::GenAlpha::new(p, &m)?;
        let mut s = m.initial_state();
        ga.initialize(&m, &mut s)?;
        for _ in 0..(2.0 / dt) as usize {
            match ga.step(&mut m, &mut s) {
                Ok(st) => {
                    if let Ok(k) = std::env::var("DOF") {
                        let k: usize = k.parse().unwrap();
                        if s.t > 1.6 { println!("t {:.4} v[{k}] {:.3} vdot {:.3e} it {}", s.t, s.v[k], s.v_dot[k], st.n_newton_iters); }
                        continue;
                    }
                    if ((s.t / dt).round() as usize) % 10 == 0 {
                        { let e = m.energies(&s.q, &s.v); println!("t {:.3} maxrot {:.3} it {} res {:.2e} E {:.4e} T {:.4} U {:.4} tip {:.4?}", s.t, m.max_nodal_rotation(&s.q), st.n_newton_iters, m.constraint_residual(&s.q), e.total(), e.kinetic, e.elastic, m.tip_position(&s.q).as_slice()); }
                    }
                }
                Err(e) => {
                    println!("{e} maxrot {:.3}", m.max_nodal_rotation(&s.q));
                    break;
                }
            }
        }
        return Ok(());
    }
    let t0 = std::time::Instant::now();
    let (rec, stats) = simulate::record(&mut m, IntegratorParams::new(rho, dt), 2.0)?;
    let wall = t0.elapsed();
    let every = (0.1 / dt).round() as usize;
    for s in rec.iter().step_by(every) {
        println!(
            "t {:.3} tip {:9.5} {:9.5} {:9.5} fold {:8.3} deg  E {:+.3e}  T {:.4} U {:.3e} res {:.2e} it {}",
            s.t,
            s.tip.x,
            s.tip.y,
            s.tip.z,
            s.fold.to_degrees(),
            s.energies.total(),
            s.energies.kinetic,
            s.energies.elastic,
            s.constraint_residual,
            s.newton_iterations
        );
    }
    println!("{stats:?} wall {wall:?}");
    if let Some(path) = a.get(7) {
        let mut out = String::from("t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,residual\n");
        for s in &rec {
            out += &format!(
                "{},{},{},{},{},{},{},{},{},{}\n",
                s.t, s.tip.x, s.tip.y, s.tip.z, s.fold, s.energies.kinetic, s.energies.elastic,
                s.energies.potential, s.energies.total(), s.constraint_residual
            );
        }
        std::fs::write(path, out)?;
    }
    Ok(())
}
