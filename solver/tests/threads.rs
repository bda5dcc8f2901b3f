//! One case on several threads: the transforms, spectral products and
//! energy terms are shared out, and the solvers' vector passes run over
//! fixed pieces of cells whose partial sums are combined in piece order, so
//! the results with 1, 2 and 3 threads are identical to the bit.

mod common;

use common::table_1a_fe;
use solver::{solve_case, CaseOutput, CaseSpec, KernelCache, LoadHistory, Threads};

/// `spec` solved on `threads` threads; `every_size`: share the transforms
/// and vector passes however small the grid (the tests' grids are below the
/// size from which they are shared by default, and the test is about the
/// bits).
fn solve_with(spec: &CaseSpec, threads: usize, every_size: bool) -> CaseOutput {
    let mut cache = KernelCache::new();
    let t = Threads::new(threads).unwrap();
    cache.set_threads(if every_size { t.at_every_size() } else { t });
    solve_case(spec, &mut cache).unwrap()
}

/// Every scalar (but the timings), every field and every turning point's
/// fields of `a` and `b` to the bit.
fn assert_same_bits(a: &CaseOutput, b: &CaseOutput, what: &str) {
    let timeless = |o: &CaseOutput| {
        let mut s = o.scalars.clone();
        s.seconds = 0.0;
        s.kernel_seconds = 0.0;
        // Debug prints every f64 so that it reads back to the same bits.
        format!("{s:?}")
    };
    assert_eq!(timeless(a), timeless(b), "scalars, {what}");
    let same = |x: &[f64], y: &[f64]| {
        x.len() == y.len() && x.iter().zip(y).all(|(u, v)| u.to_bits() == v.to_bits())
    };
    for ((name, x), (_, y)) in a.fields.named().iter().zip(b.fields.named()) {
        assert!(same(x, y), "field {name} differs, {what}");
    }
    assert_eq!(a.turning.len(), b.turning.len(), "turning points, {what}");
    for (s, t) in a.turning.iter().zip(&b.turning) {
        assert_eq!(s.step, t.step);
        let fields = same(&s.p, &t.p) && same(&s.qx, &t.qx) && same(&s.qy, &t.qy);
        assert!(fields, "turning point {} differs, {what}", s.step);
    }
}

/// `spec` on 1, 2 and 3 threads: the same bits; returns the 1-thread output.
fn same_on_1_2_and_3_threads(spec: &CaseSpec, every_size: bool) -> CaseOutput {
    let one = solve_with(spec, 1, every_size);
    for threads in [2, 3] {
        let other = solve_with(spec, threads, every_size);
        assert_same_bits(&one, &other, &format!("{threads} threads"));
    }
    one
}

fn partial_slip(o: &CaseOutput) -> (usize, usize) {
    let stuck = o.fields.stick.iter().filter(|&&s| s > 0.5).count();
    let contact = o.fields.p.iter().filter(|&&p| p > 0.0).count();
    (stuck, contact)
}

/// Fe(111) under Table 1a's load at 30° (x and y tractions both non-zero),
/// coupled, on a domain of 3.6 Hertz radii so the tangential solver runs on
/// its contact window (a second operator) too.
#[test]
fn anisotropic_coupled_partial_slip_is_bit_identical_on_1_2_and_3_threads() {
    let mut spec = table_1a_fe(64, 6.0, true, 0.6);
    spec.material = solver::presets::material("Fe(111)").unwrap();
    spec.load.angle_deg = 30.0;
    let one = same_on_1_2_and_3_threads(&spec, true);
    assert!(one.scalars.converged);
    assert!(one.scalars.coupling_iterations > 1, "coupling ran");
    let (stuck, contact) = partial_slip(&one);
    assert!(
        stuck > 0 && stuck < contact,
        "partial slip: {stuck} of {contact}"
    );
}

/// Table 1a at 256², the size from which the transforms and the flat
/// passes over the grid are shared by default (no lowered grain): normal
/// contact alone (no tangential force), then coupled partial slip at 30°.
#[test]
fn table_1a_at_256_is_bit_identical_on_1_2_and_3_threads_at_the_default_grain() {
    let normal = table_1a_fe(256, 1.0, false, 0.0);
    let one = same_on_1_2_and_3_threads(&normal, false);
    assert!(one.scalars.converged);
    let mut coupled = table_1a_fe(256, 1.0, true, 0.6);
    coupled.load.angle_deg = 30.0;
    let one = same_on_1_2_and_3_threads(&coupled, false);
    assert!(one.scalars.converged);
    let (stuck, contact) = partial_slip(&one);
    assert!(
        stuck > 0 && stuck < contact,
        "partial slip: {stuck} of {contact}"
    );
}

/// A short fretting history (loading to 0.6 μP, unloading to −0.6 μP):
/// uncoupled at 128² (the increments' Fourier-preconditioned CG; 16 pieces
/// of the flat passes, 4–7 of the contact's), 4 increments a segment, and
/// coupled at 64² of 6 µm (a coupled increment costs several passes), 2.
#[test]
fn uncoupled_and_coupled_load_histories_are_bit_identical_on_1_2_and_3_threads() {
    for (coupling, n, spacing_um, steps) in [(false, 128, 2.0, 4), (true, 64, 6.0, 2)] {
        let spec = CaseSpec {
            history: Some(LoadHistory {
                tangential_ratios: vec![0.0, 0.6, -0.6],
                normal_forces_n: None,
                increments: solver::Increments::Fixed(steps),
                sampling: Default::default(),
                shifts_m: None,
                wear: None,
            }),
            ..table_1a_fe(n, spacing_um, coupling, 0.6)
        };
        let one = same_on_1_2_and_3_threads(&spec, true);
        assert!(one.scalars.converged, "coupling {coupling}");
        let h = one.scalars.history.as_ref().unwrap();
        // The frictionless normal loading, then 2 segments of increments.
        assert_eq!(h.steps.len(), 1 + 2 * steps, "coupling {coupling}");
        assert!(!one.turning.is_empty(), "coupling {coupling}");
    }
}

/// The active-set iteration (`solver.tangential_method = "active-set"`): a
/// coupled monotonic case and an uncoupled history, the same bits on 1, 2
/// and 3 threads at every size (its passes over the cells run in order; its
/// transforms are the operator's).
#[test]
fn the_active_set_iteration_is_bit_identical_on_1_2_and_3_threads() {
    for (coupling, history) in [(true, false), (false, true)] {
        let mut spec = table_1a_fe(128, 2.0, coupling, 0.6);
        spec.numerics.tangential_method = solver::TangentialMethod::ActiveSet;
        if history {
            spec.history = Some(LoadHistory {
                tangential_ratios: vec![0.0, 0.6, -0.6],
                normal_forces_n: None,
                increments: solver::Increments::Fixed(4),
                sampling: Default::default(),
                shifts_m: None,
                wear: None,
            });
        }
        let one = same_on_1_2_and_3_threads(&spec, true);
        assert!(one.scalars.converged, "coupling {coupling}");
    }
}

/// A surface with a hardness (issue #50): the capped conjugate gradient's
/// passes run over the same fixed pieces, so a coupled partial-slip case
/// whose plastic zone spans several pieces (64² of 4.5 µm, H = 0.7 p0 of
/// Hertz's peak) is the same bits on 1, 2 and 3 threads.
#[test]
fn a_capped_coupled_case_is_bit_identical_on_1_2_and_3_threads() {
    let mut spec = table_1a_fe(64, 4.5, true, 0.6);
    let (_, p0) = common::hertz_1a();
    spec.material = spec
        .material
        .with_limits(solver::Limits {
            hardness: Some(0.7 * p0),
            shear_limit: None,
        })
        .unwrap();
    let one = same_on_1_2_and_3_threads(&spec, true);
    assert!(one.scalars.converged);
    let capped = one.fields.p.iter().filter(|&&v| v >= 0.7 * p0).count();
    assert!(
        capped > 1024,
        "a plastic zone over several pieces: {capped} cells"
    );
    let (stuck, contact) = partial_slip(&one);
    assert!(
        stuck > 0 && stuck < contact,
        "partial slip: {stuck} of {contact}"
    );
}
