//! The CSV formats the command line writes and the Python package reproduces: the time-history
//! columns of a run (docs/outputs.md §2) and the header of a static sweep's `static_<f>.csv`.

use std::fmt::Write as _;

use aeroelastic::run::Row;

/// Column header of a formulation's CSV.
pub const HEADER: &str =
    "t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,constraint_residual,newton_iterations";

/// Column header with aerodynamics (`aero_work` after `total`, `lift` and the wing loads at the
/// end).
pub const HEADER_AERO: &str = "t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,aero_work,constraint_residual,\
newton_iterations,lift,root_bending_moment,root_torque,hinge_moment";

/// Which optional column groups a time-history CSV has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Columns {
    /// The aerodynamic columns (`aero_work`, `lift`, the wing loads, the control surfaces').
    pub aero: bool,
    /// `spring` and `dissipated` (force elements or hinge events).
    pub springs: bool,
    /// `roll_rate` (a case with a `roll_joint`).
    pub roll: bool,
    /// `thrust_work` (a case with thrust).
    pub thrust: bool,
}

impl Columns {
    /// The groups a row has values for.
    pub fn of_row(r: &Row) -> Self {
        Self {
            aero: r.aero_work.is_finite(),
            springs: r.spring.is_finite(),
            roll: r.roll_rate.is_finite(),
            thrust: r.thrust_work.is_finite(),
        }
    }

    /// The groups any of `rows` has values for.
    pub fn of(rows: &[Row]) -> Self {
        rows.iter().map(Self::of_row).fold(Self::default(), |a, b| Self {
            aero: a.aero || b.aero,
            springs: a.springs || b.springs,
            roll: a.roll || b.roll,
            thrust: a.thrust || b.thrust,
        })
    }
}

/// The header line (without newline) of a CSV with the column groups `c`: `roll_rate` after
/// `fold`, `spring` and `dissipated` after `potential`, `thrust_work` after `total`, the
/// aerodynamic columns; with
/// aerodynamics, a `<name>_hinge_moment` column per control surface (`surfaces`, the case's
/// `aero.control_surfaces` names in order) at the end.
pub fn header(c: Columns, surfaces: &[String]) -> String {
    let aero = c.aero;
    let header = if aero { HEADER_AERO } else { HEADER };
    let mut h =
        if c.springs { header.replace(",potential,", ",potential,spring,dissipated,") } else { header.to_string() };
    if c.roll {
        h = h.replacen(",fold,", ",fold,roll_rate,", 1);
    }
    if c.thrust {
        h = h.replacen(",total,", ",total,thrust_work,", 1);
    }
    if aero {
        for name in surfaces {
            let _ = write!(h, ",{name}_hinge_moment");
        }
    }
    h
}

/// Append one row (with its newline) in the columns of [`header`]`(c, surfaces)` with
/// `n_surfaces` control surfaces.
pub fn push_row(s: &mut String, r: &Row, c: Columns, n_surfaces: usize) {
    let aero = c.aero;
    let _ = write!(s, "{:.6},{:.9e},{:.9e},{:.9e},{:.9e},", r.t, r.tip[0], r.tip[1], r.tip[2], r.fold);
    if c.roll {
        let _ = write!(s, "{:.9e},", r.roll_rate);
    }
    let _ = write!(s, "{:.9e},{:.9e},{:.9e},", r.kinetic, r.elastic, r.potential);
    if c.springs {
        let _ = write!(s, "{:.9e},{:.9e},", r.spring, r.dissipated);
    }
    let _ = write!(s, "{:.9e},", r.total);
    if c.thrust {
        let _ = write!(s, "{:.9e},", r.thrust_work);
    }
    if aero {
        let _ = write!(s, "{:.9e},", r.aero_work);
    }
    let _ = write!(s, "{:.3e},{}", r.constraint_residual, r.newton_iterations);
    if aero {
        let _ = write!(s, ",{:.6e},{:.6e},{:.6e},{:.6e}", r.lift, r.root_bending_moment, r.root_torque, r.hinge_moment);
        for h in r.control_hinge_moments.iter().take(n_surfaces) {
            let _ = write!(s, ",{h:.6e}");
        }
    }
    s.push('\n');
}

/// Render rows as CSV text: the aerodynamic columns when the run has them, and `spring` (hinge
/// spring potential) and `dissipated` (work of the dampers since t = 0) after `potential` when
/// the model has force elements; the control surfaces' hinge moments (`surfaces`, their names)
/// at the end of the aerodynamic columns.
pub fn to_csv(rows: &[Row], surfaces: &[String]) -> String {
    let c = Columns::of(rows);
    let mut s = String::with_capacity(rows.len() * (220 + 14 * surfaces.len()));
    s.push_str(&header(c, surfaces));
    s.push('\n');
    for r in rows {
        push_row(&mut s, r, c, surfaces.len());
    }
    s
}

/// Column header of `static_<f>.csv`.
pub const STATIC_HEADER: &str = "airspeed,fold_deg,tip_x,tip_y,tip_z,root_bending_moment,root_torque,hinge_moment,lift,\
root_force_x,root_force_y,root_force_z,root_moment_x,root_moment_y,root_moment_z,newton_iterations,converged,drag,\
sideslip_deg,profile_drag,induced_drag";

/// The header of `static_<f>.csv` with a `<name>_hinge_moment` column per control surface after
/// `induced_drag`.
pub fn static_header(surfaces: &[String]) -> String {
    let mut h = STATIC_HEADER.to_string();
    for name in surfaces {
        let _ = write!(h, ",{name}_hinge_moment");
    }
    h
}

/// The control-surface names of a case's aerodynamics (none without `aero`).
pub fn surface_names(aero: Option<&aeroelastic::aero::AeroSettings>) -> Vec<String> {
    aero.map(|a| a.control_surfaces.iter().map(|c| c.name.clone()).collect()).unwrap_or_default()
}

/// The hinge events of a run as CSV (`<formulation>_events.csv`): per event the time it acted
/// (s), the joint's name (`joints`: the case's joint names by index, `joint<k>` for an unnamed
/// one), the action, the fold angle then (degrees) and the kinetic energy a lock removed (J).
pub fn events_csv(events: &[aeroelastic::events::EventRecord], joints: &[Option<String>]) -> String {
    let mut s = String::from("t,joint,action,fold_deg,energy_loss\n");
    for e in events {
        let name = joints.get(e.joint).cloned().flatten().unwrap_or_else(|| format!("joint{}", e.joint));
        let _ =
            writeln!(s, "{:.6},{name},{},{:.9e},{:.9e}", e.time, e.action.as_str(), e.fold.to_degrees(), e.energy_loss);
    }
    s
}
