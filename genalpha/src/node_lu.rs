//! LU of a *node-banded* block: the band of a beam whose unknowns come in nodes of [`P`] = 6
//! (position and rotation) and whose elements couple nodes at most `kb` apart (two for
//! three-node elements). It is the elimination of the scalar band LU of
//! [`banded`](crate::banded), without pivoting and in the same order, carried out on 6×6 node
//! blocks: fixed-size kernels that the compiler unrolls and vectorises, where the scalar band
//! LU spends most of its instructions on loop control over columns of 5–17 entries. Structurally
//! zero node blocks (two middle nodes of neighbouring elements) are skipped.
//!
//! Blocks are stored column-major (`b[c][r]` is row `r`, column `c`), so that every kernel
//! sweeps contiguous columns. They are also the assembly storage: a direct assembly adds whole
//! nodes of an element matrix straight into them ([`NodeBand::add_nodes`]), so the scalar band is
//! neither filled nor gathered; a matrix given densely is gathered from the band
//! ([`NodeBand::gather`]).

// The kernels index rows and columns of fixed-size blocks as the algebra writes them.
#![allow(clippy::needless_range_loop)]

/// Unknowns per node.
pub(crate) const P: usize = 6;

/// A node block, column-major.
type Blk = [[f64; P]; P];

/// The node-block factors of one band block.
#[derive(Debug, Clone)]
pub(crate) struct NodeBand {
    /// Nodes.
    nn: usize,
    /// Node bandwidth: node blocks (i, j) with |i − j| ≤ kb may be non-zero.
    kb: usize,
    /// Block (i, j) at [`idx`](Self::idx): the matrix, then `L` (unit lower, strictly below the
    /// diagonal) and `U` (upper) in place.
    a: Vec<Blk>,
    /// Whether block (i, j) is non-zero: set from the assembled blocks ([`gather`](Self::gather)
    /// or [`find_nonzero_blocks`](Self::find_nonzero_blocks)), then extended by the fill-in of
    /// the factorisation.
    nz: Vec<bool>,
    /// Reciprocals of the pivots.
    inv_diag: Vec<f64>,
}

/// `y[..P] −= x · s`.
#[inline(always)]
fn axpy(y: &mut [f64; P], s: f64, x: &[f64; P]) {
    for r in 0..P {
        y[r] -= x[r] * s;
    }
}

/// `y −= B x` (B a node block).
#[inline(always)]
fn sub_mul_vec(y: &mut [f64; P], b: &Blk, x: &[f64; P]) {
    for c in 0..P {
        axpy(y, x[c], &b[c]);
    }
}

/// `A −= L U` (node blocks).
#[inline(always)]
fn sub_mul(a: &mut Blk, l: &Blk, u: &Blk) {
    for c in 0..P {
        for k in 0..P {
            axpy(&mut a[c], u[c][k], &l[k]);
        }
    }
}

impl NodeBand {
    /// Set up for a band block of `m` unknowns whose nodes couple at most `kb` apart; `None`
    /// when `m` is not a whole number of nodes.
    pub fn new(m: usize, kb: usize) -> Option<Self> {
        if !m.is_multiple_of(P) || m == 0 || kb == 0 {
            return None;
        }
        let nn = m / P;
        let nb = nn * (2 * kb + 1);
        Some(Self { nn, kb, a: vec![[[0.0; P]; P]; nb], nz: vec![false; nb], inv_diag: vec![0.0; m] })
    }

    #[inline(always)]
    fn idx(&self, i: usize, j: usize) -> usize {
        i * (2 * self.kb + 1) + j + self.kb - i
    }

    /// Zero the blocks before a direct assembly.
    pub fn clear(&mut self) {
        self.a.iter_mut().for_each(|b| *b = [[0.0; P]; P]);
    }

    /// Entry (i, j) of the block (local indices), 0 outside the node band.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (ni, nj) = (i / P, j / P);
        if ni.abs_diff(nj) > self.kb { 0.0 } else { self.a[self.idx(ni, nj)][j % P][i % P] }
    }

    /// `A[i0 + r, j] += s · src[r]` (local indices); false if a non-zero falls outside the node
    /// band (it is dropped).
    #[inline]
    pub fn add_column(&mut self, i0: usize, j: usize, src: &[f64], s: f64) -> bool {
        let (nj, c) = (j / P, j % P);
        let mut inside = true;
        let mut i = i0;
        let mut rest = src;
        while !rest.is_empty() {
            let (ni, r0) = (i / P, i % P);
            let len = (P - r0).min(rest.len());
            let (seg, tail) = rest.split_at(len);
            if ni.abs_diff(nj) <= self.kb {
                let k = self.idx(ni, nj);
                for (d, x) in self.a[k][c][r0..r0 + len].iter_mut().zip(seg) {
                    *d += s * x;
                }
            } else {
                inside &= seg.iter().all(|x| *x == 0.0);
            }
            i += len;
            rest = tail;
        }
        inside
    }

    /// `A[i0 + r, j0 + c] += s · data[c · ld + r]` for a sub-block of whole nodes (`i0`, `j0`,
    /// `n_r`, `n_c` multiples of [`P`]; local indices); false if a non-zero falls outside the
    /// node band (it is dropped).
    #[allow(clippy::too_many_arguments)] // the signature of AssemblyTarget::add_submatrix
    pub fn add_nodes(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, data: &[f64], ld: usize, s: f64) -> bool {
        debug_assert!([i0, j0, n_r, n_c].iter().all(|x| x.is_multiple_of(P)));
        let mut inside = true;
        for bj in 0..n_c / P {
            let nj = j0 / P + bj;
            for bi in 0..n_r / P {
                let ni = i0 / P + bi;
                let src = |c: usize| {
                    let o = (bj * P + c) * ld + bi * P;
                    &data[o..o + P]
                };
                if ni.abs_diff(nj) > self.kb {
                    inside &= (0..P).all(|c| src(c).iter().all(|x| *x == 0.0));
                    continue;
                }
                let k = self.idx(ni, nj);
                for c in 0..P {
                    let col: &[f64; P] = src(c).try_into().expect("a node");
                    let dst = &mut self.a[k][c];
                    for r in 0..P {
                        dst[r] += s * col[r];
                    }
                }
            }
        }
        inside
    }

    /// The largest pivot candidate: max |A_ii| before the factorisation.
    pub fn max_abs_diag(&self) -> f64 {
        (0..self.nn)
            .flat_map(|i| (0..P).map(move |k| (i, k)))
            .fold(0.0_f64, |m, (i, k)| m.max(self.a[self.idx(i, i)][k][k].abs()))
    }

    /// Copy a scalar band (by columns, entry (i, j) at `j (2w + 1) + i − j + w`) into node
    /// blocks; false if a non-zero lies outside the node band (then this cannot factorise it).
    pub fn gather(&mut self, band: &[f64], w: usize) -> bool {
        let (nn, kb, ld) = (self.nn, self.kb, 2 * w + 1);
        let m = nn * P;
        for j in 0..m {
            let (nj, c) = (j / P, j % P);
            let col = &band[j * ld..(j + 1) * ld];
            // Rows of the scalar band in this column: lo..hi.
            let (lo, hi) = (j.saturating_sub(w), (j + w + 1).min(m));
            for ni in nj.saturating_sub(kb)..(nj + kb + 1).min(nn) {
                let k = self.idx(ni, nj);
                let dst = &mut self.a[k][c];
                let (r0, r1) = (ni * P, ni * P + P);
                if r0 >= lo && r1 <= hi {
                    dst.copy_from_slice(&col[r0 + w - j..r1 + w - j]);
                } else {
                    for (r, d) in dst.iter_mut().enumerate() {
                        let i = r0 + r;
                        *d = if i >= lo && i < hi { col[i + w - j] } else { 0.0 };
                    }
                }
            }
            // Entries of the scalar band outside the node band must be zero.
            let (in_lo, in_hi) = (nj.saturating_sub(kb) * P, ((nj + kb + 1).min(nn)) * P);
            if col[lo + w - j..in_lo.max(lo) + w - j].iter().any(|x| *x != 0.0)
                || col[in_hi.min(hi) + w - j..hi + w - j].iter().any(|x| *x != 0.0)
            {
                return false;
            }
        }
        self.find_nonzero_blocks();
        true
    }

    /// Mark the blocks that hold a non-zero (before [`factorize`](Self::factorize): the
    /// assembled pattern may change from one matrix to the next).
    pub fn find_nonzero_blocks(&mut self) {
        for (nz, b) in self.nz.iter_mut().zip(&self.a) {
            *nz = b.iter().flatten().any(|x| *x != 0.0);
        }
    }

    /// In-place block LU without pivoting; false if a pivot is at most `tiny` in magnitude.
    #[inline(always)]
    pub fn factorize(&mut self, tiny: f64) -> bool {
        let (nn, kb) = (self.nn, self.kb);
        for i in 0..nn {
            let di = self.idx(i, i);
            // The diagonal block: L_ii U_ii.
            let mut d = self.a[di];
            for k in 0..P {
                let p = d[k][k];
                if p.abs() <= tiny || !p.is_finite() {
                    return false;
                }
                let inv = 1.0 / p;
                self.inv_diag[i * P + k] = inv;
                for r in k + 1..P {
                    d[k][r] *= inv;
                }
                for c in k + 1..P {
                    let u = d[c][k];
                    for r in k + 1..P {
                        d[c][r] -= d[k][r] * u;
                    }
                }
            }
            self.a[di] = d;
            let last = (i + kb).min(nn - 1);
            // U_ij = L_ii⁻¹ A_ij (column sweeps).
            for j in i + 1..=last {
                let k = self.idx(i, j);
                if !self.nz[k] {
                    continue;
                }
                let x = &mut self.a[k];
                for col in x.iter_mut() {
                    for kk in 0..P {
                        let xk = col[kk];
                        for r in kk + 1..P {
                            col[r] -= d[kk][r] * xk;
                        }
                    }
                }
            }
            // L_ji = A_ji U_ii⁻¹: column k is (A[k] − Σ_{l<k} X[l] U_lk) / U_kk.
            let inv = &self.inv_diag[i * P..i * P + P];
            for j in i + 1..=last {
                let k = self.idx(j, i);
                if !self.nz[k] {
                    continue;
                }
                let mut x = self.a[k];
                for kk in 0..P {
                    for l in 0..kk {
                        let u = d[kk][l];
                        let xl = x[l];
                        axpy(&mut x[kk], u, &xl);
                    }
                    for r in 0..P {
                        x[kk][r] *= inv[kk];
                    }
                }
                self.a[k] = x;
            }
            // Schur updates A_ab −= L_ai U_ib.
            for a in i + 1..=last {
                let la = self.idx(a, i);
                if !self.nz[la] {
                    continue;
                }
                let l = self.a[la];
                for b in i + 1..=last {
                    let ub = self.idx(i, b);
                    if !self.nz[ub] {
                        continue;
                    }
                    let u = self.a[ub];
                    let ab = self.idx(a, b);
                    sub_mul(&mut self.a[ab], &l, &u);
                    self.nz[ab] = true;
                }
            }
        }
        true
    }

    /// Whether node block (i, j) is non-zero (after the fill-in of the last factorisation).
    #[cfg(test)]
    pub fn is_nonzero(&self, i: usize, j: usize) -> bool {
        i.abs_diff(j) <= self.kb && self.nz[self.idx(i, j)]
    }

    /// Node `i` of a vector as a block-sized array.
    #[inline(always)]
    fn seg(y: &[f64], i: usize) -> [f64; P] {
        y[i * P..i * P + P].try_into().expect("a node")
    }

    /// Overwrite `y` with `L⁻¹ y`; `y` is zero before unknown `start`.
    #[inline(always)]
    pub fn forward(&self, y: &mut [f64], start: usize) {
        let (nn, kb) = (self.nn, self.kb);
        let n0 = start / P;
        for i in n0..nn {
            let mut yi = Self::seg(y, i);
            for j in i.saturating_sub(kb).max(n0)..i {
                let k = self.idx(i, j);
                if self.nz[k] {
                    sub_mul_vec(&mut yi, &self.a[k], &Self::seg(y, j));
                }
            }
            let d = &self.a[self.idx(i, i)];
            for kk in 0..P {
                let yk = yi[kk];
                for r in kk + 1..P {
                    yi[r] -= d[kk][r] * yk;
                }
            }
            y[i * P..i * P + P].copy_from_slice(&yi);
        }
    }

    /// Overwrite `y` with `U⁻¹ y`.
    #[inline(always)]
    pub fn backward(&self, y: &mut [f64]) {
        let (nn, kb) = (self.nn, self.kb);
        for i in (0..nn).rev() {
            let mut yi = Self::seg(y, i);
            for j in i + 1..(i + kb + 1).min(nn) {
                let k = self.idx(i, j);
                if self.nz[k] {
                    sub_mul_vec(&mut yi, &self.a[k], &Self::seg(y, j));
                }
            }
            let d = &self.a[self.idx(i, i)];
            for kk in (0..P).rev() {
                let yk = yi[kk] * self.inv_diag[i * P + kk];
                yi[kk] = yk;
                for r in 0..kk {
                    yi[r] -= d[kk][r] * yk;
                }
            }
            y[i * P..i * P + P].copy_from_slice(&yi);
        }
    }

    /// [`right_solve`](Self::right_solve) on `L` rows of `z` at once (row `rows[l]` at
    /// `z[rows[l] m..]`, `m` unknowns), all zero before node `n0`. Each row gets exactly the
    /// operations of `right_solve` from node `n0`, in the same order (every sum from −0.0, as
    /// `Iterator::sum` starts); the rows run in the lanes of fixed-size arrays, so that the
    /// products with a block vectorise across rows instead of ending in horizontal sums.
    #[inline(always)]
    pub fn right_solve_lanes<const L: usize>(&self, z: &mut [f64], m: usize, rows: [usize; L], n0: usize) {
        let (nn, kb) = (self.nn, self.kb);
        let seg = |z: &[f64], i: usize| -> [[f64; L]; P] {
            std::array::from_fn(|c| std::array::from_fn(|l| z[rows[l] * m + i * P + c]))
        };
        for j in n0..nn {
            let mut zj = seg(z, j);
            for i in j.saturating_sub(kb).max(n0)..j {
                let k = self.idx(i, j);
                if self.nz[k] {
                    let (u, zi) = (&self.a[k], seg(z, i));
                    for (c, x) in zj.iter_mut().enumerate() {
                        let mut acc = [-0.0; L];
                        for r in 0..P {
                            for l in 0..L {
                                acc[l] += zi[r][l] * u[c][r];
                            }
                        }
                        for l in 0..L {
                            x[l] -= acc[l];
                        }
                    }
                }
            }
            let d = &self.a[self.idx(j, j)];
            for kk in 0..P {
                let mut s = [-0.0; L];
                for l in 0..kk {
                    for ll in 0..L {
                        s[ll] += zj[l][ll] * d[kk][l];
                    }
                }
                let inv = self.inv_diag[j * P + kk];
                for ll in 0..L {
                    zj[kk][ll] = (zj[kk][ll] - s[ll]) * inv;
                }
            }
            for (c, x) in zj.iter().enumerate() {
                for l in 0..L {
                    z[rows[l] * m + j * P + c] = x[l];
                }
            }
        }
    }

    /// Overwrite the row vector `z` with `z U⁻¹`; `z` is zero before unknown `start`.
    #[inline(always)]
    pub fn right_solve(&self, z: &mut [f64], start: usize) {
        let (nn, kb) = (self.nn, self.kb);
        let n0 = start / P;
        for j in n0..nn {
            let mut zj = Self::seg(z, j);
            for i in j.saturating_sub(kb).max(n0)..j {
                let k = self.idx(i, j);
                if self.nz[k] {
                    let (u, zi) = (&self.a[k], Self::seg(z, i));
                    for (c, x) in zj.iter_mut().enumerate() {
                        *x -= (0..P).map(|r| zi[r] * u[c][r]).sum::<f64>();
                    }
                }
            }
            let d = &self.a[self.idx(j, j)];
            for kk in 0..P {
                let s: f64 = (0..kk).map(|l| zj[l] * d[kk][l]).sum();
                zj[kk] = (zj[kk] - s) * self.inv_diag[j * P + kk];
            }
            z[j * P..j * P + P].copy_from_slice(&zj);
        }
    }
}
