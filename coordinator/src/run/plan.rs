//! The cases of a sweep, each under its [`CaseKey`], and who should solve
//! which next. Owns dispatch order (K_E calibration cases first, material
//! affinity) and dispatch state; knows no IPC and no files. A case becomes
//! `Done` only through `record::Recorder`, which owns the plan during a run.
//!
//! (A later check of the keys — no duplicates, no two angles closer than
//! 0.1° — belongs in [`Plan::new`], the one place cases enter.)

use std::collections::HashSet;
use std::time::Instant;

use solver::{CaseSpec, KernelKey, Surface};

use crate::case::CaseKey;

/// Where a case stands.
#[derive(Clone, Debug, PartialEq)]
pub enum CaseState {
    /// Waiting for a worker.
    Pending,
    /// Sent to worker `k` at the given instant.
    InFlight {
        /// Worker index.
        worker: usize,
        /// When it was dispatched.
        since: Instant,
    },
    /// Recorded (journalled); never dispatched again.
    Done,
}

/// One case of the sweep.
#[derive(Clone, Debug)]
pub struct PlannedCase {
    /// Case identity from the config.
    pub key: CaseKey,
    /// Its specification.
    pub spec: CaseSpec,
    /// The kernel it needs.
    pub kernel_key: KernelKey,
    /// A flat case of an anisotropic material: its K_E(ψ) calibrates the
    /// patterned cases at the same angle, so it is dispatched first.
    pub calibration: bool,
    /// Dispatch state.
    pub state: CaseState,
    /// Dispatches so far (a worker died or sent a bad result on the others).
    pub attempts: u32,
}

/// All cases of a sweep and their dispatch state.
#[derive(Debug, Default)]
pub struct Plan {
    /// Cases in config order.
    pub cases: Vec<PlannedCase>,
}

/// True for a flat case of an anisotropic material (a K_E calibration case).
pub fn is_calibration(spec: &CaseSpec) -> bool {
    !spec.material.is_isotropic() && matches!(spec.surface, Surface::Flat)
}

impl Plan {
    /// Plan the given cases (config order is kept for ties).
    pub fn new(cases: Vec<(CaseKey, CaseSpec)>) -> Self {
        let cases = cases
            .into_iter()
            .map(|(key, spec)| PlannedCase {
                kernel_key: KernelKey::of(&spec),
                calibration: is_calibration(&spec),
                key,
                spec,
                state: CaseState::Pending,
                attempts: 0,
            })
            .collect();
        Plan { cases }
    }

    /// Index of a case.
    pub fn index_of(&self, key: &CaseKey) -> Option<usize> {
        self.cases.iter().position(|c| c.key == *key)
    }

    /// Index of the case whose key displays as `text` (string equality, for
    /// journals written before keys were typed; nothing is parsed).
    pub fn index_of_display(&self, text: &str) -> Option<usize> {
        self.cases.iter().position(|c| c.key.to_string() == text)
    }

    /// Case `i` was sent to `worker`: in flight from now, one more attempt.
    pub fn dispatched(&mut self, i: usize, worker: usize) {
        let case = &mut self.cases[i];
        case.attempts += 1;
        case.state = CaseState::InFlight {
            worker,
            since: Instant::now(),
        };
    }

    /// Case `i` waits for a worker again (its worker died or sent a bad
    /// result: the attempt counts). A recorded case stays recorded.
    pub fn requeue(&mut self, i: usize) {
        if self.cases[i].state != CaseState::Done {
            self.cases[i].state = CaseState::Pending;
        }
    }

    /// Case `i` came back unsolved from a worker that moved on (handed back,
    /// not crashed on): pending again, and the attempt does not count.
    pub fn hand_back(&mut self, i: usize) {
        if self.cases[i].state != CaseState::Done {
            self.cases[i].state = CaseState::Pending;
            self.cases[i].attempts = self.cases[i].attempts.saturating_sub(1);
        }
    }

    /// Case `i` is recorded; only `record::Recorder` calls this.
    pub(super) fn mark_done(&mut self, i: usize) {
        self.cases[i].state = CaseState::Done;
    }

    /// The worker case `i` is in flight to, and for how long.
    pub fn in_flight(&self, i: usize) -> Option<(usize, std::time::Duration)> {
        match self.cases[i].state {
            CaseState::InFlight { worker, since } => Some((worker, since.elapsed())),
            _ => None,
        }
    }

    /// Cases not yet recorded.
    pub fn remaining(&self) -> usize {
        self.cases
            .iter()
            .filter(|c| c.state != CaseState::Done)
            .count()
    }

    /// Cases waiting for a worker.
    pub fn pending(&self) -> usize {
        self.cases
            .iter()
            .filter(|c| c.state == CaseState::Pending)
            .count()
    }

    /// The next case for a worker holding kernels `own`, while the other live
    /// workers hold `others`: calibration cases first; within a class, a case
    /// whose kernel the worker already has, else one whose kernel nobody has,
    /// else any (no worker idles while cases remain).
    pub fn pick(&self, own: &HashSet<KernelKey>, others: &HashSet<KernelKey>) -> Option<usize> {
        let pending = |c: &&PlannedCase| c.state == CaseState::Pending;
        let class = if self.cases.iter().filter(pending).any(|c| c.calibration) {
            |c: &PlannedCase| c.calibration
        } else {
            |_: &PlannedCase| true
        };
        let candidates = || {
            self.cases
                .iter()
                .enumerate()
                .filter(|(_, c)| c.state == CaseState::Pending && class(c))
        };
        candidates()
            .find(|(_, c)| own.contains(&c.kernel_key))
            .or_else(|| candidates().find(|(_, c)| !others.contains(&c.kernel_key)))
            .or_else(|| candidates().next())
            .map(|(i, _)| i)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use solver::{Grid, Load, Material, Numerics};

    fn spec(material: &str, angle: f64) -> CaseSpec {
        CaseSpec {
            material: Material::isotropic(material, 100e9, 0.3).unwrap(),
            surface: Surface::Flat,
            grid: Grid::square(32, 1e-5),
            load: Load {
                indenter_radius_m: 0.2,
                normal_force_n: 100.0,
                friction: 0.3,
                tangential_ratio: 0.5,
                angle_deg: angle,
            },
            numerics: quick_numerics(),
            history: None,
            indenter: None,
        }
    }

    /// Loose, uncoupled settings for plan and output tests (nothing is solved).
    pub(crate) fn quick_numerics() -> Numerics {
        Numerics {
            coupling: false,
            tolerance: 1e-8,
            tangential_tolerance: 1e-6,
            max_iterations: 100,
            coupling_tolerance: 1e-6,
            max_coupling_iterations: 5,
            ..Numerics::default()
        }
    }

    fn key(material: &str, surface: &str, angle: f64) -> CaseKey {
        CaseKey::new(material, surface, angle)
    }

    fn plan() -> Plan {
        Plan::new(vec![
            (key("A", "flat", 0.0), spec("A", 0.0)),
            (key("A", "flat", 45.0), spec("A", 45.0)),
            (key("B", "flat", 0.0), spec("B", 0.0)),
            (key("B", "flat", 45.0), spec("B", 45.0)),
        ])
    }

    #[test]
    fn second_worker_takes_the_other_material() {
        let p = plan();
        let first = p.pick(&HashSet::new(), &HashSet::new()).unwrap();
        assert_eq!(first, 0);
        let a: HashSet<KernelKey> = [p.cases[0].kernel_key.clone()].into();
        let second = p.pick(&HashSet::new(), &a).unwrap();
        assert_eq!(p.cases[second].key.to_string(), "B/flat/000.0");
    }

    #[test]
    fn calibration_cases_go_first() {
        let mut aniso = spec("C", 0.0);
        let iso = aniso.material.equivalent;
        aniso.material.elasticity =
            solver::Elasticity::Anisotropic(solver::Anisotropic(iso.stiffness()));
        let mut patterned = aniso.clone();
        patterned.surface = Surface::Lattice {
            island: solver::Island::Circle { diameter: 4e-4 },
            pitch: 1.28e-3,
            height: 3e-5,
            offset: [0.0, 0.0],
            lattice: solver::LatticeKind::Square,
            sampling: solver::Sampling::Area,
        };
        let p = Plan::new(vec![
            (key("A", "flat", 0.0), spec("A", 0.0)),
            (key("C", "circle-A", 0.0), patterned),
            (key("C", "flat", 0.0), aniso),
        ]);
        let own: HashSet<KernelKey> = [p.cases[0].kernel_key.clone()].into();
        assert_eq!(p.pick(&own, &HashSet::new()), Some(2));
    }

    #[test]
    fn worker_keeps_its_material_and_never_idles() {
        let mut p = plan();
        let a: HashSet<KernelKey> = [p.cases[0].kernel_key.clone()].into();
        let b: HashSet<KernelKey> = [p.cases[2].kernel_key.clone()].into();
        p.cases[0].state = CaseState::Done;
        assert_eq!(p.pick(&a, &b), Some(1));
        p.cases[1].state = CaseState::Done;
        // A's cases are gone: worker A helps with B rather than idle.
        assert_eq!(p.pick(&a, &b), Some(2));
        for c in &mut p.cases {
            c.state = CaseState::Done;
        }
        assert_eq!(p.pick(&a, &b), None);
        assert_eq!(p.remaining(), 0);
    }

    #[test]
    fn cases_are_found_by_key_and_old_journals_by_display_text() {
        let p = plan();
        assert_eq!(p.index_of(&key("B", "flat", 45.0)), Some(3));
        assert_eq!(p.index_of(&key("B", "flat", 46.0)), None);
        assert_eq!(p.index_of_display("A/flat/045.0"), Some(1));
        assert_eq!(p.index_of_display("A/flat/45"), None);
    }

    #[test]
    fn a_recorded_case_is_never_requeued() {
        let mut p = plan();
        p.dispatched(0, 1);
        assert_eq!(p.in_flight(0).map(|(w, _)| w), Some(1));
        assert_eq!(p.cases[0].attempts, 1);
        p.hand_back(0);
        assert_eq!(
            (p.cases[0].state.clone(), p.cases[0].attempts),
            (CaseState::Pending, 0)
        );
        p.dispatched(0, 1);
        p.mark_done(0);
        p.requeue(0);
        p.hand_back(0);
        assert_eq!(p.cases[0].state, CaseState::Done);
        assert_eq!(p.remaining(), 3);
    }
}
