//! Stresses below the surface of one solved case (`[stress]`, issue #38):
//! which states and where ([`compute`]), the scalars `case.json` carries
//! ([`StressScalars`]) and the files ([`write`]: `stress/*.npy` and PNG maps
//! with the contact edge marked). The stresses themselves are
//! `solver::stress`; nothing here changes a solve. Called by `solve`,
//! Python and the sweep's outputs (`sweep`); imports none of them.

use std::path::Path;

use anyhow::{anyhow, Result};
use solver::stress::{max_principal, tresca, von_mises, COMPONENTS};
pub use solver::stress_summary::{
    Located, StateScalars, StateStress, StressRequest, StressScalars, SwtScalars,
    CROSSLAND_DEFINITION, MAXIMA_DEFINITION, SWT_DEFINITION,
};
use solver::{CaseScalars, CaseSpec, Fields, TurningState};

use crate::config::StressCfg;
use crate::float_text::fmt_f64;

/// The stresses of a case ([`solver::stress_summary::CaseStress`]) and the
/// depths of its planes as configured (µm, for the file names).
pub struct StressOutput {
    /// The stresses, fields and scalars.
    pub case: solver::stress_summary::CaseStress,
    depths_um: Vec<f64>,
}

impl std::ops::Deref for StressOutput {
    type Target = solver::stress_summary::CaseStress;
    fn deref(&self) -> &Self::Target {
        &self.case
    }
}

/// A scalar of the stress tensor.
type Invariant = fn([f64; 6]) -> f64;

/// Computes the stresses `cfg` asks for on the states of a solved case
/// (see [`solver::stress_summary::compute`]).
pub fn compute(
    cfg: &StressCfg,
    spec: &CaseSpec,
    scalars: &CaseScalars,
    fields: &Fields,
    turning: &[TurningState],
) -> Result<StressOutput> {
    let case = solver::stress_summary::compute(&cfg.request(), spec, scalars, fields, turning)
        .map_err(|e| anyhow!("[stress]: {e}"))?;
    Ok(StressOutput {
        case,
        depths_um: cfg.depths_um.clone(),
    })
}

/// The derived maps written beside the six components.
const DERIVED: [(&str, Invariant); 3] = [
    ("von_mises", von_mises),
    ("tresca", tresca),
    ("s1", max_principal),
];

/// One array of the stresses of a case, as written to `stress/<name>.npy`.
pub struct StressArray {
    /// File stem (see [`write`]).
    pub name: String,
    /// Rows (y, or the depths of a slice).
    pub rows: usize,
    /// Columns (x, or along the slice's line).
    pub cols: usize,
    /// Row-major values, Pa.
    pub data: Vec<f64>,
}

/// Every array of `so` with its name: per state (suffix `_stepK` when
/// there are several) `plane_<z>um_<c>` (n x n, rows y, columns x) and
/// `slice_<along|across>_<c>` (rows = `slice_depths_m`, columns along the
/// line), `c` the six components (`sxx` … `sxy`), `von_mises`, `tresca`,
/// `s1`; with two states or more `plane_<z>um_crossland` and
/// `slice_<along|across>_crossland`; `surface_swt` (n x n, Smith–Watson–Topper
/// over the surface). The files of [`write`] and Python's
/// `Result.stress`.
pub fn arrays(so: &StressOutput) -> Vec<StressArray> {
    let mut out = Vec::new();
    each_array(so, |arr| {
        out.push(arr);
        Ok(())
    })
    .expect("collecting fails nowhere");
    out
}

/// [`arrays`] one at a time to `f` (the first error stops it): [`write`]
/// holds one array, not a copy of every state's fields.
fn each_array(so: &StressOutput, mut f: impl FnMut(StressArray) -> Result<()>) -> Result<()> {
    let n = so.grid.n;
    let rows = so.scalars.slice_depths_m.len();
    let many = so.states.len() > 1;
    let mut push = |name: String, rows: usize, data: Vec<f64>| {
        f(StressArray {
            name,
            rows,
            cols: n,
            data,
        })
    };
    for st in &so.states {
        let suffix = state_suffix(many, st.step);
        for (k, f) in st.planes.iter().enumerate() {
            let stem = format!("plane_{}um{suffix}", fmt_f64(so.depths_um[k]));
            for (c, name) in COMPONENTS.iter().enumerate() {
                push(format!("{stem}_{name}"), n, f.components[c].clone())?;
            }
            for (name, g) in DERIVED {
                push(format!("{stem}_{name}"), n, f.map(g))?;
            }
        }
        for (label, lines) in [("along", &st.along), ("across", &st.across)] {
            if lines.is_empty() {
                continue;
            }
            let stem = format!("slice_{label}{suffix}");
            for (c, name) in COMPONENTS.iter().enumerate() {
                let vals = lines.iter().flat_map(|f| f.components[c].clone()).collect();
                push(format!("{stem}_{name}"), rows, vals)?;
            }
            for (name, g) in DERIVED {
                push(
                    format!("{stem}_{name}"),
                    rows,
                    lines.iter().flat_map(|f| f.map(g)).collect(),
                )?;
            }
        }
    }
    for (k, f) in so.crossland_planes.iter().enumerate() {
        push(
            format!("plane_{}um_crossland", fmt_f64(so.depths_um[k])),
            n,
            f.clone(),
        )?;
    }
    if let Some([al, ac]) = &so.crossland_slices {
        push("slice_along_crossland".into(), rows, al.clone())?;
        push("slice_across_crossland".into(), rows, ac.clone())?;
    }
    push("surface_swt".into(), n, so.swt_surface.clone())
}

fn state_suffix(many: bool, step: Option<usize>) -> String {
    match (many, step) {
        (true, Some(k)) => format!("_step{k}"),
        _ => String::new(),
    }
}

/// Writes `stress/` under `dir`: every array of [`arrays`] as
/// `<name>.npy`, and von Mises PNG maps (over p_H) of every plane and
/// slice with the contact edge marked. Returns the warnings of maps that
/// could not be drawn (the numbers are written first).
pub fn write(dir: &Path, so: &StressOutput, title: &str) -> Result<Vec<String>> {
    let dir = dir.join("stress");
    std::fs::create_dir_all(&dir).map_err(|e| anyhow!("cannot create {}: {e}", dir.display()))?;
    each_array(so, |arr| {
        super::npy::write_npy_2d(
            &dir.join(format!("{}.npy", arr.name)),
            arr.rows,
            arr.cols,
            &arr.data,
        )
    })?;
    let n = so.grid.n;
    let many = so.states.len() > 1;
    let mut warnings = Vec::new();
    let a = so.contact_radius_m;
    let rows = so.scalars.slice_depths_m.len();
    let z_max = so.scalars.slice_depths_m.last().copied().unwrap_or(0.0);
    let mut draw = |file: String, heat: &super::maps::Heat| {
        if let Err(e) = super::maps::write_heat(&dir.join(&file), heat) {
            warnings.push(format!("{file} not drawn: {e:#}"));
        }
    };
    for st in &so.states {
        let suffix = state_suffix(many, st.step);
        for (k, f) in st.planes.iter().enumerate() {
            let stem = format!("plane_{}um{suffix}", fmt_f64(so.depths_um[k]));
            let norm: Vec<f64> = f.map(von_mises).iter().map(|v| v / so.p_h).collect();
            let marks = plane_edge(&so.grid, &st.p, a);
            let half = 0.5 * (n as f64 - 1.0);
            let ext = (so.grid.dx * half / a, so.grid.dy * half / a);
            let t = format!("{title}, z = {:.3} a{suffix}", so.depths_m[k] / a);
            draw(
                format!("{stem}_von_mises.png"),
                &super::maps::Heat {
                    title: &t,
                    label: "von Mises / p_H",
                    cols: n,
                    rows: n,
                    values: &norm,
                    x_range: (-ext.0, ext.0),
                    y_range: (-ext.1, ext.1),
                    axes: ("x / a", "y / a"),
                    marks: &marks,
                    light_marks: &[],
                },
            );
        }
        for (label, lines, line_is_row) in [
            ("along", &st.along, so.along_is_row),
            ("across", &st.across, !so.along_is_row),
        ] {
            if lines.is_empty() {
                continue;
            }
            let norm: Vec<f64> = lines
                .iter()
                .flat_map(|f| f.map(von_mises))
                .map(|v| v / so.p_h)
                .collect();
            let d = if line_is_row { so.grid.dx } else { so.grid.dy };
            let half = 0.5 * (n as f64 - 1.0) * d / a;
            let marks = line_edge(&so.grid, &st.p, so.centre, line_is_row, a);
            let t = format!("{title}, slice {label} the force{suffix}");
            draw(
                format!("slice_{label}{suffix}_von_mises.png"),
                &super::maps::Heat {
                    title: &t,
                    label: "von Mises / p_H",
                    cols: n,
                    rows,
                    values: &norm,
                    x_range: (-half, half),
                    y_range: (0.0, -z_max / a),
                    axes: (if line_is_row { "x / a" } else { "y / a" }, "-z / a"),
                    marks: &marks,
                    light_marks: &[],
                },
            );
        }
    }
    Ok(warnings)
}

/// Surface cells on the contact edge (in contact, a neighbour not), in units of a.
fn plane_edge(grid: &solver::Grid, p: &[f64], a: f64) -> Vec<(f64, f64)> {
    let n = grid.n;
    let mut marks = Vec::new();
    for iy in 1..n - 1 {
        for ix in 1..n - 1 {
            let i = iy * n + ix;
            if p[i] > 0.0 && [i - 1, i + 1, i - n, i + n].iter().any(|&j| p[j] <= 0.0) {
                marks.push((grid.x(ix) / a, grid.y(iy) / a));
            }
        }
    }
    marks
}

/// Where the line of a slice leaves contact at the surface, in units of a.
fn line_edge(
    grid: &solver::Grid,
    p: &[f64],
    (ix0, iy0): (usize, usize),
    row: bool,
    a: f64,
) -> Vec<(f64, f64)> {
    let n = grid.n;
    let at = |i: usize| if row { p[iy0 * n + i] } else { p[i * n + ix0] };
    let coord = |i: usize| if row { grid.x(i) } else { grid.y(i) };
    (1..n)
        .filter(|&i| (at(i) > 0.0) != (at(i - 1) > 0.0))
        .map(|i| (0.5 * (coord(i) + coord(i - 1)) / a, 0.0))
        .collect()
}
