//! Shared set-up of the validation tests: the paper's Table 1a case.
#![allow(dead_code)]

pub mod axisym;
pub mod md;

use solver::influence::isotropic_cell;
use solver::normal::{solve_normal, NormalCache, NormalProblem};
use solver::tangential::{
    TangentialMethod, TangentialProblem, TangentialSolution, TangentialStart,
};
use solver::Material;
use solver::Operator;
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

/// [`table_1a_fe`] on `n` cells of `spacing_um` under `cycles` fretting
/// cycles of ±`amplitude` μP after the first loading, in `increments`.
pub fn fretting_1a(
    (n, spacing_um): (usize, f64),
    coupling: bool,
    amplitude: f64,
    cycles: usize,
    increments: solver::Increments,
) -> CaseSpec {
    let mut ratios = vec![0.0, amplitude];
    for _ in 0..cycles {
        ratios.extend([-amplitude, amplitude]);
    }
    CaseSpec {
        history: Some(solver::LoadHistory {
            tangential_ratios: ratios,
            normal_forces_n: None,
            increments,
            sampling: Default::default(),
            shifts_m: None,
            wear: None,
        }),
        ..table_1a_fe(n, spacing_um, coupling, amplitude)
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

/// Table 1a's normal load, N, and friction coefficient.
pub const LOAD_1A: f64 = 20.0;
/// See [`LOAD_1A`].
pub const MU_1A: f64 = 0.28571;

/// Hertz's contact radius (m) and peak pressure (Pa) of Table 1a (Fe,
/// E = 210 GPa, ν = 0.3, rigid sphere of 18 mm, P = [`LOAD_1A`]).
pub fn hertz_1a() -> (f64, f64) {
    let e_star = 210.0e9 / (1.0 - 0.3 * 0.3);
    let a = (3.0 * LOAD_1A * 18.0e-3 / (4.0 * e_star)).cbrt();
    (a, 3.0 * LOAD_1A / (2.0 * std::f64::consts::PI * a * a))
}

/// Fe (E = 210 GPa, ν = 0.3) under a sphere of 18 mm: the operator of an
/// `n x n` grid of cell `d` and the sphere's separation on it.
pub fn fe_sphere(n: usize, d: f64) -> (Operator, Vec<f64>) {
    let grid = Grid { n, dx: d, dy: d };
    let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
    let g = e / (2.0 * (1.0 + nu));
    let op = Operator::build(grid, |x, y| isotropic_cell(g, nu, x, y, d, d));
    let h: Vec<f64> = (0..grid.len())
        .map(|i| {
            let (x, y) = (grid.x(i % n), grid.y(i / n));
            (x * x + y * y) / (2.0 * r)
        })
        .collect();
    (op, h)
}

/// Fe (E = 210 GPa, ν = 0.3) under a sphere of 18 mm at Table 1a's load:
/// the Hertz pressure on an `n x n` grid of cell `d`, and the operator.
pub fn hertz_fe(n: usize, d: f64) -> (Operator, Vec<f64>) {
    let (mut op, h) = fe_sphere(n, d);
    let mut cache = NormalCache::new(&mut op);
    let p = solve_normal(&mut op, &mut cache, &NormalProblem::new(&h, LOAD_1A))
        .unwrap()
        .p;
    (op, p)
}

/// Two tangential solutions of the pressure `p` compared: max |Δq| / (μ
/// p_max), |Δδt| / |δt| and the number of cells whose stick state differs.
pub fn tangential_difference(
    a: &TangentialSolution,
    b: &TangentialSolution,
    p: &[f64],
) -> (f64, f64, usize) {
    let pmax = p.iter().cloned().fold(0.0, f64::max);
    let dq = (0..p.len())
        .map(|i| (a.qx[i] - b.qx[i]).hypot(a.qy[i] - b.qy[i]))
        .fold(0.0, f64::max)
        / (MU_1A * pmax);
    let dt =
        (a.shift[0] - b.shift[0]).hypot(a.shift[1] - b.shift[1]) / a.shift[0].hypot(a.shift[1]);
    let stick = (0..p.len()).filter(|&i| a.stick[i] != b.stick[i]).count();
    (dq, dt, stick)
}

/// The quick sweep's conditions (Table 1c: R = 200 mm, P = 6 kN, μ = 0.3,
/// 128² of 60 µm), F = 0.6 μP along `angle_deg`, coupled, one step.
pub fn quick_1c(material: &str, surface: &str, angle_deg: f64) -> CaseSpec {
    CaseSpec {
        material: solver::presets::material(material).unwrap(),
        surface: solver::presets::surface(surface).unwrap(),
        grid: Grid::square(128, 60e-6),
        load: Load {
            indenter_radius_m: 0.2,
            normal_force_n: 6000.0,
            friction: 0.3,
            tangential_ratio: 0.6,
            angle_deg,
        },
        numerics: Numerics::default(),
        history: None,
        indenter: None,
    }
}

/// Cattaneo's step on the pressure `p` of [`hertz_fe`]: F = 0.6 μP along x
/// from rest, KKT tolerance 1e-6, by `method`.
pub fn cattaneo_problem(p: &[f64], method: TangentialMethod) -> TangentialProblem<'_> {
    TangentialProblem {
        p,
        friction: MU_1A,
        force: [0.6 * MU_1A * LOAD_1A, 0.0],
        extra: None,
        tolerance: 1e-6,
        slip_floor: 0.0,
        max_iterations: 5000,
        start: TangentialStart::Proportional,
        precondition: false,
        method,
    }
}
