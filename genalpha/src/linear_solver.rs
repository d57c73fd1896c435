//! The linear-solver seam: symbolic set-up once, numeric factorisation per Newton matrix,
//! solve in place. faer types never leave this file.

use crate::banded::{BandedBorder, BorderedBandLu};
use crate::{AssemblyTarget, DenseMatrix};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::{PartialPivLuParams, lu_in_place, lu_in_place_scratch};
use faer::linalg::lu::partial_pivoting::solve::{solve_in_place, solve_in_place_scratch};
use faer::perm::PermRef;
use faer::{Mat, MatMut, MatRef, Par, Spec};

/// A linear solver with the three phases of diffsol's `LinearSolver`.
pub trait LinearSolver {
    /// Prepare for matrices of dimension `n` (symbolic analysis; called once per topology).
    fn set_dimension(&mut self, n: usize);
    /// The structure the system declared (called after `set_dimension`). Default: ignored.
    fn set_structure(&mut self, _structure: &BandedBorder) {}
    /// Factorise `a`. Returns the first zero pivot row if `a` is singular.
    fn factorize(&mut self, a: &DenseMatrix) -> Result<(), usize>;
    /// Overwrite `b` with `A⁻¹ b` for the last factorised `A`.
    fn solve_in_place(&mut self, b: &mut [f64]);
    /// The solver's own storage, if it lets the integrator assemble the iteration matrix into
    /// it directly (then [`factorize_assembled`](Self::factorize_assembled) factorises it).
    /// Default: none — the integrator assembles a [`DenseMatrix`] and calls
    /// [`factorize`](Self::factorize).
    fn assembly_target(&mut self) -> Option<&mut dyn AssemblyTarget> {
        None
    }
    /// Factorise what was assembled into [`assembly_target`](Self::assembly_target) since its
    /// last `clear`. [`Assembled::UseDense`] asks the integrator to assemble the same matrix
    /// densely and call [`factorize`](Self::factorize) instead (an entry fell outside the
    /// storage, or the structured factorisation met a tiny pivot and wants its dense fallback).
    fn factorize_assembled(&mut self) -> Result<Assembled, usize> {
        Ok(Assembled::UseDense)
    }
    /// Factorise the matrix held as entries (with pivoting, in memory proportional to its
    /// non-zeros): the fallback of a structured factorisation that met a tiny pivot, without
    /// an `n × n` matrix. Returns false when the solver has no such factorisation (then the
    /// integrator assembles the matrix densely). Default: false.
    fn factorize_entries(&mut self, _entries: &Entries) -> Result<bool, usize> {
        Ok(false)
    }
}

/// A square matrix as a list of entries (row, column, value; repeated positions add up), filled
/// through [`AssemblyTarget`]: the assembly of a fallback factorisation without `n²` storage.
#[derive(Debug, Clone, Default)]
pub struct Entries {
    n: usize,
    triplets: Vec<faer::sparse::Triplet<usize, usize, f64>>,
}

impl Entries {
    /// An empty `n × n` matrix.
    pub fn new(n: usize) -> Self {
        Self { n, triplets: Vec::new() }
    }
    /// The number of entries held (repeated positions counted each time).
    pub fn len(&self) -> usize {
        self.triplets.len()
    }
    /// True when no entry is held.
    pub fn is_empty(&self) -> bool {
        self.triplets.is_empty()
    }
}

impl AssemblyTarget for Entries {
    fn clear(&mut self) {
        self.triplets.clear();
    }
    fn add(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(i < self.n && j < self.n, "Entries::add: ({i}, {j}) outside {0} × {0}", self.n);
        if v != 0.0 {
            self.triplets.push(faer::sparse::Triplet { row: i, col: j, val: v });
        }
    }
    fn get(&self, i: usize, j: usize) -> f64 {
        self.triplets.iter().filter(|t| t.row == i && t.col == j).map(|t| t.val).sum()
    }
}

/// Outcome of [`LinearSolver::factorize_assembled`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Assembled {
    /// Factorised; solves may follow.
    Factorized,
    /// Not factorised: assemble densely and call [`LinearSolver::factorize`].
    UseDense,
}

/// Direct assembly into the bordered band storage (offered whenever a structure is declared; an
/// entry outside it sends that matrix to the dense path).
impl AssemblyTarget for DenseLu {
    fn clear(&mut self) {
        if let Some(s) = &mut self.structured {
            s.clear();
        }
    }
    #[inline]
    fn add(&mut self, i: usize, j: usize, v: f64) {
        if let Some(s) = &mut self.structured {
            s.add(i, j, v);
        }
    }
    fn add_slice(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, block: &[f64], s: f64) {
        if let Some(st) = &mut self.structured {
            st.add_slice(i0, j0, n_r, n_c, block, s);
        }
    }
    fn add_submatrix(&mut self, i0: usize, j0: usize, n_r: usize, n_c: usize, data: &[f64], ld: usize, s: f64) {
        if let Some(st) = &mut self.structured {
            st.add_submatrix(i0, j0, n_r, n_c, data, ld, s);
        }
    }
    fn get(&self, i: usize, j: usize) -> f64 {
        self.structured.as_ref().map_or(0.0, |s| s.get(i, j))
    }
}

/// Largest dimension the dense LU (and every dense fallback built on it) factorises densely:
/// above it a matrix that the structured factorisation cannot take goes to faer's sparse LU
/// (with pivoting) instead of an `n³`-time, `8 n²`-byte dense one.
pub const DENSE_FALLBACK_MAX: usize = 4000;

/// Dense LU with partial pivoting (faer, sequential, in place). Its `n × n` storage is allocated
/// at the first dense factorisation, so a solver that only ever takes the structured path never
/// holds it; matrices larger than [`DENSE_FALLBACK_MAX`] are factorised by faer's sparse LU
/// (allocating per factorisation: a fallback, not the time loop's path).
///
/// If the system declares a [`BandedBorder`] structure, the matrix is factorised by the
/// bordered band LU instead (block-banded part without pivoting, by 6×6 node blocks when the
/// structure declares nodes; dense Schur complement of the border); a tiny band pivot makes that
/// factorisation fall back to the dense one.
pub struct DenseLu {
    n: usize,
    structured: Option<BorderedBandLu>,
    /// The structure was checked against an actual matrix.
    structure_checked: bool,
    /// The last factorisation is the structured one.
    use_structured: bool,
    lu: Mat<f64>,
    /// The sparse LU of the last factorisation above [`DENSE_FALLBACK_MAX`].
    sparse: Option<faer::sparse::linalg::solvers::Lu<usize, f64>>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    buf: MemBuffer,
}

impl std::fmt::Debug for DenseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLu").field("n", &self.n).finish_non_exhaustive()
    }
}

impl Default for DenseLu {
    fn default() -> Self {
        Self {
            n: 0,
            structured: None,
            structure_checked: false,
            use_structured: false,
            lu: Mat::zeros(0, 0),
            sparse: None,
            perm: Vec::new(),
            perm_inv: Vec::new(),
            buf: MemBuffer::new(StackReq::EMPTY),
        }
    }
}

impl DenseLu {
    /// faer's sparse LU of the non-zeros of `a`; `Err(row)` when it is singular.
    fn factorize_sparse(&mut self, a: &DenseMatrix) -> Result<(), usize> {
        use faer::sparse::Triplet;
        let n = self.n;
        let data = a.as_slice();
        let mut entries = Vec::new();
        for j in 0..n {
            for (i, &v) in data[j * n..(j + 1) * n].iter().enumerate() {
                if v != 0.0 {
                    entries.push(Triplet { row: i, col: j, val: v });
                }
            }
        }
        self.factorize_triplets(&entries)
    }

    /// faer's sparse LU of the `n × n` matrix with these entries (repeated positions add up).
    fn factorize_triplets(&mut self, entries: &[faer::sparse::Triplet<usize, usize, f64>]) -> Result<(), usize> {
        use faer::sparse::SparseColMat;
        use faer::sparse::linalg::LuError;
        let n = self.n;
        let m = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, entries).map_err(|_| 0_usize)?;
        match m.sp_lu() {
            Ok(lu) => {
                self.sparse = Some(lu);
                Ok(())
            }
            Err(LuError::SymbolicSingular { index }) => Err(index),
            Err(_) => Err(0),
        }
    }

    /// The dense storage and faer's scratch, at the first dense factorisation.
    fn allocate_dense(&mut self) {
        let n = self.n;
        if self.lu.nrows() == n && self.lu.ncols() == n {
            return;
        }
        self.lu = Mat::zeros(n, n);
        let req = StackReq::any_of(&[
            lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Spec::<PartialPivLuParams, f64>::default()),
            solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        self.buf = MemBuffer::new(req);
    }
}

impl LinearSolver for DenseLu {
    fn set_dimension(&mut self, n: usize) {
        self.n = n;
        self.lu = Mat::zeros(0, 0);
        self.perm = vec![0; n];
        self.perm_inv = vec![0; n];
        self.buf = MemBuffer::new(StackReq::EMPTY);
    }

    fn set_structure(&mut self, structure: &BandedBorder) {
        self.structured = structure.is_valid(self.n).then(|| BorderedBandLu::new(self.n, structure));
        self.structure_checked = false;
    }

    fn factorize(&mut self, a: &DenseMatrix) -> Result<(), usize> {
        assert!(a.n_rows() == self.n && a.n_cols() == self.n, "factorize: dimension mismatch");
        if let Some(s) = &mut self.structured
            && !self.structure_checked
        {
            self.structure_checked = true;
            if !s.fits(a) {
                self.structured = None;
            }
        }
        if let Some(s) = &mut self.structured {
            debug_assert!(s.fits(a), "the matrix does not fit the declared structure");
            if s.factorize(a).is_ok() {
                self.use_structured = true;
                return Ok(());
            }
        }
        self.use_structured = false;
        self.sparse = None;
        if self.n > DENSE_FALLBACK_MAX {
            return self.factorize_sparse(a);
        }
        self.allocate_dense();
        let src = MatRef::from_column_major_slice(a.as_slice(), self.n, self.n);
        self.lu.copy_from(src);
        let stack = MemStack::new(&mut self.buf);
        lu_in_place(self.lu.as_mut(), &mut self.perm, &mut self.perm_inv, Par::Seq, stack, Default::default());
        let scale = (0..self.n).map(|i| self.lu[(i, i)].abs()).fold(0.0_f64, f64::max);
        for i in 0..self.n {
            let d = self.lu[(i, i)];
            if !d.is_finite() || d.abs() <= 1e-14 * scale {
                return Err(i);
            }
        }
        Ok(())
    }

    fn assembly_target(&mut self) -> Option<&mut dyn AssemblyTarget> {
        // From the first matrix on: the storage records an entry outside the declared structure
        // (then `factorize_assembled` asks for the dense path, which checks the structure
        // against the whole matrix), so no dense matrix need confirm it first.
        if self.structured.is_some() { Some(self) } else { None }
    }

    fn factorize_assembled(&mut self) -> Result<Assembled, usize> {
        let Some(s) = &mut self.structured else { return Ok(Assembled::UseDense) };
        if s.assembled_outside() {
            self.structured = None; // the declared structure is incomplete
            return Ok(Assembled::UseDense);
        }
        if s.assembled_outside_nodes() {
            // A coupling beyond a block's node band: the dense matrix moves that block to the
            // scalar band (see `BorderedBandLu::factorize`), then direct assembly resumes.
            return Ok(Assembled::UseDense);
        }
        if s.factorize_gathered().is_err() {
            return Ok(Assembled::UseDense); // the dense path retries and falls back to the dense LU
        }
        self.use_structured = true;
        // A dense fallback's storage is not kept beside the structured factors: a banded
        // problem holds no n² buffer between fallbacks.
        if self.lu.nrows() > 0 || self.sparse.is_some() {
            self.lu = Mat::zeros(0, 0);
            self.sparse = None;
        }
        Ok(Assembled::Factorized)
    }

    fn factorize_entries(&mut self, entries: &Entries) -> Result<bool, usize> {
        assert!(entries.n == self.n, "factorize_entries: dimension mismatch");
        self.use_structured = false;
        self.sparse = None;
        // A dense fallback's storage is not kept beside the sparse factors.
        self.lu = Mat::zeros(0, 0);
        self.factorize_triplets(&entries.triplets)?;
        Ok(true)
    }

    fn solve_in_place(&mut self, b: &mut [f64]) {
        assert!(b.len() == self.n, "solve: dimension mismatch");
        if self.use_structured
            && let Some(s) = &mut self.structured
        {
            s.solve_in_place(b);
            return;
        }
        if let Some(lu) = &self.sparse {
            use faer::linalg::solvers::SolveCore as _;
            lu.solve_in_place_with_conj(faer::Conj::No, MatMut::from_column_major_slice_mut(b, self.n, 1));
            return;
        }
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, self.n);
        let rhs = MatMut::from_column_major_slice_mut(b, self.n, 1);
        let stack = MemStack::new(&mut self.buf);
        solve_in_place(self.lu.as_ref(), self.lu.as_ref(), perm, rhs, Par::Seq, stack);
    }
}
