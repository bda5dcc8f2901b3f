//! The operator's unit tests: its build and apply against direct summation
//! (isotropic and crystals, every path, split columns, threads), reciprocity,
//! the cut cells' factor and the tangential self-compliance and inverse.

use super::*;
use crate::green::influence::isotropic_cell;

fn pseudo_random(len: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..len)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.3
        })
        .collect()
}

/// The cut cells' factor: a whole cell's compliance at cover 1, the
/// straight-edge form `(1 + β (1 − c)) / c` above the floor, the floor's
/// value below it.
#[test]
fn the_cut_factor_is_whole_at_full_cover_and_floored_for_slivers() {
    assert_eq!(cut_self_factor(1.0), 1.0);
    let half = cut_self_factor(0.5);
    assert!((half - (1.0 + 0.5 * CUT_CELL_BETA) / 0.5).abs() < 1e-15);
    let floor = cut_self_factor(CUT_COVER_FLOOR);
    assert!((floor - 13.6).abs() < 1e-12, "{floor}");
    assert_eq!(cut_self_factor(0.02), floor);
    assert!(cut_self_factor(0.3) < floor && cut_self_factor(0.3) > half);
}

/// A cell's own tangential compliance, from the spectra, is the mean of
/// the closed-form `K_xx(0, 0)` and `K_yy(0, 0)` (dx ≠ dy, so they differ).
#[test]
fn tangential_self_is_the_cells_own_compliance() {
    let grid = grid(24, 1.0e-6, 1.7e-6);
    let (g, nu) = (80.0e9, 0.3);
    let op = Operator::build(grid, |x, y| isotropic_cell(g, nu, x, y, grid.dx, grid.dy));
    let k = isotropic_cell(g, nu, 0.0, 0.0, grid.dx, grid.dy);
    let want = 0.5 * (k[X][X] + k[Y][Y]);
    assert!(k[X][X] != k[Y][Y]);
    let err = (op.tangential_self() - want).abs() / want;
    assert!(err < 1e-12, "{} vs {want}: {err:e}", op.tangential_self());
}

/// The inverse of the `2N`-circulant embedding, shifted, against a dense
/// inverse of that circulant built from the kernel tables (isotropic and
/// a (111) crystal, whose `K_xy` spectrum is complex), on both FFT paths.
#[test]
fn tangential_inverse_equals_the_dense_circulant_inverse() {
    let grid = grid(6, 1.0e-6, 1.0e-6);
    let iso = |x: f64, y: f64| isotropic_cell(80.0e9, 0.27, x, y, grid.dx, grid.dy);
    let ops = [
        Operator::build(grid, iso),
        Operator::build(grid, cu111_cell(grid)),
    ];
    for mut op in ops {
        for split in [false, true] {
            op = op.with_split_columns(split);
            let n = grid.n;
            let m = 2 * n;
            let tab = [
                [op.table(X, X), op.table(X, Y)],
                [op.table(Y, X), op.table(Y, Y)],
            ];
            let shift = 2.0 * op.tangential_self();
            // A[(a, p), (b, p')] = K_ab(p − p') on the wrap-around grid.
            let dim = 2 * m * m;
            let mut a = nalgebra::DMatrix::<f64>::zeros(dim, dim);
            for (ia, ta) in tab.iter().enumerate() {
                for (ib, t) in ta.iter().enumerate() {
                    for py in 0..m {
                        for px in 0..m {
                            for qy in 0..m {
                                for qx in 0..m {
                                    let (dy, dx) = ((py + m - qy) % m, (px + m - qx) % m);
                                    a[(ia * m * m + py * m + px, ib * m * m + qy * m + qx)] =
                                        t[dy * m + dx];
                                }
                            }
                        }
                    }
                }
            }
            for k in 0..dim {
                a[(k, k)] += shift;
            }
            let inv = a
                .try_inverse()
                .expect("the shifted circulant is invertible");
            let tx = pseudo_random(n * n, 3);
            let ty = pseudo_random(n * n, 4);
            let mut rhs = nalgebra::DVector::<f64>::zeros(dim);
            for iy in 0..n {
                for ix in 0..n {
                    rhs[iy * m + ix] = tx[iy * n + ix];
                    rhs[m * m + iy * m + ix] = ty[iy * n + ix];
                }
            }
            let want = inv * rhs;
            let (mut ux, mut uy) = (vec![0.0; n * n], vec![0.0; n * n]);
            op.tangential_inverse(shift, (&tx, &ty), (&mut ux, &mut uy));
            let mut err = 0.0_f64;
            let mut top = 0.0_f64;
            for iy in 0..n {
                for ix in 0..n {
                    let (wx, wy) = (want[iy * m + ix], want[m * m + iy * m + ix]);
                    err = err
                        .max((wx - ux[iy * n + ix]).abs())
                        .max((wy - uy[iy * n + ix]).abs());
                    top = top.max(wx.abs()).max(wy.abs());
                }
            }
            assert!(err < 1e-10 * top, "split {split}: {err:e} of {top:e}");
        }
    }
}

#[test]
fn dcfft_equals_direct_summation_on_16x16_to_1e12() {
    let grid = grid(16, 1.0e-6, 1.3e-6);
    let (g, nu) = (80.0e9, 0.27);
    let cell = |x: f64, y: f64| isotropic_cell(g, nu, x, y, grid.dx, grid.dy);
    let mut op = Operator::build(grid, cell);
    let n = grid.n;
    let t: Vec<Vec<f64>> = (0..3).map(|c| pseudo_random(n * n, 7 + c as u64)).collect();
    let mut u: Vec<Vec<f64>> = (0..3).map(|_| vec![0.0; n * n]).collect();
    {
        let [ux, uy, uz] = &mut u[..] else {
            unreachable!()
        };
        op.apply(
            &[(X, &t[0]), (Y, &t[1]), (Z, &t[2])],
            &mut [(X, ux), (Y, uy), (Z, uz)],
        );
    }
    let want = direct(grid, &cell, &t);
    let mut max_err: f64 = 0.0;
    let mut max_val: f64 = 0.0;
    for (w, got) in want.iter().zip(&u) {
        for (a, b) in w.iter().zip(got) {
            max_err = max_err.max((a - b).abs());
            max_val = max_val.max(a.abs());
        }
    }
    assert!(
        max_err < 1e-12 * max_val,
        "max err {max_err:e} vs {max_val:e}"
    );
}

/// Direct summation of `u_a = Σ_b K_ab * t_b` with the cell function.
fn direct(grid: Grid, cell: &impl Fn(f64, f64) -> Block, t: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = grid.n;
    let mut u = vec![vec![0.0; n * n]; 3];
    for iy in 0..n {
        for ix in 0..n {
            for jy in 0..n {
                for jx in 0..n {
                    let k = cell(
                        (ix as f64 - jx as f64) * grid.dx,
                        (iy as f64 - jy as f64) * grid.dy,
                    );
                    for (a, ua) in u.iter_mut().enumerate() {
                        for (b, tb) in t.iter().enumerate() {
                            ua[iy * n + ix] += k[a][b] * tb[jy * n + jx];
                        }
                    }
                }
            }
        }
    }
    u
}

fn grid(n: usize, dx: f64, dy: f64) -> Grid {
    Grid { n, dx, dy }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn cu111_cell(grid: Grid) -> impl Fn(f64, f64) -> Block {
    crate::model::presets::material("Cu(111)")
        .unwrap()
        .model()
        .cell_influence(grid)
}

#[test]
fn influence_tables_are_reciprocal_for_isotropic_and_111_crystals() {
    // Betti: K_ji(r) = K_ij(−r); on the wrap-around grid −r is index m − i.
    let grid = grid(12, 20e-6, 20e-6);
    let iso = |x: f64, y: f64| isotropic_cell(48.0e9, 0.34, x, y, grid.dx, grid.dy);
    for tables in [
        Operator::tables(grid, iso),
        Operator::tables(grid, cu111_cell(grid)),
    ] {
        let m = 2 * grid.n;
        let scale = tables.iter().map(|t| max_abs(t)).fold(0.0, f64::max);
        let neg = |i: usize| (m - i) % m;
        let mut worst: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                for iy in 0..m {
                    for ix in 0..m {
                        let a = tables[3 * i + j][iy * m + ix];
                        let b = tables[3 * j + i][neg(iy) * m + neg(ix)];
                        worst = worst.max((a - b).abs());
                    }
                }
            }
        }
        assert!(
            worst < 1e-12 * scale,
            "reciprocity violated by {worst:e} of {scale:e}"
        );
        // The off-diagonal couplings are not trivially zero.
        assert!(max_abs(&tables[1]) > 1e-3 * scale || max_abs(&tables[2]) > 1e-3 * scale);
    }
}

#[test]
fn row_by_row_build_equals_the_table_build() {
    let grid = grid(10, 20e-6, 20e-6);
    let cell = cu111_cell(grid);
    let a = Operator::build(grid, &cell).with_spectra(Spectra::clone);
    let b =
        Operator::from_tables(grid, &Operator::tables(grid, &cell)).with_spectra(Spectra::clone);
    let scale = a.diag[Z].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (x, y) in a.diag.iter().zip(&b.diag) {
        for (u, v) in x.iter().zip(y) {
            assert!((u - v).abs() < 1e-13 * scale);
        }
    }
    for (x, y) in a.off.iter().zip(&b.off) {
        for (u, v) in x.iter().zip(y) {
            assert!((u - v).norm() < 1e-13 * scale);
        }
    }
    assert_eq!(a.bytes(), 9 * Spectra::len_for(grid.n) * 8);
}

#[test]
fn anisotropic_apply_equals_direct_summation_on_every_path() {
    for split in [false, true] {
        apply_equals_direct_summation_on_every_path(split);
    }
}

/// Split columns (`crate::operators::fft2`) keep the kernel spectra in split order;
/// the tables and window operators made from them are those of whole
/// columns, to round-off.
#[test]
fn split_columns_give_the_same_tables_and_windows() {
    let grid = grid(12, 20e-6, 25e-6);
    let cell = cu111_cell(grid);
    let mut whole = Operator::build(grid, &cell).with_split_columns(false);
    let mut split = Operator::build(grid, &cell).with_split_columns(true);
    let close = |a: &[f64], b: &[f64]| {
        let scale = max_abs(a);
        assert!(scale > 0.0);
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-13 * scale, "{x:e} vs {y:e}");
        }
    };
    close(&whole.table(Z, Z), &split.table(Z, Z));
    close(&whole.table(X, Y), &split.table(X, Y));
    assert_eq!(
        whole.with_spectra(Spectra::clone),
        split.with_spectra(Spectra::clone)
    );
    let t = [pseudo_random(64, 3), pseudo_random(64, 4)];
    let mut u = [vec![0.0; 64], vec![0.0; 64], vec![0.0; 64], vec![0.0; 64]];
    let [a, b, c, d] = &mut u;
    whole.window_operator(8).tangential(&t[0], &t[1], a, b);
    split.window_operator(8).tangential(&t[0], &t[1], c, d);
    close(a, c);
    close(b, d);
}

/// Split columns run each column the same way on any thread: 1 and 2
/// threads give the same bits (solver/tests/threads.rs checks whole
/// solves, on grids too small for split columns).
#[test]
fn split_columns_give_the_same_bits_on_1_and_2_threads() {
    let grid = grid(12, 20e-6, 25e-6);
    let cell = cu111_cell(grid);
    let t = [pseudo_random(144, 5), pseudo_random(144, 6)];
    let run = |threads: usize| {
        let mut op = Operator::build(grid, &cell).with_split_columns(true);
        op.set_threads(&crate::base::parallel::Threads::new(threads).unwrap());
        let (mut ux, mut uy) = (vec![0.0; 144], vec![0.0; 144]);
        op.tangential(&t[0], &t[1], &mut ux, &mut uy);
        let energy = op.tangential_energy(&t[0], &t[1]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        (bits(&ux), bits(&uy), energy.to_bits())
    };
    assert_eq!(run(1), run(2));
}

fn apply_equals_direct_summation_on_every_path(split: bool) {
    // The reciprocal storage (K_yx from K_xy etc.) and each apply path
    // (1, 2 or 3 sources; 1, 2 or 3 destinations) against direct sums.
    let grid = grid(12, 20e-6, 25e-6);
    let cell = cu111_cell(grid);
    let mut op = Operator::build(grid, &cell).with_split_columns(split);
    let n = grid.n;
    let t: Vec<Vec<f64>> = (0..3)
        .map(|c| pseudo_random(n * n, 11 + c as u64))
        .collect();
    let zero = vec![0.0; n * n];
    let only = |keep: &[usize]| -> Vec<Vec<f64>> {
        (0..3)
            .map(|c| {
                if keep.contains(&c) {
                    t[c].clone()
                } else {
                    zero.clone()
                }
            })
            .collect()
    };
    let check = |got: &[f64], want: &[f64], what: &str| {
        let scale = max_abs(want);
        let err = got
            .iter()
            .zip(want)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-12 * scale, "{what}: err {err:e} of {scale:e}");
    };
    // Three sources to three destinations.
    let want = direct(grid, &cell, &t);
    let (mut ux, mut uy, mut uz) = (zero.clone(), zero.clone(), zero.clone());
    op.apply(
        &[(X, &t[0]), (Y, &t[1]), (Z, &t[2])],
        &mut [(X, &mut ux), (Y, &mut uy), (Z, &mut uz)],
    );
    check(&ux, &want[0], "3->x");
    check(&uy, &want[1], "3->y");
    check(&uz, &want[2], "3->z");
    // Tangential (two sources, two destinations, fused).
    let want = direct(grid, &cell, &only(&[X, Y]));
    op.tangential(&t[0], &t[1], &mut ux, &mut uy);
    check(&ux, &want[0], "xy->x");
    check(&uy, &want[1], "xy->y");
    // Accumulating variant: twice the field gives twice the displacement.
    op.tangential_add(&t[0], &t[1], &mut ux, &mut uy);
    let twice = |v: &[f64]| v.iter().map(|x| 2.0 * x).collect::<Vec<f64>>();
    check(&ux, &twice(&want[0]), "xy->x added");
    check(&uy, &twice(&want[1]), "xy->y added");
    op.apply(&[(X, &t[0]), (Y, &t[1])], &mut [(Z, &mut uz)]);
    check(&uz, &want[2], "xy->z");
    // The energy product by Parseval equals t · (K t) in real space.
    let direct_energy: f64 = (0..n * n)
        .map(|i| t[0][i] * want[0][i] + t[1][i] * want[1][i])
        .sum();
    let energy = op.tangential_energy(&t[0], &t[1]);
    assert!(
        (energy - direct_energy).abs() < 1e-12 * direct_energy.abs(),
        "energy {energy:e} vs {direct_energy:e}"
    );
    // Pressure to every component.
    let want = direct(grid, &cell, &only(&[Z]));
    op.apply(&[(Z, &t[2])], &mut [(X, &mut ux), (Y, &mut uy)]);
    check(&ux, &want[0], "z->x");
    check(&uy, &want[1], "z->y");
    op.normal(&t[2], &mut uz);
    check(&uz, &want[2], "z->z");
}
