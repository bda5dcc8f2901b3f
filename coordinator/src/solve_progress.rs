//! How `mpcontact solve` shows it is working: one live line on stderr with
//! the elapsed time and the solver's phase (load-path segment k of n and the
//! path's time left, coupling pass, normal or tangential iteration), on a
//! terminal only and never with
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
        bar.set_message(describe(&Phase::default(), None));
        // The spinner and the clock move even while one iteration of a large
        // grid, or a kernel build, takes seconds between ticks.
        bar.enable_steady_tick(REFRESH);
        let shown = bar.clone();
        let mut last: Option<Instant> = None;
        // A load path's first segment seen and when: the rate since then
        // gives the time left (a long wear run's hundreds of segments cost
        // about the same each).
        let mut first: Option<(usize, Instant)> = None;
        let previous = solver::set_tick_hook(Some(Box::new(move || {
            if last.is_some_and(|t| t.elapsed() < REFRESH) {
                return;
            }
            last = Some(Instant::now());
            let phase = solver::phase();
            let left = phase.segment.and_then(|(k, n)| {
                let &mut (k0, t0) = first.get_or_insert((k, Instant::now()));
                time_left(k0, t0.elapsed(), k, n)
            });
            shown.set_message(describe(&phase, left));
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

/// The time a path has left at segment `k` of `n`, from the `elapsed`
/// time since segment `k0` began: the segments done since then at
/// their mean rate (`None` until one is done).
pub fn time_left(k0: usize, elapsed: Duration, k: usize, n: usize) -> Option<Duration> {
    let done = k.checked_sub(k0).filter(|&d| d > 0)?;
    Some(elapsed.mul_f64((n + 1).saturating_sub(k) as f64 / done as f64))
}

/// The text of the line for `phase` (after the elapsed time and the case)
/// with the path's time `left`, e.g. `segment 3/80 · about 1m05s left ·
/// pass 2 · tangential iteration 145` (the pass is the coupling loop's).
/// Short enough for 80 columns after the case.
pub fn describe(phase: &Phase, left: Option<Duration>) -> String {
    let mut parts = Vec::new();
    if let Some((k, n)) = phase.segment {
        parts.push(format!("segment {k}/{n}"));
    }
    if let Some(left) = left {
        let s = left.as_secs();
        parts.push(if s >= 3600 {
            format!("about {}h{:02}m left", s / 3600, s % 3600 / 60)
        } else {
            format!("about {}m{:02}s left", s / 60, s % 60)
        });
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
    fn the_line_names_segment_pass_and_iteration_in_that_order() {
        let phase = Phase {
            segment: Some((3, 80)),
            pass: Some(2),
            stage: Stage::Tangential,
            iterations: 145,
        };
        assert_eq!(
            describe(&phase, None),
            "segment 3/80 · pass 2 · tangential iteration 145"
        );
        assert_eq!(
            describe(&phase, Some(Duration::from_secs(65))),
            "segment 3/80 · about 1m05s left · pass 2 · tangential iteration 145"
        );
        assert_eq!(
            describe(&phase, Some(Duration::from_secs(3 * 3600 + 7 * 60))),
            "segment 3/80 · about 3h07m left · pass 2 · tangential iteration 145"
        );
    }

    #[test]
    fn the_time_left_is_the_rate_so_far_over_the_segments_to_go() {
        // Seen first at segment 1; at segment 11 of 100, 10 done in
        // 20 s: 90 to go (11 included) at 2 s.
        let left = time_left(1, Duration::from_secs(20), 11, 100);
        assert_eq!(left, Some(Duration::from_secs(180)));
        assert_eq!(time_left(5, Duration::from_secs(3), 5, 100), None);
        // At the last segment, what it takes at the rate so far.
        assert_eq!(
            time_left(90, Duration::from_secs(20), 100, 100),
            Some(Duration::from_secs(2))
        );
    }

    #[test]
    fn the_line_leaves_out_what_the_case_does_not_have() {
        let normal = Phase {
            stage: Stage::Normal,
            iterations: 12,
            ..Phase::default()
        };
        assert_eq!(describe(&normal, None), "normal iteration 12");
        let kernel = Phase {
            stage: Stage::Kernel,
            ..Phase::default()
        };
        assert_eq!(describe(&kernel, None), "building the kernel");
        assert_eq!(describe(&Phase::default(), None), "starting");
    }
}
