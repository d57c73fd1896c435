//! Time-history CSV files: the run output format of docs/outputs.md §2 and reading external references.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::time::{Duration, Instant};

use crate::Error;
use crate::run::Row;

/// Column header of a formulation's CSV.
pub const HEADER: &str =
    "t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,constraint_residual,newton_iterations";

/// Column header with aerodynamics (`aero_work` after `total`, `lift` and the wing loads at the
/// end).
pub const HEADER_AERO: &str = "t,tip_x,tip_y,tip_z,fold,kinetic,elastic,potential,total,aero_work,constraint_residual,\
newton_iterations,lift,root_bending_moment,root_torque,hinge_moment";

/// The header line (without newline) of a CSV with or without the aerodynamic and the force
/// element columns.
pub fn header(aero: bool, springs: bool) -> String {
    let header = if aero { HEADER_AERO } else { HEADER };
    if springs { header.replace(",potential,", ",potential,spring,dissipated,") } else { header.to_string() }
}

/// Append one row (with its newline) in the columns of [`header`]`(aero, springs)`.
pub fn push_row(s: &mut String, r: &Row, aero: bool, springs: bool) {
    let _ = write!(
        s,
        "{:.6},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},",
        r.t, r.tip[0], r.tip[1], r.tip[2], r.fold, r.kinetic, r.elastic, r.potential,
    );
    if springs {
        let _ = write!(s, "{:.9e},{:.9e},", r.spring, r.dissipated);
    }
    let _ = write!(s, "{:.9e},", r.total);
    if aero {
        let _ = write!(s, "{:.9e},", r.aero_work);
    }
    let _ = write!(s, "{:.3e},{}", r.constraint_residual, r.newton_iterations);
    if aero {
        let _ = write!(s, ",{:.6e},{:.6e},{:.6e},{:.6e}", r.lift, r.root_bending_moment, r.root_torque, r.hinge_moment);
    }
    s.push('\n');
}

/// Render rows as CSV text: the aerodynamic columns when the run has them, and `spring` (hinge
/// spring potential) and `dissipated` (work of the dampers since t = 0) after `potential` when
/// the model has force elements.
pub fn to_csv(rows: &[Row]) -> String {
    let aero = rows.iter().any(|r| r.aero_work.is_finite());
    let springs = rows.iter().any(|r| r.spring.is_finite());
    let mut s = String::with_capacity(rows.len() * 220);
    s.push_str(&header(aero, springs));
    s.push('\n');
    for r in rows {
        push_row(&mut s, r, aero, springs);
    }
    s
}

/// A time-history CSV written while the run proceeds (docs/outputs.md §2): the header at the
/// first row (whose columns decide the header, as [`to_csv`] decides from all rows), then whole
/// rows. Rows wait in memory at most [`STREAM_FLUSH`] (a background thread writes what a slow
/// step leaves waiting) and are written with one call each time, never cut: the file on disk
/// is at every moment a valid CSV of the rows written so far.
#[derive(Debug)]
pub struct CsvStream {
    inner: Arc<Mutex<StreamInner>>,
    columns: Option<(bool, bool)>,
}

#[derive(Debug)]
struct StreamInner {
    file: std::fs::File,
    path: std::path::PathBuf,
    buf: String,
    last_flush: Instant,
}

impl StreamInner {
    fn flush(&mut self) -> Result<(), String> {
        use std::io::Write as _;
        self.last_flush = Instant::now();
        if self.buf.is_empty() {
            return Ok(());
        }
        let r = self.file.write_all(self.buf.as_bytes());
        self.buf.clear();
        r.map_err(|e| format!("{}: {e}", self.path.display()))
    }
}

/// Longest time a finished row waits in memory before it is written to the file.
pub const STREAM_FLUSH: Duration = Duration::from_millis(500);

/// Streams with rows that may be waiting; the flusher thread writes them.
static STREAMS: Mutex<Vec<Weak<Mutex<StreamInner>>>> = Mutex::new(Vec::new());
static FLUSHER: OnceLock<()> = OnceLock::new();

fn start_flusher() {
    FLUSHER.get_or_init(|| {
        let spawned = std::thread::Builder::new().name("csv-flush".into()).spawn(|| {
            loop {
                std::thread::sleep(STREAM_FLUSH / 2);
                let mut v = STREAMS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                v.retain(|w| match w.upgrade() {
                    Some(s) => {
                        if let Ok(mut s) = s.try_lock()
                            && s.last_flush.elapsed() >= STREAM_FLUSH / 2
                        {
                            let _ = s.flush();
                        }
                        true
                    }
                    None => false,
                });
            }
        });
        // Without the thread rows are still written at every push after STREAM_FLUSH.
        drop(spawned);
    });
}

impl CsvStream {
    /// Create (truncate) the file.
    pub fn create(path: &Path) -> Result<Self, Error> {
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| Error::Io(format!("{}: {e}", d.display())))?;
        }
        let file = std::fs::File::create(path).map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
        let inner = Arc::new(Mutex::new(StreamInner {
            file,
            path: path.to_path_buf(),
            buf: String::with_capacity(1 << 14),
            last_flush: Instant::now(),
        }));
        start_flusher();
        STREAMS.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(Arc::downgrade(&inner));
        Ok(Self { inner, columns: None })
    }

    /// Append a row; written to the file at once if the last write is [`STREAM_FLUSH`] old.
    pub fn push(&mut self, r: &Row) -> Result<(), String> {
        let mut s = self.inner.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let (aero, springs) = *self.columns.get_or_insert_with(|| {
            let c = (r.aero_work.is_finite(), r.spring.is_finite());
            s.buf.push_str(&header(c.0, c.1));
            s.buf.push('\n');
            c
        });
        push_row(&mut s.buf, r, aero, springs);
        if s.last_flush.elapsed() >= STREAM_FLUSH || s.buf.len() > 1 << 20 {
            s.flush()?;
        }
        Ok(())
    }

    /// Write the buffered rows to the file.
    pub fn flush(&mut self) -> Result<(), String> {
        self.inner.lock().unwrap_or_else(std::sync::PoisonError::into_inner).flush()
    }
}

impl Drop for CsvStream {
    fn drop(&mut self) {
        let _ = self.flush();
    }
}

/// A reference time history: times and tip positions.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Times, s (increasing).
    pub t: Vec<f64>,
    /// Tip positions, m.
    pub tip: Vec<[f64; 3]>,
}

/// Read a CSV with a header naming at least `t, tip_x, tip_y, tip_z`; `#` lines are comments.
pub fn read_curve(path: &Path) -> Result<Curve, Error> {
    let file = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::Reference { file: file.clone(), msg: e.to_string() })?;
    parse_curve(&text).map_err(|msg| Error::Reference { file, msg })
}

/// Parse CSV text (see [`read_curve`]).
pub fn parse_curve(text: &str) -> Result<Curve, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty());
    let (_, header) = lines.next().ok_or("no header line")?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |name: &str| cols.iter().position(|c| *c == name).ok_or(format!("no column `{name}`"));
    let (it, ix, iy, iz) = (col("t")?, col("tip_x")?, col("tip_y")?, col("tip_z")?);
    let mut c = Curve { t: Vec::new(), tip: Vec::new() };
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').collect();
        let get = |i: usize| -> Result<f64, String> {
            f.get(i)
                .ok_or(format!("line {}: too few columns", n + 1))?
                .trim()
                .parse::<f64>()
                .map_err(|e| format!("line {}: {e}", n + 1))
        };
        let t = get(it)?;
        if let Some(&last) = c.t.last()
            && t <= last
        {
            return Err(format!("line {}: time {t} does not increase", n + 1));
        }
        c.t.push(t);
        c.tip.push([get(ix)?, get(iy)?, get(iz)?]);
    }
    if c.t.is_empty() {
        return Err("no data rows".into());
    }
    Ok(c)
}

impl Curve {
    /// Linear interpolation of the tip at time `t`; `None` outside the curve's time range.
    pub fn tip_at(&self, t: f64) -> Option<[f64; 3]> {
        let n = self.t.len();
        if n == 0 || t < self.t[0] - 1e-12 || t > self.t[n - 1] + 1e-12 {
            return None;
        }
        let k = self.t.partition_point(|&x| x < t);
        if k == 0 {
            return Some(self.tip[0]);
        }
        if k >= n {
            return Some(self.tip[n - 1]);
        }
        let (t0, t1) = (self.t[k - 1], self.t[k]);
        let w = (t - t0) / (t1 - t0);
        let (a, b) = (self.tip[k - 1], self.tip[k]);
        Some([a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2])])
    }
}

/// Write a file, creating its folder, atomically ([`crate::atomic::write`]: a reader sees the
/// old contents or the new, never a part).
pub fn write_file(path: &Path, contents: &str) -> Result<(), Error> {
    crate::atomic::write(path, contents.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_interpolates() {
        let c = parse_curve("# meta\nt,tip_x,tip_y,tip_z,extra\n0,1,0,0,9\n1,3,2,-2,9\n").unwrap();
        assert_eq!(c.tip_at(0.5), Some([2.0, 1.0, -1.0]));
        assert_eq!(c.tip_at(1.5), None);
    }

    #[test]
    fn rejects_missing_column_and_bad_number() {
        assert!(parse_curve("t,tip_x,tip_y\n0,1,2\n").unwrap_err().contains("tip_z"));
        assert!(parse_curve("t,tip_x,tip_y,tip_z\n0,1,x,2\n").unwrap_err().contains("line 2"));
    }
}
