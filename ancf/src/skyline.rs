//! A variable-band ("skyline") LU for the integrator's iteration matrix, behind
//! [`genalpha::LinearSolver`].
//!
//! ANCF matrices are banded: a node couples only to its neighbours (half-bandwidth 23 in node
//! order), the joints add a few rows. The solver
//!
//! 1. orders the unknowns once (the integrator's matrix keeps its structure): rows with an exactly zero diagonal (Lagrange-multiplier rows of the
//!    DAE) are moved right behind the last coordinate they couple to, so that no zero pivot is met
//!    and their profile stays short;
//! 2. finds the profile (first non-zero of every row/column) from the matrix itself;
//! 3. factorises `P A Pᵀ = L U` in Crout form without pivoting inside the profile (stable for the
//!    mass-dominated, symmetric-positive-definite-like iteration matrices of a time step, and for
//!    their saddle-point extension by constraint rows);
//! 4. falls back to the dense partial-pivoting LU ([`genalpha::DenseLu`]) if a pivot is tiny or
//!    the profile is not much sparser than the full matrix.
//!
//! Buffers are sized in `set_dimension` and, for the envelope, when the profile is first known
//! (its length, never `n²`); the dense fallback's `n × n` storage only if it is used. After the
//! first factorisation of a given profile, factorising and solving do not allocate.

use genalpha::{Assembled, AssemblyTarget, DenseLu, DenseMatrix, Entries, LinearSolver};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Skyline LU with dense fallback. See the module documentation.
#[derive(Debug, Default)]
pub struct SkylineLu {
    n: usize,
    /// New position → original index.
    order: Vec<usize>,
    /// Original index → new position.
    inverse: Vec<usize>,
    /// First index of the profile of row/column `i` (new numbering).
    first: Vec<usize>,
    lptr: Vec<usize>,
    uptr: Vec<usize>,
    lval: Vec<f64>,
    uval: Vec<f64>,
    inv_diag: Vec<f64>,
    /// Per-row pivot floors of the factorisation in hand ([`SkylineLu::pivot_floors`]).
    floor: Vec<f64>,
    /// `|a_ii|` of the matrix being factorised and its reciprocal (0 where `a_ii` is 0): scratch
    /// of [`SkylineLu::pivot_floors`].
    diag_abs: Vec<f64>,
    inv_diag_abs: Vec<f64>,
    /// Width of the column group starting at each column ([`SkylineLu::column_groups`]).
    group_width: Vec<u8>,
    work: Vec<f64>,
    is_multiplier: Vec<bool>,
    last_coupled: Vec<usize>,
    ordered: bool,
    /// Known sparsity: `(n_primary, adjacency)`; indices ≥ `n_primary` are multiplier rows.
    structure: Option<(usize, Vec<Vec<usize>>)>,
    /// Whether the U column `i` gathers consecutive original rows (`order[first[i]..=i]`).
    contiguous: Vec<bool>,
    contiguity_known: bool,
    /// Set by the model while its matrices are symmetric: the entry-by-entry check is skipped.
    symmetric_hint: Option<Arc<AtomicBool>>,
    dense: DenseLu,
    use_dense: bool,
    /// Direct assembly ([`AssemblyTarget`]): offered when the structure is known and its profile
    /// fits; `direct_symmetric` is the symmetry hint read at `clear` (then only U is assembled);
    /// `direct_outside` records an entry outside the profile (the assembly is then redone densely,
    /// and direct assembly is no longer offered).
    direct_ok: bool,
    direct_symmetric: bool,
    direct_outside: bool,
    /// Skyline factorisations done.
    pub n_skyline: usize,
    /// Dense fallback factorisations done.
    pub n_dense: usize,
}

impl SkylineLu {
    /// A solver that finds the matrix structure by scanning every matrix it factorises; call
    /// `set_dimension` (the integrator does) before use.
    pub fn new() -> Self {
        Self::default()
    }

    /// A solver for matrices whose non-zeros lie within a known symmetric structure:
    /// `adjacency[i]` lists the indices coupled to `i`; indices `≥ n_primary` are multiplier
    /// rows (zero diagonal). Order and profile are computed once in `set_dimension`; entries
    /// outside the structure are ignored, so the structure must be complete.
    pub fn with_structure(n_primary: usize, adjacency: Vec<Vec<usize>>) -> Self {
        Self { structure: Some((n_primary, adjacency)), ..Self::default() }
    }

    /// Let the model vouch for the symmetry of its matrices: while `flag` is true, the values
    /// are taken as symmetric without the entry-by-entry check (only the upper triangle of the
    /// permuted matrix is read). While it is false, every matrix is checked.
    pub fn with_symmetry_hint(mut self, flag: Arc<AtomicBool>) -> Self {
        self.symmetric_hint = Some(flag);
        self
    }

    fn order_from_structure(&mut self) {
        let Some((n_primary, adj)) = &self.structure else { return };
        let n = self.n;
        self.order.clear();
        let np = *n_primary;
        let last: Vec<Option<usize>> =
            adj[np..n].iter().map(|list| list.iter().copied().filter(|&j| j < np).max()).collect();
        for i in 0..np {
            self.order.push(i);
            self.order.extend(last.iter().enumerate().filter(|(_, l)| **l == Some(i)).map(|(k, _)| np + k));
        }
        self.order.extend(last.iter().enumerate().filter(|(_, l)| l.is_none()).map(|(k, _)| np + k));
        for (new, &old) in self.order.iter().enumerate() {
            self.inverse[old] = new;
        }
        for (i, f) in self.first.iter_mut().enumerate() {
            *f = i;
        }
        for (old_i, list) in adj.iter().enumerate() {
            for &old_j in list {
                let (a, b) = (self.inverse[old_i], self.inverse[old_j]);
                let (hi, lo) = if a > b { (a, b) } else { (b, a) };
                self.first[hi] = self.first[hi].min(lo);
            }
        }
        self.ordered = true;
    }

    fn order_unknowns(&mut self, a: &[f64]) {
        let n = self.n;
        for i in 0..n {
            self.is_multiplier[i] = a[i * n + i] == 0.0;
            self.last_coupled[i] = usize::MAX;
        }
        for c in 0..n {
            let col = &a[c * n..(c + 1) * n];
            for (r, &x) in col.iter().enumerate() {
                if x != 0.0 && r != c {
                    if self.is_multiplier[r] && !self.is_multiplier[c] {
                        let l = &mut self.last_coupled[r];
                        *l = if *l == usize::MAX { c } else { (*l).max(c) };
                    }
                    if self.is_multiplier[c] && !self.is_multiplier[r] {
                        let l = &mut self.last_coupled[c];
                        *l = if *l == usize::MAX { r } else { (*l).max(r) };
                    }
                }
            }
        }
        self.order.clear();
        for i in 0..n {
            if self.is_multiplier[i] {
                continue;
            }
            self.order.push(i);
            for m in 0..n {
                if self.is_multiplier[m] && self.last_coupled[m] == i {
                    self.order.push(m);
                }
            }
        }
        for m in 0..n {
            if self.is_multiplier[m] && self.last_coupled[m] == usize::MAX {
                self.order.push(m);
            }
        }
        for (new, &old) in self.order.iter().enumerate() {
            self.inverse[old] = new;
        }
    }

    /// Returns false when the skyline path cannot be used for this matrix.
    fn factorize_skyline(&mut self, a: &[f64]) -> bool {
        let n = self.n;
        if self.structure.is_none() {
            if !self.ordered {
                self.order_unknowns(a);
                self.ordered = true;
            }
            // Profile in the new numbering from every non-zero (both triangles).
            for (i, f) in self.first.iter_mut().enumerate() {
                *f = i;
            }
            for c in 0..n {
                let nc = self.inverse[c];
                for (r, &x) in a[c * n..(c + 1) * n].iter().enumerate() {
                    if x != 0.0 {
                        let nr = self.inverse[r];
                        let (hi, lo) = if nr > nc { (nr, nc) } else { (nc, nr) };
                        if lo < self.first[hi] {
                            self.first[hi] = lo;
                        }
                    }
                }
            }
        }
        if !self.set_pointers() {
            return false;
        }
        if !self.contiguity_known {
            for (i, c) in self.contiguous.iter_mut().enumerate() {
                *c = self.order[self.first[i]..=i].windows(2).all(|w| w[1] == w[0] + 1);
            }
            // fixed with the structure; found from every matrix otherwise
            self.contiguity_known = self.structure.is_some();
        }
        // Gather the envelope of P A Pᵀ: U columns (with diagonal), and whether the values are
        // symmetric up to round-off (no follower moments): then L = D⁻¹Uᵀ, half the work.
        let known_symmetric = self.symmetric_hint.as_ref().is_some_and(|f| f.load(Ordering::Relaxed));
        let mut symmetric = true;
        for i in 0..n {
            let (oi, fi, up) = (self.order[i], self.first[i], self.uptr[i]);
            let col = &a[oi * n..(oi + 1) * n]; // A[·, order[i]]
            let u_col = self.uval[up..=up + (i - fi)].iter_mut().zip(&self.order[fi..=i]);
            if known_symmetric {
                if self.contiguous[i] {
                    // the rows fi..=i are consecutive original rows: one copy
                    let o0 = self.order[fi];
                    self.uval[up..=up + (i - fi)].copy_from_slice(&col[o0..=o0 + (i - fi)]);
                } else {
                    for (u, &ok) in u_col {
                        *u = col[ok];
                    }
                }
            } else {
                for (u, &ok) in u_col {
                    // U column i, row fi + k: A[order[fi + k], order[i]]
                    let x = col[ok];
                    *u = x;
                    // against L row i, column fi + k: A[order[i], order[fi + k]]
                    let y = a[ok * n + oi];
                    symmetric &= (x - y).abs() <= 1e-10 * (x.abs() + y.abs());
                }
            }
        }
        if !symmetric {
            for i in 0..n {
                let (oi, fi, lp) = (self.order[i], self.first[i], self.lptr[i]);
                for (l, &ok) in self.lval[lp..lp + (i - fi)].iter_mut().zip(&self.order[fi..i]) {
                    // L row i, column fi + k: A[order[i], order[fi + k]]
                    *l = a[ok * n + oi];
                }
            }
        }
        self.factor_in_place(symmetric)
    }

    /// Offsets of the U columns and L rows in `uval`/`lval` from the profile; false when the
    /// profile does not fit the buffers (then the dense LU is used).
    fn set_pointers(&mut self) -> bool {
        let n = self.n;
        let (mut lsize, mut usize_) = (0, 0);
        for i in 0..n {
            self.lptr[i] = lsize;
            self.uptr[i] = usize_;
            lsize += i - self.first[i];
            usize_ += i - self.first[i] + 1;
        }
        self.lptr[n] = lsize;
        self.uptr[n] = usize_;
        self.column_groups();
        // Profiles larger than a third of the matrix go to the dense LU; the envelope storage
        // grows to what the profile needs (never n²).
        if lsize > n * n / 6 + n || usize_ > n * n / 6 + 2 * n {
            return false;
        }
        if self.lval.len() < lsize {
            self.lval.resize(lsize, 0.0);
        }
        if self.uval.len() < usize_ {
            self.uval.resize(usize_, 0.0);
        }
        true
    }

    /// Factorise the envelope held in `uval` (U columns with the diagonal) and, unless
    /// `symmetric`, `lval` (L rows); false on a tiny pivot.
    fn factor_in_place(&mut self, symmetric: bool) -> bool {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.factor_in_place_avx2(symmetric) };
        }
        self.factor_in_place_generic(symmetric)
    }

    /// [`Self::factor_in_place`] compiled with AVX2: wider vectors, no FMA, so the same
    /// arithmetic in the same order and the same factors bit for bit.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn factor_in_place_avx2(&mut self, symmetric: bool) -> bool {
        self.factor_in_place_generic(symmetric)
    }

    #[inline(always)]
    fn factor_in_place_generic(&mut self, symmetric: bool) -> bool {
        let n = self.n;
        self.pivot_floors(symmetric);
        if symmetric {
            return self.factorize_symmetric();
        }
        // Crout, in place.
        for j in 0..n {
            let fj = self.first[j];
            let (lpj, upj) = (self.lptr[j], self.uptr[j]);
            for i in fj..j {
                let fi = self.first[i];
                let lo = fi.max(fj);
                let (lpi, upi) = (self.lptr[i], self.uptr[i]);
                // U[i][j] −= L[i][lo..i] · U[lo..i][j]
                let s = dot(&self.lval[lpi + (lo - fi)..lpi + (i - fi)], &self.uval[upj + (lo - fj)..upj + (i - fj)]);
                self.uval[upj + (i - fj)] -= s;
                let inv_d = self.inv_diag[i];
                if symmetric {
                    self.lval[lpj + (i - fj)] = self.uval[upj + (i - fj)] * inv_d;
                } else {
                    // L[j][i] = (A[j][i] − L[j][lo..i] · U[lo..i][i]) / U[i][i]
                    let s =
                        dot(&self.lval[lpj + (lo - fj)..lpj + (i - fj)], &self.uval[upi + (lo - fi)..upi + (i - fi)]);
                    self.lval[lpj + (i - fj)] = (self.lval[lpj + (i - fj)] - s) * inv_d;
                }
            }
            let s = dot(&self.lval[lpj..lpj + (j - fj)], &self.uval[upj..upj + (j - fj)]);
            let d = self.uval[upj + (j - fj)] - s;
            self.uval[upj + (j - fj)] = d;
            if !d.is_finite() || d.abs() <= self.floor[j] {
                return false;
            }
            self.inv_diag[j] = 1.0 / d;
        }
        true
    }

    /// The pivot below which row `i` counts as singular: 1e-13 of the magnitude of what forms
    /// it, its diagonal `|a_ii|` or the largest first elimination term `|a_ik a_ki / a_kk|`
    /// (k < i in the profile). A multiplier row (zero diagonal) has the scale of its Schur
    /// complement `Σ b_k² / a_kk`, which is the inverse of a stiffness: against the matrix's
    /// largest diagonal, as this test was before, a stiff structure's constraint pivots
    /// (1e-9 against 1e9 on SHARPy's Horten wing) read as zero and sent every factorisation to
    /// the dense LU. For the other rows the floor is at most the old one (`a_ik² ≤ a_ii a_kk`
    /// for the positive definite structural blocks), so no pivot accepted before is refused.
    #[inline(always)]
    fn pivot_floors(&mut self, symmetric: bool) {
        let n = self.n;
        if self.floor.len() != n {
            self.floor.resize(n, 0.0);
        }
        self.diag_abs.resize(n, 0.0);
        self.inv_diag_abs.resize(n, 0.0);
        for (i, (d, inv)) in self.diag_abs.iter_mut().zip(self.inv_diag_abs.iter_mut()).enumerate() {
            *d = self.uval[self.uptr[i] + (i - self.first[i])].abs();
            *inv = if *d > 0.0 { 1.0 / *d } else { 0.0 };
        }
        for i in 0..n {
            let (fi, up) = (self.first[i], self.uptr[i]);
            let u = &self.uval[up..up + (i - fi)]; // A[fi..i][i]
            let l = if symmetric { u } else { &self.lval[self.lptr[i]..self.lptr[i] + (i - fi)] }; // A[i][fi..i]
            let term = largest_elimination_term(l, u, &self.inv_diag_abs[fi..i]);
            self.floor[i] = 1e-13 * self.diag_abs[i].max(term);
        }
    }

    /// Crout for symmetric values (`L = D⁻¹Uᵀ`): column `j` of `U` and row `j` of `L` from the
    /// rows of `L` above. Consecutive columns, and consecutive rows, with the same profile start
    /// are taken together (columns in fours, else pairs; rows in pairs), so that each loaded value
    /// serves several products (the node-ordered ANCF unknowns come in runs of 12 with a common
    /// start). The grouping is [`column_groups`](Self::column_groups), fixed with the profile.
    #[inline(always)]
    fn factorize_symmetric(&mut self) -> bool {
        let n = self.n;
        let mut j = 0;
        while j < n {
            let width = self.group_width[j];
            let ok = match width {
                4 => self.symmetric_column_quad(j),
                2 => self.symmetric_column_pair(j),
                _ => self.symmetric_column(j),
            };
            if !ok {
                return false;
            }
            j += width as usize;
        }
        true
    }

    /// The column groups of [`factorize_symmetric`](Self::factorize_symmetric) from the profile:
    /// `group_width[j]` is 4, 2 or 1 at the first column `j` of each group (runs of four with a
    /// common start whose rows pair like two pairs, else pairs, else single columns). Computed
    /// with the profile ([`set_pointers`](Self::set_pointers)), not per factorisation.
    fn column_groups(&mut self) {
        let n = self.n;
        self.group_width.resize(n, 1);
        let mut j = 0;
        while j < n {
            let f = self.first[j];
            let run = self.first[j..n.min(j + 4)].iter().take_while(|&&x| x == f).count();
            let width = match run {
                4 if self.quad_pairs_rows_like_pairs(j) => 4,
                2..=4 => 2,
                _ => 1,
            };
            self.group_width[j] = width;
            j += width as usize;
        }
    }

    /// Whether the rows above column `j` pair up (consecutive rows with a common profile
    /// start) in the same way for the columns `j, j + 1` as for `j + 2, j + 3`, i.e. unless the
    /// greedy pairing over `first[j] .. j` leaves row `j - 1` alone while it could pair with row
    /// `j`. Then [`symmetric_column_quad`](Self::symmetric_column_quad) sums exactly like two
    /// [`symmetric_column_pair`](Self::symmetric_column_pair) calls.
    #[inline(always)]
    fn quad_pairs_rows_like_pairs(&self, j: usize) -> bool {
        let f = self.first[j];
        if j == f || self.first[j - 1] != f {
            return true;
        }
        let mut i = f;
        while i + 1 < j {
            i += if self.first[i + 1] == self.first[i] { 2 } else { 1 };
        }
        i == j // row j - 1 was paired with row j - 2
    }

    /// Pivot `j` of the symmetric factorisation from its reduced diagonal entry.
    #[inline(always)]
    fn set_pivot(&mut self, j: usize, d: f64) -> bool {
        if !d.is_finite() || d.abs() <= self.floor[j] {
            return false;
        }
        self.inv_diag[j] = 1.0 / d;
        true
    }

    /// Column `j` alone (see [`factorize_symmetric`](Self::factorize_symmetric)).
    #[inline(always)]
    fn symmetric_column(&mut self, j: usize) -> bool {
        let fj = self.first[j];
        let (lpj, upj) = (self.lptr[j], self.uptr[j]);
        let (l_done, l_rest) = self.lval.split_at_mut(lpj);
        let l_j = &mut l_rest[..j - fj];
        let u_j = &mut self.uval[upj..=upj + (j - fj)];
        let mut i = fj;
        while i < j {
            let fi = self.first[i];
            let lo = fi.max(fj);
            let lpi = self.lptr[i];
            let l_i = &l_done[lpi + (lo - fi)..lpi + (i - fi)];
            if i + 1 < j && self.first[i + 1] == fi {
                // rows i and i + 1: U[i][j], then U[i+1][j] with its term L[i+1][i] U[i][j]
                let lpi1 = self.lptr[i + 1];
                let l_i1 = &l_done[lpi1 + (lo - fi)..lpi1 + (i - fi)];
                let (s0, s1) = dot2(l_i, l_i1, &u_j[lo - fj..i - fj]);
                let u0 = u_j[i - fj] - s0;
                u_j[i - fj] = u0;
                l_j[i - fj] = u0 * self.inv_diag[i];
                let u1 = u_j[i + 1 - fj] - s1 - l_done[lpi1 + (i - fi)] * u0;
                u_j[i + 1 - fj] = u1;
                l_j[i + 1 - fj] = u1 * self.inv_diag[i + 1];
                i += 2;
            } else {
                let u0 = u_j[i - fj] - dot(l_i, &u_j[lo - fj..i - fj]);
                u_j[i - fj] = u0;
                l_j[i - fj] = u0 * self.inv_diag[i];
                i += 1;
            }
        }
        let d = u_j[j - fj] - dot(l_j, &u_j[..j - fj]);
        u_j[j - fj] = d;
        self.set_pivot(j, d)
    }

    /// Columns `j` and `j + 1` with the same profile start `f` together.
    #[inline(always)]
    fn symmetric_column_pair(&mut self, j: usize) -> bool {
        let floor_j = self.floor[j];
        let f = self.first[j];
        let (lpj, upj, upj1) = (self.lptr[j], self.uptr[j], self.uptr[j + 1]);
        let (l_done, l_rest) = self.lval.split_at_mut(lpj);
        let (l_j, l_rest) = l_rest.split_at_mut(j - f);
        let l_j1 = &mut l_rest[..j + 1 - f];
        let (u_j, u_rest) = self.uval[upj..].split_at_mut(upj1 - upj);
        let u_j1 = &mut u_rest[..j + 2 - f];
        let mut i = f;
        while i < j {
            let fi = self.first[i];
            let lo = fi.max(f);
            let lpi = self.lptr[i];
            let l_i = &l_done[lpi + (lo - fi)..lpi + (i - fi)];
            let (di, uj, uj1) = (self.inv_diag[i], &u_j[lo - f..i - f], &u_j1[lo - f..i - f]);
            if i + 1 < j && self.first[i + 1] == fi {
                let lpi1 = self.lptr[i + 1];
                let l_i1 = &l_done[lpi1 + (lo - fi)..lpi1 + (i - fi)];
                let s = dot2x2(l_i, l_i1, uj, uj1);
                let l_i1_i = l_done[lpi1 + (i - fi)];
                let di1 = self.inv_diag[i + 1];
                let a0 = u_j[i - f] - s[0];
                let b0 = u_j1[i - f] - s[1];
                let a1 = u_j[i + 1 - f] - s[2] - l_i1_i * a0;
                let b1 = u_j1[i + 1 - f] - s[3] - l_i1_i * b0;
                (u_j[i - f], u_j1[i - f], u_j[i + 1 - f], u_j1[i + 1 - f]) = (a0, b0, a1, b1);
                (l_j[i - f], l_j1[i - f], l_j[i + 1 - f], l_j1[i + 1 - f]) = (a0 * di, b0 * di, a1 * di1, b1 * di1);
                i += 2;
            } else {
                let (s0, s1) = dot2(uj, uj1, l_i);
                let (a0, b0) = (u_j[i - f] - s0, u_j1[i - f] - s1);
                (u_j[i - f], u_j1[i - f]) = (a0, b0);
                (l_j[i - f], l_j1[i - f]) = (a0 * di, b0 * di);
                i += 1;
            }
        }
        // pivot j, then row j of column j + 1, then pivot j + 1
        let d = u_j[j - f] - dot(l_j, &u_j[..j - f]);
        u_j[j - f] = d;
        if !d.is_finite() || d.abs() <= floor_j {
            return false;
        }
        let dj = 1.0 / d;
        let u = u_j1[j - f] - dot(l_j, &u_j1[..j - f]);
        u_j1[j - f] = u;
        l_j1[j - f] = u * dj;
        let d1 = u_j1[j + 1 - f] - dot(l_j1, &u_j1[..j + 1 - f]);
        u_j1[j + 1 - f] = d1;
        self.inv_diag[j] = dj;
        self.set_pivot(j + 1, d1)
    }
    /// Columns `j .. j + 4` with the same profile start `f` together: the rows above `j` in
    /// pairs against all four columns (eight products per loaded pair of `L` values), then the
    /// 4 × 4 diagonal block as two column pairs. Every product is summed in the same order as
    /// in [`symmetric_column_pair`](Self::symmetric_column_pair) on the pairs `(j, j + 1)` and
    /// `(j + 2, j + 3)`, so both give the same factors bit for bit.
    #[inline(always)]
    fn symmetric_column_quad(&mut self, j: usize) -> bool {
        let floors = [self.floor[j], self.floor[j + 1], self.floor[j + 2], self.floor[j + 3]];
        let f = self.first[j];
        let m = j - f;
        // the L rows j .. j + 4 and the U columns j .. j + 4 follow each other in storage
        let (l_done, l_rest) = self.lval.split_at_mut(self.lptr[j]);
        let (l0, l_rest) = l_rest.split_at_mut(m);
        let (l1, l_rest) = l_rest.split_at_mut(m + 1);
        let (l2, l_rest) = l_rest.split_at_mut(m + 2);
        let l3 = &mut l_rest[..m + 3];
        let (u0, u_rest) = self.uval[self.uptr[j]..].split_at_mut(m + 1);
        let (u1, u_rest) = u_rest.split_at_mut(m + 2);
        let (u2, u_rest) = u_rest.split_at_mut(m + 3);
        let u3 = &mut u_rest[..m + 4];
        let mut i = f;
        while i < j {
            let fi = self.first[i];
            let lo = fi.max(f);
            let lpi = self.lptr[i];
            let l_i = &l_done[lpi + (lo - fi)..lpi + (i - fi)];
            let (k0, k) = (lo - f, i - f);
            let di = self.inv_diag[i];
            if i + 1 < j && self.first[i + 1] == fi {
                let lpi1 = self.lptr[i + 1];
                let l_i1 = &l_done[lpi1 + (lo - fi)..lpi1 + (i - fi)];
                let s = dot4x2(l_i, l_i1, [&u0[k0..k], &u1[k0..k], &u2[k0..k], &u3[k0..k]]);
                let l_i1_i = l_done[lpi1 + (i - fi)];
                let di1 = self.inv_diag[i + 1];
                for (c, (u, l)) in
                    [(&mut *u0, &mut *l0), (&mut *u1, &mut *l1), (&mut *u2, &mut *l2), (&mut *u3, &mut *l3)]
                        .into_iter()
                        .enumerate()
                {
                    let a = u[k] - s[c];
                    let b = u[k + 1] - s[4 + c] - l_i1_i * a;
                    (u[k], u[k + 1]) = (a, b);
                    (l[k], l[k + 1]) = (a * di, b * di1);
                }
                i += 2;
            } else {
                let s = dot4x1(l_i, [&u0[k0..k], &u1[k0..k], &u2[k0..k], &u3[k0..k]]);
                for (c, (u, l)) in
                    [(&mut *u0, &mut *l0), (&mut *u1, &mut *l1), (&mut *u2, &mut *l2), (&mut *u3, &mut *l3)]
                        .into_iter()
                        .enumerate()
                {
                    let a = u[k] - s[c];
                    u[k] = a;
                    l[k] = a * di;
                }
                i += 1;
            }
        }
        // pivots j, j + 1
        let Some((dj, dj1)) = pair_diagonal(l0, l1, u0, u1, m, (floors[0], floors[1])) else { return false };
        (self.inv_diag[j], self.inv_diag[j + 1]) = (dj, dj1);
        // rows j, j + 1 of columns j + 2, j + 3
        let s = dot2x2(l0, &l1[..m], &u2[..m], &u3[..m]);
        let l_i1_i = l1[m];
        let a0 = u2[m] - s[0];
        let b0 = u3[m] - s[1];
        let a1 = u2[m + 1] - s[2] - l_i1_i * a0;
        let b1 = u3[m + 1] - s[3] - l_i1_i * b0;
        (u2[m], u3[m], u2[m + 1], u3[m + 1]) = (a0, b0, a1, b1);
        (l2[m], l3[m], l2[m + 1], l3[m + 1]) = (a0 * dj, b0 * dj, a1 * dj1, b1 * dj1);
        // pivots j + 2, j + 3
        let Some((dj2, dj3)) = pair_diagonal(l2, l3, u2, u3, m + 2, (floors[2], floors[3])) else { return false };
        (self.inv_diag[j + 2], self.inv_diag[j + 3]) = (dj2, dj3);
        true
    }
}

/// `max_k |l_k u_k| inv_k` with `inv_k = 1 / d_k` (0 where `d_k` is 0; a NaN term is skipped
/// as `f64::max` skips it). The reciprocals are taken once per row, not once per profile entry:
/// a division per entry cost about an eighth of the factorisation, and the floor only decides
/// between this LU and the dense one, so its last bit does not matter. Four running maxima
/// without branches (the maximum does not depend on the order).
#[inline(always)]
fn largest_elimination_term(l: &[f64], u: &[f64], inv_d: &[f64]) -> f64 {
    let term = |l: f64, u: f64, inv: f64| (l * u).abs() * inv;
    let mut m = [0.0_f64; 4];
    let (lc, uc, dc) = (l.chunks_exact(4), u.chunks_exact(4), inv_d.chunks_exact(4));
    let (lr, ur, dr) = (lc.remainder(), uc.remainder(), dc.remainder());
    for ((l, u), d) in lc.zip(uc).zip(dc) {
        for c in 0..4 {
            let x = term(l[c], u[c], d[c]);
            m[c] = if x > m[c] { x } else { m[c] };
        }
    }
    for ((&l, &u), &d) in lr.iter().zip(ur).zip(dr) {
        let x = term(l, u, d);
        m[0] = if x > m[0] { x } else { m[0] };
    }
    m[0].max(m[1]).max(m[2].max(m[3]))
}

/// The 2 × 2 diagonal block of a column pair whose rows above it are reduced: pivot `m` of
/// column `u0` (L row `l0`, length `m`), row `m` of column `u1` (giving `l1[m]`), pivot `m + 1`
/// of `u1` (L row `l1`, length `m + 1`). The inverse pivots, or `None` for a pivot at or below
/// its floor.
#[inline(always)]
fn pair_diagonal(
    l0: &[f64],
    l1: &mut [f64],
    u0: &mut [f64],
    u1: &mut [f64],
    m: usize,
    (floor0, floor1): (f64, f64),
) -> Option<(f64, f64)> {
    let d = u0[m] - dot(l0, &u0[..m]);
    u0[m] = d;
    if !d.is_finite() || d.abs() <= floor0 {
        return None;
    }
    let dj = 1.0 / d;
    let u = u1[m] - dot(l0, &u1[..m]);
    u1[m] = u;
    l1[m] = u * dj;
    let d1 = u1[m + 1] - dot(&l1[..m + 1], &u1[..m + 1]);
    u1[m + 1] = d1;
    if !d1.is_finite() || d1.abs() <= floor1 {
        return None;
    }
    Some((dj, 1.0 / d1))
}

/// `[l0·u0, l0·u1, l0·u2, l0·u3, l1·u0, …, l1·u3]` over the length of `l0`, each product summed
/// as in [`dot2x2`] (even and odd terms apart, then the odd last term).
#[inline(always)]
fn dot4x2(l0: &[f64], l1: &[f64], u: [&[f64]; 4]) -> [f64; 8] {
    let n = l0.len();
    let l1 = &l1[..n];
    let [u0, u1, u2, u3] = u.map(|c| &c[..n]);
    let split = n - n % 2;
    let (mut e, mut o) = ([0.0; 8], [0.0; 8]);
    for (((((a, b), x0), x1), x2), x3) in l0[..split]
        .chunks_exact(2)
        .zip(l1[..split].chunks_exact(2))
        .zip(u0[..split].chunks_exact(2))
        .zip(u1[..split].chunks_exact(2))
        .zip(u2[..split].chunks_exact(2))
        .zip(u3[..split].chunks_exact(2))
    {
        for (c, x) in [x0, x1, x2, x3].into_iter().enumerate() {
            e[c] += a[0] * x[0];
            o[c] += a[1] * x[1];
            e[4 + c] += b[0] * x[0];
            o[4 + c] += b[1] * x[1];
        }
    }
    let mut s = [0.0; 8];
    for c in 0..8 {
        s[c] = e[c] + o[c];
    }
    if split < n {
        let k = split;
        for (c, x) in [u0, u1, u2, u3].into_iter().enumerate() {
            s[c] += l0[k] * x[k];
            s[4 + c] += l1[k] * x[k];
        }
    }
    s
}

/// `[l·u0, l·u1, l·u2, l·u3]` over the length of `l`, each summed as in [`dot2`].
#[inline(always)]
fn dot4x1(l: &[f64], u: [&[f64]; 4]) -> [f64; 4] {
    let n = l.len();
    let [u0, u1, u2, u3] = u.map(|c| &c[..n]);
    let split = n - n % 2;
    let (mut e, mut o) = ([0.0; 4], [0.0; 4]);
    for ((((a, x0), x1), x2), x3) in l[..split]
        .chunks_exact(2)
        .zip(u0[..split].chunks_exact(2))
        .zip(u1[..split].chunks_exact(2))
        .zip(u2[..split].chunks_exact(2))
        .zip(u3[..split].chunks_exact(2))
    {
        for (c, x) in [x0, x1, x2, x3].into_iter().enumerate() {
            e[c] += x[0] * a[0];
            o[c] += x[1] * a[1];
        }
    }
    let mut s = [0.0; 4];
    for c in 0..4 {
        s[c] = e[c] + o[c];
    }
    if split < n {
        for (c, x) in [u0, u1, u2, u3].into_iter().enumerate() {
            s[c] += x[split] * l[split];
        }
    }
    s
}

/// `[l0·u0, l0·u1, l1·u0, l1·u1]` over the length of `u0`.
#[inline(always)]
fn dot2x2(l0: &[f64], l1: &[f64], u0: &[f64], u1: &[f64]) -> [f64; 4] {
    let n = u0.len();
    let (l0, l1, u1) = (&l0[..n], &l1[..n], &u1[..n]);
    let split = n - n % 2;
    let mut acc = [0.0; 8];
    for (((a, b), x), y) in l0[..split]
        .chunks_exact(2)
        .zip(l1[..split].chunks_exact(2))
        .zip(u0[..split].chunks_exact(2))
        .zip(u1[..split].chunks_exact(2))
    {
        acc[0] += a[0] * x[0];
        acc[1] += a[1] * x[1];
        acc[2] += a[0] * y[0];
        acc[3] += a[1] * y[1];
        acc[4] += b[0] * x[0];
        acc[5] += b[1] * x[1];
        acc[6] += b[0] * y[0];
        acc[7] += b[1] * y[1];
    }
    let mut s = [acc[0] + acc[1], acc[2] + acc[3], acc[4] + acc[5], acc[6] + acc[7]];
    if split < n {
        let k = split;
        s[0] += l0[k] * u0[k];
        s[1] += l0[k] * u1[k];
        s[2] += l1[k] * u0[k];
        s[3] += l1[k] * u1[k];
    }
    s
}

/// `(a·c, b·c)` over the length of `c`.
#[inline(always)]
fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
    let n = c.len();
    let (a, b) = (&a[..n], &b[..n]);
    let split = n - n % 2;
    let mut acc = [0.0; 4];
    for ((x, y), z) in a[..split].chunks_exact(2).zip(b[..split].chunks_exact(2)).zip(c[..split].chunks_exact(2)) {
        acc[0] += x[0] * z[0];
        acc[1] += x[1] * z[1];
        acc[2] += y[0] * z[0];
        acc[3] += y[1] * z[1];
    }
    let (mut s0, mut s1) = (acc[0] + acc[1], acc[2] + acc[3]);
    if split < n {
        s0 += a[split] * c[split];
        s1 += b[split] * c[split];
    }
    (s0, s1)
}

#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    // four independent accumulators so that the compiler can vectorise the short dot products
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0; 4];
    let split = n - n % 4;
    for (x, y) in a[..split].chunks_exact(4).zip(b[..split].chunks_exact(4)) {
        acc[0] += x[0] * y[0];
        acc[1] += x[1] * y[1];
        acc[2] += x[2] * y[2];
        acc[3] += x[3] * y[3];
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (x, y) in a[split..].iter().zip(&b[split..]) {
        s += x * y;
    }
    s
}

/// Direct assembly into the envelope: entry (i, j) of the original numbering goes to U column
/// `inverse[j]` (rows at or above the diagonal) or L row `inverse[i]` (below it). While the model
/// vouches for symmetry only U is kept, and lower entries are dropped (they mirror U).
impl AssemblyTarget for SkylineLu {
    fn clear(&mut self) {
        self.direct_symmetric = self.symmetric_hint.as_ref().is_some_and(|f| f.load(Ordering::Relaxed));
        self.direct_outside = false;
        let n = self.n;
        self.uval[..self.uptr[n]].fill(0.0);
        if !self.direct_symmetric {
            self.lval[..self.lptr[n]].fill(0.0);
        }
    }

    #[inline]
    fn add(&mut self, i: usize, j: usize, v: f64) {
        let (a, b) = (self.inverse[i], self.inverse[j]);
        if a <= b {
            if a < self.first[b] {
                self.direct_outside |= v != 0.0;
                return;
            }
            self.uval[self.uptr[b] + (a - self.first[b])] += v;
        } else if !self.direct_symmetric {
            if b < self.first[a] {
                self.direct_outside |= v != 0.0;
                return;
            }
            self.lval[self.lptr[a] + (b - self.first[a])] += v;
        }
    }

    fn add_symmetric_upper(&mut self, i0: usize, n_b: usize, block: &[f64], s: f64) {
        let a0 = self.inverse[i0];
        // No multiplier row sits between the block's coordinates: U column segments are contiguous.
        let contiguous = self.inverse[i0 + n_b - 1] == a0 + n_b - 1;
        if !self.direct_symmetric {
            for c in 0..n_b {
                for r in 0..=c {
                    let x = s * block[c * n_b + r];
                    self.add(i0 + r, i0 + c, x);
                    if r != c {
                        self.add(i0 + c, i0 + r, x);
                    }
                }
            }
            return;
        }
        if !contiguous {
            // coordinates keep their order (multiplier rows are only inserted between them), so
            // row r ≤ column c of the block stays in U
            for c in 0..n_b {
                let b = self.inverse[i0 + c];
                let (fb, ub) = (self.first[b], self.uptr[b]);
                for (r, x) in block[c * n_b..=c * n_b + c].iter().enumerate() {
                    let a = self.inverse[i0 + r];
                    if a < fb {
                        self.direct_outside |= *x != 0.0;
                        continue;
                    }
                    self.uval[ub + (a - fb)] += s * x;
                }
            }
            return;
        }
        for c in 0..n_b {
            let (b, col) = (a0 + c, &block[c * n_b..=c * n_b + c]);
            let fb = self.first[b];
            if a0 < fb {
                // the block reaches above the profile: only zeros may lie there
                let (above, inside) = col.split_at((fb - a0).min(c + 1));
                self.direct_outside |= above.iter().any(|&x| x != 0.0);
                let start = self.uptr[b];
                for (u, x) in self.uval[start..start + inside.len()].iter_mut().zip(inside) {
                    *u += s * x;
                }
                continue;
            }
            let start = self.uptr[b] + (a0 - fb);
            for (u, x) in self.uval[start..=start + c].iter_mut().zip(col) {
                *u += s * x;
            }
        }
    }

    fn add_symmetric_indexed(&mut self, idx: &[usize], block: &[f64], s: f64) {
        let n = idx.len();
        if !self.direct_symmetric {
            for (c, &j) in idx.iter().enumerate() {
                for (r, &i) in idx.iter().enumerate() {
                    self.add(i, j, s * block[c * n + r]);
                }
            }
            return;
        }
        // increasing coordinates keep their order in the new numbering: rows r ≤ c are in U
        for (c, &j) in idx.iter().enumerate() {
            let b = self.inverse[j];
            let (fb, ub) = (self.first[b], self.uptr[b]);
            for (&i, x) in idx[..=c].iter().zip(&block[c * n..=c * n + c]) {
                let a = self.inverse[i];
                if a < fb {
                    self.direct_outside |= *x != 0.0;
                    continue;
                }
                self.uval[ub + (a - fb)] += s * x;
            }
        }
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        let (a, b) = (self.inverse[i], self.inverse[j]);
        let (a, b, upper) = if a <= b || self.direct_symmetric { (a.min(b), a.max(b), true) } else { (a, b, false) };
        if upper {
            if a < self.first[b] { 0.0 } else { self.uval[self.uptr[b] + (a - self.first[b])] }
        } else if b < self.first[a] {
            0.0
        } else {
            self.lval[self.lptr[a] + (b - self.first[a])]
        }
    }
}

impl LinearSolver for SkylineLu {
    fn set_dimension(&mut self, n: usize) {
        self.n = n;
        self.order = Vec::with_capacity(n);
        self.inverse = vec![0; n];
        self.first = vec![0; n];
        self.lptr = vec![0; n + 1];
        self.uptr = vec![0; n + 1];
        // sized by `set_pointers` to the profile
        self.lval = Vec::new();
        self.uval = Vec::new();
        self.work = vec![0.0; n];
        self.inv_diag = vec![0.0; n];
        self.floor = vec![0.0; n];
        self.diag_abs = vec![0.0; n];
        self.inv_diag_abs = vec![0.0; n];
        self.group_width = vec![1; n];
        self.is_multiplier = vec![false; n];
        self.last_coupled = vec![0; n];
        self.contiguous = vec![false; n];
        self.contiguity_known = false;
        self.ordered = false;
        self.dense.set_dimension(n);
        if let Some((_, adj)) = &self.structure {
            assert_eq!(adj.len(), n, "SkylineLu: the structure has the wrong dimension");
            self.order_from_structure();
            self.direct_ok = self.set_pointers();
        }
    }

    fn factorize(&mut self, a: &DenseMatrix) -> Result<(), usize> {
        assert!(a.n_rows() == self.n && a.n_cols() == self.n, "factorize: dimension mismatch");
        if self.factorize_skyline(a.as_slice()) {
            self.use_dense = false;
            self.n_skyline += 1;
            Ok(())
        } else {
            self.use_dense = true;
            self.n_dense += 1;
            self.dense.factorize(a)
        }
    }

    fn assembly_target(&mut self) -> Option<&mut dyn AssemblyTarget> {
        if self.direct_ok { Some(self) } else { None }
    }

    /// The fallback's sparse LU with pivoting (large matrices the skyline cannot take).
    fn factorize_entries(&mut self, entries: &Entries) -> Result<bool, usize> {
        let done = self.dense.factorize_entries(entries)?;
        if done {
            self.use_dense = true;
            self.n_dense += 1;
        }
        Ok(done)
    }

    fn factorize_assembled(&mut self) -> Result<Assembled, usize> {
        if self.direct_outside {
            // the structure given by the model is incomplete: scan dense matrices from now on
            self.direct_ok = false;
            self.structure = None;
            self.ordered = false;
            self.contiguity_known = false;
            return Ok(Assembled::UseDense);
        }
        if !self.factor_in_place(self.direct_symmetric) {
            return Ok(Assembled::UseDense); // tiny pivot: the dense path retries and falls back
        }
        self.use_dense = false;
        self.n_skyline += 1;
        Ok(Assembled::Factorized)
    }

    fn solve_in_place(&mut self, b: &mut [f64]) {
        assert!(b.len() == self.n, "solve: dimension mismatch");
        if self.use_dense {
            self.dense.solve_in_place(b);
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            unsafe { self.solve_skyline_avx2(b) };
            return;
        }
        self.solve_skyline(b)
    }
}

impl SkylineLu {
    /// [`Self::solve_skyline`] compiled with AVX2 (the same arithmetic, see
    /// [`Self::factor_in_place_avx2`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_skyline_avx2(&mut self, b: &mut [f64]) {
        self.solve_skyline(b)
    }

    /// Forward and backward substitution with the skyline factors.
    #[inline(always)]
    fn solve_skyline(&mut self, b: &mut [f64]) {
        let n = self.n;
        let y = &mut self.work;
        // L y = P b, rows with a common profile start in fours or pairs (fours only where they
        // sum like two pairs: an even number of terms before the first row)
        let mut i = 0;
        while i < n {
            let fi = self.first[i];
            let l0 = &self.lval[self.lptr[i]..self.lptr[i] + (i - fi)];
            let run = self.first[i..n.min(i + 4)].iter().take_while(|&&x| x == fi).count();
            if run == 4 && (i - fi).is_multiple_of(2) {
                let m = i - fi;
                let row = |r: usize| &self.lval[self.lptr[i + r]..self.lptr[i + r] + (m + r)];
                let (l1, l2, l3) = (row(1), row(2), row(3));
                let (mut e, mut o) = ([0.0; 4], [0.0; 4]);
                for ((((a, b), c), d), z) in l0
                    .chunks_exact(2)
                    .zip(l1.chunks_exact(2))
                    .zip(l2.chunks_exact(2))
                    .zip(l3.chunks_exact(2))
                    .zip(y[fi..i].chunks_exact(2))
                {
                    for (r, x) in [a, b, c, d].into_iter().enumerate() {
                        e[r] += x[0] * z[0];
                        o[r] += x[1] * z[1];
                    }
                }
                let y0 = b[self.order[i]] - (e[0] + o[0]);
                let y1 = b[self.order[i + 1]] - (e[1] + o[1]) - l1[m] * y0;
                e[2] += l2[m] * y0;
                o[2] += l2[m + 1] * y1;
                e[3] += l3[m] * y0;
                o[3] += l3[m + 1] * y1;
                let y2 = b[self.order[i + 2]] - (e[2] + o[2]);
                let y3 = b[self.order[i + 3]] - (e[3] + o[3]) - l3[m + 2] * y2;
                y[i..i + 4].copy_from_slice(&[y0, y1, y2, y3]);
                i += 4;
            } else if run >= 2 {
                let l1 = &self.lval[self.lptr[i + 1]..self.lptr[i + 1] + (i + 1 - fi)];
                let (s0, s1) = dot2(l0, &l1[..i - fi], &y[fi..i]);
                let y0 = b[self.order[i]] - s0;
                y[i] = y0;
                y[i + 1] = b[self.order[i + 1]] - s1 - l1[i - fi] * y0;
                i += 2;
            } else {
                y[i] = b[self.order[i]] - dot(l0, &y[fi..i]);
                i += 1;
            }
        }
        // U x = y by columns, columns with a common profile start in fours or pairs (a four
        // updates every entry in the same order as two pairs)
        let mut j = n;
        while j > 0 {
            j -= 1;
            let fj = self.first[j];
            let col = |c: usize| &self.uval[self.uptr[c]..self.uptr[c] + (c - fj)];
            let uj = col(j);
            let xj = y[j] * self.inv_diag[j];
            y[j] = xj;
            let same = |c: usize| self.first[c] == fj;
            if j > fj + 2 && same(j - 1) && same(j - 2) && same(j - 3) {
                let (uj1, uj2, uj3) = (col(j - 1), col(j - 2), col(j - 3));
                let xj1 = (y[j - 1] - uj[j - 1 - fj] * xj) * self.inv_diag[j - 1];
                y[j - 1] = xj1;
                for k in [j - 2, j - 3] {
                    y[k] -= uj[k - fj] * xj + uj1[k - fj] * xj1;
                }
                let xj2 = y[j - 2] * self.inv_diag[j - 2];
                y[j - 2] = xj2;
                let xj3 = (y[j - 3] - uj2[j - 3 - fj] * xj2) * self.inv_diag[j - 3];
                y[j - 3] = xj3;
                for ((((yk, u0), u1), u2), u3) in y[fj..j - 3].iter_mut().zip(uj).zip(uj1).zip(uj2).zip(uj3) {
                    *yk = (*yk - (u0 * xj + u1 * xj1)) - (u2 * xj2 + u3 * xj3);
                }
                j -= 3;
            } else if j > fj && same(j - 1) {
                let uj1 = col(j - 1);
                let xj1 = (y[j - 1] - uj[j - 1 - fj] * xj) * self.inv_diag[j - 1];
                y[j - 1] = xj1;
                for ((yk, u0), u1) in y[fj..j - 1].iter_mut().zip(uj).zip(uj1) {
                    *yk -= u0 * xj + u1 * xj1;
                }
                j -= 1;
            } else {
                for (yk, u) in y[fj..j].iter_mut().zip(uj) {
                    *yk -= u * xj;
                }
            }
        }
        for i in 0..n {
            b[self.order[i]] = y[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn solve_both(a: &DenseMatrix, b: &[f64]) -> (Vec<f64>, Vec<f64>, usize) {
        let n = a.n_rows();
        let mut s = SkylineLu::new();
        s.set_dimension(n);
        s.factorize(a).unwrap();
        let mut x = b.to_vec();
        s.solve_in_place(&mut x);
        let mut d = DenseLu::default();
        d.set_dimension(n);
        d.factorize(a).unwrap();
        let mut y = b.to_vec();
        d.solve_in_place(&mut y);
        (x, y, s.n_skyline)
    }

    /// A banded SPD matrix with a saddle-point border (two multiplier rows coupling to the
    /// first and the middle unknowns), like a constrained ANCF iteration matrix.
    /// The symmetric non-zero structure of `a`, as `SkylineLu::with_structure` takes it.
    fn adjacency_of(a: &DenseMatrix) -> Vec<Vec<usize>> {
        let n = a.n_rows();
        (0..n).map(|i| (0..n).filter(|&j| a.get(i, j) != 0.0 || a.get(j, i) != 0.0).collect()).collect()
    }

    fn kkt(n: usize, bw: usize) -> DenseMatrix {
        let m = n + 2;
        let mut a = DenseMatrix::zeros(m, m);
        for i in 0..n {
            for j in i.saturating_sub(bw)..(i + bw + 1).min(n) {
                let v = if i == j { 10.0 + i as f64 * 0.1 } else { 1.0 / (1.0 + (i + 2 * j) as f64) };
                *a.get_mut(i, j) = v;
                *a.get_mut(j, i) = v;
            }
        }
        for (row, cols) in [(n, [0usize, 1]), (n + 1, [n / 2, n / 2 + 1])] {
            for (k, c) in cols.iter().enumerate() {
                *a.get_mut(row, *c) = 1.0 + k as f64;
                *a.get_mut(*c, row) = 1.0 + k as f64;
            }
        }
        a
    }

    #[test]
    fn matches_dense_lu_on_a_banded_saddle_point_matrix() {
        let a = kkt(60, 5);
        let b: Vec<f64> = (0..62).map(|i| (i as f64 * 0.37).sin()).collect();
        let (x, y, n_skyline) = solve_both(&a, &b);
        assert_eq!(n_skyline, 1, "the skyline path must be taken");
        for (p, q) in x.iter().zip(&y) {
            assert_relative_eq!(p, q, epsilon = 1e-12, max_relative = 1e-10);
        }
        // the same with the structure given up front
        let adjacency = adjacency_of(&a);
        let mut s = SkylineLu::with_structure(60, adjacency);
        s.set_dimension(62);
        s.factorize(&a).unwrap();
        let mut z = b.to_vec();
        s.solve_in_place(&mut z);
        assert_eq!(s.n_skyline, 1);
        for (p, q) in z.iter().zip(&y) {
            assert_relative_eq!(p, q, epsilon = 1e-12, max_relative = 1e-10);
        }
    }

    #[test]
    fn symmetry_hint_skips_the_check_only_while_set() {
        let a = kkt(40, 4);
        let b: Vec<f64> = (0..42).map(|i| (i as f64 * 0.21).cos()).collect();
        let (_, y, _) = solve_both(&a, &b);
        let adjacency = adjacency_of(&a);
        let flag = Arc::new(AtomicBool::new(true));
        let mut s = SkylineLu::with_structure(40, adjacency).with_symmetry_hint(Arc::clone(&flag));
        s.set_dimension(42);
        s.factorize(&a).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        for (p, q) in x.iter().zip(&y) {
            assert_relative_eq!(p, q, epsilon = 1e-12, max_relative = 1e-10);
        }
        // an unsymmetric matrix with the flag cleared is checked and solved as such
        let mut c = a.clone();
        *c.get_mut(3, 5) += 0.25;
        let (_, y, _) = solve_both(&c, &b);
        flag.store(false, Ordering::Relaxed);
        s.factorize(&c).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        for (p, q) in x.iter().zip(&y) {
            assert_relative_eq!(p, q, epsilon = 1e-12, max_relative = 1e-10);
        }
    }

    /// The KKT matrix assembled straight into the envelope (symmetric blocks by their upper
    /// triangle, the rest entry by entry) solves bit for bit like the gathered one, with the
    /// symmetry hint set and cleared; an entry outside the structure asks for the dense path.
    #[test]
    fn direct_assembly_matches_the_gather() {
        let a = kkt(40, 4);
        let b: Vec<f64> = (0..42).map(|i| (i as f64 * 0.13).sin()).collect();
        let adjacency = adjacency_of(&a);
        for (symmetric, unsymmetric_entry) in [(true, 0.0), (false, 0.0), (false, 0.25)] {
            let mut c = a.clone();
            *c.get_mut(3, 5) += unsymmetric_entry;
            let flag = Arc::new(AtomicBool::new(symmetric));
            let mut gathered = SkylineLu::with_structure(40, adjacency.clone()).with_symmetry_hint(Arc::clone(&flag));
            gathered.set_dimension(42);
            gathered.factorize(&c).unwrap();
            let mut x_gathered = b.clone();
            gathered.solve_in_place(&mut x_gathered);

            let mut direct = SkylineLu::with_structure(40, adjacency.clone()).with_symmetry_hint(Arc::clone(&flag));
            direct.set_dimension(42);
            let target = direct.assembly_target().expect("a known structure offers direct assembly");
            target.clear();
            // the coordinate block as 8 × 8 symmetric blocks on the diagonal (upper triangle) plus
            // the couplings between them, then the constraint rows and columns
            // (the unsymmetric matrix goes entry by entry)
            let blocks = if unsymmetric_entry == 0.0 { 5 } else { 0 };
            let mut blk = vec![0.0; 64];
            for k in 0..blocks {
                for cc in 0..8 {
                    for r in 0..8 {
                        blk[cc * 8 + r] = if r <= cc { c.get(8 * k + r, 8 * k + cc) } else { f64::NAN };
                    }
                }
                target.add_symmetric_upper(8 * k, 8, &blk, 1.0);
            }
            for j in 0..42 {
                for i in 0..42 {
                    let same_block = i < 8 * blocks && j < 8 * blocks && i / 8 == j / 8;
                    let x = c.get(i, j);
                    if !same_block && x != 0.0 {
                        target.add(i, j, x);
                    }
                }
            }
            if !symmetric {
                // lower triangles are kept while the hint is off
                assert_eq!(target.get(5, 3), c.get(5, 3));
            }
            assert_eq!(direct.factorize_assembled(), Ok(Assembled::Factorized));
            let mut x_direct = b.clone();
            direct.solve_in_place(&mut x_direct);
            assert_eq!(x_direct, x_gathered, "symmetric hint {symmetric}, extra entry {unsymmetric_entry}");
        }
        let mut s = SkylineLu::with_structure(40, adjacency);
        s.set_dimension(42);
        let target = s.assembly_target().unwrap();
        target.clear();
        target.add(0, 30, 1.0);
        assert_eq!(s.factorize_assembled(), Ok(Assembled::UseDense));
        assert!(s.assembly_target().is_none());
    }

    /// A block-tridiagonal SPD matrix in `nb` blocks of `bs` unknowns (like node-ordered ANCF
    /// coordinates: every unknown of block k couples to blocks k − 1..=k + 1), with two
    /// multiplier rows coupling to a few unknowns in the middle of blocks 0 and 2.
    fn block_kkt(nb: usize, bs: usize) -> DenseMatrix {
        let n = nb * bs;
        let mut a = DenseMatrix::zeros(n + 2, n + 2);
        for i in 0..n {
            for j in 0..n {
                if i.abs_diff(j) < 2 * bs && (i / bs).abs_diff(j / bs) <= 1 {
                    let v = if i == j { 20.0 + (i % 7) as f64 } else { 1.0 / (2.0 + ((i * j) % 11) as f64) };
                    *a.get_mut(i, j) = v;
                }
            }
        }
        for (row, cols) in [(n, [1usize, 3]), (n + 1, [2 * bs + 2, 2 * bs + 5])] {
            for (k, c) in cols.iter().enumerate() {
                *a.get_mut(row, *c) = 1.0 + k as f64;
                *a.get_mut(*c, row) = 1.0 + k as f64;
            }
        }
        a
    }

    /// Runs of columns with a common profile start (panels of 4 to 12 columns, pairs, single
    /// columns after the multiplier rows) solve like the dense LU, through the symmetric path.
    #[test]
    fn panels_of_node_blocks_match_dense_lu() {
        for (nb, bs) in [(12, 12), (12, 7), (12, 5), (12, 3), (12, 16)] {
            let a = block_kkt(nb, bs);
            let m = nb * bs + 2;
            let b: Vec<f64> = (0..m).map(|i| (i as f64 * 0.29).sin()).collect();
            let (_, y, _) = solve_both(&a, &b);
            let adjacency = adjacency_of(&a);
            for hint in [true, false] {
                let flag = Arc::new(AtomicBool::new(hint));
                let mut s = SkylineLu::with_structure(nb * bs, adjacency.clone()).with_symmetry_hint(flag);
                s.set_dimension(m);
                s.factorize(&a).unwrap();
                assert_eq!(s.n_skyline, 1, "blocks {nb} x {bs}: the skyline path must be taken");
                let mut x = b.clone();
                s.solve_in_place(&mut x);
                for (p, q) in x.iter().zip(&y) {
                    assert_relative_eq!(p, q, epsilon = 1e-13, max_relative = 1e-11);
                }
            }
        }
    }

    /// A stiff structure's constraint pivots are the inverse of its stiffness: with diagonals of
    /// 1e9 the multiplier rows' pivots are about 1e-9, far below 1e-13 of the largest diagonal,
    /// yet not singular. The skyline path takes them (nalgebra's fully pivoted LU agrees), and a
    /// repeated constraint row, which is singular, still goes to the dense fallback.
    #[test]
    fn stiff_constraint_pivots_stay_on_the_skyline() {
        let mut a = kkt(60, 5);
        for i in 0..60 {
            for j in 0..60 {
                let v = a.get(i, j);
                *a.get_mut(i, j) = 1e8 * v;
            }
        }
        let b: Vec<f64> = (0..62).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut s = SkylineLu::new();
        s.set_dimension(62);
        s.factorize(&a).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&mut x);
        assert_eq!((s.n_skyline, s.n_dense), (1, 0), "the skyline path must be taken");
        let full = nalgebra::DMatrix::from_fn(62, 62, |i, j| a.get(i, j));
        let y = full.full_piv_lu().solve(&nalgebra::DVector::from_vec(b.clone())).unwrap();
        let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (p, q) in x.iter().zip(&y) {
            assert!((p - q).abs() <= 1e-10 * scale, "{p} vs {q}");
        }
        // The second multiplier row made a copy of the first: singular.
        for c in 0..62 {
            let v = a.get(60, c);
            *a.get_mut(61, c) = v;
            *a.get_mut(c, 61) = v;
        }
        let mut s = SkylineLu::new();
        s.set_dimension(62);
        let _ = s.factorize(&a);
        assert_eq!((s.n_skyline, s.n_dense), (0, 1));
    }

    #[test]
    fn falls_back_to_dense_for_a_zero_pivot() {
        // [[0 1], [1 0]] has zero diagonals but no coupling that could be reordered.
        let mut a = DenseMatrix::zeros(2, 2);
        *a.get_mut(0, 1) = 1.0;
        *a.get_mut(1, 0) = 1.0;
        let mut s = SkylineLu::new();
        s.set_dimension(2);
        s.factorize(&a).unwrap();
        let mut x = vec![2.0, 3.0];
        s.solve_in_place(&mut x);
        assert_eq!(s.n_dense, 1);
        assert_relative_eq!(x[0], 3.0, epsilon = 1e-15);
        assert_relative_eq!(x[1], 2.0, epsilon = 1e-15);
    }
}
