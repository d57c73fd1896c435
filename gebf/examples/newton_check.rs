//! Development check: compare the Newton matrix the integrator assembles with a finite-difference
//! Jacobian of the actual Newton map x ↦ (r + Bᵀμ, B v) at a state in the middle of a run.
use gebf::{Model, Options, samples};
use genalpha::{Coefficients, ConstrainedSystem, DenseMatrix, GenAlpha, IntegratorParams};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let get = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (c, beta, t_stop) = (get(1, 1.0), get(2, 45.0), get(3, 1.0));
    let (b, j, g) = samples::double_pendulum(c, beta, 5);
    let mut m = Model::new(&b, &j, g, Options::default()).unwrap();
    let mut p = IntegratorParams::new(0.8, 0.002);
    p.newton.reuse_factorization = false;
    let mut ga = GenAlpha::new(p, &m).unwrap();
    let mut s = m.initial_state();
    ga.initialize(&m, &mut s).unwrap();
    while s.t < t_stop - 1e-9 {
        ga.step(&mut m, &mut s).unwrap();
    }
    let cf = Coefficients::new(p.rho_inf, p.dt);
    let h = cf.h;
    let n = m.n_dof();
    let nc = m.n_velocity_constraints();
    // Predictor as in genalpha.
    let mut a1 = vec![0.0; n];
    let mut delta = vec![0.0; n];
    let mut v1 = vec![0.0; n];
    for i in 0..n {
        a1[i] = (s.v_dot[i] - cf.alpha_m * s.a[i]) / (1.0 - cf.alpha_m);
        delta[i] = s.v[i] + h * (0.5 - cf.beta) * s.a[i] + h * cf.beta * a1[i];
        v1[i] = s.v[i] + h * (1.0 - cf.gamma) * s.a[i] + h * cf.gamma * a1[i];
    }
    let vd1 = s.v_dot.clone();
    let mu = s.mu.clone();
    let qn = s.q.clone();
    let f = |x: &[f64]| -> Vec<f64> {
        let hd: Vec<f64> = (0..n).map(|i| h * delta[i] + x[i]).collect();
        let mut q = qn.clone();
        m.retract_inplace(&qn, &hd, &mut q);
        let v: Vec<f64> = (0..n).map(|i| v1[i] + cf.gamma_prime * x[i]).collect();
        let vd: Vec<f64> = (0..n).map(|i| vd1[i] + cf.beta_prime * x[i]).collect();
        let mut r = vec![0.0; n];
        m.residual_inplace(0.0, &q, &v, &vd, &mut r);
        let mut bm = DenseMatrix::zeros(nc, n);
        m.psi_v_inplace(0.0, &q, &mut bm.view());
        bm.add_mul_transpose_vec_inplace(&mu, &mut r);
        let mut ps = vec![0.0; nc];
        m.psi_inplace(0.0, &q, &v, &mut ps);
        r.extend(ps);
        r
    };
    // Analytic at the predictor.
    let hd: Vec<f64> = (0..n).map(|i| h * delta[i]).collect();
    let mut q = qn.clone();
    m.retract_inplace(&qn, &hd, &mut q);
    let mut k = DenseMatrix::zeros(n + nc, n);
    {
        let mut top = k.block(0, 0, n, n);
        m.iteration_matrix_inplace(0.0, &q, &v1, &vd1, cf.beta_prime, cf.gamma_prime, 1.0, &mut top);
        m.constraint_force_tangent_inplace(0.0, &q, &[], &mu, 1.0, &mut top);
    }
    {
        let mut bot = k.block(n, 0, nc, n);
        m.psi_v_inplace(0.0, &q, &mut bot.scaled(cf.gamma_prime));
        m.psi_q_inplace(0.0, &q, &v1, &mut bot);
    }
    let eps = 1e-7;
    let mut worst = vec![(0.0f64, 0usize); 2];
    let mut scale = [0.0f64; 2];
    for jj in 0..n {
        let mut xp = vec![0.0; n];
        xp[jj] = eps;
        let fp = f(&xp);
        xp[jj] = -eps;
        let fm = f(&xp);
        for i in 0..n + nc {
            let fd = (fp[i] - fm[i]) / (2.0 * eps);
            let blk = usize::from(i >= n);
            let d = (fd - k.get(i, jj)).abs();
            scale[blk] = scale[blk].max(k.get(i, jj).abs());
            if d > worst[blk].0 {
                worst[blk] = (d, i * 1000 + jj);
            }
        }
    }
    // Condition of the scaled Newton matrix [K/β′ ... ; γ′B/γ′ ...].
    let mut full = nalgebra::DMatrix::<f64>::zeros(n + nc, n + nc);
    for i in 0..n + nc {
        for jj in 0..n {
            let sc = if i < n { 1.0 / cf.beta_prime } else { 1.0 / cf.gamma_prime };
            full[(i, jj)] = k.get(i, jj) * sc;
        }
    }
    let mut bm = DenseMatrix::zeros(nc, n);
    m.psi_v_inplace(0.0, &q, &mut bm.view());
    for i in 0..nc {
        for jj in 0..n {
            full[(jj, n + i)] = bm.get(i, jj);
        }
    }
    let svd = full.clone().svd(false, true);
    let sv = svd.singular_values.clone();
    let imin = sv.imin();
    let vt = svd.v_t.unwrap();
    let row = vt.row(imin);
    let mut idx: Vec<usize> = (0..n + nc).collect();
    idx.sort_by(|a, b| row[*b].abs().partial_cmp(&row[*a].abs()).unwrap());
    for &i in idx.iter().take(30) { if row[i].abs() > 0.01 { println!("  null comp {i}: {:.4}", row[i]); } }
    println!("t {:.4}: singular values max {:.3e} min {:.3e} (cond {:.3e})", s.t, sv.max(), sv.min(), sv.max() / sv.min());
    let mut svs: Vec<f64> = sv.iter().copied().collect();
    svs.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!("smallest: {:?}", &svs[..6]);
    // Newton with the analytic matrix from the predictor: residual norms.
    let mut x = vec![0.0; n];
    let mut muv = mu.clone();
    for it in 0..6 {
        let fx = f(&x);
        let rn = fx[..n].iter().fold(0.0f64, |a, b| a.max(b.abs())) / cf.beta_prime;
        let pn = fx[n..].iter().fold(0.0f64, |a, b| a.max(b.abs()));
        println!("newton it {it}: res {rn:.3e} psi {pn:.3e}");
        let _ = &mut muv;
        break;
    }
    println!("dynamic rows: worst abs diff {:.3e} (row {}, col {}), scale {:.3e}", worst[0].0, worst[0].1 / 1000, worst[0].1 % 1000, scale[0]);
    println!("constraint rows: worst abs diff {:.3e} (row {}, col {}), scale {:.3e}", worst[1].0, worst[1].1 / 1000, worst[1].1 % 1000, scale[1]);
}
