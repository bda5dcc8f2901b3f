//! `[sweep]`: which materials, surfaces, force angles and balls make the
//! cases, and that every case has its own identity. The names are resolved by
//! `materials` and `surfaces`; the cases are made in `Config::cases`.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Force angles: `{ start, stop, step }` (stop included) or a list.
/// Read through [`AnglesCfg::try_from`], so that a missing or unknown key of
/// the range is named (serde's untagged enums only say that nothing matched).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged, try_from = "toml::Value")]
pub enum AnglesCfg {
    /// Inclusive range.
    Range {
        /// First angle, degrees.
        start: f64,
        /// Last angle (included when hit), degrees.
        stop: f64,
        /// Step, degrees.
        step: f64,
    },
    /// Explicit list, degrees.
    List(Vec<f64>),
}

/// Most angles one sweep may list (a range or a list): 180° in 0.1° steps
/// is 1801, so this only stops runaway inputs before they allocate.
pub const MAX_ANGLES: usize = 100_000;

impl TryFrom<toml::Value> for AnglesCfg {
    type Error = String;

    fn try_from(v: toml::Value) -> std::result::Result<Self, String> {
        let number = |v: &toml::Value, what: &str| match v {
            toml::Value::Float(x) => Ok(*x),
            toml::Value::Integer(i) => Ok(*i as f64),
            other => Err(format!(
                "{what} must be a number of degrees, got {}",
                other.type_str()
            )),
        };
        match v {
            toml::Value::Array(items) => {
                if items.len() > MAX_ANGLES {
                    return Err(format!(
                        "{} angles is too many (at most {MAX_ANGLES})",
                        items.len()
                    ));
                }
                let list = items
                    .iter()
                    .enumerate()
                    .map(|(i, x)| number(x, &format!("entry {i}")))
                    .collect::<std::result::Result<_, _>>()?;
                Ok(AnglesCfg::List(list))
            }
            toml::Value::Table(t) => {
                if let Some(k) = t
                    .keys()
                    .find(|k| !["start", "stop", "step"].contains(&k.as_str()))
                {
                    return Err(format!(
                        "unknown key `{k}` in the range (expected start, stop, step)"
                    ));
                }
                let get = |k: &str| {
                    t.get(k)
                        .ok_or_else(|| {
                            format!("the range needs `{k}` (start, stop, step in degrees)")
                        })
                        .and_then(|v| number(v, k))
                };
                Ok(AnglesCfg::Range {
                    start: get("start")?,
                    stop: get("stop")?,
                    step: get("step")?,
                })
            }
            other => Err(format!(
                "expected a list of angles or {{ start, stop, step }}, got {}",
                other.type_str()
            )),
        }
    }
}

impl AnglesCfg {
    /// The angles, degrees.
    pub fn values(&self) -> Result<Vec<f64>> {
        match self {
            AnglesCfg::List(v) => {
                if v.is_empty() || v.iter().any(|a| !a.is_finite()) {
                    bail!("sweep.angles_deg: the list must be non-empty and finite");
                }
                if v.len() > MAX_ANGLES {
                    bail!(
                        "sweep.angles_deg: {} angles is too many (at most {MAX_ANGLES})",
                        v.len()
                    );
                }
                Ok(v.clone())
            }
            AnglesCfg::Range { start, stop, step } => {
                if !(start.is_finite() && stop.is_finite() && step.is_finite())
                    || *step <= 0.0
                    || stop < start
                {
                    bail!("sweep.angles_deg: need finite start ≤ stop and step > 0, got start = {start}, stop = {stop}, step = {step}");
                }
                // Counted in floating point: (stop − start)/step can exceed
                // any integer (step = 1e-300), and must not wrap to zero.
                let count = ((stop - start) / step + 1e-9).floor() + 1.0;
                if count > MAX_ANGLES as f64 {
                    bail!(
                        "sweep.angles_deg: start = {start}, stop = {stop}, step = {step} gives {count:.3e} angles, too many (at most {MAX_ANGLES})"
                    );
                }
                Ok((0..count as usize)
                    .map(|k| start + k as f64 * step)
                    .collect())
            }
        }
    }
}

/// `[sweep]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepCfg {
    /// Preset names or keys of `[materials.*]`.
    pub materials: Vec<String>,
    /// Preset names or keys of `[surfaces.*]`.
    #[serde(default = "default_surfaces")]
    pub surfaces: Vec<String>,
    /// Force directions.
    #[serde(default = "default_angles")]
    pub angles_deg: AnglesCfg,
    /// Balls to compare (`sweep.indenters`): presets or keys of
    /// `[materials.*]`, [`RIGID`] for a rigid ball. Absent: no ball axis,
    /// the one ball of `indenter.material` (or rigid) presses every case.
    /// Not written back when absent, so that configs without it echo (and
    /// resume) as before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub indenters: Option<Vec<String>>,
    /// Normal loads to sweep (`sweep.normal_loads_n`), N: each case once per
    /// load, which replaces `load.normal_n`. Absent: no load axis. Not
    /// written back when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_loads_n: Option<Vec<f64>>,
    /// Displacement amplitudes of a fretting map (`sweep.amplitudes_um`),
    /// µm: each case once per amplitude, the amplitude of `[history]
    /// fretting = { cycles = N }` (displacement control). Absent: no
    /// amplitude axis. Not written back when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitudes_um: Option<Vec<f64>>,
    /// Crystal orientations (`sweep.orientations`): every material of the
    /// sweep, a cubic `[materials.*]` table, cut once per orientation.
    /// Absent: each material as its table gives it. Not written back when
    /// absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientations: Option<super::orientations::OrientationsCfg>,
}

/// The name that means "no ball" in `sweep.indenters`.
pub const RIGID: &str = "rigid";

fn default_surfaces() -> Vec<String> {
    vec!["flat".into()]
}

fn default_angles() -> AnglesCfg {
    AnglesCfg::List(vec![0.0])
}

impl SweepCfg {
    /// Both lists name something.
    pub(super) fn check_lists(&self) -> Result<()> {
        if self.materials.is_empty() {
            bail!("sweep.materials: list at least one material");
        }
        if self.surfaces.is_empty() {
            bail!("sweep.surfaces: list at least one surface");
        }
        if self.indenters.as_ref().is_some_and(Vec::is_empty) {
            bail!("sweep.indenters: list at least one ball (`{RIGID}` for a rigid one), or leave the key out");
        }
        for (key, values, what) in [
            (
                "sweep.normal_loads_n",
                &self.normal_loads_n,
                "normal load, N",
            ),
            (
                "sweep.amplitudes_um",
                &self.amplitudes_um,
                "displacement amplitude, µm",
            ),
        ] {
            let Some(values) = values else { continue };
            if values.is_empty() {
                bail!("{key}: list at least one {what}, or leave the key out");
            }
            if let Some((i, v)) = values
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v > 0.0))
            {
                bail!("{key}[{i}] = {v}: must be positive and finite (a {what})");
            }
            let mut seen = Vec::new();
            for v in values {
                if seen.contains(v) {
                    bail!("{key}: {v} is listed twice; every case must be unique");
                }
                seen.push(*v);
            }
        }
        Ok(())
    }

    /// The normal loads of the load axis (`None`: no axis, one load).
    pub fn load_axis(&self) -> Vec<Option<f64>> {
        match &self.normal_loads_n {
            Some(v) => v.iter().copied().map(Some).collect(),
            None => vec![None],
        }
    }

    /// The amplitudes of the amplitude axis (`None`: no axis).
    pub fn amplitude_axis(&self) -> Vec<Option<f64>> {
        match &self.amplitudes_um {
            Some(v) => v.iter().copied().map(Some).collect(),
            None => vec![None],
        }
    }

    /// Every case must have its own identity: no material, surface or ball
    /// listed twice, and no two angles that case ids and outputs (0.1°)
    /// cannot tell apart. (Repeated keys made `run` re-send a case forever,
    /// #20 item 1.)
    pub(super) fn check_unique(&self, angles: &[f64]) -> Result<()> {
        let no_balls = Vec::new();
        for (key, names) in [
            ("sweep.materials", &self.materials),
            ("sweep.surfaces", &self.surfaces),
            (
                "sweep.indenters",
                self.indenters.as_ref().unwrap_or(&no_balls),
            ),
        ] {
            let mut seen = std::collections::HashSet::new();
            if let Some(name) = names.iter().find(|n| !seen.insert(n.as_str())) {
                bail!("{key}: `{name}` is listed twice; every case must be unique");
            }
        }
        // The text the ids show; `+ 0.0` makes −0 and 0 the same angle.
        let mut shown: BTreeMap<String, f64> = BTreeMap::new();
        for &a in angles {
            let text = format!("{:.1}", a + 0.0);
            if let Some(prev) = shown.insert(text.clone(), a) {
                bail!(
                    "sweep.angles_deg: {prev}° and {a}° both read {text}° in case ids and outputs, which resolve 0.1°; give angles at least 0.1° apart"
                );
            }
        }
        Ok(())
    }
}

/// The config key of a solver parameter set by the sweep.
pub(super) fn config_key(param: &str) -> Option<String> {
    (param == "load.angle_deg").then(|| "sweep.angles_deg".to_string())
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use super::*;
    use crate::config::Config;

    #[test]
    fn issue20_item1_repeated_cases_are_refused_naming_them() {
        let cases: [(&str, &str, &str); 6] = [
            (
                "materials = [\"Fe\"]",
                "materials = [\"Fe\", \"Fe\"]",
                "`Fe` is listed twice",
            ),
            (
                "surfaces = [\"flat\"]",
                "surfaces = [\"flat\", \"flat\"]",
                "sweep.surfaces",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = [0.0, 0.0]",
                "sweep.angles_deg",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = [0.0, 0.01]",
                "0° and 0.01° both read 0.0°",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = { start = 0, stop = 1, step = 0.04 }",
                "sweep.angles_deg",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = [-0.0, 0.0]",
                "sweep.angles_deg",
            ),
        ];
        for (from, to, expect) in cases {
            let text = BASE.replace(from, to);
            assert_ne!(text, BASE, "{to}");
            let e = err(&text, &[]);
            assert!(e.contains(expect), "{to}: {e}");
        }
        // Angles 0.1° apart are distinct cases.
        let ok = BASE.replace(
            "angles_deg = { start = 0, stop = 90, step = 45 }",
            "angles_deg = [0.0, 0.1, 0.2]",
        );
        assert_eq!(Config::parse(&ok, &[]).unwrap().cases().unwrap().len(), 3);
    }

    #[test]
    fn issue35_ball_axis_errors_name_the_key() {
        let axis = |list: &str| {
            BASE.replace(
                "surfaces = [\"flat\"]",
                &format!("surfaces = [\"flat\"]\nindenters = {list}"),
            )
        };
        let cases: [(String, &str); 5] = [
            (axis("[]"), "sweep.indenters: list at least one ball"),
            (
                axis("[\"rigid\", \"steel\", \"steel\"]"),
                "sweep.indenters: `steel` is listed twice",
            ),
            (
                axis("[\"rigid\", \"Vibranium\"]"),
                "sweep.indenters: unknown material `Vibranium`",
            ),
            (
                axis("[\"steel\"]")
                    .replace("radius_mm = 18.0", "radius_mm = 18.0\nmaterial = \"WC\""),
                "indenter.material and sweep.indenters",
            ),
            (
                format!(
                    "{}\n[materials.rigid]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\n",
                    axis("[\"rigid\"]")
                ),
                "sweep.indenters: `rigid` means a rigid ball",
            ),
        ];
        for (text, expect) in cases {
            assert_ne!(text, BASE);
            let e = err(&text, &[]);
            assert!(e.contains(expect), "{expect}: {e}");
        }
        // Via --set too, and a good axis expands to every ball in turn.
        let e = err(BASE, &["sweep.indenters=[\"rigid\", \"glas\"]"]);
        assert!(
            e.contains("sweep.indenters: unknown material `glas`"),
            "{e}"
        );
        let c = Config::parse(&axis("[\"rigid\", \"steel\"]"), &[]).unwrap();
        let cases = c.cases().unwrap();
        let ids: Vec<String> = cases.iter().map(|(k, _)| k.to_string()).collect();
        assert_eq!(
            ids,
            [
                "Fe/flat/000.0@rigid",
                "Fe/flat/000.0@steel",
                "Fe/flat/045.0@rigid",
                "Fe/flat/045.0@steel",
                "Fe/flat/090.0@rigid",
                "Fe/flat/090.0@steel",
            ]
        );
        assert!(cases[0].1.indenter.is_none());
        assert_eq!(cases[1].1.indenter.as_ref().unwrap().name, "steel");
        // The config echo keeps the axis (a resume compares it) and only then.
        assert!(c.to_toml().contains("indenters"));
        assert!(!Config::parse(BASE, &[])
            .unwrap()
            .to_toml()
            .contains("indenters"));
    }

    #[test]
    fn issue37_map_axes_errors_name_the_key() {
        let axes = |lists: &str, history: &str| {
            format!(
                "{}\n[history]\n{history}\n",
                BASE.replace(
                    "surfaces = [\"flat\"]",
                    &format!("surfaces = [\"flat\"]\n{lists}")
                )
            )
        };
        let cycles = "fretting = { cycles = 1 }";
        let cases: [(String, &str); 10] = [
            (
                axes("amplitudes_um = []", cycles),
                "sweep.amplitudes_um: list at least one",
            ),
            (
                axes("amplitudes_um = [1.0, -2.0]", cycles),
                "sweep.amplitudes_um[1] = -2: must be positive and finite",
            ),
            (
                axes("amplitudes_um = [1.0, 1.0]", cycles),
                "sweep.amplitudes_um: 1 is listed twice",
            ),
            (
                axes("amplitudes_um = [1.0]\nnormal_loads_n = [0.0]", cycles),
                "sweep.normal_loads_n[0] = 0: must be positive",
            ),
            (
                axes("normal_loads_n = [10.0, 10.0]", cycles),
                "sweep.normal_loads_n: 10 is listed twice",
            ),
            (
                BASE.replace(
                    "surfaces = [\"flat\"]",
                    "surfaces = [\"flat\"]\namplitudes_um = [1.0]",
                ),
                "sweep.amplitudes_um: needs [history] fretting = { cycles = N }",
            ),
            (
                axes("amplitudes_um = [1.0]", "tangential_um = [0.0, 1.0]"),
                "sweep.amplitudes_um: needs [history] fretting = { cycles = N }",
            ),
            (
                axes(
                    "amplitudes_um = [1.0]",
                    "fretting = { displacement_um = 1.0, cycles = 1 }",
                ),
                "history.fretting.displacement_um and sweep.amplitudes_um both set",
            ),
            (
                axes(
                    "amplitudes_um = [1.0]",
                    "fretting = { amplitude_ratio = 0.5, cycles = 1 }",
                ),
                "history.fretting.amplitude_ratio is force control",
            ),
            (
                axes(
                    "normal_loads_n = [10.0]",
                    "tangential_ratios = [0.0, 0.5]\nnormal_n = [20.0, 20.0]",
                ),
                "history.normal_n and sweep.normal_loads_n both set",
            ),
        ];
        for (text, expect) in cases {
            let e = err(&text, &[]);
            assert!(e.contains(expect), "{expect}: {e}");
        }
        // Without the axis, fretting = { cycles } alone says where the
        // amplitude goes.
        let e = err(&axes("", cycles), &[]);
        assert!(
            e.contains("or the amplitudes as sweep.amplitudes_um"),
            "{e}"
        );
        // A good map: loads × amplitudes per angle, each with its own path.
        let c = Config::parse(
            &axes(
                "angles_deg = [0.0]\nnormal_loads_n = [10.0, 20.0]\namplitudes_um = [0.5, 1.5]",
                "fretting = { cycles = 2 }",
            )
            .replace("angles_deg = { start = 0, stop = 90, step = 45 }\n", ""),
            &[],
        )
        .unwrap();
        let cases = c.cases().unwrap();
        let ids: Vec<String> = cases.iter().map(|(k, _)| k.to_string()).collect();
        assert_eq!(
            ids,
            [
                "Fe/flat/000.0@10N@0.5um",
                "Fe/flat/000.0@10N@1.5um",
                "Fe/flat/000.0@20N@0.5um",
                "Fe/flat/000.0@20N@1.5um",
            ]
        );
        assert_eq!(cases[2].1.load.normal_force_n, 20.0);
        let h = cases[1].1.history.as_ref().unwrap();
        assert_eq!(
            h.shifts_m.as_ref().unwrap(),
            &[0.0, 1.5e-6, -1.5e-6, 1.5e-6, -1.5e-6, 1.5e-6]
        );
        assert!(c.to_toml().contains("amplitudes_um"));
        assert!(!Config::parse(BASE, &[])
            .unwrap()
            .to_toml()
            .contains("amplitudes_um"));
        // `solve`'s single case: the axes' first values.
        assert_eq!(c.spec("Fe", "flat", 0.0).unwrap().load.normal_force_n, 10.0);
    }

    #[test]
    fn issue20_item6_angle_counts_are_bounded() {
        let range = "angles_deg = { start = 0, stop = 90, step = 45 }";
        let e = err(
            &BASE.replace(
                range,
                "angles_deg = { start = 0, stop = 180, step = 1e-300 }",
            ),
            &[],
        );
        assert!(
            e.contains("sweep.angles_deg") && e.contains("too many"),
            "{e}"
        );
        let long: Vec<String> = (0..MAX_ANGLES + 1).map(|i| format!("{i}.0")).collect();
        let e = err(
            &BASE.replace(range, &format!("angles_deg = [{}]", long.join(","))),
            &[],
        );
        assert!(e.contains("too many"), "{}", &e[..e.len().min(300)]);
    }

    #[test]
    fn issue20_item7_range_keys_are_named() {
        let range = "angles_deg = { start = 0, stop = 90, step = 45 }";
        let e = err(
            &BASE.replace(range, "angles_deg = { start = 0, stop = 90 }"),
            &[],
        );
        assert!(e.contains("needs `step`") && e.contains("line"), "{e}");
        let e = err(
            &BASE.replace(
                range,
                "angles_deg = { start = 0, stop = 90, step = 45, extra = 1 }",
            ),
            &[],
        );
        assert!(e.contains("unknown key `extra`"), "{e}");
        let e = err(&BASE.replace(range, "angles_deg = \"all\""), &[]);
        assert!(e.contains("expected a list of angles"), "{e}");
        // Integers are degrees too.
        let ok = Config::parse(&BASE.replace(range, "angles_deg = [0, 45]"), &[]).unwrap();
        assert_eq!(ok.sweep.angles_deg.values().unwrap(), [0.0, 45.0]);
    }
}
