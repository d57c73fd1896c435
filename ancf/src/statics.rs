//! Static equilibrium by Newton's method with load stepping, on the full coordinates:
//!
//! $$ \begin{bmatrix} K_t & \Phi_q^T \\ \Phi_q & 0 \end{bmatrix}
//!    \begin{bmatrix} \Delta q \\ \Delta\lambda \end{bmatrix}
//!  = -\begin{bmatrix} f_{el}(q) - \lambda_L Q(q) + \Phi_q^T\lambda \\ \Phi(q) \end{bmatrix} $$
//!
//! with the load factor `λ_L` ramped linearly over the load steps. The Newton iteration is the
//! integrator crate's generic one ([`genalpha::analysis::StaticSolver`]) on `FullCoordinates`,
//! the model in its DAE form whatever [`SolvePath`](crate::SolvePath) it integrates with.

use crate::Error;
use crate::model::Model;
use genalpha::analysis::{self, StaticSolver};
use genalpha::{ConstrainedSystem, MatView};

/// Static solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticsParams {
    /// Number of equal load increments (default 10).
    pub n_load_steps: usize,
    /// Newton iterations per load step (default 30).
    pub max_iter: usize,
    /// Convergence: weighted increment (slopes × element length) below `tol`, m (default 1e-11).
    pub tol: f64,
}

impl Default for StaticsParams {
    fn default() -> Self {
        Self { n_load_steps: 10, max_iter: 30, tol: 1e-11 }
    }
}

/// A static equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticSolution {
    /// Full nodal coordinates.
    pub q: Vec<f64>,
    /// Joint multipliers (constraint forces in the equations' units).
    pub lambda: Vec<f64>,
    /// Newton iterations, all load steps.
    pub n_iterations: usize,
}

/// The model on its full nodal coordinates with every joint row as a holonomic constraint (the
/// [`SolvePath::Dae`](crate::SolvePath::Dae) form, whatever path the model was built with): what
/// the static solver and the modal analysis work on. No damping: `c_c` is ignored.
pub(crate) struct FullCoordinates<'a>(pub(crate) &'a Model);

impl ConstrainedSystem for FullCoordinates<'_> {
    fn n_coords(&self) -> usize {
        self.0.n_full_coords()
    }
    fn n_dof(&self) -> usize {
        self.0.n_full_coords()
    }
    fn n_holonomic(&self) -> usize {
        self.0.n_constraint_rows()
    }
    fn residual_inplace(&self, t: f64, q: &[f64], _v: &[f64], v_dot: &[f64], r: &mut [f64]) {
        self.0.full_residual(t, q, v_dot, r);
    }
    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        _v: &[f64],
        _v_dot: &[f64],
        c_m: f64,
        _c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.0.assemble_full_inplace(t, q, c_m, c_k, k);
    }
    fn phi_inplace(&self, _t: f64, q: &[f64], phi: &mut [f64]) {
        for (p, row) in phi.iter_mut().zip(self.0.rows()) {
            *p = row.value(q);
        }
    }
    fn phi_q_inplace(&self, _t: f64, _q: &[f64], j: &mut MatView<'_>) {
        for (i, row) in self.0.rows().iter().enumerate() {
            for &(col, c) in &row.entries {
                j.add(i, col, c);
            }
        }
    }
    fn phi_q_is_constant(&self) -> bool {
        true
    }
    fn increment_weight(&self, i: usize) -> f64 {
        self.0.full_weight(i)
    }
    fn adjust_static_step(&self, q: &[f64], dq: &mut [f64]) {
        self.0.turn_node_steps(q, dq);
    }
}

impl Model {
    /// Solve for static equilibrium under gravity and the point loads, starting from the
    /// reference configuration. Works on the full coordinates whatever [`SolvePath`](crate::SolvePath) the model
    /// was built with; the load factor is left at 1.
    pub fn solve_static(&mut self, params: StaticsParams) -> Result<StaticSolution, Error> {
        let generic = analysis::StaticParams { max_iter: params.max_iter, tol: params.tol, rel_residual_tol: 0.0 };
        let mut solver = StaticSolver::new(&FullCoordinates(self), generic);
        let mut x = analysis::StaticSolution::guess(&FullCoordinates(self), self.reference_coordinates());
        let n_steps = params.n_load_steps.max(1);
        for load_factor in analysis::load_steps(n_steps) {
            self.set_load_factor(load_factor);
            if let Err(e) = solver.solve(&FullCoordinates(self), 0.0, &mut x) {
                self.set_load_factor(1.0);
                return Err(match e {
                    genalpha::Error::SingularMatrix { pivot, .. } => Error::SingularMatrix { pivot },
                    genalpha::Error::NonFinite { iter, .. } => {
                        Error::StaticsDiverged { load_factor, iter, residual_norm: x.residual_norm }
                    }
                    _ => Error::StaticsDiverged { load_factor, iter: params.max_iter, residual_norm: x.residual_norm },
                });
            }
        }
        self.set_load_factor(1.0);
        Ok(StaticSolution { q: x.q, lambda: x.lambda, n_iterations: x.n_iterations })
    }

    /// The former name of [`solve_static`](Self::solve_static) (GEBF's spelling is the one kept).
    #[deprecated(note = "renamed to `solve_static`, as in gebf")]
    pub fn solve_statics(&mut self, params: StaticsParams) -> Result<StaticSolution, Error> {
        self.solve_static(params)
    }
}
