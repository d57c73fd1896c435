//! Catalogue of reference geometries used by the tests, the benchmark and the harness.

use crate::lattice::{ChordwiseSpacing, HingeColumn, LatticeSpec};
use crate::station::SpanStation;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// Section frame of a flat wing in the aerodynamic frame (flow along +x, span along +y, z up):
/// `x_s = +y`, `y_s = −x` (towards the leading edge), `z_s = +z`.
pub fn aero_frame() -> Matrix3<f64> {
    Matrix3::from_columns(&[Vector3::y(), -Vector3::x(), Vector3::z()])
}

/// Spanwise distribution of the stations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpanSpacing {
    /// Equal strips.
    Uniform,
    /// Cosine clustering at both ends (`y = −cos(π j/N)` mapped to the span).
    Cosine,
    /// Cosine clustering at the far end only (half wings with a symmetry plane at the start).
    HalfCosine,
}

fn span_fraction(j: usize, n: usize, spacing: SpanSpacing) -> f64 {
    let t = j as f64 / n as f64;
    match spacing {
        SpanSpacing::Uniform => t,
        SpanSpacing::Cosine => 0.5 * (1.0 - (std::f64::consts::PI * t).cos()),
        SpanSpacing::HalfCosine => (0.5 * std::f64::consts::PI * t).sin(),
    }
}

/// Flat rectangular wing of chord `chord` from `y0` to `y1` in the aerodynamic frame, leading
/// edge on x = 0, `n_span` strips.
pub fn rectangular_wing(y0: f64, y1: f64, chord: f64, n_span: usize, spacing: SpanSpacing) -> Vec<SpanStation> {
    (0..=n_span)
        .map(|j| {
            let y = y0 + (y1 - y0) * span_fraction(j, n_span, spacing);
            SpanStation::new(Vector3::new(0.0, y, 0.0), aero_frame(), chord, 0.0)
        })
        .collect()
}

/// Right half of a flat elliptic wing (aerodynamic frame, root at y = 0) of aspect ratio
/// `aspect_ratio` (full span² / full area) and root chord `c0`, straight quarter-chord line on
/// x = 0, `n_span` strips clustered towards the tip. The tip station, where the ellipse closes,
/// gets the chord of the ellipse at the mid-point of the last strip so that the last panel keeps
/// a finite area (that strip's area is then the exact elliptic area to first order).
pub fn elliptic_half_wing(aspect_ratio: f64, c0: f64, n_span: usize) -> Vec<SpanStation> {
    // Area of the full elliptic wing: π b c0 / 4 → AR = b² / area = 4b/(π c0).
    let b = aspect_ratio * std::f64::consts::PI * c0 / 4.0;
    let half = 0.5 * b;
    (0..=n_span)
        .map(|j| {
            let t = span_fraction(j, n_span, SpanSpacing::HalfCosine);
            let t_chord =
                if j == n_span { 0.5 * (t + span_fraction(j - 1, n_span, SpanSpacing::HalfCosine)) } else { t };
            let c = c0 * (1.0 - t_chord * t_chord).max(0.0).sqrt();
            SpanStation::new(Vector3::new(0.0, half * t, 0.0), aero_frame(), c, 0.25 * c)
        })
        .collect()
}

/// The paper's flared hinged wing (Otsuka, Cheng & Palacios 2024, Table 3-4): semispan 16 m along
/// +X (12 m inner + 4 m outer), chord 1 m, beam axis at mid-chord, leading edge towards +Y, flow
/// along −Y; 24 + 8 spanwise and 4 chordwise panels; flare 10°.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlaredWing {
    /// Inner body length, m.
    pub inner_length: f64,
    /// Outer body length, m.
    pub outer_length: f64,
    /// Chord, m.
    pub chord: f64,
    /// Spanwise panels on the inner body.
    pub n_inner: usize,
    /// Spanwise panels on the outer body.
    pub n_outer: usize,
    /// Chordwise panels.
    pub n_chordwise: usize,
    /// Flare angle β, rad.
    pub flare: f64,
    /// Angle of attack: nose-up pitch of the whole wing about +X, rad.
    pub aoa: f64,
    /// Blend the slant over this many columns on each side of the hinge (docs/uvlm.md §7): column at
    /// distance d gets slant β·(1 − d/(blend + 1)). 0 = only the hinge column is slanted; needed
    /// when tanβ·c/2 approaches the panel width (fine spanwise meshes).
    pub blend_columns: usize,
}

impl Default for FlaredWing {
    fn default() -> Self {
        Self {
            inner_length: 12.0,
            outer_length: 4.0,
            chord: 1.0,
            n_inner: 24,
            n_outer: 8,
            n_chordwise: 4,
            flare: 10f64.to_radians(),
            aoa: 0.0,
            blend_columns: 0,
        }
    }
}

impl FlaredWing {
    /// Meshing specification (hinge column `n_inner`).
    pub fn spec(&self) -> LatticeSpec {
        LatticeSpec {
            n_chordwise: self.n_chordwise,
            spacing: ChordwiseSpacing::Uniform,
            hinge: Some(HingeColumn { column: self.n_inner, flare: self.flare }),
            min_corner_angle_deg: 2.0,
        }
    }

    /// Global hinge axis `a = sinβ·x_s + cosβ·y_s` of the inner body's end frame.
    pub fn hinge_axis(&self) -> Vector3<f64> {
        let pitch = Rotation3::from_axis_angle(&Vector3::x_axis(), self.aoa);
        pitch * Vector3::new(self.flare.sin(), self.flare.cos(), 0.0)
    }

    /// Stations with the outer body folded by `fold` (rad, docs/conventions.md §4: right-hand rule about
    /// −a, positive lifts the tip towards +z).
    pub fn stations(&self, fold: f64) -> Vec<SpanStation> {
        let pitch = Rotation3::from_axis_angle(&Vector3::x_axis(), self.aoa);
        let frame = *pitch.matrix();
        let hinge = Vector3::new(self.inner_length, 0.0, 0.0);
        let axis = Unit::new_normalize(-self.hinge_axis());
        let rot = Rotation3::from_axis_angle(&axis, fold);
        let n = self.n_inner + self.n_outer;
        let slant = |j: usize| {
            let d = j.abs_diff(self.n_inner);
            if d <= self.blend_columns { self.flare * (1.0 - d as f64 / (self.blend_columns + 1) as f64) } else { 0.0 }
        };
        (0..=n)
            .map(|j| {
                let station = if j <= self.n_inner {
                    let x = self.inner_length * j as f64 / self.n_inner as f64;
                    SpanStation::new(Vector3::new(x, 0.0, 0.0), frame, self.chord, 0.5 * self.chord)
                } else {
                    let x = self.inner_length + self.outer_length * (j - self.n_inner) as f64 / self.n_outer as f64;
                    let o = hinge + rot * (Vector3::new(x, 0.0, 0.0) - hinge);
                    SpanStation::new(o, rot.matrix() * frame, self.chord, 0.5 * self.chord)
                };
                SpanStation { slant: slant(j), ..station }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn elliptic_wing_has_requested_aspect_ratio() {
        let st = elliptic_half_wing(8.0, 1.0, 200);
        let half_span = st.last().unwrap().origin.y;
        let area: f64 = st.windows(2).map(|w| 0.5 * (w[0].chord + w[1].chord) * (w[1].origin.y - w[0].origin.y)).sum();
        assert_relative_eq!((2.0 * half_span).powi(2) / (2.0 * area), 8.0, max_relative = 2e-3);
    }

    #[test]
    fn flared_wing_hinge_and_fold_convention() {
        let w = FlaredWing::default();
        let a = w.hinge_axis();
        assert_relative_eq!(a.x, 10f64.to_radians().sin(), epsilon = 1e-15);
        // Positive fold lifts the tip towards +z; the hinge station does not move.
        let up = w.stations(0.3);
        let down = w.stations(-0.3);
        assert!(up.last().unwrap().origin.z > 0.5 && down.last().unwrap().origin.z < -0.5);
        assert_eq!(up[w.n_inner].origin, w.stations(0.0)[w.n_inner].origin);
    }
}
