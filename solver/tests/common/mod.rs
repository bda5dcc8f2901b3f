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

/// Willis's elliptical Hertz contact (`solver::indentation::willis_contact`)
/// as (a, b, orientation of a from x in rad, p₀), a the long semi-axis.
pub fn willis(h33: &dyn Fn(f64) -> f64, load: f64, radius: f64) -> (f64, f64, f64, f64) {
    let w = solver::indentation::willis_contact(h33, load, radius);
    (w.long_m, w.short_m, w.long_angle_rad, w.p_max_pa)
}

/// Semi-axes, orientation (rad from x, of the first) and peak of a pressure
/// field from its second moments: for p₀ √(1 − xᵀAx), ∫ p x xᵀ dA / P has
/// the eigenvalues a²/5 and b²/5.
pub fn ellipse_of(p: &[f64], grid: solver::Grid) -> (f64, f64, f64) {
    let n = grid.n;
    let (mut sxx, mut syy, mut sxy, mut sum) = (0.0, 0.0, 0.0, 0.0);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (grid.x(i), grid.y(j));
            let v = p[j * n + i];
            sxx += v * x * x;
            syy += v * y * y;
            sxy += v * x * y;
            sum += v;
        }
    }
    let (sxx, syy, sxy) = (sxx / sum, syy / sum, sxy / sum);
    let mean = 0.5 * (sxx + syy);
    let dev = (0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy).sqrt();
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    (
        (5.0 * (mean + dev)).sqrt(),
        (5.0 * (mean - dev)).sqrt(),
        angle,
    )
}

/// `|a/b − 1|`.
pub fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Cu (Table 2's cubic constants) cut with the general normal [1 2 3], x
/// along [1 1 −1]: no symmetry element of the crystal lies in the frame.
pub fn cu_123() -> Material {
    Material::cubic(
        "Cu[123]",
        [168.4e9, 121.4e9, 75.4e9],
        [1.0, 2.0, 3.0],
        [1.0, 1.0, -1.0],
        None,
    )
    .unwrap()
}
