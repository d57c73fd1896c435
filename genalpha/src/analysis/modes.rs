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
//! **Precision.** A dense eigensolver makes absolute errors of order `ε ‖K̃‖ = ε ω_max²`, so a low
//! frequency carries a relative error up to about `ε (ω_max/ω)² / 2`: 2e-6 for the first bending
//! mode of a GEBF cantilever (ω_max/ω₁ ≈ 1.3e5), 5e-6 for ANCF, whose cross-section penalty modes
//! reach ω_max ≈ 1e6–4e6 rad/s (measured differences are 10–30 times smaller). The damped
//! (first-order) form is no better than that bound. Shift-and-invert about the low end of the
//! spectrum would remove it, at the cost of a regular shifted matrix.

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
    /// Undamped natural modes of the reduced, symmetrised problem `Nᵀ K N φ = ω² Nᵀ M N φ`
    /// (`C` is ignored; an unsymmetric `K` is replaced by its symmetric part, see
    /// [`is_stiffness_symmetric`](Self::is_stiffness_symmetric) and
    /// [`damped_modes`](Self::damped_modes) for the exact eigenvalues then).
    ///
    /// # Errors
    /// [`Error::MassNotPositiveDefinite`]; [`Error::DecompositionNotConverged`].
    pub fn natural_modes(&self) -> Result<NaturalModes, Error> {
        let nf = self.n_free();
        let l = self.mass_factor()?;
        let a = symmetrised(&congruence(&l, &symmetrised(&self.reduced_stiffness)));
        let eig = a
            .try_symmetric_eigen(f64::EPSILON, max_eigen_iter(nf))
            .ok_or(Error::DecompositionNotConverged { n: nf })?;
        let mut order: Vec<usize> = (0..nf).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        let omega_squared: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i]).collect();
        let omega = omega_squared.iter().map(|w2| w2.signum() * w2.abs().sqrt()).collect();
        let mut shapes = DMatrix::zeros(self.n_dof(), nf);
        for (c, &i) in order.iter().enumerate() {
            let y = l.tr_solve_lower_triangular(&eig.eigenvectors.column(i)).expect("a Cholesky factor is regular");
            let mut phi = &self.null_space * y;
            if phi.iter().copied().fold(0.0_f64, |m, x| if x.abs() > m.abs() { x } else { m }) < 0.0 {
                phi.neg_mut();
            }
            shapes.set_column(c, &phi);
        }
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
