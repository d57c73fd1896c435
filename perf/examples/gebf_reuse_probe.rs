//! Probe: why does GEBF's iteration matrix of the previous step contract poorly on the current
//! one? Spectral radius of I − A_old⁻¹ A_new over one step of the paper's c = 1, β = 45°
//! pendulum, and the same with one part of A_new (mass, damping/gyroscopic, stiffness, joint
//! rows) taken from the old state, to see which part drives the change, and the largest nodal
//! rotation against the body frame. Measured: 0.015–0.1 while the nodes stay within 0.1 rad of
//! their frame; 0.25–0.49 in 1.35–1.8 s, where the bodies whip (nodal rotations up to 0.33 rad)
//! and the mass and stiffness parts change alike. Not a rigid turn that a change of unknowns
//! could take out, as ANCF's (`ancf_corotation_probe`): GEBF's unknowns already follow the frame.
use gebf::{Model, Options, samples};
use genalpha::{ConstrainedSystem, DenseMatrix, GenAlpha, IntegratorParams, State};
use nalgebra::DMatrix;
use perf::reuse_radius;

struct Parts {
    m: DMatrix<f64>,
    c: DMatrix<f64>,
    k: DMatrix<f64>,
    joints: DMatrix<f64>,
}

fn parts(model: &Model, s: &State, gp: f64) -> Parts {
    let (n, nv) = (model.n_dof(), model.n_velocity_constraints());
    let na = n + nv;
    let block = |cm: f64, cc: f64, ck: f64| {
        let mut a = DenseMatrix::zeros(na, na);
        model.iteration_matrix_inplace(s.t, &s.q, &s.v, &s.v_dot, cm, cc, ck, &mut a.block(0, 0, n, n));
        DMatrix::from_column_slice(na, na, a.as_slice())
    };
    let mut a = DenseMatrix::zeros(na, na);
    model.psi_v_inplace(s.t, &s.q, &mut a.block(n, 0, nv, n));
    let mut bq = DenseMatrix::zeros(na, na);
    model.psi_q_inplace(s.t, &s.q, &s.v, &mut bq.block(n, 0, nv, n));
    let mut joints = DMatrix::from_column_slice(na, na, a.as_slice());
    for i in 0..nv {
        for j in 0..n {
            let b = joints[(n + i, j)];
            joints[(j, n + i)] = b;
            joints[(n + i, j)] = b + bq.get(n + i, j) / gp;
        }
    }
    Parts { m: block(1.0, 0.0, 0.0), c: block(0.0, 1.0, 0.0), k: block(0.0, 0.0, 1.0), joints }
}

fn assemble(p: [&Parts; 4], bp: f64, gp: f64) -> DMatrix<f64> {
    &p[0].m + &p[1].c * (gp / bp) + &p[2].k * (1.0 / bp) + &p[3].joints
}

fn main() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    let mut model = Model::new(&b, &j, g, Options::default()).unwrap();
    let mut ga: GenAlpha = GenAlpha::new(IntegratorParams::new(0.8, 0.002), &model).unwrap();
    let co = ga.coefficients();
    let (bp, gp) = (co.beta_prime, co.gamma_prime);
    let mut s = model.initial_state();
    ga.initialize(&model, &mut s).unwrap();
    for step in 1..=1000 {
        let old = s.clone();
        ga.step(&mut model, &mut s).unwrap();
        let every = if (650..=900).contains(&step) { 25 } else { 100 }; // finer where the pendulum whips
        if step % every != 0 {
            continue;
        }
        let (po, pn) = (parts(&model, &old, gp), parts(&model, &s, gp));
        let a_new = assemble([&pn, &pn, &pn, &pn], bp, gp);
        let rho = |p: [&Parts; 4]| reuse_radius(&assemble(p, bp, gp), &a_new, 300);
        println!(
            "t = {:.3}  |psi|max {:.3}  rho(old) {:.3}  old M only {:.3}  old C only {:.3}  old K only {:.3}  old joints only {:.3}",
            s.t,
            model.max_nodal_rotation(&s.q),
            rho([&po, &po, &po, &po]),
            rho([&po, &pn, &pn, &pn]),
            rho([&pn, &po, &pn, &pn]),
            rho([&pn, &pn, &po, &pn]),
            rho([&pn, &pn, &pn, &po]),
        );
    }
}
