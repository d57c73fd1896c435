//! The strip correction of the lattice's station loads by the section polars (issue 37,
//! docs/section_aero.md §7): every panel column of a body with a polar is a strip; its lattice
//! force goes through [`aerofoil::correct_strip`] and the change (lift replaced by the polar's,
//! profile drag added at the quarter chord, the polar's moment about the span) is shared half and
//! half by the column's two stations, with the rigid-arm transfer of the lattice's own loads.
//!
//! A strip between stations `j` and `j + 1` (quarter-chord points `p_j`, `p_{j+1}`):
//! frame `x̂ = (p_{j+1} − p_j)/|…|` (span: the line of the strip's bound vortex; the stations'
//! own span axes would tilt it by half the angle between two bodies where they meet, since the
//! station there carries the inner body's frame), `ŷ` the mean chord direction made
//! perpendicular to `x̂`, `ẑ = x̂ × ŷ`; chord the mean of the two; width `|p_{j+1} − p_j|`; the point
//! `p = (p_j + p_{j+1})/2`; its flow the air velocity relative to it without the lattice's own
//! induced velocity (the downwash is in the lattice's lift, hence in the effective incidence).

use std::sync::Arc;

use nalgebra::{DMatrix, Matrix3, Vector3};

use crate::aero::{SectionLoad, StationMap};
use crate::problem::Problem;
use crate::section_polars::polars_by_body;

/// The polars of a problem's bodies with the air they act in.
#[derive(Debug, Clone, PartialEq)]
pub struct StripPolars {
    by_body: Vec<Option<Arc<aerofoil::Polar>>>,
    /// The dynamic-stall constants of every body (`None`: off), read by the strip march only.
    dynamic_by_body: Vec<Option<aerofoil::DynamicStallConstants>>,
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
    /// The polar's lift slope `dcl/dα` at that incidence, 1/rad (NaN without a polar; filled by
    /// [`StripPolars::correct`] and [`StripPolars::correct_strips`] only).
    pub cl_slope: Vec<f64>,
    /// Sum of the change of force over the strips, N.
    pub total_delta: Vector3<f64>,
    /// Sum of the profile drag forces `cd qS d̂` over the strips (each along its strip's
    /// section-plane flow; global), N.
    pub profile_drag: Vector3<f64>,
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
        let mut dynamic_by_body = vec![None; problem.bodies.len()];
        for p in &problem.polars {
            for &b in &p.bodies {
                if let Some(slot) = dynamic_by_body.get_mut(b) {
                    *slot = p.dynamic_stall;
                }
            }
        }
        Ok(Some(Self {
            by_body: polars_by_body(&problem.polars, problem.bodies.len())?,
            dynamic_by_body,
            rho: aero.rho,
            kinematic_viscosity: aero.kinematic_viscosity,
        }))
    }

    /// The polar of body `body`, if it has one.
    pub fn polar_of(&self, body: usize) -> Option<&aerofoil::Polar> {
        self.by_body.get(body).and_then(Option::as_deref)
    }

    /// The dynamic-stall constants of body `body`, if its polar has the model on.
    pub fn dynamic_stall_of(&self, body: usize) -> Option<&aerofoil::DynamicStallConstants> {
        self.dynamic_by_body.get(body).and_then(Option::as_ref)
    }

    /// The air's density, kg/m³.
    pub fn rho(&self) -> f64 {
        self.rho
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
        self.correct_strips(stations, map, &loads.strip, flow, reynolds_factor, out, report)
    }

    /// [`StripPolars::correct`] of the lattice's strip forces `strips` (`uvlm::Loads::strip`, one
    /// per panel column, surface after surface).
    ///
    /// # Errors
    /// The polar's range errors, naming the strip and its body.
    #[allow(clippy::too_many_arguments)] // the lattice (stations, map, strips), the flow, the output
    pub fn correct_strips(
        &self,
        stations: &[uvlm::SpanStation],
        map: &[StationMap],
        strips: &[[f64; 3]],
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
        report.cl_slope.clear();
        report.cl_slope.resize(n, f64::NAN);
        report.total_delta = Vector3::zeros();
        report.profile_drag = Vector3::zeros();
        for st in self.placed(stations, map) {
            let g = StripGeometry { frame: st.frame, chord: st.chord, width: st.width };
            let (df, dm, c) = self
                .correct_one(
                    st.polar,
                    &aerofoil::LatticeSection::THIN_PLATE,
                    &g,
                    flow(st.j, st.p),
                    reynolds_factor,
                    Vector3::from(strips[st.i]),
                )
                .map_err(|e| format!("polar of strip {} (body {}): {e}", st.j, st.body))?;
            for (k, f, m) in shares(stations, (st.j, st.p), df, dm) {
                out[k].force += f;
                out[k].moment += m;
            }
            report.delta_force[st.j] = df;
            report.alpha[st.j] = c.alpha;
            report.cl[st.j] = c.coefficients.cl;
            report.cl_slope[st.j] = c.coefficients.dcl;
            report.total_delta += df;
            report.profile_drag += st.frame * (c.profile_drag() * c.drag_dir);
        }
        Ok(())
    }

    /// The correction linearised about the lattice solution with strip forces `strips` on
    /// `stations` (driven as `map` says), each strip in the flow `flow(j, p)` (as
    /// [`StripPolars::correct`], at the strips' own Reynolds numbers): per strip, the
    /// derivatives of the change of its loads in its lattice force at fixed flow
    /// (`Correction::force_jacobian`, `moment_jacobian`: the polar's local slopes over the
    /// lattice's) and in its flow at fixed lattice force (`d_force_d_flow`, `d_moment_d_flow`),
    /// in global axes.
    ///
    /// # Errors
    /// The polar's range errors, naming the strip and its body.
    pub fn linearise(
        &self,
        stations: &[uvlm::SpanStation],
        map: &[StationMap],
        strips: &[[f64; 3]],
        flow: impl Fn(usize, Vector3<f64>) -> Vector3<f64>,
    ) -> Result<LinearCorrection, String> {
        let mut out = LinearCorrection { strips: Vec::new(), n_strips: strips.len(), n_stations: stations.len() };
        for st in self.placed(stations, map) {
            let c = self.correct_placed(&st, flow(st.j, st.p), Vector3::from(strips[st.i]))?;
            let (r, rt) = (st.frame, st.frame.transpose());
            out.strips.push(LinearStrip {
                j: st.j,
                i: st.i,
                p: st.p,
                force: r * (c.force_jacobian() - Matrix3::identity()) * rt,
                moment: r * c.moment_jacobian() * rt,
                force_flow: r * c.d_force_d_flow * rt,
                moment_flow: r * c.d_moment_d_flow * rt,
            });
        }
        Ok(out)
    }

    /// The strips of the lattice on `stations` whose body has a polar.
    fn placed<'a>(
        &'a self,
        stations: &'a [uvlm::SpanStation],
        map: &'a [StationMap],
    ) -> impl Iterator<Item = PlacedStrip<'a>> + 'a {
        let n = stations.len().saturating_sub(1);
        (0..n).filter_map(move |j| {
            // Stations j and j + 1 bound a strip when they are on one lifting surface; the
            // lattice's strips run surface after surface, one fewer than stations on each.
            if map[j].lifting != map[j + 1].lifting {
                return None;
            }
            let body = map[j + 1].body;
            let polar = self.by_body.get(body).and_then(Option::as_ref)?;
            let (a, b) = (&stations[j], &stations[j + 1]);
            let (pa, pb) = (a.origin + a.arm(0.25), b.origin + b.arm(0.25));
            let frame = strip_frame(pb - pa, &a.frame, &b.frame);
            Some(PlacedStrip {
                j,
                i: j - map[j].lifting,
                body,
                polar,
                frame,
                p: 0.5 * (pa + pb),
                chord: 0.5 * (a.chord + b.chord),
                width: (pb - pa).norm(),
            })
        })
    }

    /// The correction of strip `st` with the global flow `flow` and its lattice force `force`
    /// (global), at the strip's own Reynolds number.
    fn correct_placed(
        &self,
        st: &PlacedStrip<'_>,
        flow: Vector3<f64>,
        force: Vector3<f64>,
    ) -> Result<aerofoil::Correction, String> {
        let g = StripGeometry { frame: st.frame, chord: st.chord, width: st.width };
        self.correct_one(st.polar, &aerofoil::LatticeSection::THIN_PLATE, &g, flow, 1.0, force)
            .map(|(_, _, c)| c)
            .map_err(|e| format!("polar of strip {} (body {}): {e}", st.j, st.body))
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

/// A panel column of a body with a polar, between stations `j` and `j + 1`.
struct PlacedStrip<'a> {
    /// Its first station.
    j: usize,
    /// Its index among the lattice's strips (`uvlm::Loads::strip`).
    i: usize,
    body: usize,
    polar: &'a aerofoil::Polar,
    /// Span, chord (towards the leading edge) and normal, global.
    frame: Matrix3<f64>,
    /// The quarter-chord midpoint, m.
    p: Vector3<f64>,
    chord: f64,
    width: f64,
}

/// The shares of the change `df`, `dm` (about the quarter-chord midpoint `p`) of the loads of
/// the strip from station `j` to `j + 1`: half and half to its two stations, with the rigid-arm
/// transfer; `(station, force, moment)`.
fn shares(
    stations: &[uvlm::SpanStation],
    (j, p): (usize, Vector3<f64>),
    df: Vector3<f64>,
    dm: Vector3<f64>,
) -> [(usize, Vector3<f64>, Vector3<f64>); 2] {
    [j, j + 1].map(|k| (k, 0.5 * df, (p - stations[k].origin).cross(&(0.5 * df)) + 0.5 * dm))
}

/// One strip of a [`LinearCorrection`], global axes.
#[derive(Debug, Clone, PartialEq)]
struct LinearStrip {
    /// Its first station and its index among the lattice's strips.
    j: usize,
    i: usize,
    /// Its quarter-chord midpoint, about which `moment` and `moment_flow` act.
    p: Vector3<f64>,
    /// `∂ΔF/∂F_inv` and `∂ΔM/∂F_inv` at fixed flow.
    force: Matrix3<f64>,
    moment: Matrix3<f64>,
    /// `∂ΔF/∂u` and `∂ΔM/∂u` at fixed lattice force.
    force_flow: Matrix3<f64>,
    moment_flow: Matrix3<f64>,
}

/// The strip correction linearised about a lattice solution ([`StripPolars::linearise`]): the
/// change of the station loads per change of the strips' lattice forces and of their flows.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearCorrection {
    strips: Vec<LinearStrip>,
    n_strips: usize,
    n_stations: usize,
}

impl LinearCorrection {
    /// Station loads `[F, M]` per station (6·stations) per unit lattice force of each strip
    /// (3·strips, stacked as `uvlm::Loads::strip`), at fixed flow; `stations` those of the
    /// linearisation (their origins are the moments' reference points).
    pub fn load_per_strip_force(&self, stations: &[uvlm::SpanStation]) -> DMatrix<f64> {
        self.map(stations, |s| (s.force, s.moment))
    }

    /// Station loads (6·stations) per unit flow velocity at each strip's quarter-chord midpoint
    /// (3·strips, global axes), at fixed lattice forces.
    pub fn load_per_strip_flow(&self, stations: &[uvlm::SpanStation]) -> DMatrix<f64> {
        self.map(stations, |s| (s.force_flow, s.moment_flow))
    }

    /// The quarter-chord midpoint of every corrected strip, by its index among the lattice's
    /// strips (`None`: no polar).
    pub fn points(&self) -> Vec<Option<Vector3<f64>>> {
        let mut out = vec![None; self.n_strips];
        for s in &self.strips {
            out[s.i] = Some(s.p);
        }
        out
    }

    /// The station loads per strip input of the 3 × 3 blocks `of(strip)` (force, moment about
    /// the strip's point), shared as [`StripPolars::correct`] shares them.
    fn map(
        &self,
        stations: &[uvlm::SpanStation],
        of: impl Fn(&LinearStrip) -> (Matrix3<f64>, Matrix3<f64>),
    ) -> DMatrix<f64> {
        let mut k = DMatrix::zeros(6 * self.n_stations, 3 * self.n_strips);
        for s in &self.strips {
            let (f, m) = of(s);
            for c in 0..3 {
                let (df, dm) = (f.column(c).into_owned(), m.column(c).into_owned());
                for (st, force, moment) in shares(stations, (s.j, s.p), df, dm) {
                    for a in 0..3 {
                        k[(6 * st + a, 3 * s.i + c)] += force[a];
                        k[(6 * st + 3 + a, 3 * s.i + c)] += moment[a];
                    }
                }
            }
        }
        k
    }
}

/// The strip frame (columns span, chord towards the leading edge, normal) with its span along
/// `span` (from the strip's inner quarter-chord point to its outer one) and its chord the mean of
/// the two station frames' chord directions, made perpendicular to it.
fn strip_frame(span: Vector3<f64>, a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix3<f64> {
    // A strip of no width (coincident quarter-chord points) keeps the stations' mean span axis.
    let x = span.try_normalize(1e-300).unwrap_or_else(|| (a.column(0) + b.column(0)).normalize());
    let y0 = a.column(1) + b.column(1);
    let y = (y0 - x * x.dot(&y0)).normalize();
    let z = x.cross(&y);
    Matrix3::from_columns(&[x, y, z])
}
