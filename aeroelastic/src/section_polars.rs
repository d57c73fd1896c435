//! Section polars of a problem (issue 37, docs/section_aero.md §7): the case field
//! `aero.polars` ([`PolarSpec`]: which bodies, which file, what to do outside its ranges) and the
//! loaded tables the analyses read ([`BodyPolar`], in [`Problem::polars`](crate::Problem)).
//!
//! The analyses read no files: a front end reads each [`PolarSpec::file`] (the harness, relative
//! to the case file, with `aerofoil::read_polar`) and hands the typed [`aerofoil::Polar`]s over.

use std::sync::Arc;

use crate::problem::Problem;

/// One entry of `aero.polars`: a polar file for some bodies.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct PolarSpec {
    /// Body indices (0-based, in the order of `bodies`) whose lattice strips this polar corrects;
    /// each body at most once over all entries. Bodies without a polar keep the lattice's loads.
    pub bodies: Vec<usize>,
    /// The polar CSV file (columns `alpha_deg, cl, cd, cm` and `re` for several Reynolds numbers;
    /// docs/section_aero.md §2), relative to the case file's folder.
    pub file: String,
    /// What an incidence or Reynolds number outside the table does; default: an error for both.
    #[cfg_attr(feature = "serde", serde(default))]
    pub bounds: PolarBounds,
    /// The dynamic-stall model of these bodies' strips (docs/section_aero.md §8); absent: off
    /// (the polar read quasi-steadily). Only the strip-theory march (`aero.model: "strip"`)
    /// applies it.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub dynamic_stall: Option<DynamicStallSpec>,
}

/// The constants of the dynamic-stall model (`aero.polars[i].dynamic_stall`), dimensionless;
/// every field defaults to the value of [`aerofoil::DynamicStallConstants::default`] (sources in
/// docs/section_aero.md §8.2), so `"dynamic_stall": {}` turns the model on with them.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct DynamicStallSpec {
    /// Wagner amplitude of the slow pole `A₁` (default 0.165, Jones).
    pub a1: f64,
    /// Slow pole `b₁`, per semichord travelled (default 0.0455, Jones).
    pub b1: f64,
    /// Wagner amplitude of the fast pole `A₂` (default 0.335, Jones).
    pub a2: f64,
    /// Fast pole `b₂`, per semichord travelled (default 0.3, Jones).
    pub b2: f64,
    /// Pressure-lag time constant `T_p`, semichords (default 1.7).
    pub t_p: f64,
    /// Separation-point time constant `T_f`, semichords (default 3.0).
    pub t_f: f64,
    /// Attached-flow lift slope, 1/rad; absent: the polar's largest secant slope about its
    /// zero-lift incidence.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub lift_slope: Option<f64>,
}

impl Default for DynamicStallSpec {
    fn default() -> Self {
        let c = aerofoil::DynamicStallConstants::default();
        Self { a1: c.a1, b1: c.b1, a2: c.a2, b2: c.b2, t_p: c.t_p, t_f: c.t_f, lift_slope: c.lift_slope }
    }
}

impl DynamicStallSpec {
    /// The `aerofoil` crate's constants.
    pub fn constants(&self) -> aerofoil::DynamicStallConstants {
        let s = *self;
        aerofoil::DynamicStallConstants {
            a1: s.a1,
            b1: s.b1,
            a2: s.a2,
            b2: s.b2,
            t_p: s.t_p,
            t_f: s.t_f,
            lift_slope: s.lift_slope,
        }
    }
}

/// The range rules of a polar (`aero.polars[i].bounds`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct PolarBounds {
    /// Incidence outside the table: `error` (default; the analysis fails naming the strip),
    /// `clamp` (end values, zero slope) or `flat_plate` (Viterna–Corrigan to ±90°).
    pub alpha: AlphaBound,
    /// Reynolds number outside a multi-Re table's range: `error` (default; a case whose free
    /// stream is outside is refused at validation, a strip that leaves it during a run fails
    /// the run naming the strip) or `clamp` (the nearest table).
    pub re: ReBound,
}

/// Incidence outside a polar's table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AlphaBound {
    /// An error naming the strip and the incidence.
    #[default]
    Error,
    /// The nearest end of the table (coefficients held, slopes zero).
    Clamp,
    /// The flat-plate (Viterna–Corrigan) extrapolation from the table's end to ±90°.
    FlatPlate,
}

/// Reynolds number outside a polar's range.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ReBound {
    /// An error naming the strip (or, at validation, the airspeed) and the Reynolds number.
    #[default]
    Error,
    /// The nearest table.
    Clamp,
}

impl PolarBounds {
    /// The `aerofoil` crate's rules.
    pub fn aerofoil(self) -> aerofoil::Bounds {
        aerofoil::Bounds {
            alpha: match self.alpha {
                AlphaBound::Error => aerofoil::AlphaOutOfRange::Error,
                AlphaBound::Clamp => aerofoil::AlphaOutOfRange::Clamp,
                AlphaBound::FlatPlate => aerofoil::AlphaOutOfRange::FlatPlate,
            },
            re: match self.re {
                ReBound::Error => aerofoil::OutOfRange::Error,
                ReBound::Clamp => aerofoil::OutOfRange::Clamp,
            },
        }
    }
}

/// A loaded polar and the bodies it corrects (the typed form of a [`PolarSpec`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPolar {
    /// Body indices.
    pub bodies: Vec<usize>,
    /// The polar, with its range rules set (shared: problems are cloned per sweep point).
    pub polar: Arc<aerofoil::Polar>,
    /// The dynamic-stall constants of these bodies' strips (`None`: off).
    pub dynamic_stall: Option<aerofoil::DynamicStallConstants>,
}

/// The polar of every body (`None`: uncorrected), from the loaded entries `polars` of a problem
/// with `n_bodies` bodies.
///
/// # Errors
/// A body index out of range or given twice (the message names the field).
pub fn polars_by_body(polars: &[BodyPolar], n_bodies: usize) -> Result<Vec<Option<Arc<aerofoil::Polar>>>, String> {
    let mut out: Vec<Option<Arc<aerofoil::Polar>>> = vec![None; n_bodies];
    let mut owner = vec![usize::MAX; n_bodies];
    for (i, p) in polars.iter().enumerate() {
        for (k, &b) in p.bodies.iter().enumerate() {
            if b >= n_bodies {
                return Err(format!("aero.polars[{i}].bodies[{k}]: body {b} does not exist (the case has {n_bodies})"));
            }
            if owner[b] != usize::MAX {
                return Err(format!(
                    "aero.polars[{i}].bodies[{k}]: body {b} already has the polar of aero.polars[{}]",
                    owner[b]
                ));
            }
            owner[b] = i;
            out[b] = Some(p.polar.clone());
        }
    }
    Ok(out)
}

/// Why `analysis` cannot run `problem` with a strip tip loss, which only the statics' strips
/// apply (docs/statics.md §8).
pub fn refuse_tip_loss(problem: &Problem, analysis: &str) -> Result<(), String> {
    if problem.aero.as_ref().is_some_and(|a| !a.strip_tip_loss.is_none()) {
        return Err(format!(
            "aero.strip_tip_loss: only the statics' strips apply a tip loss; the {analysis} would ignore it \
             (docs/statics.md §8)"
        ));
    }
    Ok(())
}
