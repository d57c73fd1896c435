//! Control surfaces on the lattice: the chordwise rows of a flapped column, the hinge line, the
//! rotation of the nodes behind it and the hinge moment (docs/uvlm.md §15).
//!
//! A column whose station carries a [`StationFlap`](crate::StationFlap) of chord fraction `E`
//! puts grid row `r = M − clamp(round(M·E), 1, M − 1)` exactly on the hinge, `η_r = 1 − E`: the
//! `r` panels ahead of it and the `M − r` panels behind it each follow the lattice's chordwise
//! spacing over their own part of the chord. The nodes behind the hinge (rows `r+1..=M`) are
//! rotated by the deflection δ about the hinge line: through the column's hinge node, along the
//! line joining the undeflected hinge points (at the same chord fraction `E`) of the two
//! neighbouring stations (one-sided at the lattice ends), oriented along increasing column index.
//! On a straight-tapered planform those hinge points are collinear, so every column turns about
//! the same line and the flap stays a rigidly rotated plane; rotating each column about its own
//! span axis `x_s` instead would warp a tapered flap.

use crate::error::{Result, UvlmError};
use crate::lattice::{ChordwiseSpacing, Lattice};
use crate::loads::Loads;
use std::ops::RangeInclusive;

/// The control surface of one grid column as the lattice placed it (last station update).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnFlap {
    /// Chordwise grid row on the hinge line (1..M−1); rows after it are on the flap.
    pub hinge_row: usize,
    /// The column's hinge node (on the hinge line), m.
    pub hinge_point: [f64; 3],
    /// Unit direction of the hinge line, along increasing column index.
    pub hinge_axis: [f64; 3],
    /// Flap chord over section chord `E`.
    pub chord_fraction: f64,
    /// Deflection δ, rad, positive trailing edge down (right-handed about `hinge_axis`).
    pub deflection: f64,
    /// Deflection rate dδ/dt, rad/s.
    pub rate: f64,
}

/// Grid row on the hinge of a column of `n_chordwise` panels (≥ 2) with a flap of chord fraction
/// `chord_fraction`: `M − clamp(round(M·E), 1, M − 1)`, so that the flap has the nearest integer
/// number of panels to `M·E` and at least one panel lies on each side of the hinge.
///
/// # Panics
/// If `n_chordwise < 2`.
pub fn hinge_row(n_chordwise: usize, chord_fraction: f64) -> usize {
    assert!(n_chordwise >= 2, "a flapped column needs at least 2 chordwise panels");
    let m = n_chordwise;
    let n_flap = ((m as f64) * chord_fraction).round() as usize;
    m - n_flap.clamp(1, m - 1)
}

/// Chordwise fraction of grid row `i` of a flapped column (hinge row `row`, chord fraction `e`).
pub(crate) fn flap_eta(spacing: ChordwiseSpacing, i: usize, m: usize, row: usize, e: f64) -> f64 {
    let eta_h = 1.0 - e;
    if i == row {
        eta_h
    } else if i < row {
        eta_h * spacing.eta(i, row)
    } else {
        eta_h + e * spacing.eta(i - row, m - row)
    }
}

/// Rotate point `p` about the line through `h` along the unit vector `t` by `angle` (Rodrigues).
pub(crate) fn rotate_about(p: [f64; 3], h: [f64; 3], t: [f64; 3], angle: f64) -> [f64; 3] {
    let v = [p[0] - h[0], p[1] - h[1], p[2] - h[2]];
    let (s, c) = angle.sin_cos();
    let tv = t[0] * v[0] + t[1] * v[1] + t[2] * v[2];
    let txv = cross(t, v);
    std::array::from_fn(|q| h[q] + v[q] * c + txv[q] * s + t[q] * tv * (1.0 - c))
}

#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Hinge moment of the control surface covering grid columns `columns` (every one flapped), N·m:
/// the moment about each column's hinge line of the nodal loads on that column's ring nodes
/// behind the hinge (rows `hinge_row..=M`: ring row `r` is a quarter panel aft of the hinge, on
/// the flap's first panel),
///
/// $$ H = \sum_{j} \sum_{i \ge r_j} \big((x_{ij} - h_j) \times f_{ij}\big)\cdot t_j, $$
///
/// positive trailing edge down (it drives the deflection δ up; lift on the flap gives H < 0).
/// The nodal loads of a grid column hold half of each adjacent panel column, so the two panel
/// columns at the edges of a part-span flap (one side flapped, the other not) count half.
/// `loads` must be the solution on `lattice`'s current geometry.
pub fn hinge_moment(lattice: &Lattice, loads: &Loads, columns: RangeInclusive<usize>) -> Result<f64> {
    let (m, nc) = (lattice.n_chordwise(), lattice.n_spanwise() + 1);
    if loads.nodal.len() != lattice.n_nodes() || loads.positions.len() != lattice.n_nodes() {
        return Err(UvlmError::LengthMismatch { what: "loads", expected: lattice.n_nodes(), got: loads.nodal.len() });
    }
    let mut h_total = 0.0;
    for j in columns {
        let f =
            lattice.column_flaps().get(j).copied().flatten().ok_or(UvlmError::NoFlap { column: j, n_columns: nc })?;
        for i in f.hinge_row..=m {
            let k = i * nc + j;
            let (x, force) = (loads.positions[k], loads.nodal[k]);
            let r = [x[0] - f.hinge_point[0], x[1] - f.hinge_point[1], x[2] - f.hinge_point[2]];
            let mo = cross(r, force);
            h_total += mo[0] * f.hinge_axis[0] + mo[1] * f.hinge_axis[1] + mo[2] * f.hinge_axis[2];
        }
    }
    Ok(h_total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::LatticeSpec;
    use crate::station::{SpanStation, StationFlap, StationVelocity};
    use approx::assert_relative_eq;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn hinge_row_rounds_and_keeps_both_sides() {
        assert_eq!(hinge_row(4, 0.25), 3);
        assert_eq!(hinge_row(32, 0.25), 24);
        assert_eq!(hinge_row(10, 0.25), 7); // round(2.5) = 3 flap panels
        assert_eq!(hinge_row(4, 0.01), 3); // at least one flap panel
        assert_eq!(hinge_row(4, 0.99), 1); // at least one panel ahead
        assert_eq!(hinge_row(2, 0.5), 1);
    }

    #[test]
    fn flap_rows_put_a_node_on_the_hinge() {
        for spacing in [ChordwiseSpacing::Uniform, ChordwiseSpacing::Cosine] {
            let (m, e) = (7, 0.3);
            let r = hinge_row(m, e);
            assert_eq!(flap_eta(spacing, r, m, r, e), 0.7);
            assert_eq!(flap_eta(spacing, 0, m, r, e), 0.0);
            assert_relative_eq!(flap_eta(spacing, m, m, r, e), 1.0, epsilon = 1e-15);
            for i in 1..=m {
                assert!(flap_eta(spacing, i, m, r, e) > flap_eta(spacing, i - 1, m, r, e));
            }
        }
        // Uniform spacing with M·E an integer: the rows of the unflapped column.
        for i in 0..=8 {
            assert_relative_eq!(flap_eta(ChordwiseSpacing::Uniform, i, 8, 6, 0.25), i as f64 / 8.0, epsilon = 1e-15);
        }
    }

    /// Flat wing along +Y, flow along +X, leading edge on x = 0 (x_s = +Y, y_s = −X), `n`
    /// strips of width 1 and chord `chord(y)`, leading edge swept back by `sweep` (x = y tan(sweep)),
    /// every station in `flapped` with a flap.
    fn wing(
        n: usize,
        sweep: f64,
        chord: impl Fn(f64) -> f64,
        flap: StationFlap,
        flapped: RangeInclusive<usize>,
    ) -> Vec<SpanStation> {
        let frame = Matrix3::from_columns(&[Vector3::y(), -Vector3::x(), Vector3::z()]);
        (0..=n)
            .map(|j| {
                let y = j as f64;
                let mut st = SpanStation::new(Vector3::new(y * sweep.tan(), y, 0.0), frame, chord(y), 0.0);
                st.flap = flapped.contains(&j).then_some(flap);
                st
            })
            .collect()
    }

    #[test]
    fn flapped_column_geometry() {
        let d = 10f64.to_radians();
        let lat = Lattice::from_stations(LatticeSpec::new(4), &wing(2, 0.0, |_| 1.0, StationFlap::new(0.25, d), 0..=2))
            .unwrap();
        for j in 0..=2 {
            let f = lat.column_flaps()[j].unwrap();
            assert_eq!(f.hinge_row, 3);
            assert_relative_eq!(f.hinge_point[0], 0.75, epsilon = 1e-15);
            assert_relative_eq!(f.hinge_axis[1], 1.0, epsilon = 1e-15);
            let g = |i: usize| lat.grid_nodes()[lat.node_index(i, j)];
            assert_eq!(g(2), [0.5, j as f64, 0.0]);
            // Trailing edge down for a positive deflection.
            assert_relative_eq!(g(4)[0], 0.75 + 0.25 * d.cos(), epsilon = 1e-15);
            assert_relative_eq!(g(4)[2], -0.25 * d.sin(), epsilon = 1e-15);
        }
        // M = 1 leaves no room for a hinge.
        let st = wing(2, 0.0, |_| 1.0, StationFlap::new(0.25, d), 1..=1);
        assert!(matches!(
            Lattice::from_stations(LatticeSpec::new(1), &st),
            Err(UvlmError::FlapTooFewChordwise { station: 1, n_chordwise: 1 })
        ));
    }

    /// On a straight-tapered (here also swept) planform the hinge points at one chord fraction are collinear, so
    /// every column turns about the same line: the deflected flap is one plane.
    #[test]
    fn tapered_flap_stays_planar() {
        let st = wing(4, 0.5, |y| 1.0 - 0.15 * y, StationFlap::new(0.3, 15f64.to_radians()), 0..=4);
        let lat = Lattice::from_stations(LatticeSpec { spacing: ChordwiseSpacing::Cosine, ..LatticeSpec::new(7) }, &st)
            .unwrap();
        let row = lat.column_flaps()[0].unwrap().hinge_row;
        // The hinge line x = y tan(0.5) + 0.7 (1 − 0.15 y), not the stations' x_s = +Y.
        let slope = 0.5f64.tan() - 0.7 * 0.15;
        for f in lat.column_flaps() {
            assert_relative_eq!(f.unwrap().hinge_axis[0], slope / (1.0 + slope * slope).sqrt(), epsilon = 1e-14);
        }
        let g = |i: usize, j: usize| lat.grid_nodes()[lat.node_index(i, j)];
        let (p0, p1, p2) = (g(row, 0), g(row, 4), g(7, 0));
        let nrm = cross(std::array::from_fn(|q| p1[q] - p0[q]), std::array::from_fn(|q| p2[q] - p0[q]));
        let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
        for i in row..=7 {
            for j in 0..=4 {
                let x = g(i, j);
                let dist = (0..3).map(|q| (x[q] - p0[q]) * nrm[q] / len).sum::<f64>();
                assert!(dist.abs() < 1e-14, "node ({i}, {j}) off the flap plane by {dist:e}");
            }
        }
    }

    /// The node velocities behind the hinge carry δ̇ t × (x − h): they equal the central
    /// difference of the node positions in δ times δ̇ (stations at rest otherwise).
    #[test]
    fn flap_rate_gives_node_velocities() {
        let (d, rate, eps) = (0.2, 3.0, 1e-6);
        let make =
            |delta: f64| wing(3, 0.0, |y| 1.0 - 0.1 * y, StationFlap { rate, ..StationFlap::new(0.3, delta) }, 0..=3);
        let spec = LatticeSpec::new(6);
        let mut lat = Lattice::from_stations(spec, &make(d)).unwrap();
        lat.update_stations(&make(d), Some(&[StationVelocity::default(); 4][..])).unwrap();
        let (plus, minus) = (
            Lattice::from_stations(spec, &make(d + eps)).unwrap(),
            Lattice::from_stations(spec, &make(d - eps)).unwrap(),
        );
        for k in 0..lat.n_nodes() {
            for q in 0..3 {
                let fd = rate * (plus.grid_nodes()[k][q] - minus.grid_nodes()[k][q]) / (2.0 * eps);
                assert_relative_eq!(lat.grid_velocities()[k][q], fd, epsilon = 1e-8);
            }
        }
        // At rest (no station velocities) the rate is not applied.
        let rest = Lattice::from_stations(spec, &make(d)).unwrap();
        assert!(rest.grid_velocities().iter().all(|v| *v == [0.0; 3]));
    }

    /// A part-span flap: the grid stays valid (the edge panels, one side deflected and the other
    /// not, are warped), the unflapped columns are exactly today's grid, and the hinge moment
    /// is only defined on flapped columns.
    #[test]
    fn part_span_flap_edges_and_hinge_moment() {
        // M·E = 1.5 rounds to 2 flap panels: hinge row 3 at η = 0.7 against the plain η = 0.6.
        let st = wing(6, 0.0, |_| 1.0, StationFlap::new(0.3, 20f64.to_radians()), 2..=4);
        let lat = Lattice::from_stations(LatticeSpec::new(5), &st).unwrap();
        let plain =
            Lattice::from_stations(LatticeSpec::new(5), &wing(6, 0.0, |_| 1.0, StationFlap::default(), 7..=7)).unwrap(); // no station flapped
        assert_eq!(lat.column_flaps()[2].unwrap().hinge_row, 3);
        assert_relative_eq!(lat.grid_nodes()[lat.node_index(3, 2)][0], 0.7, epsilon = 1e-15);
        for j in [0, 1, 5, 6] {
            assert!(lat.column_flaps()[j].is_none());
            for i in 0..=5 {
                assert_eq!(lat.grid_nodes()[lat.node_index(i, j)], plain.grid_nodes()[plain.node_index(i, j)]);
            }
        }
        // One upward unit force on the trailing-edge ring node of column 3: H = −(arm) < 0.
        let mut loads =
            Loads { nodal: vec![[0.0; 3]; lat.n_nodes()], positions: lat.ring_nodes().to_vec(), ..Default::default() };
        let k = lat.node_index(5, 3);
        loads.nodal[k] = [0.0, 0.0, 1.0];
        let f = lat.column_flaps()[3].unwrap();
        let x = loads.positions[k];
        let arm = ((x[0] - f.hinge_point[0]).powi(2) + (x[2] - f.hinge_point[2]).powi(2)).sqrt();
        let h = hinge_moment(&lat, &loads, 2..=4).unwrap();
        let d = f.deflection;
        assert_relative_eq!(h, -arm * d.cos(), max_relative = 1e-14);
        assert!(matches!(hinge_moment(&lat, &loads, 1..=4), Err(UvlmError::NoFlap { column: 1, .. })));
        assert!(matches!(hinge_moment(&lat, &loads, 6..=7), Err(UvlmError::NoFlap { column: 6, .. })));
    }

    #[test]
    fn rotation_is_right_handed() {
        // About +x by 90°: +y goes to +z; the axis point stays.
        let p = rotate_about([1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2);
        assert_relative_eq!(p[0], 1.0, epsilon = 1e-15);
        assert_relative_eq!(p[1], 0.0, epsilon = 1e-15);
        assert_relative_eq!(p[2], 1.0, epsilon = 1e-15);
    }
}
