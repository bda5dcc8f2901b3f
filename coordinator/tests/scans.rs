//! Measured surfaces (issue #61) through the config, as a user gives them:
//! the paper's circle-A and square-B patterns written as `.x3p` scans at
//! 4x finer pixels, read back and resampled, give μa against the force
//! angle within 0.5 % of the analytic patterns on the same grid
//! (`sampling = "area"`), and a tilted copy the same after plane
//! levelling; a ladder resamples each level; bad scans are refused naming
//! the file and what is wrong.

use coordinator::config::Config;
use coordinator::scan_file::x3p::{self, DataType};
use solver::{solve_case, Grid, KernelCache, Scan, Surface};

/// The paper's Table 1(c) load (`tests/configs/table1c-coarse.toml`) at
/// F = 0.6 μP, coupled, on 96 cells of 80 µm: the 7.68 mm of its 384 cells
/// of 20 µm (the contact stays inside); the surfaces' list is `SURFACES`.
fn config_text() -> String {
    let base = include_str!("../../tests/configs/table1c-coarse.toml")
        .replace("points = 32", "points = 96")
        .replace("spacing_um = 200.0", "spacing_um = 80.0")
        .replace("tangential_ratio = 0.3", "tangential_ratio = 0.6");
    assert!(base.contains("points = 96") && base.contains("tangential_ratio = 0.6"));
    base + "\n[sweep]\nmaterials = [\"Cu\"]\nsurfaces = [\"SURFACES\"]\nangles_deg = [0.0, 30.0, 45.0, 90.0]\n\n[solver]\ncoupling = true\n"
}

/// `pattern` (a preset) measured at the centres of `4 n` pixels of a
/// quarter cell each way, plus the tilt `slope` (x, y), as a scan.
fn measured(pattern: &str, cells: usize, cell: f64, slope: [f64; 2]) -> Scan {
    let mut surface = solver::presets::surface(pattern).unwrap();
    if let Surface::Lattice { sampling, .. } = &mut surface {
        *sampling = solver::Sampling::Centre;
    }
    let pixels = Grid::square(4 * cells, 0.25 * cell);
    let mut h = surface.heights(&pixels);
    for (i, v) in h.iter_mut().enumerate() {
        let (x, y) = (pixels.x(i % pixels.n), pixels.y(i / pixels.n));
        *v += slope[0] * x + slope[1] * y;
    }
    Scan::new(pixels.n, pixels.n, pixels.dx, pixels.dy, h).unwrap()
}

/// μa of every case of `config`, by (surface, angle).
fn mu_a(config: &Config) -> Vec<(String, f64, f64)> {
    let mut cache = KernelCache::new();
    config
        .cases()
        .unwrap()
        .into_iter()
        .map(|(key, spec)| {
            let out = solve_case(&spec, &mut cache).unwrap();
            (
                key.surface.clone(),
                key.angle_deg,
                out.scalars.mu_a.unwrap(),
            )
        })
        .collect()
}

/// μa of circle-A and square-B measured at 4 x 4 pixels a cell (as read
/// back, and tilted then plane-levelled, both `sampling = "area"`; and
/// with the cells' mean) against the analytic patterns on `cells` cells
/// of `cell` at `angles`: the largest relative difference of the first two.
fn measured_patterns_against_analytic(cells: usize, cell: f64, angles: &[f64]) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let mut tables = String::new();
    for pattern in ["circle-A", "square-B"] {
        let flat = measured(pattern, cells, cell, [0.0, 0.0]);
        let tilted = measured(pattern, cells, cell, [2e-3, -1e-3]);
        x3p::write(
            &dir.path().join(format!("{pattern}.x3p")),
            &flat,
            DataType::D,
        )
        .unwrap();
        x3p::write(
            &dir.path().join(format!("{pattern}-tilted.x3p")),
            &tilted,
            DataType::D,
        )
        .unwrap();
        tables += &format!(
            "\n[surfaces.{pattern}-scan]\nshape = \"scan\"\nfile = \"{pattern}.x3p\"\nlevelling = \"none\"\nsampling = \"area\"\n\n[surfaces.{pattern}-tilted]\nshape = \"scan\"\nfile = \"{pattern}-tilted.x3p\"\nlevelling = \"plane\"\nsampling = \"area\"\n\n[surfaces.{pattern}-mean]\nshape = \"scan\"\nfile = \"{pattern}.x3p\"\nlevelling = \"none\"\n"
        );
    }
    let names = [
        "circle-A",
        "circle-A-scan",
        "circle-A-tilted",
        "circle-A-mean",
        "square-B",
        "square-B-scan",
        "square-B-tilted",
        "square-B-mean",
    ];
    let angle_list: Vec<String> = angles.iter().map(|a| format!("{a:?}")).collect();
    let text = config_text()
        .replace("SURFACES", &names.join("\", \""))
        .replace("points = 96", &format!("points = {cells}"))
        .replace(
            "spacing_um = 80.0",
            &format!("spacing_um = {:?}", cell * 1e6),
        )
        .replace(
            "angles_deg = [0.0, 30.0, 45.0, 90.0]",
            &format!("angles_deg = [{}]", angle_list.join(", ")),
        )
        + &tables;
    let c = Config::parse_in(&text, &[], dir.path()).unwrap();
    let mu = mu_a(&c);
    let of = |s: &str, a: f64| {
        mu.iter()
            .find(|(n, angle, _)| n == s && *angle == a)
            .unwrap()
            .2
    };
    let mut worst: f64 = 0.0;
    for pattern in ["circle-A", "square-B"] {
        for &a in angles {
            let analytic = of(pattern, a);
            for scan in ["scan", "tilted", "mean"] {
                let measured = of(&format!("{pattern}-{scan}"), a);
                let rel = measured / analytic - 1.0;
                println!(
                    "{pattern} ψ = {a}°: μa analytic {analytic:.5}, {scan} {measured:.5} ({:+.3} %)",
                    100.0 * rel
                );
                if scan != "mean" {
                    worst = worst.max(rel.abs());
                }
            }
        }
    }
    println!(
        "{cells}² cells of {} µm: largest |difference| {:.3} %",
        cell * 1e6,
        100.0 * worst
    );
    worst
}

/// The coarse grid of CI. The cells' mean of the same pixels
/// (`sampling = "mean"`, the default) smears each cut cell's edge into an
/// intermediate height: a different, coarser surface, printed for the
/// record (docs/validation.md).
#[test]
fn issue61_patterns_measured_at_4x_finer_pixels_give_mu_a_within_half_a_percent() {
    let worst = measured_patterns_against_analytic(96, 80e-6, &[0.0, 30.0, 45.0, 90.0]);
    assert!(worst < 0.005, "{worst}");
}

/// The paper's grid, 384² cells of 20 µm (1536² pixels of 5 µm), every
/// 15°: minutes, so run by hand (`-- --ignored`; docs/validation.md).
#[test]
#[ignore]
fn issue61_patterns_measured_at_4x_finer_pixels_full_size() {
    let angles: Vec<f64> = (0..=6).map(|k| 15.0 * k as f64).collect();
    let worst = measured_patterns_against_analytic(384, 20e-6, &angles);
    assert!(worst < 0.005, "{worst}");
}

#[test]
fn issue61_a_ladder_resamples_the_scan_on_each_level_and_check_reports_it() {
    let dir = tempfile::tempdir().unwrap();
    let scan = measured("circle-B", 96, 80e-6, [0.0, 0.0]);
    x3p::write(&dir.path().join("b.x3p"), &scan, DataType::F).unwrap();
    let tables = "\n[surfaces.b]\nshape = \"scan\"\nfile = \"b.x3p\"\n";
    let text = config_text().replace("SURFACES", "b") + tables;
    let c = Config::parse_in(&text, &["convergence.levels=2".into()], dir.path()).unwrap();
    let cases = c.cases().unwrap();
    let grids: Vec<(usize, usize)> = cases
        .iter()
        .map(|(_, spec)| match &spec.surface {
            Surface::Resampled { n, .. } => (*n, spec.grid.n),
            other => panic!("{other:?}"),
        })
        .collect();
    assert!(grids.iter().all(|(a, b)| a == b), "{grids:?}");
    assert!(grids.iter().any(|g| g.0 == 96) && grids.iter().any(|g| g.0 > 96));
    // The levels share one resampled surface each.
    let report = coordinator::dry_run::report(&c, 1).unwrap();
    println!("{report}");
    assert!(
        report.contains("b.x3p, 384 x 384 pixels of 20 x 20 µm")
            && report.contains("levelling plane")
            && report.contains("on cells of 80 x 80 µm (mean): Sa"),
        "{report}"
    );
    let r = c.scan_report("b", 0).unwrap().unwrap();
    // The heights are 30 µm on 30.7 % of the surface: the mean levels to
    // zero and Sq of a two-level surface is h sqrt(f (1 - f)).
    let f = solver::presets::surface("circle-B").unwrap().density();
    let sq = 30.0 * (f * (1.0 - f)).sqrt();
    println!("Sq {} µm, two-level {sq} µm", r.scan.sq_um);
    assert!((r.scan.sq_um / sq - 1.0).abs() < 0.02, "{}", r.scan.sq_um);
    assert!((r.scan.sz_um - 30.0).abs() < 1e-4, "{}", r.scan.sz_um);
}

#[test]
fn issue61_bad_scans_name_the_file_and_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let err = |tables: &str| {
        let text = config_text().replace("SURFACES", "s") + tables;
        format!(
            "{:#}",
            Config::parse_in(&text, &[], dir.path()).unwrap_err()
        )
    };
    // Smaller than the grid: both extents.
    let small = Scan::new(100, 80, 20e-6, 20e-6, vec![0.0; 8000]).unwrap();
    x3p::write(&dir.path().join("small.x3p"), &small, DataType::D).unwrap();
    let e = err("[surfaces.s]\nshape = \"scan\"\nfile = \"small.x3p\"\n");
    println!("{e}");
    assert!(
        e.contains("small.x3p")
            && e.contains(
                "the scan is 2000.0000 x 1600.0000 µm but the grid spans 7680.0000 x 7680.0000 µm"
            ),
        "{e}"
    );
    // Missing points refused with their count, filled on request.
    let mut h = vec![0.0; 400 * 400];
    h[1234] = f64::NAN;
    h[1235] = f64::NAN;
    let holes = Scan::new(400, 400, 20e-6, 20e-6, h).unwrap();
    x3p::write(&dir.path().join("holes.x3p"), &holes, DataType::F).unwrap();
    let e = err("[surfaces.s]\nshape = \"scan\"\nfile = \"holes.x3p\"\n");
    assert!(
        e.contains("surfaces.s.missing")
            && e.contains("holes.x3p")
            && e.contains("2 missing points of 160000"),
        "{e}"
    );
    let text = config_text().replace("SURFACES", "s")
        + "[surfaces.s]\nshape = \"scan\"\nfile = \"holes.x3p\"\nmissing = \"fill\"\n";
    Config::parse_in(&text, &[], dir.path()).unwrap();
    // An unknown format, listing what is read.
    std::fs::write(dir.path().join("scan.plu"), b"whatever").unwrap();
    let e = err("[surfaces.s]\nshape = \"scan\"\nfile = \"scan.plu\"\n");
    assert!(
        e.contains("scan.plu")
            && e.contains("unknown scan format `.plu`")
            && e.contains(".x3p")
            && e.contains("mpcontact.convert"),
        "{e}"
    );
    // A truncated file.
    let bytes = std::fs::read(dir.path().join("holes.x3p")).unwrap();
    std::fs::write(dir.path().join("cut.x3p"), &bytes[..bytes.len() - 100]).unwrap();
    let e = err("[surfaces.s]\nshape = \"scan\"\nfile = \"cut.x3p\"\n");
    assert!(
        e.contains("cut.x3p") && e.contains("corrupt or truncated"),
        "{e}"
    );
    // A 1-D profile in an .npy.
    coordinator::output::npy::write_npy_2d(&dir.path().join("line.npy"), 1, 500, &[0.0; 500])
        .unwrap();
    let e = err("[surfaces.s]\nshape = \"scan\"\nfile = \"line.npy\"\npixel_um = 20.0\n");
    assert!(e.contains("line.npy") && e.contains("1-D profile"), "{e}");
    // An .npy without its pixel size.
    let e = err("[surfaces.s]\nshape = \"scan\"\nfile = \"line.npy\"\n");
    assert!(e.contains("pixel_um"), "{e}");
}

/// A scan's cases are height-map cases: resampled once per surface and
/// grid by the config, a `sampling = "mean"` scan solves to the same bits
/// as a height map of the same heights (the same work, so the same cost
/// in a sweep; docs/performance.md).
#[test]
fn issue61_a_scan_case_is_a_height_map_case() {
    let dir = tempfile::tempdir().unwrap();
    let scan = measured("circle-B", 64, 120e-6, [0.0, 0.0]);
    x3p::write(&dir.path().join("b.x3p"), &scan, DataType::D).unwrap();
    let text = config_text()
        .replace("SURFACES", "b")
        .replace("points = 96", "points = 64")
        .replace("spacing_um = 80.0", "spacing_um = 120.0")
        + "\n[surfaces.b]\nshape = \"scan\"\nfile = \"b.x3p\"\nlevelling = \"none\"\n";
    let c = Config::parse_in(&text, &[], dir.path()).unwrap();
    let (_, spec) = c.cases().unwrap().remove(0);
    let Surface::Resampled {
        n,
        heights,
        cover: None,
    } = &spec.surface
    else {
        panic!("{:?}", spec.surface)
    };
    let map = solver::CaseSpec {
        surface: Surface::Heightmap {
            n: *n,
            heights: heights.clone(),
        },
        ..spec.clone()
    };
    let mut cache = KernelCache::new();
    let a = solve_case(&spec, &mut cache).unwrap().scalars;
    let b = solve_case(&map, &mut cache).unwrap().scalars;
    let strip = |s: &solver::CaseScalars| {
        let mut v = serde_json::to_value(s).unwrap();
        for k in ["seconds", "kernel_seconds"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    assert_eq!(strip(&a), strip(&b));
    println!(
        "scan and height map: μa {:?}, {} normal iterations each",
        a.mu_a, a.normal.iterations
    );
}
