//! Run one double-pendulum case and compare the tip with a reference CSV.
//! Usage: pendulum_check c beta_deg n_el dt rho_inf [kirchhoff|mixed] [dae|ode] [reference.csv]
use ancf::{Curvature, Model, Options, SolvePath, samples};
use genalpha::IntegratorParams;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let c: f64 = a[1].parse().unwrap();
    let beta: f64 = a[2].parse().unwrap();
    let n_el: usize = a[3].parse().unwrap();
    let dt: f64 = a[4].parse().unwrap();
    let rho: f64 = a[5].parse().unwrap();
    let curvature = match a.get(6).map(|s| s.as_str()) {
        Some("mixed") => Curvature::Mixed,
        Some("kirchhoff") => Curvature::Kirchhoff,
        _ => Curvature::Hybrid,
    };
    let path = match a.get(7).map(|s| s.as_str()) {
        Some("ode") => SolvePath::Ode,
        _ => SolvePath::Dae,
    };
    let reference: Vec<[f64; 4]> = a
        .get(8)
        .map(|p| {
            std::fs::read_to_string(p)
                .unwrap()
                .lines()
                .filter(|l| !l.starts_with('#') && !l.starts_with('t'))
                .map(|l| {
                    let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                    [v[0], v[1], v[2], v[3]]
                })
                .collect()
        })
        .unwrap_or_default();
    let (mut bodies, joints, g) = samples::double_pendulum(c, beta, n_el);
    let env = |k: &str, d: f64| std::env::var(k).ok().map(|v| v.parse::<f64>().unwrap()).unwrap_or(d);
    for b in &mut bodies {
        b.section.ga_y *= env("GAFAC", 1.0);
        b.section.ga_z *= env("GAFAC", 1.0);
        b.section.ei_yy *= env("EIFAC", 1.0);
        b.section.ei_zz *= env("EIFAC", 1.0);
        b.section.gj *= env("GJFAC", 1.0);
        b.section.rho_ixx *= env("JFAC", 1.0);
        b.section.rho_iyy *= env("JFAC", 1.0);
        b.section.rho_izz *= env("JFAC", 1.0);
    }
    let penalty_factor = env("PEN", 1.0);
    let shear_gradient_factor = env("KAPPA", 1000.0);
    let mut model =
        Model::new(&bodies, &joints, g, Options { path, curvature, penalty_factor, shear_gradient_factor }).unwrap();
    let mut params = IntegratorParams::new(rho, dt);
    if std::env::var("NOEST").is_ok() {
        params.newton.estimate_convergence = false;
    }
    if let Ok(h) = std::env::var("HALVINGS") {
        params.newton.max_step_halvings = h.parse().unwrap();
    }
    let mut ga = genalpha::GenAlpha::with_solver(params, &model, model.linear_solver()).unwrap();
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).unwrap();
    let n = (2.0 / dt).round() as usize;
    let t0 = Instant::now();
    let mut out = std::env::var("OUT").ok().map(|p| std::fs::File::create(p).unwrap());
    let mut max_err: f64 = 0.0;
    let mut t_max = 0.0;
    let e0 = model.energies(&s.q, &s.v).total();
    let (mut max_t, mut drift, mut max_res, mut max_y, mut max_fold): (f64, f64, f64, f64, f64) =
        (0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 0..n {
        match ga.step(&mut model, &mut s) {
            Err(e) => {
                println!("step {k}: {e}");
                break;
            }
            Ok(st) => {
                if std::env::var("STEPSTATS").is_ok() && (k % 200 < 5 || st.n_substeps > 1 || st.n_newton_iters > 8) {
                    println!("step {k}: {st:?}");
                }
            }
        }
        if std::env::var("FAST").is_ok() {
            continue;
        }
        let tip = model.tip_position(&s.q);
        if let Some(f) = out.as_mut() {
            use std::io::Write;
            writeln!(f, "{},{},{},{}", s.t, tip.x, tip.y, tip.z).unwrap();
        }
        let en = model.energies(&s.q, &s.v);
        if std::env::var("NODES").is_ok() && (k + 1) % (n / 20) == 0 {
            let qf = model.full_coordinates(&s.q);
            let mut line = String::new();
            for node in 0..qf.len() / 12 {
                let v = |b: usize| {
                    nalgebra::Vector3::new(qf[12 * node + 3 * b], qf[12 * node + 3 * b + 1], qf[12 * node + 3 * b + 2])
                };
                let eyy = 0.5 * (v(2).norm_squared() - 1.0);
                let exx = 0.5 * (v(1).norm_squared() - 1.0);
                line += &format!(" {:.0}/{:.0}", eyy * 1e6, exx * 1e6);
            }
            println!("t {:.3} eps_yy/eps_xx (1e-6) per node:{}", s.t, line);
        }
        if std::env::var("KINDS").is_ok() && (k + 1) % (n / 20) == 0 {
            let u = model.elastic_energy_by_kind(&s.q);
            println!("t {:.3} U {:.3e} by kind {:?}", s.t, en.elastic, u.map(|x| format!("{x:.2e}")));
        }
        max_t = max_t.max(en.kinetic);
        drift = drift.max((en.total() - e0).abs());
        max_res = max_res.max(model.constraint_residual(&s.q));
        max_y = max_y.max(tip.y.abs());
        max_fold = max_fold.max(model.fold_angle(&s.q, 1).unwrap().abs());
        if !reference.is_empty() {
            let t = s.t;
            let i = reference.partition_point(|r| r[0] <= t).clamp(1, reference.len() - 1);
            let (r0, r1) = (reference[i - 1], reference[i]);
            let w = (t - r0[0]) / (r1[0] - r0[0]);
            let p: Vec<f64> = (1..4).map(|j| r0[j] + w * (r1[j] - r0[j])).collect();
            let err = ((tip.x - p[0]).powi(2) + (tip.y - p[1]).powi(2) + (tip.z - p[2]).powi(2)).sqrt();
            if err > max_err {
                max_err = err;
                t_max = t;
            }
            if (k + 1) % (n / 20) == 0 {
                println!(
                    "t {:.3} tip ({:.5} {:.5} {:.5}) ref ({:.5} {:.5} {:.5}) err {:.2e}",
                    t, tip.x, tip.y, tip.z, p[0], p[1], p[2], err
                );
            }
        }
    }
    let wall = t0.elapsed();
    let st = ga.stats();
    println!(
        "wall {:.3?} steps {} newton {} (max {}) factorizations {} | max tip err {:.3e} m at t={:.3} | drift/Tmax {:.3e} | max residual {:.2e} | max|y| {:.2e} | max|fold| {:.3} deg",
        wall,
        st.n_steps,
        st.n_newton_iters,
        st.max_newton_iters,
        st.n_factorizations,
        max_err,
        t_max,
        drift / max_t,
        max_res,
        max_y,
        max_fold.to_degrees()
    );
}
