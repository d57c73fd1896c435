//! Several lifting surfaces in one solver (docs/uvlm.md §16).
//!
//! A [`Uvlm`] holds one or more [`Surface`]s: each a structured lattice with its own stations,
//! [`crate::LatticeSpec`] (chordwise panels, spacing, hinge column, flaps) and its own wake shed
//! from its own trailing edge. All bound rings of all surfaces and all wakes induce on all
//! collocation points: one influence matrix over the global ring numbering (surface after
//! surface, [`Surface::rings`]), one solve. Loads come back per surface ([`Surface::loads`],
//! whose nodal loads follow that surface's grid, so its `column_loads_inplace` takes that
//! surface's station origins) and together ([`Uvlm::loads`], concatenated in surface order).

use crate::error::{Result, UvlmError};
use crate::lattice::Lattice;
use crate::loads::Loads;
use crate::params::UvlmParams;
use crate::solver::Uvlm;
use crate::station::{SpanStation, StationVelocity};
use crate::wake::Wake;
use std::ops::{Range, RangeInclusive};

/// One lifting surface of a [`Uvlm`]: its lattice, its wake and its loads of the last solve.
#[derive(Debug)]
pub struct Surface {
    pub(crate) lattice: Lattice,
    pub(crate) wake: Wake,
    pub(crate) loads: Loads,
    /// Its rings in the global numbering of the unknowns.
    pub(crate) rings: Range<usize>,
    /// The trailing-edge ring row of the last committed step (convected by `advance_wake`), the
    /// upstream edge of the next row shed.
    pub(crate) prev_te: Vec<[f64; 3]>,
    /// Work row of `n_spanwise + 1` nodes.
    pub(crate) row_buf: Vec<[f64; 3]>,
    /// Work row of `n_spanwise` circulations (the row shed next).
    pub(crate) gamma_row: Vec<f64>,
    /// Circulation of the newest wake row, per column (the trailing-edge segment's force).
    pub(crate) te_shed: Vec<f64>,
    /// The lattice version the current influence matrix was built with.
    pub(crate) aic_version: Option<u64>,
}

impl Surface {
    /// A surface with an empty wake of up to `n_wake_rows` rows, its rings numbered from `ring0`.
    pub(crate) fn new(lattice: Lattice, ring0: usize, n_wake_rows: usize) -> Self {
        let (m, n) = (lattice.n_chordwise(), lattice.n_spanwise());
        let prev_te = (0..=n).map(|j| lattice.ring_nodes()[lattice.node_index(m, j)]).collect();
        Self {
            wake: Wake::new(n, n_wake_rows),
            loads: Loads::default(),
            rings: ring0..ring0 + lattice.n_rings(),
            prev_te,
            row_buf: vec![[0.0; 3]; n + 1],
            gamma_row: vec![0.0; n],
            te_shed: vec![0.0; n],
            aic_version: None,
            lattice,
        }
    }

    /// The lattice (current geometry).
    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }
    /// The wake shed from this surface's trailing edge.
    pub fn wake(&self) -> &Wake {
        &self.wake
    }
    /// Loads on this surface of the last solve: nodal forces on its ring nodes (its grid's
    /// numbering), its strips and totals.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }
    /// Its rings in the global numbering of the unknowns: `&uvlm.gamma()[s.rings()]` are its
    /// circulations (local index `i·N + j`).
    pub fn rings(&self) -> Range<usize> {
        self.rings.clone()
    }
}

impl Uvlm {
    /// A solver for several lifting surfaces, numbered in the order given, each with an empty
    /// wake (impulsive start). One lattice gives exactly [`Uvlm::new`]'s solver.
    ///
    /// # Errors
    /// No lattice ([`UvlmError::NoSurfaces`]) or invalid parameters.
    pub fn with_surfaces(lattices: Vec<Lattice>, params: UvlmParams) -> Result<Self> {
        Self::from_lattices(lattices, params)
    }

    /// Number of lifting surfaces.
    pub fn n_surfaces(&self) -> usize {
        self.surfaces.len()
    }

    /// All surfaces, in their numbering.
    pub fn surfaces(&self) -> &[Surface] {
        &self.surfaces
    }

    /// Surface `k`.
    ///
    /// # Errors
    /// [`UvlmError::UnknownSurface`] if there is no surface `k`.
    pub fn surface(&self, k: usize) -> Result<&Surface> {
        self.surfaces.get(k).ok_or(UvlmError::UnknownSurface { surface: k, n_surfaces: self.surfaces.len() })
    }

    /// Move surface `k`'s lattice to new station frames and velocities (see
    /// [`Lattice::update_stations`]). Does not allocate.
    ///
    /// # Errors
    /// [`UvlmError::UnknownSurface`], or the lattice's error (wrong number of stations, …)
    /// wrapped in [`UvlmError::InSurface`] naming the surface; the lattice keeps its geometry.
    pub fn update_stations_of(
        &mut self,
        k: usize,
        stations: &[SpanStation],
        velocities: Option<&[StationVelocity]>,
    ) -> Result<()> {
        let s = self.surface_mut(k)?;
        s.lattice.update_stations(stations, velocities).map_err(|e| e.in_surface(k))
    }

    /// Set surface `k`'s grid nodes and velocities directly (see [`Lattice::set_grid`]).
    ///
    /// # Errors
    /// As [`Uvlm::update_stations_of`].
    pub fn set_grid_of(&mut self, k: usize, positions: &[[f64; 3]], velocities: &[[f64; 3]]) -> Result<()> {
        let s = self.surface_mut(k)?;
        s.lattice.set_grid(positions, velocities).map_err(|e| e.in_surface(k))
    }

    /// Hinge moment of the control surface covering grid columns `columns` of surface `k`, from
    /// the loads of the last solve, N·m, positive trailing edge down (see [`crate::hinge_moment`]).
    ///
    /// # Errors
    /// [`UvlmError::UnknownSurface`], or a column without a flap ([`UvlmError::NoFlap`] wrapped
    /// in [`UvlmError::InSurface`]).
    pub fn hinge_moment_of(&self, k: usize, columns: RangeInclusive<usize>) -> Result<f64> {
        let s = self.surface(k)?;
        crate::flap::hinge_moment(&s.lattice, &s.loads, columns).map_err(|e| e.in_surface(k))
    }

    fn surface_mut(&mut self, k: usize) -> Result<&mut Surface> {
        let n_surfaces = self.surfaces.len();
        self.surfaces.get_mut(k).ok_or(UvlmError::UnknownSurface { surface: k, n_surfaces })
    }

    /// The only surface, for the one-surface calls (`call`); an error with several.
    pub(crate) fn only_surface(&self, call: &'static str) -> Result<&Surface> {
        match self.surfaces.as_slice() {
            [s] => Ok(s),
            _ => Err(UvlmError::SeveralSurfaces { call, n_surfaces: self.surfaces.len() }),
        }
    }

    /// The only surface, mutably (see [`Uvlm::only_surface`]).
    pub(crate) fn only_surface_mut(&mut self, call: &'static str) -> Result<&mut Surface> {
        let n_surfaces = self.surfaces.len();
        match self.surfaces.as_mut_slice() {
            [s] => Ok(s),
            _ => Err(UvlmError::SeveralSurfaces { call, n_surfaces }),
        }
    }
}
