//! # mpcontact coordinator
//!
//! The `mpcontact` command line: config loading (`config`), single in-process
//! solves (`solve`), the multi-process sweep runner over iceoryx2 (`run`), and
//! the files they write. Physics lives in `solver`; messages in `protocol`.
//! A case is named by one typed key (`case::CaseKey`) everywhere.

pub mod atomic;
pub mod case;
pub mod config;
pub mod convergence;
pub mod cost;
pub mod dry_run;
pub mod float_text;
pub mod history_out;
pub mod maps;
pub mod memory;
pub mod npy;
pub mod run;
pub mod shard;
pub mod solve;
pub mod solve_progress;
pub mod stress_out;
