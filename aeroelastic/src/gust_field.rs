//! The flow field of a gust setting: where its front starts on a lattice and the
//! [`FlowField`] that convects it with the free stream (docs/gust.md).

use uvlm::FlowField;

use crate::aero_settings::AeroSettings;
use crate::gust_settings::GustSpec;

/// The point the front of `spec` passes at the start of a run on a lattice whose stations are
/// `stations`: `x0` upstream (along the free stream) of the most upstream leading-edge point.
pub fn gust_front(spec: &GustSpec, aero: &AeroSettings, stations: &[uvlm::SpanStation]) -> Result<[f64; 3], String> {
    let v_inf = aero.free_stream();
    let u = (v_inf[0] * v_inf[0] + v_inf[1] * v_inf[1] + v_inf[2] * v_inf[2]).sqrt();
    if !(u.is_finite() && u > 0.0) {
        return Err("the free stream is zero".into());
    }
    let dir = nalgebra::Vector3::from(v_inf) / u;
    let lead = stations
        .iter()
        .map(|st| st.origin + st.frame.column(1) * st.le_offset)
        .min_by(|a, b| dir.dot(a).total_cmp(&dir.dot(b)))
        .ok_or("no lattice stations")?;
    Ok((lead - dir * spec.x0()).into())
}

/// The disturbance field of `spec` for a lattice whose stations are `stations` at time `t0`
/// (the front `x0` upstream of the most upstream leading-edge point), for a run to `t_end`.
pub fn disturbance(
    spec: &GustSpec,
    aero: &AeroSettings,
    stations: &[uvlm::SpanStation],
    t_end: f64,
    t0: f64,
) -> Result<Box<dyn FlowField>, String> {
    let v_inf = aero.free_stream();
    let u = (v_inf[0] * v_inf[0] + v_inf[1] * v_inf[1] + v_inf[2] * v_inf[2]).sqrt();
    if !(u.is_finite() && u > 0.0) {
        return Err("the free stream is zero".into());
    }
    let x0 = spec.x0();
    let front = gust_front(spec, aero, stations)?;
    let e = |e: uvlm::UvlmError| e.to_string();
    let conv = uvlm::Convection::new(v_inf, front, t0).map_err(e)?;
    Ok(match spec {
        GustSpec::OneMinusCosine { gradient_m, direction, .. } => {
            Box::new(uvlm::OneMinusCosine::new(conv, *gradient_m, spec.velocity(aero.rho), *direction).map_err(e)?)
        }
        GustSpec::SharpEdged { velocity, direction, .. } => {
            Box::new(uvlm::SharpEdged::new(conv, *velocity, *direction).map_err(e)?)
        }
        GustSpec::Sinusoidal { velocity, frequency_hz, wavelength_m, cycles, direction, .. } => {
            let lambda = wavelength_m.unwrap_or_else(|| u / frequency_hz.unwrap_or(f64::NAN));
            Box::new(uvlm::Sinusoidal::new(conv, *velocity, lambda, *cycles, false, *direction).map_err(e)?)
        }
        GustSpec::VonKarman { intensity, length_scale_m, seed, n_modes, min_wavelength_m, direction, .. } => {
            let params = uvlm::VonKarmanParams {
                intensity: *intensity,
                length_scale: *length_scale_m,
                seed: seed.ok_or("seed: von Kármán turbulence needs a seed")?,
                n_modes: *n_modes,
                min_wavelength: min_wavelength_m.unwrap_or(aero.chord_extremes().0),
                table_length: u * (t_end - t0).max(0.0) + x0 + 4.0 * aero.chord_extremes().1,
            };
            Box::new(uvlm::VonKarman::new(conv, params, *direction).map_err(e)?)
        }
    })
}
