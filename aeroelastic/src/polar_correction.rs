//! The strip correction of the lattice's station loads by the section polars (issue 37,
//! docs/section_aero.md §7): every panel column of a body with a polar is a strip; its lattice
//! force goes through [`aerofoil::correct_strip`] and the change (lift replaced by the polar's,
//! profile drag added at the quarter chord, the polar's moment about the span) is shared half and
//! half by the column's two stations, with the rigid-arm transfer of the lattice's own loads.
//!
//! A strip between stations `j` and `j + 1` (quarter-chord points `p_j`, `p_{j+1}`):
//! frame `x̂ = (x_j + x_{j+1})/|…|` (span), `ŷ` the mean chord direction made perpendicular to
//! `x̂`, `ẑ = x̂ × ŷ`; chord the mean of the two; width `|(p_{j+1} − p_j)·x̂|`; the point
//! `p = (p_j + p_{j+1})/2`; its flow the air velocity relative to it without the lattice's own
//! induced velocity (the downwash is in the lattice's lift, hence in the effective incidence).

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use crate::aero::{SectionLoad, StationMap};
use crate::problem::Problem;
use crate::section_polars::polars_by_body;

/// The polars of a problem's bodies with the air they act in.
#[derive(Debug, Clone, PartialEq)]
pub struct StripPolars {
    by_body: Vec<Option<Arc<aerofoil::Polar>>>,
    rho: f64,
    kinematic_viscosity: f64,
}

/// What the correction of one lattice solution gave, per strip (panel column) and in total.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StripReport {
    /// Change of every strip's force by the correction, N (global; zero on strips without a
    /// polar).
    pub delta_force: Vec<Vector3<f64>>,
    /// Effective incidence of every strip, rad (NaN without a polar).
    pub alpha: Vec<f64>,
    /// Section lift coefficient of the polar at that incidence (NaN without a polar).
    pub cl: Vec<f64>,
    /// Sum of the change of force over the strips, N.
    pub total_delta: Vector3<f64>,
    /// Sum of the profile drag `cd qS` over the strips, N.
    pub profile_drag: f64,
}

impl StripPolars {
    /// The polars of `problem` (`None` when it has none).
    ///
    /// # Errors
    /// A body index out of range or given twice; `aero.polars` given but not loaded into
    /// [`Problem::polars`].
    pub fn of(problem: &Problem) -> Result<Option<Self>, String> {
        let Some(aero) = problem.aero.as_ref() else { return Ok(None) };
        if problem.polars.is_empty() {
            if !aero.polars.is_empty() {
                return Err("aero.polars: the polar files were not loaded into the problem (Problem::polars)".into());
            }
            return Ok(None);
        }
        Ok(Some(Self {
            by_body: polars_by_body(&problem.polars, problem.bodies.len())?,
            rho: aero.rho,
            kinematic_viscosity: aero.kinematic_viscosity,
        }))
    }

    /// The polar of body `body`, if it has one.
    pub fn polar_of(&self, body: usize) -> Option<&aerofoil::Polar> {
        self.by_body.get(body).and_then(Option::as_deref)
    }

    /// The air's kinematic viscosity, m²/s.
    pub fn kinematic_viscosity(&self) -> f64 {
        self.kinematic_viscosity
    }

    /// Correct the station loads `out` (the lattice's, lumped to the stations) of the lattice
    /// solution `loads` on `stations` (driven as `map` says); `flow(p)` is the air velocity
    /// relative to the structure at the global point `p`, without the lattice's induction.
    /// The strips' Reynolds numbers are `reynolds_factor` times their own `V c / ν` (1 but in
    /// the statics' load stepping, which holds them at the target airspeed's while the dynamic
    /// pressure is ramped).
    ///
    /// # Errors
    /// The polar's range errors, naming the strip and its body.
    #[allow(clippy::too_many_arguments)] // the lattice (stations, map, loads), the flow, the output
    pub fn correct(
        &self,
        stations: &[uvlm::SpanStation],
        map: &[StationMap],
        loads: &uvlm::Loads,
        flow: impl Fn(usize, Vector3<f64>) -> Vector3<f64>,
        reynolds_factor: f64,
        out: &mut [SectionLoad],
        report: &mut StripReport,
    ) -> Result<(), String> {
        let n = stations.len().saturating_sub(1);
        report.delta_force.clear();
        report.delta_force.resize(n, Vector3::zeros());
        report.alpha.clear();
        report.alpha.resize(n, f64::NAN);
        report.cl.clear();
        report.cl.resize(n, f64::NAN);
        report.total_delta = Vector3::zeros();
        report.profile_drag = 0.0;
        for j in 0..n {
            // Stations j and j + 1 bound a strip when they are on one lifting surface; the
            // lattice's strips run surface after surface, one fewer than stations on each.
            if map[j].lifting != map[j + 1].lifting {
                continue;
            }
            let i = j - map[j].lifting;
            let body = map[j + 1].body;
            let Some(polar) = self.polar_of(body) else { continue };
            let (a, b) = (&stations[j], &stations[j + 1]);
            let (pa, pb) = (a.origin + a.arm(0.25), b.origin + b.arm(0.25));
            let frame = strip_frame(&a.frame, &b.frame);
            let p = 0.5 * (pa + pb);
            let geometry =
                StripGeometry { frame, chord: 0.5 * (a.chord + b.chord), width: (pb - pa).dot(&frame.column(0)).abs() };
            let force = Vector3::from(loads.strip[i]);
            let (df, dm, c) = self
                .correct_one(
                    polar,
                    &aerofoil::LatticeSection::THIN_PLATE,
                    &geometry,
                    flow(j, p),
                    reynolds_factor,
                    force,
                )
                .map_err(|e| format!("polar of strip {j} (body {body}): {e}"))?;
            for (k, st) in [(j, a), (j + 1, b)] {
                out[k].force += 0.5 * df;
                out[k].moment += (p - st.origin).cross(&(0.5 * df)) + 0.5 * dm;
            }
            report.delta_force[j] = df;
            report.alpha[j] = c.alpha;
            report.cl[j] = c.coefficients.cl;
            report.total_delta += df;
            report.profile_drag += c.profile_drag();
        }
        Ok(())
    }

    /// Correct one strip of geometry `g` whose uncorrected force `force` (global, N; no moment
    /// about its quarter chord) comes from the lift line `line` (the lattice's thin plate, or a
    /// strip model's own slope), in the air velocity `flow` relative to it (global, m/s), its
    /// Reynolds number `reynolds_factor` times its own `V c/ν`: the change of force and the
    /// moment about the quarter chord (global), and the correction (strip frame).
    ///
    /// # Errors
    /// The polar's range errors, an impossible strip.
    pub fn correct_one(
        &self,
        polar: &aerofoil::Polar,
        line: &aerofoil::LatticeSection,
        g: &StripGeometry,
        flow: Vector3<f64>,
        reynolds_factor: f64,
        force: Vector3<f64>,
    ) -> Result<(Vector3<f64>, Vector3<f64>, aerofoil::Correction), aerofoil::AerofoilError> {
        let strip = aerofoil::Strip {
            flow: g.frame.transpose() * flow,
            chord: g.chord,
            width: g.width,
            rho: self.rho,
            kinematic_viscosity: self.kinematic_viscosity / reynolds_factor,
            fixed_reynolds: None,
            quarter_chord: Vector3::zeros(),
        };
        let inviscid = aerofoil::StripLoads { force: g.frame.transpose() * force, moment: Vector3::zeros() };
        let c = aerofoil::correct_strip(polar, line, &strip, &inviscid)?;
        Ok((g.frame * (c.loads.force - inviscid.force), g.frame * c.loads.moment, c))
    }
}

/// A strip's frame (columns span `x̂`, chord towards the leading edge `ŷ`, normal `ẑ`; global,
/// orthonormal), chord and span width, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripGeometry {
    /// The frame.
    pub frame: Matrix3<f64>,
    /// Chord, m.
    pub chord: f64,
    /// Width along `x̂`, m.
    pub width: f64,
}

/// The strip frame between two station frames (columns span, chord towards the leading edge,
/// normal), re-orthonormalised.
fn strip_frame(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix3<f64> {
    let x = (a.column(0) + b.column(0)).normalize();
    let y0 = a.column(1) + b.column(1);
    let y = (y0 - x * x.dot(&y0)).normalize();
    let z = x.cross(&y);
    Matrix3::from_columns(&[x, y, z])
}
