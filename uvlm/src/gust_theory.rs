//! Thin-aerofoil gust theory to verify the UVLM against (docs/gust.md §5): Theodorsen's
//! function, Sears' function and the **exact** Küssner function, the latter by a numerical
//! inverse Fourier transform of Sears' function (not only its exponential fits).
//!
//! Reduced frequency `k = ω b / U` (b the semichord), distance travelled `s = U t / b` in
//! semichords. Lift per unit span of a flat plate in a sinusoidal gust whose velocity at the
//! **mid-chord** is `w₀ e^{iωt}`: `L = 2π ρ U b w₀ S(k) e^{iωt}`, with
//!
//! $$ S(k) = \big(J_0(k) - i J_1(k)\big) C(k) + i J_1(k), \qquad
//!    C(k) = \frac{H^{(2)}_1(k)}{H^{(2)}_1(k) + i H^{(2)}_0(k)}. $$
//!
//! Referred to the gust at the **leading edge**, `S_LE(k) = S(k) e^{−ik}`. The lift after a
//! sharp-edged gust whose front reaches the leading edge at `s = 0` is `2π ρ U b w₀ ψ(s)`, and ψ is
//! the step response of the causal system `S_LE`:
//!
//! $$ \psi(s) = \frac{2}{\pi} \int_0^\infty \mathrm{Re}\,S_{LE}(k) \frac{\sin k s}{k}\, dk. $$

use nalgebra::Complex;

/// Bessel function J₀(x) (rational approximations of Numerical Recipes §6.5, absolute error
/// below 1e-8).
pub fn bessel_j0(x: f64) -> f64 {
    let ax = x.abs();
    if ax < 8.0 {
        let y = x * x;
        let a = 57568490574.0
            + y * (-13362590354.0 + y * (651619640.7 + y * (-11214424.18 + y * (77392.33017 + y * (-184.9052456)))));
        let b = 57568490411.0 + y * (1029532985.0 + y * (9494680.718 + y * (59272.64853 + y * (267.8532712 + y))));
        a / b
    } else {
        let z = 8.0 / ax;
        let y = z * z;
        let xx = ax - 0.785398164;
        let a = 1.0 + y * (-0.1098628627e-2 + y * (0.2734510407e-4 + y * (-0.2073370639e-5 + y * 0.2093887211e-6)));
        let b = -0.1562499995e-1
            + y * (0.1430488765e-3 + y * (-0.6911147651e-5 + y * (0.7621095161e-6 - y * 0.934935152e-7)));
        (std::f64::consts::FRAC_2_PI / ax).sqrt() * (xx.cos() * a - z * xx.sin() * b)
    }
}

/// Bessel function J₁(x) (Numerical Recipes §6.5).
pub fn bessel_j1(x: f64) -> f64 {
    let ax = x.abs();
    if ax < 8.0 {
        let y = x * x;
        let a = x
            * (72362614232.0
                + y * (-7895059235.0
                    + y * (242396853.1 + y * (-2972611.439 + y * (15704.48260 + y * (-30.16036606))))));
        let b = 144725228442.0 + y * (2300535178.0 + y * (18583304.74 + y * (99447.43394 + y * (376.9991397 + y))));
        a / b
    } else {
        let z = 8.0 / ax;
        let y = z * z;
        let xx = ax - 2.356194491;
        let a = 1.0 + y * (0.183105e-2 + y * (-0.3516396496e-4 + y * (0.2457520174e-5 + y * (-0.240337019e-6))));
        let b =
            0.04687499995 + y * (-0.2002690873e-3 + y * (0.8449199096e-5 + y * (-0.88228987e-6 + y * 0.105787412e-6)));
        let r = (std::f64::consts::FRAC_2_PI / ax).sqrt() * (xx.cos() * a - z * xx.sin() * b);
        if x < 0.0 { -r } else { r }
    }
}

/// Bessel function Y₀(x), x > 0 (Numerical Recipes §6.5).
pub fn bessel_y0(x: f64) -> f64 {
    if x < 8.0 {
        let y = x * x;
        let a = -2957821389.0
            + y * (7062834065.0 + y * (-512359803.6 + y * (10879881.29 + y * (-86327.92757 + y * 228.4622733))));
        let b = 40076544269.0 + y * (745249964.8 + y * (7189466.438 + y * (47447.26470 + y * (226.1030244 + y))));
        a / b + std::f64::consts::FRAC_2_PI * bessel_j0(x) * x.ln()
    } else {
        let z = 8.0 / x;
        let y = z * z;
        let xx = x - 0.785398164;
        let a = 1.0 + y * (-0.1098628627e-2 + y * (0.2734510407e-4 + y * (-0.2073370639e-5 + y * 0.2093887211e-6)));
        let b = -0.1562499995e-1
            + y * (0.1430488765e-3 + y * (-0.6911147651e-5 + y * (0.7621095161e-6 + y * (-0.934945152e-7))));
        (std::f64::consts::FRAC_2_PI / x).sqrt() * (xx.sin() * a + z * xx.cos() * b)
    }
}

/// Bessel function Y₁(x), x > 0 (Numerical Recipes §6.5).
pub fn bessel_y1(x: f64) -> f64 {
    if x < 8.0 {
        let y = x * x;
        let a = x
            * (-0.4900604943e13
                + y * (0.1275274390e13
                    + y * (-0.5153438139e11 + y * (0.7349264551e9 + y * (-0.4237922726e7 + y * 0.8511937935e4)))));
        let b = 0.2499580570e14
            + y * (0.4244419664e12
                + y * (0.3733650367e10 + y * (0.2245904002e8 + y * (0.1020426050e6 + y * (0.3549632885e3 + y)))));
        a / b + std::f64::consts::FRAC_2_PI * (bessel_j1(x) * x.ln() - 1.0 / x)
    } else {
        let z = 8.0 / x;
        let y = z * z;
        let xx = x - 2.356194491;
        let a = 1.0 + y * (0.183105e-2 + y * (-0.3516396496e-4 + y * (0.2457520174e-5 + y * (-0.240337019e-6))));
        let b =
            0.04687499995 + y * (-0.2002690873e-3 + y * (0.8449199096e-5 + y * (-0.88228987e-6 + y * 0.105787412e-6)));
        (std::f64::consts::FRAC_2_PI / x).sqrt() * (xx.sin() * a + z * xx.cos() * b)
    }
}

/// Theodorsen's function C(k), k > 0 (C(0) = 1).
pub fn theodorsen(k: f64) -> Complex<f64> {
    if k <= 0.0 {
        return Complex::new(1.0, 0.0);
    }
    let h0 = Complex::new(bessel_j0(k), -bessel_y0(k));
    let h1 = Complex::new(bessel_j1(k), -bessel_y1(k));
    h1 / (h1 + Complex::<f64>::i() * h0)
}

/// Sears' function S(k), gust referred to the mid-chord (S(0) = 1).
pub fn sears(k: f64) -> Complex<f64> {
    if k <= 0.0 {
        return Complex::new(1.0, 0.0);
    }
    let (j0, j1) = (bessel_j0(k), bessel_j1(k));
    Complex::new(j0, -j1) * theodorsen(k) + Complex::new(0.0, j1)
}

/// Sears' function referred to the gust at the leading edge, `S(k) e^{−ik}`.
pub fn sears_leading_edge(k: f64) -> Complex<f64> {
    sears(k) * Complex::new(k.cos(), -k.sin())
}

/// The exact Küssner function ψ(s), tabulated once: Re S_LE on a grid of reduced frequencies,
/// integrated against `sin(ks)/k` by Simpson's rule on `[0, k_max]`.
#[derive(Debug, Clone)]
pub struct Kussner {
    dk: f64,
    re: Vec<f64>,
}

impl Kussner {
    /// The table with step `dk` up to `k_max` (the integrand decays like `k^{-3/2}`; `dk = 0.004`,
    /// `k_max = 400` resolve ψ to about 1e-4 for `s ≤ 40`).
    ///
    /// # Panics
    /// If `dk` or `k_max` is not positive and finite.
    pub fn new(dk: f64, k_max: f64) -> Self {
        assert!(dk > 0.0 && k_max > dk && k_max.is_finite(), "Kussner::new: dk {dk}, k_max {k_max}");
        let mut n = (k_max / dk).ceil() as usize;
        n += n % 2; // Simpson: an even number of intervals
        let re = (0..=n).map(|i| sears_leading_edge(i as f64 * dk).re).collect();
        Self { dk, re }
    }

    /// ψ(s): lift after a sharp-edged gust over its final value, s semichords after the front
    /// reached the leading edge (0 for s ≤ 0).
    pub fn psi(&self, s: f64) -> f64 {
        if s <= 0.0 {
            return 0.0;
        }
        let n = self.re.len() - 1;
        let mut sum = 0.0;
        for (i, &r) in self.re.iter().enumerate() {
            let k = i as f64 * self.dk;
            let kern = if i == 0 { s } else { (k * s).sin() / k };
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            sum += w * r * kern;
        }
        2.0 / std::f64::consts::PI * sum * self.dk / 3.0
    }
}

impl Default for Kussner {
    fn default() -> Self {
        Self::new(0.004, 400.0)
    }
}

/// Jones's three-exponential fit of Küssner's function,
/// `1 − 0.236 e^{−0.058 s} − 0.513 e^{−0.364 s} − 0.171 e^{−2.42 s}` (for comparison only).
pub fn kussner_jones(s: f64) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    1.0 - 0.236 * (-0.058 * s).exp() - 0.513 * (-0.364 * s).exp() - 0.171 * (-2.42 * s).exp()
}

/// The two-exponential fit of Küssner's function (Sears & Sparks),
/// `1 − ½ e^{−0.13 s} − ½ e^{−s}` (for comparison only).
pub fn kussner_two_exponential(s: f64) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    1.0 - 0.5 * (-0.13 * s).exp() - 0.5 * (-s).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn bessel_values() {
        // Abramowitz & Stegun, Table 9.1.
        assert_relative_eq!(bessel_j0(1.0), 0.7651976866, epsilon = 1e-8);
        assert_relative_eq!(bessel_j1(1.0), 0.4400505857, epsilon = 1e-8);
        assert_relative_eq!(bessel_y0(1.0), 0.0882569642, epsilon = 1e-8);
        assert_relative_eq!(bessel_y1(1.0), -0.7812128213, epsilon = 1e-8);
        assert_relative_eq!(bessel_j0(10.0), -0.2459357645, epsilon = 1e-8);
        assert_relative_eq!(bessel_j1(10.0), 0.0434727462, epsilon = 1e-8);
        assert_relative_eq!(bessel_y0(10.0), 0.0556711673, epsilon = 1e-8);
        assert_relative_eq!(bessel_y1(10.0), 0.2490154242, epsilon = 1e-8);
    }

    /// Theodorsen's F and G at k = 0.1 and 0.5 (Bisplinghoff, Ashley & Halfman, Table 5-1).
    #[test]
    fn theodorsen_values() {
        let c = theodorsen(0.1);
        assert_relative_eq!(c.re, 0.8319, epsilon = 2e-4);
        assert_relative_eq!(c.im, -0.1723, epsilon = 2e-4);
        let c = theodorsen(0.5);
        assert_relative_eq!(c.re, 0.5979, epsilon = 2e-4);
        assert_relative_eq!(c.im, -0.1507, epsilon = 2e-4);
    }

    /// The exact ψ starts at 0, tends to 1, and Jones's fit (good to about 1 % from one
    /// semichord on; the exact ψ rises like √s at first, which no sum of exponentials follows)
    /// follows it.
    #[test]
    fn exact_kussner() {
        let k = Kussner::default();
        assert_eq!(k.psi(0.0), 0.0);
        for s in [0.25, 0.5, 1.0, 2.0, 4.0, 10.0, 20.0] {
            println!(
                "psi({s}) = {:.4} exact, {:.4} Jones, {:.4} two-exponential",
                k.psi(s),
                kussner_jones(s),
                kussner_two_exponential(s)
            );
        }
        for s in [1.0, 2.0, 5.0, 10.0, 20.0, 40.0] {
            let (e, j) = (k.psi(s), kussner_jones(s));
            assert!((e - j).abs() < 0.012, "s = {s}: exact {e}, Jones {j}");
        }
        assert!(k.psi(200.0) > 0.985 && k.psi(200.0) < 1.0);
        // Monotone rise.
        let mut last = 0.0;
        for i in 1..200 {
            let p = k.psi(0.1 * i as f64);
            assert!(p > last, "ψ not rising at s = {}", 0.1 * i as f64);
            last = p;
        }
    }

    /// |S| and its phase at a few reduced frequencies (k → 0: 1; |S| ≈ 1/√(2πk) for large k).
    #[test]
    fn sears_limits() {
        assert_relative_eq!(sears(1e-6).norm(), 1.0, epsilon = 1e-4);
        let s = sears(20.0);
        assert_relative_eq!(s.norm(), 1.0 / (2.0 * std::f64::consts::PI * 20.0).sqrt(), max_relative = 0.02);
    }
}
