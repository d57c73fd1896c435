//! Modes of a [`Linearisation`]: undamped natural modes, and the complex eigenvalues of the damped
//! (or non-conservative) first-order form.
//!
//! With the reduced matrices `M_r = Nᵀ M N` (symmetrised, positive definite), `C_r`, `K_r` and
//! the Cholesky factor `M_r = L Lᵀ`, the substitution `y = L⁻ᵀ z` gives
//!
//! $$ \ddot z + \tilde C \dot z + \tilde K z = 0,\qquad \tilde C = L^{-1} C_r L^{-T},\quad
//!    \tilde K = L^{-1} K_r L^{-T} .$$
//!
//! Undamped modes: the symmetric eigenproblem of `K̃` (from `K_r` symmetrised), `ω² = eig K̃`,
//! shapes `N L⁻ᵀ e` (mass-orthonormal). Damped modes: the eigenvalues `s` of
//!
//! $$ A = \begin{bmatrix} 0 & w I \\ -\tilde K / w & -\tilde C \end{bmatrix}
//!    \quad\text{on}\quad x = (z, \dot z / w),$$
//!
//! where the scale `w = √max|K̃|` balances the two blocks (without it the entries span ω_max², and
//! the low eigenvalues of a stiff model lose digits in the Schur iteration), from nalgebra's real
//! Schur form; a shape by inverse iteration on `P(s) = s² M_r + s C_r + K_r` next to `s`.
//! Dense O(n³) eigen-solvers are adequate at our sizes (n_free < 500).
//!
//! **Precision.** A dense eigensolver makes absolute errors of order `ε ‖K̃‖ = ε ω_max²`, so in
//! the direct form a low frequency carries a relative error up to about `ε (ω_max/ω)² / 2`: on
//! ANCF, whose cross-section penalty modes reach ω_max ≈ 1e6–1e7 rad/s, a free hinge's fold mode
//! (ω ≈ 0.2 rad/s, spring 1e-4 N·m/rad) is lost in round-off and may come out negative.
//! [`natural_modes`](Linearisation::natural_modes) therefore solves by shift-and-invert about
//! `σ = −τ`, `τ = SHIFT_RATIO · ‖K̃‖_F`: the eigenvalues `μ = 1/(ω² + τ)` of
//! `Lᵀ (K_r + τ M_r)⁻¹ L` are found to `ε max|μ|`, which gives the low modes relative accuracy;
//! the modes above the point where the direct form's bound is the smaller get their `ω²` by a
//! Rayleigh–Ritz step in the subspace the inverse form's vectors span for them, so that the
//! shapes stay one mass-orthonormal basis. The damped (first-order) form still has the direct
//! form's bound.

use super::{Linearisation, symmetrised};
use crate::Error;
use nalgebra::{Cholesky, Complex, DMatrix, DVector, Schur};

/// Iteration cap of the dense eigen-solvers (sweeps, far above what they need).
fn max_eigen_iter(n: usize) -> usize {
    10_000 + 100 * n
}

/// Undamped natural modes, ascending in `ω²`.
#[derive(Debug, Clone, PartialEq)]
pub struct NaturalModes {
    /// Eigenvalues `ω²`, rad²/s², ascending; negative for a statically unstable motion.
    pub omega_squared: Vec<f64>,
    /// Circular frequencies `sign(ω²) √|ω²|`, rad/s.
    pub omega: Vec<f64>,
    /// Mode shapes in the tangent space (n_dof × n_free): columns mass-orthonormal,
    /// `φ_iᵀ M φ_j = δ_ij`, each with its largest-magnitude entry positive.
    pub shapes: DMatrix<f64>,
}

/// One eigenvalue of the damped linear system (motions `e^{s t}`).
#[derive(Debug, Clone, PartialEq)]
pub struct DampedMode {
    /// `s`, 1/s; for an underdamped mode `−ζω ± iω√(1 − ζ²)` (the `+` one is listed).
    pub eigenvalue: Complex<f64>,
    /// The shape in the tangent space (length n_dof), scaled so that its largest-magnitude entry
    /// is 1; `None` unless requested.
    pub shape: Option<DVector<Complex<f64>>>,
}

impl DampedMode {
    /// Undamped-equivalent circular frequency `ω = |s|`, rad/s.
    pub fn frequency(&self) -> f64 {
        self.eigenvalue.norm()
    }
    /// Damped circular frequency `Im s`, rad/s.
    pub fn damped_frequency(&self) -> f64 {
        self.eigenvalue.im
    }
    /// Damping ratio `ζ = −Re s / |s|` (negative: the motion grows, e.g. flutter); 0 for `s = 0`.
    pub fn damping_ratio(&self) -> f64 {
        let w = self.frequency();
        if w > 0.0 { -self.eigenvalue.re / w } else { 0.0 }
    }
}

impl Linearisation {
    /// Undamped natural modes of the reduced, symmetrised problem `Nᵀ K N φ = ω² Nᵀ M N φ`, the
    /// low ones by shift-and-invert and the high ones by a Rayleigh–Ritz step in their subspace
    /// (module documentation, **Precision**)
    /// (`C` is ignored; an unsymmetric `K` is replaced by its symmetric part, see
    /// [`is_stiffness_symmetric`](Self::is_stiffness_symmetric) and
    /// [`damped_modes`](Self::damped_modes) for the exact eigenvalues then).
    ///
    /// # Errors
    /// [`Error::MassNotPositiveDefinite`]; [`Error::DecompositionNotConverged`].
    pub fn natural_modes(&self) -> Result<NaturalModes, Error> {
        let nf = self.n_free();
        let l = self.mass_factor()?;
        let k_r = symmetrised(&self.reduced_stiffness);
        let k_tilde = symmetrised(&congruence(&l, &k_r));
        // The largest |ω²| is at most the Frobenius norm, and at least that over √n: a scale for
        // the shift and the error estimates, without a second eigen-solve.
        let scale = k_tilde.norm();
        let pairs = match shift_invert(&l, &k_r, scale)? {
            Some(inverse) => split_and_refine(&k_tilde, inverse, scale)?,
            None => symmetric_eigen(k_tilde)?,
        };
        let mut omega_squared = Vec::with_capacity(nf);
        let mut shapes = DMatrix::zeros(self.n_dof(), nf);
        for (c, (w2, e)) in pairs.into_iter().enumerate() {
            let y = l.tr_solve_lower_triangular(&e).expect("a Cholesky factor is regular");
            let mut phi = &self.null_space * y;
            if phi.iter().copied().fold(0.0_f64, |m, x| if x.abs() > m.abs() { x } else { m }) < 0.0 {
                phi.neg_mut();
            }
            shapes.set_column(c, &phi);
            omega_squared.push(w2);
        }
        let omega = omega_squared.iter().map(|w2| w2.signum() * w2.abs().sqrt()).collect();
        Ok(NaturalModes { omega_squared, omega, shapes })
    }

    /// Eigenvalues of the damped reduced system `M_r ÿ + C_r ẏ + K_r y = 0` (no symmetry
    /// assumed), one per complex-conjugate pair (`Im s > 0`) and every real one (so a rigid-body
    /// motion shows up as two zeros), sorted by `|s|`; with the shapes of the first `n_shapes`.
    ///
    /// # Errors
    /// [`Error::MassNotPositiveDefinite`]; [`Error::DecompositionNotConverged`] (also when inverse
    /// iteration for a shape meets an exactly singular matrix).
    pub fn damped_modes(&self, n_shapes: usize) -> Result<Vec<DampedMode>, Error> {
        let nf = self.n_free();
        let l = self.mass_factor()?;
        let k = congruence(&l, &self.reduced_stiffness);
        let c = congruence(&l, &self.reduced_damping);
        let w = k.amax().sqrt().max(c.amax());
        let w = if w.is_finite() && w > 0.0 { w } else { 1.0 };
        let mut a = DMatrix::zeros(2 * nf, 2 * nf);
        for i in 0..nf {
            a[(i, nf + i)] = w;
        }
        a.view_mut((nf, 0), (nf, nf)).copy_from(&(k / -w));
        a.view_mut((nf, nf), (nf, nf)).copy_from(&(-c));
        let schur = Schur::try_new(a, f64::EPSILON, max_eigen_iter(2 * nf))
            .ok_or(Error::DecompositionNotConverged { n: 2 * nf })?;
        let mut eigenvalues: Vec<Complex<f64>> =
            quasi_triangular_eigenvalues(&schur.unpack().1).into_iter().filter(|s| s.im >= 0.0).collect();
        if !eigenvalues.iter().all(|s| s.re.is_finite() && s.im.is_finite()) {
            return Err(Error::DecompositionNotConverged { n: 2 * nf });
        }
        eigenvalues.sort_by(|x, y| x.norm().total_cmp(&y.norm()).then(x.im.total_cmp(&y.im)));
        let m_r = symmetrised(&self.reduced_mass);
        eigenvalues
            .into_iter()
            .enumerate()
            .map(|(i, s)| {
                let shape = if i < n_shapes {
                    let y = pencil_null_vector(&m_r, &self.reduced_damping, &self.reduced_stiffness, s, w)
                        .ok_or(Error::DecompositionNotConverged { n: nf })?;
                    Some(self.expand_complex(&y))
                } else {
                    None
                };
                Ok(DampedMode { eigenvalue: s, shape })
            })
            .collect()
    }

    /// Cholesky factor `L` of the symmetrised reduced mass matrix.
    fn mass_factor(&self) -> Result<DMatrix<f64>, Error> {
        let nf = self.n_free();
        if nf == 0 {
            return Ok(DMatrix::zeros(0, 0));
        }
        Cholesky::new(symmetrised(&self.reduced_mass))
            .map(|c| c.l())
            .ok_or(Error::MassNotPositiveDefinite { n_free: nf })
    }

    /// `N y` for a complex reduced vector, scaled so that its largest-magnitude entry is 1.
    fn expand_complex(&self, y: &DVector<Complex<f64>>) -> DVector<Complex<f64>> {
        let re = &self.null_space * y.map(|x| x.re);
        let im = &self.null_space * y.map(|x| x.im);
        let v = DVector::from_fn(re.len(), |i, _| Complex::new(re[i], im[i]));
        let big = v.iter().copied().fold(Complex::new(0.0, 0.0), |m, x| if x.norm() > m.norm() { x } else { m });
        if big.norm() > 0.0 { v / big } else { v }
    }
}

/// Eigenpairs `(λ, e)`: an eigenvalue and its unit vector.
type Pairs = Vec<(f64, DVector<f64>)>;

/// Eigenpairs `(λ, e)` of a symmetric matrix, ascending in `λ`.
fn symmetric_eigen(a: DMatrix<f64>) -> Result<Pairs, Error> {
    let n = a.nrows();
    let eig = a.try_symmetric_eigen(f64::EPSILON, max_eigen_iter(n)).ok_or(Error::DecompositionNotConverged { n })?;
    let mut pairs: Pairs = (0..n).map(|i| (eig.eigenvalues[i], eig.eigenvectors.column(i).into_owned())).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(pairs)
}

/// The shift `−τ` of the inverse iteration, relative to the largest `|ω²|`: far enough from
/// zero that `K_r + τ M_r` is regular with a free mechanism (`ω² = 0`), close enough that the
/// low modes keep their digits (their `ω²` come with errors of about `ε τ`).
pub const SHIFT_RATIO: f64 = 1e-8;

/// Eigenpairs `(ω², e)` of the pencil `(K_r, M_r = L Lᵀ)` by shift-and-invert about `σ = −τ`,
/// `τ = SHIFT_RATIO · scale`: the symmetric matrix `B = Lᵀ (K_r + τ M_r)⁻¹ L` has the
/// eigenvalues `μ = 1/(ω² + τ)` and the same vectors `e` as `L⁻¹ K_r L⁻ᵀ`. A dense eigensolver
/// gets `μ` to `ε max|μ|`, so the modes nearest zero come with relative accuracy (the direct form
/// has absolute errors `ε max|ω²|`); ascending in `ω²`. `None` (no refinement) when the shifted
/// matrix is singular to working precision.
fn shift_invert(l: &DMatrix<f64>, k_r: &DMatrix<f64>, scale: f64) -> Result<Option<Pairs>, Error> {
    let n = k_r.nrows();
    if n == 0 || !(scale.is_finite() && scale > 0.0) {
        return Ok(None);
    }
    let tau = SHIFT_RATIO * scale;
    let a = k_r + l * l.transpose() * tau;
    let Some(x) = a.lu().solve(l) else { return Ok(None) }; // A⁻¹ L
    if !x.iter().all(|v| v.is_finite()) {
        return Ok(None);
    }
    let b = symmetrised(&(l.transpose() * x));
    let mut pairs: Vec<(f64, DVector<f64>)> =
        symmetric_eigen(b)?.into_iter().filter(|(mu, _)| *mu != 0.0).map(|(mu, e)| (1.0 / mu - tau, e)).collect();
    if pairs.len() != n {
        return Ok(None);
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(Some(pairs))
}

/// One mass-orthonormal basis from the shift-and-invert pairs (ascending in `ω²`): the low modes
/// keep the inverse form's `ω²`, whose errors are about `ε (ω² + τ)² / (ω²_min + τ)`, as long as
/// that is below the direct form's `ε · scale`; the vectors of the rest span the high subspace
/// (orthogonal to the low modes to working precision, however the inverse form resolves them
/// among themselves), and a Rayleigh–Ritz step in that subspace, the eigenpairs of `Eₕᵀ K̃ Eₕ`,
/// gives their `ω²` to the direct form's accuracy. Taking whole modes from two separate solves
/// instead can break a near-degenerate pair at the switch into two copies of one direction.
fn split_and_refine(k_tilde: &DMatrix<f64>, inverse: Pairs, scale: f64) -> Result<Pairs, Error> {
    let tau = SHIFT_RATIO * scale;
    let low = inverse.first().map_or(0.0, |p| p.0) + tau;
    let p = inverse.iter().take_while(|(w2, _)| (w2 + tau).powi(2) < scale * low).count();
    let mut pairs = inverse;
    let high = pairs.split_off(p);
    if !high.is_empty() {
        let e_h = DMatrix::from_columns(&high.iter().map(|(_, e)| e.clone()).collect::<Vec<_>>());
        let h = symmetrised(&(e_h.transpose() * k_tilde * &e_h));
        pairs.extend(symmetric_eigen(h)?.into_iter().map(|(w2, v)| (w2, &e_h * v)));
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(pairs)
}

/// `L⁻¹ A L⁻ᵀ` for a lower-triangular regular `L` (any square `A`).
fn congruence(l: &DMatrix<f64>, a: &DMatrix<f64>) -> DMatrix<f64> {
    let x = l.solve_lower_triangular(a).expect("a Cholesky factor is regular"); // L⁻¹ A
    l.solve_lower_triangular(&x.transpose()).expect("a Cholesky factor is regular").transpose() // (L⁻¹ (L⁻¹A)ᵀ)ᵀ
}

/// Eigenvalues of a real quasi-upper-triangular (Schur) matrix: its 1×1 and 2×2 diagonal blocks.
/// (nalgebra's own `complex_eigenvalues` assumes every remaining 2×2 block has complex roots.)
fn quasi_triangular_eigenvalues(t: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let n = t.nrows();
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        if i + 1 < n && t[(i + 1, i)] != 0.0 {
            let (a, b, c, d) = (t[(i, i)], t[(i, i + 1)], t[(i + 1, i)], t[(i + 1, i + 1)]);
            let (mean, half) = (0.5 * (a + d), 0.5 * (a - d));
            let disc = half * half + b * c;
            if disc < 0.0 {
                let im = (-disc).sqrt();
                out.extend([Complex::new(mean, im), Complex::new(mean, -im)]);
            } else {
                let r = disc.sqrt();
                out.extend([Complex::new(mean + r, 0.0), Complex::new(mean - r, 0.0)]);
            }
            i += 2;
        } else {
            out.push(Complex::new(t[(i, i)], 0.0));
            i += 1;
        }
    }
    out
}

/// A null vector of `P(s) = s² M + s C + K` by inverse iteration, `x ← P(σ)⁻¹ P'(σ) x`, with the
/// shift `σ` a relative 1e-9 off `s` (the converged eigenvalue makes `P(s)` singular to rounding;
/// `w` is the frequency scale, for `s ≈ 0`). Three sweeps: each divides the error by about
/// `|σ − s|` over the distance to the next eigenvalue.
fn pencil_null_vector(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    s: Complex<f64>,
    w: f64,
) -> Option<DVector<Complex<f64>>> {
    let n = m.nrows();
    let cplx = |a: &DMatrix<f64>| a.map(|x| Complex::new(x, 0.0));
    let (m, c, k) = (cplx(m), cplx(c), cplx(k));
    let delta = 1e-9 * s.norm().max(1e-6 * w);
    let sigma = s + Complex::new(delta, delta);
    let p = &m * (sigma * sigma) + &c * sigma + &k;
    let dp = &m * (sigma * 2.0) + &c;
    let lu = p.lu();
    // a fixed start with components in every direction
    let mut x = DVector::from_fn(n, |i, _| Complex::new(1.0 + (0.618_034 * i as f64).fract(), 0.5));
    for _ in 0..3 {
        x = lu.solve(&(&dp * &x))?;
        let norm = x.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        x /= Complex::new(norm, 0.0);
    }
    Some(x)
}
