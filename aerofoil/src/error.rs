//! Typed errors of the aerofoil crate.

use std::path::PathBuf;

/// Everything that can go wrong when reading a polar, evaluating it or correcting a strip.
///
/// File errors name the file, the 1-based line (the header is line 1, comment and blank lines
/// count) and the column as the header spells it, so that a caller can report them as they are.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AerofoilError {
    /// The file could not be read.
    #[error("{}: cannot read the polar file: {message}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The operating system's message.
        message: String,
    },
    /// The file has no header line (it is empty or holds only comments).
    #[error("{}: no header line (expected the columns alpha_deg, cl, cd, cm [, re])", file.display())]
    NoHeader {
        /// The file.
        file: PathBuf,
    },
    /// A required column is missing from the header.
    #[error("{}:{line}: the header has no column `{column}`", file.display())]
    MissingColumn {
        /// The file.
        file: PathBuf,
        /// Line of the header.
        line: usize,
        /// The missing column.
        column: &'static str,
    },
    /// The header names a column that is not known, or names one twice.
    #[error("{}:{line}: header column {index} `{column}` is unknown or repeated", file.display())]
    BadColumn {
        /// The file.
        file: PathBuf,
        /// Line of the header.
        line: usize,
        /// 1-based position of the column in the header.
        index: usize,
        /// The column as written.
        column: String,
    },
    /// A data line has a different number of fields than the header.
    #[error("{}:{line}: {got} fields, the header has {expected}", file.display())]
    FieldCount {
        /// The file.
        file: PathBuf,
        /// Line of the data row.
        line: usize,
        /// Number of header columns.
        expected: usize,
        /// Number of fields on the line.
        got: usize,
    },
    /// A field is not a number.
    #[error("{}:{line}: column `{column}`: `{text}` is not a number", file.display())]
    NotANumber {
        /// The file.
        file: PathBuf,
        /// Line of the data row.
        line: usize,
        /// The column.
        column: &'static str,
        /// The field as written.
        text: String,
    },
    /// A field holds an impossible value: non-finite, a negative drag coefficient, a Reynolds
    /// number that is not positive.
    #[error("{}:{line}: column `{column}`: invalid value {value:e} ({reason})", file.display())]
    InvalidValue {
        /// The file.
        file: PathBuf,
        /// Line of the data row.
        line: usize,
        /// The column.
        column: &'static str,
        /// The value.
        value: f64,
        /// Why it is refused.
        reason: &'static str,
    },
    /// Incidences do not increase strictly within one Reynolds number's table, or the Reynolds
    /// numbers do not increase from one table to the next (tables must be contiguous and
    /// sorted by `re`).
    #[error("{}:{line}: column `{column}`: {value} does not exceed the previous row's {previous}", file.display())]
    Unsorted {
        /// The file.
        file: PathBuf,
        /// Line of the offending row.
        line: usize,
        /// The column (`alpha_deg` or `re`).
        column: &'static str,
        /// The value on this line.
        value: f64,
        /// The value on the previous data line of the same table.
        previous: f64,
    },
    /// A table (one Reynolds number, or the whole file without `re`) has fewer than two rows.
    #[error("{}:{line}: the table at Re = {re:e} has {n_rows} row(s), at least 2 are needed", file.display())]
    TooFewRows {
        /// The file.
        file: PathBuf,
        /// Line of the table's first row (the header's when there are none).
        line: usize,
        /// The table's Reynolds number (NaN when the file has no `re` column).
        re: f64,
        /// Number of rows.
        n_rows: usize,
    },
    /// An incidence outside the polar's range, with no extrapolation allowed.
    #[error("incidence {alpha_deg:.3}° outside the polar's range [{min_deg:.3}°, {max_deg:.3}°]")]
    IncidenceOutOfRange {
        /// The incidence asked for, degrees.
        alpha_deg: f64,
        /// Smallest incidence of the table used, degrees.
        min_deg: f64,
        /// Largest incidence of the table used, degrees.
        max_deg: f64,
    },
    /// A Reynolds number outside the polar's range, with no extrapolation allowed.
    #[error("Reynolds number {re:.4e} outside the polar's range [{min:.4e}, {max:.4e}]")]
    ReynoldsOutOfRange {
        /// The Reynolds number asked for.
        re: f64,
        /// Smallest Reynolds number of the polar.
        min: f64,
        /// Largest Reynolds number of the polar.
        max: f64,
    },
    /// A polar built in code is inconsistent (see [`crate::Polar::new`]).
    #[error("invalid polar: table {table}, {what}")]
    InvalidPolar {
        /// Index of the offending table.
        table: usize,
        /// What is wrong.
        what: &'static str,
    },
    /// A strip's input is impossible (non-finite, chord/width/density/viscosity not positive,
    /// no flow in the section plane).
    #[error("invalid strip input `{field}` = {value:e}")]
    InvalidStrip {
        /// The field of [`crate::Strip`] or [`crate::LatticeSection`].
        field: &'static str,
        /// The value (its norm for a vector).
        value: f64,
    },
    /// A dynamic-stall constant, input or time step is impossible (non-finite, out of range).
    #[error("invalid dynamic-stall input `{field}` = {value:e}")]
    InvalidDynamicStall {
        /// The field of [`crate::DynamicStallConstants`] or [`crate::SectionFlow`], or `dt`.
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// The polar has no zero-lift incidence (its lift does not change sign) at this Reynolds
    /// number, so the dynamic-stall model has no lift line.
    #[error("the polar has no zero-lift incidence at Re = {re:.4e}")]
    NoZeroLift {
        /// The Reynolds number.
        re: f64,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, AerofoilError>;
