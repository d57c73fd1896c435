//! Section ties at the hinge nodes (docs/ancf.md §3.5). A hinge's equations act on single nodal
//! slopes; in a geometrically exact beam its axis is fixed in the section. At every node a hinge
//! acts on, the model holds the nodal triad `(r_x, r_y, r_z)` orthonormal with the energy of its
//! metric strains,
//!
//! $$ U_t = \tfrac12 \sum_s k_s s^2,\qquad s \in \{\tfrac12(|r_a|^2 - 1),\ r_a\cdot r_b\}, $$
//!
//! `k_s = c_t EI_s / l` with the EI (or GJ) of the rotation each strain resists, zero for the
//! strains with `r_x` where the hinge's rows do not involve `r_x`. The joint's moment then
//! reaches the section through a stiffness that grows as the mesh is refined; without it, only
//! through the node's shear and penalty terms, whose stiffness (`GA l`, `EA l`) vanishes with the
//! element length.

use nalgebra::SMatrix;

/// 9×9 matrix over the node's `(r_x, r_y, r_z)`.
pub(crate) type TieMatrix = SMatrix<f64, 9, 9>;

/// The six metric strains of the nodal triad `(r_x, r_y, r_z)`: `(a, b)` block pairs.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// One tied node.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NodeTie {
    /// Full index of the node's `r_x` (its `r_y`, `r_z` follow).
    pub first: usize,
    /// Stiffness on the metric strains `½(|r_x|²−1), ½(|r_y|²−1), ½(|r_z|²−1), r_x·r_y,
    /// r_x·r_z, r_y·r_z` (N·m).
    pub k: [f64; 6],
}

#[inline]
fn block(q: &[f64], first: usize, a: usize) -> [f64; 3] {
    let i = first + 3 * a;
    [q[i], q[i + 1], q[i + 2]]
}

#[inline]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl NodeTie {
    /// The triad and its six metric strains.
    #[inline]
    fn strains(&self, q: &[f64]) -> ([[f64; 3]; 3], [f64; 6]) {
        let x = [block(q, self.first, 0), block(q, self.first, 1), block(q, self.first, 2)];
        let s = PAIRS.map(|(a, b)| if a == b { 0.5 * (dot(&x[a], &x[a]) - 1.0) } else { dot(&x[a], &x[b]) });
        (x, s)
    }

    /// Energy, J.
    pub(crate) fn energy(&self, q: &[f64]) -> f64 {
        let (_, s) = self.strains(q);
        s.iter().zip(&self.k).map(|(s, k)| 0.5 * k * s * s).sum()
    }

    /// `r += ∂U/∂q`.
    pub(crate) fn add_force(&self, q: &[f64], r: &mut [f64]) {
        let (x, s) = self.strains(q);
        for (((a, b), s), k) in PAIRS.iter().zip(&s).zip(&self.k) {
            let f = k * s;
            for i in 0..3 {
                if a == b {
                    r[self.first + 3 * a + i] += f * x[*a][i];
                } else {
                    r[self.first + 3 * a + i] += f * x[*b][i];
                    r[self.first + 3 * b + i] += f * x[*a][i];
                }
            }
        }
    }

    /// `c · ∂²U/∂q²` on the node's nine slope coordinates (symmetric). With `newton` (Newton's
    /// iteration matrix of a time step, `c > 0`) only the positive semidefinite part is kept:
    /// the geometric term `c k_s s ∂²s` of a compressed stretch (`s = ½(|r_a|² − 1) < 0`,
    /// negative definite on that slope) and of every angle `r_a·r_b` (indefinite) is left out.
    /// At the tie's stiffness such terms can outweigh the light slopes' inertia and make the
    /// iteration matrix near-singular (docs/ancf.md §3.5). The residual is unchanged.
    pub(crate) fn tangent(&self, q: &[f64], c: f64, newton: bool) -> TieMatrix {
        let (x, s) = self.strains(q);
        let mut t = TieMatrix::zeros();
        for (((a, b), s), k) in PAIRS.iter().zip(&s).zip(&self.k) {
            let (a, b) = (*a, *b);
            // gradient of the strain over the nine coordinates
            let mut g = [0.0; 9];
            for i in 0..3 {
                if a == b {
                    g[3 * a + i] = x[a][i];
                } else {
                    g[3 * a + i] = x[b][i];
                    g[3 * b + i] = x[a][i];
                }
            }
            let ck = c * k;
            for j in 0..9 {
                for i in 0..=j {
                    t[(i, j)] += ck * g[i] * g[j];
                }
            }
            let h = if newton && (a != b || *s < 0.0) { 0.0 } else { c * k * s };
            for i in 0..3 {
                if a == b {
                    t[(3 * a + i, 3 * a + i)] += h;
                } else {
                    t[(3 * a + i, 3 * b + i)] += h; // a < b: upper triangle
                }
            }
        }
        for j in 0..9 {
            for i in j + 1..9 {
                t[(i, j)] = t[(j, i)];
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    fn tie() -> NodeTie {
        NodeTie { first: 2, k: [3.0, 1.5, 2.0, 0.7, 1.1, 0.4] }
    }

    /// A perturbed triad at indices 2..11 of a 12-vector.
    fn state(seed: f64) -> Vec<f64> {
        let mut q: Vec<f64> = (0..12).map(|i| 0.1 * ((i as f64 * 1.7 + seed).sin())).collect();
        for a in 0..3 {
            q[2 + 3 * a + a] += 1.0;
        }
        q
    }

    /// The force is the gradient of the energy and the tangent the derivative of the force
    /// (central differences, relative 1e-7), and the tangent is symmetric.
    #[test]
    fn force_and_tangent_match_finite_differences() {
        let t = tie();
        for seed in [0.3, 1.1, 2.9] {
            let q = state(seed);
            let mut f = vec![0.0; 12];
            t.add_force(&q, &mut f);
            let k = t.tangent(&q, 1.0, false);
            let h = 1e-6;
            let fmax = f.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            for j in 0..9 {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[2 + j] += h;
                qm[2 + j] -= h;
                let du = (t.energy(&qp) - t.energy(&qm)) / (2.0 * h);
                assert!((du - f[2 + j]).abs() < 1e-7 * fmax, "force {j}: {du} vs {}", f[2 + j]);
                let (mut fp, mut fm) = (vec![0.0; 12], vec![0.0; 12]);
                t.add_force(&qp, &mut fp);
                t.add_force(&qm, &mut fm);
                for i in 0..9 {
                    let d = (fp[2 + i] - fm[2 + i]) / (2.0 * h);
                    assert!((d - k[(i, j)]).abs() < 1e-7 * k.amax(), "tangent ({i}, {j}): {d} vs {}", k[(i, j)]);
                }
            }
            assert_eq!(k, k.transpose());
            assert!(f[..2].iter().chain(&f[11..]).all(|&x| x == 0.0), "only the triad is loaded");
        }
    }

    /// Newton's tangent differs from the exact one by the term `k s I` of the compressed slope
    /// (`r_x` here; `r_y`, `r_z` are stretched) and the angles' terms `k s (e_a e_bᵀ + e_b e_aᵀ)`.
    #[test]
    fn newton_tangent_drops_the_compressed_stretch_and_angle_terms() {
        let t = tie();
        let mut q = vec![0.0; 12];
        let x = [[0.9, 0.05, 0.0], [0.0, 1.1, 0.02], [0.01, 0.0, 1.05]];
        for (a, xa) in x.iter().enumerate() {
            q[2 + 3 * a..5 + 3 * a].copy_from_slice(xa);
        }
        let (exact, newton) = (t.tangent(&q, 0.7, false), t.tangent(&q, 0.7, true));
        assert_eq!(newton, newton.transpose());
        let s = t.strains(&q).1;
        let d = newton - exact;
        for j in 0..9 {
            for i in 0..9 {
                let (a, b) = (i / 3, j / 3);
                let expected = if i % 3 != j % 3 {
                    0.0
                } else if a == b {
                    if s[a] < 0.0 { -0.7 * t.k[a] * s[a] } else { 0.0 }
                } else {
                    let p = PAIRS.iter().position(|&pair| pair == (a.min(b), a.max(b))).unwrap();
                    -0.7 * t.k[p] * s[p]
                };
                assert!((d[(i, j)] - expected).abs() < 1e-12 * exact.amax(), "({i}, {j}): {} vs {expected}", d[(i, j)]);
            }
        }
        assert!(s[0] < 0.0 && s[1] > 0.0 && s[2] > 0.0, "r_x compressed, r_y and r_z stretched: {s:?}");
    }

    /// An orthonormal triad in any orientation stores no energy and feels no force.
    #[test]
    fn rotated_orthonormal_triad_is_free() {
        let r = Rotation3::from_scaled_axis(Vector3::new(0.4, -1.3, 2.2)).into_inner();
        let mut q = vec![0.0; 12];
        for a in 0..3 {
            for i in 0..3 {
                q[2 + 3 * a + i] = r[(i, a)];
            }
        }
        let mut f = vec![0.0; 12];
        tie().add_force(&q, &mut f);
        assert!(tie().energy(&q) < 1e-30);
        assert!(f.iter().all(|x| x.abs() < 1e-14), "{f:?}");
    }
}
