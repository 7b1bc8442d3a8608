//! Progress of long work on stderr; silent with `--quiet`.
//!
//! On a terminal an indicatif bar with the elapsed time and an ETA; otherwise (a log file, a
//! pipe) one line at most every [`LOG_EVERY`] with done/total, the elapsed time and the ETA, so
//! that long runs are visible in logs too.

use chatter_progress::Observer;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Least time between two progress lines when stderr is not a terminal.
pub const LOG_EVERY: Duration = Duration::from_secs(5);

/// A progress report (hidden when quiet) that implements the library observers.
pub struct Bar {
    bar: ProgressBar,
    /// Lines for logs: the last time one was written; None on a terminal or when quiet.
    log: Option<Mutex<Instant>>,
    message: String,
}

impl Bar {
    /// A report of `total` steps with a message.
    pub fn new(total: u64, message: &str, quiet: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let bar = if quiet || !terminal {
            // a hidden bar still keeps the position and the rate for the log lines
            let b = ProgressBar::hidden();
            b.set_length(total);
            b
        } else {
            ProgressBar::new(total)
        };
        if let Ok(style) =
            ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {elapsed} (ETA {eta})")
        {
            bar.set_style(style);
        }
        bar.set_message(message.to_string());
        Self {
            bar,
            log: (!quiet && !terminal).then(|| Mutex::new(Instant::now())),
            message: message.to_string(),
        }
    }

    /// A first line for logs with the size of the work (`what`, e.g. "2 s at 20000 Hz"), so
    /// that a log shows the work has started before the first [`LOG_EVERY`] has passed; nothing
    /// on a terminal (the bar shows it) or when quiet.
    pub fn announce(&self, what: &str) {
        if self.log.is_some() {
            eprintln!("{}: started, {what}", self.message);
        }
    }

    /// Set the position.
    pub fn set(&self, done: usize) {
        self.bar.set_position(done as u64);
        self.log_line("");
    }

    /// Progress inside the current step (e.g. a sampler's stage), shown beside the message.
    pub fn detail(&self, text: &str) {
        self.bar.set_message(format!("{} ({text})", self.message));
        self.log_line(&format!(" ({text})"));
    }

    /// A line for logs, at most every [`LOG_EVERY`], when stderr is not a terminal.
    fn log_line(&self, detail: &str) {
        let Some(log) = &self.log else { return };
        let Ok(mut last) = log.lock() else { return };
        if last.elapsed() >= LOG_EVERY {
            *last = Instant::now();
            eprintln!(
                "{}: {}/{}{detail}, {:.0} s elapsed, about {:.0} s left",
                self.message,
                self.bar.position(),
                self.bar.length().unwrap_or(0),
                self.bar.elapsed().as_secs_f64(),
                self.bar.eta().as_secs_f64()
            );
        }
    }

    /// Finish and clear.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Steps (speeds, paths) set the position; a fraction sets it in thousandths (a bar of 1000).
impl Observer for Bar {
    fn steps_done(&self, done: usize, _total: usize) {
        self.set(done);
    }

    fn fraction_done(&self, fraction: f64) {
        self.set((fraction * 1000.0) as usize);
    }
}

/// One long computation without steps to count (e.g. the dominant multiplier of a large
/// operator): a spinner with the elapsed time on a terminal; for logs, a line when it starts
/// with the size of the work and a line when it ends; nothing when quiet.
pub struct Working {
    spinner: Option<ProgressBar>,
    log: bool,
    message: String,
    start: Instant,
}

impl Working {
    /// Start: `message` says what runs and how big it is.
    pub fn start(message: &str, quiet: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let spinner = (!quiet && terminal).then(|| {
            let s = ProgressBar::new_spinner();
            if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
                s.set_style(style);
            }
            s.set_message(message.to_string());
            s.enable_steady_tick(Duration::from_millis(200));
            s
        });
        let log = !quiet && !terminal;
        if log {
            eprintln!("{message}: started");
        }
        Self {
            spinner,
            log,
            message: message.to_string(),
            start: Instant::now(),
        }
    }

    /// Finish: clear the spinner, or a line with the time taken for logs.
    pub fn finish(self) {
        if let Some(s) = &self.spinner {
            s.finish_and_clear();
        }
        if self.log {
            eprintln!(
                "{}: done in {:.1} s",
                self.message,
                self.start.elapsed().as_secs_f64()
            );
        }
    }
}
