//! The expected cost of cases and kernel builds, from measured times: the
//! one cost model behind `check`'s time estimate and the balance of shards.
//! Knows the cases' kind and grid; measures nothing itself.

use solver::{CaseSpec, Surface};

/// Seconds a case takes on one worker at 384², by kind: the means of the 260
/// cases of configs/paper-1c-sweep.toml on the 2-core development machine
/// (coupled, Table 1(c) load): flat 1.10 s (isotropic) and 1.13 s ((111)),
/// patterned 0.92 s and 0.97 s. Patterned cases are *not* dearer: their
/// contact is smaller; anisotropy adds ~4 %.
fn seconds_at_384(spec: &CaseSpec) -> f64 {
    let flat = matches!(spec.surface, Surface::Flat);
    match (flat, spec.material.is_isotropic()) {
        (true, true) => 1.10,
        (true, false) => 1.13,
        (false, true) => 0.92,
        (false, false) => 0.97,
    }
}

/// A case's time grows like N^2.5 (the transforms' N² log N and the
/// iterations' slow growth with N): configs/quick.toml's cases take 0.064 s
/// on average at 128² against 0.98 s at 384², (384/128)^2.48 = 15.3.
const CASE_EXPONENT: f64 = 2.5;

/// An increment of a load history costs about 1.5 monotonic solves of the
/// same case: 1.3× on Table 1(a) Fe at 256² coupled (1.87 s against 1.47 s),
/// about 1.7× on configs/fretting-sweep.toml's 128² cases.
const INCREMENT_COST: f64 = 1.5;

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
