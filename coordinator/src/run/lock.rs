//! The exclusive claim of a sweep on its output directory: an advisory lock
//! (`flock`) on the directory itself, held for the life of the run. Owns only
//! that lock.
//!
//! The kernel releases the lock when its holder exits, however it exits
//! (SIGKILL included), so there is no stale lock to judge and no lock file to
//! leave behind. The pid file of older builds (`.mpcontact.lock`) raced: two
//! runs that both found a dead pid in it both went on (2 of 20 trials).

use anyhow::Context;
use std::fs::{File, TryLockError};
use std::path::Path;

/// The lock file of builds before the directory lock; removed when found.
const OLD_LOCK_FILE: &str = ".mpcontact.lock";

/// An exclusive claim on an output directory for the life of a run.
pub struct DirLock {
    /// The open directory; closing it releases the lock.
    _dir: File,
}

impl DirLock {
    /// Take the lock of `out_dir` (an existing directory); refused while
    /// another process holds it.
    pub fn take(out_dir: &Path) -> anyhow::Result<DirLock> {
        let dir = File::open(out_dir)
            .with_context(|| format!("cannot open the output directory {}", out_dir.display()))?;
        match dir.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => anyhow::bail!(
                "{} is in use by a running sweep (another mpcontact run holds its lock)",
                out_dir.display()
            ),
            Err(TryLockError::Error(e)) => {
                return Err(e).with_context(|| format!("cannot lock {}", out_dir.display()))
            }
        }
        let _ = std::fs::remove_file(out_dir.join(OLD_LOCK_FILE));
        Ok(DirLock { _dir: dir })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn issue20_item10_only_one_of_two_simultaneous_runs_gets_the_directory() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        for trial in 0..50 {
            // A pid file of an older build naming a dead process, as SIGKILL left it.
            std::fs::write(dir.join(OLD_LOCK_FILE), "4194304\n").unwrap();
            let barrier = std::sync::Barrier::new(2);
            let (a, b) = std::thread::scope(|s| {
                let take = || {
                    barrier.wait();
                    DirLock::take(dir)
                };
                let a = s.spawn(take);
                let b = s.spawn(take);
                (a.join().unwrap(), b.join().unwrap())
            });
            assert!(
                a.is_ok() != b.is_ok(),
                "trial {trial}: exactly one run may hold the directory"
            );
            let e = format!("{:#}", a.err().or(b.err()).unwrap());
            assert!(e.contains("in use by a running sweep"), "{e}");
        }
        // Released with its holder, and no lock file is left behind.
        drop(DirLock::take(dir).unwrap());
        let _again = DirLock::take(dir).unwrap();
        assert!(!dir.join(OLD_LOCK_FILE).exists());
    }
}
