//! How `mpcontact solve` shows it is working: one live line on stderr with
//! the elapsed time and the solver's phase (load increment k of n, coupling
//! pass, normal or tangential iteration), on a terminal only and never with
//! `--quiet`. Owns only stderr; reads the phase through the solver's tick
//! hook, so no number of the solve changes. `run`'s bar is `run::progress`.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use solver::{Phase, Stage, TickHook};

/// How often the line's text follows the solver: ticks come per iteration
/// (thousands a second on small grids), a person reads a few changes a second.
const REFRESH: Duration = Duration::from_millis(100);

/// The live line of one solve, shown from [`SolveProgress::start`] until it
/// is dropped (which clears it and puts the thread's previous tick hook back).
pub struct SolveProgress {
    bar: ProgressBar,
    previous: Option<TickHook>,
}

impl SolveProgress {
    /// Shows the progress of the solve about to run on this thread, labelled
    /// `case`; `None` (nothing shown) with `quiet` or when stderr is not a
    /// terminal, where a redrawn line would only litter a log.
    pub fn start(quiet: bool, case: &str) -> Option<Self> {
        if quiet || !std::io::stderr().is_terminal() {
            return None;
        }
        let bar = ProgressBar::new_spinner();
        // `wide_msg`: cut at the terminal's width rather than wrapped onto
        // a second line.
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {prefix}: {wide_msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_prefix(case.to_string());
        bar.set_message(describe(&Phase::default()));
        // The spinner and the clock move even while one iteration of a large
        // grid, or a kernel build, takes seconds between ticks.
        bar.enable_steady_tick(REFRESH);
        let shown = bar.clone();
        let mut last: Option<Instant> = None;
        let previous = solver::set_tick_hook(Some(Box::new(move || {
            if last.is_some_and(|t| t.elapsed() < REFRESH) {
                return;
            }
            last = Some(Instant::now());
            shown.set_message(describe(&solver::phase()));
        })));
        Some(SolveProgress { bar, previous })
    }
}

impl Drop for SolveProgress {
    fn drop(&mut self) {
        solver::set_tick_hook(self.previous.take());
        self.bar.finish_and_clear();
    }
}

/// The text of the line for `phase` (after the elapsed time and the case),
/// e.g. `increment 3/80 · pass 2 · tangential iteration 145` (the pass is
/// the coupling loop's). Short enough for 80 columns after the case.
pub fn describe(phase: &Phase) -> String {
    let mut parts = Vec::new();
    if let Some((k, n)) = phase.increment {
        parts.push(format!("increment {k}/{n}"));
    }
    if let Some(k) = phase.pass {
        parts.push(format!("pass {k}"));
    }
    parts.push(match phase.stage {
        Stage::Starting => "starting".to_string(),
        Stage::Kernel => "building the kernel".to_string(),
        Stage::Normal => format!("normal iteration {}", phase.iterations),
        Stage::Tangential => format!("tangential iteration {}", phase.iterations),
    });
    parts.join(" · ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_names_increment_pass_and_iteration_in_that_order() {
        let phase = Phase {
            increment: Some((3, 80)),
            pass: Some(2),
            stage: Stage::Tangential,
            iterations: 145,
        };
        assert_eq!(
            describe(&phase),
            "increment 3/80 · pass 2 · tangential iteration 145"
        );
    }

    #[test]
    fn the_line_leaves_out_what_the_case_does_not_have() {
        let normal = Phase {
            stage: Stage::Normal,
            iterations: 12,
            ..Phase::default()
        };
        assert_eq!(describe(&normal), "normal iteration 12");
        let kernel = Phase {
            stage: Stage::Kernel,
            ..Phase::default()
        };
        assert_eq!(describe(&kernel), "building the kernel");
        assert_eq!(describe(&Phase::default()), "starting");
    }
}
