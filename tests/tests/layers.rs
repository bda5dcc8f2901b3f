//! The layers of the solver (solver/src/lib.rs, "Layers") and of the
//! coordinator (coordinator/src/lib.rs, output/mod.rs): every module imports
//! only from modules listed before it here, so there is no import circle
//! and no layer reaches up; every source file belongs to a listed module.
//! The reader is `mpcontact_e2e::layers`.

use mpcontact_e2e::layers::Layers;
use std::path::Path;

fn crate_src(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(name)
        .join("src")
}

/// The solver's modules in import order: (layer folder, module).
fn solver() -> Layers {
    Layers {
        src: crate_src("solver"),
        order: &[
            ("", "error"),
            ("base", "progress"),
            ("base", "parallel"),
            ("base", "grid"),
            ("base", "geometry"),
            ("base", "cover"),
            ("green", "influence"),
            ("green", "aniso"),
            ("model", "material"),
            ("model", "surface"),
            ("model", "roughness"),
            ("model", "scan"),
            ("model", "resample"),
            ("model", "self_affine"),
            ("model", "presets"),
            ("model", "radii"),
            ("model", "spec"),
            ("operators", "fft2"),
            ("operators", "operator"),
            ("operators", "multilevel"),
            ("operators", "stress"),
            ("operators", "kernels"),
            ("solve", "normal"),
            ("solve", "tangential"),
            ("solve", "resident"),
            ("solve", "coupling"),
            ("solve", "wear"),
            ("solve", "history"),
            ("post", "results"),
            ("post", "stress_summary"),
            ("post", "indentation"),
            ("", "case"),
        ],
        roots: &["lib.rs"],
    }
}

/// The coordinator's modules in import order. `config` and `run` are one
/// module each (their files import one another); `output` is a folder of
/// layers: the outputs never import the sweep runner or the solve that
/// call them.
fn coordinator() -> Layers {
    Layers {
        src: crate_src("coordinator"),
        order: &[
            ("", "float_text"),
            ("", "case"),
            ("", "convergence"),
            ("", "solve_progress"),
            ("", "scan_file"),
            ("", "config"),
            ("", "memory"),
            ("", "cost"),
            ("", "preflight"),
            ("output", "atomic"),
            ("output", "npy"),
            ("output", "plot"),
            ("output", "maps"),
            ("output", "wear"),
            ("output", "history"),
            ("output", "stress"),
            ("output", "sweep"),
            ("output", "fretting_map"),
            ("output", "orientation_map"),
            ("", "solve"),
            ("", "dry_run"),
            ("", "shard"),
            ("", "run"),
        ],
        roots: &["lib.rs", "main.rs"],
    }
}

#[test]
fn every_module_imports_only_from_modules_before_it() {
    let wrong: Vec<String> = [solver(), coordinator()]
        .iter()
        .flat_map(Layers::violations)
        .collect();
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn every_source_file_is_in_the_order() {
    for layers in [solver(), coordinator()] {
        let (extra, missing) = layers.unlisted();
        assert!(
            extra.is_empty() && missing.is_empty(),
            "not in the order: {extra:?}; listed but absent: {missing:?}"
        );
    }
}

/// The check above sees what it must: uses through folder paths, root
/// re-exports, `{…}` groups and `super::` between a folder's files.
#[test]
fn the_reader_finds_uses_through_paths_re_exports_groups_and_super() {
    let s = solver();
    let root = s.root_names();
    assert_eq!(root.get("CaseSpec").map(String::as_str), Some("spec"));
    assert_eq!(root.get("normal").map(String::as_str), Some("normal"));
    let history = s.uses("solve", "history");
    for m in ["coupling", "radii", "resident", "spec"] {
        assert!(history.contains(&m.to_string()), "{m} in {history:?}");
    }
    assert!(s.uses("post", "results").contains(&"history".to_string()));
    let c = coordinator();
    let run = c.uses("", "run");
    for m in ["atomic", "config", "history", "shard", "sweep"] {
        assert!(run.contains(&m.to_string()), "{m} in {run:?}");
    }
    let stress = c.uses("output", "stress");
    for m in ["config", "float_text", "maps", "npy"] {
        assert!(stress.contains(&m.to_string()), "{m} in {stress:?}");
    }
    assert!(c
        .uses("output", "fretting_map")
        .contains(&"sweep".to_string()));
    assert!(c.uses("", "solve").contains(&"stress".to_string()));
}
