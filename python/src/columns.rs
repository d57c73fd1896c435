//! Rows as NumPy columns named as in the CLI's CSV files, and back.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use aeroelastic::run::Row;
use aeroelastic::stability::StabilityOutput;
use aeroelastic::statics::StaticOutput;

/// One column of the time-history CSV: its name and how to read it from a row.
type Getter = fn(&Row) -> f64;

/// How to write a column's value into a row.
type Setter = fn(&mut Row, f64);

/// Every column a row can have, by its CSV name.
const COLUMNS: [(&str, Getter); 20] = [
    ("t", |r| r.t),
    ("tip_x", |r| r.tip[0]),
    ("tip_y", |r| r.tip[1]),
    ("tip_z", |r| r.tip[2]),
    ("fold", |r| r.fold),
    ("roll_rate", |r| r.roll_rate),
    ("kinetic", |r| r.kinetic),
    ("elastic", |r| r.elastic),
    ("potential", |r| r.potential),
    ("spring", |r| r.spring),
    ("dissipated", |r| r.dissipated),
    ("total", |r| r.total),
    ("thrust_work", |r| r.thrust_work),
    ("aero_work", |r| r.aero_work),
    ("constraint_residual", |r| r.constraint_residual),
    ("newton_iterations", |r| r.newton_iterations as f64),
    ("lift", |r| r.lift),
    ("root_bending_moment", |r| r.root_bending_moment),
    ("root_torque", |r| r.root_torque),
    ("hinge_moment", |r| r.hinge_moment),
];

/// The CSV column names of these rows (`casefile::csv::header`: aerodynamic columns when the run
/// has them, `spring` and `dissipated` when the model has force elements or hinge events,
/// `thrust_work` when it has thrusts,
/// `roll_rate` with a roll joint, the control surfaces' `<name>_hinge_moment` last).
fn header(rows: &[Row], surfaces: &[String]) -> Vec<String> {
    casefile::csv::header(casefile::csv::Columns::of(rows), surfaces).split(',').map(str::to_string).collect()
}

/// The rows as a dict of NumPy arrays keyed by the CSV's column names (`newton_iterations` as
/// int64, the others float64, each value the row's `f64` unrounded), with the hinge moments of
/// the control surfaces `surfaces` (their names).
pub fn run_columns<'py>(py: Python<'py>, rows: &[Row], surfaces: &[String]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for name in header(rows, &[]) {
        let (_, get) = COLUMNS.iter().find(|(n, _)| *n == name).expect("every CSV column has a getter");
        if name == "newton_iterations" {
            let v: Vec<i64> = rows.iter().map(|r| r.newton_iterations as i64).collect();
            d.set_item(name, PyArray1::from_vec(py, v))?;
        } else {
            let v: Vec<f64> = rows.iter().map(get).collect();
            d.set_item(name, PyArray1::from_vec(py, v))?;
        }
    }
    let aero = rows.iter().any(|r| r.aero_work.is_finite());
    for (i, name) in surfaces.iter().enumerate().filter(|_| aero) {
        let v: Vec<f64> = rows.iter().map(|r| r.control_hinge_moments[i]).collect();
        d.set_item(format!("{name}_hinge_moment"), PyArray1::from_vec(py, v))?;
    }
    Ok(d)
}

/// A column of a dict as `f64`s (integer arrays converted).
fn column(d: &Bound<'_, PyDict>, name: &str) -> PyResult<Option<Vec<f64>>> {
    let Some(v) = d.get_item(name)? else { return Ok(None) };
    if let Ok(a) = v.extract::<PyReadonlyArray1<'_, f64>>() {
        return Ok(Some(a.as_array().to_vec()));
    }
    if let Ok(a) = v.extract::<PyReadonlyArray1<'_, i64>>() {
        return Ok(Some(a.as_array().iter().map(|&x| x as f64).collect()));
    }
    Err(PyValueError::new_err(format!("column `{name}`: not a one-dimensional float64 or int64 array")))
}

/// Rows from a dict of columns (the inverse of [`run_columns`]; absent columns are NaN).
pub fn rows_of(d: &Bound<'_, PyDict>) -> PyResult<Vec<Row>> {
    let t = column(d, "t")?.ok_or_else(|| PyKeyError::new_err("t"))?;
    let n = t.len();
    let nan = Row {
        t: f64::NAN,
        tip: [f64::NAN; 3],
        fold: f64::NAN,
        roll_rate: f64::NAN,
        kinetic: f64::NAN,
        elastic: f64::NAN,
        potential: f64::NAN,
        spring: f64::NAN,
        dissipated: f64::NAN,
        total: f64::NAN,
        thrust_work: f64::NAN,
        constraint_residual: f64::NAN,
        newton_iterations: 0,
        aero_work: f64::NAN,
        lift: f64::NAN,
        root_bending_moment: f64::NAN,
        root_torque: f64::NAN,
        hinge_moment: f64::NAN,
        control_hinge_moments: [f64::NAN; aeroelastic::control_surface::MAX_CONTROL_SURFACES],
    };
    let mut rows = vec![nan; n];
    let setters: [(&str, Setter); 20] = [
        ("t", |r, x| r.t = x),
        ("roll_rate", |r, x| r.roll_rate = x),
        ("tip_x", |r, x| r.tip[0] = x),
        ("tip_y", |r, x| r.tip[1] = x),
        ("tip_z", |r, x| r.tip[2] = x),
        ("fold", |r, x| r.fold = x),
        ("kinetic", |r, x| r.kinetic = x),
        ("elastic", |r, x| r.elastic = x),
        ("potential", |r, x| r.potential = x),
        ("spring", |r, x| r.spring = x),
        ("dissipated", |r, x| r.dissipated = x),
        ("total", |r, x| r.total = x),
        ("thrust_work", |r, x| r.thrust_work = x),
        ("aero_work", |r, x| r.aero_work = x),
        ("constraint_residual", |r, x| r.constraint_residual = x),
        ("newton_iterations", |r, x| r.newton_iterations = x as usize),
        ("lift", |r, x| r.lift = x),
        ("root_bending_moment", |r, x| r.root_bending_moment = x),
        ("root_torque", |r, x| r.root_torque = x),
        ("hinge_moment", |r, x| r.hinge_moment = x),
    ];
    for (name, set) in setters {
        if let Some(v) = column(d, name)? {
            if v.len() != n {
                return Err(PyValueError::new_err(format!("column `{name}` has {} values, `t` has {n}", v.len())));
            }
            for (r, x) in rows.iter_mut().zip(v) {
                set(r, x);
            }
        }
    }
    for (i, name) in surface_names(d)?.iter().enumerate() {
        let key = format!("{name}_hinge_moment");
        let v = column(d, &key)?.unwrap_or_default();
        if v.len() != n {
            return Err(PyValueError::new_err(format!("column `{key}` has {} values, `t` has {n}", v.len())));
        }
        for (r, x) in rows.iter_mut().zip(v) {
            r.control_hinge_moments[i] = x;
        }
    }
    Ok(rows)
}

/// The control surfaces of a dict of columns: the `<name>_hinge_moment` keys in order (at most
/// [`MAX_CONTROL_SURFACES`](aeroelastic::control_surface::MAX_CONTROL_SURFACES)).
pub fn surface_names(d: &Bound<'_, PyDict>) -> PyResult<Vec<String>> {
    let mut names = Vec::new();
    for k in d.keys() {
        let k: String = k.extract()?;
        if let Some(name) = k.strip_suffix("_hinge_moment").filter(|n| !n.is_empty()) {
            names.push(name.to_string());
        }
    }
    if names.len() > aeroelastic::control_surface::MAX_CONTROL_SURFACES {
        return Err(PyValueError::new_err(format!(
            "{} control-surface hinge-moment columns, at most {}",
            names.len(),
            aeroelastic::control_surface::MAX_CONTROL_SURFACES
        )));
    }
    Ok(names)
}

/// A static sweep as a dict of arrays keyed by the columns of `static_<f>.csv`
/// (`casefile::csv::static_header`; `newton_iterations` int64, `converged` bool; the control
/// surfaces' `<name>_hinge_moment` for `surfaces`, their names).
pub fn static_columns<'py>(py: Python<'py>, out: &StaticOutput, surfaces: &[String]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let p = &out.points;
    let f = |g: fn(&aeroelastic::statics::StaticPoint) -> f64| PyArray1::from_vec(py, p.iter().map(g).collect());
    d.set_item("airspeed", f(|p| p.airspeed))?;
    d.set_item("fold_deg", f(|p| p.fold_deg))?;
    d.set_item("tip_x", f(|p| p.tip[0]))?;
    d.set_item("tip_y", f(|p| p.tip[1]))?;
    d.set_item("tip_z", f(|p| p.tip[2]))?;
    d.set_item("root_bending_moment", f(|p| p.loads.root_bending_moment))?;
    d.set_item("root_torque", f(|p| p.loads.root_torque))?;
    d.set_item("hinge_moment", f(|p| p.loads.hinge_moment))?;
    d.set_item("lift", f(|p| p.lift))?;
    d.set_item("root_force_x", f(|p| p.loads.root_force[0]))?;
    d.set_item("root_force_y", f(|p| p.loads.root_force[1]))?;
    d.set_item("root_force_z", f(|p| p.loads.root_force[2]))?;
    d.set_item("root_moment_x", f(|p| p.loads.root_moment[0]))?;
    d.set_item("root_moment_y", f(|p| p.loads.root_moment[1]))?;
    d.set_item("root_moment_z", f(|p| p.loads.root_moment[2]))?;
    let it: Vec<i64> = p.iter().map(|p| p.newton_iterations as i64).collect();
    d.set_item("newton_iterations", PyArray1::from_vec(py, it))?;
    let ok: Vec<bool> = p.iter().map(|p| p.error.is_none()).collect();
    d.set_item("converged", PyArray1::from_vec(py, ok))?;
    d.set_item("drag", f(|p| p.drag))?;
    d.set_item("sideslip_deg", f(|p| p.sideslip_deg))?;
    d.set_item("profile_drag", f(|p| p.profile_drag))?;
    d.set_item("induced_drag", f(|p| p.drag - p.profile_drag))?;
    for (i, name) in surfaces.iter().enumerate() {
        let v: Vec<f64> = p.iter().map(|p| p.control_hinge_moments.get(i).copied().unwrap_or(f64::NAN)).collect();
        d.set_item(format!("{name}_hinge_moment"), PyArray1::from_vec(py, v))?;
    }
    debug_assert_eq!(d.len(), casefile::csv::static_header(surfaces).split(',').count());
    Ok(d)
}

/// A stability sweep as a dict of arrays keyed by the columns of `stability_<f>.csv` (one entry
/// per airspeed and tracked mode: `airspeed`, `mode`, `real`, `imag`, `frequency_hz`,
/// `frequency_rad_s`, `damping_ratio`, `converged`) plus `summary`: the flutter and divergence
/// speeds (None when not found in the sweep).
pub fn stability_columns<'py>(py: Python<'py>, out: &StabilityOutput) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let rows: Vec<(f64, &aeroelastic::stability::Root)> =
        out.points.iter().flat_map(|p| p.roots.iter().map(move |r| (p.airspeed, r))).collect();
    let f = |g: fn(&(f64, &aeroelastic::stability::Root)) -> f64| PyArray1::from_vec(py, rows.iter().map(g).collect());
    d.set_item("airspeed", f(|x| x.0))?;
    let modes: Vec<i64> = rows.iter().map(|x| x.1.mode as i64).collect();
    d.set_item("mode", PyArray1::from_vec(py, modes))?;
    d.set_item("real", f(|x| x.1.real))?;
    d.set_item("imag", f(|x| x.1.imag))?;
    d.set_item("frequency_hz", f(|x| x.1.frequency_hz()))?;
    d.set_item("frequency_rad_s", f(|x| x.1.imag))?;
    d.set_item("damping_ratio", f(|x| x.1.damping_ratio()))?;
    let ok: Vec<bool> = rows.iter().map(|x| x.1.converged).collect();
    d.set_item("converged", PyArray1::from_vec(py, ok))?;
    let summary = PyDict::new(py);
    summary.set_item("flutter_speed", out.flutter_speed)?;
    summary.set_item("flutter_frequency_rad_s", out.flutter_frequency_rad_s)?;
    summary.set_item("flutter_mode", out.flutter_mode)?;
    summary.set_item("divergence_speed", out.divergence_speed)?;
    if out.points.iter().any(|p| !p.flight_roots.is_empty()) {
        // About a trim: the rigid-body roots, one dict per airspeed and root.
        let modes = PyList::empty(py);
        for p in &out.points {
            for r in &p.flight_roots {
                let m = PyDict::new(py);
                m.set_item("airspeed", p.airspeed)?;
                m.set_item("name", &r.name)?;
                m.set_item("real", r.real)?;
                m.set_item("imag", r.imag)?;
                m.set_item("period_s", r.period_s())?;
                m.set_item("damping_ratio", r.damping_ratio())?;
                m.set_item("symmetric", r.symmetric)?;
                m.set_item("rigid", r.rigid)?;
                modes.append(m)?;
            }
        }
        summary.set_item("flight_modes", modes)?;
    }
    d.set_item("summary", summary)?;
    Ok(d)
}
