//! How a sweep reports progress: an `indicatif` bar on a terminal, plain log
//! lines otherwise, nothing with `--quiet`. Owns only stderr output.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// The progress reporter of one sweep.
pub enum Progress {
    /// Nothing at all.
    Quiet,
    /// One line per event on stderr.
    Log {
        /// Cases in the sweep.
        total: usize,
    },
    /// A live bar.
    Bar(ProgressBar),
}

impl Progress {
    /// Choose by `quiet` and whether stderr is a terminal.
    pub fn new(quiet: bool, total: usize, already: usize) -> Self {
        if quiet {
            Progress::Quiet
        } else if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(total as u64);
            bar.set_style(
                ProgressStyle::with_template(
                    "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} cases, ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar.set_position(already as u64);
            Progress::Bar(bar)
        } else {
            Progress::Log { total }
        }
    }

    /// A case was recorded.
    pub fn case_done(&self, done: usize, line: &str, workers: &str) {
        match self {
            Progress::Quiet => {}
            Progress::Log { total } => eprintln!("[{done}/{total}] {line}"),
            Progress::Bar(b) => {
                b.set_position(done as u64);
                b.set_message(workers.to_string());
            }
        }
    }

    /// Something worth telling (a dead worker, a rejected message).
    pub fn note(&self, line: &str) {
        match self {
            Progress::Quiet => {}
            Progress::Log { .. } => eprintln!("{line}"),
            Progress::Bar(b) => b.println(line),
        }
    }

    /// The sweep is over.
    pub fn finish(&self) {
        if let Progress::Bar(b) = self {
            b.finish_and_clear();
        }
    }
}
