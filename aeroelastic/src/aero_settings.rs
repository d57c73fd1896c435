//! The aerodynamic settings of a problem (`aero`): air, free stream, lattice, wake, images and
//! the coupling iteration, and the UVLM parameters they give.

use std::sync::atomic::{AtomicUsize, Ordering};

use crate::gust_settings::GustSpec;
pub use crate::planform::{LiftingSurface, Sections, SurfacePlan, Taper};

/// Aerodynamic settings of a case.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AeroSettings {
    /// Air density, kg/m³.
    pub rho: f64,
    /// Free-stream velocity, m/s (global). With `airspeed` it gives only the direction; omitted,
    /// the free stream is `airspeed` along −Y.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub v_inf: Option<[f64; 3]>,
    /// Free-stream speed, m/s: replaces the magnitude of `v_inf` (or flows along −Y without it).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub airspeed: Option<f64>,
    /// Sideslip angle β, degrees, in the flight-mechanics convention: positive when the relative
    /// wind comes from the right (starboard). The span runs along +X (starboard) and the flow
    /// along −Y, so the free stream of `v_inf`/`airspeed` is turned about the vertical axis (+Z)
    /// by −β: a stream along −Y becomes `−V (sin β, cos β, 0)`, blowing from the tip towards the
    /// root for β > 0 (docs/case-file.md). Default 0, in (−90, 90).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero"))]
    pub sideslip_deg: f64,
    /// Chord, m: one number for every body, or `[root, tip]` per body (linear taper), in body
    /// order. A body's root must meet its parent's tip across a shared hinge column. The
    /// one-surface shorthand (every body, in order): required without `surfaces`, refused with it.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub chord: Option<Taper>,
    /// Distance from the beam axis to the leading edge along the section y axis, m (0.5·chord
    /// for a mid-chord axis): one number or `[root, tip]` per body, as `chord`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub le_offset: Option<Taper>,
    /// How the lattice's grid columns are cut: `"normal"` to the beam axis (default) or
    /// `"streamwise"` (along the free stream without sideslip; `chord` and `le_offset` are then
    /// measured along the stream). The same on an unswept wing. Shorthand, as `chord`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Sections::is_normal"))]
    pub sections: Sections,
    /// Spanwise panels per body, in body order (shorthand, as `chord`).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub panels_per_body: Vec<usize>,
    /// Several lifting surfaces, each a chain of bodies with its own planform, panels and wake,
    /// solved in one influence system; bodies on no surface carry no aerodynamics. Without it,
    /// `chord`, `le_offset`, `sections` and `panels_per_body` make one surface of every body.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub surfaces: Vec<LiftingSurface>,
    /// Chordwise panels.
    pub n_chordwise: usize,
    /// Wake rows kept (truncation).
    pub n_wake_rows: usize,
    /// Vortex cut-off radius for bound and wake filaments, m (SHARPy-style; ~1 cm needed at high
    /// AoA). Default 1e-6 m.
    #[cfg_attr(feature = "serde", serde(default = "default_cutoff"))]
    pub cutoff_radius: f64,
    /// Close the truncated wake with semi-infinite legs along the free stream (removes the
    /// ≈ −1.3 % lift bias of a 40-row wake); default false (the paper's and SHARPy's set-up).
    #[cfg_attr(feature = "serde", serde(default))]
    pub wake_closure: bool,
    /// Apply the Kutta–Joukowski force to the trailing-edge segment, whose net circulation
    /// Γ_w0 − Γ_TE is what the last step shed (as SHARPy's linear UVLM and Ptera Software do);
    /// default false (SHARPy's time-marching UVLM and the paper: the segment carries no load).
    /// Zero in steady flow; a first-order discretisation term otherwise (≈ −ρ·h·Δy·dΓ_TE/dt with
    /// h the wake row length), which vanishes as the chordwise panels are refined.
    #[cfg_attr(feature = "serde", serde(default))]
    pub te_segment_force: bool,
    /// Give the last panel row's trailing-edge corners their quarter of the unsteady load term
    /// ρ·A·n·dΓ/dt; default true (the whole term acts). False reproduces SHARPy's time-marching
    /// UVLM, which skips those corners: the last row applies half its unsteady load.
    #[cfg_attr(feature = "serde", serde(default = "default_true"))]
    pub unsteady_te_corners: bool,
    /// Mirror planes (at most two, perpendicular): a wind-tunnel wall or floor at a wall-mounted
    /// model's root, an aircraft's plane of symmetry, the ground. Each reflects every bound and
    /// wake vortex (image vortices). Default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub images: Vec<MirrorPlane>,
    /// Coupling iteration settings.
    #[cfg_attr(feature = "serde", serde(default))]
    pub coupling: Coupling,
    /// A gust or turbulence field convected with the free stream (docs/gust.md); default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub gust: Option<GustSpec>,
    /// Sum the far wake to within 1e-6 of the free-stream speed at every point instead of
    /// exactly (docs/uvlm.md §14): a wake of at least `wake_aggregation_min_segments` filaments
    /// (its images included) goes through the UVLM's treecode, a shorter one is summed directly
    /// in mixed precision (`wake_mixed_precision`); default true. `false` sums every wake
    /// directly in f64.
    #[cfg_attr(feature = "serde", serde(default = "default_true"))]
    pub wake_aggregation: bool,
    /// The wake size from which `wake_aggregation` applies, filaments (the far wake's segments
    /// with their images); default 8000 (`uvlm::WakeAggregation::AUTO_MIN_SEGMENTS`: about 120
    /// rows of the paper's wing or 90 of Healy's, where the treecode breaks even with the
    /// mixed-precision direct sum, docs/uvlm.md §14). 0 aggregates every wake.
    #[cfg_attr(feature = "serde", serde(default = "default_aggregation_min_segments"))]
    pub wake_aggregation_min_segments: usize,
    /// With `wake_aggregation`: sum the far wake (rows one and on) in mixed precision where the
    /// treecode does not apply (positions and sums in f64, the kernel in f32; within 1e-6 of the
    /// free-stream speed, docs/uvlm.md §14); default true. `false` sums it in f64.
    #[cfg_attr(feature = "serde", serde(default = "default_true"))]
    pub wake_mixed_precision: bool,
    /// Solve for the circulations of a moving lattice on the factorisation of an earlier
    /// influence matrix, refined against the current one to 1e-12 of the largest circulation,
    /// and factorise again only when the refinement slows (docs/uvlm.md §9); default true.
    /// `false` factorises every change of the matrix (with `wake_aggregation: false`, bit for bit
    /// the exact f64 path).
    #[cfg_attr(feature = "serde", serde(default = "default_true"))]
    pub aic_refinement: bool,
    /// Section polars (issue 37, docs/section_aero.md): the lattice's loads on the strips of
    /// these bodies are corrected by the polar (lift, profile drag, moment); default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub polars: Vec<crate::section_polars::PolarSpec>,
    /// Kinematic viscosity of the air, m²/s, for the strips' Reynolds number `V c / ν` with
    /// `polars`; default 1.5e-5 (air near 20 °C).
    #[cfg_attr(feature = "serde", serde(default = "default_kinematic_viscosity"))]
    pub kinematic_viscosity: f64,
    /// The time march's and the statics' aerodynamics: `"uvlm"` (default, the lattice and its
    /// wake) or `"strip"` (quasi-steady thin-aerofoil strips at the span stations, no wake:
    /// docs/coupling.md §9; in the statics the steady strips of `strip_statics.rs`, with the
    /// section polars and `strip_tip_loss`, docs/statics.md §8). Stability (its own
    /// `stability.aerodynamics`), gust and trim use the lattice whatever this says.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "AeroModel::is_uvlm"))]
    pub model: AeroModel,
    /// Lift slope of the strips of `model: "strip"`, 1/rad. Default 2π.
    #[cfg_attr(feature = "serde", serde(default = "default_lift_slope"))]
    pub strip_lift_slope: f64,
    /// The static strips' tip loss (`model: "strip"`, statics only): `"none"` (default: every
    /// strip two-dimensional) or `"lifting_line"` (each strip's incidence scaled by the
    /// lifting-line factor of its planform, docs/statics.md §8).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "TipLoss::is_none"))]
    pub strip_tip_loss: TipLoss,
    /// Trailing-edge control surfaces (at most 16): flaps over span ranges of bodies, at a fixed
    /// deflection or a schedule in time (docs/case-file.md); default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub control_surfaces: Vec<crate::control_surface::ControlSurface>,
}

/// The time march's aerodynamic model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AeroModel {
    /// The unsteady vortex lattice.
    #[default]
    Uvlm,
    /// Quasi-steady strip theory.
    Strip,
}

impl AeroModel {
    /// Whether this is the default.
    pub fn is_uvlm(&self) -> bool {
        *self == AeroModel::Uvlm
    }
}

/// The tip loss of the static strips (`aero.strip_tip_loss`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum TipLoss {
    /// Two-dimensional strips.
    #[default]
    None,
    /// Prandtl's lifting line (Glauert's series) on the flat planform mirrored at its root: each
    /// strip's incidence times the ratio of its lifting-line lift to its two-dimensional lift
    /// at a uniform incidence.
    LiftingLine,
}

impl TipLoss {
    /// Whether this is the default (no tip loss).
    pub fn is_none(&self) -> bool {
        *self == TipLoss::None
    }
}

/// A mirror plane of the flow.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct MirrorPlane {
    /// A point of the plane, m (global).
    pub point: [f64; 3],
    /// Its normal (any non-zero length), global.
    pub normal: [f64; 3],
}

impl AeroSettings {
    /// The UVLM parameters of these settings with free stream `v_inf`: wake, cores, images, reuse
    /// and aggregation of the wake; single-threaded (runs are parallel across cases) unless
    /// [`register_runs`] counts this run alone.
    pub fn uvlm_params(&self, v_inf: [f64; 3]) -> uvlm::UvlmParams {
        let mut params = uvlm::UvlmParams::new(self.rho, v_inf);
        params.n_wake_rows = self.n_wake_rows;
        params.wake_closure = self.wake_closure;
        params.te_segment_force = self.te_segment_force;
        params.unsteady_te_corners = self.unsteady_te_corners;
        params.bound_core = uvlm::CoreModel::CutOff { radius: self.cutoff_radius };
        params.wake_core = uvlm::CoreModel::CutOff { radius: self.cutoff_radius };
        params.images = self.images.iter().map(|p| uvlm::ImagePlane { point: p.point, normal: p.normal }).collect();
        params.parallel =
            if ACTIVE_RUNS.load(Ordering::SeqCst) == 1 { uvlm::Parallel::Auto } else { uvlm::Parallel::Off };
        params.wake_reuse = if self.coupling.reuse_wake { uvlm::WakeReuse::Frozen } else { uvlm::WakeReuse::Recompute };
        params.wake_aggregation = if self.wake_aggregation {
            uvlm::WakeAggregation {
                min_segments: self.wake_aggregation_min_segments,
                mixed_precision: self.wake_mixed_precision,
                ..uvlm::WakeAggregation::treecode()
            }
        } else {
            uvlm::WakeAggregation::off()
        };
        params.aic_refinement = self.aic_refinement;
        params
    }
}

/// Time marches under way in this process through [`register_runs`].
static ACTIVE_RUNS: AtomicUsize = AtomicUsize::new(0);

/// Registers `n` time marches that go side by side until the guard drops. While exactly one is
/// under way it may use every rayon thread for its Biot–Savart sums (`uvlm::Parallel::Auto`);
/// with several (or any other concurrent caller registering its own), each keeps one thread.
/// A counter rather than a flag, so that concurrent callers (tests, library users) cannot
/// switch each other's setting, and the guard releases it on a panic too.
#[must_use = "the runs count as under way only while the guard lives"]
pub fn register_runs(n: usize) -> RunsGuard {
    ACTIVE_RUNS.fetch_add(n, Ordering::SeqCst);
    RunsGuard(n)
}

/// Guard of [`register_runs`].
pub struct RunsGuard(usize);

impl Drop for RunsGuard {
    fn drop(&mut self) {
        ACTIVE_RUNS.fetch_sub(self.0, Ordering::SeqCst);
    }
}

#[cfg(feature = "serde")]
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

#[cfg(feature = "serde")]
fn default_lift_slope() -> f64 {
    2.0 * std::f64::consts::PI
}

#[cfg(feature = "serde")]
fn default_cutoff() -> f64 {
    1e-6
}

fn default_aggregation_min_segments() -> usize {
    uvlm::WakeAggregation::AUTO_MIN_SEGMENTS
}

fn default_kinematic_viscosity() -> f64 {
    1.5e-5
}

fn default_true() -> bool {
    true
}

impl AeroSettings {
    /// The free-stream velocity, m/s: `v_inf`, scaled to `airspeed` when both are given, or
    /// `airspeed` along −Y, turned about +Z by −`sideslip_deg`. Validated cases have one of them.
    pub fn free_stream(&self) -> [f64; 3] {
        let v = self.stream_without_sideslip();
        if self.sideslip_deg == 0.0 {
            return v;
        }
        // A rotation about +Z by −β: x' = x cos β + y sin β, y' = −x sin β + y cos β.
        let (s, c) = self.sideslip_deg.to_radians().sin_cos();
        [v[0] * c + v[1] * s, -v[0] * s + v[1] * c, v[2]]
    }

    /// The free stream before the sideslip turns it, m/s.
    pub fn stream_without_sideslip(&self) -> [f64; 3] {
        match (self.v_inf, self.airspeed) {
            (Some(v), None) => v,
            (Some(v), Some(u)) => {
                let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                [u * v[0] / n, u * v[1] / n, u * v[2] / n]
            }
            (None, Some(u)) => [0.0, -u, 0.0],
            (None, None) => [0.0; 3],
        }
    }

    /// The free stream's speed, m/s.
    pub fn speed(&self) -> f64 {
        let v = self.free_stream();
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }
}

/// Aero-structure coupling per step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct Coupling {
    /// Extra sub-iterations per step (0 = loosely coupled).
    pub max_sub_iterations: usize,
    /// Relative change of the station loads that ends the sub-iterations.
    pub tolerance: f64,
    /// Relaxation factor of the loads between sub-iterations, in (0, 1].
    pub relaxation: f64,
    /// Compute the wake's induction once per step and reuse it in the sub-iterations (only the
    /// trailing-edge filaments and the bound rings follow the structure's motion; docs/uvlm.md
    /// §9); default true. False recomputes the whole wake at every sub-iteration.
    pub reuse_wake: bool,
    /// The loads of a strongly coupled step's first structural solve (docs/coupling.md §4).
    pub predictor: LoadPredictor,
}

impl Default for Coupling {
    fn default() -> Self {
        Self {
            max_sub_iterations: 0,
            tolerance: 1e-4,
            relaxation: 1.0,
            reuse_wake: true,
            predictor: LoadPredictor::default(),
        }
    }
}

/// Where the first structural solve of a strongly coupled step (`max_sub_iterations` ≥ 1) takes
/// its loads from. Both end on the same test, the sub-iterations' relative load change within
/// `tolerance`; a loosely coupled step always solves at the predicted structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LoadPredictor {
    /// The loads of the last two steps extrapolated linearly to the new time: no aerodynamic
    /// solve before the structure's first step, one fewer per step.
    #[default]
    Extrapolate,
    /// An aerodynamic solve at the structure predicted from its state at the step's start.
    Solve,
}

impl AeroSettings {
    /// The lifting surfaces resolved against `case`'s bodies: `surfaces`, or the one-surface
    /// shorthand of every body in order. Checks the names, the lists against the bodies, that no
    /// body is on two surfaces and that the shorthand and `surfaces` are not mixed; the errors
    /// name the field. (That consecutive bodies are joined by a flared hinge is checked where
    /// the stations are laid out, [`crate::aero::station_map`].)
    pub fn surface_plans(&self, case: &crate::problem::Problem) -> Result<Vec<SurfacePlan>, String> {
        if self.surfaces.is_empty() {
            let (Some(chord), Some(le_offset)) = (&self.chord, &self.le_offset) else {
                let missing = if self.chord.is_none() { "aero.chord" } else { "aero.le_offset" };
                return Err(format!(
                    "{missing}: missing (give `chord`, `le_offset` and `panels_per_body`, or `surfaces`)"
                ));
            };
            let plan = SurfacePlan {
                name: "wing".into(),
                field: "aero".into(),
                bodies: (0..case.bodies.len()).collect(),
                chord: chord.clone(),
                le_offset: le_offset.clone(),
                panels: self.panels_per_body.clone(),
                sections: self.sections,
                n_chordwise: self.n_chordwise,
            };
            plan.check()?;
            return Ok(vec![plan]);
        }
        let shorthand = [
            ("aero.chord", self.chord.is_some()),
            ("aero.le_offset", self.le_offset.is_some()),
            ("aero.panels_per_body", !self.panels_per_body.is_empty()),
            ("aero.sections", !self.sections.is_normal()),
        ];
        if let Some((field, _)) = shorthand.iter().find(|x| x.1) {
            return Err(format!("{field}: give it per surface in `aero.surfaces`, not beside it"));
        }
        let mut out: Vec<SurfacePlan> = Vec::with_capacity(self.surfaces.len());
        for (k, s) in self.surfaces.iter().enumerate() {
            let field = format!("aero.surfaces[{k}]");
            if s.name.is_empty() || self.surfaces[..k].iter().any(|o| o.name == s.name) {
                return Err(format!("{field}.name: `{}` is empty or names another surface too", s.name));
            }
            if s.bodies.is_empty() {
                return Err(format!("{field}.bodies: a surface needs at least one body"));
            }
            let mut bodies = Vec::with_capacity(s.bodies.len());
            for (i, name) in s.bodies.iter().enumerate() {
                let b = case.body_index(name).ok_or_else(|| format!("{field}.bodies[{i}]: no body named `{name}`"))?;
                if bodies.contains(&b) {
                    return Err(format!("{field}.bodies[{i}]: `{name}` is already on this surface"));
                }
                if let Some(o) = out.iter().position(|p| p.bodies.contains(&b)) {
                    return Err(format!("{field}.bodies[{i}]: `{name}` is already on aero.surfaces[{o}]"));
                }
                bodies.push(b);
            }
            let plan = SurfacePlan {
                name: s.name.clone(),
                bodies,
                chord: s.chord.clone(),
                le_offset: s.le_offset.clone(),
                panels: s.panels_per_body.clone(),
                sections: s.sections,
                n_chordwise: s.n_chordwise.unwrap_or(self.n_chordwise),
                field,
            };
            plan.check()?;
            out.push(plan);
        }
        Ok(out)
    }

    /// The size of the lattice: its grid columns (stations) and bound rings over every surface.
    pub fn lattice_size(&self) -> (f64, f64) {
        let columns = |p: &[usize]| p.iter().map(|&x| x as f64).sum::<f64>() + 1.0;
        if self.surfaces.is_empty() {
            let c = columns(&self.panels_per_body);
            return (c, c * self.n_chordwise as f64);
        }
        self.surfaces.iter().fold((0.0, 0.0), |(c, r), s| {
            let cs = columns(&s.panels_per_body);
            (c + cs, r + cs * s.n_chordwise.unwrap_or(self.n_chordwise) as f64)
        })
    }

    /// The smallest and largest chord of every surface, m (root and tip values).
    pub fn chord_extremes(&self) -> (f64, f64) {
        let all = self.chord.iter().chain(self.surfaces.iter().map(|s| &s.chord)).flat_map(Taper::values);
        all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| (lo.min(c), hi.max(c)))
    }

    /// Chord and leading-edge offset per body of `case` (`[root, tip]` each) from the surfaces;
    /// `None` for a body on no surface.
    pub fn body_planforms(&self, case: &crate::problem::Problem) -> Result<Vec<Option<[[f64; 2]; 2]>>, String> {
        let mut out = vec![None; case.bodies.len()];
        for plan in self.surface_plans(case)? {
            for (i, &b) in plan.bodies.iter().enumerate() {
                let ends = |t: &Taper| [t.at(i, 0.0), t.at(i, 1.0)];
                out[b] = Some([ends(&plan.chord), ends(&plan.le_offset)]);
            }
        }
        Ok(out)
    }
}
