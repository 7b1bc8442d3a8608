//! Progress bars on stderr for long work; silent with `--quiet`.

use chatter_stability::boundary::BoundaryObserver;
use indicatif::{ProgressBar, ProgressStyle};

/// An indicatif bar (hidden when quiet) that implements the library observers.
pub struct Bar(ProgressBar);

impl Bar {
    /// A bar of `total` steps with a message.
    pub fn new(total: u64, message: &str, quiet: bool) -> Self {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(total)
        };
        if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {elapsed}") {
            bar.set_style(style);
        }
        bar.set_message(message.to_string());
        Self(bar)
    }
    /// Set the position.
    pub fn set(&self, done: usize) {
        self.0.set_position(done as u64);
    }
    /// Finish and clear.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl BoundaryObserver for Bar {
    fn speed_done(&self, done: usize, _total: usize) {
        self.0.set_position(done as u64);
    }
}

impl chatter_dynamics::simulate::SimulationObserver for Bar {
    fn progress(&self, fraction: f64) {
        self.0.set_position((fraction * 1000.0) as u64);
    }
}
