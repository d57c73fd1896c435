//! Shape functions of the two-node element (docs/ancf.md §1) and the interpolated fields.
//!
//! Element coordinates are eight nodal 3-vectors ("blocks"), in this order:
//! `[r¹, r¹_x, r¹_y, r¹_z, r², r²_x, r²_y, r²_z]` (24 numbers). With ξ = x/l the position of the
//! material point (x, y, z) is
//!
//! $$ r(x,y,z) = h_1 r^1 + h_2 r^1_x + h_3 r^2 + h_4 r^2_x
//!      + y\,[(1-\xi) r^1_y + \xi r^2_y] + z\,[(1-\xi) r^1_z + \xi r^2_z] $$
//!
//! with the cubic Hermite functions `h1 = 1−3ξ²+2ξ³`, `h2 = l(ξ−2ξ²+ξ³)`, `h3 = 3ξ²−2ξ³`,
//! `h4 = l(ξ³−ξ²)`.

/// Number of nodal 3-vectors per element.
pub const N_BLOCKS: usize = 8;
/// Coordinates per node.
pub const NODE_DOF: usize = 12;
/// Coordinates per element.
pub const ELEMENT_DOF: usize = 24;

/// A field along the beam axis that the strains are built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// Axis tangent r_x = ∂r/∂x at y = z = 0.
    X = 0,
    /// Axis second derivative r_xx.
    XX = 1,
    /// Section slope r_y.
    Y = 2,
    /// Section slope r_z.
    Z = 3,
    /// Derivative r_y,x.
    YX = 4,
    /// Derivative r_z,x.
    ZX = 5,
}

/// Number of [`Field`]s.
pub const N_FIELDS: usize = 6;

/// All fields in index order.
pub const FIELDS: [Field; N_FIELDS] = [Field::X, Field::XX, Field::Y, Field::Z, Field::YX, Field::ZX];

/// Sparse interpolation of one field: `f = Σ weight · e[block]` over at most four blocks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldWeights {
    /// Number of used entries.
    pub n: usize,
    /// Block indices.
    pub block: [usize; 4],
    /// Weights (units 1/m, 1/m² or 1 as the field requires).
    pub weight: [f64; 4],
}

impl FieldWeights {
    /// Weights from `(block, weight)` pairs (at most four); zero weights are dropped.
    pub fn new(entries: &[(usize, f64)]) -> Self {
        let mut w = Self { n: 0, block: [0; 4], weight: [0.0; 4] };
        for &(b, x) in entries.iter().filter(|e| e.1 != 0.0) {
            w.block[w.n] = b;
            w.weight[w.n] = x;
            w.n += 1;
        }
        w
    }

    /// Dense weights over the eight blocks.
    pub fn dense(&self) -> [f64; N_BLOCKS] {
        let mut d = [0.0; N_BLOCKS];
        for k in 0..self.n {
            d[self.block[k]] += self.weight[k];
        }
        d
    }

    /// Evaluate the field from the element coordinates `e` (24 numbers).
    #[inline]
    pub fn eval(&self, e: &[f64]) -> [f64; 3] {
        let mut f = [0.0; 3];
        for k in 0..self.n {
            let b = 3 * self.block[k];
            let w = self.weight[k];
            f[0] += w * e[b];
            f[1] += w * e[b + 1];
            f[2] += w * e[b + 2];
        }
        f
    }
}

/// Hermite functions (h1, h2, h3, h4) at ξ for element length `l`.
pub fn hermite(xi: f64, l: f64) -> [f64; 4] {
    let (x2, x3) = (xi * xi, xi * xi * xi);
    [1.0 - 3.0 * x2 + 2.0 * x3, l * (xi - 2.0 * x2 + x3), 3.0 * x2 - 2.0 * x3, l * (x3 - x2)]
}

/// First x-derivatives of the Hermite functions.
pub fn hermite_dx(xi: f64, l: f64) -> [f64; 4] {
    let x2 = xi * xi;
    [(-6.0 * xi + 6.0 * x2) / l, 1.0 - 4.0 * xi + 3.0 * x2, (6.0 * xi - 6.0 * x2) / l, 3.0 * x2 - 2.0 * xi]
}

/// Second x-derivatives of the Hermite functions.
pub fn hermite_dxx(xi: f64, l: f64) -> [f64; 4] {
    [(-6.0 + 12.0 * xi) / (l * l), (-4.0 + 6.0 * xi) / l, (6.0 - 12.0 * xi) / (l * l), (6.0 * xi - 2.0) / l]
}

/// Interpolation weights of every [`Field`] at ξ, indexed by `Field as usize`.
pub fn field_weights(xi: f64, l: f64) -> [FieldWeights; N_FIELDS] {
    let c = [0, 1, 4, 5]; // centreline blocks r¹, r¹_x, r², r²_x
    let h1 = hermite_dx(xi, l);
    let h2 = hermite_dxx(xi, l);
    let centre = |h: [f64; 4]| FieldWeights::new(&[(c[0], h[0]), (c[1], h[1]), (c[2], h[2]), (c[3], h[3])]);
    [
        centre(h1),
        centre(h2),
        FieldWeights::new(&[(2, 1.0 - xi), (6, xi)]),
        FieldWeights::new(&[(3, 1.0 - xi), (7, xi)]),
        FieldWeights::new(&[(2, -1.0 / l), (6, 1.0 / l)]),
        FieldWeights::new(&[(3, -1.0 / l), (7, 1.0 / l)]),
    ]
}

/// Weights of the material point (ξ, y, z) on the eight blocks: `r = Σ w_b e_b` (the 3×24
/// matrix `S(x, y, z)` is `w ⊗ I₃`).
pub fn point_weights(xi: f64, l: f64, y: f64, z: f64) -> [f64; N_BLOCKS] {
    let h = hermite(xi, l);
    [h[0], h[1], y * (1.0 - xi), z * (1.0 - xi), h[2], h[3], y * xi, z * xi]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn hermite_interpolates_nodal_values_and_slopes() {
        let l = 0.7;
        let h0 = hermite(0.0, l);
        let h1 = hermite(1.0, l);
        assert_relative_eq!(h0[0], 1.0, epsilon = 1e-15);
        assert_relative_eq!(h1[2], 1.0, epsilon = 1e-15);
        let d0 = hermite_dx(0.0, l);
        let d1 = hermite_dx(1.0, l);
        assert_relative_eq!(d0[1], 1.0, epsilon = 1e-15);
        assert_relative_eq!(d1[3], 1.0, epsilon = 1e-15);
        for k in [0, 2, 3] {
            assert_relative_eq!(d0[k], 0.0, epsilon = 1e-15);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let (l, h) = (0.3, 1e-6);
        for xi in [0.1, 0.5, 0.77] {
            let (p, m) = (hermite(xi + h, l), hermite(xi - h, l));
            let (dp, dm) = (hermite_dx(xi + h, l), hermite_dx(xi - h, l));
            let d = hermite_dx(xi, l);
            let dd = hermite_dxx(xi, l);
            for k in 0..4 {
                assert_relative_eq!(d[k], (p[k] - m[k]) / (2.0 * h * l), epsilon = 1e-8);
                assert_relative_eq!(dd[k], (dp[k] - dm[k]) / (2.0 * h * l), epsilon = 1e-6);
            }
        }
    }

    #[test]
    fn straight_reference_fields() {
        // e0 of an element from (1,2,3) along x with unit section slopes.
        let l = 0.25;
        let mut e = [0.0; 24];
        let nodes = [[1.0, 2.0, 3.0], [1.0 + l, 2.0, 3.0]];
        for (n, r) in nodes.iter().enumerate() {
            e[12 * n..12 * n + 3].copy_from_slice(r);
            e[12 * n + 3] = 1.0;
            e[12 * n + 7] = 1.0;
            e[12 * n + 11] = 1.0;
        }
        let w = field_weights(0.3, l);
        assert_relative_eq!(w[Field::X as usize].eval(&e)[0], 1.0, epsilon = 1e-14);
        assert_relative_eq!(w[Field::XX as usize].eval(&e)[0], 0.0, epsilon = 1e-12);
        assert_relative_eq!(w[Field::Y as usize].eval(&e)[1], 1.0, epsilon = 1e-14);
        assert_relative_eq!(w[Field::ZX as usize].eval(&e)[2], 0.0, epsilon = 1e-14);
        let p = point_weights(0.3, l, 0.1, -0.2);
        let mut r = [0.0; 3];
        for b in 0..8 {
            for i in 0..3 {
                r[i] += p[b] * e[3 * b + i];
            }
        }
        assert_relative_eq!(r[0], 1.0 + 0.3 * l, epsilon = 1e-14);
        assert_relative_eq!(r[1], 2.1, epsilon = 1e-14);
        assert_relative_eq!(r[2], 2.8, epsilon = 1e-14);
    }
}
