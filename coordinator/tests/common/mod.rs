//! Helpers shared by the end-to-end tests of the sweep runner (`run_e2e`,
//! `run_features`): the real `mpcontact` binary on a small sweep (32² grid,
//! Cu and Ni × flat and circle-A × 3 angles), its commands and outputs.
//!
//! Each sweep runs under its own iceoryx2 prefix (`MPCONTACT_IPC_PREFIX`) so
//! the tests can check that no shared-memory file of that run is left behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub const EXE: &str = env!("CARGO_BIN_EXE_mpcontact");

pub const CONFIG: &str = concat!(
    include_str!("../../../tests/configs/table1c-coarse.toml"),
    r#"
[sweep]
materials = ["Cu", "Ni"]
surfaces = ["flat", "circle-A"]
angles_deg = { start = 0, stop = 90, step = 45 }

"#,
    include_str!("../../../tests/configs/solver-fast.toml")
);

pub const CASES: usize = 12;

pub fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("run_e2e-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("sweep.toml"), CONFIG).unwrap();
    d
}

pub fn prefix(tag: &str) -> String {
    format!("mpcontact_t{}{tag}_", std::process::id())
}

pub fn sweep_cmd(dir: &Path, out: &str, workers: usize, tag: &str) -> Command {
    let mut c = Command::new(EXE);
    c.args(["run"])
        .arg(dir.join("sweep.toml"))
        .args(["--workers", &workers.to_string(), "--out"])
        .arg(dir.join(out))
        .env("MPCONTACT_IPC_PREFIX", prefix(tag));
    c
}

pub fn check_ok(out: &Output, what: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        finished(&out.status, &err),
        "{what} failed: {}\n{err}",
        out.status,
    );
}

/// A sweep that ran to its end: exit 0, or — when a case has no result
/// (failed or not converged), which the console then says — the exit
/// status `coordinator::case::EXIT_NOT_ALL_OK` (#59).
pub fn finished(status: &std::process::ExitStatus, stderr: &str) -> bool {
    status.success()
        || (status.code() == Some(coordinator::case::EXIT_NOT_ALL_OK.into())
            && stderr.contains("cases have no result"))
}

/// Shared-memory files of a prefix, except the 16-byte `global_mgmt` file
/// iceoryx2 keeps per prefix (removed here).
pub fn shm_leftovers(tag: &str) -> Vec<String> {
    let p = prefix(tag);
    let mut left = Vec::new();
    for e in std::fs::read_dir("/dev/shm").unwrap().flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if name.starts_with(&p) {
            if name.ends_with("global_mgmt") {
                let _ = std::fs::remove_file(e.path());
            } else {
                left.push(name);
            }
        }
    }
    left
}

pub fn read_csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

/// results.csv without the columns that legitimately differ between runs
/// (`seconds`, `worker`).
pub fn physics_columns(path: &Path) -> String {
    let rows = read_csv(path);
    let header = &rows[0];
    let skip: Vec<usize> = header
        .iter()
        .enumerate()
        .filter(|(_, h)| *h == "seconds" || *h == "worker")
        .map(|(i, _)| i)
        .collect();
    assert_eq!(skip.len(), 2, "{header:?}");
    rows.iter()
        .map(|r| {
            r.iter()
                .enumerate()
                .filter(|(i, _)| !skip.contains(i))
                .map(|(_, v)| v.as_str())
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

pub fn journal_cases(out: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(out.join("journal.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["kind"] == "case")
        .collect()
}

pub fn summary(o: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(o.join("summary.json")).unwrap()).unwrap()
}
