//! What a phase of a command prints: its lines kept in the order written and printed whole when
//! the phase ends, so that phases going side by side (`harness all`) never interleave their lines
//! and never draw over the progress bars.

use std::io::Write as _;

use crate::progress::Progress;

/// The stream a line goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stream {
    Out,
    Err,
}

/// A phase's console lines, stdout and stderr in the order written, until [`Lines::print`].
#[derive(Debug, Default)]
pub struct Lines(Vec<(Stream, String)>);

impl Lines {
    /// No lines yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// A line for stdout (without its newline).
    pub fn out(&mut self, line: impl Into<String>) {
        self.0.push((Stream::Out, line.into()));
    }

    /// A line for stderr (without its newline).
    pub fn err(&mut self, line: impl Into<String>) {
        self.0.push((Stream::Err, line.into()));
    }

    /// Whether no line was kept.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Print the lines kept so far, each to its stream, in one piece (the progress bars hidden
    /// meanwhile, and no other thread's lines between them), and forget them.
    pub fn print(&mut self, progress: &Progress) {
        if self.0.is_empty() {
            return;
        }
        let lines = std::mem::take(&mut self.0);
        progress.suspend(|| {
            // Both locks in this order wherever they are taken together: the lines of two phases
            // cannot interleave. A closed pipe (`| head`) is not worth a panic.
            let (mut out, mut err) = (std::io::stdout().lock(), std::io::stderr().lock());
            for (stream, line) in &lines {
                // stdout is flushed at each newline, stderr is unbuffered: the order across the
                // two streams holds where both go to one terminal or file.
                let _ = match stream {
                    Stream::Out => writeln!(out, "{line}"),
                    Stream::Err => writeln!(err, "{line}"),
                };
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lines keep their order and stream; printing none prints nothing.
    #[test]
    fn lines_keep_order() {
        let mut l = Lines::new();
        assert!(l.is_empty());
        l.out("a");
        l.err("b");
        l.out(String::from("c"));
        assert_eq!(l.0, vec![(Stream::Out, "a".into()), (Stream::Err, "b".into()), (Stream::Out, "c".into())]);
        Lines::new().print(&Progress::Off);
    }
}
