//! Fault injection for the end-to-end tests of the runner, read from the
//! environment (inherited from the coordinator). Compiled only with the
//! `fault-injection` cargo feature, which the tests enable and a shipped
//! build does not. The worker hooks touch nothing but the worker's own
//! process; the journal hook is read by the coordinator (through
//! [`crate::test_journal_sync_delay`], which is `None` without the feature),
//! so that one feature switch holds every hook of the runner.
//!
//! * `MPCONTACT_TEST_HANG_CASE=<case>` with `MPCONTACT_TEST_HANG_MARKER=<path>`:
//!   the first worker to receive that case creates the marker file and then
//!   sleeps forever (alive, silent); a later worker finds the marker and
//!   solves the case normally.
//! * `MPCONTACT_TEST_CRASH_CASE=<case>`: every worker that receives that
//!   case aborts the process (SIGABRT).
//!
//! * `MPCONTACT_TEST_JOURNAL_SYNC_DELAY_MS=<ms>`: the coordinator sleeps
//!   that long after every journal sync, as a journal on a slow disk would
//!   (a loaded NFS or Lustre scratch: 300 ms per `fdatasync` was seen, #33).
//!
//! `<case>` is the case key's display text (e.g. `Cu/flat/045.0`), compared
//! as a string.

/// Hang once on `MPCONTACT_TEST_HANG_CASE`.
pub const HANG_CASE_ENV: &str = "MPCONTACT_TEST_HANG_CASE";
/// Marker file making the hang happen once.
pub const HANG_MARKER_ENV: &str = "MPCONTACT_TEST_HANG_MARKER";
/// Abort on `MPCONTACT_TEST_CRASH_CASE`, every time.
pub const CRASH_CASE_ENV: &str = "MPCONTACT_TEST_CRASH_CASE";

/// Delay every journal sync of the coordinator by this many milliseconds.
pub const JOURNAL_SYNC_DELAY_ENV: &str = "MPCONTACT_TEST_JOURNAL_SYNC_DELAY_MS";

/// The journal sync delay asked for by [`JOURNAL_SYNC_DELAY_ENV`] (None when
/// unset; a value that is not a whole number of milliseconds is named on
/// stderr and ignored — a test hook must not stop a run).
pub fn journal_sync_delay() -> Option<std::time::Duration> {
    let v = std::env::var(JOURNAL_SYNC_DELAY_ENV).ok()?;
    match v.trim().parse::<u64>() {
        Ok(ms) => Some(std::time::Duration::from_millis(ms)),
        Err(e) => {
            eprintln!("test hook {JOURNAL_SYNC_DELAY_ENV}={v:?} ignored: {e}");
            None
        }
    }
}

/// Apply the hooks for the case displayed as `case` (no-op when the
/// variables are unset).
pub fn before_solve(case: &str) {
    if std::env::var(CRASH_CASE_ENV).is_ok_and(|c| c == case) {
        eprintln!("test hook {CRASH_CASE_ENV}: aborting on {case}");
        std::process::abort();
    }
    if std::env::var(HANG_CASE_ENV).is_ok_and(|c| c == case) {
        let Some(marker) = std::env::var_os(HANG_MARKER_ENV) else {
            return;
        };
        let first = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&marker)
            .is_ok();
        if first {
            eprintln!("test hook {HANG_CASE_ENV}: hanging on {case}");
            loop {
                std::thread::sleep(std::time::Duration::from_secs(3600));
            }
        }
    }
}
