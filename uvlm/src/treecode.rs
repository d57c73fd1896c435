//! Far-field aggregation of a set of vortex segments (a treecode): the wake's induction at many
//! points at a cost that grows sub-linearly with the wake's length (docs/uvlm.md §14).
//!
//! The segments are sorted into a binary tree of clusters (median splits of their midpoints along
//! the longest side). A cluster with centre `c` carries the Cartesian moments of its segments,
//!
//! $$ M_m = \sum_s \Gamma_s \int_0^1 (B_s - A_s)\,(x_s(\tau) - c)^m\, d\tau ,\qquad |m| \le p, $$
//!
//! computed exactly with Gauss–Legendre points on each segment and shifted from the leaves to the
//! root. At a point `P` with `R = P − c` the cluster induces, to order `p`,
//!
//! $$ u(P) \approx \sum_{|m|\le p} M_m \times g_m(R),\qquad
//!    g_{m,i} = (m_i + 1)\, a_{m+e_i}(R), $$
//!
//! with `a_k` the Taylor coefficients of `1/|R − ξ|` in `ξ`, from the recurrence of Lindsay &
//! Krasny (J Comput Phys 172, 2001)
//!
//! $$ |k|\,|R|^2 a_k = (2|k| - 1) \sum_i R_i\, a_{k-e_i} - (|k| - 1) \sum_i a_{k-2e_i}. $$
//!
//! **Error bound.** The terms of degree `n` in `ξ` of `1/|R − ξ|` are `|ξ|ⁿ Pₙ(cos γ)/|R|ⁿ⁺¹`,
//! whose gradient in `R` has the radial part `(n+1) Pₙ` and the angular part `sin γ Pₙ'(cos γ)`
//! times `|ξ|ⁿ/|R|ⁿ⁺²`. Sonine's inequality `(1 − x²) Pₙ'(x)² ≤ n(n+1) (1 − Pₙ(x)²)` bounds
//! the sum of their squares by `(n+1)(n + Pₙ²) ≤ (n+1)²`, so the gradient is at most
//! `(n+1)|ξ|ⁿ/|R|ⁿ⁺²`, with equality on the axis (γ = 0). A cluster of radius `ρ` (every segment
//! end within `ρ` of `c`) and absolute strength `A = Σ |Γ_s| |B_s − A_s|` evaluated at distance
//! `d > ρ` is therefore in error by at most
//!
//! $$ E \le \frac{A}{4\pi d^2}\, S(\rho/d),\qquad
//!    S(t) = \sum_{n>p} (n+1)\,t^n = t^{p+1}\,\frac{(p+2) - (p+1)\,t}{(1-t)^2}, $$
//!
//! which a short segment across the axis at distance ρ attains.
//!
//! **Shape factor.** Segment by segment the degree-n term is bounded by `(n+1) rₛⁿ/dⁿ⁺²`, `rₛ`
//! the distance of the segment's farther end from `c`, so the cluster's error is at most
//! `Σ_{n>p} (n+1) B_n/dⁿ⁺²` with the radial moments `B_n = Σ |Γ_s| |B_s − A_s| rₛⁿ/4π`; bounding
//! `B_n ≤ B_{p+1} ρ^{n−p−1}` beyond `n = p + 1` gives `E ≤ f_{p+1} A S(ρ/d)/(4π d²)` with the
//! shape factor `f_m = B_m/(B_0 ρᵐ) ≤ 1` (`B_0 = A/4π`). A cluster whose segments spread over
//! its ball has `f` well below 1 (a uniform flat disc `2/(m + 2)`, a quarter at `m = 6`), and
//! the bound is attained with `f` as without it by a segment on the axis. Each cluster keeps `B_0 … B_{p+1}`; they are linear in the absolute strengths, so a
//! kept tree's changes of strength update them as they update the moments.
//!
//! A cluster is used at a block of points when `f_{p+1} S(ρ/d)/(4π d²) ≤ ε / A_total` at the block's
//! nearest point (ε the absolute tolerance, `A_total` the strength of all segments), so the
//! errors of all the clusters used at a point add up to at most ε. It is then evaluated at the
//! lowest order `q ≤ p` whose bound `f_{q+1} S` still passes that test: the order-`q` expansion is the
//! order-`p` one truncated to its terms of degree `≤ q`, so the same bound holds with `q`.
//! Otherwise its children are visited, and a leaf is summed directly with the block kernels.
//! The expansion is that of the singular line vortex: a vortex core or cut-off changes a far
//! segment's induction only where a point lies within the core radius of the segment's axis
//! line, where the singular induction is itself of the order of the core radius.

use std::ops::{Add, AddAssign, Div, Mul, Sub};

use crate::biot_savart::{Filaments, Isa, LANES, NodeBlock, fill_block, isa, velocity_block};
use crate::induce::{Points, use_threads};
use crate::mixed::{Block32, Filaments32, LANES32, add_lanes};
use crate::params::Parallel;
use crate::scratch::{ScratchPool, TREE_CHUNKS_PER_THREAD};

/// Largest expansion order supported.
pub const MAX_ORDER: usize = 12;

/// Distance from a cluster's centre, m, below which a mixed-precision traversal evaluates the
/// expansion in f64: the Taylor coefficients grow as `|R|^-(p+2)`, which leaves f32's range
/// (3.4e38) below about 3e-6 m at `p = 5` and 2e-3 m at [`MAX_ORDER`]; at 1 cm they stay below
/// 1e28 at every order.
const F32_MIN_DISTANCE: f64 = 1e-2;

/// Points per traversal block: the mixed kernel's width, so that a near leaf is summed sixteen
/// points at a time; the f64 expansions and legs take the block in two halves of [`LANES`].
const BLOCK: usize = LANES32;
const _: () = assert!(BLOCK == 2 * LANES, "a block is two halves of the f64 lanes");

/// A multi-index table: every `k` with `|k| ≤ degree`, sorted by degree.
#[derive(Debug, Clone, Default)]
struct Indices {
    k: Vec<[u8; 3]>,
    /// Position of `k − e_i` (or `u32::MAX`).
    down1: Vec<[u32; 3]>,
    /// Position of `k − 2 e_i` (or `u32::MAX`).
    down2: Vec<[u32; 3]>,
}

const NONE: u32 = u32::MAX;

impl Indices {
    fn new(degree: usize) -> Self {
        let mut k = Vec::new();
        for n in 0..=degree {
            for a in (0..=n).rev() {
                for b in (0..=n - a).rev() {
                    k.push([a as u8, b as u8, (n - a - b) as u8]);
                }
            }
        }
        let pos = |q: [i32; 3]| -> u32 {
            if q.iter().any(|&x| x < 0) {
                return NONE;
            }
            k.iter().position(|m| [m[0] as i32, m[1] as i32, m[2] as i32] == q).map_or(NONE, |p| p as u32)
        };
        let mut down1 = Vec::with_capacity(k.len());
        let mut down2 = Vec::with_capacity(k.len());
        for m in &k {
            let m = [m[0] as i32, m[1] as i32, m[2] as i32];
            let mut d1 = [NONE; 3];
            let mut d2 = [NONE; 3];
            for i in 0..3 {
                let mut q = m;
                q[i] -= 1;
                d1[i] = pos(q);
                q[i] -= 1;
                d2[i] = pos(q);
            }
            down1.push(d1);
            down2.push(d2);
        }
        Self { k, down1, down2 }
    }

    fn position(&self, m: [u8; 3]) -> usize {
        // Sorted by degree: search only within the degree's range.
        self.k.iter().position(|q| *q == m).expect("multi-index in table")
    }
}

/// One cluster of the tree: the segments `perm[start..end]`.
#[derive(Debug, Clone, Copy, Default)]
struct Cluster {
    center: [f64; 3],
    radius: f64,
    start: u32,
    end: u32,
    /// First child (the second is `child + 1`), or `NONE` for a leaf.
    child: u32,
    /// Leaf number (index into `leaves`), or `NONE`.
    leaf: u32,
}

/// Work counters of the evaluations, for the benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TreeStats {
    /// Point–segment pairs summed directly (leaves), per lane.
    pub n_direct_pairs: u64,
    /// Point–cluster expansions evaluated, per lane.
    pub n_expansions: u64,
}

/// A treecode over the segments of a [`Filaments`] set (its legs are summed directly).
#[derive(Debug, Clone, Default)]
pub struct Treecode {
    order: usize,
    leaf_size: usize,
    /// Moments (degree ≤ p) and Taylor coefficients (degree ≤ p + 1).
    mom_idx: Indices,
    taylor_idx: Indices,
    /// Per moment m: positions of m + e_i in the Taylor table and the factors m_i + 1.
    grad: Vec<([u32; 3], [f64; 3])>,
    /// Per Taylor coefficient: (2n − 1)/n and (n − 1)/n.
    rec: Vec<(f64, f64)>,

    /// Per moment m ≠ 0: the position of m − e_i and i, for the first i with m_i > 0.
    up: Vec<(u32, u8)>,
    /// The leaf moments' samples and lane accumulators.
    samples: MomentSamples,
    /// The workspace of [`Treecode::set_segments`].
    edits: Edits,
    /// Gauss–Legendre points on [0, 1] and weights (summing to 1).
    gauss: Vec<(f64, f64)>,
    /// The shift of moments to a parent's centre: `(j, k − j, C(k, j))` for every `j ≤ k`,
    /// grouped by `k`; `shift_rows[k]` is the range of `k`'s entries.
    shift: Vec<(u32, [u8; 3], f64)>,
    shift_rows: Vec<(u32, u32)>,
    /// Segment order of the tree (indices into the source set).
    perm: Vec<u32>,
    mid: Vec<[f64; 3]>,
    clusters: Vec<Cluster>,
    /// `clusters.len() × n_moments` vector moments.
    moments: Vec<[f64; 3]>,
    /// `clusters.len() × (p + 2)` radial strength moments `B_m = Σ |Γ/4π| |B − A| rᵐ`,
    /// `m = 0..=p+1` (r the distance of the segment's farther end from the centre; `B_0` is the
    /// cluster's absolute strength), and the shape factors `B_m/(B_0 ρᵐ)` ∈ [0, 1] of the error
    /// bound derived from them.
    radial: Vec<f64>,
    shape: Vec<f64>,
    /// The segments' ends and absolute strengths times lengths in tree order, for the radial
    /// moments' vectorised sums.
    ends: SegmentEnds,
    /// `clusters.len() × n_taylor` coefficients `B_k` of the Taylor coefficients in the
    /// expansion, `u = Σ_k a_k B_k` ([`curl_coefficients`]), derived from the moments.
    curl: Vec<[f64; 3]>,
    /// `curl` rounded to f32, for the mixed-precision expansions.
    curl32: Vec<[f32; 3]>,
    /// `rec` rounded to f32.
    rec32: Vec<(f32, f32)>,
    /// Each leaf's segments as a set of its own (each node of the leaf once) for the block
    /// kernels.
    leaves: Vec<Filaments>,
    /// Sum the near leaves in mixed precision (mixed.rs), with these f32 constants per leaf.
    mixed: bool,
    leaves32: Vec<Filaments32>,
    /// Per node of the source set: the last leaf fill that copied it (`stamp_gen`), and its
    /// index in that leaf.
    node_stamp: Vec<u64>,
    node_slot: Vec<u32>,
    stamp_gen: u64,
    n_leaves: usize,
    /// The set's legs, summed directly.
    legs: Filaments,
    /// Per source segment: the leaf cluster holding it and its index in that leaf's set.
    seg_leaf: Vec<u32>,
    seg_slot: Vec<u32>,
    /// Per cluster: its parent (`NONE` for the root).
    parent: Vec<u32>,
    /// Σ |Γ/4π| |B − A| over all segments.
    total_strength: f64,
    /// The traversals' workspace: one entry per threaded chunk of point blocks (the first
    /// serves the serial loop).
    scratch: ScratchPool<Scratch>,
    /// The threaded loop's velocities and direct pairs per point block, scattered to the points
    /// after the loop.
    block_out: Vec<BlockOut>,
}

/// One leaf's (segment, Gauss point) samples, padded to whole blocks of [`LANES`], and the
/// per-lane monomials and moment sums of the leaf.
#[derive(Debug, Clone, Default)]
struct MomentSamples {
    ax: Vec<f64>,
    ay: Vec<f64>,
    az: Vec<f64>,
    xx: Vec<f64>,
    xy: Vec<f64>,
    xz: Vec<f64>,
    mono: Vec<[f64; LANES]>,
    acc: Vec<[[f64; LANES]; 3]>,
}

impl MomentSamples {
    /// No samples.
    fn clear(&mut self) {
        for v in [&mut self.ax, &mut self.ay, &mut self.az, &mut self.xx, &mut self.xy, &mut self.xz] {
            v.clear();
        }
    }

    /// The Gauss samples of the segment from `pa` along `l` with strength `g`: weights
    /// `g w l`, positions relative to `centre`.
    fn push_segment(&mut self, gauss: &[(f64, f64)], pa: [f64; 3], l: [f64; 3], g: f64, centre: [f64; 3]) {
        for &(t, w) in gauss {
            let gw = g * w;
            self.ax.push(gw * l[0]);
            self.ay.push(gw * l[1]);
            self.az.push(gw * l[2]);
            self.xx.push(pa[0] + t * l[0] - centre[0]);
            self.xy.push(pa[1] + t * l[1] - centre[1]);
            self.xz.push(pa[2] + t * l[2] - centre[2]);
        }
    }

    /// Pad the samples to whole blocks with zero weights and add their moments (monomials of
    /// the positions times the weights, table `up`) to `mom`.
    fn accumulate(&mut self, up: &[(u32, u8)], mom: &mut [[f64; 3]]) {
        let n = self.ax.len().div_ceil(LANES) * LANES;
        for v in [&mut self.ax, &mut self.ay, &mut self.az, &mut self.xx, &mut self.xy, &mut self.xz] {
            v.resize(n, 0.0);
        }
        for a in self.acc.iter_mut() {
            *a = [[0.0; LANES]; 3];
        }
        self.mono[0] = [1.0; LANES];
        match isa() {
            Isa::Generic => moments_generic(up, self),
            // SAFETY: the features were detected at run time.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { moments_avx2(up, self) },
            // SAFETY: the features were detected at run time.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { moments_avx512(up, self) },
        }
        for (mm, acc) in mom.iter_mut().zip(&self.acc) {
            for q in 0..3 {
                mm[q] += acc[q].iter().sum::<f64>();
            }
        }
    }
}

/// The changes of [`Treecode::set_segments`]: per changed segment its first node, its vector and
/// its change of strength; (cluster, change) for the segment's leaf and every cluster above.
#[derive(Debug, Clone, Default)]
struct Edits {
    deltas: Vec<([f64; 3], [f64; 3], f64, f64)>,
    touched: Vec<(u32, u32)>,
}

/// The velocities at one block's points and the point–filament pairs summed directly.
type BlockOut = ([[f64; BLOCK]; 3], u64);

/// Scratch of a traversal (one per chunk of point blocks).
#[derive(Debug, Clone, Default)]
struct Scratch {
    stack: Vec<u32>,
    taylor: Vec<[f64; LANES]>,
    taylor32: Vec<[f32; BLOCK]>,
    stats: TreeStats,
    blk: NodeBlock,
    blk32: Block32<BLOCK>,
}

impl Treecode {
    /// An empty treecode of expansion order `order` (≤ [`MAX_ORDER`]) with at most `leaf_size`
    /// segments per leaf.
    ///
    /// # Panics
    /// If `order > MAX_ORDER` or `leaf_size == 0`.
    pub fn new(order: usize, leaf_size: usize) -> Self {
        assert!(order <= MAX_ORDER && leaf_size > 0, "treecode order ≤ {MAX_ORDER}, leaf size ≥ 1");
        let mom_idx = Indices::new(order);
        let taylor_idx = Indices::new(order + 1);
        let grad = mom_idx
            .k
            .iter()
            .map(|m| {
                let mut pos = [0u32; 3];
                let mut fac = [0.0; 3];
                for i in 0..3 {
                    let mut q = *m;
                    q[i] += 1;
                    pos[i] = taylor_idx.position(q) as u32;
                    fac[i] = (m[i] + 1) as f64;
                }
                (pos, fac)
            })
            .collect();
        let rec: Vec<(f64, f64)> = taylor_idx
            .k
            .iter()
            .map(|m| {
                let n = (m[0] + m[1] + m[2]) as f64;
                if n == 0.0 { (0.0, 0.0) } else { ((2.0 * n - 1.0) / n, (n - 1.0) / n) }
            })
            .collect();
        let up = mom_idx
            .k
            .iter()
            .enumerate()
            .map(|(kp, m)| match (0..3).find(|&i| m[i] > 0) {
                Some(i) => (mom_idx.down1[kp][i], i as u8),
                None => (NONE, 0),
            })
            .collect();
        let mut binom = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
        for n in 0..=MAX_ORDER {
            binom[n][0] = 1.0;
            for k in 1..=n {
                binom[n][k] = binom[n - 1][k - 1] + if k < n { binom[n - 1][k] } else { 0.0 };
            }
        }
        let (mut shift, mut shift_rows) = (Vec::new(), Vec::new());
        for (kp, k) in mom_idx.k.iter().enumerate() {
            let start = shift.len() as u32;
            for (jp, j) in mom_idx.k.iter().enumerate().take(kp + 1) {
                if (0..3).all(|q| j[q] <= k[q]) {
                    let e = [k[0] - j[0], k[1] - j[1], k[2] - j[2]];
                    let c = (0..3).map(|q| binom[k[q] as usize][j[q] as usize]).product();
                    shift.push((jp as u32, e, c));
                }
            }
            shift_rows.push((start, shift.len() as u32));
        }
        Self {
            order,
            leaf_size,
            gauss: gauss_legendre(order / 2 + 1),
            mom_idx,
            taylor_idx,
            grad,
            rec32: rec.iter().map(|&(a, b): &(f64, f64)| (a as f32, b as f32)).collect(),
            rec,
            up,
            shift,
            shift_rows,
            ..Self::default()
        }
    }

    /// Sum the near leaves in mixed precision (f32 kernel, f64 positions and sums; mixed.rs),
    /// and evaluate the expansions in f32 on whole blocks, from the next [`Treecode::build`] on.
    pub(crate) fn set_mixed(&mut self, mixed: bool) {
        self.mixed = mixed;
    }

    /// Expansion order p.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Counters of the evaluations since the last [`Treecode::build`] (serial and threaded).
    pub fn stats(&self) -> TreeStats {
        let mut t = TreeStats::default();
        for sc in self.scratch.entries() {
            t.n_direct_pairs += sc.stats.n_direct_pairs;
            t.n_expansions += sc.stats.n_expansions;
        }
        t
    }

    /// Sort the segments of `fil` into the tree and compute every cluster's moments.
    pub fn build(&mut self, fil: &Filaments) {
        let ns = fil.n_segments();
        for sc in self.scratch.entries_mut() {
            sc.stats = TreeStats::default();
        }
        self.perm.clear();
        self.perm.extend(0..ns as u32);
        self.mid.clear();
        self.total_strength = 0.0;
        for s in 0..ns {
            let (a, b) = fil.segment_nodes(s);
            let (pa, pb) = (fil.node(a as usize), fil.node(b as usize));
            self.mid.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])]);
            let l = ((pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2) + (pb[2] - pa[2]).powi(2)).sqrt();
            self.total_strength += fil.seg_g[s].abs() * l;
        }
        self.clusters.clear();
        self.n_leaves = 0;
        if ns > 0 {
            self.split(fil);
        }
        self.fill_leaves(fil);
        if self.mixed {
            self.leaves32.resize_with(self.n_leaves, Filaments32::default);
            for (c, leaf) in self.leaves32.iter_mut().zip(&self.leaves[..self.n_leaves]) {
                c.load(leaf);
            }
        }
        self.index_segments();
        self.compute_moments(fil);
        self.compute_radial(fil);
        self.legs.clear();
        for l in 0..fil.n_legs() {
            let a = self.legs.push_node(fil.node(fil.leg_a[l] as usize));
            self.legs.leg_a.push(a);
            self.legs.leg_d.push(fil.leg_d[l]);
            self.legs.leg_g.push(fil.leg_g[l]);
            self.legs.leg_core2.push(fil.leg_core2[l]);
            self.legs.leg_cut2.push(fil.leg_cut2[l]);
        }
    }

    /// Sum the set's legs elsewhere: the tree holds its segments only.
    pub(crate) fn drop_legs(&mut self) {
        self.legs.clear();
    }

    /// The parents of the clusters and, per source segment, its leaf and slot in the leaf.
    fn index_segments(&mut self) {
        self.parent.clear();
        self.parent.resize(self.clusters.len(), NONE);
        self.seg_leaf.resize(self.perm.len(), NONE);
        self.seg_slot.resize(self.perm.len(), 0);
        for (ci, c) in self.clusters.iter().enumerate() {
            if c.child != NONE {
                self.parent[c.child as usize] = ci as u32;
                self.parent[c.child as usize + 1] = ci as u32;
            } else {
                for (slot, &s) in self.perm[c.start as usize..c.end as usize].iter().enumerate() {
                    self.seg_leaf[s as usize] = ci as u32;
                    self.seg_slot[s as usize] = slot as u32;
                }
            }
        }
    }

    /// Give source segments of the built set new strengths (as stored, with their 1/4π) and
    /// core constants, `(segment, g, core2, cut2)` each: the leaves' copies take them, and the
    /// moments of each leaf and of every cluster above it change by the segments' moments times
    /// their change of strength (the moments are linear in the strengths). The segments keep
    /// their places and the clusters their centres and radii, which still bound every segment
    /// (a strength of 0 removes a segment). The total strength follows, so the error bound holds
    /// as at a build.
    ///
    /// Each touched cluster sums the (segment, Gauss point) samples of its changed segments
    /// through the leaf moments' vectorised kernel, once for all of them.
    pub(crate) fn set_segments(&mut self, changes: &[(u32, f64, f64, f64)]) {
        let edits = &mut self.edits;
        edits.deltas.clear();
        edits.touched.clear();
        for &(s, g, core2, cut2) in changes {
            let s = s as usize;
            let ci = self.seg_leaf[s] as usize;
            let slot = self.seg_slot[s] as usize;
            let leaf = &mut self.leaves[self.clusters[ci].leaf as usize];
            let old = leaf.seg_g[slot];
            leaf.seg_core2[slot] = core2;
            leaf.seg_cut2[slot] = cut2;
            if self.mixed {
                self.leaves32[self.clusters[ci].leaf as usize].set_segment(slot, g, core2, cut2);
            }
            if g == old {
                continue;
            }
            leaf.seg_g[slot] = g;
            let (pa, pb) = (leaf.node(leaf.seg_a[slot] as usize), leaf.node(leaf.seg_b[slot] as usize));
            let l = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
            let len = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
            self.total_strength = (self.total_strength + (g.abs() - old.abs()) * len).max(0.0);
            let d = edits.deltas.len() as u32;
            edits.deltas.push((pa, l, g - old, g.abs() - old.abs()));
            let mut c = ci;
            loop {
                edits.touched.push((c as u32, d));
                match self.parent[c] {
                    NONE => break,
                    p => c = p as usize,
                }
            }
        }
        edits.touched.sort_unstable();
        let nm = self.mom_idx.k.len();
        let sm = &mut self.samples;
        sm.mono.resize(nm, [0.0; LANES]);
        sm.acc.resize(nm, [[0.0; LANES]; 3]);
        let np = self.order + 2;
        for group in edits.touched.chunk_by(|a, b| a.0 == b.0) {
            let ci = group[0].0 as usize;
            let centre = self.clusters[ci].center;
            sm.clear();
            for &(_, d) in group {
                let (pa, l, dg, dabs) = edits.deltas[d as usize];
                sm.push_segment(&self.gauss, pa, l, dg, centre);
                let pb = [pa[0] + l[0], pa[1] + l[1], pa[2] + l[2]];
                add_radial(&mut self.radial[ci * np..(ci + 1) * np], pa, pb, centre, dabs);
            }
            let rho = self.clusters[ci].radius;
            shape_factors(&self.radial[ci * np..(ci + 1) * np], &mut self.shape[ci * np..(ci + 1) * np], rho);
            let mom = &mut self.moments[ci * nm..(ci + 1) * nm];
            sm.accumulate(&self.up, mom);
            let nt = self.taylor_idx.k.len();
            curl_coefficients(&self.grad, mom, &mut self.curl[ci * nt..(ci + 1) * nt]);
            for (b32, b) in self.curl32[ci * nt..(ci + 1) * nt].iter_mut().zip(&self.curl[ci * nt..(ci + 1) * nt]) {
                *b32 = b.map(|x| x as f32);
            }
        }
    }

    /// Every cluster's radial strength moments and shape factors (see `radial`): the segments'
    /// ends are laid out in tree order once, so that each cluster's are one contiguous run.
    fn compute_radial(&mut self, fil: &Filaments) {
        let np = self.order + 2;
        self.radial.clear();
        self.radial.resize(self.clusters.len() * np, 0.0);
        self.shape.resize(self.clusters.len() * np, 0.0);
        self.ends.load(fil, &self.perm);
        let isa = isa();
        for ci in 0..self.clusters.len() {
            let c = self.clusters[ci];
            let out = &mut self.radial[ci * np..(ci + 1) * np];
            let run = c.start as usize..c.end as usize;
            match isa {
                Isa::Generic => radial_generic(&self.ends, run, c.center, out),
                // SAFETY: the features were detected at run time.
                #[cfg(target_arch = "x86_64")]
                Isa::Avx2 => unsafe { radial_avx2(&self.ends, run, c.center, out) },
                // SAFETY: the features were detected at run time.
                #[cfg(target_arch = "x86_64")]
                Isa::Avx512 => unsafe { radial_avx512(&self.ends, run, c.center, out) },
            }
            self.update_shape(ci);
        }
    }

    /// Cluster `ci`'s shape factors from its radial moments ([`shape_factors`]).
    fn update_shape(&mut self, ci: usize) {
        let np = self.order + 2;
        let rho = self.clusters[ci].radius;
        shape_factors(&self.radial[ci * np..(ci + 1) * np], &mut self.shape[ci * np..(ci + 1) * np], rho);
    }

    /// Build the clusters by median splits (preorder; children adjacent).
    fn split(&mut self, fil: &Filaments) {
        self.clusters.push(Cluster {
            start: 0,
            end: self.perm.len() as u32,
            child: NONE,
            leaf: NONE,
            ..Default::default()
        });
        let mut c = 0;
        while c < self.clusters.len() {
            let (start, end) = (self.clusters[c].start as usize, self.clusters[c].end as usize);
            let (center, radius, lo, hi) = bounding_ball(fil, &self.perm[start..end]);
            self.clusters[c].center = center;
            self.clusters[c].radius = radius;
            if end - start <= self.leaf_size {
                self.clusters[c].leaf = self.n_leaves as u32;
                self.n_leaves += 1;
            } else {
                // Split the midpoints along the longest side of the ends' bounding box.
                let axis = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b]))).unwrap_or(0);
                let half = (end - start) / 2;
                let mid = &self.mid;
                self.perm[start..end]
                    .select_nth_unstable_by(half, |&a, &b| mid[a as usize][axis].total_cmp(&mid[b as usize][axis]));
                let first = self.clusters.len() as u32;
                self.clusters[c].child = first;
                let k = (start + half) as u32;
                self.clusters.push(Cluster {
                    start: start as u32,
                    end: k,
                    child: NONE,
                    leaf: NONE,
                    ..Default::default()
                });
                self.clusters.push(Cluster {
                    start: k,
                    end: end as u32,
                    child: NONE,
                    leaf: NONE,
                    ..Default::default()
                });
            }
            c += 1;
        }
    }

    /// Copy each leaf's segments into a set of its own.
    fn fill_leaves(&mut self, fil: &Filaments) {
        if self.leaves.len() < self.n_leaves {
            self.leaves.resize(self.n_leaves, Filaments::default());
        }
        if self.node_stamp.len() < fil.n_nodes() {
            self.node_stamp.resize(fil.n_nodes(), 0);
            self.node_slot.resize(fil.n_nodes(), 0);
        }
        for c in &self.clusters {
            if c.leaf == NONE {
                continue;
            }
            let leaf = &mut self.leaves[c.leaf as usize];
            leaf.clear();
            // A node shared by segments of the leaf is copied once (`stamp` marks the nodes
            // already copied into this leaf, `slot` their index in it).
            self.stamp_gen += 1;
            let (stamp, slot, generation) = (&mut self.node_stamp, &mut self.node_slot, self.stamp_gen);
            let mut copy = |n: u32, leaf: &mut Filaments| -> u32 {
                let n = n as usize;
                if stamp[n] != generation {
                    stamp[n] = generation;
                    slot[n] = leaf.push_node(fil.node(n));
                }
                slot[n]
            };
            for &s in &self.perm[c.start as usize..c.end as usize] {
                let s = s as usize;
                let (a, b) = fil.segment_nodes(s);
                let ia = copy(a, leaf);
                let ib = copy(b, leaf);
                leaf.seg_a.push(ia);
                leaf.seg_b.push(ib);
                leaf.seg_g.push(fil.seg_g[s]);
                leaf.seg_core2.push(fil.seg_core2[s]);
                leaf.seg_cut2.push(fil.seg_cut2[s]);
            }
        }
    }

    /// Leaf moments from Gauss points, then shifted to the parents (children follow their
    /// parents in `clusters`, so a reverse sweep sees every child first).
    ///
    /// A leaf's (segment, Gauss point) samples go [`LANES`] at a time: each monomial of the
    /// moment table is its parent's times one coordinate (`up`), accumulated per lane and
    /// summed over the lanes once per leaf.
    fn compute_moments(&mut self, fil: &Filaments) {
        let nm = self.mom_idx.k.len();
        self.moments.clear();
        self.moments.resize(self.clusters.len() * nm, [0.0; 3]);
        let p = self.order;
        let sm = &mut self.samples;
        sm.mono.resize(nm, [0.0; LANES]);
        sm.acc.resize(nm, [[0.0; LANES]; 3]);
        for (ci, c) in self.clusters.iter().enumerate() {
            if c.leaf == NONE {
                continue;
            }
            // The samples: weights Γ w (B − A) and positions relative to the centre.
            sm.clear();
            for &s in &self.perm[c.start as usize..c.end as usize] {
                let s = s as usize;
                let (a, b) = fil.segment_nodes(s);
                let (pa, pb) = (fil.node(a as usize), fil.node(b as usize));
                let l = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
                sm.push_segment(&self.gauss, pa, l, fil.seg_g[s], c.center);
            }
            let mom = &mut self.moments[ci * nm..(ci + 1) * nm];
            mom.fill([0.0; 3]);
            sm.accumulate(&self.up, mom);
        }
        // M_k(parent) = Σ_children Σ_{j ≤ k} C(k, j) δ^{k − j} M_j(child), both children in one
        // sweep of the table, each k summed in registers (the table is grouped by k).
        let mut pw2 = [[[0.0; MAX_ORDER + 1]; 3]; 2];
        for ci in (0..self.clusters.len()).rev() {
            let c = self.clusters[ci];
            if c.child == NONE {
                continue;
            }
            let ch = c.child as usize;
            for (h, pw) in pw2.iter_mut().enumerate() {
                let cc = self.clusters[ch + h].center;
                let delta = [cc[0] - c.center[0], cc[1] - c.center[1], cc[2] - c.center[2]];
                for q in 0..3 {
                    pw[q][0] = 1.0;
                    for e in 1..=p {
                        pw[q][e] = pw[q][e - 1] * delta[q];
                    }
                }
            }
            let (lo, hi) = self.moments.split_at_mut(ch * nm);
            let parent = &mut lo[ci * nm..(ci + 1) * nm];
            let (c0, c1) = (&hi[..nm], &hi[nm..2 * nm]);
            for (kp, &(start, end)) in self.shift_rows.iter().enumerate() {
                let mut acc = [0.0; 3];
                for &(jp, e, coef) in &self.shift[start as usize..end as usize] {
                    let (e0, e1, e2) = (e[0] as usize, e[1] as usize, e[2] as usize);
                    let f0 = coef * pw2[0][0][e0] * pw2[0][1][e1] * pw2[0][2][e2];
                    let f1 = coef * pw2[1][0][e0] * pw2[1][1][e1] * pw2[1][2][e2];
                    let (m0, m1) = (c0[jp as usize], c1[jp as usize]);
                    for q in 0..3 {
                        acc[q] += f0 * m0[q] + f1 * m1[q];
                    }
                }
                for q in 0..3 {
                    parent[kp][q] += acc[q];
                }
            }
        }
        let nt = self.taylor_idx.k.len();
        self.curl.clear();
        self.curl.resize(self.clusters.len() * nt, [0.0; 3]);
        for (mom, curl) in self.moments.chunks_exact(nm).zip(self.curl.chunks_exact_mut(nt)) {
            curl_coefficients(&self.grad, mom, curl);
        }
        self.curl32.clear();
        self.curl32.extend(self.curl.iter().map(|b| b.map(|x| x as f32)));
    }

    /// Velocity induced by the set at every point of `pts`, added to `out`, to within `tol`
    /// (m/s, absolute) at each point. `order` lists the points in blocks of sixteen that are
    /// close together ([`block_order`]). Returns the point–filament pairs summed directly.
    pub(crate) fn add_velocity_inplace(
        &mut self,
        pts: &Points,
        order: &[u32],
        tol: f64,
        out: &mut [[f64; 3]],
        parallel: Parallel,
    ) -> u64 {
        assert_eq!(out.len(), pts.len(), "treecode: output length");
        assert_eq!(order.len(), pts.len(), "treecode: order length");
        let n_blocks = pts.len().div_ceil(BLOCK);
        // Rough work: every point against a leaf's worth of segments per level.
        let work = pts.len() * self.leaf_size * self.clusters.len().max(1).ilog2() as usize * 16;
        if use_threads(parallel, work) && n_blocks > 1 {
            return self.add_blocks_threaded(pts, order, tol, out);
        }
        let mut pairs = 0u64;
        let mut pool = std::mem::take(&mut self.scratch);
        let sc = pool.first();
        for b in 0..n_blocks {
            let (bx, by, bz) = gather(pts, order, b);
            let mut u = [[0.0; BLOCK]; 3];
            pairs += self.block(&bx, &by, &bz, tol, &mut u, sc);
            scatter(order, b, &u, out);
        }
        self.scratch = pool;
        pairs
    }

    /// The point blocks on rayon, each chunk of blocks with its own scratch entry: the blocks
    /// write disjoint points of `out` (through `order`), so compute into `block_out`, then
    /// scatter in block order. Returns the pairs summed directly.
    fn add_blocks_threaded(&mut self, pts: &Points, order: &[u32], tol: f64, out: &mut [[f64; 3]]) -> u64 {
        let n_blocks = pts.len().div_ceil(BLOCK);
        let (mut pool, mut res) = (std::mem::take(&mut self.scratch), std::mem::take(&mut self.block_out));
        res.resize(n_blocks, ([[0.0; BLOCK]; 3], 0));
        pool.for_each_chunk(&mut res, 1, TREE_CHUNKS_PER_THREAD, |first, chunk, sc| {
            for (i, (u, pairs)) in chunk.iter_mut().enumerate() {
                let (bx, by, bz) = gather(pts, order, first + i);
                *u = [[0.0; BLOCK]; 3];
                *pairs = self.block(&bx, &by, &bz, tol, u, sc);
            }
        });
        let mut pairs = 0;
        for (b, (u, p)) in res.iter().enumerate() {
            scatter(order, b, u, out);
            pairs += p;
        }
        (self.scratch, self.block_out) = (pool, res);
        pairs
    }

    /// Velocity induced by the set at `points`, to within `tol` (m/s, absolute) at each point
    /// (allocating convenience for checks and benchmarks).
    pub fn velocity(&mut self, points: &[[f64; 3]], tol: f64) -> Vec<[f64; 3]> {
        let mut pts = Points::default();
        for p in points {
            pts.push(*p);
        }
        let (mut order, mut stack) = (Vec::new(), Vec::new());
        block_order(&pts, &mut order, &mut stack);
        let mut out = vec![[0.0; 3]; points.len()];
        self.add_velocity_inplace(&pts, &order, tol, &mut out, Parallel::Off);
        out
    }

    /// One block of points: traverse the tree.
    fn block(
        &self,
        px: &[f64; BLOCK],
        py: &[f64; BLOCK],
        pz: &[f64; BLOCK],
        tol: f64,
        u: &mut [[f64; BLOCK]; 3],
        sc: &mut Scratch,
    ) -> u64 {
        let mut pairs = 0u64;
        let halves = Halves::of(px, py, pz);
        if self.legs.n_legs() > 0 {
            halves.each(u, |hx, hy, hz, uh| {
                fill_block(&self.legs, hx, hy, hz, &mut sc.blk);
                velocity_block(&self.legs, &sc.blk, uh);
            });
            pairs += (BLOCK * self.legs.n_legs()) as u64;
        }
        if self.clusters.is_empty() {
            return pairs;
        }
        // Accept a cluster when S(ρ/d)/d² ≤ ε / A_total (strengths carry the 1/4π).
        let budget = if self.total_strength > 0.0 { tol / self.total_strength } else { f64::INFINITY };
        let p = self.order as i32;
        if sc.taylor.len() < self.taylor_idx.k.len() {
            sc.taylor.resize(self.taylor_idx.k.len(), [0.0; LANES]);
            sc.taylor32.resize(self.taylor_idx.k.len(), [0.0; BLOCK]);
        }
        sc.stack.clear();
        sc.stack.push(0);
        while let Some(ci) = sc.stack.pop() {
            let c = self.clusters[ci as usize];
            let mut d2min = f64::INFINITY;
            for l in 0..BLOCK {
                let d2 = (px[l] - c.center[0]).powi(2) + (py[l] - c.center[1]).powi(2) + (pz[l] - c.center[2]).powi(2);
                d2min = d2min.min(d2);
            }
            let d = d2min.sqrt();
            let t = c.radius / d;
            let allowed = budget * d2min;
            let np = self.order + 2;
            let f = &self.shape[ci as usize * np..(ci as usize + 1) * np];
            if d > c.radius && f[p as usize + 1] * tail_bound(t, p) <= allowed {
                // The lowest order whose bound still holds: its expansion is the order-p one
                // truncated to `|k| ≤ q + 1` (`B_k` holds the moments of degree `|k| − 1`).
                let mut q = p;
                while q > 0 && f[q as usize] * tail_bound(t, q - 1) <= allowed {
                    q -= 1;
                }
                let nt = self.taylor_idx.k.len();
                let (ci, c) = (ci as usize, c.center);
                let ncf = n_coefficients(q as usize + 1);
                // Closer than F32_MIN_DISTANCE the coefficients could leave f32's range.
                let isa = isa();
                let idx = &self.taylor_idx;
                if self.mixed && d2min >= F32_MIN_DISTANCE * F32_MIN_DISTANCE {
                    let curl = &self.curl32[ci * nt..ci * nt + ncf];
                    expansion_on(isa, idx, &self.rec32, curl, c, px, py, pz, &mut sc.taylor32, u);
                } else {
                    let (curl, a) = (&self.curl[ci * nt..ci * nt + ncf], &mut sc.taylor[..]);
                    halves.each(u, |px, py, pz, u| expansion_on(isa, idx, &self.rec, curl, c, px, py, pz, a, u));
                }
                sc.stats.n_expansions += BLOCK as u64;
            } else if c.leaf != NONE {
                let leaf = &self.leaves[c.leaf as usize];
                if self.mixed {
                    add_lanes(leaf, &self.leaves32[c.leaf as usize], &[*px, *py, *pz], &mut sc.blk32, u);
                } else {
                    halves.each(u, |hx, hy, hz, uh| {
                        fill_block(leaf, hx, hy, hz, &mut sc.blk);
                        velocity_block(leaf, &sc.blk, uh);
                    });
                }
                let n = (BLOCK * leaf.n_segments()) as u64;
                pairs += n;
                sc.stats.n_direct_pairs += n;
            } else {
                sc.stack.push(c.child);
                sc.stack.push(c.child + 1);
            }
        }
        pairs
    }
}

/// `S(t) = Σ_{n>p} (n+1) tⁿ`, the error bound's series of the order-`p` expansion of a cluster
/// of radius `t d` at distance `d` (module documentation), for `0 ≤ t < 1`.
fn tail_bound(t: f64, p: i32) -> f64 {
    t.powi(p + 1) * ((p + 2) as f64 - (p + 1) as f64 * t) / ((1.0 - t) * (1.0 - t))
}

/// The shape factors `f[m] = B_m/(B_0 ρᵐ)` of radial moments `b` of a cluster of radius `ρ`,
/// clamped to [0, 1] (where rounding of the moments' updates could leave them), 0 for a cluster
/// without strength.
fn shape_factors(b: &[f64], f: &mut [f64], rho: f64) {
    let mut scale = b[0];
    for (fm, bm) in f.iter_mut().zip(b) {
        *fm = if b[0] > 0.0 && scale > 0.0 { (bm / scale).clamp(0.0, 1.0) } else { 0.0 };
        scale *= rho;
    }
}

/// Add `w |B − A| rᵐ` to `out[m]` for every `m`, r the farther of `A` and `B` from `c`: one
/// segment's radial strength moments (`w` its absolute strength, or a change of it).
fn add_radial(out: &mut [f64], pa: [f64; 3], pb: [f64; 3], c: [f64; 3], w: f64) {
    let dist =
        |x: [f64; 3], y: [f64; 3]| ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt();
    let r = dist(pa, c).max(dist(pb, c));
    let mut term = w * dist(pa, pb);
    for o in out.iter_mut() {
        *o += term;
        term *= r;
    }
}

/// Number of Taylor coefficients `a_k` with `|k| ≤ degree` ([`Indices`] lists them by degree).
fn n_coefficients(degree: usize) -> usize {
    (degree + 1) * (degree + 2) * (degree + 3) / 6
}

/// A block's points as two halves of [`LANES`], split once per block for the f64 kernels.
struct Halves([[[f64; LANES]; 3]; 2]);

impl Halves {
    fn of(px: &[f64; BLOCK], py: &[f64; BLOCK], pz: &[f64; BLOCK]) -> Self {
        Self(std::array::from_fn(|h| [px, py, pz].map(|p| std::array::from_fn(|l| p[h * LANES + l]))))
    }

    /// `f` on each half with that half's velocities, added to `u`'s.
    #[inline(always)]
    fn each(
        &self,
        u: &mut [[f64; BLOCK]; 3],
        mut f: impl FnMut(&[f64; LANES], &[f64; LANES], &[f64; LANES], &mut [[f64; LANES]; 3]),
    ) {
        for (h, [hx, hy, hz]) in self.0.iter().enumerate() {
            let mut uh = [[0.0; LANES]; 3];
            f(hx, hy, hz, &mut uh);
            for (uq, hq) in u.iter_mut().zip(&uh) {
                for l in 0..LANES {
                    uq[h * LANES + l] += hq[l];
                }
            }
        }
    }
}

/// The points of block `b` of `order` (the last point repeated past the end).
fn gather(pts: &Points, order: &[u32], b: usize) -> ([f64; BLOCK], [f64; BLOCK], [f64; BLOCK]) {
    let (mut bx, mut by, mut bz) = ([0.0; BLOCK], [0.0; BLOCK], [0.0; BLOCK]);
    for l in 0..BLOCK {
        let i = order[(b * BLOCK + l).min(order.len() - 1)] as usize;
        bx[l] = pts.x[i];
        by[l] = pts.y[i];
        bz[l] = pts.z[i];
    }
    (bx, by, bz)
}

/// Add block `b`'s velocities to its points in `out`.
fn scatter(order: &[u32], b: usize, u: &[[f64; BLOCK]; 3], out: &mut [[f64; 3]]) {
    for l in 0..BLOCK.min(order.len() - b * BLOCK) {
        let o = &mut out[order[b * BLOCK + l] as usize];
        o[0] += u[0][l];
        o[1] += u[1][l];
        o[2] += u[2][l];
    }
}

/// [`expansion_lanes`] compiled for each instruction set, chosen at run time.
/// The number type of an expansion's recurrence and sum: f64, or f32 in mixed precision. Only
/// IEEE additions, multiplications, divisions and square roots (no fused operations), so every
/// instruction set gives the same bits.
trait Lane: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + AddAssign {
    const ZERO: Self;
    const ONE: Self;
    /// `x` rounded to this type.
    fn of(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn sqrt(self) -> Self;
}

impl Lane for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn of(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

impl Lane for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
}

macro_rules! expansion_variants {
    ($($name:ident $(, $feat:literal)?);*) => {$(
        $(#[cfg(target_arch = "x86_64")] #[target_feature(enable = $feat)])?
        #[allow(clippy::too_many_arguments)] // as expansion_lanes
        fn $name<T: Lane, const N: usize>(
            idx: &Indices,
            rec: &[(T, T)],
            curl: &[[T; 3]],
            c: [f64; 3],
            px: &[f64; N],
            py: &[f64; N],
            pz: &[f64; N],
            a: &mut [[T; N]],
            u: &mut [[f64; N]; 3],
        ) {
            expansion_lanes(idx, rec, curl, c, px, py, pz, a, u);
        }
    )*};
}
expansion_variants!(expansion_generic; expansion_avx2, "avx2,fma"; expansion_avx512, "avx512f,avx2,fma");

/// [`expansion_lanes`] compiled for the instruction set `isa`.
#[allow(clippy::too_many_arguments)] // as expansion_lanes
#[inline(always)]
fn expansion_on<T: Lane, const N: usize>(
    isa: Isa,
    idx: &Indices,
    rec: &[(T, T)],
    curl: &[[T; 3]],
    c: [f64; 3],
    px: &[f64; N],
    py: &[f64; N],
    pz: &[f64; N],
    a: &mut [[T; N]],
    u: &mut [[f64; N]; 3],
) {
    match isa {
        Isa::Generic => expansion_generic(idx, rec, curl, c, px, py, pz, a, u),
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { expansion_avx2(idx, rec, curl, c, px, py, pz, a, u) },
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { expansion_avx512(idx, rec, curl, c, px, py, pz, a, u) },
    }
}

/// Taylor coefficients at `N` points and the sum over the moments, lane by lane, in the number
/// type `T`: `R = P − c` formed in f64 and rounded to `T`, the recurrence and the sum in `T`,
/// the sum added to the f64 velocities. In f64 on halves of a block ([`LANES`]); in f32 on
/// whole blocks ([`BLOCK`]).
#[allow(clippy::too_many_arguments)] // tables, coefficients, centre, points, scratch and output
#[inline(always)]
fn expansion_lanes<T: Lane, const N: usize>(
    idx: &Indices,
    rec: &[(T, T)],
    curl: &[[T; 3]],
    c: [f64; 3],
    px: &[f64; N],
    py: &[f64; N],
    pz: &[f64; N],
    a: &mut [[T; N]],
    u: &mut [[f64; N]; 3],
) {
    let mut r = [[T::ZERO; N]; 3];
    let mut inv_r2 = [T::ZERO; N];
    for l in 0..N {
        r[0][l] = T::of(px[l] - c[0]);
        r[1][l] = T::of(py[l] - c[1]);
        r[2][l] = T::of(pz[l] - c[2]);
        let r2 = r[0][l] * r[0][l] + r[1][l] * r[1][l] + r[2][l] * r[2][l];
        inv_r2[l] = T::ONE / r2;
        a[0][l] = inv_r2[l].sqrt();
    }
    // The coefficients of `curl` only: those of degree ≤ q + 1, listed by degree.
    for k in 1..curl.len() {
        let (c1, c2) = rec[k];
        let (d1, d2) = (idx.down1[k], idx.down2[k]);
        let mut acc1 = [T::ZERO; N];
        let mut acc2 = [T::ZERO; N];
        for i in 0..3 {
            if d1[i] != NONE {
                let prev = a[d1[i] as usize];
                for l in 0..N {
                    acc1[l] += r[i][l] * prev[l];
                }
            }
            if d2[i] != NONE {
                let prev = a[d2[i] as usize];
                for l in 0..N {
                    acc2[l] += prev[l];
                }
            }
        }
        let out = &mut a[k];
        for l in 0..N {
            out[l] = (c1 * acc1[l] - c2 * acc2[l]) * inv_r2[l];
        }
    }
    // a_0 (|k| = 0) has no coefficient: the velocity is a gradient's curl. Summed in registers,
    // then added to `u`.
    let mut acc = [[T::ZERO; N]; 3];
    for (b, ak) in curl.iter().zip(&a[..curl.len()]).skip(1) {
        for l in 0..N {
            acc[0][l] += ak[l] * b[0];
            acc[1][l] += ak[l] * b[1];
            acc[2][l] += ak[l] * b[2];
        }
    }
    for (uq, aq) in u.iter_mut().zip(&acc) {
        for l in 0..N {
            uq[l] += aq[l].to_f64();
        }
    }
}

/// The coefficients `B_k` (one per Taylor coefficient `a_k`) of the expansion
/// `u = Σ_m M_m × g_m`, `g_{m,i} = (m_i + 1) a_{m+e_i}`, regrouped by Taylor coefficient:
/// `u = Σ_k a_k B_k`, with `B_{m+e_i} += (m_i + 1) (M_m × e_i)` for every moment `m` and axis
/// `i`. The evaluation then costs three products per coefficient instead of nine per moment.
fn curl_coefficients(grad: &[([u32; 3], [f64; 3])], mom: &[[f64; 3]], curl: &mut [[f64; 3]]) {
    curl.fill([0.0; 3]);
    for (m, (pos, fac)) in mom.iter().zip(grad) {
        let (px, py, pz) = (pos[0] as usize, pos[1] as usize, pos[2] as usize);
        // M × e_x = (0, M_z, −M_y), M × e_y = (−M_z, 0, M_x), M × e_z = (M_y, −M_x, 0).
        curl[px][1] += fac[0] * m[2];
        curl[px][2] -= fac[0] * m[1];
        curl[py][0] -= fac[1] * m[2];
        curl[py][2] += fac[1] * m[0];
        curl[pz][0] += fac[2] * m[1];
        curl[pz][1] -= fac[2] * m[0];
    }
}

/// Every block of a leaf's moment samples: the monomials `x^k` (each its parent `up[k].0` times
/// coordinate `up[k].1`; `mono[0] = 1`) weighted by the samples' `alpha`, added to `acc` lane by
/// lane.
#[inline(always)]
fn moments_body(up: &[(u32, u8)], sm: &mut MomentSamples) {
    let (mono, acc) = (&mut sm.mono, &mut sm.acc);
    for b in (0..sm.ax.len()).step_by(LANES) {
        let lanes = |v: &[f64]| -> [f64; LANES] { v[b..b + LANES].try_into().expect("a block of lanes") };
        let alpha = [lanes(&sm.ax), lanes(&sm.ay), lanes(&sm.az)];
        let x = [lanes(&sm.xx), lanes(&sm.xy), lanes(&sm.xz)];
        for q in 0..3 {
            for l in 0..LANES {
                acc[0][q][l] += alpha[q][l];
            }
        }
        for k in 1..up.len() {
            let (parent, axis) = (up[k].0 as usize, up[k].1 as usize);
            let prev = mono[parent];
            let mut m = [0.0; LANES];
            for l in 0..LANES {
                m[l] = prev[l] * x[axis][l];
            }
            mono[k] = m;
            let a = &mut acc[k];
            for q in 0..3 {
                for l in 0..LANES {
                    a[q][l] += alpha[q][l] * m[l];
                }
            }
        }
    }
}

fn moments_generic(up: &[(u32, u8)], sm: &mut MomentSamples) {
    moments_body(up, sm);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn moments_avx2(up: &[(u32, u8)], sm: &mut MomentSamples) {
    moments_body(up, sm);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn moments_avx512(up: &[(u32, u8)], sm: &mut MomentSamples) {
    moments_body(up, sm);
}

/// Segments' ends (`a`, `b`) and absolute strengths times lengths (`w`), structure of arrays.
#[derive(Debug, Clone, Default)]
struct SegmentEnds {
    a: [Vec<f64>; 3],
    b: [Vec<f64>; 3],
    w: Vec<f64>,
}

impl SegmentEnds {
    /// The segments of `fil` in the order `perm`.
    fn load(&mut self, fil: &Filaments, perm: &[u32]) {
        for v in self.a.iter_mut().chain(self.b.iter_mut()) {
            v.clear();
        }
        self.w.clear();
        for &s in perm {
            let (a, b) = fil.segment_nodes(s as usize);
            let (pa, pb) = (fil.node(a as usize), fil.node(b as usize));
            for q in 0..3 {
                self.a[q].push(pa[q]);
                self.b[q].push(pb[q]);
            }
            let l = ((pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2) + (pb[2] - pa[2]).powi(2)).sqrt();
            self.w.push(fil.seg_g[s as usize].abs() * l);
        }
    }
}

/// `out[m] = Σ w rᵐ` over the segments `run` of `e` (r the farther end's distance from `c`),
/// [`LANES`] segments at a time (the remainder in the first lanes), summed over the lanes at
/// the end: the same order of operations on every instruction set.
#[inline(always)]
fn radial_body(e: &SegmentEnds, run: std::ops::Range<usize>, c: [f64; 3], out: &mut [f64]) {
    let np = out.len();
    let mut acc = [[0.0f64; LANES]; MAX_ORDER + 2];
    let (a, b, w) = (&e.a, &e.b, &e.w[run.clone()]);
    let (ax, ay, az) = (&a[0][run.clone()], &a[1][run.clone()], &a[2][run.clone()]);
    let (bx, by, bz) = (&b[0][run.clone()], &b[1][run.clone()], &b[2][run]);
    let n = w.len();
    for i in (0..n).step_by(LANES) {
        let k = LANES.min(n - i);
        let mut t = [0.0; LANES];
        let mut r = [0.0; LANES];
        for l in 0..k {
            let j = i + l;
            let da = (ax[j] - c[0]).powi(2) + (ay[j] - c[1]).powi(2) + (az[j] - c[2]).powi(2);
            let db = (bx[j] - c[0]).powi(2) + (by[j] - c[1]).powi(2) + (bz[j] - c[2]).powi(2);
            r[l] = if da > db { da } else { db }.sqrt();
            t[l] = w[j];
        }
        for am in acc[..np].iter_mut() {
            for l in 0..LANES {
                am[l] += t[l];
                t[l] *= r[l];
            }
        }
    }
    for (o, am) in out.iter_mut().zip(&acc) {
        *o = am.iter().sum();
    }
}

fn radial_generic(e: &SegmentEnds, run: std::ops::Range<usize>, c: [f64; 3], out: &mut [f64]) {
    radial_body(e, run, c, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn radial_avx2(e: &SegmentEnds, run: std::ops::Range<usize>, c: [f64; 3], out: &mut [f64]) {
    radial_body(e, run, c, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
fn radial_avx512(e: &SegmentEnds, run: std::ops::Range<usize>, c: [f64; 3], out: &mut [f64]) {
    radial_body(e, run, c, out);
}

/// Centre of the bounding box of the segments' ends, the largest distance of an end from it,
/// and the box's lower and upper corners.
fn bounding_ball(fil: &Filaments, segs: &[u32]) -> ([f64; 3], f64, [f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    // Plain comparisons rather than f64::min/max: the nodes are finite, and these compile to
    // single min/max instructions.
    for &s in segs {
        let (a, b) = fil.segment_nodes(s as usize);
        for n in [a, b] {
            let p = fil.node(n as usize);
            for q in 0..3 {
                lo[q] = if p[q] < lo[q] { p[q] } else { lo[q] };
                hi[q] = if p[q] > hi[q] { p[q] } else { hi[q] };
            }
        }
    }
    let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
    let mut r2 = 0.0_f64;
    for &s in segs {
        let (a, b) = fil.segment_nodes(s as usize);
        for n in [a, b] {
            let p = fil.node(n as usize);
            let d2 = (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2);
            r2 = if d2 > r2 { d2 } else { r2 };
        }
    }
    (c, r2.sqrt(), lo, hi)
}

/// Gauss–Legendre points and weights on [0, 1] (weights sum to 1), `n` points, exact for
/// polynomials of degree ≤ 2n − 1.
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // Newton on P_n from the Chebyshev guess.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pm = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pm) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((0.5 * (1.0 + x), 0.5 * w));
    }
    out
}

/// An order of the points in which consecutive blocks of sixteen (the traversal's blocks) are
/// close together: median splits along the longest side, at multiples of sixteen.
pub(crate) fn block_order(pts: &Points, order: &mut Vec<u32>, stack: &mut Vec<(usize, usize)>) {
    order.clear();
    order.extend(0..pts.len() as u32);
    stack.clear();
    stack.push((0, pts.len()));
    while let Some((start, end)) = stack.pop() {
        if end - start <= BLOCK {
            continue;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let coord = |i: u32, q: usize| match q {
            0 => pts.x[i as usize],
            1 => pts.y[i as usize],
            _ => pts.z[i as usize],
        };
        for &i in &order[start..end] {
            for q in 0..3 {
                lo[q] = lo[q].min(coord(i, q));
                hi[q] = hi[q].max(coord(i, q));
            }
        }
        let axis = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b]))).unwrap_or(0);
        let n_blocks = (end - start).div_ceil(BLOCK);
        let k = (n_blocks / 2) * BLOCK;
        order[start..end].select_nth_unstable_by(k, |&a, &b| coord(a, axis).total_cmp(&coord(b, axis)));
        stack.push((start, start + k));
        stack.push((start + k, end));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aic::{WakePart, build_known_wake};
    use crate::biot_savart::CoreModel;
    use crate::induce::induced_velocity;

    /// A small deterministic generator in [0, 1).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn max_error(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(u, v)| ((u[0] - v[0]).powi(2) + (u[1] - v[1]).powi(2) + (u[2] - v[2]).powi(2)).sqrt())
            .fold(0.0, f64::max)
    }

    #[test]
    fn gauss_legendre_is_exact() {
        for n in 1..=7 {
            let g = gauss_legendre(n);
            for deg in 0..2 * n {
                let q: f64 = g.iter().map(|(t, w)| w * t.powi(deg as i32)).sum();
                assert!((q - 1.0 / (deg as f64 + 1.0)).abs() < 1e-14, "n {n} degree {deg}: {q}");
            }
        }
    }

    /// Random segments (a cloud 4 × 2 × 1 with random strengths of both signs) and points in and
    /// around it (a box 16 × 12 × 6 about it): at every order the treecode is within its tolerance of the direct sum at every
    /// point (1e-6 at orders 4 to 8, 1e-3 at order 3), and it did aggregate (the check can
    /// fail).
    #[test]
    fn treecode_matches_direct_on_random_segments() {
        let mut rng = Lcg(7);
        let mut fil = Filaments::default();
        let core = CoreModel::CutOff { radius: 1e-9 };
        for _ in 0..3000 {
            let a = [4.0 * rng.next(), 2.0 * rng.next(), rng.next()];
            let b = [a[0] + 0.1 * (rng.next() - 0.5), a[1] + 0.1 * (rng.next() - 0.5), a[2] + 0.1 * (rng.next() - 0.5)];
            let (ia, ib) = (fil.push_node(a), fil.push_node(b));
            fil.push_segment(ia, ib, 2.0 * rng.next() - 1.0, &core);
        }
        let pts: Vec<[f64; 3]> =
            (0..300).map(|_| [16.0 * rng.next() - 6.0, 12.0 * rng.next() - 5.0, 6.0 * rng.next() - 2.5]).collect();
        let direct = induced_velocity(&[&fil], &pts);
        for (order, tol) in [(3, 1e-3), (4, 1e-6), (6, 1e-6), (8, 1e-6)] {
            let mut tree = Treecode::new(order, 32);
            tree.build(&fil);
            let u = tree.velocity(&pts, tol);
            let err = max_error(&u, &direct);
            assert!(err <= tol, "order {order}: error {err:e} > {tol:e}");
            assert!(tree.stats().n_expansions > 0, "order {order}: nothing aggregated");
        }
        // A loose tolerance aggregates more and stays within it.
        let mut tree = Treecode::new(4, 32);
        tree.build(&fil);
        let u = tree.velocity(&pts, 1e-3);
        assert!(max_error(&u, &direct) <= 1e-3);
    }

    /// The error bound is attained, so it cannot be tightened: a short segment across the line
    /// from the cluster's centre to the point, at the cluster's radius on that line, is the
    /// worst case of `(n + 1)|ξ|ⁿ/|R|ⁿ⁺²` for every degree n (γ = 0). The cluster holds it and a
    /// weak segment opposite (to put the centre between them); with the tolerance set at the
    /// bound the root is accepted at order p, and the error is the bound to within the
    /// segment's length (1e-3 of the radius; measured 1 − 2e-5 to 1 − 3e-6). The former bound
    /// with `(2n + 1)` in place of `(n + 1)` is 1.8–1.9 times the error here.
    ///
    /// With the strong segment at half the radius (weak ones at ±ρ) the shape factor `2^{-(p+1)}`
    /// makes the bound's leading term that segment's: at t = 0.1 the error is about 0.93 of the
    /// bound (its tail is bounded at the radius), where a factor taken at the wrong power or
    /// radius would be off by 2 or more.
    #[test]
    fn error_bound_is_attained_on_the_axis() {
        let core = CoreModel::CutOff { radius: 1e-12 };
        let cluster = |segs: &[(f64, f64)], h: f64| {
            let mut fil = Filaments::default();
            for &(x, g) in segs {
                let (a, b) = (fil.push_node([x, 0.0, -h]), fil.push_node([x, 0.0, h]));
                fil.push_segment(a, b, g, &core);
            }
            fil
        };
        // The inside segment is longer (4 % of the radius): the direct sum of a segment of
        // length l at distance d carries a rounding of about ε (d/l)², which must stay well
        // below the truncation error at t = 0.1.
        let at_radius = cluster(&[(1.0, 1.0), (-1.0, 1e-9)], 1e-3);
        let inside = cluster(&[(0.5, 1.0), (1.0, 1e-9), (-1.0, 1e-9)], 2e-2);
        let cases =
            [(&at_radius, &[0.3, 0.5, 0.7][..], &[2, 4, 6, 8][..], 0.999), (&inside, &[0.1][..], &[2, 4, 6][..], 0.9)];
        for (fil, ts, orders, lo) in cases {
            for &t in ts {
                for &order in orders {
                    let mut tree = Treecode::new(order, 32);
                    tree.build(fil);
                    let radius = tree.clusters[0].radius;
                    let d = radius / t;
                    let f = tree.shape[order + 1];
                    let bound = tree.total_strength * f * tail_bound(t, order as i32) / (d * d);
                    let pts = [[d, 0.0, 0.0]];
                    let exact = induced_velocity(&[fil], &pts);
                    let u = tree.velocity(&pts, bound * (1.0 + 1e-9));
                    assert_eq!(tree.stats().n_direct_pairs, 0, "t {t} order {order}: not aggregated");
                    let ratio = max_error(&u, &exact) / bound;
                    println!("t {t} order {order}: shape {f:.3e}, error / bound {ratio:.6}");
                    assert!((lo..=1.0).contains(&ratio), "t {t} order {order}: error / bound {ratio}");
                }
            }
        }
    }

    /// The bound with the clusters' shape factors holds where they matter: 400 random clusters
    /// of a few short segments of both signs, one strong segment well inside the ball of weak
    /// ones, evaluated at a point at ρ/t in a random direction (t from 0.2 to 0.8) with the
    /// tolerance set at the cluster's bound (so the root is accepted): the error is within it
    /// every time, and the shape factors are below 1/4 on average.
    #[test]
    fn shape_factor_bound_holds_on_random_clusters() {
        let core = CoreModel::CutOff { radius: 1e-12 };
        let mut rng = Lcg(11);
        let unit = |rng: &mut Lcg| loop {
            let v = [2.0 * rng.next() - 1.0, 2.0 * rng.next() - 1.0, 2.0 * rng.next() - 1.0];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.1 && n <= 1.0 {
                return [v[0] / n, v[1] / n, v[2] / n];
            }
        };
        let (mut worst, mut fsum) = (0.0f64, 0.0);
        for case in 0..400 {
            let mut fil = Filaments::default();
            for k in 0..6 {
                let (r, g) = if k == 0 {
                    (0.4 * rng.next(), 1.0)
                } else {
                    (0.8 + 0.2 * rng.next(), 1e-3 * (2.0 * rng.next() - 1.0))
                };
                let (e, dl) = (unit(&mut rng), unit(&mut rng));
                let a = [r * e[0], r * e[1], r * e[2]];
                let b = [a[0] + 0.05 * dl[0], a[1] + 0.05 * dl[1], a[2] + 0.05 * dl[2]];
                let (ia, ib) = (fil.push_node(a), fil.push_node(b));
                fil.push_segment(ia, ib, g, &core);
            }
            let order = 2 + case % 7;
            let t = 0.2 + 0.6 * rng.next();
            let mut tree = Treecode::new(order, 32);
            tree.build(&fil);
            let (c, radius) = (tree.clusters[0].center, tree.clusters[0].radius);
            let f = tree.shape[order + 1];
            fsum += f;
            let d = radius / t;
            let e = unit(&mut rng);
            let pts = [[c[0] + d * e[0], c[1] + d * e[1], c[2] + d * e[2]]];
            let bound = tree.total_strength * f * tail_bound(t, order as i32) / (d * d);
            let exact = induced_velocity(&[&fil], &pts);
            let u = tree.velocity(&pts, bound * (1.0 + 1e-9));
            assert_eq!(tree.stats().n_direct_pairs, 0, "case {case}: not aggregated");
            let ratio = max_error(&u, &exact) / bound;
            assert!(ratio <= 1.0, "case {case}, order {order}, t {t}: error / bound {ratio}");
            worst = worst.max(ratio);
        }
        println!("largest error / bound {worst:.3}, mean shape factor {:.3}", fsum / 400.0);
        assert!(fsum / 400.0 < 0.25, "mean shape factor {}", fsum / 400.0);
    }

    /// The f32 expansions give the same bits on every instruction set the machine has (no fused
    /// operations, IEEE division and square root), and agree with the f64 ones to about 1e-6 of
    /// the velocity.
    #[test]
    fn f32_expansions_agree_across_instruction_sets() {
        let mut rng = Lcg(3);
        let core = CoreModel::CutOff { radius: 1e-9 };
        let mut fil = Filaments::default();
        for _ in 0..200 {
            let a = [rng.next(), rng.next(), 0.2 * rng.next()];
            let b = [a[0] + 0.1 * rng.next(), a[1] + 0.1 * rng.next(), a[2]];
            let (ia, ib) = (fil.push_node(a), fil.push_node(b));
            fil.push_segment(ia, ib, 2.0 * rng.next() - 1.0, &core);
        }
        let mut tree = Treecode::new(6, 256);
        tree.set_mixed(true);
        tree.build(&fil);
        let nt = tree.taylor_idx.k.len();
        let (curl32, curl) = (&tree.curl32[..nt], &tree.curl[..nt]);
        let c = tree.clusters[0].center;
        let p: [[f64; BLOCK]; 3] = std::array::from_fn(|q| std::array::from_fn(|_| 4.0 + 3.0 * rng.next() - q as f64));
        let run = |isa: Isa| {
            let mut a = vec![[0.0f32; BLOCK]; nt];
            let mut u = [[0.0; BLOCK]; 3];
            // Called with an instruction set only when it is detected below.
            expansion_on(isa, &tree.taylor_idx, &tree.rec32, curl32, c, &p[0], &p[1], &p[2], &mut a, &mut u);
            u
        };
        let generic = run(Isa::Generic);
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            assert_eq!(run(Isa::Avx2), generic, "AVX2");
            if std::is_x86_feature_detected!("avx512f") {
                assert_eq!(run(Isa::Avx512), generic, "AVX-512");
            }
        }
        let mut a = vec![[0.0; LANES]; nt];
        for h in 0..2 {
            let half = |q: usize| -> [f64; LANES] { std::array::from_fn(|l| p[q][h * LANES + l]) };
            let mut u = [[0.0; LANES]; 3];
            expansion_generic(&tree.taylor_idx, &tree.rec, curl, c, &half(0), &half(1), &half(2), &mut a, &mut u);
            for l in 0..LANES {
                let (v, w) = ([0, 1, 2].map(|q| u[q][l]), [0, 1, 2].map(|q| generic[q][h * LANES + l]));
                let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let e = ((v[0] - w[0]).powi(2) + (v[1] - w[1]).powi(2) + (v[2] - w[2]).powi(2)).sqrt();
                assert!(e <= 2e-6 * n, "lane {}: f32 {w:?} against f64 {v:?}", h * LANES + l);
            }
        }
    }

    /// The wake of the paper's wing after 120 steps (120 rows, 25 m/s, dt 0.01 s, 5°, folding,
    /// closure legs, a mirror plane): at the collocation points and at points spread over the
    /// wake the treecode is within 1e-6 |V∞| of the direct sum.
    #[test]
    fn treecode_matches_direct_on_a_real_wake() {
        use crate::samples::FlaredWing;
        use crate::{ImagePlane, Lattice, Uvlm, UvlmParams};
        let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
        let lat = Lattice::from_stations(wing.spec(), &wing.stations(0.0)).unwrap();
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.n_wake_rows = 120;
        p.wake_closure = true;
        p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
        p.wake_core = CoreModel::CutOff { radius: 0.01 };
        let mut uv = Uvlm::new(lat, p.clone()).unwrap();
        for k in 0..120 {
            let fold = 0.3 * (0.05 * k as f64).sin();
            uv.update_stations(&wing.stations(fold), None).unwrap();
            uv.step(0.01).unwrap();
        }
        let lat = uv.lattice();
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let te = &lat.ring_nodes()[m * (n + 1)..];
        let mut fil = Filaments::default();
        let dir = Some([0.0, -1.0, 0.0]);
        build_known_wake(&mut fil, te, uv.wake(), dir, &p.wake_core, &p.bound_core, &p.images, WakePart::All);
        let mut pts: Vec<[f64; 3]> = lat.collocation().to_vec();
        for r in (0..120).step_by(7) {
            for j in (0..=n).step_by(3) {
                let q = uv.wake().node(r, j);
                pts.push([q[0] + 0.1, q[1] + 0.05, q[2] + 0.2]);
            }
        }
        let direct = induced_velocity(&[&fil], &pts);
        let tol = 1e-6 * 25.0;
        for (order, mixed) in [(4, false), (6, false), (8, false), (4, true), (6, true), (8, true)] {
            let mut tree = Treecode::new(order, 64);
            tree.set_mixed(mixed);
            tree.build(&fil);
            let u = tree.velocity(&pts, tol);
            let err = max_error(&u, &direct);
            println!("order {order}, mixed {mixed}: error {err:.3e} m/s, stats {:?}", tree.stats());
            assert!(err <= tol, "order {order}, mixed {mixed}: error {err:e}");
            assert!(tree.stats().n_expansions > 0);
        }
    }
}
