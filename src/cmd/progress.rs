//! Progress for long commands: an `indicatif` spinner on standard error, hidden
//! with `--quiet` or when standard error is not a terminal.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// A counted sequence of named steps.
pub struct Steps {
    bar: Option<ProgressBar>,
}

impl Steps {
    /// A progress display for about `total` steps.
    pub fn new(total: u64, quiet: bool) -> Steps {
        if quiet || !std::io::stderr().is_terminal() {
            return Steps { bar: None };
        }
        let bar = ProgressBar::new(total);
        if let Ok(style) = ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_msg}")
        {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        Steps { bar: Some(bar) }
    }

    /// Starts the next step.
    pub fn step(&self, msg: &str) {
        if let Some(b) = &self.bar {
            b.inc(1);
            b.set_message(msg.to_string());
        }
    }

    /// Clears the display.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Drop for Steps {
    fn drop(&mut self) {
        self.finish();
    }
}

impl deadreckon_eval::Progress for Steps {
    fn step(&self, what: &str) {
        Steps::step(self, what)
    }
}

/// A bar counting drives (`batch`), hidden with `--quiet` or when standard
/// error is not a terminal.
pub fn drives_bar(total: usize, quiet: bool) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let b = ProgressBar::new(total as u64);
    if let Ok(style) = ProgressStyle::with_template(
        "{bar:30} {pos}/{len} drives [{elapsed_precise}, eta {eta}] {wide_msg}",
    ) {
        b.set_style(style);
    }
    Some(b)
}
