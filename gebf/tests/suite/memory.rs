//! No `n²` buffer for a banded problem: the integrator's dense iteration matrix is allocated only
//! when a matrix has to take the dense path (#19).

use gebf::{Model, Options, samples};
use genalpha::{ConstrainedSystem as _, GenAlpha, IntegratorParams};

/// The paper's flared pendulum at 5, 40, 200 and 1,000 elements per body (24,012 unknowns): the
/// start and 50 steps never assemble the integrator's dense `n × n` matrix, nor hand a matrix to
/// the sparse fallback (whose fill grows as `n²` on this matrix): the bordered band storage takes
/// the start's mass matrix and every iteration matrix. In the mass matrix alone a floating
/// frame's rotation is resisted only by the clamped root node's share of the inertia (the free
/// nodes can follow it): its Schur complement column is small throughout but independent, and
/// the Schur LU tests each pivot against its own column.
#[test]
fn banded_runs_hold_no_dense_matrix() {
    for n_el in [5, 40, 200, 1000] {
        let (b, j, g) = samples::double_pendulum(1.0, 45.0, n_el);
        let mut m = Model::new(&b, &j, g, Options { stabilization: true, ..Options::default() }).unwrap();
        let mut ga = GenAlpha::new(IntegratorParams::new(0.8, 0.002), &m).unwrap();
        let mut s = m.initial_state();
        ga.initialize(&m, &mut s).unwrap();
        for _ in 0..50 {
            ga.step(&mut m, &mut s).unwrap();
        }
        println!("{n_el} el/body: {} unknowns, dense assemblies: {}", m.n_dof(), ga.dense_assemblies());
        assert!(!ga.holds_dense_matrix(), "{n_el} elements per body");
        assert_eq!(ga.dense_assemblies(), 0, "{n_el} elements per body");
        assert_eq!(ga.sparse_fallbacks(), 0, "{n_el} elements per body");
    }
}

/// [`genalpha::DenseLu`] without the declared structure: every matrix assembled densely and
/// factorised by the dense LU with partial pivoting.
struct DenseOnly(genalpha::DenseLu);

impl genalpha::LinearSolver for DenseOnly {
    fn set_dimension(&mut self, n: usize) {
        self.0.set_dimension(n);
    }
    fn factorize(&mut self, a: &genalpha::DenseMatrix) -> Result<(), usize> {
        self.0.factorize(a)
    }
    fn solve_in_place(&mut self, b: &mut [f64]) {
        self.0.solve_in_place(b);
    }
}

/// [`genalpha::DenseLu`] without the declared structure but with its sparse LU: the start's
/// matrix goes to `factorize_entries`.
struct SparseOnly(genalpha::DenseLu);

impl genalpha::LinearSolver for SparseOnly {
    fn set_dimension(&mut self, n: usize) {
        self.0.set_dimension(n);
    }
    fn factorize(&mut self, a: &genalpha::DenseMatrix) -> Result<(), usize> {
        self.0.factorize(a)
    }
    fn factorize_entries(&mut self, entries: &genalpha::Entries) -> Result<bool, usize> {
        self.0.factorize_entries(entries)
    }
    fn solve_in_place(&mut self, b: &mut [f64]) {
        self.0.solve_in_place(b);
    }
}

/// `[M Φ_qᵀ Bᵀ; Φ_q 0 0; B 0 0] [v̇; λ; μ] = [−g; 0; 0]` at the start (at rest, so the
/// constraints' velocity terms vanish): the largest residual of the dynamic rows against the
/// largest force (`g`, `M v̇`), and of the constraint rows against `|Φ_q|∞ |v̇|∞`.
fn start_residuals(m: &Model, s: &genalpha::State) -> (f64, f64) {
    let (n, n_h, n_v) = (m.n_dof(), m.n_holonomic(), m.n_velocity_constraints());
    let inf = |v: &[f64]| v.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    let (mut g, mut r) = (vec![0.0; n], vec![0.0; n]);
    m.residual_inplace(s.t, &s.q, &s.v, &vec![0.0; n], &mut g);
    m.residual_inplace(s.t, &s.q, &s.v, &s.v_dot, &mut r);
    let inertia = r.iter().zip(&g).fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
    let (mut phi_q, mut b) = (genalpha::DenseMatrix::zeros(n_h, n), genalpha::DenseMatrix::zeros(n_v, n));
    m.phi_q_inplace(s.t, &s.q, &mut phi_q.block(0, 0, n_h, n));
    m.psi_v_inplace(s.t, &s.q, &mut b.block(0, 0, n_v, n));
    let mut rows = vec![0.0; n_h + n_v];
    let mut jac = 0.0_f64;
    for (j, rj) in r.iter_mut().enumerate() {
        let (hol, vel) = rows.split_at_mut(n_h);
        for (i, row) in hol.iter_mut().enumerate() {
            *rj += phi_q.get(i, j) * s.lambda[i];
            *row += phi_q.get(i, j) * s.v_dot[j];
            jac = jac.max(phi_q.get(i, j).abs());
        }
        for (i, row) in vel.iter_mut().enumerate() {
            *rj += b.get(i, j) * s.mu[i];
            *row += b.get(i, j) * s.v_dot[j];
            jac = jac.max(b.get(i, j).abs());
        }
    }
    (inf(&r) / inf(&g).max(inertia), inf(&rows) / (jac * inf(&s.v_dot)))
}

/// The consistent start of the pendulum with 40 elements per body, factorised three ways: the
/// bordered band LU (the default; its Schur complement holds the frame rotation's small
/// column), the sparse LU with pivoting from the entries, and the dense LU with partial
/// pivoting. Each solves the start's equations to round-off (relative residuals at most 1e-12,
/// a few hundred ε for 972 unknowns), and their accelerations agree to 1e-7 of the largest
/// (they differ along that rotation, which the mass matrix alone barely resists).
#[test]
fn structured_start_solves_the_start_equations() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 40);
    let m = Model::new(&b, &j, g, Options { stabilization: true, ..Options::default() }).unwrap();
    let params = IntegratorParams::new(0.8, 0.002);
    let mut structured = GenAlpha::new(params, &m).unwrap();
    let mut s0 = m.initial_state();
    structured.initialize(&m, &mut s0).unwrap();
    assert_eq!((structured.dense_assemblies(), structured.sparse_fallbacks()), (0, 0));
    let mut sparse = GenAlpha::with_solver(params, &m, SparseOnly(genalpha::DenseLu::default())).unwrap();
    let mut s1 = m.initial_state();
    sparse.initialize(&m, &mut s1).unwrap();
    assert_eq!((sparse.dense_assemblies(), sparse.sparse_fallbacks()), (0, 1));
    let mut dense = GenAlpha::with_solver(params, &m, DenseOnly(genalpha::DenseLu::default())).unwrap();
    let mut s2 = m.initial_state();
    dense.initialize(&m, &mut s2).unwrap();
    assert_eq!(dense.dense_assemblies(), 1);
    for (what, s) in [("structured", &s0), ("sparse", &s1), ("dense", &s2)] {
        let (dynamic, constraint) = start_residuals(&m, s);
        println!("{what} start: dynamic residual {dynamic:.2e}, constraint residual {constraint:.2e}");
        assert!(dynamic <= 1e-12 && constraint <= 1e-12, "{what}: {dynamic:e}, {constraint:e}");
    }
    let scale = s2.v_dot.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    for (what, s) in [("structured", &s0), ("sparse", &s1)] {
        let diff = s.v_dot.iter().zip(&s2.v_dot).fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
        println!("v_dot: largest {scale:.3e}, {what} - dense {diff:.3e}");
        assert!(diff <= 1e-7 * scale, "{what}: {diff:e} against {scale:e}");
    }
}
