//! What the stresses below the surface cost (docs/performance.md, issues
//! #38 and #51): the plan of a material, the kernel of one depth plane, the
//! three traction transforms of a state, a full plane and one line (a row
//! of an x–z slice), and an x–z slice of 41 rows as `stress_summary` makes
//! it (the surface row from the surface plane, the others together
//! without planes), with the surface plane built and kept (a sweep's later cases),
//! for an isotropic and a (111) substrate.
//!
//! `cargo run --release -p mpcontact-solver --example stress_cost -- [N ...]`

use solver::stress::{Line, StressPlan};
use solver::{presets, Grid};
use std::time::Instant;

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("grid sizes"))
        .collect();
    let sizes = if sizes.is_empty() {
        vec![256, 512]
    } else {
        sizes
    };
    println!("| material | n | plan s | plane kernel s (z = 0.5a) | plane kernel s (z = 0) | tractions s | apply plane s | apply line s | slice of 41 rows s | the same, surface plane kept s |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for name in ["Fe", "Fe(111)"] {
        let material = presets::material(name).unwrap();
        for &n in &sizes {
            // A Hertz pressure of radius a = n/4 cells with q = 0.3 p.
            let grid = Grid::square(n, 1e-6);
            let a = 0.25 * n as f64 * 1e-6;
            let mut p = vec![0.0; n * n];
            for iy in 0..n {
                for ix in 0..n {
                    let r2 = (grid.x(ix).powi(2) + grid.y(iy).powi(2)) / (a * a);
                    p[iy * n + ix] = if r2 < 1.0 {
                        1e9 * (1.0 - r2).sqrt()
                    } else {
                        0.0
                    };
                }
            }
            let qx: Vec<f64> = p.iter().map(|v| 0.3 * v).collect();
            let qy = vec![0.0; n * n];
            let t0 = Instant::now();
            let mut plan = StressPlan::new(&material, grid).unwrap();
            let t_plan = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let plane = plan.plane(0.5 * a).unwrap();
            let t_kernel = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let surface = plan.plane(0.0).unwrap();
            let t_kernel0 = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let t = plan.tractions(&p, &qx, &qy);
            let t_tr = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let f = plan.apply(&plane, &t);
            let t_apply = t0.elapsed().as_secs_f64();
            let t0 = Instant::now();
            let l = plan.apply_line(&plane, &t, Line::Row(n / 2));
            let t_line = t0.elapsed().as_secs_f64();
            assert_eq!(f.len(), n * n);
            assert_eq!(l.len(), n);
            // A slice as stress_summary makes it.
            let rows = 41;
            let depths: Vec<f64> = (0..rows)
                .map(|k| 2.0 * a * k as f64 / (rows - 1) as f64)
                .collect();
            let states = [t];
            let mut slice = |surface: Option<&solver::stress::StressPlane>| {
                let t0 = Instant::now();
                let own;
                let top = match surface {
                    Some(s) => s,
                    None => {
                        own = plan.plane(0.0).unwrap();
                        &own
                    }
                };
                let _ = plan.apply_line(top, &states[0], Line::Row(n / 2));
                let _ = plan
                    .slice(&depths[1..], &states, &[Line::Row(n / 2)])
                    .unwrap();
                t0.elapsed().as_secs_f64()
            };
            let t_slice = slice(None);
            let t_slice_kept = slice(Some(&surface));
            println!(
                "| {name} | {n} | {t_plan:.2} | {t_kernel:.3} | {t_kernel0:.2} | {t_tr:.3} | {t_apply:.3} | {t_line:.3} | {t_slice:.2} | {t_slice_kept:.2} |"
            );
        }
    }
}
