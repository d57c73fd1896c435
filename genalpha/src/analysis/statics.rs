//! Static equilibrium of a constrained system by Newton's method, with continuation.
//!
//! Each iteration solves the bordered system (tangent unknowns `δq`, then the multiplier
//! increments of the holonomic and the velocity rows)
//!
//! $$ \begin{bmatrix} K + \partial(\Phi_q^T\lambda + B^T\mu)/\partial q & s\,G^T \\ s\,G & 0
//!    \end{bmatrix}
//!    \begin{bmatrix} \delta q \\ \delta\nu / s \end{bmatrix}
//!  = -\begin{bmatrix} r + \Phi_q^T\lambda + B^T\mu \\ s\,\Phi \\ s\,b \end{bmatrix},\qquad
//!    G = \begin{bmatrix}\Phi_q \\ B\end{bmatrix},$$
//!
//! with `K = ∂r/∂q` at `v = v_dot = 0`, and updates `q ← q ∘ exp(δq)`, `(λ, μ) ← (λ, μ) + δν`.
//! The constraint rows and columns are scaled by `s = max(1, max_i |K_ii|)` so that the pivots of
//! the two blocks stay balanced (`δν` is recovered unscaled). The velocity rows restrict every
//! increment to `B δq = −b`: for joints written at velocity level (`b = 0`) the iterates move
//! along the joints to first order, as a time step would.
//!
//! Converged when the weighted increment `max_i |w_i δq_i|` (the model's
//! [`increment_weight`](crate::ConstrainedSystem::increment_weight)) is at most
//! [`StaticParams::tol`], or the residual has fallen below [`StaticParams::rel_residual_tol`]
//! times its value at the start of the solve.
//!
//! **Two matrices.** Every solve starts with the exact tangent (`residual_and_iteration_matrix_inplace`
//! with `c_k = 1`), so Newton converges quadratically where it converges. A model may also offer
//! a matrix at rest ([`residual_and_static_matrix_inplace`](crate::ConstrainedSystem::residual_and_static_matrix_inplace),
//! with [`has_static_matrix`](crate::ConstrainedSystem::has_static_matrix)): ANCF's tangent
//! without the geometric terms of its near-rigid strains. When the exact iteration fails (a
//! non-finite residual after every halving, a singular matrix) or stalls
//! ([`STALL_ITERATIONS`] iterations without a new smallest increment), the solve starts again from
//! the same estimate with that matrix (linear convergence, the same equilibrium: the residual is
//! exact). The iterations of both attempts count in [`StaticSolution::n_iterations`].
//!
//! An iterate at which the residual cannot be evaluated (non-finite: e.g. an aerodynamic lattice
//! that folds over) is not an error while the step can still be halved: the iteration goes back
//! to the previous iterate and takes half the step, at most [`MAX_BACKTRACKS`] times per
//! iteration.

use crate::{ConstrainedSystem, DenseLu, DenseMatrix, Error, LinearSolver};

/// Halvings of one Newton step whose iterate has a non-finite residual, before the solve fails.
pub const MAX_BACKTRACKS: usize = 8;

/// Iterations without a new smallest increment after which Newton with the exact tangent is
/// taken to stall, on a system that has a matrix at rest to fall back on.
pub const STALL_ITERATIONS: usize = 5;

/// The matrix of a Newton iteration at rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Tangent {
    /// The exact tangent `∂r/∂q` ([`ConstrainedSystem::residual_and_iteration_matrix_inplace`]).
    Exact,
    /// The model's matrix at rest ([`ConstrainedSystem::residual_and_static_matrix_inplace`]).
    AtRest,
}

/// Watches the weighted increments of a Newton iteration for a stall: [`STALL_ITERATIONS`]
/// iterations in a row without a new smallest increment.
#[derive(Debug, Default)]
struct Stall {
    best: Option<f64>,
    since_best: usize,
}

impl Stall {
    /// Record an increment; whether the iteration stalls.
    fn record(&mut self, increment: f64) -> bool {
        match self.best {
            Some(b) if increment >= b => self.since_best += 1,
            _ => {
                self.best = Some(increment);
                self.since_best = 0;
            }
        }
        self.since_best >= STALL_ITERATIONS
    }
}

/// Whether a failure of Newton with the exact tangent is retried with the matrix at rest: an
/// iterate that left the region where the residual is finite, a singular tangent, or a stall
/// (reported before the iteration cap `max_iter`). An iteration that still makes progress at the
/// cap is not: the matrix at rest converges no faster.
fn retry_at_rest(e: &Error, max_iter: usize) -> bool {
    match e {
        Error::NonFinite { .. } | Error::SingularMatrix { .. } => true,
        Error::StaticNotConverged { iter, .. } => *iter < max_iter,
        _ => false,
    }
}

/// Settings of the static Newton iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticParams {
    /// Maximum Newton iterations per solve (per continuation step); default 30.
    pub max_iter: usize,
    /// Convergence: weighted infinity norm of the increment, in the units of the model's
    /// increment weights (m for beams: rotations and slopes times a length); default 1e-11.
    pub tol: f64,
    /// Alternative convergence: the infinity norm of the equilibrium residual below this
    /// fraction of its value at the start of the solve (default 1e-12; 0 turns it off). Needed
    /// where the matrix is nearly singular in a direction the load does not excite, so that the
    /// increment stalls at round-off above `tol`.
    pub rel_residual_tol: f64,
}

impl Default for StaticParams {
    fn default() -> Self {
        Self { max_iter: 30, tol: 1e-11, rel_residual_tol: 1e-12 }
    }
}

/// A static equilibrium, or the estimate a solve starts from and updates in place.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticSolution {
    /// Coordinates (storage vector, length `n_coords`).
    pub q: Vec<f64>,
    /// Multipliers of the holonomic constraints (generalised forces per unit Φ).
    pub lambda: Vec<f64>,
    /// Multipliers of the velocity constraints.
    pub mu: Vec<f64>,
    /// Newton iterations (linear solves) spent on this solution, all solves and steps.
    pub n_iterations: usize,
    /// Infinity norm of the equilibrium residual `r + Φ_qᵀλ + Bᵀμ` at `q` (the model's force
    /// units), at the end of the last solve; on failure, at the last iterate.
    pub residual_norm: f64,
    /// Infinity norm of the constraint residuals `Φ(q)` and `b(q)` at `q` (at the end of the
    /// last solve).
    pub constraint_norm: f64,
    /// Weighted infinity norm of the last Newton increment (see [`StaticParams::tol`]).
    pub increment_norm: f64,
}

impl StaticSolution {
    /// The estimate `q0` with zero multipliers.
    ///
    /// # Panics
    /// When `q0` does not have the system's `n_coords` entries.
    pub fn guess<S: ConstrainedSystem + ?Sized>(system: &S, q0: &[f64]) -> Self {
        assert_eq!(q0.len(), system.n_coords(), "q0 has the wrong length");
        Self {
            q: q0.to_vec(),
            lambda: vec![0.0; system.n_holonomic()],
            mu: vec![0.0; system.n_velocity_constraints()],
            n_iterations: 0,
            residual_norm: f64::NAN,
            constraint_norm: f64::NAN,
            increment_norm: f64::NAN,
        }
    }
}

/// The static Newton iteration with its workspace, built once for a system's dimensions and
/// reused for every solve of a continuation.
#[derive(Debug)]
pub struct StaticSolver {
    params: StaticParams,
    n: usize,
    n_h: usize,
    n_v: usize,
    mat: DenseMatrix,
    jac: DenseMatrix,
    lu: DenseLu,
    r: Vec<f64>,
    rhs: Vec<f64>,
    zeros: Vec<f64>,
    weights: Vec<f64>,
    constraint: Vec<f64>,
    multipliers: Vec<f64>,
    /// The previous iterate's coordinates and multipliers, and its step (all unknowns, the
    /// multipliers' part unscaled), for halving a step that lands where the residual is not finite.
    q_prev: Vec<f64>,
    nu_prev: Vec<f64>,
    step: Vec<f64>,
    /// The estimate a solve starts from (coordinates; multipliers), for the retry with the
    /// matrix at rest.
    q_start: Vec<f64>,
    nu_start: Vec<f64>,
}

impl StaticSolver {
    /// A solver sized for `system`.
    pub fn new<S: ConstrainedSystem + ?Sized>(system: &S, params: StaticParams) -> Self {
        let (n, n_h, n_v) = (system.n_dof(), system.n_holonomic(), system.n_velocity_constraints());
        let n_all = n + n_h + n_v;
        let mut lu = DenseLu::default();
        lu.set_dimension(n_all);
        Self {
            params,
            n,
            n_h,
            n_v,
            mat: DenseMatrix::zeros(n_all, n_all),
            jac: DenseMatrix::zeros(n_h + n_v, n),
            lu,
            r: vec![0.0; n],
            rhs: vec![0.0; n_all],
            zeros: vec![0.0; n],
            weights: (0..n).map(|i| system.increment_weight(i)).collect(),
            constraint: vec![0.0; n_h + n_v],
            multipliers: vec![0.0; n_h + n_v],
            q_prev: vec![0.0; system.n_coords()],
            nu_prev: vec![0.0; n_h + n_v],
            step: vec![0.0; n_all],
            q_start: vec![0.0; system.n_coords()],
            nu_start: Vec::with_capacity(n_h + n_v),
        }
    }

    /// The settings.
    pub fn params(&self) -> &StaticParams {
        &self.params
    }

    /// Replace the settings (the same system: the buffers are kept).
    pub fn set_params(&mut self, params: StaticParams) {
        self.params = params;
    }

    /// Newton from the estimate `x` to the equilibrium of `system` at time `t` (forces as the
    /// system currently defines them), with the exact tangent and, where that fails or stalls on
    /// a system with a matrix at rest, again from `x` with that matrix (module documentation).
    /// On success `x` holds the equilibrium; on failure, the last iterate with its residual and
    /// increment norms.
    ///
    /// # Errors
    /// The last attempt's: [`Error::StaticNotConverged`] after `max_iter` iterations, [`Error::SingularMatrix`]
    /// (e.g. a mechanism: a motion with neither stiffness nor constraint), [`Error::NonFinite`].
    ///
    /// # Panics
    /// When `system` or `x` do not have the dimensions this solver was built for.
    pub fn solve<S: ConstrainedSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        x: &mut StaticSolution,
    ) -> Result<(), Error> {
        self.solve_normalised(system, t, x, |_| {})
    }

    /// [`solve`](Self::solve), with `normalise` applied to the coordinates after every update
    /// (e.g. a CRV rescaling that keeps rotation vectors on one branch; it must not change the
    /// configuration they describe).
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    ///
    /// # Panics
    /// As [`solve`](Self::solve).
    pub fn solve_normalised<S: ConstrainedSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        x: &mut StaticSolution,
        normalise: impl Fn(&mut [f64]),
    ) -> Result<(), Error> {
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        assert!(
            system.n_dof() == n && system.n_holonomic() == n_h && system.n_velocity_constraints() == n_v,
            "the system's dimensions differ from the solver's"
        );
        assert!(
            x.q.len() == self.q_prev.len() && x.lambda.len() == n_h && x.mu.len() == n_v,
            "the estimate's dimensions differ from the system's"
        );
        self.q_start.copy_from_slice(&x.q);
        self.nu_start.clear();
        self.nu_start.extend(x.lambda.iter().chain(x.mu.iter()));
        let exact = self.newton(system, t, x, &normalise, Tangent::Exact);
        match exact {
            Err(e) if system.has_static_matrix() && retry_at_rest(&e, self.params.max_iter) => {
                x.q.copy_from_slice(&self.q_start);
                let (l, m) = self.nu_start.split_at(n_h);
                x.lambda.copy_from_slice(l);
                x.mu.copy_from_slice(m);
                self.newton(system, t, x, &normalise, Tangent::AtRest)
            }
            other => other,
        }
    }

    /// Newton's iteration from `x` with the matrix `tangent`. With [`Tangent::Exact`] on a
    /// system that has a matrix at rest, an iteration that stalls (see [`Stall`]) gives up early.
    fn newton<S: ConstrainedSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        x: &mut StaticSolution,
        normalise: &impl Fn(&mut [f64]),
        tangent: Tangent,
    ) -> Result<(), Error> {
        let n = self.n;
        let mut res0 = f64::NAN;
        // Fraction of the last step taken, and its halvings so far (None before the first step).
        let mut halving: Option<(f64, usize)> = None;
        let mut stall = Stall::default();
        let watch = tangent == Tangent::Exact && system.has_static_matrix();
        for iter in 0..self.params.max_iter {
            let res = self.assemble(system, t, x, tangent);
            x.residual_norm = res;
            if !res.is_finite() {
                match halving {
                    Some((alpha, k)) if k < MAX_BACKTRACKS => {
                        self.take_step(system, x, 0.5 * alpha, normalise);
                        halving = Some((0.5 * alpha, k + 1));
                        continue;
                    }
                    _ => return Err(Error::NonFinite { t, iter }),
                }
            }
            if iter == 0 || res0.is_nan() {
                res0 = res;
            } else if res <= self.params.rel_residual_tol * res0 {
                self.finish(system, t, x);
                return Ok(());
            }
            self.lu.factorize(&self.mat).map_err(|pivot| Error::SingularMatrix { t, pivot })?;
            self.lu.solve_in_place(&mut self.rhs);
            if !self.rhs.iter().all(|v| v.is_finite()) {
                return Err(Error::NonFinite { t, iter });
            }
            let scale = self.constraint_scale();
            x.increment_norm = self.rhs[..n].iter().zip(&self.weights).fold(0.0_f64, |m, (d, w)| m.max((d * w).abs()));
            if watch && stall.record(x.increment_norm) {
                return Err(Error::StaticNotConverged {
                    t,
                    iter,
                    residual_norm: x.residual_norm,
                    increment_norm: x.increment_norm,
                });
            }
            self.q_prev.copy_from_slice(&x.q);
            for (p, l) in self.nu_prev.iter_mut().zip(x.lambda.iter().chain(x.mu.iter())) {
                *p = *l;
            }
            self.step.copy_from_slice(&self.rhs);
            self.step[n..].iter_mut().for_each(|d| *d *= scale);
            self.take_step(system, x, 1.0, normalise);
            halving = Some((1.0, 0));
            x.n_iterations += 1;
            if x.increment_norm <= self.params.tol {
                self.finish(system, t, x);
                return Ok(());
            }
        }
        Err(Error::StaticNotConverged {
            t,
            iter: self.params.max_iter,
            residual_norm: x.residual_norm,
            increment_norm: x.increment_norm,
        })
    }

    /// `x ← (q_prev ∘ exp(α δq), ν_prev + α δν)` with the stored step.
    fn take_step<S: ConstrainedSystem + ?Sized>(
        &mut self,
        system: &S,
        x: &mut StaticSolution,
        alpha: f64,
        normalise: &impl Fn(&mut [f64]),
    ) {
        let n = self.n;
        self.rhs[..n].iter_mut().zip(&self.step[..n]).for_each(|(r, d)| *r = alpha * d);
        system.adjust_static_step(&self.q_prev, &mut self.rhs[..n]);
        system.retract_inplace(&self.q_prev, &self.rhs[..n], &mut x.q);
        normalise(&mut x.q);
        system.note_static_step(&self.q_prev, &self.rhs[..n]);
        for ((l, p), d) in x.lambda.iter_mut().chain(x.mu.iter_mut()).zip(&self.nu_prev).zip(&self.step[n..]) {
            *l = p + alpha * d;
        }
    }

    /// The scale of the constraint rows and columns: `max(1, max_i |K_ii|)`, read back from the
    /// assembled matrix.
    fn constraint_scale(&self) -> f64 {
        (0..self.n).map(|i| self.mat.get(i, i).abs()).fold(1.0, f64::max)
    }

    /// Evaluate the equilibrium residual (into `r`) and the constraint Jacobian (into `jac`) at
    /// `x`; returns the residual's infinity norm.
    fn residual<S: ConstrainedSystem + ?Sized>(&mut self, system: &S, t: f64, x: &StaticSolution) -> f64 {
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        system.residual_inplace(t, &x.q, &self.zeros, &self.zeros, &mut self.r);
        self.constraint_rows(system, t, x);
        self.jac.add_mul_transpose_vec_inplace(&self.multipliers, &mut self.r);
        debug_assert_eq!(self.multipliers.len(), n_h + n_v);
        inf_norm(&self.r[..n])
    }

    /// `jac = [Φ_q; B]`, `constraint = [Φ; b]` and `multipliers = [λ; μ]` at `x`.
    fn constraint_rows<S: ConstrainedSystem + ?Sized>(&mut self, system: &S, t: f64, x: &StaticSolution) {
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        self.jac.fill_zero();
        system.phi_q_inplace(t, &x.q, &mut self.jac.block(0, 0, n_h, n));
        system.psi_v_inplace(t, &x.q, &mut self.jac.block(n_h, 0, n_v, n));
        let (phi, psi) = self.constraint.split_at_mut(n_h);
        system.phi_inplace(t, &x.q, phi);
        system.psi_inplace(t, &x.q, &self.zeros, psi);
        self.multipliers[..n_h].copy_from_slice(&x.lambda);
        self.multipliers[n_h..].copy_from_slice(&x.mu);
    }

    /// The bordered matrix and the right-hand side at `x`; returns the residual's infinity norm.
    fn assemble<S: ConstrainedSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        x: &StaticSolution,
        tangent: Tangent,
    ) -> f64 {
        let (n, n_c) = (self.n, self.n_h + self.n_v);
        self.mat.fill_zero();
        {
            let mut k = self.mat.block(0, 0, n, n);
            match tangent {
                Tangent::Exact => system.residual_and_iteration_matrix_inplace(
                    t,
                    &x.q,
                    &self.zeros,
                    &self.zeros,
                    &mut self.r,
                    0.0,
                    0.0,
                    1.0,
                    &mut k,
                ),
                Tangent::AtRest => system.residual_and_static_matrix_inplace(t, &x.q, &self.zeros, &mut self.r, &mut k),
            }
            system.constraint_force_tangent_inplace(t, &x.q, &x.lambda, &x.mu, 1.0, &mut k);
        }
        self.constraint_rows(system, t, x);
        self.jac.add_mul_transpose_vec_inplace(&self.multipliers, &mut self.r);
        let scale = self.constraint_scale();
        for i in 0..n_c {
            for j in 0..n {
                let g = scale * self.jac.get(i, j);
                *self.mat.get_mut(n + i, j) = g;
                *self.mat.get_mut(j, n + i) = g;
            }
        }
        for (b, r) in self.rhs.iter_mut().zip(&self.r) {
            *b = -r;
        }
        for (b, c) in self.rhs[n..].iter_mut().zip(&self.constraint) {
            *b = -scale * c;
        }
        inf_norm(&self.r)
    }

    /// The residual and constraint norms at the converged `x`.
    fn finish<S: ConstrainedSystem + ?Sized>(&mut self, system: &S, t: f64, x: &mut StaticSolution) {
        x.residual_norm = self.residual(system, t, x);
        x.constraint_norm = inf_norm(&self.constraint);
    }
}

/// The infinity norm of `v`, NaN when any entry is NaN (`f64::max` would skip it, and a
/// residual a model could not evaluate would pass for zero).
fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| if x.is_nan() || m.is_nan() { f64::NAN } else { m.max(x.abs()) })
}

/// The equilibrium of `system` at time `t` under its current loads, by Newton from `q0` with
/// zero multipliers.
///
/// # Errors
/// As [`StaticSolver::solve`].
///
/// # Panics
/// When `q0` does not have the system's `n_coords` entries.
pub fn solve_static<S: ConstrainedSystem + ?Sized>(
    system: &S,
    t: f64,
    q0: &[f64],
    params: &StaticParams,
) -> Result<StaticSolution, Error> {
    let mut x = StaticSolution::guess(system, q0);
    StaticSolver::new(system, *params).solve(system, t, &mut x)?;
    Ok(x)
}

/// Continuation: for each value `p` of `path` in turn, `set_parameter(system, p)`, then Newton
/// from the previous equilibrium (coordinates and multipliers; the first from `q0` with zero
/// multipliers). Returns the equilibrium at every value of the path. With
/// [`load_steps`]`(n)` as the path and a closure that scales the loads this is load stepping;
/// any other parameter (an airspeed, a prescribed angle) works the same way.
///
/// # Errors
/// [`Error::InvalidParameter`] for an empty path; [`Error::ContinuationFailed`] naming the step
/// and the parameter value, with the solver's error as its source.
///
/// # Panics
/// When `q0` does not have the system's `n_coords` entries, or `set_parameter` changes the
/// system's dimensions.
pub fn solve_static_path<S: ConstrainedSystem + ?Sized>(
    system: &mut S,
    t: f64,
    q0: &[f64],
    params: &StaticParams,
    path: &[f64],
    mut set_parameter: impl FnMut(&mut S, f64),
) -> Result<Vec<StaticSolution>, Error> {
    if path.is_empty() {
        return Err(Error::InvalidParameter {
            field: "path",
            reason: "a continuation needs at least one value".into(),
        });
    }
    let mut solver = StaticSolver::new(&*system, *params);
    let mut x = StaticSolution::guess(&*system, q0);
    let mut out = Vec::with_capacity(path.len());
    for (step, &p) in path.iter().enumerate() {
        set_parameter(system, p);
        solver.solve(&*system, t, &mut x).map_err(|e| Error::ContinuationFailed {
            step,
            parameter: p,
            source: Box::new(e),
        })?;
        out.push(x.clone());
    }
    Ok(out)
}

/// The load factors `1/n, 2/n, …, 1` of `n` equal load steps (none for `n = 0`).
pub fn load_steps(n: usize) -> Vec<f64> {
    (1..=n).map(|k| k as f64 / n as f64).collect()
}
