//! Short vector kernels shared by the factorisations and the Newton loop. The unknowns number a
//! few hundred at most, so what decides the speed is the dependency chain, not the memory: a
//! single running sum waits for every addition in turn, four partial sums pipeline and
//! vectorise.

/// `Σ a_i b_i` over the shorter of the two, with four partial sums.
#[inline(always)]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    let mut acc = [0.0; 4];
    for (x, y) in ca.zip(cb) {
        for i in 0..4 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// `y −= s x`.
#[inline(always)]
pub(crate) fn sub_scaled(y: &mut [f64], s: f64, x: &[f64]) {
    for (a, b) in y.iter_mut().zip(x) {
        *a -= s * b;
    }
}

/// Whether any entry of `x` is non-zero (or NaN), as `x_i != 0.0` says: the entries' bits or-ed,
/// the sign bit shifted out (−0.0 is zero). Integer operations without branches, which
/// vectorise where eight floating-point comparisons would not.
#[inline(always)]
fn any_nonzero(x: &[f64]) -> bool {
    x.iter().fold(0u64, |a, v| a | v.to_bits()) << 1 != 0
}

/// Index of the first non-zero of `x`. Tested eight at a time without an early exit inside a
/// group ([`any_nonzero`]), since most scanned rows and columns of a
/// bordered matrix's border, and of a constraint Jacobian, are entirely zero.
#[inline(always)]
pub(crate) fn first_nonzero(x: &[f64]) -> Option<usize> {
    let chunks = x.chunks_exact(8);
    let tail = x.len() - chunks.remainder().len();
    for (g, c) in chunks.enumerate() {
        if any_nonzero(c) {
            return c.iter().position(|v| *v != 0.0).map(|o| 8 * g + o);
        }
    }
    x[tail..].iter().position(|v| *v != 0.0).map(|o| tail + o)
}

/// Index of the last non-zero of `x`, eight at a time from the end (see [`first_nonzero`]).
#[inline(always)]
pub(crate) fn last_nonzero(x: &[f64]) -> Option<usize> {
    let chunks = x.rchunks_exact(8);
    let head = chunks.remainder().len();
    for (g, c) in chunks.enumerate() {
        if any_nonzero(c) {
            return c.iter().rposition(|v| *v != 0.0).map(|o| x.len() - 8 * (g + 1) + o);
        }
    }
    x[..head].iter().rposition(|v| *v != 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_sums_every_term_for_every_length() {
        for n in 0..13 {
            let a: Vec<f64> = (0..n).map(|i| i as f64 + 1.0).collect();
            let b: Vec<f64> = (0..n).map(|i| 2.0 - i as f64).collect();
            let exact: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            assert_eq!(dot(&a, &b), exact, "n = {n}"); // small integers: exact in any order
        }
        assert_eq!(dot(&[1.0, 2.0, 3.0], &[1.0]), 1.0); // the shorter length
    }

    #[test]
    fn any_nonzero_matches_the_comparison_with_zero() {
        for v in [0.0, -0.0, 1e-310, -2.5, f64::NAN, f64::INFINITY] {
            for k in 0..5 {
                let mut x = [0.0, -0.0, 0.0, 0.0, -0.0];
                x[k] = v;
                assert_eq!(any_nonzero(&x), x.iter().any(|y| *y != 0.0), "{v} at {k}");
            }
        }
        assert!(!any_nonzero(&[]));
    }

    #[test]
    fn first_and_last_nonzero_find_the_ends_across_groups_of_eight() {
        for n in 0..20 {
            for (i, k) in (0..n).flat_map(|i| (i..n).map(move |k| (i, k))) {
                let mut x = vec![-0.0; n];
                x[i] = 1.0;
                x[k] = f64::NAN;
                assert_eq!((first_nonzero(&x), last_nonzero(&x)), (Some(i), Some(k)), "n = {n}");
            }
            assert_eq!((first_nonzero(&vec![0.0; n]), last_nonzero(&vec![-0.0; n])), (None, None));
        }
    }
}
