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

use crate::biot_savart::Filaments;
use crate::induce::Points;

/// The factor `k` of a segment pair (`u = Γ/4π · k · r₁×r₂`) for the load points.
#[inline]
pub(crate) fn segment_factor(r1: [f64; 3], r2: [f64; 3], core2: f64, cut2: f64) -> ([f64; 3], f64) {
    let c = [r1[1] * r2[2] - r1[2] * r2[1], r1[2] * r2[0] - r1[0] * r2[2], r1[0] * r2[1] - r1[1] * r2[0]];
    let h = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let n1 = (r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]).sqrt();
    let n2 = (r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]).sqrt();
    let dot = r1[0] * r2[0] + r1[1] * r2[1] + r1[2] * r2[2];
    let n12 = n1 * n2;
    let l2 = (r1[0] - r2[0]).powi(2) + (r1[1] - r2[1]).powi(2) + (r1[2] - r2[2]).powi(2);
    if dot > 0.0 {
        // Outside the segment: the cut-off radius round the end points only.
        let rc2 = if l2 > 0.0 { cut2 / l2 } else { f64::INFINITY };
        if n1 * n1 <= rc2 || n2 * n2 <= rc2 {
            return (c, 0.0);
        }
        let core = if core2 > 0.0 { h / (h + core2) } else { 1.0 };
        return (c, (n1 + n2) / (n12 * (n12 + dot)) * core);
    }
    let h2 = h + core2;
    if h2 > cut2 && n12 > 0.0 { (c, (n1 + n2) * (n12 - dot) / (n12 * h2)) } else { (c, 0.0) }
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

/// The crate kernel's factor of a segment pair, with the block kernels' arithmetic (so that the
/// term they added is removed exactly).
#[inline]
fn kernel_segment(r1: [f64; 3], r2: [f64; 3], core2: f64, cut2: f64) -> f64 {
    let cx = r1[1] * r2[2] - r1[2] * r2[1];
    let cy = r1[2] * r2[0] - r1[0] * r2[2];
    let cz = r1[0] * r2[1] - r1[1] * r2[0];
    let h2 = cx * cx + cy * cy + cz * cz + core2;
    let n1 = (r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]).sqrt();
    let n2 = (r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]).sqrt();
    let n12 = n1 * n2;
    let dot = r1[0] * r2[0] + r1[1] * r2[1] + r1[2] * r2[2];
    let num = (n1 + n2) * (n12 - dot);
    if h2 > cut2 && n12 > 0.0 { num / (n12 * h2) } else { 0.0 }
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
/// trailing leg — by the regular form of [`segment_factor`] and [`leg_factor`] where the point
/// lies outside the segment (module doc). Other filaments are never collinear with a load point
/// of a ring lattice by construction, and keep the block kernels' value.
pub(crate) fn correct_axis_extensions(fil: &Filaments, layout: &ExtensionLayout, pts: &Points, u: &mut [[f64; 3]]) {
    let mut p = 0;
    for sl in &layout.surfaces {
        let (m, n) = (sl.m, sl.n);
        let nc = n + 1;
        for s in 0..sl.n_load {
            let x = [pts.x[p], pts.y[p], pts.z[p]];
            let o = &mut u[p];
            p += 1;
            for c in 0..layout.n_copies {
                let seg = |b: usize| c * layout.n_base_seg + b;
                if s < m * n || s >= m * n + m * nc {
                    // A spanwise point: the segments of its row.
                    let i = if s < m * n { s / n } else { m };
                    let first = if i < m { sl.seg0 + i * n } else { sl.seg0 + m * n + m * nc };
                    for b in first..first + n {
                        fix_segment(fil, seg(b), x, o);
                    }
                } else {
                    // A chordwise point: the segments of its column and its trailing leg.
                    let j = (s - m * n) % nc;
                    for i in 0..m {
                        fix_segment(fil, seg(sl.seg0 + m * n + i * nc + j), x, o);
                    }
                    if sl.finite {
                        fix_segment(fil, seg(sl.seg0 + sl.n_lattice_seg + j), x, o);
                    } else if layout.n_base_leg > 0 {
                        fix_leg(fil, c * layout.n_base_leg + sl.leg0 + j, x, o);
                    }
                }
            }
        }
    }
}

/// Replace segment `f`'s block-kernel term at `x` in `o` by the regular form when `x` lies
/// outside the segment.
fn fix_segment(fil: &Filaments, f: usize, x: [f64; 3], o: &mut [f64; 3]) {
    let (a, b) = (fil.node(fil.seg_a[f] as usize), fil.node(fil.seg_b[f] as usize));
    let r1 = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
    let r2 = [x[0] - b[0], x[1] - b[1], x[2] - b[2]];
    if r1[0] * r2[0] + r1[1] * r2[1] + r1[2] * r2[2] <= 0.0 {
        return;
    }
    let (core2, cut2, g) = (fil.seg_core2[f], fil.seg_cut2[f], fil.seg_g[f]);
    let (cv, k) = segment_factor(r1, r2, core2, cut2);
    let (gk_old, gk_new) = (g * kernel_segment(r1, r2, core2, cut2), g * k);
    for q in 0..3 {
        o[q] = o[q] - gk_old * cv[q] + gk_new * cv[q];
    }
}

/// Replace leg `l`'s block-kernel term at `x` in `o` by the regular form when `x` lies upstream
/// of its start.
fn fix_leg(fil: &Filaments, l: usize, x: [f64; 3], o: &mut [f64; 3]) {
    let a = fil.node(fil.leg_a[l] as usize);
    let d = fil.leg_d[l];
    let r = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
    if d[0] * r[0] + d[1] * r[1] + d[2] * r[2] >= 0.0 {
        return;
    }
    let (core2, cut2, g) = (fil.leg_core2[l], fil.leg_cut2[l], fil.leg_g[l]);
    let (cv, k) = leg_factor(r, d, core2, cut2);
    let (gk_old, gk_new) = (g * kernel_leg(r, d, core2, cut2), g * k);
    for q in 0..3 {
        o[q] = o[q] - gk_old * cv[q] + gk_new * cv[q];
    }
}
