//! Shared set-up of the validation tests: the paper's Table 1a case.
#![allow(dead_code)]

use solver::Material;
use solver::Surface;
use solver::{CaseSpec, Grid, Load, Numerics};

/// Table 1a, isotropic Fe: E = 210 GPa, ν = 0.3, R = 18 mm, P = 20 N, μ = 0.28571,
/// F = 0.6 μP, on `n` cells of `spacing_um`.
pub fn table_1a_fe(n: usize, spacing_um: f64, coupling: bool, ratio: f64) -> CaseSpec {
    CaseSpec {
        material: Material::isotropic("Fe", 210.0e9, 0.3).unwrap(),
        surface: Surface::Flat,
        grid: Grid::square(n, spacing_um * 1e-6),
        load: Load {
            indenter_radius_m: 18.0e-3,
            normal_force_n: 20.0,
            friction: 0.28571,
            tangential_ratio: ratio,
            angle_deg: 0.0,
        },
        numerics: Numerics {
            coupling,
            coupling_tolerance: 1e-8,
            ..Numerics::default()
        },
        history: None,
        indenter: None,
    }
}
