//! PNG contour maps of one case's surface fields, in the paper's style
//! (Figs. 4, 5, 7, 8): p/p_H, qx/p_H, qy/p_H, slip magnitude and the
//! stick/slip map, axes in units of the contact radius, with a colour bar;
//! [`Heat`], a rectangular map with marks (the stress planes and slices);
//! and the surface a case was solved on with its contact and stick
//! outlines over it ([`write_surface_map`]). Drawing only (through
//! `plot`); the fields come from `solver::Fields`.

use anyhow::Result;
use plotters::prelude::*;
use solver::{CaseScalars, Fields};
use std::borrow::Cow;
use std::path::Path;

use super::plot::{self, err, ramp, Area, ColourBar, Figure, Frame, Unit};

/// The size of a map (PNG).
const SIZE: (u32, u32) = (760, 640);
/// The width of the map; its colour bar takes the rest.
const MAP_WIDTH: u32 = 620;

/// One map: `values` (n x n, row-major [iy][ix]) drawn over |x|, |y| ≤
/// extent·a, under `label`; with a `unit` (`m`), the values are in it and
/// shown with the prefix that makes them read 1–1000 ([`Unit`]).
struct Map<'a> {
    file: Cow<'a, str>,
    label: Cow<'a, str>,
    values: Vec<f64>,
    unit: Option<&'static str>,
}

impl Map<'_> {
    /// The map with its values in the unit that reads 1–1000 and the unit
    /// named in its label (as it is: without a unit).
    fn in_its_unit(mut self) -> Self {
        if let Some(base) = self.unit.take() {
            let largest = self.values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let u = Unit::for_largest(base, 1, largest);
            self.values.iter_mut().for_each(|v| *v *= u.factor);
            self.label = format!("{} ({})", self.label, u.text).into();
        }
        self
    }
}

/// The colour bar beside a map: the ramp from `lo` to `hi` under `label`.
fn colour_bar<DB: DrawingBackend>(bar: &Area<DB>, label: &str, lo: f64, hi: f64) -> Result<()> {
    ColourBar {
        label,
        title: 14,
        margins: [12, 50, 8, 8],
        ticks: 13,
        steps: 200,
    }
    .draw(bar, lo, hi)
}

/// A [`Map`] of a case as drawn: its title, the grid (n cells of dx), the
/// contact radius a and the extent of the axes in units of a.
struct MapFigure<'a> {
    title: &'a str,
    map: &'a Map<'a>,
    n: usize,
    dx: f64,
    a: f64,
    extent: f64,
}

impl Figure for MapFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<()> {
        let &MapFigure {
            title,
            map,
            n,
            dx,
            a,
            extent,
        } = self;
        let (main, bar) = root.split_horizontally(MAP_WIDTH);
        let half = 0.5 * (n as f64 - 1.0);
        let to_x = |i: usize| (i as f64 - half) * dx / a;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let inside = |i: usize| to_x(i).abs() <= extent;
        for iy in (0..n).filter(|&i| inside(i)) {
            for ix in (0..n).filter(|&i| inside(i)) {
                let v = map.values[iy * n + ix];
                if v.is_finite() {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
        }
        if !(lo.is_finite() && hi > lo) {
            (lo, hi) = (lo.min(0.0), lo.max(0.0) + 1.0);
        }
        let frame = Frame {
            title: 18,
            margin: 10,
            labels: (40, 50),
        };
        let mut chart = frame.chart(&main, title, -extent..extent, -extent..extent)?;
        plot::axes(&mut chart, "x / a", "y / a", false)?;
        let h = 0.5 * dx / a;
        chart
            .draw_series((0..n).filter(|&i| inside(i)).flat_map(|iy| {
                let values = &map.values;
                (0..n).filter(move |&i| inside(i)).map(move |ix| {
                    let (x, y) = (to_x(ix), to_x(iy));
                    let t = (values[iy * n + ix] - lo) / (hi - lo);
                    Rectangle::new([(x - h, y - h), (x + h, y + h)], ramp(t).filled())
                })
            }))
            .map_err(err)?;
        colour_bar(&bar, &map.label, lo, hi)
    }
}

/// Writes `p.png`, `qx.png`, `qy.png`, `slip.png` and `stick.png` into `dir`
/// (and `plastic.png`, the dent, on a surface with a hardness; `wear.png`
/// and `ball_wear.png`, the worn depths, after a path with a wear law).
/// `title` names the case (material, surface, ψ). Axes are x/a with a the
/// apparent contact radius; tractions are normalised by the Hertz pressure p_H.
pub fn write_maps(
    dir: &Path,
    title: &str,
    fields: &Fields,
    s: &CaseScalars,
    spacing_m: f64,
) -> Result<()> {
    let n = fields.n;
    let ph = s.hertz_pressure_pa;
    let a = s.contact_radius_m.max(spacing_m);
    let norm = |v: &[f64]| v.iter().map(|x| x / ph).collect::<Vec<f64>>();
    let slip: Vec<f64> = fields
        .sx
        .iter()
        .zip(&fields.sy)
        .map(|(x, y)| x.hypot(*y))
        .collect();
    // Stick/slip map: 0 outside contact, 1 slip, 2 stick.
    let status: Vec<f64> = (0..n * n)
        .map(|i| {
            if fields.p[i] <= 0.0 {
                0.0
            } else if fields.stick[i] > 0.5 {
                2.0
            } else {
                1.0
            }
        })
        .collect();
    let mut maps = vec![
        Map {
            file: "p.png".into(),
            label: "p / p_H".into(),
            values: norm(&fields.p),
            unit: None,
        },
        Map {
            file: "qx.png".into(),
            label: "qx / p_H".into(),
            values: norm(&fields.qx),
            unit: None,
        },
        Map {
            file: "qy.png".into(),
            label: "qy / p_H".into(),
            values: norm(&fields.qy),
            unit: None,
        },
        Map {
            file: "slip.png".into(),
            label: "|s|".into(),
            values: slip,
            unit: Some("m"),
        },
        Map {
            file: "stick.png".into(),
            label: "0 free, 1 slip, 2 stick".into(),
            values: status,
            unit: None,
        },
    ];
    // On a surface with a hardness: the dent (permanent plastic
    // penetration).
    if !fields.plastic.is_empty() {
        maps.push(Map {
            file: "plastic.png".into(),
            label: "plastic penetration".into(),
            values: fields.plastic.clone(),
            unit: Some("m"),
        });
    }
    // After a path with a wear law: the worn depths (the substrate's in
    // its own frame, the ball's in the grid's).
    for (file, label, worn) in [
        ("wear.png", "worn depth", &fields.wear),
        ("ball_wear.png", "ball worn", &fields.ball_wear),
    ] {
        if !worn.is_empty() {
            maps.push(Map {
                file: file.into(),
                label: label.into(),
                values: worn.clone(),
                unit: Some("m"),
            });
        }
    }
    // And at the saved cycles (the last is `wear.png`'s).
    for (cycle, worn) in &fields.wear_saved {
        maps.push(Map {
            file: format!("wear_cycle_{cycle}.png").into(),
            label: format!("worn depth, simulated cycle {cycle}").into(),
            values: worn.clone(),
            unit: Some("m"),
        });
    }
    let extent = (1.3_f64).min(0.5 * n as f64 * spacing_m / a);
    for m in maps.into_iter().map(Map::in_its_unit) {
        let m = &m;
        let path = dir.join(m.file.as_ref());
        let label = format!("{title}: {}", m.label);
        let figure = MapFigure {
            title: &label,
            map: m,
            n,
            dx: spacing_m,
            a,
            extent,
        };
        plot::write(&path, SIZE, &figure)?;
    }
    Ok(())
}

/// A rectangular map of `values` (`rows x cols`, row major, row 0 at
/// `y_range.0`) over `x_range x y_range` (cell centres at the ends), with
/// black marks at `marks`: the stress planes and slices (`output::stress`),
/// where the marks are the contact edge.
pub struct Heat<'a> {
    /// Title above the map.
    pub title: &'a str,
    /// Label of the colour bar.
    pub label: &'a str,
    /// Columns and rows.
    pub cols: usize,
    /// See `cols`.
    pub rows: usize,
    /// The values.
    pub values: &'a [f64],
    /// First and last column's coordinate.
    pub x_range: (f64, f64),
    /// First and last row's coordinate.
    pub y_range: (f64, f64),
    /// Axis names.
    pub axes: (&'a str, &'a str),
    /// Points to mark (black).
    pub marks: &'a [(f64, f64)],
    /// More points to mark, in white (a second outline).
    pub light_marks: &'a [(f64, f64)],
}

/// Draws a [`Heat`] map into `path` (PNG, written whole or not at all).
pub fn write_heat(path: &Path, heat: &Heat) -> Result<()> {
    plot::write(path, SIZE, heat)
}

impl Figure for Heat<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> Result<()> {
        let m = self;
        let (main, bar) = root.split_horizontally(MAP_WIDTH);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in m.values.iter().filter(|v| v.is_finite()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        if !(lo.is_finite() && hi > lo) {
            (lo, hi) = (lo.min(0.0), lo.max(0.0) + 1.0);
        }
        let step = |r: (f64, f64), k: usize| {
            if k > 1 {
                (r.1 - r.0) / (k - 1) as f64
            } else {
                1.0
            }
        };
        let (hx, hy) = (0.5 * step(m.x_range, m.cols), 0.5 * step(m.y_range, m.rows));
        let (x0, x1) = (m.x_range.0 - hx, m.x_range.1 + hx);
        let (ya, yb) = (m.y_range.0 - hy, m.y_range.1 + hy);
        let (y0, y1) = (ya.min(yb), ya.max(yb));
        let frame = Frame {
            title: 16,
            margin: 10,
            labels: (40, 50),
        };
        let mut chart = frame.chart(&main, m.title, x0..x1, y0..y1)?;
        plot::axes(&mut chart, m.axes.0, m.axes.1, false)?;
        let (dx, dy) = (2.0 * hx, 2.0 * hy);
        chart
            .draw_series((0..m.rows).flat_map(|r| {
                (0..m.cols).map(move |c| {
                    let x = m.x_range.0 + c as f64 * dx;
                    let y = m.y_range.0 + r as f64 * dy;
                    let t = (m.values[r * m.cols + c] - lo) / (hi - lo);
                    Rectangle::new(
                        [(x - hx, y - hy.abs()), (x + hx, y + hy.abs())],
                        ramp(t).filled(),
                    )
                })
            }))
            .map_err(err)?;
        chart
            .draw_series(
                m.marks
                    .iter()
                    .map(|&(x, y)| Circle::new((x, y), 2, BLACK.filled())),
            )
            .map_err(err)?;
        chart
            .draw_series(
                m.light_marks
                    .iter()
                    .map(|&(x, y)| Circle::new((x, y), 2, WHITE.filled())),
            )
            .map_err(err)?;
        colour_bar(&bar, m.label, lo, hi)
    }
}

/// The cells of `inside` (n x n) with a 4-neighbour outside it (or on the
/// grid's edge): the zone's outline, as cell centres in µm.
fn outline(inside: &[bool], n: usize, dx: f64, dy: f64) -> Vec<(f64, f64)> {
    let half = 0.5 * (n as f64 - 1.0);
    (0..n * n)
        .filter(|&i| {
            let (iy, ix) = (i / n, i % n);
            inside[i]
                && (ix == 0
                    || iy == 0
                    || ix + 1 == n
                    || iy + 1 == n
                    || !inside[i - 1]
                    || !inside[i + 1]
                    || !inside[i - n]
                    || !inside[i + n])
        })
        .map(|i| {
            (
                ((i % n) as f64 - half) * dx * 1e6,
                ((i / n) as f64 - half) * dy * 1e6,
            )
        })
        .collect()
}

/// Writes `surface.png` into `dir`: the heights the case was solved on
/// (µm, n x n cells of `dx x dy`) with the contact's outline (black) and
/// the stick zone's (white) over them.
pub fn write_surface_map(
    dir: &Path,
    title: &str,
    heights: &[f64],
    fields: &Fields,
    (dx, dy): (f64, f64),
) -> Result<()> {
    let n = fields.n;
    let contact: Vec<bool> = fields.p.iter().map(|&p| p > 0.0).collect();
    let stick: Vec<bool> = (0..n * n)
        .map(|i| contact[i] && fields.stick[i] > 0.5)
        .collect();
    let values: Vec<f64> = heights.iter().map(|h| h * 1e6).collect();
    let (x1, y1) = (
        0.5 * (n as f64 - 1.0) * dx * 1e6,
        0.5 * (n as f64 - 1.0) * dy * 1e6,
    );
    let label = format!("{title}: surface, contact (black) and stick (white) outlines");
    let heat = Heat {
        title: &label,
        label: "height (µm)",
        cols: n,
        rows: n,
        values: &values,
        x_range: (-x1, x1),
        y_range: (-y1, y1),
        axes: ("x (µm)", "y (µm)"),
        marks: &outline(&contact, n, dx, dy),
        light_marks: &outline(&stick, n, dx, dy),
    };
    write_heat(&dir.join("surface.png"), &heat)
}
