//! The files of a case whose load path wears the surface: `wear.csv` (one
//! row per simulated cycle), `wear_profiles.csv` (the worn depth through
//! the contact's centre along x and y at the saved cycles) and the same
//! profiles overlaid as PNG and SVG, as fretting papers print a scar.
//! Used by `mpcontact solve` and, per case, by a sweep; computes nothing
//! the solver did not.

use crate::float_text::fmt_f64;
use anyhow::Result;
use plotters::prelude::*;
use solver::{Grid, HistoryOutput, WearCycle};
use std::fmt::Write as _;
use std::path::Path;

use super::plot::{self, err, Area, Figure, Frame, Unit, PALETTE};

/// Header of `wear.csv`.
pub const WEAR_HEADER: &str = "cycle,physical_cycles,worn_volume_m3,worn_volume_per_cycle_m3,depth_max_m,depth_max_x_m,depth_max_y_m,depth_increment_max_m,scar_area_m2,scar_extent_x_m,scar_extent_y_m,contact_radius_m,stick_radius_m,force_amplitude_n,shift_amplitude_m,dissipated_j,regime,worn_through_cells,ball_worn_volume_m3,ball_depth_max_m";

/// Text of `wear.csv`.
pub fn wear_csv(h: &HistoryOutput) -> String {
    let mut out = String::from(WEAR_HEADER);
    out.push('\n');
    for c in &h.wear_cycles {
        let cells = [
            c.physical_cycles,
            c.worn_volume_m3,
            c.worn_volume_per_cycle_m3,
            c.depth_max_m,
            c.depth_max_at_m[0],
            c.depth_max_at_m[1],
            c.depth_increment_max_m,
            c.scar_area_m2,
            c.scar_extent_m[0],
            c.scar_extent_m[1],
            c.contact_radius_m,
            c.stick_radius_m,
            c.force_amplitude_n,
            c.shift_amplitude_m,
            c.dissipated_j,
        ];
        let _ = write!(out, "{}", c.cycle);
        for v in cells {
            let _ = write!(out, ",{}", fmt_f64(v));
        }
        let _ = writeln!(
            out,
            ",{},{},{},{}",
            c.regime,
            c.worn_through_cells,
            fmt_f64(c.ball_worn_volume_m3),
            fmt_f64(c.ball_depth_max_m)
        );
    }
    out
}

/// The cycles whose profiles were kept.
fn saved(h: &HistoryOutput) -> Vec<&WearCycle> {
    h.wear_cycles
        .iter()
        .filter(|c| !c.profile_x_m.is_empty())
        .collect()
}

/// Text of `wear_profiles.csv` on the case's `grid`: the position from the
/// centre, then per saved cycle its depth along x and along y.
pub fn profiles_csv(h: &HistoryOutput, grid: &Grid) -> String {
    let cycles = saved(h);
    let mut out = String::from("position_m");
    for c in &cycles {
        let _ = write!(out, ",x_cycle_{0},y_cycle_{0}", c.cycle);
    }
    out.push('\n');
    for i in 0..grid.n {
        out.push_str(&fmt_f64(grid.x(i)));
        for c in &cycles {
            let _ = write!(
                out,
                ",{},{}",
                fmt_f64(c.profile_x_m[i]),
                fmt_f64(c.profile_y_m[i])
            );
        }
        out.push('\n');
    }
    out
}

/// A saved cycle's profiles: its label, then (position, surface) along x
/// and along y, in m with the depth negative.
type ProfileLine = (String, Vec<(f64, f64)>, Vec<(f64, f64)>);

/// The profiles as drawn.
struct Profiles<'a> {
    lines: Vec<ProfileLine>,
    title: &'a str,
}

fn profile_lines(h: &HistoryOutput, grid: &Grid) -> Vec<ProfileLine> {
    let line = |p: &[f64]| -> Vec<(f64, f64)> {
        p.iter()
            .enumerate()
            .map(|(i, &d)| (grid.x(i), -d))
            .collect()
    };
    saved(h)
        .into_iter()
        .map(|c| {
            let label = format!("{:.0} cycles", c.physical_cycles);
            (label, line(&c.profile_x_m), line(&c.profile_y_m))
        })
        .collect()
}

/// Width of the legend column beside the profiles.
const LEGEND: u32 = 170;

impl Figure for Profiles<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<()> {
        let pts = self
            .lines
            .iter()
            .flat_map(|(_, x, y)| x.iter().chain(y.iter()));
        let (mut xlo, mut xhi, mut ylo) = (f64::INFINITY, f64::NEG_INFINITY, 0.0_f64);
        for &(x, y) in pts {
            xlo = xlo.min(x);
            xhi = xhi.max(x);
            ylo = ylo.min(y);
        }
        if !xlo.is_finite() || xhi <= xlo {
            (xlo, xhi) = (-1e-6, 1e-6);
        }
        if ylo >= 0.0 {
            ylo = -1e-12;
        }
        // Positions in µm, depths in the unit that makes the deepest read
        // 1–1000 (a scar of 2e-9 m reads 2 nm, not 0.002 µm).
        let ux = Unit::for_largest("m", 1, xlo.abs().max(xhi.abs()));
        let uy = Unit::for_largest("m", 1, ylo);
        let (xlo, xhi, ylo) = (xlo * ux.factor, xhi * ux.factor, ylo * uy.factor);
        let yp = -ylo * 0.08;
        // The legend in its own column: inside a panel it covered the scar.
        let (plots, legend) = root.split_horizontally(root.dim_in_pixel().0 - LEGEND);
        let panels = plots.split_evenly((1, 2));
        let frame = Frame {
            title: 16,
            margin: 12,
            labels: (44, 70),
        };
        for (k, panel) in panels.iter().enumerate() {
            let axis = ["x (the force direction at 0°)", "y"][k];
            let mut chart = frame.chart(
                panel,
                &format!("{}: worn depth along {axis}", self.title),
                xlo..xhi,
                (ylo - yp)..yp,
            )?;
            plot::axes(
                &mut chart,
                &format!("{} through the centre ({})", ["x", "y"][k], ux.text),
                &format!("surface ({}, worn depth below 0)", uy.text),
                true,
            )?;
            for (j, (_, x, y)) in self.lines.iter().enumerate() {
                let colour = PALETTE[j % PALETTE.len()];
                let line: Vec<(f64, f64)> = if k == 0 { x } else { y }
                    .iter()
                    .map(|&(p, d)| (p * ux.factor, d * uy.factor))
                    .collect();
                chart
                    .draw_series(LineSeries::new(line, colour.stroke_width(2)))
                    .map_err(err)?;
            }
        }
        let entries: Vec<(String, RGBColor, u32)> = self
            .lines
            .iter()
            .enumerate()
            .map(|(j, (label, _, _))| (label.clone(), PALETTE[j % PALETTE.len()], 2))
            .collect();
        plot::line_legend(&legend, &entries)
    }
}

/// Writes `wear.csv`, `wear_profiles.csv` and `wear_profiles.png|svg` into
/// `dir` when the path wore the surface (nothing otherwise). The tables
/// are written first; a picture that cannot be drawn is returned as a
/// warning, not an error.
pub fn write_wear(dir: &Path, h: &HistoryOutput, grid: &Grid, title: &str) -> Result<Vec<String>> {
    if h.wear_cycles.is_empty() {
        return Ok(Vec::new());
    }
    std::fs::create_dir_all(dir)?;
    super::atomic::write(&dir.join("wear.csv"), wear_csv(h).as_bytes())?;
    super::atomic::write(
        &dir.join("wear_profiles.csv"),
        profiles_csv(h, grid).as_bytes(),
    )?;
    let figure = Profiles {
        lines: profile_lines(h, grid),
        title,
    };
    let mut warnings = Vec::new();
    for name in ["wear_profiles.png", "wear_profiles.svg"] {
        if let Err(e) = plot::write(&dir.join(name), (1200 + LEGEND, 480), &figure) {
            warnings.push(format!("{name}: {e:#}"));
        }
    }
    Ok(warnings)
}

/// The warnings of a worn path: a cycle jump too coarse (see
/// [`solver::WEAR_JUMP_LIMIT`]), islands worn through.
pub fn wear_warnings(h: &HistoryOutput) -> Vec<String> {
    let mut warnings = Vec::new();
    // Without a jump every cycle is simulated: a cycle that wears that much
    // is the wear coefficient's doing, not the jump's (#59 item 2).
    let jumped = h
        .wear_cycles
        .first()
        .is_some_and(|c| c.physical_cycles != c.cycle as f64);
    if let Some(ratio) = h.wear_jump_ratio.filter(|&r| r > solver::WEAR_JUMP_LIMIT) {
        warnings.push(if jumped {
            format!(
                "a simulated cycle wore up to {:.1} % of the approach (above {} %): the cycle jump (history.wear.physical_cycles / history.fretting.cycles) may be too coarse for the worn profile's transient; simulate more cycles and compare",
                100.0 * ratio,
                100.0 * solver::WEAR_JUMP_LIMIT
            )
        } else {
            format!(
                "one cycle wore up to {:.1} % of the approach, with no cycle jump: the wear coefficient (history.wear.k_mm3_per_nm or alpha_mm3_per_j) makes the contact conform within a few cycles, a worn contact whose pressure is far from Hertz's",
                100.0 * ratio
            )
        });
    }
    if let Some(c) = h.wear_cycles.iter().find(|c| c.worn_through_cells > 0) {
        warnings.push(format!(
            "islands worn through from simulated cycle {} ({:.0} physical cycles): {} cells worn deeper than their island's height, {} by the end; the pattern no longer describes them (wear.csv, worn_through_cells)",
            c.cycle,
            c.physical_cycles,
            c.worn_through_cells,
            h.wear_cycles.last().map_or(0, |l| l.worn_through_cells)
        ));
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;

    fn worn() -> HistoryOutput {
        let cycle = |k: usize, saved: bool| WearCycle {
            cycle: k,
            physical_cycles: 100.0 * k as f64,
            worn_volume_m3: 1e-15 * k as f64,
            regime: "partial".into(),
            profile_x_m: if saved { vec![0.0, 2e-8, 0.0] } else { vec![] },
            profile_y_m: if saved { vec![0.0, 1e-8, 0.0] } else { vec![] },
            ..Default::default()
        };
        HistoryOutput {
            wear_cycles: vec![cycle(1, false), cycle(2, true)],
            wear_jump_ratio: Some(0.05),
            ..Default::default()
        }
    }

    #[test]
    fn the_wear_table_has_a_row_per_cycle_and_the_profiles_a_column_per_saved_cycle() {
        let h = worn();
        let text = wear_csv(&h);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0], WEAR_HEADER);
        assert!(lines[2].starts_with("2,200,2e-15,"), "{}", lines[2]);
        assert!(lines[2].ends_with(",partial,0,0,0"), "{}", lines[2]);
        assert_eq!(
            lines[0].split(',').count(),
            lines[2].split(',').count(),
            "a value per column"
        );
        let profiles = profiles_csv(&h, &Grid::square(3, 1e-6));
        let rows: Vec<&str> = profiles.lines().collect();
        assert_eq!(rows[0], "position_m,x_cycle_2,y_cycle_2");
        assert_eq!(rows[2], "0,2e-8,1e-8");
        let warnings = wear_warnings(&h);
        assert!(warnings.len() == 1 && warnings[0].contains("5.0 %"));
        assert!(warnings[0].contains("cycle jump"));
        // Without a jump the coefficient is named, not the jump.
        let mut unjumped = h.clone();
        for c in &mut unjumped.wear_cycles {
            c.physical_cycles = c.cycle as f64;
        }
        let warnings = wear_warnings(&unjumped);
        assert!(
            warnings.len() == 1
                && warnings[0].contains("no cycle jump")
                && warnings[0].contains("k_mm3_per_nm"),
            "{warnings:?}"
        );
        assert!(wear_warnings(&HistoryOutput::default()).is_empty());
        let mut through = h.clone();
        through.wear_jump_ratio = Some(0.01);
        through.wear_cycles[1].worn_through_cells = 12;
        let warnings = wear_warnings(&through);
        assert!(
            warnings.len() == 1
                && warnings[0].contains("from simulated cycle 2 (200 physical cycles): 12 cells"),
            "{warnings:?}"
        );
    }
}
