//! Probe: does co-rotating an earlier step's iteration matrix by each node's rotation increment
//! bring its contraction on the current one down? Spectral radius of I − K_old⁻¹ K_new, against
//! I − (R K_old Rᵀ)⁻¹ K_new with R = diag(I₄ ⊗ ΔR_node, I on multipliers), on the c = 1, β = 45°
//! pendulum (DAE), by power iteration.
use ancf::frame::{node_turn, rotation_angle};
use ancf::{Model, Options, SolvePath, samples};
use genalpha::{ConstrainedSystem, DenseMatrix, IntegratorParams};
use nalgebra::DMatrix;
use perf::reuse_radius;

fn kkt(model: &Model, q: &[f64], ck: f64) -> DMatrix<f64> {
    let (n, nh) = (model.n_dof(), model.n_holonomic());
    let mut m = DenseMatrix::zeros(n + nh, n + nh);
    let z = vec![0.0; n];
    model.iteration_matrix_inplace(0.0, q, &z, &z, 1.0, 0.0, ck, &mut m.block(0, 0, n, n));
    model.phi_q_inplace(0.0, q, &mut m.block(n, 0, nh, n));
    for j in 0..n {
        for i in 0..nh {
            let x = m.get(n + i, j);
            *m.get_mut(j, n + i) = x;
        }
    }
    DMatrix::from_column_slice(n + nh, n + nh, m.as_slice())
}

fn main() {
    let (bodies, joints, g) = samples::double_pendulum(1.0, 45.0, 5);
    let mut model = Model::new(&bodies, &joints, g, Options { path: SolvePath::Dae, ..Default::default() }).unwrap();
    let params = IntegratorParams::new(0.8, 0.002);
    let mut ga = model.integrator(params).unwrap();
    let ck = 1.0 / ga.coefficients().beta_prime;
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).unwrap();
    let (n, nh) = (model.n_dof(), model.n_holonomic());
    let nodes = n / 12;
    for step in 1..=1000 {
        let q_old = s.q.clone();
        ga.step(&mut model, &mut s).unwrap();
        if step % 100 != 0 {
            continue;
        }
        let (k_old, k_new) = (kkt(&model, &q_old, ck), kkt(&model, &s.q, ck));
        let mut r = DMatrix::<f64>::identity(n + nh, n + nh);
        let mut worst = 0.0_f64;
        for node in 0..nodes {
            let o = 12 * node;
            let dr = node_turn(&q_old[o + 3..o + 12], &s.q[o + 3..o + 12]);
            worst = worst.max(rotation_angle(&dr));
            for b in 0..4 {
                let o = 12 * node + 3 * b;
                r.view_mut((o, o), (3, 3)).copy_from(&dr);
            }
        }
        let k_co = &r * &k_old * r.transpose();
        println!(
            "t = {:.3}  largest node turn {:.4} rad  rho(old) {:.3}  rho(co-rotated) {:.3}",
            s.t,
            worst,
            reuse_radius(&k_old, &k_new, 200),
            reuse_radius(&k_co, &k_new, 200)
        );
    }
}
