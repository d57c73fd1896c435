//! The stability settings of a problem (`stability`) and the steady wake of the static and
//! linear analyses ([`WakeSettings`]).

/// The `stability` block of a case.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct StabilitySettings {
    /// Airspeeds of the sweep, m/s, in increasing order.
    pub airspeeds: Vec<f64>,
    /// Number of modes to track and report (the lowest structural modes).
    pub modes: usize,
    /// The state to linearise about: `"equilibrium"` (default; the static aeroelastic
    /// equilibrium at each airspeed) or `"undeformed"` (the reference configuration, loads ignored).
    #[cfg_attr(feature = "serde", serde(default))]
    pub about: About,
    /// Structural modes in the basis of the flutter equation (default: `max(2·modes, 20)`, at most
    /// the free motions).
    #[cfg_attr(feature = "serde", serde(default))]
    pub basis_modes: Option<usize>,
    /// The aerodynamics of the flutter equation: `"uvlm"` (default; the lattice) or `"strip"`
    /// (2-D Theodorsen strips at the lattice's stations, R. T. Jones' approximation of C; no tip
    /// loss: the model of strip-theory references such as Patil, Hodges & Cesnik's).
    #[cfg_attr(feature = "serde", serde(default))]
    pub aerodynamics: AeroModel,
    /// The frozen wake of the linear aerodynamics; default: the time-marching wake
    /// (`aero.n_wake_rows` rows of `airspeed·dt`, closed when `aero.wake_closure`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub wake: Option<WakeSettings>,
}

/// The state a stability analysis linearises about.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum About {
    /// The static aeroelastic equilibrium at each airspeed.
    #[default]
    Equilibrium,
    /// The undeformed reference configuration.
    Undeformed,
    /// The trimmed free aircraft in level flight at each airspeed (the case's `trim`): the
    /// elastic roots and the rigid-body roots (phugoid, short period, Dutch roll, roll subsidence,
    /// spiral).
    Trim,
}

/// The aerodynamic model of a stability analysis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum AeroModel {
    /// The linearised UVLM.
    #[default]
    Uvlm,
    /// Two-dimensional Theodorsen strips.
    Strip,
}

/// A frozen wake of straight rows along the free stream: the linear aerodynamics'
/// (`stability.wake`) or the static solution's (`static.wake`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct WakeSettings {
    /// Length of a wake row along the free stream, m.
    pub row_length: f64,
    /// Number of rows.
    pub rows: usize,
    /// Close with semi-infinite legs. Default false.
    #[cfg_attr(feature = "serde", serde(default))]
    pub closure: bool,
}

/// Most airspeeds in one stability sweep.
pub const MAX_STABILITY_POINTS: usize = 200;
/// Most wake rings of the linear aerodynamics.
pub const MAX_LINEAR_WAKE_RINGS: usize = 200_000;

impl StabilitySettings {
    /// Every impossible value, naming its field.
    ///
    /// # Errors
    /// A message naming the field.
    pub fn validate(&self) -> Result<(), String> {
        if self.airspeeds.is_empty() {
            return Err("stability.airspeeds: empty list".into());
        }
        if self.airspeeds.len() > MAX_STABILITY_POINTS {
            return Err(format!(
                "stability.airspeeds: {} points, more than {MAX_STABILITY_POINTS}",
                self.airspeeds.len()
            ));
        }
        for (k, &u) in self.airspeeds.iter().enumerate() {
            if !(u.is_finite() && u > 0.0) {
                return Err(format!("stability.airspeeds[{k}]: {u} is not a positive airspeed"));
            }
            if k > 0 && u <= self.airspeeds[k - 1] {
                return Err(format!("stability.airspeeds[{k}]: {u} does not increase"));
            }
        }
        if self.modes == 0 || self.modes > 100 {
            return Err(format!("stability.modes: {} is not in 1..=100", self.modes));
        }
        if let Some(b) = self.basis_modes
            && (b < self.modes || b > 400)
        {
            return Err(format!("stability.basis_modes: {b} is not in modes..=400"));
        }
        if let Some(w) = &self.wake {
            if !(w.row_length.is_finite() && w.row_length > 0.0) {
                return Err(format!("stability.wake.row_length: {} is not positive", w.row_length));
            }
            if w.rows == 0 || w.rows > 4000 {
                return Err(format!("stability.wake.rows: {} is not in 1..=4000", w.rows));
            }
        }
        Ok(())
    }
}

impl WakeSettings {
    /// Every impossible value, naming its field under `prefix` (e.g. `static.wake`).
    ///
    /// # Errors
    /// A message naming the field.
    pub fn validate(&self, prefix: &str) -> Result<(), String> {
        if !(self.row_length.is_finite() && self.row_length > 0.0 && self.row_length <= 1e6) {
            return Err(format!("{prefix}.row_length: {} is not in (0, 1e6] m", self.row_length));
        }
        if self.rows == 0 || self.rows > 4000 {
            return Err(format!("{prefix}.rows: {} is not in 1..=4000", self.rows));
        }
        Ok(())
    }

    /// The steady UVLM wake of these settings: the rows' total length without closure, the
    /// semi-infinite legs with it.
    pub fn steady_wake(&self) -> uvlm::SteadyWake {
        if self.closure {
            uvlm::SteadyWake::SemiInfinite
        } else {
            uvlm::SteadyWake::Finite { length: self.rows as f64 * self.row_length }
        }
    }
}
