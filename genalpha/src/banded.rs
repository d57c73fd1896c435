//! LU of a bordered block-banded matrix by Schur complement.
//!
//! A system may declare ([`ConstrainedSystem::matrix_structure`](crate::ConstrainedSystem)) that
//! its iteration matrix has diagonal *blocks* of unknowns which couple, inside the block, only
//! within a band of half-width `w`, and otherwise only to the *border*: every unknown in no block
//! (e.g. the floating-frame velocities of a beam) plus every constraint row and multiplier the
//! integrator appends. Ordering the border last,
//!
//! $$ A = \begin{bmatrix} D & E \\ F & G \end{bmatrix},\qquad
//!    S = G - F D^{-1} E ,$$
//!
//! `D` is factorised block by block in band storage *without pivoting* (the blocks of a
//! structural iteration matrix, `M + γ′/β′ C + K/β′`, are close to symmetric positive definite),
//! and the small dense Schur complement `S` with partial pivoting. If a band pivot is tiny
//! relative to its block's diagonal, the factorisation reports it and the caller falls back to
//! the dense LU. Cost for a beam with n nodal unknowns per block, band w and border b:
//! O(n w² + n w b + n b²) instead of O((n + b)³).
//!
//! Layout choices (they decide the speed at these small sizes, where every loop is short):
//! the band is stored by columns, so that the columns of `L` below and of `U` above the diagonal
//! are contiguous and both triangular solves are column sweeps (`y[k+1..] -= l_k y_k`,
//! independent updates that vectorise) instead of row dot products (one serial chain of
//! additions per row). The Schur complement is formed as `S = G − Z Y` with `Y = L⁻¹E` (by
//! columns, each starting its forward sweep at its first non-zero) and `Z = F U⁻¹` (by rows,
//! each starting at its first non-zero): joint columns and rows touch only a body's last node,
//! so they need no full backward sweep and their products with `Z`, `Y` are a few terms long.
//! The solve follows: `c = L⁻¹ b_I`, `S x_B = b_B − Z c`, `x_I = U⁻¹ (c − Y x_B)`.
//!
//! A structure that declares nodes ([`BandedBorder::node_bandwidth`]: six unknowns per node,
//! nodes further apart never coupled) has its blocks assembled and factorised on 6×6 node blocks
//! instead ([`NodeBand`]): the same elimination in fixed-size kernels, 11–17 % fewer instructions
//! for a GEBF pendulum run than the scalar band.
//! Dot products that remain use four partial sums.

use crate::DenseMatrix;
use crate::node_lu::NodeBand;
use crate::vecops::{dot, first_nonzero, last_nonzero, sub_scaled};

/// The declared structure: diagonal blocks `(first, len, half_bandwidth)` of the unknowns
/// (tangent indices); every index in no block belongs to the border, and so do all constraint
/// rows/multipliers appended by the integrator.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct BandedBorder {
    /// `(first index, number of unknowns, half-bandwidth)` of each block; blocks must not overlap.
    pub blocks: Vec<(usize, usize, usize)>,
    /// The blocks are node-banded: their unknowns come in nodes of six (a beam's position and
    /// rotation) and nodes further apart than this never couple (two for three-node elements).
    /// The LU then works on 6×6 node blocks (the `node_lu` module). A non-zero outside that
    /// pattern (but inside the band) sends its block to the scalar band LU for good: at once when
    /// the matrix is given densely, after one dense matrix when it is assembled in place.
    /// `None`: a scalar band.
    pub node_bandwidth: Option<usize>,
}

impl BandedBorder {
    /// Whether the blocks are disjoint and inside `0..n`.
    pub fn is_valid(&self, n: usize) -> bool {
        let mut b = self.blocks.clone();
        b.sort_unstable();
        let mut end = 0;
        for &(first, len, _) in &b {
            if first < end || first + len > n || len == 0 {
                return false;
            }
            end = first + len;
        }
        true
    }
}

/// One band block, factorised in place.
#[derive(Debug, Clone)]
struct Block {
    first: usize,
    m: usize,
    w: usize,
    /// Band storage by columns: entry (i, j) with |i − j| ≤ w at `j (2w + 1) + (i − j + w)`
    /// (slots outside the matrix stay zero and are never read).
    band: Vec<f64>,
    /// Reciprocals of the pivots (the diagonal of `U`): the back substitution multiplies, so
    /// that no division sits on its critical path.
    inv_diag: Vec<f64>,
    /// Envelope ([`Block::envelope`]): reach of column k of `L` below the diagonal, of row k
    /// of `U` right of it, and the first row of column k of `U`.
    len_l: Vec<usize>,
    len_u: Vec<usize>,
    u_top: Vec<usize>,
    /// Border columns (indices into the border) with a non-zero entry of `E` in this block.
    cols: Vec<usize>,
    /// First non-zero row of each active column of `E`.
    col_start: Vec<usize>,
    /// Border rows with a non-zero entry of `F` in this block.
    rows: Vec<usize>,
    /// Range `lo..hi` of the non-zero columns of each active row of `F`.
    row_range: Vec<(usize, usize)>,
    /// `E`, all border columns, by columns: m × n_b (as assembled).
    e: Vec<f64>,
    /// `E` then `Y = L⁻¹ E` on the active columns, by columns: m × cols.len().
    x: Vec<f64>,
    /// `Z = F U⁻¹` on the active rows, by rows: rows.len() × m.
    z: Vec<f64>,
    /// `F`, row-major n_b × m (all border rows; only the active ones are used).
    f: Vec<f64>,
    /// Node-block factors when the structure declares nodes ([`BandedBorder::node_bandwidth`]).
    nodal: Option<NodeBand>,
    /// The last factorisation went through `nodal`.
    use_nodal: bool,
    /// The matrix was assembled straight into `nodal`'s blocks (`band` is not filled).
    nodal_direct: bool,
}

impl Block {
    /// The envelope of the band: how far the columns of `L` reach below the diagonal and the
    /// rows of `U` to its right, fill-in included (LU without pivoting fills only inside the
    /// envelope: column k of `L` reaches the lowest non-zero of the columns ≤ k, row k of `U`
    /// the rightmost column whose highest non-zero is ≤ k), and the first row of each column
    /// of `U`. A three-node element couples its middle node over 11 unknowns, not the declared
    /// 17, so this roughly halves the band work of a beam.
    fn envelope(&mut self) {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        self.len_u.iter_mut().for_each(|x| *x = 0);
        let mut reach_l = 0;
        for j in 0..m {
            let col = &self.band[j * ld..(j + 1) * ld];
            let lo = w - j.min(w); // offsets of rows ≥ 0
            let hi = w + w.min(m - 1 - j); // offsets of rows < m
            let top = col[lo..w].iter().position(|x| *x != 0.0).map_or(j, |o| j + lo + o - w);
            let bottom = col[w + 1..=hi].iter().rposition(|x| *x != 0.0).map_or(j, |o| j + 1 + o);
            reach_l = reach_l.max(bottom);
            self.len_l[j] = reach_l - j;
            // len_u[i] holds, for now, the rightmost column whose highest non-zero is row i.
            self.len_u[top] = self.len_u[top].max(j);
        }
        let mut reach_u = 0;
        for k in 0..m {
            reach_u = reach_u.max(self.len_u[k]).max(k);
            self.len_u[k] = reach_u - k;
        }
        let mut top = 0;
        for k in 0..m {
            while top + self.len_u[top] < k {
                top += 1;
            }
            self.u_top[k] = top;
        }
    }

    /// In-place LU without pivoting (right-looking, by columns, inside the envelope); false if
    /// a pivot is tiny.
    #[inline(always)]
    fn factorize(&mut self) -> bool {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        if let Some(nb) = &mut self.nodal {
            let assembled = if self.nodal_direct {
                nb.find_nonzero_blocks();
                true
            } else {
                nb.gather(&self.band, w)
            };
            if assembled {
                self.use_nodal = true;
                let tiny = 1e-13 * nb.max_abs_diag();
                return nb.factorize(tiny);
            }
            // A non-zero outside the node band: the scalar band LU from now on.
            self.nodal = None;
        }
        self.use_nodal = false;
        let scale = (0..m).map(|j| self.band[j * ld + w].abs()).fold(0.0_f64, f64::max);
        let tiny = 1e-13 * scale;
        self.envelope();
        for k in 0..m {
            let (len, len_u) = (self.len_l[k], self.len_u[k]); // rows k+1..=k+len, columns k+1..=k+len_u
            let (head, tail) = self.band.split_at_mut((k + 1) * ld);
            let col_k = &mut head[k * ld..];
            let p = col_k[w];
            if p.abs() <= tiny || !p.is_finite() {
                return false;
            }
            let inv_p = 1.0 / p;
            self.inv_diag[k] = inv_p;
            let l = &mut col_k[w + 1..w + 1 + len];
            l.iter_mut().for_each(|x| *x *= inv_p);
            let l = &*l;
            // Column j = k + jj: row k at offset w − jj, rows k+1..=k+len right below it.
            for (jj, col_j) in tail.chunks_exact_mut(ld).take(len_u).enumerate() {
                let o = w - jj - 1;
                let u = col_j[o];
                if u != 0.0 {
                    sub_scaled(&mut col_j[o + 1..o + 1 + len], u, l);
                }
            }
        }
        true
    }

    /// Overwrite the vector `y` (length m) with `L⁻¹ y`, by column sweeps.
    #[inline(always)]
    fn forward_vec(&self, y: &mut [f64]) {
        if let (true, Some(nb)) = (self.use_nodal, &self.nodal) {
            return nb.forward(y, 0);
        }
        let ld = 2 * self.w + 1;
        for k in 0..self.m {
            let yk = y[k];
            if yk != 0.0 {
                let len = self.len_l[k];
                let o = k * ld + self.w + 1;
                sub_scaled(&mut y[k + 1..k + 1 + len], yk, &self.band[o..o + len]);
            }
        }
    }

    /// Overwrite the vector `y` (length m) with `U⁻¹ y`, by column sweeps.
    #[inline(always)]
    fn backward_vec(&self, y: &mut [f64]) {
        if let (true, Some(nb)) = (self.use_nodal, &self.nodal) {
            return nb.backward(y);
        }
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        for k in (0..m).rev() {
            let yk = y[k] * self.inv_diag[k];
            y[k] = yk;
            let lo = self.u_top[k];
            sub_scaled(&mut y[lo..k], yk, &self.band[k * ld + lo + w - k..k * ld + w]);
        }
    }

    /// `Y = L⁻¹ E` on the active columns of `E`, stored by columns in `x` (m × cols.len(); each
    /// column is zero before its first non-zero, so its sweep starts there). The sweep runs over
    /// the rows outside and the columns inside, so that the columns' independent update chains
    /// overlap.
    #[inline(always)]
    fn forward_cols(&mut self) {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        let nc = self.cols.len();
        let x = &mut self.x[..m * nc];
        let starts = &self.col_start;
        if let (true, Some(nb)) = (self.use_nodal, &self.nodal) {
            for (xc, &s) in x.chunks_exact_mut(m).zip(starts) {
                nb.forward(xc, s);
            }
            return;
        }
        let k0 = starts.iter().copied().min().unwrap_or(m);
        for k in k0..m {
            let len = self.len_l[k];
            let l = &self.band[k * ld + w + 1..k * ld + w + 1 + len];
            for (xc, &s) in x.chunks_exact_mut(m).zip(starts) {
                let xk = xc[k];
                if k >= s && xk != 0.0 {
                    sub_scaled(&mut xc[k + 1..k + 1 + len], xk, l);
                }
            }
        }
    }

    /// `Z = F U⁻¹` on the active rows of `F`, stored by rows in `z` (rows.len() × m; row r is
    /// zero before `row_range[r].0`). Left-looking, so that each step reads a contiguous column
    /// of `U`: `z_j = (f_j − Σ_{i<j} z_i U_ij) / U_jj`; the rows run inside, so that their
    /// independent chains overlap.
    #[inline(always)]
    fn right_solve_rows(&mut self) {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        let z = &mut self.z[..m * self.rows.len()];
        for ((zr, &r), &(lo, _)) in z.chunks_exact_mut(m).zip(&self.rows).zip(&self.row_range) {
            zr[..lo].fill(0.0);
            zr[lo..].copy_from_slice(&self.f[r * m + lo..(r + 1) * m]);
        }
        if let (true, Some(nb)) = (self.use_nodal, &self.nodal) {
            if self.rows.len() > 64 {
                for (zr, &(lo, _)) in z.chunks_exact_mut(m).zip(&self.row_range) {
                    nb.right_solve(zr, lo);
                }
            } else {
                right_solve_grouped(nb, z, m, &self.row_range);
            }
            return;
        }
        let j0 = self.row_range.iter().map(|r| r.0).min().unwrap_or(m);
        for j in j0..m {
            let top = self.u_top[j];
            let ucol = &self.band[j * ld + top + w - j..j * ld + w];
            let inv = self.inv_diag[j];
            for (zr, &(lo, _)) in z.chunks_exact_mut(m).zip(&self.row_range) {
                if j >= lo {
                    let a = top.max(lo);
                    let (done, rest) = zr.split_at_mut(j);
                    rest[0] = (rest[0] - dot(&done[a..], &ucol[a - top..])) * inv;
                }
            }
        }
    }
}

/// `Z = F U⁻¹` on node blocks for up to 64 rows (`z`: rows of `m` unknowns, row `r` zero
/// before `ranges[r].0`): rows that start in the same node go through
/// [`NodeBand::right_solve_lanes`] four (or fewer) at a time, each with the arithmetic of its own
/// [`NodeBand::right_solve`]. The rows of a beam block start in two or three nodes (the frame
/// velocities' at the first, a joint's at the last), so most go four at a time.
#[inline(always)]
fn right_solve_grouped(nb: &NodeBand, z: &mut [f64], m: usize, ranges: &[(usize, usize)]) {
    let nr = ranges.len();
    let mut pending: u64 = if nr == 64 { !0 } else { (1 << nr) - 1 };
    while pending != 0 {
        let n0 = ranges[pending.trailing_zeros() as usize].0 / crate::node_lu::P;
        let (mut lanes, mut count) = ([0; 4], 0);
        let mut bits = pending;
        while bits != 0 && count < 4 {
            let r = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if ranges[r].0 / crate::node_lu::P == n0 {
                lanes[count] = r;
                count += 1;
                pending &= !(1 << r);
            }
        }
        match count {
            4 => nb.right_solve_lanes::<4>(z, m, lanes, n0),
            3 => nb.right_solve_lanes::<3>(z, m, [lanes[0], lanes[1], lanes[2]], n0),
            2 => nb.right_solve_lanes::<2>(z, m, [lanes[0], lanes[1]], n0),
            _ => nb.right_solve_lanes::<1>(z, m, [lanes[0]], n0),
        }
    }
}

/// The bordered band LU.
#[derive(Debug, Clone, Default)]
pub(crate) struct BorderedBandLu {
    n: usize,
    blocks: Vec<Block>,
    /// Border indices, increasing.
    border: Vec<usize>,
    /// Schur complement LU, row-major n_b × n_b, and its row permutation.
    s: Vec<f64>,
    perm: Vec<usize>,
    /// Largest magnitude of each column of the Schur complement before its elimination (the
    /// scale its pivot is tested against).
    col_scale: Vec<f64>,
    /// Scratch of length n_b.
    tmp: Vec<f64>,
    /// Border solution, length n_b.
    xb: Vec<f64>,
    /// Block of each unknown (`usize::MAX` for the border).
    owner: Vec<usize>,
    /// Position of each unknown in the border (`usize::MAX` inside a block).
    border_pos: Vec<usize>,
    /// Direct assembly met a non-zero entry outside the structure.
    outside: bool,
    /// Direct assembly met a non-zero inside the band but outside the node band: the matrix must
    /// be given densely once, which sends that block to the scalar band.
    node_overflow: bool,
    /// Every block's active `E` columns and `F` rows are those of the stored values (the last
    /// factorisation went through all blocks).
    active_known: bool,
}

impl BorderedBandLu {
    /// Set up for an `n × n` matrix whose first unknowns follow `structure`.
    pub fn new(n: usize, structure: &BandedBorder) -> Self {
        let mut in_block = vec![false; n];
        for &(first, len, _) in &structure.blocks {
            in_block[first..first + len].iter_mut().for_each(|b| *b = true);
        }
        let border: Vec<usize> = (0..n).filter(|&i| !in_block[i]).collect();
        let mut owner = vec![usize::MAX; n];
        for (bi, &(first, len, _)) in structure.blocks.iter().enumerate() {
            owner[first..first + len].iter_mut().for_each(|o| *o = bi);
        }
        let nb = border.len();
        let mut border_pos = vec![usize::MAX; n];
        for (c, &b) in border.iter().enumerate() {
            border_pos[b] = c;
        }
        let blocks = structure
            .blocks
            .iter()
            .map(|&(first, m, w)| Block {
                first,
                m,
                w,
                band: vec![0.0; m * (2 * w + 1)],
                inv_diag: vec![0.0; m],
                len_l: vec![0; m],
                len_u: vec![0; m],
                u_top: vec![0; m],
                cols: Vec::with_capacity(nb),
                col_start: Vec::with_capacity(nb),
                rows: Vec::with_capacity(nb),
                row_range: Vec::with_capacity(nb),
                e: vec![0.0; m * nb],
                x: vec![0.0; m * nb],
                z: vec![0.0; nb * m],
                f: vec![0.0; nb * m],
                nodal: structure.node_bandwidth.and_then(|kb| NodeBand::new(m, kb)),
                use_nodal: false,
                nodal_direct: false,
            })
            .collect();
        Self {
            n,
            blocks,
            border,
            s: vec![0.0; nb * nb],
            perm: vec![0; nb],
            col_scale: vec![0.0; nb],
            tmp: vec![0.0; nb],
            xb: vec![0.0; nb],
            owner,
            border_pos,
            outside: false,
            node_overflow: false,
            active_known: false,
        }
    }

    /// Whether `a` has no non-zero entry outside the declared structure.
    pub fn fits(&self, a: &DenseMatrix) -> bool {
        let owner = &self.owner;
        for j in 0..self.n {
            for i in 0..self.n {
                let (oi, oj) = (owner[i], owner[j]);
                if oi == usize::MAX || oj == usize::MAX {
                    continue; // border row or column
                }
                let inside = oi == oj && i.abs_diff(j) <= self.blocks[oi].w;
                if !inside && a.get(i, j) != 0.0 {
                    return false;
                }
            }
        }
        true
    }

    /// Factorise; `Err(row)` on a tiny band pivot or a singular Schur complement.
    pub fn factorize(&mut self, a: &DenseMatrix) -> Result<(), usize> {
        let n = self.n;
        assert!(a.n_rows() == n && a.n_cols() == n, "factorize: dimension mismatch");
        let data = a.as_slice();
        let nb = self.border.len();
        // Schur complement starts as G.
        for (c, &bj) in self.border.iter().enumerate() {
            let col = &data[bj * n..(bj + 1) * n];
            for (r, &bi) in self.border.iter().enumerate() {
                self.s[r * nb + c] = col[bi];
            }
        }
        for blk in &mut self.blocks {
            let (first, m, w) = (blk.first, blk.m, blk.w);
            let ld = 2 * w + 1;
            blk.nodal_direct = false;
            // The band, column by column (contiguous in both storages).
            for j in 0..m {
                let (lo, hi) = (j.saturating_sub(w), (j + w + 1).min(m));
                let src = &data[(first + j) * n + first + lo..(first + j) * n + first + hi];
                blk.band[j * ld + lo + w - j..j * ld + hi + w - j].copy_from_slice(src);
            }
            // All border rows of F, column by column of the block (contiguous in the
            // column-major storage), and all border columns of E.
            for j in 0..m {
                let col = &data[(first + j) * n..(first + j + 1) * n];
                for (c, &bi) in self.border.iter().enumerate() {
                    blk.f[c * m + j] = col[bi];
                }
            }
            for (c, &bj) in self.border.iter().enumerate() {
                blk.e[c * m..(c + 1) * m].copy_from_slice(&data[bj * n + first..bj * n + first + m]);
            }
        }
        self.factorize_gathered()
    }

    /// Zero the storage before a direct assembly ([`AssemblyTarget`]). After a complete
    /// factorisation only the columns of `E` and rows of `F` it found non-zero need zeroing.
    pub fn clear(&mut self) {
        self.outside = false;
        self.node_overflow = false;
        self.s.fill(0.0);
        let tracked = std::mem::replace(&mut self.active_known, false);
        for blk in &mut self.blocks {
            if let Some(nb) = &mut blk.nodal {
                nb.clear();
                blk.nodal_direct = true;
            } else {
                blk.band.fill(0.0);
            }
            let m = blk.m;
            if tracked {
                blk.cols.iter().for_each(|&c| blk.e[c * m..(c + 1) * m].fill(0.0));
                blk.rows.iter().for_each(|&r| blk.f[r * m..(r + 1) * m].fill(0.0));
            } else {
                blk.e.fill(0.0);
                blk.f.fill(0.0);
            }
        }
    }

    /// A(i, j) += v in the block storage (a non-zero outside the structure is recorded, see
    /// [`assembled_outside`](Self::assembled_outside)).
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        let (oi, oj) = (self.owner[i], self.owner[j]);
        let nb = self.border.len();
        match (oi != usize::MAX, oj != usize::MAX) {
            (true, true) => {
                let blk = &mut self.blocks[oi];
                if oi != oj || i.abs_diff(j) > blk.w {
                    self.outside |= v != 0.0;
                    return;
                }
                let (il, jl) = (i - blk.first, j - blk.first);
                if let (true, Some(nb)) = (blk.nodal_direct, &mut blk.nodal) {
                    self.node_overflow |= !nb.add_column(il, jl, &[v], 1.0);
                    return;
                }
                blk.band[jl * (2 * blk.w + 1) + il + blk.w - jl] += v;
            }
            (true, false) => {
                let blk = &mut self.blocks[oi];
                blk.e[self.border_pos[j] * blk.m + i - blk.first] += v;
            }
            (false, true) => {
                let blk = &mut self.blocks[oj];
                blk.f[self.border_pos[i] * blk.m + j - blk.first] += v;
            }
            (false, false) => self.s[self.border_pos[i] * nb + self.border_pos[j]] += v,
        }
    }

    /// `A[i0.., j0..] += s · block` (column-major `n_r × n_c`); contiguous band and `E` column
    /// segments are added as slices.
    pub fn add_slice(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, block: &[f64], s: f64) {
        if n_r == 0 {
            return;
        }
        let (oi, oi_last) = (self.owner[i0], self.owner[i0 + n_r - 1]);
        let rows_in_one_block = oi != usize::MAX && oi == oi_last;
        for c in 0..n_c {
            let j = j0 + c;
            let src = &block[c * n_r..(c + 1) * n_r];
            let oj = self.owner[j];
            if rows_in_one_block && (oj == oi || oj == usize::MAX) {
                let blk = &mut self.blocks[oi];
                let il0 = i0 - blk.first;
                let dst = if oj == oi {
                    let (jl, w) = (j - blk.first, blk.w);
                    if let (true, Some(nb)) = (blk.nodal_direct, &mut blk.nodal) {
                        self.node_overflow |= !nb.add_column(il0, jl, src, s);
                        continue;
                    }
                    if i0 + w < j || j + w < i0 + n_r - 1 {
                        // part of the column is outside the band: entry by entry
                        for (r, x) in src.iter().enumerate() {
                            self.add(i0 + r, j, s * x);
                        }
                        continue;
                    }
                    let o = jl * (2 * w + 1) + il0 + w - jl;
                    &mut blk.band[o..o + n_r]
                } else {
                    let o = self.border_pos[j] * blk.m + il0;
                    &mut blk.e[o..o + n_r]
                };
                for (d, x) in dst.iter_mut().zip(src) {
                    *d += s * x;
                }
            } else if oi == usize::MAX
                && oi_last == usize::MAX
                && self.border_pos[i0 + n_r - 1] == self.border_pos[i0] + n_r - 1
            {
                // consecutive border rows: a strided segment of F (column j in a block) or of G
                let p0 = self.border_pos[i0];
                let (dst, stride) = if oj == usize::MAX {
                    let nb = self.border.len();
                    (&mut self.s[p0 * nb + self.border_pos[j]..], nb)
                } else {
                    let blk = &mut self.blocks[oj];
                    (&mut blk.f[p0 * blk.m + j - blk.first..], blk.m)
                };
                for (d, x) in dst.iter_mut().step_by(stride).zip(src) {
                    *d += s * x;
                }
            } else {
                for (r, x) in src.iter().enumerate() {
                    self.add(i0 + r, j, s * x);
                }
            }
        }
    }

    /// The block all of `i0..i0 + n` lie in, or `usize::MAX` if they are consecutive border
    /// unknowns, or `None` for a mixed range.
    fn range_owner(&self, i0: usize, n: usize) -> Option<usize> {
        let (o0, o1) = (self.owner[i0], self.owner[i0 + n - 1]);
        if o0 != o1 {
            return None;
        }
        if o0 == usize::MAX && self.border_pos[i0 + n - 1] != self.border_pos[i0] + n - 1 {
            return None;
        }
        Some(o0)
    }

    /// `A[i0 + r, j0 + c] += s · data[c · ld + r]`: a sub-block of a column-major matrix with
    /// leading dimension `ld`, classified once (band, `E`, `F` or `G` part) and added by
    /// contiguous runs; mixed ranges go column by column.
    #[allow(clippy::too_many_arguments)]
    pub fn add_submatrix(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, data: &[f64], ld: usize, s: f64) {
        if n_r == 0 || n_c == 0 {
            return;
        }
        let nb = self.border.len();
        match (self.range_owner(i0, n_r), self.range_owner(j0, n_c)) {
            (Some(bi), Some(bj)) if bi != usize::MAX && bi == bj => {
                let blk = &mut self.blocks[bi];
                let (w, ld_b) = (blk.w, 2 * blk.w + 1);
                let il0 = i0 - blk.first;
                if let (true, Some(nb)) = (blk.nodal_direct, &mut blk.nodal) {
                    let jl0 = j0 - blk.first;
                    if [il0, jl0, n_r, n_c].iter().all(|x| x.is_multiple_of(crate::node_lu::P)) {
                        self.node_overflow |= !nb.add_nodes(il0, jl0, n_r, n_c, data, ld, s);
                        return;
                    }
                    for c in 0..n_c {
                        self.node_overflow |= !nb.add_column(il0, jl0 + c, &data[c * ld..c * ld + n_r], s);
                    }
                    return;
                }
                if i0 + w < j0 + n_c - 1 || j0 + w < i0 + n_r - 1 {
                    // part of the block is outside the band
                    for c in 0..n_c {
                        self.add_slice(i0, j0 + c, n_r, 1, &data[c * ld..c * ld + n_r], s);
                    }
                    return;
                }
                for c in 0..n_c {
                    let jl = j0 + c - blk.first;
                    let o = jl * ld_b + il0 + w - jl;
                    for (d, x) in blk.band[o..o + n_r].iter_mut().zip(&data[c * ld..c * ld + n_r]) {
                        *d += s * x;
                    }
                }
            }
            (Some(bi), Some(usize::MAX)) if bi != usize::MAX => {
                let blk = &mut self.blocks[bi];
                let (m, il0, p0) = (blk.m, i0 - blk.first, self.border_pos[j0]);
                for c in 0..n_c {
                    let o = (p0 + c) * m + il0;
                    for (d, x) in blk.e[o..o + n_r].iter_mut().zip(&data[c * ld..c * ld + n_r]) {
                        *d += s * x;
                    }
                }
            }
            (Some(usize::MAX), Some(bj)) if bj != usize::MAX => {
                let blk = &mut self.blocks[bj];
                let (m, jl0, p0) = (blk.m, j0 - blk.first, self.border_pos[i0]);
                for r in 0..n_r {
                    let o = (p0 + r) * m + jl0;
                    for (c, d) in blk.f[o..o + n_c].iter_mut().enumerate() {
                        *d += s * data[c * ld + r];
                    }
                }
            }
            (Some(usize::MAX), Some(usize::MAX)) => {
                let (p0, q0) = (self.border_pos[i0], self.border_pos[j0]);
                for r in 0..n_r {
                    let o = (p0 + r) * nb + q0;
                    for (c, d) in self.s[o..o + n_c].iter_mut().enumerate() {
                        *d += s * data[c * ld + r];
                    }
                }
            }
            _ => {
                for c in 0..n_c {
                    self.add_slice(i0, j0 + c, n_r, 1, &data[c * ld..c * ld + n_r], s);
                }
            }
        }
    }

    /// Entry (i, j) as assembled (0 outside the structure).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (oi, oj) = (self.owner[i], self.owner[j]);
        let nb = self.border.len();
        match (oi != usize::MAX, oj != usize::MAX) {
            (true, true) => {
                let blk = &self.blocks[oi];
                if oi != oj || i.abs_diff(j) > blk.w {
                    return 0.0;
                }
                let (il, jl) = (i - blk.first, j - blk.first);
                if let (true, Some(nb)) = (blk.nodal_direct, &blk.nodal) {
                    return nb.get(il, jl);
                }
                blk.band[jl * (2 * blk.w + 1) + il + blk.w - jl]
            }
            (true, false) => {
                let blk = &self.blocks[oi];
                blk.e[self.border_pos[j] * blk.m + i - blk.first]
            }
            (false, true) => {
                let blk = &self.blocks[oj];
                blk.f[self.border_pos[i] * blk.m + j - blk.first]
            }
            (false, false) => self.s[self.border_pos[i] * nb + self.border_pos[j]],
        }
    }

    /// Whether a direct assembly met a non-zero entry outside the structure.
    pub fn assembled_outside(&self) -> bool {
        self.outside
    }

    /// Whether a direct assembly met a non-zero inside the band but outside a block's node band
    /// (it was dropped): give the matrix densely instead, which moves that block to the scalar
    /// band LU for good.
    pub fn assembled_outside_nodes(&self) -> bool {
        self.node_overflow
    }

    /// Factorise the gathered or directly assembled storage (band, `E`, `F`, `G` in `s`).
    pub fn factorize_gathered(&mut self) -> Result<(), usize> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.factorize_gathered_avx2() };
        }
        self.factorize_gathered_generic()
    }

    /// [`Self::factorize_gathered`] compiled with AVX2: wider vectors, no FMA, so the same
    /// arithmetic in the same order and the same factors bit for bit.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn factorize_gathered_avx2(&mut self) -> Result<(), usize> {
        self.factorize_gathered_generic()
    }

    #[inline(always)]
    fn factorize_gathered_generic(&mut self) -> Result<(), usize> {
        let nb = self.border.len();
        for blk in &mut self.blocks {
            let (first, m) = (blk.first, blk.m);
            // The active rows of F with the range of their non-zeros, and the active columns
            // of E with their first non-zero, found on every matrix: entries that vanish at
            // rest may not vanish later.
            blk.rows.clear();
            blk.row_range.clear();
            blk.cols.clear();
            blk.col_start.clear();
            for c in 0..nb {
                let frow = &blk.f[c * m..(c + 1) * m];
                if let Some(lo) = first_nonzero(frow) {
                    let hi = last_nonzero(frow).map_or(lo + 1, |j| j + 1);
                    blk.rows.push(c);
                    blk.row_range.push((lo, hi));
                }
                if let Some(s) = first_nonzero(&blk.e[c * m..(c + 1) * m]) {
                    blk.cols.push(c);
                    blk.col_start.push(s);
                }
            }
            for (cc, &c) in blk.cols.iter().enumerate() {
                blk.x[cc * m..(cc + 1) * m].copy_from_slice(&blk.e[c * m..(c + 1) * m]);
            }
            if !blk.factorize() {
                return Err(first);
            }
            // S = G − F D⁻¹ E = G − Z Y with Y = L⁻¹ E, Z = F U⁻¹: Y is zero above each
            // column's first non-zero and Z left of each row's, so a product runs from the later
            // of the two to the end (joint columns and rows touch only a body's last node).
            blk.forward_cols();
            blk.right_solve_rows();
            for (zr, (&br, &(lo, _))) in blk.z.chunks_exact(m).zip(blk.rows.iter().zip(&blk.row_range)) {
                let srow = &mut self.s[br * nb..(br + 1) * nb];
                for ((&c, yc), &st) in blk.cols.iter().zip(blk.x.chunks_exact(m)).zip(&blk.col_start) {
                    let a = lo.max(st);
                    srow[c] -= dot(&zr[a..], &yc[a..]);
                }
            }
        }
        self.active_known = true;
        if nb == 0 {
            return Ok(()); // no border: the band's factors are the whole factorisation
        }
        // Dense LU of S with partial pivoting. A pivot is tested against its own column's
        // largest entry before the elimination, not against all of S: the border mixes units
        // (frame velocities, rotation rates, multipliers), and a column that is small throughout
        // but independent, such as a floating frame's rotation in the mass matrix alone (only
        // the clamped root node's share of the inertia: 5e-8 against 2e7 elsewhere at 40
        // elements per body), is not singular. A column the elimination reduces to rounding is.
        self.col_scale.fill(0.0);
        for row in self.s.chunks_exact(nb) {
            for (c, x) in self.col_scale.iter_mut().zip(row) {
                *c = c.max(x.abs());
            }
        }
        for (i, p) in self.perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..nb {
            let (piv, pmax) =
                (k..nb).map(|i| (i, self.s[i * nb + k].abs())).fold((k, -1.0), |b, x| if x.1 > b.1 { x } else { b });
            if pmax <= 1e-14 * self.col_scale[k] || !pmax.is_finite() {
                return Err(self.border[k]);
            }
            if piv != k {
                for c in 0..nb {
                    self.s.swap(k * nb + c, piv * nb + c);
                }
                self.perm.swap(k, piv);
            }
            let (head, tail) = self.s.split_at_mut((k + 1) * nb);
            let row_k = &head[k * nb + k + 1..(k + 1) * nb];
            let p = head[k * nb + k];
            for row_i in tail.chunks_exact_mut(nb) {
                let l = row_i[k] / p;
                row_i[k] = l;
                if l != 0.0 {
                    sub_scaled(&mut row_i[k + 1..], l, row_k);
                }
            }
        }
        Ok(())
    }

    /// Overwrite `b` with `A⁻¹ b`.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { self.solve_avx2(b) };
            return;
        }
        self.solve_generic(b)
    }

    /// [`Self::solve_in_place`] compiled with AVX2 (the same arithmetic).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_avx2(&mut self, b: &mut [f64]) {
        self.solve_generic(b)
    }

    #[inline(always)]
    fn solve_generic(&mut self, b: &mut [f64]) {
        let nb = self.border.len();
        // c = L⁻¹ b on the blocks, and b_B − Z c into tmp.
        for (t, &bi) in self.tmp.iter_mut().zip(&self.border) {
            *t = b[bi];
        }
        for blk in &self.blocks {
            let c = &mut b[blk.first..blk.first + blk.m];
            blk.forward_vec(c);
            for (zr, (&br, &(lo, _))) in blk.z.chunks_exact(blk.m).zip(blk.rows.iter().zip(&blk.row_range)) {
                self.tmp[br] -= dot(&zr[lo..], &c[lo..]);
            }
        }
        // x_B = S⁻¹ (…): forward with the permutation, then back; kept in `xb`.
        let xb = &mut self.xb;
        for i in 0..nb {
            let s = dot(&self.s[i * nb..i * nb + i], &xb[..i]);
            xb[i] = self.tmp[self.perm[i]] - s;
        }
        for i in (0..nb).rev() {
            let s = xb[i] - dot(&self.s[i * nb + i + 1..(i + 1) * nb], &xb[i + 1..]);
            xb[i] = s / self.s[i * nb + i];
        }
        for (&x, &bi) in xb.iter().zip(&self.border) {
            b[bi] = x;
        }
        // x_I = U⁻¹ (c − Y x_B).
        for blk in &self.blocks {
            let c = &mut b[blk.first..blk.first + blk.m];
            for ((&col, yc), &st) in blk.cols.iter().zip(blk.x.chunks_exact(blk.m)).zip(&blk.col_start) {
                sub_scaled(&mut c[st..], xb[col], &yc[st..]);
            }
            blk.backward_vec(c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pseudo-random numbers in [−0.5, 0.5) from a linear congruential sequence.
    fn lcg(seed: u64) -> impl FnMut() -> f64 {
        let mut seed = seed;
        move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// The pattern of a chain of `n_el` three-node elements with `dpn` unknowns per node (nodes
    /// 1..=2 n_el; node 0 is not an unknown; an element couples nodes 2e..=2e+2) and `nb` border
    /// unknowns after them: random entries where two nodes share an element (only inside a node
    /// unless `couple`), `diag` added to the block diagonal, a full frame-like border row and
    /// column `m`, with `joint` a joint row `m + 1` and column `m + 2` touching only the last
    /// node, and 3 + noise on the border diagonal. Returns the matrix and `m`.
    fn element_chain(
        n_el: usize,
        dpn: usize,
        nb: usize,
        seed: u64,
        diag: f64,
        couple: bool,
        joint: bool,
    ) -> (DenseMatrix, usize) {
        let m = 2 * n_el * dpn;
        let n = m + nb;
        let mut a = DenseMatrix::zeros(n, n);
        let mut rnd = lcg(seed);
        let node = |i: usize| i / dpn + 1;
        for j in 0..m {
            for i in 0..m {
                let (ni, nj) = (node(i), node(j));
                let same = (0..n_el).any(|e| (2 * e..=2 * e + 2).contains(&ni) && (2 * e..=2 * e + 2).contains(&nj));
                if same && (couple || ni == nj) {
                    *a.get_mut(i, j) = rnd();
                }
            }
            *a.get_mut(j, j) += diag;
            *a.get_mut(m, j) = rnd();
            *a.get_mut(j, m) = rnd();
            if joint && node(j) == 2 * n_el {
                *a.get_mut(m + 1, j) = rnd();
                *a.get_mut(j, m + 2) = rnd();
            }
        }
        for j in m..n {
            *a.get_mut(j, j) = 3.0 + rnd();
        }
        (a, m)
    }

    /// A random diagonally dominant `n × n` matrix with the structure `st`: random values in
    /// each block's band, random values and sparsity in the border rows and columns.
    fn random_bordered(n: usize, st: &BandedBorder, seed: u64) -> DenseMatrix {
        let mut a = DenseMatrix::zeros(n, n);
        let mut rnd = lcg(seed);
        let owner = |i: usize| st.blocks.iter().position(|&(f, m, _)| i >= f && i < f + m);
        for j in 0..n {
            for i in 0..n {
                let keep = match (owner(i), owner(j)) {
                    (Some(bi), Some(bj)) => bi == bj && i.abs_diff(j) <= st.blocks[bi].2,
                    _ => rnd() > 0.0, // border: random sparsity
                };
                if keep {
                    *a.get_mut(i, j) = rnd();
                }
            }
            *a.get_mut(j, j) += 6.0;
        }
        a
    }

    /// A random diagonally dominant bordered band matrix, solved both ways.
    #[test]
    fn matches_dense_solve() {
        let n = 40;
        let st = BandedBorder { blocks: vec![(0, 15, 3), (18, 17, 5)], node_bandwidth: None };
        assert!(st.is_valid(n));
        let a = random_bordered(n, &st, 7);
        let mut lu = BorderedBandLu::new(n, &st);
        assert!(lu.fits(&a));
        lu.factorize(&a).unwrap();
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = vec![0.0; n];
        a.mul_vec_inplace(&x_true, &mut b);
        lu.solve_in_place(&mut b);
        for (x, y) in b.iter().zip(&x_true) {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
        // An entry outside the structure is detected.
        let mut a = a;
        *a.get_mut(2, 12) = 1.0;
        assert!(!lu.fits(&a));
    }

    /// Blocks that cover every unknown leave no border: the band factors alone solve it (an
    /// unconstrained model's ODE path).
    #[test]
    fn a_structure_without_border_solves() {
        let n = 33;
        let st = BandedBorder { blocks: vec![(0, 15, 3), (15, 18, 4)], node_bandwidth: None };
        assert!(st.is_valid(n));
        let a = random_bordered(n, &st, 11);
        let mut lu = BorderedBandLu::new(n, &st);
        lu.factorize(&a).unwrap();
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.61).cos()).collect();
        let mut b = vec![0.0; n];
        a.mul_vec_inplace(&x_true, &mut b);
        lu.solve_in_place(&mut b);
        for (x, y) in b.iter().zip(&x_true) {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
    }

    /// Direct assembly (entry by entry, by slices and by strided sub-blocks, twice with a clear
    /// in between) factorises to the same solution as the dense gather, bit for bit, and an entry
    /// outside the structure is reported.
    #[test]
    fn direct_assembly_matches_the_dense_gather() {
        let n = 40;
        let st = BandedBorder { blocks: vec![(0, 15, 3), (18, 17, 5)], node_bandwidth: None };
        let a = random_bordered(n, &st, 11);
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let mut b = vec![0.0; n];
        a.mul_vec_inplace(&x_true, &mut b);
        let mut dense = BorderedBandLu::new(n, &st);
        dense.factorize(&a).unwrap();
        let mut x_dense = b.clone();
        dense.solve_in_place(&mut x_dense);

        let mut direct = BorderedBandLu::new(n, &st);
        // first a different matrix, so that clearing is exercised
        direct.clear();
        for i in 0..n {
            direct.add(i, i, 3.0);
        }
        direct.factorize_gathered().unwrap();
        direct.clear();
        let data = a.as_slice();
        // columns 0..10 entry by entry, 10..18 as slices of whole columns, the rest as strided
        // sub-blocks over row ranges that split at the block boundaries
        for j in 0..10 {
            for i in 0..n {
                let x = a.get(i, j);
                if x != 0.0 {
                    direct.add(i, j, x);
                }
            }
        }
        for j in 10..18 {
            direct.add_slice(0, j, n, 1, &data[j * n..(j + 1) * n], 1.0);
        }
        for (r0, r1) in [(0, 15), (15, 18), (18, 35), (35, 40)] {
            for (c0, c1) in [(18, 35), (35, 40)] {
                let (nr, nc) = (r1 - r0, c1 - c0);
                // only what is inside the structure (outside entries are zero in `a` anyway)
                direct.add_submatrix(r0, c0, nr, nc, &data[c0 * n + r0..], n, 1.0);
            }
        }
        assert!(!direct.assembled_outside());
        for (i, j) in [(0, 0), (3, 5), (20, 40 - 1), (16, 2), (17, 30)] {
            assert_eq!(direct.get(i, j), a.get(i, j), "entry ({i}, {j})");
        }
        direct.factorize_gathered().unwrap();
        let mut x_direct = b.clone();
        direct.solve_in_place(&mut x_direct);
        assert_eq!(x_direct, x_dense);
        for (x, y) in x_direct.iter().zip(&x_true) {
            assert!((x - y).abs() < 1e-12, "{x} vs {y}");
        }
        // An entry outside the structure (two blocks coupled) is recorded.
        direct.clear();
        direct.add(2, 20, 1.0);
        assert!(direct.assembled_outside());
    }

    /// The pattern of a chain of three-node elements with 2 unknowns per node (an element
    /// couples nodes 2e..=2e+2: half-bandwidth 5, but the middle nodes reach only 3), border
    /// columns touching only the last node or all nodes: the envelope solve equals the dense
    /// one, and the envelope is narrower than the band where it should be.
    #[test]
    fn envelope_of_an_element_chain_matches_dense_solve() {
        let (n_el, dpn) = (4, 2);
        let nb = 3;
        let (mut a, m) = element_chain(n_el, dpn, nb, 11, 4.0, true, true);
        let n = m + nb;
        let st = BandedBorder { blocks: vec![(0, m, 3 * dpn - 1)], node_bandwidth: None };
        *a.get_mut(m + 1, m + 2) = 0.5;
        *a.get_mut(m + 2, m + 1) = 0.7;
        let mut lu = BorderedBandLu::new(n, &st);
        assert!(lu.fits(&a));
        lu.factorize(&a).unwrap();
        let blk = &lu.blocks[0];
        // First unknown of node 1 (a middle node) reaches the end of node 2; of node 2 (an
        // element end) the end of node 4.
        assert_eq!(blk.len_l[0], 2 * dpn - 1);
        assert_eq!(blk.len_l[dpn], 3 * dpn - 1);
        assert_eq!(blk.len_u[0], 2 * dpn - 1);
        assert_eq!(blk.u_top[3 * dpn], dpn); // node 4's column starts at node 2
        assert_eq!(blk.col_start, vec![0, m - dpn]);
        assert_eq!(blk.row_range, vec![(0, m), (m - dpn, m)]);
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.61).cos()).collect();
        let mut b = vec![0.0; n];
        a.mul_vec_inplace(&x_true, &mut b);
        lu.solve_in_place(&mut b);
        for (x, y) in b.iter().zip(&x_true) {
            approx::assert_relative_eq!(*x, *y, epsilon = 1e-12);
        }
    }

    /// A chain of three-node elements with six unknowns per node (a beam), declared
    /// node-banded: the node-block LU solves like the dense LU, skips the zero blocks between
    /// middle nodes, and a matrix with a non-zero outside the node band (inside the scalar band)
    /// is factorised by the scalar band LU instead, with the same solution.
    #[test]
    fn node_blocks_of_an_element_chain_match_dense_solve() {
        let (n_el, dpn) = (5, 6);
        let nb = 4;
        let (a, m) = element_chain(n_el, dpn, nb, 5, 6.0, true, true);
        let n = m + nb;
        let st = BandedBorder { blocks: vec![(0, m, 3 * dpn - 1)], node_bandwidth: Some(2) };
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.43).sin()).collect();
        let mut b = vec![0.0; n];
        a.mul_vec_inplace(&x_true, &mut b);
        let solve = |a: &DenseMatrix| {
            let mut lu = BorderedBandLu::new(n, &st);
            assert!(lu.fits(a));
            lu.factorize(a).unwrap();
            let mut x = b.clone();
            lu.solve_in_place(&mut x);
            (x, lu.blocks[0].use_nodal)
        };
        let (x, nodal) = solve(&a);
        assert!(nodal);
        for (x, y) in x.iter().zip(&x_true) {
            approx::assert_relative_eq!(*x, *y, epsilon = 1e-12);
        }
        // Node 1 and node 3 (middle nodes of elements 0 and 1) do not couple: the block is
        // skipped, also after the fill-in.
        let lu = {
            let mut lu = BorderedBandLu::new(n, &st);
            lu.factorize(&a).unwrap();
            lu
        };
        let band = lu.blocks[0].nodal.as_ref().unwrap();
        assert!(!band.is_nonzero(0, 2) && !band.is_nonzero(2, 0) && band.is_nonzero(1, 3));
        // Direct assembly into the node blocks (whole nodes as sub-blocks, a misaligned range
        // column by column, the border entry by entry) gives the same solution bit for bit.
        let mut direct = BorderedBandLu::new(n, &st);
        direct.factorize(&a).unwrap(); // the first factorisation goes through the dense gather
        direct.clear();
        let data = a.as_slice();
        for (r0, r1) in [(0, 24), (24, 60)] {
            for (c0, c1) in [(0, 30), (30, 60)] {
                if (c0, c1) == (30, 60) && r0 == 24 {
                    direct.add_submatrix(r0 + 1, c0, r1 - r0 - 1, c1 - c0, &data[c0 * n + r0 + 1..], n, 1.0);
                    direct.add_submatrix(r0, c0, 1, c1 - c0, &data[c0 * n + r0..], n, 1.0);
                } else {
                    direct.add_submatrix(r0, c0, r1 - r0, c1 - c0, &data[c0 * n + r0..], n, 1.0);
                }
            }
        }
        for j in 0..n {
            for i in 0..n {
                if (i >= m || j >= m) && a.get(i, j) != 0.0 {
                    direct.add(i, j, a.get(i, j));
                }
            }
        }
        assert!(!direct.assembled_outside());
        assert_eq!(direct.get(7, 13), a.get(7, 13));
        direct.factorize_gathered().unwrap();
        assert!(direct.blocks[0].use_nodal);
        let mut x_direct = b.clone();
        direct.solve_in_place(&mut x_direct);
        assert_eq!(x_direct, x);
        direct.clear();
        direct.add(5, 3 * dpn, 1.0); // nodes 1 and 4, inside the scalar band: outside the node band
        assert!(direct.assembled_outside_nodes() && !direct.assembled_outside());
        // Nodes 1 and 4 coupled (three apart, inside the scalar band 17): scalar band LU.
        let mut a2 = a.clone();
        *a2.get_mut(5, 3 * dpn) = 0.25;
        let mut b2 = vec![0.0; n];
        a2.mul_vec_inplace(&x_true, &mut b2);
        let mut lu2 = BorderedBandLu::new(n, &st);
        lu2.factorize(&a2).unwrap();
        assert!(!lu2.blocks[0].use_nodal);
        let rhs2 = b2.clone();
        lu2.solve_in_place(&mut b2);
        for (x, y) in b2.iter().zip(&x_true) {
            approx::assert_relative_eq!(*x, *y, epsilon = 1e-12);
        }
        // The direct assembly that met that coupling, given densely once, continues in place on
        // the scalar band.
        direct.factorize(&a2).unwrap();
        assert!(!direct.blocks[0].use_nodal && direct.blocks[0].nodal.is_none());
        direct.clear();
        for j in 0..n {
            for i in 0..n {
                if a2.get(i, j) != 0.0 {
                    direct.add(i, j, a2.get(i, j));
                }
            }
        }
        assert!(!direct.assembled_outside_nodes() && !direct.assembled_outside());
        direct.factorize_gathered().unwrap();
        let mut x2 = rhs2;
        direct.solve_in_place(&mut x2);
        for (x, y) in x2.iter().zip(&x_true) {
            approx::assert_relative_eq!(*x, *y, epsilon = 1e-12);
        }
    }

    /// Direct assembly into node blocks whose pattern differs from the last dense matrix's (here:
    /// no dense matrix before it, and a block-diagonal one before it, as a lumped mass in
    /// `initialize` would give) still solves exactly: the non-zero blocks are found on every
    /// matrix, not kept from the last gather.
    #[test]
    fn direct_node_assembly_finds_its_own_nonzero_blocks() {
        let (n_el, dpn) = (3, 6);
        let chain = |couple: bool, seed: u64| element_chain(n_el, dpn, 2, seed, 6.0, couple, false).0;
        let m = 2 * n_el * dpn;
        let n = m + 2;
        let st = BandedBorder { blocks: vec![(0, m, 3 * dpn - 1)], node_bandwidth: Some(2) };
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin()).collect();
        let residual = |lu: &mut BorderedBandLu, a: &DenseMatrix| {
            lu.clear();
            for j in 0..n {
                for i in 0..n {
                    if a.get(i, j) != 0.0 {
                        lu.add(i, j, a.get(i, j));
                    }
                }
            }
            assert!(!lu.assembled_outside());
            lu.factorize_gathered().unwrap();
            assert!(lu.blocks[0].use_nodal);
            let mut x = b.clone();
            lu.solve_in_place(&mut x);
            let mut ax = vec![0.0; n];
            a.mul_vec_inplace(&x, &mut ax);
            ax.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max)
        };
        let a = chain(true, 4);
        let mut fresh = BorderedBandLu::new(n, &st);
        assert!(residual(&mut fresh, &a) < 1e-12);
        let mut after_diagonal = BorderedBandLu::new(n, &st);
        after_diagonal.factorize(&chain(false, 3)).unwrap();
        assert!(residual(&mut after_diagonal, &a) < 1e-12);
    }

    /// The grouped scans find the first and last non-zero wherever they are, including in the
    /// partial group and in none.
    #[test]
    fn nonzero_scans_match_the_plain_search() {
        for n in [0, 1, 7, 8, 9, 16, 21] {
            for a in 0..=n {
                for b in a..=n {
                    let mut x = vec![0.0; n];
                    if a < n {
                        x[a] = -1.0;
                    }
                    if b < n {
                        x[b] = 2.0;
                    }
                    assert_eq!(first_nonzero(&x), x.iter().position(|v| *v != 0.0), "n {n} a {a} b {b}");
                    assert_eq!(last_nonzero(&x), x.iter().rposition(|v| *v != 0.0), "n {n} a {a} b {b}");
                }
            }
        }
    }

    /// A zero pivot in a block is reported (the caller then falls back to the dense LU).
    #[test]
    fn tiny_band_pivot_is_reported() {
        let n = 6;
        let st = BandedBorder { blocks: vec![(0, 4, 1)], node_bandwidth: None };
        let mut a = DenseMatrix::zeros(n, n);
        for i in 0..n {
            *a.get_mut(i, i) = 2.0;
        }
        *a.get_mut(1, 0) = 1.0;
        *a.get_mut(0, 1) = 4.0; // eliminating row 1 zeroes its pivot: 2 − 1·4/2 = 0
        let mut lu = BorderedBandLu::new(n, &st);
        assert_eq!(lu.factorize(&a), Err(0));
    }

    /// The Schur complement's pivots are tested against their own columns: a border unknown in
    /// other units, whose column is 1e-16 of the others (its pivot far below 1e-14 of the
    /// largest entry, as a floating frame's rotation in a mass matrix alone), is factorised
    /// and solved as accurately as the unscaled system (partial pivoting does not see a
    /// column's scale), where a test against the whole matrix called it singular; a border
    /// column that the elimination reduces to rounding (a copy of another) is still reported.
    #[test]
    fn schur_pivots_are_tested_against_their_columns() {
        let n = 40;
        let st = BandedBorder { blocks: vec![(0, 15, 3), (18, 17, 5)], node_bandwidth: None };
        let mut a = random_bordered(n, &st, 11);
        let (small, scale) = (16, 1e-16); // a border unknown
        for i in 0..n {
            *a.get_mut(i, small) *= scale;
        }
        let mut lu = BorderedBandLu::new(n, &st);
        lu.factorize(&a).unwrap();
        let mut x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        x_true[small] /= scale;
        let mut b = vec![0.0; n];
        a.mul_vec_inplace(&x_true, &mut b);
        lu.solve_in_place(&mut b);
        for (i, (x, y)) in b.iter().zip(&x_true).enumerate() {
            assert!((x - y).abs() < 1e-12 * y.abs().max(1.0), "unknown {i}: {x} vs {y}");
        }
        // Border column 39 a copy of border column 38: singular.
        for i in 0..n {
            *a.get_mut(i, 39) = a.get(i, 38);
        }
        assert!(lu.factorize(&a).is_err());
    }
}
