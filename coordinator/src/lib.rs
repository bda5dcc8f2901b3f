//! # mpcontact coordinator
//!
//! The `mpcontact` command line: config loading (`config`), single in-process
//! solves (`solve`), the multi-process sweep runner over iceoryx2 (`run`), and
//! the files they write (`output`). Physics lives in `solver`; messages in
//! `protocol`.
//! A case is named by one typed key (`case::CaseKey`) everywhere.
//!
//! Layers, each importing only from itself and those before it (checked by
//! the workspace's `tests/tests/layers.rs`, which lists the modules in
//! order): foundations (`case`, `convergence`, `float_text`,
//! `solve_progress`, `scan_file`) → `config` →
//! `memory`, `cost`, `preflight`, `output` → `solve`, `dry_run`, `shard` → `run`.

pub mod case;
pub mod config;
pub mod convergence;
pub mod cost;
pub mod dry_run;
pub mod float_text;
pub mod memory;
pub mod output;
pub mod preflight;
pub mod run;
pub mod scan_file;
pub mod shard;
pub mod solve;
pub mod solve_progress;
