//! The worker's sign of life while it computes: the solver's long loops tick
//! (`solver::set_tick_hook`), and at most every
//! [`protocol::HEARTBEAT_INTERVAL`] a tick writes the time into the run's
//! heartbeat file for this worker, which the coordinator reads. A long
//! computation therefore never looks like a hang; silence does. Owns only
//! that file.

use std::fs::File;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// The open heartbeat file and when it was last written; the file is
/// removed when the worker ends.
pub struct Heartbeat {
    file: File,
    path: std::path::PathBuf,
    last: Option<Instant>,
}

impl Drop for Heartbeat {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

fn unix_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}

impl Heartbeat {
    /// Creates (or truncates) the heartbeat file of worker `index` of `run_id`.
    pub fn open(run_id: &str, index: usize) -> anyhow::Result<Heartbeat> {
        let path = protocol::heartbeat_path(run_id, index)?;
        let file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(true)
            .write(true)
            .open(&path)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", path.display()))?;
        Ok(Heartbeat {
            file,
            path,
            last: None,
        })
    }

    /// Beat now.
    pub fn beat(&mut self) {
        // A beat that cannot be written is not fatal: the coordinator then
        // judges by the dispatch time, as for a silent worker.
        let _ = protocol::write_heartbeat(&self.file, unix_ns());
        self.last = Some(Instant::now());
    }

    /// Beat if the last beat is older than the interval (the tick hook).
    pub fn tick(&mut self) {
        if self
            .last
            .is_none_or(|t| t.elapsed() >= protocol::HEARTBEAT_INTERVAL)
        {
            self.beat();
        }
    }
}
