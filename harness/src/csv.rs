//! Time-history CSV files: the run output format of docs/outputs.md §2 (its columns and the
//! reference curves are [`casefile::csv`] and [`casefile::curve`], re-exported here), streamed
//! while a run proceeds, and atomic file writes.

use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::time::{Duration, Instant};

use crate::Error;
use crate::run::Row;

pub use casefile::csv::{Columns, HEADER, HEADER_AERO, header, push_row, to_csv};
pub use casefile::curve::{Curve, parse_curve, read_curve};

/// A time-history CSV written while the run proceeds (docs/outputs.md §2): the header at the
/// first row (whose columns decide the header, as [`to_csv`] decides from all rows), then whole
/// rows. Rows wait in memory at most [`STREAM_FLUSH`] (a background thread writes what a slow
/// step leaves waiting) and are written with one call each time, never cut: the file on disk
/// is at every moment a valid CSV of the rows written so far.
#[derive(Debug)]
pub struct CsvStream {
    inner: Arc<Mutex<StreamInner>>,
    columns: Option<Columns>,
    /// The control surfaces' names: a hinge-moment column each (with aerodynamics).
    surfaces: Vec<String>,
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
    /// Create (truncate) the file, for a case with the control surfaces `surfaces` (their names,
    /// in order; empty without).
    pub fn create(path: &Path, surfaces: Vec<String>) -> Result<Self, Error> {
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
        Ok(Self { inner, columns: None, surfaces })
    }

    /// Append a row; written to the file at once if the last write is [`STREAM_FLUSH`] old.
    pub fn push(&mut self, r: &Row) -> Result<(), String> {
        let mut s = self.inner.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let c = *self.columns.get_or_insert_with(|| {
            let c = Columns::of_row(r);
            s.buf.push_str(&header(c, &self.surfaces));
            s.buf.push('\n');
            c
        });
        push_row(&mut s.buf, r, c, self.surfaces.len());
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

/// Write a file, creating its folder, atomically ([`crate::atomic::write`]: a reader sees the
/// old contents or the new, never a part).
pub fn write_file(path: &Path, contents: &str) -> Result<(), Error> {
    crate::atomic::write(path, contents.as_bytes())
}
