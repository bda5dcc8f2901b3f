//! Fretting maps (issue #37): the outputs of a sweep with the amplitude axis
//! `sweep.amplitudes_um` (and optionally `sweep.normal_loads_n`):
//! `fretting_map.csv` (one row per case), `fretting_transitions.csv` (the
//! transition amplitude per material × surface × angle × ball × load) and
//! the figure `fretting_map.png`/`.svg`. Reads the cases' per-cycle history
//! results; no physics.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::plot::{self, err, Area, Figure, Frame, Panels, Unit, PALETTE};
use super::sweep::{csv_field as cell, Row};
use crate::float_text::{fmt_f64, fmt_opt as opt};

/// Header of `fretting_map.csv` (`indenter` after `surface` in a sweep over
/// balls).
pub const FRETTING_MAP_HEADER: &str = "material,surface,angle_deg,normal_n,amplitude_um,status,regime,dissipated_j,energy_ratio,force_amplitude_n,shift_amplitude_m";
/// Header of `fretting_transitions.csv` (`indenter` after `surface` in a
/// sweep over balls).
pub const TRANSITIONS_HEADER: &str =
    "material,surface,angle_deg,normal_n,transition_um,last_partial_um,first_gross_um,method";

/// One case of the map.
#[derive(Clone, Debug)]
pub struct MapPoint {
    /// Material, surface, ball (`None` without a ball axis).
    pub material: String,
    /// Surface name.
    pub surface: String,
    /// Ball of a sweep over balls.
    pub indenter: Option<String>,
    /// Force angle, degrees.
    pub angle_deg: f64,
    /// Normal load, N.
    pub normal_n: f64,
    /// Displacement amplitude, µm.
    pub amplitude_um: f64,
    /// `ok`, `not_converged`, `failed`.
    pub status: String,
    /// `partial`, `gross`, `mixed` (None when the case has no result).
    pub regime: Option<String>,
    /// Energy dissipated in the last cycle, J.
    pub dissipated_j: Option<f64>,
    /// A = W/(4F*δ*).
    pub energy_ratio: Option<f64>,
    /// F*, N.
    pub force_amplitude_n: Option<f64>,
    /// δ*, m.
    pub shift_amplitude_m: Option<f64>,
}

/// The map's points: level-0 cases with an amplitude, by material,
/// surface, ball, angle, load and amplitude (numerically).
pub fn map_points(rows: &[Row]) -> Vec<MapPoint> {
    let mut v: Vec<MapPoint> = rows
        .iter()
        .filter(|r| r.key.level == 0)
        .filter_map(|r| {
            let key = r.key;
            let amplitude_um = key.amplitude_um?;
            let h = r.scalars.as_ref().and_then(|s| s.history.as_ref());
            Some(MapPoint {
                material: key.material.clone(),
                surface: key.surface.clone(),
                indenter: key.indenter.clone(),
                angle_deg: key.angle_deg,
                normal_n: r.spec.load.normal_force_n,
                amplitude_um,
                status: r.status.to_string(),
                regime: h.and_then(|h| h.regime.clone()),
                dissipated_j: h.and_then(|h| h.dissipated_energy_per_cycle_j),
                energy_ratio: h.and_then(|h| h.energy_ratio),
                force_amplitude_n: h.and_then(|h| h.force_amplitude_n),
                shift_amplitude_m: h.and_then(|h| h.shift_amplitude_m),
            })
        })
        .collect();
    v.sort_by(|a, b| {
        (&a.material, &a.surface, &a.indenter)
            .cmp(&(&b.material, &b.surface, &b.indenter))
            .then(a.angle_deg.total_cmp(&b.angle_deg))
            .then(a.normal_n.total_cmp(&b.normal_n))
            .then(a.amplitude_um.total_cmp(&b.amplitude_um))
    });
    v
}

fn header(h: &str, balls: bool) -> String {
    if balls {
        h.replacen("material,surface,", "material,surface,indenter,", 1)
    } else {
        h.to_string()
    }
}

fn identity(p: &MapPoint, balls: bool) -> String {
    let mut s = format!("{},{},", cell(&p.material), cell(&p.surface));
    if balls {
        s.push_str(&cell(p.indenter.as_deref().unwrap_or_default()));
        s.push(',');
    }
    s.push_str(&fmt_f64(p.angle_deg));
    s
}

/// Text of `fretting_map.csv`.
pub fn fretting_map_csv(points: &[MapPoint]) -> String {
    let balls = points.iter().any(|p| p.indenter.is_some());
    let mut out = header(FRETTING_MAP_HEADER, balls);
    out.push('\n');
    for p in points {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{}",
            identity(p, balls),
            fmt_f64(p.normal_n),
            fmt_f64(p.amplitude_um),
            p.status,
            p.regime.as_deref().unwrap_or_default(),
            opt(p.dissipated_j),
            opt(p.energy_ratio),
            opt(p.force_amplitude_n),
            opt(p.shift_amplitude_m),
        );
    }
    out
}

/// The transition of one line of the map (one material × surface × angle ×
/// ball × load, over amplitude).
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    /// Interpolated transition amplitude, µm (`None`: the regime does not
    /// change from partial to gross along the line).
    pub amplitude_um: Option<f64>,
    /// Largest partial-slip amplitude below the first gross one, µm.
    pub last_partial_um: Option<f64>,
    /// Smallest amplitude in gross (or mixed) slip, µm.
    pub first_gross_um: Option<f64>,
    /// `energy_ratio` (A interpolated linearly in amplitude to its
    /// transition value 0.2 when the bracket's A values straddle it),
    /// `midpoint` (otherwise, the bracket's middle), empty without one.
    pub method: &'static str,
}

/// The energy ratio A at the partial/gross transition of a sphere
/// (Mindlin–Deresiewicz, PHYSICS.md §5c).
pub const TRANSITION_ENERGY_RATIO: f64 = 0.2;

/// The transition along `line` (points of one line, any order): between
/// the first amplitude whose regime is not `partial` and the largest
/// `partial` one below it, interpolated linearly in amplitude where A
/// crosses 0.2 (else the bracket's middle). Cases without a regime are
/// skipped.
pub fn transition(line: &[&MapPoint]) -> Transition {
    let mut pts: Vec<&MapPoint> = line
        .iter()
        .copied()
        .filter(|p| p.regime.is_some())
        .collect();
    pts.sort_by(|a, b| a.amplitude_um.total_cmp(&b.amplitude_um));
    let none = Transition {
        amplitude_um: None,
        last_partial_um: None,
        first_gross_um: None,
        method: "",
    };
    let is_partial = |p: &MapPoint| p.regime.as_deref() == Some("partial");
    let Some(g) = pts.iter().position(|p| !is_partial(p)) else {
        return none;
    };
    let Some(lp) = pts[..g].last() else {
        return Transition {
            first_gross_um: Some(pts[g].amplitude_um),
            ..none
        };
    };
    let gp = pts[g];
    let (a0, a1) = (lp.amplitude_um, gp.amplitude_um);
    let (amplitude, method) = match (lp.energy_ratio, gp.energy_ratio) {
        (Some(r0), Some(r1))
            if (r0 - TRANSITION_ENERGY_RATIO) * (r1 - TRANSITION_ENERGY_RATIO) <= 0.0
                && r1 != r0 =>
        {
            let t = (TRANSITION_ENERGY_RATIO - r0) / (r1 - r0);
            (a0 + t.clamp(0.0, 1.0) * (a1 - a0), "energy_ratio")
        }
        _ => (0.5 * (a0 + a1), "midpoint"),
    };
    Transition {
        amplitude_um: Some(amplitude),
        last_partial_um: Some(a0),
        first_gross_um: Some(a1),
        method,
    }
}

/// Identity of a line of the map: material, surface, ball, angle, load.
type LineId = (String, String, Option<String>, u64, u64);

fn lines(points: &[MapPoint]) -> Vec<(LineId, Vec<&MapPoint>)> {
    // Plan order of first appearance, so the CSV follows the sweep.
    let mut order: Vec<LineId> = Vec::new();
    let mut by: BTreeMap<LineId, Vec<&MapPoint>> = BTreeMap::new();
    for p in points {
        let id = (
            p.material.clone(),
            p.surface.clone(),
            p.indenter.clone(),
            p.angle_deg.to_bits(),
            p.normal_n.to_bits(),
        );
        if !by.contains_key(&id) {
            order.push(id.clone());
        }
        by.entry(id).or_default().push(p);
    }
    order
        .into_iter()
        .map(|id| {
            let v = by.remove(&id).unwrap_or_default();
            (id, v)
        })
        .collect()
}

/// Text of `fretting_transitions.csv`.
pub fn transitions_csv(points: &[MapPoint]) -> String {
    let balls = points.iter().any(|p| p.indenter.is_some());
    let mut out = header(TRANSITIONS_HEADER, balls);
    out.push('\n');
    for (_, line) in lines(points) {
        let t = transition(&line);
        let _ = writeln!(
            out,
            "{},{},{},{},{},{}",
            identity(line[0], balls),
            fmt_f64(line[0].normal_n),
            opt(t.amplitude_um),
            opt(t.last_partial_um),
            opt(t.first_gross_um),
            t.method,
        );
    }
    out
}

/// Marker colour of a regime.
fn regime_colour(regime: Option<&str>) -> RGBColor {
    match regime {
        Some("partial") => PALETTE[0],
        Some("gross") => PALETTE[1],
        Some("mixed") => PALETTE[3],
        _ => RGBColor(150, 150, 150),
    }
}

/// One panel: a material × surface at its first angle (and first ball).
struct MapPanel<'a> {
    title: String,
    points: Vec<&'a MapPoint>,
    /// (load, transition amplitude) per load with a transition.
    transitions: Vec<(f64, f64)>,
}

/// Draws `fretting_map.png` / `.svg` (by `path`'s extension): one panel per
/// material × surface (first angle, first ball); amplitude on x, normal
/// load on y with several loads (energy per cycle in mJ with one), marker
/// colour the regime, the transition amplitude marked.
pub fn plot_map(path: &Path, points: &[MapPoint]) -> anyhow::Result<()> {
    let mut panels: Vec<MapPanel> = Vec::new();
    let mut index: BTreeMap<(String, String), usize> = BTreeMap::new();
    for p in points {
        let k = (p.material.clone(), p.surface.clone());
        let i = *index.entry(k).or_insert_with(|| {
            panels.push(MapPanel {
                title: format!("{} / {}, ψ = {}°", p.material, p.surface, p.angle_deg),
                points: Vec::new(),
                transitions: Vec::new(),
            });
            panels.len() - 1
        });
        let first = panels[i].points.first().map(|f| (f.angle_deg, &f.indenter));
        if first.is_none_or(|(a, b)| a == p.angle_deg && *b == p.indenter) {
            panels[i].points.push(p);
        }
    }
    for panel in &mut panels {
        let owned: Vec<MapPoint> = panel.points.iter().map(|p| (*p).clone()).collect();
        for (_, line) in lines(&owned) {
            if let Some(a) = transition(&line).amplitude_um {
                panel.transitions.push((line[0].normal_n, a));
            }
        }
    }
    let loads = {
        let mut v: Vec<u64> = points.iter().map(|p| p.normal_n.to_bits()).collect();
        v.sort();
        v.dedup();
        v.len()
    };
    let layout = Panels {
        count: panels.len(),
        legend: 140,
    };
    let figure = MapFigure {
        panels,
        layout,
        by_load: loads > 1,
    };
    plot::write(path, figure.layout.size(), &figure)
}

/// The map as drawn: its panels in their grid beside the legend; y the
/// normal load (`by_load`, several loads) or the energy per cycle.
struct MapFigure<'a> {
    panels: Vec<MapPanel<'a>>,
    layout: Panels,
    by_load: bool,
}

impl Figure for MapFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> anyhow::Result<()> {
        let (panels, by_load) = (&self.panels, self.by_load);
        let (areas, legend) = self.layout.split(root);
        // Units that read 1–1000, the same in every panel: the amplitude
        // (µm), the normal load (N or kN) or the energy per cycle.
        let all = panels.iter().flat_map(|p| p.points.iter());
        let largest = |f: &dyn Fn(&MapPoint) -> Option<f64>| {
            all.clone()
                .filter_map(|p| f(p))
                .fold(0.0_f64, |m, v| m.max(v.abs()))
        };
        let ux = Unit::for_largest("m", 1, largest(&|p| Some(p.amplitude_um * 1e-6)));
        let uy = if by_load {
            Unit::for_largest("N", 1, largest(&|p| Some(p.normal_n)))
        } else {
            Unit::for_largest("J", 1, largest(&|p| p.dissipated_j))
        };
        let x_of = |amplitude_um: f64| amplitude_um * 1e-6 * ux.factor;
        let y_of = |p: &MapPoint| -> Option<f64> {
            if by_load {
                Some(p.normal_n * uy.factor)
            } else {
                p.dissipated_j.map(|w| w * uy.factor)
            }
        };
        for (panel, area) in panels.iter().zip(areas.iter()) {
            let xs = panel.points.iter().map(|p| x_of(p.amplitude_um));
            let (xlo, xhi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
            let ys: Vec<f64> = panel.points.iter().filter_map(|p| y_of(p)).collect();
            let (mut ylo, mut yhi) = ys
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
                    (a.min(y), b.max(y))
                });
            if !ylo.is_finite() {
                (ylo, yhi) = (0.0, 1.0);
            }
            if by_load {
                let pad = ((yhi - ylo) * 0.1).max(0.1 * yhi.abs().max(1e-3));
                (ylo, yhi) = (ylo - pad, yhi + pad);
            } else {
                (ylo, yhi) = (0.0, yhi.max(1e-12) * 1.1);
            }
            let (xlo, xhi) = if xlo.is_finite() {
                let pad = ((xhi - xlo) * 0.05).max(0.05 * xhi.abs().max(1e-3));
                (xlo - pad, xhi + pad)
            } else {
                (0.0, 1.0)
            };
            let frame = Frame {
                title: 20,
                margin: 10,
                labels: (40, 70),
            };
            let mut chart = frame.chart(area, &panel.title, xlo..xhi, ylo..yhi)?;
            let y_desc = if by_load {
                format!("normal load P ({})", uy.text)
            } else {
                format!("energy per cycle ({})", uy.text)
            };
            plot::axes(
                &mut chart,
                &format!("displacement amplitude Δ ({})", ux.text),
                &y_desc,
                true,
            )?;
            if !by_load {
                let mut line: Vec<(f64, f64)> = panel
                    .points
                    .iter()
                    .filter_map(|p| Some((x_of(p.amplitude_um), y_of(p)?)))
                    .collect();
                line.sort_by(|a, b| a.0.total_cmp(&b.0));
                chart
                    .draw_series(LineSeries::new(
                        line,
                        RGBColor(160, 160, 160).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
            chart
                .draw_series(panel.points.iter().filter_map(|p| {
                    let y = y_of(p)?;
                    let c = regime_colour(p.regime.as_deref());
                    Some(Circle::new((x_of(p.amplitude_um), y), 6, c.filled()))
                }))
                .map_err(err)?;
            // The transition: a dashed vertical line with one load, the
            // transition line through the loads with several.
            let black = BLACK.stroke_width(2);
            if by_load {
                let mut t = panel.transitions.clone();
                t.sort_by(|a, b| a.0.total_cmp(&b.0));
                let line: Vec<(f64, f64)> =
                    t.iter().map(|&(p, a)| (x_of(a), p * uy.factor)).collect();
                chart
                    .draw_series(LineSeries::new(line.clone(), black))
                    .map_err(err)?;
                chart
                    .draw_series(line.iter().map(|&c| Cross::new(c, 6, black)))
                    .map_err(err)?;
            } else {
                for &(_, a_um) in &panel.transitions {
                    let a = x_of(a_um);
                    chart
                        .draw_series(DashedLineSeries::new([(a, ylo), (a, yhi)], 6, 4, black))
                        .map_err(err)?;
                    chart
                        .draw_series([Text::new(
                            format!(" transition {a:.2} {}", ux.text),
                            (a, yhi),
                            ("sans-serif", 14).into_font(),
                        )])
                        .map_err(err)?;
                }
            }
        }
        // Legend: the regimes and the transition.
        let items: [(&str, Option<&str>); 4] = [
            ("partial slip", Some("partial")),
            ("gross slip", Some("gross")),
            ("mixed", Some("mixed")),
            ("no result", None),
        ];
        for (k, (label, regime)) in items.iter().enumerate() {
            let y = 40 + 26 * k as i32;
            legend
                .draw(&Circle::new((14, y), 6, regime_colour(*regime).filled()))
                .map_err(err)?;
            legend
                .draw(&Text::new(
                    *label,
                    (28, y - 8),
                    ("sans-serif", 15).into_font(),
                ))
                .map_err(err)?;
        }
        let y = 40 + 26 * 4;
        legend
            .draw(&PathElement::new(
                vec![(6, y), (22, y)],
                BLACK.stroke_width(2),
            ))
            .map_err(err)?;
        legend
            .draw(&Text::new(
                "transition",
                (28, y - 8),
                ("sans-serif", 15).into_font(),
            ))
            .map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(a: f64, regime: &str, ratio: f64) -> MapPoint {
        MapPoint {
            material: "Cu".into(),
            surface: "flat".into(),
            indenter: None,
            angle_deg: 0.0,
            normal_n: 6000.0,
            amplitude_um: a,
            status: "ok".into(),
            regime: Some(regime.into()),
            dissipated_j: Some(1e-6 * a),
            energy_ratio: Some(ratio),
            force_amplitude_n: Some(1.0),
            shift_amplitude_m: Some(a * 1e-6),
        }
    }

    #[test]
    fn issue37_transition_is_interpolated_in_its_bracket() {
        let pts = [
            pt(1.0, "partial", 0.1),
            pt(2.0, "partial", 0.15),
            pt(3.0, "gross", 0.25),
            pt(4.0, "gross", 0.5),
        ];
        let line: Vec<&MapPoint> = pts.iter().rev().collect();
        let t = transition(&line);
        assert_eq!(t.last_partial_um, Some(2.0));
        assert_eq!(t.first_gross_um, Some(3.0));
        assert_eq!(t.method, "energy_ratio");
        assert!((t.amplitude_um.unwrap() - 2.5).abs() < 1e-12);
        // No crossing of A = 0.2 in the bracket: its middle.
        let pts2 = [pt(1.0, "partial", 0.1), pt(3.0, "gross", 0.15)];
        let t = transition(&pts2.iter().collect::<Vec<_>>());
        assert_eq!((t.amplitude_um, t.method), (Some(2.0), "midpoint"));
        // No change: empty.
        let all_partial = [pt(1.0, "partial", 0.1), pt(2.0, "partial", 0.1)];
        let t = transition(&all_partial.iter().collect::<Vec<_>>());
        assert_eq!(t.amplitude_um, None);
        let csv = transitions_csv(&all_partial);
        assert_eq!(csv.lines().nth(1), Some("Cu,flat,0,6000,,,,"), "{csv}");
        let csv = fretting_map_csv(&pts);
        assert!(csv.starts_with(FRETTING_MAP_HEADER));
        assert_eq!(
            csv.lines().nth(3),
            Some("Cu,flat,0,6000,3,ok,gross,3e-6,0.25,1,3e-6"),
            "{csv}"
        );
    }
}
