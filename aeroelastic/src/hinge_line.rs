//! Where a flared hinge's line crosses the chord (`joints[i].hinge_line_y`): the joint placed on
//! the beam axis where that line meets it (docs/statics.md §6).
//!
//! A flared hinge turns about the axis `a = sin β x + cos β y` of the parent's end section. The
//! real hinge is a line along `a`; a beam model joins its bodies at one point of the beam axis,
//! which must lie on that line. When the line crosses the parent's end station at `y = y_h` from
//! the axis (towards the leading edge), the point `(s, y_h)` moves along `a` to `y = 0` after
//! `−y_h / cos β`, i.e. `δ = −y_h tan β` along the span: the joint sits at `s = L_parent + δ`.
//! The child's outer end and everything on it stay where they are in space.

use crate::problem::{Joint, Problem};

/// A flared hinge with a hinge line off the beam axis, resolved: its joint index, parent, child
/// and the shift `δ` of the joint along the parent's beam axis, m.
struct Shift {
    joint: usize,
    parent: usize,
    child: usize,
    delta: f64,
}

impl Problem {
    /// The flared hinges whose `hinge_line_y` is not zero, with their shifts.
    fn hinge_line_shifts(&self) -> Vec<Shift> {
        self.joints
            .iter()
            .enumerate()
            .filter_map(|(joint, j)| match j {
                Joint::FlaredHinge { parent, child, flare_deg, hinge_line_y, .. } if *hinge_line_y != 0.0 => {
                    Some(Shift {
                        joint,
                        parent: self.body_index(parent)?,
                        child: self.body_index(child)?,
                        delta: -hinge_line_y * flare_deg.to_radians().tan(),
                    })
                }
                _ => None,
            })
            .collect()
    }

    /// Why the hinge lines cannot be placed: the field (`joints[i].hinge_line_y`) and the reason.
    ///
    /// # Errors
    /// A non-finite value, a flare of ±90° (the line never meets the axis), a parent or child
    /// that would lose its length or with a built-in twist (its table is not moved), a point
    /// mass or thrust of the child that would leave it, a control surface on either body.
    pub fn check_hinge_lines(&self) -> Result<(), (String, String)> {
        for (i, j) in self.joints.iter().enumerate() {
            if let Joint::FlaredHinge { hinge_line_y, flare_deg, .. } = j {
                let field = format!("joints[{i}].hinge_line_y");
                if !hinge_line_y.is_finite() {
                    return Err((field, format!("must be finite, got {hinge_line_y}")));
                }
                if *hinge_line_y != 0.0 && flare_deg.abs() >= 89.0 {
                    return Err((
                        field,
                        format!("needs a flare within ±89° (the line meets the axis), got {flare_deg}"),
                    ));
                }
            }
        }
        for sh in self.hinge_line_shifts() {
            let field = format!("joints[{}].hinge_line_y", sh.joint);
            let (p, c) = (&self.bodies[sh.parent], &self.bodies[sh.child]);
            let err = |msg: String| Err((field.clone(), msg));
            if p.length + sh.delta <= 0.0 || c.length - sh.delta <= 0.0 {
                return err(format!(
                    "moves the joint {:+.4} m along the span, past the end of `{}` or `{}`",
                    sh.delta, p.name, c.name
                ));
            }
            if p.twist_deg.is_some() || c.twist_deg.is_some() {
                return err(format!("not with a built-in twist (`twist_deg`) of `{}` or `{}`", p.name, c.name));
            }
            let inside = |at: f64| (0.0..=c.length - sh.delta).contains(&(at - sh.delta));
            if let Some(k) = c.point_masses.iter().position(|m| !inside(m.at)) {
                return err(format!("moves the joint past point_masses[{k}] of `{}`", c.name));
            }
            if let Some(k) = self.thrust.iter().position(|t| t.body == c.name && !inside(t.at)) {
                return err(format!("moves the joint past thrust[{k}] on `{}`", c.name));
            }
            let surfaces = self.aero.as_ref().map_or(&[][..], |a| &a.control_surfaces[..]);
            // A control surface's span ends on panel edges, which move with the bodies' lengths.
            if let Some(k) = surfaces.iter().position(|s| s.body == c.name || s.body == p.name) {
                return err(format!(
                    "not with a control surface on `{}` or `{}` (aero.control_surfaces[{k}])",
                    p.name, c.name
                ));
            }
        }
        Ok(())
    }

    /// This problem with every flared hinge's joint placed on its hinge line (`hinge_line_y`,
    /// then zero): the parent lengthened and the child shortened by `δ = −y_h tan β`, the child's
    /// `start` moved by `δ` along the parent's beam axis, its point masses and thrusts by `−δ`
    /// along it. Call on a problem that passed [`Problem::check_hinge_lines`]
    /// (the case file's conversion does); a problem without such a hinge is returned unchanged.
    pub fn with_hinge_lines(mut self) -> Problem {
        let shifts = self.hinge_line_shifts();
        if shifts.is_empty() {
            return self;
        }
        let placed = self.placements();
        for sh in shifts {
            let axis = placed[sh.parent].1;
            self.bodies[sh.parent].length += sh.delta;
            let child = &mut self.bodies[sh.child];
            child.length -= sh.delta;
            if let Some(s) = child.start.as_mut() {
                for (k, v) in s.iter_mut().enumerate() {
                    *v += sh.delta * axis[k];
                }
            }
            child.point_masses.iter_mut().for_each(|m| m.at -= sh.delta);
            let name = child.name.clone();
            self.thrust.iter_mut().filter(|t| t.body == name).for_each(|t| t.at -= sh.delta);
            if let Joint::FlaredHinge { hinge_line_y, .. } = &mut self.joints[sh.joint] {
                *hinge_line_y = 0.0;
            }
        }
        self
    }
}
