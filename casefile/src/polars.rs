//! The section polars of a case (`aero.polars`): each file read relative to the case file's
//! folder and validated, the body indices checked, and the free stream's Reynolds number checked
//! against each table's range, into the typed [`aeroelastic::section_polars::BodyPolar`]s that
//! [`Case::problem`] hands to the analyses. Every refusal names the field (and the file's own
//! errors the file, line and column).

use std::path::Path;
use std::sync::Arc;

use aeroelastic::aero_settings::AeroModel;
use aeroelastic::section_polars::{BodyPolar, DynamicStallSpec, ReBound};

use super::Case;

impl Case {
    /// Read the polar files of `aero.polars` (relative to `dir`) into [`Case::polars`].
    ///
    /// # Errors
    /// A missing, unreadable or invalid file (unsorted, non-finite, fewer than two rows per
    /// table), an unknown or repeated body, a non-positive `aero.kinematic_viscosity`, or a
    /// free-stream Reynolds number (`aero.airspeed` and every `static.airspeeds`) outside a
    /// multi-Re table's range while `bounds.re` is `error`; the message names the field.
    pub fn load_polars(&mut self, dir: &Path) -> Result<(), String> {
        self.polars.clear();
        let Some(aero) = &self.aero else { return Ok(()) };
        if aero.polars.is_empty() {
            return Ok(());
        }
        let nu = aero.kinematic_viscosity;
        if !(nu.is_finite() && nu > 0.0) {
            return Err(format!("aero.kinematic_viscosity: {nu} is not a positive number"));
        }
        let mut loaded = Vec::with_capacity(aero.polars.len());
        for (i, spec) in aero.polars.iter().enumerate() {
            if spec.bodies.is_empty() {
                return Err(format!("aero.polars[{i}].bodies: empty list"));
            }
            for (k, &b) in spec.bodies.iter().enumerate() {
                if b >= self.bodies.len() {
                    return Err(format!(
                        "aero.polars[{i}].bodies[{k}]: body {b} does not exist (the case has {} bodies)",
                        self.bodies.len()
                    ));
                }
                if let Some(j) = aero.polars[..i]
                    .iter()
                    .position(|s| s.bodies.contains(&b))
                    .or_else(|| spec.bodies[..k].contains(&b).then_some(i))
                {
                    return Err(format!(
                        "aero.polars[{i}].bodies[{k}]: body {b} already has the polar of aero.polars[{j}]"
                    ));
                }
            }
            let polar = aerofoil::read_polar(&dir.join(&spec.file))
                .map_err(|e| format!("aero.polars[{i}].file: {e}"))?
                .with_bounds(spec.bounds.aerofoil());
            if let (Some((lo, hi)), ReBound::Error) = (polar.re_range(), spec.bounds.re) {
                let speeds = aero.airspeed.iter().chain(self.statics.iter().flat_map(|s| s.airspeeds.iter()));
                // The strips' chords: the root and tip of each body of this polar.
                let planforms = aero.body_planforms(&self.problem())?;
                let chords: Vec<f64> = spec
                    .bodies
                    .iter()
                    .filter_map(|&b| planforms.get(b).copied().flatten())
                    .flat_map(|p| p[0])
                    .collect();
                for (v, c) in speeds.flat_map(|&v| chords.iter().map(move |&c| (v, c))) {
                    let re = v * c / nu;
                    if !(lo..=hi).contains(&re) {
                        return Err(format!(
                            "aero.polars[{i}].file: {}: the free stream's Reynolds number {re:.4e} at {v} m/s \
                             (aero.chord {c} m, aero.kinematic_viscosity {nu} m²/s) is outside the table's range \
                             [{lo:.4e}, {hi:.4e}]; give a polar that covers it or set aero.polars[{i}].bounds.re \
                             to \"clamp\"",
                            spec.file
                        ));
                    }
                }
            }
            let dynamic_stall = match &spec.dynamic_stall {
                Some(ds) => Some(dynamic_stall(i, ds, &polar, aero.model)?),
                None => None,
            };
            loaded.push(BodyPolar { bodies: spec.bodies.clone(), polar: Arc::new(polar), dynamic_stall });
        }
        self.polars = loaded;
        Ok(())
    }
}

/// The constants of `aero.polars[i].dynamic_stall`, checked: each in range, the polar with a
/// zero-lift incidence (its lift line), and the strip march as the analysis.
fn dynamic_stall(
    i: usize,
    spec: &DynamicStallSpec,
    polar: &aerofoil::Polar,
    model: AeroModel,
) -> Result<aerofoil::DynamicStallConstants, String> {
    let field = format!("aero.polars[{i}].dynamic_stall");
    if model != AeroModel::Strip {
        return Err(format!(
            "{field}: only the strip-theory march applies the dynamic-stall model; set aero.model to \"strip\" \
             or remove it (docs/section_aero.md §8)"
        ));
    }
    let constants = spec.constants();
    let named = |e: aerofoil::AerofoilError| match e {
        aerofoil::AerofoilError::InvalidDynamicStall { field: f, value } => {
            format!("{field}.{f}: {value} is out of range (docs/section_aero.md §8.2)")
        }
        e => format!("{field}: {e}"),
    };
    constants.validate().map_err(named)?;
    // The lift line at the polar's first table (any Reynolds number for a single table): a polar
    // whose lift never changes sign has none.
    let re = polar.re_range().map_or(1.0, |r| r.0);
    aerofoil::DynamicStall::new(polar, re, constants).map_err(named)?;
    Ok(constants)
}
