//! The generalized-α stepper (Arnold–Brüls or Chung–Hulbert form, with scaled constraint rows).

use crate::vecops::{dot, first_nonzero};
use crate::{
    Assembled, AssemblyTarget, Coefficients, ConstrainedSystem, DENSE_FALLBACK_MAX, DenseLu, DenseMatrix, Entries,
    Error, Form, IntegratorParams, IterationRecord, LinearSolver, MatView, Predictor, Stats, StepStats,
};

/// Where [`GenAlpha::assemble_with_residual`] puts the iteration matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum AssembleInto {
    /// The solver's own storage, when it offers one (else the dense matrix).
    Solver,
    /// A list of entries, for the solver's sparse fallback.
    Entries,
    /// The dense `n_all × n_all` matrix.
    Dense,
}

/// The integrator's state at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Time, s.
    pub t: f64,
    /// Coordinates (storage, length `n_coords`).
    pub q: Vec<f64>,
    /// Velocities (tangent, length `n_dof`).
    pub v: Vec<f64>,
    /// Accelerations v̇ (in the [`Form::ChungHulbert`] form, v̇ at the step's weighted instant).
    pub v_dot: Vec<f64>,
    /// Generalized-α pseudo-accelerations a.
    pub a: Vec<f64>,
    /// Multipliers of the holonomic constraints.
    pub lambda: Vec<f64>,
    /// Multipliers of the velocity constraints.
    pub mu: Vec<f64>,
}

impl State {
    /// A state at rest at `q0` with zero accelerations and multipliers, sized for `sys`.
    ///
    /// # Panics
    /// When `q0.len() != sys.n_coords()`.
    pub fn at_rest<S: ConstrainedSystem + ?Sized>(sys: &S, t: f64, q0: Vec<f64>) -> Self {
        assert_eq!(q0.len(), sys.n_coords(), "q0 has the wrong length");
        let n = sys.n_dof();
        Self {
            t,
            q: q0,
            v: vec![0.0; n],
            v_dot: vec![0.0; n],
            a: vec![0.0; n],
            lambda: vec![0.0; sys.n_holonomic()],
            mu: vec![0.0; sys.n_velocity_constraints()],
        }
    }
}

/// The generalized-α integrator with its preallocated workspace.
///
/// Generic over the linear solver; [`DenseLu`] by default.
#[derive(Debug)]
pub struct GenAlpha<L: LinearSolver = DenseLu> {
    params: IntegratorParams,
    c: Coefficients,
    n: usize,
    n_h: usize,
    n_v: usize,
    solver: L,
    /// The dense `n_all × n_all` iteration matrix, allocated at its first use only: a solver
    /// that takes the matrix into its own storage ([`LinearSolver::assembly_target`]) never
    /// needs it unless it falls back to the dense path, so a banded problem holds no `n²`
    /// buffer.
    matrix: DenseMatrix,
    /// Its dimension once allocated, `n + n_h + n_v`.
    n_all: usize,
    /// Φ_q and B at the end of the step: the constraint rows (and, in the Arnold–Brüls form,
    /// the constraint forces).
    phi_q: DenseMatrix,
    b_mat: DenseMatrix,
    /// Φ_q and B at the weighted state `q_α` of the Chung–Hulbert form: the constraint forces
    /// (empty in the Arnold–Brüls form).
    phi_q_alpha: DenseMatrix,
    b_alpha: DenseMatrix,
    phi_q_ready: bool,
    /// Columns of Φ_q with a non-zero entry (constraints touch few coordinates).
    phi_q_cols: Vec<usize>,
    /// Columns of `phi_q_alpha` with a non-zero entry.
    phi_q_alpha_cols: Vec<usize>,
    /// Columns of B that have been non-zero in some assembly (their Bᵀ entries are rewritten).
    b_cols_written: Vec<bool>,
    /// Columns of B that were non-zero at its last evaluation.
    b_nz_cols: Vec<usize>,
    /// Columns of `b_alpha` that were non-zero at its last evaluation.
    b_alpha_nz_cols: Vec<usize>,
    /// The Chung–Hulbert form is in use: forces at the weighted state below.
    weighted: bool,
    /// The weighted state `t_α`, `q_α`, `v_α` of the current iterate, the tangent increment
    /// `(1 − α_f) h Δq_n` that gives `q_α`, and `v_n`.
    t_alpha: f64,
    q_alpha: Vec<f64>,
    v_alpha: Vec<f64>,
    hdelta_alpha: Vec<f64>,
    v_n: Vec<f64>,
    have_factorization: bool,
    /// The coordinates the factorisation in hand was made at, and the rotations that carry it to
    /// the current step ([`ConstrainedSystem::corotation_inplace`]); `corotated`: the solves
    /// apply them (a factorisation from an earlier step, with rotations).
    q_factorized: Vec<f64>,
    rotations: Vec<f64>,
    corotated: bool,
    /// A co-rotated increment is projected back onto the linearised constraints with
    /// `P = Φ_q` on its non-zero columns (`n_h × n_c`, row-major) and `Q = Pᵀ (P Pᵀ)⁻¹`
    /// (`n_c × n_h`, row-major), both built once for a constant `Φ_q`; `projection_x` gathers
    /// the increment on those columns. `projection_ok`: built, `P Pᵀ` positive definite;
    /// `constraint_target`: the constraint rows' right-hand side of the solve in hand.
    projection_rows: Vec<f64>,
    projection_op: Vec<f64>,
    projection_x: Vec<f64>,
    projection_ok: Option<bool>,
    constraint_target: Vec<f64>,
    /// Matrices assembled densely ([`GenAlpha::dense_assemblies`]).
    n_dense_assemblies: usize,
    /// Where the last iteration matrix was assembled.
    assembled: AssembleInto,
    /// The iteration matrix as entries, for the sparse fallback above [`DENSE_FALLBACK_MAX`].
    fallback_entries: Entries,
    /// Iteration matrices handed to the solver's sparse fallback as entries
    /// ([`GenAlpha::sparse_fallbacks`]).
    n_sparse_fallbacks: usize,
    /// Steps left during which the factorisation is refreshed at each step's predictor, because
    /// a factorisation reused from an earlier step recently failed to contract.
    refresh_steps_left: usize,
    rhs: Vec<f64>,
    r: Vec<f64>,
    phi: Vec<f64>,
    psi: Vec<f64>,
    q_n: Vec<f64>,
    delta: Vec<f64>,
    hdelta: Vec<f64>,
    weights: Vec<f64>,
    /// State at the start of the current attempt (for retrying a failed step in halves).
    backup: State,
    /// The predictor of the current attempt (for restarting Newton with a fresh matrix).
    predictor: State,
    predictor_delta: Vec<f64>,
    /// The iterate before the last update made with a factorisation from an earlier iterate
    /// (to step back to when that update diverged).
    previous: State,
    previous_delta: Vec<f64>,
    /// The steps `s_0, s_1, …` taken with the current factorisation in this step, `n_all` each
    /// (Broyden's update, see [`broyden_correct`](Self::broyden_correct)).
    broyden_steps: Vec<f64>,
    /// Their squared norms.
    broyden_norms: Vec<f64>,
    /// The plain modified-Newton step, kept while it is corrected.
    broyden_plain: Vec<f64>,
    /// Per-iteration records while tracing is on.
    trace: Option<Vec<IterationRecord>>,
    /// v̇ at the start of the current attempt, and at the start of the last converged step
    /// (for [`Predictor::ExtrapolatedAcceleration`]).
    v_dot_n: Vec<f64>,
    v_dot_previous: Vec<f64>,
    /// (end time, size bits) of the last converged step.
    last_step: Option<(f64, u64)>,
    stats: Stats,
    /// With local error control: the halvings a step starts at. A run whose error needs short
    /// steps would otherwise retry every step from its full length and discard the attempts of
    /// every level above the one it needs; this remembers that level (deeper at once when a
    /// step needed it, one level shallower after [`GROW_AFTER`] steps that did not).
    start_depth: usize,
    /// Steps in a row completed at `start_depth` without a further halving.
    calm_steps: usize,
    /// The shallowest depth a sub-step of the current step was accepted at.
    shallowest: usize,
}

impl GenAlpha<DenseLu> {
    /// An integrator with the dense LU solver.
    pub fn new<S: ConstrainedSystem + ?Sized>(params: IntegratorParams, sys: &S) -> Result<Self, Error> {
        Self::with_solver(params, sys, DenseLu::default())
    }
}

/// Broyden's update scales the corrected step by `1/(1 − s_kᵀz/|s_k|²)`; a larger factor than
/// this means the secant model has broken down (Kelley §7.3), and the plain step is taken.
const MAX_BROYDEN_GAIN: f64 = 10.0;

/// Steps during which the factorisation is refreshed at the predictor after a reused one failed.
const REFRESH_STEPS: usize = 10;

/// With local error control, steps in a row completed at their starting depth before the next
/// starts one halving shallower (probing for a longer step costs one rejected attempt per sub-step
/// every this many steps).
const GROW_AFTER: usize = 4;

/// After four iterations with a reused matrix, keep it while its contraction predicts at most
/// this many more iterations to the tolerance (an assembly and factorisation cost about five
/// iterations). The prediction extrapolates the last contraction linearly, which is pessimistic
/// once Broyden's corrections make it superlinear: 5 rather than 3 saves 2.4 % of the work on
/// GEBF's c = 0.01 pendulum, 0.3–1.5 % on the other soft cases, and moves the rest by < 0.7 %.
const MAX_MORE_ITERATIONS: f64 = 5.0;

/// Iterations a linearly contracting iteration (ratio `theta`) needs to bring the scaled
/// increment `inc_norm` below 1.
fn iterations_to_converge(inc_norm: f64, theta: f64) -> f64 {
    if theta <= 0.0 {
        return 0.0;
    }
    inc_norm.max(1.0).ln() / -theta.min(0.999).ln()
}

fn copy_state(from: &State, to: &mut State) {
    to.t = from.t;
    to.q.copy_from_slice(&from.q);
    to.v.copy_from_slice(&from.v);
    to.v_dot.copy_from_slice(&from.v_dot);
    to.a.copy_from_slice(&from.a);
    to.lambda.copy_from_slice(&from.lambda);
    to.mu.copy_from_slice(&from.mu);
}

/// `phi_q = Φ_q(t, q)` and the list of its non-zero columns.
fn eval_phi_q<S: ConstrainedSystem + ?Sized>(
    sys: &S,
    t: f64,
    q: &[f64],
    phi_q: &mut DenseMatrix,
    cols: &mut Vec<usize>,
) {
    phi_q.fill_zero();
    sys.phi_q_inplace(t, q, &mut phi_q.view());
    let (n_h, n) = (phi_q.n_rows(), phi_q.n_cols());
    cols.clear();
    cols.extend((0..n).filter(|&j| (0..n_h).any(|i| phi_q.get(i, j) != 0.0)));
}

/// `b = B(t, q)` and the list of its non-zero columns. Only the columns found non-zero last
/// time need zeroing (the others still are): a joint touches a few unknowns.
fn eval_b<S: ConstrainedSystem + ?Sized>(sys: &S, t: f64, q: &[f64], b: &mut DenseMatrix, nz_cols: &mut Vec<usize>) {
    let (n_v, n) = (b.n_rows(), b.n_cols());
    let data = b.as_mut_slice();
    for &j in nz_cols.iter() {
        data[j * n_v..(j + 1) * n_v].fill(0.0);
    }
    sys.psi_v_inplace(t, q, &mut b.view());
    // Most columns are zero: skip them eight entries at a time, and after a non-zero the rest of
    // its column.
    nz_cols.clear();
    let data = &b.as_slice()[..n * n_v];
    let mut p = 0;
    while let Some(o) = first_nonzero(&data[p..]) {
        let j = (p + o) / n_v;
        nz_cols.push(j);
        p = (j + 1) * n_v;
    }
}

/// The constraint Jacobians at the start (one Φ_q and B for both sides: the weighted state is
/// the state itself), for assembling the initial mass system.
struct MassBorder<'a> {
    n: usize,
    n_h: usize,
    n_v: usize,
    phi_q: &'a DenseMatrix,
    phi_q_cols: &'a [usize],
    b: &'a DenseMatrix,
    b_cols: &'a [usize],
}

impl MassBorder<'_> {
    /// `[M Φ_qᵀ Bᵀ; Φ_q 0 0; B 0 0]` at `s` into `target` (cleared first).
    fn assemble<S: ConstrainedSystem + ?Sized>(&self, sys: &S, s: &State, target: &mut dyn AssemblyTarget) {
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        target.clear();
        {
            let mut k = MatView::direct(&mut *target, 0, 0, n, n);
            sys.iteration_matrix_inplace(s.t, &s.q, &s.v, &s.v_dot, 1.0, 0.0, 0.0, &mut k);
        }
        for &j in self.phi_q_cols {
            for i in (0..n_h).filter(|&i| self.phi_q.get(i, j) != 0.0) {
                let x = self.phi_q.get(i, j);
                target.add(n + i, j, x);
                target.add(j, n + i, x);
            }
        }
        if n_v > 0 {
            for &j in self.b_cols {
                let col = &self.b.as_slice()[j * n_v..(j + 1) * n_v];
                for (i, &x) in col.iter().enumerate().filter(|(_, x)| **x != 0.0) {
                    target.add(n + n_h + i, j, x);
                    target.add(j, n + n_h + i, x);
                }
            }
        }
    }
}

/// One unknown's weighted increment against its tolerance, `|Δx w| / (atol + rtol |h δ w|)`.
#[inline]
fn increment_ratio(dx: f64, w: f64, hdelta: f64, atol: f64, rtol: f64) -> f64 {
    (dx * w).abs() / (atol + rtol * (hdelta * w).abs())
}

/// `max_i |Δx_i w_i| / (atol + rtol |h δ_i w_i|)`: the increment against its tolerance (all
/// values finite). Four running maxima, so that the divisions of consecutive entries overlap
/// instead of waiting for each other through one running maximum (the maximum does not depend on
/// the order).
fn increment_norm(dx: &[f64], w: &[f64], hdelta: &[f64], atol: f64, rtol: f64) -> f64 {
    let ratio = |((d, w), hd): ((&f64, &f64), &f64)| increment_ratio(*d, *w, *hd, atol, rtol);
    let mut m = [0.0_f64; 4];
    let n4 = dx.len() - dx.len() % 4;
    for (k, e) in dx[..n4].iter().zip(&w[..n4]).zip(&hdelta[..n4]).enumerate() {
        let x = ratio(e);
        let slot = &mut m[k % 4];
        *slot = if x > *slot { x } else { *slot };
    }
    for e in dx[n4..].iter().zip(&w[n4..]).zip(&hdelta[n4..]) {
        let x = ratio(e);
        m[0] = if x > m[0] { x } else { m[0] };
    }
    m[0].max(m[1]).max(m[2].max(m[3]))
}

/// `max_i |x_i|`, NaN if any entry is NaN. Four running maxima and a NaN flag, all without
/// branches, so that consecutive entries do not wait for each other (the previous fold also
/// forgot a NaN that was followed by a number: `f64::max` ignores NaN).
fn inf_norm(x: &[f64]) -> f64 {
    let mut m = [0.0_f64; 4];
    let mut nan = false;
    let chunks = x.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..4 {
            let a = c[i].abs();
            m[i] = if a > m[i] { a } else { m[i] };
            nan |= c[i].is_nan();
        }
    }
    for v in rest {
        let a = v.abs();
        m[0] = if a > m[0] { a } else { m[0] };
        nan |= v.is_nan();
    }
    if nan { f64::NAN } else { m[0].max(m[1]).max(m[2].max(m[3])) }
}

impl<L: LinearSolver> GenAlpha<L> {
    /// An integrator with a given linear solver.
    pub fn with_solver<S: ConstrainedSystem + ?Sized>(
        params: IntegratorParams,
        sys: &S,
        mut solver: L,
    ) -> Result<Self, Error> {
        params.validate()?;
        let (n, n_h, n_v, n_q) = (sys.n_dof(), sys.n_holonomic(), sys.n_velocity_constraints(), sys.n_coords());
        let n_all = n + n_h + n_v;
        solver.set_dimension(n_all);
        let structure = sys.matrix_structure();
        if let Some(st) = &structure {
            solver.set_structure(st);
        }
        let weighted = params.form == Form::ChungHulbert;
        let (n_hw, n_vw, n_w, n_qw) = if weighted { (n_h, n_v, n, n_q) } else { (0, 0, 0, 0) };
        Ok(Self {
            params,
            c: params.coefficients(),
            n,
            n_h,
            n_v,
            solver,
            matrix: DenseMatrix::zeros(0, 0),
            n_all,
            phi_q: DenseMatrix::zeros(n_h, n),
            b_mat: DenseMatrix::zeros(n_v, n),
            phi_q_alpha: DenseMatrix::zeros(n_hw, n_w),
            b_alpha: DenseMatrix::zeros(n_vw, n_w),
            phi_q_ready: false,
            phi_q_cols: Vec::with_capacity(n),
            phi_q_alpha_cols: Vec::with_capacity(n_w),
            b_cols_written: vec![false; n],
            b_nz_cols: Vec::with_capacity(n),
            b_alpha_nz_cols: Vec::with_capacity(n_w),
            weighted,
            t_alpha: 0.0,
            q_alpha: vec![0.0; n_qw],
            v_alpha: vec![0.0; n_w],
            hdelta_alpha: vec![0.0; n_w],
            v_n: vec![0.0; n_w],
            have_factorization: false,
            n_dense_assemblies: 0,
            assembled: AssembleInto::Dense,
            fallback_entries: Entries::default(),
            n_sparse_fallbacks: 0,
            refresh_steps_left: 0,
            q_factorized: vec![0.0; n_q],
            rotations: Vec::with_capacity(n),
            corotated: false,
            projection_rows: Vec::new(),
            projection_op: Vec::new(),
            projection_x: Vec::new(),
            projection_ok: None,
            constraint_target: vec![0.0; n_h],
            rhs: vec![0.0; n_all],
            r: vec![0.0; n],
            phi: vec![0.0; n_h],
            psi: vec![0.0; n_v],
            q_n: vec![0.0; n_q],
            delta: vec![0.0; n],
            hdelta: vec![0.0; n],
            weights: (0..n).map(|i| sys.increment_weight(i)).collect(),
            backup: State::at_rest(sys, 0.0, vec![0.0; n_q]),
            predictor: State::at_rest(sys, 0.0, vec![0.0; n_q]),
            predictor_delta: vec![0.0; n],
            previous: State::at_rest(sys, 0.0, vec![0.0; n_q]),
            previous_delta: vec![0.0; n],
            broyden_steps: Vec::with_capacity(n_all * (params.newton.max_iter + 1)),
            broyden_norms: Vec::with_capacity(params.newton.max_iter + 1),
            broyden_plain: vec![0.0; n_all],
            trace: None,
            v_dot_n: vec![0.0; n],
            v_dot_previous: vec![0.0; n],
            last_step: None,
            start_depth: 0,
            calm_steps: 0,
            shallowest: 0,
            stats: Stats::default(),
        })
    }

    /// Parameters in use.
    pub fn params(&self) -> &IntegratorParams {
        &self.params
    }
    /// Chung–Hulbert coefficients in use.
    pub fn coefficients(&self) -> &Coefficients {
        &self.c
    }
    /// Accumulated statistics.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }

    /// Record every Newton iteration from now on ([`take_trace`](Self::take_trace)), or stop
    /// recording and drop the records. Off by default; when on, the records grow without bound
    /// (a few per step), so it is meant for diagnosing convergence, not for long runs.
    pub fn set_trace(&mut self, on: bool) {
        self.trace = on.then(Vec::new);
    }

    /// The iterations recorded since tracing was switched on or last taken (empty when off).
    pub fn take_trace(&mut self) -> Vec<IterationRecord> {
        self.trace.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Φ_q and B at the end of the step `(t, q)` and, in the Chung–Hulbert form, at the weighted
    /// state (`self.t_alpha`, `self.q_alpha`, which the caller has set). In that form the
    /// end-of-step Φ_q and B only enter the matrix's constraint rows, so they are evaluated only
    /// when `assembling` (the constraint residuals Φ and Ψ are the model's own functions).
    fn update_jacobians<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S, t: f64, q: &[f64], assembling: bool) {
        let rows = assembling || !self.weighted;
        if self.n_h > 0 && !(self.phi_q_ready && sys.phi_q_is_constant()) {
            // Forget the previous Φ_q in the assembled matrix: its non-zero columns may move.
            // (Nothing to forget before the dense matrix exists.)
            let (n, n_h) = (self.n, self.n_h);
            let dense = self.matrix.n_rows() > 0;
            if rows && dense {
                for &j in &self.phi_q_cols {
                    (0..n_h).for_each(|i| *self.matrix.get_mut(n + i, j) = 0.0);
                }
            }
            let force_cols = if self.weighted { &self.phi_q_alpha_cols } else { &self.phi_q_cols };
            for &j in force_cols.iter().filter(|_| dense) {
                (0..n_h).for_each(|i| *self.matrix.get_mut(j, n + i) = 0.0);
            }
            if rows {
                eval_phi_q(sys, t, q, &mut self.phi_q, &mut self.phi_q_cols);
            }
            if self.weighted {
                eval_phi_q(sys, self.t_alpha, &self.q_alpha, &mut self.phi_q_alpha, &mut self.phi_q_alpha_cols);
            }
            self.phi_q_ready = true;
        }
        if self.n_v > 0 {
            if rows {
                eval_b(sys, t, q, &mut self.b_mat, &mut self.b_nz_cols);
            }
            if self.weighted {
                eval_b(sys, self.t_alpha, &self.q_alpha, &mut self.b_alpha, &mut self.b_alpha_nz_cols);
            }
        }
    }

    /// Copy Φ_q and B into the constraint rows of the assembled matrix, and the force
    /// Jacobians' transposes into its multiplier columns. Only the non-zero columns of Φ_q are
    /// written: its zero columns stay zero from the matrix's creation (nothing else writes to the
    /// constraint rows and columns of Φ).
    fn place_constraint_blocks(&mut self) {
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        let weighted = self.weighted;
        let (phi_f, phi_f_cols, b_f) = if weighted {
            (&self.phi_q_alpha, &self.phi_q_alpha_cols, &self.b_alpha)
        } else {
            (&self.phi_q, &self.phi_q_cols, &self.b_mat)
        };
        for &j in &self.phi_q_cols {
            for i in 0..n_h {
                *self.matrix.get_mut(n + i, j) = self.phi_q.get(i, j);
            }
        }
        for &j in phi_f_cols {
            for i in 0..n_h {
                *self.matrix.get_mut(j, n + i) = phi_f.get(i, j);
            }
        }
        if n_v > 0 {
            // Only columns of B that are, or once were, non-zero: a velocity constraint touches
            // a few coordinates, and a column that was never written is still zero in Bᵀ.
            for j in 0..n {
                let col = &self.b_mat.as_slice()[j * n_v..(j + 1) * n_v];
                let col_f = &b_f.as_slice()[j * n_v..(j + 1) * n_v];
                self.b_cols_written[j] |= col.iter().chain(col_f).any(|&x| x != 0.0);
                if !self.b_cols_written[j] {
                    continue;
                }
                for (i, (&x, &xf)) in col.iter().zip(col_f).enumerate() {
                    *self.matrix.get_mut(n + n_h + i, j) += x;
                    *self.matrix.get_mut(j, n + n_h + i) = xf;
                }
            }
        }
    }

    /// Allocate the dense matrix at its first use (zero, as the constraint blocks' bookkeeping
    /// assumes), before a dense assembly.
    fn ensure_dense(&mut self) {
        self.n_dense_assemblies += 1;
        if self.matrix.n_rows() != self.n_all {
            self.matrix = DenseMatrix::zeros(self.n_all, self.n_all);
        }
    }

    /// Free the dense matrix (and forget which columns of Bᵀ it held).
    fn discard_dense(&mut self) {
        if self.matrix.n_rows() > 0 {
            self.matrix = DenseMatrix::zeros(0, 0);
            self.b_cols_written.iter_mut().for_each(|w| *w = false);
        }
    }

    /// How many matrices (the start's included) have been assembled into the dense
    /// `n_all × n_all` matrix: a solver without its own storage, or a fallback.
    pub fn dense_assemblies(&self) -> usize {
        self.n_dense_assemblies
    }

    /// How many matrices went to the solver's sparse LU as entries: the start's mass matrix when
    /// the structured factorisation cannot take it, and iteration matrices above
    /// [`DENSE_FALLBACK_MAX`] unknowns that the solver's storage cannot take (no `n²` storage is
    /// allocated for them).
    pub fn sparse_fallbacks(&self) -> usize {
        self.n_sparse_fallbacks
    }

    /// Whether the dense `n_all × n_all` matrix has been allocated (it is only on a dense
    /// assembly: a solver without its own storage, or a fallback).
    pub fn holds_dense_matrix(&self) -> bool {
        self.matrix.n_rows() > 0
    }

    /// Zero the blocks of the assembled matrix that the model adds to (K, and the velocity
    /// constraint rows that receive ∂Ψ/∂q); the Φ_q blocks are overwritten by
    /// [`place_constraint_blocks`](Self::place_constraint_blocks) and the multiplier block
    /// stays zero.
    fn clear_added_blocks(&mut self) {
        let (n, n_h) = (self.n, self.n_h);
        let n_all = self.matrix.n_rows();
        let data = self.matrix.as_mut_slice();
        // Whole columns, also outside a declared structure: a model that writes outside it
        // (which the solvers detect and then drop the structure) must not leave entries to pile
        // up from one dense assembly to the next. Dense assemblies are rare when the solver
        // offers its own storage (the first matrix, and hand-overs).
        for col in data.chunks_exact_mut(n_all).take(n) {
            col[..n].fill(0.0);
            col[n + n_h..].fill(0.0);
        }
    }

    /// `r += Φ_qᵀ λ + Bᵀ μ` (the force Jacobians).
    #[inline]
    fn add_constraint_forces(&mut self, lambda: &[f64], mu: &[f64]) {
        let (n_h, n_v) = (self.n_h, self.n_v);
        let (phi_f, phi_f_cols, b_f, b_f_cols) = if self.weighted {
            (&self.phi_q_alpha, &self.phi_q_alpha_cols, &self.b_alpha, &self.b_alpha_nz_cols)
        } else {
            (&self.phi_q, &self.phi_q_cols, &self.b_mat, &self.b_nz_cols)
        };
        // Φ_q and B are stored by columns: column j's entries are contiguous.
        let phi = phi_f.as_slice();
        for &j in phi_f_cols {
            self.r[j] += dot(&phi[j * n_h..(j + 1) * n_h], lambda);
        }
        if n_v > 0 {
            let data = b_f.as_slice();
            for &j in b_f_cols {
                self.r[j] += dot(&data[j * n_v..(j + 1) * n_v], mu);
            }
        }
    }

    /// Consistent initial accelerations and multipliers:
    /// `[M Φ_qᵀ Bᵀ; Φ_q 0 0; B 0 0] [v̇; λ; μ] = [−g; −(Φ_q v)_q v; −(B v)_q v]`
    /// (scleronomic constraints: ∂b/∂t = 0). Sets `a = v̇`.
    pub fn initialize<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S, s: &mut State) -> Result<(), Error> {
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        self.last_step = None; // a new start: nothing to extrapolate from
        if self.weighted {
            // At the start the weighted state is the state itself.
            self.t_alpha = s.t;
            self.q_alpha.copy_from_slice(&s.q);
        }
        self.update_jacobians(sys, s.t, &s.q, true);
        if !self.factorize_mass_direct(sys, s)? && !self.factorize_mass_entries(sys, s)? {
            self.ensure_dense();
            self.matrix.fill_zero();
            sys.iteration_matrix_inplace(s.t, &s.q, &s.v, &s.v_dot, 1.0, 0.0, 0.0, &mut self.matrix.block(0, 0, n, n));
            self.place_constraint_blocks();
            self.solver.factorize(&self.matrix).map_err(|pivot| Error::SingularMatrix { t: s.t, pivot })?;
        }
        self.have_factorization = false; // this is the mass matrix, not the iteration matrix
        let zeros = vec![0.0; n];
        sys.residual_inplace(s.t, &s.q, &s.v, &zeros, &mut self.r);
        for i in 0..n {
            self.rhs[i] = -self.r[i];
        }
        sys.phi_qq_vv_inplace(s.t, &s.q, &s.v, &mut self.phi);
        for i in 0..n_h {
            self.rhs[n + i] = -self.phi[i];
        }
        if n_v > 0 {
            let mut psi_q = DenseMatrix::zeros(n_v, n);
            sys.psi_q_inplace(s.t, &s.q, &s.v, &mut psi_q.view());
            psi_q.mul_vec_inplace(&s.v, &mut self.psi);
            for i in 0..n_v {
                self.rhs[n + n_h + i] = -self.psi[i];
            }
        }
        self.solver.solve_in_place(&mut self.rhs);
        if !self.rhs.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFinite { t: s.t, iter: 0 });
        }
        s.v_dot.copy_from_slice(&self.rhs[..n]);
        s.a.copy_from_slice(&self.rhs[..n]);
        s.lambda.copy_from_slice(&self.rhs[n..n + n_h]);
        s.mu.copy_from_slice(&self.rhs[n + n_h..]);
        if self.solver.assembly_target().is_some() {
            // The mass matrix took the dense path (a solver whose structured factorisation needs
            // pivoting for it): the iteration matrices go to the solver's storage, so the dense
            // matrix is not kept (it is allocated again, zero, if a fallback needs it).
            self.discard_dense();
        }
        let np = &self.params.newton;
        if np.corotate && np.reuse_factorization && self.projection_ok.is_none() {
            // Set up the co-rotated solves' projection here, so that no step allocates.
            self.can_corotate(sys);
        }
        Ok(())
    }

    /// `[M Φ_qᵀ Bᵀ; Φ_q 0 0; B 0 0]` at `s` (the Jacobians evaluated at `s.q`) assembled into the
    /// solver's own storage and factorised there; false when the solver has no such storage or
    /// asks for the dense path.
    fn factorize_mass_direct<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S, s: &State) -> Result<bool, Error> {
        let (jac, solver) = self.mass_border();
        let Some(target) = solver.assembly_target() else { return Ok(false) };
        jac.assemble(sys, s, target);
        match self.solver.factorize_assembled().map_err(|pivot| Error::SingularMatrix { t: s.t, pivot })? {
            Assembled::Factorized => Ok(true),
            Assembled::UseDense => Ok(false),
        }
    }

    /// The same matrix as [`factorize_mass_direct`](Self::factorize_mass_direct) assembled as
    /// entries and factorised by the solver's sparse LU with pivoting (when it has one): the
    /// fallback when the structured factorisation meets a tiny pivot, in memory proportional to
    /// the non-zeros. A floating frame's rotation is one: with the mass alone the nodes can
    /// follow it, so its Schur complement is only the share of the clamped nodes
    /// (docs/integrator.md §8.1).
    fn factorize_mass_entries<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S, s: &State) -> Result<bool, Error> {
        let mut entries = Entries::new(self.n_all);
        let (jac, solver) = self.mass_border();
        jac.assemble(sys, s, &mut entries);
        let done = solver.factorize_entries(&entries).map_err(|pivot| Error::SingularMatrix { t: s.t, pivot })?;
        self.n_sparse_fallbacks += usize::from(done);
        Ok(done)
    }

    /// The start's constraint Jacobians beside the solver (borrowed apart, so that the matrix
    /// can be assembled into the solver's own storage).
    fn mass_border(&mut self) -> (MassBorder<'_>, &mut L) {
        let Self { solver, n, n_h, n_v, phi_q, phi_q_cols, b_mat, b_nz_cols, .. } = self;
        (MassBorder { n: *n, n_h: *n_h, n_v: *n_v, phi_q, phi_q_cols, b: b_mat, b_cols: b_nz_cols }, solver)
    }

    /// Advance `s` by one step `dt`. If Newton fails, the step is retried as two half steps
    /// (recursively, up to `newton.max_step_halvings` deep). On error `s` is left at the last
    /// iterate (for plotting what was computed); the caller decides whether to stop.
    ///
    /// With local error control (`newton.local_error_tol` > 0) a step starts at the halving
    /// depth the previous steps needed (see `start_depth`); without it every step starts whole.
    pub fn step<S: ConstrainedSystem + ?Sized>(&mut self, sys: &mut S, s: &mut State) -> Result<StepStats, Error> {
        let h = self.params.dt;
        let controlled = self.params.newton.local_error_tol > 0.0;
        let d0 = if controlled { self.start_depth.min(self.params.newton.max_step_halvings) } else { 0 };
        self.shallowest = usize::MAX;
        let out = self.advance_split(sys, s, h, d0);
        if self.c.h != h {
            self.set_step_size(h);
        }
        let st = out?;
        if controlled {
            self.remember_depth(d0);
        }
        self.stats.record(&st);
        Ok(st)
    }

    /// After a step started at depth `d0`: go deeper at once when every sub-step needed it,
    /// one level shallower after [`GROW_AFTER`] steps in a row that did not.
    fn remember_depth(&mut self, d0: usize) {
        if self.shallowest > d0 && self.shallowest != usize::MAX {
            self.start_depth = self.shallowest;
            self.calm_steps = 0;
        } else {
            self.start_depth = d0;
            self.calm_steps += 1;
            if self.calm_steps >= GROW_AFTER && self.start_depth > 0 {
                self.start_depth -= 1;
                self.calm_steps = 0;
            }
        }
    }

    /// The step `h` as `2^depth` sub-steps of `h / 2^depth`, each halved further as
    /// [`advance`](Self::advance) does; the statistics summed over the sub-steps.
    fn advance_split<S: ConstrainedSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        s: &mut State,
        h: f64,
        depth: usize,
    ) -> Result<StepStats, Error> {
        let n = 1usize << depth;
        let hs = h / n as f64;
        let mut total = self.advance(sys, s, hs, depth)?;
        for _ in 1..n {
            let st = self.advance(sys, s, hs, depth)?;
            total = StepStats {
                n_newton_iters: total.n_newton_iters + st.n_newton_iters,
                n_factorizations: total.n_factorizations + st.n_factorizations,
                n_substeps: total.n_substeps + st.n_substeps,
                ..st
            };
        }
        Ok(total)
    }

    fn set_step_size(&mut self, h: f64) {
        self.c = Coefficients::new(self.params.rho_inf, h);
        self.have_factorization = false; // the matrix depends on h
    }

    /// One step of size `h`, halved recursively on Newton failure or too large a local error.
    fn advance<S: ConstrainedSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        s: &mut State,
        h: f64,
        depth: usize,
    ) -> Result<StepStats, Error> {
        if self.c.h != h {
            self.set_step_size(h);
        }
        let retry = depth < self.params.newton.max_step_halvings;
        if retry {
            copy_state(s, &mut self.backup);
        }
        match self.attempt(sys, s) {
            Ok(st) if !(retry && self.local_error_too_large(s)) => {
                self.shallowest = self.shallowest.min(depth);
                return Ok(st);
            }
            Ok(_) => {} // converged, but the step was too long for its local error: halve it
            Err(e) if !retry || matches!(e, Error::InvalidParameter { .. }) => return Err(e),
            Err(_) => {}
        }
        copy_state(&self.backup, s);
        let a = self.advance(sys, s, 0.5 * h, depth + 1)?;
        let b = self.advance(sys, s, 0.5 * h, depth + 1)?;
        Ok(StepStats {
            n_newton_iters: a.n_newton_iters + b.n_newton_iters,
            n_factorizations: a.n_factorizations + b.n_factorizations,
            n_substeps: a.n_substeps + b.n_substeps,
            ..b
        })
    }

    /// Local error control (off when `newton.local_error_tol` is 0): the position update
    /// `q_{n+1} = q_n + h v_n + h²[(½ − β) a_n + β a_{n+1}]` differs from the Taylor series by
    /// `h²(β − 1/6)(a_{n+1} − a_n) + O(h⁴)` (Zienkiewicz & Xie's estimator for Newmark-type
    /// schemes), measured in the increment's weighted max norm against the tolerance (in the
    /// Chung–Hulbert form with `v̇_α` for `a`, see below). `self.backup` holds the state at the
    /// start of the step.
    fn local_error_too_large(&self, s: &State) -> bool {
        let tol = self.params.newton.local_error_tol;
        if tol <= 0.0 {
            return false;
        }
        let c = self.c;
        let k = c.h * c.h * (c.beta - 1.0 / 6.0).abs();
        // In the Chung–Hulbert form `a` carries the undamped spurious root at rho_inf = 1
        // (it alternates about the acceleration); the weighted v̇_α is smooth and changes by the
        // same h·(jerk) to leading order.
        let (x, x0) = if self.weighted { (&s.v_dot, &self.backup.v_dot) } else { (&s.a, &self.backup.a) };
        let est = (0..self.n).fold(0.0_f64, |m, i| m.max(self.weights[i] * (x[i] - x0[i]).abs()));
        k * est > tol
    }

    fn forget_broyden_steps(&mut self) {
        self.broyden_steps.clear();
        self.broyden_norms.clear();
    }

    /// Broyden's ("good") rank-one updates of a reused factorisation `A₀`, applied to the
    /// modified-Newton step `z = −A₀⁻¹F` in `self.rhs` without forming any matrix (Kelley,
    /// *Iterative Methods for Linear and Nonlinear Equations*, SIAM 1995, §7.3, `brsol`): with
    /// `s_0 … s_k` the steps taken since the factorisation (all full steps),
    /// `z ← z + s_{j+1} (s_jᵀz)/|s_j|²` for `j < k`, then `s_{k+1} = z / (1 − s_kᵀz/|s_k|²)`.
    /// The first step after a factorisation is plain Newton. Each later one costs `k + 1`
    /// dot products and axpys on the unknowns, against a linear contraction of the reused
    /// matrix where the iteration matrix drifts within a step (the tip torsion of the paper's
    /// flexible pendulums; GEBF's root section rotating against its floating frame, a stiff,
    /// nearly massless direction whose entries follow the frame's velocity). The step is
    /// recorded for the next correction. A scaling factor above [`MAX_BROYDEN_GAIN`] means the
    /// secant model broke down: the plain step is taken and the sequence restarts from it (3–8
    /// times per run on the c = 0.1 pendulums and GEBF's c = 0.01, never on the others).
    fn broyden_correct(&mut self) {
        let m = self.rhs.len();
        let k = self.broyden_norms.len();
        if k > 0 {
            self.broyden_plain.copy_from_slice(&self.rhs);
            for j in 0..k - 1 {
                let c = dot(&self.broyden_steps[j * m..(j + 1) * m], &self.rhs) / self.broyden_norms[j];
                for (z, s) in self.rhs.iter_mut().zip(&self.broyden_steps[(j + 1) * m..(j + 2) * m]) {
                    *z += c * s;
                }
            }
            let c = dot(&self.broyden_steps[(k - 1) * m..k * m], &self.rhs) / self.broyden_norms[k - 1];
            let f = 1.0 / (1.0 - c);
            if f.is_finite() && f.abs() <= MAX_BROYDEN_GAIN {
                self.rhs.iter_mut().for_each(|z| *z *= f);
            } else {
                // Breakdown: take the plain step and start a new sequence from it.
                self.rhs.copy_from_slice(&self.broyden_plain);
                self.forget_broyden_steps();
            }
        }
        if k <= self.params.newton.max_iter {
            let norm2 = dot(&self.rhs, &self.rhs);
            if norm2 > 0.0 && norm2.is_finite() {
                self.broyden_steps.extend_from_slice(&self.rhs);
                self.broyden_norms.push(norm2);
            }
        }
    }

    /// The step's predictor: `v̇_{n+1} = v̇_n`, or extrapolated from `v̇_{n−1}` when the last step
    /// was contiguous and of the same size (in the Chung–Hulbert form, the same for `v̇_α`); the
    /// start of the Newton iteration, with `q_n`, `δ` and `h δ` set.
    fn predict<S: ConstrainedSystem + ?Sized>(&mut self, sys: &mut S, s: &mut State) {
        let c = self.c;
        let (h, n) = (c.h, self.n);
        let np = self.params.newton;
        let weighted = self.weighted;
        self.q_n.copy_from_slice(&s.q);
        if weighted {
            self.v_n.copy_from_slice(&s.v);
        }
        let extrapolate =
            np.predictor == Predictor::ExtrapolatedAcceleration && self.last_step == Some((s.t, h.to_bits()));
        if np.predictor == Predictor::ExtrapolatedAcceleration {
            self.v_dot_n.copy_from_slice(&s.v_dot); // becomes v̇_{n−1} for the next step
        }
        for i in 0..n {
            let a_n = s.a[i];
            // a_{n+1} from (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) v̇_{n+1} + α_f v̇_n.
            let v_dot_n = s.v_dot[i];
            let a1 = if extrapolate {
                s.v_dot[i] = 2.0 * v_dot_n - self.v_dot_previous[i];
                if weighted {
                    // v̇_α = (1 − α_m) a_{n+1} + α_m a_n.
                    (s.v_dot[i] - c.alpha_m * a_n) / (1.0 - c.alpha_m)
                } else {
                    ((1.0 - c.alpha_f) * s.v_dot[i] + c.alpha_f * v_dot_n - c.alpha_m * a_n) / (1.0 - c.alpha_m)
                }
            } else {
                (v_dot_n - c.alpha_m * a_n) / (1.0 - c.alpha_m)
            };
            self.delta[i] = s.v[i] + h * (0.5 - c.beta) * a_n + h * c.beta * a1;
            s.v[i] += h * (1.0 - c.gamma) * a_n + h * c.gamma * a1;
            s.a[i] = a1;
            self.hdelta[i] = h * self.delta[i];
        }
        sys.retract_inplace(&self.q_n, &self.hdelta, &mut s.q);
    }

    /// Back to the step's predictor, with the factorisation dropped.
    fn restart_from_predictor(&mut self, s: &mut State) {
        let (h, n) = (self.c.h, self.n);
        copy_state(&self.predictor, s);
        self.delta.copy_from_slice(&self.predictor_delta);
        for i in 0..n {
            self.hdelta[i] = h * self.delta[i];
        }
        self.have_factorization = false;
    }

    /// Whether a reused factorisation may be co-rotated: no velocity constraints, and holonomic
    /// ones only with a constant, full-rank `Φ_q` (whose projection is then built once).
    fn can_corotate<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S) -> bool {
        if self.n_v > 0 {
            return false;
        }
        if self.n_h == 0 {
            return true;
        }
        if !(self.phi_q_ready && sys.phi_q_is_constant()) {
            return false;
        }
        if self.projection_ok.is_none() {
            self.projection_ok = Some(self.build_projection());
        }
        self.projection_ok == Some(true)
    }

    /// `P` and `Q` of the projection onto the constraints (see the fields); false if `P Pᵀ` is
    /// not positive definite to 1e-12 of its diagonal (dependent constraint rows). Once per run.
    fn build_projection(&mut self) -> bool {
        let (n_h, n_c) = (self.n_h, self.phi_q_cols.len());
        let p = nalgebra::DMatrix::from_fn(n_h, n_c, |i, k| self.phi_q.get(i, self.phi_q_cols[k]));
        let g = &p * p.transpose();
        let Some(chol) = g.clone().cholesky() else { return false };
        // The pivots are the squared diagonal of the factor.
        let independent = (0..n_h).all(|j| chol.l_dirty()[(j, j)].powi(2) > 1e-12 * g[(j, j)].abs());
        if !independent {
            return false;
        }
        // Q = Pᵀ (P Pᵀ)⁻¹ row-major is (P Pᵀ)⁻¹ P column-major: Q's row k is its column k.
        let q = chol.solve(&p);
        self.projection_rows = p.transpose().as_slice().to_vec(); // P row-major
        self.projection_op = q.as_slice().to_vec();
        self.projection_x = vec![0.0; n_c];
        true
    }

    /// `x += Φ_qᵀ (Φ_q Φ_qᵀ)⁻¹ (g − Φ_q x)` on the increment in `rhs` (`g` its constraint rows'
    /// target): the least change that satisfies the linearised constraints, which a co-rotated
    /// solve satisfies only to the turn of the constrained nodes.
    fn project_onto_constraints(&mut self) {
        let n_h = self.n_h;
        if n_h == 0 {
            return;
        }
        let x = &mut self.projection_x;
        for (xk, &c) in x.iter_mut().zip(&self.phi_q_cols) {
            *xk = self.rhs[c];
        }
        let e = &mut self.constraint_target;
        for (ei, p) in e.iter_mut().zip(self.projection_rows.chunks_exact(x.len())) {
            *ei -= dot(p, x);
        }
        for (&c, q) in self.phi_q_cols.iter().zip(self.projection_op.chunks_exact(n_h)) {
            self.rhs[c] += dot(q, e);
        }
    }

    /// The Newton increment: the scaled residuals of the dynamic rows and the constraints' as
    /// the right-hand side, solved in place with the current factorisation.
    fn solve_increment<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S, c_vdot: f64) {
        let (n, n_h, n_v, c) = (self.n, self.n_h, self.n_v, self.c);
        let inv_c_vdot = 1.0 / c_vdot;
        for (b, r) in self.rhs[..n].iter_mut().zip(&self.r) {
            *b = -r * inv_c_vdot;
        }
        for i in 0..n_h {
            self.rhs[n + i] = -self.phi[i];
        }
        for i in 0..n_v {
            self.rhs[n + n_h + i] = -self.psi[i] / c.gamma_prime;
        }
        if self.corotated {
            // x = R A₀⁻¹ Rᵀ b on the dynamic rows (the constraint rows keep their frame), then
            // projected back onto the linearised constraints
            self.constraint_target.copy_from_slice(&self.rhs[n..n + n_h]);
            sys.corotate_inplace(&self.rotations, &mut self.rhs[..n], true);
            self.solver.solve_in_place(&mut self.rhs);
            sys.corotate_inplace(&self.rotations, &mut self.rhs[..n], false);
            self.project_onto_constraints();
        } else {
            self.solver.solve_in_place(&mut self.rhs);
        }
    }

    /// Apply the solved increment to the step's unknowns and multipliers and retract the
    /// coordinates; the increment's weighted norm.
    fn apply_increment<S: ConstrainedSystem + ?Sized>(&mut self, sys: &mut S, s: &mut State, c_vdot: f64) -> f64 {
        let (n, n_h, n_v, c) = (self.n, self.n_h, self.n_v, self.c);
        let (h, np) = (c.h, self.params.newton);
        let (inv_h, inv_beta_h2) = (1.0 / h, 1.0 / (c.beta * h * h)); // no divisions in the loop
        let dxs = &self.rhs[..n];
        for (((d, hd), dx), (v, (v_dot, a))) in self
            .delta
            .iter_mut()
            .zip(self.hdelta.iter_mut())
            .zip(dxs)
            .zip(s.v.iter_mut().zip(s.v_dot.iter_mut().zip(s.a.iter_mut())))
        {
            *d += dx * inv_h;
            *hd = h * *d;
            *v += c.gamma_prime * dx;
            *v_dot += c_vdot * dx;
            *a += dx * inv_beta_h2;
        }
        let inc_norm = increment_norm(dxs, &self.weights, &self.hdelta, np.atol, np.rtol);
        for i in 0..n_h {
            s.lambda[i] += c_vdot * self.rhs[n + i];
        }
        for i in 0..n_v {
            s.mu[i] += c_vdot * self.rhs[n + n_h + i];
        }
        sys.retract_inplace(&self.q_n, &self.hdelta, &mut s.q);
        inc_norm
    }

    /// A converged step: the refresh count, the extrapolating predictor's history, the time and
    /// the system's post-step hook.
    fn accept<S: ConstrainedSystem + ?Sized>(&mut self, sys: &mut S, s: &mut State, t1: f64) {
        self.refresh_steps_left = self.refresh_steps_left.saturating_sub(1);
        if self.params.newton.predictor == Predictor::ExtrapolatedAcceleration {
            std::mem::swap(&mut self.v_dot_previous, &mut self.v_dot_n);
            self.last_step = Some((t1, self.c.h.to_bits()));
        }
        s.t = t1;
        sys.post_step(t1, &mut s.q, &mut s.v, &mut s.v_dot, &mut s.a);
    }

    /// The dynamic residual at the current iterate (or its weighted state) with the constraint
    /// forces, and the iteration matrix when `need` says it is refactorised here (one pass over
    /// the elements).
    fn residual_at<S: ConstrainedSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_n: f64,
        t1: f64,
        s: &mut State,
        need: bool,
    ) {
        let weighted = self.weighted;
        if weighted {
            self.set_weighted_state(sys, t_n, s);
        }
        self.update_jacobians(sys, t1, &s.q, need);
        if need {
            self.assemble_with_residual(sys, t1, s, AssembleInto::Solver);
        } else if weighted {
            sys.residual_inplace(self.t_alpha, &self.q_alpha, &self.v_alpha, &s.v_dot, &mut self.r);
        } else {
            sys.residual_inplace(t1, &s.q, &s.v, &s.v_dot, &mut self.r);
        }
        self.stats.n_residual_evals += 1;
        self.add_constraint_forces(&s.lambda, &s.mu);
    }

    /// One Newton iteration's record for the trace, when one is kept.
    fn record_iteration(&mut self, t1: f64, iter: usize, need: bool, res_norm: f64, stats: &StepStats, inc_norm: f64) {
        let (n, h, np) = (self.n, self.c.h, self.params.newton);
        if let Some(trace) = &mut self.trace {
            let dxs = &self.rhs[..n];
            let ratio = |i: usize| increment_ratio(dxs[i], self.weights[i], self.hdelta[i], np.atol, np.rtol);
            let worst_unknown = (0..n).fold(0, |w, i| if ratio(i) > ratio(w) { i } else { w });
            trace.push(IterationRecord {
                t: t1,
                h,
                iter,
                factorized: need,
                residual_norm: res_norm,
                phi_norm: stats.phi_norm,
                psi_norm: stats.psi_norm,
                increment_norm: inc_norm,
                worst_unknown,
            });
        }
    }

    /// One Newton solve for a step of the current size `self.c.h`.
    fn attempt<S: ConstrainedSystem + ?Sized>(&mut self, sys: &mut S, s: &mut State) -> Result<StepStats, Error> {
        let c = self.c;
        let h = c.h;
        let np = self.params.newton;
        let t1 = s.t + h;

        let (t_n, weighted) = (s.t, self.weighted);
        self.predict(sys, s);
        let keep_predictor = np.reuse_factorization;
        if keep_predictor {
            copy_state(s, &mut self.predictor);
            self.predictor_delta.copy_from_slice(&self.delta);
        }

        // The weights of the dynamic rows: ∂v̇/∂x of the Newton unknown x (the scaling of the
        // dynamic rows is its inverse, and the multipliers move by it times their unknowns).
        // In the Chung–Hulbert form every weighted quantity moves by (1 − α_f) times its
        // end-of-step value, so the scaled matrix is the same.
        let c_vdot = if weighted { (1.0 - c.alpha_f) * c.beta_prime } else { c.beta_prime };
        let mut stats = StepStats { n_substeps: 1, ..StepStats::default() };
        let mut prev_inc = f64::INFINITY;
        let mut fresh = false; // factorisation made at this iterate's matrix
        let mut factorized_this_step = false;
        let mut inc_norm = f64::INFINITY;
        let mut prev_prev_inc = f64::INFINITY;
        let mut step_back = false; // back at an earlier iterate: factorise here
        let mut rotations_known = false; // this step's rotations of an earlier factorisation
        self.forget_broyden_steps();
        for iter in 1..=np.max_iter + 1 {
            // Constraints at the current iterate first: if the increment says converged, the
            // dynamic residual is not needed.
            sys.phi_inplace(t1, &s.q, &mut self.phi);
            sys.psi_inplace(t1, &s.q, &s.v, &mut self.psi);
            let phi_norm = inf_norm(&self.phi);
            let psi_norm = inf_norm(&self.psi);
            stats.phi_norm = phi_norm;
            stats.psi_norm = psi_norm;
            if !(phi_norm.is_finite() && psi_norm.is_finite()) {
                return Err(Error::NonFinite { t: t1, iter });
            }
            // Converged when the last increment, or the error estimate θ/(1 − θ)·|Δ| of a
            // contracting iteration (θ = |Δ_k|/|Δ_{k−1}|, two increments of the current
            // sequence: after a restart or a step back `prev_inc` is infinite and θ says
            // nothing), is below the tolerance. With a co-rotated matrix θ is taken from the
            // second and third increments at the earliest: the first removes the predictor's
            // error, which the co-rotated matrix takes out almost exactly (θ ≈ 2e-4 on a spinning
            // stiff body) while the rest contracts far more slowly, so that the first two
            // increments promise an accuracy the iterate does not have.
            let theta = inc_norm / prev_inc;
            let small = inc_norm <= 1.0
                || (np.estimate_convergence
                    && prev_inc.is_finite()
                    && (!self.corotated || iter >= 4)
                    && theta < 0.5
                    && theta / (1.0 - theta) * inc_norm <= 1.0);
            if iter > 1 && small && phi_norm <= np.phi_tol && psi_norm <= np.psi_tol {
                stats.n_newton_iters = iter - 1;
                self.accept(sys, s, t1);
                return Ok(stats);
            }
            // A fresh matrix whose increments grew twice in a row: give up early (the caller
            // halves the step).
            if factorized_this_step && fresh && inc_norm > 2.0 * prev_inc && prev_inc > 2.0 * prev_prev_inc {
                break;
            }
            if iter > np.max_iter {
                break;
            }
            // Decide whether to (re)factorise.
            let contraction = inc_norm / prev_inc;
            if keep_predictor && contraction > 1.0 && !factorized_this_step {
                // Diverging with a matrix from an earlier step: the iterate may already be
                // spoiled, so restart from the predictor with a fresh matrix.
                self.restart_from_predictor(s);
                self.refresh_steps_left = REFRESH_STEPS;
                inc_norm = f64::INFINITY;
                prev_inc = f64::INFINITY;
                self.forget_broyden_steps();
                continue;
            }
            if !step_back && factorized_this_step && !fresh && contraction > 1.0 {
                // The last update, made with this step's factorisation from an earlier
                // iterate, diverged: it may have spoiled the iterate (modified Newton overshoots
                // where the matrix changes fast), so step back to the iterate before it and
                // factorise there, i.e. continue with full Newton.
                copy_state(&self.previous, s);
                self.delta.copy_from_slice(&self.previous_delta);
                inc_norm = prev_inc;
                prev_inc = prev_prev_inc;
                prev_prev_inc = f64::INFINITY;
                step_back = true;
                self.forget_broyden_steps();
                continue;
            }
            let need = step_back
                || !np.reuse_factorization
                || !self.have_factorization
                || (iter == 1 && self.refresh_steps_left > 0)
                || (iter > 1 && contraction > np.max_contraction && !fresh)
                || (iter > 4 && !fresh && iterations_to_converge(inc_norm, contraction) > MAX_MORE_ITERATIONS);
            // Dynamic residual at the current iterate (or its weighted state), with the iteration
            // matrix when it is refactorised here (one pass over the elements).
            self.residual_at(sys, t_n, t1, s, need);
            let res_norm = inf_norm(&self.r) / c_vdot;
            stats.residual_norm = res_norm;
            if !res_norm.is_finite() {
                return Err(Error::NonFinite { t: t1, iter });
            }
            if need {
                if iter > 1 && !factorized_this_step && !self.corotated {
                    // The matrix of an earlier step did not contract: the matrix changes fast,
                    // so refresh it at the predictor for the next steps. (Not after a
                    // co-rotated one: the turning that outdates a matrix within a few steps is
                    // taken out, and what is left outdates it slowly; on ANCF's c = 1, β = 45°
                    // pendulum the window cost 0.44 factorisations a step against 0.97 solves.)
                    self.refresh_steps_left = REFRESH_STEPS;
                }
                self.factorize_iteration_matrix(sys, t1, s)?;
                self.have_factorization = true;
                stats.n_factorizations += 1;
                fresh = true;
                factorized_this_step = true;
                self.q_factorized.copy_from_slice(&s.q);
                self.corotated = false;
            } else {
                if !factorized_this_step && !rotations_known {
                    // An earlier step's matrix: turned to this step's predictor once.
                    self.corotated = np.corotate
                        && self.can_corotate(sys)
                        && sys.corotation_inplace(&self.q_factorized, &s.q, &mut self.rotations);
                    rotations_known = true;
                }
                fresh = false;
                if factorized_this_step {
                    // The iterate a diverging update steps back to (only after this step's own
                    // factorisation: with an earlier step's matrix it restarts from the predictor).
                    copy_state(s, &mut self.previous);
                    self.previous_delta.copy_from_slice(&self.delta);
                }
            }
            step_back = false;
            self.solve_increment(sys, c_vdot);
            if np.broyden && np.reuse_factorization {
                if need {
                    self.forget_broyden_steps(); // the sequence restarts from the new matrix
                }
                self.broyden_correct();
            }
            if !self.rhs.iter().all(|x| x.is_finite()) {
                return Err(Error::NonFinite { t: t1, iter });
            }
            // Update.
            prev_prev_inc = prev_inc;
            prev_inc = inc_norm;
            inc_norm = self.apply_increment(sys, s, c_vdot);
            self.record_iteration(t1, iter, need, res_norm, &stats, inc_norm);
        }
        Err(Error::NewtonDiverged {
            t: t1,
            iter: np.max_iter,
            residual_norm: stats.residual_norm,
            increment_norm: inc_norm,
            phi_norm: stats.phi_norm,
            psi_norm: stats.psi_norm,
        })
    }

    /// The Chung–Hulbert form's weighted state of the iterate `s` of a step from `t_n`:
    /// `q_α = q_n ∘ exp((1 − α_f) h Δq_n)`, `v_α = (1 − α_f) v + α_f v_n`, `t_α`.
    fn set_weighted_state<S: ConstrainedSystem + ?Sized>(&mut self, sys: &S, t_n: f64, s: &State) {
        let c = self.c;
        let w = 1.0 - c.alpha_f;
        for (((ha, d), va), (v, v0)) in
            self.hdelta_alpha.iter_mut().zip(&self.delta).zip(self.v_alpha.iter_mut()).zip(s.v.iter().zip(&self.v_n))
        {
            *ha = w * c.h * d;
            *va = w * v + c.alpha_f * v0;
        }
        sys.retract_inplace(&self.q_n, &self.hdelta_alpha, &mut self.q_alpha);
        self.t_alpha = t_n + w * c.h;
    }

    /// Assemble the scaled iteration matrix at the current iterate, and evaluate the residual
    /// there into `self.r` (without constraint forces): into the solver's own storage when
    /// `direct` is allowed and the solver offers one ([`LinearSolver::assembly_target`]), else into
    /// the dense matrix.
    fn assemble_with_residual<S: ConstrainedSystem + ?Sized>(
        &mut self,
        sys: &S,
        t1: f64,
        s: &State,
        into: AssembleInto,
    ) {
        let c = self.c;
        let (n, n_h, n_v) = (self.n, self.n_h, self.n_v);
        let (c_m, c_c, c_k) = (1.0, c.gamma_prime / c.beta_prime, 1.0 / c.beta_prime);
        // Where the forces are evaluated: the end of the step or the weighted state.
        let (t_f, q_f, v_f) =
            if self.weighted { (self.t_alpha, &self.q_alpha[..], &self.v_alpha[..]) } else { (t1, &s.q[..], &s.v[..]) };
        let (phi_f, phi_f_cols, b_f, b_f_cols) = if self.weighted {
            (&self.phi_q_alpha, &self.phi_q_alpha_cols, &self.b_alpha, &self.b_alpha_nz_cols)
        } else {
            (&self.phi_q, &self.phi_q_cols, &self.b_mat, &self.b_nz_cols)
        };
        // A solver without storage of its own takes the dense matrix, or entries above the
        // dense fallback's size.
        let into = match into {
            AssembleInto::Solver if self.solver.assembly_target().is_none() => self.fallback_form(),
            into => into,
        };
        self.assembled = into;
        let mut entries = (into == AssembleInto::Entries).then(|| Entries::new(self.n_all));
        let target: Option<&mut dyn AssemblyTarget> = match (&mut entries, into) {
            (Some(e), _) => Some(e),
            (None, AssembleInto::Solver) => self.solver.assembly_target(),
            _ => None,
        };
        if let Some(target) = target {
            target.clear();
            {
                let mut k = MatView::direct(&mut *target, 0, 0, n, n);
                sys.residual_and_iteration_matrix_inplace(t_f, q_f, v_f, &s.v_dot, &mut self.r, c_m, c_c, c_k, &mut k);
                sys.constraint_force_tangent_inplace(t_f, q_f, &s.lambda, &s.mu, c_k, &mut k);
            }
            if n_v > 0 {
                let mut j = MatView::direct(&mut *target, n + n_h, 0, n_v, n);
                sys.psi_q_inplace(t1, &s.q, &s.v, &mut j.scaled(1.0 / c.gamma_prime));
            }
            // Constraint rows at the end of the step, multiplier columns from the force Jacobians
            // (the same matrix in the Arnold–Brüls form: one pass).
            for &j in &self.phi_q_cols {
                for i in (0..n_h).filter(|&i| self.phi_q.get(i, j) != 0.0) {
                    let x = self.phi_q.get(i, j);
                    target.add(n + i, j, x);
                    if !self.weighted {
                        target.add(j, n + i, x);
                    }
                }
            }
            if self.weighted {
                for &j in phi_f_cols {
                    for i in (0..n_h).filter(|&i| phi_f.get(i, j) != 0.0) {
                        target.add(j, n + i, phi_f.get(i, j));
                    }
                }
            }
            if n_v > 0 {
                for &j in &self.b_nz_cols {
                    let col = &self.b_mat.as_slice()[j * n_v..(j + 1) * n_v];
                    for (i, &x) in col.iter().enumerate().filter(|(_, x)| **x != 0.0) {
                        target.add(n + n_h + i, j, x);
                        if !self.weighted {
                            target.add(j, n + n_h + i, x);
                        }
                    }
                }
                if self.weighted {
                    for &j in b_f_cols {
                        let col = &b_f.as_slice()[j * n_v..(j + 1) * n_v];
                        for (i, &x) in col.iter().enumerate().filter(|(_, x)| **x != 0.0) {
                            target.add(j, n + n_h + i, x);
                        }
                    }
                }
            }
            if let Some(e) = entries {
                self.fallback_entries = e;
            }
            return;
        }
        self.assembled = AssembleInto::Dense;
        self.ensure_dense();
        self.clear_added_blocks();
        let (t_f, q_f, v_f) =
            if self.weighted { (self.t_alpha, &self.q_alpha[..], &self.v_alpha[..]) } else { (t1, &s.q[..], &s.v[..]) };
        {
            let mut k = self.matrix.block(0, 0, n, n);
            sys.residual_and_iteration_matrix_inplace(t_f, q_f, v_f, &s.v_dot, &mut self.r, c_m, c_c, c_k, &mut k);
            sys.constraint_force_tangent_inplace(t_f, q_f, &s.lambda, &s.mu, c_k, &mut k);
        }
        if n_v > 0 {
            let mut j = self.matrix.block(n + n_h, 0, n_v, n);
            sys.psi_q_inplace(t1, &s.q, &s.v, &mut j.scaled(1.0 / c.gamma_prime));
        }
        self.place_constraint_blocks();
    }

    /// Factorise the matrix of the last [`assemble_with_residual`](Self::assemble_with_residual).
    /// When the solver's own storage asks for the dense path, the same matrix is assembled
    /// again (the residual is recomputed with the same values, and the constraint forces added
    /// to it again) and factorised (a solver whose storage met an entry outside its structure
    /// stops offering it): densely, or above [`DENSE_FALLBACK_MAX`] unknowns as entries for the
    /// solver's sparse LU with pivoting (densely only for a solver without one).
    fn factorize_iteration_matrix<S: ConstrainedSystem + ?Sized>(
        &mut self,
        sys: &S,
        t1: f64,
        s: &State,
    ) -> Result<(), Error> {
        let singular = |pivot| Error::SingularMatrix { t: t1, pivot };
        if self.assembled == AssembleInto::Solver {
            match self.solver.factorize_assembled().map_err(singular)? {
                Assembled::Factorized => return Ok(()),
                Assembled::UseDense => {
                    // The storage met an entry outside the declared structure (or could not
                    // factorise). The residual is recomputed on the way: add the constraint
                    // forces again.
                    let into = self.fallback_form();
                    self.assemble_with_residual(sys, t1, s, into);
                    self.add_constraint_forces(&s.lambda, &s.mu);
                }
            }
        }
        if self.assembled == AssembleInto::Entries {
            let entries = std::mem::take(&mut self.fallback_entries);
            self.n_sparse_fallbacks += 1;
            if self.solver.factorize_entries(&entries).map_err(singular)? {
                return Ok(());
            }
            // A solver without a sparse LU: the dense matrix after all.
            self.assemble_with_residual(sys, t1, s, AssembleInto::Dense);
            self.add_constraint_forces(&s.lambda, &s.mu);
        }
        self.solver.factorize(&self.matrix).map_err(singular)
    }

    /// Where a matrix the solver's storage cannot take is assembled: the dense matrix, or
    /// entries for the solver's sparse LU above [`DENSE_FALLBACK_MAX`] unknowns (no `n²`
    /// storage).
    fn fallback_form(&self) -> AssembleInto {
        if self.n_all > DENSE_FALLBACK_MAX { AssembleInto::Entries } else { AssembleInto::Dense }
    }
}

#[cfg(test)]
mod norm_tests {
    use super::inf_norm;
    use crate::{GenAlpha, IntegratorParams, tests::Oscillator};

    /// Kelley's recursion on a stored step `s_0`: the plain step `z` becomes
    /// `z / (1 − s_0ᵀz/|s_0|²)` and is recorded; when that factor exceeds the allowed gain the
    /// plain step is kept and the sequence restarts from it.
    #[test]
    fn broyden_step_is_scaled_or_falls_back_on_breakdown() {
        let sys = Oscillator { m: 1.0, k: 1.0 };
        let mut ga = GenAlpha::new(IntegratorParams::new(0.9, 1e-2), &sys).unwrap();
        ga.rhs[0] = 2.0;
        ga.broyden_correct(); // first step: recorded as is
        assert_eq!((ga.rhs[0], ga.broyden_norms.len()), (2.0, 1));
        ga.rhs[0] = 1.0; // s_0ᵀz/|s_0|² = 1/2: scaled by 2
        ga.broyden_correct();
        assert_eq!((ga.rhs[0], ga.broyden_norms.len()), (2.0, 2));
        ga.forget_broyden_steps();
        ga.rhs[0] = 1.0;
        ga.broyden_correct();
        ga.rhs[0] = 0.95; // factor 1/(1 − 0.95) = 20 > the allowed gain: plain step, new sequence
        ga.broyden_correct();
        assert_eq!(ga.rhs[0], 0.95);
        assert_eq!(ga.broyden_norms.len(), 1);
        assert_eq!(ga.broyden_steps[0], 0.95);
    }

    #[test]
    fn inf_norm_is_the_largest_magnitude_and_keeps_nan() {
        assert_eq!(inf_norm(&[]), 0.0);
        assert_eq!(inf_norm(&[1.0, -7.5, 3.0, 2.0, -0.5, 6.0]), 7.5);
        assert_eq!(inf_norm(&[1.0, 2.0, 3.0, 4.0, 5.0, -9.0, 7.0]), 9.0);
        assert_eq!(inf_norm(&[f64::NEG_INFINITY, 1.0]), f64::INFINITY);
        // NaN anywhere, also followed by numbers (in a chunk of four and in the remainder)
        for k in 0..7 {
            let mut x = vec![1.0; 7];
            x[k] = f64::NAN;
            assert!(inf_norm(&x).is_nan(), "NaN at {k}");
        }
    }
}
