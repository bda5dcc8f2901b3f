//! What every figure of the outputs shares: a [`Figure`] drawn on a PNG or
//! an SVG back end (by the file's extension) and written whole or not at
//! all ([`write`]), the frame of a chart, the grid of panels beside a
//! legend, the colours (series palette, map ramp) and a map's colour bar.
//! Knows no physics and no output's data; draws only what it is given.

use std::ops::Range;
use std::path::Path;

use anyhow::{anyhow, Result};
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

/// A figure of panels of 560 x 400 pixels, two a row, with a legend
/// column `legend` pixels wide at the right.
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

    /// The figure's size.
    pub fn size(&self) -> (u32, u32) {
        let rows = self.count.div_ceil(2).max(1);
        (560 * self.cols() as u32 + self.legend, 400 * rows as u32)
    }

    /// The panels' areas (row by row) and the legend's.
    pub fn split<DB: DrawingBackend>(&self, root: &Area<DB>) -> (Vec<Area<DB>>, Area<DB>) {
        let (plots, legend) = root.split_horizontally(root.dim_in_pixel().0 - self.legend);
        let cols = self.cols();
        let rows = self.count.div_ceil(cols).max(1);
        (plots.split_evenly((rows, cols)), legend)
    }
}

/// Draws `points` on `chart` as a line of `colour`, 2 px, whose legend
/// entry is `label`.
pub fn labelled_line<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    points: &[(f64, f64)],
    colour: RGBColor,
    label: &str,
) -> Result<()> {
    chart
        .draw_series(LineSeries::new(
            points.iter().copied(),
            colour.stroke_width(2),
        ))
        .map_err(err)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
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
/// `steps` bands under `label`, ticks with `decimals` decimals.
pub struct ColourBar<'a> {
    /// Caption above the bar.
    pub label: &'a str,
    /// Font size of the caption.
    pub title: u32,
    /// Margins: top, bottom, left, right.
    pub margins: [u32; 4],
    /// Font size of the ticks.
    pub ticks: u32,
    /// Decimals of the ticks.
    pub decimals: usize,
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
        let decimals = self.decimals;
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_label_style(("sans-serif", self.ticks))
            .y_label_formatter(&|v| format!("{v:.decimals$}"))
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
