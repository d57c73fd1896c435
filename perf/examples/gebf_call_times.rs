//! Per-call times of the four kernels of a Newton iteration on a real paper-case state
//! (c = 0.01, beta 45°, 5 elements per body, at t = 0.5 s): residual, iteration matrix,
//! bordered band factorisation and solve (checked against the dense LU). Each figure is the
//! minimum over 9 trials of the mean per call, which is robust to other load on the machine.
//!
//! `cargo run --release -p perf --example gebf_call_times [-- matrix|residual]`: with an argument,
//! only that kernel runs, 100 000 times (for `perf record`).
use gebf::{Model, Options, samples, simulate};
use genalpha::{ConstrainedSystem, DenseLu, DenseMatrix, IntegratorParams, LinearSolver};

fn time(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..9)
        .map(|_| {
            let t0 = std::time::Instant::now();
            for _ in 0..reps {
                f();
            }
            t0.elapsed().as_secs_f64() / reps as f64 * 1e6
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (b, j, g) = samples::double_pendulum(0.01, 45.0, 5);
    let mut m = Model::new(&b, &j, g, Options::default())?;
    let (s, _) = simulate::run(&mut m, IntegratorParams::new(0.8, 0.002), 0.5, |_, _, _| {})?;
    let n = m.n_dof();
    let nv = m.n_velocity_constraints();
    let na = n + nv;
    let mut a = DenseMatrix::zeros(na, na);
    let c = IntegratorParams::new(0.8, 0.002).coefficients();
    let (c_m, c_c, c_k) = (1.0, c.gamma_prime / c.beta_prime, 1.0 / c.beta_prime);
    m.iteration_matrix_inplace(s.t, &s.q, &s.v, &s.v_dot, c_m, c_c, c_k, &mut a.block(0, 0, n, n));
    m.constraint_force_tangent_inplace(s.t, &s.q, &s.lambda, &s.mu, c_k, &mut a.block(0, 0, n, n));
    let mut bm = DenseMatrix::zeros(nv, n);
    m.psi_v_inplace(s.t, &s.q, &mut bm.view());
    m.psi_q_inplace(s.t, &s.q, &s.v, &mut a.block(n, 0, nv, n).scaled(1.0 / c.gamma_prime));
    for jj in 0..n {
        for i in 0..nv {
            *a.get_mut(n + i, jj) += bm.get(i, jj);
            *a.get_mut(jj, n + i) = bm.get(i, jj);
        }
    }
    if let Some(mode) = std::env::args().nth(1) {
        let mut k = DenseMatrix::zeros(n, n);
        let mut r = vec![0.0; n];
        for _ in 0..100000 {
            if mode == "matrix" {
                m.iteration_matrix_inplace(
                    s.t,
                    std::hint::black_box(&s.q),
                    &s.v,
                    &s.v_dot,
                    c_m,
                    c_c,
                    c_k,
                    &mut k.view(),
                );
            } else {
                m.residual_inplace(s.t, std::hint::black_box(&s.q), &s.v, &s.v_dot, &mut r);
            }
        }
        return Ok(());
    }
    let mut lu = DenseLu::default();
    lu.set_dimension(na);
    lu.set_structure(&m.matrix_structure().unwrap());
    let mut dense = DenseLu::default();
    dense.set_dimension(na);
    dense.factorize(&a).unwrap();
    lu.factorize(&a).unwrap();
    let rhs: Vec<f64> = (0..na).map(|i| (i as f64 * 0.37).sin()).collect();
    let (mut x1, mut x2) = (rhs.clone(), rhs.clone());
    lu.solve_in_place(&mut x1);
    dense.solve_in_place(&mut x2);
    let err = x1.iter().zip(&x2).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let scale = x2.iter().map(|a| a.abs()).fold(0.0, f64::max);
    println!("max |x_band - x_dense| / max|x| = {:.3e}", err / scale);
    let tf = time(2000, || lu.factorize(std::hint::black_box(&a)).unwrap());
    let ts = time(10000, || {
        x1.copy_from_slice(&rhs);
        lu.solve_in_place(std::hint::black_box(&mut x1));
    });
    let mut r = vec![0.0; n];
    let tr = time(2000, || m.residual_inplace(s.t, std::hint::black_box(&s.q), &s.v, &s.v_dot, &mut r));
    let mut k = DenseMatrix::zeros(n, n);
    let tm = time(1000, || {
        m.iteration_matrix_inplace(s.t, std::hint::black_box(&s.q), &s.v, &s.v_dot, c_m, c_c, c_k, &mut k.view())
    });
    println!("residual {tr:.2} us, matrix {tm:.2} us, factorize {tf:.2} us, solve {ts:.2} us");
    Ok(())
}
