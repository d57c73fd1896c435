//! The derivative of a steady solution's loads with respect to the lattice's vertex positions
//! (docs/uvlm.md §17): the static aeroelastic tangent's aerodynamic part without one lattice
//! solve per structural unknown.
//!
//! The steady system on ring nodes `X` (semi-infinite or finite frozen wake along `V∞`, images
//! included) is `R(Γ, X) = (V∞ + U(c_p; Γ, X))·n_p = 0` with `U` the bound filaments' induction at
//! the collocation points `c_p` (ring centroids) and `n_p` the ring normals, so
//!
//! $$ \frac{d\Gamma}{dX} = -A^{-1}\,\frac{\partial R}{\partial X}\Big|_\Gamma ,\qquad
//!    A = \frac{\partial R}{\partial \Gamma}. $$
//!
//! `∂R/∂X` holds the Biot–Savart derivatives with respect to every filament's end points and the
//! evaluation point, and the normals' derivatives. The Joukowski force of lattice segment `s`,
//! `f_s = ρ g_s (V∞ + u(x_s)) × (x_B − x_A)`, split half and half to its end nodes, is
//! differentiated in its net circulation `g_s` (through `dΓ/dX`), in the induced velocity at its
//! midpoint (its circulations and its geometry) and in its own length vector. The hard cut-off
//! is differentiated as the solver evaluates it: a pair inside the cut-off round the segment
//! contributes nothing, and neither does its derivative; on the axis extension the regular value
//! of [`crate::axis_extension`] and its derivative. The lattice must be at rest in a uniform free stream (the
//! statics); Scully cores sized by the panel lengths are refused.

use nalgebra::DMatrix;

use crate::aic::{BoundSystem, TrailingEdge};
use crate::biot_savart::{CoreModel, Filaments};
use crate::dense_lu::DenseLu;
use crate::error::{Result, UvlmError};
use crate::params::SteadyWake;
use crate::solver::Uvlm;

type M3 = [[f64; 3]; 3];

/// A steady solution's loads and their derivatives with respect to the ring nodes of every
/// lattice (stacked surface after surface, each in its [`crate::Lattice::ring_nodes`] order;
/// coordinate `3 v + axis` of vertex `v`).
#[derive(Debug, Clone)]
pub struct SteadyLoadDerivative {
    /// Ring nodes per surface (`(M+1)(N+1)` each).
    pub n_nodes: Vec<usize>,
    /// The ring circulations of the solution, m²/s.
    pub gamma: Vec<f64>,
    /// The nodal forces (as [`crate::Loads::nodal`], stacked), N.
    pub nodal: Vec<[f64; 3]>,
    /// The strip forces (as [`crate::Loads::strip`], stacked), N.
    pub strip: Vec<[f64; 3]>,
    /// `dΓ/dX`, `n_rings × 3 n_vertices`, m/s.
    pub d_gamma: DMatrix<f64>,
    /// `d nodal / dX`, `3 n_vertices × 3 n_vertices`, N/m.
    pub d_nodal: DMatrix<f64>,
    /// `d strip / dX`, `3 n_strips × 3 n_vertices`, N/m.
    pub d_strip: DMatrix<f64>,
    /// The same derivatives' columns with respect to the grid nodes instead of the ring nodes
    /// are `· T`, [`SteadyLoadDerivative::ring_from_grid`].
    n_chordwise: Vec<usize>,
}

impl SteadyLoadDerivative {
    /// Number of vertices (ring nodes of all surfaces).
    pub fn n_vertices(&self) -> usize {
        self.n_nodes.iter().sum()
    }

    /// The linear map `T` (`3 n_vertices × 3 n_vertices`) from the grid nodes to the ring nodes
    /// (each ring node a quarter panel downstream of its grid node along the grid line: `dX =
    /// T dG`), so that a derivative with respect to the grid nodes is `D · T`.
    pub fn ring_from_grid(&self) -> DMatrix<f64> {
        let nv = self.n_vertices();
        let mut t = DMatrix::zeros(3 * nv, 3 * nv);
        let mut v0 = 0;
        for (&nn, &m) in self.n_nodes.iter().zip(&self.n_chordwise) {
            let nc = nn / (m + 1);
            for i in 0..=m {
                for j in 0..nc {
                    let k = v0 + i * nc + j;
                    let (other, w) = if i < m { (k + nc, 0.25) } else { (k - nc, -0.25) };
                    for a in 0..3 {
                        t[(3 * k + a, 3 * k + a)] += 1.0 - w;
                        t[(3 * k + a, 3 * other + a)] += w;
                    }
                }
            }
            v0 += nn;
        }
        t
    }
}

/// `[v]×`: the matrix of `x ↦ v × x`.
fn skew(v: [f64; 3]) -> M3 {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `c ⊗ g + k S`: the Jacobian of `k(r) c(r)` given `∂k/∂r = g` and `∂c/∂r = S`.
fn outer_plus(c: [f64; 3], g: [f64; 3], k: f64, s: &M3) -> M3 {
    let mut j = [[0.0; 3]; 3];
    for i in 0..3 {
        for l in 0..3 {
            j[i][l] = c[i] * g[l] + k * s[i][l];
        }
    }
    j
}

/// The segment kernel (without Γ/4π) at `r₁ = P − A`, `r₂ = P − B` with the core `core2 =
/// κ |r₁ − r₂|²` and the cut-off threshold `cut2` of [`crate::biot_savart`], and its Jacobians
/// `∂u/∂r₁`, `∂u/∂r₂` (zero inside the cut-off, as the value).
fn segment_jacobian(r1: [f64; 3], r2: [f64; 3], kappa: f64, cut2: f64) -> ([f64; 3], M3, M3) {
    let zero = ([0.0; 3], [[0.0; 3]; 3], [[0.0; 3]; 3]);
    let c = cross(r1, r2);
    let r0 = sub(r1, r2);
    let l2 = dot(r0, r0);
    let hc = dot(c, c) + kappa * l2;
    let (n1, n2) = (dot(r1, r1).sqrt(), dot(r2, r2).sqrt());
    let n12 = n1 * n2;
    let d = dot(r1, r2);
    if d > 0.0 {
        // Outside the segment: the load points' regular form (crate::axis_extension).
        let rc2 = if l2 > 0.0 { cut2 / l2 } else { f64::INFINITY };
        if n1 * n1 <= rc2 || n2 * n2 <= rc2 {
            return zero;
        }
        if kappa == 0.0 {
            return extension_jacobian(r1, r2, c, n1, n2, d);
        }
    } else if !(hc > cut2 && n12 > 0.0) {
        return zero;
    }
    let num = (n1 + n2) * (n12 - d);
    let den = n12 * hc;
    let k = num / den;
    let (r2c, cr1) = (cross(r2, c), cross(c, r1));
    let mut g1 = [0.0; 3];
    let mut g2 = [0.0; 3];
    for q in 0..3 {
        let dn1 = r1[q] / n1 * (n12 - d) + (n1 + n2) * (n2 * r1[q] / n1 - r2[q]);
        let dn2 = r2[q] / n2 * (n12 - d) + (n1 + n2) * (n1 * r2[q] / n2 - r1[q]);
        let dd1 = n2 * r1[q] / n1 * hc + n12 * (2.0 * r2c[q] + 2.0 * kappa * r0[q]);
        let dd2 = n1 * r2[q] / n2 * hc + n12 * (2.0 * cr1[q] - 2.0 * kappa * r0[q]);
        g1[q] = (dn1 - k * dd1) / den;
        g2[q] = (dn2 - k * dd2) / den;
    }
    let mut s1 = skew(r2);
    s1.iter_mut().flatten().for_each(|x| *x = -*x);
    let j1 = outer_plus(c, g1, k, &s1);
    let j2 = outer_plus(c, g2, k, &skew(r1));
    ([k * c[0], k * c[1], k * c[2]], j1, j2)
}

/// The regular form of the segment kernel on its axis extension (crate::axis_extension) and its
/// Jacobians, given `c = r₁ × r₂`, the norms and `d = r₁·r₂`.
fn extension_jacobian(r1: [f64; 3], r2: [f64; 3], c: [f64; 3], n1: f64, n2: f64, d: f64) -> ([f64; 3], M3, M3) {
    let n12 = n1 * n2;
    let pp = n12 + d;
    let den = n12 * pp;
    let k = (n1 + n2) / den;
    let mut g1 = [0.0; 3];
    let mut g2 = [0.0; 3];
    for q in 0..3 {
        let dd1 = n2 * r1[q] / n1 * pp + n12 * (n2 * r1[q] / n1 + r2[q]);
        let dd2 = n1 * r2[q] / n2 * pp + n12 * (n1 * r2[q] / n2 + r1[q]);
        g1[q] = (r1[q] / n1 - k * dd1) / den;
        g2[q] = (r2[q] / n2 - k * dd2) / den;
    }
    let mut s1 = skew(r2);
    s1.iter_mut().flatten().for_each(|x| *x = -*x);
    ([k * c[0], k * c[1], k * c[2]], outer_plus(c, g1, k, &s1), outer_plus(c, g2, k, &skew(r1)))
}

/// The semi-infinite leg's kernel (without Γ/4π) at `r = P − A` along the unit `d`, with the
/// constant `core2` and threshold `cut2`, and its Jacobian `∂u/∂r`.
fn leg_jacobian(r: [f64; 3], d: [f64; 3], core2: f64, cut2: f64) -> ([f64; 3], M3) {
    let c = cross(d, r);
    let h = dot(c, c);
    let rn = dot(r, r).sqrt();
    let dr = dot(d, r);
    if dr < 0.0 {
        // Upstream of the start: the load points' regular form (crate::axis_extension).
        if rn * rn <= cut2 {
            return ([0.0; 3], [[0.0; 3]; 3]);
        }
        if core2 == 0.0 {
            // k = 1 / (|r| (|r| − d·r)).
            let den = rn * (rn - dr);
            let k = 1.0 / den;
            let mut g = [0.0; 3];
            for q in 0..3 {
                g[q] = -(r[q] / rn * (rn - dr) + rn * (r[q] / rn - d[q])) / (den * den);
            }
            return ([k * c[0], k * c[1], k * c[2]], outer_plus(c, g, k, &skew(d)));
        }
    } else if !(h > cut2 && rn > 0.0) {
        return ([0.0; 3], [[0.0; 3]; 3]);
    }
    let hc = h + core2;
    let num = rn + dot(d, r);
    let den = hc * rn;
    let k = num / den;
    let cd = cross(c, d);
    let mut g = [0.0; 3];
    for q in 0..3 {
        let dn = r[q] / rn + d[q];
        let dd = 2.0 * cd[q] * rn + hc * r[q] / rn;
        g[q] = (dn - k * dd) / den;
    }
    ([k * c[0], k * c[1], k * c[2]], outer_plus(c, g, k, &skew(d)))
}

/// The induction of every filament at one point, with the Jacobians with respect to the
/// filament's end points (an `A` and, for segments, a `B`); the point's own Jacobian is minus
/// their sum.
struct PointInduction {
    /// Per filament (segments, then legs): the unit kernel `ũ` (without the strength).
    u: Vec<[f64; 3]>,
    /// `∂ũ/∂A`, `∂ũ/∂B` (legs: `B` unused).
    ja: Vec<M3>,
    jb: Vec<M3>,
}

impl PointInduction {
    fn new(n: usize) -> Self {
        Self { u: vec![[0.0; 3]; n], ja: vec![[[0.0; 3]; 3]; n], jb: vec![[[0.0; 3]; 3]; n] }
    }

    fn evaluate(&mut self, fil: &Filaments, kappa: &[f64], p: [f64; 3]) {
        let ns = fil.n_segments();
        for s in 0..ns {
            let (a, b) = (fil.node(fil.seg_a[s] as usize), fil.node(fil.seg_b[s] as usize));
            let (u, j1, j2) = segment_jacobian(sub(p, a), sub(p, b), kappa[s], fil.seg_cut2[s]);
            self.u[s] = u;
            self.ja[s] = neg(&j1);
            self.jb[s] = neg(&j2);
        }
        for l in 0..fil.n_legs() {
            let a = fil.node(fil.leg_a[l] as usize);
            let (u, j) = leg_jacobian(sub(p, a), fil.leg_d[l], fil.leg_core2[l], fil.leg_cut2[l]);
            self.u[ns + l] = u;
            self.ja[ns + l] = neg(&j);
            self.jb[ns + l] = [[0.0; 3]; 3];
        }
    }
}

fn neg(m: &M3) -> M3 {
    let mut o = *m;
    o.iter_mut().flatten().for_each(|x| *x = -*x);
    o
}

/// `a · b`.
fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut o = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            o[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    o
}

/// The bound system of the solver's lattices and everything the derivative needs about it.
struct Bound {
    bs: BoundSystem,
    /// Per filament node: the vertex it is (or reflects, or lies a fixed distance behind) and
    /// `∂node/∂vertex`.
    node_map: Vec<(usize, M3)>,
    /// Per filament: its rings and the strength per unit ring circulation (with 1/4π).
    incidence: Vec<Vec<(usize, f64)>>,
    /// Per segment: `κ = core2 / length²`.
    kappa: Vec<f64>,
    n_rings: usize,
}

impl Bound {
    fn new(uv: &Uvlm) -> Result<Self> {
        let p = uv.params();
        if let CoreModel::Scully { fraction } = p.bound_core {
            return Err(UvlmError::InvalidParameter {
                field: "bound_core (scully, for the load derivative)",
                value: fraction,
            });
        }
        let v = uv.flow().free_stream();
        let vn = dot(v, v).sqrt();
        if vn.is_nan() || vn <= 0.0 {
            return Err(UvlmError::InvalidParameter { field: "v_inf", value: vn });
        }
        let dir = [v[0] / vn, v[1] / vn, v[2] / vn];
        let te = match p.steady_wake {
            SteadyWake::SemiInfinite => TrailingEdge::Steady(dir),
            SteadyWake::Finite { length } => TrailingEdge::SteadyFinite { dir, length },
        };
        let lats: Vec<_> = uv.surfaces().iter().map(|s| s.lattice()).collect();
        let mut bs = BoundSystem::default();
        bs.build_surfaces(lats.iter().copied(), te, &p.bound_core, &p.images);
        let n_rings: usize = lats.iter().map(|l| l.n_rings()).sum();
        // Filament nodes: per surface its ring nodes, then (finite wake) its far nodes; then
        // the image copies of all of them.
        let n_copies = match p.images.len() {
            0 => 1,
            1 => 2,
            _ => 4,
        };
        let nn = bs.fil.n_nodes() / n_copies;
        let mut base = Vec::with_capacity(nn);
        let mut v0 = 0;
        for (k, lat) in lats.iter().enumerate() {
            let node0 = bs.surface(k).node0;
            let end = if k + 1 < lats.len() { bs.surface(k + 1).node0 } else { nn };
            let (m, nc) = (lat.n_chordwise(), lat.n_spanwise() + 1);
            for i in 0..end - node0 {
                let local = if i < lat.n_nodes() { i } else { m * nc + (i - lat.n_nodes()) };
                base.push(v0 + local);
            }
            v0 += lat.n_nodes();
        }
        let units: Vec<[f64; 3]> = p.images.iter().map(|q| q.unit_normal()).collect();
        let reflect = |u: [f64; 3]| {
            let mut r = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    r[i][j] = f64::from(u8::from(i == j)) - 2.0 * u[i] * u[j];
                }
            }
            r
        };
        let id = reflect([0.0; 3]);
        let copy_j: Vec<M3> = match units.len() {
            0 => vec![id],
            1 => vec![id, reflect(units[0])],
            _ => vec![id, reflect(units[0]), reflect(units[1]), mat_mul(&reflect(units[1]), &reflect(units[0]))],
        };
        let node_map = (0..bs.fil.n_nodes()).map(|i| (base[i % nn], copy_j[i / nn])).collect();
        // Strength of every filament per unit ring circulation, by probing the linear map.
        let nf = bs.fil.n_segments() + bs.fil.n_legs();
        let mut incidence = vec![Vec::new(); nf];
        let mut e = vec![0.0; n_rings];
        for r in 0..n_rings {
            e[r] = 1.0;
            bs.set_strengths(&e);
            e[r] = 0.0;
            let fil = &bs.fil;
            for (f, inc) in incidence.iter_mut().enumerate() {
                let g = if f < fil.n_segments() { fil.seg_g[f] } else { fil.leg_g[f - fil.n_segments()] };
                if g != 0.0 {
                    inc.push((r, g));
                }
            }
        }
        let kappa = (0..bs.fil.n_segments())
            .map(|s| {
                let (a, b) = (bs.fil.node(bs.fil.seg_a[s] as usize), bs.fil.node(bs.fil.seg_b[s] as usize));
                let l2 = dot(sub(b, a), sub(b, a));
                if l2 > 0.0 { bs.fil.seg_core2[s] / l2 } else { 0.0 }
            })
            .collect();
        Ok(Self { bs, node_map, incidence, kappa, n_rings })
    }

    /// End nodes (filament node indices) of filament `f`: `(A, Some(B))` for segments.
    fn ends(&self, f: usize) -> (usize, Option<usize>) {
        let fil = &self.bs.fil;
        let ns = fil.n_segments();
        if f < ns { (fil.seg_a[f] as usize, Some(fil.seg_b[f] as usize)) } else { (fil.leg_a[f - ns] as usize, None) }
    }

    /// Add `w · ∂(·)/∂node` (a row `w` of 3 against the node's 3 coordinates, times `scale`) to
    /// row `row` of `out`, mapped to the node's vertex.
    fn add_row(&self, out: &mut DMatrix<f64>, row: usize, node: usize, w: [f64; 3]) {
        let (v, j) = &self.node_map[node];
        for c in 0..3 {
            let x = w[0] * j[0][c] + w[1] * j[1][c] + w[2] * j[2][c];
            out[(row, 3 * v + c)] += x;
        }
    }

    /// Add `M · ∂(·)/∂node` (3 rows from `row0`) to `out`, mapped to the node's vertex.
    fn add_block(&self, out: &mut DMatrix<f64>, row0: usize, node: usize, m: &M3) {
        for (i, w) in m.iter().enumerate() {
            self.add_row(out, row0 + i, node, *w);
        }
    }
}

impl Uvlm {
    /// The steady solution on the current lattices and the derivatives of its circulations,
    /// nodal and strip forces with respect to the ring nodes (module doc; docs/uvlm.md §17).
    /// Builds and factorises its own influence matrix; the solver's state is not touched.
    ///
    /// # Errors
    /// A lattice that moves, a non-uniform external flow, a Scully core sized by the panels
    /// (`bound_core`), a zero free stream, or a singular influence matrix.
    pub fn steady_load_derivative(&self) -> Result<SteadyLoadDerivative> {
        let moving = self.surfaces.iter().any(|s| s.lattice.grid_velocities().iter().flatten().any(|v| *v != 0.0));
        if moving {
            return Err(UvlmError::InvalidParameter { field: "lattice velocity", value: 1.0 });
        }
        if !self.flow().is_uniform() {
            return Err(UvlmError::InvalidParameter { field: "disturbance (for the load derivative)", value: 1.0 });
        }
        let mut b = Bound::new(self)?;
        let v_inf = self.flow().free_stream();
        let n_nodes: Vec<usize> = self.surfaces.iter().map(|s| s.lattice.n_nodes()).collect();
        let nv: usize = n_nodes.iter().sum();
        let nr = b.n_rings;
        let mut lu = DenseLu::new(nr);
        lu.factorize_row_major(&influence_matrix(&b, self)).map_err(|pivot| UvlmError::SingularAic { pivot })?;
        let mut gamma: Vec<f64> =
            self.surfaces.iter().flat_map(|s| s.lattice.normals().iter().map(|n| -dot(v_inf, *n))).collect();
        lu.solve_in_place(&mut gamma);
        if !gamma.iter().all(|g| g.is_finite()) {
            return Err(UvlmError::NonFiniteSolution { step: 0 });
        }
        b.bs.set_strengths(&gamma);
        let g_x = collocation_derivative(self, &b, v_inf, nv);
        let mut d_gamma = DMatrix::zeros(nr, 3 * nv);
        let mut col = vec![0.0; nr];
        for c in 0..3 * nv {
            for r in 0..nr {
                col[r] = -g_x[(r, c)];
            }
            lu.solve_in_place(&mut col);
            d_gamma.column_mut(c).copy_from_slice(&col);
        }
        let n_strips: usize = self.surfaces.iter().map(|s| s.lattice.n_spanwise()).sum();
        let mut out = SteadyLoadDerivative {
            n_chordwise: self.surfaces.iter().map(|s| s.lattice.n_chordwise()).collect(),
            n_nodes,
            gamma,
            nodal: vec![[0.0; 3]; nv],
            strip: vec![[0.0; 3]; n_strips],
            d_gamma,
            d_nodal: DMatrix::zeros(0, 0),
            d_strip: DMatrix::zeros(0, 0),
        };
        segment_loads(self, &b, v_inf, &mut out);
        Ok(out)
    }
}

/// The influence matrix `A` (row-major) of the bound system `b` at the solver's collocation
/// points and normals.
fn influence_matrix(b: &Bound, uv: &Uvlm) -> Vec<f64> {
    let nr = b.n_rings;
    let fil = &b.bs.fil;
    let nf = fil.n_segments() + fil.n_legs();
    let mut a = vec![0.0; nr * nr];
    let mut pi = PointInduction::new(nf);
    let mut p = 0;
    for s in uv.surfaces() {
        let lat = s.lattice();
        for (c, n) in lat.collocation().iter().zip(lat.normals()) {
            pi.evaluate(fil, &b.kappa, *c);
            for f in 0..nf {
                let un = dot(pi.u[f], *n);
                for &(r, g) in &b.incidence[f] {
                    a[p * nr + r] += g * un;
                }
            }
            p += 1;
        }
    }
    a
}

/// The strength of filament `f` of `fil` (with 1/4π).
fn strength(fil: &Filaments, f: usize) -> f64 {
    if f < fil.n_segments() { fil.seg_g[f] } else { fil.leg_g[f - fil.n_segments()] }
}

/// `∂R/∂X` at fixed Γ (`n_rings × 3 n_vertices`) of the collocation rows `R_p = (V∞ + U(c_p))·n_p`,
/// the strengths of `b` set to the solution.
fn collocation_derivative(uv: &Uvlm, b: &Bound, v_inf: [f64; 3], nv: usize) -> DMatrix<f64> {
    let fil = &b.bs.fil;
    let nf = fil.n_segments() + fil.n_legs();
    let mut g_x = DMatrix::zeros(b.n_rings, 3 * nv);
    let mut pi = PointInduction::new(nf);
    let (mut p, mut v0) = (0, 0);
    for s in uv.surfaces() {
        let lat = s.lattice();
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let ring_nodes = lat.ring_nodes();
        for i in 0..m {
            for j in 0..n {
                let nrm = lat.normals()[i * n + j];
                pi.evaluate(fil, &b.kappa, lat.collocation()[i * n + j]);
                let mut u = [0.0; 3];
                let mut dp = [0.0; 3];
                for f in 0..nf {
                    let g = strength(fil, f);
                    if g == 0.0 {
                        continue;
                    }
                    let (na, nb) = b.ends(f);
                    // n·∂U/∂A = g nᵀ ∂ũ/∂A; the point's own derivative is minus the ends' sum.
                    let wa = mul_t(&pi.ja[f], nrm, g);
                    let wb = mul_t(&pi.jb[f], nrm, g);
                    b.add_row(&mut g_x, p, na, wa);
                    if let Some(nb) = nb {
                        b.add_row(&mut g_x, p, nb, wb);
                    }
                    for q in 0..3 {
                        u[q] += g * pi.u[f][q];
                        dp[q] -= wa[q] + wb[q];
                    }
                }
                let ids = [
                    lat.node_index(i, j),
                    lat.node_index(i, j + 1),
                    lat.node_index(i + 1, j + 1),
                    lat.node_index(i + 1, j),
                ];
                // (V∞ + U)·dn with n = e × f / |e × f|, e = C − A, f = B − D.
                let [pa, pb, pc, pd] = ids.map(|k| ring_nodes[k]);
                let (e, fv) = (sub(pc, pa), sub(pb, pd));
                let cvec = cross(e, fv);
                let cn = dot(cvec, cvec).sqrt();
                let w = [v_inf[0] + u[0], v_inf[1] + u[1], v_inf[2] + u[2]];
                let wn = dot(w, nrm);
                let t = [(w[0] - wn * nrm[0]) / cn, (w[1] - wn * nrm[1]) / cn, (w[2] - wn * nrm[2]) / cn];
                let (ft, te) = (cross(fv, t), cross(t, e));
                let terms = [(ids[2], 1.0, ft), (ids[0], -1.0, ft), (ids[1], 1.0, te), (ids[3], -1.0, te)];
                for (k, sgn, vec) in terms {
                    for q in 0..3 {
                        // The collocation point is the corners' mean.
                        g_x[(p, 3 * (v0 + k) + q)] += sgn * vec[q] + 0.25 * dp[q];
                    }
                }
                p += 1;
            }
        }
        v0 += lat.n_nodes();
    }
    g_x
}

/// `g · mᵀ v` (the row `vᵀ m` scaled).
fn mul_t(m: &M3, v: [f64; 3], g: f64) -> [f64; 3] {
    let mut o = [0.0; 3];
    for i in 0..3 {
        for l in 0..3 {
            o[l] += g * v[i] * m[i][l];
        }
    }
    o
}

/// The Joukowski loads of every lattice segment and their derivatives into `out` (its
/// `d_gamma` given).
fn segment_loads(uv: &Uvlm, b: &Bound, v_inf: [f64; 3], out: &mut SteadyLoadDerivative) {
    let rho = uv.params().rho;
    let fil = &b.bs.fil;
    let nf = fil.n_segments() + fil.n_legs();
    let (nr, nv) = (b.n_rings, out.n_vertices());
    let n_strips = out.strip.len();
    // ∂(nodal, strip)/∂Γ at fixed geometry, and the geometric parts, row-major while the rows
    // are accumulated.
    let mut p_nodal = RowMajor::zeros(3 * nv, nr);
    let mut p_strip = RowMajor::zeros(3 * n_strips, nr);
    let mut x_nodal = RowMajor::zeros(3 * nv, 3 * nv);
    let mut x_strip = RowMajor::zeros(3 * n_strips, 3 * nv);
    let mut fx = DMatrix::zeros(3, 3 * nv);
    let mut fg = DMatrix::zeros(3, nr);
    let mut pi = PointInduction::new(nf);
    let (mut v0, mut j0) = (0, 0);
    for (k, surf) in uv.surfaces().iter().enumerate() {
        let lat = surf.lattice();
        let (m, n) = (lat.n_chordwise(), lat.n_spanwise());
        let nc = n + 1;
        let range = b.bs.surface(k);
        for s in 0..range.n_lattice_seg - range.n_te_seg {
            let f_s = range.seg0 + s;
            let (na, nb) = (fil.seg_a[f_s] as usize, fil.seg_b[f_s] as usize);
            let (pa, pb) = (fil.node(na), fil.node(nb));
            let (va, vb) = (v0 + na - range.node0, v0 + nb - range.node0);
            let mid = [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])];
            let dl = sub(pb, pa);
            pi.evaluate(fil, &b.kappa, mid);
            let g_s = b.bs.lattice_segment_gamma(f_s);
            fx.fill(0.0);
            fg.fill(0.0);
            let mut w = v_inf;
            let mut dmid = [[0.0; 3]; 3];
            for f in 0..nf {
                let g = strength(fil, f);
                for q in 0..3 {
                    w[q] += g * pi.u[f][q];
                }
                // Through the filaments' strengths: ρ g_s (ũ_f × dl) per unit strength.
                let udl = cross(pi.u[f], dl);
                for &(r, gr) in &b.incidence[f] {
                    for q in 0..3 {
                        fg[(q, r)] += rho * g_s * gr * udl[q];
                    }
                }
                if g == 0.0 {
                    continue;
                }
                // −ρ g_s [dl]× g ∂ũ/∂(ends), and the midpoint's own share.
                let (ea, eb) = b.ends(f);
                let sk = skew(dl);
                let ma = scaled(&mat_mul(&sk, &pi.ja[f]), -rho * g_s * g);
                let mb = scaled(&mat_mul(&sk, &pi.jb[f]), -rho * g_s * g);
                b.add_block(&mut fx, 0, ea, &ma);
                if let Some(eb) = eb {
                    b.add_block(&mut fx, 0, eb, &mb);
                }
                for i in 0..3 {
                    for l in 0..3 {
                        dmid[i][l] -= ma[i][l] + mb[i][l];
                    }
                }
            }
            // Through the segment's own net strength: ρ (W × dl) per unit net circulation.
            let wdl = cross(w, dl);
            for &(r, gr) in &b.incidence[f_s] {
                for q in 0..3 {
                    fg[(q, r)] += rho * gr * (4.0 * std::f64::consts::PI) * wdl[q];
                }
            }
            // ρ g_s W × (dB − dA) and the midpoint (½ dA + ½ dB).
            let wx = scaled(&skew(w), rho * g_s);
            for (v, sgn) in [(vb, 1.0), (va, -1.0)] {
                for i in 0..3 {
                    for l in 0..3 {
                        fx[(i, 3 * v + l)] += sgn * wx[i][l] + 0.5 * dmid[i][l];
                    }
                }
            }
            let force = [rho * g_s * wdl[0], rho * g_s * wdl[1], rho * g_s * wdl[2]];
            // Half to each end node; the strip(s) as `compute_loads` shares them.
            let mut shares = vec![];
            if s < m * n {
                shares.push((j0 + s % n, 1.0));
            } else {
                let j = (s - m * n) % nc;
                let share = if j == 0 || j == n { 1.0 } else { 0.5 };
                for jj in [j.wrapping_sub(1), j] {
                    if jj < n {
                        shares.push((j0 + jj, share));
                    }
                }
            }
            for q in 0..3 {
                out.nodal[va][q] += 0.5 * force[q];
                out.nodal[vb][q] += 0.5 * force[q];
                for &(j, sh) in &shares {
                    out.strip[j][q] += sh * force[q];
                }
                for (row, wgt) in [(3 * va + q, 0.5), (3 * vb + q, 0.5)] {
                    x_nodal.add_scaled_row(row, &fx, q, wgt);
                    p_nodal.add_scaled_row(row, &fg, q, wgt);
                }
                for &(j, sh) in &shares {
                    x_strip.add_scaled_row(3 * j + q, &fx, q, sh);
                    p_strip.add_scaled_row(3 * j + q, &fg, q, sh);
                }
            }
        }
        v0 += lat.n_nodes();
        j0 += n;
    }
    out.d_nodal = x_nodal.into_matrix() + p_nodal.into_matrix() * &out.d_gamma;
    out.d_strip = x_strip.into_matrix() + p_strip.into_matrix() * &out.d_gamma;
}

/// A dense matrix stored row by row (rows are what the segment loop accumulates).
struct RowMajor {
    n_cols: usize,
    data: Vec<f64>,
}

impl RowMajor {
    fn zeros(n_rows: usize, n_cols: usize) -> Self {
        Self { n_cols, data: vec![0.0; n_rows * n_cols] }
    }

    /// `self[row, :] += w · src[q, :]`.
    fn add_scaled_row(&mut self, row: usize, src: &DMatrix<f64>, q: usize, w: f64) {
        let dst = &mut self.data[row * self.n_cols..(row + 1) * self.n_cols];
        for (c, d) in dst.iter_mut().enumerate() {
            *d += w * src[(q, c)];
        }
    }

    fn into_matrix(self) -> DMatrix<f64> {
        let n_rows = self.data.len() / self.n_cols.max(1);
        DMatrix::from_row_slice(n_rows, self.n_cols, &self.data)
    }
}

fn scaled(m: &M3, s: f64) -> M3 {
    let mut o = *m;
    o.iter_mut().flatten().for_each(|x| *x *= s);
    o
}
