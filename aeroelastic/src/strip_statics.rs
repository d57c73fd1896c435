//! Steady strip aerodynamics in the statics (`aero.model: "strip"`, docs/statics.md §8): the
//! steady limit of the stability analysis' Theodorsen strips (`stability::Strips`: at zero
//! frequency `C = 1` and only the circulatory lift `L = ½ρU_n²c·a·α_n` at the quarter chord
//! remains) and of the time march's quasi-steady strips (`strip_march.rs`), taken with the
//! deformed geometry (incidence, lift and drag directions from the section-plane flow), and with
//! two options the Healy study asks for: the section polars (`aero.polars`, read at
//! each strip's own Reynolds number) and a tip loss (`aero.strip_tip_loss`).
//!
//! A diagnostic beside the lattice, not a replacement: strips know no downwash from the trailing
//! wake (unless the lifting-line tip loss stands in for it), no interaction between the folded
//! tip and the inner wing, and no slant of the hinge column (each strip's chord is its
//! stations' own).
//!
//! At each strip (the column between two neighbouring stations of a surface; at its middle `p`,
//! frame `x` along the column, `y` the stations' mean chord direction made normal to `x`,
//! `z = x × y`; chord `c` and leading-edge offset `e` the stations' mean; width `w` the
//! stations' distance):
//! * the air's velocity `u = V∞` (the structure at rest), its section-plane part
//!   `u⊥ = u − x (x·u)`, `V = |u⊥|`, drag direction `d̂ = u⊥/V`, lift direction `l̂ = d̂ × x`;
//! * the incidence `α = atan2(u·z, −u·y)` and the effective one `α_e = F α` (`F` the tip-loss
//!   factor, 1 without);
//! * `cl, cd, cm` of the body's polar at `(α_e, Re = V c/ν)`, or `a α_e, 0, 0` without one
//!   (`a` = `aero.strip_lift_slope`);
//! * the force `qS (cl l̂ + cd d̂)` with `qS = ½ρV²c w` at the quarter chord `p + y (e − c/4)`,
//!   and the moment `cm qS c x`; lumped half to each station with the rigid-arm transfer.
//!
//! **The tip-loss factor** (`"lifting_line"`) is Prandtl's lifting line solved by Glauert's
//! series (H. Glauert, *The Elements of Aerofoil and Airscrew Theory*, 1926, ch. XI; J. D.
//! Anderson, *Fundamentals of Aerodynamics*, §5.3.2) on each lifting surface's flat planform,
//! mirrored at its root (a wall or the plane of symmetry): with `b` the mirrored span,
//! `y = (b/2) cos θ`, `Γ = 2bV Σ A_n sin nθ` (n odd) and `μ = a c/(4b)`, the monoplane equation
//! `Σ A_n sin nθ (n μ + sin θ) = μ α sin θ` at `N` stations, and the factor
//! `F(η) = cl_LL/(a α) = (4b/(a c)) Σ A_n sin nθ / α`: the strip's lift at a uniform incidence
//! over its two-dimensional lift. It has no free parameter (an elliptic planform gives
//! `F = 1/(1 + a/(π AR))` at every station, the test). Applied to the incidence, so a
//! polar's nonlinear lift is read at the lifting line's effective incidence `α − α_i`.

use nalgebra::{DMatrix, DVector, Vector3};

use crate::aero::{AeroSettings, SectionLoad, StationMap};
use crate::aero_settings::TipLoss;
use crate::polar_correction::{StripPolars, StripReport};
use crate::statics::Strip;

/// Odd terms of Glauert's series (collocation stations over the half span).
const GLAUERT_TERMS: usize = 40;

/// Prandtl's lifting line on a planform mirrored at its root, by Glauert's series.
#[derive(Debug, Clone, PartialEq)]
pub struct LiftingLine {
    /// The coefficients `A_n` (n = 1, 3, 5, …) per unit incidence.
    a: Vec<f64>,
    /// Mirrored span `b`, m.
    span: f64,
    /// Lift slope `a`, 1/rad.
    slope: f64,
}

impl LiftingLine {
    /// The lifting line of a half wing of span `semi_span` (m) with the chord `chord(η)`
    /// (`η` from 0 at the root to 1 at the tip, m), mirrored at its root, with the section lift
    /// slope `slope` (1/rad).
    ///
    /// # Errors
    /// A non-positive span or slope, a chord that is not positive and finite at a station, or a
    /// singular system.
    pub fn new(semi_span: f64, slope: f64, chord: impl Fn(f64) -> f64) -> Result<Self, String> {
        if !(semi_span > 0.0 && slope > 0.0 && semi_span.is_finite() && slope.is_finite()) {
            return Err(format!("lifting line: span {semi_span} m and lift slope {slope} must be positive"));
        }
        let n = GLAUERT_TERMS;
        let b = 2.0 * semi_span;
        let mut m = DMatrix::zeros(n, n);
        let mut rhs = DVector::zeros(n);
        for k in 0..n {
            let theta = (k + 1) as f64 * std::f64::consts::FRAC_PI_2 / n as f64;
            let c = chord(theta.cos());
            if !(c > 0.0 && c.is_finite()) {
                return Err(format!("lifting line: chord {c} m at η = {:.4}", theta.cos()));
            }
            let mu = slope * c / (4.0 * b);
            for i in 0..n {
                let nn = (2 * i + 1) as f64;
                m[(k, i)] = (nn * theta).sin() * (nn * mu + theta.sin());
            }
            rhs[k] = mu * theta.sin();
        }
        let a = m.lu().solve(&rhs).ok_or("lifting line: singular Glauert system")?;
        Ok(Self { a: a.iter().copied().collect(), span: b, slope })
    }

    /// The factor `F(η) = cl_LL / (a α)` at `η` (0 root, 1 tip) where the chord is `chord`:
    /// zero at the tip.
    pub fn factor(&self, eta: f64, chord: f64) -> f64 {
        let theta = eta.clamp(0.0, 1.0).acos();
        let sum: f64 = self.a.iter().enumerate().map(|(i, a)| a * ((2 * i + 1) as f64 * theta).sin()).sum();
        4.0 * self.span / (self.slope * chord) * sum
    }
}

/// The static strips of a problem's lifting surfaces.
#[derive(Debug, Clone, PartialEq)]
pub struct StripStatics {
    /// Per column (the first station's index): its tip-loss factor (1 without).
    factor: Vec<f64>,
    /// The polar of every body (none: the lift slope), shared with the lattice's correction.
    polars: Option<StripPolars>,
    slope: f64,
}

impl StripStatics {
    /// The strips on the stations `map` with the settings `aero` and the section polars
    /// `polars`.
    ///
    /// # Errors
    /// A lifting line that cannot be solved (a degenerate planform); control surfaces (the
    /// static strips have no flaps).
    pub fn new(map: &[StationMap], aero: &AeroSettings, polars: Option<StripPolars>) -> Result<Self, String> {
        if !aero.control_surfaces.is_empty() {
            return Err("aero.control_surfaces: the static strips (aero.model \"strip\") have no flaps".into());
        }
        let mut factor = vec![1.0; map.len()];
        if aero.strip_tip_loss == TipLoss::LiftingLine {
            for r in crate::lifting::surface_ranges(map) {
                let st = &map[r.clone()];
                // A surface has a strip only between two stations.
                let (Some(first), Some(last)) = (st.first(), st.last()) else { continue };
                if st.len() < 2 {
                    continue;
                }
                let (a0, span) = (first.arc, last.arc - first.arc);
                let chord = |eta: f64| {
                    let s = a0 + eta * span;
                    let k = st.partition_point(|m| m.arc < s).clamp(1, st.len() - 1);
                    let (p, q) = (&st[k - 1], &st[k]);
                    let w = if q.arc > p.arc { ((s - p.arc) / (q.arc - p.arc)).clamp(0.0, 1.0) } else { 0.0 };
                    p.planform_chord + w * (q.planform_chord - p.planform_chord)
                };
                let ll = LiftingLine::new(span, aero.strip_lift_slope, chord)
                    .map_err(|e| format!("aero.strip_tip_loss: {e}"))?;
                for j in r.start..r.end.saturating_sub(1) {
                    let mid = 0.5 * (map[j].arc + map[j + 1].arc);
                    let eta = (mid - a0) / span;
                    factor[j] = ll.factor(eta, chord(eta));
                }
            }
        }
        Ok(Self { factor, polars, slope: aero.strip_lift_slope })
    }

    /// The tip-loss factor of each column (by its first station; 1 without a tip loss).
    pub fn factors(&self) -> &[f64] {
        &self.factor
    }

    /// The station loads of the strips on `stations` (driven as `map` says) in the free stream of
    /// `aero`, into `out`; each strip's force, incidence and coefficient into `report`
    /// (`delta_force` holds the whole strip force: there is no lattice force to change). The
    /// polars are read at `reynolds_factor` times each strip's `V c/ν`.
    ///
    /// # Errors
    /// A polar's range error, naming the strip and its body.
    pub fn loads(
        &self,
        stations: &[uvlm::SpanStation],
        (map, aero): (&[StationMap], &AeroSettings),
        reynolds_factor: f64,
        out: &mut [SectionLoad],
        report: &mut StripReport,
    ) -> Result<(), String> {
        let n = stations.len().saturating_sub(1);
        *report = StripReport {
            delta_force: vec![Vector3::zeros(); n],
            alpha: vec![f64::NAN; n],
            cl: vec![f64::NAN; n],
            ..StripReport::default()
        };
        for l in out.iter_mut() {
            l.force = Vector3::zeros();
            l.moment = Vector3::zeros();
        }
        let u = Vector3::from(aero.free_stream());
        for j in (0..n).filter(|&j| map[j].lifting == map[j + 1].lifting) {
            let (a, b) = (&stations[j], &stations[j + 1]);
            let p = 0.5 * (a.origin + b.origin);
            let width = (b.origin - a.origin).norm();
            let Some(x) = (b.origin - a.origin).try_normalize(1e-300) else { continue };
            let y_mean = 0.5 * (a.frame.column(1) + b.frame.column(1));
            let y = (y_mean - x * x.dot(&y_mean)).normalize();
            let z = x.cross(&y);
            let (chord, le) =
                (0.5 * (map[j].chord + map[j + 1].chord), 0.5 * (map[j].le_offset + map[j + 1].le_offset));
            let u_perp = u - x * x.dot(&u);
            let speed = u_perp.norm();
            if speed == 0.0 {
                continue;
            }
            let alpha = self.factor[j] * u.dot(&z).atan2(-u.dot(&y));
            let body = map[j + 1].body;
            let (cl, cd, cm) = match self.polars.as_ref().and_then(|p| p.polar_of(body)) {
                Some(polar) => {
                    let re = speed * chord / self.polars.as_ref().map_or(1.5e-5, StripPolars::kinematic_viscosity)
                        * reynolds_factor;
                    let c =
                        polar.coefficients(alpha, re).map_err(|e| format!("polar of strip {j} (body {body}): {e}"))?;
                    (c.cl, c.cd, c.cm)
                }
                None => (self.slope * alpha, 0.0, 0.0),
            };
            let qs = 0.5 * aero.rho * speed * speed * chord * width;
            let d = u_perp / speed;
            let l = d.cross(&x);
            let force = qs * (cl * l + cd * d);
            let moment = cm * qs * chord * x;
            let r1 = p + y * (le - 0.25 * chord);
            for i in [j, j + 1] {
                out[i].force += 0.5 * force;
                out[i].moment += (r1 - stations[i].origin).cross(&(0.5 * force)) + 0.5 * moment;
            }
            report.delta_force[j] = force;
            report.alpha[j] = alpha;
            report.cl[j] = cl;
            report.total_delta += force;
            report.profile_drag += cd * qs * d;
        }
        Ok(())
    }
}

/// The spanwise rows of the strips of `report` on `stations` (as [`crate::statics::strips_of`]
/// for the lattice): lift per unit span along `lift_dir`, its coefficient at the dynamic
/// pressure `qdyn` on the planform's chord, and the effective incidence.
pub(crate) fn strip_rows(
    map: &[StationMap],
    stations: &[uvlm::SpanStation],
    report: &StripReport,
    lift_dir: Vector3<f64>,
    qdyn: f64,
) -> Vec<Strip> {
    (0..stations.len().saturating_sub(1))
        .filter(|&j| map[j].lifting == map[j + 1].lifting)
        .map(|j| {
            let (a, b) = (stations[j].origin, stations[j + 1].origin);
            let width = (b - a).norm().max(1e-300);
            let l = report.delta_force.get(j).copied().unwrap_or_default().dot(&lift_dir) / width;
            Strip {
                s: 0.5 * (map[j].arc + map[j + 1].arc),
                position: (0.5 * (a + b)).into(),
                lift_per_span: l,
                cl: l / (qdyn * 0.5 * (map[j].planform_chord + map[j + 1].planform_chord)),
                alpha: report.alpha.get(j).copied().unwrap_or(f64::NAN),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::LiftingLine;
    use std::f64::consts::PI;

    /// An elliptic planform's lifting line has the closed form `F = 1/(1 + a/(π AR))` at every
    /// station (Prandtl); Glauert's series reproduces it to rounding.
    #[test]
    fn the_lifting_line_factor_of_an_elliptic_wing_is_prandtls() {
        let (s, c0) = (0.5, 0.1);
        for slope in [2.0 * PI, 5.0] {
            let ll = LiftingLine::new(s, slope, |eta: f64| c0 * (1.0 - eta * eta).sqrt()).unwrap();
            // Mirrored span b = 2s, area π c0 b/4.
            let ar = (2.0 * s) * (2.0 * s) / (PI * c0 * 2.0 * s / 4.0);
            let exact = 1.0 / (1.0 + slope / (PI * ar));
            for eta in [0.0, 0.3, 0.7, 0.95] {
                let f = ll.factor(eta, c0 * (1.0 - eta * eta).sqrt());
                assert!((f - exact).abs() < 1e-12, "η {eta}: {f} against {exact}");
            }
        }
    }

    /// A rectangular wing's factor falls from the root to zero at the tip, and its mean lies
    /// under the elliptic wing's of the same aspect ratio (a rectangular wing is less efficient).
    #[test]
    fn a_rectangular_wing_loses_lift_towards_its_tip() {
        let (s, c) = (0.5, 0.078);
        let ll = LiftingLine::new(s, 2.0 * PI, |_| c).unwrap();
        let f: Vec<f64> = (0..=20).map(|k| ll.factor(f64::from(k) / 20.0, c)).collect();
        assert!(f.windows(2).all(|w| w[1] <= w[0] + 1e-12), "{f:?}");
        assert!(f[20].abs() < 1e-12);
        // The values docs/statics.md §8 quotes (root, mid-span, hinge, the tip body's middle).
        for (eta, v) in [(0.0, 0.9164), (0.5, 0.8891), (0.73, 0.8306), (0.865, 0.7314), (0.95, 0.5532)] {
            assert!((ll.factor(eta, c) - v).abs() < 1e-4, "F({eta}) = {}", ll.factor(eta, c));
        }
        let mean = f[..20].iter().sum::<f64>() / 20.0;
        let ar = 2.0 * s / c;
        assert!(mean < 1.0 / (1.0 + 2.0 / ar) && mean > 0.7, "mean {mean}");
    }
}
