//! End-to-end tests of the `mpcontact` binary's single-process commands:
//! `solve` outputs and its progress line, clear errors for bad input (never
//! a panic), `kernel` JSON.

use mpcontact_e2e::{exe, run};
use std::process::Command;

fn temp_dir(name: &str) -> tempfile::TempDir {
    // Removed when dropped: the tests leave nothing in the system temp dir.
    tempfile::Builder::new()
        .prefix(&format!("mpcontact-cli-{name}-"))
        .tempdir()
        .unwrap()
}

const SMALL: &str = concat!(
    "[grid]\npoints = 64\nspacing_um = 4.0\n\n",
    include_str!("../configs/table1a-fe.toml")
);

#[test]
fn solve_writes_case_json_nine_npy_fields_and_five_maps() {
    let tmp_dir = temp_dir("solve");
    let dir = tmp_dir.path().to_path_buf();
    std::fs::write(dir.join("c.toml"), SMALL).unwrap();
    let out = run(&[
        "solve",
        dir.join("c.toml").to_str().unwrap(),
        "--out",
        dir.join("o").to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("o/case.json")).unwrap()).unwrap();
    for key in [
        "contact_radius_m",
        "stick_radius_m",
        "delta_t_m",
        "delta_z_m",
        "p_max_pa",
        "contact_area_m2",
        "stick_area_m2",
        "mu_a",
        "converged",
        "normal_iterations",
        "tangential_iterations",
        "coupling_iterations",
    ] {
        assert!(json.get(key).is_some(), "case.json lacks {key}");
    }
    assert_eq!(json["angle_deg"], 30.0);
    // Equilibrium as written: the tangential force points at 30°.
    let f = json["tangential_force_n"].as_array().unwrap();
    let (fx, fy) = (f[0].as_f64().unwrap(), f[1].as_f64().unwrap());
    assert!((fy.atan2(fx).to_degrees() - 30.0).abs() < 1e-6);
    for name in ["p", "qx", "qy", "sx", "sy", "stick", "ux", "uy", "uz"] {
        let bytes = std::fs::read(dir.join(format!("o/{name}.npy"))).unwrap();
        let header = String::from_utf8_lossy(&bytes[..128.min(bytes.len())]).to_string();
        assert!(
            header.contains("(64, 64") && header.contains("<f8"),
            "{name}: {header}"
        );
        assert!(bytes.len() >= 64 * 64 * 8);
    }
    for name in ["p", "qx", "qy", "slip", "stick"] {
        let bytes = std::fs::read(dir.join(format!("o/{name}.png"))).unwrap();
        assert_eq!(&bytes[1..4], b"PNG", "{name}.png is a PNG");
    }
}

/// Words only the progress line of `solve` prints (stage, increment, pass).
const PROGRESS_WORDS: [&str; 4] = ["iteration", "increment", "pass ", "building the kernel"];

/// A short fretting history (3 segments of 5 increments at 64², about a
/// second): long enough for the progress line to be drawn several times.
fn fretting_small() -> String {
    format!(
        "{SMALL}\n[history]\nfretting = {{ amplitude_ratio = 0.6, cycles = 1 }}\nsteps_per_segment = 5\n"
    )
}

#[test]
fn issue33_item2_solve_shows_progress_only_on_a_terminal_and_not_with_quiet() {
    let tmp_dir = temp_dir("progress");
    let dir = tmp_dir.path().to_path_buf();
    let config = dir.join("c.toml");
    std::fs::write(&config, fretting_small()).unwrap();
    let solve = |out: &str, quiet: bool| -> Vec<String> {
        let mut args = vec![
            "solve".to_string(),
            config.display().to_string(),
            "--out".into(),
            dir.join(out).display().to_string(),
        ];
        if quiet {
            args.push("--quiet".into());
        }
        args
    };

    // stderr a pipe (a log, a batch job): no progress, not even with the
    // line cleared; the result line on stdout as always.
    for (out, quiet) in [("pipe", false), ("pipe-quiet", true)] {
        let o = Command::new(exe())
            .args(solve(out, quiet))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(
            !PROGRESS_WORDS.iter().any(|w| err.contains(w)) && !err.contains('\r'),
            "progress on a pipe (quiet = {quiet}): {err:?}"
        );
        assert!(String::from_utf8_lossy(&o.stdout).starts_with("a = "));
    }

    // On a terminal (a pseudo-terminal from util-linux `script`): the line
    // shows the increments and iterations, and `--quiet` silences it.
    let has_script = Command::new("script")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_script {
        eprintln!("no `script` (util-linux) to run solve on a terminal: that half is not checked");
        return;
    }
    let on_terminal = |args: Vec<String>| -> String {
        let line = std::iter::once(exe().display().to_string())
            .chain(args)
            .map(|a| format!("'{a}'"))
            .collect::<Vec<_>>()
            .join(" ");
        let o = Command::new("script")
            .args(["-q", "-e", "-c", &line, "/dev/null"])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(o.status.success(), "{text}");
        text
    };
    let shown = on_terminal(solve("tty", false));
    for w in ["segment ", "/3", "pass ", "iteration "] {
        assert!(shown.contains(w), "no `{w}` in the progress: {shown:?}");
    }
    let quiet = on_terminal(solve("tty-quiet", true));
    assert!(
        !PROGRESS_WORDS.iter().any(|w| quiet.contains(w)),
        "--quiet on a terminal: {quiet:?}"
    );
    assert!(quiet.contains("a = "), "{quiet:?}");
    // Progress changes no number: the same case.json with and without it
    // (but for the timings).
    let scalars = |out: &str| {
        let mut v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(out).join("case.json")).unwrap(),
        )
        .unwrap();
        for k in ["seconds", "kernel_seconds"] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    assert_eq!(scalars("tty"), scalars("pipe"));
    assert_eq!(scalars("tty-quiet"), scalars("pipe"));
}

fn expect_error(config: &str, sets: &[&str], needle: &str) {
    let tmp_dir = temp_dir(&format!("bad{}", needle.len()));
    let dir = tmp_dir.path().to_path_buf();
    std::fs::write(dir.join("c.toml"), config).unwrap();
    let mut args = vec![
        "solve".to_string(),
        dir.join("c.toml").display().to_string(),
        "--out".into(),
        dir.join("o").display().to_string(),
    ];
    for s in sets {
        args.push("--set".into());
        args.push(s.to_string());
    }
    let out = Command::new(exe()).args(&args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{sets:?}: {err}");
    assert!(
        err.contains(needle),
        "{sets:?}: expected `{needle}` in: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn bad_input_is_a_clear_error_not_a_panic() {
    expect_error(SMALL, &["load.tangential_ratio=1.2"], "gross sliding");
    expect_error(SMALL, &["load.normal_n=0"], "load.normal_n");
    expect_error(SMALL, &["grid.spacing_um=-1"], "grid.spacing_um");
    expect_error(SMALL, &["load.friction=nan"], "load.friction");
    // 64 cells of 0.5 µm cannot hold a 105 µm contact.
    expect_error(SMALL, &["grid.spacing_um=0.5"], "edge of the domain");
    expect_error(
        &SMALL.replace("friction = 0.28571", "friction = 0.28571\nfrction = 1"),
        &[],
        "frction",
    );
}

/// Issue #59 items 1 and 12: `solve` on a hardness the domain cannot
/// carry (H = 0.01 GPa, or 1e-300: P/H is hundreds of times the domain's
/// area) gave `not_converged` and exit 0, or blamed friction under a
/// tangential load; `hardness_gpa = 1e300` read "got inf Pa". Each is now
/// an error naming the key, with what was written.
#[test]
fn issue59_a_hardness_the_domain_cannot_carry_or_beyond_any_surface_names_its_key() {
    for h in ["0.01", "1e-300"] {
        for ratio in ["0.6", "0.0"] {
            expect_error(
                SMALL,
                &[
                    &format!("materials.Fe.hardness_gpa={h}"),
                    &format!("load.tangential_ratio={ratio}"),
                ],
                "invalid materials.Fe.hardness_gpa: the hardness",
            );
        }
    }
    expect_error(
        SMALL,
        &["materials.Fe.hardness_gpa=1e300"],
        "materials.Fe.hardness_gpa = 1e300: must be positive",
    );
}

/// Issue #59 item 12: `solve` on a case that did not converge wrote
/// `not_converged` into case.json and said nothing, exit 0. Now stderr says
/// so and the exit status is 4 (`coordinator::case::EXIT_NOT_ALL_OK`),
/// the outputs written.
#[test]
fn issue59_item12_solve_of_a_case_that_does_not_converge_says_so_and_exits_4() {
    let tmp_dir = temp_dir("unconverged");
    let dir = tmp_dir.path().to_path_buf();
    std::fs::write(dir.join("c.toml"), SMALL).unwrap();
    let out = run(&[
        "solve",
        dir.join("c.toml").to_str().unwrap(),
        "--set",
        "solver.max_iterations=2",
        "--quiet",
        "--out",
        dir.join("o").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(4), "{err}");
    assert!(err.contains("did not converge"), "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("o/case.json")).unwrap()).unwrap();
    assert_eq!(json["status"], "not_converged");
    assert_eq!(json["converged"], false);
}

#[test]
fn kernel_prints_h_theta_matching_the_isotropic_closed_form() {
    let out = run(&["kernel", "--material", "Cu", "--angles-deg", "0:90:45"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v.as_array().unwrap();
    assert_eq!(rows.len(), 3);
    let (e, nu) = (128.73e9, 0.345);
    let g = e / (2.0 * (1.0 + nu));
    for row in rows {
        let th = row["theta_deg"].as_f64().unwrap().to_radians();
        let h33 = row["H_re"][2][2].as_f64().unwrap();
        let h13_im = row["H_im"][0][2].as_f64().unwrap();
        assert!((h33 * g / (1.0 - nu) - 1.0).abs() < 1e-9);
        let want = -(1.0 - 2.0 * nu) * th.cos() / (2.0 * g);
        assert!((h13_im - want).abs() < 1e-9 * (1.0 / g));
    }
}

#[test]
fn materials_lists_the_six_presets() {
    let out = run(&["materials"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for m in ["Fe ", "Cu ", "Ni ", "Fe(111)", "Cu(111)", "Ni(111)"] {
        assert!(text.contains(m), "{m}");
    }
}

#[test]
fn issue20_item11_out_that_is_a_file_is_named() {
    let tmp_dir = temp_dir("outfile");
    let dir = tmp_dir.path().to_path_buf();
    std::fs::write(dir.join("c.toml"), SMALL).unwrap();
    let file = dir.join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let out = run(&[
        "run",
        &dir.join("c.toml").display().to_string(),
        "--out",
        &file.display().to_string(),
        "--quiet",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&file.display().to_string()) && err.contains("not a directory"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

#[test]
fn dry_run_of_the_paper_sweep_reports_260_cases_and_writes_nothing() {
    let tmp_dir = temp_dir("dry");
    let out_dir = tmp_dir.path().join("never");
    let config = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../configs/paper-1c-sweep.toml"
    );
    let out = run(&[
        "run",
        config,
        "--dry-run",
        "--out",
        &out_dir.display().to_string(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("cases:     260 = 4 materials x 5 surfaces x 13 angles"),
        "{text}"
    );
    assert!(text.contains("kernels:   4") && text.contains("memory:") && text.contains("time:"));
    assert!(!out_dir.exists(), "a dry run wrote {}", out_dir.display());
    // `check` says the same; a bad config fails as `run` would.
    let check = run(&["check", config]);
    assert!(String::from_utf8_lossy(&check.stdout).contains("cases:     260"));
    let bad = run(&["check", config, "--set", "load.normal_n=-1"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("load.normal_n"));
}
