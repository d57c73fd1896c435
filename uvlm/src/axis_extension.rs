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

use crate::biot_savart::{Filaments, LANES};
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

/// Overwrite `out[p]` with the induction of the filaments `fil` at point `p` of `pts` (module
/// doc). Returns the point–filament pairs counted as the block kernels count them.
pub(crate) fn bound_induction_at_load_points(fil: &Filaments, pts: &Points, out: &mut [[f64; 3]]) -> u64 {
    for (p, o) in out.iter_mut().enumerate().take(pts.len()) {
        let x = [pts.x[p], pts.y[p], pts.z[p]];
        let mut u = [0.0; 3];
        for s in 0..fil.n_segments() {
            let (a, b) = (fil.node(fil.seg_a[s] as usize), fil.node(fil.seg_b[s] as usize));
            let r1 = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
            let r2 = [x[0] - b[0], x[1] - b[1], x[2] - b[2]];
            let (c, k) = segment_factor(r1, r2, fil.seg_core2[s], fil.seg_cut2[s]);
            let gk = fil.seg_g[s] * k;
            for q in 0..3 {
                u[q] += gk * c[q];
            }
        }
        for l in 0..fil.n_legs() {
            let a = fil.node(fil.leg_a[l] as usize);
            let r = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
            let (c, k) = leg_factor(r, fil.leg_d[l], fil.leg_core2[l], fil.leg_cut2[l]);
            let gk = fil.leg_g[l] * k;
            for q in 0..3 {
                u[q] += gk * c[q];
            }
        }
        *o = u;
    }
    (pts.len().div_ceil(LANES) * LANES * fil.n_filaments()) as u64
}
