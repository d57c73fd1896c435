//! Exact elimination of the linear joints: the constant velocity transformation of paper
//! eq. 6–7,
//!
//! $$ q = B z + q_p,\qquad \Phi_q B = 0,\qquad \dot q = B \dot z,\qquad
//!    B^T M B\, \ddot z + B^T\big(f_{el}(q) - Q\big) = 0 . $$
//!
//! `B` comes from a Gauss–Jordan reduction of the constant `Φ_q` with the pivot chosen per row
//! as the largest coefficient (ties go to the later coordinate, i.e. the child body): every
//! dependent coordinate is expressed through independent ones only, with divisors of magnitude
//! at least `1/√3` of the row — no division by `cos β` that would break at β = 90°.
//! `z` are the independent nodal coordinates themselves, so `B` is an identity on them plus a few
//! sparse rows for the dependent ones.

use crate::Error;
use crate::joint::ConstraintRow;

/// The constant elimination `q = B z + q_p`.
#[derive(Debug, Clone, PartialEq)]
pub struct Reduction {
    n_full: usize,
    n_reduced: usize,
    /// CSR over full coordinates: row `i` of B is `entries[ptr[i]..ptr[i+1]]` as (z, coefficient).
    ptr: Vec<usize>,
    entries: Vec<(usize, f64)>,
    /// `q_p`.
    offset: Vec<f64>,
    /// z index of each full coordinate, `None` when dependent.
    z_of: Vec<Option<usize>>,
    /// Full index of each z.
    full_of: Vec<usize>,
}

impl Reduction {
    /// Eliminate `rows` (constraint equations on `n_full` coordinates).
    ///
    /// Returns [`Error::RedundantJoint`] naming the first joint whose equation is a combination
    /// of earlier ones.
    pub fn new(rows: &[ConstraintRow], n_full: usize) -> Result<Self, Error> {
        let m = rows.len();
        let mut a = vec![vec![0.0; n_full]; m];
        let mut c = vec![0.0; m];
        let mut scale = vec![0.0_f64; m];
        for (i, row) in rows.iter().enumerate() {
            for &(j, x) in &row.entries {
                a[i][j] += x;
                scale[i] = scale[i].max(x.abs());
            }
            c[i] = row.rhs;
        }
        let mut pivot_of_row = vec![0; m];
        let mut is_pivot = vec![false; n_full];
        for i in 0..m {
            let mut best = 0.0;
            let mut p = usize::MAX;
            for (j, &x) in a[i].iter().enumerate() {
                if !is_pivot[j] && x.abs() > 0.0 && x.abs() >= best * (1.0 - 1e-12) {
                    best = best.max(x.abs());
                    p = j;
                }
            }
            if p == usize::MAX || best <= 1e-10 * scale[i] {
                return Err(Error::RedundantJoint { joint: rows[i].joint });
            }
            let d = a[i][p];
            a[i].iter_mut().for_each(|x| *x /= d);
            c[i] /= d;
            let (pivot_row, ci) = (a[i].clone(), c[i]);
            for k in 0..m {
                if k != i {
                    let f = a[k][p];
                    if f != 0.0 {
                        for (x, y) in a[k].iter_mut().zip(&pivot_row) {
                            *x -= f * y;
                        }
                        a[k][p] = 0.0;
                        c[k] -= f * ci;
                    }
                }
            }
            pivot_of_row[i] = p;
            is_pivot[p] = true;
        }
        let mut z_of = vec![None; n_full];
        let mut full_of = Vec::new();
        for j in 0..n_full {
            if !is_pivot[j] {
                z_of[j] = Some(full_of.len());
                full_of.push(j);
            }
        }
        let mut row_of_pivot = vec![usize::MAX; n_full];
        for (i, &p) in pivot_of_row.iter().enumerate() {
            row_of_pivot[p] = i;
        }
        let mut ptr = vec![0];
        let mut entries = Vec::new();
        let mut offset = vec![0.0; n_full];
        for j in 0..n_full {
            if let Some(z) = z_of[j] {
                entries.push((z, 1.0));
            } else {
                let i = row_of_pivot[j];
                for (k, &x) in a[i].iter().enumerate() {
                    if k != j && x.abs() > 1e-15 {
                        let z = z_of[k].expect("Gauss-Jordan leaves only independent columns in a pivot row");
                        entries.push((z, -x));
                    }
                }
                offset[j] = c[i];
            }
            ptr.push(entries.len());
        }
        Ok(Self { n_full, n_reduced: full_of.len(), ptr, entries, offset, z_of, full_of })
    }

    /// Number of full coordinates.
    pub fn n_full(&self) -> usize {
        self.n_full
    }
    /// Number of independent coordinates `z`.
    pub fn n_reduced(&self) -> usize {
        self.n_reduced
    }
    /// Row `i` of `B` as `(z, coefficient)` pairs.
    #[inline]
    pub fn row(&self, i: usize) -> &[(usize, f64)] {
        &self.entries[self.ptr[i]..self.ptr[i + 1]]
    }
    /// z index of a full coordinate, `None` when it is dependent.
    pub fn z_of(&self, i: usize) -> Option<usize> {
        self.z_of[i]
    }
    /// Full index of independent coordinate `z`.
    pub fn full_of(&self, z: usize) -> usize {
        self.full_of[z]
    }

    /// `q = B z + q_p`.
    pub fn expand_inplace(&self, z: &[f64], q: &mut [f64]) {
        for (i, qi) in q.iter_mut().enumerate() {
            *qi = self.offset[i] + self.row(i).iter().map(|&(k, c)| c * z[k]).sum::<f64>();
        }
    }
    /// `v = B ż`.
    pub fn expand_rate_inplace(&self, zd: &[f64], v: &mut [f64]) {
        for (i, vi) in v.iter_mut().enumerate() {
            *vi = self.row(i).iter().map(|&(k, c)| c * zd[k]).sum::<f64>();
        }
    }
    /// `r_z = Bᵀ r`.
    pub fn project_inplace(&self, r: &[f64], rz: &mut [f64]) {
        rz.iter_mut().for_each(|x| *x = 0.0);
        for (i, ri) in r.iter().enumerate() {
            for &(k, c) in self.row(i) {
                rz[k] += c * ri;
            }
        }
    }
    /// The independent part of a full coordinate vector (`z` such that `B z + q_p = q` when
    /// `q` satisfies the constraints).
    pub fn restrict(&self, q: &[f64]) -> Vec<f64> {
        self.full_of.iter().map(|&i| q[i]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn rows(beta: f64) -> Vec<ConstraintRow> {
        // Two 3-coordinate "nodes" [r, a] on 12 coordinates: q0..2 = r¹, q3..5 = r¹_x, q6..8 = r¹_y,
        // q9..11 = r², ...; a flared-hinge-like pair of equations on coordinates 0..12 and 12..24.
        let (s, c) = (beta.sin(), beta.cos());
        let mut out = Vec::new();
        for i in 0..3 {
            out.push(ConstraintRow { entries: vec![(i, 1.0), (12 + i, -1.0)], rhs: 0.0, joint: 0 });
            out.push(ConstraintRow {
                entries: vec![(3 + i, s), (6 + i, c), (15 + i, -s), (18 + i, -c)],
                rhs: 0.0,
                joint: 0,
            });
        }
        out
    }

    #[test]
    fn null_space_of_the_flared_hinge_for_every_beta() {
        for beta in [0.0, 0.3, std::f64::consts::FRAC_PI_4, 1.5, std::f64::consts::FRAC_PI_2, -1.2] {
            let r = rows(beta);
            let red = Reduction::new(&r, 24).unwrap();
            assert_eq!(red.n_reduced(), 18);
            // Φ_q B = 0 column by column, and the largest coefficient in B is bounded.
            for z in 0..18 {
                let mut e = vec![0.0; 18];
                e[z] = 1.0;
                let mut q = vec![0.0; 24];
                red.expand_rate_inplace(&e, &mut q);
                for row in &r {
                    assert_relative_eq!(row.value(&q), 0.0, epsilon = 1e-14);
                }
                assert!(q.iter().all(|x| x.abs() <= 2.0 + 1e-12));
            }
        }
    }

    #[test]
    fn redundant_rows_are_reported() {
        let mut r = rows(0.2);
        r.push(ConstraintRow { entries: vec![(1, 2.0), (13, -2.0)], rhs: 0.0, joint: 1 });
        assert_eq!(Reduction::new(&r, 24).unwrap_err(), Error::RedundantJoint { joint: 1 });
    }

    #[test]
    fn particular_solution_satisfies_inhomogeneous_rows() {
        let r = vec![
            ConstraintRow { entries: vec![(0, 1.0)], rhs: 0.5, joint: 0 },
            ConstraintRow { entries: vec![(1, 0.6), (2, 0.8)], rhs: 1.0, joint: 0 },
        ];
        let red = Reduction::new(&r, 4).unwrap();
        let z = vec![0.3, -0.7];
        let mut q = vec![0.0; 4];
        red.expand_inplace(&z, &mut q);
        for row in &r {
            assert_relative_eq!(row.value(&q), 0.0, epsilon = 1e-14);
        }
    }
}
