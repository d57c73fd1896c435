//! How the linear UVLM's residual and nodal forces change when the frozen wakes' nodes move
//! ([`LinearUvlm::wake_node_derivatives`], docs/gust.md §7): in the time-marching scheme the
//! wake's nodes follow the trailing edge's past motion and drift with a gust.

use nalgebra::DMatrix;

use crate::biot_savart::Filaments;
use crate::flow::Flow;
use crate::linear::LinearUvlm;
use crate::linear_stack::{Frozen, stacked_loads, unit_wake_ring};

/// How the residual and the nodal forces change when the frozen wakes' nodes move (see
/// [`LinearUvlm::wake_node_derivatives`]). Node `(k, t)` is the downstream corner of wake row `k`
/// behind trailing-edge node `t` of the stacked numbering ([`crate::SurfaceBlock::te_nodes`]:
/// each surface's `N_s + 1` trailing-edge nodes, surface after surface).
#[derive(Debug, Clone)]
pub struct WakeNodeDerivatives {
    /// Per wake row `k`: the residual (n_rings) per unit displacement of each downstream node
    /// `(k, t)` along each global axis, columns `3t + axis` (n_rings × 3·n_te_nodes).
    pub residual: Vec<DMatrix<f64>>,
    /// Per wake row `k`: the stacked nodal forces per unit displacement of the same nodes
    /// (3·n_nodes × 3·n_te_nodes).
    pub force: Vec<DMatrix<f64>>,
    /// Per wake row `k`: the stacked strip forces ([`Loads::strip`](crate::Loads::strip), the
    /// trailing-edge column numbering) per unit displacement of the same nodes
    /// (3·n_strips × 3·n_te_nodes).
    pub strip: Vec<DMatrix<f64>>,
}

/// The (up to four) rings of a wake of `rows` rows and `n` columns with a corner at node
/// `(k, j)`: row k (its downstream corner), row k + 1 (its upstream corner).
fn rings_at(rows: usize, n: usize, k: usize, j: usize) -> Vec<(usize, usize)> {
    let mut rings = Vec::with_capacity(4);
    for kk in [k, k + 1] {
        if kk < rows {
            for jj in [j.wrapping_sub(1), j] {
                if jj < n {
                    rings.push((kk, jj));
                }
            }
        }
    }
    rings
}

impl LinearUvlm {
    /// Derivatives of the residual and of the nodal forces with respect to the positions of the
    /// frozen wakes' nodes, the circulations held (bound rings `Γ₀`, every wake ring `Γ_TE,0` of
    /// its column). Node `(k, t)` is the downstream corner of wake ring row `k` behind
    /// trailing-edge node `t`; in the time-marching scheme it is where that trailing-edge node
    /// was `τ_k` ago, convected with the external flow since, so it moves with the trailing
    /// edge's past motion and drifts with a gust. The steady wake carries the trailing-edge
    /// circulation, so these terms are first order wherever `Γ₀` varies along the span (its
    /// trailing vortices).
    ///
    /// Central differences (a step of 1e-5 of the row's length) of the velocity induced by the
    /// (up to four) wake rings with a corner at the node; the forces are then exact in that
    /// velocity (the load routine is linear in it).
    pub fn wake_node_derivatives(&self) -> WakeNodeDerivatives {
        let p = &self.params;
        let lats = &self.lattices;
        let (nr, nf, n_te) = (self.n_rings(), self.n_force(), self.n_te_nodes());
        let g_te: Vec<f64> = self.te_rings.iter().map(|&r| self.gamma0[r]).collect();
        let mut fz = Frozen::default();
        let shed = self.reference_shed();
        fz.build(lats, &self.gamma0, &self.wakes, self.closure, p);
        fz.induce_all();
        let u_mid0 = fz.u_mid.clone();
        let flow = Flow::new(p.v_inf);
        let mut v_mid0 = vec![[0.0; 3]; fz.mid.len()];
        flow.velocity_inplace(&fz.mid, 0.0, &mut v_mid0);
        let nrm: Vec<[f64; 3]> = lats.iter().flat_map(|l| l.normals().iter().copied()).collect();
        let rows = self.wakes[0].n_rows();
        let mut wakes = self.wakes.clone();
        let mut fil = Filaments::default();
        let (mut du_col, mut du_mid) = (vec![[0.0; 3]; fz.col.len()], vec![[0.0; 3]; fz.mid.len()]);
        let mut u_pm = u_mid0.clone();
        let ns = 3 * g_te.len();
        let (mut plus, mut minus) = (vec![0.0; nf], vec![0.0; nf]);
        let (mut plus_s, mut minus_s) = (vec![0.0; ns], vec![0.0; ns]);
        let mut out = WakeNodeDerivatives {
            residual: Vec::with_capacity(rows),
            force: Vec::with_capacity(rows),
            strip: Vec::with_capacity(rows),
        };
        for k in 0..rows {
            let (mut zr, mut zf) = (DMatrix::zeros(nr, 3 * n_te), DMatrix::zeros(nf, 3 * n_te));
            let mut zs = DMatrix::zeros(ns, 3 * n_te);
            for (s, (lat, b)) in lats.iter().zip(&self.blocks).enumerate() {
                let te = lat.trailing_edge_nodes();
                let n = lat.n_spanwise();
                let len = {
                    let a = if k == 0 { te[0] } else { self.wakes[s].node(k - 1, 0) };
                    let b = self.wakes[s].node(k, 0);
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
                };
                let h = 1e-5 * len.max(1e-9);
                for (j, t) in b.te_nodes.clone().enumerate() {
                    let rings = rings_at(rows, n, k, j);
                    for axis in 0..3 {
                        du_col.iter_mut().for_each(|x| *x = [0.0; 3]);
                        du_mid.iter_mut().for_each(|x| *x = [0.0; 3]);
                        for sgn in [1.0, -1.0] {
                            let mut d = [0.0; 3];
                            d[axis] = sgn * h;
                            wakes[s].displace(k, j, d);
                            for &(kk, jj) in &rings {
                                unit_wake_ring(&mut fil, te, &wakes[s], kk, jj, self.closure, p);
                                fz.induce(&[&fil]);
                                let w = sgn * g_te[b.te_columns.start + jj] / (2.0 * h);
                                for (a, b) in du_col.iter_mut().zip(&fz.u_col) {
                                    for q in 0..3 {
                                        a[q] += w * b[q];
                                    }
                                }
                                for (a, b) in du_mid.iter_mut().zip(&fz.u_mid) {
                                    for q in 0..3 {
                                        a[q] += w * b[q];
                                    }
                                }
                            }
                            d[axis] = -d[axis];
                            wakes[s].displace(k, j, d);
                        }
                        let c = 3 * t + axis;
                        for r in 0..nr {
                            zr[(r, c)] = (0..3).map(|q| du_col[r][q] * nrm[r][q]).sum();
                        }
                        fz.bs.set_strengths(&self.gamma0);
                        for (sgn, buf, sbuf) in [(1.0, &mut plus, &mut plus_s), (-1.0, &mut minus, &mut minus_s)] {
                            for (s, u) in u_pm.iter_mut().enumerate() {
                                for q in 0..3 {
                                    u[q] = u_mid0[s][q] + sgn * du_mid[s][q];
                                }
                            }
                            let (bs, blocks, o) = (&fz.bs, &self.blocks, (&mut buf[..], Some(&mut sbuf[..])));
                            stacked_loads(&mut fz.loads, bs, lats, blocks, &v_mid0, &u_pm, None, Some(&shed), p, o);
                        }
                        for i in 0..nf {
                            zf[(i, c)] = 0.5 * (plus[i] - minus[i]);
                        }
                        for i in 0..ns {
                            zs[(i, c)] = 0.5 * (plus_s[i] - minus_s[i]);
                        }
                    }
                }
            }
            out.residual.push(zr);
            out.force.push(zf);
            out.strip.push(zs);
        }
        out
    }
}
