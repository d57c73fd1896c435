//! Development timing of the pieces of one Newton iteration (min over repetitions).
use gebf::{Model, Options, samples};
use genalpha::{ConstrainedSystem, DenseLu, DenseMatrix, LinearSolver};
use std::time::Instant;

fn min_time(mut f: impl FnMut(), reps: usize) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let t0 = Instant::now();
        for _ in 0..20 {
            f();
        }
        best = best.min(t0.elapsed().as_secs_f64() / 20.0);
    }
    best * 1e6
}

fn main() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    let m = Model::new(&b, &j, g, Options::default()).unwrap();
    let s = m.initial_state();
    let n = m.n_dof();
    let nc = m.n_velocity_constraints();
    let mut q = s.q.clone();
    let dq: Vec<f64> = (0..n).map(|i| 1e-3 * ((i * 7919 % 13) as f64 - 6.0)).collect();
    m.retract_inplace(&s.q, &dq, &mut q);
    let v: Vec<f64> = (0..n).map(|i| 0.1 * ((i * 31 % 7) as f64 - 3.0)).collect();
    let a = v.clone();
    let mut r = vec![0.0; n];
    if std::env::var("ONLY_MATRIX").is_ok() {
        let mut k = DenseMatrix::zeros(n, n);
        for _ in 0..20000 {
            m.iteration_matrix_inplace(0.0, &q, &v, &a, 1.0, 1e-3, 1e-5, &mut k.view());
        }
        return;
    }
    let t_res = min_time(|| m.residual_inplace(0.0, &q, &v, &a, &mut r), 50);
    let mut k = DenseMatrix::zeros(n + nc, n + nc);
    let t_mat = min_time(
        || {
            k.fill_zero();
            let mut blk = k.block(0, 0, n, n);
            m.iteration_matrix_inplace(0.0, &q, &v, &a, 1.0, 1e-3, 1e-5, &mut blk);
        },
        50,
    );
    // A nonsingular matrix for the LU timing: add the constraint blocks and a diagonal shift.
    let mut bm = DenseMatrix::zeros(nc, n);
    m.psi_v_inplace(0.0, &q, &mut bm.view());
    for i in 0..nc {
        for jj in 0..n {
            *k.get_mut(n + i, jj) = bm.get(i, jj);
            *k.get_mut(jj, n + i) = bm.get(i, jj);
        }
    }
    let mut lu = DenseLu::default();
    lu.set_dimension(n + nc);
    if std::env::var("STRUCT").is_ok() {
        lu.set_structure(&m.matrix_structure().unwrap());
    }
    // diagonal shift on the constraint block to make the test matrix safely nonsingular is not
    // needed: [M Bᵀ; B 0] is nonsingular.
    let t_lu = min_time(|| lu.factorize(&k).unwrap(), 50);
    if std::env::var("ONLY_LU").is_ok() {
        let mut rhs = vec![1.0; n + nc];
        for _ in 0..100000 {
            lu.factorize(&k).unwrap();
            lu.solve_in_place(&mut rhs);
        }
        return;
    }
    let mut rhs = vec![1.0; n + nc];
    let t_solve = min_time(|| lu.solve_in_place(&mut rhs), 50);
    let mut psi = vec![0.0; nc];
    let t_psi = min_time(|| m.psi_inplace(0.0, &q, &v, &mut psi), 50);
    let t_en = min_time(|| { std::hint::black_box(m.energies(&q, &v)); }, 50);
    println!("n = {} + {nc}: residual {t_res:.1} µs, iteration matrix {t_mat:.1} µs, LU {t_lu:.1} µs, solve {t_solve:.1} µs, psi {t_psi:.2} µs, energies {t_en:.1} µs", n);
}
