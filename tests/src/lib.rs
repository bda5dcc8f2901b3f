//! End-to-end tests of the `mpcontact` binary live in `tests/tests/`; this
//! library holds what several of them share: the binary and how to run it,
//! and the reader of the crates' layers.

use std::path::PathBuf;
use std::process::{Command, Output};

pub mod layers;

/// The `mpcontact` binary of the same build. `cargo test --workspace` builds it
/// (the coordinator's own integration tests need it).
pub fn exe() -> PathBuf {
    let mut p = std::env::current_exe().unwrap();
    p.pop();
    if p.ends_with("deps") {
        p.pop();
    }
    let exe = p.join("mpcontact");
    assert!(
        exe.exists(),
        "{} not built: run `cargo test --workspace`",
        exe.display()
    );
    exe
}

/// `mpcontact ARGS`, run to its end.
pub fn run(args: &[&str]) -> Output {
    Command::new(exe())
        .args(args)
        .output()
        .expect("run mpcontact")
}
