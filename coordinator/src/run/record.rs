//! The record of a sweep: the plan, the journal and the outcome of every
//! finished case, held together by [`Recorder`] — the only way to record a
//! result, and it never records a case twice. Knows no IPC and no processes;
//! writes only the journal (through `journal`).

use std::path::Path;

use super::journal::{Entry, Journal, Line, Outcome};
use super::plan::{CaseState, Plan, PlannedCase};

/// Plan + journal + outcomes of one sweep.
pub struct Recorder {
    plan: Plan,
    journal: Journal,
    /// Outcome of `plan.cases[i]`, once recorded.
    outcomes: Vec<Option<Outcome>>,
    recorded: usize,
}

/// What [`Recorder::open`] found of an earlier run.
pub struct Resumed {
    /// Cases taken from the journal.
    pub cases: usize,
    /// A torn last journal line was dropped.
    pub torn_tail: bool,
}

/// A case that was just recorded.
pub struct Recorded {
    /// What was journalled (the status may have become `failed` when the
    /// result could not be written as JSON).
    pub outcome: Outcome,
}

impl Recorder {
    /// Open the journal in `out_dir` for `plan` (new, or `resume`d: the
    /// journalled cases of the plan count as recorded; a typed key is matched
    /// by value, an older line by its display text).
    pub fn open(
        mut plan: Plan,
        out_dir: &Path,
        run_id: &str,
        config: &str,
        resume: bool,
        names: super::OptionNames,
    ) -> anyhow::Result<(Recorder, Resumed)> {
        let (journal, previous) = Journal::open(out_dir, run_id, config, resume, names)?;
        let mut outcomes: Vec<Option<Outcome>> = vec![None; plan.cases.len()];
        for entry in previous.entries {
            let i = match &entry.key {
                Some(key) => plan.index_of(key),
                None => plan.index_of_display(&entry.case_id),
            };
            if let Some(i) = i {
                plan.mark_done(i);
                outcomes[i] = Some(entry.outcome);
            }
        }
        let recorded = outcomes.iter().flatten().count();
        let rec = Recorder {
            plan,
            journal,
            outcomes,
            recorded,
        };
        let resumed = Resumed {
            cases: recorded,
            torn_tail: previous.torn_tail,
        };
        Ok((rec, resumed))
    }

    /// The cases and their dispatch state.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// Cases recorded so far (resumed ones included).
    pub fn recorded(&self) -> usize {
        self.recorded
    }

    /// Case `i` was sent to `worker`.
    pub fn dispatched(&mut self, i: usize, worker: usize) {
        self.plan.dispatched(i, worker);
    }

    /// Case `i` goes back to the queue; see [`Plan::requeue`].
    pub fn requeue(&mut self, i: usize) {
        self.plan.requeue(i);
    }

    /// Case `i` was handed back unsolved; see [`Plan::hand_back`].
    pub fn hand_back(&mut self, i: usize) {
        self.plan.hand_back(i);
    }

    /// Record case `i`: journal `outcome` (synced), then mark the case done;
    /// the answer that follows is the acknowledgement. `None` when the case
    /// was already recorded (nothing is written).
    pub fn record(&mut self, i: usize, mut outcome: Outcome) -> anyhow::Result<Option<Recorded>> {
        let case = &self.plan.cases[i];
        if case.state == CaseState::Done {
            return Ok(None);
        }
        // JSON has no NaN/∞: a record that would not read back on --resume
        // keeps its status but loses its scalars, with the reason.
        let line = Line::Case(Box::new(Entry::new(&case.key, outcome.clone())));
        let readable = serde_json::to_string(&line)
            .ok()
            .and_then(|t| serde_json::from_str::<Line>(&t).ok())
            .is_some();
        if !readable {
            outcome.scalars = None;
            outcome.status = crate::case::Status::Failed;
            outcome.error = Some("result holds non-finite values".into());
        }
        self.journal.append(&Line::Case(Box::new(Entry::new(
            &case.key,
            outcome.clone(),
        ))))?;
        self.plan.mark_done(i);
        self.outcomes[i] = Some(outcome.clone());
        self.recorded += 1;
        Ok(Some(Recorded { outcome }))
    }

    /// Every case with its outcome (None while unrecorded), in plan order.
    pub fn results(&self) -> (&[PlannedCase], &[Option<Outcome>]) {
        (&self.plan.cases, &self.outcomes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::{CaseKey, Status};
    use solver::CaseScalars;

    fn plan() -> Plan {
        let cfg = crate::config::Config::parse(
            "[grid]\npoints = 16\nspacing_um = 400.0\n[indenter]\nradius_mm = 200.0\n\
             [load]\nnormal_n = 6000.0\nfriction = 0.3\n\
             [sweep]\nmaterials = [\"Cu\"]\nangles_deg = [0.0, 15.0]\n",
            &[],
        )
        .unwrap();
        Plan::new(cfg.cases().unwrap())
    }

    fn ok(worker: u32) -> Outcome {
        Outcome {
            status: Status::Ok,
            error: None,
            worker,
            seconds: 0.25,
            kernel_builds: 1,
            scalars: Some(CaseScalars {
                contact_radius_m: 1.0 / 3.0,
                ..Default::default()
            }),
            stress: None,
        }
    }

    fn tmp(name: &str) -> tempfile::TempDir {
        // Removed when dropped: tests leave nothing in the system temp dir.
        tempfile::Builder::new()
            .prefix(&format!("mpc-{name}-"))
            .tempdir()
            .unwrap()
    }

    #[test]
    fn a_case_is_recorded_once_and_resumes_by_key() {
        let tmp_dir = tmp("once");
        let d = tmp_dir.path().to_path_buf();
        let (mut rec, resumed) =
            Recorder::open(plan(), &d, "r1", "cfg", false, crate::run::OptionNames::CLI).unwrap();
        assert_eq!(resumed.cases, 0);
        rec.dispatched(1, 0);
        assert!(rec.record(1, ok(0)).unwrap().is_some());
        assert!(rec.record(1, ok(7)).unwrap().is_none(), "recorded twice");
        assert_eq!(rec.recorded(), 1);
        drop(rec);
        let (rec, resumed) =
            Recorder::open(plan(), &d, "r2", "cfg", true, crate::run::OptionNames::CLI).unwrap();
        assert_eq!(resumed.cases, 1);
        assert_eq!(rec.plan().remaining(), 1);
        let (cases, outcomes) = rec.results();
        assert_eq!(cases[1].key, CaseKey::new("Cu", "flat", 15.0));
        assert_eq!(outcomes[1].as_ref(), Some(&ok(0)));
        assert_eq!(outcomes[0], None);
    }

    #[test]
    fn an_old_journal_resumes_by_display_text() {
        let tmp_dir = tmp("old");
        let d = tmp_dir.path().to_path_buf();
        drop(Recorder::open(plan(), &d, "r1", "cfg", false, crate::run::OptionNames::CLI).unwrap());
        let old = "{\"kind\":\"case\",\"case_id\":\"Cu/flat/015.0\",\"status\":\"not-converged\",\
                   \"error\":null,\"worker\":1,\"seconds\":0.5,\"kernel_builds\":1,\"scalars\":null}\n";
        let path = d.join(super::super::journal::JOURNAL_FILE);
        let text = std::fs::read_to_string(&path).unwrap() + old;
        std::fs::write(&path, text).unwrap();
        let (rec, resumed) =
            Recorder::open(plan(), &d, "r2", "cfg", true, crate::run::OptionNames::CLI).unwrap();
        assert_eq!(resumed.cases, 1);
        let (_, outcomes) = rec.results();
        assert_eq!(outcomes[1].as_ref().unwrap().status, Status::NotConverged);
    }

    #[test]
    fn non_finite_scalars_are_recorded_as_failed() {
        let tmp_dir = tmp("nan");
        let d = tmp_dir.path().to_path_buf();
        let (mut rec, _) =
            Recorder::open(plan(), &d, "r1", "cfg", false, crate::run::OptionNames::CLI).unwrap();
        let mut bad = ok(0);
        if let Some(s) = bad.scalars.as_mut() {
            s.p_max_pa = f64::NAN;
        }
        let r = rec.record(0, bad).unwrap().unwrap();
        assert_eq!(r.outcome.status, Status::Failed);
        assert!(r.outcome.scalars.is_none());
    }
}
