//! The bound system: unit-strength filaments of the lattice (each shared edge once, with its
//! ring incidences), the aerodynamic influence coefficient (AIC) matrix and the known wake.
//!
//! Unknowns are the bound ring circulations Γ. Unsteady solves use the explicit Kutta condition
//! (as SHARPy and Ptera Software): each step the trailing-edge circulation of the previous step
//! is shed into a new wake row, so the whole wake is known and the trailing-edge edge of the rings
//! is a bound filament of net strength Γ_w0 − Γ_TE (which carries the circulation shed during the
//! step). Steady solves close the rings with semi-infinite legs from the trailing-edge nodes along
//! the free stream (the trailing-edge edge then cancels), or with a finite frozen wake: legs of a
//! given length along the free stream and a spanwise segment joining their far ends, each strip's
//! wake one ring carrying its trailing-edge circulation (the steady state of an unclosed wake of
//! straight rows). Edge net strengths
//! (segment directions along increasing indices):
//! spanwise `(i, j)→(i, j+1)`: `Γ(i, j) − Γ(i−1, j)`; chordwise `(i, j)→(i+1, j)`:
//! `Γ(i, j−1) − Γ(i, j)`. The AIC row of collocation point `c_p` is
//!
//! $$ A_{pr} = \sum_{f \ni r} s_{fr}\, u_f(c_p)\cdot n_p ,$$
//!
//! with `s_fr = ±1` the incidence of filament `f` on ring `r` (image copies included).

use crate::biot_savart::{CoreModel, Filaments, LANES, NodeBlock, fill_block, influence_block, load_lanes};
use crate::images::{ImagePlane, append_images, copy_signs};
use crate::induce::{Points, use_threads};
use crate::lattice::Lattice;
use crate::params::Parallel;
use crate::scratch::{DIRECT_CHUNKS_PER_THREAD, ScratchPool};
use crate::wake::Wake;

const NONE: u32 = u32::MAX;

/// How the bound system ends at the trailing edge.
#[derive(Debug, Clone, Copy)]
pub(crate) enum TrailingEdge {
    /// Unsteady: the trailing-edge spanwise edge of the rings is a bound filament; the wake
    /// (explicit Kutta condition, rows carrying the circulations shed at earlier steps) is known.
    Unsteady,
    /// Steady: semi-infinite legs along the unit vector carry the trailing-edge circulations
    /// (the trailing-edge spanwise edge cancels).
    Steady([f64; 3]),
    /// Steady with a finite frozen wake: legs of length `length` (m) along the unit vector `dir`
    /// from the trailing-edge nodes, and spanwise segments joining their far ends, which close
    /// each strip's wake ring (net strength −Γ_TE of the strip).
    SteadyFinite {
        /// Unit direction of the wake.
        dir: [f64; 3],
        /// Wake length, m.
        length: f64,
    },
}

/// Where one surface's filaments and unknowns sit in a [`BoundSystem`] of several surfaces.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct SurfaceRange {
    /// Index of the surface's first segment: its lattice segments are
    /// `seg0 .. seg0 + n_lattice_seg` (spanwise rows, chordwise columns, then the trailing-edge
    /// edge in unsteady mode), followed by its finite steady wake if any.
    pub(crate) seg0: usize,
    /// Number of its lattice segments (they carry loads).
    pub(crate) n_lattice_seg: usize,
    /// The last `n_te_seg` of its lattice segments are the trailing-edge edge (unsteady mode only).
    pub(crate) n_te_seg: usize,
    /// Index of its first node in the filament set (its ring nodes, in the lattice's order).
    pub(crate) node0: usize,
}

/// Unit-strength bound filaments with incidences, of one or several surfaces (lattices) in one
/// global numbering: surface `k`'s rings are the unknowns `ring0 .. ring0 + n_rings` (surface
/// after surface), its nodes and segments one contiguous block each ([`SurfaceRange`]); the legs
/// of all surfaces follow all segments, and the image copies follow everything.
#[derive(Debug, Clone, Default)]
pub(crate) struct BoundSystem {
    /// Filaments (image copies appended); strengths are unit × copy sign until
    /// [`BoundSystem::set_strengths`] is called.
    pub(crate) fil: Filaments,
    /// Ring incidences of the base segments, then (`inc_leg`) of the base legs.
    inc: Vec<[(u32, f64); 2]>,
    inc_leg: Vec<[(u32, f64); 2]>,
    /// The incidences of every filament, image copies included, in the filaments' order (the
    /// AIC's ring sums read them per block of points: no index arithmetic per filament).
    inc_all: Vec<[(u32, f64); 2]>,
    n_base_seg: usize,
    n_base_leg: usize,
    /// Per surface: where its filaments and rings are.
    surfaces: Vec<SurfaceRange>,
    n_copies: usize,
    n_planes: usize,
    base_gamma: Vec<f64>,
}

impl BoundSystem {
    /// Rebuild for the current geometry of one lattice (the tests' shorthand of
    /// [`BoundSystem::build_surfaces`]).
    #[cfg(test)]
    pub(crate) fn build(&mut self, lat: &Lattice, te: TrailingEdge, core: &CoreModel, planes: &[ImagePlane]) {
        self.build_surfaces(std::iter::once(lat), te, core, planes);
    }

    /// Rebuild for the current geometry of several lattices (surfaces), numbered in the order
    /// given. One lattice gives exactly the filaments of [`BoundSystem::build`]. Does not
    /// allocate once warm.
    pub(crate) fn build_surfaces<'a>(
        &mut self,
        lats: impl Iterator<Item = &'a Lattice>,
        te: TrailingEdge,
        core: &CoreModel,
        planes: &[ImagePlane],
    ) {
        self.fil.clear();
        self.inc.clear();
        self.inc_leg.clear();
        self.surfaces.clear();
        let mut ring0 = 0;
        for lat in lats {
            let range = self.push_surface(lat, ring0, te, core);
            self.surfaces.push(range);
            ring0 += lat.n_rings();
        }
        self.n_base_seg = self.fil.n_segments();
        self.n_base_leg = self.fil.n_legs();
        self.n_planes = planes.len();
        self.n_copies = copy_signs(planes.len()).len();
        append_images(&mut self.fil, planes);
        self.inc_all.clear();
        for f in 0..self.n_filaments() {
            let (b, _) = self.base_of(f);
            self.inc_all.push(*self.incidences(b));
        }
    }

    /// Where surface `k`'s filaments and rings are.
    pub(crate) fn surface(&self, k: usize) -> &SurfaceRange {
        &self.surfaces[k]
    }

    /// Append one lattice's nodes, segments and legs, its rings numbered from `ring0`.
    fn push_surface(&mut self, lat: &Lattice, ring0: usize, te: TrailingEdge, core: &CoreModel) -> SurfaceRange {
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let nc = n + 1;
        let fil = &mut self.fil;
        let node0 = fil.n_nodes();
        let seg0 = fil.n_segments();
        for p in lat.ring_nodes() {
            fil.push_node(*p);
        }
        let ring = |i: usize, j: usize| (ring0 + i * n + j) as u32;
        let node = |i: usize, j: usize| (node0 + i * nc + j) as u32;
        let nodes = lat.ring_nodes();
        // Distance of two lattice nodes given by their local indices.
        let dist = |a: usize, b: usize| {
            let (p, q) = (nodes[a], nodes[b]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let local = |i: usize, j: usize| i * nc + j;
        // Local chordwise panel length of a spanwise edge at node row i, column j..j+1.
        let chord_scale = |i: usize, j: usize| {
            let (r0, r1) = if i < m { (i, i + 1) } else { (i - 1, i) };
            0.5 * (dist(local(r0, j), local(r1, j)) + dist(local(r0, j + 1), local(r1, j + 1)))
        };
        // Spanwise lattice edges, rows 0..M−1.
        for i in 0..m {
            for j in 0..n {
                fil.push_segment_scaled(node(i, j), node(i, j + 1), 1.0, core, chord_scale(i, j));
                let prev = if i > 0 { (ring(i - 1, j), -1.0) } else { (NONE, 0.0) };
                self.inc.push([(ring(i, j), 1.0), prev]);
            }
        }
        // Chordwise lattice edges.
        for i in 0..m {
            for j in 0..nc {
                fil.push_segment(node(i, j), node(i + 1, j), 1.0, core);
                let right = if j < n { (ring(i, j), -1.0) } else { (NONE, 0.0) };
                let left = if j > 0 { (ring(i, j - 1), 1.0) } else { (NONE, 0.0) };
                self.inc.push([right, left]);
            }
        }
        let mut range = SurfaceRange { seg0, n_lattice_seg: fil.n_segments() - seg0, n_te_seg: 0, node0 };
        let te_ring = |j: usize| ring(m - 1, j);
        // Incidences of a trailing leg from trailing-edge node j.
        let leg_inc = |j: usize| {
            let right = if j < n { (te_ring(j), -1.0) } else { (NONE, 0.0) };
            let left = if j > 0 { (te_ring(j - 1), 1.0) } else { (NONE, 0.0) };
            [right, left]
        };
        match te {
            TrailingEdge::Unsteady => {
                // Trailing-edge edge (M, j)→(M, j+1): −Γ_TE (the shed row's +Γ_w0 is in the known wake).
                for j in 0..n {
                    fil.push_segment_scaled(node(m, j), node(m, j + 1), 1.0, core, chord_scale(m, j));
                    self.inc.push([(te_ring(j), -1.0), (NONE, 0.0)]);
                }
                range.n_lattice_seg = fil.n_segments() - seg0;
                range.n_te_seg = n;
            }
            TrailingEdge::Steady(dir) => {
                for j in 0..nc {
                    let len = dist(local(m - 1, j), local(m, j));
                    fil.push_leg(node(m, j), dir, 1.0, core, len);
                    self.inc_leg.push(leg_inc(j));
                }
            }
            TrailingEdge::SteadyFinite { dir, length } => {
                // Far ends of the legs: node (m, j) + length·dir, after the lattice's nodes.
                let far0 = fil.n_nodes() as u32;
                for j in 0..nc {
                    let p = nodes[local(m, j)];
                    fil.push_node([p[0] + length * dir[0], p[1] + length * dir[1], p[2] + length * dir[2]]);
                }
                let far = |j: usize| far0 + j as u32;
                // Legs (m, j) → far(j), with the incidences and core of the semi-infinite legs
                // (sized by the trailing-edge panel's chordwise length).
                for j in 0..nc {
                    let len = dist(local(m - 1, j), local(m, j));
                    fil.push_segment_scaled(node(m, j), far(j), 1.0, core, len);
                    self.inc.push(leg_inc(j));
                }
                // Closing spanwise segments far(j) → far(j+1): the downstream edge of strip j's
                // wake ring, −Γ_TE(j).
                for j in 0..n {
                    fil.push_segment_scaled(far(j), far(j + 1), 1.0, core, chord_scale(m, j));
                    self.inc.push([(te_ring(j), -1.0), (NONE, 0.0)]);
                }
            }
        }
        range
    }

    /// Total number of filaments (with images).
    pub(crate) fn n_filaments(&self) -> usize {
        self.fil.n_filaments()
    }

    /// Base filament index and copy sign of total filament `f` (segments first, then legs).
    #[inline]
    fn base_of(&self, f: usize) -> (usize, usize) {
        let ns = self.n_base_seg * self.n_copies;
        if f < ns {
            (f % self.n_base_seg, f / self.n_base_seg)
        } else {
            let l = f - ns;
            (self.n_base_seg + l % self.n_base_leg, l / self.n_base_leg)
        }
    }

    /// Ring incidences of base filament `b` (segments first, then legs).
    #[inline]
    fn incidences(&self, b: usize) -> &[(u32, f64); 2] {
        if b < self.n_base_seg { &self.inc[b] } else { &self.inc_leg[b - self.n_base_seg] }
    }

    /// Net strength of base filament `b` for ring circulations `gamma`.
    #[inline]
    fn net(&self, b: usize, gamma: &[f64]) -> f64 {
        self.incidences(b).iter().filter(|(r, _)| *r != NONE).map(|(r, s)| s * gamma[*r as usize]).sum()
    }

    /// Net circulation of base segment `s` (a lattice segment: see [`SurfaceRange`]).
    pub(crate) fn lattice_segment_gamma(&self, s: usize) -> f64 {
        self.base_gamma[s]
    }

    /// Put the net strengths of the ring circulations on every filament (images with their sign).
    pub(crate) fn set_strengths(&mut self, gamma: &[f64]) {
        let nb = self.n_base_seg + self.n_base_leg;
        self.base_gamma.clear();
        for b in 0..nb {
            let g = self.net(b, gamma);
            self.base_gamma.push(g);
        }
        for (c, &sign) in copy_signs(self.n_planes).iter().enumerate() {
            for b in 0..self.n_base_seg {
                self.fil.set_segment_gamma(c * self.n_base_seg + b, sign * self.base_gamma[b]);
            }
            for b in 0..self.n_base_leg {
                self.fil.set_leg_gamma(c * self.n_base_leg + b, sign * self.base_gamma[self.n_base_seg + b]);
            }
        }
    }

    /// Assemble the `n_rings × n_rings` AIC at the collocation points `col` with normals `nrm`
    /// (SoA) into `aic`, laid out as `layout` says ([`AicLayout::len`] entries). Returns the
    /// number of point–filament pairs evaluated. `scratch` is the caller's workspace (one entry
    /// per threaded chunk of row blocks).
    pub(crate) fn assemble_aic(
        &self,
        col: &Points,
        nrm: &Points,
        aic: &mut [f64],
        layout: AicLayout,
        parallel: Parallel,
        scratch: &mut ScratchPool<NodeBlock>,
    ) -> u64 {
        let n = col.len();
        assert_eq!(aic.len(), layout.len(n), "assemble_aic: dimension");
        let pairs = n.div_ceil(LANES) * LANES * self.n_filaments();
        self.fill_aic(col, nrm, aic, layout, use_threads(parallel, pairs), scratch);
        pairs as u64
    }

    /// The AIC's blocks of [`LANES`] rows in `layout`, on rayon when `threaded`.
    fn fill_aic(
        &self,
        col: &Points,
        nrm: &Points,
        aic: &mut [f64],
        layout: AicLayout,
        threaded: bool,
        scratch: &mut ScratchPool<NodeBlock>,
    ) {
        let n = col.len();
        if n == 0 {
            return;
        }
        let nf = self.n_filaments();
        let work = |b: usize, out: &mut [f64], blk: &mut NodeBlock| {
            let (px, py, pz) = (load_lanes(&col.x, b), load_lanes(&col.y, b), load_lanes(&col.z, b));
            let (nx, ny, nz) = (load_lanes(&nrm.x, b), load_lanes(&nrm.y, b), load_lanes(&nrm.z, b));
            fill_block(&self.fil, &px, &py, &pz, blk);
            influence_block(&self.fil, blk, &nx, &ny, &nz);
            // Summed per ring in the filaments' order (ring-major, one cache line per
            // filament): the same additions as summing into the rows directly.
            let NodeBlock { infl, rings, .. } = blk;
            let sum_rings = |rings: &mut [[f64; LANES]]| {
                rings.fill([0.0; LANES]);
                for (v, inc) in infl.iter().zip(&self.inc_all[..nf]) {
                    for &(r, s) in inc {
                        if r == NONE {
                            continue;
                        }
                        let acc = &mut rings[r as usize];
                        for (a, vl) in acc.iter_mut().zip(v) {
                            *a += s * vl;
                        }
                    }
                }
            };
            match layout {
                AicLayout::BlockRings => sum_rings(as_lanes(out)),
                AicLayout::RowMajor => {
                    rings.resize(n, [0.0; LANES]);
                    sum_rings(&mut rings[..n]);
                    for (l, row) in out.chunks_mut(n).enumerate() {
                        for (x, ring) in row.iter_mut().zip(rings.iter()) {
                            *x = ring[l];
                        }
                    }
                }
            }
        };
        let block_len = LANES * n;
        if threaded {
            scratch.for_each_chunk(aic, block_len, DIRECT_CHUNKS_PER_THREAD, |first, chunk, blk| {
                for (i, out) in chunk.chunks_mut(block_len).enumerate() {
                    work(first + i, out, blk);
                }
            });
        } else {
            let blk = scratch.first();
            for (b, out) in aic.chunks_mut(block_len).enumerate() {
                work(b, out, blk);
            }
        }
    }
}

/// How [`BoundSystem::assemble_aic`] lays the influence matrix out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum AicLayout {
    /// `aic[i n + j]`.
    RowMajor,
    /// The layout the solver factorises from: for each block `b` of [`LANES`] collocation rows
    /// and each ring `r`, the block's lanes at `aic[(b n + r) LANES ..][..LANES]` (rows past `n`
    /// in the last block hold the last point's values). The same values as the row-major
    /// matrix, without transposing a block's ring sums into rows.
    BlockRings,
}

impl AicLayout {
    /// Entries of an `n × n` matrix in this layout.
    pub(crate) fn len(self, n: usize) -> usize {
        match self {
            AicLayout::RowMajor => n * n,
            AicLayout::BlockRings => n.div_ceil(LANES) * n * LANES,
        }
    }
}

/// `v` (a multiple of [`LANES`] long) as lanes.
fn as_lanes(v: &mut [f64]) -> &mut [[f64; LANES]] {
    let (lanes, rest) = v.as_chunks_mut::<LANES>();
    debug_assert!(rest.is_empty(), "a whole number of blocks");
    lanes
}

/// Which filaments of the known wake [`build_known_wake`] builds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum WakePart {
    /// The whole known wake.
    All,
    /// The filaments touching the trailing edge (node row 0): the trailing-edge spanwise edge
    /// and the chordwise legs of the newest ring row. They move with the lattice within a step.
    Near,
    /// Everything else (node rows ≥ 1: the newest row's downstream edge, the older rows and the
    /// closure legs), fixed within a step once the wake has been advanced.
    Far,
}

/// Build the known wake: every wake ring row with its shed circulation (explicit Kutta
/// condition), net strengths per edge, optional closure legs along `closure_dir`, and images.
/// Node row 0 is the trailing-edge ring row `te` (the upstream edge of the newest wake row, +Γ_w0),
/// node row `r + 1` the wake's detached row `r`. Segments of exactly zero net strength are skipped.
/// The spanwise edge on the trailing edge coincides with the bound trailing-edge edge and takes
/// the bound core `te_core`, so that the two cancel exactly at steady state. `part` selects the
/// whole wake or its near / far part (the two together hold the filaments of `All`, each with
/// only the nodes it uses).
#[cfg(test)] // the solver and the linear model append the wakes of all surfaces, then the images
#[allow(clippy::too_many_arguments)] // the wake, its two cores, closure, images and the part
pub(crate) fn build_known_wake(
    fil: &mut Filaments,
    te: &[[f64; 3]],
    wake: &Wake,
    closure_dir: Option<[f64; 3]>,
    core: &CoreModel,
    te_core: &CoreModel,
    planes: &[ImagePlane],
    part: WakePart,
) {
    fil.clear();
    append_known_wake(fil, te, wake, closure_dir, (core, te_core), part);
    append_images(fil, planes);
}

/// Names of a wake's segments that stay with them as the wake is convected and new rows are
/// shed: surface, push number of the segment's downstream node row ([`Wake::n_pushed`]),
/// spanwise edge or chordwise leg, strip, and image copy. In the order [`append_known_wake`] and
/// [`append_images`] lay the segments out the keys ascend, so two key lists are compared by
/// one merge. A persistent treecode of the far wake uses them to find what changed
/// (wake_tree.rs).
#[derive(Debug, Clone, Default)]
pub(crate) struct SegmentKeys {
    pub(crate) keys: Vec<u64>,
    /// The surface of the segments pushed next (< 64).
    pub(crate) surface: u64,
}

/// Largest push number a key holds.
const KEY_ROW_MAX: u64 = (1 << 35) - 1;

impl SegmentKeys {
    /// Forget every key.
    pub(crate) fn clear(&mut self) {
        self.keys.clear();
    }

    /// The key of a segment of the current surface at push number `row`, a chordwise leg or a
    /// spanwise edge, on strip `j`: surface in bits 56–61, `KEY_ROW_MAX − row` in 21–55 (newer
    /// rows first), the kind in bit 20, the strip in 0–19.
    fn push(&mut self, row: u64, chordwise: bool, j: usize) {
        let row = KEY_ROW_MAX - row.min(KEY_ROW_MAX);
        self.keys.push((self.surface << 56) | (row << 21) | (u64::from(chordwise) << 20) | (j as u64 & 0xf_ffff));
    }

    /// The keys of the image copies of [`append_images`]: copy `c` of every key, with `c` in
    /// bits 62–63.
    pub(crate) fn append_images(&mut self, n_planes: usize) {
        let n = self.keys.len();
        for c in 1..crate::images::copy_signs(n_planes).len() as u64 {
            for i in 0..n {
                let k = self.keys[i];
                self.keys.push(k | (c << 62));
            }
        }
    }

    /// Whether the keys name every segment uniquely (fewer than 64 surfaces, 2^20 strips).
    pub(crate) fn representable(n_surfaces: usize, n_spanwise: usize) -> bool {
        n_surfaces < 64 && n_spanwise < (1 << 20)
    }

    /// The surface and the push number of the row a key names.
    pub(crate) fn surface_and_row(key: u64) -> (usize, u64) {
        (((key >> 56) & 0x3f) as usize, KEY_ROW_MAX - ((key >> 21) & KEY_ROW_MAX))
    }

    /// The largest key of `key`'s surface and image copy whose row's push number is at least
    /// `oldest` (newer rows have smaller keys).
    pub(crate) fn last_key_from(key: u64, oldest: u64) -> u64 {
        (key & (0xff << 56)) | ((KEY_ROW_MAX - oldest.min(KEY_ROW_MAX)) << 21) | 0x1f_ffff
    }
}

/// Node rows of the far wake to build (`head`, `tail`): the spanwise edges at node rows
/// `1..=head` and `tail..`, the chordwise legs ending there, the closure legs, and only the
/// nodes these use. The rows between are left out: a tree kept across steps holds them
/// unchanged (wake_tree.rs). `head + 2 ≤ tail − 1`, so that at least one node row is left out.
pub(crate) type FarRows = (usize, usize);

/// Append one surface's known wake (as [`build_known_wake`], without images, its segments
/// unnamed) to `fil`, after what it holds: the wakes of several surfaces go into one set, then
/// the images of all.
pub(crate) fn append_known_wake(
    fil: &mut Filaments,
    te: &[[f64; 3]],
    wake: &Wake,
    closure_dir: Option<[f64; 3]>,
    (core, te_core): (&CoreModel, &CoreModel),
    part: WakePart,
) {
    append_wake_rows(fil, te, wake, closure_dir, core, te_core, part, None, None);
}

/// [`append_known_wake`], of the far part only the node rows `rows` when given ([`FarRows`]),
/// each segment's name pushed to `keys` when given.
#[allow(clippy::too_many_arguments)] // the wake, its two cores, closure, part, rows and the keys' sink
pub(crate) fn append_wake_rows(
    fil: &mut Filaments,
    te: &[[f64; 3]],
    wake: &Wake,
    closure_dir: Option<[f64; 3]>,
    core: &CoreModel,
    te_core: &CoreModel,
    part: WakePart,
    rows: Option<FarRows>,
    mut keys: Option<&mut SegmentKeys>,
) {
    let len = wake.n_rows();
    let n = wake.n_spanwise();
    let nc = n + 1;
    if len == 0 {
        return;
    }
    // Node rows held by this part: k_first ..= k_last.
    let (k_first, k_last) = match part {
        WakePart::All => (0, len),
        WakePart::Near => (0, 1),
        WakePart::Far => (1, len),
    };
    // Position of node (k, j): 0 = trailing edge, k ≥ 1 = detached row k − 1.
    let pos = |k: usize, j: usize| if k == 0 { te[j] } else { wake.node(k - 1, j) };
    // The node rows kept: all, or `k_first..=head` and `tail − 1..=k_last` (legs ending at
    // `tail` start at `tail − 1`), packed.
    let rows = rows.filter(|&(head, tail)| part == WakePart::Far && head + 2 < tail && tail <= len);
    let kept = |k: usize| rows.is_none_or(|(head, tail)| k <= head || k >= tail);
    let slot = |k: usize| match rows {
        Some((head, tail)) if k > head => head + 1 - k_first + (k - (tail - 1)),
        _ => k - k_first,
    };
    let node0 = fil.n_nodes();
    for k in k_first..=k_last {
        if rows.is_none_or(|(head, tail)| k <= head || k + 1 >= tail) {
            for j in 0..nc {
                fil.push_node(pos(k, j));
            }
        }
    }
    let node = |k: usize, j: usize| (node0 + slot(k) * nc + j) as u32;
    let dist = |a: (usize, usize), b: (usize, usize)| {
        let (p, q) = (pos(a.0, a.1), pos(b.0, b.1));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    };
    let closed = closure_dir.is_some();
    let g = |r: isize, j: isize| -> f64 {
        if r >= 0 && (r as usize) < len && j >= 0 && (j as usize) < n {
            wake.gamma(r as usize, j as usize)
        } else {
            0.0
        }
    };
    // Spanwise edges at node rows [s_lo, s_hi], chordwise legs ending at node rows [c_lo, c_hi].
    let (s_range, c_range) = match part {
        WakePart::All => (0..=len, 1..=len),
        WakePart::Near => (0..=0, 1..=1),
        WakePart::Far => (1..=len, 2..=len),
    };
    for k in 0..=len {
        // Spanwise edge at node row k: upstream edge of ring k (+Γ_k), downstream edge of ring k − 1 (−Γ_{k−1}).
        let r = k as isize;
        if s_range.contains(&k) && kept(k) {
            for j in 0..n {
                let up = if closed && k == len { 0.0 } else { g(r - 1, j as isize) };
                let s = g(r, j as isize) - up;
                if s != 0.0 {
                    let (k0, k1) = if k < len { (k, k + 1) } else { (k - 1, k) };
                    let c = if k == 0 { te_core } else { core };
                    let scale = if c.uses_scale() {
                        0.5 * (dist((k0, j), (k1, j)) + dist((k0, j + 1), (k1, j + 1)))
                    } else {
                        0.0
                    };
                    fil.push_segment_scaled(node(k, j), node(k, j + 1), s, c, scale);
                    if let Some(keys) = keys.as_deref_mut() {
                        keys.push(wake.n_pushed() - k as u64, false, j);
                    }
                }
            }
        }
        // Chordwise legs of ring k − 1: (k−1, j)→(k, j).
        if c_range.contains(&k) && kept(k) {
            for j in 0..nc {
                let s = g(r - 1, j as isize - 1) - g(r - 1, j as isize);
                if s != 0.0 {
                    fil.push_segment(node(k - 1, j), node(k, j), s, core);
                    if let Some(keys) = keys.as_deref_mut() {
                        keys.push(wake.n_pushed() - k as u64, true, j);
                    }
                }
            }
        }
    }
    if let Some(dir) = closure_dir
        && part != WakePart::Near
    {
        let r = len as isize - 1;
        for j in 0..nc {
            let s = g(r, j as isize - 1) - g(r, j as isize);
            if s != 0.0 {
                let l = dist((len, j), (len - 1, j));
                fil.push_leg(node(len, j), dir, s, core, l);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::LatticeSpec;
    use crate::samples::{SpanSpacing, rectangular_wing};
    use approx::assert_relative_eq;

    fn lattice() -> Lattice {
        Lattice::from_stations(LatticeSpec::new(2), &rectangular_wing(0.0, 2.0, 1.0, 2, SpanSpacing::Uniform)).unwrap()
    }

    /// Net edge strengths reproduce the rings: the filament set with strengths equals the sum of
    /// the four legs of every ring, and each shared edge appears once.
    #[test]
    fn net_strengths_equal_sum_of_rings() {
        let lat = lattice();
        let core = CoreModel::CutOff { radius: 0.0 };
        let mut bs = BoundSystem::default();
        bs.build(&lat, TrailingEdge::Unsteady, &core, &[]);
        // (M+1)·N spanwise + M·(N+1) chordwise edges: 3·2 + 2·3 = 12 (rings would have 16 legs).
        assert_eq!(bs.fil.n_segments(), 12);
        let gamma = [0.3, -0.2, 0.7, 0.4];
        bs.set_strengths(&gamma);
        let p = [0.4, 0.7, 0.3];
        let u = bs.fil.velocity_at(p);
        let mut e = [0.0; 3];
        let x = lat.ring_nodes();
        for i in 0..2 {
            for j in 0..2 {
                let c = lat.ring_corners(i, j);
                for k in 0..4 {
                    let v = crate::biot_savart::segment_velocity(p, x[c[k]], x[c[(k + 1) % 4]], gamma[i * 2 + j], core);
                    for q in 0..3 {
                        e[q] += v[q];
                    }
                }
            }
        }
        for q in 0..3 {
            assert_relative_eq!(u[q], e[q], max_relative = 1e-12);
        }
    }

    /// A positive ring induces downwash (against its normal) at its own collocation point.
    #[test]
    fn aic_diagonal_is_negative() {
        let lat = lattice();
        let mut bs = BoundSystem::default();
        bs.build(&lat, TrailingEdge::Unsteady, &CoreModel::default(), &[]);
        let (mut col, mut nrm) = (Points::default(), Points::default());
        for (c, n) in lat.collocation().iter().zip(lat.normals()) {
            col.push(*c);
            nrm.push(*n);
        }
        let mut aic = vec![0.0; 16];
        bs.assemble_aic(&col, &nrm, &mut aic, AicLayout::RowMajor, Parallel::Off, &mut ScratchPool::default());
        for r in 0..4 {
            assert!(aic[r * 4 + r] < 0.0);
        }
    }

    /// The threaded assembly (row blocks in chunks, each with its own scratch entry) equals the
    /// serial one bit for bit, with images and at two thread counts sharing one workspace.
    #[test]
    fn threaded_aic_equals_serial() {
        let lat =
            Lattice::from_stations(LatticeSpec::new(6), &rectangular_wing(0.0, 4.0, 1.0, 11, SpanSpacing::Uniform))
                .unwrap();
        let mut bs = BoundSystem::default();
        let planes = [ImagePlane::through_origin([0.0, 1.0, 0.0])];
        bs.build(&lat, TrailingEdge::Unsteady, &CoreModel::default(), &planes);
        let (mut col, mut nrm) = (Points::default(), Points::default());
        for (c, n) in lat.collocation().iter().zip(lat.normals()) {
            col.push(*c);
            nrm.push(*n);
        }
        let n = col.len();
        let mut scratch = ScratchPool::default();
        let mut serial = vec![0.0; n * n];
        bs.fill_aic(&col, &nrm, &mut serial, AicLayout::RowMajor, false, &mut scratch);
        let n_blocked = AicLayout::BlockRings.len(n);
        let mut blocked = vec![0.0; n_blocked];
        bs.fill_aic(&col, &nrm, &mut blocked, AicLayout::BlockRings, false, &mut scratch);
        for threads in [2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut threaded = vec![f64::NAN; n * n];
            pool.install(|| bs.fill_aic(&col, &nrm, &mut threaded, AicLayout::RowMajor, true, &mut scratch));
            assert_eq!(serial, threaded, "{threads} threads");
            assert!(scratch.entries().len() > 1, "{threads} threads: not chunked");
            let mut threaded = vec![f64::NAN; n_blocked];
            pool.install(|| bs.fill_aic(&col, &nrm, &mut threaded, AicLayout::BlockRings, true, &mut scratch));
            assert_eq!(blocked, threaded, "{threads} threads, blocks of rings");
        }
        // The block layout holds the row-major matrix's values (n is not a multiple of LANES
        // here, so the last block's padding rows are exercised too).
        assert_ne!(n % LANES, 0);
        for i in 0..n {
            for j in 0..n {
                let (b, l) = (i / LANES, i % LANES);
                assert_eq!(blocked[(b * n + j) * LANES + l].to_bits(), serial[i * n + j].to_bits(), "({i}, {j})");
            }
        }
        // And factorises to the same LU.
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let (mut lu_rows, mut lu_blocks) = (crate::dense_lu::DenseLu::new(n), crate::dense_lu::DenseLu::new(n));
        lu_rows.factorize_row_major(&serial).unwrap();
        lu_blocks.factorize_block_rings(&blocked, LANES).unwrap();
        let (mut x_rows, mut x_blocks) = (rhs.clone(), rhs);
        lu_rows.solve_in_place(&mut x_rows);
        lu_blocks.solve_in_place(&mut x_blocks);
        assert_eq!(x_rows, x_blocks);
    }

    /// Rows of equal circulation leave no spanwise filament inside the wake (they are skipped).
    #[test]
    fn uniform_wake_rows_cancel() {
        let lat = lattice();
        let mut wake = Wake::new(2, 3);
        for r in 0..3 {
            let x = 1.0 + r as f64;
            wake.push_front(&[[x, 0.0, 0.0], [x, 1.0, 0.0], [x, 2.0, 0.0]], &[0.5, 0.5]);
        }
        let mut fil = Filaments::default();
        let te = &lat.ring_nodes()[2 * 3..];
        let core = CoreModel::default();
        build_known_wake(&mut fil, te, &wake, None, &core, &core, &[], WakePart::All);
        // TE row (+Γ) and last row (−Γ): 2 + 2 spanwise; chordwise: only the two outer columns × 3 rows.
        assert_eq!(fil.n_segments(), 4 + 6);
        build_known_wake(&mut fil, te, &wake, Some([1.0, 0.0, 0.0]), &core, &core, &[], WakePart::All);
        assert_eq!((fil.n_segments(), fil.n_legs()), (2 + 6, 2));
    }
}
