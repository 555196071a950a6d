//! Progress on stderr for long single runs (one composite, a report, a mask): the libraries
//! report stages through `glassdb_io::Progress`, and [`Spinner`] shows the current one with the
//! elapsed time, only when stderr is a terminal. Tests and pipes see nothing.

use std::io::IsTerminal as _;
use std::time::Duration;

use glassdb_io::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// A spinner naming the current stage of `what` (`compose: encode`), or nothing at all when
/// stderr is not a terminal.
pub struct Spinner {
    what: String,
    bar: Option<ProgressBar>,
}

impl Spinner {
    /// A spinner for `what` on a terminal's stderr; hidden otherwise.
    pub fn on_terminal(what: &str) -> Spinner {
        if !std::io::stderr().is_terminal() {
            return Spinner {
                what: what.to_string(),
                bar: None,
            };
        }
        let bar = ProgressBar::new_spinner();
        if let Ok(style) = ProgressStyle::with_template("{spinner} {prefix}{msg} ({elapsed})") {
            bar.set_style(style);
        }
        bar.enable_steady_tick(Duration::from_millis(120));
        Spinner::with_bar(what, bar)
    }

    fn with_bar(what: &str, bar: ProgressBar) -> Spinner {
        bar.set_message(what.to_string());
        Spinner {
            what: what.to_string(),
            bar: Some(bar),
        }
    }

    /// Runs `f` (which prints to stdout) with the spinner out of the way.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some(bar) => bar.suspend(f),
            None => f(),
        }
    }

    /// Removes the spinner (before the command prints its result).
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Drop for Spinner {
    fn drop(&mut self) {
        self.finish();
    }
}

impl Progress for Spinner {
    fn stage(&self, name: &str) {
        if let Some(bar) = &self.bar {
            bar.set_message(format!("{}: {name}", self.what));
        }
    }

    fn step(&self, done: u64, total: u64) {
        if let Some(bar) = &self.bar {
            bar.set_prefix(format!("[{done}/{total}] "));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spinner_names_each_stage_as_it_begins() {
        let spinner = Spinner::with_bar("compose", ProgressBar::hidden());
        let bar = spinner.bar.clone().unwrap();
        assert_eq!(bar.message(), "compose");
        let mut seen = Vec::new();
        for stage in glassdb_compose::FRAME_STAGES {
            spinner.stage(stage);
            seen.push(bar.message());
        }
        assert_eq!(
            seen,
            ["compose: decode", "compose: composite", "compose: encode"]
        );
        spinner.step(2, 5);
        assert_eq!(bar.prefix(), "[2/5] ");
        assert_eq!(spinner.suspend(|| 7), 7);
    }
}
