//! A newcomer's first commands (issue #62): `run` and `solve` write by
//! default into folders named after the config, so two configs never share
//! one; `check` (and `run` before it starts) refuses what a solve would
//! refuse in its first moments, with the solve's own message.

use mpcontact_e2e::exe;
use std::path::Path;
use std::process::{Command, Output};

fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("mpcontact-newcomer-{name}-"))
        .tempdir()
        .unwrap()
}

/// Table 1(a) Fe on 64 cells of 4 µm (a = 105 µm spans 26 cells), one angle.
const SMALL: &str = concat!(
    "[grid]\npoints = 64\nspacing_um = 4.0\n\n",
    include_str!("../configs/table1a-fe.toml")
);

/// `mpcontact ARGS` run in `dir`.
fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(exe())
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn issue62_default_outputs_are_named_after_the_config_and_never_collide() {
    let tmp = temp_dir("defaults");
    let dir = tmp.path();
    std::fs::write(dir.join("first.toml"), SMALL).unwrap();
    std::fs::write(dir.join("second.toml"), SMALL).unwrap();
    // Two configs' sweeps, one after the other, no --out: each its folder
    // (before #62 the second was refused: `out already holds a sweep`).
    for name in ["first.toml", "second.toml"] {
        let o = run_in(dir, &["run", name, "--workers", "1", "--quiet"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
    for stem in ["first", "second"] {
        assert!(
            dir.join("out").join(stem).join("results.csv").is_file(),
            "{stem}"
        );
    }
    // `check` names the folder `run` would use and what it holds.
    let o = run_in(dir, &["check", "first.toml"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("output:    out/first holds a sweep"),
        "{text}{}",
        stderr(&o)
    );
    // The same config again is its own sweep: refused without --resume,
    // naming the folder; with it, nothing is solved again.
    let o = run_in(dir, &["run", "first.toml", "--workers", "1", "--quiet"]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("out/first already holds a sweep") && e.contains("use --resume"),
        "{e}"
    );
    let o = run_in(
        dir,
        &["run", "first.toml", "--workers", "1", "--quiet", "--resume"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // A shard has its own folder inside the config's.
    let o = run_in(
        dir,
        &[
            "run",
            "first.toml",
            "--workers",
            "1",
            "--quiet",
            "--shard",
            "0/2",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("out/first/shard-0/shard.json").is_file());
    // A solve writes beside the sweeps, never into one.
    let o = run_in(dir, &["solve", "first.toml"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("out-solve/first/case.json").is_file());
    assert!(!dir.join("out/first/case.json").exists());
    // `--out` still chooses the folder.
    let o = run_in(dir, &["solve", "first.toml", "--out", "mine"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("mine/case.json").is_file());
}

/// The case label (`Fe/flat/000.0: ` or `Fe/flat/30°: `) off an error line.
fn message(e: &str) -> String {
    let line = e
        .lines()
        .find(|l| l.starts_with("error: "))
        .unwrap_or_else(|| panic!("no error line in {e}"));
    let (_, rest) = line
        .trim_start_matches("error: ")
        .split_once(": ")
        .unwrap_or_else(|| panic!("no case label in {line}"));
    rest.to_string()
}

/// `configs/fretting-wear.toml --set grid.points=128` (the issue's case): 128
/// cells of 1.25 µm end at 79 µm, inside the 105 µm contact. Before #62
/// `check` called it valid and `solve` then stopped at once; now `check`,
/// `run --dry-run` and `run` refuse it before anything is written, with the
/// solve's message.
#[test]
fn issue62_check_refuses_a_contact_at_the_domain_edge_as_solve_does() {
    let tmp = temp_dir("edge");
    let dir = tmp.path();
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs/fretting-wear.toml");
    let small = ["--set", "grid.points=128"];
    let with = |cmd: &[&str]| -> Vec<String> {
        cmd.iter()
            .chain(&[config])
            .chain(&small)
            .map(|s| s.to_string())
            .collect()
    };
    let solve = Command::new(exe())
        .args(with(&["solve"]))
        .args(["--out", "s"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert_eq!(solve.status.code(), Some(2), "{}", stderr(&solve));
    let want = message(&stderr(&solve));
    assert!(want.contains("edge of the domain"), "{want}");
    for cmd in [&["check"][..], &["run", "--dry-run"], &["run", "--quiet"]] {
        let o = Command::new(exe())
            .args(with(cmd))
            .args(["--out", "o"])
            .current_dir(dir)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{cmd:?}: {e}");
        assert_eq!(message(&e), want, "{cmd:?}");
        assert!(!e.contains("panicked"), "{e}");
    }
    // `run` refused before its journal: the folder can be used at once.
    assert!(!dir.join("o/journal.jsonl").exists());
    // At the config's own 256 cells the contact fits, and `check` says how
    // close it comes: the last cell centre inside Hertz's a = 105.4 µm is
    // at 104.4 µm, of the 159.4 µm to the outermost cells' (65.5 %).
    let o = Command::new(exe())
        .args(["check", config])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        text.contains("none at the domain's edge; the widest, Fe/flat/000.0, reaches 65 %"),
        "{text}"
    );
}

/// Several refused cases: `check` names each with its message, in the
/// sweep's order, and counts them. Table 1(a) at 80 N (a = 167 µm) on 96
/// cells of 2 µm (the outermost at 95 µm), at two angles.
#[test]
fn issue62_check_names_every_refused_case_in_the_sweep_order() {
    let text = SMALL
        .replace("points = 64", "points = 96")
        .replace("spacing_um = 4.0", "spacing_um = 2.0")
        .replace("angles_deg = [30.0]", "angles_deg = [0.0, 90.0]")
        .replace("normal_n = 20.0", "normal_n = 80.0");
    let tmp = temp_dir("several");
    std::fs::write(tmp.path().join("c.toml"), text).unwrap();
    let o = run_in(tmp.path(), &["check", "c.toml"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    let first = e.find("Fe/flat/000.0: the contact reaches the edge");
    let second = e.find("Fe/flat/090.0: the contact reaches the edge");
    assert!(first.is_some() && second > first, "{e}");
    assert!(
        e.contains("2 of 2 cases refused in their first moments"),
        "{e}"
    );
}
