//! What a sweep will do, without doing it: `mpcontact check CONFIG` and
//! `mpcontact run CONFIG --dry-run`. The expanded sweep, the kernels to
//! build or found in the cache, estimates of memory and time, and the first
//! moments of every case (`preflight`: the normal contacts), refused as a
//! solve would refuse them. Writes nothing.

use anyhow::Result;
use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::config::Config;
use crate::cost::{
    case_seconds, kernel_seconds, stress_kernels, stress_sweep_seconds, CASE_EXPONENT,
};
use solver::KernelKey;

/// An estimate of `s` seconds for people ("about 0 s" read as if nothing
/// would run: below half a second it is "under 1 s").
fn about_seconds(s: f64) -> String {
    if s < 0.5 {
        "under 1 s".into()
    } else if s < 90.0 {
        format!("about {s:.0} s")
    } else if s < 5400.0 {
        format!("about {:.1} min", s / 60.0)
    } else {
        format!("about {:.1} h", s / 3600.0)
    }
}

/// The dry-run report of `config` run on `workers` workers; errors exactly
/// as `run` would give them before starting (config, memory, a case refused
/// in its first moments).
pub fn report(config: &Config, workers: usize) -> Result<String> {
    let cases = config.cases()?;
    anyhow::ensure!(!cases.is_empty(), "the sweep has no cases");
    // The finest ladder level sets the memory a worker needs.
    let n = config.finest_points();
    let angles = config.sweep.angles_deg.values()?;
    // Kernels in first-use order, with whether the store holds them.
    let store = worker::kernel_store::FileStore::default_location()
        .map(worker::kernel_store::FileStore::new);
    let mut kernels: BTreeMap<KernelKey, (String, bool, bool, usize)> = BTreeMap::new();
    for (key, spec) in &cases {
        let persistent = solver::persists(spec);
        if let std::collections::btree_map::Entry::Vacant(slot) = kernels.entry(KernelKey::of(spec))
        {
            let cached = persistent && store.as_ref().is_some_and(|s| s.holds(slot.key()));
            // The pair a kernel is made for: the substrate, and the ball when
            // it is elastic.
            let bodies = match &spec.indenter {
                Some(ball) => format!("{} + ball {}", key.material, ball.name),
                None => key.material.clone(),
            };
            slot.insert((bodies, persistent, cached, spec.grid.n));
        }
    }
    let stress_bytes = config.stress.as_ref().map_or(0.0, |cfg| {
        crate::memory::stress_bytes(n, cfg, cases.iter().map(|(_, s)| s))
    });
    let per_worker = crate::memory::worker_bytes(n, kernels.len()) + stress_bytes;
    crate::memory::check_fits(
        &format!(
            "the sweep (finest grid {0} x {0} cells{1})",
            n,
            crate::memory::stress_states_note(config.stress.as_ref(), cases.iter().map(|(_, s)| s))
        ),
        per_worker,
        workers,
        crate::memory::available_bytes(),
    )?;
    let first_moments = crate::preflight::check(
        cases.iter().map(|(k, s)| (k, s)),
        crate::preflight::Kernels::ReadOnly,
    )?;
    let mut s = String::new();
    let n0 = config.grid.points;
    let mm = n0 as f64 * config.grid.spacing_um / 1000.0;
    let _ = writeln!(
        s,
        "grid:      {n0} x {n0} cells of {} µm ({mm:.2} mm square domain)",
        config.grid.spacing_um
    );
    let levels = config.convergence.levels;
    if levels > 1 {
        let sizes: Vec<String> = (0..levels)
            .map(|k| {
                let g = config.level_grid(k);
                format!("{}² ({:.3} µm)", g.n, g.dx * 1e6)
            })
            .collect();
        let _ = writeln!(s, "ladder:    {levels} levels: {}", sizes.join(", "));
    }
    let list = |v: &[String]| v.join(", ");
    let balls = match &config.sweep.indenters {
        Some(names) => format!("{} balls ({})", names.len(), list(names)),
        None => config
            .indenter
            .material
            .as_deref()
            .unwrap_or(crate::config::RIGID)
            .to_string(),
    };
    let _ = writeln!(
        s,
        "indenter:  R = {} mm, {balls}",
        config.indenter.radius_mm
    );
    let _ = writeln!(
        s,
        "materials: {} ({})",
        config.sweep.materials.len(),
        list(&config.sweep.materials)
    );
    let orientations = config.orientations()?;
    let per_crystal = orientations.len() / config.sweep.materials.len().max(1);
    if !orientations.is_empty() {
        let shown: Vec<String> = orientations
            .iter()
            .take(per_crystal)
            .map(|o| crate::config::orientations::miller_text(o.normal))
            .collect();
        let _ = writeln!(
            s,
            "orientations: {per_crystal} per crystal, each its own kernel ({})",
            shown.join(" ")
        );
    }
    let _ = writeln!(
        s,
        "surfaces:  {} ({})",
        config.sweep.surfaces.len(),
        list(&config.sweep.surfaces)
    );
    for w in config.unresolved_patterns(&config.sweep.surfaces)? {
        let _ = writeln!(s, "warning:   {w}");
    }
    for name in &config.sweep.surfaces {
        for level in 0..config.convergence.levels {
            if let Some(r) = config.scan_report(name, level)? {
                let _ = writeln!(s, "{}", scan_lines(name, &r, level == 0));
            }
        }
    }
    let shown: Vec<String> = angles.iter().map(|a| format!("{a}")).collect();
    let _ = writeln!(s, "angles:    {} ({} deg)", angles.len(), shown.join(", "));
    let mut ball_axis = match &config.sweep.indenters {
        Some(names) => format!(" x {} balls", names.len()),
        None => String::new(),
    };
    if let Some(v) = &config.sweep.normal_loads_n {
        ball_axis.push_str(&format!(" x {} normal loads", v.len()));
    }
    if let Some(v) = &config.sweep.amplitudes_um {
        ball_axis.push_str(&format!(" x {} amplitudes", v.len()));
    }
    let _ = writeln!(
        s,
        "cases:     {} = {} materials{} x {} surfaces x {} angles{ball_axis} x {levels} level(s)",
        cases.len(),
        config.sweep.materials.len(),
        if orientations.is_empty() {
            String::new()
        } else {
            format!(" x {per_crystal} orientations")
        },
        config.sweep.surfaces.len(),
        angles.len()
    );
    let to_build = kernels.values().filter(|(_, _, cached, _)| !cached).count();
    let _ = writeln!(
        s,
        "kernels:   {} ({to_build} to build, {} from the cache)",
        kernels.len(),
        kernels.len() - to_build
    );
    for (material, persistent, cached, n) in kernels.values() {
        let what = match (persistent, cached) {
            (false, _) => "closed form, built each run",
            (true, true) => "anisotropic, in the kernel cache",
            (true, false) => "anisotropic, to build (then cached)",
        };
        let _ = writeln!(s, "           {material} at {n}²: {what}");
    }
    if let Some((key, reach)) = &first_moments.widest {
        let _ = writeln!(
            s,
            "contacts:  every case's frictionless normal contact solved ({:.1} s), none at the domain's edge; the widest, {key}, reaches {:.0} % of the way from the centre to the outermost cells",
            first_moments.seconds,
            100.0 * reach
        );
    }
    let workers_used = workers.min(cases.len()).max(1);
    let _ = writeln!(
        s,
        "memory:    about {:.0} MB per worker x {workers} worker(s) (520 B per cell for one kernel, 180 B per cell per further kernel; measured peaks in docs/performance.md{})",
        per_worker / 1e6,
        if stress_bytes > 0.0 {
            format!("; [stress] {:.0} MB of it", stress_bytes / 1e6)
        } else {
            String::new()
        }
    );
    let stress: f64 = match &config.stress {
        Some(cfg) => {
            let t = stress_sweep_seconds(cases.iter().map(|(_, spec)| spec), cfg, workers_used);
            let states = cases
                .iter()
                .map(|(_, spec)| crate::memory::stress_states(cfg, spec))
                .max()
                .unwrap_or(1);
            let _ = writeln!(
                s,
                "stress:    {} depth kernels per material (planes and the surface for SWT; slice rows need none), built once by each worker and kept; about {:.1} s a case more on average (measured at 256², scaled as N², for each state computed: {states} a case at most, stress.states = \"{}\")",
                stress_kernels(cfg),
                t / cases.len() as f64,
                cfg.states
            );
            t
        }
        None => 0.0,
    };
    let solving: f64 = stress
        + cases
            .iter()
            .map(|(_, spec)| case_seconds(spec))
            .sum::<f64>();
    let total = solving
        + kernels
            .values()
            .filter(|(_, _, cached, _)| !cached)
            .map(|&(_, _, _, n)| kernel_seconds(n))
            .sum::<f64>();
    let _ = writeln!(
        s,
        "time:      {} on {workers_used} worker(s) ({:.2} s a case on average: the paper sweep's measured means per kind of case at 384², scaled as N^{CASE_EXPONENT}; a guide within a factor of 2)",
        about_seconds(total / workers_used as f64),
        solving / cases.len() as f64
    );
    Ok(s)
}

/// What `check` says of a scan or random surface on one grid: the scan
/// (first level only) and its roughness there.
fn scan_lines(name: &str, r: &crate::config::ScanReport, first: bool) -> String {
    let rough = |g: &crate::config::RoughnessUm| {
        format!(
            "Sa {:.4} µm, Sq {:.4} µm, Sz {:.4} µm, Sdq {:.4}",
            g.sa_um, g.sq_um, g.sz_um, g.sdq
        )
    };
    // Lengths to the nanometre, without trailing zeros (a width of n
    // pixels is often a last bit off its decimal value).
    let um = |v: f64| {
        let t = format!("{v:.3}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let mut s = String::new();
    if first {
        s += &format!(
            "scan:      {name}: {}, {} x {} pixels of {} x {} µm ({} x {} µm), {} missing ({}), levelling {}, apex at ({}, {}) µm\n           as prepared: {}\n",
            r.source,
            r.pixels[0],
            r.pixels[1],
            um(r.pixel_um[0]),
            um(r.pixel_um[1]),
            um(r.extent_um[0]),
            um(r.extent_um[1]),
            r.missing_points,
            r.missing,
            r.levelling,
            um(r.apex_um[0]),
            um(r.apex_um[1]),
            rough(&r.scan),
        );
    }
    s += &format!(
        "           on cells of {} x {} µm ({}): {}",
        um(r.cell_um[0]),
        um(r.cell_um[1]),
        r.sampling,
        rough(&r.grid)
    );
    s
}
