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
        MatView { m: self, row0: 0, col0: 0, n_rows: r, n_cols: c, scale: 1.0 }
    }
    /// A view of the block starting at (row0, col0) with the given size.
    ///
    /// # Panics
    /// When the block does not fit.
    pub fn block(&mut self, row0: usize, col0: usize, n_rows: usize, n_cols: usize) -> MatView<'_> {
        assert!(row0 + n_rows <= self.n_rows && col0 + n_cols <= self.n_cols);
        MatView { m: self, row0, col0, n_rows, n_cols, scale: 1.0 }
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

/// A mutable window into a [`DenseMatrix`] that scales everything added to it.
///
/// Models write their Jacobians through `add`; the integrator decides where the block sits in
/// the assembled matrix and by which factor it is multiplied.
#[derive(Debug)]
pub struct MatView<'a> {
    m: &'a mut DenseMatrix,
    row0: usize,
    col0: usize,
    n_rows: usize,
    n_cols: usize,
    scale: f64,
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
    /// The same window with every addition multiplied by `s` (on top of the current factor).
    pub fn scaled(&mut self, s: f64) -> MatView<'_> {
        MatView {
            m: self.m,
            row0: self.row0,
            col0: self.col0,
            n_rows: self.n_rows,
            n_cols: self.n_cols,
            scale: self.scale * s,
        }
    }
    /// A sub-window at (i0, j0) of this view.
    ///
    /// # Panics
    /// When the sub-block does not fit.
    pub fn sub(&mut self, i0: usize, j0: usize, n_rows: usize, n_cols: usize) -> MatView<'_> {
        assert!(i0 + n_rows <= self.n_rows && j0 + n_cols <= self.n_cols);
        MatView { m: self.m, row0: self.row0 + i0, col0: self.col0 + j0, n_rows, n_cols, scale: self.scale }
    }
    /// A(i, j) += scale · v.
    ///
    /// # Panics
    /// When (i, j) is outside the view.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(i < self.n_rows && j < self.n_cols, "({i}, {j}) outside a {}x{} view", self.n_rows, self.n_cols);
        *self.m.get_mut(self.row0 + i, self.col0 + j) += self.scale * v;
    }
    /// Add a fixed-size block with its top-left corner at (i0, j0).
    ///
    /// # Panics
    /// When the block does not fit.
    #[inline]
    pub fn add_block<const R: usize, const C: usize>(&mut self, i0: usize, j0: usize, b: &SMatrix<f64, R, C>) {
        assert!(i0 + R <= self.n_rows && j0 + C <= self.n_cols);
        let n = self.m.n_rows;
        for (c, bcol) in b.as_slice().chunks_exact(R).enumerate() {
            let base = (self.col0 + j0 + c) * n + self.row0 + i0;
            let col = &mut self.m.data[base..base + R];
            for (x, y) in col.iter_mut().zip(bcol) {
                *x += self.scale * y;
            }
        }
    }
    /// Add `s · block` where `block` is a column-major `n_r × n_c` slice, at (i0, j0).
    ///
    /// # Panics
    /// When the block does not fit or the slice has the wrong length.
    pub fn add_slice(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, block: &[f64], s: f64) {
        assert!(i0 + n_r <= self.n_rows && j0 + n_c <= self.n_cols && block.len() == n_r * n_c);
        let n = self.m.n_rows;
        for c in 0..n_c {
            let base = (self.col0 + j0 + c) * n + self.row0 + i0;
            let col = &mut self.m.data[base..base + n_r];
            for (x, b) in col.iter_mut().zip(&block[c * n_r..(c + 1) * n_r]) {
                *x += self.scale * s * b;
            }
        }
    }
    /// Entry (i, j) of the view (unscaled value stored in the matrix).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.m.get(self.row0 + i, self.col0 + j)
    }
}
