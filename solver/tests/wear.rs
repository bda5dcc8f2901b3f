//! Wear along a load path (issue #49, PHYSICS.md §5d): the substrate's
//! worn depth per increment, `dh = k p |ds|` (Archard) or `dh = α |q · ds|`
//! (dissipated energy), joins the separation the next increment sees.
//! Checked against the closed forms of gross slip for a rigid sphere
//! without coupling: while the contact slides its surface has moved
//! elastically by u(r) = δ*(1 − r²/2a²), pressure-weighted mean 0.8 δ*, so a
//! cycle 0 → +Δ → −Δ → 0 from rest wears V₁ = 4kP(Δ − δ*) (Δ ≥ 2δ*) and
//! every later one V = 4kP(Δ − 0.8δ*); and the energy law's volume is α
//! times the dissipated energy.
mod common;

use common::{LOAD_1A, MU_1A};
use solver::{solve_case, KernelCache, LoadHistory, Wear, WearLaw};

/// Mindlin's δ* = 3μP(2 − ν)/(16 a G) on Table 1(a) Fe.
fn delta_star() -> f64 {
    let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
    let a = (3.0 * LOAD_1A * r / (4.0 * e / (1.0 - nu * nu))).cbrt();
    let g = e / (2.0 * (1.0 + nu));
    3.0 * MU_1A * LOAD_1A * (2.0 - nu) / (16.0 * a * g)
}

/// The shifts `shifts` imposed on Table 1(a) Fe at 128² of 2 µm,
/// coupling off, with `law`, `steps` increments per segment.
fn worn(law: WearLaw, shifts: Vec<f64>, steps: usize) -> solver::CaseOutput {
    let mut spec = common::table_1a_fe(128, 2.0, false, 0.0);
    spec.history = Some(LoadHistory {
        tangential_ratios: Vec::new(),
        normal_forces_n: None,
        increments: solver::Increments::Fixed(steps),
        sampling: Default::default(),
        shifts_m: Some(shifts),
        wear: Some(Wear::new(law)),
    });
    solve_case(&spec, &mut KernelCache::new()).expect("the path solves")
}

#[test]
fn archard_wear_in_gross_slip_follows_the_sliding_distance() {
    // A coefficient so small that the worn depth (≈ 1e-17 m) leaves the
    // contact as it is: the volume is then k P times the sliding distance.
    let k = 1e-20;
    let ds = delta_star();
    let amplitude = 3.0 * ds;
    let a = amplitude;
    let out = worn(
        WearLaw::Archard { k },
        vec![0.0, a, -a, 0.0, a, -a, 0.0],
        20,
    );
    assert!(out.scalars.converged);
    let h = out.scalars.history.expect("a path");
    let at = |j: usize| h.steps[h.turning_steps[j]].worn_volume_m3;
    let first = at(3);
    let second = at(6) - at(3);
    let v1 = 4.0 * k * LOAD_1A * (amplitude - ds);
    let v2 = 4.0 * k * LOAD_1A * (amplitude - 0.8 * ds);
    println!(
        "first cycle {first:.6e} m³ against 4kP(Δ − δ*) {v1:.6e} ({:+.2e}); second {second:.6e} against 4kP(Δ − 0.8δ*) {v2:.6e} ({:+.2e})",
        first / v1 - 1.0,
        second / v2 - 1.0
    );
    assert!((first / v1 - 1.0).abs() < 0.01, "first cycle");
    assert!((second / v2 - 1.0).abs() < 0.01, "later cycle");
    // The path's total (these cycles start and end at 0, not at a turning
    // point of their own: no two-segment cycle to report).
    assert_eq!(h.worn_volume_m3, Some(at(6)));
    assert_eq!(h.worn_volume_per_cycle_m3, None);
    // The worn depth field carries the volume.
    let da = 4e-12;
    let field: f64 = out.fields.wear.iter().sum::<f64>() * da;
    assert!((field / at(6) - 1.0).abs() < 1e-12);
    assert_eq!(
        h.worn_depth_max_m,
        Some(out.fields.wear.iter().cloned().fold(0.0, f64::max))
    );
}

#[test]
fn the_energy_law_wears_alpha_times_the_dissipated_energy() {
    let alpha = 1e-20;
    let a = 3.0 * delta_star();
    let out = worn(WearLaw::Energy { alpha }, vec![0.0, a, -a, a], 10);
    let h = out.scalars.history.expect("a path");
    let volume = h.worn_volume_m3.expect("worn");
    let energy = h.dissipated_total_j;
    println!(
        "worn {volume:.9e} m³, α × dissipated {:.9e} m³",
        alpha * energy
    );
    // To the trapezoidal rule's sign: at the stick–slip transitions a few
    // cells' mean traction and slip increment make a slightly negative
    // product, which the dissipated energy sums with its sign and the law's
    // |q · ds| does not (9e-8 of the total on two cycles at 10 increments).
    assert!((volume / (alpha * energy) - 1.0).abs() < 1e-6);
    let per_cycle = h.worn_volume_per_cycle_m3.expect("a cycle");
    let w = h.dissipated_energy_per_cycle_j.expect("a cycle");
    println!(
        "last cycle: worn {per_cycle:.9e} m³, α × dissipated {:.9e} m³",
        alpha * w
    );
    assert!((per_cycle / (alpha * w) - 1.0).abs() < 1e-6);
}

/// Table 1(a) Fe at 128² of 2.5 µm (the domain spans 1.6 a: a worn
/// partial-slip contact grows past the Hertz radius), coupling off, under
/// `cycles` fretting cycles of ±0.6 μP (10 increments per segment), Archard
/// wear with `k`, each simulated cycle standing for `jump` physical ones.
fn fretted(k: f64, cycles: usize, jump: f64) -> solver::CaseOutput {
    let mut spec = common::table_1a_fe(128, 2.5, false, 0.0);
    let mut ratios = vec![0.0, 0.6];
    for _ in 0..cycles {
        ratios.extend([-0.6, 0.6]);
    }
    spec.history = Some(LoadHistory {
        tangential_ratios: ratios,
        normal_forces_n: None,
        increments: solver::Increments::Fixed(10),
        sampling: Default::default(),
        shifts_m: None,
        wear: Some(Wear {
            law: WearLaw::Archard { k },
            ball: None,
            jump,
        }),
    });
    solve_case(&spec, &mut KernelCache::new()).expect("the path solves")
}

/// Hertz's radius and E* of Table 1(a) Fe.
fn hertz_1a() -> (f64, f64) {
    let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
    let es = e / (1.0 - nu * nu);
    ((3.0 * LOAD_1A * r / (4.0 * es)).cbrt(), es)
}

#[test]
fn partial_slip_wear_confines_the_pressure_to_the_stick_zone() {
    // PHYSICS.md §5d: under a constant force amplitude the slip annulus
    // wears until it carries nothing, the stick radius stays, and the
    // pressure tends to Ciavarella & Hills's sphere on a contact confined
    // to r < c.
    let (a, es) = hertz_1a();
    let r_ball = 18.0e-3;
    let c = a * 0.4_f64.cbrt();
    let ch = |r: f64| {
        if r >= c {
            return 0.0;
        }
        let s = (c * c - r * r).sqrt();
        2.0 * es / (std::f64::consts::PI * r_ball) * s
            + (LOAD_1A - 4.0 * es * c.powi(3) / (3.0 * r_ball))
                / (2.0 * std::f64::consts::PI * c * s)
    };
    let (n, h) = (128, 2.5e-6);
    let da = h * h;
    let at = |i: usize| {
        let x = (i % n) as f64 - 0.5 * (n as f64 - 1.0);
        let y = (i / n) as f64 - 0.5 * (n as f64 - 1.0);
        x.hypot(y) * h
    };
    // The limit averaged over each cell (8 × 8 points: it is singular at
    // c), the load outside c and the distance ∫|p − p_CH| dA.
    let sub = 8;
    let limit: Vec<f64> = (0..n * n)
        .map(|i| {
            let (x0, y0) = (
                (i % n) as f64 - 0.5 * n as f64,
                (i / n) as f64 - 0.5 * n as f64,
            );
            let mut s = 0.0;
            for u in 0..sub {
                for v in 0..sub {
                    let x = (x0 + (u as f64 + 0.5) / sub as f64) * h;
                    let y = (y0 + (v as f64 + 0.5) / sub as f64) * h;
                    s += ch(x.hypot(y));
                }
            }
            s / (sub * sub) as f64
        })
        .collect();
    // The limit's own singular edge cannot be matched cell by cell: within
    // two cells of c the loads are compared, elsewhere the pressures.
    let band = |i: usize| (at(i) - c).abs() <= 2.0 * h;
    let measure = |p: &[f64]| {
        let outside: f64 = (0..p.len())
            .filter(|&i| at(i) > c + 2.0 * h)
            .map(|i| p[i])
            .sum::<f64>()
            * da;
        let (mut off, mut on) = (0.0, 0.0);
        for i in 0..p.len() {
            if band(i) {
                on += p[i] - limit[i];
            } else {
                off += (p[i] - limit[i]).abs();
            }
        }
        (outside / LOAD_1A, (off + on.abs()) * da / LOAD_1A)
    };
    // A jump of 2e5 cycles per simulated one at k = 1e-5 mm³/(N·m): the
    // first simulated cycle wears ~4 % of the approach.
    let k = 1e-5 * 1e-9;
    let mut rows = Vec::new();
    for cycles in [1, 4, 12] {
        let out = fretted(k, cycles, 2e5);
        assert!(out.scalars.converged, "{cycles} cycles");
        let hist = out.scalars.history.expect("a path");
        let last = hist.wear_cycles.last().expect("a cycle").clone();
        let (outside, distance) = measure(&out.fields.p);
        println!(
            "{cycles:>2} cycles: load beyond c + 2 cells {outside:.4} P, distance to the limit {distance:.4} P, stick radius {:.4} c, depth {:.3e} m, energy {:.3e} J",
            last.stick_radius_m / c,
            last.depth_max_m,
            last.dissipated_j
        );
        rows.push((outside, distance, last));
    }
    // The stick radius stays (Mindlin's c, to the apparent radius's
    // discretisation).
    for (_, _, last) in &rows {
        assert!((last.stick_radius_m / c - 1.0).abs() < 0.02);
    }
    // The load leaves the slip annulus, the pressure approaches the limit
    // (to a floor: see docs/validation.md), and the energy per cycle falls
    // as the annulus stops slipping under load.
    assert!(rows[1].0 < 0.2 * rows[0].0 && rows[2].0 < 1e-3);
    assert!(rows[1].1 < 0.25 * rows[0].1 && rows[2].1 < 0.25 * rows[0].1);
    assert!(rows[2].2.dissipated_j < 0.05 * rows[0].2.dissipated_j);
}

#[test]
fn a_cycle_jump_converges_at_first_order() {
    // The same 8e4 physical cycles as 2, 4 and 8 simulated ones: the worn
    // volume and the largest depth change by about half as much each time
    // the jump is halved (the scheme is first order in the jump).
    let k = 1e-5 * 1e-9;
    let ends: Vec<(f64, f64)> = [2usize, 4, 8]
        .iter()
        .map(|&cycles| {
            let out = fretted(k, cycles, 8e4 / cycles as f64);
            assert!(out.scalars.converged);
            let hist = out.scalars.history.expect("a path");
            let last = hist.wear_cycles.last().expect("a cycle").clone();
            assert_eq!(last.physical_cycles, 8e4);
            // The records agree with the path's totals and the field.
            assert_eq!(hist.wear_cycles.len(), cycles);
            assert_eq!(Some(last.worn_volume_m3), hist.worn_volume_m3);
            // Both per physical cycle.
            assert_eq!(
                Some(last.worn_volume_per_cycle_m3),
                hist.worn_volume_per_cycle_m3
            );
            let deepest = out.fields.wear.iter().cloned().fold(0.0, f64::max);
            assert_eq!(last.depth_max_m, deepest);
            let per_cycle: f64 = hist
                .wear_cycles
                .iter()
                .map(|c| c.worn_volume_per_cycle_m3)
                .sum();
            let first_loading = hist.steps[hist.turning_steps[1]].worn_volume_m3;
            let jump = 8e4 / cycles as f64;
            assert!(
                (first_loading + per_cycle * jump - last.worn_volume_m3).abs()
                    < 1e-9 * last.worn_volume_m3
            );
            assert!(
                last.profile_x_m.len() == 128
                    && hist.wear_cycles[0].profile_x_m.is_empty() == (cycles > 1)
            );
            println!(
                "jump {:>6}: volume {:.6e} m³, depth {:.6e} m",
                8e4 / cycles as f64,
                last.worn_volume_m3,
                last.depth_max_m
            );
            (last.worn_volume_m3, last.depth_max_m)
        })
        .collect();
    for (name, pick) in [("volume", 0usize), ("depth", 1)] {
        let v = |j: usize| if pick == 0 { ends[j].0 } else { ends[j].1 };
        let (d1, d2) = ((v(0) - v(1)).abs(), (v(1) - v(2)).abs());
        println!(
            "{name}: differences {d1:.3e}, {d2:.3e} (ratio {:.2})",
            d2 / d1
        );
        assert!(d2 < 0.7 * d1, "{name}");
    }
}

#[test]
fn islands_worn_through_are_counted() {
    // Circular islands 20 nm high (the approach is 0.6 µm) under a cycle
    // that wears ~0.1 µm: the slip annulus's islands are worn through, and
    // the record counts their cells; 2 µm islands are not.
    let count = |height: f64| {
        let mut spec = common::table_1a_fe(64, 5.0, false, 0.0);
        spec.surface = solver::Surface::Lattice {
            island: solver::Island::Circle { diameter: 24e-6 },
            pitch: 40e-6,
            height,
            offset: [0.0, 0.0],
            lattice: solver::LatticeKind::Square,
            sampling: solver::Sampling::Area,
        };
        spec.history = Some(LoadHistory {
            tangential_ratios: vec![0.0, 0.6, -0.6, 0.6],
            normal_forces_n: None,
            increments: solver::Increments::Fixed(5),
            sampling: Default::default(),
            shifts_m: None,
            wear: Some(Wear {
                law: WearLaw::Archard { k: 1e-5 * 1e-9 },
                ball: None,
                jump: 2e6,
            }),
        });
        let out = solve_case(&spec, &mut KernelCache::new()).expect("the path solves");
        let last = out.scalars.history.expect("a path").wear_cycles[0].clone();
        println!(
            "islands {height:e} m: depth {:.3e} m, {} cells worn through",
            last.depth_max_m, last.worn_through_cells
        );
        (last.depth_max_m, last.worn_through_cells)
    };
    let (depth, through) = count(20e-9);
    assert!(depth > 2.0 * 20e-9 && through > 0);
    let (depth, through) = count(2e-6);
    assert!(depth < 2e-6 && through == 0);
}

/// Table 1(a) Fe on `n`² cells of `spacing_um`, coupling off, under the
/// imposed shifts `shifts` (10 increments per segment), the substrate
/// wearing with Archard's `k` and the ball with `k_ball`.
fn both_wear(
    n: usize,
    spacing_um: f64,
    shifts: Vec<f64>,
    k: f64,
    k_ball: f64,
) -> solver::CaseOutput {
    let mut spec = common::table_1a_fe(n, spacing_um, false, 0.0);
    spec.history = Some(LoadHistory {
        tangential_ratios: Vec::new(),
        normal_forces_n: None,
        increments: solver::Increments::Fixed(10),
        sampling: Default::default(),
        shifts_m: Some(shifts),
        wear: Some(Wear {
            law: WearLaw::Archard { k },
            ball: Some(WearLaw::Archard { k: k_ball }),
            jump: 1.0,
        }),
    });
    solve_case(&spec, &mut KernelCache::new()).expect("the path solves")
}

#[test]
fn the_ball_wears_by_its_own_coefficient_in_its_own_frame() {
    // Gross slip at Δ = 3δ*, the ball with half the substrate's k: every
    // cell's ball wear is half the substrate's, and the ball's frame keeps
    // the volume as it moves, so its volume is half the substrate's.
    let k = 1e-20;
    let a3 = 3.0 * delta_star();
    let out = both_wear(128, 2.0, vec![0.0, a3, -a3, a3], k, 0.5 * k);
    let h = out.scalars.history.expect("a path");
    let (sub, ball) = (
        h.worn_volume_m3.expect("worn"),
        h.ball_worn_volume_m3.expect("the ball wore"),
    );
    let field: f64 = out.fields.ball_wear.iter().sum::<f64>() * 4e-12;
    println!("substrate {sub:.9e} m³, ball {ball:.9e} m³ (field {field:.9e})");
    assert!((ball / (0.5 * sub) - 1.0).abs() < 1e-12);
    assert!((field / ball - 1.0).abs() < 1e-12);
    let last = h.wear_cycles.last().expect("a cycle");
    assert_eq!(last.ball_worn_volume_m3, ball);

    // Gross slip at Δ = 20 µm (7 cells of 3 µm) with one body wearing at a
    // time: the same volume either way (k P times the sliding distance),
    // but the substrate's scar spans the contact's travel, 2(a + Δ), and
    // the ball's, which moves with its contact, only the contact, 2a.
    let d = 20e-6;
    let path = vec![0.0, d, -d, d];
    let substrate = both_wear(128, 3.0, path.clone(), k, 0.0);
    let on_ball = both_wear(128, 3.0, path, 0.0, k);
    let hs = substrate.scalars.history.expect("a path");
    let hb = on_ball.scalars.history.expect("a path");
    let (vs, vb) = (
        hs.worn_volume_m3.expect("worn"),
        hb.ball_worn_volume_m3.expect("worn"),
    );
    let extent = |w: &[f64]| {
        let max = w.iter().cloned().fold(0.0, f64::max);
        let cols: Vec<usize> = (0..w.len())
            .filter(|&i| w[i] > 0.01 * max)
            .map(|i| i % 128)
            .collect();
        let (lo, hi) = (cols.iter().min().unwrap(), cols.iter().max().unwrap());
        (hi - lo + 1) as f64 * 3e-6
    };
    let (es, eb) = (
        extent(&substrate.fields.wear),
        extent(&on_ball.fields.ball_wear),
    );
    let a = out.scalars.contact_radius_m;
    println!(
        "Δ = 20 µm: volumes substrate {vs:.6e}, ball {vb:.6e} m³; scar along x: substrate {:.1} µm (2(a + Δ) = {:.1}), ball {:.1} µm (2a = {:.1})",
        es * 1e6,
        2e6 * (a + d),
        eb * 1e6,
        2e6 * a
    );
    assert!((vb / vs - 1.0).abs() < 0.01);
    assert!((es - 2.0 * (a + d)).abs() < 4.0 * 3e-6);
    assert!((eb - 2.0 * a).abs() < 4.0 * 3e-6);
    assert!(((es - eb) - 2.0 * d).abs() < 3.0 * 3e-6);
    assert!(substrate.fields.ball_wear.iter().all(|&v| v == 0.0));
    assert!(on_ball.fields.wear.iter().all(|&v| v == 0.0));
}
