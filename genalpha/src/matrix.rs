//! The assembled matrix the models write into, and views of its blocks.

use nalgebra::SMatrix;

/// Dense column-major matrix owned by the integrator's workspace.
///
/// Models never see the linear-algebra backend: they add entries through a [`MatView`].
#[derive(Debug, Clone, PartialEq)]
pub struct DenseMatrix {
    n_rows: usize,
    n_cols: usize,
    data: Vec<f64>,
}

impl DenseMatrix {
    /// A zero matrix.
    pub fn zeros(n_rows: usize, n_cols: usize) -> Self {
        Self { n_rows, n_cols, data: vec![0.0; n_rows * n_cols] }
    }
    /// Number of rows.
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }
    /// Number of columns.
    pub fn n_cols(&self) -> usize {
        self.n_cols
    }
    /// Set every entry to zero.
    pub fn fill_zero(&mut self) {
        self.data.iter_mut().for_each(|x| *x = 0.0);
    }
    /// Entry (i, j).
    ///
    /// # Panics
    /// When (i, j) is out of range.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.n_rows && j < self.n_cols);
        self.data[j * self.n_rows + i]
    }
    /// Mutable entry (i, j).
    ///
    /// # Panics
    /// When (i, j) is out of range.
    #[inline]
    pub fn get_mut(&mut self, i: usize, j: usize) -> &mut f64 {
        assert!(i < self.n_rows && j < self.n_cols);
        &mut self.data[j * self.n_rows + i]
    }
    /// Column-major storage.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }
    /// Mutable column-major storage.
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.data
    }
    /// A view of the whole matrix.
    pub fn view(&mut self) -> MatView<'_> {
        let (r, c) = (self.n_rows, self.n_cols);
        MatView { m: Target::Dense(self), row0: 0, col0: 0, n_rows: r, n_cols: c, scale: 1.0 }
    }
    /// A view of the block starting at (row0, col0) with the given size.
    ///
    /// # Panics
    /// When the block does not fit.
    pub fn block(&mut self, row0: usize, col0: usize, n_rows: usize, n_cols: usize) -> MatView<'_> {
        assert!(row0 + n_rows <= self.n_rows && col0 + n_cols <= self.n_cols);
        MatView { m: Target::Dense(self), row0, col0, n_rows, n_cols, scale: 1.0 }
    }
    /// y = A x.
    ///
    /// # Panics
    /// On dimension mismatch.
    pub fn mul_vec_inplace(&self, x: &[f64], y: &mut [f64]) {
        assert!(x.len() == self.n_cols && y.len() == self.n_rows);
        y.iter_mut().for_each(|v| *v = 0.0);
        for (j, xj) in x.iter().enumerate() {
            if *xj == 0.0 {
                continue;
            }
            let col = &self.data[j * self.n_rows..(j + 1) * self.n_rows];
            for (yi, aij) in y.iter_mut().zip(col) {
                *yi += aij * xj;
            }
        }
    }
    /// y += Aᵀ x.
    ///
    /// # Panics
    /// On dimension mismatch.
    pub fn add_mul_transpose_vec_inplace(&self, x: &[f64], y: &mut [f64]) {
        assert!(x.len() == self.n_rows && y.len() == self.n_cols);
        for (j, yj) in y.iter_mut().enumerate() {
            let col = &self.data[j * self.n_rows..(j + 1) * self.n_rows];
            *yj += col.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        }
    }
}

/// Storage a linear solver offers for assembling the iteration matrix in place (its band or
/// profile), so that the integrator need not fill and copy a dense `n × n` matrix.
///
/// Indices are those of the assembled matrix (coordinates, then multipliers). An entry outside
/// the storage's structure must not be dropped silently: the target remembers it and the next
/// [`LinearSolver::factorize_assembled`](crate::LinearSolver::factorize_assembled) asks for the
/// dense path instead.
pub trait AssemblyTarget {
    /// Zero every stored entry (before an assembly).
    fn clear(&mut self);
    /// A(i, j) += v.
    fn add(&mut self, i: usize, j: usize, v: f64);
    /// `A[i0 + r, j0 + c] += s · block[c · n_r + r]` (column-major `n_r × n_c` block).
    fn add_slice(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, block: &[f64], s: f64) {
        for c in 0..n_c {
            for r in 0..n_r {
                let x = block[c * n_r + r];
                if x != 0.0 {
                    self.add(i0 + r, j0 + c, s * x);
                }
            }
        }
    }
    /// `A[i0 + r, j0 + c] += s · data[c · ld + r]` for `r < n_r`, `c < n_c`: a sub-block of a
    /// column-major matrix with leading dimension `ld`. Default: one [`add_slice`](Self::add_slice)
    /// per column.
    #[allow(clippy::too_many_arguments)]
    fn add_submatrix(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, data: &[f64], ld: usize, s: f64) {
        for c in 0..n_c {
            self.add_slice(i0, j0 + c, n_r, 1, &data[c * ld..c * ld + n_r], s);
        }
    }
    /// Add `s · block` for a symmetric `n_b × n_b` block on the diagonal at (i0, i0), given by
    /// its upper triangle only (`block[c · n_b + r]` for `r ≤ c`; the strictly lower part is
    /// ignored). A target that stores one triangle of a symmetric matrix writes it once.
    fn add_symmetric_upper(&mut self, i0: usize, n_b: usize, block: &[f64], s: f64) {
        for c in 0..n_b {
            for r in 0..=c {
                let x = block[c * n_b + r];
                if x != 0.0 {
                    self.add(i0 + r, i0 + c, s * x);
                    if r != c {
                        self.add(i0 + c, i0 + r, s * x);
                    }
                }
            }
        }
    }
    /// `A[idx[r], idx[c]] += s · block[c · n + r]` for a symmetric `n × n` block (`n =
    /// idx.len()`, both triangles given) at the increasing indices `idx`. A target that stores
    /// one triangle of a symmetric matrix reads only the upper one.
    fn add_symmetric_indexed(&mut self, idx: &[usize], block: &[f64], s: f64) {
        let n = idx.len();
        for (c, &j) in idx.iter().enumerate() {
            for (r, &i) in idx.iter().enumerate() {
                let x = block[c * n + r];
                if x != 0.0 {
                    self.add(i, j, s * x);
                }
            }
        }
    }
    /// Entry (i, j) as assembled so far (0 outside the structure).
    fn get(&self, i: usize, j: usize) -> f64;
}

/// Where a [`MatView`] writes.
enum Target<'a> {
    Dense(&'a mut DenseMatrix),
    Direct(&'a mut dyn AssemblyTarget),
}

impl std::fmt::Debug for Target<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Dense(m) => write!(f, "Dense({}x{})", m.n_rows, m.n_cols),
            Self::Direct(_) => write!(f, "Direct"),
        }
    }
}

/// A mutable window into the assembled matrix (a [`DenseMatrix`] or a solver's own storage,
/// an [`AssemblyTarget`]) that scales everything added to it.
///
/// Models write their Jacobians through `add`; the integrator decides where the block sits in
/// the assembled matrix and by which factor it is multiplied.
#[derive(Debug)]
pub struct MatView<'a> {
    m: Target<'a>,
    row0: usize,
    col0: usize,
    n_rows: usize,
    n_cols: usize,
    scale: f64,
}

impl<'a> MatView<'a> {
    /// A view of the block at (row0, col0) of the given size in a solver's storage.
    pub fn direct(target: &'a mut dyn AssemblyTarget, row0: usize, col0: usize, n_rows: usize, n_cols: usize) -> Self {
        MatView { m: Target::Direct(target), row0, col0, n_rows, n_cols, scale: 1.0 }
    }
}

impl MatView<'_> {
    /// Rows of the view.
    pub fn n_rows(&self) -> usize {
        self.n_rows
    }
    /// Columns of the view.
    pub fn n_cols(&self) -> usize {
        self.n_cols
    }
    fn reborrow(&mut self) -> Target<'_> {
        match &mut self.m {
            Target::Dense(m) => Target::Dense(m),
            Target::Direct(t) => Target::Direct(&mut **t),
        }
    }
    /// The same window with every addition multiplied by `s` (on top of the current factor).
    pub fn scaled(&mut self, s: f64) -> MatView<'_> {
        let (row0, col0, n_rows, n_cols, scale) = (self.row0, self.col0, self.n_rows, self.n_cols, self.scale * s);
        MatView { m: self.reborrow(), row0, col0, n_rows, n_cols, scale }
    }
    /// A sub-window at (i0, j0) of this view.
    ///
    /// # Panics
    /// When the sub-block does not fit.
    pub fn sub(&mut self, i0: usize, j0: usize, n_rows: usize, n_cols: usize) -> MatView<'_> {
        assert!(i0 + n_rows <= self.n_rows && j0 + n_cols <= self.n_cols);
        let (row0, col0, scale) = (self.row0 + i0, self.col0 + j0, self.scale);
        MatView { m: self.reborrow(), row0, col0, n_rows, n_cols, scale }
    }
    /// A(i, j) += scale · v.
    ///
    /// # Panics
    /// When (i, j) is outside the view.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(i < self.n_rows && j < self.n_cols, "({i}, {j}) outside a {}x{} view", self.n_rows, self.n_cols);
        match &mut self.m {
            Target::Dense(m) => *m.get_mut(self.row0 + i, self.col0 + j) += self.scale * v,
            Target::Direct(t) => t.add(self.row0 + i, self.col0 + j, self.scale * v),
        }
    }
    /// Add a fixed-size block with its top-left corner at (i0, j0).
    ///
    /// # Panics
    /// When the block does not fit.
    #[inline]
    pub fn add_block<const R: usize, const C: usize>(&mut self, i0: usize, j0: usize, b: &SMatrix<f64, R, C>) {
        assert!(i0 + R <= self.n_rows && j0 + C <= self.n_cols);
        match &mut self.m {
            Target::Dense(m) => {
                let n = m.n_rows;
                for (c, bcol) in b.as_slice().chunks_exact(R).enumerate() {
                    let base = (self.col0 + j0 + c) * n + self.row0 + i0;
                    let col = &mut m.data[base..base + R];
                    for (x, y) in col.iter_mut().zip(bcol) {
                        *x += self.scale * y;
                    }
                }
            }
            Target::Direct(t) => t.add_slice(self.row0 + i0, self.col0 + j0, R, C, b.as_slice(), self.scale),
        }
    }
    /// Add a symmetric `N × N` block on the diagonal of the whole matrix at (i0, i0) of the view
    /// (the view's row and column offsets must be equal there), given by its upper triangle: the
    /// strictly lower part of `b` is ignored.
    ///
    /// # Panics
    /// When the block does not fit or does not sit on the matrix diagonal.
    #[inline]
    pub fn add_symmetric_upper<const N: usize>(&mut self, i0: usize, b: &SMatrix<f64, N, N>) {
        assert!(i0 + N <= self.n_rows && i0 + N <= self.n_cols && self.row0 == self.col0);
        match &mut self.m {
            Target::Dense(m) => {
                let (n, first) = (m.n_rows, self.row0 + i0);
                for c in 0..N {
                    for r in 0..=c {
                        let x = self.scale * b[(r, c)];
                        m.data[(first + c) * n + first + r] += x;
                        if r != c {
                            m.data[(first + r) * n + first + c] += x;
                        }
                    }
                }
            }
            Target::Direct(t) => t.add_symmetric_upper(self.row0 + i0, N, b.as_slice(), self.scale),
        }
    }
    /// Add `s · block` where `block` is a column-major `n_r × n_c` slice, at (i0, j0).
    ///
    /// # Panics
    /// When the block does not fit or the slice has the wrong length.
    pub fn add_slice(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, block: &[f64], s: f64) {
        assert!(block.len() == n_r * n_c, "a {n_r}x{n_c} block from {} values", block.len());
        self.add_submatrix(i0, j0, n_r, n_c, block, n_r, s);
    }
    /// Add `s · data[c · ld + r]` at (i0 + r, j0 + c) for `r < n_r`, `c < n_c`: a sub-block of a
    /// column-major matrix with leading dimension `ld` (e.g. some rows and columns of an element
    /// matrix).
    ///
    /// # Panics
    /// When the block does not fit or `data` is too short.
    #[allow(clippy::too_many_arguments)]
    pub fn add_submatrix(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, data: &[f64], ld: usize, s: f64) {
        assert!(i0 + n_r <= self.n_rows && j0 + n_c <= self.n_cols && n_r <= ld);
        assert!(n_c == 0 || data.len() >= (n_c - 1) * ld + n_r);
        match &mut self.m {
            Target::Dense(m) => {
                let n = m.n_rows;
                for c in 0..n_c {
                    let base = (self.col0 + j0 + c) * n + self.row0 + i0;
                    let col = &mut m.data[base..base + n_r];
                    for (x, b) in col.iter_mut().zip(&data[c * ld..c * ld + n_r]) {
                        *x += self.scale * s * b;
                    }
                }
            }
            Target::Direct(t) => t.add_submatrix(self.row0 + i0, self.col0 + j0, n_r, n_c, data, ld, self.scale * s),
        }
    }
    /// Add a symmetric `n × n` block (column-major, both triangles) at the rows and columns
    /// `idx` (increasing, `n = idx.len()`) of a view on the matrix diagonal.
    ///
    /// # Panics
    /// When an index is outside the view, `block` is too short, or the view is off the diagonal.
    pub fn add_symmetric_indexed(&mut self, idx: &[usize], block: &[f64]) {
        let n = idx.len();
        assert!(block.len() >= n * n && self.row0 == self.col0);
        assert!(idx.windows(2).all(|w| w[0] < w[1]) && idx.last().is_none_or(|&i| i < self.n_rows.min(self.n_cols)));
        match &mut self.m {
            Target::Dense(m) => {
                let nr = m.n_rows;
                for (c, &j) in idx.iter().enumerate() {
                    for (r, &i) in idx.iter().enumerate() {
                        m.data[(self.col0 + j) * nr + self.row0 + i] += self.scale * block[c * n + r];
                    }
                }
            }
            Target::Direct(t) => {
                if self.row0 == 0 {
                    t.add_symmetric_indexed(idx, block, self.scale);
                } else {
                    // (no offset index list without allocating: entry by entry)
                    for (c, &j) in idx.iter().enumerate() {
                        for (r, &i) in idx.iter().enumerate() {
                            t.add(self.row0 + i, self.col0 + j, self.scale * block[c * n + r]);
                        }
                    }
                }
            }
        }
    }
    /// Entry (i, j) of the view (unscaled value stored in the matrix).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        match &self.m {
            Target::Dense(m) => m.get(self.row0 + i, self.col0 + j),
            Target::Direct(t) => t.get(self.row0 + i, self.col0 + j),
        }
    }
}
