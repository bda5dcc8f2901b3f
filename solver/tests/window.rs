//! Contact windows: tangential solves on the smallest square window that holds
//! the contact cells, with that window's own operator, must equal the solves on
//! the whole grid (the tractions vanish outside the contact, so the two are the
//! same equations).

mod common;

use solver::operator::{Grid, Operator, X, Y};
use solver::tangential::{
    solve_tangential, solve_tangential_on_grid, TangentialProblem, TangentialStart,
};
use solver::window::{contact_window, Window, WindowCache};
use solver::{solve_case, KernelCache};

fn cu111(grid: Grid) -> Operator {
    solver::build_operator(&solver::presets::material("Cu(111)").unwrap(), grid)
}

fn grid(n: usize) -> Grid {
    Grid {
        n,
        dx: 10e-6,
        dy: 10e-6,
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// A Hertz-like pressure of radius `a` cells centred at cell `(cx, cy)`.
fn pressure(n: usize, a: f64, cx: f64, cy: f64) -> Vec<f64> {
    let mut p = vec![0.0; n * n];
    for iy in 0..n {
        for ix in 0..n {
            let r2 = ((ix as f64 - cx).powi(2) + (iy as f64 - cy).powi(2)) / (a * a);
            if r2 < 1.0 {
                p[iy * n + ix] = 1.0e8 * (1.0 - r2).sqrt();
            }
        }
    }
    p
}

#[test]
fn a_window_operator_applies_tractions_inside_it_exactly() {
    let (n, nw, x0, y0) = (40, 24, 13, 3);
    let mut op = cu111(grid(n));
    let win = Window {
        grid_n: n,
        n: nw,
        x0,
        y0,
    };
    // Smooth non-trivial tractions on the window only.
    let part = |c: usize| -> Vec<f64> {
        (0..nw * nw)
            .map(|k| ((k * (7 + c)) % 17) as f64 - 8.0 + 0.1 * c as f64)
            .collect()
    };
    let t: Vec<Vec<f64>> = (0..2).map(part).collect();
    let full: Vec<Vec<f64>> = t.iter().map(|f| win.scatter(f, 0.0)).collect();
    let mut u_full: Vec<Vec<f64>> = (0..2).map(|_| vec![0.0; n * n]).collect();
    let mut u_win: Vec<Vec<f64>> = (0..2).map(|_| vec![0.0; nw * nw]).collect();
    {
        let [ux, uy] = &mut u_full[..] else {
            unreachable!()
        };
        op.apply(&[(X, &full[0]), (Y, &full[1])], &mut [(X, ux), (Y, uy)]);
    }
    let mut windows = WindowCache::default();
    {
        let [ux, uy] = &mut u_win[..] else {
            unreachable!()
        };
        // The tangential block only: what a window operator holds.
        windows
            .operator(&mut op, nw)
            .apply(&[(X, &t[0]), (Y, &t[1])], &mut [(X, ux), (Y, uy)]);
    }
    assert_eq!(windows.side(), Some(nw));
    for (c, (uf, uw)) in u_full.iter().zip(&u_win).enumerate() {
        let want = win.gather(uf);
        let scale = max_abs(&want);
        assert!(scale > 0.0);
        let err = max_diff(&want, uw);
        assert!(err < 1e-12 * scale, "component {c}: {err:e} of {scale:e}");
    }
}

#[test]
fn contact_windows_hold_the_contact_and_are_only_used_when_clearly_smaller() {
    let n = 100;
    // Contact over columns 70..=89 and rows 5..=16: side 20 -> 24, clamped.
    let mut p = vec![0.0; n * n];
    for iy in 5..=16 {
        for ix in 70..=89 {
            p[iy * n + ix] = 1.0;
        }
    }
    let w = contact_window(n, &p).unwrap();
    assert_eq!((w.n, w.x0, w.y0), (24, 70, 5));
    // Sides with a factor 5 are skipped: 33 cells need 48 (not 40).
    p[37 * n + 70] = 1.0;
    assert_eq!(contact_window(n, &p).unwrap().n, 48);
    // Near the far edge the window is moved inside the grid.
    p.iter_mut().for_each(|v| *v = 0.0);
    p[99 * n + 99] = 1.0;
    p[90 * n + 95] = 1.0;
    let w = contact_window(n, &p).unwrap();
    assert_eq!((w.n, w.x0, w.y0), (16, 84, 84));
    // Round trip of a field through the window.
    let f: Vec<f64> = (0..n * n).map(|k| k as f64).collect();
    let back = w.scatter(&w.gather(&f), -1.0);
    for iy in 0..n {
        for ix in 0..n {
            let inside = (84..100).contains(&ix) && (84..100).contains(&iy);
            let want = if inside { f[iy * n + ix] } else { -1.0 };
            assert_eq!(back[iy * n + ix], want);
        }
    }
    // Contact over 90 % of the side, or none: the whole grid.
    p.iter_mut().for_each(|v| *v = 0.0);
    p[0] = 1.0;
    p[89 * n + 89] = 1.0;
    assert_eq!(contact_window(n, &p), None);
    assert_eq!(contact_window(n, &[0.0; 100 * 100]), None);
}

#[test]
fn windowed_and_whole_grid_tangential_solves_agree_for_a_111_crystal() {
    let n = 64;
    let mut op = cu111(grid(n));
    // Off-centre contact near a corner, so the window is clamped to the grid.
    let p = pressure(n, 12.0, 48.0, 20.5);
    let da = grid(n).cell_area();
    let normal: f64 = p.iter().sum::<f64>() * da;
    let mu = 0.3;
    let f = 0.5 * mu * normal;
    let force = [f * 0.8, f * 0.6];
    // A coupling term, as the coupled solve supplies it.
    let ex: Vec<f64> = (0..n * n).map(|k| 1e-9 * ((k % n) as f64 - 30.0)).collect();
    let ey: Vec<f64> = (0..n * n).map(|k| 2e-9 * ((k / n) as f64 - 9.0)).collect();
    let prob = TangentialProblem {
        p: &p,
        friction: mu,
        force,
        extra: Some((&ex, &ey)),
        tolerance: 1e-10,
        slip_floor: 0.0,
        max_iterations: 20_000,
        start: TangentialStart::Proportional,
        precondition: false,
        method: Default::default(),
    };
    let whole = solve_tangential_on_grid(&mut op, &prob).unwrap();
    let mut windows = WindowCache::default();
    let win = solve_tangential(&mut op, &mut windows, &prob).unwrap();
    assert_eq!(windows.side(), Some(24), "the 24 x 24 window was used");
    assert!(whole.report.converged && win.report.converged);
    let qs = max_abs(&whole.qx).max(max_abs(&whole.qy));
    let dq = max_diff(&whole.qx, &win.qx).max(max_diff(&whole.qy, &win.qy));
    assert!(dq < 1e-7 * qs, "tractions differ by {dq:e} of {qs:e}");
    let ss = max_abs(&whole.sx).max(max_abs(&whole.sy));
    let ds = max_diff(&whole.sx, &win.sx).max(max_diff(&whole.sy, &win.sy));
    assert!(
        ss > 0.0 && ds < 1e-6 * ss,
        "slips differ by {ds:e} of {ss:e}"
    );
    let shift = whole.shift[0].hypot(whole.shift[1]);
    let dshift = (whole.shift[0] - win.shift[0]).hypot(whole.shift[1] - win.shift[1]);
    assert!(dshift < 1e-8 * shift, "shift {dshift:e} of {shift:e}");
    let nstick = whole.stick.iter().filter(|&&s| s).count();
    assert!(nstick > 0 && nstick < p.iter().filter(|&&v| v > 0.0).count());
    assert_eq!(whole.stick, win.stick, "stick sets");
    // Force balance of the windowed tractions.
    let fx: f64 = win.qx.iter().sum::<f64>() * da;
    let fy: f64 = win.qy.iter().sum::<f64>() * da;
    assert!((fx - force[0]).hypot(fy - force[1]) < 1e-9 * f);
}

#[test]
fn only_the_operator_in_use_keeps_its_window() {
    // Table 1a on 64 cells of 5 µm: contact about 42 cells across, window 48.
    let a = common::table_1a_fe(64, 5.0, false, 0.6);
    let mut b = a.clone();
    b.material = solver::Material::isotropic("Fe-soft", 150.0e9, 0.3).unwrap();
    let mut cache = KernelCache::new();
    let out = solve_case(&a, &mut cache).unwrap();
    assert!(out.scalars.converged);
    assert_eq!(cache.resident(&a).unwrap().0.windows.side(), Some(48));
    let out = solve_case(&b, &mut cache).unwrap();
    assert!(out.scalars.converged);
    assert!(cache.resident(&b).unwrap().0.windows.side().is_some());
    assert_eq!(cache.resident(&a).unwrap().0.windows.side(), None);
}
