//! Shared set-up of the validation tests: the paper's Table 1a case.
#![allow(dead_code)]

use solver::Material;
use solver::Surface;
use solver::{CaseSpec, Grid, Load, Numerics};
use std::f64::consts::PI;

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

/// Willis's solution of a sphere (radius `radius`) pressed with `load` into an
/// anisotropic half-space (Willis 1966), for the normal compliance
/// `h33(θ)` (1/Pa) of the contact: the pressure is p₀ √(1 − xᵀAx) on an
/// ellipse, and the normal displacement it makes inside the ellipse is
/// (ab p₀/8) ∫ h33(θ)/s(θ) [1 − (n·x)²/s(θ)²] dθ, n = (cos θ, sin θ),
/// s(θ) = |L n| with L the ellipse's semi-axes (the Fourier transform of the
/// half-ellipsoid, integrated along each direction). Matching the sphere's
/// profile makes M = ∫ h33 n nᵀ/s³ dθ a multiple of the identity, which
/// fixes the axes ratio and orientation; then a³ and p₀ follow from the
/// load. Returns (a, b, orientation of a from x in rad, p₀).
pub fn willis(h33: &dyn Fn(f64) -> f64, load: f64, radius: f64) -> (f64, f64, f64, f64) {
    let m = 4096;
    let table: Vec<(f64, f64)> = (0..m)
        .map(|k| {
            let th = 2.0 * PI * k as f64 / m as f64;
            (th, h33(th))
        })
        .collect();
    // M for semi-axes (1, e) with the first along φ.
    let moment = |e: f64, phi: f64| {
        let mut mm = [0.0; 3];
        for &(th, h) in &table {
            let (c, s) = ((th - phi).cos(), (th - phi).sin());
            let sv = (c * c + e * e * s * s).sqrt();
            let w = h / (sv * sv * sv);
            mm[0] += w * th.cos() * th.cos();
            mm[1] += w * th.sin() * th.sin();
            mm[2] += w * th.cos() * th.sin();
        }
        let d = 2.0 * PI / m as f64;
        [mm[0] * d, mm[1] * d, mm[2] * d]
    };
    let residual = |e: f64, phi: f64| {
        let mm = moment(e, phi);
        let t = mm[0] + mm[1];
        [(mm[0] - mm[1]) / t, 2.0 * mm[2] / t]
    };
    // Newton in (ln e, φ) with a finite-difference Jacobian, from an
    // ellipse (at e = 1 the orientation is undetermined and the Jacobian
    // singular), steps limited to 0.2.
    let (mut le, mut phi) = (-0.05_f64, 0.1_f64);
    for _ in 0..50 {
        let f = residual(le.exp(), phi);
        if f[0].hypot(f[1]) < 1e-14 {
            break;
        }
        let h = 1e-6;
        let fe = residual((le + h).exp(), phi);
        let fp = residual(le.exp(), phi + h);
        let j = [
            [(fe[0] - f[0]) / h, (fp[0] - f[0]) / h],
            [(fe[1] - f[1]) / h, (fp[1] - f[1]) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let dl = (j[1][1] * f[0] - j[0][1] * f[1]) / det;
        let dp = (j[0][0] * f[1] - j[1][0] * f[0]) / det;
        let scale = (0.2 / dl.abs().max(dp.abs())).min(1.0);
        le -= scale * dl;
        phi -= scale * dp;
    }
    let e = le.exp();
    let mm = moment(e, phi);
    let mt = 0.5 * (mm[0] + mm[1]);
    // (a b p₀/8) M/a³ = I/(2R) with p₀ = 3P/(2π a b): a³ = 3 P R mt/(8π).
    let a = (3.0 * load * radius * mt / (8.0 * PI)).cbrt();
    let b = e * a;
    (a, b, phi, 3.0 * load / (2.0 * PI * a * b))
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
