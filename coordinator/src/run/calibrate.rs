//! The K_E calibration of a sweep's recorded outcomes: each case of the
//! plan with its journalled outcome becomes an output row
//! ([`crate::output::sweep::Row`]), an anisotropic material's K_E (and μa)
//! taken from its flat twin. The only place the run's plan and journal
//! meet the outputs, which know neither.

use solver::calibrate_on_flat;

use super::journal::Outcome;
use super::plan::PlannedCase;
use crate::case::Status;
use crate::output::sweep::Row;

/// Apply the K_E calibration: patterned (and flat) cases of anisotropic
/// materials get K_E(ψ) from the flat case of the same material, grid and
/// angle, and μa recomputed with it. Cases without a flat twin keep the
/// worker's isotropic-equivalent K_E.
/// `records[i]` is the outcome of `cases[i]` (None: not recorded).
pub fn calibrate<'a>(cases: &'a [PlannedCase], records: &'a [Option<Outcome>]) -> Vec<Row<'a>> {
    let mut rows = Vec::new();
    for (case, record) in cases.iter().zip(records) {
        let Some(record) = record else {
            continue;
        };
        let mut scalars = record.scalars.clone();
        if let Some(s) = scalars.as_mut() {
            let spec = &case.spec;
            if spec.needs_flat_calibration() {
                let twin_spec = spec.flat_twin();
                let twin = cases.iter().position(|c| c.spec == twin_spec);
                let flat = twin
                    .and_then(|t| records.get(t).and_then(Option::as_ref))
                    .filter(|r| r.status != Status::Failed)
                    .and_then(|r| r.scalars.as_ref());
                if let Some(flat) = flat {
                    calibrate_on_flat(s, flat, &spec.load);
                }
            }
        }
        rows.push(Row {
            key: &case.key,
            spec: &case.spec,
            status: record.status,
            seconds: record.seconds,
            worker: record.worker,
            stress: record.stress.as_ref(),
            scalars,
        });
    }
    // The order of the display text (as when cases were named by strings).
    rows.sort_by_cached_key(|r| r.key.to_string());
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::CaseKey;
    use crate::output::sweep::results_csv;
    use solver::{calibrate_k_e, mu_apparent, CaseScalars, CaseSpec, Surface};

    fn aniso_case(surface_name: &str, surface: Surface) -> PlannedCase {
        let iso = solver::Isotropic::new(130e9, 0.34).unwrap();
        let mut c = iso.stiffness();
        c[(0, 0)] *= 1.2;
        let spec = CaseSpec {
            material: solver::Material {
                name: "Cu(111)".into(),
                elasticity: solver::Elasticity::Anisotropic(solver::Anisotropic(c)),
                equivalent: iso,
                limits: Default::default(),
            },
            surface,
            grid: solver::Grid::square(32, 1e-4),
            load: solver::Load {
                indenter_radius_m: 0.2,
                normal_force_n: 6000.0,
                friction: 0.3,
                tangential_ratio: 0.6,
                angle_deg: 30.0,
            },
            numerics: super::super::plan::tests::quick_numerics(),
            history: None,
            indenter: None,
        };
        let key = CaseKey::new("Cu(111)", surface_name, 30.0);
        let mut plan = super::super::plan::Plan::new(vec![(key, spec)]);
        plan.cases.remove(0)
    }

    fn record(a: f64, c: f64, dt: f64) -> Outcome {
        Outcome {
            status: Status::Ok,
            error: None,
            worker: 0,
            seconds: 1.0,
            kernel_builds: 1,
            scalars: Some(CaseScalars {
                mu_a_contact_radius_m: a,
                mu_a_stick_radius_m: c,
                delta_t_m: dt,
                mu_a: Some(0.0),
                k_e: 1.0,
                ..Default::default()
            }),
            stress: None,
        }
    }

    #[test]
    fn anisotropic_mu_a_uses_k_e_from_the_flat_twin() {
        let lattice = solver::presets::surface("circle-A").expect("a preset");
        let flat = aniso_case("flat", Surface::Flat);
        let pat = aniso_case("circle-A", lattice);
        assert!(flat.calibration && !pat.calibration);
        let cases = vec![pat, flat];
        let records = vec![
            Some(record(2.5e-3, 1.4e-3, 4e-6)),
            Some(record(2e-3, 1.5e-3, 3e-6)),
        ];
        let rows = calibrate(&cases, &records);
        let flat_row = rows.iter().find(|r| r.key.surface == "flat").unwrap();
        let pat_row = rows.iter().find(|r| r.key.surface == "circle-A").unwrap();
        let fs = flat_row.scalars.as_ref().unwrap();
        // By construction Eq. 19 with the calibrated K_E returns μ on the flat case.
        assert!((fs.mu_a.unwrap() - 0.3).abs() < 1e-12, "{:?}", fs.mu_a);
        let outcome = |i: usize| records[i].as_ref().unwrap();
        let k_e = calibrate_k_e(outcome(1).scalars.as_ref().unwrap(), 0.3, 6000.0);
        let ps = pat_row.scalars.as_ref().unwrap();
        assert_eq!(ps.k_e, k_e);
        assert_eq!(ps.k_e_source, "flat-calibrated");
        let want = mu_apparent(outcome(0).scalars.as_ref().unwrap(), 6000.0, k_e);
        assert_eq!(ps.mu_a.unwrap(), want);
        assert_eq!(pat_row.key.to_string(), "Cu(111)/circle-A/030.0");
    }

    #[test]
    fn issue35_each_ball_calibrates_on_its_own_flat_twin() {
        let lattice = solver::presets::surface("circle-A").expect("a preset");
        let steel = solver::presets::material("steel").unwrap();
        let with_ball = |mut c: PlannedCase, ball: Option<&solver::Material>| {
            let name = ball.map_or("rigid", |m| m.name.as_str());
            c.key = c.key.with_indenter(name);
            c.spec.indenter = ball.cloned();
            c
        };
        let cases = vec![
            with_ball(aniso_case("circle-A", lattice.clone()), None),
            with_ball(aniso_case("flat", Surface::Flat), None),
            with_ball(aniso_case("circle-A", lattice), Some(&steel)),
            with_ball(aniso_case("flat", Surface::Flat), Some(&steel)),
        ];
        let records = vec![
            Some(record(2.5e-3, 1.4e-3, 4e-6)),
            Some(record(2e-3, 1.5e-3, 3e-6)),
            Some(record(2.9e-3, 1.6e-3, 5e-6)),
            Some(record(2.4e-3, 1.7e-3, 6e-6)),
        ];
        let rows = calibrate(&cases, &records);
        let ids: Vec<String> = rows.iter().map(|r| r.key.to_string()).collect();
        assert_eq!(
            ids,
            [
                "Cu(111)/circle-A/030.0@rigid",
                "Cu(111)/circle-A/030.0@steel",
                "Cu(111)/flat/030.0@rigid",
                "Cu(111)/flat/030.0@steel",
            ]
        );
        let flat_k_e = |i: usize| {
            calibrate_k_e(
                records[i].as_ref().unwrap().scalars.as_ref().unwrap(),
                0.3,
                6000.0,
            )
        };
        assert_ne!(flat_k_e(1), flat_k_e(3));
        assert_eq!(rows[0].scalars.as_ref().unwrap().k_e, flat_k_e(1));
        assert_eq!(rows[1].scalars.as_ref().unwrap().k_e, flat_k_e(3));
        // The CSVs name the ball after the surface.
        let csv = results_csv(&rows);
        assert!(
            csv.starts_with("material,surface,indenter,angle_deg,status,"),
            "{csv}"
        );
        assert!(csv.contains("\nCu(111),circle-A,steel,30,ok,"), "{csv}");
    }
}
