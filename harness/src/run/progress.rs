//! Progress for long runs (book: cli.md): a bar with ETA when stderr is a terminal; otherwise nothing,
//! unless `--progress` asks for plain lines (so that in a log or a pipe an error is the only line
//! on stderr).

use crate::run::runner::Observer;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;

/// The CLI's observer.
pub struct Progress {
    bar: Mutex<Option<ProgressBar>>,
    terminal: bool,
    lines: bool,
}

impl Progress {
    /// A progress reporter for stderr: a bar on a terminal; plain lines elsewhere only when
    /// `lines` is set (`--progress`).
    pub fn new(lines: bool) -> Self {
        Progress { bar: Mutex::new(None), terminal: std::io::stderr().is_terminal(), lines }
    }
    /// Clears the bar at the end of an experiment.
    pub fn finish(&self) {
        if let Ok(mut b) = self.bar.lock() {
            if let Some(bar) = b.take() {
                bar.finish_and_clear();
            }
        }
    }
}

impl Default for Progress {
    fn default() -> Self {
        Self::new(false)
    }
}

impl Observer for Progress {
    fn cell_done(&self, done: usize, total: usize, label: &str, resumed: bool) {
        let tag = if resumed { " (resumed)" } else { "" };
        if !self.terminal {
            if self.lines {
                eprintln!("[{done}/{total}] {label}{tag}");
            }
            return;
        }
        let Ok(mut slot) = self.bar.lock() else { return };
        let bar = slot.get_or_insert_with(|| {
            let b = ProgressBar::new(total as u64);
            if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} cells, ETA {eta} {msg}") {
                b.set_style(style);
            }
            b
        });
        bar.set_position(done as u64);
        bar.set_message(format!("{label}{tag}"));
    }
}
