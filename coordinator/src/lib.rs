//! # mpcontact coordinator
//!
//! The `mpcontact` command line: config loading (`config`), single in-process
//! solves (`solve`), the multi-process sweep runner over iceoryx2 (`run`), and
//! the files they write. Physics lives in `solver`; messages in `protocol`.
//! A case is named by one typed key (`case::CaseKey`) everywhere.

#[path = "output/atomic.rs"]
pub mod atomic;
pub mod case;
pub mod config;
pub mod convergence;
pub mod cost;
pub mod dry_run;
pub mod float_text;
#[path = "output/history.rs"]
pub mod history_out;
#[path = "output/maps.rs"]
pub mod maps;
pub mod memory;
#[path = "output/npy.rs"]
pub mod npy;
pub mod run;
pub mod shard;
pub mod solve;
pub mod solve_progress;
#[path = "output/stress.rs"]
pub mod stress_out;
