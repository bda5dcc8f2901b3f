//! Will the workers fit in memory? An estimate of one worker's peak from the
//! grid and the kernels it keeps, checked against what the machine has
//! available before any worker starts, so that a sweep is refused with the
//! numbers instead of starting workers that cannot finish. Owns no files
//! but `/proc/meminfo`, which it only reads.

use anyhow::{bail, Result};

/// Peak bytes per grid cell of a worker solving a coupled case with one
/// resident kernel: measured peaks 131.2 MB at 512² (500 B/cell), 502 MB at
/// 1024² (479) and 1.92 GB at 2048² (458), docs/performance.md; 520 leaves
/// a margin.
const BYTES_PER_CELL: f64 = 520.0;

/// Bytes per cell of each further resident kernel (another material): the
/// stored spectra (144 B/cell), the coarse levels and plans.
const KERNEL_BYTES_PER_CELL: f64 = 180.0;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Estimated peak bytes of one worker on an `n x n` grid holding `kernels`
/// kernels (at least one).
pub fn worker_bytes(n: usize, kernels: usize) -> f64 {
    let cells = (n * n) as f64;
    cells * (BYTES_PER_CELL + KERNEL_BYTES_PER_CELL * kernels.saturating_sub(1) as f64)
}

/// Estimated extra peak bytes of `[stress]` in a worker on an `n x n` grid
/// for a sweep of `materials` materials (counted from the arrays, B per
/// cell): the depth kernels a worker keeps between cases
/// (`solver::stress_summary::StressCache`: the surface's and the
/// requested planes' of each material, 576 each, within
/// `KEPT_PLANE_BYTES`, the current material's surface beyond it) and one
/// more in flight when they do not all fit, the transforms' scratch (256),
/// per state the traction spectra (96) and its planes (48 each, the
/// surface's for SWT included) and its slices' rows (48 B a point, two
/// lines of `n`), the slices' partial transforms of a batch of states,
/// the Crossland and SWT maps (8 each), and a history's turning points'
/// tractions (24 each).
/// 256², Fe and Fe(111), one state, two planes and 41 slice rows (Table
/// 1(a) with `[stress]`): 307 MB with the solve's kernels, 355 MB peak RSS
/// measured of a worker of `mpcontact run --workers 2` (issue #51,
/// docs/performance.md; the allocator's slack is not counted). The states
/// and materials are those of the cases `specs` (`stress_states`,
/// `sweep_materials`); every state is held until the case's fields are
/// written (Crossland's parameter reads them all at each point).
pub fn stress_bytes<'a>(
    n: usize,
    cfg: &crate::config::StressCfg,
    specs: impl Iterator<Item = &'a solver::CaseSpec> + Clone,
) -> f64 {
    let states = specs
        .clone()
        .map(|s| stress_states(cfg, s))
        .max()
        .unwrap_or(1);
    let materials = sweep_materials(specs.clone()).len();
    let cells = (n * n) as f64;
    let planes = (cfg.depths_um.len() + 1) as f64;
    let kernel = 576.0 * cells;
    let wanted = planes * materials.max(1) as f64 * kernel;
    let budget = solver::stress_summary::KEPT_PLANE_BYTES.max(kernel);
    let kernels = if wanted <= budget {
        wanted
    } else {
        budget + kernel
    };
    let rows = if cfg.slices { cfg.slice_rows } else { 0 };
    let state = cells * (96.0 + 48.0 * planes) + 2.0 * (rows * n) as f64 * 48.0;
    // The slices' partial transforms of a batch of states (the rows below
    // the surface; `solver::stress::SLICE_BATCH_BYTES`).
    let sliced = match rows.saturating_sub(1) {
        0 => 0.0,
        below => {
            let each = solver::stress::slice_state_bytes(n, below, 2);
            let batch = (solver::stress::SLICE_BATCH_BYTES / each).max(1);
            (each * batch.min(states.max(1))) as f64
        }
    };
    // The tractions of every turning point of a history (three fields),
    // kept by the solve for the stresses whichever states are chosen:
    // 49 MB for 1000 fretting cycles at 32², measured 91 MB peak with the
    // default `last_cycle` (issue #59).
    let turning = specs
        .clone()
        .filter_map(|s| s.history.as_ref().map(|h| h.turning_points(&s.load).len()))
        .max()
        .unwrap_or(0);
    kernels
        + cells * (256.0 + 8.0 * (planes + 1.0) + 24.0 * turning as f64)
        + states.max(1) as f64 * state
        + sliced
}

/// The materials of a sweep's `specs`, each with its first case and its
/// number of cases: a worker keeps depth kernels for each
/// (`stress_bytes`), and builds them once (`cost::stress_sweep_seconds`).
pub fn sweep_materials<'a>(
    specs: impl Iterator<Item = &'a solver::CaseSpec>,
) -> Vec<(&'a solver::CaseSpec, usize)> {
    let mut materials: Vec<(&solver::CaseSpec, usize)> = Vec::new();
    for spec in specs {
        match materials
            .iter_mut()
            .find(|(s, _)| s.material == spec.material)
        {
            Some((_, cases)) => *cases += 1,
            None => materials.push((spec, 1)),
        }
    }
    materials
}

/// The states a case `spec` has its stresses computed at: those of its
/// load history's turning points `stress.states` chooses, else one.
pub fn stress_states(cfg: &crate::config::StressCfg, spec: &solver::CaseSpec) -> usize {
    match &spec.history {
        Some(h) => cfg
            .chosen_states()
            .count(h.turning_points(&spec.load).len()),
        None => 1,
    }
}

/// What a stressed history's states add to a memory refusal's subject:
/// their number and the key that chooses them (empty for a few states).
pub fn stress_states_note<'a>(
    cfg: Option<&crate::config::StressCfg>,
    specs: impl Iterator<Item = &'a solver::CaseSpec>,
) -> String {
    use solver::stress_summary::LAST_CYCLE_TURNING;
    let Some(cfg) = cfg else {
        return String::new();
    };
    let states = specs.map(|s| stress_states(cfg, s)).max().unwrap_or(1);
    if states <= LAST_CYCLE_TURNING {
        return String::new();
    }
    format!(
        ", with [stress] at {states} states of its load history (stress.states = \"{}\"; \"last_cycle\" computes {LAST_CYCLE_TURNING})",
        cfg.states
    )
}

/// `MemAvailable` of `/proc/meminfo`, bytes; `None` where it cannot be read.
pub fn available_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// Refuses `workers` processes of `per_worker` bytes each when they exceed
/// `available` (unknown: no check), saying how many would fit.
pub fn check_fits(
    what: &str,
    per_worker: f64,
    workers: usize,
    available: Option<f64>,
) -> Result<()> {
    let Some(available) = available else {
        return Ok(());
    };
    let total = per_worker * workers as f64;
    if total <= available {
        return Ok(());
    }
    let fit = (available / per_worker).floor() as usize;
    let advice = if fit == 0 {
        "not even one worker fits: use a coarser grid (grid.points)".to_string()
    } else {
        format!("--workers {fit} would fit")
    };
    bail!(
        "{what} needs about {:.2} GiB per worker × {workers} worker(s) = {:.2} GiB, but {:.2} GiB of memory are available; {advice}",
        per_worker / GIB,
        total / GIB,
        available / GIB
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn issue20_item4_workers_that_cannot_fit_are_refused_with_the_estimate() {
        // 2048² with 2 materials: 4.19 M cells × 700 B = 2.73 GiB a worker.
        let per = worker_bytes(2048, 2);
        assert!((per / GIB - 2.734).abs() < 0.001, "{}", per / GIB);
        let e = check_fits("the sweep", per, 4, Some(6.0 * GIB))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("2.73 GiB per worker × 4") && e.contains("--workers 2 would fit"),
            "{e}"
        );
        let e = check_fits("the sweep", per, 1, Some(1.0 * GIB))
            .unwrap_err()
            .to_string();
        assert!(e.contains("not even one worker fits"), "{e}");
        check_fits("the sweep", per, 2, Some(6.0 * GIB)).unwrap();
        check_fits("the sweep", per, 64, None).unwrap();
        // The estimate covers the measured 512² peak (131.2 MB) without
        // doubling it.
        let at512 = worker_bytes(512, 1);
        assert!((131.2e6..1.5 * 131.2e6).contains(&at512), "{at512}");
    }

    /// Issue #59 item 8: 1000 fretting cycles at 32² with `[stress]` at
    /// every turning point were killed at 8.7 GB (check: 396 MB). The
    /// estimate counts the 2002 states (each state's planes and slices,
    /// a batch's slice transforms, the history's turning tractions), a
    /// machine with less is refused naming `stress.states`, and the
    /// default `last_cycle` computes three. (Measured peaks against these
    /// estimates: docs/performance.md, "A long stressed history".)
    #[test]
    fn issue59_a_stressed_history_is_priced_per_state_and_refused_by_its_key() {
        let text = |states: &str| {
            format!("[grid]\npoints = 32\nspacing_um = 8.0\n[indenter]\nradius_mm = 18.0\n[load]\nnormal_n = 20.0\nfriction = 0.28571\n[sweep]\nmaterials = [\"Fe\"]\nangles_deg = [0.0]\n[history]\nfretting = {{ amplitude_ratio = 0.6, cycles = 1000 }}\nsteps_per_segment = 1\n[stress]\ndepths_um = [10.0]\n{states}")
        };
        let estimate = |states: &str| {
            let c = crate::config::Config::parse(&text(states), &[]).unwrap();
            let spec = crate::solve::CaseChoice::new(&c, None, None, None)
                .unwrap()
                .spec;
            let cfg = c.stress.unwrap();
            let bytes = stress_bytes(32, &cfg, std::iter::once(&spec));
            (
                bytes,
                stress_states_note(Some(&cfg), std::iter::once(&spec)),
            )
        };
        let (all, note) = estimate("states = \"turning\"\n");
        let (last, quiet) = estimate("");
        // 2002 states of 0.32 MB (planes, slices), 16 of 3.9 MB sliced
        // at once, 49 MB of turning tractions: 0.7 GB.
        assert!((0.6e9..0.8e9).contains(&all), "{all}");
        assert!(last < 0.1e9, "{last}");
        assert!(quiet.is_empty());
        let e = check_fits(&format!("this case{note}"), all, 1, Some(0.5 * GIB))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("with [stress] at 2002 states of its load history (stress.states = \"turning\"; \"last_cycle\" computes 3)"),
            "{e}"
        );
    }

    #[test]
    fn grid_size_is_one_memory_rule_with_the_estimate_in_the_message() {
        // No fixed cap below what memory allows: 4096² (8.1 GiB) fits a
        // 24 GiB machine, 8192² (32.5 GiB) does not, and the message says so.
        let machine = Some(22.1 * GIB);
        check_fits("this case", worker_bytes(4096, 1), 1, machine).unwrap();
        let e = check_fits(
            "this case (8192 x 8192 cells)",
            worker_bytes(8192, 1),
            1,
            machine,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("this case (8192 x 8192 cells) needs about 32.50 GiB")
                && e.contains("use a coarser grid (grid.points)"),
            "{e}"
        );
        // The solver's own bound is far above any machine's memory.
        assert!(worker_bytes(solver::MAX_GRID_POINTS, 1) > 100.0 * GIB);
    }
}
