//! The constant consistent element mass matrix (docs/ancf.md §2).
//!
//! $$ M_e = \int_0^l \big[m\,S_c^T S_c + D_{yy} S_y^T S_y + D_{zz} S_z^T S_z\big]\,dx
//!        = \bar m \otimes I_3 $$
//!
//! with the classical Hermite block `m l/420 [156 22l 54 −13l; …]` on (r¹, r¹_x, r², r²_x) and
//! `D l/6 [2 1; 1 2]` on the section slopes. `D_yy`, `D_zz` come from
//! [`Section::slope_inertias`](crate::Section::slope_inertias).

use crate::shape::{N_BLOCKS, point_weights};

/// The 8×8 scalar factor `m̄` of the element mass matrix `m̄ ⊗ I₃`, kg (blocks as in
/// [`shape`](crate::shape)).
pub fn element_mass(mass: f64, d_yy: f64, d_zz: f64, l: f64) -> [[f64; N_BLOCKS]; N_BLOCKS] {
    let mut m = [[0.0; N_BLOCKS]; N_BLOCKS];
    let c = mass * l / 420.0;
    let hermite = [
        [156.0, 22.0 * l, 54.0, -13.0 * l],
        [22.0 * l, 4.0 * l * l, 13.0 * l, -3.0 * l * l],
        [54.0, 13.0 * l, 156.0, -22.0 * l],
        [-13.0 * l, -3.0 * l * l, -22.0 * l, 4.0 * l * l],
    ];
    let cb = [0, 1, 4, 5];
    for i in 0..4 {
        for j in 0..4 {
            m[cb[i]][cb[j]] = c * hermite[i][j];
        }
    }
    for (d, (b1, b2)) in [(d_yy, (2, 6)), (d_zz, (3, 7))] {
        let s = d * l / 6.0;
        m[b1][b1] = 2.0 * s;
        m[b2][b2] = 2.0 * s;
        m[b1][b2] = s;
        m[b2][b1] = s;
    }
    m
}

/// The terms a centre-of-mass offset `cg = [y_c, z_c]` (section frame, m) adds to the scalar
/// factor of [`element_mass`], kg (docs/ancf.md §12.1). The section's centre of mass moves with
/// `r_cg = S(x, y_c, z_c) e = (w_c + w_o)ᵀ e`, so its kinetic energy adds
///
/// $$ \int_0^l m\,\big(w_c w_o^T + w_o w_c^T + w_o w_o^T\big)\,dx,\qquad
///    w_o = y_c\,N_y + z_c\,N_z $$
///
/// (`N_y`, `N_z` the linear weights of `r_y`, `r_z`): the first-moment cross terms between the
/// centreline and the slopes, and `m y_c²`, `m z_c²`, `m y_c z_c` on the slopes. Integrated by
/// 3-point Gauss quadrature, exact for these polynomials (degree ≤ 4 in ξ).
pub fn cg_offset_mass(mass: f64, cg: [f64; 2], l: f64) -> [[f64; N_BLOCKS]; N_BLOCKS] {
    let mut m = [[0.0; N_BLOCKS]; N_BLOCKS];
    let d = 0.5 * (0.6_f64).sqrt();
    for (xi, w) in [(0.5 - d, 5.0 / 18.0), (0.5, 8.0 / 18.0), (0.5 + d, 5.0 / 18.0)] {
        let wc = point_weights(xi, l, 0.0, 0.0);
        let mut wo = [0.0; N_BLOCKS];
        for (blocks, c) in [((2, 6), cg[0]), ((3, 7), cg[1])] {
            wo[blocks.0] = c * (1.0 - xi);
            wo[blocks.1] = c * xi;
        }
        let f = mass * w * l;
        for a in 0..N_BLOCKS {
            for b in 0..N_BLOCKS {
                m[a][b] += f * (wc[a] * wo[b] + wo[a] * wc[b] + wo[a] * wo[b]);
            }
        }
    }
    m
}

/// The non-zero entries `(row block, column block, value)` of [`element_mass`].
pub fn nonzeros(m: &[[f64; N_BLOCKS]; N_BLOCKS]) -> Vec<(usize, usize, f64)> {
    let mut nz = Vec::new();
    for (a, row) in m.iter().enumerate() {
        for (b, &x) in row.iter().enumerate() {
            if x != 0.0 {
                nz.push((a, b, x));
            }
        }
    }
    nz
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::point_weights;
    use approx::assert_relative_eq;

    /// ∫ ρ S(x,y,z)ᵀ S(x,y,z) dV by 4-point Gauss in x and a rectangular section sampled at
    /// its corners-free 2×2 Gauss points (exact for the polynomial degrees involved).
    fn quadrature_mass(mass: f64, width: f64, height: f64, l: f64) -> [[f64; 8]; 8] {
        let gx = [
            (0.5 - 0.430_568_155_797_026_3, 0.173_927_422_568_726_9),
            (0.5 - 0.169_990_521_792_428_1, 0.326_072_577_431_273_1),
            (0.5 + 0.169_990_521_792_428_1, 0.326_072_577_431_273_1),
            (0.5 + 0.430_568_155_797_026_3, 0.173_927_422_568_726_9),
        ];
        let g2 = [-0.5 / 3f64.sqrt(), 0.5 / 3f64.sqrt()];
        let mut m = [[0.0; 8]; 8];
        for (xi, wx) in gx {
            for y in g2 {
                for z in g2 {
                    let w = point_weights(xi, l, y * width, z * height);
                    let weight = mass * wx * l * 0.25;
                    for a in 0..8 {
                        for b in 0..8 {
                            m[a][b] += weight * w[a] * w[b];
                        }
                    }
                }
            }
        }
        m
    }

    #[test]
    fn matches_quadrature_of_the_shape_functions() {
        let (mass, w, h, l) = (2.7, 0.3, 0.1, 0.4);
        // rectangle: D_yy = ∫ρy² = m w²/12 (on r_y), D_zz = m h²/12.
        let m = element_mass(mass, mass * w * w / 12.0, mass * h * h / 12.0, l);
        let q = quadrature_mass(mass, w, h, l);
        for a in 0..8 {
            for b in 0..8 {
                assert_relative_eq!(m[a][b], q[a][b], epsilon = 1e-14, max_relative = 1e-12);
            }
        }
    }

    /// A rectangle whose centre sits at (y_c, z_c): the closed form plus the offset terms equal
    /// quadrature of `ρ SᵀS` over the shifted rectangle (the slope inertias about the centre).
    #[test]
    fn offset_section_matches_quadrature_of_the_shifted_rectangle() {
        let (mass, w, h, l, yc, zc) = (2.7, 0.3, 0.1, 0.4, 0.07, -0.04);
        let mut m = element_mass(mass, mass * w * w / 12.0, mass * h * h / 12.0, l);
        let extra = cg_offset_mass(mass, [yc, zc], l);
        let gx = [
            (0.5 - 0.430_568_155_797_026_3, 0.173_927_422_568_726_9),
            (0.5 - 0.169_990_521_792_428_1, 0.326_072_577_431_273_1),
            (0.5 + 0.169_990_521_792_428_1, 0.326_072_577_431_273_1),
            (0.5 + 0.430_568_155_797_026_3, 0.173_927_422_568_726_9),
        ];
        let g2 = [-0.5 / 3f64.sqrt(), 0.5 / 3f64.sqrt()];
        let mut q = [[0.0; 8]; 8];
        for (xi, wx) in gx {
            for y in g2 {
                for z in g2 {
                    let p = point_weights(xi, l, yc + y * w, zc + z * h);
                    for a in 0..8 {
                        for b in 0..8 {
                            q[a][b] += mass * wx * l * 0.25 * p[a] * p[b];
                        }
                    }
                }
            }
        }
        for a in 0..8 {
            for b in 0..8 {
                m[a][b] += extra[a][b];
                assert_relative_eq!(m[a][b], q[a][b], epsilon = 1e-14, max_relative = 1e-12);
            }
        }
    }

    #[test]
    fn rigid_translation_carries_the_total_mass() {
        let (mass, l) = (1.3, 0.6);
        let m = element_mass(mass, 1e-3, 2e-3, l);
        // unit translation: r blocks = 1, slopes 0.
        let u = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let total: f64 = (0..8).flat_map(|a| (0..8).map(move |b| (a, b))).map(|(a, b)| u[a] * m[a][b] * u[b]).sum();
        assert_relative_eq!(total, mass * l, epsilon = 1e-14);
    }
}
