//! Files written whole or not at all: the content goes to a temporary file
//! beside the target, is synced, and is renamed over it. A full disk or a
//! crash leaves the previous file (or none), never a file cut mid-row; every
//! error names the file. Owns no format.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The temporary name for `path`: hidden, in the same directory (so the
/// rename stays on one file system), with the same extension (drawing
/// back ends choose their format by it).
fn temp_for(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!(".{stem}.tmp{}{ext}", std::process::id()))
}

/// Has `write` produce the file at a temporary path, then syncs it and
/// renames it to `path`. On any error the temporary is removed and `path`
/// is left as it was.
pub fn replace_with(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let tmp = temp_for(path);
    let result = write(&tmp)
        .and_then(|()| {
            std::fs::File::open(&tmp)
                .and_then(|f| f.sync_all())
                .context("cannot sync it")
        })
        .and_then(|()| std::fs::rename(&tmp, path).context("cannot move it into place"));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("while writing {}", path.display()))
}

/// Writes `bytes` to `path` whole or not at all.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    replace_with(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(anyhow::Error::from)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn issue20_item9_a_failed_write_leaves_the_old_file_and_no_temporary() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("results.csv");
        write(&path, b"old,complete\n").unwrap();
        // A writer that fails half-way, as a full disk makes it.
        let e = replace_with(&path, |t| {
            std::fs::write(t, b"new,cut")?;
            anyhow::bail!("No space left on device (os error 28)")
        })
        .unwrap_err();
        let msg = format!("{e:#}");
        assert!(msg.contains(&path.display().to_string()), "{msg}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old,complete\n");
        let names: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "no temporary left: {names:?}");
        // A whole write replaces it.
        write(&path, b"new,complete\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new,complete\n");
        assert_eq!(temp_for(&path).extension().unwrap(), "csv");
    }
}
