//! The files of a case with a load history: `history.csv` (one row per
//! increment) and the hysteresis loop (F versus δt along the force
//! direction, one line per cycle) as PNG and SVG. Used by `mpcontact solve`
//! and, per case, by a sweep; computes nothing the solver did not.

use crate::float_text::fmt_f64;
use anyhow::{Context, Result};
use plotters::prelude::*;
use solver::{Grid, HistoryOutput};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, Area, Figure, Frame, Unit, PALETTE};

/// Header of `history.csv`.
pub const HISTORY_HEADER: &str = "step,normal_force_n,fx_n,fy_n,delta_x_m,delta_y_m,delta_z_m,contact_area_m2,stick_area_m2,stick_radius_m,dissipated_j,segment,converged,segment_increments";

/// The column `history.csv` gains on a path with a wear law: the volume
/// worn from the start of the path to the increment (a path without one
/// has the header above, to the byte).
pub const HISTORY_WEAR_COLUMN: &str = "worn_volume_m3";

/// The columns `history.csv` gains on a surface with a hardness (after the
/// wear column, if any): the area at the cap and the dent's deepest cell so
/// far (a path without a hardness has the header above, to the byte).
pub const HISTORY_PLASTIC_COLUMNS: &str = "plastic_area_m2,plastic_penetration_max_m";

/// Text of `history.csv`.
pub fn history_csv(h: &HistoryOutput) -> String {
    let wear = h.worn_volume_m3.is_some();
    let plastic = h.steps.iter().any(|r| r.plastic_area_m2.is_some());
    let mut out = String::from(HISTORY_HEADER);
    if wear {
        out.push(',');
        out.push_str(HISTORY_WEAR_COLUMN);
    }
    if plastic {
        out.push(',');
        out.push_str(HISTORY_PLASTIC_COLUMNS);
    }
    out.push('\n');
    for r in &h.steps {
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.step,
            fmt_f64(r.normal_force_n),
            fmt_f64(r.force_n[0]),
            fmt_f64(r.force_n[1]),
            fmt_f64(r.delta_t_m[0]),
            fmt_f64(r.delta_t_m[1]),
            fmt_f64(r.delta_z_m),
            fmt_f64(r.contact_area_m2),
            fmt_f64(r.stick_area_m2),
            fmt_f64(r.stick_radius_m),
            fmt_f64(r.dissipated_j),
            r.segment,
            r.converged,
            r.segment_increments,
        );
        if wear {
            let _ = write!(out, ",{}", fmt_f64(r.worn_volume_m3));
        }
        if plastic {
            let _ = write!(
                out,
                ",{},{}",
                fmt_f64(r.plastic_area_m2.unwrap_or(0.0)),
                fmt_f64(r.plastic_penetration_max_m.unwrap_or(0.0))
            );
        }
        out.push('\n');
    }
    out
}

/// The loop's lines: (label, [(δt m, F N)]) along the force direction. The
/// first loading is its own line; then one line per cycle (two segments).
fn loop_lines(h: &HistoryOutput) -> Vec<(String, Vec<(f64, f64)>)> {
    let along = |v: [f64; 2]| v[0] * h.direction[0] + v[1] * h.direction[1];
    let point = |k: usize| {
        let r = &h.steps[k];
        (along(r.delta_t_m), along(r.force_n))
    };
    let t = &h.turning_steps;
    let mut lines = Vec::new();
    if t.len() < 2 {
        return lines;
    }
    // Only the loops sampled at a fixed resolution: the others are a few
    // points each (auto increments), which a line would draw as a polygon.
    let sampled = |seg: usize| h.sampled_segments.contains(&seg);
    if sampled(0) {
        lines.push((
            "first loading".to_string(),
            (t[0]..=t[1]).map(point).collect(),
        ));
    }
    let mut j = 1;
    let mut cycle = 1;
    while j < t.len() - 1 {
        let end = (j + 2).min(t.len() - 1);
        if (j..end).all(sampled) {
            lines.push((
                format!("cycle {cycle}"),
                (t[j]..=t[end]).map(point).collect(),
            ));
        }
        j += 2;
        cycle += 1;
    }
    lines
}

/// The hysteresis loop as drawn: its lines and title.
struct Hysteresis<'a> {
    lines: Vec<(String, Vec<(f64, f64)>)>,
    title: &'a str,
}

/// Draws the hysteresis loop to `path` (PNG or SVG by extension).
pub fn plot_hysteresis(path: &Path, h: &HistoryOutput, title: &str) -> Result<()> {
    let lines = loop_lines(h);
    plot::write(path, (760, 520), &Hysteresis { lines, title })
}

/// At most this many cycles are drawn: the first, the last and evenly
/// spaced ones between (a worn path has a hundred; `history.csv` has all).
const CYCLES_DRAWN: usize = 5;

/// Which of `n` cycles are drawn (0-based, ascending).
fn drawn_cycles(n: usize) -> Vec<usize> {
    if n <= CYCLES_DRAWN {
        return (0..n).collect();
    }
    let mut v: Vec<usize> = (0..CYCLES_DRAWN)
        .map(|i| (i as f64 * (n - 1) as f64 / (CYCLES_DRAWN - 1) as f64).round() as usize)
        .collect();
    v.dedup();
    v
}

impl Figure for Hysteresis<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<()> {
        let Some((first, cycles)) = self.lines.split_first() else {
            return Ok(());
        };
        let cycles: Vec<&(String, Vec<(f64, f64)>)> = drawn_cycles(cycles.len())
            .into_iter()
            .map(|k| &cycles[k])
            .collect();
        let pts = std::iter::once(first)
            .chain(cycles.iter().copied())
            .flat_map(|(_, l)| l.iter());
        let (mut xlo, mut xhi, mut ylo, mut yhi) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in pts {
            xlo = xlo.min(x);
            xhi = xhi.max(x);
            ylo = ylo.min(y);
            yhi = yhi.max(y);
        }
        // δt and F in the units that make them read 1–1000 (nm or µm; N).
        let (ux, uy) = if !xlo.is_finite() || xhi <= xlo || yhi <= ylo {
            (xlo, xhi, ylo, yhi) = (-1.0, 1.0, -1.0, 1.0);
            (
                Unit::for_largest("m", 1, 0.0),
                Unit::for_largest("N", 1, 0.0),
            )
        } else {
            (
                Unit::for_largest("m", 1, xlo.abs().max(xhi.abs())),
                Unit::for_largest("N", 1, ylo.abs().max(yhi.abs())),
            )
        };
        let scaled = |l: &[(f64, f64)]| -> Vec<(f64, f64)> {
            l.iter()
                .map(|&(x, y)| (x * ux.factor, y * uy.factor))
                .collect()
        };
        let (xlo, xhi, ylo, yhi) = (
            xlo * ux.factor,
            xhi * ux.factor,
            ylo * uy.factor,
            yhi * uy.factor,
        );
        let (xp, yp) = ((xhi - xlo) * 0.05, (yhi - ylo) * 0.05);
        let frame = Frame {
            title: 20,
            margin: 12,
            labels: (44, 64),
        };
        let mut chart = frame.chart(
            root,
            self.title,
            (xlo - xp)..(xhi + xp),
            (ylo - yp)..(yhi + yp),
        )?;
        plot::axes(
            &mut chart,
            &format!("tangential shift δt along the force ({})", ux.text),
            &format!("tangential force F ({})", uy.text),
            true,
        )?;
        // A loop closes after its first cycle, so the later cycles run on
        // top of the earlier ones: each is drawn narrower than the one
        // before it, on top, and cycle 1 stays visible as the outermost band
        // (before #62 cycle 2 hid it). The cycles in the palette's first
        // five colours; the first loading in black, first in the legend and
        // drawn again over the cycles.
        let first_line = scaled(&first.1);
        plot::labelled_line(&mut chart, &first_line, (BLACK, 2), &first.0)?;
        // 4 px narrower each (2 px with five cycles: the widest 10 px).
        let step = (10 / cycles.len().saturating_sub(1).max(1)).min(4) as u32;
        for (k, (label, line)) in cycles.iter().enumerate() {
            let width = 2 + step * (cycles.len() - 1 - k) as u32;
            let colour = PALETTE[k % 5];
            plot::labelled_line(&mut chart, &scaled(line), (colour, width), label)?;
        }
        chart
            .draw_series(LineSeries::new(first_line, BLACK.stroke_width(2)))
            .map_err(plot::err)?;
        plot::legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        Ok(())
    }
}

/// Writes `history.csv`, `hysteresis.png` and `hysteresis.svg` into `dir`,
/// and with a wear law the files of [`super::wear::write_wear`].
/// The tables are written first; the pictures that could not be drawn are
/// returned (the caller reports them as lost outputs, an error once the
/// rest is written). The path's warnings are [`path_warnings`].
pub fn write_history(
    dir: &Path,
    h: &HistoryOutput,
    grid: &Grid,
    title: &str,
) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    super::atomic::write(&dir.join("history.csv"), history_csv(h).as_bytes())?;
    let mut lost = Vec::new();
    for name in ["hysteresis.png", "hysteresis.svg"] {
        if let Err(e) = plot_hysteresis(&dir.join(name), h, title) {
            lost.push(format!("{name}: {e:#}"));
        }
    }
    lost.extend(super::wear::write_wear(dir, h, grid, title)?);
    Ok(lost)
}

/// Every warning of a path, each prefixed by the case's title: the wear's
/// ([`super::wear::wear_warnings`]) and the increments'
/// ([`history_warnings`]).
pub fn path_warnings(h: &HistoryOutput, title: &str) -> Vec<String> {
    super::wear::wear_warnings(h)
        .into_iter()
        .chain(history_warnings(h))
        .map(|w| format!("{title}: {w}"))
        .collect()
}

/// The warnings of a path's increments: auto increments that could not
/// meet their tolerance.
pub fn history_warnings(h: &HistoryOutput) -> Vec<String> {
    let mut warnings = Vec::new();
    if h.auto_tolerance_met == Some(false) {
        warnings.push(format!(
            "some increments reached the smallest auto increment (1/4096 of a segment) or the path's {} increments above history.tolerance (auto_tolerance_met = false in case.json): the path changes faster than the tolerance allows; loosen history.tolerance or split the path (more simulated cycles with a wear law)",
            solver::MAX_HISTORY_STEPS
        ));
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;
    use solver::HistoryStep;

    fn history() -> HistoryOutput {
        let steps = (0..=6)
            .map(|k| HistoryStep {
                step: k,
                segment: k.div_ceil(2),
                force_n: [[0.0, 1.0, 2.0, 0.0, -2.0, 0.0, 2.0][k], 0.0],
                delta_t_m: [[0.0, 1e-6, 3e-6, 1e-6, -3e-6, -1e-6, 3e-6][k], 0.0],
                converged: true,
                ..Default::default()
            })
            .collect();
        HistoryOutput {
            direction: [1.0, 0.0],
            steps,
            turning_steps: vec![0, 2, 4, 6],
            sampled_segments: vec![0, 1, 2],
            ..Default::default()
        }
    }

    #[test]
    fn history_table_has_a_row_per_step_and_the_issue_columns_first() {
        let text = history_csv(&history());
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 8);
        assert!(lines[0].starts_with(
            "step,normal_force_n,fx_n,fy_n,delta_x_m,delta_y_m,delta_z_m,contact_area_m2,stick_area_m2,stick_radius_m,dissipated_j"
        ));
        assert!(lines[3].starts_with("2,0,2,0,3e-6,0,"), "{}", lines[3]);
        assert_eq!(lines[0], HISTORY_HEADER);
    }

    #[test]
    fn a_hardness_adds_the_plastic_columns_last() {
        let mut h = history();
        for (k, r) in h.steps.iter_mut().enumerate() {
            r.plastic_area_m2 = Some(1e-9 * k as f64);
            r.plastic_penetration_max_m = Some(2e-7);
        }
        let text = history_csv(&h);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            format!("{HISTORY_HEADER},{HISTORY_PLASTIC_COLUMNS}")
        );
        assert!(lines[3].ends_with(",true,0,2e-9,2e-7"), "{}", lines[3]);
    }

    /// Up to five cycles all; of more, the first, the last and three
    /// evenly between.
    #[test]
    fn issue62_the_loop_draws_the_first_and_last_cycles_of_a_long_path() {
        assert_eq!(drawn_cycles(2), [0, 1]);
        assert_eq!(drawn_cycles(5), [0, 1, 2, 3, 4]);
        assert_eq!(drawn_cycles(100), [0, 25, 50, 74, 99]);
    }

    #[test]
    fn loop_lines_split_first_loading_and_cycles() {
        let lines = loop_lines(&history());
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].1.len(), 3);
        // The cycle runs from the first turning point back to the last.
        assert_eq!(lines[1].1.first(), Some(&(3e-6, 2.0)));
        assert_eq!(lines[1].1.last(), Some(&(3e-6, 2.0)));
        assert_eq!(lines[1].1.len(), 5);
        // A cycle of auto increments is not drawn (a few points are no loop).
        let mut auto = history();
        auto.sampled_segments = vec![0];
        assert_eq!(loop_lines(&auto).len(), 1);
    }
}
