//! Shards of a sweep and their merge (`run --shard K/N`, `mpcontact merge`):
//! what a shard's directory says about itself (`shard.json`), and the
//! checks and outputs of a merge — the same files a single run of the config
//! writes, from the shards' journals. Solves nothing; starts no worker.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};

use super::journal::{first_difference, Journal, Outcome, JOURNAL_FILE};
use super::lock::DirLock;
use super::plan::Plan;
use super::summary::RunSummary;
use crate::config::Config;
use crate::shard::Shard;

/// A shard's description, in its output directory.
pub const SHARD_FILE: &str = "shard.json";

/// What `shard.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// Which shard of how many.
    pub shard: Shard,
    /// The config's directory (relative paths in it, e.g. height maps).
    pub config_dir: PathBuf,
}

/// Writes `shard.json` into a shard's output directory; a resumed shard
/// must be the same shard.
pub(super) fn write_shard_info(
    out_dir: &Path,
    shard: Shard,
    config_dir: &Path,
) -> anyhow::Result<()> {
    let path = out_dir.join(SHARD_FILE);
    let info = ShardInfo {
        shard,
        config_dir: std::fs::canonicalize(config_dir).unwrap_or_else(|_| config_dir.to_path_buf()),
    };
    if let Ok(text) = std::fs::read_to_string(&path) {
        if let Ok(old) = serde_json::from_str::<ShardInfo>(&text) {
            if old.shard != shard {
                bail!(
                    "{} holds shard {} of the sweep, not {shard}; use another --out",
                    out_dir.display(),
                    old.shard
                );
            }
        }
    }
    crate::output::atomic::write(
        &path,
        (serde_json::to_string_pretty(&info)? + "\n").as_bytes(),
    )
}

/// One shard as read for a merge.
struct ShardRun {
    dir: PathBuf,
    info: ShardInfo,
    config: String,
    _lock: DirLock,
}

fn read_shard(dir: &Path) -> anyhow::Result<ShardRun> {
    let name = dir.display();
    let info: ShardInfo = serde_json::from_str(
        &std::fs::read_to_string(dir.join(SHARD_FILE))
            .with_context(|| format!("{name} is not a shard of a sweep (no {SHARD_FILE})"))?,
    )
    .with_context(|| format!("{name}/{SHARD_FILE} is not readable"))?;
    let lock = DirLock::take(dir).with_context(|| format!("shard {name} is still running"))?;
    let config = Journal::read_config(&dir.join(JOURNAL_FILE))
        .with_context(|| format!("shard {name} has no journal"))?;
    Ok(ShardRun {
        dir: dir.to_path_buf(),
        info,
        config,
        _lock: lock,
    })
}

/// Merges the shards in `dirs` into `out_dir`: checks that they come from
/// one config, that all N shards are there once, and that together they
/// record every case exactly once; then writes `results.csv`, `curves.csv`,
/// `summary.json` and the plots as a single run of the config would (the K_E
/// calibration of anisotropic cases uses the flat cases of any shard).
pub fn merge_shards(dirs: &[PathBuf], out_dir: &Path) -> anyhow::Result<RunSummary> {
    anyhow::ensure!(!dirs.is_empty(), "merge: name the shard directories");
    let mut seen = std::collections::BTreeSet::new();
    for d in dirs {
        if !seen.insert(std::fs::canonicalize(d).unwrap_or_else(|_| d.clone())) {
            bail!("shard {} is given twice", d.display());
        }
    }
    let shards = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let first = &shards[0];
    for s in &shards[1..] {
        if s.config != first.config {
            bail!(
                "shards {} and {} come from different configs ({})",
                first.dir.display(),
                s.dir.display(),
                first_difference(&first.config, &s.config)
            );
        }
        if s.info.shard.count != first.info.shard.count {
            bail!(
                "shard {} is one of {} shards, shard {} one of {}",
                s.dir.display(),
                s.info.shard.count,
                first.dir.display(),
                first.info.shard.count
            );
        }
    }
    let count = first.info.shard.count;
    let mut by_index: BTreeMap<usize, &ShardRun> = BTreeMap::new();
    for s in &shards {
        if let Some(other) = by_index.insert(s.info.shard.index, s) {
            bail!(
                "shard {} is given twice: {} and {}",
                s.info.shard,
                other.dir.display(),
                s.dir.display()
            );
        }
    }
    let missing: Vec<String> = (0..count)
        .filter(|k| !by_index.contains_key(k))
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        bail!("missing shard(s) {} of {count}", missing.join(", "));
    }
    let config = Config::parse_in(&first.config, &[], &first.info.config_dir)
        .context("the shards' config")?;
    let cases = config.cases()?;
    let of = crate::shard::assign(&cases, count);
    let plan = Plan::new(cases);
    let mut outcomes: Vec<Option<Outcome>> = vec![None; plan.cases.len()];
    let mut owner: Vec<Option<&Path>> = vec![None; plan.cases.len()];
    for s in &shards {
        for entry in Journal::read_entries(&s.dir.join(JOURNAL_FILE))? {
            let i = match &entry.key {
                Some(key) => plan.index_of(key),
                None => plan.index_of_display(&entry.case_id),
            }
            .with_context(|| {
                format!(
                    "shard {} records {}, which is not a case of the config",
                    s.dir.display(),
                    entry.case_id
                )
            })?;
            if let Some(other) = owner[i] {
                bail!(
                    "case {} is recorded by two shards: {} and {}",
                    entry.case_id,
                    other.display(),
                    s.dir.display()
                );
            }
            owner[i] = Some(&s.dir);
            outcomes[i] = Some(entry.outcome);
        }
    }
    let lost: Vec<String> = (0..plan.cases.len())
        .filter(|&i| outcomes[i].is_none())
        .map(|i| format!("{} (shard {}/{count})", plan.cases[i].key, of[i]))
        .collect();
    if !lost.is_empty() {
        let shown = lost.iter().take(10).cloned().collect::<Vec<_>>().join(", ");
        bail!(
            "{} case(s) not recorded by any shard: {shown}{}; resume those shards with --resume",
            lost.len(),
            if lost.len() > 10 { ", …" } else { "" }
        );
    }
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("cannot create the output directory {}", out_dir.display()))?;
    let mut summary = RunSummary {
        run_id: format!("merge of {count} shards"),
        out_dir: out_dir.to_path_buf(),
        total: plan.cases.len(),
        ..Default::default()
    };
    summary.tally(&plan.cases, &outcomes);
    let orientations = config.orientations()?;
    super::write_outputs(
        out_dir,
        &plan.cases,
        &outcomes,
        &mut summary,
        &first.config,
        &orientations,
    )?;
    Ok(summary)
}
