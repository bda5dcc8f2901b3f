//! The exclusive claim of a sweep on its output directory
//! (`.mpcontact.lock`, holding the coordinator's pid). Owns only that file.

use anyhow::Context;
use std::path::{Path, PathBuf};

/// An exclusive claim on an output directory for the life of a run.
pub struct DirLock(PathBuf);

impl DirLock {
    /// Take the lock of `out_dir`; refused while the pid in an existing lock
    /// file is a running process (a stale lock is replaced).
    pub fn take(out_dir: &Path) -> anyhow::Result<DirLock> {
        let path = out_dir.join(".mpcontact.lock");
        for _ in 0..2 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut f) => {
                    use std::io::Write;
                    writeln!(f, "{}", std::process::id())?;
                    return Ok(DirLock(path));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let pid = std::fs::read_to_string(&path).unwrap_or_default();
                    let pid = pid.trim();
                    if !pid.is_empty() && Path::new(&format!("/proc/{pid}")).exists() {
                        anyhow::bail!(
                            "{} is in use by a running sweep (pid {pid})",
                            out_dir.display()
                        );
                    }
                    let _ = std::fs::remove_file(&path);
                }
                Err(e) => return Err(e).context(format!("while locking {}", out_dir.display())),
            }
        }
        anyhow::bail!("cannot lock {}", out_dir.display())
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}
