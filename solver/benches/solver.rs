//! Criterion benchmarks of the solver's hot paths: one DC-FFT operator
//! application (pressure → uz, and the full 3x3 coupled apply) per grid size,
//! kernel construction (isotropic closed forms and a (111) crystal), a Hertz
//! normal solve and a coupled partial-slip solve (paper Table 1a conditions).
//! Run: `cargo bench -p mpcontact-solver --bench solver`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use solver::operator::{X, Y, Z};
use solver::{build_operator, solve_case, CaseSpec, Grid, KernelCache};

#[path = "../tests/common/mod.rs"]
mod common;

/// Paper Table 1a (isotropic Fe, coupled) on `n` cells of a 256 µm domain.
fn table_1a(n: usize, ratio: f64) -> CaseSpec {
    common::table_1a_fe(n, 0.5 * 512.0 / n as f64, true, ratio)
}

fn operator_apply(c: &mut Criterion) {
    let mut g = c.benchmark_group("operator_apply");
    g.sample_size(10);
    for n in [128usize, 256, 512, 1024] {
        let grid = Grid {
            n,
            dx: 1e-6,
            dy: 1e-6,
        };
        let material = solver::presets::material("Fe").unwrap();
        let mut op = build_operator(&material, grid);
        let t: Vec<Vec<f64>> = (0..3)
            .map(|k| (0..n * n).map(|i| ((i * 7 + k) % 13) as f64).collect())
            .collect();
        let mut u: Vec<Vec<f64>> = (0..3).map(|_| vec![0.0; n * n]).collect();
        g.bench_with_input(BenchmarkId::new("p_to_uz", n), &n, |b, _| {
            b.iter(|| op.normal(&t[2], &mut u[2]))
        });
        g.bench_with_input(BenchmarkId::new("coupled_3x3", n), &n, |b, _| {
            b.iter(|| {
                let [ux, uy, uz] = &mut u[..] else {
                    unreachable!()
                };
                op.apply(
                    &[(X, &t[0]), (Y, &t[1]), (Z, &t[2])],
                    &mut [(X, ux), (Y, uy), (Z, uz)],
                )
            })
        });
    }
    g.finish();
}

fn kernel_build(c: &mut Criterion) {
    let mut g = c.benchmark_group("kernel_build");
    g.sample_size(10);
    for name in ["Fe", "Fe(111)"] {
        for n in [128usize, 256] {
            let grid = Grid {
                n,
                dx: 1e-6,
                dy: 1e-6,
            };
            let material = solver::presets::material(name).unwrap();
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| build_operator(&material, grid))
            });
        }
    }
    g.finish();
}

fn solves(c: &mut Criterion) {
    let mut g = c.benchmark_group("solve");
    g.sample_size(10);
    for n in [128usize, 256] {
        let mut cache = KernelCache::new();
        let hertz = table_1a(n, 0.0);
        solve_case(&hertz, &mut cache).unwrap();
        g.bench_with_input(BenchmarkId::new("hertz_normal", n), &n, |b, _| {
            b.iter(|| solve_case(&hertz, &mut cache).unwrap())
        });
        let slip = table_1a(n, 0.6);
        g.bench_with_input(BenchmarkId::new("coupled_partial_slip", n), &n, |b, _| {
            b.iter(|| solve_case(&slip, &mut cache).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, operator_apply, kernel_build, solves);
criterion_main!(benches);
