//! The reader behind `tests/tests/layers.rs`: which modules of a crate a
//! module's code uses, read from the sources, so that a test can check
//! that every module imports only from modules listed before it (no import
//! circle, no layer reaching up).
//!
//! It reads every `crate::…` path of a module's code — a module, a layer
//! folder's module, a `{…}` group of either, or a name the crate root
//! re-exports (`pub use folder::module::Name`) — and `super::…` between the
//! files of a layer folder. `#[cfg(test)]` tests (a folder module's
//! `tests.rs` too) and comments are left out (tests may drive a whole case).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A crate's modules in import order.
pub struct Layers {
    /// The crate's `src` folder.
    pub src: PathBuf,
    /// (layer folder, module): a module may use the ones before it. A
    /// folder is `""` for a module at the crate root; a module may be a
    /// file or a folder of its own (all its files belong to it).
    pub order: &'static [(&'static str, &'static str)],
    /// Root files besides the modules: `lib.rs`, `main.rs`.
    pub roots: &'static [&'static str],
}

impl Layers {
    fn is_folder(&self, name: &str) -> bool {
        self.order.iter().any(|(f, _)| *f == name && !f.is_empty())
    }

    fn is_module(&self, name: &str) -> bool {
        self.order.iter().any(|(_, m)| *m == name)
    }

    /// The module's source files (a folder module's every file).
    pub fn files(&self, folder: &str, module: &str) -> Vec<PathBuf> {
        let base = self.src.join(folder);
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

    /// Names the crate root re-exports, and the module each comes from.
    pub fn root_names(&self) -> BTreeMap<String, String> {
        let lib = code(&self.src.join("lib.rs"));
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
            let module = head.trim_end_matches("::").rsplit("::").next().unwrap();
            for item in items.split(',').map(str::trim).filter(|s| !s.is_empty()) {
                // A re-exported module names itself.
                let owner = if self.is_module(item) { item } else { module };
                names.insert(item.to_string(), owner.to_string());
            }
        }
        names
    }

    /// The modules named by a path `rest` (what follows `crate::`, or
    /// `super::` inside the layer folder `folder`).
    fn named(
        &self,
        rest: &str,
        folder: &str,
        root: &BTreeMap<String, String>,
        out: &mut Vec<String>,
    ) {
        let rest = rest.trim_start();
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                self.named(item, folder, root, out);
            }
            return;
        }
        let first = ident_at(rest);
        let after = rest[first.len()..].trim_start();
        if folder.is_empty() && self.is_folder(first) {
            // crate::folder::module, crate::folder::{a, b}
            if let Some(tail) = after.strip_prefix("::") {
                self.named(tail, first, root, out);
            }
        } else if self.order.iter().any(|(f, m)| *f == folder && *m == first) {
            out.push(first.to_string());
        } else if folder.is_empty() {
            if let Some(m) = root.get(first) {
                out.push(m.clone());
            }
        }
    }

    /// The modules a module's code uses.
    pub fn uses(&self, folder: &str, module: &str) -> Vec<String> {
        let root = self.root_names();
        let mut out = Vec::new();
        for f in self.files(folder, module) {
            let text = code(&f);
            for (prefix, within) in [("crate::", ""), ("super::", folder)] {
                // `super::` names a sibling only in a layer folder's own
                // files (in a folder module's files, the module itself).
                if prefix == "super::"
                    && (folder.is_empty() || f.parent() != Some(&self.src.join(folder)))
                {
                    continue;
                }
                let mut rest = &text[..];
                while let Some(i) = rest.find(prefix) {
                    rest = &rest[i + prefix.len()..];
                    self.named(rest, within, &root, &mut out);
                }
            }
        }
        out.sort();
        out.dedup();
        out.retain(|m| m != module);
        out
    }

    /// Every use of a module listed at or after the user: empty when the
    /// order holds.
    pub fn violations(&self) -> Vec<String> {
        let place = |m: &str| self.order.iter().position(|(_, x)| *x == m);
        let mut wrong = Vec::new();
        for (i, (folder, module)) in self.order.iter().enumerate() {
            for used in self.uses(folder, module) {
                match place(&used) {
                    Some(j) if j < i => {}
                    Some(_) => {
                        wrong.push(format!("{folder}/{module} uses {used}, listed after it"))
                    }
                    None => wrong.push(format!("{folder}/{module} uses {used}, not in the order")),
                }
            }
        }
        wrong
    }

    /// The crate's source files that the order does not account for, and
    /// the files it lists that are not there: both empty when every file
    /// belongs to a listed module, root or layer folder's `mod.rs`.
    pub fn unlisted(&self) -> (Vec<PathBuf>, Vec<PathBuf>) {
        let mut listed: Vec<_> = self
            .order
            .iter()
            .flat_map(|(f, m)| self.files(f, m))
            .collect();
        listed.extend(self.roots.iter().map(|r| self.src.join(r)));
        for (folder, _) in self.order.iter().filter(|(f, _)| !f.is_empty()) {
            listed.push(self.src.join(folder).join("mod.rs"));
        }
        listed.sort();
        listed.dedup();
        let mut found = Vec::new();
        let mut stack = vec![self.src.clone()];
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
        let extra = found
            .iter()
            .filter(|p| !listed.contains(p))
            .cloned()
            .collect();
        let missing = listed
            .iter()
            .filter(|p| !found.contains(p))
            .cloned()
            .collect();
        (extra, missing)
    }
}

/// The code of a file without its tests and comments.
fn code(path: &Path) -> String {
    // A folder module's `tests.rs` is its `#[cfg(test)] mod tests;`.
    if path.file_name().is_some_and(|n| n == "tests.rs") {
        return String::new();
    }
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
