//! Auto increments (`history.steps_per_segment = "auto"`): the step-size
//! control that solves each segment in as few increments as the path's
//! estimate accepts at `history.tolerance`, and what it keeps from one
//! segment to the next.

use super::walk::{Walk, INTERIOR_COUPLING};
use crate::error::SolverError;
use crate::model::spec::{AUTO_LOAD_STEP, AUTO_WEAR_STEP, MAX_HISTORY_STEPS};
use crate::solve::resident::Resident;

/// Smallest increment auto increments take, as a fraction of its segment:
/// where the estimate still asks for less, the increment is taken and the
/// path says the tolerance was not met ([`HistoryOutput::auto_tolerance_met`]).
pub(super) const AUTO_MIN_FRACTION: f64 = 1.0 / 4096.0;

/// The load (P, tangential target) at fraction `t` of the segment from `a`
/// to `b` (`b` itself at `t = 1`).
pub(super) fn along_segment(a: (f64, f64), b: (f64, f64), t: f64) -> (f64, f64) {
    if t >= 1.0 {
        b
    } else {
        (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
    }
}

/// Auto increments along a path: the step-size control of each segment
/// from the path's estimate ([`PathEstimate`]), and what it keeps from one
/// segment to the next.
#[derive(Debug)]
pub(super) struct AutoSteps {
    /// The approach of the path's start (the worn depth's scale), m.
    pub(super) approach0: f64,
    /// The dissipation of the last segment, J: the scale of the next one's
    /// energy tolerance.
    pub(super) last_segment_work: f64,
    /// The mean fraction of its segment the last auto segment's increments
    /// took: the next segment's first try, and with it the size its
    /// increments grow to at most (a fretting path repeats its reversals:
    /// larger tries were turned down 4 times a reversal on Table 1(a) Fe,
    /// coupled, 256²).
    pub(super) mean_span: f64,
    /// Increments solved and turned down.
    pub(super) rejected: usize,
    /// Every increment met the tolerance.
    pub(super) tolerance_met: bool,
}

impl Default for AutoSteps {
    fn default() -> Self {
        AutoSteps {
            approach0: 0.0,
            last_segment_work: 0.0,
            mean_span: 1.0,
            rejected: 0,
            tolerance_met: true,
        }
    }
}

impl AutoSteps {
    /// Solves the segment from load `a` to `b` (the path's `segment`) in
    /// as few increments as the estimate accepts at `tolerance`.
    pub(super) fn segment(
        &mut self,
        walk: &mut Walk,
        res: &mut Resident,
        (a, b): ((f64, f64), (f64, f64)),
        segment: usize,
        tolerance: f64,
        check: &impl Fn(&[f64]) -> Result<(), SolverError>,
    ) -> Result<(), SolverError> {
        // The normal load may change by κ·tol of itself per increment (a
        // bound known before solving).
        let load_step = AUTO_LOAD_STEP * tolerance;
        // The largest increment from fraction t: ΔP within κ·tol of the
        // smaller load at its ends (a ramp 0.5 → 20 N takes 148 increments
        // in geometric progression, not 1560 of the smallest).
        let dp = (b.0 - a.0).abs();
        let most = |t: f64| {
            if dp > 0.0 {
                let p_t = a.0 + t * (b.0 - a.0);
                // Unloading, the smaller end is the increment's own.
                let smaller = if b.0 < a.0 {
                    p_t * (1.0 - load_step)
                } else {
                    p_t
                };
                (load_step * smaller / dp).min(1.0)
            } else {
                1.0
            }
        };
        let mut h = self.mean_span.min(most(0.0));
        let taken_before = walk.rows.len();
        let mut t = 0.0;
        // The segment's dissipation as its first trial sees it.
        let mut whole: Option<f64> = None;
        let moves = a.1 != b.1;
        while t < 1.0 {
            let t1 = if t + h >= 1.0 - 1e-9 { 1.0 } else { t + h };
            let load = along_segment(a, b, t1);
            if load == walk.load {
                walk.hold(segment);
                t = t1;
                continue;
            }
            // Inside the segment the coupling loop need only be as tight as
            // the path's tolerance can see; its last increment (a turning
            // point) is solved to the configured one.
            let interior = (t1 < 1.0).then_some(INTERIOR_COUPLING * tolerance);
            let trial = walk.trial(res, load, interior, check)?;
            let e = trial.estimate;
            let span = t1 - t;
            // The energy's share: its error against the tolerance's part of
            // the segment's dissipation (the last segment's, or the first
            // trial's over the whole segment: an increment of a first
            // loading dissipates as Q³ and is not held to its own share);
            // only where the tangential load moves.
            let whole = *whole.get_or_insert(e.work_j / span);
            let scale = self.last_segment_work.max(whole) * span;
            let energy = if moves && e.error_j > 0.0 {
                e.error_j / (tolerance * scale.max(f64::MIN_POSITIVE))
            } else {
                0.0
            };
            let pressure = (load.0 - walk.load.0).abs() / load.0.min(walk.load.0);
            let worn = e.worn_m / self.approach0.abs().max(f64::MIN_POSITIVE);
            let ratio = energy
                .max(pressure / load_step)
                .max(worn / (AUTO_WEAR_STEP * tolerance));
            let room = walk.rows.len() < MAX_HISTORY_STEPS;
            if ratio > 1.0 && span > AUTO_MIN_FRACTION && room {
                self.rejected += 1;
                h = (span * (0.9 / ratio).max(0.2)).max(AUTO_MIN_FRACTION);
                continue;
            }
            self.tolerance_met &= ratio <= 1.0;
            walk.accept(res, trial, segment, check)?;
            t = t1;
            // The estimate's error is second order in the increment, its
            // budget first order: the ratio grows as the increment.
            let grow = if ratio > 0.0 {
                (0.8 / ratio).min(1.5)
            } else {
                1.5
            };
            h = (span * grow).max(AUTO_MIN_FRACTION).min(most(t));
        }
        self.mean_span = 1.0 / (walk.rows.len() - taken_before).max(1) as f64;
        Ok(())
    }
}
