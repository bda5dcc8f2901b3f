//! Stresses below the surface of one solved case (`[stress]`, issue #38):
//! which states and where ([`compute`]), the scalars `case.json` carries
//! ([`StressScalars`]) and the files ([`write`]: `stress/*.npy` and PNG maps
//! with the contact edge marked). The stresses themselves are
//! `solver::stress`; nothing here changes a solve.

use std::path::Path;

use anyhow::{anyhow, Result};
use serde::Serialize;
use solver::stress::{max_principal, tresca, von_mises, Line, StressField, StressPlan, COMPONENTS};
use solver::{CaseScalars, CaseSpec, Fields, TurningState};

use crate::config::StressCfg;
use crate::float_text::fmt_f64;

/// How the Crossland parameter is formed from the states computed.
pub const CROSSLAND_DEFINITION: &str = "Crossland: sqrt(J2,a) + alpha * sigma_H,max at every point computed (planes and slices), J2,a of the deviatoric amplitude taken as half the largest difference between two states' deviators (exact for two states, the extremes of a fretting cycle; with more, the smallest enclosing sphere's radius exceeds it by at most 2/sqrt(3) for three states and sqrt(5/3) for more), sigma_H,max the largest hydrostatic stress over the states; needs at least two states (a load history)";

/// Where the maxima are sought.
pub const MAXIMA_DEFINITION: &str = "maxima over the points computed: every plane of stress.depths_um and the two slices (the grid row and column through the cell nearest the pressure centroid; 'along' is the one nearer the force direction); the surface peak is the stress along the force direction, sigma_tt = sxx c^2 + syy s^2 + 2 sxy s c, on the top row of the 'along' slice";

/// A value and its place (m; z into the body).
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct Located {
    /// The value, Pa.
    pub value_pa: f64,
    /// The value over the Hertz pressure p_H.
    pub over_p_h: f64,
    /// x, y, z of the point, m.
    pub at_m: [f64; 3],
}

/// The scalars of one state.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct StateScalars {
    /// Increment of the load history (None: the case's only state).
    pub step: Option<usize>,
    /// Largest von Mises stress.
    pub max_von_mises: Located,
    /// Largest Tresca (maximum shear) stress.
    pub max_tresca: Located,
    /// Largest principal stress.
    pub max_principal: Located,
    /// Peak surface stress along the force direction (with slices).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_peak_along_force: Option<Located>,
}

/// What `case.json` carries under `stress`.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct StressScalars {
    /// One entry per state computed.
    pub states: Vec<StateScalars>,
    /// Crossland's parameter over the states (two or more).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crossland: Option<Located>,
    /// Crossland's α.
    pub crossland_alpha: f64,
    /// See [`CROSSLAND_DEFINITION`].
    pub crossland_definition: &'static str,
    /// See [`MAXIMA_DEFINITION`].
    pub maxima_definition: &'static str,
    /// Depths of the slices' rows, m.
    pub slice_depths_m: Vec<f64>,
    /// The slice along the force: `x` (a grid row) or `y` (a column).
    pub slice_along: &'static str,
    /// The cell centre the slices pass through (x, y), m.
    pub slice_through_m: [f64; 2],
}

/// One state's stresses on the planes and slices.
pub struct StateStress {
    /// Increment (None: the case's only state).
    pub step: Option<usize>,
    /// Pressure of the state (for the contact edge in the maps), Pa.
    pub p: Vec<f64>,
    /// One field per depth of `stress.depths_um`.
    pub planes: Vec<StressField>,
    /// The slice along the force: one line per slice depth.
    pub along: Vec<StressField>,
    /// The slice across the force.
    pub across: Vec<StressField>,
}

/// The stresses of a case: its states, and the scalars.
pub struct StressOutput {
    /// The states.
    pub states: Vec<StateStress>,
    /// The scalars (`case.json`).
    pub scalars: StressScalars,
    /// Crossland's parameter on each plane (with two states or more).
    pub crossland_planes: Vec<Vec<f64>>,
    /// Crossland's parameter on the slices (rows = depths).
    pub crossland_slices: Option<[Vec<f64>; 2]>,
    /// Grid row and column of the slices.
    pub centre: (usize, usize),
    /// The slice along the force is a grid row.
    pub along_is_row: bool,
    depths_m: Vec<f64>,
    depths_um: Vec<f64>,
    grid: solver::Grid,
    contact_radius_m: f64,
    p_h: f64,
}

/// A state's increment (None: the case's only state) and its `p, qx, qy`.
type StateTractions<'a> = (Option<usize>, &'a [f64], &'a [f64], &'a [f64]);

/// A scalar of the stress tensor.
type Invariant = fn([f64; 6]) -> f64;

/// Cell nearest the pressure centroid.
fn centroid(grid: &solver::Grid, p: &[f64]) -> (usize, usize) {
    let n = grid.n;
    let (mut w, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for iy in 0..n {
        for ix in 0..n {
            let v = p[iy * n + ix];
            w += v;
            sx += v * ix as f64;
            sy += v * iy as f64;
        }
    }
    if w <= 0.0 {
        return (n / 2, n / 2);
    }
    let r = |v: f64| (v / w).round().clamp(0.0, (n - 1) as f64) as usize;
    (r(sx), r(sy))
}

/// Computes the stresses `cfg` asks for on the states of a solved case:
/// the turning points of its load history (or its final state), else
/// the case's one state.
pub fn compute(
    cfg: &StressCfg,
    spec: &CaseSpec,
    scalars: &CaseScalars,
    fields: &Fields,
    turning: &[TurningState],
) -> Result<StressOutput> {
    let grid = spec.grid;
    let n = grid.n;
    let states: Vec<StateTractions> = if cfg.states == "turning" && !turning.is_empty() {
        turning
            .iter()
            .map(|t| (Some(t.step), &t.p[..], &t.qx[..], &t.qy[..]))
            .collect()
    } else {
        vec![(None, &fields.p[..], &fields.qx[..], &fields.qy[..])]
    };
    let mut plan = StressPlan::new(&spec.material, grid).map_err(|e| anyhow!("[stress]: {e}"))?;
    let tractions: Vec<_> = states
        .iter()
        .map(|(_, p, qx, qy)| plan.tractions(p, qx, qy))
        .collect();
    let (ix0, iy0) = centroid(&grid, &fields.p);
    let psi = spec.load.angle_deg.to_radians();
    let along_is_row = psi.cos().abs() >= psi.sin().abs();
    let (along, across) = if along_is_row {
        (Line::Row(iy0), Line::Column(ix0))
    } else {
        (Line::Column(ix0), Line::Row(iy0))
    };
    let a = if scalars.contact_radius_m > 0.0 {
        scalars.contact_radius_m
    } else {
        scalars.hertz_radius_m
    };
    let slice_depths: Vec<f64> = if cfg.slices {
        let deepest = cfg.slice_depth_um.map_or(2.0 * a, |d| d * 1e-6);
        (0..cfg.slice_rows)
            .map(|k| deepest * k as f64 / (cfg.slice_rows - 1) as f64)
            .collect()
    } else {
        Vec::new()
    };
    let mut out: Vec<StateStress> = states
        .iter()
        .map(|(step, p, _, _)| StateStress {
            step: *step,
            p: p.to_vec(),
            planes: Vec::new(),
            along: Vec::new(),
            across: Vec::new(),
        })
        .collect();
    // One kernel per depth, applied to every state.
    for &z in &slice_depths {
        let plane = plan.plane(z).map_err(|e| anyhow!("[stress]: {e}"))?;
        for (s, t) in out.iter_mut().zip(&tractions) {
            s.along.push(plan.apply_line(&plane, t, along));
            s.across.push(plan.apply_line(&plane, t, across));
        }
    }
    let depths_m: Vec<f64> = cfg.depths_um.iter().map(|d| d * 1e-6).collect();
    for &z in &depths_m {
        let plane = plan.plane(z).map_err(|e| anyhow!("[stress]: {e}"))?;
        for (s, t) in out.iter_mut().zip(&tractions) {
            s.planes.push(plan.apply(&plane, t));
        }
    }
    let p_h = scalars.hertz_pressure_pa;
    let at_line = |line: Line, i: usize, z: f64| match line {
        Line::Row(iy) => [grid.x(i), grid.y(iy), z],
        Line::Column(ix) => [grid.x(ix), grid.y(i), z],
    };
    let located = |v: f64, at: [f64; 3]| Located {
        value_pa: v,
        over_p_h: v / p_h,
        at_m: at,
    };
    // Every point computed of a state: (tensor, place).
    let points = |s: &StateStress| -> Vec<([f64; 6], [f64; 3])> {
        let mut pts = Vec::new();
        for (line, rows) in [(along, &s.along), (across, &s.across)] {
            for f in rows.iter() {
                for i in 0..f.len() {
                    pts.push((f.at(i), at_line(line, i, f.depth_m)));
                }
            }
        }
        for f in &s.planes {
            for i in 0..f.len() {
                pts.push((f.at(i), [grid.x(i % n), grid.y(i / n), f.depth_m]));
            }
        }
        pts
    };
    let best = |pts: &[([f64; 6], [f64; 3])], f: &dyn Fn([f64; 6]) -> f64| {
        let mut b = (f64::NEG_INFINITY, [0.0; 3]);
        for (s, at) in pts {
            let v = f(*s);
            if v > b.0 {
                b = (v, *at);
            }
        }
        located(b.0, b.1)
    };
    let (c, s) = (psi.cos(), psi.sin());
    let along_force = |t: [f64; 6]| t[0] * c * c + t[1] * s * s + 2.0 * t[5] * s * c;
    let mut state_scalars = Vec::new();
    for st in &out {
        let pts = points(st);
        let surface_peak = st.along.first().map(|top| {
            let vals = top.map(along_force);
            let pk = solver::stress::peak(&vals).expect("a line has points");
            located(pk.value, at_line(along, pk.index, 0.0))
        });
        state_scalars.push(StateScalars {
            step: st.step,
            max_von_mises: best(&pts, &von_mises),
            max_tresca: best(&pts, &tresca),
            max_principal: best(&pts, &max_principal),
            surface_peak_along_force: surface_peak,
        });
    }
    // Crossland over the states.
    let alpha = cfg.crossland_alpha;
    let crossland_at = |ts: &[[f64; 6]]| -> f64 {
        let dev = |t: &[f64; 6]| {
            let m = (t[0] + t[1] + t[2]) / 3.0;
            [t[0] - m, t[1] - m, t[2] - m, t[3], t[4], t[5]]
        };
        let mut amp: f64 = 0.0;
        for i in 0..ts.len() {
            for j in i + 1..ts.len() {
                let (a, b) = (dev(&ts[i]), dev(&ts[j]));
                let d: [f64; 6] = std::array::from_fn(|k| 0.5 * (a[k] - b[k]));
                let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
                    + d[3] * d[3]
                    + d[4] * d[4]
                    + d[5] * d[5];
                amp = amp.max(j2.sqrt());
            }
        }
        let sh = ts
            .iter()
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .fold(f64::NEG_INFINITY, f64::max);
        amp + alpha * sh
    };
    let (mut crossland_planes, mut crossland_slices, mut crossland) = (Vec::new(), None, None);
    if out.len() >= 2 {
        let field_of = |get: &dyn Fn(&StateStress) -> &StressField| -> Vec<f64> {
            let len = get(&out[0]).len();
            (0..len)
                .map(|i| {
                    let ts: Vec<[f64; 6]> = out.iter().map(|s| get(s).at(i)).collect();
                    crossland_at(&ts)
                })
                .collect()
        };
        for k in 0..depths_m.len() {
            crossland_planes.push(field_of(&|s: &StateStress| &s.planes[k]));
        }
        let slice = |which: usize| -> Vec<f64> {
            (0..slice_depths.len())
                .flat_map(|r| {
                    if which == 0 {
                        field_of(&|s: &StateStress| &s.along[r])
                    } else {
                        field_of(&|s: &StateStress| &s.across[r])
                    }
                })
                .collect()
        };
        if !slice_depths.is_empty() {
            crossland_slices = Some([slice(0), slice(1)]);
        }
        let mut b = (f64::NEG_INFINITY, [0.0; 3]);
        for (k, f) in crossland_planes.iter().enumerate() {
            for (i, &v) in f.iter().enumerate() {
                if v > b.0 {
                    b = (v, [grid.x(i % n), grid.y(i / n), depths_m[k]]);
                }
            }
        }
        if let Some(sl) = &crossland_slices {
            for (line, vals) in [(along, &sl[0]), (across, &sl[1])] {
                for (i, &v) in vals.iter().enumerate() {
                    if v > b.0 {
                        b = (v, at_line(line, i % n, slice_depths[i / n]));
                    }
                }
            }
        }
        crossland = Some(located(b.0, b.1));
    }
    Ok(StressOutput {
        scalars: StressScalars {
            states: state_scalars,
            crossland,
            crossland_alpha: alpha,
            crossland_definition: CROSSLAND_DEFINITION,
            maxima_definition: MAXIMA_DEFINITION,
            slice_depths_m: slice_depths,
            slice_along: if along_is_row { "x" } else { "y" },
            slice_through_m: [grid.x(ix0), grid.y(iy0)],
        },
        states: out,
        crossland_planes,
        crossland_slices,
        centre: (ix0, iy0),
        along_is_row,
        depths_m,
        depths_um: cfg.depths_um.clone(),
        grid,
        contact_radius_m: a,
        p_h,
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
/// `slice_<along|across>_crossland`. The files of [`write`] and Python's
/// `Result.stress`.
pub fn arrays(so: &StressOutput) -> Vec<StressArray> {
    let n = so.grid.n;
    let rows = so.scalars.slice_depths_m.len();
    let many = so.states.len() > 1;
    let mut out = Vec::new();
    let mut push = |name: String, rows: usize, data: Vec<f64>| {
        out.push(StressArray {
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
                push(format!("{stem}_{name}"), n, f.components[c].clone());
            }
            for (name, g) in DERIVED {
                push(format!("{stem}_{name}"), n, f.map(g));
            }
        }
        for (label, lines) in [("along", &st.along), ("across", &st.across)] {
            if lines.is_empty() {
                continue;
            }
            let stem = format!("slice_{label}{suffix}");
            for (c, name) in COMPONENTS.iter().enumerate() {
                let vals = lines.iter().flat_map(|f| f.components[c].clone()).collect();
                push(format!("{stem}_{name}"), rows, vals);
            }
            for (name, g) in DERIVED {
                push(
                    format!("{stem}_{name}"),
                    rows,
                    lines.iter().flat_map(|f| f.map(g)).collect(),
                );
            }
        }
    }
    for (k, f) in so.crossland_planes.iter().enumerate() {
        push(
            format!("plane_{}um_crossland", fmt_f64(so.depths_um[k])),
            n,
            f.clone(),
        );
    }
    if let Some([al, ac]) = &so.crossland_slices {
        push("slice_along_crossland".into(), rows, al.clone());
        push("slice_across_crossland".into(), rows, ac.clone());
    }
    out
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
    for arr in arrays(so) {
        crate::npy::write_npy_2d(
            &dir.join(format!("{}.npy", arr.name)),
            arr.rows,
            arr.cols,
            &arr.data,
        )?;
    }
    let n = so.grid.n;
    let many = so.states.len() > 1;
    let mut warnings = Vec::new();
    let a = so.contact_radius_m;
    let rows = so.scalars.slice_depths_m.len();
    let z_max = so.scalars.slice_depths_m.last().copied().unwrap_or(0.0);
    let mut draw = |file: String, heat: &crate::maps::Heat| {
        if let Err(e) = crate::maps::write_heat(&dir.join(&file), heat) {
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
                &crate::maps::Heat {
                    title: &t,
                    label: "von Mises / p_H",
                    cols: n,
                    rows: n,
                    values: &norm,
                    x_range: (-ext.0, ext.0),
                    y_range: (-ext.1, ext.1),
                    axes: ("x / a", "y / a"),
                    marks: &marks,
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
                &crate::maps::Heat {
                    title: &t,
                    label: "von Mises / p_H",
                    cols: n,
                    rows,
                    values: &norm,
                    x_range: (-half, half),
                    y_range: (0.0, -z_max / a),
                    axes: (if line_is_row { "x / a" } else { "y / a" }, "-z / a"),
                    marks: &marks,
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

#[cfg(test)]
mod tests {
    use crate::config::Config;
    use crate::solve::{solve_in_memory, write_solved, CaseChoice};

    const FE: &str = "[grid]\npoints = 64\nspacing_um = 5.0\n[indenter]\nradius_mm = 18.0\n[load]\nnormal_n = 20.0\nfriction = 0.28571\n[sweep]\nmaterials = [\"Fe\"]\nangles_deg = [0.0]\n[history]\ntangential_ratios = [0.0, 0.6, -0.6]\nsteps_per_segment = 2\n";

    /// A fretting path's turning states: the frictionless start has the
    /// Hertz von Mises peak (0.62 p_H, Hamilton), the two reversed
    /// states mirror each other (trailing-edge tension behind the force),
    /// and the files and keys appear only with the section.
    #[test]
    fn issue38_turning_states_mirror_and_outputs_only_with_the_section() {
        let text = format!("{FE}[stress]\ndepths_um = [0.0]\nslice_rows = 16\n");
        let c = Config::parse(&text, &[]).unwrap();
        let solved = solve_in_memory(CaseChoice::new(&c, None, None, None).unwrap(), 1).unwrap();
        let s = &solved.stress.as_ref().unwrap().scalars;
        let steps: Vec<_> = s.states.iter().map(|st| st.step).collect();
        assert_eq!(steps, vec![Some(0), Some(2), Some(4)]);
        let start = s.states[0].max_von_mises.over_p_h;
        assert!(
            (start - 0.62).abs() < 0.02,
            "frictionless von Mises {start}"
        );
        let (plus, minus) = (
            s.states[1].surface_peak_along_force.unwrap(),
            s.states[2].surface_peak_along_force.unwrap(),
        );
        assert!(
            plus.at_m[0] < 0.0 && minus.at_m[0] > 0.0,
            "{plus:?} {minus:?}"
        );
        assert!((plus.value_pa / minus.value_pa - 1.0).abs() < 0.01);
        assert!(s.crossland.unwrap().value_pa > 0.0);
        let dir = std::env::temp_dir().join(format!("mpc-stress-{}", std::process::id()));
        write_solved(&solved, &dir).unwrap();
        let json = std::fs::read_to_string(dir.join("case.json")).unwrap();
        assert!(json.contains("\"stress\""));
        for f in [
            "plane_0um_step2_sxx.npy",
            "slice_along_step4_von_mises.npy",
            "slice_across_crossland.npy",
        ] {
            assert!(dir.join("stress").join(f).is_file(), "{f}");
        }
        std::fs::remove_dir_all(&dir).unwrap();

        let plain = Config::parse(FE, &[]).unwrap();
        let solved =
            solve_in_memory(CaseChoice::new(&plain, None, None, None).unwrap(), 1).unwrap();
        assert!(solved.stress.is_none());
        write_solved(&solved, &dir).unwrap();
        let json = std::fs::read_to_string(dir.join("case.json")).unwrap();
        assert!(!json.contains("\"stress\"") && !dir.join("stress").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
