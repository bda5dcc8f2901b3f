//! The expected cost of cases and kernel builds, from measured times: the
//! one cost model behind `check`'s time estimate and the balance of shards.
//! Knows the cases' kind and grid; measures nothing itself.

use solver::{CaseSpec, Surface};

/// Seconds a case takes on one worker at 384², by kind: the means of the 260
/// cases of configs/paper-1c-sweep.toml on the 2-core development machine
/// (coupled, Table 1(c) load, 2 workers; commit 19ee3eb): flat 0.87 s
/// (isotropic) and 0.88 s ((111)), patterned 0.80 s and 0.83 s. Patterned
/// cases are *not* dearer: their contact is smaller; anisotropy adds ~3 %.
fn seconds_at_384(spec: &CaseSpec) -> f64 {
    let flat = matches!(spec.surface, Surface::Flat);
    match (flat, spec.material.is_isotropic()) {
        (true, true) => 0.87,
        (true, false) => 0.88,
        (false, true) => 0.80,
        (false, false) => 0.83,
    }
}

/// A case's time grows like N^2.35 (the transforms' N² log N and the
/// iterations' slow growth with N): configs/quick.toml's cases take 0.063 s
/// on average at 128² against 0.825 s at 384², (384/128)^2.34 = 13.1.
pub const CASE_EXPONENT: f64 = 2.35;

/// An increment of a load history costs about 0.6 monotonic solves of the
/// same case (it starts next to its solution): 0.61× on Table 1(a) Fe at 256²
/// coupled (bench/fretting.sh: 0.49 s against 0.80 s), 0.59× on
/// configs/fretting-sweep.toml's 128² cases against configs/quick.toml's
/// (commit 19ee3eb; before it the monotonic solves were slower, 0.55×).
const INCREMENT_COST: f64 = 0.6;

/// Expected seconds of one case on one worker.
pub fn case_seconds(spec: &CaseSpec) -> f64 {
    let one = seconds_at_384(spec) * (spec.grid.n as f64 / 384.0).powf(CASE_EXPONENT);
    match &spec.history {
        Some(h) => {
            let segments = h.turning_points(&spec.load).len().saturating_sub(1);
            one * INCREMENT_COST * (segments * h.steps_per_segment).max(1) as f64
        }
        None => one,
    }
}

/// Expected seconds to build one kernel on an `n x n` grid: 0.35 s at 384²
/// (isotropic and (111) alike), growing like N².
pub fn kernel_seconds(n: usize) -> f64 {
    0.35 * (n as f64 / 384.0).powi(2)
}
