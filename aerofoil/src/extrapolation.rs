//! Past the table: the Viterna–Corrigan flat-plate extrapolation (Viterna & Corrigan 1982, as
//! AirfoilPrep and WISDEM use it), from the table's last row at `α_s` up to ±90°:
//!
//! $$ cl = \frac{cd_{max}}{2}\sin 2\alpha + A_2\frac{\cos^2\alpha}{\sin\alpha}, \qquad
//!    cd = cd_{max}\sin^2\alpha + B_2\cos\alpha, $$
//! $$ A_2 = (cl_s - cd_{max}\sin\alpha_s\cos\alpha_s)\frac{\sin\alpha_s}{\cos^2\alpha_s}, \qquad
//!    B_2 = \frac{cd_s - cd_{max}\sin^2\alpha_s}{\cos\alpha_s}, $$
//!
//! continuous with the table at `α_s` (not in slope), a flat plate normal to the flow at 90°
//! (`cl = 0`, `cd = cd_max`). `cd_max = 2.0`, the two-dimensional flat plate (Hoerner). The
//! moment coefficient is held at its end value: the crate has no flat-plate model of it.

/// Drag coefficient of a two-dimensional flat plate normal to the flow.
pub(crate) const CD_MAX: f64 = 2.0;

/// `(cl, cd, dcl/dα, dcd/dα)` at `alpha`, extrapolated from the end row `(alpha_s, cl_s, cd_s)`
/// on the same side of zero (`|alpha| ≥ |alpha_s|`, `0 < |alpha_s|`, `|alpha| ≤ π/2`).
pub(crate) fn viterna(alpha_s: f64, cl_s: f64, cd_s: f64, alpha: f64) -> (f64, f64, f64, f64) {
    let (ss, cs) = alpha_s.sin_cos();
    let a1 = 0.5 * CD_MAX;
    let a2 = (cl_s - CD_MAX * ss * cs) * ss / (cs * cs);
    let b2 = (cd_s - CD_MAX * ss * ss) / cs;
    let (s, c) = alpha.sin_cos();
    let cl = a1 * (2.0 * alpha).sin() + a2 * c * c / s;
    let cd = CD_MAX * s * s + b2 * c;
    let dcl = 2.0 * a1 * (2.0 * alpha).cos() - a2 * c * (2.0 * s * s + c * c) / (s * s);
    let dcd = 2.0 * CD_MAX * s * c - b2 * s;
    (cl, cd, dcl, dcd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn continuous_at_the_table_and_a_flat_plate_at_ninety_degrees() {
        for (alpha_s, cl_s, cd_s) in [(0.35, 0.9, 0.08), (-0.3, -0.8, 0.06)] {
            let (cl, cd, _, _) = viterna(alpha_s, cl_s, cd_s, alpha_s);
            assert_relative_eq!(cl, cl_s, max_relative = 1e-13);
            assert_relative_eq!(cd, cd_s, max_relative = 1e-13);
            let end = FRAC_PI_2.copysign(alpha_s);
            let (cl, cd, _, _) = viterna(alpha_s, cl_s, cd_s, end);
            assert!(cl.abs() < 1e-12, "no lift at 90°: {cl}");
            assert_relative_eq!(cd, CD_MAX, max_relative = 1e-13);
        }
    }

    #[test]
    fn slopes_are_the_derivatives() {
        let h = 1e-6;
        for alpha in [0.4, 0.8, 1.2, 1.5, -0.5, -1.1] {
            let alpha_s: f64 = 0.35f64.copysign(alpha);
            let f = |a| viterna(alpha_s, 0.9 * alpha_s.signum(), 0.08, a);
            let (_, _, dcl, dcd) = f(alpha);
            assert_relative_eq!(dcl, (f(alpha + h).0 - f(alpha - h).0) / (2.0 * h), epsilon = 1e-7);
            assert_relative_eq!(dcd, (f(alpha + h).1 - f(alpha - h).1) / (2.0 * h), epsilon = 1e-7);
        }
    }
}
