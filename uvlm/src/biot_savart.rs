//! Biot–Savart induction of straight vortex segments and semi-infinite legs.
//!
//! For a point P and a segment A→B of strength Γ, with r₁ = P − A, r₂ = P − B, r₀ = B − A,
//!
//! $$ u = \frac{\Gamma}{4\pi}\,(r_1\times r_2)\,
//!        \frac{(|r_1|+|r_2|)\,(|r_1||r_2| - r_1\cdot r_2)}{|r_1||r_2|\,(|r_1\times r_2|^2 + r_c^2|r_0|^2)} $$
//!
//! (the Katz–Plotkin formula rewritten without the cancellation of
//! `r0·(r1/|r1| − r2/|r2|)`). `r_c = 0` is the singular line vortex; `r_c > 0` is the Scully
//! (Vatistas n = 1) core. A hard cut-off (SHARPy) zeroes the induction within a distance ε of the
//! filament axis instead. A semi-infinite leg from A along the unit vector d gives
//!
//! $$ u = \frac{\Gamma}{4\pi}\,\frac{d\times r}{|d\times r|^2 + r_c^2}\Big(1 + \frac{d\cdot r}{|r|}\Big),\quad r = P - A. $$
//!
//! The hot kernels work on blocks of [`LANES`] evaluation points against a [`Filaments`] set in
//! structure-of-arrays layout; the vectors `P − X` and their norms are computed once per
//! (point, node) and reused by every segment that touches the node.

use serde::{Deserialize, Serialize};

/// Number of evaluation points processed together by the block kernels.
pub const LANES: usize = 8;

/// 1/(4π).
pub(crate) const INV_FOUR_PI: f64 = 0.25 * std::f64::consts::FRAC_1_PI;

/// Relative guard: the induction is zeroed when the distance to the axis is below 1e-12 × length.
const TINY_REL2: f64 = 1e-24;

/// Vortex-core model of a family of filaments.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum CoreModel {
    /// Singular line vortex with a hard cut-off (SHARPy's `vortex_radius`): the induction is zero
    /// when the point is closer than `radius` (m) to the filament axis. SHARPy's default is 1e-6 m.
    CutOff {
        /// Cut-off distance from the filament axis, m (≥ 0).
        radius: f64,
    },
    /// Scully (Vatistas n = 1) core whose radius is `fraction` × the local chordwise panel length
    /// (a chordwise segment's own length; for a spanwise segment the length of the adjacent
    /// chordwise edge), so the core shrinks with the mesh and the discrete model converges to the
    /// inviscid limit.
    Scully {
        /// Core radius over segment length, dimensionless (≥ 0).
        fraction: f64,
    },
    /// Scully core of a fixed radius (Ptera Software uses 3 % of the mean chord), m.
    ScullyRadius {
        /// Core radius, m (≥ 0).
        radius: f64,
    },
}

impl Default for CoreModel {
    /// A 1e-6 m cut-off, as SHARPy.
    fn default() -> Self {
        CoreModel::CutOff { radius: 1e-6 }
    }
}

impl CoreModel {
    /// The model's length parameter (for validation).
    pub fn parameter(&self) -> f64 {
        match *self {
            CoreModel::CutOff { radius } => radius,
            CoreModel::Scully { fraction } => fraction,
            CoreModel::ScullyRadius { radius } => radius,
        }
    }

    /// Whether [`CoreModel::coefficients`] reads its `scale` argument (only the Scully core sized
    /// from the panel): callers skip computing it otherwise.
    #[inline]
    pub fn uses_scale(&self) -> bool {
        matches!(self, CoreModel::Scully { .. })
    }

    /// Per-segment kernel constants `(core2, cut2)` for a segment of squared length `len2` whose
    /// local panel length is `scale`: the term added to |r₁×r₂|² and the threshold below which
    /// the induction is zeroed.
    #[inline]
    pub fn coefficients(&self, len2: f64, scale: f64) -> (f64, f64) {
        let guard = TINY_REL2 * len2 * len2;
        match *self {
            CoreModel::CutOff { radius } => (0.0, (radius * radius * len2).max(guard)),
            CoreModel::Scully { fraction } => (fraction * fraction * scale * scale * len2, guard),
            CoreModel::ScullyRadius { radius } => (radius * radius * len2, guard),
        }
    }

    /// Kernel constants `(core2, cut2)` of a semi-infinite leg whose local length scale is `len`.
    #[inline]
    pub fn leg_coefficients(&self, len: f64) -> (f64, f64) {
        let guard = TINY_REL2 * len * len;
        match *self {
            CoreModel::CutOff { radius } => (0.0, (radius * radius).max(guard)),
            CoreModel::Scully { fraction } => (fraction * fraction * len * len, guard),
            CoreModel::ScullyRadius { radius } => (radius * radius, guard),
        }
    }
}

/// Velocity induced at `p` by the segment `a → b` of circulation `gamma` (scalar reference
/// kernel; a [`CoreModel::Scully`] core is sized from the segment's own length).
pub fn segment_velocity(p: [f64; 3], a: [f64; 3], b: [f64; 3], gamma: f64, core: CoreModel) -> [f64; 3] {
    let len2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2);
    let (core2, cut2) = core.coefficients(len2, len2.sqrt());
    let r1 = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let r2 = [p[0] - b[0], p[1] - b[1], p[2] - b[2]];
    let n1 = (r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]).sqrt();
    let n2 = (r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]).sqrt();
    let (c, k) = pair(r1, n1, r2, n2, core2, cut2);
    let g = gamma * INV_FOUR_PI;
    [g * k * c[0], g * k * c[1], g * k * c[2]]
}

/// Velocity induced at `p` by a semi-infinite leg starting at `a` along the unit vector `dir`.
///
/// `core` is applied with the length scale `len` (used by [`CoreModel::Scully`]).
pub fn semi_infinite_velocity(
    p: [f64; 3],
    a: [f64; 3],
    dir: [f64; 3],
    gamma: f64,
    core: CoreModel,
    len: f64,
) -> [f64; 3] {
    let (core2, cut2) = core.leg_coefficients(len);
    let r = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let rn = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let (c, k) = leg(r, rn, dir, core2, cut2);
    let g = gamma * INV_FOUR_PI;
    [g * k * c[0], g * k * c[1], g * k * c[2]]
}

/// One point–segment pair: returns r₁×r₂ and the scalar factor (without Γ/4π).
#[inline(always)]
fn pair(r1: [f64; 3], n1: f64, r2: [f64; 3], n2: f64, core2: f64, cut2: f64) -> ([f64; 3], f64) {
    let cx = r1[1] * r2[2] - r1[2] * r2[1];
    let cy = r1[2] * r2[0] - r1[0] * r2[2];
    let cz = r1[0] * r2[1] - r1[1] * r2[0];
    let h2 = cx * cx + cy * cy + cz * cz + core2;
    let n12 = n1 * n2;
    let dot = r1[0] * r2[0] + r1[1] * r2[1] + r1[2] * r2[2];
    let num = (n1 + n2) * (n12 - dot);
    let ok = h2 > cut2 && n12 > 0.0;
    let den = if ok { n12 * h2 } else { 1.0 };
    let k = if ok { num / den } else { 0.0 };
    ([cx, cy, cz], k)
}

/// One point–leg pair: returns d×r and the scalar factor (without Γ/4π).
#[inline(always)]
fn leg(r: [f64; 3], rn: f64, d: [f64; 3], core2: f64, cut2: f64) -> ([f64; 3], f64) {
    let cx = d[1] * r[2] - d[2] * r[1];
    let cy = d[2] * r[0] - d[0] * r[2];
    let cz = d[0] * r[1] - d[1] * r[0];
    let h2 = cx * cx + cy * cy + cz * cz;
    let hc = h2 + core2;
    let ok = h2 > cut2 && rn > 0.0;
    let den = if ok { hc * rn } else { 1.0 };
    let dot = d[0] * r[0] + d[1] * r[1] + d[2] * r[2];
    let k = if ok { (rn + dot) / den } else { 0.0 };
    ([cx, cy, cz], k)
}

/// A set of vortex filaments in structure-of-arrays layout: nodes, straight segments between
/// nodes and semi-infinite legs starting at nodes. Strengths are stored pre-multiplied by 1/(4π).
///
/// Buffers keep their capacity across [`Filaments::clear`], so rebuilding a set of the same size
/// every time step does not allocate.
#[derive(Debug, Clone, Default)]
pub struct Filaments {
    pub(crate) x: Vec<f64>,
    pub(crate) y: Vec<f64>,
    pub(crate) z: Vec<f64>,
    pub(crate) seg_a: Vec<u32>,
    pub(crate) seg_b: Vec<u32>,
    pub(crate) seg_g: Vec<f64>,
    pub(crate) seg_core2: Vec<f64>,
    pub(crate) seg_cut2: Vec<f64>,
    pub(crate) leg_a: Vec<u32>,
    pub(crate) leg_d: Vec<[f64; 3]>,
    pub(crate) leg_g: Vec<f64>,
    pub(crate) leg_core2: Vec<f64>,
    pub(crate) leg_cut2: Vec<f64>,
}

impl Filaments {
    /// Remove everything, keeping the capacity.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.seg_a.clear();
        self.seg_b.clear();
        self.seg_g.clear();
        self.seg_core2.clear();
        self.seg_cut2.clear();
        self.leg_a.clear();
        self.leg_d.clear();
        self.leg_g.clear();
        self.leg_core2.clear();
        self.leg_cut2.clear();
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.x.len()
    }

    /// Number of straight segments.
    pub fn n_segments(&self) -> usize {
        self.seg_a.len()
    }

    /// Number of semi-infinite legs.
    pub fn n_legs(&self) -> usize {
        self.leg_a.len()
    }

    /// Number of filaments (segments + legs).
    pub fn n_filaments(&self) -> usize {
        self.n_segments() + self.n_legs()
    }

    /// Position of node `i`.
    pub fn node(&self, i: usize) -> [f64; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }

    /// Append a node; returns its index.
    pub fn push_node(&mut self, p: [f64; 3]) -> u32 {
        self.x.push(p[0]);
        self.y.push(p[1]);
        self.z.push(p[2]);
        (self.x.len() - 1) as u32
    }

    /// Append the segment `a → b` of circulation `gamma` with the given core, sized (for
    /// [`CoreModel::Scully`]) from the segment's own length.
    pub fn push_segment(&mut self, a: u32, b: u32, gamma: f64, core: &CoreModel) {
        let len = if core.uses_scale() {
            let (pa, pb) = (self.node(a as usize), self.node(b as usize));
            ((pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2) + (pb[2] - pa[2]).powi(2)).sqrt()
        } else {
            0.0
        };
        self.push_segment_scaled(a, b, gamma, core, len);
    }

    /// Append the segment `a → b` of circulation `gamma` with the given core sized from the local
    /// panel length `scale`, m.
    pub fn push_segment_scaled(&mut self, a: u32, b: u32, gamma: f64, core: &CoreModel, scale: f64) {
        let (pa, pb) = (self.node(a as usize), self.node(b as usize));
        let len2 = (pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2) + (pb[2] - pa[2]).powi(2);
        let (core2, cut2) = core.coefficients(len2, scale);
        self.seg_a.push(a);
        self.seg_b.push(b);
        self.seg_g.push(gamma * INV_FOUR_PI);
        self.seg_core2.push(core2);
        self.seg_cut2.push(cut2);
    }

    /// Append a semi-infinite leg from node `a` along the unit vector `dir`; `len` is the local
    /// length scale used by [`CoreModel::Scully`].
    pub fn push_leg(&mut self, a: u32, dir: [f64; 3], gamma: f64, core: &CoreModel, len: f64) {
        let (core2, cut2) = core.leg_coefficients(len);
        self.leg_a.push(a);
        self.leg_d.push(dir);
        self.leg_g.push(gamma * INV_FOUR_PI);
        self.leg_core2.push(core2);
        self.leg_cut2.push(cut2);
    }

    /// Set the circulation of segment `s` (not multiplied by 1/4π).
    #[inline]
    pub fn set_segment_gamma(&mut self, s: usize, gamma: f64) {
        self.seg_g[s] = gamma * INV_FOUR_PI;
    }

    /// Set the circulation of leg `l` (not multiplied by 1/4π).
    #[inline]
    pub fn set_leg_gamma(&mut self, l: usize, gamma: f64) {
        self.leg_g[l] = gamma * INV_FOUR_PI;
    }

    /// Circulation of segment `s`.
    pub fn segment_gamma(&self, s: usize) -> f64 {
        self.seg_g[s] / INV_FOUR_PI
    }

    /// Endpoints of segment `s`.
    pub fn segment_nodes(&self, s: usize) -> (u32, u32) {
        (self.seg_a[s], self.seg_b[s])
    }

    /// Velocity induced at one point by every filament (scalar path, for checks and few points).
    pub fn velocity_at(&self, p: [f64; 3]) -> [f64; 3] {
        let mut u = [0.0; 3];
        for s in 0..self.n_segments() {
            let (a, b) = (self.seg_a[s] as usize, self.seg_b[s] as usize);
            let r1 = [p[0] - self.x[a], p[1] - self.y[a], p[2] - self.z[a]];
            let r2 = [p[0] - self.x[b], p[1] - self.y[b], p[2] - self.z[b]];
            let n1 = (r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]).sqrt();
            let n2 = (r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]).sqrt();
            let (c, k) = pair(r1, n1, r2, n2, self.seg_core2[s], self.seg_cut2[s]);
            let g = self.seg_g[s] * k;
            u[0] += g * c[0];
            u[1] += g * c[1];
            u[2] += g * c[2];
        }
        for l in 0..self.n_legs() {
            let a = self.leg_a[l] as usize;
            let r = [p[0] - self.x[a], p[1] - self.y[a], p[2] - self.z[a]];
            let rn = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
            let (c, k) = leg(r, rn, self.leg_d[l], self.leg_core2[l], self.leg_cut2[l]);
            let g = self.leg_g[l] * k;
            u[0] += g * c[0];
            u[1] += g * c[1];
            u[2] += g * c[2];
        }
        u
    }
}

/// Per-block scratch: for each node of a [`Filaments`] set, the lanes of P − X (x, y, z) and |P − X|.
#[derive(Debug, Clone, Default)]
pub(crate) struct NodeBlock {
    r: Vec<[[f64; LANES]; 4]>,
    /// Per-filament normal influences of one block (only for influence matrices).
    pub(crate) infl: Vec<[f64; LANES]>,
    /// Per-ring sums of a block's lanes (only for influence matrices): ring-major, so that a
    /// filament's lanes go to one cache line instead of one per lane.
    pub(crate) rings: Vec<[f64; LANES]>,
}

/// Kernel bodies, compiled once per instruction set by [`multiversion`].
macro_rules! kernels {
    ($($attr:meta)?; $vel:ident, $infl:ident) => {
        $(#[$attr])?
        fn $vel(fil: &Filaments, blk: &NodeBlock, u: &mut [[f64; LANES]; 3]) {
            let mut ux = [0.0; LANES];
            let mut uy = [0.0; LANES];
            let mut uz = [0.0; LANES];
            let ns = fil.n_segments();
            let (sa, sb, sg, sc, st) =
                (&fil.seg_a[..ns], &fil.seg_b[..ns], &fil.seg_g[..ns], &fil.seg_core2[..ns], &fil.seg_cut2[..ns]);
            for s in 0..ns {
                let r1 = &blk.r[sa[s] as usize];
                let r2 = &blk.r[sb[s] as usize];
                let (g, core2, cut2) = (sg[s], sc[s], st[s]);
                for l in 0..LANES {
                    let (c, k) = pair(
                        [r1[0][l], r1[1][l], r1[2][l]],
                        r1[3][l],
                        [r2[0][l], r2[1][l], r2[2][l]],
                        r2[3][l],
                        core2,
                        cut2,
                    );
                    let gk = g * k;
                    ux[l] += gk * c[0];
                    uy[l] += gk * c[1];
                    uz[l] += gk * c[2];
                }
            }
            for j in 0..fil.n_legs() {
                let r = &blk.r[fil.leg_a[j] as usize];
                let (d, g, core2, cut2) = (fil.leg_d[j], fil.leg_g[j], fil.leg_core2[j], fil.leg_cut2[j]);
                for l in 0..LANES {
                    let (c, k) = leg([r[0][l], r[1][l], r[2][l]], r[3][l], d, core2, cut2);
                    let gk = g * k;
                    ux[l] += gk * c[0];
                    uy[l] += gk * c[1];
                    uz[l] += gk * c[2];
                }
            }
            for l in 0..LANES {
                u[0][l] += ux[l];
                u[1][l] += uy[l];
                u[2][l] += uz[l];
            }
        }

        $(#[$attr])?
        fn $infl(fil: &Filaments, blk: &mut NodeBlock, nx: &[f64; LANES], ny: &[f64; LANES], nz: &[f64; LANES]) {
            let ns = fil.n_segments();
            let nf = ns + fil.n_legs();
            if blk.infl.len() < nf {
                blk.infl.resize(nf, [0.0; LANES]);
            }
            let (r, infl) = (&blk.r, &mut blk.infl);
            for s in 0..ns {
                let r1 = &r[fil.seg_a[s] as usize];
                let r2 = &r[fil.seg_b[s] as usize];
                let (g, core2, cut2) = (fil.seg_g[s], fil.seg_core2[s], fil.seg_cut2[s]);
                let mut out = [0.0; LANES];
                for l in 0..LANES {
                    let (c, k) = pair(
                        [r1[0][l], r1[1][l], r1[2][l]],
                        r1[3][l],
                        [r2[0][l], r2[1][l], r2[2][l]],
                        r2[3][l],
                        core2,
                        cut2,
                    );
                    out[l] = g * k * (c[0] * nx[l] + c[1] * ny[l] + c[2] * nz[l]);
                }
                infl[s] = out;
            }
            for j in 0..fil.n_legs() {
                let rr = &r[fil.leg_a[j] as usize];
                let (d, g, core2, cut2) = (fil.leg_d[j], fil.leg_g[j], fil.leg_core2[j], fil.leg_cut2[j]);
                let mut out = [0.0; LANES];
                for l in 0..LANES {
                    let (c, k) = leg([rr[0][l], rr[1][l], rr[2][l]], rr[3][l], d, core2, cut2);
                    out[l] = g * k * (c[0] * nx[l] + c[1] * ny[l] + c[2] * nz[l]);
                }
                infl[ns + j] = out;
            }
        }
    };
}

fn fill_generic(fil: &Filaments, px: &[f64; LANES], py: &[f64; LANES], pz: &[f64; LANES], blk: &mut NodeBlock) {
    let n = fil.n_nodes();
    if blk.r.len() < n {
        blk.r.resize(n, [[0.0; LANES]; 4]);
    }
    let (xs, ys, zs) = (&fil.x[..n], &fil.y[..n], &fil.z[..n]);
    for (((r, &x), &y), &z) in blk.r[..n].iter_mut().zip(xs).zip(ys).zip(zs) {
        let mut dx = [0.0; LANES];
        let mut dy = [0.0; LANES];
        let mut dz = [0.0; LANES];
        let mut nn = [0.0; LANES];
        for l in 0..LANES {
            dx[l] = px[l] - x;
            dy[l] = py[l] - y;
            dz[l] = pz[l] - z;
            nn[l] = (dx[l] * dx[l] + dy[l] * dy[l] + dz[l] * dz[l]).sqrt();
        }
        *r = [dx, dy, dz, nn];
    }
}

kernels!(; velocity_generic, influence_generic);
#[cfg(target_arch = "x86_64")]
kernels!(target_feature(enable = "avx2,fma"); velocity_avx2, influence_avx2);
#[cfg(target_arch = "x86_64")]
kernels!(target_feature(enable = "avx512f,avx2,fma"); velocity_avx512, influence_avx512);

/// The node fill written with AVX-512 intrinsics: auto-vectorisation of the portable version
/// picks the node loop and scatters (measured 2× slower).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn fill_avx512(fil: &Filaments, px: &[f64; LANES], py: &[f64; LANES], pz: &[f64; LANES], blk: &mut NodeBlock) {
    use std::arch::x86_64::*;
    let n = fil.n_nodes();
    if blk.r.len() < n {
        blk.r.resize(n, [[0.0; LANES]; 4]);
    }
    // SAFETY: unaligned loads/stores of exactly LANES = 8 f64 from/to [f64; 8] arrays.
    unsafe {
        let (vx, vy, vz) = (_mm512_loadu_pd(px.as_ptr()), _mm512_loadu_pd(py.as_ptr()), _mm512_loadu_pd(pz.as_ptr()));
        let (xs, ys, zs) = (&fil.x[..n], &fil.y[..n], &fil.z[..n]);
        for (((r, &x), &y), &z) in blk.r[..n].iter_mut().zip(xs).zip(ys).zip(zs) {
            let dx = _mm512_sub_pd(vx, _mm512_set1_pd(x));
            let dy = _mm512_sub_pd(vy, _mm512_set1_pd(y));
            let dz = _mm512_sub_pd(vz, _mm512_set1_pd(z));
            let n2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)), _mm512_mul_pd(dz, dz));
            _mm512_storeu_pd(r[0].as_mut_ptr(), dx);
            _mm512_storeu_pd(r[1].as_mut_ptr(), dy);
            _mm512_storeu_pd(r[2].as_mut_ptr(), dz);
            _mm512_storeu_pd(r[3].as_mut_ptr(), _mm512_sqrt_pd(n2));
        }
    }
}

/// The node fill with AVX2 intrinsics (two 4-lane halves).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn fill_avx2(fil: &Filaments, px: &[f64; LANES], py: &[f64; LANES], pz: &[f64; LANES], blk: &mut NodeBlock) {
    use std::arch::x86_64::*;
    let n = fil.n_nodes();
    if blk.r.len() < n {
        blk.r.resize(n, [[0.0; LANES]; 4]);
    }
    // SAFETY: unaligned loads/stores of 4 f64 at offsets 0 and 4 of [f64; 8] arrays.
    unsafe {
        for h in [0usize, 4] {
            let vx = _mm256_loadu_pd(px.as_ptr().add(h));
            let vy = _mm256_loadu_pd(py.as_ptr().add(h));
            let vz = _mm256_loadu_pd(pz.as_ptr().add(h));
            let (xs, ys, zs) = (&fil.x[..n], &fil.y[..n], &fil.z[..n]);
            for (((r, &x), &y), &z) in blk.r[..n].iter_mut().zip(xs).zip(ys).zip(zs) {
                let dx = _mm256_sub_pd(vx, _mm256_set1_pd(x));
                let dy = _mm256_sub_pd(vy, _mm256_set1_pd(y));
                let dz = _mm256_sub_pd(vz, _mm256_set1_pd(z));
                let n2 =
                    _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
                _mm256_storeu_pd(r[0].as_mut_ptr().add(h), dx);
                _mm256_storeu_pd(r[1].as_mut_ptr().add(h), dy);
                _mm256_storeu_pd(r[2].as_mut_ptr().add(h), dz);
                _mm256_storeu_pd(r[3].as_mut_ptr().add(h), _mm256_sqrt_pd(n2));
            }
        }
    }
}

/// Instruction set chosen at run time for the block kernels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Isa {
    Generic,
    #[cfg(target_arch = "x86_64")]
    Avx2,
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

pub(crate) fn isa() -> Isa {
    static ISA: std::sync::OnceLock<Isa> = std::sync::OnceLock::new();
    *ISA.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx512f")
                && std::is_x86_feature_detected!("avx2")
                && std::is_x86_feature_detected!("fma")
            {
                return Isa::Avx512;
            }
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                return Isa::Avx2;
            }
        }
        Isa::Generic
    })
}

/// Fill the per-node block scratch for the points `p` (one block).
#[inline]
pub(crate) fn fill_block(
    fil: &Filaments,
    px: &[f64; LANES],
    py: &[f64; LANES],
    pz: &[f64; LANES],
    blk: &mut NodeBlock,
) {
    match isa() {
        Isa::Generic => fill_generic(fil, px, py, pz, blk),
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { fill_avx2(fil, px, py, pz, blk) },
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { fill_avx512(fil, px, py, pz, blk) },
    }
}

/// Add the velocity induced by all filaments at the block's points to `u`.
#[inline]
pub(crate) fn velocity_block(fil: &Filaments, blk: &NodeBlock, u: &mut [[f64; LANES]; 3]) {
    match isa() {
        Isa::Generic => velocity_generic(fil, blk, u),
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { velocity_avx2(fil, blk, u) },
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { velocity_avx512(fil, blk, u) },
    }
}

/// Per-filament normal influence `Γ_f u_f(P_l)·n_l` of one block, into `blk.infl`
/// (segments first, then legs).
#[inline]
pub(crate) fn influence_block(
    fil: &Filaments,
    blk: &mut NodeBlock,
    nx: &[f64; LANES],
    ny: &[f64; LANES],
    nz: &[f64; LANES],
) {
    match isa() {
        Isa::Generic => influence_generic(fil, blk, nx, ny, nz),
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { influence_avx2(fil, blk, nx, ny, nz) },
        // SAFETY: the features were detected at run time.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { influence_avx512(fil, blk, nx, ny, nz) },
    }
}

/// Load the `b`-th block of [`LANES`] entries of `v`, padding past the end with the last entry.
#[inline]
pub(crate) fn load_lanes(v: &[f64], b: usize) -> [f64; LANES] {
    let mut out = [0.0; LANES];
    let start = b * LANES;
    let last = v.len() - 1;
    for (l, o) in out.iter_mut().enumerate() {
        *o = v[(start + l).min(last)];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Infinite straight line vortex limit: a long segment gives Γ/(2πh).
    #[test]
    fn long_segment_matches_line_vortex() {
        let u = segment_velocity(
            [0.0, 0.0, 0.0],
            [1.0, -1e6, 0.0],
            [1.0, 1e6, 0.0],
            2.0,
            CoreModel::CutOff { radius: 0.0 },
        );
        // Γ along +y at x = 1: at the origin (r = −x) u = Γ/(2πh) · (ŷ × (−x̂)) = Γ/(2π) ẑ.
        assert_relative_eq!(u[2], 2.0 / (2.0 * std::f64::consts::PI), max_relative = 1e-10);
        assert_relative_eq!(u[0], 0.0, epsilon = 1e-15);
    }

    /// The cancellation-free form equals the textbook Katz–Plotkin form.
    #[test]
    fn matches_katz_plotkin_form() {
        let (p, a, b) = ([0.3, 0.7, -0.2], [0.0, 0.0, 0.0], [0.5, 1.2, 0.1]);
        let u = segment_velocity(p, a, b, 1.0, CoreModel::CutOff { radius: 0.0 });
        let r1 = nalgebra::Vector3::from(p) - nalgebra::Vector3::from(a);
        let r2 = nalgebra::Vector3::from(p) - nalgebra::Vector3::from(b);
        let r0 = r1 - r2;
        let c = r1.cross(&r2);
        let kp = c / c.norm_squared() * r0.dot(&(r1 / r1.norm() - r2 / r2.norm())) * INV_FOUR_PI;
        for k in 0..3 {
            assert_relative_eq!(u[k], kp[k], max_relative = 1e-12);
        }
    }

    /// A semi-infinite leg equals the limit of a very long segment.
    #[test]
    fn semi_infinite_is_long_segment_limit() {
        let (p, a, d) = ([0.3, 0.7, -0.2], [0.1, -0.2, 0.05], [0.6, 0.0, 0.8]);
        let l = 1e7;
        let b = [a[0] + l * d[0], a[1] + l * d[1], a[2] + l * d[2]];
        let core = CoreModel::CutOff { radius: 0.0 };
        let us = segment_velocity(p, a, b, 1.3, core);
        let ul = semi_infinite_velocity(p, a, d, 1.3, core, 1.0);
        for k in 0..3 {
            assert_relative_eq!(us[k], ul[k], max_relative = 1e-6);
        }
    }

    /// Points on the axis or at a node give zero, not NaN; the Scully core is finite and regular.
    #[test]
    fn singular_points_are_guarded() {
        let (a, b) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        for core in [CoreModel::CutOff { radius: 0.0 }, CoreModel::Scully { fraction: 0.1 }] {
            for p in [[0.5, 0.0, 0.0], a, b, [2.0, 0.0, 0.0]] {
                let u = segment_velocity(p, a, b, 1.0, core);
                assert_eq!(u, [0.0, 0.0, 0.0]);
            }
        }
        // Inside the Scully core the velocity grows linearly from the axis: u(h) ≈ Γ h/(2π rc²)
        // for a long segment (core sized from its own length here).
        let rc = 0.1 * 2e3;
        let h = 1e-3;
        let u = segment_velocity(
            [0.0, h, 0.0],
            [-1e3, 0.0, 0.0],
            [1e3, 0.0, 0.0],
            1.0,
            CoreModel::Scully { fraction: 0.1 },
        );
        assert_relative_eq!(u[2].abs(), h / (2.0 * std::f64::consts::PI * rc * rc), max_relative = 1e-6);
    }

    /// The hard cut-off zeroes induction within the radius and leaves it untouched outside.
    #[test]
    fn cut_off_radius() {
        let (a, b) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let core = CoreModel::CutOff { radius: 0.01 };
        assert_eq!(segment_velocity([0.5, 0.009, 0.0], a, b, 1.0, core), [0.0; 3]);
        let u = segment_velocity([0.5, 0.011, 0.0], a, b, 1.0, core);
        let u0 = segment_velocity([0.5, 0.011, 0.0], a, b, 1.0, CoreModel::CutOff { radius: 0.0 });
        assert_relative_eq!(u[2], u0[2], max_relative = 1e-15);
    }

    /// Block kernels (whatever instruction set was detected) equal the scalar path.
    #[test]
    fn block_kernels_match_scalar() {
        let mut fil = Filaments::default();
        let core = CoreModel::Scully { fraction: 0.05 };
        let mut prev = fil.push_node([0.0, 0.0, 0.0]);
        for i in 1..20 {
            let t = i as f64 * 0.37;
            let n = fil.push_node([t.sin(), 0.3 * t, t.cos() * 0.2]);
            fil.push_segment(prev, n, 0.1 * i as f64 - 0.7, &core);
            prev = n;
        }
        fil.push_leg(3, [0.6, 0.0, 0.8], 0.4, &core, 0.5);
        let pts: Vec<[f64; 3]> = (0..13).map(|i| [0.1 * i as f64, 0.5 - 0.07 * i as f64, 0.3]).collect();
        let px: Vec<f64> = pts.iter().map(|p| p[0]).collect();
        let py: Vec<f64> = pts.iter().map(|p| p[1]).collect();
        let pz: Vec<f64> = pts.iter().map(|p| p[2]).collect();
        let mut blk = NodeBlock::default();
        for b in 0..pts.len().div_ceil(LANES) {
            let (bx, by, bz) = (load_lanes(&px, b), load_lanes(&py, b), load_lanes(&pz, b));
            fill_block(&fil, &bx, &by, &bz, &mut blk);
            let mut u = [[0.0; LANES]; 3];
            velocity_block(&fil, &blk, &mut u);
            let n = [0.0, 0.6, 0.8];
            influence_block(&fil, &mut blk, &[n[0]; LANES], &[n[1]; LANES], &[n[2]; LANES]);
            for l in 0..LANES {
                let i = (b * LANES + l).min(pts.len() - 1);
                let us = fil.velocity_at(pts[i]);
                for k in 0..3 {
                    assert_relative_eq!(u[k][l], us[k], max_relative = 1e-12, epsilon = 1e-15);
                }
                let un: f64 = (0..fil.n_filaments()).map(|f| blk.infl[f][l]).sum();
                assert_relative_eq!(un, us[1] * n[1] + us[2] * n[2], max_relative = 1e-12, epsilon = 1e-15);
            }
        }
    }

    /// Every compiled instruction-set variant (portable, AVX2, AVX-512 when the CPU has them)
    /// gives the same block velocities and influences.
    #[test]
    fn all_isa_variants_agree() {
        let mut fil = Filaments::default();
        let core = CoreModel::CutOff { radius: 1e-3 };
        for i in 0..30 {
            let t = i as f64 * 0.21;
            fil.push_node([t.cos(), t.sin(), 0.1 * t]);
        }
        for i in 0..29u32 {
            fil.push_segment(i, i + 1, 1.0 + 0.1 * i as f64, &core);
        }
        fil.push_leg(5, [1.0, 0.0, 0.0], -0.3, &core, 0.2);
        let px = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8];
        let (py, pz) = ([0.3; LANES], [-0.2; LANES]);
        let n = [0.0, 0.0, 1.0];
        let (nx, ny, nz) = ([n[0]; LANES], [n[1]; LANES], [n[2]; LANES]);
        let run = |fill: &dyn Fn(&mut NodeBlock),
                   vel: &dyn Fn(&NodeBlock, &mut [[f64; LANES]; 3]),
                   infl: &dyn Fn(&mut NodeBlock)| {
            let mut blk = NodeBlock::default();
            fill(&mut blk);
            let mut u = [[0.0; LANES]; 3];
            vel(&blk, &mut u);
            infl(&mut blk);
            (u, blk.infl.clone())
        };
        let reference = run(&|b| fill_generic(&fil, &px, &py, &pz, b), &|b, u| velocity_generic(&fil, b, u), &|b| {
            influence_generic(&fil, b, &nx, &ny, &nz)
        });
        let mut variants = Vec::new();
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: features detected above.
                variants.push(run(
                    &|b| unsafe { fill_avx2(&fil, &px, &py, &pz, b) },
                    &|b, u| unsafe { velocity_avx2(&fil, b, u) },
                    &|b| unsafe { influence_avx2(&fil, b, &nx, &ny, &nz) },
                ));
            }
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("fma") {
                // SAFETY: features detected above.
                variants.push(run(
                    &|b| unsafe { fill_avx512(&fil, &px, &py, &pz, b) },
                    &|b, u| unsafe { velocity_avx512(&fil, b, u) },
                    &|b| unsafe { influence_avx512(&fil, b, &nx, &ny, &nz) },
                ));
            }
        }
        for (u, infl) in &variants {
            for k in 0..3 {
                for l in 0..LANES {
                    assert_relative_eq!(u[k][l], reference.0[k][l], max_relative = 1e-12, epsilon = 1e-14);
                }
            }
            for (a, b) in infl.iter().zip(&reference.1) {
                for l in 0..LANES {
                    assert_relative_eq!(a[l], b[l], max_relative = 1e-12, epsilon = 1e-14);
                }
            }
        }
    }
}
