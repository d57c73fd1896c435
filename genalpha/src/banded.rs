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

use crate::DenseMatrix;

/// The declared structure: diagonal blocks `(first, len, half_bandwidth)` of the unknowns
/// (tangent indices); every index in no block belongs to the border, and so do all constraint
/// rows/multipliers appended by the integrator.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct BandedBorder {
    /// `(first index, number of unknowns, half-bandwidth)` of each block; blocks must not overlap.
    pub blocks: Vec<(usize, usize, usize)>,
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
    /// Band storage, row-major: entry (i, j) with |i − j| ≤ w at `i (2w + 1) + (j − i + w)`.
    band: Vec<f64>,
    /// Border columns (indices into the border) with a non-zero entry of `E` in this block.
    cols: Vec<usize>,
    /// Border rows with a non-zero entry of `F` in this block.
    rows: Vec<usize>,
    /// `E` then `X = D⁻¹ E` on the active columns, row-major m × cols.len().
    x: Vec<f64>,
    /// `F` on the active rows, row-major rows.len() × m.
    f: Vec<f64>,
}

impl Block {
    /// In-place LU without pivoting; false if a pivot is tiny.
    fn factorize(&mut self) -> bool {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        let scale = (0..m).map(|i| self.band[i * ld + w].abs()).fold(0.0_f64, f64::max);
        let tiny = 1e-13 * scale;
        for k in 0..m {
            let p = self.band[k * ld + w];
            if p.abs() <= tiny || !p.is_finite() {
                return false;
            }
            let end = (k + w + 1).min(m);
            let len = end - k - 1; // columns k+1..end
            let (head, tail) = self.band.split_at_mut((k + 1) * ld);
            // Row k, columns k+1..end, at offsets w+1..w+1+len.
            let row_k = &head[k * ld + w + 1..k * ld + w + 1 + len];
            for i in k + 1..end {
                let r = &mut tail[(i - k - 1) * ld..(i - k) * ld];
                // (i, k) at offset k − i + w; (i, j) at j − i + w.
                let ik = k + w - i;
                let l = r[ik] / p;
                r[ik] = l;
                if l != 0.0 {
                    for (x, y) in r[ik + 1..ik + 1 + len].iter_mut().zip(row_k) {
                        *x -= l * y;
                    }
                }
            }
        }
        true
    }

    /// Overwrite the vector `y` (length m) with `D⁻¹ y`.
    fn solve_vec(&self, y: &mut [f64]) {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        for i in 1..m {
            let lo = i.saturating_sub(w);
            let row = &self.band[i * ld + lo + w - i..i * ld + w];
            let s: f64 = row.iter().zip(&y[lo..i]).map(|(l, x)| l * x).sum();
            y[i] -= s;
        }
        for i in (0..m).rev() {
            let hi = (i + w + 1).min(m);
            let row = &self.band[i * ld + w + 1..i * ld + w + 1 + (hi - i - 1)];
            let s: f64 = row.iter().zip(&y[i + 1..hi]).map(|(u, x)| u * x).sum();
            y[i] = (y[i] - s) / self.band[i * ld + w];
        }
    }

    /// Overwrite the row-major `m × nc` block `x` with `D⁻¹ x` (all columns at once).
    fn solve_rows(&self, x: &mut [f64], nc: usize) {
        let (m, w) = (self.m, self.w);
        let ld = 2 * w + 1;
        for i in 1..m {
            let (done, rest) = x.split_at_mut(i * nc);
            let xi = &mut rest[..nc];
            for k in i.saturating_sub(w)..i {
                let l = self.band[i * ld + k + w - i];
                if l != 0.0 {
                    for (a, b) in xi.iter_mut().zip(&done[k * nc..(k + 1) * nc]) {
                        *a -= l * b;
                    }
                }
            }
        }
        for i in (0..m).rev() {
            let (head, rest) = x.split_at_mut((i + 1) * nc);
            let xi = &mut head[i * nc..];
            for k in i + 1..(i + w + 1).min(m) {
                let u = self.band[i * ld + k + w - i];
                if u != 0.0 {
                    let xk = &rest[(k - i - 1) * nc..(k - i) * nc];
                    for (a, b) in xi.iter_mut().zip(xk) {
                        *a -= u * b;
                    }
                }
            }
            let d = 1.0 / self.band[i * ld + w];
            xi.iter_mut().for_each(|a| *a *= d);
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
    /// Scratch of length n_b.
    tmp: Vec<f64>,
    /// Border solution, length n_b.
    xb: Vec<f64>,
    /// Scratch flags, length n_b.
    flags: Vec<bool>,
    /// Block of each unknown (`usize::MAX` for the border).
    owner: Vec<usize>,
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
        let blocks = structure
            .blocks
            .iter()
            .map(|&(first, m, w)| Block {
                first,
                m,
                w,
                band: vec![0.0; m * (2 * w + 1)],
                cols: Vec::with_capacity(nb),
                rows: Vec::with_capacity(nb),
                x: vec![0.0; m * nb],
                f: vec![0.0; nb * m],
            })
            .collect();
        Self {
            n,
            blocks,
            border,
            s: vec![0.0; nb * nb],
            perm: vec![0; nb],
            tmp: vec![0.0; nb],
            xb: vec![0.0; nb],
            flags: vec![false; nb],
            owner,
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
        let nb = self.border.len();
        assert!(a.n_rows() == self.n && a.n_cols() == self.n, "factorize: dimension mismatch");
        // Schur complement starts as G.
        for (r, &bi) in self.border.iter().enumerate() {
            for (c, &bj) in self.border.iter().enumerate() {
                self.s[r * nb + c] = a.get(bi, bj);
            }
        }
        for blk in &mut self.blocks {
            let (first, m, w) = (blk.first, blk.m, blk.w);
            let data = a.as_slice();
            let n = self.n;
            let ld = 2 * w + 1;
            blk.band.iter_mut().for_each(|x| *x = 0.0);
            for j in 0..m {
                let col = &data[(first + j) * n + first..(first + j) * n + first + m];
                let lo = j.saturating_sub(w);
                let hi = (j + w + 1).min(m);
                for (i, x) in col.iter().enumerate().take(hi).skip(lo) {
                    blk.band[i * ld + j + w - i] = *x;
                }
            }
            // Active border rows (F) and columns (E) of this block, found on every matrix:
            // entries that vanish at rest may not vanish later. Rows are scanned column by
            // column of the block (contiguous in the column-major storage).
            blk.rows.clear();
            blk.cols.clear();
            self.flags.iter_mut().for_each(|f| *f = false);
            for j in 0..m {
                let col = &data[(first + j) * n..(first + j + 1) * n];
                for (c, &bj) in self.border.iter().enumerate() {
                    if col[bj] != 0.0 {
                        self.flags[c] = true;
                    }
                }
            }
            for (c, &bj) in self.border.iter().enumerate() {
                if self.flags[c] {
                    blk.rows.push(c);
                }
                if data[bj * n + first..bj * n + first + m].iter().any(|x| *x != 0.0) {
                    blk.cols.push(c);
                }
            }
            let nc = blk.cols.len();
            for j in 0..m {
                let col = &data[(first + j) * n..(first + j + 1) * n];
                for (r, &c) in blk.rows.iter().enumerate() {
                    blk.f[r * m + j] = col[self.border[c]];
                }
            }
            for (cc, &c) in blk.cols.iter().enumerate() {
                let bj = self.border[c];
                let col = &data[bj * n + first..bj * n + first + m];
                for (i, x) in col.iter().enumerate() {
                    blk.x[i * nc + cc] = *x;
                }
            }
            if !blk.factorize() {
                return Err(first);
            }
            if nc == 0 {
                continue;
            }
            // X = D⁻¹ E on the active columns, all at once.
            let mut x = std::mem::take(&mut blk.x);
            blk.solve_rows(&mut x[..m * nc], nc);
            blk.x = x;
            // S[rows, cols] −= F X.
            for (r, &br) in blk.rows.iter().enumerate() {
                let frow = &blk.f[r * m..(r + 1) * m];
                let srow = &mut self.s[br * nb..(br + 1) * nb];
                for (k, &fk) in frow.iter().enumerate() {
                    if fk == 0.0 {
                        continue;
                    }
                    let xrow = &blk.x[k * nc..(k + 1) * nc];
                    for (&c, x) in blk.cols.iter().zip(xrow) {
                        srow[c] -= fk * x;
                    }
                }
            }
        }
        // Dense LU of S with partial pivoting.
        let scale = self.s.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        for (i, p) in self.perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..nb {
            let (piv, pmax) =
                (k..nb).map(|i| (i, self.s[i * nb + k].abs())).fold((k, -1.0), |b, x| if x.1 > b.1 { x } else { b });
            if pmax <= 1e-14 * scale || !pmax.is_finite() {
                return Err(self.border[k]);
            }
            if piv != k {
                for c in 0..nb {
                    self.s.swap(k * nb + c, piv * nb + c);
                }
                self.perm.swap(k, piv);
            }
            let p = self.s[k * nb + k];
            for i in k + 1..nb {
                let l = self.s[i * nb + k] / p;
                self.s[i * nb + k] = l;
                if l != 0.0 {
                    for c in k + 1..nb {
                        self.s[i * nb + c] -= l * self.s[k * nb + c];
                    }
                }
            }
        }
        Ok(())
    }

    /// Overwrite `b` with `A⁻¹ b`.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let nb = self.border.len();
        // y = D⁻¹ b on the blocks.
        for blk in &self.blocks {
            blk.solve_vec(&mut b[blk.first..blk.first + blk.m]);
        }
        // b_B ← b_B − F y, into tmp.
        for (r, &bi) in self.border.iter().enumerate() {
            self.tmp[r] = b[bi];
        }
        for blk in &self.blocks {
            let y = &b[blk.first..blk.first + blk.m];
            for (r, &br) in blk.rows.iter().enumerate() {
                let frow = &blk.f[r * blk.m..(r + 1) * blk.m];
                self.tmp[br] -= frow.iter().zip(y).map(|(f, y)| f * y).sum::<f64>();
            }
        }
        // x_B = S⁻¹ (…): forward with the permutation, then back; kept in `xb`.
        let xb = &mut self.xb;
        for i in 0..nb {
            let row = &self.s[i * nb..i * nb + i];
            xb[i] = self.tmp[self.perm[i]] - row.iter().zip(&xb[..i]).map(|(a, b)| a * b).sum::<f64>();
        }
        for i in (0..nb).rev() {
            let row = &self.s[i * nb + i + 1..(i + 1) * nb];
            let s = xb[i] - row.iter().zip(&xb[i + 1..]).map(|(a, b)| a * b).sum::<f64>();
            xb[i] = s / self.s[i * nb + i];
        }
        for (r, &bi) in self.border.iter().enumerate() {
            b[bi] = xb[r];
        }
        // x_I = y − X x_B.
        for blk in &self.blocks {
            let nc = blk.cols.len();
            if nc == 0 {
                continue;
            }
            for (i, bi) in b[blk.first..blk.first + blk.m].iter_mut().enumerate() {
                let xrow = &blk.x[i * nc..(i + 1) * nc];
                *bi -= xrow.iter().zip(&blk.cols).map(|(a, &c)| a * xb[c]).sum::<f64>();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random diagonally dominant bordered band matrix, solved both ways.
    #[test]
    fn matches_dense_solve() {
        let n = 40;
        let st = BandedBorder { blocks: vec![(0, 15, 3), (18, 17, 5)] };
        assert!(st.is_valid(n));
        let mut a = DenseMatrix::zeros(n, n);
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
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
        *a.get_mut(2, 12) = 1.0;
        assert!(!lu.fits(&a));
    }
}
