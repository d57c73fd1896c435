//! The static Newton step with each node's slopes turned rather than pushed (docs/ancf.md §9).
//!
//! A Newton step is linear in the coordinates. Where a node turns by an angle θ, its slope
//! vectors `r_x, r_y, r_z` move along their tangents and come out longer by `θ²/2`, and so does
//! the chord of every element that turns. The near-rigid section and axial stiffnesses act on
//! those stretches: a step that turns Healy's folding tip by 14° left 1.5e5 N of axial residual
//! behind it, and the next iteration spent itself undoing it (the iteration alternated long and
//! short steps). Here each node's slope increment `δF` (`F = [r_x r_y r_z]`) is split through
//! `A = δF F⁻¹` into its rotation `Ω = skew A` and its strain `S = sym A`, and replaced by
//!
//! ```text
//! δF' = exp(Ω) (I + S) F − F = (exp(Ω) − I)(I + S) F + S F,
//! ```
//!
//! which agrees with `δF` to first order (Newton's convergence is unchanged) and turns the slopes
//! exactly. The positions are turned along the body: each element's chord `d = r_b − r_a`, with
//! step `δd`, turns by its nodes' mean rotation `ω`,
//!
//! ```text
//! δd' = (exp(ω×) − I)(d + ρ) + ρ,   ρ = δd − ω × d,
//! ```
//!
//! and the nodes are placed from the body's first one, which keeps its linear step. A linearised
//! rigid motion of a body becomes the rigid motion. A step that would turn a node by more than
//! [`MAX_TURN`] is first shortened to it as a whole.

use nalgebra::{Matrix3, Vector3};

use crate::shape::NODE_DOF;

/// `exp(Ω) − I` for the rotation vector `w`, without forming `I + …` (so that a tiny rotation
/// keeps its digits): `α W + β W²` with `α = sin θ / θ`, `β = (1 − cos θ) / θ²`.
fn rotation_minus_identity(w: Vector3<f64>) -> Matrix3<f64> {
    let theta2 = w.norm_squared();
    let theta = theta2.sqrt();
    let (alpha, beta) = if theta < 1e-4 {
        (1.0 - theta2 / 6.0, 0.5 - theta2 / 24.0)
    } else {
        let h = (0.5 * theta).sin() / theta;
        (theta.sin() / theta, 2.0 * h * h)
    };
    let k = w.cross_matrix();
    k * alpha + k * k * beta
}

/// The previous node along the body: its position, its linear and its turned position step, and
/// its rotation.
#[derive(Clone, Copy)]
struct Previous {
    r: Vector3<f64>,
    dr: Vector3<f64>,
    turned_dr: Vector3<f64>,
    w: Vector3<f64>,
}

/// Replace the step `dq` of the nodes whose coordinates start at `first + NODE_DOF · n`,
/// `n < n_nodes` (one body, in order along it), by the turned step of the module documentation.
/// A node whose slopes are singular or whose step is not finite keeps its linear step and turns
/// its element by its neighbour's rotation alone.
pub(crate) fn turn_node_steps(first: usize, n_nodes: usize, q: &[f64], dq: &mut [f64]) {
    let mut prev: Option<Previous> = None;
    for n in 0..n_nodes {
        let i = first + NODE_DOF * n;
        let (Some(qn), Some(dn)) = (q.get(i..i + NODE_DOF), dq.get(i..i + NODE_DOF)) else {
            return;
        };
        let r = Vector3::from_column_slice(&qn[..3]);
        let dr = Vector3::from_column_slice(&dn[..3]);
        let (w, slopes) = turned_slopes(&qn[3..], &dn[3..]).unwrap_or((Vector3::zeros(), None));
        if let Some(turned) = slopes {
            dq[i + 3..i + 12].copy_from_slice(turned.as_slice());
        }
        let mut turned_dr = dr;
        if let Some(Previous { r: r0, dr: dr0, turned_dr: turned_dr0, w: w0 }) = prev {
            let (d, dd) = (r - r0, dr - dr0);
            let we = 0.5 * (w + w0);
            let rest = dd - we.cross(&d);
            let step = rotation_minus_identity(we) * (d + rest) + rest;
            let candidate = turned_dr0 + step;
            if candidate.iter().all(|x| x.is_finite()) {
                turned_dr = candidate;
            }
        }
        dq[i..i + 3].copy_from_slice(turned_dr.as_slice());
        prev = Some(Previous { r, dr, turned_dr, w });
    }
}

/// The largest rotation a static Newton step may turn a node by, rad: a longer step is shortened
/// to it as a whole. A free hinge has almost no stiffness about its axis where gravity's moment is
/// flat, so Newton's first step from the reference can turn a tip by many radians; the linear
/// step's stretch used to hold it back, the turned step would carry it round to another
/// equilibrium (an unstable one, tip against gravity). Half a radian still takes a 14° fold
/// jump of a sweep in one step.
pub(crate) const MAX_TURN: f64 = 0.5;

/// The largest rotation `|ω|` of the step `dq` over the nodes of one body (as
/// [`turn_node_steps`]); zero where none is defined.
pub(crate) fn largest_turn(first: usize, n_nodes: usize, q: &[f64], dq: &[f64]) -> f64 {
    let mut worst = 0.0_f64;
    for n in 0..n_nodes {
        let i = first + NODE_DOF * n + 3;
        let (Some(qs), Some(ds)) = (q.get(i..i + 9), dq.get(i..i + 9)) else {
            break;
        };
        if let Some((w, _)) = turned_slopes(qs, ds) {
            worst = worst.max(w.norm());
        }
    }
    worst
}

/// The rotation vector of a node's slope step `δF` (slopes `F`, both column-major 3 × 3) and the
/// turned step, `None` where there is nothing to turn (a zero step) or it is not finite; `None`
/// altogether where `F` is singular or the step not finite.
fn turned_slopes(qs: &[f64], ds: &[f64]) -> Option<(Vector3<f64>, Option<Matrix3<f64>>)> {
    let f = Matrix3::from_column_slice(&qs[..9]);
    let df = Matrix3::from_column_slice(&ds[..9]);
    if !df.iter().all(|x| x.is_finite()) {
        return None;
    }
    if df.iter().all(|&x| x == 0.0) {
        return Some((Vector3::zeros(), None));
    }
    let a = df * f.try_inverse()?;
    let w = 0.5 * Vector3::new(a[(2, 1)] - a[(1, 2)], a[(0, 2)] - a[(2, 0)], a[(1, 0)] - a[(0, 1)]);
    let s = 0.5 * (a + a.transpose());
    let sf = s * f;
    let turned = rotation_minus_identity(w) * (f + sf) + sf;
    turned.iter().all(|x| x.is_finite()).then_some((w, Some(turned)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn node(f: Matrix3<f64>) -> Vec<f64> {
        let mut q = vec![0.3, -0.2, 0.1];
        q.extend_from_slice(f.as_slice());
        q
    }

    /// A slope step that is a linearised rotation becomes the exact rotation: the turned slopes
    /// are `R F` to rounding, with no stretch.
    #[test]
    fn a_linearised_rotation_becomes_the_rotation() {
        let f = *Rotation3::from_euler_angles(0.3, -0.4, 1.1).matrix();
        let w = Vector3::new(0.05, -0.2, 0.12);
        let mut dq = vec![0.01, 0.02, -0.03];
        dq.extend_from_slice((w.cross_matrix() * f).as_slice());
        let q = node(f);
        turn_node_steps(0, 1, &q, &mut dq);
        let turned = f + Matrix3::from_column_slice(&dq[3..12]);
        let exact = Rotation3::new(w).matrix() * f;
        assert!((turned - exact).amax() < 1e-15, "{:e}", (turned - exact).amax());
        assert_eq!(&dq[..3], &[0.01, 0.02, -0.03]);
    }

    /// The turned step agrees with the linear one to first order: the difference shrinks as the
    /// square of the step (any stretch included), and a step of rounding size keeps its digits.
    #[test]
    fn the_turned_step_is_the_step_to_first_order() {
        let f = Matrix3::new(1.01, 0.02, -0.01, 0.03, 0.98, 0.02, -0.02, 0.01, 1.02);
        let dir = Matrix3::new(0.2, -0.5, 0.1, 0.4, 0.05, -0.3, -0.1, 0.35, 0.02);
        let q = node(f);
        let mut last = f64::NAN;
        for k in 1..=4 {
            let h = 10f64.powi(-k);
            let mut dq = vec![0.0; 3];
            dq.extend_from_slice((dir * h).as_slice());
            turn_node_steps(0, 1, &q, &mut dq);
            let d = (Matrix3::from_column_slice(&dq[3..12]) - dir * h).amax();
            if k > 1 {
                let ratio = last / d;
                assert!((80.0..125.0).contains(&ratio), "h = {h:e}: ratio {ratio}");
            }
            last = d;
        }
        let mut dq = vec![0.0; 3];
        dq.extend_from_slice((dir * 1e-15).as_slice());
        turn_node_steps(0, 1, &q, &mut dq);
        let d = (Matrix3::from_column_slice(&dq[3..12]) - dir * 1e-15).amax();
        assert!(d < 1e-29, "{d:e}");
    }
}
