//! Typed errors of the UVLM crate.

/// Everything that can go wrong when building a lattice or solving the flow.
///
/// Variants carry the offending indices and values so that a caller (the harness) can name them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UvlmError {
    /// Fewer than two span stations (a lattice needs at least one panel column).
    #[error("a lattice needs at least 2 span stations, got {n_stations}")]
    TooFewStations {
        /// Number of stations given.
        n_stations: usize,
    },
    /// Zero chordwise panels.
    #[error("a lattice needs at least 1 chordwise panel, got {n_chordwise}")]
    TooFewChordwise {
        /// Number of chordwise panels asked for.
        n_chordwise: usize,
    },
    /// A span station carries an impossible value (non-finite entry, chord ≤ 0, frame not a rotation).
    #[error("span station {station}: invalid `{field}` = {value:.6e}")]
    InvalidStation {
        /// Station (grid column) index.
        station: usize,
        /// Name of the offending field.
        field: &'static str,
        /// The value (or the measure of its defect, e.g. ‖RᵀR − I‖).
        value: f64,
    },
    /// The hinge column is not an interior column of the grid.
    #[error("hinge column {column} must be interior (1..{n_columns_minus_one}), it is not")]
    HingeNotInterior {
        /// Requested hinge column.
        column: usize,
        /// Number of grid columns minus one (= number of spanwise panels).
        n_columns_minus_one: usize,
    },
    /// A lattice node is NaN or infinite.
    #[error("lattice node (row {row}, column {column}) is not finite")]
    NonFiniteNode {
        /// Chordwise row.
        row: usize,
        /// Spanwise column.
        column: usize,
    },
    /// Grid columns are not monotone along the span: the spanwise step at (row, column) reverses
    /// direction with respect to the previous one (the columns cross).
    #[error("non-monotone grid columns at row {row}, column {column} (cosine of turn {cos_turn:.3})")]
    NonMonotoneColumns {
        /// Chordwise row.
        row: usize,
        /// Spanwise column where the reversal starts.
        column: usize,
        /// Cosine of the angle between consecutive spanwise steps (≤ 0 means reversal).
        cos_turn: f64,
    },
    /// Grid rows are not monotone along the chord.
    #[error("non-monotone grid rows at row {row}, column {column} (cosine of turn {cos_turn:.3})")]
    NonMonotoneRows {
        /// Chordwise row where the reversal starts.
        row: usize,
        /// Spanwise column.
        column: usize,
        /// Cosine of the angle between consecutive chordwise steps.
        cos_turn: f64,
    },
    /// A panel has (numerically) zero area.
    #[error("degenerate panel (row {row}, column {column}): area {area:.3e} m²")]
    DegeneratePanel {
        /// Chordwise row of the panel.
        row: usize,
        /// Spanwise column of the panel.
        column: usize,
        /// Panel area, m².
        area: f64,
    },
    /// A panel is non-convex, folded over or too skewed (smallest corner angle below the limit).
    #[error(
        "over-skewed panel (row {row}, column {column}): smallest corner angle {min_angle_deg:.3}° < {limit_deg:.3}°"
    )]
    SkewedPanel {
        /// Chordwise row of the panel.
        row: usize,
        /// Spanwise column of the panel.
        column: usize,
        /// Smallest signed corner angle, degrees (negative = non-convex).
        min_angle_deg: f64,
        /// The configured limit, degrees.
        limit_deg: f64,
    },
    /// Adjacent panels fold over each other (their normals point in opposite half-spaces).
    #[error("panels fold over between (row {row}, column {column}) and its neighbour (normal cosine {cos:.3})")]
    FoldedPanels {
        /// Chordwise row.
        row: usize,
        /// Spanwise column.
        column: usize,
        /// Cosine between the two normals.
        cos: f64,
    },
    /// An input slice has the wrong length.
    #[error("`{what}` has length {got}, expected {expected}")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A solver parameter is out of range.
    #[error("invalid parameter `{field}` = {value:.6e}")]
    InvalidParameter {
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// A hinge moment was asked of a grid column that carries no control surface or does not
    /// exist.
    #[error("grid column {column} carries no control surface (the lattice has {n_columns} columns)")]
    NoFlap {
        /// The column asked for.
        column: usize,
        /// Number of grid columns N + 1.
        n_columns: usize,
    },
    /// A station carries a control surface but the lattice has fewer than 2 chordwise panels
    /// (the hinge needs a panel on each side).
    #[error(
        "span station {station} carries a control surface, which needs at least 2 chordwise panels, got {n_chordwise}"
    )]
    FlapTooFewChordwise {
        /// Station (grid column) index.
        station: usize,
        /// Number of chordwise panels of the lattice.
        n_chordwise: usize,
    },
    /// The aerodynamic influence matrix is singular.
    #[error("singular aerodynamic influence matrix (zero pivot in row {pivot})")]
    SingularAic {
        /// Row of the first zero pivot.
        pivot: usize,
    },
    /// The phases of a step were called out of order.
    #[error("`{call}` called out of order: `{expected}` must come first")]
    StepOrder {
        /// The offending call.
        call: &'static str,
        /// The call that must precede it.
        expected: &'static str,
    },
    /// The circulation solution stopped being finite.
    #[error("non-finite circulation at step {step}")]
    NonFiniteSolution {
        /// Step counter when it happened.
        step: usize,
    },
    /// A solver was asked for with no lifting surface.
    #[error("a solver needs at least one lifting surface, got none")]
    NoSurfaces,
    /// A surface index beyond the solver's surfaces.
    #[error("surface {surface} does not exist (the solver has {n_surfaces} surfaces)")]
    UnknownSurface {
        /// The surface asked for.
        surface: usize,
        /// Number of surfaces.
        n_surfaces: usize,
    },
    /// A call that means the only surface (`update_stations`, `set_grid`, `hinge_moment`,
    /// `linearise`) on a solver with several: use its per-surface form (`…_of`).
    #[error("`{call}` needs a solver with one surface, this one has {n_surfaces}: use the per-surface call")]
    SeveralSurfaces {
        /// The offending call.
        call: &'static str,
        /// Number of surfaces.
        n_surfaces: usize,
    },
    /// An error of one surface's lattice or loads, naming the surface.
    #[error("surface {surface}: {source}")]
    InSurface {
        /// The surface.
        surface: usize,
        /// What went wrong on it.
        source: Box<UvlmError>,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, UvlmError>;

impl UvlmError {
    /// This error, naming surface `surface`.
    pub fn in_surface(self, surface: usize) -> Self {
        UvlmError::InSurface { surface, source: Box::new(self) }
    }
}
