//! The stacked numbering of a linear UVLM of several surfaces, and the evaluation of the
//! residual, induced velocities and loads with frozen circulations over all surfaces at once
//! (docs/uvlm.md §13, §16).
//!
//! Rings, ring nodes (nodal forces), trailing-edge columns (wake ring columns), trailing-edge
//! nodes (wake nodes) and load segments' midpoints are numbered surface after surface, each
//! surface one contiguous [`SurfaceBlock`]. All bound filaments of all surfaces and every
//! surface's frozen wake induce on all collocation points and all midpoints. One surface gives
//! exactly the one-surface sets, points and sums.

use std::ops::Range;

use crate::aic::{BoundSystem, TrailingEdge, WakePart, append_known_wake};
use crate::axis_extension::{ExtensionLayout, SurfaceLayout, correct_axis_extensions, correct_wake_extensions};
use crate::biot_savart::{Filaments, NodeBlock};
use crate::flow::Flow;
use crate::images::append_images;
use crate::induce::{Points, induced_velocity_inplace};
use crate::lattice::Lattice;
use crate::loads::{Loads, compute_loads};
use crate::params::UvlmParams;
use crate::scratch::ScratchPool;
use crate::wake::Wake;

/// Where one surface sits in the stacked vectors and matrices of a
/// [`LinearUvlm`](crate::LinearUvlm): every range is of global indices, surface after surface.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SurfaceBlock {
    /// Its rings (`M_k·N_k`, local index `i·N_k + j`): its entries of `Γ₀`, of the residual and
    /// its rows and columns of `A`, its columns of `F_Γ` and `F_Γ̇`; the same range as
    /// [`Surface::rings`](crate::Surface::rings) of the solver it was linearised from.
    pub rings: Range<usize>,
    /// Its ring nodes (`(M_k + 1)·(N_k + 1)`, its lattice's [`Lattice::ring_nodes`] order): the
    /// nodal forces of node `n` are the stacked components `3n .. 3n + 3`, so the surface's are
    /// [`SurfaceBlock::forces`].
    pub nodes: Range<usize>,
    /// Its trailing-edge columns (`N_k`): its columns of every `W_k` and `F_k`, its entries of
    /// `te_rings`.
    pub te_columns: Range<usize>,
    /// Its trailing-edge nodes (`N_k + 1`, [`Lattice::trailing_edge_nodes`] order), where its
    /// wake's node columns start: node `t` is column `3t + axis` of
    /// [`WakeNodeDerivatives`](crate::WakeNodeDerivatives). One per grid column, so also its
    /// stations in a flat list of every surface's stations
    /// ([`LinearUvlm::move_lattices`](crate::LinearUvlm::move_lattices)).
    pub te_nodes: Range<usize>,
    /// Its load segments' midpoints (columns of [`LinearGust::force`](crate::LinearGust::force),
    /// entries of its `midpoint_delays`).
    pub midpoints: Range<usize>,
}

impl SurfaceBlock {
    /// Its stacked nodal force components, `3·nodes.start .. 3·nodes.end`.
    pub fn forces(&self) -> Range<usize> {
        3 * self.nodes.start..3 * self.nodes.end
    }
}

/// The blocks of `lats` in the order given: `te_segment_force` says whether the trailing-edge
/// segments carry loads (their midpoints count).
pub(crate) fn blocks_of(lats: &[Lattice], te_segment_force: bool) -> Vec<SurfaceBlock> {
    let (mut ring, mut node, mut col, mut te, mut mid) = (0, 0, 0, 0, 0);
    lats.iter()
        .map(|lat| {
            let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
            // Unsteady mode: spanwise rows, chordwise columns, then the trailing-edge edge.
            let n_mid = m * n + m * (n + 1) + if te_segment_force { n } else { 0 };
            let b = SurfaceBlock {
                rings: ring..ring + lat.n_rings(),
                nodes: node..node + lat.ring_nodes().len(),
                te_columns: col..col + n,
                te_nodes: te..te + n + 1,
                midpoints: mid..mid + n_mid,
            };
            (ring, node, col, te, mid) = (b.rings.end, b.nodes.end, b.te_columns.end, b.te_nodes.end, b.midpoints.end);
            b
        })
        .collect()
}

/// Nodal forces of `loads` stacked into `out`.
pub(crate) fn stack(loads: &Loads, out: &mut [f64]) {
    for (k, f) in loads.nodal.iter().enumerate() {
        out[3 * k..3 * k + 3].copy_from_slice(f);
    }
}

/// Strip forces of `loads` ([`Loads::strip`]) stacked into `out` (3 per panel column).
pub(crate) fn stack_strips(loads: &Loads, out: &mut [f64]) {
    for (k, f) in loads.strip.iter().enumerate() {
        out[3 * k..3 * k + 3].copy_from_slice(f);
    }
}

/// Work buffers of an evaluation with frozen circulations, over all surfaces.
#[derive(Default)]
pub(crate) struct Frozen {
    pub(crate) bs: BoundSystem,
    pub(crate) known: Filaments,
    pub(crate) col: Points,
    pub(crate) mid: Points,
    pub(crate) u_col: Vec<[f64; 3]>,
    pub(crate) v_col: Vec<[f64; 3]>,
    pub(crate) u_mid: Vec<[f64; 3]>,
    pub(crate) v_mid: Vec<[f64; 3]>,
    /// The Biot–Savart loops' workspace (serial here).
    pub(crate) blocks: ScratchPool<NodeBlock>,
    pub(crate) loads: Loads,
    /// Where the load points and their collinear bound filaments sit (axis_extension.rs).
    pub(crate) ext: ExtensionLayout,
}

impl Frozen {
    /// Bound filaments of `lats` (unsteady mode, global ring numbering) with strengths `gamma`,
    /// the known wake of every surface (`wakes[k]` attached to surface k's trailing edge, then
    /// the images of all), the collocation points and the load segments' midpoints, surface
    /// after surface.
    pub(crate) fn build(
        &mut self,
        lats: &[Lattice],
        gamma: &[f64],
        wakes: &[Wake],
        closure: Option<[f64; 3]>,
        p: &UvlmParams,
    ) {
        self.bs.build_surfaces(lats.iter(), TrailingEdge::Unsteady, &p.bound_core, &p.images);
        self.bs.set_strengths(gamma);
        self.known.clear();
        for (lat, wake) in lats.iter().zip(wakes) {
            let te = lat.trailing_edge_nodes();
            append_known_wake(&mut self.known, te, wake, closure, (&p.wake_core, &p.bound_core), WakePart::All);
        }
        append_images(&mut self.known, &p.images);
        self.col.clear();
        for lat in lats {
            for c in lat.collocation() {
                self.col.push(*c);
            }
        }
        self.mid.clear();
        self.ext.surfaces.clear();
        let n_copies = crate::images::copy_signs(p.images.len()).len();
        self.ext.n_copies = n_copies;
        self.ext.n_base_seg = self.bs.fil.n_segments() / n_copies;
        self.ext.n_base_leg = 0;
        for k in 0..lats.len() {
            let r = self.bs.surface(k);
            let n_mid = if p.te_segment_force { r.n_lattice_seg } else { r.n_lattice_seg - r.n_te_seg };
            self.ext.surfaces.push(SurfaceLayout {
                seg0: r.seg0,
                n_load: n_mid,
                n_lattice_seg: r.n_lattice_seg,
                m: lats[k].n_chordwise(),
                n: lats[k].n_spanwise(),
                leg0: 0,
                finite: false,
            });
            for s in r.seg0..r.seg0 + n_mid {
                let (a, b) = self.bs.fil.segment_nodes(s);
                let (pa, pb) = (self.bs.fil.node(a as usize), self.bs.fil.node(b as usize));
                self.mid.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])]);
            }
        }
    }

    /// Velocity induced by `sets` at the collocation points (into `u_col`) and midpoints
    /// (`u_mid`).
    pub(crate) fn induce(&mut self, sets: &[&Filaments]) {
        self.u_col.resize(self.col.len(), [0.0; 3]);
        self.u_mid.resize(self.mid.len(), [0.0; 3]);
        induced_velocity_inplace(sets, &self.col, &mut self.u_col, crate::Parallel::Off, &mut self.blocks);
        induced_velocity_inplace(sets, &self.mid, &mut self.u_mid, crate::Parallel::Off, &mut self.blocks);
    }

    /// Velocity induced by the bound filaments and the known wake together.
    pub(crate) fn induce_all(&mut self) {
        let bsf = std::mem::take(&mut self.bs.fil);
        let known = std::mem::take(&mut self.known);
        self.induce(&[&bsf, &known]);
        self.bs.fil = bsf;
        self.correct_bound_at_midpoints();
        self.correct_wake_at_midpoints(&known);
        self.known = known;
    }

    /// The bound filaments' regular terms on their axis extensions at the midpoints, as the
    /// solver's loads take them (docs/uvlm.md §3).
    pub(crate) fn correct_bound_at_midpoints(&mut self) {
        correct_axis_extensions(&self.bs.fil, &self.ext, &self.mid, &mut self.u_mid, crate::Parallel::Off, false);
    }

    /// The wake filaments `wake`'s regular terms at the chordwise midpoints, as the solver's
    /// steady legs and time march take them (docs/uvlm.md §3).
    pub(crate) fn correct_wake_at_midpoints(&mut self, wake: &Filaments) {
        correct_wake_extensions(wake, &self.ext, &self.mid, &mut self.u_mid);
    }

    /// The free stream `v_inf` at the collocation points (`v_col`) and midpoints (`v_mid`).
    pub(crate) fn external(&mut self, v_inf: [f64; 3]) {
        let flow = Flow::new(v_inf);
        self.v_col.resize(self.col.len(), [0.0; 3]);
        self.v_mid.resize(self.mid.len(), [0.0; 3]);
        flow.velocity_inplace(&self.col, 0.0, &mut self.v_col);
        flow.velocity_inplace(&self.mid, 0.0, &mut self.v_mid);
    }
}

/// The nodal forces of every surface, stacked into `out` (`3·Σ nodes`), from the bound system
/// `bs` as it carries its strengths: `v_mid`, `u_mid` at all midpoints (stacked), `gamma_dot`
/// over all rings and `shed` over all trailing-edge columns (as [`compute_loads`] takes them per
/// surface); with `strips`, the strip forces too (3 per panel column, the stacked trailing-edge
/// column numbering [`SurfaceBlock::te_columns`]).
#[allow(clippy::too_many_arguments)] // the load routine's inputs, over the stacked surfaces
pub(crate) fn stacked_loads(
    loads: &mut Loads,
    bs: &BoundSystem,
    lats: &[Lattice],
    blocks: &[SurfaceBlock],
    v_mid: &[[f64; 3]],
    u_mid: &[[f64; 3]],
    gamma_dot: Option<&[f64]>,
    shed: Option<&[f64]>,
    p: &UvlmParams,
    (out, mut strips): (&mut [f64], Option<&mut [f64]>),
) {
    for (k, (lat, b)) in lats.iter().zip(blocks).enumerate() {
        surface_loads(loads, bs, (k, lat, b), v_mid, u_mid, gamma_dot, shed, p, (&mut *out, strips.as_deref_mut()));
    }
}

/// Surface `k`'s part of [`stacked_loads`]: its nodal forces into its entries of `out` (and its
/// strip forces into its entries of `strips`), the others untouched.
#[allow(clippy::too_many_arguments)] // the load routine's inputs, over the stacked surfaces
pub(crate) fn surface_loads(
    loads: &mut Loads,
    bs: &BoundSystem,
    (k, lat, b): (usize, &Lattice, &SurfaceBlock),
    v_mid: &[[f64; 3]],
    u_mid: &[[f64; 3]],
    gamma_dot: Option<&[f64]>,
    shed: Option<&[f64]>,
    p: &UvlmParams,
    (out, strips): (&mut [f64], Option<&mut [f64]>),
) {
    let (v, u) = (&v_mid[b.midpoints.clone()], &u_mid[b.midpoints.clone()]);
    let gd = gamma_dot.map(|g| &g[b.rings.clone()]);
    let sh = shed.map(|s| &s[b.te_columns.clone()]);
    compute_loads(loads, lat, bs, k, v, u, gd, sh, p);
    stack(loads, &mut out[b.forces()]);
    if let Some(st) = strips {
        stack_strips(loads, &mut st[3 * b.te_columns.start..3 * b.te_columns.end]);
    }
}

/// The filaments of wake ring `(k, j)` with unit circulation, exactly as
/// [`crate::aic::build_known_wake`] builds them for a wake in which only that ring circulates:
/// its upstream spanwise edge (+1; the bound core on the trailing edge), its downstream edge
/// (−1; replaced by the closure legs on the last row of a closed wake) and its two chordwise
/// edges, with images. Only the ring's own corners are nodes, so an evaluation costs four
/// filaments. `te` is the trailing edge the wake hangs from.
pub(crate) fn unit_wake_ring(
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
