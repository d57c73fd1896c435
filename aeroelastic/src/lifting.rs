//! The lattice of one or more lifting surfaces on one flat station list (issue 34 item 3).
//!
//! [`crate::aero::station_map`] lays out the stations surface after surface, each tagged with
//! its surface ([`StationMap::lifting`]); the station loads, the structure's section loads and
//! the observers keep that flat list. Here each surface's range of stations becomes one lattice
//! of a [`uvlm::Uvlm`] ([`uvlm::Uvlm::with_surfaces`]), with its own wake; one influence system
//! solves them together. With one surface every call is the one-surface solver's own
//! ([`uvlm::Uvlm::new`], `update_stations`, `loads`), so those cases are bitwise unchanged.

use std::ops::Range;

use crate::aero::StationMap;
use crate::aero_settings::AeroSettings;

/// The stations of each lifting surface: consecutive ranges of the station map, in surface
/// order.
pub fn surface_ranges(map: &[StationMap]) -> Vec<Range<usize>> {
    let mut out: Vec<Range<usize>> = Vec::new();
    for (j, m) in map.iter().enumerate() {
        match out.last_mut() {
            Some(r) if map[r.start].lifting == m.lifting => r.end = j + 1,
            _ => out.push(j..j + 1),
        }
    }
    out
}

/// Chordwise panels of lifting surface `k`: its own `n_chordwise`, or `aero.n_chordwise`.
pub fn n_chordwise_of(aero: &AeroSettings, k: usize) -> usize {
    aero.surfaces.get(k).and_then(|s| s.n_chordwise).unwrap_or(aero.n_chordwise)
}

/// The lattice layout of one surface's stations `map` (surface `k`): chordwise panels and the
/// hinge column (the station a flared hinge drives), numbered within the surface.
pub fn lattice_spec(map: &[StationMap], aero: &AeroSettings, k: usize) -> uvlm::LatticeSpec {
    let hinge = map.iter().position(|m| m.hinge).map(|j| uvlm::HingeColumn { column: j, flare: map[j].slant });
    uvlm::LatticeSpec { hinge, ..uvlm::LatticeSpec::new(n_chordwise_of(aero, k)) }
}

/// The lattices of every surface on `stations` (the stations of `map`, in its order).
pub fn lattices(
    map: &[StationMap],
    aero: &AeroSettings,
    stations: &[uvlm::SpanStation],
) -> Result<Vec<uvlm::Lattice>, uvlm::UvlmError> {
    surface_ranges(map)
        .into_iter()
        .enumerate()
        .map(|(k, r)| uvlm::Lattice::from_stations(lattice_spec(&map[r.clone()], aero, k), &stations[r]))
        .collect()
}

/// The UVLM of every surface on `stations`, each with an empty wake. One surface gives
/// [`uvlm::Uvlm::new`]'s solver.
pub fn new_uvlm(
    map: &[StationMap],
    aero: &AeroSettings,
    stations: &[uvlm::SpanStation],
    params: uvlm::UvlmParams,
) -> Result<uvlm::Uvlm, uvlm::UvlmError> {
    let mut lat = lattices(map, aero, stations)?;
    if lat.len() == 1 {
        return uvlm::Uvlm::new(lat.remove(0), params);
    }
    uvlm::Uvlm::with_surfaces(lat, params)
}

/// Move every surface's lattice to `stations` (and their velocities), split by `ranges`
/// ([`surface_ranges`]). Does not allocate.
pub fn move_lattices(
    uv: &mut uvlm::Uvlm,
    ranges: &[Range<usize>],
    stations: &[uvlm::SpanStation],
    velocities: Option<&[uvlm::StationVelocity]>,
) -> Result<(), uvlm::UvlmError> {
    if let [_] = ranges {
        return uv.update_stations(stations, velocities);
    }
    for (k, r) in ranges.iter().enumerate() {
        uv.update_stations_of(k, &stations[r.clone()], velocities.map(|v| &v[r.clone()]))?;
    }
    Ok(())
}

/// Lump the last solve's nodal loads of every surface to its stations, about `origins` (one per
/// station), into `force` and `moment`. Does not allocate.
pub fn lump_into(
    uv: &uvlm::Uvlm,
    ranges: &[Range<usize>],
    origins: &[[f64; 3]],
    force: &mut [[f64; 3]],
    moment: &mut [[f64; 3]],
) {
    if let [_] = ranges {
        uv.loads().column_loads_inplace(origins, force, moment);
        return;
    }
    for (s, r) in uv.surfaces().iter().zip(ranges) {
        s.loads().column_loads_inplace(&origins[r.clone()], &mut force[r.clone()], &mut moment[r.clone()]);
    }
}

/// Hinge moment of the control surface on stations `columns` of the flat map (one surface's),
/// from the last solve, N·m.
pub fn hinge_moment(
    uv: &uvlm::Uvlm,
    ranges: &[Range<usize>],
    columns: std::ops::RangeInclusive<usize>,
) -> Result<f64, uvlm::UvlmError> {
    if let [_] = ranges {
        return uv.hinge_moment(columns);
    }
    let k = ranges.iter().position(|r| r.contains(columns.start())).unwrap_or(0);
    let o = ranges[k].start;
    uv.hinge_moment_of(k, columns.start() - o..=columns.end() - o)
}
