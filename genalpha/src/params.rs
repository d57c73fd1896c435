//! Integrator parameters (deserialised straight from case files).

use crate::Error;

/// Newton iteration settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonParams {
    /// Maximum Newton iterations per step (default 20).
    pub max_iter: usize,
    /// Relative tolerance on the increment, against the step's motion `h·|Δq|` (default 1e-8).
    pub rtol: f64,
    /// Absolute tolerance on the increment, in the model's coordinate units (default 1e-10).
    pub atol: f64,
    /// Absolute tolerance on the holonomic constraints Φ, coordinate units (default 1e-10).
    pub phi_tol: f64,
    /// Absolute tolerance on the velocity constraints B v + b, velocity units (default 1e-8).
    pub psi_tol: f64,
    /// Reuse the factorisation across iterations and steps while Newton contracts fast
    /// (modified Newton). Default true. An update made with a factorisation from an earlier
    /// iterate of the step that increased the increment is taken back and the matrix factorised
    /// at the iterate before it (one Newton iteration is counted for the step back).
    pub reuse_factorization: bool,
    /// Contraction rate above which a reused factorisation is refreshed (default 0.2).
    pub max_contraction: f64,
    /// When Newton fails on a step (divergence, non-finite values, singular matrix), the step
    /// is retried as two half steps, recursively, at most this many times deep (default 4:
    /// down to dt/16). 0 turns the retry off. A successful run without failures is unaffected;
    /// the halvings are counted in [`Stats::n_step_halvings`](crate::Stats).
    pub max_step_halvings: usize,
    /// Also accept an iterate when the contraction estimate `θ/(1 − θ)·|Δ_k|` (θ the ratio of
    /// the last two increment norms of the current Newton sequence, θ < 0.5) is below the
    /// tolerance, as RADAU5 does (Hairer & Wanner, *Solving ODEs II*, §IV.8): a contracting
    /// iteration's remaining error is at most that, so the last, confirming solve is saved.
    /// Default true: 0.9–1.0 fewer solves per step on the paper pendulums, trajectories within
    /// 4e-6 of the tip excursion of the confirmed iterate.
    pub estimate_convergence: bool,
    /// Correct the steps made with a reused factorisation by Broyden's rank-one updates
    /// (superlinear instead of linear contraction; no extra factorisation or solve). Default
    /// true; only active with `reuse_factorization`.
    pub broyden: bool,
    /// Co-rotate a factorisation reused from an earlier step by the rotations the system gives
    /// ([`ConstrainedSystem::corotation_inplace`](crate::ConstrainedSystem::corotation_inplace)):
    /// ANCF's absolute coordinates turn their stiff section stiffness with the body, so an
    /// earlier step's matrix diverges on a turning pendulum (spectral radius 0.4–12 on the
    /// paper's c = 1, β = 45° case) but contracts at 0.005–0.16 once co-rotated. Default true;
    /// only active with `reuse_factorization`, and a no-op for systems without rotations.
    pub corotate: bool,
    /// Local error control: a converged step whose error estimate
    /// `h²|β − 1/6|·max_i w_i |a_{n+1,i} − a_{n,i}|` (coordinate units, `w` the increment
    /// weights; in the Chung–Hulbert form with the change of `v̇_α` instead of `a`) exceeds this is redone as two half steps, within `max_step_halvings`; counted
    /// like a Newton-failure halving. Default 0: off (every step has the nominal size unless
    /// Newton fails).
    pub local_error_tol: f64,
    /// How each step's Newton iteration starts (default [`Predictor::ConstantAcceleration`]).
    pub predictor: Predictor,
}

/// The predictor: the first Newton iterate of a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Predictor {
    /// `v̇_{n+1} = v̇_n` (in the Chung–Hulbert form `v̇_α` of the last step), with `v_{n+1}`,
    /// `q_{n+1}` and `a_{n+1}` from the Newmark relations.
    #[default]
    ConstantAcceleration,
    /// `v̇_{n+1} = 2 v̇_n − v̇_{n−1}` (in the Chung–Hulbert form, of `v̇_α`): the acceleration
    /// extrapolated linearly from the last two steps (when the last step had the same size and ended where this one starts; otherwise
    /// as [`ConstantAcceleration`](Self::ConstantAcceleration)). One order more accurate in h,
    /// which pays where the residual is strongly nonlinear in the velocities: GEBF's gyroscopic
    /// terms of fast-spinning floating frames. (A model whose `post_step` changes how the rates
    /// are represented, as GEBF's rescaling of rotation vectors past π does, makes the next
    /// prediction poorer for those unknowns, not wrong: Newton corrects it.)
    ExtrapolatedAcceleration,
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            max_iter: 20,
            rtol: 1e-8,
            atol: 1e-10,
            phi_tol: 1e-10,
            psi_tol: 1e-8,
            reuse_factorization: true,
            max_contraction: 0.2,
            max_step_halvings: 4,
            estimate_convergence: true,
            broyden: true,
            corotate: true,
            local_error_tol: 0.0,
            predictor: Predictor::ConstantAcceleration,
        }
    }
}

/// Where the equations of motion are enforced in each step. Both forms share the Newmark
/// relations, the parameters derived from `rho_inf`, the constraints (enforced at `t_{n+1}`)
/// and the Newton iteration; they differ in the state the forces are evaluated at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Form {
    /// Arnold & Brüls (2007): `M(q_{n+1}) v̇_{n+1} + g(q_{n+1}, v_{n+1}) + constraint forces = 0`
    /// at the end of the step, with the pseudo-acceleration recursion
    /// `(1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) v̇_{n+1} + α_f v̇_n`. Second order also for the
    /// multipliers and the index-3 constraints. At `rho_inf = 1` it is the trapezoidal rule.
    #[default]
    ArnoldBruls,
    /// Chung & Hulbert (1993): the same equations at the weighted state
    /// `q_α = q_n ∘ exp((1 − α_f) h Δq_n)`, `v_α = (1 − α_f) v_{n+1} + α_f v_n`,
    /// `v̇_α = (1 − α_m) a_{n+1} + α_m a_n`, `t_α = t_n + (1 − α_f) h`, the constraint forces
    /// with the Jacobians at `q_α` (the multipliers are the step's weighted ones). At
    /// `rho_inf = 1` (`α_m = α_f = ½`) it is the implicit midpoint rule, which conserves the
    /// quadratic invariants: the gyroscopic and Coriolis forces of a frame (`ω × p`) do no
    /// discrete work, where the trapezoidal rule's do at O(h²). The state's `v_dot` holds `v̇_α`.
    /// At `rho_inf = 1`, `a` alternates about the acceleration (the scheme's undamped spurious
    /// root, −α_m/(1 − α_m) = −1); `q` and `v` see it only through `(a_n + a_{n+1})/2 = v̇_α`.
    /// The midpoint evaluation of stiff nonlinear elastic forces can gain energy at large steps
    /// (measured on ANCF's β = 45° pendulum: 7.9e-3 of the peak kinetic energy at dt 0.002,
    /// 4.9e-4 at 0.001), the midpoint rule's known weakness in nonlinear elastodynamics.
    ChungHulbert,
}

/// Generalized-α parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegratorParams {
    /// Spectral radius at infinite frequency, in [0, 1] (1 = no numerical damping).
    pub rho_inf: f64,
    /// Time step, s.
    pub dt: f64,
    /// Where the equations of motion are enforced (default [`Form::ArnoldBruls`]).
    pub form: Form,
    /// Newton settings.
    pub newton: NewtonParams,
}

impl IntegratorParams {
    /// Parameters in the Arnold–Brüls form with default Newton settings.
    pub fn new(rho_inf: f64, dt: f64) -> Self {
        Self { rho_inf, dt, form: Form::ArnoldBruls, newton: NewtonParams::default() }
    }

    /// Check ranges; returns an error naming the field.
    pub fn validate(&self) -> Result<(), Error> {
        if !(0.0..=1.0).contains(&self.rho_inf) {
            return Err(Error::InvalidParameter {
                field: "rho_inf",
                reason: format!("{} is not in [0, 1]", self.rho_inf),
            });
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::InvalidParameter {
                field: "dt",
                reason: format!("{} is not a positive number", self.dt),
            });
        }
        let n = &self.newton;
        if n.max_iter == 0 {
            return Err(Error::InvalidParameter { field: "newton.max_iter", reason: "must be at least 1".into() });
        }
        for (field, v) in [
            ("newton.rtol", n.rtol),
            ("newton.atol", n.atol),
            ("newton.phi_tol", n.phi_tol),
            ("newton.psi_tol", n.psi_tol),
            ("newton.max_contraction", n.max_contraction),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidParameter { field, reason: format!("{v} is not a positive number") });
            }
        }
        if !(n.local_error_tol.is_finite() && n.local_error_tol >= 0.0) {
            return Err(Error::InvalidParameter {
                field: "newton.local_error_tol",
                reason: format!("{} is not a non-negative number", n.local_error_tol),
            });
        }
        Ok(())
    }

    /// The derived Chung–Hulbert coefficients.
    pub fn coefficients(&self) -> Coefficients {
        Coefficients::new(self.rho_inf, self.dt)
    }
}

/// Chung–Hulbert coefficients and the Newton factors derived from them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// α_m.
    pub alpha_m: f64,
    /// α_f.
    pub alpha_f: f64,
    /// γ.
    pub gamma: f64,
    /// β.
    pub beta: f64,
    /// Time step h, s.
    pub h: f64,
    /// β′ = (1 − α_m) / (β h² (1 − α_f)): ∂v̇/∂q.
    pub beta_prime: f64,
    /// γ′ = γ / (β h): ∂v/∂q.
    pub gamma_prime: f64,
}

impl Coefficients {
    /// Coefficients for spectral radius `rho_inf` and step `h`.
    pub fn new(rho_inf: f64, h: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        let beta = 0.25 * (gamma + 0.5).powi(2);
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta,
            h,
            beta_prime: (1.0 - alpha_m) / (beta * h * h * (1.0 - alpha_f)),
            gamma_prime: gamma / (beta * h),
        }
    }
}
