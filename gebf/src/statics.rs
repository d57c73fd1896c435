//! Static equilibrium by Newton iteration with load stepping.
//!
//! At rest the inertial forces vanish and the equations are `r(q; λ) + B(q)ᵀ mu = 0`, where
//! `λ` scales gravity and the nodal loads. The velocity-level joints `B(q) v = 0` restrict every
//! increment, `B(q) δq = 0`, so each Newton step solves
//!
//! $$ \begin{bmatrix} K + \partial(B^T\mu)/\partial q & B^T \\ B & 0 \end{bmatrix}
//!    \begin{bmatrix} \delta q \\ \delta\mu \end{bmatrix} =
//!    -\begin{bmatrix} r + B^T \mu \\ 0 \end{bmatrix} $$
//!
//! and updates `q ← q ∘ exp(δq)`. The load factor goes from `1/n_load_steps` to 1.

use crate::{Error, Model};
use genalpha::{ConstrainedSystem, DenseLu, DenseMatrix, LinearSolver};

/// Settings of the static solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticOptions {
    /// Number of equal load increments (default 10).
    pub n_load_steps: usize,
    /// Maximum Newton iterations per load step (default 30).
    pub max_iter: usize,
    /// Convergence: weighted infinity norm of the increment (m; rotations × body length),
    /// default 1e-11.
    pub tol: f64,
    /// Alternative convergence: infinity norm of the residual below this fraction of its value
    /// at the start of the load step (default 1e-12). Needed where the Newton matrix is nearly
    /// singular in directions the load does not excite (e.g. out of plane when a nodal CRV
    /// reaches 2π and T(psi) is singular).
    pub rel_residual_tol: f64,
}

impl Default for StaticOptions {
    fn default() -> Self {
        Self { n_load_steps: 10, max_iter: 30, tol: 1e-11, rel_residual_tol: 1e-12 }
    }
}

/// Outcome of a static solve.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticSolution {
    /// Equilibrium coordinates (storage vector).
    pub q: Vec<f64>,
    /// Joint reaction multipliers at equilibrium.
    pub mu: Vec<f64>,
    /// Newton iterations over all load steps.
    pub n_iterations: usize,
}

impl Model {
    /// Solve for static equilibrium under gravity and the nodal loads, starting from `q0`.
    pub fn solve_static(&mut self, q0: &[f64], opts: &StaticOptions) -> Result<StaticSolution, Error> {
        if q0.len() != self.n_coords() {
            return Err(Error::WrongLength { what: "q0", got: q0.len(), expected: self.n_coords() });
        }
        if opts.n_load_steps == 0 {
            return Err(Error::ZeroCount { field: "n_load_steps".into() });
        }
        let saved_scale = self.load_scale;
        let out = self.solve_static_inner(q0, opts);
        self.load_scale = saved_scale;
        out
    }

    fn solve_static_inner(&mut self, q0: &[f64], opts: &StaticOptions) -> Result<StaticSolution, Error> {
        let n = self.n_dof();
        let nc = self.n_velocity_constraints();
        let zeros = vec![0.0; n];
        let weights: Vec<f64> = (0..n).map(|i| self.increment_weight(i)).collect();
        let mut q = q0.to_vec();
        let mut q_new = q.clone();
        let mut mu = vec![0.0; nc];
        let mut r = vec![0.0; n];
        let mut rhs = vec![0.0; n + nc];
        let mut a = DenseMatrix::zeros(n + nc, n + nc);
        let mut b = DenseMatrix::zeros(nc, n);
        let mut lu = DenseLu::default();
        lu.set_dimension(n + nc);
        let mut total = 0;
        for step in 1..=opts.n_load_steps {
            self.load_scale = step as f64 / opts.n_load_steps as f64;
            let mut converged = false;
            let mut inc = f64::INFINITY;
            let mut res = f64::INFINITY;
            let mut res0 = f64::NAN;
            for _ in 0..opts.max_iter {
                total += 1;
                self.residual_inplace(0.0, &q, &zeros, &zeros, &mut r);
                b.fill_zero();
                self.psi_v_inplace(0.0, &q, &mut b.view());
                b.add_mul_transpose_vec_inplace(&mu, &mut r);
                res = r.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                if res0.is_nan() {
                    res0 = res;
                } else if res <= opts.rel_residual_tol * res0 {
                    converged = true;
                    break;
                }
                a.fill_zero();
                {
                    let mut k = a.block(0, 0, n, n);
                    self.iteration_matrix_inplace(0.0, &q, &zeros, &zeros, 0.0, 0.0, 1.0, &mut k);
                    self.constraint_force_tangent_inplace(0.0, &q, &[], &mu, 1.0, &mut k);
                }
                for i in 0..nc {
                    for j in 0..n {
                        let x = b.get(i, j);
                        *a.get_mut(n + i, j) = x;
                        *a.get_mut(j, n + i) = x;
                    }
                }
                lu.factorize(&a).map_err(|_| Error::StaticDiverged {
                    load_factor: self.load_scale,
                    iter: total,
                    residual_norm: res,
                    increment_norm: inc,
                })?;
                for i in 0..n {
                    rhs[i] = -r[i];
                }
                rhs[n..].iter_mut().for_each(|x| *x = 0.0);
                lu.solve_in_place(&mut rhs);
                if !rhs.iter().all(|x| x.is_finite()) {
                    break;
                }
                inc = rhs[..n].iter().zip(&weights).fold(0.0_f64, |m, (x, w)| m.max((x * w).abs()));
                self.retract_inplace(&q, &rhs[..n], &mut q_new);
                std::mem::swap(&mut q, &mut q_new);
                self.rescale_rotations(&mut q, None);
                for (m, d) in mu.iter_mut().zip(&rhs[n..]) {
                    *m += d;
                }
                if inc <= opts.tol {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return Err(Error::StaticDiverged {
                    load_factor: self.load_scale,
                    iter: total,
                    residual_norm: res,
                    increment_norm: inc,
                });
            }
        }
        Ok(StaticSolution { q, mu, n_iterations: total })
    }
}
