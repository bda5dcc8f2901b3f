//! Orientation maps (issue #39): the outputs of a sweep with
//! `sweep.orientations` — `orientations.csv` (one row per orientation ×
//! surface × ball × load × amplitude: what the orientation does, from the
//! crystal alone and from the solved cases) and the inverse-pole-figure
//! maps `ipf/<crystal>/<surface>/<quantity>.png|svg`. The crystal's own
//! quantities come from `solver::indentation`; the rest are reductions of
//! the cases' results over the force angles.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use plotters::prelude::*;

use super::plot::{self, err, ramp, Area, ColourBar, Figure, Frame, Unit};
use super::sweep::{csv_field, Axes, CurvePoint, Row};
use crate::case::CaseKey;
use crate::config::orientations::{ipf_xy, miller_text};
use crate::config::Orientation;
use crate::float_text::{fmt_f64, fmt_opt as opt};

/// Header of `orientations.csv` (`indenter`, `normal_n`, `amplitude_um`
/// after `surface` as in the other CSVs of a sweep with those axes).
pub const ORIENTATIONS_HEADER: &str = "material,orientation,x_dir,ipf_x,ipf_y,surface,indentation_modulus_gpa,compliance_ratio,contact_long_m,contact_short_m,contact_angle_deg,contact_p_max_pa,angles,mu_a_mean,mu_a_min,mu_a_max,mu_a_err_max,k_e_mean,k_e_min,k_e_max,dissipated_j_mean,dissipated_j_min,dissipated_j_max,dissipated_j_err_max";

/// One orientation on one surface (× ball × load × amplitude).
#[derive(Clone, Debug)]
pub struct OrientationRow {
    /// The orientation.
    pub orientation: Orientation,
    /// Its cases' key at angle 0 (surface and the other axes).
    pub key: CaseKey,
    /// Vlassak–Nix indentation modulus of the crystal, Pa.
    pub modulus: f64,
    /// ⟨(H11 + H22)/2⟩/⟨H33⟩.
    pub compliance_ratio: f64,
    /// Willis's frictionless contact at the case's load and ball.
    pub contact: solver::indentation::WillisContact,
    /// Force angles with a curve point.
    pub angles: usize,
    /// (mean, min, max) of μa over the angles.
    pub mu_a: Option<(f64, f64, f64)>,
    /// Largest error bar of μa over the angles (a ladder's).
    pub mu_a_err: Option<f64>,
    /// (mean, min, max) of K_E over the angles, Pa.
    pub k_e: Option<(f64, f64, f64)>,
    /// (mean, min, max) of the energy per cycle over the angles, J.
    pub dissipated: Option<(f64, f64, f64)>,
    /// Largest error bar of the energy per cycle over the angles, J.
    pub dissipated_err: Option<f64>,
}

fn stats(v: &[f64]) -> Option<(f64, f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some((mean, min, max))
}

/// The table's rows: for every orientation, each surface (× the other
/// axes) its level-0 cases were solved on, in the order of the sweep.
pub fn orientation_rows(
    rows: &[Row],
    points: &[CurvePoint],
    orientations: &[Orientation],
) -> Vec<OrientationRow> {
    let by_name: BTreeMap<&str, &Orientation> =
        orientations.iter().map(|o| (o.name.as_str(), o)).collect();
    // The crystal's own quantities, once per material; Willis's contact once
    // per material, ball and load (not per surface).
    let mut crystal: BTreeMap<String, solver::indentation::InPlaneMeans> = BTreeMap::new();
    type ContactKey = (String, Option<String>, u64);
    let mut contacts: BTreeMap<ContactKey, solver::indentation::WillisContact> = BTreeMap::new();
    let mut out: Vec<OrientationRow> = Vec::new();
    let mut index: BTreeMap<String, usize> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.key.level == 0) {
        let Some(o) = by_name.get(r.key.material.as_str()) else {
            continue;
        };
        let mut key = r.key.point();
        key.angle_deg = 0.0;
        let text = key.to_string();
        if index.contains_key(&text) {
            continue;
        }
        let spec = r.spec;
        let means = *crystal
            .entry(o.name.clone())
            .or_insert_with(|| solver::indentation::InPlaneMeans::of(&spec.material));
        let ball = spec.indenter.as_ref();
        let contact = *contacts
            .entry((
                o.name.clone(),
                ball.map(|b| b.name.clone()),
                spec.load.normal_force_n.to_bits(),
            ))
            .or_insert_with(|| {
                // The pair's normal compliance: the ball's frame is the
                // substrate's turned 180° about x, so its direction θ is the
                // ball's −θ.
                let h33 = |th: f64| {
                    spec.material.surface_compliance(th)[(2, 2)].re
                        + ball.map_or(0.0, |b| b.surface_compliance(-th)[(2, 2)].re)
                };
                solver::indentation::willis_contact(
                    &h33,
                    spec.load.normal_force_n,
                    spec.load.indenter_radius_m,
                )
            });
        let (modulus, ratio) = (means.indentation_modulus(), means.compliance_ratio());
        index.insert(text, out.len());
        out.push(OrientationRow {
            orientation: (*o).clone(),
            key,
            modulus,
            compliance_ratio: ratio,
            contact,
            angles: 0,
            mu_a: None,
            mu_a_err: None,
            k_e: None,
            dissipated: None,
            dissipated_err: None,
        });
    }
    // The curve points' reductions over the angles.
    let mut gathered: BTreeMap<usize, Vec<&CurvePoint>> = BTreeMap::new();
    for p in points {
        let mut key = p.key.clone();
        key.angle_deg = 0.0;
        if let Some(&i) = index.get(&key.to_string()) {
            gathered.entry(i).or_default().push(p);
        }
    }
    for (i, ps) in gathered {
        let row = &mut out[i];
        row.angles = ps.len();
        let mu: Vec<f64> = ps.iter().map(|p| p.mu_a.value).collect();
        row.mu_a = stats(&mu);
        let largest = |errs: &mut dyn Iterator<Item = f64>| {
            errs.fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))))
        };
        row.mu_a_err = largest(&mut ps.iter().filter_map(|p| p.mu_a.err));
        row.dissipated_err = largest(
            &mut ps
                .iter()
                .filter_map(|p| p.dissipated.as_ref().and_then(|d| d.err)),
        );
        let ke: Vec<f64> = ps.iter().map(|p| p.k_e.value).collect();
        row.k_e = stats(&ke);
        let w: Vec<f64> = ps
            .iter()
            .filter_map(|p| p.dissipated.as_ref().map(|d| d.value))
            .collect();
        if w.len() == ps.len() {
            row.dissipated = stats(&w);
        }
    }
    out
}

/// Text of `orientations.csv`.
pub fn orientations_csv(rows: &[OrientationRow]) -> String {
    let axes = Axes::of(rows.iter().map(|r| &r.key));
    let mut out = String::from(ORIENTATIONS_HEADER);
    let mut extra = String::new();
    for (on, name) in [
        (axes.balls, super::sweep::INDENTER_COLUMN),
        (axes.loads, super::sweep::NORMAL_COLUMN),
        (axes.amplitudes, super::sweep::AMPLITUDE_COLUMN),
    ] {
        if on {
            extra.push(',');
            extra.push_str(name);
        }
    }
    out = out.replacen(",surface,", &format!(",surface{extra},"), 1);
    out.push('\n');
    let triple = |v: Option<(f64, f64, f64)>| {
        let (a, b, c) = match v {
            Some((a, b, c)) => (Some(a), Some(b), Some(c)),
            None => (None, None, None),
        };
        format!("{},{},{}", opt(a), opt(b), opt(c))
    };
    for r in rows {
        let o = &r.orientation;
        let (x, y) = o.ipf_xy();
        let mut ident = csv_field(&r.key.surface);
        if axes.balls {
            ident.push(',');
            ident.push_str(&csv_field(r.key.indenter.as_deref().unwrap_or_default()));
        }
        if axes.loads {
            ident.push(',');
            ident.push_str(&opt(r.key.normal_n));
        }
        if axes.amplitudes {
            ident.push(',');
            ident.push_str(&opt(r.key.amplitude_um));
        }
        let c = &r.contact;
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            csv_field(&o.base),
            csv_field(&miller_text(o.normal)),
            csv_field(&miller_text(o.x_dir)),
            fmt_f64(x),
            fmt_f64(y),
            ident,
            fmt_f64(r.modulus / 1e9),
            fmt_f64(r.compliance_ratio),
            fmt_f64(c.long_m),
            fmt_f64(c.short_m),
            // A circular contact has no long axis.
            if c.short_m / c.long_m > 1.0 - 1e-9 {
                String::new()
            } else {
                fmt_f64(c.long_angle_rad.to_degrees())
            },
            fmt_f64(c.p_max_pa),
            r.angles,
            triple(r.mu_a),
            opt(r.mu_a_err),
            triple(r.k_e),
            triple(r.dissipated),
            opt(r.dissipated_err),
        );
    }
    out
}

/// One map: a quantity over the orientations of one crystal on one surface.
pub struct IpfMap {
    /// File stem and directory under `ipf/`.
    pub path: PathBuf,
    /// Title.
    pub title: String,
    /// Colour-bar label: the quantity, without its unit.
    pub label: String,
    /// The values' SI unit (`Pa`, `J`), shown with the prefix that makes
    /// them read 1–1000 (`plot::Unit`); `None` for a ratio.
    pub unit: Option<&'static str>,
    /// (normal, value) of each orientation.
    pub points: Vec<([f64; 3], f64)>,
}

/// The maps of `rows`: per crystal, its indentation modulus and compliance
/// ratio; per crystal × surface (× other axes), μa's mean and range over
/// the force angles, K_E's mean and the energy per cycle's mean and range,
/// for each quantity every orientation has.
pub fn ipf_maps(rows: &[OrientationRow]) -> Vec<IpfMap> {
    let mut groups: BTreeMap<(String, String), Vec<&OrientationRow>> = BTreeMap::new();
    for r in rows {
        let mut k = r.key.clone();
        k.material = String::new();
        groups
            .entry((r.orientation.base.clone(), k.to_string()))
            .or_default()
            .push(r);
    }
    let safe = |s: &str| -> String {
        s.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "._-()+@".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    };
    let mut maps = Vec::new();
    let mut crystals_done: Vec<String> = Vec::new();
    for ((base, _), rs) in &groups {
        let dir = PathBuf::from(safe(base));
        if !crystals_done.contains(base) {
            crystals_done.push(base.clone());
            let one = |f: &dyn Fn(&OrientationRow) -> f64| -> Vec<([f64; 3], f64)> {
                let mut seen = Vec::new();
                rs.iter()
                    .filter(|r| {
                        let new = !seen.contains(&r.orientation.name);
                        seen.push(r.orientation.name.clone());
                        new
                    })
                    .map(|r| (r.orientation.normal, f(r)))
                    .collect()
            };
            maps.push(IpfMap {
                path: dir.join("indentation_modulus"),
                title: format!("{base}: indentation modulus M (Vlassak–Nix)"),
                label: "M".into(),
                unit: Some("Pa"),
                points: one(&|r| r.modulus),
            });
            maps.push(IpfMap {
                path: dir.join("compliance_ratio"),
                title: format!("{base}: tangential / normal compliance"),
                label: "⟨H11+H22⟩/2⟨H33⟩".into(),
                unit: None,
                points: one(&|r| r.compliance_ratio),
            });
        }
        let r0 = rs[0];
        let surface_dir = dir.join(safe(
            &format!("{}{}", r0.key.surface, ball_and_axes(&r0.key)).replace('/', "_"),
        ));
        let what = format!("{base} / {}{}", r0.key.surface, ball_and_axes(&r0.key));
        let angles = rs.iter().map(|r| r.angles).max().unwrap_or(0);
        let mut add = |stem: &str,
                       title: String,
                       (label, unit): (&str, Option<&'static str>),
                       f: &dyn Fn(&OrientationRow) -> Option<f64>| {
            let pts: Option<Vec<([f64; 3], f64)>> = rs
                .iter()
                .map(|r| Some((r.orientation.normal, f(r)?)))
                .collect();
            // A constant (μa on a flat surface whose K_E calibrates on
            // itself, a range that is zero) is no map.
            let varies = |p: &Vec<([f64; 3], f64)>| {
                let (lo, hi) = p
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
                        (a.min(q.1), b.max(q.1))
                    });
                hi - lo > 1e-9 * lo.abs().max(hi.abs())
            };
            if let Some(points) = pts.filter(|p| !p.is_empty() && varies(p)) {
                maps.push(IpfMap {
                    path: surface_dir.join(stem),
                    title,
                    label: label.into(),
                    unit,
                    points,
                });
            }
        };
        let over = if angles > 1 {
            format!("mean over {angles} force angles")
        } else {
            "one force angle".into()
        };
        add(
            "mu_a",
            format!("{what}: μa, {over}"),
            ("μa", None),
            &|r| Some(r.mu_a?.0),
        );
        add(
            "k_e",
            format!("{what}: K_E, {over}"),
            ("K_E", Some("Pa")),
            &|r| Some(r.k_e?.0),
        );
        if angles > 1 {
            add(
                "k_e_range",
                format!("{what}: range of K_E over {angles} force angles"),
                ("max − min K_E", Some("Pa")),
                &|r| r.k_e.map(|(_, lo, hi)| hi - lo),
            );
        }
        add(
            "energy_per_cycle",
            format!("{what}: energy per cycle, {over}"),
            ("W", Some("J")),
            &|r| Some(r.dissipated?.0),
        );
        if angles > 1 {
            add(
                "mu_a_range",
                format!("{what}: range of μa over {angles} force angles"),
                ("max − min μa", None),
                &|r| r.mu_a.map(|(_, lo, hi)| hi - lo),
            );
            add(
                "energy_per_cycle_range",
                format!("{what}: range of the energy per cycle over {angles} angles"),
                ("max − min W", Some("J")),
                &|r| r.dissipated.map(|(_, lo, hi)| hi - lo),
            );
        }
    }
    maps
}

fn ball_and_axes(key: &CaseKey) -> String {
    let mut t = String::new();
    if let Some(b) = &key.indenter {
        t.push_str(&format!("@{b}"));
    }
    t.push_str(&key.axes_text());
    t
}

/// Inverse stereographic projection of the standard triangle's plane.
fn unit_of(x: f64, y: f64) -> Vector3<f64> {
    let s = x * x + y * y;
    Vector3::new(2.0 * x, 2.0 * y, 1.0 - s) / (1.0 + s)
}

/// A computed orientation in the projected plane, for the triangulation.
struct Site {
    at: spade::Point2<f64>,
    value: f64,
}

impl spade::HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> spade::Point2<f64> {
        self.at
    }
}

/// The map's interpolant: Sibson's natural-neighbour interpolation on the
/// Delaunay triangulation of the projected orientations — a convex
/// combination of the neighbours' values (no overshoot, exact at each
/// orientation), smooth between them — and, outside their convex hull
/// (the sliver between the curved (101)–(111) edge and its chords, or a
/// short list of normals), Shepard's inverse-distance weighting.
struct Interpolant<'a> {
    dt: spade::DelaunayTriangulation<Site>,
    pts: &'a [(Vector3<f64>, f64)],
}

impl<'a> Interpolant<'a> {
    fn new(pts: &'a [(Vector3<f64>, f64)]) -> Self {
        use spade::Triangulation as _;
        let mut dt = spade::DelaunayTriangulation::<Site>::new();
        for (v, value) in pts {
            let at = spade::Point2::new(v.x / (1.0 + v.z), v.y / (1.0 + v.z));
            // A repeated point (an equivalent normal) keeps the first value;
            // a point spade cannot take (not finite) is left to Shepard.
            let _ = dt.insert(Site { at, value: *value });
        }
        Interpolant { dt, pts }
    }

    fn at(&self, x: f64, y: f64) -> f64 {
        use spade::Triangulation as _;
        let inside = if self.dt.num_vertices() >= 3 {
            self.dt
                .natural_neighbor()
                .interpolate(|v| v.data().value, spade::Point2::new(x, y))
        } else {
            None
        };
        inside.unwrap_or_else(|| interpolate(&unit_of(x, y), self.pts))
    }
}

/// The value at the unit direction `v` between the orientations `pts`
/// (unit normals reduced to the triangle): Shepard's inverse-distance
/// weighting on the angle, power 2 — exact at each computed orientation,
/// bounded by the values, no overshoot between them.
fn interpolate(v: &Vector3<f64>, pts: &[(Vector3<f64>, f64)]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (p, val) in pts {
        let ang = p.dot(v).clamp(-1.0, 1.0).acos();
        // acos near 1 resolves ~1e-8 rad: closer than 1e-7 is the point.
        if ang < 1e-7 {
            return *val;
        }
        let w = 1.0 / (ang * ang);
        num += w * val;
        den += w;
    }
    num / den
}

/// Draws `map` into `<dir>/<path>.png` and `.svg`.
pub fn write_ipf(dir: &Path, map: &IpfMap) -> anyhow::Result<()> {
    let base = dir.join(&map.path);
    if let Some(parent) = base.parent() {
        std::fs::create_dir_all(parent)?;
    }
    for ext in ["png", "svg"] {
        plot::write(&base.with_extension(ext), (640, 520), map)?;
    }
    Ok(())
}

impl Figure for IpfMap {
    fn draw<DB: DrawingBackend>(&self, root: &Area<DB>) -> anyhow::Result<()> {
        let map = self;
        let (main, bar) = root.split_horizontally(520);
        // Reduced to the triangle (the cubic symmetry), as unit vectors.
        let pts: Vec<(Vector3<f64>, f64)> = map
            .points
            .iter()
            .map(|(n, v)| {
                let (x, y) = ipf_xy(*n);
                (unit_of(x, y), *v)
            })
            .collect();
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.1), b.max(p.1))
            });
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            (lo - 0.5, lo + 0.5)
        };
        let xmax = (0.5_f64).sqrt() / (1.0 + 0.5_f64.sqrt());
        let ymax = (1.0 / 3.0_f64.sqrt()) / (1.0 + 1.0 / 3.0_f64.sqrt());
        // No label areas: the triangle's corners are labelled instead.
        let frame = Frame {
            title: 15,
            margin: 20,
            labels: (0, 0),
        };
        let mut chart = frame.chart(&main, &map.title, -0.03..xmax + 0.03, -0.05..ymax + 0.06)?;
        // Fill: cells of the projected plane inside the triangle.
        let cols = 110;
        let h = (xmax + 0.0) / cols as f64;
        let rows = (ymax / h).ceil() as usize + 1;
        let field = Interpolant::new(&pts);
        let mut cells = Vec::new();
        for j in 0..rows {
            for i in 0..=cols {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                let v = unit_of(x, y);
                if v.y < 0.0 || v.x < v.y || v.z < v.x {
                    continue;
                }
                let t = (field.at(x, y) - lo) / (hi - lo);
                cells.push(Rectangle::new(
                    [(x - 0.5 * h, y - 0.5 * h), (x + 0.5 * h, y + 0.5 * h)],
                    ramp(t).filled(),
                ));
            }
        }
        chart.draw_series(cells).map_err(err)?;
        // The triangle's edges: (001)–(101), (001)–(111) straight, (101)–(111)
        // the projected great circle z = x.
        let mut edge: Vec<(f64, f64)> = vec![(0.0, 0.0), (xmax, 0.0)];
        let (a, b) = (
            Vector3::<f64>::new(1.0, 0.0, 1.0).normalize(),
            Vector3::<f64>::new(1.0, 1.0, 1.0).normalize(),
        );
        let arc = a.dot(&b).acos();
        for k in 0..=40 {
            let t = k as f64 / 40.0;
            let v = (a * ((1.0 - t) * arc).sin() + b * (t * arc).sin()) / arc.sin();
            edge.push((v.x / (1.0 + v.z), v.y / (1.0 + v.z)));
        }
        edge.push((0.0, 0.0));
        chart
            .draw_series(std::iter::once(PathElement::new(
                edge,
                BLACK.stroke_width(2),
            )))
            .map_err(err)?;
        chart
            .draw_series(pts.iter().map(|(v, _)| {
                Circle::new((v.x / (1.0 + v.z), v.y / (1.0 + v.z)), 3, BLACK.filled())
            }))
            .map_err(err)?;
        let font = ("sans-serif", 16).into_font();
        for (text, at) in [
            ("001", (-0.025, -0.03)),
            ("101", (xmax - 0.02, -0.03)),
            ("111", (ymax - 0.02, ymax + 0.02)),
        ] {
            chart
                .draw_series(std::iter::once(Text::new(text, at, font.clone())))
                .map_err(err)?;
        }
        // Colour bar: in the unit that reads 1–1000, ticks by the one rule.
        let (label, factor) = match map.unit {
            Some(base) => {
                let u = Unit::for_largest(base, 1, lo.abs().max(hi.abs()));
                (format!("{} ({})", map.label, u.text), u.factor)
            }
            None => (map.label.clone(), 1.0),
        };
        ColourBar {
            label: &label,
            title: 13,
            margins: [30, 40, 6, 0],
            ticks: 12,
            steps: 120,
        }
        .draw(&bar, lo * factor, hi * factor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_exact_at_the_orientations_and_bounded_between() {
        let pts: Vec<(Vector3<f64>, f64)> = [
            ([0.0, 0.0, 1.0], 1.0),
            ([1.0, 0.0, 1.0], 3.0),
            ([1.0, 1.0, 1.0], 2.0),
        ]
        .iter()
        .map(|(n, v)| (Vector3::from(*n).normalize(), *v))
        .collect();
        for (p, v) in &pts {
            assert_eq!(interpolate(p, &pts), *v);
        }
        let mid = Vector3::new(1.0, 0.5, 2.0).normalize();
        let m = interpolate(&mid, &pts);
        assert!(m > 1.0 && m < 3.0, "{m}");
        // Natural neighbours: exact at the sites, inside their range, and
        // linear data reproduced inside the hull (Sibson's coordinates
        // reproduce linear functions).
        let f = |x: f64, y: f64| 2.0 + 3.0 * x - 5.0 * y;
        let sites: Vec<(Vector3<f64>, f64)> = [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 3.0],
            [2.0, 1.0, 3.0],
            [1.0, 1.0, 3.0],
        ]
        .iter()
        .map(|n| {
            let u = Vector3::from(*n).normalize();
            (u, f(u.x / (1.0 + u.z), u.y / (1.0 + u.z)))
        })
        .collect();
        let field = Interpolant::new(&sites);
        for (u, v) in &sites {
            let (x, y) = (u.x / (1.0 + u.z), u.y / (1.0 + u.z));
            assert!((field.at(x, y) - v).abs() < 1e-12);
        }
        let (x, y) = (0.2, 0.05);
        assert!(
            (field.at(x, y) - f(x, y)).abs() < 1e-12,
            "{}",
            field.at(x, y)
        );
        // The projection inverts.
        let (x, y) = ipf_xy([1.0, 2.0, 3.0]);
        let v = unit_of(x, y);
        let n = Vector3::new(2.0, 1.0, 3.0).normalize();
        assert!((v - n).norm() < 1e-14);
    }
}
