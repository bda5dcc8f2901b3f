//! Deterministic shards of a sweep, for clusters (`run --shard K/N`, Slurm
//! job arrays): which cases shard K of N solves. Cases of one kernel stay
//! together where the balance allows (each shard builds as few kernels as
//! possible), and the shards' expected costs are balanced. Knows the cases
//! and their cost model; runs nothing.

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use solver::{CaseSpec, KernelKey};

use crate::case::CaseKey;
use crate::cost::{case_seconds, kernel_seconds};

/// Shard `index` of `count` (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which shard, 0-based.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl Shard {
    /// `K/N` (0 ≤ K < N), or `slurm`: `SLURM_ARRAY_TASK_ID` of
    /// `SLURM_ARRAY_TASK_COUNT` (an array `--array=0-(N-1)`).
    pub fn parse(text: &str) -> Result<Shard> {
        if text == "slurm" {
            let var = |name: &str| -> Result<usize> {
                let v = std::env::var(name).with_context(|| {
                    format!("--shard slurm: {name} is not set (not inside a Slurm job array?)")
                })?;
                v.trim()
                    .parse()
                    .with_context(|| format!("--shard slurm: {name} = {v:?} is not a number"))
            };
            let shard = Shard {
                index: var("SLURM_ARRAY_TASK_ID")?,
                count: var("SLURM_ARRAY_TASK_COUNT")?,
            };
            return shard.checked(text);
        }
        let bad = || anyhow::anyhow!("--shard {text}: expected K/N (0 ≤ K < N, e.g. 0/4) or slurm");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        Shard {
            index: k.trim().parse().map_err(|_| bad())?,
            count: n.trim().parse().map_err(|_| bad())?,
        }
        .checked(text)
    }

    fn checked(self, text: &str) -> Result<Shard> {
        if self.count == 0 || self.index >= self.count {
            bail!(
                "--shard {text}: shard {} of {} does not exist (0 ≤ K < N; Slurm arrays must start at 0)",
                self.index,
                self.count
            );
        }
        Ok(self)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The shard of each case (`cases` in config order), for `count` shards.
///
/// Cases are lined up kernel by kernel (kernels in order of first use,
/// cases in config order), each with its expected cost ([`crate::cost`];
/// each kernel's build with the first of its cases), and the line is cut into `count`
/// pieces of equal cost: a shard is balanced to within one case and touches
/// the fewest kernels a balanced cut allows (with 4 kernels and 2 or 3
/// shards, at most 2). Deterministic: the same config gives the same shards
/// anywhere. With more shards than cases some shards are empty.
pub fn assign(cases: &[(CaseKey, CaseSpec)], count: usize) -> Vec<usize> {
    let mut groups: Vec<(KernelKey, Vec<usize>)> = Vec::new();
    for (i, (_, spec)) in cases.iter().enumerate() {
        let key = KernelKey::of(spec);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(i),
            None => groups.push((key, vec![i])),
        }
    }
    // The line, and where kernels change along it (cumulative cost).
    let mut line: Vec<(usize, f64)> = Vec::with_capacity(cases.len());
    let mut boundaries = Vec::with_capacity(groups.len());
    let mut at = 0.0;
    for (_, members) in &groups {
        for (j, &i) in members.iter().enumerate() {
            let spec = &cases[i].1;
            let build = if j == 0 {
                kernel_seconds(spec.grid.n)
            } else {
                0.0
            };
            let c = build + case_seconds(spec);
            line.push((i, c));
            at += c;
        }
        boundaries.push(at);
    }
    let count = count.max(1);
    let share = at / count as f64;
    // The cuts: at equal shares, moved to a kernel boundary within 5 % of a
    // share (one kernel fewer for a shard, at a small imbalance).
    let cuts: Vec<f64> = (1..count)
        .map(|s| {
            let ideal = s as f64 * share;
            boundaries
                .iter()
                .copied()
                .filter(|b| (b - ideal).abs() <= 0.05 * share)
                .min_by(|a, b| (a - ideal).abs().total_cmp(&(b - ideal).abs()))
                .unwrap_or(ideal)
        })
        .collect();
    let mut shard_of = vec![0; cases.len()];
    let mut before = 0.0;
    for (i, c) in line {
        // The shard whose piece holds this case's midpoint.
        let mid = before + 0.5 * c;
        shard_of[i] = cuts.iter().filter(|&&cut| cut <= mid).count();
        before += c;
    }
    shard_of
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn paper() -> Vec<(CaseKey, CaseSpec)> {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../configs/paper-1c-sweep.toml"
        );
        Config::load(std::path::Path::new(path), &[])
            .unwrap()
            .cases()
            .unwrap()
    }

    #[test]
    fn shards_cover_every_case_once_and_balance_the_cost() {
        let cases = paper();
        for n in [1, 2, 3, 7, 300] {
            let of = assign(&cases, n);
            assert_eq!(of.len(), cases.len());
            assert!(of.iter().all(|&s| s < n), "N = {n}");
            // Deterministic.
            assert_eq!(of, assign(&cases, n));
            let mut load = vec![0.0; n];
            let mut kernels = vec![std::collections::BTreeSet::new(); n];
            for (i, &s) in of.iter().enumerate() {
                load[s] += case_seconds(&cases[i].1);
                kernels[s].insert(KernelKey::of(&cases[i].1));
            }
            let used = load.iter().filter(|&&l| l > 0.0).count();
            assert_eq!(used, n.min(cases.len()), "N = {n}: {used} shards used");
            let max = load.iter().cloned().fold(0.0, f64::max);
            let mean = load.iter().sum::<f64>() / used as f64;
            if n <= 7 {
                assert!(max < 1.12 * mean, "N = {n}: max {max:.1} vs mean {mean:.1}");
                // 4 kernels: a shard needs at most its share of them plus one.
                let most = 4usize.div_ceil(n) + 1;
                assert!(
                    kernels.iter().all(|k| k.len() <= most.min(4)),
                    "N = {n}: {:?}",
                    kernels.iter().map(|k| k.len()).collect::<Vec<_>>()
                );
            }
        }
        // 2 shards of 4 materials: each builds exactly two kernels.
        let of = assign(&cases, 2);
        let k0: std::collections::BTreeSet<_> = (0..cases.len())
            .filter(|&i| of[i] == 0)
            .map(|i| KernelKey::of(&cases[i].1))
            .collect();
        assert_eq!(k0.len(), 2);
    }

    #[test]
    fn shard_text_is_checked() {
        assert_eq!(Shard::parse("2/7").unwrap(), Shard { index: 2, count: 7 });
        for bad in ["7/7", "0/0", "x/2", "3", "-1/2"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        std::env::remove_var("SLURM_ARRAY_TASK_ID");
        let e = Shard::parse("slurm").unwrap_err().to_string();
        assert!(e.contains("SLURM_ARRAY_TASK_ID is not set"), "{e}");
    }
}
