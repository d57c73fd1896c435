//! The polar CSV file: `alpha_deg, cl, cd, cm`, plus `re` when the file holds several Reynolds
//! numbers.
//!
//! * The first line that is neither blank nor a comment (`#` first) is the header: the column
//!   names, comma-separated, in any order, each once; no other column is accepted (a typo fails
//!   loudly).
//! * Every other non-blank, non-comment line is one row: the incidence in degrees, the lift,
//!   profile-drag and quarter-chord moment coefficients (nose up), and the Reynolds number.
//! * With `re`, the rows of one Reynolds number form one table: tables are contiguous and in
//!   increasing Re. Within a table the incidences increase strictly. Every table has at least
//!   two rows; values are finite, `cd ≥ 0`, `re > 0`.
//!
//! Every error names the file, the 1-based line and the column ([`AerofoilError`]).

use crate::error::{AerofoilError, Result};
use crate::polar::{Polar, Table};
use std::path::{Path, PathBuf};

/// The columns, as the header spells them.
const COLUMNS: [&str; 5] = ["alpha_deg", "cl", "cd", "cm", "re"];

/// Read and validate the polar file at `path`.
pub fn read_polar(path: &Path) -> Result<Polar> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| AerofoilError::Io { file: path.to_path_buf(), message: e.to_string() })?;
    parse_polar(&text, path)
}

/// Parse and validate a polar file's text; `file` only names it in errors.
pub fn parse_polar(text: &str, file: &Path) -> Result<Polar> {
    let file_buf = || file.to_path_buf();
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !is_skipped(l));
    let (header_line, header) = lines.next().ok_or_else(|| AerofoilError::NoHeader { file: file_buf() })?;
    let index = column_index(header, header_line, file)?;
    let n_fields = header.split(',').count();
    let has_re = index[4].is_some();
    let mut builder = TableBuilder { file: file_buf(), has_re, tables: Vec::new(), current: None };
    for (line, text) in lines {
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != n_fields {
            return Err(AerofoilError::FieldCount { file: file_buf(), line, expected: n_fields, got: fields.len() });
        }
        let mut row = [0.0; 5];
        for (c, name) in COLUMNS.iter().enumerate() {
            if let Some(k) = index[c] {
                row[c] = number(fields[k], name, line, file)?;
            }
        }
        builder.push(line, row)?;
    }
    // The checks above cover every rule of `Polar::new`, which therefore does not fail here.
    Polar::new(builder.finish(header_line)?)
}

fn is_skipped(line: &str) -> bool {
    line.is_empty() || line.starts_with('#')
}

/// Position of each of [`COLUMNS`] in the header (`re` optional, the others required).
fn column_index(header: &str, line: usize, file: &Path) -> Result<[Option<usize>; 5]> {
    let mut index = [None; 5];
    for (k, name) in header.split(',').map(str::trim).enumerate() {
        let c = COLUMNS.iter().position(|c| *c == name);
        match c {
            Some(c) if index[c].is_none() => index[c] = Some(k),
            _ => {
                return Err(AerofoilError::BadColumn {
                    file: file.to_path_buf(),
                    line,
                    index: k + 1,
                    column: name.to_string(),
                });
            }
        }
    }
    for (c, name) in COLUMNS.iter().enumerate().take(4) {
        if index[c].is_none() {
            return Err(AerofoilError::MissingColumn { file: file.to_path_buf(), line, column: name });
        }
    }
    Ok(index)
}

/// One field as a finite number, with the column's own rule (`cd ≥ 0`, `re > 0`).
fn number(text: &str, column: &'static str, line: usize, file: &Path) -> Result<f64> {
    let value: f64 = text.parse().map_err(|_| AerofoilError::NotANumber {
        file: file.to_path_buf(),
        line,
        column,
        text: text.to_string(),
    })?;
    let invalid = |reason| Err(AerofoilError::InvalidValue { file: file.to_path_buf(), line, column, value, reason });
    if !value.is_finite() {
        return invalid("not finite");
    }
    match column {
        "cd" if value < 0.0 => invalid("negative drag coefficient"),
        "re" if value <= 0.0 => invalid("Reynolds number not positive"),
        _ => Ok(value),
    }
}

/// A table under construction: its first line and rows (`alpha_deg, cl, cd, cm, re`).
struct Pending {
    first_line: usize,
    last_line: usize,
    rows: Vec<[f64; 5]>,
}

struct TableBuilder {
    file: PathBuf,
    has_re: bool,
    tables: Vec<Pending>,
    current: Option<Pending>,
}

impl TableBuilder {
    fn push(&mut self, line: usize, row: [f64; 5]) -> Result<()> {
        if let Some(cur) = &self.current {
            let prev = cur.rows.last().expect("a pending table has a row");
            if self.has_re && row[4] != prev[4] {
                if row[4] < prev[4] {
                    return Err(self.unsorted(line, "re", row[4], prev[4]));
                }
                let done = self.current.take().expect("checked above");
                self.close(done)?;
            } else if row[0] <= prev[0] {
                return Err(self.unsorted(line, "alpha_deg", row[0], prev[0]));
            }
        }
        let cur = self.current.get_or_insert(Pending { first_line: line, last_line: line, rows: Vec::new() });
        cur.rows.push(row);
        cur.last_line = line;
        Ok(())
    }

    fn unsorted(&self, line: usize, column: &'static str, value: f64, previous: f64) -> AerofoilError {
        AerofoilError::Unsorted { file: self.file.clone(), line, column, value, previous }
    }

    fn close(&mut self, t: Pending) -> Result<()> {
        if t.rows.len() < 2 {
            return Err(AerofoilError::TooFewRows {
                file: self.file.clone(),
                line: t.first_line,
                re: if self.has_re { t.rows[0][4] } else { f64::NAN },
                n_rows: t.rows.len(),
            });
        }
        self.tables.push(t);
        Ok(())
    }

    fn finish(mut self, header_line: usize) -> Result<Vec<Table>> {
        let Some(last) = self.current.take() else {
            return Err(AerofoilError::TooFewRows { file: self.file, line: header_line, re: f64::NAN, n_rows: 0 });
        };
        self.close(last)?;
        let has_re = self.has_re;
        Ok(self.tables.into_iter().map(|t| to_table(t, has_re)).collect())
    }
}

fn to_table(t: Pending, has_re: bool) -> Table {
    let col = |c: usize| t.rows.iter().map(|r| r[c]).collect::<Vec<f64>>();
    Table {
        re: has_re.then(|| t.rows[0][4]),
        alpha: t.rows.iter().map(|r| r[0].to_radians()).collect(),
        cl: col(1),
        cd: col(2),
        cm: col(3),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn parse(text: &str) -> Result<Polar> {
        parse_polar(text, Path::new("p.csv"))
    }

    #[test]
    fn reads_a_multi_re_file_with_comments() {
        let text = "# made by hand\nre, alpha_deg, cl, cd, cm\n1e5, -2, -0.2, 0.02, 0.0\n1e5, 2, 0.2, 0.02, 0.0\n\n\
                    2e5,-2,-0.22,0.01,0\n2e5,0,0,0.009,0\n2e5,2,0.22,0.01,0\n";
        let p = parse(text).unwrap();
        assert_eq!(p.re_range(), Some((1e5, 2e5)));
        assert_eq!(p.tables().count(), 2);
        let c = p.coefficients(2f64.to_radians(), 2e5).unwrap();
        assert_relative_eq!(c.cl, 0.22, max_relative = 1e-12);
    }

    #[test]
    fn a_file_with_one_reynolds_number_holds_there_only() {
        let p = parse("re,alpha_deg,cl,cd,cm\n1e5,-5,-0.5,0.01,0\n1e5,5,0.5,0.01,0\n").unwrap();
        assert_eq!(p.re_range(), Some((1e5, 1e5)));
        assert_relative_eq!(
            p.coefficients(0.05, 1e5).unwrap().cl,
            0.5 * 0.05 / 5f64.to_radians(),
            max_relative = 1e-12
        );
        assert!(matches!(p.coefficients(0.05, 2e5), Err(AerofoilError::ReynoldsOutOfRange { .. })));
    }

    #[test]
    fn a_file_without_re_holds_at_every_reynolds_number() {
        let p = parse("alpha_deg,cl,cd,cm\n-5,-0.5,0.01,0\n5,0.5,0.01,0\n").unwrap();
        assert_eq!(p.re_range(), None);
        assert_relative_eq!(p.coefficients(0.0, 1e9).unwrap().cl, 0.0, epsilon = 1e-15);
    }

    #[test]
    fn errors_name_the_file_line_and_column() {
        let cases: [(&str, &str); 9] = [
            ("", "p.csv: no header"),
            ("alpha_deg,cl,cd\n", "p.csv:1: the header has no column `cm`"),
            ("alpha_deg,cl,cd,cm,cl\n", "p.csv:1: header column 5 `cl`"),
            ("alpha_deg,cl,cd,cm\n0,0,0\n", "p.csv:2: 3 fields, the header has 4"),
            ("alpha_deg,cl,cd,cm\n0,0,0,0\n# c\n1,x,0,0\n", "p.csv:4: column `cl`: `x` is not a number"),
            ("alpha_deg,cl,cd,cm\n0,0,-0.1,0\n", "p.csv:2: column `cd`: invalid value"),
            ("alpha_deg,cl,cd,cm\n0,0,0,inf\n", "p.csv:2: column `cm`: invalid value inf (not finite)"),
            ("alpha_deg,cl,cd,cm\n1,0,0,0\n1,0,0,0\n", "p.csv:3: column `alpha_deg`: 1 does not exceed"),
            ("alpha_deg,cl,cd,cm\n1,0,0,0\n", "p.csv:2: the table at Re = NaN has 1 row(s)"),
        ];
        for (text, expected) in cases {
            let msg = parse(text).unwrap_err().to_string();
            assert!(msg.starts_with(expected), "{text:?}: got `{msg}`, expected `{expected}…`");
        }
        let re_unsorted = "re,alpha_deg,cl,cd,cm\n2e5,0,0,0,0\n2e5,1,0,0,0\n1e5,0,0,0,0\n";
        assert!(parse(re_unsorted).unwrap_err().to_string().starts_with("p.csv:4: column `re`"));
        let re_single_row = "re,alpha_deg,cl,cd,cm\n1e5,0,0,0,0\n2e5,0,0,0,0\n2e5,1,0,0,0\n";
        assert!(parse(re_single_row).unwrap_err().to_string().starts_with("p.csv:2: the table at Re = 1e5 has 1"));
        let missing = read_polar(Path::new("/nonexistent/polar.csv")).unwrap_err();
        assert!(missing.to_string().starts_with("/nonexistent/polar.csv: cannot read"));
    }
}
