//! `sweep.orientations` (issue #39): crystal orientation as a sweep axis.
//! Every cubic material of the sweep (a `[materials.NAME]` table with
//! `cubic_gpa` and no `normal`/`x_dir`) is cut once per orientation: a list
//! of surface normals (Miller indices, each optionally with its in-plane x
//! direction) or a set generated over the standard triangle
//! (001)–(101)–(111) of the cubic crystal at a given angular spacing. Each
//! orientation is its own material (its own kernel), named
//! `NAME[h k l]` in case ids and outputs; [`Orientation`] keeps what it is,
//! so that nothing parses the name back.

use anyhow::{bail, Result};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Most orientations one sweep may list or generate.
pub const MAX_ORIENTATIONS: usize = 2000;
/// Finest spacing of a generated set, degrees (about 1100 orientations).
pub const MIN_SPACING_DEG: f64 = 1.0;
/// Largest Miller index a generated orientation is rounded to.
pub const MAX_GENERATED_INDEX: i64 = 24;

/// One listed orientation: a normal, or a normal with its x direction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum OrientationCfg {
    /// The surface normal (into the body), Miller indices; x by the default rule.
    Normal([f64; 3]),
    /// The normal and the in-plane x direction.
    Framed {
        /// Surface normal, Miller indices.
        normal: [f64; 3],
        /// In-plane x direction, Miller indices, ⟂ normal.
        x_dir: [f64; 3],
    },
}

/// `sweep.orientations`: a list, or `{ spacing_deg }` over the standard
/// triangle. Read through [`OrientationsCfg::try_from`] so that a wrong
/// entry is named.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, try_from = "toml::Value")]
pub enum OrientationsCfg {
    /// Listed orientations.
    List(Vec<OrientationCfg>),
    /// Generated over the standard triangle.
    Generated {
        /// Angular spacing between neighbours, degrees.
        spacing_deg: f64,
    },
}

fn triple(v: &toml::Value, what: &str) -> std::result::Result<[f64; 3], String> {
    let items = v
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or_else(|| format!("{what} must be three Miller indices like [1, 2, 3]"))?;
    let mut out = [0.0; 3];
    for (o, x) in out.iter_mut().zip(items) {
        *o = match x {
            toml::Value::Integer(i) => *i as f64,
            toml::Value::Float(f) => *f,
            _ => return Err(format!("{what} must be three numbers (Miller indices)")),
        };
    }
    if out.iter().any(|v| !v.is_finite()) || out.iter().all(|&v| v == 0.0) {
        return Err(format!("{what} = {out:?} must be finite and not all zero"));
    }
    Ok(out)
}

impl TryFrom<toml::Value> for OrientationsCfg {
    type Error = String;

    fn try_from(v: toml::Value) -> std::result::Result<Self, String> {
        match v {
            toml::Value::Array(items) => {
                if items.is_empty() {
                    return Err("list at least one orientation, or leave the key out".into());
                }
                if items.len() > MAX_ORIENTATIONS {
                    return Err(format!(
                        "{} orientations is too many (at most {MAX_ORIENTATIONS})",
                        items.len()
                    ));
                }
                let list = items
                    .iter()
                    .enumerate()
                    .map(|(i, item)| match item {
                        toml::Value::Table(t) => {
                            if let Some(k) = t
                                .keys()
                                .find(|k| !["normal", "x_dir"].contains(&k.as_str()))
                            {
                                return Err(format!(
                                    "entry {i}: unknown key `{k}` (expected normal, x_dir)"
                                ));
                            }
                            let get = |k: &str| {
                                t.get(k)
                                    .ok_or_else(|| format!("entry {i}: needs `{k}`"))
                                    .and_then(|v| triple(v, &format!("entry {i}: {k}")))
                            };
                            Ok(OrientationCfg::Framed {
                                normal: get("normal")?,
                                x_dir: get("x_dir")?,
                            })
                        }
                        other => triple(other, &format!("entry {i}")).map(OrientationCfg::Normal),
                    })
                    .collect::<std::result::Result<_, _>>()?;
                Ok(OrientationsCfg::List(list))
            }
            toml::Value::Table(t) => {
                if let Some(k) = t.keys().find(|k| k.as_str() != "spacing_deg") {
                    return Err(format!(
                        "unknown key `{k}` (a generated set takes spacing_deg only)"
                    ));
                }
                let s = match t.get("spacing_deg") {
                    Some(toml::Value::Float(x)) => *x,
                    Some(toml::Value::Integer(i)) => *i as f64,
                    Some(_) => return Err("spacing_deg must be a number of degrees".into()),
                    None => return Err("a generated set needs `spacing_deg`".into()),
                };
                if !(s.is_finite() && s >= MIN_SPACING_DEG) {
                    return Err(format!(
                        "spacing_deg = {s}: must be at least {MIN_SPACING_DEG}°"
                    ));
                }
                Ok(OrientationsCfg::Generated { spacing_deg: s })
            }
            other => Err(format!(
                "expected a list of normals or {{ spacing_deg }}, got {}",
                other.type_str()
            )),
        }
    }
}

/// One orientation of one crystal, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct Orientation {
    /// The material's name in ids and outputs: `BASE[h,k,l]`.
    pub name: String,
    /// The crystal's `[materials.*]` name.
    pub base: String,
    /// The surface normal as given (Miller indices).
    pub normal: [f64; 3],
    /// The in-plane x direction (given, or by the default rule).
    pub x_dir: [f64; 3],
}

impl Orientation {
    /// Where the normal falls in the standard triangle (001)–(101)–(111),
    /// reduced by the cubic symmetry (|components| sorted so that
    /// z ≥ x ≥ y), in the stereographic projection from −[001]:
    /// `(x, y)/(1 + z)` of the unit normal.
    pub fn ipf_xy(&self) -> (f64, f64) {
        ipf_xy(self.normal)
    }
}

/// See [`Orientation::ipf_xy`].
pub fn ipf_xy(normal: [f64; 3]) -> (f64, f64) {
    let n = Vector3::from(normal).normalize();
    let mut a = [n.x.abs(), n.y.abs(), n.z.abs()];
    a.sort_by(f64::total_cmp);
    // a[2] ≥ a[1] ≥ a[0]: z, x, y.
    (a[1] / (1.0 + a[2]), a[0] / (1.0 + a[2]))
}

/// The default in-plane x direction: `[0 1 0] × normal`, so that y lies
/// along the projection of [0 1 0] on the surface ((001): x ∥ [100];
/// (101): x ∥ [10-1]; (111): x ∥ [10-1]); for a normal along [0 1 0]
/// itself, `[0 0 1] × normal` (x ∥ [-100]).
pub fn default_x_dir(normal: [f64; 3]) -> [f64; 3] {
    let n = Vector3::from(normal);
    let mut x = Vector3::new(0.0, 1.0, 0.0).cross(&n);
    if x.norm() <= 1e-9 * n.norm() {
        x = Vector3::new(0.0, 0.0, 1.0).cross(&n);
    }
    // Miller-like: integer components stay integers (no normalising).
    [x.x + 0.0, x.y + 0.0, x.z + 0.0]
}

/// A direction's text in names: `[1 2 -3]` (shortest text of each number;
/// spaces, not commas, so that names need no quoting in CSV files).
pub fn miller_text(v: [f64; 3]) -> String {
    let t: Vec<String> = v
        .iter()
        .map(|&c| crate::float_text::fmt_f64(c + 0.0))
        .collect();
    format!("[{}]", t.join(" "))
}

fn gcd(a: i64, b: i64) -> i64 {
    if b == 0 {
        a.abs()
    } else {
        gcd(b, a % b)
    }
}

/// The generated set: points of the standard triangle (001)–(101)–(111)
/// about `spacing` degrees apart — rows of constant polar angle from [001]
/// at the spacing, each divided evenly in azimuth, plus the (101)–(111)
/// edge — each rounded to the integer direction of smallest largest index
/// (at most [`MAX_GENERATED_INDEX`]) within a quarter of the spacing and on
/// the same edge of the triangle; duplicates dropped. The corners are
/// always in the set.
pub fn generate(spacing_deg: f64) -> Vec<[f64; 3]> {
    let d = spacing_deg.to_radians();
    let unit = |v: [f64; 3]| Vector3::from(v).normalize();
    let mut targets: Vec<Vector3<f64>> = Vec::new();
    // Rows of constant θ from [001], φ from [100] towards [110] (y = x).
    let quarter = std::f64::consts::FRAC_PI_4;
    let rows = (54.74_f64.to_radians() / d).ceil() as usize;
    for i in 0..=rows {
        let th = i as f64 * d;
        let m = ((th.sin() * quarter) / d).ceil().max(1.0) as usize;
        for j in 0..=m {
            let ph = quarter * j as f64 / m as f64;
            let v = Vector3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            // Inside the triangle: z ≥ x (below the (101)–(111) edge).
            if v.z >= v.x - 1e-12 {
                targets.push(v);
            }
            if i == 0 {
                break;
            }
        }
    }
    // The (101)–(111) edge, by spherical interpolation.
    let (a, b) = (unit([1.0, 0.0, 1.0]), unit([1.0, 1.0, 1.0]));
    let arc = a.dot(&b).acos();
    let m = (arc / d).ceil() as usize;
    for j in 0..=m {
        let t = j as f64 / m as f64;
        let v = (a * ((1.0 - t) * arc).sin() + b * (t * arc).sin()) / arc.sin();
        targets.push(v);
    }
    // Thin: no two targets closer than half the spacing (edges first kept).
    let mut kept: Vec<Vector3<f64>> = Vec::new();
    for v in targets.iter().rev() {
        if kept
            .iter()
            .all(|k| k.dot(v).clamp(-1.0, 1.0).acos() > 0.5 * d)
        {
            kept.push(*v);
        }
    }
    // Integer candidates of the triangle: l ≥ h ≥ k ≥ 0, coprime.
    let mut cands: Vec<([i64; 3], Vector3<f64>)> = Vec::new();
    for l in 1..=MAX_GENERATED_INDEX {
        for h in 0..=l {
            for k in 0..=h {
                if gcd(gcd(h, k), l) == 1 {
                    cands.push((
                        [h, k, l],
                        Vector3::new(h as f64, k as f64, l as f64).normalize(),
                    ));
                }
            }
        }
    }
    let edge = |v: &Vector3<f64>| {
        [
            v.y.abs() < 1e-9,
            (v.x - v.y).abs() < 1e-9,
            (v.z - v.x).abs() < 1e-9,
        ]
    };
    let tol = 0.25 * d;
    let mut out: Vec<[f64; 3]> = Vec::new();
    for v in kept.iter().rev() {
        let on = edge(v);
        let best = cands
            .iter()
            .filter(|(_, c)| {
                let e = edge(c);
                (0..3).all(|i| !on[i] || e[i])
            })
            .map(|(m, c)| (m, c.dot(v).clamp(-1.0, 1.0).acos()))
            .filter(|&(_, ang)| ang <= tol)
            // Candidates come in increasing largest index: the first
            // within the tolerance has the smallest; ties by angle.
            .min_by(|x, y| {
                let (lx, ly) = (x.0[2], y.0[2]);
                lx.cmp(&ly).then(x.1.total_cmp(&y.1))
            });
        let m = match best {
            Some((m, _)) => [m[0] as f64, m[1] as f64, m[2] as f64],
            // No small-index direction close enough: the target itself.
            None => [v.x, v.y, v.z],
        };
        if !out.contains(&m) {
            out.push(m);
        }
    }
    out
}

/// The orientations of `base` for the config's `sweep.orientations`.
pub fn expand(base: &str, cfg: &OrientationsCfg) -> Result<Vec<Orientation>> {
    let pairs: Vec<([f64; 3], Option<[f64; 3]>)> = match cfg {
        OrientationsCfg::List(list) => list
            .iter()
            .map(|o| match o {
                OrientationCfg::Normal(n) => (*n, None),
                OrientationCfg::Framed { normal, x_dir } => (*normal, Some(*x_dir)),
            })
            .collect(),
        OrientationsCfg::Generated { spacing_deg } => generate(*spacing_deg)
            .into_iter()
            .map(|n| (n, None))
            .collect(),
    };
    if pairs.len() > MAX_ORIENTATIONS {
        bail!(
            "sweep.orientations: {} orientations, at most {MAX_ORIENTATIONS}",
            pairs.len()
        );
    }
    let mut out: Vec<Orientation> = Vec::new();
    for (normal, x_dir) in pairs {
        let mut name = format!("{base}{}", miller_text(normal));
        if let Some(x) = x_dir {
            name.push_str(&format!("x{}", miller_text(x)));
        }
        let x_dir = x_dir.unwrap_or_else(|| default_x_dir(normal));
        let same = |a: [f64; 3], b: [f64; 3]| {
            Vector3::from(a)
                .normalize()
                .dot(&Vector3::from(b).normalize())
                > 1.0 - 1e-12
        };
        if let Some(prev) = out
            .iter()
            .find(|o| same(o.normal, normal) && same(o.x_dir, x_dir))
        {
            bail!(
                "sweep.orientations: {} and {} are the same orientation; every case must be unique",
                miller_text(prev.normal),
                miller_text(normal)
            );
        }
        out.push(Orientation {
            name,
            base: base.to_string(),
            normal,
            x_dir,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use super::*;
    use crate::config::Config;

    const CU: &str = "\n[materials.Cu]\ncubic_gpa = { c11 = 168.4, c12 = 121.4, c44 = 75.4 }\n";

    fn with(orientations: &str, tables: &str) -> String {
        format!(
            "{}{tables}",
            BASE.replace(
                "materials = [\"Fe\"]",
                &format!("materials = [\"Cu\"]\norientations = {orientations}")
            )
        )
    }

    #[test]
    fn errors_name_the_key() {
        let cases: [(String, &str); 9] = [
            (with("[]", CU), "list at least one orientation"),
            (with("[[1, 2]]", CU), "entry 0 must be three Miller indices"),
            (with("[[0, 0, 0]]", CU), "not all zero"),
            (
                with("[{ normal = [1, 1, 1] }]", CU),
                "entry 0: needs `x_dir`",
            ),
            (
                with("[{ normal = [1, 1, 1], x_dir = [1, 0, 0] }]", CU),
                "not perpendicular",
            ),
            (with("{ spacing_deg = 0.1 }", CU), "spacing_deg = 0.1"),
            (
                with("[[1, 1, 1], [2, 2, 2]]", CU),
                "are the same orientation",
            ),
            (with("[[1, 1, 1]]", ""), "`Cu` is not a cubic crystal"),
            (
                with(
                    "[[1, 1, 1]]",
                    &format!("{CU}normal = [1, 1, 1]\nx_dir = [1, -1, 0]\n"),
                ),
                "materials.Cu.normal: sweep.orientations gives",
            ),
        ];
        for (text, expect) in cases {
            let e = err(&text, &[]);
            assert!(e.contains(expect), "{expect}: {e}");
            if expect.contains("entry") || expect.contains("spacing") {
                assert!(
                    e.contains("sweep.orientations") || e.contains("orientations"),
                    "{e}"
                );
            }
        }
        // Without orientations a cubic table needs its normal, and says where
        // else it can come from.
        let e = err(
            &format!("{}{CU}", BASE.replace("[\"Fe\"]", "[\"Cu\"]")),
            &[],
        );
        assert!(
            e.contains("materials.Cu.normal: required with cubic_gpa (or list"),
            "{e}"
        );
    }

    #[test]
    fn orientations_expand_the_crystal_into_named_materials() {
        let c = Config::parse(
            &with(
                "[[0, 0, 1], { normal = [1, 2, 3], x_dir = [1, 1, -1] }]",
                CU,
            ),
            &[],
        )
        .unwrap();
        let ids: Vec<String> = c
            .cases()
            .unwrap()
            .iter()
            .map(|(k, _)| k.to_string())
            .collect();
        assert_eq!(ids.len(), 6);
        assert_eq!(ids[0], "Cu[0 0 1]/flat/000.0");
        assert_eq!(ids[3], "Cu[1 2 3]x[1 1 -1]/flat/000.0");
        // The name resolves (mpcontact solve --material) and is the crystal
        // cut there: the stiffness of a single material with that frame, to
        // the bit (one function computes both).
        let single = solver::Material::cubic(
            "x",
            [168.4e9, 121.4e9, 75.4e9],
            [1.0, 2.0, 3.0],
            [1.0, 1.0, -1.0],
            None,
        )
        .unwrap();
        assert_eq!(
            c.material("Cu[1 2 3]x[1 1 -1]").unwrap().stiffness(),
            single.stiffness()
        );
        assert_eq!(c.first_material().unwrap(), "Cu[0 0 1]");
        // The echo keeps the key (a resume compares it), only when set.
        assert!(c.to_toml().contains("orientations"));
        let again = Config::parse(&c.to_toml(), &[]).unwrap();
        assert_eq!(again.orientations().unwrap(), c.orientations().unwrap());
        assert!(!Config::parse(BASE, &[])
            .unwrap()
            .to_toml()
            .contains("orientations"));
        // A generated set, through --set too.
        let g = Config::parse(
            &with("[[1, 1, 1]]", CU),
            &["sweep.orientations={ spacing_deg = 20 }".to_string()],
        )
        .unwrap();
        assert_eq!(g.orientations().unwrap().len(), generate(20.0).len());
    }

    #[test]
    fn generated_sets_cover_the_triangle_with_its_corners() {
        for spacing in [5.0, 10.0, 15.0, 20.0] {
            let set = generate(spacing);
            for corner in [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0]] {
                assert!(set.contains(&corner), "{spacing}: {corner:?} in {set:?}");
            }
            // Every point of the triangle lies within the spacing of one of
            // the set (sampled on a fine grid of the triangle).
            let unit: Vec<Vector3<f64>> =
                set.iter().map(|&v| Vector3::from(v).normalize()).collect();
            let mut worst: f64 = 0.0;
            for i in 0..=60 {
                for j in 0..=60 {
                    let th = 54.8_f64.to_radians() * i as f64 / 60.0;
                    let ph = std::f64::consts::FRAC_PI_4 * j as f64 / 60.0;
                    let v = Vector3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    if v.z < v.x {
                        continue;
                    }
                    let near = unit
                        .iter()
                        .map(|u| u.dot(&v).clamp(-1.0, 1.0).acos())
                        .fold(f64::INFINITY, f64::min);
                    worst = worst.max(near);
                }
            }
            assert!(
                worst.to_degrees() < spacing,
                "{spacing}°: a point {:.2}° from the set ({} orientations)",
                worst.to_degrees(),
                set.len()
            );
            // All inside the triangle: l ≥ h ≥ k ≥ 0.
            for v in &set {
                assert!(v[2] >= v[0] && v[0] >= v[1] && v[1] >= 0.0, "{v:?}");
            }
        }
    }

    #[test]
    fn ipf_coordinates_of_the_corners_and_of_equivalent_normals() {
        let (x, y) = ipf_xy([0.0, 0.0, 1.0]);
        assert_eq!((x, y), (0.0, 0.0));
        let (x, y) = ipf_xy([1.0, 1.0, 0.0]);
        let r = 0.5_f64.sqrt();
        assert!((x - r / (1.0 + r)).abs() < 1e-15 && y.abs() < 1e-15);
        let (x, y) = ipf_xy([-1.0, 1.0, 1.0]);
        let t = 1.0 / 3.0_f64.sqrt();
        assert!((x - t / (1.0 + t)).abs() < 1e-15 && (y - x).abs() < 1e-15);
        assert_eq!(ipf_xy([1.0, 2.0, 3.0]), ipf_xy([-3.0, 2.0, 1.0]));
    }

    #[test]
    fn default_frame_is_perpendicular_and_named() {
        for n in [
            [0.0, 0.0, 1.0],
            [1.0, 2.0, 3.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 1.0],
        ] {
            let x = default_x_dir(n);
            assert!(Vector3::from(x).norm() > 0.0);
            assert!(Vector3::from(x).dot(&Vector3::from(n)).abs() < 1e-12);
        }
        assert_eq!(default_x_dir([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        assert_eq!(default_x_dir([1.0, 1.0, 1.0]), [1.0, 0.0, -1.0]);
        assert_eq!(miller_text([-3.0, 2.0, 1.0]), "[-3 2 1]");
    }
}
