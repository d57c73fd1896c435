//! Building the linear UVLM about a steady solution of one or several surfaces
//! ([`Uvlm::linearise`], docs/uvlm.md §13, §16): the frozen wakes, the reference state, the
//! influence matrix and the exact load derivatives, over the stacked numbering of
//! [`crate::linear_stack`].

use nalgebra::DMatrix;

use crate::aic::BoundSystem;
use crate::error::{Result, UvlmError};
use crate::induce::{Points, induced_velocity_inplace};
use crate::lattice::Lattice;
use crate::linear::{LinearUvlm, LinearWake};
use crate::linear_stack::{Frozen, SurfaceBlock, blocks_of, stacked_loads, unit_wake_ring};
use crate::params::{SteadyWake, UvlmParams};
use crate::solver::Uvlm;
use crate::wake::Wake;

impl Uvlm {
    /// Solve the steady problem on the current lattices (which must be at rest) and linearise
    /// about it with the frozen wake `wake` shed by every surface (see [`crate::LinearUvlm`]).
    ///
    /// # Errors
    /// An invalid wake, a lattice that moves, or a failed steady solve.
    pub fn linearise(&mut self, wake: &LinearWake) -> Result<LinearUvlm> {
        wake.validate()?;
        let moving = self.surfaces.iter().any(|s| s.lattice.grid_velocities().iter().flatten().any(|v| *v != 0.0));
        if moving {
            return Err(UvlmError::InvalidParameter { field: "lattice velocity", value: 1.0 });
        }
        // The reference state is the steady state of this frozen wake: its rows' total length
        // without closure, the semi-infinite legs with it (the time march's steady state).
        let total: f64 = wake.row_lengths.iter().sum();
        let own = self.params().steady_wake;
        self.set_steady_wake(if wake.closure {
            SteadyWake::SemiInfinite
        } else {
            SteadyWake::Finite { length: total }
        })?;
        let solved = self.solve_steady().map(|_| ());
        self.set_steady_wake(own)?;
        solved?;
        let lattices = self.surfaces.iter().map(|s| s.lattice.clone()).collect();
        Ok(LinearUvlm::about(self.params().clone(), lattices, self.gamma().to_vec(), wake))
    }
}

/// The frozen wake of every surface: rows of lengths `xi[k + 1] − xi[k]` straight along `dir`
/// from its trailing edge, each carrying its column's trailing-edge circulation of `gamma0`.
fn frozen_wakes(lats: &[Lattice], blocks: &[SurfaceBlock], xi: &[f64], dir: [f64; 3], gamma0: &[f64]) -> Vec<Wake> {
    let k_rows = xi.len() - 1;
    lats.iter()
        .zip(blocks)
        .map(|(lat, b)| {
            let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
            let te_nodes = lat.trailing_edge_nodes();
            let g_te: Vec<f64> = (0..n).map(|j| gamma0[b.rings.start + lat.ring_index(m - 1, j)]).collect();
            // Far row first (push_front puts the nearest row at index 0).
            let mut wake = Wake::new(n, k_rows);
            let mut row = vec![[0.0; 3]; n + 1];
            for k in (0..k_rows).rev() {
                for j in 0..=n {
                    let t = te_nodes[j];
                    row[j] = [t[0] + xi[k + 1] * dir[0], t[1] + xi[k + 1] * dir[1], t[2] + xi[k + 1] * dir[2]];
                }
                wake.push_front(&row, &g_te);
            }
            wake
        })
        .collect()
}

/// The central difference with a unit step of the stacked loads along `(δΓ, δΓ_shed, δu)` about
/// the reference state: exact, the loads being bilinear in the circulations and the induced
/// velocities.
struct LoadDerivative<'a> {
    gamma0: &'a [f64],
    g_te: &'a [f64],
    u_mid0: &'a [[f64; 3]],
    v_mid0: &'a [[f64; 3]],
    plus: Vec<f64>,
    minus: Vec<f64>,
    plus_strips: Vec<f64>,
    minus_strips: Vec<f64>,
    u_pm: Vec<[f64; 3]>,
    gamma_pm: Vec<f64>,
    shed_pm: Vec<f64>,
}

impl<'a> LoadDerivative<'a> {
    fn new(gamma0: &'a [f64], g_te: &'a [f64], u_mid0: &'a [[f64; 3]], v_mid0: &'a [[f64; 3]], nf: usize) -> Self {
        Self {
            gamma0,
            g_te,
            u_mid0,
            v_mid0,
            plus: vec![0.0; nf],
            minus: vec![0.0; nf],
            plus_strips: vec![0.0; 3 * g_te.len()],
            minus_strips: vec![0.0; 3 * g_te.len()],
            u_pm: vec![[0.0; 3]; u_mid0.len()],
            gamma_pm: vec![0.0; gamma0.len()],
            shed_pm: g_te.to_vec(),
        }
    }

    /// The derivative along a unit step of ring `dgamma`, of the newest wake ring of column
    /// `dshed` (its direct load on the trailing-edge segment, with `te_segment_force`) and of the
    /// induced velocity at the midpoints by `du`, into `out` (nodal forces) and `out_strips`
    /// (strip forces).
    #[allow(clippy::too_many_arguments)] // the model (buffers, surfaces, parameters) and the step
    fn eval(
        &mut self,
        fz: &mut Frozen,
        (lats, blocks, p): (&[Lattice], &[SurfaceBlock], &UvlmParams),
        dgamma: Option<usize>,
        dshed: Option<usize>,
        du: &[[f64; 3]],
        (out, out_strips): (&mut [f64], &mut [f64]),
    ) {
        let Self { gamma0, g_te, u_mid0, v_mid0, plus, minus, plus_strips, minus_strips, u_pm, gamma_pm, shed_pm } =
            self;
        for (sgn, buf, sbuf) in [(1.0, &mut *plus, &mut *plus_strips), (-1.0, &mut *minus, &mut *minus_strips)] {
            gamma_pm.copy_from_slice(gamma0);
            if let Some(r) = dgamma {
                gamma_pm[r] += sgn;
            }
            shed_pm.copy_from_slice(g_te);
            if let Some(j) = dshed {
                shed_pm[j] += sgn;
            }
            fz.bs.set_strengths(gamma_pm);
            for (s, u) in u_pm.iter_mut().enumerate() {
                for q in 0..3 {
                    u[q] = u_mid0[s][q] + sgn * du[s][q];
                }
            }
            stacked_loads(&mut fz.loads, &fz.bs, lats, blocks, v_mid0, u_pm, None, Some(shed_pm), p, (buf, Some(sbuf)));
        }
        for k in 0..out.len() {
            out[k] = 0.5 * (plus[k] - minus[k]);
        }
        for k in 0..out_strips.len() {
            out_strips[k] = 0.5 * (plus_strips[k] - minus_strips[k]);
        }
    }
}

impl LinearUvlm {
    /// The linear model of the surfaces `lattices` (at rest) about their steady circulations
    /// `gamma0` (global ring order) in the frozen wake `wake`.
    pub(crate) fn about(p: UvlmParams, lats: Vec<Lattice>, gamma0: Vec<f64>, wake: &LinearWake) -> Self {
        let blocks = blocks_of(&lats, p.te_segment_force);
        let v = p.v_inf;
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let dir = [v[0] / speed, v[1] / speed, v[2] / speed];
        let te_rings: Vec<usize> = lats
            .iter()
            .zip(&blocks)
            .flat_map(|(lat, b)| {
                (0..lat.n_spanwise()).map(|j| b.rings.start + lat.ring_index(lat.n_chordwise() - 1, j))
            })
            .collect();
        let k_rows = wake.row_lengths.len();
        let mut xi = vec![0.0; k_rows + 1];
        for k in 0..k_rows {
            xi[k + 1] = xi[k] + wake.row_lengths[k];
        }
        // Row k carries the trailing-edge circulation of the time its downstream edge left the
        // trailing edge: the time-marching scheme's explicit Kutta condition (row k holds Γ_TE of
        // k + 1 steps ago), so that the linear model is that scheme's linearisation.
        let row_delays: Vec<f64> = (0..k_rows).map(|k| xi[k + 1] / speed).collect();
        let wakes = frozen_wakes(&lats, &blocks, &xi, dir, &gamma0);
        let closure = wake.closure.then_some(dir);
        let g_te: Vec<f64> = te_rings.iter().map(|&r| gamma0[r]).collect();
        let nrm: Vec<[f64; 3]> = lats.iter().flat_map(|l| l.normals().iter().copied()).collect();

        // Reference state.
        let mut fz = Frozen::default();
        fz.build(&lats, &gamma0, &wakes, closure, &p);
        fz.induce_all();
        fz.external(v);
        let (u_col0, u_mid0, v_mid0) = (fz.u_col.clone(), fz.u_mid.clone(), fz.v_mid.clone());
        let reference_residual: Vec<f64> =
            (0..gamma0.len()).map(|r| (0..3).map(|q| (fz.v_col[r][q] + u_col0[r][q]) * nrm[r][q]).sum()).collect();
        // The trailing-edge segment (`te_segment_force`) carries Γ_w0 − Γ_TE: zero in the
        // reference state, whose newest wake row holds the trailing-edge circulation.
        let nf = blocks.last().map_or(0, |b| 3 * b.nodes.end);
        let mut reference_forces = vec![0.0; nf];
        let mut reference_strips = vec![0.0; 3 * g_te.len()];
        let (bs, loads) = (&fz.bs, &mut fz.loads);
        let out = (&mut reference_forces[..], Some(&mut reference_strips[..]));
        stacked_loads(loads, bs, &lats, &blocks, &v_mid0, &u_mid0, None, Some(&g_te), &p, out);

        let aic = influence_matrix(&lats, &nrm, &mut fz, &p);
        let mut ld = LoadDerivative::new(&gamma0, &g_te, &u_mid0, &v_mid0, nf);
        let model = (&lats[..], &blocks[..], &p);
        let (force_gamma, force_gamma_dot, strip_gamma, strip_gamma_dot) = bound_derivatives(&mut fz, &mut ld, model);
        let rows = WakeRows { wakes: &wakes, closure, nrm: &nrm, n_rows: k_rows };
        let [row_normalwash, force_row, strip_row] = rows.derivatives(&mut fz, &mut ld, model);
        Self {
            params: p,
            lattices: lats,
            wakes,
            blocks,
            closure,
            gamma0,
            aic,
            row_delays,
            row_normalwash,
            force_gamma,
            force_gamma_dot,
            force_row,
            strip_gamma,
            strip_gamma_dot,
            strip_row,
            te_rings,
            reference_residual,
            reference_forces,
            reference_strips,
        }
    }
}

/// `A`: the unsteady-mode influence matrix of all rings on all collocation points (those of
/// `fz`), normals `nrm` stacked.
fn influence_matrix(lats: &[Lattice], nrm: &[[f64; 3]], fz: &mut Frozen, p: &UvlmParams) -> DMatrix<f64> {
    let nr = nrm.len();
    let mut aic_rm = vec![0.0; nr * nr];
    let mut nrm_pts = Points::default();
    for x in nrm {
        nrm_pts.push(*x);
    }
    // Unit strengths (the AIC reads the filaments' strengths).
    let mut unit_bs = BoundSystem::default();
    unit_bs.build_surfaces(lats.iter(), crate::aic::TrailingEdge::Unsteady, &p.bound_core, &p.images);
    unit_bs.assemble_aic(
        &fz.col,
        &nrm_pts,
        &mut aic_rm,
        crate::aic::AicLayout::RowMajor,
        crate::Parallel::Off,
        &mut fz.blocks,
    );
    DMatrix::from_row_slice(nr, nr, &aic_rm)
}

/// The bound rings' load derivatives `F_Γ` (through the loads' circulations and the velocity
/// each ring induces at every midpoint) and `F_Γ̇` (the unsteady term), one ring at a time, and
/// the same of the strip forces.
fn bound_derivatives(
    fz: &mut Frozen,
    ld: &mut LoadDerivative<'_>,
    model: (&[Lattice], &[SurfaceBlock], &UvlmParams),
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let (lats, blocks, p) = model;
    let (nr, nf, ns) = (ld.gamma0.len(), ld.plus.len(), ld.plus_strips.len());
    let mut force_gamma = DMatrix::zeros(nf, nr);
    let mut force_gamma_dot = DMatrix::zeros(nf, nr);
    let mut strip_gamma = DMatrix::zeros(ns, nr);
    let mut strip_gamma_dot = DMatrix::zeros(ns, nr);
    let mut unit = vec![0.0; nr];
    let mut col = vec![0.0; nf];
    let mut scol = vec![0.0; ns];
    let zero_gamma = vec![0.0; nr];
    let zeros_mid = vec![[0.0; 3]; ld.u_mid0.len()];
    for r in 0..nr {
        unit.fill(0.0);
        unit[r] = 1.0;
        fz.bs.set_strengths(&unit);
        let mid = std::mem::take(&mut fz.mid);
        fz.u_mid.resize(mid.len(), [0.0; 3]);
        induced_velocity_inplace(&[&fz.bs.fil], &mid, &mut fz.u_mid, crate::Parallel::Off, &mut fz.blocks);
        fz.mid = mid;
        fz.correct_bound_at_midpoints();
        let du = fz.u_mid.clone();
        ld.eval(fz, model, Some(r), None, &du, (&mut col, &mut scol));
        force_gamma.column_mut(r).copy_from_slice(&col);
        strip_gamma.column_mut(r).copy_from_slice(&scol);
        fz.bs.set_strengths(&zero_gamma);
        let v_mid0 = ld.v_mid0;
        let out = (&mut col[..], Some(&mut scol[..]));
        stacked_loads(&mut fz.loads, &fz.bs, lats, blocks, v_mid0, &zeros_mid, Some(&unit), None, p, out);
        force_gamma_dot.column_mut(r).copy_from_slice(&col);
        strip_gamma_dot.column_mut(r).copy_from_slice(&scol);
    }
    (force_gamma, force_gamma_dot, strip_gamma, strip_gamma_dot)
}

/// The frozen wakes' rows, for their derivatives.
struct WakeRows<'a> {
    wakes: &'a [Wake],
    closure: Option<[f64; 3]>,
    /// Normals at the collocation points, stacked.
    nrm: &'a [[f64; 3]],
    n_rows: usize,
}

impl WakeRows<'_> {
    /// `W_k` and `F_k` (and the strip forces' `S_k`), one unit wake ring at a time, built as the
    /// wake builder builds it (same edges, cores and images) but with only its own four corners;
    /// columns in the stacked trailing-edge numbering.
    fn derivatives(
        &self,
        fz: &mut Frozen,
        ld: &mut LoadDerivative<'_>,
        model: (&[Lattice], &[SurfaceBlock], &UvlmParams),
    ) -> [Vec<DMatrix<f64>>; 3] {
        let (lats, blocks, p) = model;
        let (nr, nf, n_cols) = (ld.gamma0.len(), ld.plus.len(), ld.g_te.len());
        let mut row_normalwash = Vec::with_capacity(self.n_rows);
        let mut force_row = Vec::with_capacity(self.n_rows);
        let mut strip_row = Vec::with_capacity(self.n_rows);
        let mut col = vec![0.0; nf];
        let mut scol = vec![0.0; 3 * n_cols];
        for k in 0..self.n_rows {
            let mut w = DMatrix::zeros(nr, n_cols);
            let mut f = DMatrix::zeros(nf, n_cols);
            let mut sf = DMatrix::zeros(3 * n_cols, n_cols);
            for ((lat, b), wake) in lats.iter().zip(blocks).zip(self.wakes) {
                let te = lat.trailing_edge_nodes();
                for (j, c) in b.te_columns.clone().enumerate() {
                    unit_wake_ring(&mut fz.known, te, wake, k, j, self.closure, p);
                    let known = std::mem::take(&mut fz.known);
                    fz.induce(&[&known]);
                    fz.correct_wake_at_midpoints(&known);
                    fz.known = known;
                    for r in 0..nr {
                        w[(r, c)] = (0..3).map(|q| fz.u_col[r][q] * self.nrm[r][q]).sum();
                    }
                    let du = fz.u_mid.clone();
                    ld.eval(fz, model, None, (k == 0).then_some(c), &du, (&mut col, &mut scol));
                    f.column_mut(c).copy_from_slice(&col);
                    sf.column_mut(c).copy_from_slice(&scol);
                }
            }
            row_normalwash.push(w);
            force_row.push(f);
            strip_row.push(sf);
        }
        [row_normalwash, force_row, strip_row]
    }
}
