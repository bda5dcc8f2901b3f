//! End-to-end tests of the sweep runner: the real `mpcontact` binary as
//! coordinator plus worker processes over iceoryx2 shared memory, on a small
//! sweep (32² grid, Cu and Ni × flat and circle-A × 3 angles).
//!
//! Each sweep runs under its own iceoryx2 prefix (`MPCONTACT_IPC_PREFIX`) so
//! the test can check that no shared-memory file of that run is left behind.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const EXE: &str = env!("CARGO_BIN_EXE_mpcontact");

const CONFIG: &str = r#"
[grid]
points = 32
spacing_um = 200.0

[indenter]
radius_mm = 200.0

[load]
normal_n = 6000.0
friction = 0.3
tangential_ratio = 0.3

[sweep]
materials = ["Cu", "Ni"]
surfaces = ["flat", "circle-A"]
angles_deg = { start = 0, stop = 90, step = 45 }

[solver]
coupling = false
tolerance = 1e-6
max_iterations = 2000
"#;

const CASES: usize = 12;

fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("run_e2e-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("sweep.toml"), CONFIG).unwrap();
    d
}

fn prefix(tag: &str) -> String {
    format!("mpcontact_t{}{tag}_", std::process::id())
}

fn sweep_cmd(dir: &Path, out: &str, workers: usize, tag: &str) -> Command {
    let mut c = Command::new(EXE);
    c.args(["run"])
        .arg(dir.join("sweep.toml"))
        .args(["--workers", &workers.to_string(), "--out"])
        .arg(dir.join(out))
        .env("MPCONTACT_IPC_PREFIX", prefix(tag));
    c
}

fn check_ok(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what} failed: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Shared-memory files of a prefix, except the 16-byte `global_mgmt` file
/// iceoryx2 keeps per prefix (removed here).
fn shm_leftovers(tag: &str) -> Vec<String> {
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

fn read_csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

/// results.csv without the columns that legitimately differ between runs
/// (`seconds`, `worker`).
fn physics_columns(path: &Path) -> String {
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

fn journal_cases(out: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(out.join("journal.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|v| v["kind"] == "case")
        .collect()
}

#[test]
fn two_workers_record_every_case_once_reuse_kernels_and_leave_no_shm() {
    let dir = scratch("two");
    let out = sweep_cmd(&dir, "out", 2, "a").output().unwrap();
    check_ok(&out, "2-worker sweep");
    let o = dir.join("out");

    // Every case exactly once, in results and in the journal.
    let rows = read_csv(&o.join("results.csv"));
    assert_eq!(rows[0].join(","), coordinator::run::RESULTS_HEADER);
    let ids: BTreeSet<(String, String, String)> = rows[1..]
        .iter()
        .map(|r| (r[0].clone(), r[1].clone(), r[2].clone()))
        .collect();
    assert_eq!(rows.len() - 1, CASES);
    assert_eq!(ids.len(), CASES);
    let journal = journal_cases(&o);
    let jids: BTreeSet<String> = journal
        .iter()
        .map(|v| v["case_id"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(journal.len(), CASES, "journal holds duplicates");
    assert_eq!(jids.len(), CASES);
    // Statuses are the solver's business; the runner records each case once
    // with a known status.
    for r in &rows[1..] {
        assert!(
            ["ok", "not_converged", "failed"].contains(&r[3].as_str()),
            "{r:?}"
        );
    }

    // Curves complete: exactly the converged cases, each with a finite μa.
    let ok: BTreeSet<(String, String, String)> = rows[1..]
        .iter()
        .filter(|r| r[3] == "ok" && !r[4].is_empty())
        .map(|r| (r[0].clone(), r[1].clone(), r[2].clone()))
        .collect();
    let curves = read_csv(&o.join("curves.csv"));
    assert_eq!(curves[0].join(","), coordinator::run::CURVES_HEADER);
    let on_curves: BTreeSet<(String, String, String)> = curves[1..]
        .iter()
        .map(|r| (r[0].clone(), r[1].clone(), r[2].clone()))
        .collect();
    assert_eq!(curves.len() - 1, on_curves.len(), "a curve point twice");
    assert_eq!(on_curves, ok);
    for r in &curves[1..] {
        let mu: f64 = r[3].parse().unwrap();
        assert!(mu.is_finite(), "{r:?}");
    }

    // Both workers worked; each built each (material, grid) kernel once:
    // its kernel count equals the number of materials it solved.
    let mut materials_by_worker: BTreeMap<u64, BTreeSet<String>> = BTreeMap::new();
    let mut builds_by_worker: BTreeMap<u64, u64> = BTreeMap::new();
    for v in &journal {
        let w = v["worker"].as_u64().unwrap();
        let m = v["case_id"].as_str().unwrap().split('/').next().unwrap();
        materials_by_worker.entry(w).or_default().insert(m.into());
        let b = builds_by_worker.entry(w).or_default();
        *b = (*b).max(v["kernel_builds"].as_u64().unwrap());
    }
    assert_eq!(materials_by_worker.len(), 2, "one worker idled");
    for (w, mats) in &materials_by_worker {
        assert_eq!(builds_by_worker[w], mats.len() as u64, "worker {w}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["total"], CASES);
    let counted = summary["ok"].as_u64().unwrap()
        + summary["not_converged"].as_u64().unwrap()
        + summary["failed"].as_u64().unwrap();
    assert_eq!(counted, CASES as u64);
    for (w, b) in builds_by_worker {
        assert_eq!(summary["kernel_builds"][w.to_string()], b);
    }
    assert!(summary["config"].as_str().unwrap().contains("circle-A"));
    assert!(o.join("mu_a_vs_angle.svg").exists());

    // Nothing of this run left in /dev/shm.
    assert_eq!(shm_leftovers("a"), Vec::<String>::new());
}

#[test]
fn one_and_two_workers_give_bit_identical_csv() {
    let dir = scratch("one-two");
    check_ok(
        &sweep_cmd(&dir, "w1", 1, "b1").output().unwrap(),
        "1 worker",
    );
    check_ok(
        &sweep_cmd(&dir, "w2", 2, "b2").output().unwrap(),
        "2 workers",
    );
    let (a, b) = (dir.join("w1"), dir.join("w2"));
    assert_eq!(
        std::fs::read(a.join("curves.csv")).unwrap(),
        std::fs::read(b.join("curves.csv")).unwrap()
    );
    assert_eq!(
        physics_columns(&a.join("results.csv")),
        physics_columns(&b.join("results.csv"))
    );
    assert!(shm_leftovers("b1").is_empty() && shm_leftovers("b2").is_empty());
}

#[test]
fn two_concurrent_sweeps_both_complete() {
    let dir = scratch("concurrent");
    let mut a = sweep_cmd(&dir, "a", 1, "c1").spawn().unwrap();
    let mut b = sweep_cmd(&dir, "b", 1, "c1").spawn().unwrap();
    assert!(a.wait().unwrap().success());
    assert!(b.wait().unwrap().success());
    for o in ["a", "b"] {
        let rows = read_csv(&dir.join(o).join("results.csv"));
        assert_eq!(rows.len() - 1, CASES, "{o}");
        assert_eq!(journal_cases(&dir.join(o)).len(), CASES, "{o}");
    }
    assert_eq!(
        std::fs::read(dir.join("a/curves.csv")).unwrap(),
        std::fs::read(dir.join("b/curves.csv")).unwrap()
    );
    assert!(shm_leftovers("c1").is_empty());
}

#[test]
fn resume_recomputes_nothing_journalled_and_matches() {
    let dir = scratch("resume");
    check_ok(
        &sweep_cmd(&dir, "out", 2, "d").output().unwrap(),
        "full sweep",
    );
    let o = dir.join("out");
    let full_curves = std::fs::read(o.join("curves.csv")).unwrap();
    // Keep the header and 9 cases, plus a torn line, as if killed mid-write.
    let text = std::fs::read_to_string(o.join("journal.jsonl")).unwrap();
    let mut kept: Vec<&str> = text.lines().take(10).collect();
    kept.push("{\"kind\":\"case\",\"case_");
    std::fs::write(o.join("journal.jsonl"), kept.join("\n")).unwrap();
    for f in ["results.csv", "curves.csv", "summary.json"] {
        std::fs::remove_file(o.join(f)).unwrap();
    }
    // Without --resume the directory is refused.
    let refused = sweep_cmd(&dir, "out", 2, "d").output().unwrap();
    assert!(!refused.status.success());
    let mut c = sweep_cmd(&dir, "out", 2, "d");
    c.arg("--resume");
    check_ok(&c.output().unwrap(), "resume");
    assert_eq!(std::fs::read(o.join("curves.csv")).unwrap(), full_curves);
    assert_eq!(journal_cases(&o).len(), CASES);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["resumed"], 9);
    assert!(shm_leftovers("d").is_empty());
}

fn children(pid: u32) -> Vec<u32> {
    std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children"))
        .unwrap_or_default()
        .split_whitespace()
        .filter_map(|p| p.parse().ok())
        .collect()
}

#[test]
fn killed_worker_is_detected_and_its_case_requeued() {
    let dir = scratch("kill");
    let started = std::time::Instant::now();
    let coord = sweep_cmd(&dir, "out", 2, "e")
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let o = dir.join("out");
    // Wait until the first case is journalled, then SIGKILL one worker mid-sweep.
    let victim = loop {
        assert!(started.elapsed().as_secs() < 60, "sweep did not start");
        let kids = children(coord.id());
        let journalled = std::fs::read_to_string(o.join("journal.jsonl"))
            .map(|t| t.lines().count() > 1)
            .unwrap_or(false);
        if journalled && kids.len() == 2 {
            break kids[0];
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let killed = Command::new("kill")
        .args(["-9", &victim.to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = coord.wait_with_output().unwrap();
    check_ok(&out, "sweep with a killed worker");
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    let journal = journal_cases(&o);
    let ids: BTreeSet<String> = journal
        .iter()
        .map(|v| v["case_id"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(journal.len(), CASES, "a case recorded twice or lost");
    assert_eq!(ids.len(), CASES);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(o.join("summary.json")).unwrap()).unwrap();
    let died = summary["per_worker"]
        .as_object()
        .unwrap()
        .values()
        .filter(|w| w["died"] == true)
        .count();
    let workers = summary["per_worker"].as_object().unwrap().len();
    // The victim may have finished its last case just before the kill; then
    // the sweep simply ends without it.
    assert!(died <= 1, "{summary}");
    assert!(workers >= 2, "{summary}");
    assert_eq!(shm_leftovers("e"), Vec::<String>::new());
}
