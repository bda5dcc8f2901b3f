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

/// Depth kernels `[stress]` builds for each case: one per plane, one per
/// slice row, and the surface plane for Smith–Watson–Topper unless a plane
/// is at 0.
pub fn stress_kernels(cfg: &crate::config::StressCfg) -> usize {
    let surface = usize::from(!cfg.depths_um.contains(&0.0));
    cfg.depths_um.len() + if cfg.slices { cfg.slice_rows } else { 0 } + surface
}

/// Expected seconds of `[stress]` in one case: its depth kernels at 0.54 s
/// each at 256² for an isotropic substrate (Fe, Table 1(a), 27 kernels:
/// `solve --threads 1` 15.8 s with the section, 1.15 s without), 1.3 times
/// that for a crystal (Fe(111) against Fe in the same sweep), growing like
/// N² (the padded grid's spectra; the transforms' log N aside).
pub fn stress_seconds(spec: &CaseSpec, cfg: &crate::config::StressCfg) -> f64 {
    let per = 0.54 * (spec.grid.n as f64 / 256.0).powi(2);
    let per = if spec.material.is_isotropic() {
        per
    } else {
        1.3 * per
    };
    per * stress_kernels(cfg) as f64
}

/// Expected seconds to build one kernel on an `n x n` grid: 0.35 s at 384²
/// (isotropic and (111) alike), growing like N².
pub fn kernel_seconds(n: usize) -> f64 {
    0.35 * (n as f64 / 384.0).powi(2)
}

#[cfg(test)]
mod tests {
    use crate::config::Config;

    const BASE: &str = "[grid]\npoints = 256\nspacing_um = 1.0\n[indenter]\nradius_mm = 18.0\n[load]\nnormal_n = 20.0\nfriction = 0.3\n[sweep]\nmaterials = [\"Fe\"]\n";

    /// The kernels `[stress]` builds, counted by hand: Table 1(a)'s section
    /// (one plane at 50 µm, 25 slice rows) needs the surface too, 27; a
    /// plane at 0 serves SWT; no slices, no rows.
    #[test]
    fn issue38_stress_kernels_are_planes_rows_and_the_surface() {
        let count = |section: &str| {
            let c = Config::parse(&format!("{BASE}[stress]\n{section}\n"), &[]).unwrap();
            super::stress_kernels(c.stress.as_ref().unwrap())
        };
        assert_eq!(count("depths_um = [50.0]\nslice_rows = 25"), 27);
        assert_eq!(count("depths_um = [0.0, 20.0]\nslices = false"), 2);
        assert_eq!(count("depths_um = [20.0]\nslices = false"), 2);
        // The measured case: 27 kernels at 256², 15.8 − 1.15 s.
        let c = Config::parse(
            &format!("{BASE}[stress]\ndepths_um = [50.0]\nslice_rows = 25\n"),
            &[],
        )
        .unwrap();
        let (_, spec) = &c.cases().unwrap()[0];
        let t = super::stress_seconds(spec, c.stress.as_ref().unwrap());
        assert!((t / (15.8 - 1.15) - 1.0).abs() < 0.05, "{t}");
    }
}
