//! Progress of runs as they proceed: on a terminal one bar per running run (simulated time,
//! steps per second, time left), elsewhere (a file, a pipe, a CI log) a plain line per run every
//! [`LINE_EVERY`]; and the announcement of each phase of a command.

use std::io::IsTerminal as _;
use std::time::{Duration, Instant};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::case::Formulation;

/// Interval of the plain progress lines when stderr is not a terminal.
pub const LINE_EVERY: Duration = Duration::from_secs(5);

/// Where progress goes.
#[derive(Debug, Clone)]
pub enum Progress {
    /// Nothing.
    Off,
    /// Bars on the terminal.
    Bars(MultiProgress),
    /// Plain lines on stderr.
    Lines,
}

impl Progress {
    /// Bars when stderr is a terminal, plain lines otherwise; [`Progress::Off`] unless `on`.
    pub fn new(on: bool) -> Self {
        if !on {
            Progress::Off
        } else if std::io::stderr().is_terminal() {
            Progress::Bars(MultiProgress::with_draw_target(ProgressDrawTarget::stderr()))
        } else {
            Progress::Lines
        }
    }

    /// The progress of one run from t = 0 to `t_end` in steps of `dt`.
    pub fn run(&self, name: &str, f: Formulation, t_end: f64, dt: f64) -> RunProgress {
        let label = format!("{name} {f}");
        let bar = match self {
            Progress::Bars(m) => {
                let b = m.add(ProgressBar::new(1000));
                if let Ok(style) = ProgressStyle::with_template("{bar:30} {msg}") {
                    b.set_style(style);
                }
                b.set_message(label.clone());
                Some(b)
            }
            _ => None,
        };
        RunProgress {
            label,
            bar,
            lines: matches!(self, Progress::Lines),
            t_end,
            dt,
            start: Instant::now(),
            last: Instant::now(),
        }
    }

    /// A bar counting `len` items of work (ladder rungs, stress cells) labelled `label`, among
    /// the runs' bars; hidden unless there are bars.
    pub fn counter(&self, len: usize, label: &str) -> ProgressBar {
        match self {
            Progress::Bars(m) => {
                let b = m.add(ProgressBar::new(len as u64));
                if let Ok(style) = ProgressStyle::with_template("{bar:30} {msg}: {pos} of {len}") {
                    b.set_style(style);
                }
                b.set_message(label.to_string());
                b
            }
            _ => ProgressBar::hidden(),
        }
    }

    /// Announce a phase of a command (`harness all`: cases, ladders, stress, energy, bench, reports).
    pub fn phase(&self, text: &str) {
        match self {
            Progress::Bars(m) => {
                let _ = m.println(format!("== {text}"));
            }
            _ => eprintln!("== {text}"),
        }
    }

    /// Run `f` (which prints) with the bars hidden, and draw them again after it.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match self {
            Progress::Bars(m) => m.suspend(f),
            _ => f(),
        }
    }
}

/// One run's progress.
#[derive(Debug)]
pub struct RunProgress {
    label: String,
    bar: Option<ProgressBar>,
    lines: bool,
    t_end: f64,
    dt: f64,
    start: Instant,
    last: Instant,
}

impl RunProgress {
    /// The text for simulated time `t`: time, steps per second, estimated time left.
    fn text(&self, t: f64) -> String {
        let wall = self.start.elapsed().as_secs_f64();
        let steps = t / self.dt;
        let rate = if wall > 0.0 { steps / wall } else { 0.0 };
        let left = if t > 0.0 { wall * (self.t_end - t) / t } else { f64::NAN };
        format!(
            "{}: t = {:.4} of {} s, {:.0} steps/s, {} left",
            self.label,
            t,
            self.t_end,
            rate,
            if left.is_finite() { format!("{left:.0} s") } else { "?".into() }
        )
    }

    /// The run reached simulated time `t`.
    pub fn update(&mut self, t: f64) {
        if let Some(b) = &self.bar {
            if self.last.elapsed() >= Duration::from_millis(100) {
                self.last = Instant::now();
                b.set_position((1000.0 * (t / self.t_end).clamp(0.0, 1.0)) as u64);
                b.set_message(self.text(t));
            }
        } else if self.lines && self.last.elapsed() >= LINE_EVERY {
            self.last = Instant::now();
            eprintln!("{}", self.text(t));
        }
    }
}

impl Drop for RunProgress {
    fn drop(&mut self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        } else if self.lines && self.start.elapsed() >= LINE_EVERY {
            eprintln!("{}: finished after {:.1} s", self.label, self.start.elapsed().as_secs_f64());
        }
    }
}

/// A progress line for a long computation without steps of its own (an analysis' sweep): every
/// [`LINE_EVERY`] on stderr, the label, the time so far and the estimate's bound, until dropped.
#[derive(Debug)]
pub struct Heartbeat {
    stop: std::sync::Arc<(std::sync::Mutex<bool>, std::sync::Condvar)>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Heartbeat {
    /// Start the lines for `label`, whose estimate is at most `bound_s` seconds.
    pub fn start(label: String, bound_s: f64) -> Self {
        let stop = std::sync::Arc::new((std::sync::Mutex::new(false), std::sync::Condvar::new()));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            let t0 = Instant::now();
            let (lock, cv) = &*flag;
            let mut done = lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            loop {
                let (d, timeout) = cv.wait_timeout(done, LINE_EVERY).unwrap_or_else(std::sync::PoisonError::into_inner);
                done = d;
                if *done {
                    return;
                }
                if timeout.timed_out() {
                    eprintln!(
                        "{label}: {:.0} s so far (estimated at most {:.0} s)",
                        t0.elapsed().as_secs_f64(),
                        bound_s
                    );
                }
            }
        });
        Self { stop, thread: Some(thread) }
    }
}

impl Drop for Heartbeat {
    fn drop(&mut self) {
        let (lock, cv) = &*self.stop;
        *lock.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = true;
        cv.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
