//! #47: a pattern far finer than the grid. A circle lattice a million
//! times finer than the cells (10¹² islands per cell) once made `solve`
//! walk every island; its cover now costs a handful of sites per cell, the
//! case is solved on the pattern's exact mean cover, and `solve` and
//! `check` say that the grid does not resolve the islands.

use mpcontact_e2e::run;

/// 128² cells of 60 µm (the quick sweep's grid) under a circle lattice of
/// pitch 6e-5 µm: 10⁻⁶ cells per pitch.
const FINE: &str = concat!(
    r#"
[grid]
points = 128
spacing_um = 60.0

[indenter]
radius_mm = 200.0

[load]
normal_n = 6000.0
friction = 0.3
tangential_ratio = 0.6

"#,
    include_str!("../configs/fine-circles.toml"),
    r#"
[sweep]
materials = ["Cu"]
surfaces = ["fine"]
angles_deg = [0.0, 45.0]
"#
);

const WARNING: &str =
    "surface `fine`: pitch 6.000e-5 µm is 1.000e-6 cells of 60 µm, below 2 cells per pitch";

#[test]
fn issue47_a_pattern_a_million_times_finer_than_the_grid_is_solved_with_a_warning() {
    let tmp_dir = tempfile::Builder::new()
        .prefix("mpcontact-fine-")
        .tempdir()
        .unwrap();
    let dir = tmp_dir.path();
    let config = dir.join("fine.toml");
    std::fs::write(&config, FINE).unwrap();
    let out = run(&[
        "solve",
        config.to_str().unwrap(),
        "--out",
        dir.join("o").to_str().unwrap(),
        "--quiet",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    println!("{stderr}");
    assert!(
        stderr.contains(&format!("warning: {WARNING}")) && stderr.contains("0.283 on average"),
        "{stderr}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("o/case.json")).unwrap()).unwrap();
    assert_eq!(json["converged"], true, "{json}");
    // Every cell carries the islands' mean cover π/4 · 0.6² (to 1e-6 of
    // it: a part period per cell), so the area in contact is that share of
    // the cells in contact.
    let p = read_npy_f64(&dir.join("o/p.npy"));
    let touching = p.iter().filter(|&&v| v > 0.0).count() as f64;
    let area = json["contact_area_m2"].as_f64().unwrap();
    let share = area / (touching * 60e-6 * 60e-6);
    let density = std::f64::consts::PI / 4.0 * 0.36;
    println!("contact area / cells in contact = {share:.12} (density {density:.12})");
    assert!(
        touching > 1000.0 && (share / density - 1.0).abs() < 1e-9,
        "{share}"
    );

    let out = run(&["check", config.to_str().unwrap(), "--workers", "1"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains(&format!("warning:   {WARNING}")),
        "{stdout}"
    );
}

/// The values of a little-endian float64 `.npy` file (the fields `solve`
/// writes), in file order.
fn read_npy_f64(path: &std::path::Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY", "{}", path.display());
    let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let text = String::from_utf8_lossy(&bytes[10..10 + header]);
    assert!(text.contains("'<f8'"), "{text}");
    bytes[10 + header..]
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect()
}
