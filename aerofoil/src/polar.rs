//! A section polar: lift, drag and moment coefficients against incidence, at one or more
//! Reynolds numbers, with their local slopes.
//!
//! Within one Reynolds number's table the coefficients are interpolated in incidence by a
//! monotone cubic ([`crate::monotone_cubic`]): C¹, so the local lift-curve slope `dcl/dα` that a
//! Newton tangent or a linear stability model uses is continuous, and free of overshoot, so a
//! stall peak is not exaggerated. Between two tables the coefficients are interpolated linearly
//! in `ln Re` (boundary-layer quantities scale with powers of Re, so equal ratios of Re are
//! equal steps), each table evaluated at the same incidence.
//!
//! Outside the table's incidence range, or its Reynolds range, [`Bounds`] decides: an error
//! (the default, the rule for bad input) or a clamp to the nearest end, where the
//! coefficients hold their end values and their incidence slopes are zero (the exact derivative
//! of the clamped function); in incidence also the flat-plate (Viterna–Corrigan) extrapolation.

use crate::error::{AerofoilError, Result};
use crate::extrapolation::viterna;
use crate::monotone_cubic::MonotoneCubic;
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// One Reynolds number's table, incidences in radians.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Reynolds number of the table (`None` for a Reynolds-independent polar of one table).
    pub re: Option<f64>,
    /// Incidences, rad, strictly increasing.
    pub alpha: Vec<f64>,
    /// Lift coefficients, one per incidence.
    pub cl: Vec<f64>,
    /// Drag coefficients (profile drag, ≥ 0), one per incidence.
    pub cd: Vec<f64>,
    /// Pitching-moment coefficients about the quarter chord, positive nose up, one per incidence.
    pub cm: Vec<f64>,
}

/// What to do with an incidence or a Reynolds number outside the table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutOfRange {
    /// Return [`AerofoilError::IncidenceOutOfRange`] or [`AerofoilError::ReynoldsOutOfRange`].
    #[default]
    Error,
    /// Use the nearest end of the table: coefficients held, incidence slopes zero.
    Clamp,
}

/// What to do with an incidence outside the table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlphaOutOfRange {
    /// Return [`AerofoilError::IncidenceOutOfRange`].
    #[default]
    Error,
    /// Use the nearest end of the table: coefficients held, incidence slopes zero.
    Clamp,
    /// The Viterna–Corrigan flat-plate extrapolation from the table's end row up to ±90°
    /// (`cd_max = 2`, `cm` held; docs/section_aero.md §3); an error beyond ±90°.
    FlatPlate,
}

/// Range rules of a polar, one per axis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Bounds {
    /// Incidence outside `[α_min, α_max]` of the table in use.
    pub alpha: AlphaOutOfRange,
    /// Reynolds number outside `[Re_min, Re_max]` of a multi-Re polar (a polar of one table
    /// without `re` accepts every Reynolds number).
    pub re: OutOfRange,
}

/// Coefficients at one incidence and Reynolds number, with their incidence slopes (per rad).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Coefficients {
    /// Lift coefficient.
    pub cl: f64,
    /// Profile-drag coefficient.
    pub cd: f64,
    /// Pitching-moment coefficient about the quarter chord, nose up.
    pub cm: f64,
    /// `dcl/dα`, 1/rad: the local lift-curve slope.
    pub dcl: f64,
    /// `dcd/dα`, 1/rad.
    pub dcd: f64,
    /// `dcm/dα`, 1/rad.
    pub dcm: f64,
    /// `∂cl/∂Re` (zero for a single table, and outside the Reynolds range when clamped).
    pub dcl_dre: f64,
    /// `∂cd/∂Re`.
    pub dcd_dre: f64,
    /// `∂cm/∂Re`.
    pub dcm_dre: f64,
}

/// A validated table with its interpolants.
#[derive(Debug, Clone, PartialEq)]
struct Fitted {
    table: Table,
    curves: [MonotoneCubic; 3],
}

impl Fitted {
    fn eval(&self, alpha: f64, rule: AlphaOutOfRange) -> Result<Coefficients> {
        let t = &self.table;
        let (lo, hi) = (t.alpha[0], *t.alpha.last().expect("validated: ≥ 2 rows"));
        let inside = (lo..=hi).contains(&alpha);
        let out_of_range = |min: f64, max: f64| {
            Err(AerofoilError::IncidenceOutOfRange {
                alpha_deg: alpha.to_degrees(),
                min_deg: min.to_degrees(),
                max_deg: max.to_degrees(),
            })
        };
        if (!inside && rule == AlphaOutOfRange::Error) || alpha.is_nan() {
            return out_of_range(lo, hi);
        }
        if !inside && rule == AlphaOutOfRange::FlatPlate {
            let end = if alpha > hi { t.alpha.len() - 1 } else { 0 };
            let alpha_s = t.alpha[end];
            // The extrapolation runs from an end on the same side of zero up to ±90°.
            if alpha.abs() > FRAC_PI_2 || alpha_s * alpha <= 0.0 {
                return out_of_range(lo.min(-FRAC_PI_2), hi.max(FRAC_PI_2));
            }
            let (cl, cd, dcl, dcd) = viterna(alpha_s, t.cl[end], t.cd[end], alpha);
            return Ok(Coefficients { cl, cd, cm: t.cm[end], dcl, dcd, ..Coefficients::default() });
        }
        let a = alpha.clamp(lo, hi);
        let (cl, dcl) = self.curves[0].eval(&t.alpha, &t.cl, a);
        let (cd, dcd) = self.curves[1].eval(&t.alpha, &t.cd, a);
        let (cm, dcm) = self.curves[2].eval(&t.alpha, &t.cm, a);
        let k = if inside { 1.0 } else { 0.0 };
        Ok(Coefficients { cl, cd, cm, dcl: k * dcl, dcd: k * dcd, dcm: k * dcm, ..Coefficients::default() })
    }
}

/// A section polar: one table, or several at increasing Reynolds numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Polar {
    tables: Vec<Fitted>,
    bounds: Bounds,
}

impl Polar {
    /// Build a polar from its tables, with the default [`Bounds`] (errors outside the ranges).
    ///
    /// Every table needs at least two rows, finite values, strictly increasing incidences and
    /// non-negative drag. Several tables need a Reynolds number each, positive and strictly
    /// increasing; one table may have none (then the polar holds at every Reynolds number).
    pub fn new(tables: Vec<Table>) -> Result<Self> {
        if tables.is_empty() {
            return Err(AerofoilError::InvalidPolar { table: 0, what: "a polar needs at least one table" });
        }
        let multi = tables.len() > 1;
        let mut fitted = Vec::with_capacity(tables.len());
        let mut last_re = 0.0;
        for (k, t) in tables.into_iter().enumerate() {
            let bad = |what| Err(AerofoilError::InvalidPolar { table: k, what });
            match t.re {
                None if multi => return bad("several tables need a Reynolds number each"),
                Some(re) if !(re.is_finite() && re > 0.0) => return bad("Reynolds number not positive"),
                Some(re) if re <= last_re => return bad("Reynolds numbers not increasing"),
                Some(re) => last_re = re,
                None => {}
            }
            let n = t.alpha.len();
            if n < 2 {
                return bad("fewer than two rows");
            }
            if t.cl.len() != n || t.cd.len() != n || t.cm.len() != n {
                return bad("columns of different lengths");
            }
            let all = t.alpha.iter().chain(&t.cl).chain(&t.cd).chain(&t.cm);
            if !all.clone().all(|v| v.is_finite()) {
                return bad("non-finite value");
            }
            if t.alpha.windows(2).any(|w| w[1] <= w[0]) {
                return bad("incidences not strictly increasing");
            }
            if t.cd.iter().any(|&c| c < 0.0) {
                return bad("negative drag coefficient");
            }
            let curves = [
                MonotoneCubic::new(&t.alpha, &t.cl),
                MonotoneCubic::new(&t.alpha, &t.cd),
                MonotoneCubic::new(&t.alpha, &t.cm),
            ];
            fitted.push(Fitted { table: t, curves });
        }
        Ok(Self { tables: fitted, bounds: Bounds::default() })
    }

    /// The straight polar `cl = slope·(α − alpha0)`, `cd = cm = 0` over `[alpha_min, alpha_max]`
    /// (rad), at every Reynolds number: with `slope = 2π`, `alpha0 = 0` it is the thin plate,
    /// the lattice's own section, and the strip correction returns the lattice's loads.
    pub fn linear(slope: f64, alpha0: f64, alpha_min: f64, alpha_max: f64) -> Result<Self> {
        let alpha = vec![alpha_min, alpha_max];
        let cl = alpha.iter().map(|a| slope * (a - alpha0)).collect();
        Self::new(vec![Table { re: None, alpha, cl, cd: vec![0.0; 2], cm: vec![0.0; 2] }])
    }

    /// The same polar with other range rules.
    pub fn with_bounds(mut self, bounds: Bounds) -> Self {
        self.bounds = bounds;
        self
    }

    /// The range rules in force.
    pub fn bounds(&self) -> Bounds {
        self.bounds
    }

    /// The tables, in increasing Reynolds number.
    pub fn tables(&self) -> impl Iterator<Item = &Table> {
        self.tables.iter().map(|f| &f.table)
    }

    /// `(Re_min, Re_max)` of a multi-Re polar; `None` for a Reynolds-independent one.
    pub fn re_range(&self) -> Option<(f64, f64)> {
        let first = self.tables[0].table.re?;
        let last = self.tables.last().and_then(|f| f.table.re)?;
        Some((first, last))
    }

    /// Coefficients and their incidence slopes at incidence `alpha` (rad) and Reynolds number `re`.
    ///
    /// Between two tables `Re_k ≤ re ≤ Re_{k+1}` the result is `(1 − w)·c_k(α) + w·c_{k+1}(α)`
    /// with `w = ln(re/Re_k) / ln(Re_{k+1}/Re_k)`; the incidence must lie in both tables' ranges.
    /// The Reynolds derivatives are those of this blend (one-sided at a table's own Re, where
    /// the blend has a kink).
    pub fn coefficients(&self, alpha: f64, re: f64) -> Result<Coefficients> {
        let rule = self.bounds.alpha;
        let Some((re_min, re_max)) = self.re_range() else {
            return self.tables[0].eval(alpha, rule);
        };
        let inside = (re_min..=re_max).contains(&re);
        if (!inside && self.bounds.re == OutOfRange::Error) || re.is_nan() {
            return Err(AerofoilError::ReynoldsOutOfRange { re, min: re_min, max: re_max });
        }
        if self.tables.len() == 1 {
            // One table at one Reynolds number (a file with `re` and a single value).
            return self.tables[0].eval(alpha, rule);
        }
        let re = re.clamp(re_min, re_max);
        let upper = self.tables.partition_point(|f| f.table.re.is_some_and(|r| r <= re));
        let k = upper.clamp(1, self.tables.len() - 1) - 1;
        let (a, b) = (&self.tables[k], &self.tables[k + 1]);
        let (ra, rb) = (a.table.re.unwrap_or(re), b.table.re.unwrap_or(re));
        let w = (re / ra).ln() / (rb / ra).ln();
        let (ca, cb) = (a.eval(alpha, rule)?, b.eval(alpha, rule)?);
        let mix = |x: f64, y: f64| (1.0 - w) * x + w * y;
        // dw/dRe; zero where the Reynolds number is clamped (the derivative of a constant).
        let dw = if inside { 1.0 / (re * (rb / ra).ln()) } else { 0.0 };
        Ok(Coefficients {
            dcl_dre: dw * (cb.cl - ca.cl),
            dcd_dre: dw * (cb.cd - ca.cd),
            dcm_dre: dw * (cb.cm - ca.cm),
            cl: mix(ca.cl, cb.cl),
            cd: mix(ca.cd, cb.cd),
            cm: mix(ca.cm, cb.cm),
            dcl: mix(ca.dcl, cb.dcl),
            dcd: mix(ca.dcd, cb.dcd),
            dcm: mix(ca.dcm, cb.dcm),
        })
    }

    /// The zero-lift incidence at Reynolds number `re`, rad: the root of `cl(α)` nearest to
    /// `α = 0` (bisection on the interpolant to 1e-12 rad), or `None` if `cl` has no sign change
    /// in the table (or `re` is refused by the bounds).
    pub fn zero_lift_alpha(&self, re: f64) -> Option<f64> {
        let cl = |a: f64| self.coefficients(a, re).ok().map(|c| c.cl);
        let knots = self.common_knots();
        let mut best: Option<f64> = None;
        for w in knots.windows(2) {
            let (mut lo, mut hi) = (w[0], w[1]);
            let (mut flo, fhi) = (cl(lo)?, cl(hi)?);
            if flo == 0.0 {
                best = nearer(best, lo);
                continue;
            }
            if flo * fhi > 0.0 {
                continue;
            }
            while hi - lo > 1e-12 {
                let mid = 0.5 * (lo + hi);
                let fm = cl(mid)?;
                if (fm < 0.0) == (flo < 0.0) {
                    (lo, flo) = (mid, fm);
                } else {
                    hi = mid;
                }
            }
            best = nearer(best, 0.5 * (lo + hi));
        }
        best
    }

    /// Every table's incidence knots that lie in all tables' ranges, sorted.
    fn common_knots(&self) -> Vec<f64> {
        let lo = self.tables.iter().map(|f| f.table.alpha[0]).fold(f64::NEG_INFINITY, f64::max);
        let hi = self.tables.iter().map(|f| *f.table.alpha.last().unwrap()).fold(f64::INFINITY, f64::min);
        let mut k: Vec<f64> =
            self.tables.iter().flat_map(|f| f.table.alpha.iter().copied()).filter(|a| (lo..=hi).contains(a)).collect();
        k.sort_by(f64::total_cmp);
        k.dedup();
        k
    }
}

fn nearer(best: Option<f64>, a: f64) -> Option<f64> {
    match best {
        Some(b) if b.abs() <= a.abs() => Some(b),
        _ => Some(a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn table(re: f64, lift_slope: f64, cd0: f64) -> Table {
        let alpha: Vec<f64> = (-10..=10).map(|k| (k as f64).to_radians()).collect();
        Table {
            re: Some(re),
            cl: alpha.iter().map(|a| lift_slope * (a + 0.02)).collect(),
            cd: alpha.iter().map(|a| cd0 + a * a).collect(),
            cm: alpha.iter().map(|a| -0.05 - 0.1 * a).collect(),
            alpha,
        }
    }

    #[test]
    fn thin_plate_line_is_exact_with_its_slope() {
        let p = Polar::linear(2.0 * PI, 0.0, -0.3, 0.3).unwrap();
        let c = p.coefficients(0.1234, 5e4).unwrap();
        assert_relative_eq!(c.cl, 2.0 * PI * 0.1234, max_relative = 1e-14);
        assert_relative_eq!(c.dcl, 2.0 * PI, max_relative = 1e-14);
        assert_eq!((c.cd, c.cm, c.dcd, c.dcm), (0.0, 0.0, 0.0, 0.0));
        assert_relative_eq!(p.zero_lift_alpha(1e5).unwrap(), 0.0, epsilon = 1e-12);
    }

    #[test]
    fn reynolds_blend_is_linear_in_log_re() {
        let p = Polar::new(vec![table(1e5, 5.0, 0.02), table(4e5, 6.0, 0.01)]).unwrap();
        // Re = 2e5 is halfway in ln Re between 1e5 and 4e5.
        let c = p.coefficients(0.05, 2e5).unwrap();
        assert_relative_eq!(c.cl, 5.5 * (0.05 + 0.02), max_relative = 1e-12);
        assert_relative_eq!(c.dcl, 5.5, max_relative = 1e-9);
        assert_relative_eq!(c.cd, 0.015 + 0.05 * 0.05, max_relative = 1e-3);
        let (h, re) = (1.0, 2e5);
        let fd = (p.coefficients(0.05, re + h).unwrap().cl - p.coefficients(0.05, re - h).unwrap().cl) / (2.0 * h);
        assert_relative_eq!(c.dcl_dre, fd, max_relative = 1e-6);
        // At a table's own Re, that table alone.
        assert_relative_eq!(p.coefficients(0.05, 4e5).unwrap().cl, 6.0 * 0.07, max_relative = 1e-12);
        assert_relative_eq!(p.zero_lift_alpha(2e5).unwrap(), -0.02, epsilon = 1e-10);
    }

    #[test]
    fn out_of_range_is_an_error_or_a_clamp() {
        let p = Polar::new(vec![table(1e5, 5.0, 0.02), table(4e5, 6.0, 0.01)]).unwrap();
        let err = p.coefficients(0.2, 2e5).unwrap_err();
        assert!(matches!(err, AerofoilError::IncidenceOutOfRange { max_deg, .. } if (max_deg - 10.0).abs() < 1e-9));
        let err = p.coefficients(0.0, 5e5).unwrap_err();
        assert!(matches!(err, AerofoilError::ReynoldsOutOfRange { min, max, .. } if min == 1e5 && max == 4e5));
        let p = p.with_bounds(Bounds { alpha: AlphaOutOfRange::Clamp, re: OutOfRange::Clamp });
        let c = p.coefficients(0.2, 5e5).unwrap();
        assert_relative_eq!(c.cl, 6.0 * (10f64.to_radians() + 0.02), max_relative = 1e-12);
        assert_eq!(c.dcl, 0.0, "clamped: the slope of a constant");
        assert_eq!(p.coefficients(0.2, 5e5).unwrap(), p.coefficients(0.3, 1e7).unwrap());
    }

    #[test]
    fn flat_plate_extrapolation_continues_the_table_to_ninety_degrees() {
        let p = Polar::new(vec![table(1e5, 5.0, 0.02)]).unwrap();
        let p = p.with_bounds(Bounds { alpha: AlphaOutOfRange::FlatPlate, ..Bounds::default() });
        let (end, eps) = (10f64.to_radians(), 1e-9);
        let (inner, outer) = (p.coefficients(end - eps, 1e5).unwrap(), p.coefficients(end + eps, 1e5).unwrap());
        assert_relative_eq!(inner.cl, outer.cl, max_relative = 1e-7);
        assert_relative_eq!(inner.cd, outer.cd, max_relative = 1e-7);
        assert_relative_eq!(outer.cm, inner.cm, max_relative = 1e-7);
        let normal = p.coefficients(PI / 2.0, 1e5).unwrap();
        assert!(normal.cl.abs() < 1e-12 && (normal.cd - 2.0).abs() < 1e-12);
        let below = p.coefficients(-PI / 3.0, 1e5).unwrap();
        assert!(below.cl < 0.0 && below.cd > 1.0, "{below:?}");
        assert!(matches!(p.coefficients(1.7, 1e5), Err(AerofoilError::IncidenceOutOfRange { .. })));
    }

    #[test]
    fn invalid_tables_are_refused() {
        let mut t = table(1e5, 5.0, 0.02);
        t.cd[3] = -0.001;
        assert!(matches!(Polar::new(vec![t]), Err(AerofoilError::InvalidPolar { what, .. }) if what.contains("drag")));
        let unsorted = vec![table(2e5, 5.0, 0.02), table(1e5, 5.0, 0.02)];
        assert!(Polar::new(unsorted).is_err());
        let mut t = table(1e5, 5.0, 0.02);
        t.alpha.swap(2, 3);
        assert!(Polar::new(vec![t]).is_err());
        assert!(Polar::new(vec![]).is_err());
    }
}
