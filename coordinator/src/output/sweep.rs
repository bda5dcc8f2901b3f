//! The files a sweep writes: `results.csv`, `curves.csv`,
//! `mu_a_vs_angle.{png,svg}` and `fields/<case>/` (`*.npy`, `stress/`), from
//! [`Row`]s (plain data: the run makes them from its plan and journal, K_E
//! calibrated). Formatting is deterministic (rows sorted by the case's
//! display text, shortest round-trip floats) so that the CSVs do not depend
//! on the number of workers. Owns no IPC, no journal and no physics.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use plotters::prelude::*;
use serde::Serialize;
use solver::stress_summary::StressScalars;
use solver::{CaseScalars, CaseSpec};

use super::plot::{self, err, Area, Figure, Frame, Panels, PALETTE};
use crate::case::{CaseKey, Status};
use crate::convergence::{estimate, Estimate};
use crate::float_text::{fmt_f64, fmt_opt as opt};

/// Header of `results.csv` (one row per case, see README.md). Users' tools
/// read these names: change one only with a reason in the docs.
pub const RESULTS_HEADER: &str = "material,surface,angle_deg,status,mu_a,k_e,contact_radius_m,stick_radius_m,delta_t_m,delta_z_m,p_max_pa,contact_area_m2,stick_area_m2,normal_iterations,tangential_iterations,coupling_iterations,seconds,worker,level,grid_points,spacing_m,mu_a_cells,k_e_cells,contact_radius_cells_m,stick_radius_cells_m";
/// Header of `curves.csv`.
pub const CURVES_HEADER: &str =
    "material,surface,angle_deg,mu_a,mu_a_err,k_e,k_e_err,method,order,mu_a_by_level,mu_a_cells";
/// Columns `results.csv` gains when the sweep computes stresses below the
/// surface (`[stress]`): over the states of a case, the largest von Mises
/// stress (Pa, over p_H, and its point), the largest Tresca and principal
/// stresses, the peak surface stress along the force (the trailing-edge
/// tension) and its point, Crossland's parameter (two states or more) and
/// its depth, and Smith–Watson–Topper's at the surface with its point and
/// critical plane. A sweep without the section has the header above, to the byte.
pub const RESULTS_STRESS_COLUMNS: &str = "max_von_mises_pa,max_von_mises_over_p_h,max_von_mises_x_m,max_von_mises_y_m,max_von_mises_z_m,max_tresca_pa,max_tresca_over_p_h,max_principal_pa,max_principal_over_p_h,surface_peak_pa,surface_peak_over_p_h,surface_peak_x_m,surface_peak_y_m,crossland_pa,crossland_z_m,swt_pa,swt_x_m,swt_y_m,swt_plane_deg";

/// Columns `results.csv` gains when a case of the sweep has a hardness
/// (`[materials.NAME] hardness_gpa`): the interface's hardness, the area at
/// the hardness and its equivalent radius, the largest permanent plastic
/// penetration and the dent's volume (empty for a case without one). A
/// sweep without a hardness has the header above, to the byte.
pub const RESULTS_PLASTIC_COLUMNS: &str =
    "hardness_pa,plastic_area_m2,plastic_radius_m,plastic_penetration_max_m,dent_volume_m3";

/// Column `curves.csv` gains when a case of the sweep has a hardness: the
/// finest level's plastic area.
pub const CURVES_PLASTIC_COLUMNS: &str = "plastic_area_m2";

/// The cells of [`RESULTS_PLASTIC_COLUMNS`] of a case (empty without a
/// plastic zone).
fn plastic_cells(s: Option<&solver::PlasticScalars>) -> String {
    let f = |g: fn(&solver::PlasticScalars) -> f64| opt(s.map(g));
    [
        f(|s| s.hardness_pa),
        f(|s| s.plastic_area_m2),
        f(|s| s.plastic_radius_m),
        f(|s| s.penetration_max_m),
        f(|s| s.dent_volume_m3),
    ]
    .join(",")
}

/// Columns `curves.csv` gains with `[stress]` (the finest level's case).
pub const CURVES_STRESS_COLUMNS: &str =
    "max_von_mises_over_p_h,max_tresca_over_p_h,surface_peak_over_p_h,swt_pa";

/// The cells of [`RESULTS_STRESS_COLUMNS`] (empty without stress scalars).
fn stress_cells(s: Option<&StressScalars>) -> String {
    use solver::stress_summary::Located;
    let Some(s) = s else {
        return ",".repeat(RESULTS_STRESS_COLUMNS.matches(',').count());
    };
    let vm = s.worst(|st| Some(st.max_von_mises));
    let tr = s.worst(|st| Some(st.max_tresca));
    let pr = s.worst(|st| Some(st.max_principal));
    let sp = s.worst(|st| st.surface_peak_along_force);
    let v = |l: Option<Located>, g: fn(&Located) -> f64| opt(l.as_ref().map(g));
    [
        v(vm, |l| l.value_pa),
        v(vm, |l| l.over_p_h),
        v(vm, |l| l.at_m[0]),
        v(vm, |l| l.at_m[1]),
        v(vm, |l| l.at_m[2]),
        v(tr, |l| l.value_pa),
        v(tr, |l| l.over_p_h),
        v(pr, |l| l.value_pa),
        v(pr, |l| l.over_p_h),
        v(sp, |l| l.value_pa),
        v(sp, |l| l.over_p_h),
        v(sp, |l| l.at_m[0]),
        v(sp, |l| l.at_m[1]),
        v(s.crossland, |l| l.value_pa),
        v(s.crossland, |l| l.at_m[2]),
        fmt_f64(s.swt.value_pa),
        fmt_f64(s.swt.at_m[0]),
        fmt_f64(s.swt.at_m[1]),
        fmt_f64(s.swt.plane_angle_deg),
    ]
    .join(",")
}

/// The column both CSVs gain, after `surface`, in a sweep over balls
/// (`sweep.indenters`): the ball's name, `rigid` for none. A sweep without
/// that axis has the headers above, to the byte.
pub const INDENTER_COLUMN: &str = "indenter";

/// The columns a fretting map's sweep axes add after `surface` (and the
/// ball): `normal_n` with `sweep.normal_loads_n`, `amplitude_um` with
/// `sweep.amplitudes_um`.
pub const NORMAL_COLUMN: &str = "normal_n";
/// See [`NORMAL_COLUMN`].
pub const AMPLITUDE_COLUMN: &str = "amplitude_um";

/// Which identity axes beyond material × surface × angle a sweep has (each
/// adds a column after `surface`).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Axes {
    pub(super) balls: bool,
    pub(super) loads: bool,
    pub(super) amplitudes: bool,
}

impl Axes {
    pub(super) fn of<'a>(keys: impl Iterator<Item = &'a CaseKey>) -> Self {
        let mut a = Axes::default();
        for k in keys {
            a.balls |= k.indenter.is_some();
            a.loads |= k.normal_n.is_some();
            a.amplitudes |= k.amplitude_um.is_some();
        }
        a
    }
}

/// `header` with the axes' columns after `surface`.
fn header_with_axes(header: &str, axes: Axes) -> String {
    let mut cols = String::from("material,surface,");
    for (on, name) in [
        (axes.balls, INDENTER_COLUMN),
        (axes.loads, NORMAL_COLUMN),
        (axes.amplitudes, AMPLITUDE_COLUMN),
    ] {
        if on {
            cols.push_str(name);
            cols.push(',');
        }
    }
    header.replacen("material,surface,", &cols, 1)
}

/// The cells that name a case's curve: `material,surface,` and, in a sweep
/// over balls, loads or amplitudes, those.
fn identity_cells(key: &CaseKey, axes: Axes) -> String {
    let mut cells = format!("{},{},", csv_field(&key.material), csv_field(&key.surface));
    if axes.balls {
        cells.push_str(&csv_field(key.indenter.as_deref().unwrap_or_default()));
        cells.push(',');
    }
    if axes.loads {
        cells.push_str(&opt(key.normal_n));
        cells.push(',');
    }
    if axes.amplitudes {
        cells.push_str(&opt(key.amplitude_um));
        cells.push(',');
    }
    cells
}

/// A finished case as the outputs see it: its identity and spec, what its
/// worker recorded, and its scalars after K_E calibration (the run's
/// `calibrate` makes them from the plan and the journal).
pub struct Row<'a> {
    /// The case.
    pub key: &'a CaseKey,
    /// Its spec.
    pub spec: &'a CaseSpec,
    /// `ok`, `not_converged` or `failed`.
    pub status: Status,
    /// Solve wall time in the worker, s.
    pub seconds: f64,
    /// Worker that solved it.
    pub worker: u32,
    /// With `[stress]`: the worker's stress scalars.
    pub stress: Option<&'a StressScalars>,
    /// Scalars with the final μa and K_E.
    pub scalars: Option<CaseScalars>,
}

/// Text of `results.csv` (with [`INDENTER_COLUMN`] in a sweep over balls).
pub fn results_csv(rows: &[Row]) -> String {
    let axes = Axes::of(rows.iter().map(|r| r.key));
    let stress = rows.iter().any(|r| r.stress.is_some());
    let plastic = rows.iter().any(|r| r.spec.limits().hardness.is_some());
    let mut out = header_with_axes(RESULTS_HEADER, axes);
    if plastic {
        out.push(',');
        out.push_str(RESULTS_PLASTIC_COLUMNS);
    }
    if stress {
        out.push(',');
        out.push_str(RESULTS_STRESS_COLUMNS);
    }
    out.push('\n');
    for r in rows {
        let s = r.scalars.as_ref();
        let f = |g: fn(&CaseScalars) -> f64| opt(s.map(g));
        let i = |g: fn(&CaseScalars) -> usize| s.map(|s| g(s).to_string()).unwrap_or_default();
        let _ = write!(
            out,
            "{}{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3},{},{},{},{},{},{},{},{}",
            identity_cells(r.key, axes),
            fmt_f64(r.spec.load.angle_deg),
            r.status,
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
            r.seconds,
            r.worker,
            r.key.level,
            r.spec.grid.n,
            fmt_f64(r.spec.grid.dx),
            opt(s.and_then(|s| s.mu_a_cells)),
            f(|s| s.k_e_cells),
            f(|s| s.contact_radius_cells_m),
            f(|s| s.stick_radius_cells_m),
        );
        if plastic {
            out.push(',');
            out.push_str(&plastic_cells(s.and_then(|s| s.plastic.as_ref())));
        }
        if stress {
            out.push(',');
            out.push_str(&stress_cells(r.stress));
        }
        out.push('\n');
    }
    out
}

pub(super) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// One point of a μa-versus-angle curve: a material × surface × angle
/// (× ball in a sweep over balls), from every level of its ladder (one level without a ladder).
#[derive(Clone, Debug)]
pub struct CurvePoint {
    /// The point's key (level 0).
    pub key: CaseKey,
    /// μa: best value and error bar over the levels.
    pub mu_a: Estimate,
    /// K_E: the same.
    pub k_e: Estimate,
    /// μa on each level, coarsest first.
    pub mu_a_by_level: Vec<f64>,
    /// μa with the paper's radii on the finest level.
    pub mu_a_cells: Option<f64>,
    /// A flat-surface case whose K_E was calibrated on itself (anisotropic
    /// material): its K_E(ψ) is the calibration curve.
    pub flat_calibration: bool,
    /// Energy dissipated per load cycle (cases with a `[history]` that
    /// closes a cycle), J: best value and error bar over the levels.
    pub dissipated: Option<Estimate>,
    /// With `[stress]`: the finest level's stress scalars.
    pub stress: Option<StressScalars>,
    /// On a surface with a hardness: the finest level's plastic zone.
    pub plastic: Option<solver::PlasticScalars>,
    /// With a wear law: the finest level's worn volume over the path (m³)
    /// and largest worn depth (m).
    pub wear: Option<(f64, f64)>,
}

/// The curve points of `rows`: each material × surface × angle whose
/// `levels` cases all solved, converged and have a μa. The second value
/// counts the points left out because a level did not.
pub fn curve_points(rows: &[Row], levels: usize) -> (Vec<CurvePoint>, usize) {
    let mut by_point: BTreeMap<String, (CaseKey, Vec<&Row>)> = BTreeMap::new();
    for r in rows {
        let key = r.key.point();
        by_point
            .entry(key.to_string())
            .or_insert_with(|| (key, Vec::new()))
            .1
            .push(r);
    }
    let (mut points, mut incomplete) = (Vec::new(), 0);
    for (_, (key, mut rs)) in by_point {
        rs.sort_by_key(|r| r.key.level);
        // (cell size, scalars) of every level that solved and converged.
        let solved: Vec<(f64, &CaseScalars)> = rs
            .iter()
            .filter(|r| r.status == Status::Ok)
            .filter_map(|r| Some((r.spec.grid.dx, r.scalars.as_ref()?)))
            .collect();
        if solved.len() != levels {
            incomplete += 1;
            continue;
        }
        // No tangential load, no μa: not a curve point, and nothing missing.
        let Some(mu_a_by_level) = solved
            .iter()
            .map(|(_, s)| s.mu_a)
            .collect::<Option<Vec<f64>>>()
        else {
            continue;
        };
        // The estimate over the levels of one scalar (None if a level lacks it).
        let over_levels = |value: &dyn Fn(&CaseScalars) -> Option<f64>| {
            let pairs: Option<Vec<(f64, f64)>> =
                solved.iter().map(|&(h, s)| Some((h, value(s)?))).collect();
            estimate(&pairs?)
        };
        let (Some(mu_a), Some(k_e)) = (over_levels(&|s| s.mu_a), over_levels(&|s| Some(s.k_e)))
        else {
            continue;
        };
        let (_, finest) = solved[solved.len() - 1];
        let dissipated = over_levels(&|s| s.history.as_ref()?.dissipated_energy_per_cycle_j);
        points.push(CurvePoint {
            key,
            mu_a,
            k_e,
            mu_a_by_level,
            mu_a_cells: finest.mu_a_cells,
            flat_calibration: rs[0].spec.surface == solver::Surface::Flat
                && finest.k_e_source == solver::K_E_FLAT_CALIBRATED,
            dissipated,
            plastic: finest.plastic,
            wear: finest
                .history
                .as_ref()
                .and_then(|h| Some((h.worn_volume_m3?, h.worn_depth_max_m?))),
            stress: rs
                .iter()
                .rev()
                .find(|r| r.status == Status::Ok)
                .and_then(|r| r.stress.cloned()),
        });
    }
    (points, incomplete)
}

/// Columns `curves.csv` gains when the sweep has a load history.
pub const CURVES_HISTORY_COLUMNS: &str = "dissipated_j,dissipated_j_err";

/// Columns `curves.csv` gains when the sweep's path wears the surface
/// (the finest level's).
pub const CURVES_WEAR_COLUMNS: &str = "worn_volume_m3,worn_depth_max_m";

/// Text of `curves.csv` (with [`INDENTER_COLUMN`] in a sweep over balls,
/// and [`CURVES_HISTORY_COLUMNS`] when any point has a dissipated energy
/// per cycle).
pub fn curves_csv(points: &[CurvePoint]) -> String {
    let history = points.iter().any(|p| p.dissipated.is_some());
    let stress = points.iter().any(|p| p.stress.is_some());
    let plastic = points.iter().any(|p| p.plastic.is_some());
    let wear = points.iter().any(|p| p.wear.is_some());
    let axes = Axes::of(points.iter().map(|p| &p.key));
    let mut out = header_with_axes(CURVES_HEADER, axes);
    if history {
        out.push(',');
        out.push_str(CURVES_HISTORY_COLUMNS);
    }
    if wear {
        out.push(',');
        out.push_str(CURVES_WEAR_COLUMNS);
    }
    if plastic {
        out.push(',');
        out.push_str(CURVES_PLASTIC_COLUMNS);
    }
    if stress {
        out.push(',');
        out.push_str(CURVES_STRESS_COLUMNS);
    }
    out.push('\n');
    for p in points {
        let by_level: Vec<String> = p.mu_a_by_level.iter().map(|&v| fmt_f64(v)).collect();
        let _ = write!(
            out,
            "{}{},{},{},{},{},{},{},{},{}",
            identity_cells(&p.key, axes),
            fmt_f64(p.key.angle_deg),
            fmt_f64(p.mu_a.value),
            opt(p.mu_a.err),
            fmt_f64(p.k_e.value),
            opt(p.k_e.err),
            p.mu_a.method.as_str(),
            opt(p.mu_a.order),
            by_level.join(";"),
            opt(p.mu_a_cells),
        );
        if history {
            let _ = write!(
                out,
                ",{},{}",
                opt(p.dissipated.as_ref().map(|d| d.value)),
                opt(p.dissipated.as_ref().and_then(|d| d.err)),
            );
        }
        if wear {
            let _ = write!(
                out,
                ",{},{}",
                opt(p.wear.map(|w| w.0)),
                opt(p.wear.map(|w| w.1))
            );
        }
        if plastic {
            let _ = write!(out, ",{}", opt(p.plastic.map(|s| s.plastic_area_m2)));
        }
        if stress {
            let s = p.stress.as_ref();
            let worst = |f: fn(
                &solver::stress_summary::StateScalars,
            ) -> Option<solver::stress_summary::Located>| {
                opt(s.and_then(|s| s.worst(f)).map(|l| l.over_p_h))
            };
            let _ = write!(
                out,
                ",{},{},{},{}",
                worst(|st| Some(st.max_von_mises)),
                worst(|st| Some(st.max_tresca)),
                worst(|st| st.surface_peak_along_force),
                opt(s.map(|s| s.swt.value_pa)),
            );
        }
        out.push('\n');
    }
    out
}

/// What `summary.json` says of one material × surface (× ball) curve.
#[derive(Clone, Debug, Serialize)]
pub struct CurveSummary {
    /// Points on the curve.
    pub points: usize,
    /// Smallest and largest μa over angle.
    pub mu_a_min: f64,
    /// See `mu_a_min`.
    pub mu_a_max: f64,
    /// Largest error bar on the curve (None without a ladder).
    pub mu_a_err_max: Option<f64>,
    /// Whether μa varies with the angle beyond its error: max − min exceeds
    /// the sum of the error bars at the two extremes (None without a ladder
    /// or with one angle).
    pub resolved: Option<bool>,
    /// With `[stress]`: the smallest and largest over angle of the
    /// largest von Mises stress over p_H (worst state of each case).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_von_mises_over_p_h_range: Option<[f64; 2]>,
    /// With `[stress]`: the angle of the largest of those, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_von_mises_worst_angle_deg: Option<f64>,
    /// With `[stress]`: the smallest and largest SWT over angle, Pa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub swt_range_pa: Option<[f64; 2]>,
}

/// A curve: material, and the surface's name in the figure's legend and
/// summary.json (`flat`, or `flat @ steel` in a sweep over balls).
type CurveId<'a> = (&'a str, String);

/// The curve points of each material × surface (× ball), keyed by
/// (material, surface label), sorted by angle: the one grouping behind
/// `summary.json`'s curves and the figure.
fn by_curve(points: &[CurvePoint]) -> BTreeMap<CurveId<'_>, Vec<&CurvePoint>> {
    let mut m: BTreeMap<CurveId<'_>, Vec<&CurvePoint>> = BTreeMap::new();
    for p in points {
        let mut surface = match &p.key.indenter {
            Some(ball) => format!("{} @ {ball}", p.key.surface),
            None => p.key.surface.clone(),
        };
        if let Some(n) = p.key.normal_n {
            surface.push_str(&format!(" @ {n} N"));
        }
        if let Some(a) = p.key.amplitude_um {
            surface.push_str(&format!(" @ {a} µm"));
        }
        m.entry((p.key.material.as_str(), surface))
            .or_default()
            .push(p);
    }
    for v in m.values_mut() {
        v.sort_by(|a, b| a.key.angle_deg.total_cmp(&b.key.angle_deg));
    }
    m
}

/// Per material × surface ("material / surface", "material / surface @
/// ball" in a sweep over balls): range of μa over angle, its error and
/// whether the variation is resolved.
pub fn curve_summaries(points: &[CurvePoint]) -> BTreeMap<String, CurveSummary> {
    let mut out = BTreeMap::new();
    for ((material, surface), pts) in by_curve(points) {
        let value = |p: &&CurvePoint| p.mu_a.value;
        let lo = pts.iter().min_by(|a, b| value(a).total_cmp(&value(b)));
        let hi = pts.iter().max_by(|a, b| value(a).total_cmp(&value(b)));
        let (Some(lo), Some(hi)) = (lo, hi) else {
            continue;
        };
        let errs: Option<Vec<f64>> = pts.iter().map(|p| p.mu_a.err).collect();
        let resolved = match (lo.mu_a.err, hi.mu_a.err) {
            (Some(el), Some(eh)) if pts.len() > 1 => Some(hi.mu_a.value - lo.mu_a.value > el + eh),
            _ => None,
        };
        // Over angle, of every point's stress scalars (None without them).
        let range = |f: &dyn Fn(&solver::stress_summary::StressScalars) -> Option<f64>| {
            let v: Option<Vec<(f64, f64)>> = pts
                .iter()
                .map(|p| Some((f(p.stress.as_ref()?)?, p.key.angle_deg)))
                .collect();
            let v = v.filter(|v| !v.is_empty())?;
            let lo = v.iter().map(|x| x.0).fold(f64::INFINITY, f64::min);
            let hi =
                v.iter().copied().fold(
                    (f64::NEG_INFINITY, 0.0),
                    |b, x| {
                        if x.0 > b.0 {
                            x
                        } else {
                            b
                        }
                    },
                );
            Some(([lo, hi.0], hi.1))
        };
        let vm = range(&|s| s.worst(|st| Some(st.max_von_mises)).map(|l| l.over_p_h));
        let swt = range(&|s| Some(s.swt.value_pa));
        out.insert(
            format!("{material} / {surface}"),
            CurveSummary {
                points: pts.len(),
                mu_a_min: lo.mu_a.value,
                mu_a_max: hi.mu_a.value,
                mu_a_err_max: errs.map(|e| e.into_iter().fold(0.0, f64::max)),
                resolved,
                max_von_mises_over_p_h_range: vm.map(|v| v.0),
                max_von_mises_worst_angle_deg: vm.map(|v| v.1),
                swt_range_pa: swt.map(|v| v.0),
            },
        );
    }
    out
}

/// One panel of the sweep's figure: named series of (angle, value, error).
struct Panel {
    title: String,
    y_desc: &'static str,
    series: BTreeMap<String, Vec<(f64, f64, Option<f64>)>>,
}

/// One panel per material, titled "material: `what`", of `value` (y and
/// its error bar) against the angle, a curve per surface of the points
/// that have one; none for a material without any.
fn panels_of(
    points: &[CurvePoint],
    what: &str,
    y_desc: &'static str,
    value: impl Fn(&CurvePoint) -> Option<(f64, Option<f64>)>,
) -> Vec<Panel> {
    let mut panels: BTreeMap<&str, Panel> = BTreeMap::new();
    for ((material, surface), pts) in by_curve(points) {
        let series: Vec<(f64, f64, Option<f64>)> = pts
            .iter()
            .filter_map(|p| {
                let (y, err) = value(p)?;
                Some((p.key.angle_deg, y, err))
            })
            .collect();
        if !series.is_empty() {
            panels
                .entry(material)
                .or_insert_with(|| Panel {
                    title: format!("{material}: {what}"),
                    y_desc,
                    series: BTreeMap::new(),
                })
                .series
                .insert(surface, series);
        }
    }
    panels.into_values().collect()
}

/// Draw μa versus angle to `path` (PNG or SVG by extension): one panel per
/// material, one series per surface with markers at the computed angles
/// and error bars where a ladder gave them, the flat surface in black; and,
/// when a material's K_E was calibrated on its flat surface, a panel of
/// K_E(ψ) (GPa) for those materials; on a surface with a hardness, a panel
/// per material of the area at the hardness (mm²); with `[stress]`, a panel
/// per material of the largest von Mises stress over p_H. The legend sits
/// beside the panels.
pub fn plot_curves(path: &Path, points: &[CurvePoint]) -> anyhow::Result<()> {
    let mut by_material: BTreeMap<&str, Panel> = BTreeMap::new();
    let mut k_e = Panel {
        title: "K_E(ψ), flat-surface calibration".into(),
        y_desc: "K_E (GPa)",
        series: BTreeMap::new(),
    };
    for ((material, surface), pts) in by_curve(points) {
        let panel = by_material.entry(material).or_insert_with(|| Panel {
            title: material.to_string(),
            y_desc: "apparent friction μa (–)",
            series: BTreeMap::new(),
        });
        let mu = pts
            .iter()
            .map(|p| (p.key.angle_deg, p.mu_a.value, p.mu_a.err));
        panel.series.insert(surface, mu.collect());
        if pts.iter().all(|p| p.flat_calibration) {
            let gpa = |v: f64| v / 1e9;
            let ke = pts
                .iter()
                .map(|p| (p.key.angle_deg, gpa(p.k_e.value), p.k_e.err.map(gpa)));
            let name = match &pts[0].key.indenter {
                Some(ball) => format!("{material} @ {ball}"),
                None => material.to_string(),
            };
            k_e.series.insert(name, ke.collect());
        }
    }
    // Energy per cycle (load histories), in μJ; with a wear law, the worn
    // volume over the path, in µm³; with [stress], the largest von Mises
    // stress over p_H: one panel per material each.
    let uj = |v: f64| v * 1e6;
    let energy = panels_of(
        points,
        "energy per cycle",
        "dissipated per cycle (μJ)",
        |p| {
            let d = p.dissipated.as_ref()?;
            Some((uj(d.value), d.err.map(uj)))
        },
    );
    let worn = panels_of(
        points,
        "worn volume",
        "worn volume over the path (μm³)",
        |p| Some((p.wear?.0 * 1e18, None)),
    );
    let stress = panels_of(
        points,
        "largest von Mises stress",
        "max von Mises / p_H (–)",
        |p| {
            let l = p.stress.as_ref()?.worst(|st| Some(st.max_von_mises))?;
            Some((l.over_p_h, None))
        },
    );
    // On a surface with a hardness: the area at the cap, in mm².
    let plastic = panels_of(points, "area at the hardness", "plastic area (mm²)", |p| {
        Some((p.plastic?.plastic_area_m2 * 1e6, None))
    });
    let mut panels: Vec<Panel> = by_material.into_values().collect();
    panels.extend(energy);
    panels.extend(worn);
    panels.extend(plastic);
    panels.extend(stress);
    if !k_e.series.is_empty() {
        panels.push(k_e);
    }
    let layout = Panels {
        count: panels.len(),
        legend: 180,
    };
    plot::write(path, layout.size(), &Curves { panels, layout })
}

/// The sweep's figure: its panels in their grid beside the legend.
struct Curves {
    panels: Vec<Panel>,
    layout: Panels,
}

impl Figure for Curves {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> anyhow::Result<()> {
        let panels = &self.panels;
        // One colour and marker per series name, the same in every panel; flat black.
        let names: Vec<&str> = {
            let mut v: Vec<&str> = panels
                .iter()
                .flat_map(|p| p.series.keys().map(String::as_str))
                .collect();
            v.sort();
            v.dedup();
            v
        };
        let style_of = |name: &str| -> (RGBAColor, usize) {
            let k = names.iter().position(|s| *s == name).unwrap_or(0);
            if name == "flat" {
                (BLACK.to_rgba(), 0)
            } else {
                (PALETTE[k % PALETTE.len()].to_rgba(), k % 3)
            }
        };
        let (areas, legend_area) = self.layout.split(root);
        for (panel, area) in panels.iter().zip(areas.iter()) {
            let (mut lo, mut hi, mut xlo, mut xhi) = (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            );
            for &(x, y, err) in panel.series.values().flatten() {
                let err = err.unwrap_or(0.0);
                lo = lo.min(y - err);
                hi = hi.max(y + err);
                xlo = xlo.min(x);
                xhi = xhi.max(x);
            }
            if !lo.is_finite() {
                (lo, hi, xlo, xhi) = (0.0, 1.0, 0.0, 180.0);
            }
            let pad = ((hi - lo) * 0.08).max(1e-3 * hi.abs().max(1.0));
            if xhi <= xlo {
                (xlo, xhi) = (xlo - 1.0, xhi + 1.0);
            }
            let xpad = (xhi - xlo) * 0.03;
            let frame = Frame {
                title: 20,
                margin: 10,
                labels: (40, 60),
            };
            let mut chart = frame.chart(
                area,
                &panel.title,
                (xlo - xpad)..(xhi + xpad),
                (lo - pad)..(hi + pad),
            )?;
            chart
                .configure_mesh()
                .x_desc("force angle ψ (deg)")
                .y_desc(panel.y_desc)
                .x_label_formatter(&|x| format!("{x:.0}"))
                .draw()
                .map_err(err)?;
            for (name, pts) in &panel.series {
                let (color, marker) = style_of(name);
                let line: Vec<(f64, f64)> = pts.iter().map(|p| (p.0, p.1)).collect();
                chart
                    .draw_series(LineSeries::new(line.iter().copied(), color.stroke_width(2)))
                    .map_err(err)?;
                let style = color.filled();
                match marker {
                    0 => chart
                        .draw_series(line.iter().map(|&c| Circle::new(c, 4, style)))
                        .map(|_| ()),
                    1 => chart
                        .draw_series(line.iter().map(|&c| TriangleMarker::new(c, 5, style)))
                        .map(|_| ()),
                    _ => chart
                        .draw_series(
                            line.iter()
                                .map(|&c| Cross::new(c, 5, color.stroke_width(2))),
                        )
                        .map(|_| ()),
                }
                .map_err(err)?;
                chart
                    .draw_series(pts.iter().filter_map(|&(x, y, err)| {
                        let err = err.filter(|&v| v > 0.0)?;
                        Some(ErrorBar::new_vertical(
                            x,
                            y - err,
                            y,
                            y + err,
                            color.stroke_width(1),
                            6,
                        ))
                    }))
                    .map_err(err)?;
            }
        }
        // The legend beside the panels, never over the data.
        for (k, name) in names.iter().enumerate() {
            let (color, marker) = style_of(name);
            let y = 30 + 24 * k as i32;
            legend_area
                .draw(&PathElement::new(
                    vec![(10, y), (40, y)],
                    color.stroke_width(3),
                ))
                .map_err(err)?;
            let style = color.filled();
            match marker {
                0 => legend_area.draw(&Circle::new((25, y), 4, style)),
                1 => legend_area.draw(&TriangleMarker::new((25, y), 5, style)),
                _ => legend_area.draw(&Cross::new((25, y), 5, color.stroke_width(2))),
            }
            .map_err(err)?;
            legend_area
                .draw(&Text::new(
                    name.to_string(),
                    (48, y - 8),
                    ("sans-serif", 16),
                ))
                .map_err(err)?;
        }
        Ok(())
    }
}

/// Directory of a case's fields: `fields/<material>/<surface>/<angle>`
/// (`fields/Cu/flat/015.0`), `<angle>@<ball>` in a sweep over balls
/// (`fields/Cu/flat/015.0@steel`, the display text's last part), each
/// component made file-name safe; ladder level k > 0 under `L<k>`.
pub fn fields_dir(out_dir: &Path, key: &CaseKey) -> PathBuf {
    let mut p = out_dir.join("fields");
    let safe = |part: &str| -> String {
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
        if safe.is_empty() || safe == "." || safe == ".." {
            "_".to_string()
        } else {
            safe
        }
    };
    p.push(safe(&key.material));
    p.push(safe(&key.surface));
    let axes = key.axes_text();
    match &key.indenter {
        Some(ball) => p.push(format!("{}@{}{axes}", key.angle_text(), safe(ball))),
        None => p.push(format!("{}{axes}", key.angle_text())),
    }
    // Level 0 keeps the directory it had before ladders existed.
    if key.level > 0 {
        p.push(format!("L{}", key.level));
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
        super::npy::write_npy(&dir.join(format!("{name}.npy")), n, &data)?;
    }
    Ok(())
}

/// With `[stress]` and fields: the stress arrays and maps of a case under
/// `fields/<case>/stress/` (the layout of `mpcontact solve`'s `stress/`),
/// recomputed here from the returned tractions with the function the
/// worker ran. A load history's turning states do not travel with the
/// fields: for those (`stress.states = "last_cycle"` or `"turning"`)
/// nothing is written and the returned note says so.
pub fn write_stress_fields(
    out_dir: &Path,
    key: &CaseKey,
    spec: &solver::CaseSpec,
    cfg: &crate::config::StressCfg,
    scalars: &CaseScalars,
    (names, field_bytes): (&[String], &[u8]),
) -> anyhow::Result<Option<String>> {
    if spec.history.is_some() && cfg.chosen_states() != solver::stress_summary::StressStates::Final
    {
        return Ok(Some(format!(
            "{key}: stress fields of a load history's turning states are not written by sweeps (its scalars are); `mpcontact solve` writes them"
        )));
    }
    let n = spec.grid.n;
    let get = |name: &str| -> anyhow::Result<Vec<f64>> {
        let k = names
            .iter()
            .position(|f| f == name)
            .ok_or_else(|| anyhow::anyhow!("no field {name}"))?;
        Ok(protocol::read_field(field_bytes, k, n * n)
            .ok_or_else(|| anyhow::anyhow!("field {name} missing"))?
            .into_owned())
    };
    let fields = solver::Fields {
        n,
        p: get("p")?,
        qx: get("qx")?,
        qy: get("qy")?,
        ..Default::default()
    };
    let so = super::stress::compute(cfg, spec, scalars, &fields, &[])?;
    let title = format!("{}, {}, ψ = {}°", key.material, key.surface, key.angle_deg);
    let warnings = super::stress::write(&fields_dir(out_dir, key), &so, &title)?;
    Ok((!warnings.is_empty()).then(|| format!("{key}: {}", warnings.join("; "))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_dir_is_safe() {
        let d = fields_dir(Path::new("/o"), &CaseKey::new("Cu(111)", "..", 45.0));
        assert_eq!(d, Path::new("/o/fields/Cu(111)/_/045.0"));
        let ball = CaseKey::new("Cu", "flat", 15.0).with_indenter("../x");
        assert_eq!(
            fields_dir(Path::new("/o"), &ball),
            Path::new("/o/fields/Cu/flat/015.0@.._x")
        );
        assert_eq!(
            fields_dir(Path::new("/o"), &ball.with_indenter("steel").at_level(1)),
            Path::new("/o/fields/Cu/flat/015.0@steel/L1")
        );
    }
}
