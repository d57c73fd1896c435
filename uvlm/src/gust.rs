//! Gusts and turbulence: frozen disturbance fields convected with the free stream
//! (docs/gust.md).
//!
//! Every field here is *frozen* in the air (Taylor's hypothesis): its velocity at a point `x` and
//! time `t` depends only on the distance the gust's front has travelled past that point,
//!
//! $$ s(x, t) = U (t - t_0) - \hat V_\infty \cdot (x - x_f), $$
//!
//! with `U = |V∞|`, `x_f` a point of the front's plane at `t_0` ([`Convection`]). So each
//! collocation point, segment midpoint and wake node sees the gust at its own position along the
//! stream: a wing with sweep, chord or a folded tip meets it where each point is.
//!
//! | field | profile `w(s)` (times the unit `direction`) |
//! |---|---|
//! | [`OneMinusCosine`] | `½ U_ds (1 − cos(π s / H))` for `0 ≤ s ≤ 2H`, else 0 (H the gust gradient, CS-25.341) |
//! | [`SharpEdged`] | `w₀` for `s ≥ 0`, else 0 |
//! | [`Sinusoidal`] | `w₀ sin(2π s / λ)` for `s ≥ 0` (or for every `s`), optionally `n` whole cycles |
//! | [`VonKarman`] | a seeded realisation of the von Kármán spectrum (intensity σ, scale L) |
//!
//! [`design_velocity`] gives the certification design velocity
//! `U_ds = U_ref F_g (H/107 m)^{1/6}` with [`cs25_reference_velocity`] for `U_ref`.
//!
//! None of the fields allocates when evaluated (the von Kármán field tabulates its realisation
//! once, at construction).

use crate::error::{Result, UvlmError};
use crate::flow::FlowField;
use crate::induce::Points;

/// How a frozen gust moves: with the free stream, its front through `front` at `t0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convection {
    /// Unit direction of the free stream.
    pub dir: [f64; 3],
    /// Free-stream speed `U`, m/s.
    pub speed: f64,
    /// A point of the front's plane at time `t0`, m (global).
    pub front: [f64; 3],
    /// Time at which the front passes `front`, s.
    pub t0: f64,
}

impl Convection {
    /// Convection with free stream `v_inf` (m/s), the front through `front` at time `t0`.
    ///
    /// # Errors
    /// [`UvlmError::InvalidParameter`] for a zero or non-finite free stream, a non-finite front or
    /// time.
    pub fn new(v_inf: [f64; 3], front: [f64; 3], t0: f64) -> Result<Self> {
        let speed = (v_inf[0] * v_inf[0] + v_inf[1] * v_inf[1] + v_inf[2] * v_inf[2]).sqrt();
        if !(speed.is_finite() && speed > 0.0) {
            return Err(UvlmError::InvalidParameter { field: "gust.v_inf", value: speed });
        }
        for (k, &c) in front.iter().enumerate() {
            if !c.is_finite() {
                return Err(UvlmError::InvalidParameter {
                    field: ["gust.front.x", "gust.front.y", "gust.front.z"][k],
                    value: c,
                });
            }
        }
        if !t0.is_finite() {
            return Err(UvlmError::InvalidParameter { field: "gust.t0", value: t0 });
        }
        Ok(Self { dir: [v_inf[0] / speed, v_inf[1] / speed, v_inf[2] / speed], speed, front, t0 })
    }

    /// Distance the front has travelled past point `x` at time `t`, m (negative before it
    /// arrives).
    #[inline]
    pub fn distance(&self, x: [f64; 3], t: f64) -> f64 {
        let d = &self.dir;
        let along = d[0] * (x[0] - self.front[0]) + d[1] * (x[1] - self.front[1]) + d[2] * (x[2] - self.front[2]);
        self.speed * (t - self.t0) - along
    }
}

/// A unit vector from `direction`.
fn unit(direction: [f64; 3]) -> Result<[f64; 3]> {
    let n = (direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]).sqrt();
    if !(n.is_finite() && n > 0.0) {
        return Err(UvlmError::InvalidParameter { field: "gust.direction", value: n });
    }
    Ok([direction[0] / n, direction[1] / n, direction[2] / n])
}

fn finite(field: &'static str, v: f64) -> Result<f64> {
    if v.is_finite() { Ok(v) } else { Err(UvlmError::InvalidParameter { field, value: v }) }
}

fn positive(field: &'static str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(UvlmError::InvalidParameter { field, value: v }) }
}

/// Batch evaluation of a profile `w(s)` along a unit direction.
#[inline]
fn add_profile(conv: &Convection, dir: [f64; 3], pts: &Points, t: f64, out: &mut [[f64; 3]], w: impl Fn(f64) -> f64) {
    assert_eq!(out.len(), pts.len(), "add_velocity_inplace: output length");
    for (k, o) in out.iter_mut().enumerate() {
        let a = w(conv.distance([pts.x[k], pts.y[k], pts.z[k]], t));
        for q in 0..3 {
            o[q] += a * dir[q];
        }
    }
}

/// The certification discrete gust (CS-25.341(a)): a 1-cos profile of gradient `H` (half its
/// length) and peak `U_ds`,
///
/// $$ w(s) = \tfrac12 U_{ds}\,\big(1 - \cos(\pi s / H)\big), \quad 0 \le s \le 2H. $$
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneMinusCosine {
    /// Convection of the frozen gust.
    pub conv: Convection,
    /// Gust gradient H, m (half the gust length).
    pub gradient: f64,
    /// Peak velocity `U_ds`, m/s (true airspeed).
    pub velocity: f64,
    /// Unit direction of the gust velocity.
    pub direction: [f64; 3],
}

impl OneMinusCosine {
    /// A 1-cos gust of gradient `gradient` (m, positive) and peak `velocity` (m/s) along
    /// `direction` (any non-zero length).
    ///
    /// # Errors
    /// [`UvlmError::InvalidParameter`] naming `gust.gradient_m`, `gust.velocity` or
    /// `gust.direction`.
    pub fn new(conv: Convection, gradient: f64, velocity: f64, direction: [f64; 3]) -> Result<Self> {
        Ok(Self {
            conv,
            gradient: positive("gust.gradient_m", gradient)?,
            velocity: finite("gust.velocity", velocity)?,
            direction: unit(direction)?,
        })
    }

    /// The profile `w(s)`, m/s.
    #[inline]
    pub fn profile(&self, s: f64) -> f64 {
        if (0.0..=2.0 * self.gradient).contains(&s) {
            0.5 * self.velocity * (1.0 - (std::f64::consts::PI * s / self.gradient).cos())
        } else {
            0.0
        }
    }
}

impl FlowField for OneMinusCosine {
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let w = self.profile(self.conv.distance(x, t));
        self.direction.map(|d| w * d)
    }
    fn add_velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        add_profile(&self.conv, self.direction, pts, t, out, |s| self.profile(s));
    }
}

/// A sharp-edged gust: `w₀` behind the front, nothing ahead of it (Küssner's problem).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharpEdged {
    /// Convection of the frozen gust.
    pub conv: Convection,
    /// Gust velocity `w₀`, m/s.
    pub velocity: f64,
    /// Unit direction of the gust velocity.
    pub direction: [f64; 3],
}

impl SharpEdged {
    /// A sharp-edged gust of `velocity` (m/s) along `direction`.
    ///
    /// # Errors
    /// [`UvlmError::InvalidParameter`] naming `gust.velocity` or `gust.direction`.
    pub fn new(conv: Convection, velocity: f64, direction: [f64; 3]) -> Result<Self> {
        Ok(Self { conv, velocity: finite("gust.velocity", velocity)?, direction: unit(direction)? })
    }

    /// The profile `w(s)`, m/s.
    #[inline]
    pub fn profile(&self, s: f64) -> f64 {
        if s >= 0.0 { self.velocity } else { 0.0 }
    }
}

impl FlowField for SharpEdged {
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let w = self.profile(self.conv.distance(x, t));
        self.direction.map(|d| w * d)
    }
    fn add_velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        add_profile(&self.conv, self.direction, pts, t, out, |s| self.profile(s));
    }
}

/// A sinusoidal gust `w₀ sin(2π s / λ)`: behind the front (`everywhere = false`), optionally for
/// `cycles` whole waves only, or over all space (`everywhere = true`, Sears' problem).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sinusoidal {
    /// Convection of the frozen gust (the phase is zero at the front).
    pub conv: Convection,
    /// Amplitude `w₀`, m/s.
    pub velocity: f64,
    /// Wavelength λ, m; a fixed point sees the frequency `U/λ`.
    pub wavelength: f64,
    /// Number of whole waves behind the front (`None`: unbounded).
    pub cycles: Option<f64>,
    /// The wave fills all space (no front).
    pub everywhere: bool,
    /// Unit direction of the gust velocity.
    pub direction: [f64; 3],
}

impl Sinusoidal {
    /// A sinusoidal gust of amplitude `velocity` (m/s) and wavelength `wavelength` (m, positive).
    ///
    /// # Errors
    /// [`UvlmError::InvalidParameter`] naming `gust.velocity`, `gust.wavelength_m`,
    /// `gust.cycles` (not positive) or `gust.direction`.
    pub fn new(
        conv: Convection,
        velocity: f64,
        wavelength: f64,
        cycles: Option<f64>,
        everywhere: bool,
        direction: [f64; 3],
    ) -> Result<Self> {
        if let Some(c) = cycles {
            positive("gust.cycles", c)?;
        }
        Ok(Self {
            conv,
            velocity: finite("gust.velocity", velocity)?,
            wavelength: positive("gust.wavelength_m", wavelength)?,
            cycles,
            everywhere,
            direction: unit(direction)?,
        })
    }

    /// The profile `w(s)`, m/s.
    #[inline]
    pub fn profile(&self, s: f64) -> f64 {
        let inside = self.everywhere || (s >= 0.0 && self.cycles.is_none_or(|c| s <= c * self.wavelength));
        if inside { self.velocity * (2.0 * std::f64::consts::PI * s / self.wavelength).sin() } else { 0.0 }
    }
}

impl FlowField for Sinusoidal {
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let w = self.profile(self.conv.distance(x, t));
        self.direction.map(|d| w * d)
    }
    fn add_velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        add_profile(&self.conv, self.direction, pts, t, out, |s| self.profile(s));
    }
}

/// Parameters of a von Kármán turbulence realisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VonKarmanParams {
    /// RMS velocity σ, m/s.
    pub intensity: f64,
    /// Turbulence length scale L, m.
    pub length_scale: f64,
    /// Seed of the random phases (a realisation is reproducible from it).
    pub seed: u64,
    /// Number of spectral lines (log-spaced wavenumbers).
    pub n_modes: usize,
    /// Shortest resolved wavelength, m (sets the highest wavenumber `2π/λ_min`).
    pub min_wavelength: f64,
    /// Longest stretch of `s` that is tabulated, m (beyond it the modes are summed directly).
    pub table_length: f64,
}

/// One-sided von Kármán spectrum of the vertical (transverse) velocity component,
/// m³/s² per rad/m:
///
/// $$ \Phi_w(\Omega) = \sigma^2 \frac{L}{\pi} \frac{1 + \tfrac83 (1.339 L \Omega)^2}{\big(1 + (1.339 L \Omega)^2\big)^{11/6}}, $$
///
/// with `∫₀^∞ Φ_w dΩ = σ²`.
pub fn von_karman_spectrum(omega: f64, intensity: f64, length_scale: f64) -> f64 {
    let a = (1.339 * length_scale * omega).powi(2);
    intensity * intensity * length_scale / std::f64::consts::PI * (1.0 + 8.0 / 3.0 * a) / (1.0 + a).powf(11.0 / 6.0)
}

/// A frozen von Kármán turbulence field: a sum of `n_modes` cosines
/// `Σ a_k cos(Ω_k s + φ_k)`, `a_k = √(2 Φ_w(Ω_k) ΔΩ_k)`, log-spaced wavenumbers from `0.01/L`
/// to `2π/λ_min`, phases from a seeded generator (SplitMix64). The realisation is tabulated on
/// `[0, table_length]` (at most 2 million entries) at a twentieth of the shortest wavelength and
/// interpolated linearly, summed directly beyond; ahead of the front (`s < 0`) the air is calm.
#[derive(Debug, Clone, PartialEq)]
pub struct VonKarman {
    /// Convection of the frozen field.
    pub conv: Convection,
    /// Unit direction of the turbulent velocity.
    pub direction: [f64; 3],
    params: VonKarmanParams,
    modes: Vec<(f64, f64, f64)>,
    ds: f64,
    table: Vec<f64>,
}

/// SplitMix64: a small, well-mixed generator, enough for random phases.
fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl VonKarman {
    /// A realisation of the spectrum with `params` along `direction`.
    ///
    /// # Errors
    /// [`UvlmError::InvalidParameter`] naming `gust.intensity`, `gust.length_scale_m`,
    /// `gust.n_modes`, `gust.min_wavelength_m`, `gust.table_length_m` or `gust.direction`.
    pub fn new(conv: Convection, params: VonKarmanParams, direction: [f64; 3]) -> Result<Self> {
        if !(params.intensity.is_finite() && params.intensity >= 0.0) {
            return Err(UvlmError::InvalidParameter { field: "gust.intensity", value: params.intensity });
        }
        let l = positive("gust.length_scale_m", params.length_scale)?;
        if params.n_modes < 2 {
            return Err(UvlmError::InvalidParameter { field: "gust.n_modes", value: params.n_modes as f64 });
        }
        let lam = positive("gust.min_wavelength_m", params.min_wavelength)?;
        let len = positive("gust.table_length_m", params.table_length)?;
        let (o_min, o_max) = (0.01 / l, 2.0 * std::f64::consts::PI / lam);
        if o_max <= o_min {
            return Err(UvlmError::InvalidParameter { field: "gust.min_wavelength_m", value: lam });
        }
        let n = params.n_modes;
        let mut rng = params.seed ^ 0x5DEE_CE66_D1CE_5EED;
        let r = (o_max / o_min).ln();
        let modes: Vec<(f64, f64, f64)> = (0..n)
            .map(|k| {
                // Line k at the log-centre of its band [Ω_k−, Ω_k+].
                let (lo, hi) = ((r * k as f64 / n as f64).exp() * o_min, (r * (k + 1) as f64 / n as f64).exp() * o_min);
                let om = (lo * hi).sqrt();
                let amp = (2.0 * von_karman_spectrum(om, params.intensity, l) * (hi - lo)).sqrt();
                let u = (splitmix64(&mut rng) >> 11) as f64 / (1u64 << 53) as f64;
                (om, amp, 2.0 * std::f64::consts::PI * u)
            })
            .collect();
        let ds = lam / 20.0;
        // At most 2 million entries and 2e8 mode evaluations to build (beyond the table the modes
        // are summed directly, which is exact but slower).
        let cap = (200_000_000 / n).clamp(2, 2_000_000);
        let n_tab = ((len / ds).ceil().min(cap as f64) as usize).max(2);
        let table = (0..=n_tab).map(|i| Self::sum(&modes, i as f64 * ds)).collect();
        Ok(Self { conv, direction: unit(direction)?, params, modes, ds, table })
    }

    fn sum(modes: &[(f64, f64, f64)], s: f64) -> f64 {
        modes.iter().map(|&(om, a, ph)| a * (om * s + ph).cos()).sum()
    }

    /// The parameters of this realisation.
    pub fn params(&self) -> &VonKarmanParams {
        &self.params
    }

    /// The spectral lines `(Ω_k rad/m, amplitude m/s, phase rad)`.
    pub fn modes(&self) -> &[(f64, f64, f64)] {
        &self.modes
    }

    /// The profile `w(s)`, m/s: zero ahead of the front, tabulated behind it.
    #[inline]
    pub fn profile(&self, s: f64) -> f64 {
        if s < 0.0 {
            return 0.0;
        }
        let u = s / self.ds;
        let i = u as usize;
        if i + 1 < self.table.len() {
            let f = u - i as f64;
            (1.0 - f) * self.table[i] + f * self.table[i + 1]
        } else {
            Self::sum(&self.modes, s)
        }
    }
}

impl FlowField for VonKarman {
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let w = self.profile(self.conv.distance(x, t));
        self.direction.map(|d| w * d)
    }
    fn add_velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        add_profile(&self.conv, self.direction, pts, t, out, |s| self.profile(s));
    }
}

/// The reference gust velocity `U_ref` of CS-25.341(a)(5), m/s **equivalent** airspeed, at
/// `altitude` (m): 17.07 m/s at sea level, linear to 13.41 m/s at 4 572 m (15 000 ft), linear to
/// 6.36 m/s at 18 288 m (60 000 ft), constant above.
pub fn cs25_reference_velocity(altitude: f64) -> f64 {
    let table = [(0.0, 17.07), (4572.0, 13.41), (18288.0, 6.36)];
    if altitude <= 0.0 {
        return table[0].1;
    }
    for w in table.windows(2) {
        let ((h0, u0), (h1, u1)) = (w[0], w[1]);
        if altitude <= h1 {
            return u0 + (u1 - u0) * (altitude - h0) / (h1 - h0);
        }
    }
    table[2].1
}

/// The design gust velocity `U_ds = U_ref F_g (H / 107 m)^{1/6}` of CS-25.341(a), in the units
/// of `u_ref`, for gradient `gradient` (m) and flight profile alleviation factor `f_g`.
pub fn design_velocity(gradient: f64, u_ref: f64, f_g: f64) -> f64 {
    u_ref * f_g * (gradient / 107.0).powf(1.0 / 6.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn conv() -> Convection {
        Convection::new([0.0, -25.0, 0.0], [0.0, 0.5, 0.0], 0.0).unwrap()
    }

    /// Each point sees the gust at its own position along the stream.
    #[test]
    fn frozen_profiles() {
        let c = conv();
        // 1 s later the front is 25 m downstream of y = 0.5.
        assert_relative_eq!(c.distance([3.0, 0.5, 7.0], 1.0), 25.0);
        assert_relative_eq!(c.distance([0.0, -24.5, 0.0], 1.0), 0.0, epsilon = 1e-12);
        // The gust is the air upstream of its front (y > 0.5 at t = 0; the flow runs along −y).
        let g = OneMinusCosine::new(c, 10.0, 2.0, [0.0, 0.0, 3.0]).unwrap();
        assert_eq!(g.velocity([0.0, 0.4, 0.0], 0.0), [0.0; 3]);
        // Peak at s = H: y = 0.5 + 10 at t = 0, and at y = 0.5 − 15 a second later.
        assert_relative_eq!(g.velocity([0.0, 10.5, 0.0], 0.0)[2], 2.0, epsilon = 1e-12);
        assert_relative_eq!(g.velocity([5.0, -14.5, 1.0], 1.0)[2], 2.0, epsilon = 1e-12);
        assert_eq!(g.velocity([0.0, 20.6, 0.0], 0.0), [0.0; 3]);
        let s = SharpEdged::new(c, 1.5, [0.0, 0.0, 1.0]).unwrap();
        assert_eq!(s.velocity([0.0, 0.6, 0.0], 0.0), [0.0, 0.0, 1.5]);
        assert_eq!(s.velocity([0.0, 0.4, 0.0], 0.0), [0.0; 3]);
        let w = Sinusoidal::new(c, 1.0, 4.0, Some(1.0), false, [0.0, 0.0, 1.0]).unwrap();
        assert_relative_eq!(w.velocity([0.0, 1.5, 0.0], 0.0)[2], 1.0, epsilon = 1e-12);
        assert_eq!(w.velocity([0.0, 4.6, 0.0], 0.0), [0.0; 3]);
        assert_eq!(w.velocity([0.0, 0.4, 0.0], 0.0), [0.0; 3]);
        let e = Sinusoidal::new(c, 1.0, 4.0, None, true, [0.0, 0.0, 1.0]).unwrap();
        assert_relative_eq!(e.velocity([0.0, -0.5, 0.0], 0.0)[2], -1.0, epsilon = 1e-12);
        // Batch and point evaluation agree.
        let mut pts = Points::default();
        for y in [12.0, 3.0, 0.0, -2.0] {
            pts.push([1.0, y, 0.0]);
        }
        let mut out = vec![[1.0; 3]; 4];
        g.add_velocity_inplace(&pts, 0.2, &mut out);
        for (k, y) in [12.0, 3.0, 0.0, -2.0].into_iter().enumerate() {
            let v = g.velocity([1.0, y, 0.0], 0.2);
            assert_eq!(out[k], [1.0 + v[0], 1.0 + v[1], 1.0 + v[2]]);
        }
    }

    #[test]
    fn invalid_parameters_name_the_field() {
        let c = conv();
        let f = |e: UvlmError| match e {
            UvlmError::InvalidParameter { field, .. } => field,
            _ => "",
        };
        assert_eq!(f(OneMinusCosine::new(c, -1.0, 1.0, [0.0, 0.0, 1.0]).unwrap_err()), "gust.gradient_m");
        assert_eq!(f(OneMinusCosine::new(c, f64::NAN, 1.0, [0.0, 0.0, 1.0]).unwrap_err()), "gust.gradient_m");
        assert_eq!(f(OneMinusCosine::new(c, 1.0, 1.0, [0.0; 3]).unwrap_err()), "gust.direction");
        assert_eq!(f(Sinusoidal::new(c, 1.0, 0.0, None, false, [0.0, 0.0, 1.0]).unwrap_err()), "gust.wavelength_m");
        assert_eq!(f(Convection::new([0.0; 3], [0.0; 3], 0.0).unwrap_err()), "gust.v_inf");
        let p = VonKarmanParams {
            intensity: 1.0,
            length_scale: -1.0,
            seed: 1,
            n_modes: 100,
            min_wavelength: 1.0,
            table_length: 10.0,
        };
        assert_eq!(f(VonKarman::new(c, p, [0.0, 0.0, 1.0]).unwrap_err()), "gust.length_scale_m");
    }

    /// The realisation's variance is the spectrum's over the resolved band, it is reproducible
    /// from the seed, and another seed gives another realisation.
    #[test]
    fn von_karman_realisation() {
        let p = VonKarmanParams {
            intensity: 1.0,
            length_scale: 50.0,
            seed: 7,
            n_modes: 400,
            min_wavelength: 2.0,
            table_length: 20_000.0,
        };
        let g = VonKarman::new(conv(), p, [0.0, 0.0, 1.0]).unwrap();
        // Variance of the lines against the integral of the spectrum over [Ω_min, Ω_max].
        let var_lines: f64 = g.modes().iter().map(|m| 0.5 * m.1 * m.1).sum();
        let (o0, o1) = (0.01 / 50.0, 2.0 * std::f64::consts::PI / 2.0);
        let n = 200_000;
        let r = (o1 / o0).ln();
        let var_spec: f64 = (0..n)
            .map(|k| {
                let (a, b) = ((r * k as f64 / n as f64).exp() * o0, (r * (k + 1) as f64 / n as f64).exp() * o0);
                von_karman_spectrum(0.5 * (a + b), 1.0, 50.0) * (b - a)
            })
            .sum();
        assert_relative_eq!(var_lines, var_spec, max_relative = 0.01);
        // The resolved band carries nearly all of σ² = 1.
        assert!(var_spec > 0.95 && var_spec < 1.0, "{var_spec}");
        // Sample variance over 400 length scales within 15 % (a finite record of a random field).
        let m = 200_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for i in 0..m {
            let w = g.profile(20_000.0 * i as f64 / m as f64);
            s1 += w;
            s2 += w * w;
        }
        let var = s2 / m as f64 - (s1 / m as f64).powi(2);
        assert!((var - var_lines).abs() < 0.15 * var_lines, "sample variance {var} vs {var_lines}");
        // Tabulated and summed agree.
        assert_relative_eq!(g.profile(1234.5), VonKarman::sum(g.modes(), 1234.5), epsilon = 5e-3);
        let again = VonKarman::new(conv(), p, [0.0, 0.0, 1.0]).unwrap();
        assert_eq!(again.profile(321.0), g.profile(321.0));
        let other = VonKarman::new(conv(), VonKarmanParams { seed: 8, ..p }, [0.0, 0.0, 1.0]).unwrap();
        assert_ne!(other.profile(321.0), g.profile(321.0));
        assert_eq!(g.profile(-1.0), 0.0);
    }

    #[test]
    fn certification_design_velocity() {
        assert_relative_eq!(cs25_reference_velocity(0.0), 17.07);
        assert_relative_eq!(cs25_reference_velocity(4572.0), 13.41);
        assert_relative_eq!(cs25_reference_velocity(30_000.0), 6.36);
        assert_relative_eq!(design_velocity(107.0, 17.07, 1.0), 17.07);
        assert_relative_eq!(design_velocity(9.0, 17.07, 0.5), 0.5 * 17.07 * (9.0f64 / 107.0).powf(1.0 / 6.0));
    }
}
