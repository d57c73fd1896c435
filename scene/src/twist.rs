//! A body's built-in (pre-)twist: the rotation of the section frame about the beam axis along
//! the body, piecewise linear in the arclength.
//!
//! The section frame at arclength `s` is the body frame turned about its x axis (the beam axis)
//! by θ(s): `frame(s) = frame · R_x(θ(s))`. θ is given as a table of points `(s, θ)`, strictly
//! increasing in `s`, interpolated linearly in between and held constant outside the table.
//! An empty table ([`Twist::none`], the default) is no twist at all: every formulation then
//! takes exactly its untwisted code path.

use nalgebra::Matrix3;

/// Piecewise-linear twist θ(s) of a body's section frame about its beam axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Twist {
    /// The table `(s, θ)`: arclength from the body's start, m, and twist angle, rad
    /// (right-handed about the body's x axis). Strictly increasing in `s`, within
    /// `[0, length]`; empty for no twist.
    points: Vec<(f64, f64)>,
}

impl Twist {
    /// No twist (θ ≡ 0): the default.
    pub fn none() -> Self {
        Self { points: Vec::new() }
    }

    /// A linear twist from `root` at `s = 0` to `tip` at `s = length`, rad. Zero at both ends
    /// gives [`Twist::none`].
    pub fn linear(root: f64, tip: f64, length: f64) -> Self {
        if root == 0.0 && tip == 0.0 { Self::none() } else { Self { points: vec![(0.0, root), (length, tip)] } }
    }

    /// A twist from its table `(s [m], θ [rad])` (checked by `Scene::validate`: finite, `s`
    /// strictly increasing and within the body).
    pub fn table(points: Vec<(f64, f64)>) -> Self {
        Self { points }
    }

    /// The table `(s, θ)`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// Whether the twist is zero everywhere by construction (an empty table).
    pub fn is_none(&self) -> bool {
        self.points.is_empty()
    }

    /// The segment `k` whose interval `[s_k, s_{k+1})` contains `s` (the last one for
    /// `s ≥ s_last`), or `None` when the table has fewer than two points or `s` lies before it.
    fn segment(&self, s: f64) -> Option<usize> {
        let p = &self.points;
        if p.len() < 2 || s < p[0].0 {
            return None;
        }
        // Number of breakpoints at or before s, less one: the segment starting at or before s.
        let k = p.partition_point(|&(sk, _)| sk <= s) - 1;
        Some(k.min(p.len() - 2))
    }

    /// θ(s), rad: linear between the table's points, constant outside the table, zero for an
    /// empty table.
    pub fn angle(&self, s: f64) -> f64 {
        let p = &self.points;
        match p.len() {
            0 => 0.0,
            1 => p[0].1,
            n => {
                if s <= p[0].0 {
                    p[0].1
                } else if s >= p[n - 1].0 {
                    p[n - 1].1
                } else {
                    let k = self.segment(s).expect("s inside the table");
                    let ((s0, t0), (s1, t1)) = (p[k], p[k + 1]);
                    t0 + (t1 - t0) * ((s - s0) / (s1 - s0))
                }
            }
        }
    }

    /// dθ/ds at `s`, rad/m: the slope of the segment containing `s`. At a breakpoint it is the
    /// slope of the segment *starting* there (the right-hand derivative), except at the table's
    /// last point, which takes the last segment's slope (the left-hand one); zero before the
    /// first point, after the last one and for a table of fewer than two points.
    pub fn rate(&self, s: f64) -> f64 {
        let p = &self.points;
        match self.segment(s) {
            Some(k) if s <= p[p.len() - 1].0 => {
                let ((s0, t0), (s1, t1)) = (p[k], p[k + 1]);
                (t1 - t0) / (s1 - s0)
            }
            _ => 0.0,
        }
    }

    /// `R_x(θ(s))`: the section frame at `s` relative to the body frame.
    pub fn rotation(&self, s: f64) -> Matrix3<f64> {
        rotation_x(self.angle(s))
    }

    /// Quadrature points `(s, weight)` over `[0, length]`: 5-point Gauss–Legendre on
    /// sub-intervals of each linear piece of θ(s) (split at [`breakpoints`](Self::breakpoints))
    /// turning by at most 0.1 rad. It integrates a polynomial of degree ≤ 9 in `s` times `cos`,
    /// `sin` of `θ` or `2θ` to rounding (the rule's error on `e^{2iθ}` over a piece turning by
    /// 0.1 rad is below `0.2¹⁰/10! ≈ 3e-14` of the piece's share, in fact far smaller).
    pub fn quadrature(&self, length: f64) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for w in self.breakpoints(length).windows(2) {
            let (a, b) = (w[0], w[1]);
            let turn = (self.angle(b) - self.angle(a)).abs();
            let n_sub = ((turn / 0.1).ceil() as usize).max(1);
            let h = (b - a) / n_sub as f64;
            for k in 0..n_sub {
                let (lo, hi) = (a + k as f64 * h, if k + 1 == n_sub { b } else { a + (k + 1) as f64 * h });
                let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                out.extend(GAUSS5.iter().map(|&(x, wx)| (mid + half * x, wx * half)));
            }
        }
        out
    }

    /// The arclengths in `[0, length]` where θ(s) may change slope: 0, the table's points inside
    /// the body, and `length`, ascending.
    pub fn breakpoints(&self, length: f64) -> Vec<f64> {
        let mut b = vec![0.0];
        b.extend(self.points.iter().map(|&(s, _)| s).filter(|&s| s > 0.0 && s < length));
        b.push(length);
        b
    }
}

/// 5-point Gauss–Legendre rule on [−1, 1]: (abscissa, weight).
const GAUSS5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// The rotation by `theta` (rad) about the x axis.
pub fn rotation_x(theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn none_is_zero_everywhere() {
        let t = Twist::none();
        assert!(t.is_none());
        for s in [-1.0, 0.0, 0.3, 2.0] {
            assert_eq!(t.angle(s), 0.0);
            assert_eq!(t.rate(s), 0.0);
        }
        assert!(Twist::linear(0.0, 0.0, 1.0).is_none());
    }

    #[test]
    fn a_table_interpolates_linearly_and_extrapolates_constantly() {
        let t = Twist::table(vec![(0.2, 0.0), (0.6, 0.4), (1.0, 0.0)]);
        assert_eq!(t.angle(0.0), 0.0);
        assert_relative_eq!(t.angle(0.4), 0.2, max_relative = 1e-15);
        assert_relative_eq!(t.angle(0.8), 0.2, max_relative = 1e-15);
        assert_eq!(t.angle(1.5), 0.0);
        assert_eq!(t.rate(0.1), 0.0);
        assert_relative_eq!(t.rate(0.4), 1.0, max_relative = 1e-15);
        // at a breakpoint: the segment starting there
        assert_relative_eq!(t.rate(0.2), 1.0, max_relative = 1e-15);
        assert_relative_eq!(t.rate(0.6), -1.0, max_relative = 1e-15);
        // the last point: the last segment's slope
        assert_relative_eq!(t.rate(1.0), -1.0, max_relative = 1e-15);
        assert_eq!(t.rate(1.0 + 1e-9), 0.0);
        assert_eq!(t.breakpoints(1.0), vec![0.0, 0.2, 0.6, 1.0]);
    }

    #[test]
    fn linear_twist_and_its_rotation() {
        let t = Twist::linear(0.1, 0.5, 2.0);
        assert_relative_eq!(t.angle(1.0), 0.3, max_relative = 1e-15);
        assert_relative_eq!(t.rate(1.7), 0.2, max_relative = 1e-15);
        let r = t.rotation(1.0);
        assert_relative_eq!(r * nalgebra::Vector3::y(), nalgebra::Vector3::new(0.0, 0.3f64.cos(), 0.3f64.sin()));
    }
}
