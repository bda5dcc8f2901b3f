//! Build time of the isotropic (Fe) operator, direct and from one mirrored
//! quadrant (issue #22): `cargo run --release -p mpcontact-solver --example
//! influence_build -- 256 512 1024 2048`. Cells of 0.5 µm × 512/N.

use solver::influence::isotropic_cell;
use solver::{Grid, Operator};
use std::time::Instant;

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("grid sizes"))
        .collect();
    let direct_too = std::env::var_os("DIRECT").is_some();
    let (g, nu) = (210.0e9 / 2.6, 0.3);
    println!("n,mirrored_s,direct_s,identical");
    for n in sizes {
        let d = 0.5e-6 * 512.0 / n as f64;
        let grid = Grid { n, dx: d, dy: d };
        let cell = |x, y| isotropic_cell(g, nu, x, y, d, d);
        let t = Instant::now();
        let mut mirrored = solver::Operator::build_mirrored(grid, cell);
        let tm = t.elapsed().as_secs_f64();
        let (td, same) = if direct_too {
            let t = Instant::now();
            let mut direct = Operator::build(grid, cell);
            let td = t.elapsed().as_secs_f64();
            (
                format!("{td:.3}"),
                (direct.with_spectra(|d| mirrored.with_spectra(|m| d == m))).to_string(),
            )
        } else {
            ("-".into(), "-".into())
        };
        println!("{n},{tm:.3},{td},{same}");
    }
}
