//! An orthonormal basis of the null space of a constraint Jacobian.

use crate::Error;
use nalgebra::{DMatrix, SVD};

/// Singular values at most `NULL_SPACE_RTOL` times the largest one count as zero.
///
/// The rows are normalised first, so this is a relative tolerance on how nearly dependent the
/// constraint rows may be before one of them is taken as redundant (a looser tolerance would
/// drop a weakly independent joint row and leave a spurious free motion; a tighter one would
/// keep a redundant row and remove a real one).
pub const NULL_SPACE_RTOL: f64 = 1e-10;

/// Iteration cap of the SVD (nalgebra counts its implicit-shift sweeps over the whole matrix).
const MAX_SVD_ITER: usize = 10_000;

/// An orthonormal basis `N` (`n × (n − rank G)`) of `ker G` for an `m × n` matrix `G`, from the
/// SVD of `G` with its rows normalised (zero rows dropped), padded with zero rows to a square
/// matrix so that nalgebra returns every right singular vector. With no rows, `N = I`.
///
/// # Errors
/// [`Error::DecompositionNotConverged`] when the SVD does not converge.
pub fn null_space(g: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
    let (m, n) = g.shape();
    let rows: Vec<usize> = (0..m).filter(|&i| g.row(i).amax() > 0.0).collect();
    if rows.is_empty() {
        return Ok(DMatrix::identity(n, n));
    }
    let mut a = DMatrix::zeros(rows.len().max(n), n);
    for (k, &i) in rows.iter().enumerate() {
        let row = g.row(i);
        a.row_mut(k).copy_from(&(row / row.norm()));
    }
    let svd = SVD::try_new(a, false, true, f64::EPSILON, MAX_SVD_ITER).ok_or(Error::DecompositionNotConverged { n })?;
    let v_t = svd.v_t.as_ref().expect("right singular vectors were requested");
    let s_max = svd.singular_values.max();
    let free: Vec<usize> = (0..n).filter(|&k| svd.singular_values[k] <= NULL_SPACE_RTOL * s_max).collect();
    let mut basis = DMatrix::zeros(n, free.len());
    for (c, &k) in free.iter().enumerate() {
        basis.set_column(c, &v_t.row(k).transpose());
    }
    Ok(basis)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn basis_is_orthonormal_and_annihilated() {
        // two independent rows, one repeated (scaled) and one zero row: rank 2 in R⁵
        let g = DMatrix::from_row_slice(
            4,
            5,
            &[
                1.0, 2.0, 0.0, -1.0, 0.5, //
                0.0, 1.0, 1.0, 0.0, 0.0, //
                2.0, 4.0, 0.0, -2.0, 1.0, //
                0.0, 0.0, 0.0, 0.0, 0.0,
            ],
        );
        let n = null_space(&g).unwrap();
        assert_eq!(n.ncols(), 3);
        assert_relative_eq!(n.transpose() * &n, DMatrix::identity(3, 3), epsilon = 1e-14);
        assert!((&g * &n).amax() < 1e-14);
    }

    #[test]
    fn no_rows_give_the_identity() {
        let n = null_space(&DMatrix::zeros(0, 4)).unwrap();
        assert_eq!(n, DMatrix::identity(4, 4));
    }
}
