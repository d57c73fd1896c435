//! A wake filament set's direct induction in mixed precision: positions in f64, the kernel in
//! f32 on [`LANES32`] points at once, sums in f64 (docs/uvlm.md §14).
//!
//! **Why.** The direct kernel in f64 spends its time on the floating-point pipes and the
//! division (docs/uvlm.md §9); f32 holds twice the lanes per instruction and divides faster. The
//! far wake (rows one and on) is where most point–segment pairs of a step are, and its
//! induction needs about six digits (the aggregation's 1e-6 |V∞|), not sixteen.
//!
//! **Accuracy.** `P/ℓ` and `X/ℓ` (ℓ the set's mean segment length, so that the products below
//! stay far from f32's range limits) are each held as two f32, the value rounded and what the
//! rounding left, and `P/ℓ − X/ℓ` is formed as `(Pₕ − Xₕ) + (Pₗ − Xₗ)`: the first difference is
//! exact when the two coordinates are within a factor of two of each other (Sterbenz), else
//! rounded by ε₃₂ of itself, so each relative vector carries a relative error of about 2ε₃₂
//! (ε₃₂ ≈ 6e-8) plus ε₃₂² of the coordinates' size, whatever its distance from the origin, from
//! eight-lane f32 operations alone (no f64 differences and conversions per point and node).
//! The kernel's factor `(|r₁|+|r₂|)(|r₁||r₂| − r₁·r₂)` cancels near a segment's axis
//! extension (`r₁·r₂ > 0`), which in f32 would lose every digit: there it takes the same law's
//! regular form `(|r₁|+|r₂|)|r₁×r₂|²/(|r₁||r₂| + r₁·r₂)` (as axis_extension.rs does in f64), and
//! a semi-infinite leg upstream of its start (`d·r < 0`) likewise takes
//! `|d×r|²/(|r| − d·r)` for `|r| + d·r`. Each pair's velocity is then within a few ε₃₂ of
//! itself, and the f32 sums run over at most [`FLUSH`] filaments before they are added to f64
//! sums. The cut-off test (`|r₁×r₂|² + core > cut`) is the kernel's own, evaluated in f32: it
//! differs from f64's only for a point within about 1e-3 of the cut-off radius of a filament's
//! cylinder surface. Measured against the f64 sum: uvlm/tests/suite/mixed.rs.

use std::ops::Range;

use crate::biot_savart::{Filaments, Isa, isa};
use crate::induce::{Points, use_threads};
use crate::params::Parallel;
use crate::scratch::{DIRECT_CHUNKS_PER_THREAD, ScratchPool};

/// Points evaluated together by the f32 kernel (one AVX-512 register of f32).
pub(crate) const LANES32: usize = 16;

/// Filaments summed in f32 before the partial sums are added to the f64 sums.
const FLUSH: usize = 256;

/// A [`Filaments`] set's per-filament constants in f32, lengths scaled by `1/ℓ`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Filaments32 {
    /// 1/ℓ, ℓ the mean segment length (1 without segments).
    inv_len: f64,
    /// The nodes' coordinates over ℓ, each as the sum of two f32 ([`split`]): x, y, z rounded,
    /// then what the rounding left of each.
    nodes: Vec<[f32; 6]>,
    seg_g: Vec<f32>,
    seg_core2: Vec<f32>,
    seg_cut2: Vec<f32>,
    leg_d: Vec<[f32; 3]>,
    leg_g: Vec<f32>,
    leg_core2: Vec<f32>,
    leg_cut2: Vec<f32>,
    /// For each run of [`FLUSH`] segments, one past the highest node index its segments and
    /// those before it use: the nodes the fill must have reached before the run's kernel.
    reach: Vec<u32>,
}

impl Filaments32 {
    /// Take `fil`'s constants (keeps capacity).
    pub(crate) fn load(&mut self, fil: &Filaments) {
        let ns = fil.n_segments();
        // The mean over at most 256 segments spread through the set: a scale, not a datum.
        let (mut total, mut count) = (0.0, 0);
        for s in (0..ns).step_by(ns.div_ceil(256).max(1)) {
            let (a, b) = fil.segment_nodes(s);
            let (pa, pb) = (fil.node(a as usize), fil.node(b as usize));
            total += ((pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2) + (pb[2] - pa[2]).powi(2)).sqrt();
            count += 1;
        }
        let len = if total > 0.0 { total / count as f64 } else { 1.0 };
        let s = 1.0 / len;
        self.inv_len = s;
        self.nodes.clear();
        self.nodes.extend((0..fil.x.len()).map(|i| {
            let ([xh, xl], [yh, yl], [zh, zl]) = (split(fil.x[i] * s), split(fil.y[i] * s), split(fil.z[i] * s));
            [xh, yh, zh, xl, yl, zl]
        }));
        // A segment's core and cut-off constants scale as length⁴, a leg's as length²; the
        // strengths (Γ/4π) are not lengths: the velocity is scaled back by 1/ℓ at the end.
        let (s2, s4) = (s * s, s * s * s * s);
        self.seg_g.clear();
        self.seg_g.extend(fil.seg_g.iter().map(|&g| g as f32));
        self.seg_core2.clear();
        self.seg_core2.extend(fil.seg_core2.iter().map(|&c| (c * s4) as f32));
        self.seg_cut2.clear();
        self.seg_cut2.extend(fil.seg_cut2.iter().map(|&c| (c * s4) as f32));
        self.leg_d.clear();
        self.leg_d.extend(fil.leg_d.iter().map(|d| [d[0] as f32, d[1] as f32, d[2] as f32]));
        self.leg_g.clear();
        self.leg_g.extend(fil.leg_g.iter().map(|&g| g as f32));
        self.leg_core2.clear();
        self.leg_core2.extend(fil.leg_core2.iter().map(|&c| (c * s2) as f32));
        self.leg_cut2.clear();
        self.leg_cut2.extend(fil.leg_cut2.iter().map(|&c| (c * s2) as f32));
        self.reach.clear();
        let mut hi = 0;
        for (a, b) in fil.seg_a[..ns].chunks(FLUSH).zip(fil.seg_b[..ns].chunks(FLUSH)) {
            hi = a.iter().chain(b).fold(hi, |h, &i| h.max(i + 1));
            self.reach.push(hi);
        }
    }
}

impl Filaments32 {
    /// Set segment `s`'s constants (as [`Filaments`] holds them: strength over 4π, core and
    /// cut-off terms in m⁴), scaled as [`Filaments32::load`] scaled them.
    pub(crate) fn set_segment(&mut self, s: usize, g: f64, core2: f64, cut2: f64) {
        let s4 = self.inv_len.powi(4);
        self.seg_g[s] = g as f32;
        self.seg_core2[s] = (core2 * s4) as f32;
        self.seg_cut2[s] = (cut2 * s4) as f32;
    }
}

/// `v` as `hi + lo` in f32: `hi` is `v` rounded, `lo` what the rounding left, rounded (so
/// `hi + lo` is within about ε₃₂² |v| of `v`).
#[inline]
fn split(v: f64) -> [f32; 2] {
    let hi = v as f32;
    [hi, (v - hi as f64) as f32]
}

/// Per-block scratch: for each node, the `N` lanes of (P − X)/ℓ (x, y, z) and its norm, in f32.
#[derive(Debug, Clone)]
pub(crate) struct Block32<const N: usize> {
    r: Vec<[[f32; N]; 4]>,
    /// Eight lanes of it at a time, where the kernel runs on eight (AVX2): a node's record in
    /// two cache lines, so that the records of a long wake stay in the core's cache between
    /// the fill and the kernel.
    eight: Vec<[[f32; 8]; 4]>,
}

impl<const N: usize> Default for Block32<N> {
    fn default() -> Self {
        Self { r: Vec::new(), eight: Vec::new() }
    }
}

/// One point–segment pair in f32: `r₁×r₂` and the factor `k` (without Γ/4π), the regular form
/// beyond the segment's ends. Products summed with fused multiply-adds (one rounding fewer each;
/// `mul_add` is exact on every target, in hardware or in software, so results do not depend on
/// the instruction set), and `|r₁||r₂||r₁×r₂|²` shared by both forms' denominators: the kernel
/// is bound by the multiplier pipes (docs/uvlm.md §9).
#[inline(always)]
fn pair32(r1: [f32; 3], n1: f32, r2: [f32; 3], n2: f32, core2: f32, cut2: f32) -> ([f32; 3], f32) {
    let cx = r1[1].mul_add(r2[2], -(r1[2] * r2[1]));
    let cy = r1[2].mul_add(r2[0], -(r1[0] * r2[2]));
    let cz = r1[0].mul_add(r2[1], -(r1[1] * r2[0]));
    let c2 = cz.mul_add(cz, cy.mul_add(cy, cx * cx));
    let h2 = c2 + core2;
    let n12 = n1 * n2;
    let dot = r1[2].mul_add(r2[2], r1[1].mul_add(r2[1], r1[0] * r2[0]));
    let beyond = dot > 0.0;
    let a = if beyond { c2 } else { n12 - dot };
    let t = n12 * h2;
    let b = if beyond { t * (n12 + dot) } else { t };
    let ok = h2 > cut2 && n12 > 0.0;
    let k = if ok { (n1 + n2) * a / b } else { 0.0 };
    ([cx, cy, cz], k)
}

/// One point–leg pair in f32: `d×r` and the factor `k`, the regular form upstream of the start.
#[inline(always)]
fn leg32(r: [f32; 3], rn: f32, d: [f32; 3], core2: f32, cut2: f32) -> ([f32; 3], f32) {
    let cx = d[1] * r[2] - d[2] * r[1];
    let cy = d[2] * r[0] - d[0] * r[2];
    let cz = d[0] * r[1] - d[1] * r[0];
    let h2 = cx * cx + cy * cy + cz * cz;
    let hc = h2 + core2;
    let dot = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
    let upstream = dot < 0.0;
    let a = if upstream { h2 } else { rn + dot };
    let b = if upstream { hc * rn * (rn - dot) } else { hc * rn };
    let ok = h2 > cut2 && rn > 0.0;
    let k = if ok { a / b } else { 0.0 };
    ([cx, cy, cz], k)
}

/// The node fill, portable: `(P − X)/ℓ` lane by lane from the two halves of each ([`split`]),
/// `(Pₕ − Xₕ) + (Pₗ − Xₗ)` in f32, and its norm from `(x² + y²) + z²`.
fn fill_generic<const N: usize>(
    c: &Filaments32,
    p: &[[[f32; N]; 3]; 2],
    rec: &mut [[[f32; N]; 4]],
    nodes: Range<usize>,
) {
    let [ph, pl] = p;
    for (r, x) in rec[nodes.clone()].iter_mut().zip(&c.nodes[nodes]) {
        for q in 0..3 {
            for l in 0..N {
                r[q][l] = (ph[q][l] - x[q]) + (pl[q][l] - x[q + 3]);
            }
        }
        for l in 0..N {
            r[3][l] = (r[0][l] * r[0][l] + r[1][l] * r[1][l] + r[2][l] * r[2][l]).sqrt();
        }
    }
}

/// The kernel body, compiled once per instruction set.
macro_rules! velocity32 {
    ($($attr:meta)?; $vel:ident) => {
        $(#[$attr])?
        fn $vel<const N: usize>(
            fil: &Filaments,
            c: &Filaments32,
            rec: &[[[f32; N]; 4]],
            segs: Range<usize>,
            legs: bool,
            u: &mut [[f64; N]; 3],
        ) {
            let ns = segs.end;
            let (sa, sb) = (&fil.seg_a[..ns], &fil.seg_b[..ns]);
            let (sg, sc, st) = (&c.seg_g[..ns], &c.seg_core2[..ns], &c.seg_cut2[..ns]);
            let mut s0 = segs.start;
            while s0 < ns {
                let s1 = (s0 + FLUSH).min(ns);
                let mut ux = [0.0f32; N];
                let mut uy = [0.0f32; N];
                let mut uz = [0.0f32; N];
                for s in s0..s1 {
                    let r1 = &rec[sa[s] as usize];
                    let r2 = &rec[sb[s] as usize];
                    let (g, core2, cut2) = (sg[s], sc[s], st[s]);
                    for l in 0..N {
                        let (cr, k) = pair32(
                            [r1[0][l], r1[1][l], r1[2][l]],
                            r1[3][l],
                            [r2[0][l], r2[1][l], r2[2][l]],
                            r2[3][l],
                            core2,
                            cut2,
                        );
                        let gk = g * k;
                        ux[l] = gk.mul_add(cr[0], ux[l]);
                        uy[l] = gk.mul_add(cr[1], uy[l]);
                        uz[l] = gk.mul_add(cr[2], uz[l]);
                    }
                }
                for l in 0..N {
                    u[0][l] += ux[l] as f64;
                    u[1][l] += uy[l] as f64;
                    u[2][l] += uz[l] as f64;
                }
                s0 = s1;
            }
            if !legs {
                return;
            }
            let nl = fil.n_legs();
            let mut ux = [0.0f32; N];
            let mut uy = [0.0f32; N];
            let mut uz = [0.0f32; N];
            for j in 0..nl {
                let r = &rec[fil.leg_a[j] as usize];
                let (d, g, core2, cut2) = (c.leg_d[j], c.leg_g[j], c.leg_core2[j], c.leg_cut2[j]);
                for l in 0..N {
                    let (cr, k) = leg32([r[0][l], r[1][l], r[2][l]], r[3][l], d, core2, cut2);
                    let gk = g * k;
                    ux[l] += gk * cr[0];
                    uy[l] += gk * cr[1];
                    uz[l] += gk * cr[2];
                }
            }
            for l in 0..N {
                u[0][l] += ux[l] as f64;
                u[1][l] += uy[l] as f64;
                u[2][l] += uz[l] as f64;
            }
        }
    };
}

velocity32!(; velocity_generic);
#[cfg(target_arch = "x86_64")]
velocity32!(target_feature(enable = "avx2,fma"); velocity_avx2);
#[cfg(target_arch = "x86_64")]
velocity32!(target_feature(enable = "avx512f,avx2,fma"); velocity_avx512);

/// [`fill_generic`] written with intrinsics, eight lanes a pass, for AVX2 and AVX-512 alike:
/// auto-vectorisation of the portable version runs across nodes with gathers and scatters, or
/// with four-lane shuffles. The same operations in the same order, without fused products, so
/// the lanes are bit-identical to it.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn fill_x86<const N: usize>(c: &Filaments32, p: &[[[f32; N]; 3]; 2], rec: &mut [[[f32; N]; 4]], nodes: Range<usize>) {
    use std::arch::x86_64::*;
    const { assert!(N.is_multiple_of(8)) };
    // SAFETY: unaligned loads and stores of 8 f32 at offset h (h + 8 ≤ N) of [f32; N] arrays.
    unsafe {
        for h in (0..N).step_by(8) {
            let ph = p[0].each_ref().map(|q| _mm256_loadu_ps(q.as_ptr().add(h)));
            let pl = p[1].each_ref().map(|q| _mm256_loadu_ps(q.as_ptr().add(h)));
            for (r, x) in rec[nodes.clone()].iter_mut().zip(&c.nodes[nodes.clone()]) {
                let d = |q: usize| {
                    _mm256_add_ps(
                        _mm256_sub_ps(ph[q], _mm256_set1_ps(x[q])),
                        _mm256_sub_ps(pl[q], _mm256_set1_ps(x[q + 3])),
                    )
                };
                let (dx, dy, dz) = (d(0), d(1), d(2));
                let n2 =
                    _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
                _mm256_storeu_ps(r[0].as_mut_ptr().add(h), dx);
                _mm256_storeu_ps(r[1].as_mut_ptr().add(h), dy);
                _mm256_storeu_ps(r[2].as_mut_ptr().add(h), dz);
                _mm256_storeu_ps(r[3].as_mut_ptr().add(h), _mm256_sqrt_ps(n2));
            }
        }
    }
}

/// [`fill_x86`] sixteen lanes a pass, for AVX-512 and `N` a multiple of 16 (the same
/// operations in the same order, so the lanes are bit-identical to [`fill_generic`]'s): half the
/// instructions of eight-lane passes.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn fill_x86_512<const N: usize>(
    c: &Filaments32,
    p: &[[[f32; N]; 3]; 2],
    rec: &mut [[[f32; N]; 4]],
    nodes: Range<usize>,
) {
    use std::arch::x86_64::*;
    assert!(N.is_multiple_of(16), "fill_x86_512: {N} lanes");
    // SAFETY: unaligned loads and stores of 16 f32 at offset h (h + 16 ≤ N) of [f32; N] arrays.
    unsafe {
        for h in (0..N).step_by(16) {
            let ph = p[0].each_ref().map(|q| _mm512_loadu_ps(q.as_ptr().add(h)));
            let pl = p[1].each_ref().map(|q| _mm512_loadu_ps(q.as_ptr().add(h)));
            for (r, x) in rec[nodes.clone()].iter_mut().zip(&c.nodes[nodes.clone()]) {
                let d = |q: usize| {
                    _mm512_add_ps(
                        _mm512_sub_ps(ph[q], _mm512_set1_ps(x[q])),
                        _mm512_sub_ps(pl[q], _mm512_set1_ps(x[q + 3])),
                    )
                };
                let (dx, dy, dz) = (d(0), d(1), d(2));
                let n2 =
                    _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
                _mm512_storeu_ps(r[0].as_mut_ptr().add(h), dx);
                _mm512_storeu_ps(r[1].as_mut_ptr().add(h), dy);
                _mm512_storeu_ps(r[2].as_mut_ptr().add(h), dz);
                _mm512_storeu_ps(r[3].as_mut_ptr().add(h), _mm512_sqrt_ps(n2));
            }
        }
    }
}

/// Run the node fill and the kernel alternately, [`FLUSH`] segments at a time: each run's kernel
/// finds the nodes the fill just wrote in the core's first-level cache (a wake's segments
/// follow its nodes row by row), where one fill of the whole set would have left them in the
/// second level. The values and the order of the sums are those of one fill followed by one
/// kernel pass.
#[inline(always)]
fn interleave<const N: usize>(
    fil: &Filaments,
    c: &Filaments32,
    rec: &mut Vec<[[f32; N]; 4]>,
    mut fill: impl FnMut(&mut [[[f32; N]; 4]], Range<usize>),
    mut kernel: impl FnMut(&[[[f32; N]; 4]], Range<usize>, bool),
) {
    let n = c.nodes.len();
    if rec.len() < n {
        rec.resize(n, [[0.0; N]; 4]);
    }
    let (ns, mut filled) = (fil.n_segments(), 0);
    for (k, &hi) in c.reach.iter().enumerate() {
        let hi = hi as usize;
        if hi > filled {
            fill(rec, filled..hi);
            filled = hi;
        }
        kernel(rec, k * FLUSH..((k + 1) * FLUSH).min(ns), false);
    }
    if filled < n {
        fill(rec, filled..n);
    }
    kernel(rec, ns..ns, true);
}

/// The lanes of block `b` of `v` (the last point repeated past the end).
fn lanes(v: &[f64], b: usize) -> [f64; LANES32] {
    let mut out = [0.0; LANES32];
    let last = v.len() - 1;
    for (l, o) in out.iter_mut().enumerate() {
        *o = v[(b * LANES32 + l).min(last)];
    }
    out
}

/// Add the induction of `fil` (its f32 constants `c`) at the `N` points `p` to `u`.
#[inline]
pub(crate) fn add_lanes<const N: usize>(
    fil: &Filaments,
    c: &Filaments32,
    p: &[[f64; N]; 3],
    blk: &mut Block32<N>,
    u: &mut [[f64; N]; 3],
) {
    add_lanes_on(isa(), fil, c, p, blk, u);
}

/// [`add_lanes`] with the kernel of `isa`, which the caller has checked the CPU supports.
#[inline]
fn add_lanes_on<const N: usize>(
    isa: Isa,
    fil: &Filaments,
    c: &Filaments32,
    p: &[[f64; N]; 3],
    blk: &mut Block32<N>,
    u: &mut [[f64; N]; 3],
) {
    let mut v = [[0.0; N]; 3];
    // The points over ℓ, split as the nodes.
    let sp = p.map(|q| q.map(|x| split(x * c.inv_len)));
    let p = &[0, 1].map(|k| sp.map(|q| q.map(|x| x[k])));
    match isa {
        Isa::Generic => interleave(
            fil,
            c,
            &mut blk.r,
            |rec, nodes| fill_generic(c, p, rec, nodes),
            |rec, segs, legs| velocity_generic(fil, c, rec, segs, legs, &mut v),
        ),
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        // Eight points at a time: with AVX2's sixteen registers, sixteen lanes (two registers per
        // quantity) spill the partial sums to the stack at every filament. Each lane's operations
        // are those of the whole block's.
        Isa::Avx2 => unsafe {
            const { assert!(N.is_multiple_of(8)) };
            for h in (0..N).step_by(8) {
                let p8 = p.each_ref().map(|k| k.each_ref().map(|q| std::array::from_fn::<f32, 8, _>(|l| q[h + l])));
                let mut v8 = [[0.0; 8]; 3];
                interleave(
                    fil,
                    c,
                    &mut blk.eight,
                    |rec, nodes| fill_x86(c, &p8, rec, nodes),
                    |rec, segs, legs| velocity_avx2::<8>(fil, c, rec, segs, legs, &mut v8),
                );
                for q in 0..3 {
                    v[q][h..h + 8].copy_from_slice(&v8[q]);
                }
            }
        },
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe {
            let fill = |rec: &mut [[[f32; N]; 4]], nodes| {
                if N.is_multiple_of(16) { fill_x86_512(c, p, rec, nodes) } else { fill_x86(c, p, rec, nodes) }
            };
            interleave(fil, c, &mut blk.r, fill, |rec, segs, legs| velocity_avx512(fil, c, rec, segs, legs, &mut v));
        },
    }
    // (P − X)/ℓ gives the velocity times ℓ.
    for q in 0..3 {
        for l in 0..N {
            u[q][l] += v[q][l] * c.inv_len;
        }
    }
}

/// Add the induction of `fil` (its f32 constants `c`) at block `b` of `pts` to `out`.
fn add_block(
    fil: &Filaments,
    c: &Filaments32,
    pts: &Points,
    b: usize,
    blk: &mut Block32<LANES32>,
    out: &mut [[f64; 3]],
) {
    let p = [lanes(&pts.x, b), lanes(&pts.y, b), lanes(&pts.z, b)];
    let mut u = [[0.0; LANES32]; 3];
    add_lanes(fil, c, &p, blk, &mut u);
    for (l, o) in out.iter_mut().enumerate() {
        for q in 0..3 {
            o[q] += u[q][l];
        }
    }
}

/// The workspace of [`add_velocity_mixed`]: the set's f32 constants and the block scratch.
#[derive(Debug, Clone, Default)]
pub(crate) struct MixedScratch {
    consts: Filaments32,
    blocks: ScratchPool<Block32<LANES32>>,
    /// Whether `consts` are those of the set of the last [`MixedScratch::load_once`], which its
    /// owner has not changed since ([`MixedScratch::forget`]), and that set's node, segment and
    /// leg counts (a set of other counts is loaded whatever the flag says).
    kept: bool,
    kept_counts: [usize; 3],
}

impl MixedScratch {
    /// Take `fil`'s f32 constants.
    fn load(&mut self, fil: &Filaments) {
        self.consts.load(fil);
        self.kept = false;
    }

    /// Take `fil`'s f32 constants unless they are held already: for a set whose owner calls
    /// [`MixedScratch::forget`] whenever it changes, so that they are loaded once per change,
    /// not once per sum (the far wake is summed at the collocation points, then at the segment
    /// midpoints, of each step).
    pub(crate) fn load_once(&mut self, fil: &Filaments) {
        let counts = [fil.n_nodes(), fil.n_segments(), fil.n_legs()];
        if !self.kept || self.kept_counts != counts {
            self.consts.load(fil);
            (self.kept, self.kept_counts) = (true, counts);
        }
    }

    /// The set of [`MixedScratch::load_once`] changed: load its constants at the next call.
    pub(crate) fn forget(&mut self) {
        self.kept = false;
    }

    /// [`add_velocity_mixed`] with `fil`'s constants loaded.
    pub(crate) fn add_velocity(
        &mut self,
        fil: &Filaments,
        pts: &Points,
        out: &mut [[f64; 3]],
        parallel: Parallel,
    ) -> u64 {
        assert_eq!(out.len(), pts.len(), "add_velocity_mixed: output length");
        if pts.is_empty() || fil.n_filaments() == 0 {
            return 0;
        }
        let c = &self.consts;
        let n_blocks = pts.len().div_ceil(LANES32);
        let pairs = n_blocks * LANES32 * fil.n_filaments();
        if use_threads(parallel, pairs) {
            self.blocks.for_each_chunk(out, LANES32, DIRECT_CHUNKS_PER_THREAD, |first, chunk, blk| {
                for (i, block) in chunk.chunks_mut(LANES32).enumerate() {
                    add_block(fil, c, pts, first + i, blk, block);
                }
            });
        } else {
            let blk = self.blocks.first();
            for (b, block) in out.chunks_mut(LANES32).enumerate() {
                add_block(fil, c, pts, b, blk, block);
            }
        }
        pairs as u64
    }
}

/// Add the velocity induced by `fil` at every point of `pts` to `out`, in mixed precision.
/// Returns the number of point–filament pairs evaluated (padded to whole blocks). Threaded as
/// [`crate::induce::induced_velocity_inplace`], and bit-identical to its serial loop.
///
/// # Panics
/// If `out.len() != pts.len()`.
pub(crate) fn add_velocity_mixed(
    fil: &Filaments,
    pts: &Points,
    out: &mut [[f64; 3]],
    parallel: Parallel,
    scratch: &mut MixedScratch,
) -> u64 {
    scratch.load(fil);
    scratch.add_velocity(fil, pts, out, parallel)
}

/// Velocity induced by `fil` at `points` in mixed precision (allocating convenience for checks
/// and benchmarks; sequential). Within about 1e-7 of the largest velocity of
/// [`crate::induced_velocity`] (tests below).
pub fn induced_velocity_mixed(fil: &Filaments, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut pts = Points::default();
    for p in points {
        pts.push(*p);
    }
    let mut out = vec![[0.0; 3]; points.len()];
    add_velocity_mixed(fil, &pts, &mut out, Parallel::Off, &mut MixedScratch::default());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::biot_savart::CoreModel;

    /// Beyond a segment's end on its axis (where the f64 kernel's `|r₁||r₂| − r₁·r₂` cancels)
    /// and beside it, the f32 factor agrees with the f64 regular form to f32 accuracy; and a
    /// leg upstream of its start likewise.
    #[test]
    fn regular_forms_hold_near_the_axis_extension() {
        let core = CoreModel::CutOff { radius: 1e-9 };
        for (p, what) in [([2.0, 1e-4, 0.0], "beyond, near the axis"), ([0.5, 0.3, 0.2], "beside")] {
            let (a, b) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
            let exact = crate::biot_savart::segment_velocity(p, a, b, 1.0, core);
            let mut fil = Filaments::default();
            let (ia, ib) = (fil.push_node(a), fil.push_node(b));
            fil.push_segment(ia, ib, 1.0, &core);
            let mut pts = Points::default();
            pts.push(p);
            let mut out = vec![[0.0; 3]];
            add_velocity_mixed(&fil, &pts, &mut out, Parallel::Off, &mut MixedScratch::default());
            let scale = exact.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for q in 0..3 {
                assert!((out[0][q] - exact[q]).abs() <= 1e-6 * scale, "{what}: {:?} vs {:?}", out[0], exact);
            }
        }
        let p = [-3.0, 2e-4, 1e-4];
        let exact = crate::biot_savart::semi_infinite_velocity(p, [0.0; 3], [1.0, 0.0, 0.0], 1.0, core, 1.0);
        let mut fil = Filaments::default();
        let a = fil.push_node([0.0; 3]);
        fil.push_leg(a, [1.0, 0.0, 0.0], 1.0, &core, 1.0);
        let mut pts = Points::default();
        pts.push(p);
        let mut out = vec![[0.0; 3]];
        add_velocity_mixed(&fil, &pts, &mut out, Parallel::Off, &mut MixedScratch::default());
        let scale = exact.iter().map(|v| v.abs()).fold(0.0, f64::max);
        for q in 0..3 {
            assert!((out[0][q] - exact[q]).abs() <= 1e-6 * scale, "leg upstream: {:?} vs {:?}", out[0], exact);
        }
    }

    fn max_error(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(u, v)| ((u[0] - v[0]).powi(2) + (u[1] - v[1]).powi(2) + (u[2] - v[2]).powi(2)).sqrt())
            .fold(0.0, f64::max)
    }

    fn mixed(fil: &Filaments, pts: &[[f64; 3]]) -> Vec<[f64; 3]> {
        induced_velocity_mixed(fil, pts)
    }

    /// Random segments of both signs (a cloud 4 × 2 × 1 m, 3000 segments of up to 0.1 m, far
    /// from the origin so that absolute coordinates would lose digits in f32) and points in and
    /// around it: within 1e-6 of the largest velocity of the direct f64 sum at every point, and
    /// threaded equal to serial bit for bit.
    #[test]
    fn mixed_matches_direct_on_random_segments() {
        let mut seed = 11u64;
        let mut rng = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let o = [1000.0, -500.0, 20.0];
        let core = CoreModel::CutOff { radius: 1e-6 };
        let mut fil = Filaments::default();
        for _ in 0..3000 {
            let a = [o[0] + 4.0 * rng(), o[1] + 2.0 * rng(), o[2] + rng()];
            let b = [a[0] + 0.1 * (rng() - 0.5), a[1] + 0.1 * (rng() - 0.5), a[2] + 0.1 * (rng() - 0.5)];
            let (ia, ib) = (fil.push_node(a), fil.push_node(b));
            fil.push_segment(ia, ib, 2.0 * rng() - 1.0, &core);
        }
        let a = fil.push_node([o[0], o[1], o[2]]);
        fil.push_leg(a, [1.0, 0.0, 0.0], 0.7, &core, 0.1);
        let pts: Vec<[f64; 3]> =
            (0..300).map(|_| [o[0] + 8.0 * rng() - 2.0, o[1] + 6.0 * rng() - 2.0, o[2] + 3.0 * rng() - 1.0]).collect();
        let direct = crate::induce::induced_velocity(&[&fil], &pts);
        let scale = direct.iter().map(|u| (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()).fold(0.0, f64::max);
        let u = mixed(&fil, &pts);
        let err = max_error(&u, &direct);
        assert!(err <= 1e-6 * scale, "error {err:e} against largest velocity {scale:e}");
        let mut p = Points::default();
        for q in &pts {
            p.push(*q);
        }
        let mut threaded = vec![[0.0; 3]; pts.len()];
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let mut scratch = MixedScratch::default();
        pool.install(|| {
            scratch.consts.load(&fil);
            let c = &scratch.consts;
            scratch.blocks.for_each_chunk(&mut threaded, LANES32, DIRECT_CHUNKS_PER_THREAD, |first, chunk, blk| {
                for (i, block) in chunk.chunks_mut(LANES32).enumerate() {
                    add_block(&fil, c, &p, first + i, blk, block);
                }
            })
        });
        assert_eq!(threaded, u);
    }

    /// Every kernel this CPU runs gives the portable kernel's lanes bit for bit, for blocks of
    /// both widths (the direct sum's and the treecode's leaves'), with points near the
    /// filaments' axes and cut-off cylinders: the f32 results do not depend on the instruction
    /// set.
    #[test]
    fn instruction_sets_agree_bit_for_bit() {
        let mut seed = 5u64;
        let mut rng = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let core = CoreModel::CutOff { radius: 1e-3 };
        let mut fil = Filaments::default();
        let mut nodes = Vec::new();
        for _ in 0..40 {
            nodes.push(fil.push_node([3.0 * rng(), 2.0 * rng(), 0.5 * rng()]));
        }
        for k in 0..700 {
            let (a, b) = (nodes[k % 40], nodes[(7 * k + 3) % 40]);
            if a != b {
                fil.push_segment(a, b, 2.0 * rng() - 1.0, &core);
            }
        }
        fil.push_leg(nodes[0], [1.0, 0.0, 0.0], 0.4, &core, 1.0);
        fil.push_leg(nodes[1], [0.0, 0.6, 0.8], -0.3, &core, 1.0);
        let mut c = Filaments32::default();
        c.load(&fil);
        let mut isas = vec![Isa::Generic];
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            isas.push(Isa::Avx2);
            if std::is_x86_feature_detected!("avx512f") {
                isas.push(Isa::Avx512);
            }
        }
        // Points on a node, on a segment's axis beyond its end, inside a cut-off, and anywhere.
        let (p0, p1) = (fil.node(nodes[3] as usize), fil.node(nodes[24] as usize));
        let mut pts: Vec<[f64; 3]> = vec![p0, [2.0 * p1[0] - p0[0], 2.0 * p1[1] - p0[1], 2.0 * p1[2] - p0[2]]];
        pts.push([p0[0] + 2e-4, p0[1], p0[2]]);
        while pts.len() < LANES32 {
            pts.push([4.0 * rng() - 0.5, 3.0 * rng() - 0.5, rng() - 0.25]);
        }
        fn run<const N: usize>(isa: Isa, fil: &Filaments, c: &Filaments32, pts: &[[f64; 3]]) -> [[f64; N]; 3] {
            let p = [0, 1, 2].map(|q| std::array::from_fn(|l| pts[l][q]));
            let (mut blk, mut u) = (Block32::<N>::default(), [[0.0; N]; 3]);
            add_lanes_on(isa, fil, c, &p, &mut blk, &mut u);
            u
        }
        let (wide, narrow) = (run::<LANES32>(Isa::Generic, &fil, &c, &pts), run::<8>(Isa::Generic, &fil, &c, &pts));
        assert!(wide.iter().flatten().all(|v| v.is_finite() && *v != 0.0));
        for isa in isas {
            assert_eq!(run::<LANES32>(isa, &fil, &c, &pts), wide, "{isa:?}, {LANES32} lanes");
            assert_eq!(run::<8>(isa, &fil, &c, &pts), narrow, "{isa:?}, 8 lanes");
        }
    }

    /// The paper's wing's far wake after 120 steps (25 m/s, dt 0.01 s, 5°, folding, closure legs,
    /// a mirror plane, SHARPy's 1e-6 m cut-off) at the collocation points, the segment midpoints
    /// and points spread over the wake: within 1e-6 |V∞| of the f64 sum.
    #[test]
    fn mixed_matches_direct_on_a_real_wake() {
        use crate::aic::{WakePart, build_known_wake};
        use crate::samples::FlaredWing;
        use crate::{ImagePlane, Lattice, Uvlm, UvlmParams};
        let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
        let lat = Lattice::from_stations(wing.spec(), &wing.stations(0.0)).unwrap();
        let mut p = UvlmParams::new(0.0889, [0.0, -25.0, 0.0]);
        p.n_wake_rows = 120;
        p.wake_closure = true;
        p.images = vec![ImagePlane::through_origin([1.0, 0.0, 0.0])];
        let mut uv = Uvlm::new(lat, p.clone()).unwrap();
        for k in 0..120 {
            let fold = 0.3 * (0.05 * k as f64).sin();
            uv.update_stations(&wing.stations(fold), None).unwrap();
            uv.step(0.01).unwrap();
        }
        let lat = uv.lattice();
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let nodes = lat.ring_nodes();
        let te = &nodes[m * (n + 1)..];
        let mut fil = Filaments::default();
        let dir = Some([0.0, -1.0, 0.0]);
        build_known_wake(&mut fil, te, uv.wake(), dir, &p.wake_core, &p.bound_core, &p.images, WakePart::Far);
        let mut pts: Vec<[f64; 3]> = lat.collocation().to_vec();
        let mid = |a: [f64; 3], b: [f64; 3]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])];
        for i in 0..=m {
            for j in 0..=n {
                let a = nodes[i * (n + 1) + j];
                if j < n {
                    pts.push(mid(a, nodes[i * (n + 1) + j + 1]));
                }
                if i < m {
                    pts.push(mid(a, nodes[(i + 1) * (n + 1) + j]));
                }
            }
        }
        for r in (0..120).step_by(7) {
            for j in (0..=n).step_by(3) {
                let q = uv.wake().node(r, j);
                pts.push([q[0] + 0.1, q[1] + 0.05, q[2] + 0.2]);
            }
        }
        let direct = crate::induce::induced_velocity(&[&fil], &pts);
        let err = max_error(&mixed(&fil, &pts), &direct);
        println!("mixed precision, real far wake: error {err:.3e} m/s at {} points", pts.len());
        assert!(err <= 1e-6 * 25.0, "error {err:e} m/s");
    }
}
