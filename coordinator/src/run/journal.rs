//! `journal.jsonl`: the append-only record of finished cases that `--resume`
//! reads. One JSON object per line; the first line is the header with the
//! config echo. Every record is flushed and synced before the coordinator
//! acknowledges the result. Owns only this file.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use solver::CaseScalars;

/// File name inside the output directory.
pub const JOURNAL_FILE: &str = "journal.jsonl";

/// One finished case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Case identity.
    pub case_id: String,
    /// `ok`, `not_converged` or `failed`.
    pub status: String,
    /// Why it failed (status `failed`).
    pub error: Option<String>,
    /// Worker that produced it.
    pub worker: u32,
    /// Solve wall time in the worker, s.
    pub seconds: f64,
    /// Kernels the worker had built when it sent this.
    pub kernel_builds: u64,
    /// Scalars as computed by the worker (μa before K_E calibration).
    pub scalars: Option<CaseScalars>,
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
    Case(Box<Record>),
}

/// The open journal.
pub struct Journal {
    file: File,
    path: PathBuf,
}

/// What a previous run left in the journal.
#[derive(Debug, Default)]
pub struct Previous {
    /// Run id of the first run.
    pub run_id: Option<String>,
    /// Records in order (the last one wins for a repeated id).
    pub records: Vec<Record>,
    /// A torn last line was dropped.
    pub torn_tail: bool,
}

fn first_difference(a: &str, b: &str) -> String {
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
    /// for the same config and dropping a torn last line.
    pub fn open(
        out_dir: &Path,
        run_id: &str,
        config: &str,
        resume: bool,
    ) -> anyhow::Result<(Journal, Previous)> {
        let path = out_dir.join(JOURNAL_FILE);
        let mut prev = Previous::default();
        if path.exists() {
            if !resume {
                bail!(
                    "{} already holds a sweep ({}); use --resume to continue it or another --out",
                    out_dir.display(),
                    JOURNAL_FILE
                );
            }
            let text = std::fs::read(&path)
                .with_context(|| format!("while reading {}", path.display()))?;
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
                        ..
                    }) if first => {
                        if old_cfg != config {
                            bail!(
                                "--resume refused: {} was written for a different config ({})",
                                path.display(),
                                first_difference(&old_cfg, config)
                            );
                        }
                        prev.run_id = Some(old);
                    }
                    Some(Line::Case(r)) if !first => prev.records.push(*r),
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
        let mut j = Journal { file, path };
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
            .with_context(|| format!("while appending to {}", self.path.display()))
    }

    /// Read all case records of a journal file (tests, tools).
    pub fn read_records(path: &Path) -> anyhow::Result<Vec<Record>> {
        let f = File::open(path)?;
        let mut out = Vec::new();
        for line in BufReader::new(f).lines() {
            if let Ok(Line::Case(r)) = serde_json::from_str::<Line>(&line?) {
                out.push(*r);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("mpc-journal-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn rec(id: &str) -> Record {
        Record {
            case_id: id.into(),
            status: "ok".into(),
            error: None,
            worker: 0,
            seconds: 0.1,
            kernel_builds: 1,
            scalars: Some(CaseScalars::default()),
        }
    }

    #[test]
    fn resume_reads_records_and_drops_torn_tail() {
        let d = tmp("torn");
        {
            let (mut j, prev) = Journal::open(&d, "r1", "cfg", false).unwrap();
            assert!(prev.records.is_empty());
            j.append(&Line::Case(Box::new(rec("a")))).unwrap();
            j.append(&Line::Case(Box::new(rec("b")))).unwrap();
        }
        let p = d.join(JOURNAL_FILE);
        let mut text = std::fs::read_to_string(&p).unwrap();
        text.push_str("{\"kind\":\"case\",\"case_id\":\"c\"");
        std::fs::write(&p, text).unwrap();
        assert!(
            Journal::open(&d, "r2", "cfg", false).is_err(),
            "needs --resume"
        );
        let (mut j, prev) = Journal::open(&d, "r2", "cfg", true).unwrap();
        assert!(prev.torn_tail);
        assert_eq!(prev.records.len(), 2);
        j.append(&Line::Case(Box::new(rec("c")))).unwrap();
        assert_eq!(Journal::read_records(&p).unwrap().len(), 3);
    }

    #[test]
    fn resume_with_other_config_is_refused_naming_the_line() {
        let d = tmp("cfg");
        drop(Journal::open(&d, "r1", "a = 1\nb = 2\n", false).unwrap());
        let err = Journal::open(&d, "r2", "a = 1\nb = 3\n", true)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("line 2"), "{err}");
    }
}
