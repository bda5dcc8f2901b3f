//! `journal.jsonl`: the append-only record of finished cases that `--resume`
//! reads. One JSON object per line; the first line is the header with the
//! config echo. Every record is flushed and synced before the coordinator
//! acknowledges the result. Owns only this file and its line format; which
//! case a line belongs to is decided by `record`, not here.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use solver::CaseScalars;

use crate::case::{CaseKey, Status};

/// File name inside the output directory.
pub const JOURNAL_FILE: &str = "journal.jsonl";

/// How one case ended: everything the journal keeps about it besides its key.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// `ok`, `not_converged` or `failed`.
    pub status: Status,
    /// Why it failed (status `failed`).
    pub error: Option<String>,
    /// Worker that produced it.
    pub worker: u32,
    /// Solve wall time in the worker, s.
    pub seconds: f64,
    /// Kernels the worker had computed itself when it sent this (the
    /// wire's `kernels_built`; in journals written before issue #47, the
    /// kernels it had made resident, loads included).
    pub kernel_builds: u64,
    /// Scalars as computed by the worker (μa before K_E calibration).
    pub scalars: Option<CaseScalars>,
    /// With `[stress]`: the stress scalars the worker computed (absent
    /// from the journal line otherwise, so sweeps without the section
    /// journal as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<solver::stress_summary::StressScalars>,
}

impl Outcome {
    /// A failure without scalars.
    pub fn failed(error: String, worker: usize, seconds: f64, kernel_builds: u64) -> Self {
        Outcome {
            status: Status::Failed,
            error: Some(error),
            worker: worker as u32,
            seconds,
            kernel_builds,
            scalars: None,
            stress: None,
        }
    }
}

/// One finished case as a journal line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// The key's display text (`Cu/flat/015.0`), for people reading the
    /// file; the only identity in journals written before typed keys.
    pub case_id: String,
    /// The case (absent in journals of older builds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub key: Option<CaseKey>,
    /// How it ended.
    #[serde(flatten)]
    pub outcome: Outcome,
}

impl Entry {
    /// The line of `key` with `outcome`.
    pub fn new(key: &CaseKey, outcome: Outcome) -> Self {
        Entry {
            case_id: key.to_string(),
            key: Some(key.clone()),
            outcome,
        }
    }
}

/// How every journal's first line (its header) begins.
const HEADER_START: &str = "{\"kind\":\"header\"";

/// The first protocol whose results hold the zones' own radii apart from
/// μa's (issue #59; 7 was #61's resampled surfaces): the journals of
/// earlier ones do not resume.
const RADII_SPLIT_VERSION: u32 = 8;

/// Refuses a journal at `path` written with `protocol_version` when its
/// results cannot be read as this build's.
fn check_version(path: &Path, protocol_version: u32) -> anyhow::Result<()> {
    if protocol_version < RADII_SPLIT_VERSION {
        bail!(
            "{} was written by an earlier build (protocol {protocol_version}), whose contact_radius_m and stick_radius_m were μa's apparent radii (now mu_a_contact_radius_m, mu_a_stick_radius_m; issue #59); run the sweep again into another --out",
            path.display()
        );
    }
    Ok(())
}

/// A journal line.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Line {
    /// First line.
    Header {
        /// Run that created the journal.
        run_id: String,
        /// The config text, for the resume comparison.
        config: String,
        /// Protocol version of the writer.
        protocol_version: u32,
    },
    /// A finished case.
    Case(Box<Entry>),
}

/// The open journal.
pub struct Journal {
    file: File,
    path: PathBuf,
    /// Test hook (fault injection, tests only): sleep this long after each
    /// sync, as on a slow disk; see `worker::test_journal_sync_delay`.
    test_sync_delay: Option<std::time::Duration>,
}

/// What a previous run left in the journal.
#[derive(Debug, Default)]
pub struct Previous {
    /// Run id of the first run.
    pub run_id: Option<String>,
    /// Case lines in order (the last one wins for a repeated case).
    pub entries: Vec<Entry>,
    /// A torn last line was dropped.
    pub torn_tail: bool,
}

pub(crate) fn first_difference(a: &str, b: &str) -> String {
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    for i in 0..la.len().max(lb.len()) {
        let (x, y) = (la.get(i).copied(), lb.get(i).copied());
        if x != y {
            return format!(
                "line {}: journalled {:?}, now {:?}",
                i + 1,
                x.unwrap_or("<none>"),
                y.unwrap_or("<none>")
            );
        }
    }
    "whitespace only".into()
}

impl Journal {
    /// Start a new journal (fails when one exists and `resume` is false), or
    /// reopen an existing one for `--resume`, checking that it was written
    /// for the same config and dropping a torn last line. Refusals name the
    /// caller's options (`names`: the CLI's flags or Python's keywords).
    pub fn open(
        out_dir: &Path,
        run_id: &str,
        config: &str,
        resume: bool,
        names: super::OptionNames,
    ) -> anyhow::Result<(Journal, Previous)> {
        let super::OptionNames {
            resume: resume_opt,
            out: out_opt,
        } = names;
        let path = out_dir.join(JOURNAL_FILE);
        let mut prev = Previous::default();
        if path.exists() {
            if !resume {
                bail!(
                    "{} already holds a sweep ({}); use {resume_opt} to continue it or another {out_opt}",
                    out_dir.display(),
                    JOURNAL_FILE
                );
            }
            let text = std::fs::read(&path)
                .with_context(|| format!("while reading {}", path.display()))?;
            // A journal starts with our header line; anything else is not
            // ours, even when it is one line without an end (which would
            // otherwise pass for a torn line and be wiped).
            let n = text.len().min(HEADER_START.len());
            if text[..n] != HEADER_START.as_bytes()[..n] {
                bail!(
                    "{resume_opt} refused: {} is not an mpcontact journal (it does not start with {HEADER_START}); move it away or choose another {out_opt}",
                    path.display()
                );
            }
            let mut good_len = 0usize;
            let mut lines = text.split_inclusive(|&b| b == b'\n').peekable();
            let mut first = true;
            while let Some(raw) = lines.next() {
                let last = lines.peek().is_none();
                let parsed = std::str::from_utf8(raw)
                    .ok()
                    .filter(|s| s.ends_with('\n'))
                    .and_then(|s| serde_json::from_str::<Line>(s.trim_end()).ok());
                match parsed {
                    Some(Line::Header {
                        run_id: old,
                        config: old_cfg,
                        protocol_version,
                    }) if first => {
                        check_version(&path, protocol_version).context("--resume refused")?;
                        if old_cfg != config {
                            bail!(
                                "{resume_opt} refused: {} was written for a different config ({})",
                                path.display(),
                                first_difference(&old_cfg, config)
                            );
                        }
                        prev.run_id = Some(old);
                    }
                    Some(Line::Case(r)) if !first => prev.entries.push(*r),
                    _ if last => {
                        prev.torn_tail = true;
                        break;
                    }
                    _ => bail!(
                        "{} is corrupt at byte {good_len}; move it away to start afresh",
                        path.display()
                    ),
                }
                first = false;
                good_len += raw.len();
            }
            let file = OpenOptions::new()
                .write(true)
                .open(&path)
                .with_context(|| format!("while opening {}", path.display()))?;
            file.set_len(good_len as u64)?;
            drop(file);
            let mut j = Journal {
                file: OpenOptions::new().append(true).open(&path)?,
                path,
                test_sync_delay: worker::test_journal_sync_delay(),
            };
            if good_len == 0 {
                j.append(&Line::Header {
                    run_id: run_id.to_string(),
                    config: config.to_string(),
                    protocol_version: protocol::PROTOCOL_VERSION,
                })?;
            }
            return Ok((j, prev));
        }
        let file = OpenOptions::new()
            .create_new(true)
            .append(true)
            .open(&path)
            .with_context(|| format!("while creating {}", path.display()))?;
        let mut j = Journal {
            file,
            path,
            test_sync_delay: worker::test_journal_sync_delay(),
        };
        j.append(&Line::Header {
            run_id: run_id.to_string(),
            config: config.to_string(),
            protocol_version: protocol::PROTOCOL_VERSION,
        })?;
        Ok((j, prev))
    }

    /// Append one line and sync it to disk.
    pub fn append(&mut self, line: &Line) -> anyhow::Result<()> {
        let mut text = serde_json::to_string(line)?;
        text.push('\n');
        self.file
            .write_all(text.as_bytes())
            .and_then(|_| self.file.sync_data())
            .with_context(|| format!("while appending to {}", self.path.display()))?;
        if let Some(delay) = self.test_sync_delay {
            std::thread::sleep(delay);
        }
        Ok(())
    }

    /// The config text of a journal's header line.
    pub fn read_config(path: &Path) -> anyhow::Result<String> {
        let f = File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
        let first = BufReader::new(f)
            .lines()
            .next()
            .transpose()?
            .unwrap_or_default();
        match serde_json::from_str::<Line>(&first) {
            Ok(Line::Header { config, .. }) => Ok(config),
            _ => bail!("{} does not start with a journal header", path.display()),
        }
    }

    /// Read all case lines of a journal file (tests, tools).
    pub fn read_entries(path: &Path) -> anyhow::Result<Vec<Entry>> {
        let f = File::open(path)?;
        let mut out = Vec::new();
        for line in BufReader::new(f).lines() {
            match serde_json::from_str::<Line>(&line?) {
                Ok(Line::Case(r)) => out.push(*r),
                Ok(Line::Header {
                    protocol_version, ..
                }) => check_version(path, protocol_version)?,
                Err(_) => {}
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::OptionNames;

    fn tmp(name: &str) -> tempfile::TempDir {
        // Removed when dropped: tests leave nothing in the system temp dir.
        tempfile::Builder::new()
            .prefix(&format!("mpc-{name}-"))
            .tempdir()
            .unwrap()
    }

    fn rec(id: &str) -> Entry {
        Entry::new(
            &CaseKey::new(id, "flat", 15.0),
            Outcome {
                status: Status::Ok,
                error: None,
                worker: 0,
                seconds: 0.1,
                kernel_builds: 1,
                scalars: Some(CaseScalars::default()),
                stress: None,
            },
        )
    }

    #[test]
    fn resume_reads_records_and_drops_torn_tail() {
        let tmp_dir = tmp("torn");
        let d = tmp_dir.path().to_path_buf();
        {
            let (mut j, prev) = Journal::open(&d, "r1", "cfg", false, OptionNames::CLI).unwrap();
            assert!(prev.entries.is_empty());
            j.append(&Line::Case(Box::new(rec("a")))).unwrap();
            j.append(&Line::Case(Box::new(rec("b")))).unwrap();
        }
        let p = d.join(JOURNAL_FILE);
        let mut text = std::fs::read_to_string(&p).unwrap();
        text.push_str("{\"kind\":\"case\",\"case_id\":\"c\"");
        std::fs::write(&p, text).unwrap();
        let refusal = |names| {
            format!(
                "{:#}",
                Journal::open(&d, "r2", "cfg", false, names).err().unwrap()
            )
        };
        let cli = refusal(OptionNames::CLI);
        assert!(
            cli.contains("use --resume to continue it or another --out"),
            "{cli}"
        );
        // Python's `run` names its own keywords, not the CLI's flags.
        let python = refusal(OptionNames::PYTHON);
        assert!(
            python.contains("use resume=True to continue it or another out="),
            "{python}"
        );
        let (mut j, prev) = Journal::open(&d, "r2", "cfg", true, OptionNames::CLI).unwrap();
        assert!(prev.torn_tail);
        assert_eq!(prev.entries.len(), 2);
        assert_eq!(prev.entries[1], rec("b"));
        j.append(&Line::Case(Box::new(rec("c")))).unwrap();
        assert_eq!(Journal::read_entries(&p).unwrap().len(), 3);
    }

    #[test]
    fn issue20_item11_a_one_line_file_that_is_not_ours_is_not_wiped() {
        let tmp_dir = tmp("foreign");
        let d = tmp_dir.path().to_path_buf();
        let p = d.join(JOURNAL_FILE);
        for foreign in ["my notes, no newline", "{\"kind\":\"case\"}\n", "x"] {
            std::fs::write(&p, foreign).unwrap();
            let e = format!(
                "{:#}",
                Journal::open(&d, "r", "cfg", true, OptionNames::CLI)
                    .err()
                    .unwrap()
            );
            assert!(e.contains("not an mpcontact journal"), "{e}");
            assert_eq!(
                std::fs::read_to_string(&p).unwrap(),
                foreign,
                "left as it was"
            );
        }
        // A header torn while being written is ours: resumed afresh.
        std::fs::write(&p, "{\"kind\":\"hea").unwrap();
        let (_, prev) = Journal::open(&d, "r", "cfg", true, OptionNames::CLI).unwrap();
        assert!(prev.torn_tail && prev.entries.is_empty());
    }

    #[test]
    fn new_lines_carry_the_typed_key_and_the_display_text() {
        let text = serde_json::to_string(&Line::Case(Box::new(rec("Cu")))).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["case_id"], "Cu/flat/015.0");
        assert_eq!(v["key"]["material"], "Cu");
        assert_eq!(v["key"]["surface"], "flat");
        assert_eq!(v["key"]["angle_deg"], 15.0);
        assert_eq!(v["status"], "ok");
    }

    #[test]
    fn lines_of_older_builds_still_read() {
        let old = r#"{"kind":"case","case_id":"Cu/flat/015.0","status":"not-converged","error":null,"worker":1,"seconds":0.5,"kernel_builds":1,"scalars":null}"#;
        let Line::Case(e) = serde_json::from_str::<Line>(old).unwrap() else {
            panic!("not a case line")
        };
        assert_eq!(e.case_id, "Cu/flat/015.0");
        assert_eq!(e.key, None);
        assert_eq!(e.outcome.status, Status::NotConverged);
        assert_eq!(e.outcome.worker, 1);
    }

    #[test]
    fn resume_with_other_config_is_refused_naming_the_line() {
        let tmp_dir = tmp("cfg");
        let d = tmp_dir.path().to_path_buf();
        drop(Journal::open(&d, "r1", "a = 1\nb = 2\n", false, OptionNames::CLI).unwrap());
        let err = Journal::open(&d, "r2", "a = 1\nb = 3\n", true, OptionNames::CLI)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("line 2"), "{err}");
    }
}
