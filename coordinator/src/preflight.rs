//! The first moments of every case of a sweep, before it starts: what
//! `solve` and a sweep's workers would refuse within them (a contact at the
//! domain's edge, a normal solve that loses contact), found by
//! `solver::preflight` on each case — the frictionless normal contact only.
//! `check`, `run --dry-run` and `run` call it. `check` writes nothing
//! (kernels are read from the store when it holds them, never stored);
//! `run` stores the kernels it builds, which its workers then load.

use anyhow::{anyhow, Result};
use solver::{CaseSpec, KernelCache, KernelKey, KernelStore, Spectra};

use crate::case::CaseKey;

/// What the first moments of a sweep's cases found, all of them accepted.
#[derive(Clone, Debug)]
pub struct Preflight {
    /// Cases checked.
    pub cases: usize,
    /// The case whose frictionless contact reaches furthest towards the
    /// domain's edge, and how far ([`solver::Preflight::reach`]: 1 is the
    /// outermost ring, which a solve refuses).
    pub widest: Option<(CaseKey, f64)>,
    /// Seconds it took.
    pub seconds: f64,
}

/// The kernel store, read only: a cached kernel is loaded (the same bits a
/// build gives), a missing one is built and forgotten; the store's
/// directory is not even created.
struct ReadOnly(worker::kernel_store::FileStore);

impl KernelStore for ReadOnly {
    fn load(&self, key: &KernelKey, len: usize) -> Option<Spectra> {
        // `holds` only opens the entry; `load` alone would first make the
        // store's directory.
        self.0.holds(key).then(|| self.0.load(key, len)).flatten()
    }

    fn save(&self, _key: &KernelKey, _spectra: &Spectra) {}
}

/// At most this many refused cases are named in the error; the rest are counted.
const NAMED: usize = 5;

/// Whether the pre-flight may add the kernels it builds to the store.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernels {
    /// Read the store only (`check`, `run --dry-run`: they write nothing).
    ReadOnly,
    /// Store what is built (`run`: its workers load them instead of
    /// building them, so the pre-flight costs only its normal solves).
    Store,
}

/// Runs the first moments of every case in `cases` on all cores, one
/// kernel resident at a time; refuses the sweep when any case is refused,
/// naming each (up to [`NAMED`]) with the message its solve would give
/// (`Fe/flat/000.0: the contact reaches the edge of the domain (…)`).
pub fn check<'a>(
    cases: impl IntoIterator<Item = (&'a CaseKey, &'a CaseSpec)>,
    kernels: Kernels,
) -> Result<Preflight> {
    let started = std::time::Instant::now();
    let threads = solver::Threads::new(solver::Threads::available())
        .map_err(|e| anyhow!("pre-flight threads: {e}"))?;
    // One kernel at a time (a sweep over orientations has dozens); within
    // one, the cases that share a contact from rest one after the other,
    // so that the normal solver's kept solution serves all but the first
    // (`solver::normal::solve_normal_from_rest`, the same bits).
    let mut order: Vec<(usize, (&CaseKey, &CaseSpec))> = cases.into_iter().enumerate().collect();
    let total = order.len();
    order.sort_by_cached_key(|(_, (key, spec))| {
        let load = key.normal_n.map(f64::to_bits);
        (
            KernelKey::of(spec),
            key.level,
            key.material.clone(),
            key.surface.clone(),
            load,
        )
    });
    let store = worker::kernel_store::FileStore::default_location();
    let mut cache: Option<(KernelKey, KernelCache)> = None;
    let mut widest: Option<(CaseKey, f64)> = None;
    let mut refused: Vec<(usize, String)> = Vec::new();
    for (index, (key, spec)) in order {
        let kernel = KernelKey::of(spec);
        if cache.as_ref().is_none_or(|(k, _)| *k != kernel) {
            // The previous kernel goes before the next is made.
            drop(cache.take());
            let mut c = match (&store, kernels) {
                (Some(dir), Kernels::ReadOnly) => KernelCache::with_store(Box::new(ReadOnly(
                    worker::kernel_store::FileStore::new(dir.clone()),
                ))),
                (Some(dir), Kernels::Store) => KernelCache::with_store(Box::new(
                    worker::kernel_store::FileStore::new(dir.clone()),
                )),
                (None, _) => KernelCache::new(),
            };
            c.set_threads(threads.clone());
            cache = Some((kernel, c));
        }
        let (_, c) = cache.as_mut().expect("made above");
        match solver::preflight(spec, c) {
            Ok(found) => {
                if widest.as_ref().is_none_or(|(_, r)| found.reach > *r) {
                    widest = Some(((*key).clone(), found.reach));
                }
            }
            Err(e) => refused.push((index, format!("{key}: {e}"))),
        }
    }
    if !refused.is_empty() {
        // Named in the sweep's order.
        refused.sort();
        let count = refused.len();
        let mut text = refused
            .into_iter()
            .take(NAMED)
            .map(|(_, line)| line)
            .collect::<Vec<_>>()
            .join("\n  ");
        if count > NAMED {
            text.push_str(&format!("\n  … and {} more", count - NAMED));
        }
        let of = if total > 1 {
            format!("\n({count} of {total} cases refused in their first moments, before any was solved)")
        } else {
            String::new()
        };
        return Err(anyhow!("{text}{of}"));
    }
    Ok(Preflight {
        cases: total,
        widest,
        seconds: started.elapsed().as_secs_f64(),
    })
}
