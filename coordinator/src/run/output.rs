//! The files a sweep writes: `results.csv`, `curves.csv`, `mu_a_vs_angle.{png,svg}`
//! and `fields/<case>/*.npy`. Formatting is deterministic (rows sorted by the
//! case's display text, shortest round-trip floats) so that the CSVs do not
//! depend on the number of workers. Owns no IPC, no journal and no physics
//! beyond the K_E calibration call into the solver.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use solver::{calibrate_on_flat, CaseScalars};

use super::journal::Outcome;
use super::plan::PlannedCase;
use crate::case::{CaseKey, Status};

/// Header of `results.csv` (one row per case, see README.md). Users' tools
/// read these names: change one only with a reason in the docs.
pub const RESULTS_HEADER: &str = "material,surface,angle_deg,status,mu_a,k_e,contact_radius_m,stick_radius_m,delta_t_m,delta_z_m,p_max_pa,contact_area_m2,stick_area_m2,normal_iterations,tangential_iterations,coupling_iterations,seconds,worker";
/// Header of `curves.csv`.
pub const CURVES_HEADER: &str = "material,surface,angle_deg,mu_a";

/// A finished case ready for output: its plan entry, its record and the
/// scalars after K_E calibration.
pub struct Row<'a> {
    /// Plan entry.
    pub case: &'a PlannedCase,
    /// Its recorded outcome.
    pub record: &'a Outcome,
    /// Scalars with the final μa and K_E.
    pub scalars: Option<CaseScalars>,
}

/// Deterministic float text: shortest round-trip digits, exponent form
/// outside [1e-3, 1e7).
pub fn fmt_f64(v: f64) -> String {
    if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e7) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

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
            case,
            record,
            scalars,
        });
    }
    // The order of the display text (as when cases were named by strings).
    rows.sort_by_cached_key(|r| r.case.key.to_string());
    rows
}

fn opt(v: Option<f64>) -> String {
    v.map(fmt_f64).unwrap_or_default()
}

/// Text of `results.csv`.
pub fn results_csv(rows: &[Row]) -> String {
    let mut out = String::from(RESULTS_HEADER);
    out.push('\n');
    for r in rows {
        let c = r.case;
        let s = r.scalars.as_ref();
        let f = |g: fn(&CaseScalars) -> f64| opt(s.map(g));
        let i = |g: fn(&CaseScalars) -> usize| s.map(|s| g(s).to_string()).unwrap_or_default();
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3},{}",
            csv_field(&c.key.material),
            csv_field(&c.key.surface),
            fmt_f64(c.spec.load.angle_deg),
            r.record.status,
            opt(s.and_then(|s| s.mu_a)),
            f(|s| s.k_e),
            f(|s| s.contact_radius_m),
            f(|s| s.stick_radius_m),
            f(|s| s.delta_t_m),
            f(|s| s.delta_z_m),
            f(|s| s.p_max_pa),
            f(|s| s.contact_area_m2),
            f(|s| s.stick_area_m2),
            i(|s| s.normal_iterations),
            i(|s| s.tangential_iterations),
            i(|s| s.coupling_iterations),
            r.record.seconds,
            r.record.worker
        );
    }
    out
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Rows that belong on a curve: solved, converged, with a μa.
pub fn curve_points<'a>(rows: &'a [Row]) -> Vec<(&'a Row<'a>, f64)> {
    rows.iter()
        .filter(|r| r.record.status == Status::Ok)
        .filter_map(|r| r.scalars.as_ref().and_then(|s| s.mu_a).map(|m| (r, m)))
        .collect()
}

/// Text of `curves.csv`.
pub fn curves_csv(rows: &[Row]) -> String {
    let mut out = String::from(CURVES_HEADER);
    out.push('\n');
    for (r, mu) in curve_points(rows) {
        let _ = writeln!(
            out,
            "{},{},{},{}",
            csv_field(&r.case.key.material),
            csv_field(&r.case.key.surface),
            fmt_f64(r.case.spec.load.angle_deg),
            fmt_f64(mu)
        );
    }
    out
}

/// Curves keyed by "material / surface": (angle, μa) sorted by angle.
pub fn curves(rows: &[Row]) -> BTreeMap<String, Vec<(f64, f64)>> {
    let mut m: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    for (r, mu) in curve_points(rows) {
        m.entry(format!("{} / {}", r.case.key.material, r.case.key.surface))
            .or_default()
            .push((r.case.spec.load.angle_deg, mu));
    }
    for v in m.values_mut() {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    m
}

/// Draw μa versus angle, one line per material × surface, to `path`
/// (PNG or SVG by extension).
pub fn plot_curves(path: &Path, curves: &BTreeMap<String, Vec<(f64, f64)>>) -> anyhow::Result<()> {
    use plotters::prelude::*;
    let is_svg = path.extension().is_some_and(|e| e == "svg");
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, plotters::coord::Shift>,
        curves: &BTreeMap<String, Vec<(f64, f64)>>,
    ) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let pts = curves.values().flatten();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut xlo, mut xhi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(a, m) in pts {
            lo = lo.min(m);
            hi = hi.max(m);
            xlo = xlo.min(a);
            xhi = xhi.max(a);
        }
        if !lo.is_finite() {
            (lo, hi, xlo, xhi) = (0.0, 1.0, 0.0, 180.0);
        }
        let pad = ((hi - lo) * 0.1).max(1e-3);
        if xhi <= xlo {
            xhi = xlo + 1.0;
        }
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption("apparent friction vs force angle", ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(xlo..xhi, (lo - pad)..(hi + pad))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        chart
            .configure_mesh()
            .x_desc("force angle ψ (deg)")
            .y_desc("μa")
            .draw()
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        for (k, (name, pts)) in curves.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))
                .map_err(|e| anyhow::anyhow!("{e:?}"))?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        root.present().map_err(|e| anyhow::anyhow!("{e:?}"))?;
        Ok(())
    }
    crate::atomic::replace_with(path, |tmp| {
        if is_svg {
            draw(SVGBackend::new(tmp, (900, 600)).into_drawing_area(), curves)
        } else {
            draw(
                BitMapBackend::new(tmp, (900, 600)).into_drawing_area(),
                curves,
            )
        }
    })
}

/// Directory of a case's fields: `fields/<material>/<surface>/<angle>`
/// (`fields/Cu/flat/015.0`), each component made file-name safe.
pub fn fields_dir(out_dir: &Path, key: &CaseKey) -> PathBuf {
    let mut p = out_dir.join("fields");
    for part in [
        key.material.as_str(),
        key.surface.as_str(),
        &key.angle_text(),
    ] {
        let safe: String = part
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "._-()+".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        p.push(if safe.is_empty() || safe == "." || safe == ".." {
            "_".to_string()
        } else {
            safe
        });
    }
    p
}

/// Write the field arrays of a result (`names[k]` is array `k` of `n²`
/// values in `field_bytes`) as `fields/<case>/<name>.npy`.
pub fn write_result_fields(
    out_dir: &Path,
    key: &CaseKey,
    n: usize,
    names: &[String],
    field_bytes: &[u8],
) -> anyhow::Result<()> {
    let dir = fields_dir(out_dir, key);
    std::fs::create_dir_all(&dir).with_context(|| format!("while creating {}", dir.display()))?;
    for (k, name) in names.iter().enumerate() {
        let data = protocol::read_field(field_bytes, k, n * n)
            .ok_or_else(|| anyhow::anyhow!("field {name} missing"))?;
        crate::npy::write_npy(&dir.join(format!("{name}.npy")), n, &data)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use solver::{calibrate_k_e, mu_apparent, CaseSpec, Surface};

    #[test]
    fn float_text_is_shortest_round_trip() {
        for v in [0.0, 0.3, 1.0 / 3.0, 1.5e-5, 6.02e23, -2.5e-12, 1234.5] {
            let t = fmt_f64(v);
            assert_eq!(t.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{t}");
        }
        assert_eq!(fmt_f64(1.5e-5), "1.5e-5");
        assert_eq!(fmt_f64(15.0), "15");
    }

    fn aniso_case(surface_name: &str, surface: Surface) -> PlannedCase {
        let iso = solver::Isotropic::new(130e9, 0.34).unwrap();
        let mut c = iso.stiffness();
        c[(0, 0)] *= 1.2;
        let spec = CaseSpec {
            material: solver::Material {
                name: "Cu(111)".into(),
                elasticity: solver::Elasticity::Anisotropic(solver::Anisotropic(c)),
                equivalent: iso,
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
                contact_radius_m: a,
                stick_radius_m: c,
                delta_t_m: dt,
                mu_a: Some(0.0),
                k_e: 1.0,
                ..Default::default()
            }),
        }
    }

    #[test]
    fn anisotropic_mu_a_uses_k_e_from_the_flat_twin() {
        let lattice = Surface::Lattice {
            island: solver::Island::Circle { diameter: 4e-4 },
            pitch: 1.28e-3,
            height: 3e-5,
            offset: [0.0, 0.0],
            lattice: solver::LatticeKind::Square,
        };
        let flat = aniso_case("flat", Surface::Flat);
        let pat = aniso_case("circle-A", lattice);
        assert!(flat.calibration && !pat.calibration);
        let cases = vec![pat, flat];
        let records = vec![
            Some(record(2.5e-3, 1.4e-3, 4e-6)),
            Some(record(2e-3, 1.5e-3, 3e-6)),
        ];
        let rows = calibrate(&cases, &records);
        let flat_row = rows.iter().find(|r| r.case.key.surface == "flat").unwrap();
        let pat_row = rows
            .iter()
            .find(|r| r.case.key.surface == "circle-A")
            .unwrap();
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
        assert_eq!(pat_row.case.key.to_string(), "Cu(111)/circle-A/030.0");
    }

    #[test]
    fn fields_dir_is_safe() {
        let d = fields_dir(Path::new("/o"), &CaseKey::new("Cu(111)", "..", 45.0));
        assert_eq!(d, Path::new("/o/fields/Cu(111)/_/045.0"));
    }
}
