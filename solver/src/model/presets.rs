//! Named materials and surfaces of the paper (Table 1 and Table 2), so configs
//! can say `"Cu(111)"` or `"circle-A"`. Values are the paper's, verbatim.

use crate::green::aniso::presets::{table2_stiffness, Table2Material};
use crate::model::material::{Anisotropic, Elasticity, Isotropic, Material};
use crate::model::surface::{Island, Surface};

const GPA: f64 = 1e9;
const UM: f64 = 1e-6;

/// All preset materials, in display order.
pub fn materials() -> Vec<Material> {
    let iso = |name: &str, e_gpa: f64, nu: f64| {
        let c = Isotropic {
            youngs: e_gpa * GPA,
            poisson: nu,
        };
        Material {
            name: name.into(),
            elasticity: Elasticity::Isotropic(c),
            equivalent: c,
            limits: Default::default(),
        }
    };
    // (111) crystals: Table 2 stiffness; isotropic-equivalent E, ν of Table 1
    // (used only to normalise and as a fallback K_E).
    let crystal = |m: Table2Material, e_gpa: f64, nu: f64| Material {
        name: m.name().into(),
        elasticity: Elasticity::Anisotropic(Anisotropic(table2_stiffness(m))),
        equivalent: Isotropic {
            youngs: e_gpa * GPA,
            poisson: nu,
        },
        limits: Default::default(),
    };
    vec![
        iso("Fe", 210.0, 0.3),
        iso("Cu", 128.73, 0.345),
        iso("Ni", 220.64, 0.302),
        crystal(Table2Material::Fe111, 220.41, 0.391),
        crystal(Table2Material::Cu111, 128.53, 0.503),
        crystal(Table2Material::Ni111, 227.34, 0.423),
        // Ball materials of tribometers (`indenter.material`): typical
        // handbook values, not the paper's.
        iso("steel", 210.0, 0.3),
        iso("WC", 614.0, 0.22),
        iso("Al2O3", 370.0, 0.22),
        iso("glass", 70.0, 0.22),
    ]
}

/// Where a preset material's constants come from.
pub fn material_source(name: &str) -> &'static str {
    match name {
        "Fe" => "paper Table 1(a): isotropic E, ν",
        "Cu" | "Ni" => "paper Table 1(c): isotropic E, ν",
        "Fe(111)" | "Cu(111)" | "Ni(111)" => {
            "paper Table 2: stiffness in the (111) frame; E, ν of Table 1 (normalisation only)"
        }
        "steel" => "ball: bearing steel (AISI 52100), typical E, ν",
        "WC" => "ball: cemented tungsten carbide (WC-6Co), typical E, ν",
        "Al2O3" => "ball: alumina (99.5 %), typical E, ν",
        "glass" => "ball: soda-lime glass, typical E, ν",
        _ => "",
    }
}

/// A preset material's typical hardness: the range a real surface of it
/// has (Vickers HV × 9.81 MPa; Tabor's H ≈ 3Y), and what spans it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HardnessRange {
    /// Softest typical hardness, Pa.
    pub low_pa: f64,
    /// Hardest typical hardness, Pa: a pressure above it yields a real surface.
    pub high_pa: f64,
    /// What the range spans.
    pub what: &'static str,
}

/// The typical hardness of the preset `name` (docs/config.md,
/// `materials.NAME.hardness_gpa`); `None` for a name that is no preset.
pub fn hardness_range(name: &str) -> Option<HardnessRange> {
    let (low, high, what) = match name {
        "Fe" => (0.7, 1.8, "annealed pure iron to mild steel"),
        "Cu" => (0.4, 1.2, "annealed to cold-worked copper"),
        "Ni" => (0.8, 1.2, "annealed nickel"),
        "Fe(111)" | "Cu(111)" | "Ni(111)" => (
            0.5,
            1.5,
            "single crystals by nanoindentation at micrometre depths",
        ),
        "steel" => (6.0, 8.0, "hardened bearing steel"),
        "WC" => (13.0, 18.0, "cemented tungsten carbide"),
        "Al2O3" => (14.0, 20.0, "sintered alumina"),
        "glass" => (5.0, 6.0, "soda-lime glass"),
        _ => return None,
    };
    Some(HardnessRange {
        low_pa: low * GPA,
        high_pa: high * GPA,
        what,
    })
}

/// The typical hardness of `m` when it is a preset (its name and elastic
/// constants: a `[materials.Fe]` table with constants of its own is not
/// the preset and has none).
pub fn typical_hardness(m: &Material) -> Option<HardnessRange> {
    let preset = material(&m.name)?;
    (preset.elasticity == m.elasticity)
        .then(|| hardness_range(&m.name))
        .flatten()
}

/// A preset material by name (case-sensitive, as printed by `mpcontact materials`).
pub fn material(name: &str) -> Option<Material> {
    materials().into_iter().find(|m| m.name == name)
}

/// All preset surfaces: name, surface.
pub fn surfaces() -> Vec<(&'static str, Surface)> {
    let lattice = |island: Island, pitch_um: f64| Surface::Lattice {
        island,
        pitch: pitch_um * UM,
        height: 30.0 * UM,
        offset: [0.0, 0.0],
        lattice: crate::model::surface::LatticeKind::Square,
        sampling: crate::model::surface::Sampling::Area,
    };
    let circle = Island::Circle {
        diameter: 400.0 * UM,
    };
    let square = Island::Square { side: 340.0 * UM };
    vec![
        ("flat", Surface::Flat),
        ("circle-A", lattice(circle, 1280.0)),
        ("circle-B", lattice(circle, 640.0)),
        ("square-A", lattice(square, 1280.0)),
        ("square-B", lattice(square, 640.0)),
    ]
}

/// A preset surface by name.
pub fn surface(name: &str) -> Option<Surface> {
    surfaces()
        .into_iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_densities_match_table_1c() {
        // Circle A 7.7 %, Circle B 30.7 %, Square A 7.1 %, Square B 28.2 %.
        for (name, d) in [
            ("circle-A", 0.077),
            ("circle-B", 0.307),
            ("square-A", 0.071),
            ("square-B", 0.282),
        ] {
            let got = surface(name).unwrap().density();
            assert!((got - d).abs() < 0.0006, "{name}: {got}");
        }
    }

    #[test]
    fn every_preset_material_has_a_typical_hardness_and_tables_of_its_own_none() {
        for m in materials() {
            let r = typical_hardness(&m).unwrap_or_else(|| panic!("{}", m.name));
            assert!(0.0 < r.low_pa && r.low_pa < r.high_pa, "{}", m.name);
        }
        let own = Material::isotropic("Fe", 100e9, 0.3).unwrap();
        assert_eq!(typical_hardness(&own), None);
    }

    #[test]
    fn crystal_presets_are_positive_definite() {
        for m in materials() {
            m.validate().unwrap();
        }
    }
}
