//! The UVLM linearised about a steady solution, in the Laplace domain (docs/uvlm.md §13).
//!
//! About a steady solution `Γ₀` on a lattice at rest, with a frozen wake of straight rows along
//! the free stream (`Γ₀` the steady state of that wake: finite without closure,
//! [`crate::SteadyWake`]), a small motion of the lattice (grid node displacements `δx` and velocities
//! `δẋ`) and small circulations `δΓ` obey
//!
//! $$ A\,\delta\Gamma + \sum_k W_k\,\delta\Gamma_{w,k} + R_x\,\delta x + R_{\dot x}\,\delta\dot x = 0 ,$$
//!
//! the non-penetration condition at the collocation points (`A` the unsteady-mode influence
//! matrix of the bound rings, `W_k` that of wake ring row `k`), with the wake carrying the
//! trailing-edge circulation of earlier times, `δΓ_{w,k}(t) = δΓ_TE(t − τ_k)`, `τ_k` the time the
//! free stream takes from the trailing edge to the downstream edge of row `k` (the time-marching
//! scheme sheds the trailing-edge circulation of the previous step into a row of length `U·dt`,
//! so row `k` holds `Γ_TE` of `k + 1` steps ago; with this delay the linear model reproduces the
//! time-marching response to 0.2 % at k ≤ 0.5, test `linear_matches_time_marching`). In the Laplace domain
//! that is `δΓ_{w,k} = e^{−s τ_k} E δΓ` (`E` picks the trailing-edge rings), so the wake needs no
//! states: the aerodynamic transfer is exact for any complex `s` (the "p-method"). The nodal
//! forces are
//!
//! $$ \delta F = F_\Gamma\,\delta\Gamma + F_{\dot\Gamma}\, s\,\delta\Gamma
//!   + \sum_k F_k\, e^{-s\tau_k} E\,\delta\Gamma + F_x\,\delta x + F_{\dot x}\,\delta\dot x .$$
//!
//! This module builds `A`, `W_k`, `F_Γ`, `F_Γ̇` and `F_k` exactly, from the same filament sets,
//! cores, images and load routine as the time-marching solver: the loads are bilinear in the
//! circulations and the induced velocities, so a central difference of the load routine with
//! a unit step is exact (to round-off). The geometric terms `R_x`, `R_ẋ`, `F_x` and `F_ẋ` depend on
//! how the caller moves the lattice (a structure's modes), so the caller differentiates
//! [`LinearUvlm::evaluate`], which returns the residual and the nodal forces of a moved lattice
//! with the reference circulations held.
//!
//! Two further inputs (docs/gust.md §7): [`LinearUvlm::gust`], a frozen gust's normalwash at the
//! collocation points and its Joukowski force at the segment midpoints, each point delayed by its
//! distance behind the gust's front; and [`LinearUvlm::wake_node_derivatives`], the residual and
//! forces per displacement of the frozen wake's nodes (which in the time-marching scheme follow
//! the trailing edge's past motion and drift with a gust).

use nalgebra::{Complex, DMatrix};

use crate::aic::{BoundSystem, TrailingEdge, WakePart, build_known_wake};
use crate::biot_savart::{Filaments, NodeBlock};
use crate::error::{Result, UvlmError};
use crate::flow::Flow;
use crate::images::append_images;
use crate::induce::{Points, induced_velocity_inplace};
use crate::lattice::Lattice;
use crate::loads::{Loads, compute_loads};
use crate::params::{SteadyWake, UvlmParams};
use crate::scratch::ScratchPool;
use crate::solver::Uvlm;
use crate::wake::Wake;

/// The frozen wake of the linear model: straight ring rows along the free stream from the
/// trailing-edge ring row.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearWake {
    /// Length of each ring row along the free stream, m (row 0 at the trailing edge).
    pub row_lengths: Vec<f64>,
    /// Close the last row with semi-infinite legs along the free stream (they carry the last
    /// row's circulation, as the time-marching `wake_closure`).
    pub closure: bool,
}

impl LinearWake {
    /// `n_rows` rows of equal length `row_length` (m): the wake of a time-marching run with
    /// `U·dt = row_length`.
    pub fn uniform(n_rows: usize, row_length: f64, closure: bool) -> Self {
        Self { row_lengths: vec![row_length; n_rows], closure }
    }

    fn validate(&self) -> Result<()> {
        if self.row_lengths.is_empty() {
            return Err(UvlmError::InvalidParameter { field: "row_lengths", value: 0.0 });
        }
        for &l in &self.row_lengths {
            if !(l.is_finite() && l > 0.0) {
                return Err(UvlmError::InvalidParameter { field: "row_lengths", value: l });
            }
        }
        Ok(())
    }
}

/// The linearised UVLM about a steady solution (see the module docs). Matrices act on the ring
/// circulations in the lattice's ring order; nodal forces are stacked `[F_0x, F_0y, F_0z, F_1x, …]`
/// over the ring nodes ([`Lattice::ring_nodes`]), the points where [`Loads::nodal`] acts.
#[derive(Debug, Clone)]
pub struct LinearUvlm {
    params: UvlmParams,
    lattice: Lattice,
    wake: Wake,
    closure: Option<[f64; 3]>,
    gamma0: Vec<f64>,
    /// Influence matrix `A` (n_rings × n_rings): normal velocity at collocation point p per unit
    /// circulation of bound ring r (unsteady mode: the trailing-edge edge is a bound filament).
    pub aic: DMatrix<f64>,
    /// Delay `τ_k` of each wake row, s.
    pub row_delays: Vec<f64>,
    /// `W_k` (n_rings × n_spanwise): normal velocity at the collocation points per unit
    /// circulation of wake ring `(k, j)`.
    pub row_normalwash: Vec<DMatrix<f64>>,
    /// `F_Γ` (3·n_nodes × n_rings).
    pub force_gamma: DMatrix<f64>,
    /// `F_Γ̇` (3·n_nodes × n_rings): the unsteady term ρ·A·n·dΓ/dt.
    pub force_gamma_dot: DMatrix<f64>,
    /// `F_k` (3·n_nodes × n_spanwise): nodal forces per unit circulation of wake ring `(k, j)`
    /// (zero when `Γ₀ = 0`).
    pub force_row: Vec<DMatrix<f64>>,
    /// Ring index of the trailing-edge ring of each spanwise column (`E`).
    pub te_rings: Vec<usize>,
    /// Residual of the reference state (the steady solution in the frozen wake), m/s; zero up to
    /// the difference between the frozen wake and the steady solver's semi-infinite legs.
    pub reference_residual: Vec<f64>,
    /// Nodal forces of the reference state, N.
    pub reference_forces: Vec<f64>,
}

/// Work buffers of an evaluation with frozen circulations.
#[derive(Default)]
struct Frozen {
    bs: BoundSystem,
    known: Filaments,
    col: Points,
    mid: Points,
    u_col: Vec<[f64; 3]>,
    v_col: Vec<[f64; 3]>,
    u_mid: Vec<[f64; 3]>,
    v_mid: Vec<[f64; 3]>,
    /// The Biot–Savart loops' workspace (serial here).
    blocks: ScratchPool<NodeBlock>,
    loads: Loads,
}

impl Frozen {
    /// Bound filaments of `lat` (unsteady mode) with strengths `gamma`, and the known wake.
    fn build(&mut self, lat: &Lattice, gamma: &[f64], wake: &Wake, closure: Option<[f64; 3]>, p: &UvlmParams) {
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        self.bs.build(lat, TrailingEdge::Unsteady, &p.bound_core, &p.images);
        self.bs.set_strengths(gamma);
        let te = &lat.ring_nodes()[m * (n + 1)..];
        build_known_wake(&mut self.known, te, wake, closure, &p.wake_core, &p.bound_core, &p.images, WakePart::All);
        self.col.clear();
        for c in lat.collocation() {
            self.col.push(*c);
        }
        self.mid.clear();
        let r = self.bs.surface(0);
        let n_mid = if p.te_segment_force { r.n_lattice_seg } else { r.n_lattice_seg - r.n_te_seg };
        for s in 0..n_mid {
            let (a, b) = self.bs.fil.segment_nodes(s);
            let (pa, pb) = (self.bs.fil.node(a as usize), self.bs.fil.node(b as usize));
            self.mid.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])]);
        }
    }

    /// Velocity induced by `sets` at the collocation points (into `u_col`) and midpoints
    /// (`u_mid`).
    fn induce(&mut self, sets: &[&Filaments]) {
        self.u_col.resize(self.col.len(), [0.0; 3]);
        self.u_mid.resize(self.mid.len(), [0.0; 3]);
        induced_velocity_inplace(sets, &self.col, &mut self.u_col, crate::Parallel::Off, &mut self.blocks);
        induced_velocity_inplace(sets, &self.mid, &mut self.u_mid, crate::Parallel::Off, &mut self.blocks);
    }
}

/// The filaments of wake ring `(k, j)` with unit circulation, exactly as
/// [`build_known_wake`] builds them for a wake in which only that ring circulates: its upstream
/// spanwise edge (+1; the bound core on the trailing edge), its downstream edge (−1; replaced by
/// the closure legs on the last row of a closed wake) and its two chordwise edges, with images.
/// Only the ring's own corners are nodes, so an evaluation costs four filaments.
fn unit_wake_ring(
    fil: &mut Filaments,
    te: &[[f64; 3]],
    wake: &Wake,
    k: usize,
    j: usize,
    closure: Option<[f64; 3]>,
    p: &UvlmParams,
) {
    fil.clear();
    let len = wake.n_rows();
    let up = |jj: usize| if k == 0 { te[jj] } else { wake.node(k - 1, jj) };
    let dist =
        |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    let (a0, a1) = (fil.push_node(up(j)), fil.push_node(up(j + 1)));
    let (b0, b1) = (fil.push_node(wake.node(k, j)), fil.push_node(wake.node(k, j + 1)));
    // Local chordwise lengths as the wake builder takes them: of this ring for its upstream edge
    // (and for the last row's downstream edge), of the next ring for an interior downstream edge.
    let own = 0.5 * (dist(up(j), wake.node(k, j)) + dist(up(j + 1), wake.node(k, j + 1)));
    let up_core = if k == 0 { &p.bound_core } else { &p.wake_core };
    fil.push_segment_scaled(a0, a1, 1.0, up_core, own);
    let closed = closure.is_some() && k + 1 == len;
    if !closed {
        let next = if k + 1 < len {
            0.5 * (dist(wake.node(k, j), wake.node(k + 1, j)) + dist(wake.node(k, j + 1), wake.node(k + 1, j + 1)))
        } else {
            own
        };
        fil.push_segment_scaled(b0, b1, -1.0, &p.wake_core, next);
    }
    fil.push_segment(a0, b0, -1.0, &p.wake_core);
    fil.push_segment(a1, b1, 1.0, &p.wake_core);
    if let (true, Some(dir)) = (closed, closure) {
        fil.push_leg(b0, dir, -1.0, &p.wake_core, dist(up(j), wake.node(k, j)));
        fil.push_leg(b1, dir, 1.0, &p.wake_core, dist(up(j + 1), wake.node(k, j + 1)));
    }
    append_images(fil, &p.images);
}

/// Nodal forces of `loads` stacked into `out`.
fn stack(loads: &Loads, out: &mut [f64]) {
    for (k, f) in loads.nodal.iter().enumerate() {
        out[3 * k..3 * k + 3].copy_from_slice(f);
    }
}

impl Uvlm {
    /// Solve the steady problem on the current lattice (which must be at rest) and linearise
    /// about it with the frozen wake `wake` (see the module docs).
    ///
    /// # Errors
    /// An invalid wake, a lattice that moves, a solver of several surfaces
    /// ([`UvlmError::SeveralSurfaces`]), or a failed steady solve.
    pub fn linearise(&mut self, wake: &LinearWake) -> Result<LinearUvlm> {
        wake.validate()?;
        // The linear model is of one surface (docs/uvlm.md §16).
        self.only_surface("linearise")?;
        if self.lattice().grid_velocities().iter().flatten().any(|v| *v != 0.0) {
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
        let p = self.params().clone();
        let lat = self.lattice().clone();
        let gamma0 = self.gamma().to_vec();
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let (nr, nn) = (lat.n_rings(), lat.ring_nodes().len());
        let v = p.v_inf;
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let dir = [v[0] / speed, v[1] / speed, v[2] / speed];
        let te_rings: Vec<usize> = (0..n).map(|j| lat.ring_index(m - 1, j)).collect();
        let te_nodes: Vec<[f64; 3]> = (0..=n).map(|j| lat.ring_nodes()[lat.node_index(m, j)]).collect();
        // Frozen wake rows, far row first (push_front puts the nearest row at index 0).
        let k_rows = wake.row_lengths.len();
        let mut xi = vec![0.0; k_rows + 1];
        for k in 0..k_rows {
            xi[k + 1] = xi[k] + wake.row_lengths[k];
        }
        // Row k carries the trailing-edge circulation of the time its downstream edge left the
        // trailing edge: the time-marching scheme's explicit Kutta condition (row k holds Γ_TE of
        // k + 1 steps ago), so that the linear model is that scheme's linearisation.
        let row_delays: Vec<f64> = (0..k_rows).map(|k| xi[k + 1] / speed).collect();
        let mut frozen_wake = Wake::new(n, k_rows);
        let g_te: Vec<f64> = te_rings.iter().map(|&r| gamma0[r]).collect();
        let mut row = vec![[0.0; 3]; n + 1];
        for k in (0..k_rows).rev() {
            for j in 0..=n {
                let t = te_nodes[j];
                row[j] = [t[0] + xi[k + 1] * dir[0], t[1] + xi[k + 1] * dir[1], t[2] + xi[k + 1] * dir[2]];
            }
            frozen_wake.push_front(&row, &g_te);
        }
        let closure = wake.closure.then_some(dir);
        let flow = Flow::new(v);

        // Reference state.
        let mut fz = Frozen::default();
        fz.build(&lat, &gamma0, &frozen_wake, closure, &p);
        {
            let bsf = std::mem::take(&mut fz.bs.fil);
            let known = std::mem::take(&mut fz.known);
            fz.induce(&[&bsf, &known]);
            fz.bs.fil = bsf;
            fz.known = known;
        }
        fz.v_col.resize(fz.col.len(), [0.0; 3]);
        fz.v_mid.resize(fz.mid.len(), [0.0; 3]);
        flow.velocity_inplace(&fz.col, 0.0, &mut fz.v_col);
        flow.velocity_inplace(&fz.mid, 0.0, &mut fz.v_mid);
        let u_col0 = fz.u_col.clone();
        let u_mid0 = fz.u_mid.clone();
        let v_mid0 = fz.v_mid.clone();
        let nrm = lat.normals();
        let reference_residual: Vec<f64> =
            (0..nr).map(|r| (0..3).map(|q| (fz.v_col[r][q] + u_col0[r][q]) * nrm[r][q]).sum()).collect();
        // The trailing-edge segment (`te_segment_force`) carries Γ_w0 − Γ_TE: zero in the
        // reference state, whose newest wake row holds the trailing-edge circulation.
        compute_loads(&mut fz.loads, &lat, &fz.bs, 0, &v_mid0, &u_mid0, None, Some(&g_te), &p);
        let mut reference_forces = vec![0.0; 3 * nn];
        stack(&fz.loads, &mut reference_forces);

        // A: the unsteady-mode influence matrix.
        let mut aic_rm = vec![0.0; nr * nr];
        let mut nrm_pts = Points::default();
        for x in nrm {
            nrm_pts.push(*x);
        }
        // Unit strengths (the AIC reads the filaments' strengths).
        let mut unit_bs = BoundSystem::default();
        unit_bs.build(&lat, TrailingEdge::Unsteady, &p.bound_core, &p.images);
        unit_bs.assemble_aic(&fz.col, &nrm_pts, &mut aic_rm, crate::Parallel::Off, &mut fz.blocks);
        let aic = DMatrix::from_row_slice(nr, nr, &aic_rm);

        // Bilinear load derivative along (δΓ, δu): central difference with a unit step, exact.
        let mut plus = vec![0.0; 3 * nn];
        let mut minus = vec![0.0; 3 * nn];
        let mut u_pm = vec![[0.0; 3]; u_mid0.len()];
        let mut gamma_pm = vec![0.0; nr];
        let mut shed_pm = g_te.clone();
        // `dshed`: a unit step of the newest wake ring of that column (its direct load on the
        // trailing-edge segment, with `te_segment_force`).
        let mut load_derivative =
            |fz: &mut Frozen, dgamma: Option<usize>, dshed: Option<usize>, du: &[[f64; 3]], out: &mut [f64]| {
                for (sgn, buf) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                    gamma_pm.copy_from_slice(&gamma0);
                    if let Some(r) = dgamma {
                        gamma_pm[r] += sgn;
                    }
                    shed_pm.copy_from_slice(&g_te);
                    if let Some(j) = dshed {
                        shed_pm[j] += sgn;
                    }
                    fz.bs.set_strengths(&gamma_pm);
                    for (s, u) in u_pm.iter_mut().enumerate() {
                        for q in 0..3 {
                            u[q] = u_mid0[s][q] + sgn * du[s][q];
                        }
                    }
                    compute_loads(&mut fz.loads, &lat, &fz.bs, 0, &v_mid0, &u_pm, None, Some(&shed_pm), &p);
                    stack(&fz.loads, buf);
                }
                for k in 0..out.len() {
                    out[k] = 0.5 * (plus[k] - minus[k]);
                }
            };

        // Bound rings: F_Γ and F_Γ̇.
        let mut force_gamma = DMatrix::zeros(3 * nn, nr);
        let mut force_gamma_dot = DMatrix::zeros(3 * nn, nr);
        let mut unit = vec![0.0; nr];
        let mut col = vec![0.0; 3 * nn];
        let zero_gamma = vec![0.0; nr];
        let zeros_mid = vec![[0.0; 3]; u_mid0.len()];
        for r in 0..nr {
            unit.fill(0.0);
            unit[r] = 1.0;
            fz.bs.set_strengths(&unit);
            let mid = std::mem::take(&mut fz.mid);
            fz.u_mid.resize(mid.len(), [0.0; 3]);
            induced_velocity_inplace(&[&fz.bs.fil], &mid, &mut fz.u_mid, crate::Parallel::Off, &mut fz.blocks);
            fz.mid = mid;
            let du = fz.u_mid.clone();
            load_derivative(&mut fz, Some(r), None, &du, &mut col);
            force_gamma.column_mut(r).copy_from_slice(&col);
            fz.bs.set_strengths(&zero_gamma);
            compute_loads(&mut fz.loads, &lat, &fz.bs, 0, &v_mid0, &zeros_mid, Some(&unit), None, &p);
            stack(&fz.loads, &mut col);
            force_gamma_dot.column_mut(r).copy_from_slice(&col);
        }

        // Wake rows: W_k and F_k, one unit ring at a time, built as the wake builder builds it
        // (same edges, cores and images) but with only its own four corners.
        let mut row_normalwash = Vec::with_capacity(k_rows);
        let mut force_row = Vec::with_capacity(k_rows);
        let te = &lat.ring_nodes()[m * (n + 1)..];
        for k in 0..k_rows {
            let mut w = DMatrix::zeros(nr, n);
            let mut f = DMatrix::zeros(3 * nn, n);
            for j in 0..n {
                unit_wake_ring(&mut fz.known, te, &frozen_wake, k, j, closure, &p);
                let known = std::mem::take(&mut fz.known);
                fz.induce(&[&known]);
                fz.known = known;
                for r in 0..nr {
                    w[(r, j)] = (0..3).map(|q| fz.u_col[r][q] * nrm[r][q]).sum();
                }
                let du = fz.u_mid.clone();
                load_derivative(&mut fz, None, (k == 0).then_some(j), &du, &mut col);
                f.column_mut(j).copy_from_slice(&col);
            }
            row_normalwash.push(w);
            force_row.push(f);
        }
        let _ = u_col0;
        Ok(LinearUvlm {
            params: p,
            lattice: lat,
            wake: frozen_wake,
            closure,
            gamma0,
            aic,
            row_delays,
            row_normalwash,
            force_gamma,
            force_gamma_dot,
            force_row,
            te_rings,
            reference_residual,
            reference_forces,
        })
    }
}

impl LinearUvlm {
    /// Circulation of the frozen wake's newest row, per column (the reference state's shed row).
    fn reference_shed(&self) -> Vec<f64> {
        (0..self.wake.n_spanwise()).map(|j| if self.wake.n_rows() > 0 { self.wake.gamma(0, j) } else { 0.0 }).collect()
    }

    /// The reference lattice (its geometry at the steady solution).
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }
    /// The steady circulations `Γ₀`.
    pub fn gamma0(&self) -> &[f64] {
        &self.gamma0
    }
    /// The parameters.
    pub fn params(&self) -> &UvlmParams {
        &self.params
    }
    /// Number of bound rings.
    pub fn n_rings(&self) -> usize {
        self.gamma0.len()
    }
    /// Number of stacked nodal force components (3 per ring node).
    pub fn n_force(&self) -> usize {
        3 * self.lattice.ring_nodes().len()
    }

    /// Non-penetration residual `(V_ext − ẋ_c + u_ind)·n` at the collocation points (m/s) and
    /// stacked nodal forces (N) of `lattice` (the reference lattice moved, with its node
    /// velocities) with the reference circulations held: the bound rings carry `Γ₀`, the wake
    /// rows keep their geometry and `Γ_TE,0`, and its first row stays attached to the moved
    /// trailing edge. Differentiating this along a motion gives the geometric terms.
    ///
    /// # Errors
    /// When `lattice` has other dimensions than the reference.
    pub fn evaluate(&self, lattice: &Lattice) -> Result<(Vec<f64>, Vec<f64>)> {
        if lattice.n_rings() != self.n_rings() || lattice.n_spanwise() != self.lattice.n_spanwise() {
            return Err(UvlmError::LengthMismatch {
                what: "lattice rings",
                expected: self.n_rings(),
                got: lattice.n_rings(),
            });
        }
        let mut fz = Frozen::default();
        fz.build(lattice, &self.gamma0, &self.wake, self.closure, &self.params);
        let bsf = std::mem::take(&mut fz.bs.fil);
        let known = std::mem::take(&mut fz.known);
        fz.induce(&[&bsf, &known]);
        fz.bs.fil = bsf;
        let flow = Flow::new(self.params.v_inf);
        fz.v_col.resize(fz.col.len(), [0.0; 3]);
        fz.v_mid.resize(fz.mid.len(), [0.0; 3]);
        flow.velocity_inplace(&fz.col, 0.0, &mut fz.v_col);
        flow.velocity_inplace(&fz.mid, 0.0, &mut fz.v_mid);
        let (nrm, cv) = (lattice.normals(), lattice.collocation_velocities());
        let residual = (0..lattice.n_rings())
            .map(|r| (0..3).map(|q| (fz.v_col[r][q] - cv[r][q] + fz.u_col[r][q]) * nrm[r][q]).sum())
            .collect();
        let shed = self.reference_shed();
        compute_loads(&mut fz.loads, lattice, &fz.bs, 0, &fz.v_mid, &fz.u_mid, None, Some(&shed), &self.params);
        let mut forces = vec![0.0; self.n_force()];
        stack(&fz.loads, &mut forces);
        Ok((residual, forces))
    }
}

/// `base + Σ_k e^{−s τ_k} M_k E`: a wake-row sum spread onto the trailing-edge ring columns
/// `te_rings` (`E`), for any row count of `base` and the `M_k` (same rows, one column per
/// spanwise column).
pub fn with_wake(
    base: &DMatrix<Complex<f64>>,
    rows: &[DMatrix<f64>],
    delays: &[f64],
    te_rings: &[usize],
    s: Complex<f64>,
) -> DMatrix<Complex<f64>> {
    let mut out = base.clone();
    for (mk, &tau) in rows.iter().zip(delays) {
        let e = (-s * tau).exp();
        for (j, &r) in te_rings.iter().enumerate() {
            for i in 0..out.nrows() {
                out[(i, r)] += e * mk[(i, j)];
            }
        }
    }
    out
}

impl LinearUvlm {
    /// `A + Σ_k e^{−sτ_k} W_k E` (n_rings × n_rings): the normal velocity at the collocation
    /// points per unit `δΓ` at Laplace variable `s` (1/s).
    pub fn normalwash_matrix(&self, s: Complex<f64>) -> DMatrix<Complex<f64>> {
        with_wake(&self.aic.map(Complex::from), &self.row_normalwash, &self.row_delays, &self.te_rings, s)
    }

    /// `F_Γ + s F_Γ̇ + Σ_k e^{−sτ_k} F_k E` (3·n_nodes × n_rings): nodal forces per unit `δΓ`.
    pub fn force_matrix(&self, s: Complex<f64>) -> DMatrix<Complex<f64>> {
        let base = self.force_gamma.map(Complex::from) + self.force_gamma_dot.map(|x| s * x);
        with_wake(&base, &self.force_row, &self.row_delays, &self.te_rings, s)
    }
}

/// The input of a frozen gust to the linear model (see [`LinearUvlm::gust`]): a gust velocity
/// `w(t) d` at the front's reference point reaches a point `x` of the lattice `τ_x = V̂∞·(x −
/// x_f)/U` later, so at Laplace variable `s` it enters the non-penetration condition as
/// `Σ_c e^{−s τ_c} (d·n_c) ŵ(s)` and the nodal forces as `Σ_m e^{−s τ_m} F_m ŵ(s)` (the
/// Joukowski force of the gust velocity at segment midpoint `m` on the reference circulations).
#[derive(Debug, Clone)]
pub struct LinearGust {
    /// `d·n_c`: normal velocity at each collocation point per unit gust velocity (residual sign,
    /// as [`LinearUvlm::evaluate`]).
    pub normalwash: Vec<f64>,
    /// Delay of each collocation point behind the front's reference point, s.
    pub collocation_delays: Vec<f64>,
    /// Nodal forces per unit gust velocity at each load segment's midpoint (3·n_nodes × n_mid).
    pub force: DMatrix<f64>,
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
        let e: Vec<Complex<f64>> = self.midpoint_delays.iter().map(|tau| (-s * tau).exp()).collect();
        (0..self.force.nrows()).map(|i| (0..self.force.ncols()).map(|m| e[m] * self.force[(i, m)]).sum()).collect()
    }
}

impl LinearUvlm {
    /// The input of a frozen gust along `direction` (any non-zero length), convected with the
    /// free stream, whose front passes `front` at time 0 (the convention of
    /// [`crate::gust::Convection`]: a point `x` sees the gust velocity of the front's reference
    /// point `V̂∞·(x − front)/U` later). The collocation points and the load segments' midpoints
    /// are those of the reference lattice; the forces are exact central differences of the load
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
        let lat = &self.lattice;
        let normalwash = lat.normals().iter().map(|n| (0..3).map(|q| d[q] * n[q]).sum()).collect();
        let collocation_delays = lat.collocation().iter().map(|c| delay(*c)).collect();
        let mut fz = Frozen::default();
        let shed = self.reference_shed();
        fz.build(lat, &self.gamma0, &self.wake, self.closure, &self.params);
        let bsf = std::mem::take(&mut fz.bs.fil);
        let known = std::mem::take(&mut fz.known);
        fz.induce(&[&bsf, &known]);
        fz.bs.fil = bsf;
        let flow = Flow::new(v);
        fz.v_mid.resize(fz.mid.len(), [0.0; 3]);
        flow.velocity_inplace(&fz.mid, 0.0, &mut fz.v_mid);
        let n_mid = fz.mid.len();
        let midpoint_delays = (0..n_mid).map(|k| delay([fz.mid.x[k], fz.mid.y[k], fz.mid.z[k]])).collect();
        let nf = self.n_force();
        let mut force = DMatrix::zeros(nf, n_mid);
        let (mut plus, mut minus) = (vec![0.0; nf], vec![0.0; nf]);
        let v_mid0 = fz.v_mid.clone();
        let mut v_pm = v_mid0.clone();
        for m in 0..n_mid {
            for (sgn, buf) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                v_pm[m] = [v_mid0[m][0] + sgn * d[0], v_mid0[m][1] + sgn * d[1], v_mid0[m][2] + sgn * d[2]];
                compute_loads(&mut fz.loads, lat, &fz.bs, 0, &v_pm, &fz.u_mid, None, Some(&shed), &self.params);
                stack(&fz.loads, buf);
            }
            v_pm[m] = v_mid0[m];
            for i in 0..nf {
                force[(i, m)] = 0.5 * (plus[i] - minus[i]);
            }
        }
        Ok(LinearGust { normalwash, collocation_delays, force, midpoint_delays })
    }
}

/// How the residual and the nodal forces change when the frozen wake's nodes move (see
/// [`LinearUvlm::wake_node_derivatives`]).
#[derive(Debug, Clone)]
pub struct WakeNodeDerivatives {
    /// Per wake row `k`: the residual (n_rings) per unit displacement of each downstream node
    /// `(k, j)` along each global axis, columns `3j + axis` (n_rings × 3·(n_spanwise + 1)).
    pub residual: Vec<DMatrix<f64>>,
    /// Per wake row `k`: the stacked nodal forces per unit displacement of the same nodes
    /// (3·n_nodes × 3·(n_spanwise + 1)).
    pub force: Vec<DMatrix<f64>>,
}

impl LinearUvlm {
    /// Derivatives of the residual and of the nodal forces with respect to the positions of the
    /// frozen wake's nodes, the circulations held (bound rings `Γ₀`, every wake ring `Γ_TE,0`).
    /// Node `(k, j)` is the downstream corner of wake ring row `k`; in the time-marching scheme
    /// it is where trailing-edge node `j` was `τ_k` ago, convected with the external flow since,
    /// so it moves with the trailing edge's past motion and drifts with a gust. The steady wake
    /// carries the trailing-edge circulation, so these terms are first order wherever `Γ₀`
    /// varies along the span (its trailing vortices).
    ///
    /// Central differences (a step of 1e-5 of the row's length) of the velocity induced by the
    /// (up to four) wake rings with a corner at the node; the forces are then exact in that
    /// velocity (the load routine is linear in it).
    pub fn wake_node_derivatives(&self) -> WakeNodeDerivatives {
        let p = &self.params;
        let lat = &self.lattice;
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let (nr, nf) = (self.n_rings(), self.n_force());
        let te: Vec<[f64; 3]> = lat.ring_nodes()[m * (n + 1)..].to_vec();
        let g_te: Vec<f64> = self.te_rings.iter().map(|&r| self.gamma0[r]).collect();
        let mut fz = Frozen::default();
        let shed = self.reference_shed();
        fz.build(lat, &self.gamma0, &self.wake, self.closure, p);
        let bsf = std::mem::take(&mut fz.bs.fil);
        let known = std::mem::take(&mut fz.known);
        fz.induce(&[&bsf, &known]);
        fz.bs.fil = bsf;
        let u_mid0 = fz.u_mid.clone();
        let flow = Flow::new(p.v_inf);
        let mut v_mid0 = vec![[0.0; 3]; fz.mid.len()];
        flow.velocity_inplace(&fz.mid, 0.0, &mut v_mid0);
        let nrm = lat.normals().to_vec();
        let rows = self.wake.n_rows();
        let mut wake = self.wake.clone();
        let mut fil = Filaments::default();
        let (mut du_col, mut du_mid) = (vec![[0.0; 3]; fz.col.len()], vec![[0.0; 3]; fz.mid.len()]);
        let mut u_pm = u_mid0.clone();
        let (mut plus, mut minus) = (vec![0.0; nf], vec![0.0; nf]);
        let mut out = WakeNodeDerivatives { residual: Vec::with_capacity(rows), force: Vec::with_capacity(rows) };
        for k in 0..rows {
            let (mut zr, mut zf) = (DMatrix::zeros(nr, 3 * (n + 1)), DMatrix::zeros(nf, 3 * (n + 1)));
            let len = {
                let a = if k == 0 { te[0] } else { self.wake.node(k - 1, 0) };
                let b = self.wake.node(k, 0);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            };
            let h = 1e-5 * len.max(1e-9);
            for j in 0..=n {
                // Rings with a corner at (k, j): row k (downstream corner), row k + 1 (upstream).
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
                for axis in 0..3 {
                    du_col.iter_mut().for_each(|x| *x = [0.0; 3]);
                    du_mid.iter_mut().for_each(|x| *x = [0.0; 3]);
                    for sgn in [1.0, -1.0] {
                        let mut d = [0.0; 3];
                        d[axis] = sgn * h;
                        wake.displace(k, j, d);
                        for &(kk, jj) in &rings {
                            unit_wake_ring(&mut fil, &te, &wake, kk, jj, self.closure, p);
                            fz.induce(&[&fil]);
                            let w = sgn * g_te[jj] / (2.0 * h);
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
                        wake.displace(k, j, d);
                    }
                    let c = 3 * j + axis;
                    for r in 0..nr {
                        zr[(r, c)] = (0..3).map(|q| du_col[r][q] * nrm[r][q]).sum();
                    }
                    fz.bs.set_strengths(&self.gamma0);
                    for (sgn, buf) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                        for (s, u) in u_pm.iter_mut().enumerate() {
                            for q in 0..3 {
                                u[q] = u_mid0[s][q] + sgn * du_mid[s][q];
                            }
                        }
                        compute_loads(&mut fz.loads, lat, &fz.bs, 0, &v_mid0, &u_pm, None, Some(&shed), p);
                        stack(&fz.loads, buf);
                    }
                    for i in 0..nf {
                        zf[(i, c)] = 0.5 * (plus[i] - minus[i]);
                    }
                }
            }
            out.residual.push(zr);
            out.force.push(zf);
        }
        out
    }
}
