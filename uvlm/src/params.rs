//! Solver parameters (plain serde structs; case JSON deserialises straight into them).

use crate::biot_savart::CoreModel;
use crate::error::{Result, UvlmError};
use crate::images::{ImagePlane, validate_planes};
use serde::{Deserialize, Serialize};

/// How the wake nodes move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WakeConvection {
    /// Convected with the external flow, free stream + disturbance (SHARPy `convection_scheme = 2`,
    /// Ptera `prescribed_wake`).
    #[default]
    Prescribed,
    /// Convected with the local velocity (external flow + induced), forward Euler.
    Free,
}

/// The wake of a steady solve ([`crate::Uvlm::solve_steady`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SteadyWake {
    /// Semi-infinite trailing legs from the trailing-edge nodes along the free stream (a ring
    /// VLM; the steady limit of a wake of any length closed by `wake_closure`).
    #[default]
    SemiInfinite,
    /// A frozen wake of straight rows of total length `length` along the free stream, without
    /// closure: every strip's wake is one ring carrying the trailing-edge circulation, two
    /// finite trailing legs from the trailing-edge nodes and a spanwise segment joining their far
    /// ends. The steady state of a time march with `n_wake_rows` rows of `|V∞|·dt` and no
    /// closure has `length = n_wake_rows·|V∞|·dt`.
    Finite {
        /// Wake length along the free stream, m (> 0, finite).
        length: f64,
    },
}

/// Threading policy of the Biot–Savart evaluations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parallel {
    /// Always one thread.
    Off,
    /// rayon over point blocks when an evaluation has at least [`PARALLEL_MIN_PAIRS`]
    /// point–filament pairs per available thread (and more than one thread exists).
    #[default]
    Auto,
}

/// How repeated solves of one step ([`crate::Uvlm::solve_step`] called again within a step:
/// the sub-iterations of a strongly coupled step) treat the wake.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WakeReuse {
    /// Every solve recomputes the whole wake's induction at the current collocation points and
    /// segment midpoints (results depend only on the committed state and the final lattice).
    #[default]
    Recompute,
    /// The induction of the wake beyond the trailing-edge filaments (which does not move within
    /// a step) is computed once per step, at the points of the step's first solve, and reused by
    /// the later solves of the step; the filaments touching the trailing edge (the newest ring
    /// row's legs and the trailing-edge edge) and the bound rings are recomputed at the current
    /// points. The error is the far wake's velocity gradient times the lattice's motion between
    /// the first and the last solve of the step (docs/uvlm.md §9).
    Frozen,
}

/// The far wake's induction to a stated accuracy instead of exactly (docs/uvlm.md §14): from
/// `min_segments` wake segments on, a treecode over the wake's segments with an error bound;
/// below it (and in the treecode's near leaves), the direct sum in mixed precision when
/// `mixed_precision` (mixed.rs). Disabled (the crate's default), every wake filament is summed
/// directly in f64, bit for bit as without the option.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WakeAggregation {
    /// Aggregate at all. Default false.
    pub enabled: bool,
    /// Sum the wake directly below this many segments (its images included). Default 0.
    pub min_segments: usize,
    /// Bound of the aggregation error of the induced velocity at every point, relative to the
    /// free-stream speed |V∞|. Default 1e-6.
    pub tolerance: f64,
    /// Order p of the clusters' Cartesian expansions, ≤ 12. Default 5 (the fastest of 4–6 on
    /// the paper's wing at 160–320 wake rows, docs/uvlm.md §14; the bound holds at any order).
    pub order: usize,
    /// Most segments in a leaf cluster (summed directly when near), ≥ 1. Default 384, the
    /// fastest of 64–1024 on the paper's wing at 320 rows (512 within 2 %; docs/uvlm.md §14).
    pub leaf_size: usize,
    /// Sum the far wake (rows one and on) directly in mixed precision where the treecode does
    /// not apply: positions in f64, the kernel in f32, sums in f64 (mixed.rs, docs/uvlm.md
    /// §14); where it applies, its near leaves and its expansions likewise. Default true; only
    /// when `enabled`.
    pub mixed_precision: bool,
}

impl WakeAggregation {
    /// The wake size from which the harness aggregates (`aero.wake_aggregation`): segments of
    /// the far wake, images included. The treecode kept across steps (p = 5, leaves of 384,
    /// 1e-6 |V∞|, near leaves in mixed precision) breaks even with the mixed-precision direct
    /// sum at about 80 rows of the paper's wing (65 segments a row, 420 points; 5200 segments)
    /// and gains under 10 % up to 120 rows (7800 segments), docs/uvlm.md §14. The shipped
    /// cases' wakes (2600 and 5300 segments) are summed directly.
    pub const AUTO_MIN_SEGMENTS: usize = 8000;

    /// Aggregation switched off: every wake filament summed directly (the default).
    pub fn off() -> Self {
        Self { enabled: false, ..Self::default() }
    }

    /// The treecode at its default accuracy (1e-6 |V∞|) for every wake size.
    pub fn treecode() -> Self {
        Self { enabled: true, ..Self::default() }
    }

    /// Whether a wake of `n_segments` segments is aggregated.
    pub fn applies(&self, n_segments: usize) -> bool {
        self.enabled && n_segments >= self.min_segments
    }
}

impl Default for WakeAggregation {
    fn default() -> Self {
        Self { enabled: false, min_segments: 0, tolerance: 1e-6, order: 5, leaf_size: 384, mixed_precision: true }
    }
}

/// Work per thread below which [`Parallel::Auto`] stays sequential (point–filament pairs).
pub const PARALLEL_MIN_PAIRS: usize = 25_000;

/// Parameters of the UVLM solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UvlmParams {
    /// Air density ρ, kg/m³.
    pub rho: f64,
    /// Free-stream (wind) velocity in the global frame, m/s. The undisturbed part of the external
    /// flow ([`crate::Flow`]; a disturbance is attached with [`crate::Uvlm::set_disturbance`]) and
    /// the direction of steady trailing legs and wake closure.
    pub v_inf: [f64; 3],
    /// Maximum number of wake ring rows kept (truncation), ≥ 1. Default 40.
    #[serde(default = "default_wake_rows")]
    pub n_wake_rows: usize,
    /// Wake convection. Default prescribed.
    #[serde(default)]
    pub wake_convection: WakeConvection,
    /// Close the truncated wake by semi-infinite trailing legs along the free stream from the last
    /// row (instead of a closing spanwise segment). Default false (SHARPy / paper set-up).
    #[serde(default)]
    pub wake_closure: bool,
    /// Core of the bound filaments (and of the newest wake ring, which belongs to the
    /// trailing-edge unknowns). Default: 1e-6 m cut-off.
    #[serde(default)]
    pub bound_core: CoreModel,
    /// Core of the wake filaments (rows ≥ 2 and closure legs). Default: 1e-6 m cut-off; a Scully
    /// core of 5–10 % of the segment length is advisable for free wakes.
    #[serde(default)]
    pub wake_core: CoreModel,
    /// Image planes (symmetry and/or ground), at most two, perpendicular.
    #[serde(default)]
    pub images: Vec<ImagePlane>,
    /// Apply the Joukowski force to the trailing-edge segment (net strength Γ_w0 − Γ_TE, the
    /// newest wake row's circulation with the bound −Γ_TE) as Ptera Software and SHARPy's linear
    /// UVLM do; default false (SHARPy's time-marching UVLM: the segment is skipped). Zero at
    /// steady state; in unsteady flow a first-order term in the wake row length.
    #[serde(default)]
    pub te_segment_force: bool,
    /// Include the unsteady load term ρ·A·n·dΓ/dt. Default true.
    #[serde(default = "default_true")]
    pub unsteady_term: bool,
    /// Give the last panel row's trailing-edge corners their quarter of the unsteady load term
    /// (default true: every ring's ρ·A·n·dΓ/dt acts whole, a quarter at each corner). False
    /// reproduces SHARPy's time-marching UVLM, which skips those corners, so that the last row
    /// applies half its unsteady load, at its leading corners.
    #[serde(default = "default_true")]
    pub unsteady_te_corners: bool,
    /// Threading of the Biot–Savart kernels. Default auto.
    #[serde(default)]
    pub parallel: Parallel,
    /// The wake of a steady solve. Default semi-infinite legs (unsteady steps ignore it).
    #[serde(default)]
    pub steady_wake: SteadyWake,
    /// Reuse of the wake's induction by repeated solves of one step. Default recompute.
    #[serde(default)]
    pub wake_reuse: WakeReuse,
    /// Far-field aggregation of the wake's induction. Default off (every filament summed
    /// directly).
    #[serde(default)]
    pub wake_aggregation: WakeAggregation,
    /// Solve for Γ with the factorisation of an earlier influence matrix, corrected by iterative
    /// refinement against the current one to 1e-12 of the largest Γ, while that converges fast
    /// (refine.rs, docs/uvlm.md §9); the matrix is factorised again when it does not. Default
    /// false: every change of the matrix is factorised, bit for bit as without the option.
    #[serde(default)]
    pub aic_refinement: bool,
}

fn default_wake_rows() -> usize {
    40
}
fn default_true() -> bool {
    true
}

impl UvlmParams {
    /// Defaults for a given density and free stream.
    pub fn new(rho: f64, v_inf: [f64; 3]) -> Self {
        Self {
            rho,
            v_inf,
            n_wake_rows: 40,
            wake_convection: WakeConvection::Prescribed,
            wake_closure: false,
            bound_core: CoreModel::default(),
            wake_core: CoreModel::default(),
            images: Vec::new(),
            te_segment_force: false,
            unsteady_term: true,
            unsteady_te_corners: true,
            parallel: Parallel::Auto,
            steady_wake: SteadyWake::SemiInfinite,
            wake_reuse: WakeReuse::Recompute,
            wake_aggregation: WakeAggregation::default(),
            aic_refinement: false,
        }
    }

    /// Check every value.
    pub fn validate(&self) -> Result<()> {
        if !(self.rho.is_finite() && self.rho > 0.0) {
            return Err(UvlmError::InvalidParameter { field: "rho", value: self.rho });
        }
        if let Some(v) = self.v_inf.iter().find(|v| !v.is_finite()) {
            return Err(UvlmError::InvalidParameter { field: "v_inf", value: *v });
        }
        if self.n_wake_rows == 0 {
            return Err(UvlmError::InvalidParameter { field: "n_wake_rows", value: 0.0 });
        }
        for (field, c) in [("bound_core", self.bound_core), ("wake_core", self.wake_core)] {
            let p = c.parameter();
            if !(p.is_finite() && p >= 0.0) {
                return Err(UvlmError::InvalidParameter { field, value: p });
            }
        }
        if let SteadyWake::Finite { length } = self.steady_wake
            && !(length.is_finite() && length > 0.0)
        {
            return Err(UvlmError::InvalidParameter { field: "steady_wake.length", value: length });
        }
        let a = &self.wake_aggregation;
        if !(a.tolerance.is_finite() && a.tolerance > 0.0) {
            return Err(UvlmError::InvalidParameter { field: "wake_aggregation.tolerance", value: a.tolerance });
        }
        if a.order > crate::treecode::MAX_ORDER {
            return Err(UvlmError::InvalidParameter { field: "wake_aggregation.order", value: a.order as f64 });
        }
        if a.leaf_size == 0 {
            return Err(UvlmError::InvalidParameter { field: "wake_aggregation.leaf_size", value: 0.0 });
        }
        validate_planes(&self.images)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_round_trip_and_unknown_fields() {
        let json = r#"{"rho": 0.0889, "v_inf": [0, -25, 0], "wake_core": {"model": "scully", "fraction": 0.05}}"#;
        let p: UvlmParams = serde_json::from_str(json).unwrap();
        assert_eq!(p.n_wake_rows, 40);
        assert_eq!(p.wake_core, CoreModel::Scully { fraction: 0.05 });
        assert!(p.validate().is_ok());
        assert!(serde_json::from_str::<UvlmParams>(r#"{"rho": 1, "v_inf": [1,0,0], "wake_rows": 3}"#).is_err());
        assert_eq!(p.steady_wake, SteadyWake::SemiInfinite);
        let finite: UvlmParams =
            serde_json::from_str(r#"{"rho": 1, "v_inf": [1,0,0], "steady_wake": {"finite": {"length": 10}}}"#).unwrap();
        assert_eq!(finite.steady_wake, SteadyWake::Finite { length: 10.0 });
        for length in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let bad = UvlmParams { steady_wake: SteadyWake::Finite { length }, ..p.clone() };
            assert!(matches!(bad.validate(), Err(UvlmError::InvalidParameter { field: "steady_wake.length", .. })));
        }
        let bad = UvlmParams { rho: -1.0, ..p };
        assert!(matches!(bad.validate(), Err(UvlmError::InvalidParameter { field: "rho", .. })));
    }
}
