//! Island edges resolved below the cell (issue #34): one flat-topped
//! plateau under a nearly flat sphere, the contact covering the whole
//! plateau. That is Boussinesq's rigid punch with a spherical face (Johnson
//! §5.2 with a spherical profile): `δ = P/(2bE*) + b²/(3R)` for a plateau of
//! radius b, while the edge pressure stays positive (P above the Hertz load
//! of a contact of radius b, `4E*b³/(3R)`).
//!
//! With the cover of the cut cells (`sampling = "area"`) the error in δz
//! falls monotonically at first order in the cell size; with whole cells by
//! their centre (`sampling = "centre"`) it jumps with the grid.

use solver::{solve_case, CaseSpec, Grid, Island, KernelCache, LatticeKind, Load, Material};
use solver::{Numerics, Sampling, Surface};

/// Fe, E* = E/(1 − ν²).
const E: f64 = 210.0e9;
const NU: f64 = 0.3;
/// Plateau radius (or half-side), m.
const B: f64 = 50.0e-6;
/// Sphere radius, m: nearly flat over the plateau.
const R: f64 = 1.0;
/// The domain's side over the plateau radius.
const DOMAIN: f64 = 2.4;
/// Grids of one domain: b/h = n / 2.4 = 10, 14.2, 20, 28.3, 40, 56.7, 80, 113.
const LADDER: [usize; 8] = [24, 34, 48, 68, 96, 136, 192, 272];

fn e_star() -> f64 {
    E / (1.0 - NU * NU)
}

/// The load: four times the Hertz load of a contact of radius b, so that the
/// punch term is 8/9 of δ and the edge pressure clearly positive.
fn load() -> f64 {
    4.0 * 4.0 * e_star() * B.powi(3) / (3.0 * R)
}

/// One plateau (island of a lattice whose pitch puts its neighbours far
/// outside the domain) centred under the apex, on `n` cells.
fn plateau(island: Island, sampling: Sampling, n: usize) -> CaseSpec {
    CaseSpec {
        material: Material::isotropic("Fe", E, NU).unwrap(),
        surface: Surface::Lattice {
            island,
            pitch: 20.0 * B,
            height: 1.0e-6,
            offset: [0.0, 0.0],
            lattice: LatticeKind::Square,
            sampling,
        },
        grid: Grid::square(n, DOMAIN * B / n as f64),
        load: Load {
            indenter_radius_m: R,
            normal_force_n: load(),
            friction: 0.3,
            tangential_ratio: 0.0,
            angle_deg: 0.0,
        },
        numerics: Numerics {
            coupling: false,
            ..Numerics::default()
        },
        history: None,
        indenter: None,
    }
}

/// The approach from the apex: δz is measured from the first touch, at the
/// plateau cell centres nearest the apex, `min r²/(2R)` below it.
fn approach(spec: &CaseSpec, cache: &mut KernelCache) -> f64 {
    let out = solve_case(spec, cache).unwrap();
    let s = out.scalars;
    assert!(s.converged && !s.base_contact, "{s:?}");
    let g = spec.grid;
    let r2 = (0..g.n)
        .map(|i| g.x(i) * g.x(i))
        .fold(f64::INFINITY, f64::min);
    s.delta_z_m + 2.0 * r2 / (2.0 * R)
}

fn circle() -> Island {
    Island::Circle { diameter: 2.0 * B }
}

/// The closed form.
fn punch() -> f64 {
    load() / (2.0 * B * e_star()) + B * B / (3.0 * R)
}

/// Orders between successive grids, `ln(e1/e2) / ln(h1/h2)`.
fn orders(errs: &[f64]) -> Vec<f64> {
    LADDER
        .windows(2)
        .zip(errs.windows(2))
        .map(|(n, e)| (e[0].abs() / e[1].abs()).ln() / (n[1] as f64 / n[0] as f64).ln())
        .collect()
}

#[test]
fn a_circular_plateau_converges_monotonically_to_the_rigid_punch() {
    let exact = punch();
    let mut cache = KernelCache::new();
    let mut table = Vec::new();
    for &n in &LADDER {
        let area = approach(&plateau(circle(), Sampling::Area, n), &mut cache) / exact - 1.0;
        let centre = approach(&plateau(circle(), Sampling::Centre, n), &mut cache) / exact - 1.0;
        table.push((n, area, centre));
    }
    println!("b/h    area      centre   (relative error in δz; δ = {exact:.6e} m)");
    for &(n, a, c) in &table {
        println!("{:5.1} {a:+.3e} {c:+.3e}", n as f64 / DOMAIN);
    }
    let errs: Vec<f64> = table.iter().map(|t| t.1).collect();
    let ord = orders(&errs);
    println!("observed orders (area): {ord:.3?}");
    for w in errs.windows(2) {
        assert!(w[1].abs() < w[0].abs(), "not monotone: {errs:?}");
        assert!(w[1].signum() == w[0].signum(), "sign change: {errs:?}");
    }
    for o in &ord {
        assert!((0.85..1.2).contains(o), "order {o}: {ord:?}");
    }
    assert!(errs.last().unwrap().abs() <= 1e-3, "{errs:?}");
}

#[test]
fn a_square_plateau_converges_monotonically_to_its_extrapolated_limit() {
    let square = Island::Square { side: 2.0 * B };
    let mut cache = KernelCache::new();
    let mut area = Vec::new();
    let mut centre = Vec::new();
    for &n in &LADDER {
        area.push(approach(&plateau(square, Sampling::Area, n), &mut cache));
        centre.push(approach(&plateau(square, Sampling::Centre, n), &mut cache));
    }
    // The reference: the grids whose cells fit the square exactly (b/h =
    // 40, 80, 160: no cut cells, so the same for both samplings),
    // extrapolated with their own observed order.
    let [f1, f2, f3] =
        [96, 192, 384].map(|n| approach(&plateau(square, Sampling::Area, n), &mut cache));
    let p_obs = ((f1 - f2) / (f2 - f3)).log2();
    let reference = f3 + (f3 - f2) / (2f64.powf(p_obs) - 1.0);
    println!("reference from b/h = 40, 80, 160: observed order {p_obs:.3}");
    println!(
        "square plateau, reference δ = {reference:.6e} m (round punch of equal area: {:.6e})",
        load() / (2.0 * (4.0 / std::f64::consts::PI).sqrt() * B * e_star())
    );
    println!("b/h    area      centre");
    let errs: Vec<f64> = area.iter().map(|d| d / reference - 1.0).collect();
    for ((&n, e), c) in LADDER.iter().zip(&errs).zip(&centre) {
        println!(
            "{:5.1} {e:+.3e} {:+.3e}",
            n as f64 / DOMAIN,
            c / reference - 1.0
        );
    }
    let ord = orders(&errs);
    println!("observed orders (area): {ord:.3?}");
    for w in errs.windows(2) {
        assert!(
            w[1].abs() < w[0].abs() && w[1].signum() == w[0].signum(),
            "{errs:?}"
        );
    }
    for o in &ord {
        assert!((0.7..1.4).contains(o), "order {o}: {ord:?}");
    }
}
