//! Progress of long work on stderr: indicatif's bar where stderr is a terminal, plain lines
//! (`progress: sweep 42 % after 12 s`) every [`LINE_EVERY`] otherwise (a log file, CI, a pipe;
//! the environment variable `HBAL_PROGRESS_EVERY` sets the interval in seconds), nothing with
//! `--json`.

use std::cell::Cell;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// How often a plain progress line is printed where stderr is not a terminal.
const LINE_EVERY: Duration = Duration::from_secs(10);

/// The progress of one piece of work, as a fraction in `[0, 1]`.
pub(crate) struct Progress {
    bar: Option<indicatif::ProgressBar>,
    /// Plain lines: the work's name and when the last line was printed.
    lines: Option<(String, Cell<Instant>)>,
    every: Duration,
    started: Instant,
}

impl Progress {
    /// Progress of `what` (`"sweep"`), silent if `hidden`.
    pub(crate) fn new(what: &str, hidden: bool) -> Self {
        let now = Instant::now();
        let terminal = std::io::stderr().is_terminal();
        let bar = (!hidden && terminal).then(|| {
            let bar = indicatif::ProgressBar::new(1000);
            bar.set_style(
                indicatif::ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            bar
        });
        Self {
            bar,
            lines: (!hidden && !terminal).then(|| (what.to_string(), Cell::new(now))),
            every: std::env::var("HBAL_PROGRESS_EVERY")
                .ok()
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|s| s.is_finite() && *s >= 0.0)
                .map_or(LINE_EVERY, Duration::from_secs_f64),
            started: now,
        }
    }

    /// The work is `fraction` done.
    pub(crate) fn set(&self, fraction: f64) {
        let f = if fraction.is_finite() {
            fraction.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if let Some(bar) = &self.bar {
            bar.set_position((f * 1000.0) as u64);
        }
        if let Some((what, last)) = &self.lines {
            if last.get().elapsed() >= self.every {
                last.set(Instant::now());
                eprintln!(
                    "progress: {what} {:.0} % after {:.0} s",
                    100.0 * f,
                    self.started.elapsed().as_secs_f64()
                );
            }
        }
    }

    /// What the work does now (the bar's message; a plain line where stderr is no terminal).
    pub(crate) fn message(&self, text: &str) {
        if let Some(bar) = &self.bar {
            bar.set_message(text.to_string());
        }
        if let Some((what, _)) = &self.lines {
            eprintln!("progress: {what}: {text}");
        }
    }

    /// Removes the bar.
    pub(crate) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// The library's progress reports drive the bar.
impl hbal::analysis::Observer for &Progress {
    fn progress(&mut self, fraction: f64) {
        self.set(fraction);
    }

    fn stage(&mut self, what: &str) {
        self.message(what);
    }
}
