//! The external flow: what the air does where the wing is not — the free stream plus an
//! optional disturbance field (gusts, turbulence), both functions of position and time.
//!
//! The solver asks the [`Flow`] for the external velocity
//!
//! $$ V_{ext}(x, t) = V_\infty + u_{dist}(x, t) $$
//!
//! at every point where the free stream enters the equations, at the time of the solution
//! ([`crate::Uvlm::time`]):
//! * the collocation points (non-penetration right-hand side `−(V_ext − ẋ_c + u_wake)·n`), at the
//!   time of the solve;
//! * the wake nodes and the trailing-edge row about to be shed (wake convection
//!   `x ← x + (V_ext + u_ind)·dt`, `u_ind` only for a free wake), at the start of the step
//!   (forward Euler);
//! * the lattice segment midpoints (Joukowski load `ρ Γ (V_ext + u_ind − ẋ) × l`), at the time of
//!   the solve;
//! * [`crate::Uvlm::velocity_at`].
//!
//! The free-stream *vector* `V∞` alone still sets directions: the semi-infinite trailing legs of a
//! steady solve and of the wake closure, the straight rows of [`crate::Uvlm::prefill_wake`], and
//! the lift/drag split of [`crate::Loads::lift_drag`]. A disturbance is a perturbation of a flow
//! whose wake leaves along `V∞`.
//!
//! With no disturbance the solver evaluates exactly the arithmetic it did when the free stream
//! was a constant, so results are bitwise those of a constant free stream. A disturbance that is
//! zero everywhere gives bitwise the same results as none (the solver adds `+0.0`), except that a
//! `−0.0` free-stream component becomes `+0.0`.
//!
//! Image planes ([`crate::ImagePlane`]) mirror the vortices, not the disturbance: the solution is
//! that of the mirrored problem, so a disturbance should be symmetric about a symmetry plane
//! (a vertical gust is; a side gust across it is not).
//!
//! ## Adding a disturbance (gust) model
//! Implement [`FlowField`] for a plain struct holding the model's parameters; `velocity` is the
//! only required method. A gust *convected with the free stream* (frozen in the air, Taylor's
//! hypothesis) is a function of the distance its front has travelled past the point,
//! `s = |V∞| t − V̂∞·(x − x_0)`; keep `V∞` (or its direction and speed) in the struct. Override
//! [`FlowField::add_velocity_inplace`] only if a batch evaluation is faster (e.g. a von Kármán
//! field summed over many modes, vectorised over the structure-of-arrays points). Evaluations
//! happen inside the time loop: do not allocate there. Then attach it with
//! [`crate::Uvlm::set_disturbance`]. A sharp-edged vertical gust:
//!
//! ```
//! use uvlm::{FlowField, Lattice, Uvlm, UvlmParams, samples::FlaredWing};
//!
//! /// Vertical velocity `w` (m/s) behind a front that enters at plane `x_0·V̂ = d_0` at t = 0
//! /// and moves with the free stream.
//! struct SharpEdgedGust {
//!     /// Unit free-stream direction.
//!     dir: [f64; 3],
//!     /// Free-stream speed, m/s.
//!     speed: f64,
//!     /// Position of the front along `dir` at t = 0, m.
//!     d_0: f64,
//!     /// Gust velocity, m/s.
//!     w: [f64; 3],
//! }
//!
//! impl FlowField for SharpEdgedGust {
//!     fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
//!         let along = self.dir[0] * x[0] + self.dir[1] * x[1] + self.dir[2] * x[2];
//!         let s = self.speed * t - (along - self.d_0); // distance behind the front, m
//!         if s >= 0.0 { self.w } else { [0.0; 3] }
//!     }
//! }
//!
//! # fn main() -> Result<(), uvlm::UvlmError> {
//! let wing = FlaredWing { aoa: 5f64.to_radians(), ..FlaredWing::default() };
//! let lattice = Lattice::from_stations(wing.spec(), &wing.stations(0.0))?;
//! let mut uvlm = Uvlm::new(lattice, UvlmParams::new(0.0889, [0.0, -25.0, 0.0]))?;
//! // Front 2 m upstream of the leading edge (flow along −y, leading edge at y ≈ 0.5 m).
//! let gust = SharpEdgedGust { dir: [0.0, -1.0, 0.0], speed: 25.0, d_0: -2.5, w: [0.0, 0.0, 1.0] };
//! let mut calm = Uvlm::new(uvlm.lattice().clone(), uvlm.params().clone())?;
//! uvlm.set_disturbance(Some(Box::new(gust)));
//! for step in 1..=20 {
//!     let (f_gust, f_calm) = (uvlm.step(0.01)?.total_force()[2], calm.step(0.01)?.total_force()[2]);
//!     // The front reaches the leading edge at t = 0.08 s: no effect before, more lift after.
//!     if step <= 7 {
//!         assert_eq!(f_gust, f_calm);
//!     } else if step >= 10 {
//!         assert!(f_gust > f_calm);
//!     }
//! }
//! assert!((uvlm.time() - 0.2).abs() < 1e-12);
//! # Ok(()) }
//! ```

use crate::induce::Points;
use std::fmt;

/// A velocity field of position and time (free stream, gust, turbulence).
///
/// `Send + Sync` so that a solver holding one can move between threads and, later, evaluate it
/// from several.
pub trait FlowField: Send + Sync {
    /// Velocity at point `x` (m, global frame) and time `t` (s), m/s.
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3];

    /// Add the velocity at every point of `pts` at time `t` to `out` (one entry per point), m/s.
    /// Must not allocate. The default calls [`FlowField::velocity`] per point; override it when a
    /// batch evaluation is cheaper.
    ///
    /// The per-point form is the required one (not the `_inplace` form, as elsewhere in the
    /// project) because a field is naturally defined point by point and allocates nothing.
    ///
    /// # Panics
    /// If `out.len() != pts.len()`.
    fn add_velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        assert_eq!(out.len(), pts.len(), "add_velocity_inplace: output length");
        for (k, o) in out.iter_mut().enumerate() {
            let v = self.velocity([pts.x[k], pts.y[k], pts.z[k]], t);
            for q in 0..3 {
                o[q] += v[q];
            }
        }
    }
}

/// Any `Fn(x, t) -> v` closure is a field (handy for tests and quick studies).
impl<F> FlowField for F
where
    F: Fn([f64; 3], f64) -> [f64; 3] + Send + Sync,
{
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        self(x, t)
    }
}

/// A velocity that is the same everywhere and at all times, m/s: the free stream, or a uniform
/// disturbance.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Uniform(pub [f64; 3]);

impl FlowField for Uniform {
    fn velocity(&self, _x: [f64; 3], _t: f64) -> [f64; 3] {
        self.0
    }
    fn add_velocity_inplace(&self, pts: &Points, _t: f64, out: &mut [[f64; 3]]) {
        assert_eq!(out.len(), pts.len(), "add_velocity_inplace: output length");
        for o in out.iter_mut() {
            for q in 0..3 {
                o[q] += self.0[q];
            }
        }
    }
}

/// The external flow seen by the lattice and its wake: a constant free stream plus an optional
/// disturbance field, `V_ext(x, t) = V∞ + u_dist(x, t)`.
pub struct Flow {
    free_stream: [f64; 3],
    disturbance: Option<Box<dyn FlowField>>,
}

impl Flow {
    /// A free stream `v_inf` (m/s, global) with no disturbance.
    pub fn new(v_inf: [f64; 3]) -> Self {
        Self { free_stream: v_inf, disturbance: None }
    }

    /// The same flow with `disturbance` added.
    pub fn with_disturbance(self, disturbance: Box<dyn FlowField>) -> Self {
        Self { disturbance: Some(disturbance), ..self }
    }

    /// The free-stream velocity `V∞`, m/s: the undisturbed flow, and the direction of steady
    /// trailing legs and of the lift/drag split.
    pub fn free_stream(&self) -> [f64; 3] {
        self.free_stream
    }

    /// The disturbance field, if any.
    pub fn disturbance(&self) -> Option<&dyn FlowField> {
        self.disturbance.as_deref()
    }

    /// Replace the disturbance (`None`: free stream only).
    pub fn set_disturbance(&mut self, disturbance: Option<Box<dyn FlowField>>) {
        self.disturbance = disturbance;
    }

    /// True when there is no disturbance: the flow is `V∞` everywhere, at all times.
    pub fn is_uniform(&self) -> bool {
        self.disturbance.is_none()
    }

    /// External velocity at every point of `pts` at time `t`, written to `out`, m/s: `V∞`
    /// copied (bitwise), then the disturbance added. Does not allocate.
    ///
    /// # Panics
    /// If `out.len() != pts.len()`.
    pub fn velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        assert_eq!(out.len(), pts.len(), "Flow::velocity_inplace: output length");
        out.fill(self.free_stream);
        if let Some(d) = &self.disturbance {
            d.add_velocity_inplace(pts, t, out);
        }
    }
}

impl FlowField for Flow {
    fn velocity(&self, x: [f64; 3], t: f64) -> [f64; 3] {
        let mut v = self.free_stream;
        if let Some(d) = &self.disturbance {
            let u = d.velocity(x, t);
            for q in 0..3 {
                v[q] += u[q];
            }
        }
        v
    }
    fn add_velocity_inplace(&self, pts: &Points, t: f64, out: &mut [[f64; 3]]) {
        Uniform(self.free_stream).add_velocity_inplace(pts, t, out);
        if let Some(d) = &self.disturbance {
            d.add_velocity_inplace(pts, t, out);
        }
    }
}

impl fmt::Debug for Flow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Flow")
            .field("free_stream", &self.free_stream)
            .field("disturbance", &self.disturbance.as_ref().map(|_| "dyn FlowField"))
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(p: &[[f64; 3]]) -> Points {
        let mut pts = Points::default();
        for x in p {
            pts.push(*x);
        }
        pts
    }

    #[test]
    fn free_stream_plus_disturbance() {
        let pts = points(&[[0.0, 0.0, 0.0], [2.0, 1.0, -1.0]]);
        let ramp = |x: [f64; 3], t: f64| [0.0, 0.0, t * x[0]];
        let flow = Flow::new([1.0, -25.0, 0.0]).with_disturbance(Box::new(ramp));
        let mut out = [[9.0; 3]; 2];
        flow.velocity_inplace(&pts, 0.5, &mut out);
        assert_eq!(out, [[1.0, -25.0, 0.0], [1.0, -25.0, 1.0]]);
        assert_eq!(flow.velocity([2.0, 1.0, -1.0], 0.5), out[1]);
        // The batch add of a composite adds the free stream and the disturbance.
        let mut acc = [[1.0, 0.0, 0.0]; 2];
        flow.add_velocity_inplace(&pts, 0.5, &mut acc);
        assert_eq!(acc, [[2.0, -25.0, 0.0], [2.0, -25.0, 1.0]]);
        assert!(!flow.is_uniform());
        assert!(Flow::new([1.0, 0.0, 0.0]).is_uniform());
        assert!(format!("{flow:?}").contains("dyn FlowField"));
    }

    /// No disturbance copies V∞ bit for bit, including a −0.0 component.
    #[test]
    fn no_disturbance_copies_free_stream() {
        let flow = Flow::new([-0.0, -25.0, 0.1]);
        let mut out = [[1.0; 3]; 3];
        flow.velocity_inplace(&points(&[[0.0; 3]; 3]), 7.0, &mut out);
        for v in out {
            assert_eq!(v.map(f64::to_bits), [-0.0f64, -25.0, 0.1].map(f64::to_bits));
        }
        assert_eq!(flow.velocity([1.0, 2.0, 3.0], 1.0).map(f64::to_bits), out[0].map(f64::to_bits));
    }
}
