//! The root pitch at which a free flared tip coasts level (fold 0) at one airspeed: a root-find
//! on the root pitch over static equilibria (docs/statics.md §8). A measure of the tip's
//! aerodynamic zero that a datum offset of the coast angle cannot fake.

use crate::problem::{Formulation, Problem};

/// Largest root pitch the search visits, degrees (either sign).
const MAX_PITCH_DEG: f64 = 30.0;
/// Static solutions the search spends at most.
const MAX_SOLVES: usize = 12;

/// The level-coast root pitch of one airspeed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LevelPitch {
    /// Root pitch, degrees, at which the fold is zero.
    pub pitch_deg: f64,
    /// The fold there, degrees (within the tolerance of zero).
    pub fold_deg: f64,
    /// Static solutions spent.
    pub n_solves: usize,
}

/// The fold (degrees) of `case` at root pitch `pitch_deg` and `airspeed` alone, formulation `f`.
///
/// # Errors
/// A case without a `static` block, or no equilibrium.
pub fn fold_at(case: &Problem, f: Formulation, airspeed: f64, pitch_deg: f64) -> Result<f64, String> {
    let mut c = case.clone();
    c.pitch_deg = pitch_deg;
    c.statics.as_mut().ok_or("the case has no `static` block")?.airspeeds = vec![airspeed];
    let out = crate::statics::run_static(&c, f);
    if let Some(e) = out.error {
        return Err(e);
    }
    let p = out.points.into_iter().next().ok_or("no point")?;
    match p.error {
        Some(e) => Err(format!("at pitch {pitch_deg:.4}°: {e}")),
        None => Ok(p.fold_deg),
    }
}

/// The root pitch at which the fold of `case` is zero at `airspeed` (formulation `f`), within
/// `tol_deg` of fold, from two known points `(pitch, fold)` (degrees): secant steps (each
/// limited to ±10° and to ±30°), then the Illinois variant of regula falsi once a
/// sign change brackets the root.
///
/// # Errors
/// A static solution that fails, a search that leaves the pitch range or does not converge in
/// 12 solutions.
pub fn level_pitch(
    case: &Problem,
    f: Formulation,
    airspeed: f64,
    start: [(f64, f64); 2],
    tol_deg: f64,
) -> Result<LevelPitch, String> {
    let [mut a, mut b] = start;
    let mut n = 0;
    // Secant steps until a sign change brackets the root.
    while a.1 * b.1 > 0.0 {
        if b.1.abs() < tol_deg {
            return Ok(LevelPitch { pitch_deg: b.0, fold_deg: b.1, n_solves: n });
        }
        let slope = (b.1 - a.1) / (b.0 - a.0);
        if !(slope.is_finite() && slope != 0.0) {
            return Err(format!("at {airspeed} m/s: the fold does not change with the pitch"));
        }
        let next = b.0 - (b.1 / slope).clamp(-10.0, 10.0);
        (a, b) = (b, (next, solve(case, f, airspeed, next, &mut n)?));
    }
    // Illinois: regula falsi, halving the value of an end kept twice in a row.
    for p in [a, b] {
        if p.1.abs() < tol_deg {
            return Ok(LevelPitch { pitch_deg: p.0, fold_deg: p.1, n_solves: n });
        }
    }
    let mut side = 0i8;
    loop {
        let x = (a.0 * b.1 - b.0 * a.1) / (b.1 - a.1);
        let c = (x, solve(case, f, airspeed, x, &mut n)?);
        if c.1.abs() < tol_deg {
            return Ok(LevelPitch { pitch_deg: c.0, fold_deg: c.1, n_solves: n });
        }
        if c.1 * b.1 > 0.0 {
            b = c;
            if side == -1 {
                a.1 *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            if side == 1 {
                b.1 *= 0.5;
            }
            side = 1;
        }
    }
}

/// [`fold_at`] within the search's limits, counting the solutions in `n`.
fn solve(case: &Problem, f: Formulation, airspeed: f64, pitch_deg: f64, n: &mut usize) -> Result<f64, String> {
    if !(pitch_deg.is_finite() && pitch_deg.abs() <= MAX_PITCH_DEG) {
        return Err(format!("at {airspeed} m/s: the level pitch lies beyond ±{MAX_PITCH_DEG}° (next {pitch_deg:.2}°)"));
    }
    if *n >= MAX_SOLVES {
        return Err(format!("at {airspeed} m/s: no level pitch within {MAX_SOLVES} static solutions"));
    }
    *n += 1;
    fold_at(case, f, airspeed, pitch_deg)
}
