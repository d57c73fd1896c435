//! Monotone piecewise-cubic Hermite interpolation (Fritsch & Carlson 1980; the node slopes of
//! Fritsch & Butland 1984, as `PCHIP` in MATLAB and SciPy).
//!
//! On each interval `[x_i, x_{i+1}]` of width `h_i` with secant `δ_i = (y_{i+1} − y_i)/h_i` the
//! interpolant is the cubic Hermite polynomial through `(x_i, y_i, d_i)` and
//! `(x_{i+1}, y_{i+1}, d_{i+1})`. The node slopes are
//!
//! $$ d_i = \begin{cases} 0 & \delta_{i-1}\,\delta_i \le 0, \\
//!    \dfrac{w_1 + w_2}{w_1/\delta_{i-1} + w_2/\delta_i},\quad w_1 = 2h_i + h_{i-1},\ w_2 = h_i + 2h_{i-1}
//!    & \text{otherwise,} \end{cases} $$
//!
//! and at the two ends the shape-preserving three-point formula. The result is C¹, never
//! overshoots the data (a stall peak stays where the table puts it), and reproduces data that lie
//! on a straight line exactly (every `d_i = δ`), which a linear polar needs to return the
//! lattice's loads unchanged.

/// One monotone cubic interpolant over strictly increasing knots.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MonotoneCubic {
    /// Node slopes `d_i`, one per knot.
    slopes: Vec<f64>,
}

impl MonotoneCubic {
    /// Slopes for values `y` at knots `x` (strictly increasing, at least two).
    ///
    /// # Panics
    /// If the lengths differ or there are fewer than two knots (the readers check both).
    pub(crate) fn new(x: &[f64], y: &[f64]) -> Self {
        let n = x.len();
        assert!(n >= 2 && y.len() == n, "MonotoneCubic: need ≥ 2 knots and one value per knot");
        let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
        let delta: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        if n == 2 {
            return Self { slopes: vec![delta[0]; 2] };
        }
        let mut slopes = vec![0.0; n];
        for i in 1..n - 1 {
            let (d0, d1) = (delta[i - 1], delta[i]);
            if d0 * d1 > 0.0 {
                let w1 = 2.0 * h[i] + h[i - 1];
                let w2 = h[i] + 2.0 * h[i - 1];
                slopes[i] = (w1 + w2) / (w1 / d0 + w2 / d1);
            }
        }
        slopes[0] = end_slope(h[0], h[1], delta[0], delta[1]);
        slopes[n - 1] = end_slope(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
        Self { slopes }
    }

    /// Value and slope `dy/dx` at `t`, which must lie in `[x_0, x_{n−1}]` (the caller clamps).
    pub(crate) fn eval(&self, x: &[f64], y: &[f64], t: f64) -> (f64, f64) {
        let i = interval(x, t);
        let h = x[i + 1] - x[i];
        let s = (t - x[i]) / h;
        let (y0, y1) = (y[i], y[i + 1]);
        let (d0, d1) = (self.slopes[i], self.slopes[i + 1]);
        let s2 = s * s;
        let s3 = s2 * s;
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        let value = h00 * y0 + h10 * h * d0 + h01 * y1 + h11 * h * d1;
        // d/dt of the basis, divided by h for d/dx.
        let g00 = (6.0 * s2 - 6.0 * s) / h;
        let g10 = 3.0 * s2 - 4.0 * s + 1.0;
        let g01 = (-6.0 * s2 + 6.0 * s) / h;
        let g11 = 3.0 * s2 - 2.0 * s;
        let slope = g00 * y0 + g10 * d0 + g01 * y1 + g11 * d1;
        (value, slope)
    }
}

/// The shape-preserving end slope from the first two intervals (`h0`, `d0` at the end).
fn end_slope(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    let d = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if d * d0 <= 0.0 {
        0.0
    } else if d0 * d1 <= 0.0 && d.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        d
    }
}

/// Index `i` of the interval `[x_i, x_{i+1}]` holding `t` (the last one for `t = x_{n−1}`).
fn interval(x: &[f64], t: f64) -> usize {
    let k = x.partition_point(|&v| v <= t);
    k.clamp(1, x.len() - 1) - 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn reproduces_a_straight_line_exactly() {
        let x = [-0.3, -0.1, 0.0, 0.05, 0.2, 0.35];
        let y: Vec<f64> = x.iter().map(|a| 2.0 * std::f64::consts::PI * a + 0.1).collect();
        let p = MonotoneCubic::new(&x, &y);
        for k in 0..=70 {
            let t = -0.3 + 0.65 * k as f64 / 70.0;
            let (v, d) = p.eval(&x, &y, t);
            assert_relative_eq!(v, 2.0 * std::f64::consts::PI * t + 0.1, epsilon = 1e-14);
            assert_relative_eq!(d, 2.0 * std::f64::consts::PI, epsilon = 1e-13);
        }
    }

    #[test]
    fn passes_through_the_knots_and_keeps_a_peak_flat() {
        // A stall-like table: the interpolant must not rise above the peak value 1.2.
        let x = [0.0, 0.1, 0.2, 0.25, 0.3, 0.4];
        let y = [0.0, 0.6, 1.1, 1.2, 0.9, 0.8];
        let p = MonotoneCubic::new(&x, &y);
        for (xi, yi) in x.iter().zip(&y) {
            assert_relative_eq!(p.eval(&x, &y, *xi).0, *yi, epsilon = 1e-15);
        }
        for k in 0..=400 {
            let (v, _) = p.eval(&x, &y, 0.4 * k as f64 / 400.0);
            assert!(v <= 1.2 + 1e-15, "overshoot {v}");
        }
        assert_eq!(p.eval(&x, &y, 0.25).1, 0.0, "a local extremum gets a zero slope");
    }

    proptest! {
        /// The slope returned is the derivative of the value (central differences, O(h²)).
        #[test]
        fn slope_is_the_derivative(ys in proptest::collection::vec(-2.0f64..2.0, 5), t in 0.01f64..0.99) {
            let x = [0.0, 0.2, 0.45, 0.7, 1.0];
            let p = MonotoneCubic::new(&x, &ys);
            let h = 1e-6;
            let fd = (p.eval(&x, &ys, t + h).0 - p.eval(&x, &ys, t - h).0) / (2.0 * h);
            let (_, d) = p.eval(&x, &ys, t);
            prop_assert!((fd - d).abs() <= 1e-6 * (1.0 + d.abs()), "fd {fd} vs {d}");
        }

        /// Monotone data give a monotone interpolant.
        #[test]
        fn monotone_data_stay_monotone(steps in proptest::collection::vec(0.0f64..1.0, 6)) {
            let x = [0.0, 0.1, 0.3, 0.35, 0.6, 0.8, 1.0];
            let mut y = vec![0.0];
            for s in &steps { y.push(y.last().unwrap() + s); }
            let p = MonotoneCubic::new(&x, &y);
            let mut last = f64::NEG_INFINITY;
            for k in 0..=500 {
                let v = p.eval(&x, &y, k as f64 / 500.0).0;
                prop_assert!(v >= last - 1e-12);
                last = v;
            }
        }
    }
}
