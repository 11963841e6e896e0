//! Progress on stderr for long runs: rate, ETA and items done. Shown only when stderr is a
//! terminal, not asked to be quiet, and the run has lasted more than a second; it never
//! touches stdout, so JSON output and exit codes are unchanged.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// A progress bar that appears after one second of work.
pub struct Progress {
    bar: Option<ProgressBar>,
    start: Instant,
    shown: AtomicBool,
}

impl Progress {
    /// A bar over `total` items named `what` (e.g. "tests"); `quiet` or a non-terminal stderr
    /// turns it off.
    pub fn new(total: u64, what: &str, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
            let style = ProgressStyle::with_template(&format!(
                "{{elapsed_precise}} [{{bar:30}}] {{human_pos}}/{{human_len}} {what} {{per_sec}} ETA {{eta}} {{msg}}"
            ))
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            b.set_style(style);
            b
        });
        Progress { bar, start: Instant::now(), shown: AtomicBool::new(false) }
    }
    /// No progress output.
    pub fn off() -> Self {
        Progress { bar: None, start: Instant::now(), shown: AtomicBool::new(false) }
    }
    /// Records `n` more items done.
    pub fn inc(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
            if !self.shown.load(Ordering::Relaxed) && self.start.elapsed() > Duration::from_secs(1) {
                self.shown.store(true, Ordering::Relaxed);
                b.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
    }
    /// Sets the message after the counts (e.g. the current format).
    pub fn message(&self, m: String) {
        if let Some(b) = &self.bar {
            b.set_message(m);
        }
    }
    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}
