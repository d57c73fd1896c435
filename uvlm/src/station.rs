//! Span stations: the section frames a structure hands to the aerodynamics.

use crate::error::{Result, UvlmError};
use nalgebra::{Matrix3, Vector3};

/// One span station: a section frame with chord data. Grid column `j` of a lattice is generated
/// from station `j`.
///
/// Section frame convention (docs/conventions.md §2): the columns of `frame` are the section axes
/// `x_s` (along the span, the direction of increasing column index), `y_s` (in the chord plane,
/// pointing to the leading edge) and `z_s = x_s × y_s` (the lifting-surface normal).
/// The grid column is the line through `origin` along `sin(slant)·x_s + cos(slant)·y_s`; its
/// node at chordwise coordinate `s` (measured along `y_s` from `origin`, `s = le_offset` at the
/// leading edge, `s = le_offset − chord` at the trailing edge) is
///
/// $$ x = \text{origin} + R\,(s\tan(\text{slant}),\ s,\ 0)^T. $$
///
/// A flared hinge (axis `a = sinβ·x_s + cosβ·y_s` of the inner body's end frame) is the column of
/// the inner body's end station with `slant = β` and `origin` on the hinge axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpanStation {
    /// Reference point on the chord line (e.g. the beam axis), m.
    pub origin: Vector3<f64>,
    /// Section frame: columns `x_s` (span), `y_s` (towards the leading edge), `z_s` (normal).
    pub frame: Matrix3<f64>,
    /// Chord length measured along `y_s`, m (> 0).
    pub chord: f64,
    /// Distance from `origin` to the leading edge along `y_s`, m (0.5·chord for a mid-chord axis).
    pub le_offset: f64,
    /// Slant of the grid column in the section x-y plane, rad (|slant| < 80°); 0 = along `y_s`.
    pub slant: f64,
    /// Control surface (flap) on this station's column, if any (see [`StationFlap`]).
    pub flap: Option<StationFlap>,
}

/// Largest control-surface deflection, degrees (exclusive): beyond it the chordwise grid lines
/// fold back at the hinge.
pub const MAX_FLAP_DEFLECTION_DEG: f64 = 80.0;

/// A trailing-edge control surface on one span station: the part of the column behind the hinge
/// at chordwise fraction `η = 1 − chord_fraction` is rotated about the hinge line by
/// `deflection` (docs/uvlm.md §15).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StationFlap {
    /// Flap chord over section chord, `E` in (0, 1).
    pub chord_fraction: f64,
    /// Deflection δ, rad (|δ| < 80°), positive trailing edge down (towards `−z_s`, more lift):
    /// a right-handed rotation about the hinge line oriented along increasing column index.
    pub deflection: f64,
    /// Deflection rate dδ/dt, rad/s, added to the node velocities behind the hinge when the
    /// lattice is given station velocities (ignored for a lattice at rest).
    pub rate: f64,
}

impl StationFlap {
    /// A flap of chord fraction `chord_fraction` at a fixed deflection (rad).
    pub fn new(chord_fraction: f64, deflection: f64) -> Self {
        Self { chord_fraction, deflection, rate: 0.0 }
    }
}

impl SpanStation {
    /// A station with an unslanted column and no control surface.
    pub fn new(origin: Vector3<f64>, frame: Matrix3<f64>, chord: f64, le_offset: f64) -> Self {
        Self { origin, frame, chord, le_offset, slant: 0.0, flap: None }
    }

    /// Position of the column point at chordwise fraction `eta` (0 = leading edge, 1 = trailing
    /// edge), relative to `origin` (the rigid arm), m.
    #[inline]
    pub fn arm(&self, eta: f64) -> Vector3<f64> {
        let s = self.le_offset - eta * self.chord;
        self.frame * Vector3::new(s * self.slant.tan(), s, 0.0)
    }

    /// Check that every field is usable.
    pub fn validate(&self, station: usize) -> Result<()> {
        let bad = |field: &'static str, value: f64| Err(UvlmError::InvalidStation { station, field, value });
        if !self.origin.iter().all(|v| v.is_finite()) {
            return bad("origin", self.origin.norm());
        }
        if !self.frame.iter().all(|v| v.is_finite()) {
            return bad("frame", f64::NAN);
        }
        let defect = (self.frame.transpose() * self.frame - Matrix3::identity()).norm();
        if defect > 1e-6 || self.frame.determinant() < 0.0 {
            return bad("frame", defect);
        }
        if !(self.chord.is_finite() && self.chord > 0.0) {
            return bad("chord", self.chord);
        }
        if !self.le_offset.is_finite() {
            return bad("le_offset", self.le_offset);
        }
        if !(self.slant.is_finite() && self.slant.abs() < 80f64.to_radians()) {
            return bad("slant", self.slant);
        }
        if let Some(f) = self.flap {
            if !(f.chord_fraction.is_finite() && f.chord_fraction > 0.0 && f.chord_fraction < 1.0) {
                return bad("flap.chord_fraction", f.chord_fraction);
            }
            if !(f.deflection.is_finite() && f.deflection.abs() < MAX_FLAP_DEFLECTION_DEG.to_radians()) {
                return bad("flap.deflection", f.deflection);
            }
            if !f.rate.is_finite() {
                return bad("flap.rate", f.rate);
            }
        }
        Ok(())
    }
}

/// Rigid-body velocity of a section frame: the velocity of `origin` and the angular velocity.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StationVelocity {
    /// Velocity of the station origin, m/s.
    pub linear: Vector3<f64>,
    /// Angular velocity of the section frame, rad/s (global components).
    pub angular: Vector3<f64>,
}

impl StationVelocity {
    /// Velocity of the point at arm `r` from the origin: `v + ω × r`.
    #[inline]
    pub fn at(&self, r: &Vector3<f64>) -> Vector3<f64> {
        self.linear + self.angular.cross(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn slanted_column_lies_on_hinge_axis() {
        let beta = 10f64.to_radians();
        let st = SpanStation { slant: beta, ..SpanStation::new(Vector3::zeros(), Matrix3::identity(), 1.0, 0.5) };
        let a = Vector3::new(beta.sin(), beta.cos(), 0.0);
        for eta in [0.0, 0.3, 1.0] {
            let r = st.arm(eta);
            assert_relative_eq!(r.cross(&a).norm(), 0.0, epsilon = 1e-15);
            assert_relative_eq!(r.y, 0.5 - eta, epsilon = 1e-15);
        }
    }

    #[test]
    fn invalid_fields_are_named() {
        let mut st = SpanStation::new(Vector3::zeros(), Matrix3::identity(), 1.0, 0.5);
        st.chord = -1.0;
        assert!(matches!(st.validate(3), Err(UvlmError::InvalidStation { station: 3, field: "chord", .. })));
        st.chord = 1.0;
        st.frame[(0, 0)] = 2.0;
        assert!(matches!(st.validate(0), Err(UvlmError::InvalidStation { field: "frame", .. })));
        st.frame = Matrix3::identity();
        st.origin.x = f64::NAN;
        assert!(matches!(st.validate(0), Err(UvlmError::InvalidStation { field: "origin", .. })));
        st.origin.x = 0.0;
        for (flap, field) in [
            (StationFlap::new(1.0, 0.1), "flap.chord_fraction"),
            (StationFlap::new(0.0, 0.1), "flap.chord_fraction"),
            (StationFlap::new(0.3, 1.5), "flap.deflection"),
            (StationFlap { rate: f64::INFINITY, ..StationFlap::new(0.3, 0.1) }, "flap.rate"),
        ] {
            st.flap = Some(flap);
            assert!(
                matches!(st.validate(2), Err(UvlmError::InvalidStation { station: 2, field: f, .. }) if f == field)
            );
        }
        st.flap = Some(StationFlap::new(0.25, -0.2));
        assert!(st.validate(2).is_ok());
    }
}
