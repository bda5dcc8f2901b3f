//! The solver's layers (solver/src/lib.rs, "Layers"): every module imports
//! only from modules listed before it here, so there is no import circle and
//! no layer reaches up. Read from the sources: every `crate::…` path of a
//! module's code (its `#[cfg(test)]` tests excepted, which may drive a whole
//! case), including the names the crate root re-exports.

use std::collections::BTreeMap;
use std::path::Path;

/// The modules in import order: (folder, module). A module may use the ones
/// before it, never one after it.
const ORDER: &[(&str, &str)] = &[
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
    ("model", "presets"),
    ("model", "radii"),
    ("model", "spec"),
    ("operators", "fft2"),
    ("operators", "operator"),
    ("operators", "multilevel"),
    ("operators", "stress"),
    ("operators", "kernels"),
    ("solve", "normal"),
    ("solve", "tangential_problem"),
    ("solve", "fista"),
    ("solve", "coarse_slip"),
    ("solve", "window"),
    ("solve", "tangential"),
    ("solve", "tangential_displacement"),
    ("solve", "resident"),
    ("solve", "coupling"),
    ("solve", "history"),
    ("post", "results"),
    ("post", "stress_summary"),
    ("post", "indentation"),
    ("", "case"),
];

fn src() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The module's source files (a folder module's every file).
fn files(folder: &str, module: &str) -> Vec<std::path::PathBuf> {
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

/// Names the crate root re-exports, and the module each comes from.
fn root_names() -> BTreeMap<String, String> {
    let lib = code(&src().join("lib.rs"));
    let mut names = BTreeMap::new();
    for stmt in lib.split(';') {
        let Some(i) = stmt.find("pub use ") else {
            continue;
        };
        let path = stmt[i + 8..].trim();
        // `folder::module::{A, B}`, `folder::module::A` or `folder::module`.
        let (head, items) = match path.find('{') {
            Some(b) => (&path[..b], path[b + 1..].trim_end_matches('}')),
            None => match path.rfind("::") {
                Some(c) => (&path[..c + 2], &path[c + 2..]),
                None => continue,
            },
        };
        let parts: Vec<&str> = head.trim_end_matches("::").split("::").collect();
        let module = parts.last().unwrap().to_string();
        for item in items.split(',') {
            let item = item.trim();
            if item.is_empty() {
                continue;
            }
            // A re-exported module names itself.
            let owner = if ORDER.iter().any(|(_, m)| *m == item) {
                item.to_string()
            } else {
                module.clone()
            };
            names.insert(item.to_string(), owner);
        }
    }
    names
}

/// The modules a module's code uses.
fn uses(folder: &str, module: &str, root: &BTreeMap<String, String>) -> Vec<String> {
    let mut out = Vec::new();
    for f in files(folder, module) {
        let text = code(&f);
        let mut rest = &text[..];
        while let Some(i) = rest.find("crate::") {
            rest = &rest[i + 7..];
            if let Some(group) = rest.strip_prefix('{') {
                let end = group.find('}').unwrap_or(group.len());
                for name in group[..end].split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
                    if let Some(m) = root.get(name) {
                        out.push(m.clone());
                    }
                }
                for (_, m) in ORDER {
                    if group[..end].contains(&format!("::{m}::")) {
                        out.push(m.to_string());
                    }
                }
                continue;
            }
            let first = ident_at(rest);
            let after = &rest[first.len()..];
            if ORDER.iter().any(|(f, _)| *f == first && !f.is_empty()) {
                // crate::folder::module
                let second = ident_at(after.trim_start_matches("::"));
                out.push(second.to_string());
            } else if let Some(m) = root.get(first) {
                out.push(m.clone());
            } else if ORDER.iter().any(|(_, m)| *m == first) {
                out.push(first.to_string());
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
    let root = root_names();
    let place = |m: &str| ORDER.iter().position(|(_, x)| *x == m);
    let mut wrong = Vec::new();
    for (i, (folder, module)) in ORDER.iter().enumerate() {
        for used in uses(folder, module, &root) {
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
/// placed in the order), and every folder is a layer of it.
#[test]
fn every_source_file_is_in_the_order() {
    let mut listed: Vec<_> = ORDER.iter().flat_map(|(f, m)| files(f, m)).collect();
    listed.push(src().join("lib.rs"));
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

/// The check above sees what it must: a use of a later module is caught,
/// through a folder path, a root re-export and a `crate::{…}` group.
#[test]
fn the_reader_finds_uses_through_paths_and_re_exports() {
    let root = root_names();
    assert_eq!(root.get("CaseSpec").map(String::as_str), Some("spec"));
    assert_eq!(root.get("normal").map(String::as_str), Some("normal"));
    let history = uses("solve", "history", &root);
    for m in ["coupling", "radii", "resident", "spec"] {
        assert!(history.contains(&m.to_string()), "{m} in {history:?}");
    }
    let results = uses("post", "results", &root);
    assert!(results.contains(&"history".to_string()), "{results:?}");
}
