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
/// Since issue #59 `contact_radius_m` and `stick_radius_m` are the zones'
/// own radii (their outlines) and μa's apparent radii are
/// `mu_a_contact_radius_m`, `mu_a_stick_radius_m` (docs/config.md,
/// "Renamed in round 5"); `pressure_hertz_misfit` says how far the
/// pressure is from Hertz's and `mu_a_non_hertz` flags μa beyond
/// [`solver::HERTZ_MISFIT_LIMIT`].
pub const RESULTS_HEADER: &str = "material,surface,angle_deg,status,mu_a,k_e,contact_radius_m,stick_radius_m,delta_t_m,delta_z_m,p_max_pa,contact_area_m2,stick_area_m2,normal_iterations,tangential_iterations,coupling_iterations,seconds,worker,level,grid_points,spacing_m,mu_a_cells,k_e_cells,contact_radius_cells_m,stick_radius_cells_m,mu_a_contact_radius_m,mu_a_stick_radius_m,pressure_hertz_misfit,mu_a_non_hertz";
/// Header of `curves.csv` (`pressure_hertz_misfit` and `mu_a_non_hertz`
/// of the finest level's case).
pub const CURVES_HEADER: &str =
    "material,surface,angle_deg,mu_a,mu_a_err,k_e,k_e_err,method,order,mu_a_by_level,mu_a_cells,pressure_hertz_misfit,mu_a_non_hertz";
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
            "{}{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3},{},{},{},{},{},{},{},{},{},{},{},{}",
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
            f(|s| s.mu_a_contact_radius_m),
            f(|s| s.mu_a_stick_radius_m),
            f(|s| s.pressure_hertz_misfit),
            flag(s.and_then(CaseScalars::mu_a_non_hertz)),
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

/// The text of a flag: `true`, `false`, empty when there is none.
fn flag(v: Option<bool>) -> String {
    v.map(|b| b.to_string()).unwrap_or_default()
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
    /// The finest level's `pressure_hertz_misfit`.
    pub hertz_misfit: f64,
    /// The finest level's `mu_a_non_hertz`: μa on a pressure further from
    /// Hertz's than [`solver::HERTZ_MISFIT_LIMIT`].
    pub non_hertz: bool,
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
/// holds the keys (level 0) of the points left out because a level did
/// not: the figure marks them.
pub fn curve_points(rows: &[Row], levels: usize) -> (Vec<CurvePoint>, Vec<CaseKey>) {
    let mut by_point: BTreeMap<String, (CaseKey, Vec<&Row>)> = BTreeMap::new();
    for r in rows {
        let key = r.key.point();
        by_point
            .entry(key.to_string())
            .or_insert_with(|| (key, Vec::new()))
            .1
            .push(r);
    }
    let (mut points, mut incomplete) = (Vec::new(), Vec::new());
    for (_, (key, mut rs)) in by_point {
        rs.sort_by_key(|r| r.key.level);
        // (cell size, scalars) of every level that solved and converged.
        let solved: Vec<(f64, &CaseScalars)> = rs
            .iter()
            .filter(|r| r.status == Status::Ok)
            .filter_map(|r| Some((r.spec.grid.dx, r.scalars.as_ref()?)))
            .collect();
        if solved.len() != levels {
            incomplete.push(key);
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
            hertz_misfit: finest.pressure_hertz_misfit,
            non_hertz: finest.mu_a_non_hertz() == Some(true),
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
            "{}{},{},{},{},{},{},{},{},{},{},{}",
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
            fmt_f64(p.hertz_misfit),
            p.non_hertz,
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

/// The name of `key`'s curve in the figure's legend and summary.json: the
/// surface, with the ball, load and amplitude of the sweep's axes
/// (`flat @ steel @ 6000 N`).
fn curve_label(key: &CaseKey) -> String {
    let mut surface = match &key.indenter {
        Some(ball) => format!("{} @ {ball}", key.surface),
        None => key.surface.clone(),
    };
    if let Some(n) = key.normal_n {
        surface.push_str(&format!(" @ {} N", fmt_f64(n)));
    }
    if let Some(a) = key.amplitude_um {
        surface.push_str(&format!(" @ {} µm", fmt_f64(a)));
    }
    surface
}

/// The curve points of each material × surface (× ball), keyed by
/// (material, surface label), sorted by angle: the one grouping behind
/// `summary.json`'s curves and the figure.
fn by_curve(points: &[CurvePoint]) -> BTreeMap<CurveId<'_>, Vec<&CurvePoint>> {
    let mut m: BTreeMap<CurveId<'_>, Vec<&CurvePoint>> = BTreeMap::new();
    for p in points {
        m.entry((p.key.material.as_str(), curve_label(&p.key)))
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

/// One panel of the sweep's figure: named series of (angle, value, error);
/// the points whose μa is flagged (`mu_a_non_hertz`), ringed; and per
/// series the angles without a result (failed or not converged), crossed
/// on the panel's floor.
#[derive(Default)]
struct Panel {
    title: String,
    y_desc: String,
    series: BTreeMap<String, Vec<(f64, f64, Option<f64>)>>,
    flagged: Vec<(String, f64, f64)>,
    missing: BTreeMap<String, Vec<f64>>,
}

/// `panels` (one quantity, values in the SI unit `base` to the `power`)
/// in the one unit that makes the largest of them read 1–1000
/// ([`plot::Unit`]), their y axis `what (unit)`.
fn in_unit(mut panels: Vec<Panel>, what: &str, base: &str, power: i32) -> Vec<Panel> {
    let largest = panels
        .iter()
        .flat_map(|p| p.series.values().flatten())
        .fold(0.0_f64, |m, &(_, y, e)| m.max(y.abs() + e.unwrap_or(0.0)));
    let u = plot::Unit::for_largest(base, power, largest);
    for p in &mut panels {
        p.y_desc = format!("{what} ({})", u.text);
        for (_, y, e) in p.series.values_mut().flatten() {
            *y *= u.factor;
            *e = e.map(|e| e * u.factor);
        }
    }
    panels
}

/// One panel per material, titled "material: `what`", of `value` (y and
/// its error bar) against the angle, a curve per surface of the points
/// that have one; none for a material without any.
fn panels_of(
    points: &[CurvePoint],
    what: &str,
    y_desc: &str,
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
                    y_desc: y_desc.to_string(),
                    ..Default::default()
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
/// per material whose K_E was calibrated on its flat surface, a panel of
/// that K_E(ψ) (its series the flat surface's, so that every line of the
/// figure is a surface of the one legend); on a surface with a hardness, a
/// panel per material of the area at the hardness; with `[stress]`, a panel
/// per material of the largest von Mises stress over p_H. Units read
/// 1–1000 ([`plot::Unit`]). The legend sits beside the panels, or in the
/// last row's empty cell. A μa on a pressure that is not Hertz's
/// (`mu_a_non_hertz`) is ringed; the `missing` points (failed or not
/// converged, [`curve_points`]) are crossed on the floor of their
/// material's μa panel, so that a curve without them says so (#59).
pub fn plot_curves(path: &Path, points: &[CurvePoint], missing: &[CaseKey]) -> anyhow::Result<()> {
    let mut by_material: BTreeMap<&str, Panel> = BTreeMap::new();
    let mu_a_panel = |material: &str| Panel {
        title: material.to_string(),
        y_desc: "apparent friction μa (–)".into(),
        ..Default::default()
    };
    for ((material, surface), pts) in by_curve(points) {
        let panel = by_material
            .entry(material)
            .or_insert_with(|| mu_a_panel(material));
        let mu = pts
            .iter()
            .map(|p| (p.key.angle_deg, p.mu_a.value, p.mu_a.err));
        panel.flagged.extend(
            pts.iter()
                .filter(|p| p.non_hertz)
                .map(|p| (surface.clone(), p.key.angle_deg, p.mu_a.value)),
        );
        panel.series.insert(surface, mu.collect());
    }
    let k_e = panels_of(points, "K_E(ψ), flat-surface calibration", "", |p| {
        p.flat_calibration.then_some((p.k_e.value, p.k_e.err))
    });
    // Energy per cycle (load histories); with a wear law, the worn volume
    // over the path; with [stress], the largest von Mises stress over p_H:
    // one panel per material each.
    let energy = panels_of(points, "energy per cycle", "", |p| {
        let d = p.dissipated.as_ref()?;
        Some((d.value, d.err))
    });
    let worn = panels_of(points, "worn volume", "", |p| Some((p.wear?.0, None)));
    let stress = panels_of(
        points,
        "largest von Mises stress",
        "max von Mises / p_H (–)",
        |p| {
            let l = p.stress.as_ref()?.worst(|st| Some(st.max_von_mises))?;
            Some((l.over_p_h, None))
        },
    );
    // On a surface with a hardness: the area at the cap.
    let plastic = panels_of(points, "area at the hardness", "", |p| {
        Some((p.plastic?.plastic_area_m2, None))
    });
    for key in missing {
        let panel = by_material
            .entry(key.material.as_str())
            .or_insert_with(|| mu_a_panel(&key.material));
        let label = curve_label(key);
        panel.series.entry(label.clone()).or_default();
        panel.missing.entry(label).or_default().push(key.angle_deg);
    }
    let mut panels: Vec<Panel> = by_material.into_values().collect();
    panels.extend(in_unit(energy, "dissipated per cycle", "J", 1));
    panels.extend(in_unit(worn, "worn volume over the path", "m", 3));
    panels.extend(in_unit(plastic, "plastic area", "m", 2));
    panels.extend(stress);
    panels.extend(in_unit(k_e, "K_E", "Pa", 1));
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
            for &x in panel.missing.values().flatten() {
                xlo = xlo.min(x);
                xhi = xhi.max(x);
            }
            if !lo.is_finite() {
                (lo, hi) = (0.0, 1.0);
            }
            if !xlo.is_finite() {
                (xlo, xhi) = (0.0, 180.0);
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
                // Room below the data for a row of crosses per curve with
                // angles missing, so that one never hides another.
                (lo - pad * (1.0 + 0.6 * panel.missing.len().saturating_sub(1) as f64))..(hi + pad),
            )?;
            plot::axes(&mut chart, "force angle ψ (deg)", &panel.y_desc, true)?;
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
            // Flagged μa ringed; angles without a result crossed on the floor.
            for (name, x, y) in &panel.flagged {
                let (color, _) = style_of(name);
                chart
                    .draw_series(std::iter::once(Circle::new(
                        (*x, *y),
                        9,
                        color.stroke_width(2),
                    )))
                    .map_err(err)?;
            }
            for (k, (name, angles)) in panel.missing.iter().enumerate() {
                let (color, _) = style_of(name);
                let floor = lo - pad * (0.5 + 0.6 * k as f64);
                chart
                    .draw_series(
                        angles
                            .iter()
                            .map(|&x| Cross::new((x, floor), 7, color.stroke_width(3))),
                    )
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
        // What the rings and the floor's crosses mean, under the legend.
        let mut y = 30 + 24 * names.len() as i32 + 12;
        let grey = BLACK.mix(0.7);
        let note = |y: i32, lines: &[&str]| -> anyhow::Result<()> {
            for (k, line) in lines.iter().enumerate() {
                legend_area
                    .draw(&Text::new(
                        line.to_string(),
                        (48, y - 8 + 16 * k as i32),
                        ("sans-serif", 14),
                    ))
                    .map_err(err)?;
            }
            Ok(())
        };
        if panels.iter().any(|p| !p.flagged.is_empty()) {
            legend_area
                .draw(&Circle::new((25, y), 9, grey.stroke_width(2)))
                .map_err(err)?;
            note(y, &["μa flagged: pressure", "not Hertz's (README)"])?;
            y += 40;
        }
        if panels.iter().any(|p| !p.missing.is_empty()) {
            legend_area
                .draw(&Cross::new((25, y), 7, grey.stroke_width(3)))
                .map_err(err)?;
            note(
                y,
                &["no result at this", "angle (failed or", "not converged)"],
            )?;
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
