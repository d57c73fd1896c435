//! Section loads and their one check, shared by every formulation.

use nalgebra::Vector3;

/// A force and moment on a section (global components), held fixed until the next
/// [`Structure::set_section_loads`](crate::Structure::set_section_loads).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionLoad {
    /// Body index.
    pub body: usize,
    /// Arclength of the section along the body, m.
    pub s: f64,
    /// Force, N.
    pub force: Vector3<f64>,
    /// Moment, N·m.
    pub moment: Vector3<f64>,
}

/// Why a list of section loads was refused. `station` is the load's index in the list (the span
/// station of the aerodynamic coupling). On this error the model keeps its previous loads.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoadError {
    /// A component of the force, the moment or the arclength is NaN or infinite.
    #[error("section load at station {station} (body {body}, s = {s} m): {field} is {value}")]
    NonFinite {
        /// Index of the load in the list.
        station: usize,
        /// Body index.
        body: usize,
        /// Arclength, m.
        s: f64,
        /// `force[k]`, `moment[k]` or `s`.
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// The body does not exist.
    #[error("section load at station {station}: body {body} does not exist (the model has {n_bodies})")]
    NoSuchBody {
        /// Index of the load in the list.
        station: usize,
        /// Body index.
        body: usize,
        /// Number of bodies.
        n_bodies: usize,
    },
    /// The arclength is outside the body (beyond a relative 1e-12 of its length).
    #[error("section load at station {station} (body {body}): s = {s} m is outside [0, {length}] m")]
    OutOfRange {
        /// Index of the load in the list.
        station: usize,
        /// Body index.
        body: usize,
        /// Arclength, m.
        s: f64,
        /// Length of the body, m.
        length: f64,
    },
    /// The model refused loads the check accepted (a value that overflows once distributed).
    #[error("section loads refused by the model: {0}")]
    Model(String),
}

const FORCE: [&str; 3] = ["force[0]", "force[1]", "force[2]"];
const MOMENT: [&str; 3] = ["moment[0]", "moment[1]", "moment[2]"];

/// Check section loads against bodies of lengths `body_length(b)` (`None`: no body `b`):
/// every value finite, every body present, every arclength within its body (to a relative
/// 1e-12). The first bad load is reported. Does not allocate.
///
/// ```
/// use formulation::{LoadError, SectionLoad, check_section_loads};
/// use nalgebra::Vector3;
/// let lengths = [1.0, 0.5];
/// let len = |b: usize| lengths.get(b).copied();
/// let ok = SectionLoad { body: 1, s: 0.5, force: Vector3::new(0.0, 0.0, 3.0), moment: Vector3::zeros() };
/// assert!(check_section_loads(&[ok], len).is_ok());
/// let nan = SectionLoad { force: Vector3::new(0.0, f64::NAN, 0.0), ..ok };
/// assert!(matches!(
///     check_section_loads(&[ok, nan], len),
///     Err(LoadError::NonFinite { station: 1, field: "force[1]", .. })
/// ));
/// let beyond = SectionLoad { s: 0.6, ..ok };
/// assert!(matches!(check_section_loads(&[beyond], len), Err(LoadError::OutOfRange { station: 0, .. })));
/// ```
pub fn check_section_loads(loads: &[SectionLoad], body_length: impl Fn(usize) -> Option<f64>) -> Result<(), LoadError> {
    for (station, l) in loads.iter().enumerate() {
        let (body, s) = (l.body, l.s);
        let non_finite = |field, value| LoadError::NonFinite { station, body, s, field, value };
        if !s.is_finite() {
            return Err(non_finite("s", s));
        }
        for k in 0..3 {
            if !l.force[k].is_finite() {
                return Err(non_finite(FORCE[k], l.force[k]));
            }
            if !l.moment[k].is_finite() {
                return Err(non_finite(MOMENT[k], l.moment[k]));
            }
        }
        let Some(length) = body_length(body) else {
            let n_bodies = (0..).take_while(|&b| body_length(b).is_some()).count();
            return Err(LoadError::NoSuchBody { station, body, n_bodies });
        };
        if s < -1e-12 * length || s > length * (1.0 + 1e-12) {
            return Err(LoadError::OutOfRange { station, body, s, length });
        }
    }
    Ok(())
}
