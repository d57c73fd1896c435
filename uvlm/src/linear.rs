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

//!
//! **Several surfaces** (docs/uvlm.md §16). A solver of several surfaces linearises into one
//! model over the solver's global numbering: rings surface after surface (rows and columns of
//! `A`, entries of the residual, columns of `F_Γ`, `F_Γ̇`), nodal forces over every surface's
//! ring nodes surface after surface (rows of every `F`), trailing-edge columns surface after
//! surface (the columns of `W_k` and `F_k`; `E` picks the global trailing-edge rings
//! [`LinearUvlm::te_rings`]). Every surface sheds its own frozen wake from its own trailing edge
//! along the free stream, row `k` of every surface with the same delay `τ_k`; all bound rings and
//! all wakes induce on all collocation and load points (a tail in the wing's wake). Where each
//! surface sits: [`LinearUvlm::blocks`] ([`SurfaceBlock`]); [`LinearUvlm::move_lattices`] and
//! [`LinearUvlm::evaluate_surfaces`] move and evaluate all surfaces. One surface is bit for bit the
//! one-surface model (test `one_surface_linear_is_bitwise_main`).

use nalgebra::{Complex, DMatrix};

use crate::error::{Result, UvlmError};
use crate::lattice::Lattice;
use crate::linear_stack::{Frozen, SurfaceBlock, stacked_loads};
use crate::params::UvlmParams;
use crate::station::{SpanStation, StationVelocity};
use crate::wake::Wake;

/// The frozen wake of the linear model: straight ring rows along the free stream from the
/// trailing-edge ring row (of every surface).
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

    pub(crate) fn validate(&self) -> Result<()> {
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

/// The linearised UVLM about a steady solution (see the module docs), of one or several
/// surfaces. Matrices act on the ring circulations in the solver's global ring order (surface
/// after surface); nodal forces are stacked `[F_0x, F_0y, F_0z, F_1x, …]` over the ring nodes
/// ([`Lattice::ring_nodes`]) of every surface, surface after surface: the points where
/// [`Loads::nodal`](crate::Loads::nodal) acts. [`LinearUvlm::blocks`] says where each surface is.
#[derive(Debug, Clone)]
pub struct LinearUvlm {
    pub(crate) params: UvlmParams,
    pub(crate) lattices: Vec<Lattice>,
    /// The frozen wake of each surface.
    pub(crate) wakes: Vec<Wake>,
    pub(crate) blocks: Vec<SurfaceBlock>,
    pub(crate) closure: Option<[f64; 3]>,
    pub(crate) gamma0: Vec<f64>,
    /// Influence matrix `A` (n_rings × n_rings): normal velocity at collocation point p per unit
    /// circulation of bound ring r (unsteady mode: the trailing-edge edge is a bound filament).
    pub aic: DMatrix<f64>,
    /// Delay `τ_k` of each wake row, s (the same for every surface).
    pub row_delays: Vec<f64>,
    /// `W_k` (n_rings × n_columns, `n_columns = Σ N_s` over the surfaces): normal velocity at the
    /// collocation points per unit circulation of wake ring `(k, j)` (column `j` in the stacked
    /// trailing-edge column numbering, [`SurfaceBlock::te_columns`]).
    pub row_normalwash: Vec<DMatrix<f64>>,
    /// `F_Γ` (3·n_nodes × n_rings).
    pub force_gamma: DMatrix<f64>,
    /// `F_Γ̇` (3·n_nodes × n_rings): the unsteady term ρ·A·n·dΓ/dt.
    pub force_gamma_dot: DMatrix<f64>,
    /// `F_k` (3·n_nodes × n_columns): nodal forces per unit circulation of wake ring `(k, j)`
    /// (zero when `Γ₀ = 0`).
    pub force_row: Vec<DMatrix<f64>>,
    /// `S_Γ` (3·n_strips × n_rings): the force on every strip ([`Loads::strip`](crate::Loads::strip),
    /// panel column `j`; stacked in the trailing-edge column numbering
    /// [`SurfaceBlock::te_columns`]) per unit `δΓ`, as `F_Γ` is the nodal forces'.
    pub strip_gamma: DMatrix<f64>,
    /// `S_Γ̇` (3·n_strips × n_rings): the strips' part of the unsteady term.
    pub strip_gamma_dot: DMatrix<f64>,
    /// `S_k` (3·n_strips × n_columns): the strip forces per unit circulation of wake ring `(k, j)`.
    pub strip_row: Vec<DMatrix<f64>>,
    /// Global ring index of the trailing-edge ring of each trailing-edge column (`E`), surface
    /// after surface.
    pub te_rings: Vec<usize>,
    /// Residual of the reference state (the steady solution in the frozen wake), m/s; zero up to
    /// the difference between the frozen wake and the steady solver's semi-infinite legs.
    pub reference_residual: Vec<f64>,
    /// Nodal forces of the reference state, N.
    pub reference_forces: Vec<f64>,
    /// Strip forces of the reference state (3·n_strips), N.
    pub reference_strips: Vec<f64>,
}

impl LinearUvlm {
    /// Circulation of the frozen wakes' newest row, per trailing-edge column (the reference
    /// state's shed row), surface after surface.
    pub(crate) fn reference_shed(&self) -> Vec<f64> {
        self.wakes
            .iter()
            .flat_map(|w| (0..w.n_spanwise()).map(|j| if w.n_rows() > 0 { w.gamma(0, j) } else { 0.0 }))
            .collect()
    }

    /// The reference lattice (its geometry at the steady solution) of a model of one surface;
    /// with several, the first surface's (as [`Uvlm::lattice`](crate::Uvlm::lattice)): use
    /// [`LinearUvlm::lattices`] there.
    pub fn lattice(&self) -> &Lattice {
        &self.lattices[0]
    }
    /// The reference lattices of all surfaces, in their numbering. To move them with a
    /// structure whose stations are one flat list, surface after surface, clone them once,
    /// move them all and evaluate them together (or update each lattice from its own range of
    /// stations, [`Lattice::update_stations`]):
    ///
    /// ```text
    /// let mut lats = lin.lattices().to_vec();
    /// lin.move_lattices(&mut lats, &stations, Some(&velocities))?;
    /// let (residual, forces) = lin.evaluate_surfaces(&lats)?;
    /// let of_k = &forces[lin.blocks()[k].forces()]; // surface k's nodal forces, its grid's order
    /// let te: Vec<[f64; 3]> = lats.iter().flat_map(|l| l.trailing_edge_nodes()).copied().collect();
    /// ```
    pub fn lattices(&self) -> &[Lattice] {
        &self.lattices
    }
    /// Number of lifting surfaces.
    pub fn n_surfaces(&self) -> usize {
        self.lattices.len()
    }
    /// Where each surface sits in the stacked numbering, in the surfaces' order.
    pub fn blocks(&self) -> &[SurfaceBlock] {
        &self.blocks
    }
    /// Where surface `k` sits in the stacked numbering.
    ///
    /// # Errors
    /// [`UvlmError::UnknownSurface`] if there is no surface `k`.
    pub fn block(&self, k: usize) -> Result<&SurfaceBlock> {
        self.blocks.get(k).ok_or(UvlmError::UnknownSurface { surface: k, n_surfaces: self.blocks.len() })
    }
    /// The steady circulations `Γ₀` (all surfaces).
    pub fn gamma0(&self) -> &[f64] {
        &self.gamma0
    }
    /// The parameters.
    pub fn params(&self) -> &UvlmParams {
        &self.params
    }
    /// Number of bound rings (all surfaces).
    pub fn n_rings(&self) -> usize {
        self.gamma0.len()
    }
    /// Number of stacked nodal force components (3 per ring node, all surfaces).
    pub fn n_force(&self) -> usize {
        self.blocks.last().map_or(0, |b| 3 * b.nodes.end)
    }
    /// Number of trailing-edge nodes, `Σ (N_s + 1)` over the surfaces: the wake node columns of
    /// [`WakeNodeDerivatives`](crate::WakeNodeDerivatives) are `3 × n_te_nodes` (each surface's
    /// trailing edge stacked, [`Lattice::trailing_edge_nodes`]; a node where two surfaces meet
    /// counts once per surface).
    pub fn n_te_nodes(&self) -> usize {
        self.blocks.last().map_or(0, |b| b.te_nodes.end)
    }

    /// Non-penetration residual `(V_ext − ẋ_c + u_ind)·n` at the collocation points (m/s) and
    /// stacked nodal forces (N) of `lattice` (the reference lattice moved, with its node
    /// velocities) with the reference circulations held: the bound rings carry `Γ₀`, the wake
    /// rows keep their geometry and `Γ_TE,0`, and its first row stays attached to the moved
    /// trailing edge. Differentiating this along a motion gives the geometric terms. A model of
    /// one surface; [`LinearUvlm::evaluate_surfaces`] for several.
    ///
    /// # Errors
    /// A model of several surfaces ([`UvlmError::SeveralSurfaces`]); `lattice` with other
    /// dimensions than the reference.
    pub fn evaluate(&self, lattice: &Lattice) -> Result<(Vec<f64>, Vec<f64>)> {
        if self.lattices.len() != 1 {
            return Err(UvlmError::SeveralSurfaces { call: "evaluate", n_surfaces: self.lattices.len() });
        }
        self.evaluate_surfaces(std::slice::from_ref(lattice))
    }

    /// Move `lattices` (the reference lattices, [`LinearUvlm::lattices`], or copies of them
    /// moved before) to `stations` (with `velocities`; `None` = at rest): one flat list of every
    /// surface's stations, surface after surface, surface k's being
    /// [`SurfaceBlock::te_nodes`] (its `N_k + 1` stations; a station where two surfaces meet
    /// comes once per surface). Then [`LinearUvlm::evaluate_surfaces`] evaluates them. Does not
    /// allocate.
    ///
    /// # Errors
    /// Another number of lattices than surfaces ([`UvlmError::LengthMismatch`] of
    /// `"lattices"`), of stations or velocities than `Σ (N_k + 1)` (of `"stations"`,
    /// `"station velocities"`), or a lattice's own error (in [`UvlmError::InSurface`] with
    /// several surfaces); the lattices before the failing one are moved.
    pub fn move_lattices(
        &self,
        lattices: &mut [Lattice],
        stations: &[SpanStation],
        velocities: Option<&[StationVelocity]>,
    ) -> Result<()> {
        let n_surfaces = self.lattices.len();
        if lattices.len() != n_surfaces {
            return Err(UvlmError::LengthMismatch { what: "lattices", expected: n_surfaces, got: lattices.len() });
        }
        let n = self.n_te_nodes();
        if stations.len() != n {
            return Err(UvlmError::LengthMismatch { what: "stations", expected: n, got: stations.len() });
        }
        if let Some(v) = velocities
            && v.len() != n
        {
            return Err(UvlmError::LengthMismatch { what: "station velocities", expected: n, got: v.len() });
        }
        for (k, (lat, b)) in lattices.iter_mut().zip(&self.blocks).enumerate() {
            let r = b.te_nodes.clone();
            let moved = lat.update_stations(&stations[r.clone()], velocities.map(|v| &v[r]));
            moved.map_err(|e| if n_surfaces == 1 { e } else { e.in_surface(k) })?;
        }
        Ok(())
    }

    /// [`LinearUvlm::evaluate`] for every surface at once: `lattices` are the reference lattices
    /// ([`LinearUvlm::lattices`]) moved, one per surface in their order. Every surface's wake
    /// stays attached to its own moved trailing edge, and every surface and wake induces on all.
    /// The residual is over all rings (global order), the nodal forces stacked over all
    /// surfaces' ring nodes ([`SurfaceBlock::forces`]).
    ///
    /// # Errors
    /// Another number of lattices than surfaces ([`UvlmError::LengthMismatch`] of
    /// `"lattices"`), or a lattice with other dimensions than its reference
    /// ([`UvlmError::LengthMismatch`] of `"lattice rings"`, in [`UvlmError::InSurface`] with
    /// several surfaces).
    pub fn evaluate_surfaces(&self, lattices: &[Lattice]) -> Result<(Vec<f64>, Vec<f64>)> {
        self.evaluate_with_strips(lattices).map(|(r, f, _)| (r, f))
    }

    /// [`LinearUvlm::evaluate_surfaces`] with the strip forces ([`Loads::strip`](crate::Loads::strip)
    /// of every surface, stacked 3 per panel column in the trailing-edge column numbering
    /// [`SurfaceBlock::te_columns`]) as the third vector.
    ///
    /// # Errors
    /// As [`LinearUvlm::evaluate_surfaces`].
    pub fn evaluate_with_strips(&self, lattices: &[Lattice]) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        self.check_lattices(lattices)?;
        let mut fz = Frozen::default();
        fz.build(lattices, &self.gamma0, &self.wakes, self.closure, &self.params);
        fz.induce_all();
        fz.external(self.params.v_inf);
        let mut residual = vec![0.0; self.n_rings()];
        for (lat, b) in lattices.iter().zip(&self.blocks) {
            let (nrm, cv) = (lat.normals(), lat.collocation_velocities());
            for (r, g) in b.rings.clone().enumerate() {
                residual[g] = (0..3).map(|q| (fz.v_col[g][q] - cv[r][q] + fz.u_col[g][q]) * nrm[r][q]).sum();
            }
        }
        let shed = self.reference_shed();
        let mut forces = vec![0.0; self.n_force()];
        let mut strips = vec![0.0; 3 * self.te_rings.len()];
        let (v, u) = (&fz.v_mid, &fz.u_mid);
        let out = (&mut forces[..], Some(&mut strips[..]));
        stacked_loads(&mut fz.loads, &fz.bs, lattices, &self.blocks, v, u, None, Some(&shed), &self.params, out);
        Ok((residual, forces, strips))
    }

    /// `lattices` has one lattice per surface, each of its reference's dimensions.
    fn check_lattices(&self, lattices: &[Lattice]) -> Result<()> {
        let n_surfaces = self.lattices.len();
        if lattices.len() != n_surfaces {
            return Err(UvlmError::LengthMismatch { what: "lattices", expected: n_surfaces, got: lattices.len() });
        }
        for (k, (lat, own)) in lattices.iter().zip(&self.lattices).enumerate() {
            if lat.n_rings() != own.n_rings() || lat.n_spanwise() != own.n_spanwise() {
                let e =
                    UvlmError::LengthMismatch { what: "lattice rings", expected: own.n_rings(), got: lat.n_rings() };
                return Err(if n_surfaces == 1 { e } else { e.in_surface(k) });
            }
        }
        Ok(())
    }
}

/// `base + Σ_k e^{−s τ_k} M_k E`: a wake-row sum spread onto the trailing-edge ring columns
/// `te_rings` (`E`), for any row count of `base` and the `M_k` (same rows, one column per
/// trailing-edge column).
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

    /// `S_Γ + s S_Γ̇ + Σ_k e^{−sτ_k} S_k E` (3·n_strips × n_rings): strip forces per unit `δΓ`.
    pub fn strip_force_matrix(&self, s: Complex<f64>) -> DMatrix<Complex<f64>> {
        let base = self.strip_gamma.map(Complex::from) + self.strip_gamma_dot.map(|x| s * x);
        with_wake(&base, &self.strip_row, &self.row_delays, &self.te_rings, s)
    }
}
