//! [`Case::validate`]: every value of a case checked before anything is built, each refusal
//! naming the field. The checks run in a fixed order (the first failing one is reported), one
//! group of fields per function.

use aeroelastic::aero::AeroSettings;

use super::{Block, Case, FormSetting, Formulation, Joint, MAX_STATIC_POINTS, StaticSettings, clip};
use super::{finite3, norm3, whole_steps};
use crate::budget::{
    MAX_BODIES, MAX_CHORDWISE, MAX_ELEMENTS_PER_BODY, MAX_LIST, MAX_NEWTON_ITER, MAX_PANELS_PER_BODY,
    MAX_STEP_HALVINGS, MAX_SUB_ITERATIONS, MAX_WAKE_ROWS,
};

/// `v` is a finite positive number.
/// A sideslip angle: finite and inside (−90°, 90°) (at ±90° the stream runs along the span).
fn sideslip(field: &str, deg: f64) -> Result<(), String> {
    if deg.is_finite() && deg.abs() < 90.0 {
        Ok(())
    } else {
        Err(format!("{field}: {deg} is not a sideslip angle in (-90, 90) degrees"))
    }
}

fn positive(field: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v > 0.0 { Ok(()) } else { Err(format!("{field}: {v} is not a positive number")) }
}

/// `v` is a finite number of at least zero.
fn non_negative(field: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v >= 0.0 { Ok(()) } else { Err(format!("{field}: {v} is not a non-negative number")) }
}

/// The case-file key of a formulation's settings block.
fn key(f: Formulation) -> &'static str {
    f.as_str()
}

impl Case {
    /// Check every value a run of both formulations reads; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        self.validate_for(&Formulation::ALL)
    }

    /// Check every value a run of the formulations `fs` reads: the shared fields, and of the
    /// settings blocks (`ancf`, `gebf`) only those of `fs`, so that a run of one formulation is
    /// not refused over the other's settings. The message names the field.
    pub fn validate_for(&self, fs: &[Formulation]) -> Result<(), String> {
        self.check_name()?;
        self.check_counts()?;
        self.check_bodies()?;
        self.check_joints()?;
        positive("stiffness_scale", self.stiffness_scale)?;
        self.check_discretisation(fs)?;
        if let Some(a) = &self.aero {
            check_aero_caps(a)?;
        }
        // Everything else about the structure, as the formulations will check it (in degrees
        // where the case speaks degrees). The scenes differ only in their element counts.
        let first = fs.first().copied().unwrap_or(Formulation::ALL[0]);
        self.scene(first).validate().map_err(|e| e.to_string())?;
        self.check_times(fs)?;
        self.check_events()?;
        self.check_references()?;
        if let Some(a) = &self.aero {
            self.check_aero(a, fs)?;
        }
        if !(self.pitch_deg.is_finite() && (-90.0..=90.0).contains(&self.pitch_deg)) {
            return Err(format!("pitch_deg: {} is not in [-90, 90]", self.pitch_deg));
        }
        if let Some(g) = self.aero.as_ref().and_then(|a| a.gust.as_ref()) {
            g.validate()?;
        }
        if let Some(g) = &self.gust {
            g.validate(&self.problem())?;
        }
        if let Some(t) = &self.trim {
            t.validate(&self.problem())?;
        }
        let initial = self.initial.name();
        if self.initial.is_trim() && self.trim.is_none() {
            return Err(format!("initial: \"{initial}\" needs a `trim` block"));
        }
        if self.initial.is_trim() && self.runs_ancf_ode(fs) {
            return Err(format!(
                "initial: \"{initial}\" needs ancf.path \"dae\" (the trim holds the free body, which changes the ODE \
                 path's coordinates)"
            ));
        }
        match (&self.statics, self.aero.is_some()) {
            (Some(st), false) => self.check_structural_static(st)?,
            (Some(st), true) => check_aero_static(st)?,
            (None, _) => {}
        }
        if let Some(st) = &self.stability {
            if self.aero.is_none() {
                return Err("stability: a stability analysis needs `aero`".into());
            }
            st.validate()?;
            if st.about == aeroelastic::stability::About::Trim {
                if self.trim.is_none() {
                    return Err("stability.about: \"trim\" needs a `trim` block".into());
                }
                if st.aerodynamics == aeroelastic::stability::AeroModel::Strip {
                    return Err(
                        "stability.aerodynamics: \"strip\" is not available about a trim (the lattice is)".into()
                    );
                }
                if self.runs_ancf_ode(fs) {
                    return Err("stability.about: \"trim\" needs ancf.path \"dae\" (the trim holds the free body, \
                                which changes the ODE path's coordinates)"
                        .into());
                }
            }
        }
        self.check_gate()
    }

    /// Whether one of the formulations `fs` runs ANCF on its ODE path, whose coordinates a trim's
    /// held free body changes.
    fn runs_ancf_ode(&self, fs: &[Formulation]) -> bool {
        fs.iter().any(|f| f.pick(self.ancf.path == aeroelastic::problem::AncfPath::Ode, false))
    }

    /// The name is a folder under the output directory (and a sweep adds `__key=value`).
    fn check_name(&self) -> Result<(), String> {
        let n = &self.name;
        let safe = |c: char| c.is_ascii_alphanumeric() || "._-+=,".contains(c);
        if n.is_empty() || n.len() > 120 || n == "." || n == ".." || !n.chars().all(safe) {
            return Err(format!(
                "name: `{n}` is not a safe file name (1 to 120 bytes of ASCII letters, digits and `._-+=,`; \
                 not `.` or `..`)"
            ));
        }
        Ok(())
    }

    /// At least one body, and the counts that the checks below (and the scene's) visit in pairs
    /// within their limits.
    fn check_counts(&self) -> Result<(), String> {
        if self.bodies.is_empty() {
            return Err("bodies: at least one body is needed".into());
        }
        let counts = [
            ("bodies", self.bodies.len(), MAX_BODIES),
            ("joints", self.joints.len(), MAX_BODIES),
            ("references", self.references.len(), MAX_LIST),
            ("gate.windows", self.gate.as_ref().map_or(0, |g| g.windows.len()), MAX_LIST),
        ];
        for (field, n, cap) in counts {
            if n > cap {
                return Err(format!("{field}: {n} entries, more than the limit of {cap}"));
            }
        }
        if let Some(i) = self.bodies.iter().position(|b| b.point_masses.len() > MAX_LIST) {
            return Err(format!(
                "bodies[{i}].point_masses: {} entries, more than the limit of {MAX_LIST}",
                self.bodies[i].point_masses.len()
            ));
        }
        Ok(())
    }

    /// Unique non-empty names and a right-handed pair of section axes per body.
    fn check_bodies(&self) -> Result<(), String> {
        for (i, b) in self.bodies.iter().enumerate() {
            let f = |s: &str| format!("bodies[{i}].{s}");
            if b.name.is_empty() {
                return Err(f("name: empty"));
            }
            if self.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(f(&format!("name: `{}` is used twice", b.name)));
            }
            if !finite3(&b.x_axis) || norm3(&b.x_axis) < 1e-12 {
                return Err(f("x_axis: not a finite non-zero vector"));
            }
            if !finite3(&b.y_axis) || norm3(&b.y_axis) < 1e-12 {
                return Err(f("y_axis: not a finite non-zero vector"));
            }
            let dot: f64 =
                (0..3).map(|k| b.x_axis[k] * b.y_axis[k]).sum::<f64>() / (norm3(&b.x_axis) * norm3(&b.y_axis));
            if dot.abs() > 1e-9 {
                return Err(f(&format!("y_axis: not perpendicular to x_axis (cosine {dot:.3e})")));
            }
            if let Some(s) = b.start
                && !finite3(&s)
            {
                return Err(f("start: not a finite point"));
            }
            if let Some(t) = &b.twist_deg {
                t.check(&f("twist_deg"), b.length)?;
            }
            for (key, deg) in [("sweep_deg", b.sweep_deg), ("dihedral_deg", b.dihedral_deg)] {
                if !(deg.is_finite() && deg.abs() <= 80.0) {
                    return Err(f(&format!("{key}: {deg} is outside ±80 degrees")));
                }
            }
            let hangs = self
                .joints
                .iter()
                .any(|j| matches!(j, aeroelastic::problem::Joint::FlaredHinge { child, .. } if *child == b.name));
            let own_axes = b.x_axis != [1.0, 0.0, 0.0] || b.y_axis != [0.0, 1.0, 0.0];
            if hangs && own_axes && (b.sweep_deg != 0.0 || b.dihedral_deg != 0.0) {
                return Err(f(
                    "x_axis: a body swept or raised relative to its parent takes its axes from the parent's end \
                     section; give either x_axis/y_axis or sweep_deg/dihedral_deg",
                ));
            }
        }
        Ok(())
    }

    /// Every joint names existing bodies, flare angles lie in [−90°, 90°], and `fold_joint` is
    /// a flared hinge.
    /// Each event on a flared hinge by name, at a time within the run or on one condition; the
    /// timed events of a hinge without triggered ones lock a free hinge or release a locked one,
    /// in time order (a triggered event's order is known only in the run, which refuses a lock
    /// of a locked hinge naming the event and the time).
    fn check_events(&self) -> Result<(), String> {
        let hinge = |field: String, name: &str| match self.joints.iter().position(|j| j.name() == Some(name)) {
            Some(j) if matches!(self.joints[j], Joint::FlaredHinge { .. }) => Ok(j),
            Some(_) => Err(format!("{field}: `{name}` is not a flared hinge")),
            None => Err(format!("{field}: no joint named `{name}`")),
        };
        let mut triggered = vec![false; self.joints.len()];
        for (k, e) in self.events.iter().enumerate() {
            let j = hinge(format!("events[{k}].joint"), &e.joint)?;
            match (e.time, &e.when) {
                (Some(t), None) => {
                    if !(t.is_finite() && t > 0.0 && t <= self.t_end) {
                        return Err(format!("events[{k}].time: {t} is not in (0, t_end = {}]", self.t_end));
                    }
                }
                (None, Some(w)) => {
                    triggered[j] = true;
                    self.check_trigger(&format!("events[{k}].when"), w, &hinge)?;
                }
                _ => return Err(format!("events[{k}]: give either `time` or `when`, not both or neither")),
            }
        }
        self.check_event_order(&triggered)
    }

    /// One condition `w` at `field`: exactly one finite threshold, a flared hinge to watch, and
    /// for the root bending moment the aerodynamics and the clamp it is measured at.
    fn check_trigger(
        &self,
        field: &str,
        w: &aeroelastic::events::Trigger,
        hinge: &dyn Fn(String, &str) -> Result<usize, String>,
    ) -> Result<(), String> {
        let set =
            [w.fold_deg_above, w.fold_deg_below, w.root_bending_moment_above, w.root_bending_moment_increment_above];
        if set.iter().filter(|x| x.is_some()).count() != 1 {
            return Err(format!(
                "{field}: give exactly one of fold_deg_above, fold_deg_below, root_bending_moment_above, \
                 root_bending_moment_increment_above"
            ));
        }
        for (name, x) in [("fold_deg_above", w.fold_deg_above), ("fold_deg_below", w.fold_deg_below)] {
            if let Some(x) = x {
                finite_in(&format!("{field}.{name}"), x)?;
            }
        }
        if let Some(j) = &w.joint {
            hinge(format!("{field}.joint"), j)?;
        }
        let moment = [
            ("root_bending_moment_above", w.root_bending_moment_above),
            ("root_bending_moment_increment_above", w.root_bending_moment_increment_above),
        ];
        if let Some((name, m)) = moment.iter().find_map(|(n, x)| x.map(|m| (*n, m))) {
            let field = format!("{field}.{name}");
            finite_in(&field, m)?;
            if w.joint.is_some() {
                return Err(format!("{field}: a root bending moment trigger watches no joint"));
            }
            let root = self.root_joint.is_some() || self.joints.iter().any(|j| matches!(j, Joint::Clamp { .. }));
            if self.aero.is_none() || !root {
                return Err(format!(
                    "{field}: needs `aero` and a clamp or a `root_joint` (where the moment is measured)"
                ));
            }
        }
        Ok(())
    }

    /// The timed events of each hinge without triggered events, in time order: a lock of a free
    /// hinge, a release of a locked one.
    fn check_event_order(&self, triggered: &[bool]) -> Result<(), String> {
        use aeroelastic::events::HingeAction;
        let mut order: Vec<usize> = (0..self.events.len()).filter(|&k| self.events[k].time.is_some()).collect();
        order.sort_by(|&a, &b| self.events[a].time.unwrap_or(0.0).total_cmp(&self.events[b].time.unwrap_or(0.0)));
        let mut locked: Vec<Option<bool>> = self
            .joints
            .iter()
            .map(|j| match j {
                Joint::FlaredHinge { locked, .. } => Some(*locked),
                _ => None,
            })
            .collect();
        for k in order {
            let e = &self.events[k];
            let Some(j) = self.joints.iter().position(|j| j.name() == Some(e.joint.as_str())) else { continue };
            let Some(state) = locked[j].as_mut().filter(|_| !triggered[j]) else { continue };
            let t = e.time.unwrap_or(0.0);
            match (e.action, *state) {
                (HingeAction::Lock, true) => {
                    return Err(format!("events[{k}].action: `{}` is already locked at t = {t}", e.joint));
                }
                (HingeAction::Release, false) => {
                    return Err(format!("events[{k}].action: `{}` is not locked at t = {t}", e.joint));
                }
                _ => *state = !*state,
            }
        }
        Ok(())
    }

    fn check_joints(&self) -> Result<(), String> {
        let body = |field: String, name: &str| -> Result<(), String> {
            if self.body_index(name).is_some() { Ok(()) } else { Err(format!("{field}: no body named `{name}`")) }
        };
        for (i, j) in self.joints.iter().enumerate() {
            match j {
                Joint::GroundHinge { body: b, .. } => {
                    body(format!("joints[{i}].body"), b)?;
                }
                Joint::FlaredHinge { parent, child, flare_deg, .. } => {
                    body(format!("joints[{i}].parent"), parent)?;
                    body(format!("joints[{i}].child"), child)?;
                    if !(flare_deg.is_finite() && (-90.0..=90.0).contains(flare_deg)) {
                        return Err(format!("joints[{i}].flare_deg: {flare_deg} is not in [-90, 90]"));
                    }
                }
                Joint::Clamp { body: b, .. } | Joint::Free { body: b, .. } => body(format!("joints[{i}].body"), b)?,
            }
        }
        self.problem_as_written().check_hinge_lines().map_err(|(field, msg)| format!("{field}: {msg}"))?;
        for (k, t) in self.thrust.iter().enumerate() {
            // the scene names the rest (`thrust[k].at`, `.direction`, `.magnitude`)
            body(format!("thrust[{k}].body"), &t.body)?;
        }
        if let Some(n) = &self.roll_joint {
            match self.joints.iter().find(|j| j.name() == Some(n.as_str())) {
                Some(Joint::GroundHinge { .. }) => {}
                Some(_) => return Err(format!("roll_joint: `{n}` is not a ground hinge")),
                None => return Err(format!("roll_joint: no joint named `{n}`")),
            }
        }
        if let Some(n) = &self.root_joint {
            match self.joints.iter().find(|j| j.name() == Some(n.as_str())) {
                Some(Joint::FlaredHinge { .. } | Joint::Clamp { .. }) => {}
                Some(_) => return Err(format!("root_joint: `{n}` is neither a flared hinge nor a clamp")),
                None => return Err(format!("root_joint: no joint named `{n}`")),
            }
        }
        if let Some(n) = &self.fold_joint {
            match self.joints.iter().find(|j| j.name() == Some(n.as_str())) {
                Some(Joint::FlaredHinge { .. }) => {}
                Some(_) => return Err(format!("fold_joint: `{n}` is not a flared hinge")),
                None => return Err(format!("fold_joint: no joint named `{n}`")),
            }
        }
        Ok(())
    }

    /// Element counts of `fs`, then their Newton iteration counts and nesting, capped (each
    /// multiplies the work of a step).
    fn check_discretisation(&self, fs: &[Formulation]) -> Result<(), String> {
        for &f in fs {
            let n = self.block(f).elements_per_body;
            n.check(&format!("{}.elements_per_body", key(f)), self.bodies.len())?;
            if let Some(i) = (0..self.bodies.len()).find(|&i| n.for_body(i) > MAX_ELEMENTS_PER_BODY) {
                return Err(format!(
                    "{}.elements_per_body: {} elements on bodies[{i}], more than the limit of {MAX_ELEMENTS_PER_BODY}",
                    key(f),
                    n.for_body(i),
                ));
            }
        }
        for &f in fs {
            let newton = self.block(f).newton;
            if newton.max_iter > MAX_NEWTON_ITER {
                return Err(format!(
                    "{}.newton.max_iter: {} is more than the limit of {MAX_NEWTON_ITER}",
                    key(f),
                    newton.max_iter,
                ));
            }
            if newton.max_step_halvings > MAX_STEP_HALVINGS {
                return Err(format!(
                    "{}.newton.max_step_halvings: {} is more than the limit of {MAX_STEP_HALVINGS}",
                    key(f),
                    newton.max_step_halvings,
                ));
            }
        }
        Ok(())
    }

    /// End time, output interval and the refinement study's end time, then per formulation of
    /// `fs` its step (a whole number of steps in each) and spectral radius, then the
    /// integrator's own checks.
    fn check_times(&self, fs: &[Formulation]) -> Result<(), String> {
        positive("t_end", self.t_end)?;
        if self.vtk.is_some_and(|v| v.stride == Some(0)) {
            return Err("vtk.stride: must be at least 1".into());
        }
        if let Some(t) = self.converge_t_end {
            positive("converge_t_end", t)?;
        }
        if let Some(o) = self.output_dt {
            positive("output_dt", o)?;
        }
        for &f in fs {
            let Block { dt, rho_inf: rho, .. } = self.block(f);
            let f = key(f);
            positive(&format!("{f}.dt"), dt)?;
            // The time loops take whole steps: a t_end (or output interval) between two steps
            // would end (or sample) the run somewhere else than the case says.
            if self.t_end < dt * (1.0 - 1e-9) {
                return Err(format!("{f}.dt: t_end = {} is shorter than one step of {dt} s", self.t_end));
            }
            for (name, t) in [("t_end", Some(self.t_end)), ("output_dt", self.output_dt)] {
                if let Some(t) = t
                    && whole_steps(t, dt).is_none()
                {
                    return Err(format!("{f}.dt: {name} = {t} is not a whole number of steps of {dt} s"));
                }
            }
            if !(0.0..=1.0).contains(&rho) {
                return Err(format!("{f}.rho_inf: {rho} is not in [0, 1]"));
            }
        }
        // The integrator's own checks (Newton tolerances, iteration counts), named by case path.
        for &f in fs {
            if let Err(genalpha::Error::InvalidParameter { field, reason }) =
                crate::scene::settings(self, f).params.validate()
            {
                return Err(format!("{f}.{field}: {reason}"));
            }
        }
        Ok(())
    }

    /// Finite time shifts and positive gate limits of the external references.
    fn check_references(&self) -> Result<(), String> {
        for (k, r) in self.references.iter().enumerate() {
            if !r.time_shift.is_finite() {
                return Err(format!("references[{k}].time_shift: not finite"));
            }
            if let Some(t) = r.tip_max_m {
                positive(&format!("references[{k}].tip_max_m"), t)?;
            }
        }
        Ok(())
    }

    /// The aerodynamics: the form of `fs`, the flow, the lattice and its stations, the coupling.
    fn check_aero(&self, a: &AeroSettings, fs: &[Formulation]) -> Result<(), String> {
        // The coupled step holds the aerodynamic loads of t_{n+1} over the step; evaluated at
        // the weighted instant t_{n+1-α_f}, they would make the coupling first order.
        for &f in fs {
            if self.block(f).form == FormSetting::ChungHulbert {
                return Err(format!(
                    "{}.form: chung_hulbert is not available with aerodynamics (the loads are those of \
                     the step's end)",
                    key(f)
                ));
            }
        }
        positive("aero.rho", a.rho)?;
        a.surface_plans(&self.problem())?;
        match (a.v_inf, a.airspeed) {
            (None, None) => return Err("aero: give the free stream as `v_inf` or `airspeed`".into()),
            (Some(v), _) if !finite3(&v) || norm3(&v) == 0.0 => {
                return Err("aero.v_inf: not a finite non-zero vector".into());
            }
            (_, Some(u)) => positive("aero.airspeed", u)?,
            _ => {}
        }
        sideslip("aero.sideslip_deg", a.sideslip_deg)?;
        if !a.strip_tip_loss.is_none() && a.model != aeroelastic::aero_settings::AeroModel::Strip {
            return Err("aero.strip_tip_loss: a tip loss of the strips needs aero.model \"strip\" (the lattice has \
                        its own three-dimensional flow)"
                .into());
        }
        if a.n_chordwise == 0 {
            return Err("aero.n_chordwise: must be at least 1".into());
        }
        if a.n_wake_rows == 0 {
            return Err("aero.n_wake_rows: must be at least 1".into());
        }
        non_negative("aero.cutoff_radius", a.cutoff_radius)?;
        if !(a.coupling.relaxation > 0.0 && a.coupling.relaxation <= 1.0) {
            return Err(format!("aero.coupling.relaxation: {} is not in (0, 1]", a.coupling.relaxation));
        }
        positive("aero.coupling.tolerance", a.coupling.tolerance)?;
        aeroelastic::aero::station_map(&self.problem(), a)?;
        // The lattice's own limit on a hinge column's slant, found here rather than at run time.
        for (i, j) in self.joints.iter().enumerate() {
            if let Joint::FlaredHinge { flare_deg, .. } = j
                && flare_deg.abs() >= uvlm::lattice::MAX_HINGE_FLARE_DEG
            {
                return Err(format!(
                    "joints[{i}].flare_deg: {flare_deg} is not below the lattice's limit of ±{}° (aero)",
                    uvlm::lattice::MAX_HINGE_FLARE_DEG
                ));
            }
        }
        Ok(())
    }

    /// A structural static case (no `aero`): dead point loads at increasing load factors.
    fn check_structural_static(&self, st: &StaticSettings) -> Result<(), String> {
        if st.point_loads.is_empty() {
            return Err(
                "static: a case without `aero` needs `static.point_loads` (a static aeroelastic sweep needs `aero`)"
                    .into(),
            );
        }
        if !st.airspeeds.is_empty() {
            return Err("static.airspeeds: a case without `aero` has no airspeeds".into());
        }
        if st.point_loads.len() > MAX_LIST {
            return Err(format!("static.point_loads: {} loads, more than {}", st.point_loads.len(), MAX_LIST));
        }
        for (k, l) in st.point_loads.iter().enumerate() {
            let Some(b) = self.bodies.iter().find(|b| b.name == l.body) else {
                return Err(format!("static.point_loads[{k}].body: no body named `{}`", clip(&l.body)));
            };
            if let Some(at) = l.at
                && !(at.is_finite() && (0.0..=b.length).contains(&at))
            {
                return Err(format!(
                    "static.point_loads[{k}].at: {at} is not in [0, {}] (the body's length)",
                    b.length
                ));
            }
            for (what, v) in [("force", l.force), ("moment", l.moment)] {
                if let Some(i) = v.iter().position(|x| !(x.is_finite() && x.abs() <= 1e12)) {
                    return Err(format!(
                        "static.point_loads[{k}].{what}[{i}]: {} is not a finite value of at most 1e12",
                        v[i]
                    ));
                }
            }
        }
        check_load_factors(&st.load_factors)?;
        if !st.references.is_empty() {
            return Err("static.references: coast-angle curves need `aero`".into());
        }
        if st.wake.is_some() {
            return Err("static.wake: the steady wake needs `aero`".into());
        }
        Ok(())
    }

    /// The gate's tolerances and windows.
    fn check_gate(&self) -> Result<(), String> {
        let Some(g) = &self.gate else { return Ok(()) };
        positive("gate.energy_drift", g.energy_drift)?;
        positive("gate.constraint_residual", g.constraint_residual)?;
        for (k, w) in g.windows.iter().enumerate() {
            if !(w.t_start.is_finite() && w.t_end.is_finite() && w.t_end > w.t_start) {
                return Err(format!("gate.windows[{k}]: t_end must exceed t_start"));
            }
            positive(&format!("gate.windows[{k}].tip_max_m"), w.tip_max_m)?;
            positive(&format!("gate.windows[{k}].tip_rms_m"), w.tip_rms_m)?;
        }
        Ok(())
    }
}

/// The lattice's sizes and the coupling's sub-iterations, capped.
fn check_aero_caps(a: &AeroSettings) -> Result<(), String> {
    let caps = [
        ("aero.n_chordwise", a.n_chordwise, MAX_CHORDWISE),
        ("aero.n_wake_rows", a.n_wake_rows, MAX_WAKE_ROWS),
        ("aero.coupling.max_sub_iterations", a.coupling.max_sub_iterations, MAX_SUB_ITERATIONS),
    ];
    for (field, v, cap) in caps {
        if v > cap {
            return Err(format!("{field}: {v} is more than the limit of {cap}"));
        }
    }
    let panels = |field: &str, list: &[usize]| match list.iter().position(|&p| p > MAX_PANELS_PER_BODY) {
        Some(i) => Err(format!("{field}[{i}]: {} is more than the limit of {MAX_PANELS_PER_BODY}", list[i])),
        None => Ok(()),
    };
    panels("aero.panels_per_body", &a.panels_per_body)?;
    for (k, s) in a.surfaces.iter().enumerate() {
        panels(&format!("aero.surfaces[{k}].panels_per_body"), &s.panels_per_body)?;
        if let Some(n) = s.n_chordwise.filter(|&n| n > MAX_CHORDWISE) {
            return Err(format!("aero.surfaces[{k}].n_chordwise: {n} is more than the limit of {MAX_CHORDWISE}"));
        }
    }
    Ok(())
}

/// A structural static case's load factors: 1 to [`MAX_STATIC_POINTS`], each in (0, 1000],
/// increasing.
fn check_load_factors(factors: &[f64]) -> Result<(), String> {
    if factors.is_empty() {
        return Err("static.load_factors: empty list".into());
    }
    if factors.len() > MAX_STATIC_POINTS {
        return Err(format!("static.load_factors: {} points, more than {MAX_STATIC_POINTS}", factors.len()));
    }
    for (k, &f) in factors.iter().enumerate() {
        if !(f.is_finite() && f > 0.0 && f <= 1e3) {
            return Err(format!("static.load_factors[{k}]: {f} is not in (0, 1000]"));
        }
        if k > 0 && f <= factors[k - 1] {
            return Err(format!("static.load_factors[{k}]: {f} does not increase"));
        }
    }
    Ok(())
}

/// A static aeroelastic sweep (with `aero`): airspeeds, labelled references, the steady wake.
fn check_aero_static(st: &StaticSettings) -> Result<(), String> {
    if !st.point_loads.is_empty() || !st.load_factors.is_empty() {
        return Err("static.point_loads: point loads are for a structural static case (without `aero`)".into());
    }
    if st.airspeeds.is_empty() {
        return Err("static.airspeeds: empty list".into());
    }
    if st.airspeeds.len() > MAX_STATIC_POINTS {
        return Err(format!("static.airspeeds: {} points, more than {MAX_STATIC_POINTS}", st.airspeeds.len()));
    }
    for (k, &u) in st.airspeeds.iter().enumerate() {
        positive(&format!("static.airspeeds[{k}]"), u)?;
    }
    if !st.sideslips_deg.is_empty() {
        if st.airspeeds.len() != 1 {
            return Err(format!(
                "static.airspeeds: a sideslip sweep (static.sideslips_deg) is at one airspeed, not {}",
                st.airspeeds.len()
            ));
        }
        if st.sideslips_deg.len() > MAX_STATIC_POINTS {
            return Err(format!(
                "static.sideslips_deg: {} points, more than {MAX_STATIC_POINTS}",
                st.sideslips_deg.len()
            ));
        }
        for (k, &b) in st.sideslips_deg.iter().enumerate() {
            sideslip(&format!("static.sideslips_deg[{k}]"), b)?;
            if st.sideslips_deg[..k].contains(&b) {
                return Err(format!("static.sideslips_deg[{k}]: {b} is given twice"));
            }
        }
    }
    for (k, r) in st.references.iter().enumerate() {
        if r.label.is_empty() {
            return Err(format!("static.references[{k}].label: empty"));
        }
    }
    if let Some(w) = &st.wake {
        w.validate("static.wake")?;
    }
    Ok(())
}

/// `value` finite, naming `field` otherwise.
fn finite_in(field: &str, value: f64) -> Result<(), String> {
    if value.is_finite() { Ok(()) } else { Err(format!("{field}: {value} is not finite")) }
}
