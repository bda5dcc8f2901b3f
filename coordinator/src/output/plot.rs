//! What every figure of the outputs shares: a [`Figure`] drawn on a PNG or
//! an SVG back end (by the file's extension) and written whole or not at
//! all ([`write`]), the frame of a chart, the grid of panels beside a
//! legend, the colours (series palette, map ramp), a map's colour bar, and
//! the one rule for tick labels ([`tick_labels`], [`Ticks`], [`axes`]) and
//! units ([`Unit`]) that every axis and colour bar follows.
//! Knows no physics and no output's data; draws only what it is given.

use std::ops::Range;
use std::path::Path;

use anyhow::{anyhow, Result};
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The area a figure draws on.
pub type Area<DB> = DrawingArea<DB, Shift>;

/// A chart with two linear axes.
pub type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A picture that draws on any plotters back end.
pub trait Figure {
    /// Draws on `root`, already white; [`write`] presents it afterwards.
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<()>;
}

/// Draws `figure` into `path` at `size` pixels, SVG for a `.svg` path and
/// PNG otherwise, written whole or not at all.
pub fn write(path: &Path, size: (u32, u32), figure: &impl Figure) -> Result<()> {
    let is_svg = path.extension().is_some_and(|e| e == "svg");
    super::atomic::replace_with(path, |tmp| {
        if is_svg {
            render(SVGBackend::new(tmp, size).into_drawing_area(), figure)
        } else {
            render(BitMapBackend::new(tmp, size).into_drawing_area(), figure)
        }
    })
}

fn render<DB: DrawingBackend>(root: Area<DB>, figure: &impl Figure) -> Result<()> {
    root.fill(&WHITE).map_err(err)?;
    figure.draw(&root)?;
    root.present().map_err(err)
}

/// A drawing error (plotters' errors are generic over the back end) as its text.
pub fn err(e: impl std::fmt::Debug) -> anyhow::Error {
    anyhow!("{e:?}")
}

/// The frame of a chart: title size (points), margin and the widths of
/// the x and y label areas (pixels).
pub struct Frame {
    /// Font size of the title.
    pub title: u32,
    /// Margin on every side.
    pub margin: u32,
    /// Heights of the x labels' area and widths of the y labels'.
    pub labels: (u32, u32),
}

impl Frame {
    /// A chart of `x` × `y` on `area` titled `title`.
    pub fn chart<'a, DB: DrawingBackend>(
        &self,
        area: &'a Area<DB>,
        title: &str,
        x: Range<f64>,
        y: Range<f64>,
    ) -> Result<Chart<'a, DB>> {
        ChartBuilder::on(area)
            .caption(title, ("sans-serif", self.title))
            .margin(self.margin)
            .x_label_area_size(self.labels.0)
            .y_label_area_size(self.labels.1)
            .build_cartesian_2d(x, y)
            .map_err(err)
    }
}

/// A figure of panels of 560 x 400 pixels, two a row, with the legend in
/// a column `legend` pixels wide at the right, or, when the panels leave
/// the last row's second cell empty, in that cell (no empty panel, no
/// extra column).
pub struct Panels {
    /// How many panels.
    pub count: usize,
    /// Width of the legend column.
    pub legend: u32,
}

impl Panels {
    /// Panels in a row: one or two.
    pub fn cols(&self) -> usize {
        self.count.clamp(1, 2)
    }

    /// Whether the legend takes the empty cell of the last row.
    fn legend_in_grid(&self) -> bool {
        self.count > 1 && self.count % 2 == 1
    }

    /// The figure's size.
    pub fn size(&self) -> (u32, u32) {
        let rows = self.count.div_ceil(2).max(1);
        let legend = if self.legend_in_grid() {
            0
        } else {
            self.legend
        };
        (560 * self.cols() as u32 + legend, 400 * rows as u32)
    }

    /// The panels' areas (row by row) and the legend's.
    pub fn split<DB: DrawingBackend>(&self, root: &Area<DB>) -> (Vec<Area<DB>>, Area<DB>) {
        let cols = self.cols();
        let rows = self.count.div_ceil(cols).max(1);
        if self.legend_in_grid() {
            let mut cells = root.split_evenly((rows, cols));
            let legend = cells.pop().expect("an odd count leaves a cell");
            return (cells, legend);
        }
        let (plots, legend) = root.split_horizontally(root.dim_in_pixel().0 - self.legend);
        (plots.split_evenly((rows, cols)), legend)
    }
}

/// Draws `points` on `chart` as a line of `colour`, `width` px, whose
/// legend entry is `label`.
pub fn labelled_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    points: &[(f64, f64)],
    (colour, width): (RGBColor, u32),
    label: &str,
) -> Result<()> {
    chart
        .draw_series(LineSeries::new(
            points.iter().copied(),
            colour.stroke_width(width),
        ))
        .map_err(err)?
        .label(label)
        .legend(move |(x, y)| {
            PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(width))
        });
    Ok(())
}

/// Draws `chart`'s legend at `position`, framed on white.
pub fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// Draws a legend of lines (label, colour, width) down `area`, beside the
/// charts it explains and never over their data.
pub fn line_legend<DB: DrawingBackend>(
    area: &Area<DB>,
    entries: &[(String, RGBColor, u32)],
) -> Result<()> {
    for (k, (label, colour, width)) in entries.iter().enumerate() {
        let y = 40 + 24 * k as i32;
        area.draw(&PathElement::new(
            vec![(10, y), (40, y)],
            colour.stroke_width(*width),
        ))
        .map_err(err)?;
        area.draw(&Text::new(label.clone(), (48, y - 8), ("sans-serif", 15)))
            .map_err(err)?;
    }
    Ok(())
}

/// Distinct, print-safe series colours (no yellow on white).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// Colour of `t ∈ [0, 1]` on a perceptually ordered ramp (dark blue → yellow).
pub fn ramp(t: f64) -> RGBColor {
    let stops = [
        (0.0, (48, 18, 59)),
        (0.25, (40, 120, 230)),
        (0.5, (30, 200, 160)),
        (0.75, (240, 200, 40)),
        (1.0, (180, 20, 10)),
    ];
    let t = t.clamp(0.0, 1.0);
    for w in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (w[0], w[1]);
        if t <= t1 {
            let u = (t - t0) / (t1 - t0);
            let mix = |a: u8, b: u8| (a as f64 + u * (b as f64 - a as f64)).round() as u8;
            return RGBColor(mix(c0.0, c1.0), mix(c0.1, c1.1), mix(c0.2, c1.2));
        }
    }
    RGBColor(180, 20, 10)
}

/// The colour bar beside a map: the [`ramp`] from `lo` to `hi` in
/// `steps` bands under `label`, its ticks labelled by [`Ticks`].
pub struct ColourBar<'a> {
    /// Caption above the bar.
    pub label: &'a str,
    /// Font size of the caption.
    pub title: u32,
    /// Margins: top, bottom, left, right.
    pub margins: [u32; 4],
    /// Font size of the ticks.
    pub ticks: u32,
    /// Bands of the ramp.
    pub steps: usize,
}

impl ColourBar<'_> {
    /// Draws the bar for values from `lo` to `hi` on `area`.
    pub fn draw<DB: DrawingBackend>(&self, area: &Area<DB>, lo: f64, hi: f64) -> Result<()> {
        let [top, bottom, left, right] = self.margins;
        let mut cb = ChartBuilder::on(area)
            .caption(self.label, ("sans-serif", self.title))
            .margin_top(top)
            .margin_bottom(bottom)
            .margin_left(left)
            .margin_right(right)
            .set_label_area_size(LabelAreaPosition::Right, 70)
            .build_cartesian_2d(0.0..1.0, lo..hi)
            .map_err(err)?;
        let ticks = Ticks::of(lo..hi);
        let label = |v: &f64| ticks.label(*v);
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(TICKS)
            .y_label_style(("sans-serif", self.ticks))
            .y_label_formatter(&label)
            .draw()
            .map_err(err)?;
        let steps = self.steps;
        cb.draw_series((0..steps).map(|k| {
            let v0 = lo + (hi - lo) * k as f64 / steps as f64;
            let v1 = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
            Rectangle::new(
                [(0.0, v0), (1.0, v1)],
                ramp((k as f64 + 0.5) / steps as f64).filled(),
            )
        }))
        .map_err(err)?;
        Ok(())
    }
}

/// At most this many labelled ticks on an axis or a colour bar.
pub const TICKS: usize = 10;

/// The labels of `ticks`, the one rule of every figure: the fewest decimals
/// (the same for all) that write every tick exactly. Ticks sit at multiples
/// of 1, 2 or 5 × 10^k, so the labels are distinct and none reads beyond
/// the data (before #62 a colour bar at three decimals read 0.001, 0.001,
/// 0.002 … and rounded its top tick 0.0025 up past a maximum of 0.0024),
/// and whole numbers carry no decimals (`12`, not `12.000`). Zero reads
/// `0` (never `-0.0`).
pub fn tick_labels(ticks: &[f64]) -> Vec<String> {
    let mut sorted: Vec<f64> = ticks.iter().copied().filter(|t| t.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    // The step between ticks sets how close a label must come to its tick;
    // one tick alone is written to its own size.
    let step = sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&d| d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let scale = if step.is_finite() {
        step
    } else {
        sorted
            .iter()
            .fold(0.0_f64, |m, t| m.max(t.abs()))
            .max(1e-300)
    };
    let text = |t: f64, d: usize| {
        let s = format!("{t:.d$}");
        if s.parse::<f64>() == Ok(0.0) {
            s.trim_start_matches('-').to_string()
        } else {
            s
        }
    };
    for d in 0..=15 {
        let labels: Vec<String> = ticks.iter().map(|&t| text(t, d)).collect();
        let exact = ticks.iter().zip(&labels).all(|(&t, l)| {
            !t.is_finite()
                || l.parse::<f64>()
                    .is_ok_and(|v| (v - t).abs() <= 1e-6 * scale)
        });
        if exact {
            return labels;
        }
    }
    ticks.iter().map(|t| format!("{t:e}")).collect()
}

/// An axis's ticks and their labels: the key points plotters draws for a
/// range (at most [`TICKS`]) labelled by [`tick_labels`].
pub struct Ticks {
    /// The tick values, ascending.
    pub values: Vec<f64>,
    /// Their labels.
    pub labels: Vec<String>,
}

impl Ticks {
    /// The ticks plotters puts on `range` with at most [`TICKS`] labels.
    pub fn of(range: Range<f64>) -> Ticks {
        let values = RangedCoordf64::from(range).key_points(TICKS);
        let labels = tick_labels(&values);
        Ticks { values, labels }
    }

    /// The label of the tick at `v` (the nearest, for a value plotters
    /// computed again).
    pub fn label(&self, v: f64) -> String {
        self.values
            .iter()
            .zip(&self.labels)
            .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
            .map_or_else(|| tick_labels(&[v]).remove(0), |(_, l)| l.clone())
    }
}

/// Draws `chart`'s axes with the tick rule on both ([`Ticks`]), described by
/// `x_desc` and `y_desc`, and the mesh lines when `grid` (a chart; a map
/// has none).
pub fn axes<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    x_desc: &str,
    y_desc: &str,
    grid: bool,
) -> Result<()> {
    let (x, y) = (Ticks::of(chart.x_range()), Ticks::of(chart.y_range()));
    let (fx, fy) = (|v: &f64| x.label(*v), |v: &f64| y.label(*v));
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(TICKS)
        .y_labels(TICKS)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .x_desc(x_desc)
        .y_desc(y_desc);
    if !grid {
        mesh.disable_mesh();
    }
    mesh.draw().map_err(err)
}

/// A unit with the SI prefix that makes a quantity read 1–1000 (areas
/// 1–10⁶ and volumes 1–10⁹, whose prefixes step by those factors): worn
/// depths of 2e-9 m read 2 nm, not 0.002 µm.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    /// Its text, e.g. `nm`, `µm³`, `GPa`.
    pub text: String,
    /// What turns a value in the SI unit into this one.
    pub factor: f64,
}

impl Unit {
    /// The unit of `base` (`m`, `N`, `J`, `Pa`) to the `power` (2 for
    /// areas, 3 for volumes) for values up to `largest` in magnitude, in
    /// the SI unit: the largest prefix under which `largest` is at least 1.
    pub fn for_largest(base: &str, power: i32, largest: f64) -> Unit {
        const PREFIXES: [(i32, &str); 9] = [
            (-12, "p"),
            (-9, "n"),
            (-6, "µ"),
            (-3, "m"),
            (0, ""),
            (3, "k"),
            (6, "M"),
            (9, "G"),
            (12, "T"),
        ];
        let largest = largest.abs();
        let fits = |e: i32| largest / 10f64.powi(e * power) >= 1.0 - 1e-12;
        let (e, prefix) = if largest.is_finite() && largest > 0.0 {
            PREFIXES
                .iter()
                .rev()
                .find(|(e, _)| fits(*e))
                .copied()
                .unwrap_or(PREFIXES[0])
        } else {
            (0, "")
        };
        let power_text = match power {
            1 => "",
            2 => "²",
            3 => "³",
            _ => "^?",
        };
        Unit {
            text: format!("{prefix}{base}{power_text}"),
            factor: 10f64.powi(-e * power),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ranges of every size and sign: the labels are distinct, each reads
    /// its tick (so none lies beyond the range), and a value in the unit
    /// [`Unit::for_largest`] picks puts the largest tick in 1–1000.
    #[test]
    fn issue62_tick_labels_are_distinct_exact_and_read_one_to_a_thousand() {
        let mut checked = 0;
        for exp in -12..=10 {
            for (lo, hi) in [
                (0.0, 1.0),
                (0.0, 2.37),
                (-3.4, 3.4),
                (0.95, 1.05),
                (-0.123, 0.04),
                (144.7, 145.3),
                (0.0, 9.99),
            ] {
                let k = 10f64.powi(exp);
                let (lo, hi) = (lo * k, hi * k);
                // Plain ticks: distinct, each inside the range it labels.
                let t = Ticks::of(lo..hi);
                assert!(t.values.len() >= 2, "{lo}..{hi}: {:?}", t.values);
                let mut seen = std::collections::BTreeSet::new();
                for (v, l) in t.values.iter().zip(&t.labels) {
                    let read: f64 = l.parse().unwrap();
                    assert!(
                        (lo..=hi).contains(&read) || (read - v).abs() <= 1e-9 * (hi - lo),
                        "{lo}..{hi}: label {l} of {v} beyond the range"
                    );
                    assert!(
                        seen.insert(l.clone()),
                        "{lo}..{hi}: {l} twice: {:?}",
                        t.labels
                    );
                    assert!(!l.starts_with("-0") || read != 0.0, "{l}");
                }
                // In the unit chosen for the range's largest magnitude the
                // largest tick reads 1–1000 (lengths).
                let u = Unit::for_largest("m", 1, lo.abs().max(hi.abs()));
                let scaled = Ticks::of(lo * u.factor..hi * u.factor);
                let top = scaled.values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                if (1e-12..1e12).contains(&lo.abs().max(hi.abs())) {
                    assert!(
                        (1.0..1000.0).contains(&top),
                        "{lo}..{hi} in {}: {top}",
                        u.text
                    );
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 23 * 7);
    }

    /// The figures of issue #62: the wear map's colour bar (0 to 2.37e-3 µm
    /// before) reads 0.0, 0.5, … 2.0 nm; the plastic map's (0–28 µm) whole
    /// numbers; μa's axis two decimals throughout.
    #[test]
    fn issue62_the_figures_of_the_issue_read_cleanly() {
        let u = Unit::for_largest("m", 1, 2.37e-9);
        assert_eq!(u.text, "nm");
        let wear = Ticks::of(0.0..2.37e-9 * u.factor);
        assert_eq!(wear.labels, ["0.0", "0.5", "1.0", "1.5", "2.0"]);
        let plastic = Ticks::of(0.0..28.4);
        assert_eq!(plastic.labels, ["0", "5", "10", "15", "20", "25"]);
        let mu = Ticks::of(0.27..0.78);
        assert!(mu.labels.iter().all(|l| l.len() == 4), "{:?}", mu.labels);
        assert_eq!(Unit::for_largest("m", 3, 4.2e-15).text, "µm³");
        assert_eq!(Unit::for_largest("m", 2, 3.1e-6).text, "mm²");
        assert_eq!(Unit::for_largest("Pa", 1, 145e9).text, "GPa");
        assert_eq!(Unit::for_largest("J", 1, 2e-7).text, "nJ");
        assert_eq!(Unit::for_largest("N", 1, 3.4).text, "N");
        assert_eq!(tick_labels(&[-1e-17, 0.5]), ["0.0", "0.5"]);
    }
}
