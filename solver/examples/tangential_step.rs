//! Time of the transforms of one tangential CG iteration (issue #22): the
//! energy product `⟨v, C v⟩` (two forward transforms) plus the slip update
//! `u += C Δq` (two forward, two inverse), on the isotropic Fe operator of
//! an `N x N` grid. `cargo run --release -p mpcontact-solver --example
//! tangential_step -- 512 1024 2048` prints ms per iteration and ns per
//! cell, the median of `REPS` (default 9) timed iterations after two warm-up ones,
//! and the fastest; `THREADS` (default 1) sets the operator's threads.

use solver::influence::isotropic_cell;
use solver::{Grid, Operator};
use std::time::Instant;

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("grid sizes"))
        .collect();
    let reps: usize = std::env::var("REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(9);
    let threads: usize = std::env::var("THREADS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1);
    let threads = solver::Threads::new(threads).expect("threads");
    let (g, nu) = (210.0e9 / 2.6, 0.3);
    println!("n,ms_per_iteration,ns_per_cell,fastest_ms");
    for n in sizes {
        let d = 0.5e-6 * 512.0 / n as f64;
        let grid = Grid { n, dx: d, dy: d };
        let mut op = Operator::build_mirrored(grid, |x, y| isotropic_cell(g, nu, x, y, d, d));
        op.set_threads(&threads);
        let field = |k: usize| -> Vec<f64> {
            (0..n * n)
                .map(|i| (((i * 7 + k) % 13) as f64 - 6.0) * 1e6)
                .collect()
        };
        let (vx, vy) = (field(0), field(1));
        let (mut ux, mut uy) = (vec![0.0; n * n], vec![0.0; n * n]);
        let mut times = Vec::new();
        let mut sink = 0.0;
        for r in 0..reps + 2 {
            let t = Instant::now();
            sink += op.tangential_energy(&vx, &vy);
            op.tangential_add(&vx, &vy, &mut ux, &mut uy);
            if r >= 2 {
                times.push(t.elapsed().as_secs_f64());
            }
        }
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        assert!(sink.is_finite() && ux[0].is_finite());
        println!(
            "{n},{:.3},{:.2},{:.3}",
            median * 1e3,
            median * 1e9 / (n * n) as f64,
            times[0] * 1e3
        );
    }
}
