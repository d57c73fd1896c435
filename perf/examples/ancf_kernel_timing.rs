//! Time the kernels of one Newton iteration on the β = 45° pendulum, deformed state.
use ancf::elastic_force::ElementMatrix;
use ancf::element::Element;
use ancf::{Model, Options, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseLu, DenseMatrix, IntegratorParams, LinearSolver};
use std::time::Instant;

fn time<F: FnMut()>(name: &str, reps: usize, mut f: F) {
    if let Some(only) = std::env::args().nth(1)
        && !name.starts_with(&only)
    {
        return;
    }
    let reps = std::env::var("REPS").ok().and_then(|r| r.parse().ok()).unwrap_or(reps);
    f();
    let mut best = f64::INFINITY;
    for _ in 0..20 {
        let t0 = Instant::now();
        for _ in 0..reps / 20 {
            f();
        }
        best = best.min(t0.elapsed().as_secs_f64() * 1e6 / (reps / 20) as f64);
    }
    println!("{name:<28} {best:>9.2} us");
}

fn main() {
    for path in [SolvePath::Dae, SolvePath::Ode] {
        println!("--- {path:?}");
        let (bodies, joints, g) = samples::double_pendulum(0.1, 45.0, 5);
        let mut model = Model::new(&bodies, &joints, g, Options { path, ..Default::default() }).unwrap();
        let params = IntegratorParams::new(0.8, 0.002);
        let mut ga = model.integrator(params).unwrap();
        let mut s = model.initial_state();
        ga.initialize(&model, &mut s).unwrap();
        for _ in 0..300 {
            ga.step(&mut model, &mut s).unwrap();
        }
        let (n, nh) = (model.n_dof(), model.n_holonomic());
        let c = *ga.coefficients();
        let mut r = vec![0.0; n];
        time("residual", 2000, || model.residual_inplace(0.0, &s.q, &s.v, &s.v_dot, &mut r));
        if path == SolvePath::Dae {
            // one element of the first body at the deformed state
            let o = model.options();
            let el = Element::new(0.1, &bodies[0].section, o.curvature, o.penalty_factor);
            let e = &s.q[12..36];
            let mut f = [0.0; 24];
            time("element force", 20000, || {
                el.add_elastic_force(e, &mut f);
            });
            let mut f4 = [[0.0; 24]; 4];
            time("element force x4 (lanes)", 20000, || {
                el.elastic_forces([e, e, e, e], &mut f4);
            });
            let mut ke = ElementMatrix::zeros();
            time("element tangent (upper)", 20000, || el.add_elastic_tangent_upper(e, 1.0, &mut ke));
        }
        let mut m = DenseMatrix::zeros(n + nh, n + nh);
        time("fill_zero", 2000, || m.fill_zero());
        let assemble = |m: &mut DenseMatrix| {
            m.fill_zero();
            let mut k = m.block(0, 0, n, n);
            model.iteration_matrix_inplace(0.0, &s.q, &s.v, &s.v_dot, 1.0, 0.0, 1.0 / c.beta_prime, &mut k);
        };
        time("iteration matrix", 2000, || assemble(&mut m));
        assemble(&mut m);
        {
            let mut j = m.block(n, 0, nh, n);
            model.phi_q_inplace(0.0, &s.q, &mut j);
        }
        for j in 0..n {
            for i in 0..nh {
                let x = m.get(n + i, j);
                *m.get_mut(j, n + i) = x;
            }
        }
        let mut sky = model.linear_solver();
        sky.set_dimension(n + nh);
        time("skyline factorize", 2000, || sky.factorize(&m).unwrap());
        let mut b: Vec<f64> = (0..n + nh).map(|i| (i as f64).sin()).collect();
        time("skyline solve", 2000, || sky.solve_in_place(&mut b));
        let mut dl = DenseLu::default();
        dl.set_dimension(n + nh);
        if let Some(st) = model.matrix_structure() {
            dl.set_structure(&st);
        }
        time("banded factorize", 2000, || dl.factorize(&m).unwrap());
        time("banded solve", 2000, || dl.solve_in_place(&mut b));
        println!("skyline {} dense fallbacks {}", sky.n_skyline, sky.n_dense);
    }
}
