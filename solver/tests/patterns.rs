//! Micropatterned surfaces and the apparent friction μa (docs/validation.md, Patterns; ladder
//! step 7): vanishing patterns, the paper's Table 1(c) patterns, and the
//! symmetries μa must have.

use solver::{calibrate_k_e, solve_case, CaseOutput, CaseSpec, Grid, KernelCache, Load, Numerics};
use solver::{Island, LatticeKind, Sampling, Surface};

/// Paper Table 1(c) conditions on `n` cells of `spacing_um`.
fn table_1c(material: &str, surface: &str, n: usize, spacing_um: f64, angle: f64) -> CaseSpec {
    CaseSpec {
        material: solver::presets::material(material).unwrap(),
        surface: solver::presets::surface(surface).unwrap(),
        grid: Grid::square(n, spacing_um * 1e-6),
        load: Load {
            indenter_radius_m: 0.2,
            normal_force_n: 6000.0,
            friction: 0.3,
            tangential_ratio: 0.6,
            angle_deg: angle,
        },
        numerics: Numerics {
            coupling_tolerance: 1e-8,
            ..Numerics::default()
        },
        history: None,
        indenter: None,
    }
}

fn solve(spec: &CaseSpec, cache: &mut KernelCache) -> CaseOutput {
    let out = solve_case(spec, cache).unwrap();
    assert!(out.scalars.converged, "{:?}", out.scalars);
    let s = &out.scalars;
    let f = spec.tangential_force();
    assert!(
        (s.normal_force_n / spec.load.normal_force_n - 1.0).abs() < 1e-8,
        "Σ p ΔA = P"
    );
    let fe = (s.tangential_force_n[0] - f[0]).hypot(s.tangential_force_n[1] - f[1]);
    assert!(fe < 1e-8 * f[0].hypot(f[1]), "Σ q ΔA = F");
    out
}

#[test]
fn a_pattern_of_vanishing_height_gives_the_flat_result() {
    let mut cache = KernelCache::new();
    let flat = solve(&table_1c("Cu", "flat", 128, 40.0, 0.0), &mut cache);
    let mut spec = table_1c("Cu", "circle-B", 128, 40.0, 0.0);
    if let Surface::Lattice {
        height, sampling, ..
    } = &mut spec.surface
    {
        *height = 1e-13;
        // Whole cells: the area sampling keeps a cut cell's lower part clear
        // of the sphere, which a vanishing height does not; it touches the
        // base and says so (below).
        *sampling = Sampling::Centre;
    }
    let low = solve(&spec, &mut cache);
    if let Surface::Lattice { sampling, .. } = &mut spec.surface {
        *sampling = Sampling::Area;
    }
    assert!(solve(&spec, &mut cache).scalars.base_contact);
    let dp = flat
        .fields
        .p
        .iter()
        .zip(&low.fields.p)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let (a, b) = (&flat.scalars, &low.scalars);
    println!(
        "max |Δp| / p_max = {:.2e}; μa {} vs {}",
        dp / a.p_max_pa,
        a.mu_a.unwrap(),
        b.mu_a.unwrap()
    );
    assert!(dp < 1e-6 * a.p_max_pa);
    assert!((a.delta_t_m / b.delta_t_m - 1.0).abs() < 1e-6);
    assert!((a.mu_a.unwrap() / b.mu_a.unwrap() - 1.0).abs() < 1e-6);
}

/// Cells on an island with a neighbour off the island, or cut by its edge.
fn edge_cells(h: &[f64], cover: &[f64], n: usize) -> Vec<bool> {
    (0..n * n)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            h[i] > 0.0
                && x > 0
                && y > 0
                && x + 1 < n
                && y + 1 < n
                && (cover[i] < 1.0 || [i - 1, i + 1, i - n, i + n].iter().any(|&j| h[j] <= 0.0))
        })
        .collect()
}

#[test]
fn table_1c_patterns_contact_island_tops_and_dense_patterns_lower_mu_a() {
    let mut cache = KernelCache::new();
    let mut rows = Vec::new();
    for surface in ["flat", "circle-A", "circle-B", "square-A", "square-B"] {
        let spec = table_1c("Cu", surface, 192, 40.0, 0.0);
        let out = solve(&spec, &mut cache);
        let s = &out.scalars;
        let n = spec.grid.n;
        let h = spec.surface.heights(&spec.grid);
        let cover = spec
            .surface
            .cover(&spec.grid)
            .unwrap_or_else(|| vec![1.0; n * n]);
        // Where does the shear traction on the covered part (a cut cell's
        // mean over its cover) peak? On an island edge cell.
        let q = |i: usize| out.fields.qx[i].abs() / cover[i];
        let imax = (0..n * n).max_by(|&i, &j| q(i).total_cmp(&q(j))).unwrap();
        let on_edge = edge_cells(&h, &cover, n)[imax];
        println!(
            "{surface:9} μa = {:.4}  a = {:.3} mm  c = {:.3} mm  stick area = {:.3} mm²  p_max/p_H = {:.2}  q_max/p_H = {:.2}  base touched: {}  qx peak on an edge cell: {on_edge}",
            s.mu_a.unwrap(),
            s.contact_radius_m * 1e3,
            s.stick_radius_m * 1e3,
            s.stick_area_m2 * 1e6,
            s.p_max_pa / s.hertz_pressure_pa,
            s.q_max_pa / s.hertz_pressure_pa,
            s.base_contact
        );
        if surface != "flat" {
            assert!(!s.base_contact, "{surface}: the base plane is touched");
            assert!(on_edge, "{surface}: qx peaks inside an island");
        }
        rows.push((surface, s.mu_a.unwrap(), s.stick_radius_m));
    }
    let get = |name: &str| rows.iter().find(|r| r.0 == name).unwrap();
    for (sparse, dense) in [("circle-A", "circle-B"), ("square-A", "square-B")] {
        assert!(get(sparse).1 > get(dense).1, "μa({sparse}) > μa({dense})");
        assert!(
            get(sparse).2 > get(dense).2,
            "stick zone narrows with density"
        );
    }
    // The flat surface (density 1) has the narrowest stick zone of all.
    assert!(rows.iter().all(|r| r.2 >= get("flat").2));
}

#[test]
fn centred_square_lattice_mu_a_is_symmetric_about_45_degrees() {
    let mut cache = KernelCache::new();
    for surface in ["circle-B", "square-B"] {
        for (psi, mirror) in [(15.0, 75.0), (30.0, 60.0), (0.0, 90.0)] {
            let a = solve(&table_1c("Cu", surface, 128, 40.0, psi), &mut cache)
                .scalars
                .mu_a
                .unwrap();
            let b = solve(&table_1c("Cu", surface, 128, 40.0, mirror), &mut cache)
                .scalars
                .mu_a
                .unwrap();
            println!("{surface} μa({psi}) = {a:.6}, μa({mirror}) = {b:.6}");
            assert!((a / b - 1.0).abs() < 0.005);
        }
    }
}

#[test]
fn hexagonal_lattice_and_stripes_solve_with_equilibrium() {
    let mut cache = KernelCache::new();
    let mut spec = table_1c("Cu", "flat", 128, 50.0, 30.0);
    spec.surface = Surface::Lattice {
        island: Island::Circle { diameter: 400e-6 },
        pitch: 700e-6,
        height: 30e-6,
        offset: [0.0, 0.0],
        lattice: LatticeKind::Hexagonal,
        sampling: Sampling::Area,
    };
    let hex = solve(&spec, &mut cache).scalars;
    spec.surface = Surface::Stripes {
        width: 300e-6,
        pitch: 700e-6,
        height: 30e-6,
        angle_deg: 90.0,
        offset: 0.0,
        sampling: Sampling::Area,
    };
    let stripes = solve(&spec, &mut cache).scalars;
    println!(
        "hexagonal μa = {:?}, stripes μa = {:?}",
        hex.mu_a, stripes.mu_a
    );
    assert!(!hex.base_contact && !stripes.base_contact);
}

#[test]
fn flat_isotropic_mu_a_does_not_depend_on_the_force_direction() {
    let mut cache = KernelCache::new();
    let mu: Vec<f64> = [0.0, 30.0, 45.0]
        .iter()
        .map(|&psi| {
            solve(&table_1c("Cu", "flat", 256, 20.0, psi), &mut cache)
                .scalars
                .mu_a
                .unwrap()
        })
        .collect();
    println!("flat Cu μa(0, 30, 45) = {mu:?}");
    for m in &mu {
        assert!((m / mu[0] - 1.0).abs() < 0.005);
    }
}

#[test]
fn flat_111_k_e_has_the_crystal_symmetry() {
    // K_E(ψ) on flat Cu(111): period 120° and mirror ψ → −ψ (x ∥ [1 1 −2]).
    let mut cache = KernelCache::new();
    let k_e = |psi: f64, cache: &mut KernelCache| {
        let spec = table_1c("Cu(111)", "flat", 256, 20.0, psi);
        let s = solve(&spec, cache).scalars;
        calibrate_k_e(&s, spec.load.friction, spec.load.normal_force_n)
    };
    let (k0, k120, k30, km30, k90) = (
        k_e(0.0, &mut cache),
        k_e(120.0, &mut cache),
        k_e(30.0, &mut cache),
        k_e(-30.0, &mut cache),
        k_e(90.0, &mut cache),
    );
    println!(
        "Cu(111) K_E(0, 120, 30, -30, 90) = {k0:.5e} {k120:.5e} {k30:.5e} {km30:.5e} {k90:.5e} Pa"
    );
    assert!((k0 / k120 - 1.0).abs() < 0.005, "period 120°");
    assert!((k30 / km30 - 1.0).abs() < 0.005, "mirror about ψ = 0");
    assert!(
        (k30 / k90 - 1.0).abs() < 0.005,
        "30° and 90° are mirror images about 60°"
    );
}

#[test]
fn an_unresolved_slip_zone_is_a_named_error_not_an_infinite_mu_a() {
    // 32² cells of 200 µm: the few contact cells on the circle-A islands all
    // stay below the friction bound at F = 0.3 μP, so a = c.
    let mut spec = table_1c("Ni", "circle-A", 32, 200.0, 0.0);
    spec.load.tangential_ratio = 0.3;
    spec.numerics.coupling = false;
    // Whole cells, as the paper samples them (with the cut cells' cover
    // the outline slips even here).
    if let Surface::Lattice { sampling, .. } = &mut spec.surface {
        *sampling = Sampling::Centre;
    }
    let err = solve_case(&spec, &mut KernelCache::new()).unwrap_err();
    assert!(
        matches!(err, solver::SolverError::SlipUnresolved { .. }),
        "{err}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("contact cells stick") && msg.contains("grid.spacing_um"),
        "{msg}"
    );
    // The same surface resolved finely enough slips at its outline.
    let mut fine = table_1c("Ni", "circle-A", 128, 50.0, 0.0);
    fine.load.tangential_ratio = 0.3;
    fine.numerics.coupling = false;
    let ok = solve_case(&fine, &mut KernelCache::new()).unwrap();
    let s = &ok.scalars;
    assert!(s.stick_radius_m < s.contact_radius_m);
    assert!(s.mu_a.is_some_and(|m| m.is_finite() && m > 0.0));
}

/// Isotropic kernels are exactly mirror symmetric, so the default start on
/// Ni circle-A at 32² of 200 µm (the central island's 2x2 top) has gaps equal
/// to the bit: the solver once stopped there, unconverged, with 4 contact
/// cells carrying 37.5 GPa while the neighbouring islands interpenetrated by
/// 0.84 δz. A 2x2 punch carrying 6000 N sinks ~60 µm (P(1 − ν²)/(E·2s)), far
/// more than the 4 µm the sphere's profile lifts the next islands, so they
/// must touch.
#[test]
fn a_start_set_with_equal_gaps_admits_the_cells_that_interpenetrate() {
    let mut spec = table_1c("Ni", "circle-A", 32, 200.0, 0.0);
    spec.numerics.coupling = false;
    let mut cache = KernelCache::new();
    let (res, _) = cache.resident(&spec).unwrap();
    let h0 = spec.initial_gap();
    let normal = res
        .solve_normal(&solver::normal::NormalProblem {
            tolerance: spec.numerics.tolerance,
            max_iterations: spec.numerics.max_iterations,
            ..solver::normal::NormalProblem::new(&h0, spec.load.normal_force_n)
        })
        .unwrap();
    let r = &normal.report;
    assert!(
        r.converged && r.penetration == 0.0 && r.gap_residual < 1e-10,
        "{r:?}"
    );
    let contact = normal.p.iter().filter(|&&v| v > 0.0).count();
    assert!(contact > 4, "{contact} contact cells");
    let da = spec.grid.dx * spec.grid.dy;
    let load = normal.p.iter().sum::<f64>() * da;
    assert!((load / spec.load.normal_force_n - 1.0).abs() < 1e-12);
}

/// An unconverged solve is flagged as not converged, not reported as a grid
/// that does not resolve the slip zone: near gross sliding (F = 0.995 μP) the
/// converged stick zone spans less than two cells (SlipUnresolved), but a
/// coupled solve stopped after one coupling pass has not converged, and that
/// is what the case must say.
#[test]
fn an_unconverged_solve_is_flagged_not_called_unresolved() {
    let mut spec = table_1c("Ni", "flat", 32, 200.0, 0.0);
    spec.numerics.coupling = false;
    spec.load.tangential_ratio = 0.995;
    match solve_case(&spec, &mut KernelCache::new()) {
        Err(solver::SolverError::SlipUnresolved { .. }) => {}
        other => panic!("{:?}", other.map(|o| o.scalars)),
    }
    // The tangential solve converges in 10 iterations and the normal one
    // needs over 20, so no shared budget stops the tangential one alone: the
    // coupled loop stopped after its first pass has not converged.
    spec.numerics.coupling = true;
    spec.numerics.max_coupling_iterations = 1;
    let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
    let s = &out.scalars;
    assert!(
        s.normal.converged && s.coupling_iterations == 1 && !s.converged,
        "{s:?}"
    );
}

/// A coupled solve stopped by its pass budget reports the slip of its last
/// tangential solve on every cell of the grid: zero on the stick cells and,
/// on the slip cells still in contact, opposed to the traction (the
/// friction law; the last normal solve may have moved the contact's edge).
#[test]
fn a_solve_stopped_by_its_coupling_budget_keeps_its_slip_field() {
    for passes in [1, 2] {
        let mut spec = table_1c("Ni", "flat", 32, 200.0, 0.0);
        spec.numerics.coupling = true;
        spec.numerics.max_coupling_iterations = passes;
        let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
        let (s, f) = (&out.scalars, &out.fields);
        assert!(!s.converged && s.coupling_iterations == passes, "{s:?}");
        let len = f.n * f.n;
        assert_eq!((f.sx.len(), f.sy.len()), (len, len), "{passes} passes");
        let mut slipping = 0;
        for i in 0..len {
            let slip = f.sx[i].hypot(f.sy[i]);
            if f.stick[i] == 1.0 {
                assert_eq!(slip, 0.0, "stick cell {i}");
            } else if slip > 1e-3 * s.delta_t_m.abs() && f.p[i] > 0.0 {
                slipping += 1;
                let q = f.qx[i].hypot(f.qy[i]);
                let cos = (f.sx[i] * f.qx[i] + f.sy[i] * f.qy[i]) / (slip * q);
                assert!(cos < -0.99, "cell {i}: slip at cos {cos} to the traction");
            }
        }
        assert!(slipping > 0, "{passes} passes: no slip zone");
    }
}
