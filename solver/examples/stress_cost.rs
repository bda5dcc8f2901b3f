//! What the stresses below the surface cost (docs/performance.md, issue
//! #38): the plan of a material, the kernel of one depth plane, the three
//! traction transforms of a state, a full plane and one line (a row of an
//! x–z slice), for an isotropic and a (111) substrate.
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
    println!("| material | n | plan s | plane kernel s (z = 0.5a) | plane kernel s (z = 0) | tractions s | apply plane s | apply line s | slice of 41 rows s |");
    println!("|---|---|---|---|---|---|---|---|---|");
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
            drop(surface);
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
            // A slice: one kernel per row (the shallow rows with aliases).
            let rows = 41;
            let t0 = Instant::now();
            for k in 0..rows {
                let z = 2.0 * a * k as f64 / (rows - 1) as f64;
                let pl = plan.plane(z).unwrap();
                let _ = plan.apply_line(&pl, &t, Line::Row(n / 2));
            }
            let t_slice = t0.elapsed().as_secs_f64();
            println!(
                "| {name} | {n} | {t_plan:.2} | {t_kernel:.2} | {t_kernel0:.2} | {t_tr:.3} | {t_apply:.3} | {t_line:.3} | {t_slice:.1} |"
            );
        }
    }
}
