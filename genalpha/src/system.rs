//! The trait a structural model implements.

use crate::{BandedBorder, MatView};

/// A constrained second-order system
///
/// $$ r(q, v, \dot v, t) = M(q)\dot v + g(q, v, t),\qquad \Phi(q) = 0,\qquad \Psi = B(q) v + b(q, t) = 0 $$
///
/// (the integrator adds the constraint forces `Φ_qᵀ λ + Bᵀ μ` itself).
///
/// Coordinates `q` live in a storage vector of length [`n_coords`](Self::n_coords), which may
/// exceed the tangent dimension [`n_dof`](Self::n_dof) (unit quaternions). Velocities, accelerations
/// and every Jacobian column are tangent-space quantities of length `n_dof`. A perturbation of `q`
/// is `q ∘ exp(δ)`, the model's [`retract_inplace`](Self::retract_inplace); "∂/∂q" below always
/// means the derivative along that perturbation. For vector coordinates the default additive
/// retraction makes these plain partial derivatives.
///
/// Every method writes into buffers the integrator owns: nothing allocates in the time loop.
pub trait ConstrainedSystem {
    /// Length of the stored coordinate vector `q`.
    fn n_coords(&self) -> usize;
    /// Tangent dimension: length of `v`, `v_dot` and of the residual.
    fn n_dof(&self) -> usize;
    /// Number of holonomic constraint rows Φ(q) = 0.
    fn n_holonomic(&self) -> usize {
        0
    }
    /// Number of velocity-level constraint rows B(q) v + b = 0.
    fn n_velocity_constraints(&self) -> usize {
        0
    }

    /// `q_out = q ∘ exp(dq)`. Default: `q_out = q + dq` (requires `n_coords == n_dof`).
    fn retract_inplace(&self, q: &[f64], dq: &[f64], q_out: &mut [f64]) {
        for ((o, a), b) in q_out.iter_mut().zip(q).zip(dq) {
            *o = a + b;
        }
    }

    /// `r = M(q) v_dot + g(q, v, t)`: inertial, gyroscopic, internal and (with a minus sign)
    /// external generalised forces, without constraint forces.
    fn residual_inplace(&self, t: f64, q: &[f64], v: &[f64], v_dot: &[f64], r: &mut [f64]);

    /// `k += c_m ∂r/∂v_dot + c_c ∂r/∂v + c_k ∂r/∂q`, an `n_dof × n_dof` view.
    #[allow(clippy::too_many_arguments)] // the three coefficients are the generalized-α weights
    fn iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    );

    /// The residual and `k += c_m ∂r/∂v_dot + c_c ∂r/∂v + c_k ∂r/∂q` at the same state, for
    /// models whose matrix evaluation produces the residual on the way (the integrator calls this
    /// whenever it refactorises). Must give the same values as the two calls. Default: the two.
    #[allow(clippy::too_many_arguments)] // the union of the two methods' arguments
    fn residual_and_iteration_matrix_inplace(
        &self,
        t: f64,
        q: &[f64],
        v: &[f64],
        v_dot: &[f64],
        r: &mut [f64],
        c_m: f64,
        c_c: f64,
        c_k: f64,
        k: &mut MatView<'_>,
    ) {
        self.residual_inplace(t, q, v, v_dot, r);
        self.iteration_matrix_inplace(t, q, v, v_dot, c_m, c_c, c_k, k);
    }

    /// Told by the static solver ([`crate::analysis::StaticSolver`]) that it moved from `q_from`
    /// to `q_from ∘ exp(dq)`, before it evaluates the system there: a system that keeps part
    /// of its matrix from an earlier state can correct that part along the step (a secant
    /// update). Default: nothing.
    fn note_static_step(&self, _q_from: &[f64], _dq: &[f64]) {}

    /// The static solver's Newton step `dq` from `q`, which the model may replace by another
    /// with the same first order (so that Newton's convergence is unchanged) that a linearised
    /// step would make worse: ANCF turns the rotational part of each node's slope increment into
    /// an exact rotation, where the linear one would stretch the slopes by half the square of the
    /// angle against their stiff section strains (docs/ancf.md §9). The solver then retracts the
    /// replaced step and tells [`note_static_step`](Self::note_static_step) that one. Default:
    /// nothing.
    fn adjust_static_step(&self, _q: &[f64], _dq: &mut [f64]) {}

    /// Holonomic constraint residual Φ(q) (length `n_holonomic`).
    fn phi_inplace(&self, _t: f64, _q: &[f64], _phi: &mut [f64]) {}
    /// `j += Φ_q`, an `n_holonomic × n_dof` view.
    fn phi_q_inplace(&self, _t: f64, _q: &[f64], _j: &mut MatView<'_>) {}
    /// Whether `Φ_q` is constant (ANCF's linear joints): then it is assembled only once.
    fn phi_q_is_constant(&self) -> bool {
        false
    }
    /// `(Φ_q v)_q v`, the quadratic velocity term of the acceleration-level constraint, used for
    /// consistent initial accelerations. Default: zero (linear constraints).
    fn phi_qq_vv_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
    }

    /// Velocity-level constraint residual Ψ = B(q) v + b(q, t) (length `n_velocity_constraints`).
    fn psi_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], _psi: &mut [f64]) {}
    /// `j += B(q)`, an `n_velocity_constraints × n_dof` view.
    fn psi_v_inplace(&self, _t: f64, _q: &[f64], _j: &mut MatView<'_>) {}
    /// `j += ∂(B(q) v + b)/∂q` at fixed `v`.
    fn psi_q_inplace(&self, _t: f64, _q: &[f64], _v: &[f64], _j: &mut MatView<'_>) {}

    /// `k += c_k ∂(Φ_qᵀ λ + Bᵀ μ)/∂q` at fixed multipliers. Default: nothing (constant Jacobians).
    fn constraint_force_tangent_inplace(
        &self,
        _t: f64,
        _q: &[f64],
        _lambda: &[f64],
        _mu: &[f64],
        _c_k: f64,
        _k: &mut MatView<'_>,
    ) {
    }

    /// Called after every accepted step: CRV rescaling (with its rate transformation),
    /// position-level projection, renormalisation. `q`, `v`, `v_dot`, `a` may be changed
    /// consistently. Default: nothing.
    fn post_step(&mut self, _t: f64, _q: &mut [f64], _v: &mut [f64], _v_dot: &mut [f64], _a: &mut [f64]) {}

    /// Optional sparsity of the iteration matrix: diagonal blocks of unknowns that couple only
    /// within a band and to the remaining unknowns (the border; all constraint rows belong to
    /// it). The default dense LU then factorises by Schur complement on the border. Default:
    /// none (dense).
    fn matrix_structure(&self) -> Option<BandedBorder> {
        None
    }

    /// Newton's fallback matrix at rest ([`analysis::StaticSolver`](crate::analysis::StaticSolver)):
    /// `r = r(q, 0, 0, t)` and `k += K̂` with `K̂` an approximation of the tangent `∂r/∂q` that
    /// Newton's iteration converges with, if only linearly (the residual is exact, so the
    /// equilibrium is the same). The static solver starts every solve with the exact tangent and
    /// retries with this matrix, from the same estimate, only where the exact tangent's iteration
    /// fails or stalls, and only when [`has_static_matrix`](Self::has_static_matrix). ANCF leaves
    /// out the geometric terms of its near-rigid strains there, which a transient strain of an
    /// iterate makes dominate the soft motions (docs/ancf.md §9). `zeros` holds `n_dof` zeros
    /// (the velocities and accelerations at rest). Default: the exact tangent,
    /// [`residual_and_iteration_matrix_inplace`](Self::residual_and_iteration_matrix_inplace)
    /// with `c_k = 1`.
    fn residual_and_static_matrix_inplace(&self, t: f64, q: &[f64], zeros: &[f64], r: &mut [f64], k: &mut MatView<'_>) {
        self.residual_and_iteration_matrix_inplace(t, q, zeros, zeros, r, 0.0, 0.0, 1.0, k);
    }

    /// Whether [`residual_and_static_matrix_inplace`](Self::residual_and_static_matrix_inplace)
    /// differs from the exact tangent (then the static solver falls back on it). Default: false.
    fn has_static_matrix(&self) -> bool {
        false
    }

    /// Weight of tangent component `i` in the increment norm: 1 for positions in metres; a
    /// characteristic length for dimensionless coordinates (slopes, rotations). Default 1.
    fn increment_weight(&self, _i: usize) -> f64 {
        1.0
    }

    /// Rotations `R` that carry an iteration matrix made at `q_ref` to the configuration `q`,
    /// `A(q) ≈ R A(q_ref) Rᵀ`, written into `rotations` in the system's own layout; false (the
    /// default) when the system has none. The integrator reserves room for `n_dof` values, so a
    /// layout within that allocates nothing. A formulation in absolute coordinates turns its
    /// stiffness with the body: the matrix of an earlier step, reused for Newton's iteration,
    /// then contracts poorly on a body that turns, while the co-rotated one
    /// (`x = R A(q_ref)⁻¹ Rᵀ r`) contracts as on a body at rest. Only a preconditioner: the
    /// iteration converges to the same solution with or without it.
    fn corotation_inplace(&self, _q_ref: &[f64], _q: &[f64], _rotations: &mut Vec<f64>) -> bool {
        false
    }

    /// `x ← R x`, or `x ← Rᵀ x` if `transpose`, on the Newton unknowns (`n_dof` tangent
    /// components) with rotations from [`corotation_inplace`](Self::corotation_inplace).
    fn corotate_inplace(&self, _rotations: &[f64], _x: &mut [f64], _transpose: bool) {}
}
