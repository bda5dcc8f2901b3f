//! One case on several threads: the transforms, spectral products and
//! energy terms are shared out, every sum stays in its serial order, so the
//! results with 1, 2 and 3 threads are identical to the bit.

mod common;

use common::table_1a_fe;
use solver::{solve_case, CaseOutput, KernelCache, Threads};

/// Fe(111) under Table 1a's load at 30° (x and y tractions both non-zero),
/// coupled, on a domain of 3.6 Hertz radii so the tangential solver runs on
/// its contact window (a second operator) too.
fn solve_with(threads: usize) -> CaseOutput {
    let mut spec = table_1a_fe(64, 6.0, true, 0.6);
    spec.material = solver::presets::material("Fe(111)").unwrap();
    spec.load.angle_deg = 30.0;
    let mut cache = KernelCache::new();
    // At 64² every transform is below the size from which stages are
    // shared by default: share them anyway, the test is about the bits.
    cache.set_threads(Threads::new(threads).unwrap().at_every_size());
    solve_case(&spec, &mut cache).unwrap()
}

#[test]
fn anisotropic_coupled_partial_slip_is_bit_identical_on_1_2_and_3_threads() {
    let one = solve_with(1);
    assert!(one.scalars.converged);
    assert!(one.scalars.coupling_iterations > 1, "coupling ran");
    let stuck = one.fields.stick.iter().filter(|&&s| s > 0.5).count();
    let contact = one.fields.p.iter().filter(|&&p| p > 0.0).count();
    assert!(
        stuck > 0 && stuck < contact,
        "partial slip: {stuck} of {contact}"
    );
    let timeless = |o: &CaseOutput| {
        let mut s = o.scalars.clone();
        s.seconds = 0.0;
        s.kernel_seconds = 0.0;
        // Debug prints every f64 so that it reads back to the same bits.
        format!("{s:?}")
    };
    for threads in [2, 3] {
        let other = solve_with(threads);
        assert_eq!(
            timeless(&one),
            timeless(&other),
            "scalars, {threads} threads"
        );
        for ((name, a), (_, b)) in one.fields.named().iter().zip(other.fields.named()) {
            let same =
                a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "field {name} differs with {threads} threads");
        }
    }
}
