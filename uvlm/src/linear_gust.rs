//! The input of a frozen gust to the linear UVLM (docs/gust.md §7): its normalwash at the
//! collocation points and its Joukowski force at the load segments' midpoints, each point
//! delayed by its distance behind the gust's front; over every surface (stacked numbering,
//! [`crate::SurfaceBlock`]).

use nalgebra::{Complex, DMatrix};

use crate::error::{Result, UvlmError};
use crate::linear::LinearUvlm;
use crate::linear_stack::{Frozen, surface_loads};

/// The input of a frozen gust to the linear model (see [`LinearUvlm::gust`]): a gust velocity
/// `w(t) d` at the front's reference point reaches a point `x` of the lattice `τ_x = V̂∞·(x −
/// x_f)/U` later, so at Laplace variable `s` it enters the non-penetration condition as
/// `Σ_c e^{−s τ_c} (d·n_c) ŵ(s)` and the nodal forces as `Σ_m e^{−s τ_m} F_m ŵ(s)` (the
/// Joukowski force of the gust velocity at segment midpoint `m` on the reference circulations).
/// Collocation points are the rings (global order), midpoints those of every surface's load
/// segments surface after surface ([`crate::SurfaceBlock::midpoints`]).
#[derive(Debug, Clone)]
pub struct LinearGust {
    /// `d·n_c`: normal velocity at each collocation point per unit gust velocity (residual sign,
    /// as [`LinearUvlm::evaluate`]).
    pub normalwash: Vec<f64>,
    /// Delay of each collocation point behind the front's reference point, s.
    pub collocation_delays: Vec<f64>,
    /// Nodal forces per unit gust velocity at each load segment's midpoint (3·n_nodes × n_mid);
    /// a midpoint loads its own surface only.
    pub force: DMatrix<f64>,
    /// Strip forces ([`Loads::strip`](crate::Loads::strip), 3·n_strips, the trailing-edge column
    /// numbering) per unit gust velocity at each load segment's midpoint (3·n_strips × n_mid).
    pub strip_force: DMatrix<f64>,
    /// Delay of each load segment midpoint, s.
    pub midpoint_delays: Vec<f64>,
}

impl LinearGust {
    /// Residual (n_rings) per unit `ŵ(s)`.
    pub fn normalwash_at(&self, s: Complex<f64>) -> Vec<Complex<f64>> {
        self.normalwash.iter().zip(&self.collocation_delays).map(|(w, tau)| (-s * tau).exp() * w).collect()
    }

    /// Stacked nodal forces (3·n_nodes) per unit `ŵ(s)`, at fixed circulations.
    pub fn force_at(&self, s: Complex<f64>) -> Vec<Complex<f64>> {
        Self::delayed(&self.force, &self.midpoint_delays, s)
    }

    /// Stacked strip forces (3·n_strips) per unit `ŵ(s)`, at fixed circulations.
    pub fn strip_force_at(&self, s: Complex<f64>) -> Vec<Complex<f64>> {
        Self::delayed(&self.strip_force, &self.midpoint_delays, s)
    }

    /// `Σ_m e^{−s τ_m} m[:, m]`.
    fn delayed(m: &DMatrix<f64>, delays: &[f64], s: Complex<f64>) -> Vec<Complex<f64>> {
        let e: Vec<Complex<f64>> = delays.iter().map(|tau| (-s * tau).exp()).collect();
        (0..m.nrows()).map(|i| (0..m.ncols()).map(|c| e[c] * m[(i, c)]).sum()).collect()
    }
}

impl LinearUvlm {
    /// The input of a frozen gust along `direction` (any non-zero length), convected with the
    /// free stream, whose front passes `front` at time 0 (the convention of
    /// [`crate::gust::Convection`]: a point `x` sees the gust velocity of the front's reference
    /// point `V̂∞·(x − front)/U` later). The collocation points and the load segments' midpoints
    /// are those of the reference lattices; the forces are exact central differences of the load
    /// routine with a unit step (they are linear in the external velocity).
    ///
    /// # Errors
    /// A zero or non-finite direction.
    pub fn gust(&self, direction: [f64; 3], front: [f64; 3]) -> Result<LinearGust> {
        let dn = (direction[0].powi(2) + direction[1].powi(2) + direction[2].powi(2)).sqrt();
        if !(dn.is_finite() && dn > 0.0) {
            return Err(UvlmError::InvalidParameter { field: "gust.direction", value: dn });
        }
        let d = direction.map(|x| x / dn);
        let v = self.params.v_inf;
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let vh = v.map(|x| x / speed);
        let delay = |x: [f64; 3]| (0..3).map(|q| vh[q] * (x[q] - front[q])).sum::<f64>() / speed;
        let lats = &self.lattices;
        let normalwash = lats.iter().flat_map(|l| l.normals()).map(|n| (0..3).map(|q| d[q] * n[q]).sum()).collect();
        let collocation_delays = lats.iter().flat_map(|l| l.collocation()).map(|c| delay(*c)).collect();
        let mut fz = Frozen::default();
        let shed = self.reference_shed();
        fz.build(lats, &self.gamma0, &self.wakes, self.closure, &self.params);
        fz.induce_all();
        fz.external(v);
        let n_mid = fz.mid.len();
        debug_assert_eq!(n_mid, self.blocks.last().map_or(0, |b| b.midpoints.end));
        let midpoint_delays = (0..n_mid).map(|k| delay([fz.mid.x[k], fz.mid.y[k], fz.mid.z[k]])).collect();
        let (nf, ns) = (self.n_force(), 3 * self.te_rings.len());
        let mut force = DMatrix::zeros(nf, n_mid);
        let mut strip_force = DMatrix::zeros(ns, n_mid);
        let (mut plus, mut minus) = (vec![0.0; nf], vec![0.0; nf]);
        let (mut plus_s, mut minus_s) = (vec![0.0; ns], vec![0.0; ns]);
        let v_mid0 = fz.v_mid.clone();
        let mut v_pm = v_mid0.clone();
        for (k, (lat, b)) in lats.iter().zip(&self.blocks).enumerate() {
            for m in b.midpoints.clone() {
                for (sgn, buf, sbuf) in [(1.0, &mut plus, &mut plus_s), (-1.0, &mut minus, &mut minus_s)] {
                    v_pm[m] = [v_mid0[m][0] + sgn * d[0], v_mid0[m][1] + sgn * d[1], v_mid0[m][2] + sgn * d[2]];
                    let (bs, u, out) = (&fz.bs, &fz.u_mid, (&mut buf[..], Some(&mut sbuf[..])));
                    surface_loads(&mut fz.loads, bs, (k, lat, b), &v_pm, u, None, Some(&shed), &self.params, out);
                }
                v_pm[m] = v_mid0[m];
                for i in b.forces() {
                    force[(i, m)] = 0.5 * (plus[i] - minus[i]);
                }
                for i in 3 * b.te_columns.start..3 * b.te_columns.end {
                    strip_force[(i, m)] = 0.5 * (plus_s[i] - minus_s[i]);
                }
            }
        }
        Ok(LinearGust { normalwash, collocation_delays, force, strip_force, midpoint_delays })
    }
}
