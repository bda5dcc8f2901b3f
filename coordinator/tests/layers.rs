//! The coordinator's layers (coordinator/src/lib.rs and output/mod.rs):
//! every module imports only from modules listed before it here, so there
//! is no import circle and no layer reaches up — above all, the outputs
//! never import the sweep runner or the solve that call them. Read from the
//! sources: every `crate::…` path of a module's code, and `super::…` between
//! the files of a layer folder (`#[cfg(test)]` tests excepted, which may
//! drive a whole solve).

use std::path::{Path, PathBuf};

/// The modules in import order: (folder, module). A module may use the ones
/// before it, never one after it. `config` and `run` are one module each
/// (their files import one another); `output` is a folder of layers.
const ORDER: &[(&str, &str)] = &[
    ("", "case"),
    ("", "convergence"),
    ("", "float_text"),
    ("", "solve_progress"),
    ("", "config"),
    ("", "memory"),
    ("", "cost"),
    ("output", "atomic"),
    ("output", "npy"),
    ("output", "plot"),
    ("output", "maps"),
    ("output", "history"),
    ("output", "stress"),
    ("output", "sweep"),
    ("output", "fretting_map"),
    ("output", "orientation_map"),
    ("", "solve"),
    ("", "dry_run"),
    ("", "shard"),
    ("", "run"),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Whether `name` is a folder of layers (not a module of its own).
fn is_folder(name: &str) -> bool {
    ORDER.iter().any(|(f, _)| *f == name && !f.is_empty())
}

/// The module's source files (a folder module's every file).
fn files(folder: &str, module: &str) -> Vec<PathBuf> {
    let base = src().join(folder);
    let file = base.join(format!("{module}.rs"));
    if file.exists() {
        return vec![file];
    }
    let dir = base.join(module);
    let mut out: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    out.sort();
    out
}

/// The code of a file without its tests and comments.
fn code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = match text.find("#[cfg(test)]") {
        Some(i) => &text[..i],
        None => &text[..],
    };
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The modules named by a path `rest` (what follows `crate::`, or
/// `super::` inside the layer folder `folder`): a module, a folder's
/// module, or a `{…}` group of either.
fn named(rest: &str, folder: &str, out: &mut Vec<String>) {
    let rest = rest.trim_start();
    if let Some(group) = rest.strip_prefix('{') {
        let end = group.find('}').unwrap_or(group.len());
        for item in group[..end].split(',') {
            named(item, folder, out);
        }
        return;
    }
    let first = ident_at(rest);
    let after = rest[first.len()..].trim_start();
    if folder.is_empty() && is_folder(first) {
        // crate::output::module, crate::output::{a, b}
        if let Some(tail) = after.strip_prefix("::") {
            named(tail, first, out);
        }
    } else if ORDER.iter().any(|(f, m)| *f == folder && *m == first) {
        out.push(first.to_string());
    }
}

/// The modules a module's code uses.
fn uses(folder: &str, module: &str) -> Vec<String> {
    let mut out = Vec::new();
    for f in files(folder, module) {
        let text = code(&f);
        for (prefix, within) in [("crate::", ""), ("super::", folder)] {
            // `super::` names a sibling only in a layer folder's own files.
            if prefix == "super::" && folder.is_empty() {
                continue;
            }
            let mut rest = &text[..];
            while let Some(i) = rest.find(prefix) {
                rest = &rest[i + prefix.len()..];
                named(rest, within, &mut out);
            }
        }
    }
    out.sort();
    out.dedup();
    out.retain(|m| m != module);
    out
}

#[test]
fn every_module_imports_only_from_modules_before_it() {
    let place = |m: &str| ORDER.iter().position(|(_, x)| *x == m);
    let mut wrong = Vec::new();
    for (i, (folder, module)) in ORDER.iter().enumerate() {
        for used in uses(folder, module) {
            match place(&used) {
                Some(j) if j < i => {}
                Some(_) => wrong.push(format!("{folder}/{module} uses {used}, listed after it")),
                None => wrong.push(format!("{folder}/{module} uses {used}, not in ORDER")),
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Every source file belongs to a module of [`ORDER`] (a new file must be
/// placed in the order), and every folder of layers is one of it.
#[test]
fn every_source_file_is_in_the_order() {
    let mut listed: Vec<_> = ORDER.iter().flat_map(|(f, m)| files(f, m)).collect();
    listed.push(src().join("lib.rs"));
    listed.push(src().join("main.rs"));
    for (folder, _) in ORDER.iter().filter(|(f, _)| !f.is_empty()) {
        listed.push(src().join(folder).join("mod.rs"));
    }
    listed.sort();
    listed.dedup();
    let mut found = Vec::new();
    let mut stack = vec![src()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                found.push(p);
            }
        }
    }
    found.sort();
    assert_eq!(found, listed);
}

/// The check above sees what it must: uses through `crate::` paths, a
/// folder's `{…}` group and `super::` between an output's files.
#[test]
fn the_reader_finds_uses_through_paths_groups_and_super() {
    let run = uses("", "run");
    for m in ["atomic", "config", "history", "shard", "sweep"] {
        assert!(run.contains(&m.to_string()), "{m} in {run:?}");
    }
    let stress = uses("output", "stress");
    for m in ["config", "float_text", "maps", "npy"] {
        assert!(stress.contains(&m.to_string()), "{m} in {stress:?}");
    }
    assert!(uses("output", "fretting_map").contains(&"sweep".to_string()));
    assert!(uses("", "solve").contains(&"stress".to_string()));
}
