//! Output files that appear whole or not at all, and output folders that one run owns at a time.
//!
//! * [`write()`]: the contents go to a temporary file beside the target, which is then renamed over
//!   it, so a reader (or a run killed mid-write) sees the old file or the new one, never a part.
//! * [`claim_dir`]: an exclusive lock on `<dir>/.lock` (`flock`, released by the kernel when the
//!   process ends, however it ends). A second run into the same folder waits for the first,
//!   polling so that a signal ends the wait; the same process claiming a folder twice is an
//!   error, never a wait on itself.
//!   While the lock is held the run clears the files an earlier run left ([`clear_outputs`]).

use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use crate::Error;

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Write `contents` to `path` atomically (temporary file in the same folder, then rename),
/// creating the folder.
pub fn write(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp-{}-{}", std::process::id(), COUNTER.fetch_add(1, Ordering::Relaxed)));
    let done = std::fs::write(&tmp, contents).and_then(|()| std::fs::rename(&tmp, path));
    done.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::Io(format!("{}: {e}", path.display()))
    })
}

/// A temporary file beside a target, for a writer that creates its file itself (such as an
/// SVG backend, which also writes on drop): [`commit`](Self::commit) renames it over the target;
/// dropped without that, the temporary file is removed. Declare it before the writer, so that
/// the writer (dropped first) cannot leave its file behind on an early return.
#[derive(Debug)]
pub struct TempFile {
    tmp: PathBuf,
    target: PathBuf,
    done: bool,
}

impl TempFile {
    /// A temporary path beside `target` (its folder created); nothing is written yet.
    pub fn new(target: &Path) -> Result<Self, Error> {
        let dir = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let tmp = dir.join(format!(".{name}.tmp-{}-{}", std::process::id(), COUNTER.fetch_add(1, Ordering::Relaxed)));
        Ok(Self { tmp, target: target.to_path_buf(), done: false })
    }

    /// The temporary path to write.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// Rename the finished temporary file over the target.
    pub fn commit(mut self) -> Result<(), Error> {
        self.done = true;
        std::fs::rename(&self.tmp, &self.target).map_err(|e| {
            let _ = std::fs::remove_file(&self.tmp);
            Error::Io(format!("{}: {e}", self.target.display()))
        })
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// An output folder held by this process until dropped.
#[derive(Debug)]
pub struct DirLock {
    /// The folder.
    pub dir: PathBuf,
    /// The folder's key in [`HELD`].
    key: PathBuf,
    _file: File,
}

/// The folders this process holds: `flock` locks belong to an open file, so a second claim of
/// a folder by the same process would wait on itself for ever. It is refused instead.
static HELD: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// How often a lock wait looks at the lock and at the signal flag.
const POLL: Duration = Duration::from_millis(50);

fn held() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    HELD.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Take the exclusive lock of `dir` (created if missing), waiting while another process holds
/// it. The wait polls the lock and the signal flag ([`crate::signal::interrupted`]): a SIGTERM
/// or Ctrl-C ends it with an error. A folder this process already holds is an error at once
/// (two runs of one command with the same name), never a wait.
pub fn claim_dir(dir: &Path) -> Result<DirLock, Error> {
    let io = |e: std::io::Error| Error::Io(format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(io)?;
    let key = std::fs::canonicalize(dir).map_err(io)?;
    {
        let mut h = held();
        if h.contains(&key) {
            return Err(Error::Io(format!(
                "{}: this command already writes into this folder (two of its runs have the same name)",
                dir.display()
            )));
        }
        h.push(key.clone());
    }
    let locked = OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(dir.join(".lock"))
        .and_then(|file| lock(&file, dir).map(|()| file));
    match locked {
        Ok(file) => Ok(DirLock { dir: dir.to_path_buf(), key, _file: file }),
        Err(e) => {
            held().retain(|k| k != &key);
            Err(io(e))
        }
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        held().retain(|k| k != &self.key);
    }
}

#[cfg(target_os = "linux")]
fn lock(file: &File, dir: &Path) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    let fd = file.as_raw_fd();
    let mut announced = false;
    loop {
        // SAFETY: flock on a file descriptor this function borrows; no memory is shared.
        if unsafe { libc::flock(fd, libc::LOCK_EX | libc::LOCK_NB) } == 0 {
            return Ok(());
        }
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::WouldBlock && e.kind() != std::io::ErrorKind::Interrupted {
            return Err(e);
        }
        if crate::signal::interrupted() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "interrupted while waiting for another run writing this folder",
            ));
        }
        if !announced {
            eprintln!("waiting for another run writing {}", dir.display());
            announced = true;
        }
        std::thread::sleep(POLL);
    }
}

#[cfg(not(target_os = "linux"))]
fn lock(_file: &File, _dir: &Path) -> std::io::Result<()> {
    Ok(())
}

/// The prefixes of the files the analysis commands (`static`, `stability`, `gust` and `trim`)
/// write into a case's folder beside its runs' files: a run does not remove them.
const ANALYSIS_PREFIXES: [&str; 4] = ["static_", "stability_", "gust_", "trim_"];

/// Remove what a run writes into its folder (CSV, JSON, SVG, Markdown, HTML, leftover temporary
/// files, the `vtk/` folder), so that no file of an earlier run stays beside the new run's.
/// Call it holding the folder's [`DirLock`]; the files named in `keep` stay.
pub fn clear_outputs(lock: &DirLock, keep: &[&str]) -> Result<(), Error> {
    let dir = &lock.dir;
    let io = |e: std::io::Error| Error::Io(format!("{}: {e}", dir.display()));
    for e in std::fs::read_dir(dir).map_err(io)? {
        let Ok(e) = e else { continue };
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        let is_dir = e.file_type().map(|t| t.is_dir()).unwrap_or(false);
        // The analyses' files belong to other commands writing into the folder.
        if keep.contains(&name.as_str()) || ANALYSIS_PREFIXES.iter().any(|a| name.starts_with(a)) {
            continue;
        }
        if is_dir && name == "vtk" {
            std::fs::remove_dir_all(&p).map_err(io)?;
        } else if !is_dir {
            let ours = [".csv", ".json", ".svg", ".md", ".html"].iter().any(|x| name.ends_with(x))
                || (name.starts_with('.') && name.contains(".tmp-"));
            if ours {
                std::fs::remove_file(&p).map_err(io)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_replaces_whole_and_leaves_no_temporary() {
        let d = std::env::temp_dir().join(format!("harness-atomic-{}", std::process::id()));
        let p = d.join("a.json");
        write(&p, b"old").unwrap();
        write(&p, b"new").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 1, "{names:?}");
        let analyses = ["static_ancf.csv", "stability_gebf.json", "gust_history_ancf.csv", "trim_gebf.json"];
        for a in analyses {
            write(&d.join(a), b"an analysis").unwrap();
        }
        let lock = claim_dir(&d).unwrap();
        clear_outputs(&lock, &[]).unwrap();
        assert!(!p.exists());
        assert!(d.join(".lock").exists());
        for a in analyses {
            assert!(d.join(a).exists(), "{a}: an analysis' file removed by a run");
        }
        let _ = std::fs::remove_dir_all(&d);
    }

    /// Issue 38: a sweep whose points had one name claimed its folder twice and waited for
    /// ever on its own lock. The second claim is an error at once; after the first is dropped
    /// the folder can be claimed again.
    #[test]
    fn a_second_claim_by_the_same_process_fails_at_once_issue_38() {
        let d = std::env::temp_dir().join(format!("harness-atomic-twice-{}", std::process::id()));
        let first = claim_dir(&d).unwrap();
        let e = claim_dir(&d).unwrap_err().to_string();
        assert!(e.contains("same name"), "{e}");
        drop(first);
        let again = claim_dir(&d).unwrap();
        drop(again);
        let _ = std::fs::remove_dir_all(&d);
    }
}
