//! Run one double-pendulum case (docs/cases.md §1) and compare the tip with a reference CSV.
//!
//! Usage: `pendulum_check c beta_deg n_el dt rho_inf [hybrid|kirchhoff|mixed] [dae|ode] [reference.csv]`
//!
//! Environment: `OUT=file.csv` writes `t,tip_x,tip_y,tip_z`; `KAPPA`, `PEN` set the
//! shear-gradient and penalty factors; `KINDS=1` prints the elastic energy by strain kind;
//! `FAST=1` skips all sensors (timing); `NOEST=1` switches genalpha's convergence estimate off;
//! `FULL=1` refactorises at every Newton iteration.
use ancf::{Curvature, Model, Options, SolvePath, samples};
use genalpha::IntegratorParams;
use nalgebra::Vector3;
use std::io::Write;
use std::time::Instant;

fn reference(path: &str) -> Vec<(f64, Vector3<f64>)> {
    std::fs::read_to_string(path)
        .expect("readable reference")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('t'))
        .map(|l| {
            let v: Vec<f64> = l.split(',').take(4).map(|x| x.parse().expect("a number")).collect();
            (v[0], Vector3::new(v[1], v[2], v[3]))
        })
        .collect()
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 6 {
        eprintln!(
            "usage: pendulum_check c beta_deg n_el dt rho_inf [hybrid|kirchhoff|mixed] [dae|ode] [reference.csv]"
        );
        std::process::exit(2);
    }
    let num = |i: usize| a[i].parse::<f64>().expect("a number");
    let (c, beta, n_el, dt, rho) = (num(1), num(2), num(3) as usize, num(4), num(5));
    let curvature = match a.get(6).map(String::as_str) {
        Some("kirchhoff") => Curvature::Kirchhoff,
        Some("mixed") => Curvature::Mixed,
        _ => Curvature::Hybrid,
    };
    let path = if a.get(7).map(String::as_str) == Some("ode") { SolvePath::Ode } else { SolvePath::Dae };
    let reference = a.get(8).map(|p| reference(p)).unwrap_or_default();
    let env = |k: &str, d: f64| std::env::var(k).ok().map(|v| v.parse::<f64>().expect("a number")).unwrap_or(d);
    let flag = |k: &str| std::env::var(k).is_ok();

    let (bodies, joints, g) = samples::double_pendulum(c, beta, n_el);
    let options = Options {
        path,
        curvature,
        penalty_factor: env("PEN", 1.0),
        joint_tie_factor: env("TIE", Options::default().joint_tie_factor),
    };
    let mut model = Model::new(&bodies, &joints, g, options).expect("valid scene");
    let mut params = IntegratorParams::new(rho, dt);
    params.newton.estimate_convergence = !flag("NOEST");
    params.newton.reuse_factorization = !flag("FULL");
    let mut ga = model.integrator(params).expect("valid parameters");
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).expect("consistent start");
    let mut out = std::env::var("OUT").ok().map(|p| std::fs::File::create(p).expect("writable output"));

    let n = (2.0 / dt).round() as usize;
    let e0 = model.energies(&s.q, &s.v).total();
    let (mut max_err, mut t_err, mut t_max, mut drift, mut max_res) = (0.0_f64, 0.0, 0.0_f64, 0.0_f64, 0.0_f64);
    let t0 = Instant::now();
    for k in 0..n {
        if let Err(e) = ga.step(&mut model, &mut s) {
            println!("step {k}: {e}");
            break;
        }
        if flag("FAST") {
            continue;
        }
        let tip = model.tip_position(&s.q);
        let en = model.energies(&s.q, &s.v);
        t_max = t_max.max(en.kinetic);
        drift = drift.max((en.total() - e0).abs());
        max_res = max_res.max(model.constraint_residual(&s.q));
        if let Some(f) = out.as_mut() {
            writeln!(f, "{},{},{},{}", s.t, tip.x, tip.y, tip.z).expect("writable output");
        }
        if flag("KINDS") && (k + 1) % (n / 20).max(1) == 0 {
            let u = model.elastic_energy_by_kind(&s.q);
            println!("t {:.3} U {:.3e} by kind {:?}", s.t, en.elastic, u.map(|x| format!("{x:.2e}")));
        }
        if !reference.is_empty() {
            let i = reference.partition_point(|r| r.0 <= s.t).clamp(1, reference.len() - 1);
            let (r0, r1) = (reference[i - 1], reference[i]);
            let p = r0.1 + (r1.1 - r0.1) * ((s.t - r0.0) / (r1.0 - r0.0));
            let err = (tip - p).norm();
            if err > max_err {
                (max_err, t_err) = (err, s.t);
            }
        }
    }
    let st = ga.stats();
    println!(
        "wall {:.3?} steps {} newton {} (max {}) factorizations {} residuals {} halvings {} | max tip error {:.3e} m at t = {:.3} | \
         energy drift / T_max {:.3e} | max constraint residual {:.2e}",
        t0.elapsed(),
        st.n_steps,
        st.n_newton_iters,
        st.max_newton_iters,
        st.n_factorizations,
        st.n_residual_evals,
        st.n_step_halvings,
        max_err,
        t_err,
        drift / t_max,
        max_res
    );
}
