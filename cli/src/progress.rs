//! The progress bar of long commands and the messages printed around it.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// A progress bar on stderr, hidden when `quiet` or when stderr is not a terminal (a log file
/// or a test would otherwise fill with redraws). Messages go above the bar when it is shown,
/// straight to stderr when it is hidden, and nowhere when `quiet`.
pub struct Progress {
    bar: ProgressBar,
    quiet: bool,
}

impl Progress {
    /// A bar of `len` units drawn with `template` (indicatif's syntax).
    pub fn new(quiet: bool, len: u64, template: &str) -> Self {
        let bar = if quiet || !std::io::stderr().is_terminal() {
            ProgressBar::hidden()
        } else {
            let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(template) {
                b.set_style(style);
            }
            b
        };
        Self { bar, quiet }
    }

    /// The bar itself, to move it.
    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    /// Prints one line of information.
    pub fn message(&self, line: &str) {
        if self.quiet {
            return;
        }
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl rt_experiment::Progress for Progress {
    fn set_length(&self, units: u64) {
        self.bar.set_length(units);
    }

    fn set_position(&self, units: u64) {
        self.bar.set_position(units);
    }

    fn set_message(&self, text: String) {
        self.bar.set_message(text);
    }

    fn message(&self, line: &str) {
        Progress::message(self, line);
    }
}
