//! What a normal solve costs, elastic and capped (issue #62 folded the
//! elastic Polonsky–Keer iteration and #50's capped CG into one): the
//! iterations and operator applications of the normal solves of the
//! paper's Table 1(c) surfaces on Cu (R = 200 mm, P = 6 kN), elastic and
//! with H = 0.9 and 0.5 GPa, from rest (the nested start a case begins
//! with) and warm (a coupling pass's kind: the last pressure with the
//! extra gap of a tangential displacement); and the normal iterations of
//! whole cases whose normal solves are mostly warm: a fretting history on
//! Table 1(a) Fe (coupled, 2 cycles of ±0.6 μP) and a coupled case of
//! Table 1(c). Prints markdown tables and the sums; the iteration counts
//! do not depend on the thread count.
//!
//! `cargo run --release -p mpcontact-solver --example normal_cost -- 256 60`
//! (grid points, cell size in µm; default 256 of 60 µm, a 15.4 mm domain
//! that holds the softer contacts)

use solver::normal::NormalProblem;
use solver::{presets, solve_case, CaseSpec, Grid, KernelCache, Load, LoadHistory, Numerics};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args
        .first()
        .map_or(256, |a| a.parse().expect("grid points"));
    let spacing_um: f64 = args.get(1).map_or(60.0, |a| a.parse().expect("µm"));
    let mut cache = KernelCache::new();
    println!("| surface | H (GPa) | from rest: its / applications (coarse its) | warm: its / applications |");
    println!("|---|---|---|---|");
    let mut sums = [0usize; 4];
    for surface in ["flat", "circle-A", "circle-B", "square-A", "square-B"] {
        for hardness_gpa in [None, Some(0.9), Some(0.5)] {
            let mut material = presets::material("Cu").expect("preset");
            material.limits.hardness = hardness_gpa.map(|h| h * 1e9);
            let spec = CaseSpec {
                material,
                surface: presets::surface(surface).expect("preset"),
                grid: Grid::square(n, spacing_um * 1e-6),
                load: Load {
                    indenter_radius_m: 0.2,
                    normal_force_n: 6000.0,
                    friction: 0.3,
                    tangential_ratio: 0.6,
                    angle_deg: 0.0,
                },
                numerics: Numerics::default(),
                history: None,
                indenter: None,
            };
            let (res, _) = cache.resident(&spec).expect("kernel");
            let terrain = spec.surface.terrain(&spec.grid);
            res.operator.set_cover(terrain.cover.as_deref());
            let h0 = spec.initial_gap_on(&terrain.heights);
            let problem = NormalProblem {
                tolerance: spec.numerics.tolerance,
                max_iterations: spec.numerics.max_iterations,
                hardness: spec.limits().hardness,
                ..NormalProblem::new(&h0, spec.load.normal_force_n)
            };
            let rest = res.solve_normal(&problem).expect("from rest");
            // The extra gap of a tangential traction along x: odd in x,
            // 2 % of the approach at the contact's edge (uz(q) of Table
            // 1(c)'s coupled cases is of that order).
            let grid = spec.grid;
            let a = (0..grid.len())
                .filter(|&i| rest.p[i] > 0.0)
                .map(|i| grid.x(i % n).hypot(grid.y(i / n)))
                .fold(0.0, f64::max);
            let extra: Vec<f64> = (0..grid.len())
                .map(|i| {
                    let (x, y) = (grid.x(i % n), grid.y(i / n));
                    0.02 * rest.approach * (x / a) * (-(x * x + y * y) / (a * a)).exp()
                })
                .collect();
            let warm = res
                .solve_normal(&NormalProblem {
                    p_init: Some(&rest.p),
                    extra_gap: Some(&extra),
                    ..problem
                })
                .expect("warm");
            let (r, w) = (rest.report, warm.report);
            assert!(r.converged && w.converged, "{surface} {hardness_gpa:?}");
            let h = hardness_gpa.map_or("elastic".to_string(), |h| h.to_string());
            println!(
                "| {surface} | {h} | {} / {} ({}) | {} / {} |",
                r.iterations, r.applications, r.coarse_iterations, w.iterations, w.applications
            );
            for (s, v) in
                sums.iter_mut()
                    .zip([r.iterations, r.applications, w.iterations, w.applications])
            {
                *s += v;
            }
        }
    }
    println!(
        "| sum | | {} / {} | {} / {} |",
        sums[0], sums[1], sums[2], sums[3]
    );
    println!("\n| case | normal / tangential / coupling iterations |\n|---|---|");
    // Table 1(a) Fe fretted (configs/fretting-fe.toml on n² cells of the
    // same 256 µm domain, 10 increments a segment).
    let mut fe = CaseSpec {
        material: presets::material("Fe").expect("preset"),
        surface: presets::surface("flat").expect("preset"),
        grid: Grid::square(n, 256e-6 / n as f64),
        load: Load {
            indenter_radius_m: 0.018,
            normal_force_n: 20.0,
            friction: 0.28571,
            tangential_ratio: 0.6,
            angle_deg: 0.0,
        },
        numerics: Numerics::default(),
        history: None,
        indenter: None,
    };
    let out = solve_case(&fe, &mut cache).expect("Table 1(a)");
    let row = |name: &str, s: &solver::CaseScalars| {
        println!(
            "| {name} | {} / {} / {} |",
            s.normal_iterations, s.tangential_iterations, s.coupling_iterations
        )
    };
    row("Table 1(a) Fe", &out.scalars);
    fe.history = Some(LoadHistory {
        tangential_ratios: vec![0.0, 0.6, -0.6, 0.6, -0.6, 0.6],
        normal_forces_n: None,
        increments: solver::Increments::Fixed(10),
        sampling: Default::default(),
        shifts_m: None,
        wear: None,
    });
    let out = solve_case(&fe, &mut cache).expect("fretting");
    row("Table 1(a) Fe fretted", &out.scalars);
}
