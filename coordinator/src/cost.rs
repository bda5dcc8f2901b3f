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

/// With a wear law each increment adds a normal solve on the worn surface:
/// about 0.09 of a coupled monotonic solve without coupling, nothing
/// measurable with it (bench/wear.sh at 256² of 1.25 µm, 3f916f7: 0.040 s
/// an increment uncoupled against a coupled monotonic solve's 0.44 s).
const WEAR_INCREMENT_COST: f64 = 0.09;

/// A case on a surface with a hardness costs about 1.3 elastic ones: the
/// paper's Table 1(c) surfaces at 512² took 1.19× the elastic sweep's time
/// with H = 0.9 GPa and 1.36× with 0.5 GPa (fastest of 4 rounds,
/// `bench/capped.sh`; 2.0–3.4× before the capped CG, 1.4–1.7× before it
/// kept one displacement; docs/performance.md, "A capped surface").
const CAPPED_COST: f64 = 1.3;

/// Expected seconds of one case on one worker.
pub fn case_seconds(spec: &CaseSpec) -> f64 {
    let mut one = seconds_at_384(spec) * (spec.grid.n as f64 / 384.0).powf(CASE_EXPONENT);
    if spec.limits().hardness.is_some() {
        one *= CAPPED_COST;
    }
    match &spec.history {
        Some(h) => {
            let increment = match h.wear {
                Some(_) => INCREMENT_COST + WEAR_INCREMENT_COST,
                None => INCREMENT_COST,
            };
            one * increment * spec.expected_increments() as f64
        }
        None => one,
    }
}

/// Depth kernels `[stress]` builds for each material and grid: one per
/// plane below the surface, and the surface plane (SWT and the slices' top
/// row); a sweep's worker keeps them for its later cases of that material
/// (`solver::stress_summary::StressCache`). A slice's rows need none
/// (`solver::stress::StressPlan::slice`).
pub fn stress_kernels(cfg: &crate::config::StressCfg) -> usize {
    cfg.depths_um.iter().filter(|&&z| z != 0.0).count() + 1
}

/// A crystal's stresses cost this many times an isotropic body's (its
/// roots' exponentials per frequency and depth).
const STRESS_CRYSTAL: f64 = 1.2;

/// Expected seconds of `[stress]` in one case at 256² once its material's
/// kernels are built (a sweep's worker after its first case of that
/// material), scaled as N² (the padded grid's spectra): each plane applied
/// (the surface's for SWT included) 0.025 s with its summaries, each slice
/// row 0.0025 s (`cargo run --release -p mpcontact-solver --example
/// stress_cost`, one thread, issue #51), and 4.5 ms a state whatever the
/// grid, for each state computed (`memory::stress_states`: a load
/// history's turning points). A fretting sweep of 100 cycles with
/// `stress.states = "turning"` (202 states, one plane, 41 slice rows) took
/// 7 ms a state more than with `final` at 32² and 14 ms at 64² (issue #59;
/// the N² part alone 2.4 and 9.5 ms).
pub fn stress_seconds(spec: &CaseSpec, cfg: &crate::config::StressCfg) -> f64 {
    const APPLY_S: f64 = 0.025;
    const ROW_S: f64 = 0.0025;
    const STATE_S: f64 = 0.0045;
    let rows = if cfg.slices {
        cfg.slice_rows as f64
    } else {
        0.0
    };
    let states = crate::memory::stress_states(cfg, spec) as f64;
    let per = states
        * ((APPLY_S * stress_kernels(cfg) as f64 + ROW_S * rows)
            * (spec.grid.n as f64 / 256.0).powi(2)
            + STATE_S);
    if spec.material.is_isotropic() {
        per
    } else {
        STRESS_CRYSTAL * per
    }
}

/// Expected seconds to build the depth kernels of one material at 256²,
/// scaled as N²: the surface plane 0.2 s (its near field's alias sums),
/// each plane below it 0.06 s, the periodic images' anchors of the slices
/// 0.1 s (the example `stress_cost`, issue #51).
pub fn stress_build_seconds(spec: &CaseSpec, cfg: &crate::config::StressCfg) -> f64 {
    const SURFACE_S: f64 = 0.2;
    const PLANE_S: f64 = 0.06;
    const ANCHORS_S: f64 = 0.1;
    let anchors = if cfg.slices { ANCHORS_S } else { 0.0 };
    let per = (SURFACE_S + PLANE_S * (stress_kernels(cfg) - 1) as f64 + anchors)
        * (spec.grid.n as f64 / 256.0).powi(2);
    if spec.material.is_isotropic() {
        per
    } else {
        STRESS_CRYSTAL * per
    }
}

/// Expected seconds of `[stress]` over a sweep's `specs` on `workers`
/// workers: every case's, and each material's kernels built once by each
/// worker that meets it (at most its cases), an upper bound for workers
/// that meet few materials.
pub fn stress_sweep_seconds<'a>(
    specs: impl Iterator<Item = &'a CaseSpec> + Clone,
    cfg: &crate::config::StressCfg,
    workers: usize,
) -> f64 {
    let materials = crate::memory::sweep_materials(specs.clone());
    let builds: f64 = materials
        .iter()
        .map(|(spec, cases)| stress_build_seconds(spec, cfg) * workers.min(*cases).max(1) as f64)
        .sum();
    builds + specs.map(|spec| stress_seconds(spec, cfg)).sum::<f64>()
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
    /// (one plane at 50 µm, 25 slice rows) needs the plane and the surface,
    /// 2 (the rows deeper than 5 cells need none); a plane at 0 is the
    /// surface's; no slices, no rows.
    #[test]
    fn issue51_stress_kernels_are_the_planes_and_the_surface() {
        let count = |section: &str| {
            let c = Config::parse(&format!("{BASE}[stress]\n{section}\n"), &[]).unwrap();
            super::stress_kernels(c.stress.as_ref().unwrap())
        };
        assert_eq!(count("depths_um = [50.0]\nslice_rows = 25"), 2);
        assert_eq!(count("depths_um = [0.0, 20.0]\nslices = false"), 2);
        assert_eq!(count("depths_um = [20.0]\nslices = false"), 2);
        assert_eq!(count("depths_um = [0.0]\nslices = false"), 1);
        // The measured sweep (docs/performance.md, "Stresses below the
        // surface"): Table 1(a) of Fe and Fe(111) at 0/30/60/90°, 256² of
        // 1 µm, `depths_um = [10, 25]` and the default slices, one
        // worker: 2.27 s more than without the section.
        const MEASURED_S: f64 = 2.27;
        let c = Config::parse(
            &format!(
                "{}[stress]\ndepths_um = [10.0, 25.0]\n",
                BASE.replace(
                    "[\"Fe\"]",
                    "[\"Fe\", \"Fe(111)\"]\nangles_deg = [0.0, 30.0, 60.0, 90.0]"
                )
            ),
            &[],
        )
        .unwrap();
        let cases = c.cases().unwrap();
        assert_eq!(cases.len(), 8);
        let t = super::stress_sweep_seconds(
            cases.iter().map(|(_, s)| s),
            c.stress.as_ref().unwrap(),
            1,
        );
        assert!((t / MEASURED_S - 1.0).abs() < 0.15, "{t}");
    }
}
