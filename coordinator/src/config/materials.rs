//! `[materials.NAME]`: custom materials (isotropic, a full stiffness or
//! cubic constants with an orientation), how a name resolves (tables first,
//! then presets) and the config keys of a material's solver parameters.

use super::orientations::Orientation;
use super::{within, Config, RIGID};
use anyhow::{anyhow, bail, Result};
use serde::{Deserialize, Serialize};
use solver::{Isotropic, Material, SolverError};

/// Isotropic constants in GPa.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsoCfg {
    /// Young's modulus, GPa.
    pub youngs_gpa: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

/// Cubic constants in GPa.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CubicCfg {
    /// C11, GPa.
    pub c11: f64,
    /// C12, GPa.
    pub c12: f64,
    /// C44, GPa.
    pub c44: f64,
}

/// `[materials.NAME]`: exactly one of `isotropic`, `stiffness_gpa`, `cubic_gpa`.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialCfg {
    /// Isotropic constants.
    pub isotropic: Option<IsoCfg>,
    /// Full 6x6 Voigt stiffness in the surface frame (xx, yy, zz, yz, xz, xy; z into the body), GPa.
    pub stiffness_gpa: Option<Vec<Vec<f64>>>,
    /// Cubic constants, rotated so that z ∥ `normal` and x ∥ `x_dir`.
    pub cubic_gpa: Option<CubicCfg>,
    /// Surface normal (Miller indices) for `cubic_gpa`.
    pub normal: Option<[f64; 3]>,
    /// In-plane x direction (Miller indices) for `cubic_gpa`.
    pub x_dir: Option<[f64; 3]>,
    /// Isotropic-equivalent constants for normalisation (default: Hill average).
    pub equivalent: Option<IsoCfg>,
    /// Hardness H of the surface, GPa: the contact pressure is capped at H
    /// (an elastic–perfectly plastic surface). A table with only
    /// `hardness_gpa` / `shear_limit_gpa` adds them to the preset of its name.
    pub hardness_gpa: Option<f64>,
    /// Shear limit τ_c of the surface, GPa: the shear traction is capped at
    /// min(μp, τ_c).
    pub shear_limit_gpa: Option<f64>,
}

impl MaterialCfg {
    /// How many of `isotropic`, `stiffness_gpa`, `cubic_gpa` the table gives.
    fn elastic_keys(&self) -> usize {
        [
            self.isotropic.is_some(),
            self.stiffness_gpa.is_some(),
            self.cubic_gpa.is_some(),
        ]
        .iter()
        .filter(|&&b| b)
        .count()
    }

    /// The plastic limits of the table `name`, in Pa, each checked as
    /// written (GPa): positive and at most [`MAX_LIMIT_GPA`] (#59:
    /// `hardness_gpa = 1e300` was refused as "got inf Pa").
    fn limits(&self, name: &str) -> Result<solver::Limits> {
        for (key, v) in [
            ("hardness_gpa", self.hardness_gpa),
            ("shear_limit_gpa", self.shear_limit_gpa),
        ] {
            if let Some(v) = v.filter(|&v| !(v > 0.0 && v <= MAX_LIMIT_GPA)) {
                bail!(
                    "materials.{name}.{key} = {}: must be positive and at most {MAX_LIMIT_GPA} GPa (no surface is harder than diamond's 100 GPa or so; leave the key out for an elastic surface)",
                    crate::float_text::fmt_f64(v)
                );
            }
        }
        Ok(solver::Limits {
            hardness: self.hardness_gpa.map(|v| v * 1e9),
            shear_limit: self.shear_limit_gpa.map(|v| v * 1e9),
        })
    }

    /// Whether the table gives plastic limits.
    fn has_limits(&self) -> bool {
        self.hardness_gpa.is_some() || self.shear_limit_gpa.is_some()
    }
}

/// The largest hardness or shear limit a table may give, GPa.
pub const MAX_LIMIT_GPA: f64 = 1e4;

/// The key in `[materials.NAME]` of a material parameter.
pub(super) fn material_key<'a>(param: &'a str, cfg: Option<&MaterialCfg>) -> &'a str {
    let cubic = cfg.is_some_and(|m| m.cubic_gpa.is_some());
    match param {
        "youngs" => "isotropic.youngs_gpa",
        "poisson" => "isotropic.poisson",
        "stiffness" if cubic => "cubic_gpa",
        "stiffness" => "stiffness_gpa",
        "orientation" => "normal",
        "hardness" => "hardness_gpa",
        "shear_limit" => "shear_limit_gpa",
        other => other,
    }
}

/// One material of the sweep: its name in case ids and outputs, the
/// material, and the orientation it was cut at (`sweep.orientations`).
#[derive(Clone, Debug)]
pub struct SweepMaterial {
    /// Name in ids and outputs (`Cu`, or `Cu[1 2 3]` for an orientation).
    pub name: String,
    /// The material.
    pub material: Material,
    /// The orientation of a crystal cut by `sweep.orientations`.
    pub orientation: Option<Orientation>,
}

impl Config {
    /// Resolves a material name: an orientation of `sweep.orientations`
    /// (`Cu[1 2 3]`), `[materials.NAME]`, then presets.
    pub fn material(&self, name: &str) -> Result<Material> {
        if self.sweep.orientations.is_some() && !self.materials.contains_key(name) {
            if let Some(o) = self.orientations()?.into_iter().find(|o| o.name == name) {
                return self.cut(&o);
            }
        }
        self.material_for("sweep.materials", name)
    }

    /// The sweep's materials in order: each of `sweep.materials`, or with
    /// `sweep.orientations` each crystal once per orientation. Errors name
    /// the key.
    pub fn sweep_materials(&self) -> Result<Vec<SweepMaterial>> {
        if self.sweep.orientations.is_none() {
            return self
                .sweep
                .materials
                .iter()
                .map(|m| {
                    Ok(SweepMaterial {
                        name: m.clone(),
                        material: self.material(m)?,
                        orientation: None,
                    })
                })
                .collect();
        }
        self.orientations()?
            .into_iter()
            .map(|o| {
                Ok(SweepMaterial {
                    name: o.name.clone(),
                    material: self.cut(&o)?,
                    orientation: Some(o),
                })
            })
            .collect()
    }

    /// The crystal `o.base` cut at the orientation `o`.
    fn cut(&self, o: &Orientation) -> Result<Material> {
        let cfg = &self.materials[&o.base];
        let explain = |e| {
            anyhow!(
                "sweep.orientations: {} of `{}`: {e}",
                super::orientations::miller_text(o.normal),
                o.base
            )
        };
        cubic(&o.name, cfg, o.normal, o.x_dir, &explain)?
            .with_limits(cfg.limits(&o.base)?)
            .map_err(|e| self.explain(within("material", e), &o.base, ""))
    }

    /// Every `[materials.NAME]` table resolved, those the sweep does not
    /// use included (#59: an invalid unused `materials.Zz.hardness_gpa`
    /// passed `check`); the crystals `sweep.orientations` cuts are checked
    /// at their orientations instead.
    pub(super) fn check_material_tables(&self) -> Result<()> {
        for name in self.materials.keys() {
            let cut = self.sweep.orientations.is_some() && self.sweep.materials.contains(name);
            if !cut {
                self.material_for("materials", name)?;
            }
        }
        Ok(())
    }

    /// The name of the sweep's first material (a single case's default):
    /// the first of `sweep.materials`, at its first orientation with
    /// `sweep.orientations`.
    pub fn first_material(&self) -> Result<String> {
        if self.sweep.orientations.is_none() {
            return Ok(self.sweep.materials[0].clone());
        }
        Ok(self.orientations()?.swap_remove(0).name)
    }

    /// The orientations of `sweep.orientations` in order, crystal by
    /// crystal (empty without the key): every material of the sweep must
    /// be a cubic `[materials.NAME]` table without `normal`/`x_dir`.
    pub fn orientations(&self) -> Result<Vec<Orientation>> {
        let Some(orientations) = &self.sweep.orientations else {
            return Ok(Vec::new());
        };
        let mut out = Vec::new();
        for base in &self.sweep.materials {
            let cfg = self
                .materials
                .get(base)
                .filter(|c| c.cubic_gpa.is_some())
                .ok_or_else(|| {
                    anyhow!("sweep.orientations: `{base}` is not a cubic crystal; orientations cut `[materials.NAME]` tables with `cubic_gpa` (and without `normal`/`x_dir`, which the orientations give)")
                })?;
            if cfg.normal.is_some() || cfg.x_dir.is_some() {
                bail!("materials.{base}.normal: sweep.orientations gives the orientations of `{base}`; leave `normal` and `x_dir` out of its table");
            }
            out.extend(super::orientations::expand(base, orientations)?);
        }
        Ok(out)
    }

    /// The ball's material (`indenter.material`), `None` for a rigid ball.
    pub fn indenter_material(&self) -> Result<Option<Material>> {
        self.indenter
            .material
            .as_deref()
            .map(|name| self.material_for("indenter.material", name))
            .transpose()
    }

    /// The balls of the sweep, in order: each with its name in case keys
    /// (`None` without `sweep.indenters`: the one ball of
    /// `indenter.material`, or rigid, is no part of any identity) and its
    /// material (`None`: rigid). Errors name the key.
    pub fn balls(&self) -> Result<Vec<(Option<String>, Option<Material>)>> {
        let Some(names) = &self.sweep.indenters else {
            return Ok(vec![(None, self.indenter_material()?)]);
        };
        if self.indenter.material.is_some() {
            bail!("indenter.material and sweep.indenters both choose the ball: give one ball as indenter.material, or the balls to compare as sweep.indenters (`{RIGID}` for a rigid one), not both");
        }
        if names.iter().any(|n| n == RIGID) && self.materials.contains_key(RIGID) {
            bail!("sweep.indenters: `{RIGID}` means a rigid ball, so the table [materials.{RIGID}] cannot be a ball; rename the table");
        }
        names
            .iter()
            .map(|name| Ok((Some(name.clone()), self.ball("sweep.indenters", name)?)))
            .collect()
    }

    /// The ball `name` given under `key`: `rigid` (`None`), a preset or a
    /// `[materials.NAME]` table.
    pub fn ball(&self, key: &str, name: &str) -> Result<Option<Material>> {
        if name == RIGID {
            return Ok(None);
        }
        self.material_for(key, name).map(Some)
    }

    /// The ball a single case is pressed by when none is chosen: the first
    /// of `sweep.indenters`, else `indenter.material`, else rigid.
    pub fn default_ball(&self) -> Result<Option<Material>> {
        Ok(self.balls()?.swap_remove(0).1)
    }

    /// Resolves a material name given under the config key `key`.
    fn material_for(&self, key: &str, name: &str) -> Result<Material> {
        if let Some(m) = self.materials.get(name) {
            let explain = |e| self.explain(within("material", e), name, "");
            let limits = m.limits(name)?;
            let elastic = if m.elastic_keys() == 0 && m.has_limits() {
                // Limits added to a preset.
                solver::presets::material(name).ok_or_else(|| {
                    anyhow!("materials.{name}: `{name}` is not a preset (see `mpcontact materials`), so its table needs its elastic constants: one of `isotropic`, `stiffness_gpa`, `cubic_gpa`")
                })?
            } else {
                build_material(name, m, &explain)?
            };
            return elastic.with_limits(limits).map_err(explain);
        }
        solver::presets::material(name).ok_or_else(|| {
            anyhow!("{key}: unknown material `{name}` (not a preset — see `mpcontact materials` — and no [materials.\"{name}\"] table)")
        })
    }
}

/// A material from its `[materials.NAME]` table; `explain` turns the
/// solver's errors (parameters of the material) into config errors.
fn build_material(
    name: &str,
    m: &MaterialCfg,
    explain: &dyn Fn(SolverError) -> anyhow::Error,
) -> Result<Material> {
    let key = |k: &str| format!("materials.{name}.{k}");
    if m.elastic_keys() != 1 {
        bail!("materials.{name}: give exactly one of `isotropic`, `stiffness_gpa`, `cubic_gpa` (or, for a preset of that name, only `hardness_gpa` / `shear_limit_gpa`)");
    }
    if let Some(iso) = m.isotropic {
        if m.equivalent.is_some() {
            bail!(
                "{}: only applies to anisotropic materials (an isotropic material is its own equivalent)",
                key("equivalent")
            );
        }
        if m.normal.is_some() || m.x_dir.is_some() {
            bail!(
                "{}: `normal`/`x_dir` only apply to `cubic_gpa`",
                key("normal")
            );
        }
        return Material::isotropic(name, iso.youngs_gpa * 1e9, iso.poisson).map_err(explain);
    }
    let equivalent = equivalent_of(m);
    if let Some(rows) = &m.stiffness_gpa {
        if rows.len() != 6 || rows.iter().any(|r| r.len() != 6) {
            bail!(
                "{}: must be 6 rows of 6 numbers (GPa)",
                key("stiffness_gpa")
            );
        }
        let c = nalgebra::Matrix6::from_fn(|i, j| rows[i][j] * 1e9);
        return Material::with_stiffness(name, c, equivalent).map_err(explain);
    }
    let normal = m.normal.ok_or_else(|| {
        anyhow!(
            "{}: required with cubic_gpa (or list the crystal's orientations in sweep.orientations)",
            key("normal")
        )
    })?;
    let x_dir = m
        .x_dir
        .ok_or_else(|| anyhow!("{}: required with cubic_gpa", key("x_dir")))?;
    cubic(name, m, normal, x_dir, explain)
}

/// The isotropic-equivalent constants of table `m`. They only normalise
/// (the paper's Cu(111) has ν = 0.503): taken as given; the material
/// checks them.
fn equivalent_of(m: &MaterialCfg) -> Option<Isotropic> {
    m.equivalent.map(|e| Isotropic {
        youngs: e.youngs_gpa * 1e9,
        poisson: e.poisson,
    })
}

/// The cubic crystal of table `m` cut with `normal` and `x_dir`.
fn cubic(
    name: &str,
    m: &MaterialCfg,
    normal: [f64; 3],
    x_dir: [f64; 3],
    explain: &dyn Fn(SolverError) -> anyhow::Error,
) -> Result<Material> {
    let cub = m.cubic_gpa.expect("a cubic table");
    let equivalent = equivalent_of(m);
    let constants = [cub.c11 * 1e9, cub.c12 * 1e9, cub.c44 * 1e9];
    Material::cubic(name, constants, normal, x_dir, equivalent).map_err(explain)
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use crate::config::Config;

    #[test]
    fn bad_materials_are_explained() {
        let poisson = format!(
            "{BASE}\n[materials.rubber]\nisotropic = {{ youngs_gpa = 0.01, poisson = 0.6 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"rubber\"]");
        assert!(err(&poisson, &[]).contains("(-1, 0.5]"));
        let zero_e = format!(
            "{BASE}\n[materials.void]\nisotropic = {{ youngs_gpa = 0.0, poisson = 0.3 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"void\"]");
        assert!(err(&zero_e, &[]).contains("Young"));
        let mut rows = vec![vec![0.0; 6]; 6];
        rows[0][0] = 100.0;
        let not_pd = format!("{BASE}\n[materials.bad]\nstiffness_gpa = {rows:?}\n")
            .replace("materials = [\"Fe\"]", "materials = [\"bad\"]");
        assert!(
            err(&not_pd, &[]).contains("positive definite"),
            "{}",
            err(&not_pd, &[])
        );
    }

    #[test]
    fn issue50_plastic_limits_add_to_presets_and_tables_or_are_explained() {
        // On a preset: its constants, with the limits in Pa. (Cells of
        // 5 µm: BASE's 64² of 2 µm cannot hold the contact, and since #59 a
        // hardness whose P/H does not fit the domain is refused.)
        let base = BASE.replace("spacing_um = 2.0", "spacing_um = 5.0");
        let hard = format!("{base}\n[materials.Fe]\nhardness_gpa = 1.5\nshear_limit_gpa = 0.2\n");
        let c = Config::parse(&hard, &[]).unwrap();
        let fe = c.material("Fe").unwrap();
        assert_eq!(fe.limits.hardness, Some(1.5e9));
        assert_eq!(fe.limits.shear_limit, Some(0.2e9));
        assert_eq!(
            fe.elasticity,
            solver::presets::material("Fe").unwrap().elasticity
        );
        // Beside a table's own constants.
        let own = format!(
            "{base}\n[materials.soft]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\nhardness_gpa = 0.5\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"soft\"]");
        let c = Config::parse(&own, &[]).unwrap();
        assert_eq!(c.material("soft").unwrap().limits.hardness, Some(0.5e9));
        // Wrong values name their key.
        let negative = hard.replace("hardness_gpa = 1.5", "hardness_gpa = -1.0");
        let e = err(&negative, &[]);
        assert!(
            e.contains("materials.Fe.hardness_gpa") && e.contains("positive"),
            "{e}"
        );
        // Limits alone under a name that is no preset.
        let orphan = format!("{BASE}\n[materials.alloy]\nhardness_gpa = 1.0\n")
            .replace("materials = [\"Fe\"]", "materials = [\"alloy\"]");
        let e = err(&orphan, &[]);
        assert!(e.contains("not a preset"), "{e}");
    }

    #[test]
    fn issue59_item12_a_hardness_beyond_any_surface_is_refused_as_written() {
        // It was "got inf Pa": 1e300 GPa overflows in Pa.
        for (v, text) in [("1e300", "1e300"), ("-0.5", "-0.5"), ("nan", "NaN")] {
            for key in ["hardness_gpa", "shear_limit_gpa"] {
                let e = err(&format!("{BASE}\n[materials.Fe]\n{key} = {v}\n"), &[]);
                assert!(
                    e.contains(&format!("materials.Fe.{key} = {text}:")) && !e.contains("inf"),
                    "{e}"
                );
            }
        }
    }

    #[test]
    fn issue59_item12_an_unused_invalid_material_fails_check() {
        // The sweep uses Fe only; Zz's table is still read, and refused.
        for (table, key) in [
            ("hardness_gpa = -1.0", "materials.Zz.hardness_gpa"),
            ("hardness_gpa = 1.0", "materials.Zz: `Zz` is not a preset"),
            (
                "isotropic = { youngs_gpa = 100.0, poisson = 0.7 }",
                "materials.Zz.isotropic.poisson",
            ),
            (
                "cubic_gpa = { c11 = 168.4, c12 = 121.4, c44 = 75.4 }",
                "materials.Zz.normal",
            ),
        ] {
            let e = err(&format!("{BASE}\n[materials.Zz]\n{table}\n"), &[]);
            assert!(e.contains(key), "{table}: {e}");
        }
        let fine = format!(
            "{BASE}\n[materials.Zz]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\nhardness_gpa = 1.0\n"
        );
        Config::parse(&fine, &[]).unwrap();
    }

    #[test]
    fn issue59_item1_a_hardness_the_domain_cannot_carry_names_its_key_not_friction() {
        // BASE: Table 1(a) Fe on 64² of 2 µm under F = 0.6 μP, where
        // 0.01 GPa gave "gross sliding … Σ μp ΔA" (P/H is 20 times the
        // domain's area at 5 µm cells, 122 times here).
        for ratio in ["0.6", "0.0"] {
            let text = format!("{BASE}\n[materials.Fe]\nhardness_gpa = 0.01\n").replace(
                "tangential_ratio = 0.6",
                &format!("tangential_ratio = {ratio}"),
            );
            let e = err(&text, &[]);
            assert!(
                e.contains("invalid materials.Fe.hardness_gpa")
                    && e.contains("P/H")
                    && !e.contains("sliding"),
                "{e}"
            );
        }
    }

    #[test]
    fn issue20_item8_equivalent_constants_are_checked_or_refused() {
        let iso = format!(
            "{BASE}\n[materials.soft]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\nequivalent = {{ youngs_gpa = nan, poisson = 0.3 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"soft\"]");
        let e = err(&iso, &[]);
        assert!(e.contains("materials.soft.equivalent"), "{e}");
        let aniso = format!(
            "{BASE}\n[materials.odd]\ncubic_gpa = {{ c11 = 257.1, c12 = 125.9, c44 = 108.6 }}\nnormal = [1, 1, 1]\nx_dir = [1, 1, -2]\nequivalent = {{ youngs_gpa = nan, poisson = 0.3 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"odd\"]");
        let e = err(&aniso, &[]);
        assert!(e.contains("materials.odd.equivalent"), "{e}");
    }

    #[test]
    fn cubic_material_with_111_normal_reproduces_the_fe111_preset() {
        // Back-fitted cubic constants of Fe (see docs/validation.md), frame z ∥ [111], x ∥ [11-2].
        let text = format!(
            "{BASE}\n[materials.fe111]\ncubic_gpa = {{ c11 = 257.120, c12 = 125.913, c44 = 108.576 }}\nnormal = [1, 1, 1]\nx_dir = [1, 1, -2]\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"fe111\"]");
        let c = Config::parse(&text, &[]).unwrap();
        let mine = c.material("fe111").unwrap().stiffness();
        let preset = solver::presets::material("Fe(111)").unwrap().stiffness();
        let worst = (mine - preset).amax();
        assert!(worst < 0.05e9, "max deviation {worst:e} Pa");
    }
}
