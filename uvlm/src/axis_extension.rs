//! The bound filaments' induction at the load points, regular on the filaments' axis extensions.
//!
//! The kernel of [`crate::biot_savart`] writes a segment's factor as
//! `(|r₁|+|r₂|)(|r₁||r₂| − r₁·r₂) / (|r₁||r₂| (|r₁×r₂|² + r_c²|r₀|²))` and zeroes it closer than
//! the cut-off radius to the segment's *axis*. On the axis beyond the segment's end points
//! (`r₁·r₂ > 0`) the law is regular and vanishes linearly with the distance `d` to the axis, but
//! there `|r₁||r₂| − r₁·r₂ ≈ |r₁×r₂|²/(2|r₁||r₂|)` cancels (relative rounding error
//! `ε |r₁|²|r₂|²/|r₁×r₂|²`), and the cut-off zeroes it within `r_c` of the axis. Every load point
//! of a ring lattice (a segment's midpoint) lies on the axis extensions of the other segments of
//! its row and column (and of its column's trailing leg when the chord is along the stream), so
//! on a nearly straight row the loads jumped by `O(r_c)` where a point crossed the cut-off
//! cylinder and carried rounding noise of order `ε/d` just outside it: they were not
//! differentiable at the scale of the structure's difference quotients (docs/uvlm.md §3).
//!
//! Here, outside the segment (`r₁·r₂ > 0`) the same law is evaluated in its regular form
//!
//! $$ u = \frac{\Gamma}{4\pi}\,(r_1\times r_2)\,\frac{(|r_1|+|r_2|)\,|r_1\times r_2|^2}
//!        {|r_1||r_2|\,(|r_1||r_2| + r_1\cdot r_2)\,(|r_1\times r_2|^2 + r_c^2|r_0|^2)} $$
//!
//! (no cancellation; no cut-off unless an end point is within the cut-off radius), and upstream of
//! a semi-infinite leg's start (`d·r < 0`) as `(d × r)|d×r|² / ((|d×r|² + r_c²) |r| (|r| − d·r))`.
//! Inside the segment (or downstream along a leg) it is the crate's kernel, cut-off included.

use crate::aic::WakePart;
use crate::biot_savart::{CoreModel, Filaments, INV_FOUR_PI, Isa, isa};
use crate::induce::{Points, use_threads};
use crate::params::Parallel;
use crate::wake::Wake;
use rayon::prelude::*;

/// A segment pair seen from a load point (`u = Γ/4π · k · r₁×r₂`): `r₁×r₂`, `r₁·r₂`, the block
/// kernels' factor `k` (their arithmetic, so that the term they added is removed exactly) and the
/// regular form's `k` outside the segment (`r₁·r₂ > 0`; zero only within the cut-off radius of an
/// end point). Branch-free, so that [`run_factors`] compiles to vector instructions; the caller
/// uses the regular factor only outside the segment.
#[inline(always)]
fn pair_factors(r1: [f64; 3], r2: [f64; 3], core2: f64, cut2: f64) -> ([f64; 3], f64, f64, f64) {
    let c = [r1[1] * r2[2] - r1[2] * r2[1], r1[2] * r2[0] - r1[0] * r2[2], r1[0] * r2[1] - r1[1] * r2[0]];
    let h = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let n1 = (r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]).sqrt();
    let n2 = (r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]).sqrt();
    let dot = r1[0] * r2[0] + r1[1] * r2[1] + r1[2] * r2[2];
    let n12 = n1 * n2;
    let l2 = (r1[0] - r2[0]).powi(2) + (r1[1] - r2[1]).powi(2) + (r1[2] - r2[2]).powi(2);
    let rc2 = if l2 > 0.0 { cut2 / l2 } else { f64::INFINITY };
    let core = if core2 > 0.0 { h / (h + core2) } else { 1.0 };
    let regular = (n1 + n2) / (n12 * (n12 + dot)) * core;
    let new = if n1 * n1 <= rc2 || n2 * n2 <= rc2 { 0.0 } else { regular };
    let h2 = h + core2;
    let kernel = (n1 + n2) * (n12 - dot) / (n12 * h2);
    let old = if h2 > cut2 && n12 > 0.0 { kernel } else { 0.0 };
    (c, dot, old, new)
}

/// The factor `k` of a semi-infinite leg pair (`u = Γ/4π · k · d×r`) for the load points.
#[inline]
pub(crate) fn leg_factor(r: [f64; 3], d: [f64; 3], core2: f64, cut2: f64) -> ([f64; 3], f64) {
    let c = [d[1] * r[2] - d[2] * r[1], d[2] * r[0] - d[0] * r[2], d[0] * r[1] - d[1] * r[0]];
    let h = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let rn = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let dr = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
    if dr < 0.0 {
        // Upstream of the start: |r| + d·r = |d×r|² / (|r| − d·r).
        if rn * rn <= cut2 {
            return (c, 0.0);
        }
        let core = if core2 > 0.0 { h / (h + core2) } else { 1.0 };
        return (c, core / (rn * (rn - dr)));
    }
    if h > cut2 && rn > 0.0 { (c, (rn + dr) / ((h + core2) * rn)) } else { (c, 0.0) }
}

/// One surface's place in the bound system, for [`correct_axis_extensions`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct SurfaceLayout {
    /// Its first segment and its number of load segments (load points, in segment order).
    pub(crate) seg0: usize,
    pub(crate) n_load: usize,
    /// Its lattice segments (a finite steady wake's legs follow them).
    pub(crate) n_lattice_seg: usize,
    /// Chordwise and spanwise panels.
    pub(crate) m: usize,
    pub(crate) n: usize,
    /// Its first semi-infinite leg.
    pub(crate) leg0: usize,
    /// Whether its trailing legs are the segments of a finite steady wake.
    pub(crate) finite: bool,
}

/// The bound system's layout: surfaces, base filaments and image copies.
#[derive(Debug, Clone, Default)]
pub(crate) struct ExtensionLayout {
    pub(crate) surfaces: Vec<SurfaceLayout>,
    pub(crate) n_base_seg: usize,
    pub(crate) n_base_leg: usize,
    pub(crate) n_copies: usize,
}

impl ExtensionLayout {
    /// The segment pairs [`correct_axis_extensions`] evaluates (a bound on them: every point
    /// takes the longer of its row and its column).
    fn n_axis_pairs(&self) -> usize {
        self.surfaces.iter().map(|sl| sl.n_load * (sl.n.max(sl.m + 1))).sum::<usize>() * self.n_copies
    }
}

/// The crate kernel's factor of a leg pair, with the block kernels' arithmetic.
#[inline]
fn kernel_leg(r: [f64; 3], d: [f64; 3], core2: f64, cut2: f64) -> f64 {
    let cx = d[1] * r[2] - d[2] * r[1];
    let cy = d[2] * r[0] - d[0] * r[2];
    let cz = d[0] * r[1] - d[1] * r[0];
    let h2 = cx * cx + cy * cy + cz * cz;
    let rn = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let dot = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
    if h2 > cut2 && rn > 0.0 { (rn + dot) / ((h2 + core2) * rn) } else { 0.0 }
}

/// Replace, in the bound filaments' induction `u` at the load points `pts` (every surface's
/// lattice segment midpoints, as [`crate::Uvlm`] lists them), the block kernels' term of every
/// filament whose axis passes along the point's row or column — the segments of its row (a
/// spanwise point) or column (a chordwise point) with their image copies, and its column's
/// trailing leg — by the regular form of [`pair_factors`] and [`leg_factor`] where the point
/// lies outside the segment (module doc). Other filaments are never collinear with a load point
/// of a ring lattice by construction, and keep the block kernels' value.
///
/// With `cutoff_only` (`u` summed by the mixed-precision kernel, which takes the regular form
/// outside the filaments itself: mixed.rs) only the filaments whose cut-off cylinder holds the
/// point are corrected, where the kernel's cut-off zeroed what the regular form keeps.
pub(crate) fn correct_axis_extensions(
    fil: &Filaments,
    layout: &ExtensionLayout,
    pts: &Points,
    u: &mut [[f64; 3]],
    parallel: Parallel,
    cutoff_only: bool,
) {
    let points = |p0: usize, out: &mut [[f64; 3]]| correct_axis_points(fil, layout, pts, p0, out, cutoff_only);
    if use_threads(parallel, AXIS_PAIR_COST * layout.n_axis_pairs()) {
        u.par_chunks_mut(AXIS_CHUNK).enumerate().for_each(|(c, out)| points(c * AXIS_CHUNK, out));
    } else {
        points(0, u);
    }
}

/// Load points per task of a threaded [`correct_axis_extensions`].
const AXIS_CHUNK: usize = 48;

/// The cost of a regular-form pair of [`correct_axis_extensions`] in block-kernel pairs (its two
/// square roots and two divisions against the kernel's share of a node's), for
/// [`use_threads`].
const AXIS_PAIR_COST: usize = 4;

/// [`correct_axis_extensions`] at the load points `p0..p0 + out.len()`, into `out`. Copy by
/// copy, then point by point (each point takes its corrections in the same order as point by
/// point, copy by copy); the segments of a spanwise row are gathered once for the row's points.
fn correct_axis_points(
    fil: &Filaments,
    layout: &ExtensionLayout,
    pts: &Points,
    p0: usize,
    out: &mut [[f64; 3]],
    cutoff_only: bool,
) {
    let mut ch = RunChunk::new();
    ch.cutoff_only = cutoff_only;
    let mut row = RowCache::new();
    for c in 0..layout.n_copies {
        let seg = |b: usize| c * layout.n_base_seg + b;
        let mut base = 0;
        for sl in &layout.surfaces {
            let (m, n) = (sl.m, sl.n);
            let nc = n + 1;
            let (lo, hi) = (p0.max(base), (p0 + out.len()).min(base + sl.n_load));
            for p in lo..hi {
                let s = p - base;
                let x = [pts.x[p], pts.y[p], pts.z[p]];
                let o = &mut out[p - p0];
                if s < m * n || s >= m * n + m * nc {
                    // A spanwise point: the segments of its row.
                    let i = if s < m * n { s / n } else { m };
                    let first = if i < m { sl.seg0 + i * n } else { sl.seg0 + m * n + m * nc };
                    match row.segments(fil, (seg(first), n)) {
                        Some(segs) => fix_run(&mut ch, segs.iter().copied(), x, o),
                        None => fix_run(&mut ch, (first..first + n).map(|b| filament(fil, seg(b))), x, o),
                    }
                } else {
                    // A chordwise point: the segments of its column and its trailing leg.
                    let j = (s - m * n) % nc;
                    let column = (0..m).map(|i| sl.seg0 + m * n + i * nc + j);
                    let finite = sl.finite.then_some(sl.seg0 + sl.n_lattice_seg + j);
                    fix_run(&mut ch, column.chain(finite).map(|b| filament(fil, seg(b))), x, o);
                    if !sl.finite && layout.n_base_leg > 0 {
                        fix_leg(fil, c * layout.n_base_leg + sl.leg0 + j, x, o, cutoff_only);
                    }
                }
            }
            base += sl.n_load;
        }
    }
}

/// Segments a [`RowCache`] holds (longer rows are gathered point by point).
const ROW_CACHE: usize = 256;

/// The consecutive segments of one spanwise row of the bound system, gathered once for the
/// row's load points rather than once per point (a fixed array: the loop does not allocate).
struct RowCache {
    /// The first filament and the count held.
    held: Option<(usize, usize)>,
    segs: [Segment; ROW_CACHE],
}

impl RowCache {
    fn new() -> Self {
        Self { held: None, segs: [([0.0; 3], [0.0; 3], (0.0, 0.0, 0.0)); ROW_CACHE] }
    }

    /// The `len` filaments of `fil` from `first`, gathered if they are not held; `None` for a
    /// row longer than the cache.
    fn segments(&mut self, fil: &Filaments, (first, len): (usize, usize)) -> Option<&[Segment]> {
        if len > ROW_CACHE {
            return None;
        }
        if self.held != Some((first, len)) {
            for (s, f) in self.segs.iter_mut().zip(first..first + len) {
                *s = filament(fil, f);
            }
            self.held = Some((first, len));
        }
        Some(&self.segs[..len])
    }
}

/// Replace, at every chordwise load point of `layout` (a point on the axis extension of its
/// column's streamwise filaments, and of the wake's filaments leaving that column's trailing-edge
/// node when the chord is along the stream), the block kernels' term of every filament of the
/// wake set `wake` by the regular form where the point lies outside it: the linear model's frozen
/// wake and its unit rings then take the terms the steady solve's trailing legs (or finite wake)
/// take (docs/uvlm.md §3). A filament off the point's axis changes by rounding only.
pub(crate) fn correct_wake_extensions(wake: &Filaments, layout: &ExtensionLayout, pts: &Points, u: &mut [[f64; 3]]) {
    let mut ch = RunChunk::new();
    let mut p = 0;
    for sl in &layout.surfaces {
        let (m, n) = (sl.m, sl.n);
        for s in 0..sl.n_load {
            let i = p;
            p += 1;
            if s < m * n || s >= m * n + m * (n + 1) {
                continue;
            }
            let x = [pts.x[i], pts.y[i], pts.z[i]];
            fix_run(&mut ch, (0..wake.n_segments()).map(|f| filament(wake, f)), x, &mut u[i]);
            for l in 0..wake.n_legs() {
                fix_leg(wake, l, x, &mut u[i], false);
            }
        }
    }
}

/// One surface's known wake as [`crate::aic::append_known_wake`] lays it out, for
/// [`correct_wake_columns`].
pub(crate) struct WakeColumns<'a> {
    /// The trailing-edge nodes (node row 0), the wake and its closure direction.
    pub(crate) te: &'a [[f64; 3]],
    pub(crate) wake: &'a Wake,
    pub(crate) closure: Option<[f64; 3]>,
    pub(crate) core: &'a CoreModel,
    pub(crate) part: WakePart,
    /// Correct only the filaments whose cut-off cylinder holds the point (where the kernel's
    /// cut-off zeroes what the regular form keeps); elsewhere outside a filament the two forms
    /// are the same law and differ by rounding. For a wake summed through the treecode, whose
    /// far clusters are expansions of the singular law, not the kernel.
    pub(crate) cutoff_only: bool,
}

/// The time march's counterpart of [`correct_wake_extensions`] without a pass over the whole
/// wake: at the chordwise load points of surface `sl` (from `p0` in `pts`), the streamwise
/// filaments of their own column in the part `w.part` of the wake (the chordwise legs from node
/// row k − 1 to k and the closure leg, with the strengths, cores and arithmetic of
/// [`crate::aic::append_known_wake`]) take the regular form where the point lies outside them.
/// Those are the filaments whose axis passes near the point: the steady solve's trailing leg (or
/// finite wake) of that column, cut into rows.
pub(crate) fn correct_wake_columns(
    sl: &SurfaceLayout,
    p0: usize,
    w: &WakeColumns<'_>,
    pts: &Points,
    u: &mut [[f64; 3]],
) {
    let (wake, len) = (w.wake, w.wake.n_rows());
    let (m, n) = (sl.m, sl.n);
    let nc = n + 1;
    if len == 0 || sl.n_load < m * n + m * nc {
        return;
    }
    let rows = match w.part {
        WakePart::All => 1..=len,
        WakePart::Near => 1..=1,
        WakePart::Far => 2..=len,
    };
    let pos = |k: usize, j: usize| if k == 0 { w.te[j] } else { wake.node(k - 1, j) };
    let g = |r: usize, j: isize| if j >= 0 && (j as usize) < n { wake.gamma(r, j as usize) } else { 0.0 };
    if w.cutoff_only {
        cutoff_columns(sl, p0, w, pts, u, rows.clone());
    }
    let mut ch = RunChunk::new();
    for s in m * n..m * n + m * nc {
        let j = (s - m * n) % nc;
        let i = p0 + s;
        let x = [pts.x[i], pts.y[i], pts.z[i]];
        if !w.cutoff_only {
            // The column's nodes row by row: each row's node ends one leg and starts the next.
            let mut b = pos(rows.start() - 1, j);
            let column = rows.clone().filter_map(|k| {
                let a = b;
                b = pos(k, j);
                let gamma = g(k - 1, j as isize - 1) - g(k - 1, j as isize);
                (gamma != 0.0).then(|| {
                    let len2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2);
                    let (core2, cut2) = w.core.coefficients(len2, len2.sqrt());
                    (a, b, (gamma * INV_FOUR_PI, core2, cut2))
                })
            });
            fix_run(&mut ch, column, x, &mut u[i]);
        }
        if let Some(dir) = w.closure
            && w.part != WakePart::Near
        {
            let gamma = g(len - 1, j as isize - 1) - g(len - 1, j as isize);
            if gamma != 0.0 {
                let (a, b) = (pos(len, j), pos(len - 1, j));
                let l = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
                let (core2, cut2) = w.core.leg_coefficients(l);
                fix_leg_at(a, dir, (gamma * INV_FOUR_PI, core2, cut2), x, &mut u[i]);
            }
        }
    }
}

/// [`correct_wake_columns`] with `cutoff_only`: the streamwise filaments of each column, [`RUN`]
/// rows at a time (their strengths and cores computed once for the column's points), corrected
/// at each of the column's load points only where the point lies in the filament's cut-off
/// cylinder (`|r₁×r₂|² + core2 ≤ cut2`, the kernel's own test).
///
/// The rows go in chunks of [`RUN`] across all the columns, so that the chunk's node rows, one
/// cache line per two or three nodes, are read from memory once for the columns that share them
/// rather than once per column. Each point still takes its filaments in row order, one at a
/// time ([`flush_run`]), so the chunking does not change its sums.
fn cutoff_columns(
    sl: &SurfaceLayout,
    p0: usize,
    w: &WakeColumns<'_>,
    pts: &Points,
    u: &mut [[f64; 3]],
    rows: std::ops::RangeInclusive<usize>,
) {
    let (m, n, wake) = (sl.m, sl.n, w.wake);
    let nc = n + 1;
    let mut ch = RunChunk::new();
    let pos = |k: usize, j: usize| if k == 0 { w.te[j] } else { wake.node(k - 1, j) };
    let g = |r: usize, j: isize| if j >= 0 && (j as usize) < n { wake.gamma(r, j as usize) } else { 0.0 };
    let mut legs = [([0.0; 3], [0.0; 3], (0.0, 0.0, 0.0)); RUN];
    let (first, last) = (*rows.start(), *rows.end());
    let mut k0 = first;
    while k0 <= last {
        let k1 = (k0 + RUN - 1).min(last);
        for j in 0..nc {
            let mut b = pos(k0 - 1, j);
            let mut count = 0;
            for k in k0..=k1 {
                let a = b;
                b = pos(k, j);
                let gamma = g(k - 1, j as isize - 1) - g(k - 1, j as isize);
                if gamma != 0.0 {
                    let len2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2);
                    let (core2, cut2) = w.core.coefficients(len2, len2.sqrt());
                    legs[count] = (a, b, (gamma * INV_FOUR_PI, core2, cut2));
                    count += 1;
                }
            }
            for row in 0..m {
                let i = p0 + m * n + row * nc + j;
                let x = [pts.x[i], pts.y[i], pts.z[i]];
                let inside =
                    legs[..count].iter().filter(|(a, b, (_, core2, cut2))| in_cutoff(x, *a, *b, *core2, *cut2));
                fix_run(&mut ch, inside.copied(), x, &mut u[i]);
            }
        }
        k0 = k1 + 1;
    }
}

/// Whether `x` lies in the cut-off cylinder of the segment `a → b` (the kernel's test,
/// `|r₁×r₂|² + core2 ≤ cut2`), where the kernel zeroes its term.
#[inline]
fn in_cutoff(x: [f64; 3], a: [f64; 3], b: [f64; 3], core2: f64, cut2: f64) -> bool {
    let (r1, r2) = ([x[0] - a[0], x[1] - a[1], x[2] - a[2]], [x[0] - b[0], x[1] - b[1], x[2] - b[2]]);
    let c = [r1[1] * r2[2] - r1[2] * r2[1], r1[2] * r2[0] - r1[0] * r2[2], r1[0] * r2[1] - r1[1] * r2[0]];
    c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + core2 <= cut2
}

/// Segments per chunk of [`fix_run`].
const RUN: usize = 32;

/// A chunk of segments of [`fix_run`] seen from one point, laid out by lanes so that
/// [`run_factors`] compiles to vector instructions: the inputs (`r₁`, `r₂`, `Γ/4π`, `core2`,
/// `cut2`) and what it writes (`r₁·r₂`, `r₁×r₂` and the kernel's and the regular form's `Γk/4π`).
struct RunChunk {
    r1: [[f64; RUN]; 3],
    r2: [[f64; RUN]; 3],
    g: [f64; RUN],
    core2: [f64; RUN],
    cut2: [f64; RUN],
    dot: [f64; RUN],
    c: [[f64; RUN]; 3],
    old: [f64; RUN],
    new: [f64; RUN],
    /// Correct only the lanes whose point the kernel's cut-off held (`old` zero): where the
    /// mixed-precision kernel, which takes the regular form elsewhere, summed the filaments.
    cutoff_only: bool,
}

impl RunChunk {
    /// A chunk of zeros, reused point after point (lanes past a run's length keep the previous
    /// run's finite values, which [`flush_run`] does not read).
    fn new() -> Self {
        Self {
            r1: [[0.0; RUN]; 3],
            r2: [[0.0; RUN]; 3],
            g: [0.0; RUN],
            core2: [0.0; RUN],
            cut2: [0.0; RUN],
            dot: [0.0; RUN],
            c: [[0.0; RUN]; 3],
            old: [0.0; RUN],
            new: [0.0; RUN],
            cutoff_only: false,
        }
    }
}

/// A segment `a → b` with `(Γ/4π, core2, cut2)`.
type Segment = ([f64; 3], [f64; 3], (f64, f64, f64));

/// Segment `f` of `fil`.
#[inline]
fn filament(fil: &Filaments, f: usize) -> Segment {
    (
        fil.node(fil.seg_a[f] as usize),
        fil.node(fil.seg_b[f] as usize),
        (fil.seg_g[f], fil.seg_core2[f], fil.seg_cut2[f]),
    )
}

/// Replace the block kernels' term of each segment of `segs` at `x` in `o` by the regular form
/// where `x` lies outside it, in their order, a chunk of [`RUN`] at a time through the vectorised
/// [`run_factors`] (Rust does not fuse multiplications and additions, so each lane rounds as the
/// scalar [`pair_factors`] does).
fn fix_run(ch: &mut RunChunk, segs: impl Iterator<Item = Segment>, x: [f64; 3], o: &mut [f64; 3]) {
    let mut k = 0;
    for (a, b, (g, core2, cut2)) in segs {
        for q in 0..3 {
            ch.r1[q][k] = x[q] - a[q];
            ch.r2[q][k] = x[q] - b[q];
        }
        (ch.g[k], ch.core2[k], ch.cut2[k]) = (g, core2, cut2);
        k += 1;
        if k == RUN {
            flush_run(ch, k, o);
            k = 0;
        }
    }
    if k > 0 {
        flush_run(ch, k, o);
    }
}

/// The factors of the first `k` lanes of `ch`, and their updates of `o` in lane order (lanes
/// whose point lies on the segment, `r₁·r₂ ≤ 0`, are left as the block kernels summed them).
fn flush_run(ch: &mut RunChunk, k: usize, o: &mut [f64; 3]) {
    match isa() {
        Isa::Generic => run_factors_generic(ch),
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { run_factors_avx2(ch) },
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { run_factors_avx512(ch) },
    }
    for j in 0..k {
        if ch.dot[j] <= 0.0 || (ch.cutoff_only && ch.old[j] != 0.0) {
            continue;
        }
        for q in 0..3 {
            o[q] = o[q] - ch.old[j] * ch.c[q][j] + ch.new[j] * ch.c[q][j];
        }
    }
}

/// [`pair_factors`] of every lane of a [`RunChunk`] (a lane on its segment is skipped by
/// [`flush_run`]), compiled once per instruction set.
macro_rules! run_factors {
    ($($attr:meta)?; $name:ident) => {
        $(#[$attr])?
        fn $name(ch: &mut RunChunk) {
            for j in 0..RUN {
                let (r1, r2) = ([ch.r1[0][j], ch.r1[1][j], ch.r1[2][j]], [ch.r2[0][j], ch.r2[1][j], ch.r2[2][j]]);
                let (c, dot, old, new) = pair_factors(r1, r2, ch.core2[j], ch.cut2[j]);
                ch.dot[j] = dot;
                (ch.c[0][j], ch.c[1][j], ch.c[2][j]) = (c[0], c[1], c[2]);
                (ch.old[j], ch.new[j]) = (ch.g[j] * old, ch.g[j] * new);
            }
        }
    };
}

run_factors!(; run_factors_generic);
#[cfg(target_arch = "x86_64")]
run_factors!(target_feature(enable = "avx2,fma"); run_factors_avx2);
#[cfg(target_arch = "x86_64")]
run_factors!(target_feature(enable = "avx512f,avx2,fma"); run_factors_avx512);

/// Replace leg `l`'s block-kernel term at `x` in `o` by the regular form when `x` lies upstream
/// of its start (with `cutoff_only`, only where the kernel's cut-off zeroed the term: see
/// [`RunChunk::cutoff_only`]).
fn fix_leg(fil: &Filaments, l: usize, x: [f64; 3], o: &mut [f64; 3], cutoff_only: bool) {
    let a = fil.node(fil.leg_a[l] as usize);
    let (g, core2, cut2) = (fil.leg_g[l], fil.leg_core2[l], fil.leg_cut2[l]);
    let r = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
    if cutoff_only && kernel_leg(r, fil.leg_d[l], core2, cut2) != 0.0 {
        return;
    }
    fix_leg_at(a, fil.leg_d[l], (g, core2, cut2), x, o);
}

/// [`fix_leg`] of the leg from `a` along `d` with `(Γ/4π, core2, cut2)`.
fn fix_leg_at(a: [f64; 3], d: [f64; 3], (g, core2, cut2): (f64, f64, f64), x: [f64; 3], o: &mut [f64; 3]) {
    let r = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
    if d[0] * r[0] + d[1] * r[1] + d[2] * r[2] >= 0.0 {
        return;
    }
    let (cv, k) = leg_factor(r, d, core2, cut2);
    let (gk_old, gk_new) = (g * kernel_leg(r, d, core2, cut2), g * k);
    for q in 0..3 {
        o[q] = o[q] - gk_old * cv[q] + gk_new * cv[q];
    }
}
