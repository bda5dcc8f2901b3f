//! The cost of a measured surface before any solve (issue #61): reading a
//! 4096² `.x3p`, levelling it (the plane; and a degree-3 polynomial) and
//! resampling it onto a case's grid (256² cells, each the mean of 16 x 16
//! pixels, and 1024² cells of 4 x 4).
//!
//!     cargo run --release -p mpcontact --example scan_cost [PIXELS]
//!
//! Writes the scan (f64 heights, deflated) into a temporary directory
//! first, untimed; prints each step's wall time, best of three.

use coordinator::scan_file::x3p::{self, DataType};
use solver::{Grid, Levelling, Missing, Scan};
use std::time::Instant;

fn best_of_three<T>(mut f: impl FnMut() -> T) -> (T, f64) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..3 {
        let t = Instant::now();
        let v = f();
        best = best.min(t.elapsed().as_secs_f64());
        out = Some(v);
    }
    (out.expect("three runs"), best)
}

fn main() -> anyhow::Result<()> {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(4096);
    let pixel = 0.5e-6;
    // A tilted, wavy surface: a few micrometres of form and roughness.
    let h: Vec<f64> = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 * pixel, (i / n) as f64 * pixel);
            1e-3 * x - 2e-3 * y + 1e-6 * (x * 3.1e4).sin() * (y * 1.7e4).cos()
        })
        .collect();
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("scan.x3p");
    x3p::write(&path, &Scan::new(n, n, pixel, pixel, h)?, DataType::D)?;
    let bytes = std::fs::metadata(&path)?.len();
    let (scan, read) = best_of_three(|| x3p::read(&path).expect("the scan written above"));
    let (plane, level) = best_of_three(|| {
        scan.prepared(Missing::Refuse, Levelling::Polynomial { degree: 1 })
            .expect("a levelled scan")
    });
    let (_, cubic) = best_of_three(|| {
        scan.prepared(Missing::Refuse, Levelling::Polynomial { degree: 3 })
            .expect("a levelled scan")
    });
    let extent = n as f64 * pixel;
    let centre = [0.5 * extent, 0.5 * extent];
    let mut resampled = Vec::new();
    for cells in [256, 1024] {
        let grid = Grid::square(cells, extent / cells as f64);
        let (_, t) = best_of_three(|| solver::resample(&plane, centre, &grid).expect("inside"));
        resampled.push((cells, t));
    }
    println!(
        "{n}² scan ({:.0} MB .x3p): read {read:.3} s, plane {level:.3} s (degree 3: {cubic:.3} s)",
        bytes as f64 / 1e6
    );
    for (cells, t) in &resampled {
        println!("  resample onto {cells}²: {t:.3} s");
    }
    println!(
        "read + plane + resample onto 256²: {:.3} s",
        read + level + resampled[0].1
    );
    Ok(())
}
