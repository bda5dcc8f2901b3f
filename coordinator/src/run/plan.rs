//! The cases of a sweep and who should solve which next. Owns dispatch order
//! (K_E calibration cases first, material affinity); knows no IPC and no files.

use std::collections::HashSet;

use solver::{CaseSpec, KernelKey, Surface};

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
        since: std::time::Instant,
    },
    /// Recorded (journalled); never dispatched again.
    Done,
}

/// One case of the sweep.
#[derive(Clone, Debug)]
pub struct PlannedCase {
    /// Case identity from the config, e.g. `Cu/flat/015.0`.
    pub id: String,
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
    pub fn new(cases: Vec<(String, CaseSpec)>) -> Self {
        let cases = cases
            .into_iter()
            .map(|(id, spec)| PlannedCase {
                kernel_key: KernelKey::of(&spec),
                calibration: is_calibration(&spec),
                id,
                spec,
                state: CaseState::Pending,
                attempts: 0,
            })
            .collect();
        Plan { cases }
    }

    /// Index of a case id.
    pub fn index_of(&self, id: &str) -> Option<usize> {
        self.cases.iter().position(|c| c.id == id)
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
mod tests {
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
            numerics: Numerics {
                coupling: false,
                tolerance: 1e-8,
                tangential_tolerance: 1e-6,
                max_iterations: 100,
                coupling_tolerance: 1e-6,
                max_coupling_iterations: 5,
            },
        }
    }

    fn plan() -> Plan {
        Plan::new(vec![
            ("A/flat/000.0".into(), spec("A", 0.0)),
            ("A/flat/045.0".into(), spec("A", 45.0)),
            ("B/flat/000.0".into(), spec("B", 0.0)),
            ("B/flat/045.0".into(), spec("B", 45.0)),
        ])
    }

    #[test]
    fn second_worker_takes_the_other_material() {
        let p = plan();
        let first = p.pick(&HashSet::new(), &HashSet::new()).unwrap();
        assert_eq!(first, 0);
        let a: HashSet<KernelKey> = [p.cases[0].kernel_key.clone()].into();
        let second = p.pick(&HashSet::new(), &a).unwrap();
        assert_eq!(p.cases[second].id, "B/flat/000.0");
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
        };
        let p = Plan::new(vec![
            ("A/flat/000.0".into(), spec("A", 0.0)),
            ("C/circle-A/000.0".into(), patterned),
            ("C/flat/000.0".into(), aniso),
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
}
