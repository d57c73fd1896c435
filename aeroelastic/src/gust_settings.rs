//! The gust settings: the disturbance field `aero.gust` ([`GustSpec`]) and the gust sweep over
//! gradients and fold-hinge states ([`GustSweep`], [`HingeState`]); docs/gust.md.

/// Sea-level density of the standard atmosphere, kg/m³ (equivalent to true airspeed).
pub const RHO_SEA_LEVEL: f64 = 1.225;

fn up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

fn one() -> f64 {
    1.0
}

fn default_modes() -> usize {
    200
}

/// A gust or turbulence field (`aero.gust`). Every kind is frozen in the air and convected with
/// the free stream; its front is `x0` metres upstream of the wing's most upstream leading-edge
/// point when the run starts.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields))]
pub enum GustSpec {
    /// The certification discrete gust `½ U_ds (1 − cos(π s/H))` over `0 ≤ s ≤ 2H`.
    OneMinusCosine {
        /// Gust gradient H, m (half the gust length; CS-25: 9 to 107 m).
        gradient_m: f64,
        /// Peak gust velocity U_ds, m/s (true airspeed). Give this or `certification`.
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        velocity: Option<f64>,
        /// U_ds from the certification rule instead of `velocity`.
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        certification: Option<Certification>,
        /// Distance of the front upstream of the wing's leading edge at the start, m (default 0).
        #[cfg_attr(feature = "serde", serde(default))]
        x0: f64,
        /// Direction of the gust velocity, global (any non-zero length; default up, +Z).
        #[cfg_attr(feature = "serde", serde(default = "up"))]
        direction: [f64; 3],
    },
    /// A sharp-edged gust of `velocity` behind its front.
    SharpEdged {
        /// Gust velocity, m/s.
        velocity: f64,
        /// Distance of the front upstream of the wing's leading edge at the start, m (default 0).
        #[cfg_attr(feature = "serde", serde(default))]
        x0: f64,
        /// Direction of the gust velocity (default +Z).
        #[cfg_attr(feature = "serde", serde(default = "up"))]
        direction: [f64; 3],
    },
    /// A sinusoidal gust `velocity · sin(2π s/λ)` behind its front.
    Sinusoidal {
        /// Amplitude, m/s.
        velocity: f64,
        /// Frequency seen by a fixed point, Hz (λ = airspeed / f). Give this or `wavelength_m`.
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        frequency_hz: Option<f64>,
        /// Wavelength λ, m.
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        wavelength_m: Option<f64>,
        /// Whole waves behind the front (default: unbounded).
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        cycles: Option<f64>,
        /// Distance of the front upstream of the wing's leading edge at the start, m (default 0).
        #[cfg_attr(feature = "serde", serde(default))]
        x0: f64,
        /// Direction of the gust velocity (default +Z).
        #[cfg_attr(feature = "serde", serde(default = "up"))]
        direction: [f64; 3],
    },
    /// Continuous turbulence: a seeded realisation of the von Kármán spectrum.
    VonKarman {
        /// RMS velocity σ, m/s.
        intensity: f64,
        /// Length scale L, m (762 m in the certification rule; scale with the wing).
        length_scale_m: f64,
        /// Seed of the random phases (required: a realisation is reproducible only from it).
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        seed: Option<u64>,
        /// Spectral lines (default 200).
        #[cfg_attr(feature = "serde", serde(default = "default_modes"))]
        n_modes: usize,
        /// Shortest resolved wavelength, m (default: the chord).
        #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
        min_wavelength_m: Option<f64>,
        /// Distance of the front upstream of the wing's leading edge at the start, m (default 0).
        #[cfg_attr(feature = "serde", serde(default))]
        x0: f64,
        /// Direction of the turbulent velocity (default +Z).
        #[cfg_attr(feature = "serde", serde(default = "up"))]
        direction: [f64; 3],
    },
}

/// The certification design gust velocity, `U_ds = scale · U_ref(altitude) · F_g · (H/107)^{1/6}`
/// (CS-25.341(a)), U_ref in equivalent airspeed converted to true airspeed with `aero.rho`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Certification {
    /// Altitude, m (U_ref 17.07 m/s EAS at sea level, 13.41 at 4 572 m, 6.36 at 18 288 m and above).
    pub altitude_m: f64,
    /// Flight profile alleviation factor F_g, in (0, 1] (default 1).
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub f_g: f64,
    /// Factor on the design velocity (default 1): a scaled model or a scaled regime.
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub scale: f64,
}

impl GustSpec {
    /// The kind as spelled in the case file.
    pub fn kind(&self) -> &'static str {
        match self {
            GustSpec::OneMinusCosine { .. } => "one_minus_cosine",
            GustSpec::SharpEdged { .. } => "sharp_edged",
            GustSpec::Sinusoidal { .. } => "sinusoidal",
            GustSpec::VonKarman { .. } => "von_karman",
        }
    }

    /// Check every value, naming the field (`aero.gust.<field>`).
    pub fn validate(&self) -> Result<(), String> {
        let f = |n: &str| format!("aero.gust.{n}");
        let finite = |n: &str, v: f64| if v.is_finite() { Ok(()) } else { Err(format!("{}: {v} is not finite", f(n))) };
        let length = |n: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{}: {v} is not a positive, finite length", f(n)))
            }
        };
        let dir_ok = |d: &[f64; 3]| {
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if n.is_finite() && n > 0.0 { Ok(()) } else { Err(format!("{}: {d:?} is not a direction", f("direction"))) }
        };
        let x0_ok = |x0: f64| {
            if x0.is_finite() && x0 >= 0.0 {
                Ok(())
            } else {
                Err(format!("{}: {x0} is not a non-negative, finite distance", f("x0")))
            }
        };
        match self {
            GustSpec::OneMinusCosine { gradient_m, velocity, certification, x0, direction } => {
                length("gradient_m", *gradient_m)?;
                match (velocity, certification) {
                    (Some(v), None) => finite("velocity", *v)?,
                    (None, Some(c)) => {
                        finite("certification.altitude_m", c.altitude_m)?;
                        if !(c.f_g.is_finite() && c.f_g > 0.0 && c.f_g <= 1.0) {
                            return Err(format!("{}: {} is not in (0, 1]", f("certification.f_g"), c.f_g));
                        }
                        if !(c.scale.is_finite() && c.scale > 0.0) {
                            return Err(format!("{}: {} is not a positive number", f("certification.scale"), c.scale));
                        }
                    }
                    _ => return Err(format!("{}: give exactly one of `velocity` and `certification`", f("velocity"))),
                }
                x0_ok(*x0)?;
                dir_ok(direction)
            }
            GustSpec::SharpEdged { velocity, x0, direction } => {
                finite("velocity", *velocity)?;
                x0_ok(*x0)?;
                dir_ok(direction)
            }
            GustSpec::Sinusoidal { velocity, frequency_hz, wavelength_m, cycles, x0, direction } => {
                finite("velocity", *velocity)?;
                match (frequency_hz, wavelength_m) {
                    (Some(hz), None) => length("frequency_hz", *hz)?,
                    (None, Some(l)) => length("wavelength_m", *l)?,
                    _ => {
                        return Err(format!(
                            "{}: give exactly one of `frequency_hz` and `wavelength_m`",
                            f("wavelength_m")
                        ));
                    }
                }
                if let Some(c) = cycles {
                    length("cycles", *c)?;
                }
                x0_ok(*x0)?;
                dir_ok(direction)
            }
            GustSpec::VonKarman { intensity, length_scale_m, seed, n_modes, min_wavelength_m, x0, direction } => {
                if !(intensity.is_finite() && *intensity >= 0.0) {
                    return Err(format!("{}: {intensity} is not a non-negative, finite velocity", f("intensity")));
                }
                length("length_scale_m", *length_scale_m)?;
                if seed.is_none() {
                    return Err(format!(
                        "{}: von Kármán turbulence needs a seed (a realisation is reproducible only from it)",
                        f("seed")
                    ));
                }
                if !(2..=10_000).contains(n_modes) {
                    return Err(format!("{}: {n_modes} is not in 2..=10000", f("n_modes")));
                }
                if let Some(l) = min_wavelength_m {
                    length("min_wavelength_m", *l)?;
                }
                x0_ok(*x0)?;
                dir_ok(direction)
            }
        }
    }

    /// Peak (or amplitude, or RMS) gust velocity, m/s true airspeed, in air of density `rho`
    /// (kg/m³, `aero.rho`: the certification rule's equivalent airspeed converted).
    pub fn velocity(&self, rho: f64) -> f64 {
        match self {
            GustSpec::OneMinusCosine { gradient_m, velocity, certification, .. } => match (velocity, certification) {
                (Some(v), _) => *v,
                (None, Some(c)) => {
                    let eas = c.scale
                        * uvlm::gust::design_velocity(
                            *gradient_m,
                            uvlm::gust::cs25_reference_velocity(c.altitude_m),
                            c.f_g,
                        );
                    eas * (RHO_SEA_LEVEL / rho).sqrt()
                }
                (None, None) => f64::NAN,
            },
            GustSpec::SharpEdged { velocity, .. } | GustSpec::Sinusoidal { velocity, .. } => *velocity,
            GustSpec::VonKarman { intensity, .. } => *intensity,
        }
    }

    /// The same gust with gradient `h` (a 1-cos gust; others unchanged).
    pub fn with_gradient(&self, h: f64) -> Self {
        let mut g = self.clone();
        if let GustSpec::OneMinusCosine { gradient_m, .. } = &mut g {
            *gradient_m = h;
        }
        g
    }

    /// Distance of the front upstream of the wing at the start, m.
    pub fn x0(&self) -> f64 {
        match self {
            GustSpec::OneMinusCosine { x0, .. }
            | GustSpec::SharpEdged { x0, .. }
            | GustSpec::Sinusoidal { x0, .. }
            | GustSpec::VonKarman { x0, .. } => *x0,
        }
    }

    /// Direction of the gust velocity, as given (any non-zero length).
    pub fn direction(&self) -> [f64; 3] {
        match self {
            GustSpec::OneMinusCosine { direction, .. }
            | GustSpec::SharpEdged { direction, .. }
            | GustSpec::Sinusoidal { direction, .. }
            | GustSpec::VonKarman { direction, .. } => *direction,
        }
    }

    /// Direction of the gust velocity, to change in place (a flight in body axes turns it with
    /// the flow, docs/trim.md §5).
    pub fn direction_mut(&mut self) -> &mut [f64; 3] {
        match self {
            GustSpec::OneMinusCosine { direction, .. }
            | GustSpec::SharpEdged { direction, .. }
            | GustSpec::Sinusoidal { direction, .. }
            | GustSpec::VonKarman { direction, .. } => direction,
        }
    }

    /// The gradient of a 1-cos gust, m (NaN for other kinds).
    pub fn gradient(&self) -> f64 {
        match self {
            GustSpec::OneMinusCosine { gradient_m, .. } => *gradient_m,
            _ => f64::NAN,
        }
    }
}

/// A state of the fold hinge in a gust sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(tag = "state", rename_all = "snake_case", deny_unknown_fields))]
pub enum HingeState {
    /// The hinge as the case has it, unlocked (with the case's own spring, if any).
    Free,
    /// The hinge locked at its reference fold (the conventional wing).
    Locked,
    /// Unlocked, with a rotational spring (and damper) replacing the case's own.
    Spring {
        /// Stiffness, N·m/rad.
        stiffness: f64,
        /// Damping, N·m·s/rad (default 0).
        #[cfg_attr(feature = "serde", serde(default))]
        damping: f64,
    },
    /// Locked at the equilibrium (whose state is the locked wing's), and released when the gust
    /// raises the root bending moment by more than this over its value there, N·m: a
    /// load-triggered release (a hinge event, docs/coupling.md §8).
    Release {
        /// The root bending moment increment that releases the hinge, N·m.
        root_bending_moment_increment_above: f64,
    },
}

impl HingeState {
    /// `free`, `locked` or `spring` (the CSV's `hinge` column).
    pub fn label(&self) -> &'static str {
        match self {
            HingeState::Free => "free",
            HingeState::Locked => "locked",
            HingeState::Spring { .. } => "spring",
            HingeState::Release { .. } => "release",
        }
    }

    /// The spring stiffness, N·m/rad (NaN unless sprung).
    pub fn stiffness(&self) -> f64 {
        match self {
            HingeState::Spring { stiffness, .. } => *stiffness,
            _ => f64::NAN,
        }
    }
}

/// The gust sweep of a case (`gust`): 1-cos gusts of the case's `aero.gust` over gradients (or
/// gust frequencies `f = V/(2H)`) and hinge states.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct GustSweep {
    /// Gust gradients H, m. Give this or `frequencies_hz`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub gradients_m: Vec<f64>,
    /// Gust frequencies `f = V/(2H)`, Hz (the gust's length passes a point in 1/f).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub frequencies_hz: Vec<f64>,
    /// Hinge states, e.g. `[{"state": "free"}, {"state": "locked"}, {"state": "spring",
    /// "stiffness": 100}]`.
    pub hinges: Vec<HingeState>,
    /// Duration of each gust run, s (default: the case's `t_end`).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub t_end: Option<f64>,
}

/// Gust runs per sweep, at most.
pub const MAX_GUST_RUNS: usize = 400;

impl GustSweep {
    /// The gradients of the sweep, m, for free-stream speed `airspeed`.
    pub fn gradients(&self, airspeed: f64) -> Vec<f64> {
        if self.gradients_m.is_empty() {
            self.frequencies_hz.iter().map(|f| airspeed / (2.0 * f)).collect()
        } else {
            self.gradients_m.clone()
        }
    }
}
