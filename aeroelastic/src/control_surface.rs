//! Control surfaces of a problem (`aero.control_surfaces`, issue 34 item 4): trailing-edge flaps
//! over a span range of one body, at a fixed deflection or following a schedule in time; their
//! checks against the lattice's stations, and the deflection a station carries at a time
//! (docs/uvlm.md §15 places the flap on the lattice, docs/case-file.md describes the fields).

use crate::problem::Problem;

/// Most control surfaces a case may have (the rows keep their hinge moments in a fixed array).
pub const MAX_CONTROL_SURFACES: usize = 16;

/// One entry of `aero.control_surfaces`: a trailing-edge flap on a span range of one body.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ControlSurface {
    /// Name: the CSV column `<name>_hinge_moment`, and `--set aero.control_surfaces.<name>.…`.
    pub name: String,
    /// The body it is hinged to (its name).
    pub body: String,
    /// Arclength range `[s0, s1]` along the body, m: panel edges of the body's lattice strips.
    pub span: [f64; 2],
    /// Flap chord over section chord, in (0, 1).
    pub chord_fraction: f64,
    /// Deflection, degrees, trailing edge down positive: a number, or a schedule `[[t, deg], …]`.
    pub deflection_deg: Deflection,
}

/// A deflection: fixed, or a schedule in time (linear in between, held outside).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub enum Deflection {
    /// A fixed deflection, degrees.
    Fixed(f64),
    /// Points `[t (s), deflection (deg)]`, strictly increasing in time.
    Schedule(Vec<[f64; 2]>),
}

impl Deflection {
    /// Deflection (degrees) and its rate (degrees/s) at time `t`: linear between the schedule's
    /// points, the rate the slope of the segment holding `t` (`[t_i, t_{i+1})`); before the
    /// first point and from the last on, the end value and zero rate.
    pub fn at(&self, t: f64) -> (f64, f64) {
        match self {
            Deflection::Fixed(d) => (*d, 0.0),
            Deflection::Schedule(p) => {
                let (Some(first), Some(last)) = (p.first(), p.last()) else { return (0.0, 0.0) };
                if t < first[0] {
                    return (first[1], 0.0);
                }
                if t >= last[0] {
                    return (last[1], 0.0);
                }
                let i = p.partition_point(|x| x[0] <= t) - 1;
                let (a, b) = (p[i], p[i + 1]);
                let slope = (b[1] - a[1]) / (b[0] - a[0]);
                (a[1] + slope * (t - a[0]), slope)
            }
        }
    }

    /// The deflections this gives, degrees (the fixed value or every schedule point's).
    fn values(&self) -> Vec<f64> {
        match self {
            Deflection::Fixed(d) => vec![*d],
            Deflection::Schedule(p) => p.iter().map(|x| x[1]).collect(),
        }
    }
}

impl ControlSurface {
    /// The lattice flap of this surface at time `t` (None: steady, the deflection at t = 0 at
    /// rest).
    pub fn flap_at(&self, t: Option<f64>) -> uvlm::StationFlap {
        let (d, rate) = self.deflection_deg.at(t.unwrap_or(0.0));
        uvlm::StationFlap {
            chord_fraction: self.chord_fraction,
            deflection: d.to_radians(),
            rate: if t.is_some() { rate.to_radians() } else { 0.0 },
        }
    }

    /// Whether `other` is deflected as this surface at every time: the same chord fraction and
    /// deflection (number or schedule). Such surfaces may meet at a station.
    pub fn alike(&self, other: &ControlSurface) -> bool {
        self.chord_fraction == other.chord_fraction && self.deflection_deg == other.deflection_deg
    }

    /// Whether this surface covers arclength `s` of body `body` (a panel edge; tolerance 1e-9
    /// of the body length).
    fn covers(&self, case: &Problem, body: usize, s: f64) -> bool {
        let b = &case.bodies[body];
        let tol = 1e-9 * b.length;
        b.name == self.body && s >= self.span[0] - tol && s <= self.span[1] + tol
    }
}

/// The control surface covering the station at arclength `s` of body `body` (index into
/// `surfaces`); a hinge column (the inner body's end) is covered too by a surface of the next
/// body (`next`, the hinge column's outer body) that starts at its root. Two surfaces on one station column are an error.
pub(crate) fn surface_at(
    case: &Problem,
    surfaces: &[ControlSurface],
    body: usize,
    s: f64,
    next: Option<usize>,
) -> Result<Option<usize>, String> {
    let on = |c: &ControlSurface| c.covers(case, body, s) || next.is_some_and(|n| c.covers(case, n, 0.0));
    let mut found = surfaces.iter().enumerate().filter(|(_, c)| on(c)).map(|(i, _)| i);
    match (found.next(), found.next()) {
        (Some(a), Some(b)) if surfaces[a].alike(&surfaces[b]) && found.next().is_none() => Ok(Some(a)),
        (Some(a), Some(b)) => Err(format!(
            "aero.control_surfaces[{b}]: shares a lattice station column with aero.control_surfaces[{a}] \
             (body `{}` at s = {s}); surfaces must be apart by at least one panel, or have one chord fraction \
             and one deflection",
            case.bodies[body].name
        )),
        (a, None) => Ok(a),
        (None, Some(_)) => unreachable!("a second match implies a first"),
    }
}

/// Check the control surfaces against the bodies and their lattice strips (`lattice[b]`: body
/// `b`'s spanwise and chordwise panels, `None` on no lifting surface); the messages name the
/// field (`aero.control_surfaces[1].span`).
pub fn check(case: &Problem, surfaces: &[ControlSurface], lattice: &[Option<(usize, usize)>]) -> Result<(), String> {
    if surfaces.len() > MAX_CONTROL_SURFACES {
        return Err(format!("aero.control_surfaces: {} surfaces, at most {MAX_CONTROL_SURFACES}", surfaces.len()));
    }
    let max = uvlm::MAX_FLAP_DEFLECTION_DEG;
    for (i, c) in surfaces.iter().enumerate() {
        let at = format!("aero.control_surfaces[{i}]");
        if c.name.is_empty() || surfaces[..i].iter().any(|o| o.name == c.name) {
            return Err(format!("{at}.name: `{}` is empty or names another surface too", c.name));
        }
        let Some(b) = case.body_index(&c.body) else {
            return Err(format!("{at}.body: no body named `{}`", c.body));
        };
        let Some((n, n_chordwise)) = lattice.get(b).copied().flatten() else {
            return Err(format!("{at}.body: `{}` is on no lifting surface", c.body));
        };
        if n_chordwise < 2 {
            return Err(format!(
                "aero.n_chordwise: {n_chordwise} on `{}`'s surface; a control surface needs at least 2 chordwise panels \
                 (one on each side of its hinge)",
                c.body
            ));
        }
        let len = case.bodies[b].length;
        let [s0, s1] = c.span;
        if !(s0.is_finite() && s1.is_finite() && 0.0 <= s0 && s0 < s1 && s1 <= len * (1.0 + 1e-9)) {
            return Err(format!("{at}.span: [{s0}, {s1}] is not a range 0 ≤ s0 < s1 ≤ {len} (the body's length)"));
        }
        let h = len / n.max(1) as f64;
        for s in [s0, s1] {
            if (s / h - (s / h).round()).abs() * h > 1e-9 * len {
                return Err(format!(
                    "{at}.span: {s} is not a panel edge of body `{}` (must be a multiple of length / panels_per_body = {h})",
                    c.body
                ));
            }
        }
        if !(c.chord_fraction > 0.0 && c.chord_fraction < 1.0) {
            return Err(format!("{at}.chord_fraction: {} is not in (0, 1)", c.chord_fraction));
        }
        if let Deflection::Schedule(p) = &c.deflection_deg {
            if p.is_empty() {
                return Err(format!("{at}.deflection_deg: an empty schedule"));
            }
            if p.iter().any(|x| !x[0].is_finite()) || p.windows(2).any(|w| w[1][0] <= w[0][0]) {
                return Err(format!(
                    "{at}.deflection_deg: the schedule's times are not finite and strictly increasing"
                ));
            }
        }
        if let Some(d) = c.deflection_deg.values().into_iter().find(|d| !(d.is_finite() && d.abs() < max)) {
            return Err(format!("{at}.deflection_deg: {d} is not a finite deflection within ±{max}°"));
        }
    }
    Ok(())
}

/// Each surface's station columns in `map` (a station shared with an alike surface that
/// carries it, [`surface_at`], starts the later surface's range too).
pub(crate) fn columns(
    map: &[crate::aero::StationMap],
    surfaces: &[ControlSurface],
) -> Result<Vec<std::ops::RangeInclusive<usize>>, String> {
    let mut out = Vec::with_capacity(surfaces.len());
    for (i, c) in surfaces.iter().enumerate() {
        let mut js = map.iter().enumerate().filter(|(_, m)| m.control == Some(i)).map(|(j, _)| j);
        let mut first =
            js.next().ok_or_else(|| format!("aero.control_surfaces[{i}].span: covers no lattice station"))?;
        let last = js.next_back().unwrap_or(first);
        let shared = |j: usize| {
            map[j].lifting == map[first].lifting
                && map[j].control.is_some_and(|a| a != i && surfaces.get(a).is_some_and(|o| o.alike(c)))
        };
        if first > 0 && shared(first - 1) {
            first -= 1;
        }
        out.push(first..=last);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_is_linear_and_held() {
        let d = Deflection::Schedule(vec![[0.0, 0.0], [0.1, 2.0], [0.3, 2.0]]);
        assert_eq!(d.at(-1.0), (0.0, 0.0));
        let (x, r) = d.at(0.05);
        assert!((x - 1.0).abs() < 1e-12 && (r - 20.0).abs() < 1e-9);
        assert_eq!(d.at(0.2), (2.0, 0.0));
        assert_eq!(d.at(0.3), (2.0, 0.0));
        assert_eq!(d.at(5.0), (2.0, 0.0));
        assert_eq!(Deflection::Fixed(3.0).at(7.0), (3.0, 0.0));
    }
}
