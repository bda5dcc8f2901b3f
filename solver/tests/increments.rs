//! Load paths in increments chosen by the path (issue #60, PHYSICS.md §5b):
//! the dissipation from the increment's end against the closed forms and
//! against fine fixed increments, auto increments on every kind of path
//! (uncoupled and coupled fretting, Spence's normal loading with friction,
//! gross slip under displacement control, a capped surface, wear with a
//! cycle jump), and the findings of #59 on paths (negative energies, the
//! first loading worn M times, a path without tangential load, μa under
//! displacement control). Table 1a Fe at 128² of 2 µm throughout.
mod common;

use common::md::Md;
use common::{fretting_1a, table_1a_fe, LOAD_1A as P, MU_1A as MU};
use solver::{
    solve_case, CaseOutput, CaseSpec, HistoryOutput, Increments, KernelCache, LoadHistory,
    LoopSampling, Wear, WearLaw,
};

/// `cycles` fretting cycles of ±`amplitude` μP after the first loading, in
/// `increments`, coupled or not.
fn fretting(coupling: bool, amplitude: f64, cycles: usize, increments: Increments) -> CaseSpec {
    fretting_1a((128, 2.0), coupling, amplitude, cycles, increments)
}

fn auto() -> Increments {
    Increments::Auto {
        tolerance: solver::AUTO_TOLERANCE,
    }
}

fn solve(spec: &CaseSpec) -> CaseOutput {
    solve_case(spec, &mut KernelCache::new()).expect("the path solves")
}

fn history(out: &CaseOutput) -> &HistoryOutput {
    out.scalars.history.as_ref().expect("a history")
}

fn energy(out: &CaseOutput) -> f64 {
    history(out).dissipated_energy_per_cycle_j.unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Uncoupled fretting at ±0.6 μP: one increment per segment dissipates
/// what twenty do, within 5.8e-4 (measured; the slip directions of the
/// discrete contact turn a little as a slip zone grows: ν couples x and y
/// slips, and with ν = 0 the difference is 1e-6, below), and what
/// Mindlin–Deresiewicz's closed form does within the grid's 0.43 %. Auto
/// increments take one per segment and turn none down.
#[test]
fn one_increment_per_segment_dissipates_what_twenty_do_uncoupled() {
    let fine = energy(&solve(&fretting(false, 0.6, 2, Increments::Fixed(20))));
    let closed = Md::new().energy(0.6 * MU * P);
    assert!(rel(fine, closed) < 0.01, "{fine:e} vs {closed:e}");
    for k in [1, 2, 5] {
        let e = energy(&solve(&fretting(false, 0.6, 2, Increments::Fixed(k))));
        eprintln!("{k} per segment: {e:e} ({:+.2e} of 20's)", e / fine - 1.0);
        assert!(rel(e, fine) < 1e-3, "{k}: {e:e} vs {fine:e}");
        assert!(rel(e, closed) < 0.01, "{k}: {e:e} vs {closed:e}");
    }
    let out = solve(&fretting(false, 0.6, 2, auto()));
    let h = history(&out);
    assert_eq!(h.increments_per_segment, vec![1; 5]);
    assert_eq!(h.auto_rejected, Some(0));
    assert_eq!(h.auto_tolerance_met, Some(true));
    assert!(rel(energy(&out), fine) < 1e-3);
    // A loop of a few points is no loop: no area is claimed for it.
    assert_eq!(h.loop_area_per_cycle_j, None);
    // Every cycle's energy, from the dissipation (the two agree once the
    // loop has closed after the first cycle).
    assert_eq!(h.dissipated_per_cycle_j.len(), 2);
    assert!(rel(h.dissipated_per_cycle_j[0], h.dissipated_per_cycle_j[1]) < 1e-4);
}

/// Where the slip directions cannot turn (ν = 0: Cerruti's x–y coupling
/// vanishes, every slip is along the force) the end tractions' work is
/// exact at any increment size: one increment per segment and sixteen give
/// the same energy per cycle and end state to the solver's tolerance (the
/// trapezoid of before lost 26 % at two increments per segment).
#[test]
fn the_dissipation_is_exact_at_any_increment_size_where_slip_directions_are_fixed() {
    let with_nu0 = |k: usize| {
        let mut spec = fretting(false, 0.6, 1, Increments::Fixed(k));
        spec.material = solver::Material::isotropic("nu0", 210.0e9, 0.0).unwrap();
        solve(&spec)
    };
    let (one, fine) = (with_nu0(1), with_nu0(16));
    let (e1, e16) = (energy(&one), energy(&fine));
    eprintln!("ν = 0: {e1:e} in one increment a segment, {e16:e} in 16");
    assert!(rel(e1, e16) < 1e-5, "{e1:e} vs {e16:e}");
    assert!(rel(one.scalars.delta_t_m, fine.scalars.delta_t_m) < 1e-6);
    assert!(rel(one.scalars.stick_area_m2, fine.scalars.stick_area_m2) < 1e-6);
}

/// Coupled fretting: the contact's edge moves by a few cells as the force
/// reverses and the friction bound changes under slip, so the path matters
/// (one increment per segment: −0.43 %); auto increments bring the energy
/// per cycle within the tolerance of twenty increments per segment (5.2e-4
/// measured) in fewer increments.
#[test]
fn coupled_auto_increments_dissipate_what_twenty_do_within_the_tolerance() {
    let fine = solve(&fretting(true, 0.6, 1, Increments::Fixed(20)));
    let out = solve(&fretting(true, 0.6, 1, auto()));
    let h = history(&out);
    let (e, e20) = (energy(&out), energy(&fine));
    eprintln!(
        "coupled auto {e:e} in {:?} ({} turned down), 20 a segment {e20:e}",
        h.increments_per_segment,
        h.auto_rejected.unwrap()
    );
    assert!(rel(e, e20) < 1.5e-3, "{e:e} vs {e20:e}");
    assert!(h.increments_per_segment.iter().all(|&k| k < 20));
    assert!(out.scalars.converged);
    assert!(rel(out.scalars.delta_t_m, fine.scalars.delta_t_m) < 1e-3);
}

/// Every increment dissipates at least nothing (#59 item 4: one increment
/// per segment gave −8.7e-23 J a cycle with the trapezoid; heavy wear gave
/// negative increments), and a path of one increment per segment has a
/// positive energy per cycle.
#[test]
fn no_increment_dissipates_less_than_nothing() {
    let mut spec = fretting(true, 0.6, 2, Increments::Fixed(1));
    let out = solve(&spec);
    assert!(energy(&out) > 0.0);
    assert!(history(&out).steps.iter().all(|r| r.dissipated_j >= 0.0));
    // Heavy energy-law wear on the same path.
    let h = spec.history.as_mut().unwrap();
    h.wear = Some(Wear::new(WearLaw::Energy { alpha: 1e-11 }));
    h.increments = auto();
    let out = solve(&spec);
    let h = history(&out);
    assert!(h.steps.iter().all(|r| r.dissipated_j >= 0.0));
    // The energy law wears α times the dissipated energy, to round-off.
    let v = h.worn_volume_m3.unwrap();
    assert!(rel(v, 1e-11 * h.dissipated_total_j) < 1e-9, "{v:e}");
}

/// Spence's normal loading with friction (coupled, μ = 0.3, 0.5 → 20 N):
/// its stick zone depends on the path, and auto increments (the normal
/// load's change bounded by 25 tolerances of itself per increment: a
/// geometric progression) read the stick area of 400 fixed ones within
/// 0.5 %.
#[test]
fn spence_in_auto_increments_reads_the_stick_zone_of_fine_increments() {
    let spence = |increments: Increments| {
        let mut spec = table_1a_fe(128, 2.0, true, 0.0);
        spec.load.friction = 0.3;
        spec.history = Some(LoadHistory {
            tangential_ratios: vec![0.0, 0.0],
            normal_forces_n: Some(vec![0.5, 20.0]),
            increments,
            sampling: LoopSampling::default(),
            shifts_m: None,
            wear: None,
        });
        solve(&spec)
    };
    let (out, fine) = (spence(auto()), spence(Increments::Fixed(400)));
    let ratio = |o: &CaseOutput| (o.scalars.stick_area_m2 / o.scalars.contact_area_m2).sqrt();
    let (c, c_fine) = (ratio(&out), ratio(&fine));
    let taken = history(&out).increments_per_segment[0];
    eprintln!("Spence: c/a {c} in {taken} auto increments, {c_fine} in 400");
    assert!(rel(c, c_fine) < 5e-3, "{c} vs {c_fine}");
    assert!(c < 0.95 && taken < 400);
    // The last increments change P by at most 2.5 % of itself.
    let steps = &history(&out).steps;
    let last = &steps[steps.len() - 2..];
    let dp = (last[1].normal_force_n - last[0].normal_force_n) / last[0].normal_force_n;
    assert!(dp <= 0.025 * 1.001, "{dp}");
}

/// Gross slip under displacement control at Δ = 3δ*: a segment slides as
/// a whole in one increment, and the energy per cycle is 4μP(Δ − 0.8δ*)
/// within 0.5 % (6.7e-5 measured).
#[test]
fn gross_slip_in_auto_increments_dissipates_the_closed_form() {
    let md = Md::new();
    let amplitude = 3.0 * md.delta_star;
    let mut spec = table_1a_fe(128, 2.0, false, 0.0);
    spec.history = Some(LoadHistory {
        tangential_ratios: Vec::new(),
        normal_forces_n: None,
        increments: auto(),
        sampling: LoopSampling::default(),
        shifts_m: Some(vec![
            0.0, amplitude, -amplitude, amplitude, -amplitude, amplitude,
        ]),
        wear: None,
    });
    let out = solve(&spec);
    let h = history(&out);
    let closed = 4.0 * MU * P * (amplitude - 0.8 * md.delta_star);
    eprintln!(
        "gross slip: {:e} vs {closed:e} in {:?}",
        energy(&out),
        h.increments_per_segment
    );
    assert!(rel(energy(&out), closed) < 5e-3);
    assert_eq!(h.regime.as_deref(), Some("gross"));
    assert!(h.increments_per_segment.iter().all(|&k| k <= 2));
    // μa reads a force-controlled partial slip: none here (#59 item 10).
    assert_eq!(out.scalars.mu_a, None);
    assert_eq!(out.scalars.mu_a_cells, None);
}

/// A fretting path on a capped surface (H = 0.6 GPa against a Hertz peak
/// of 0.86 GPa), coupled: auto increments agree with twenty a segment
/// within 1e-3 in the energy per cycle (7.8e-4 measured) and the dent's
/// volume (3.4e-5).
#[test]
fn a_capped_path_in_auto_increments_agrees_with_twenty_a_segment() {
    let capped = |increments| {
        let mut spec = fretting(true, 0.6, 1, increments);
        spec.material.limits.hardness = Some(0.6e9);
        solve(&spec)
    };
    let (out, fine) = (capped(auto()), capped(Increments::Fixed(20)));
    let dent = |o: &CaseOutput| o.scalars.plastic.as_ref().unwrap().dent_volume_m3;
    eprintln!(
        "capped: {:e} vs {:e}, dent {:e} vs {:e}",
        energy(&out),
        energy(&fine),
        dent(&out),
        dent(&fine)
    );
    assert!(rel(energy(&out), energy(&fine)) < 1e-3);
    assert!(rel(dent(&out), dent(&fine)) < 1e-3);
}

/// A wear path (Archard, k = 1e-5 mm³/(N·m), 10⁴ physical cycles as 10
/// simulated): auto increments bound the depth an increment wears (1e-4 of
/// the approach) and agree with twenty a segment within 1e-3 in the energy
/// per cycle and the worn volume (3.0e-4 and 4.3e-4 measured).
#[test]
fn a_wear_path_in_auto_increments_agrees_with_twenty_a_segment() {
    let worn = |increments| {
        let mut spec = fretting(false, 0.6, 10, increments);
        spec.grid = solver::Grid::square(128, 2.5e-6);
        let h = spec.history.as_mut().unwrap();
        h.wear = Some(Wear {
            jump: 1000.0,
            ..Wear::new(WearLaw::Archard { k: 1e-14 })
        });
        solve(&spec)
    };
    let (out, fine) = (worn(auto()), worn(Increments::Fixed(20)));
    let volume = |o: &CaseOutput| history(o).worn_volume_m3.unwrap();
    eprintln!(
        "wear: energy {:e} vs {:e}, volume {:e} vs {:e}, {:?}",
        energy(&out),
        energy(&fine),
        volume(&out),
        volume(&fine),
        history(&out).increments_per_segment
    );
    assert!(rel(energy(&out), energy(&fine)) < 1e-3);
    assert!(rel(volume(&out), volume(&fine)) < 1e-3);
}

/// The first loading happens once and wears once whatever the cycle jump
/// (#59 item 11: it wore M times): after the first segment the worn volume
/// of a path with M = 50 is that of M = 1, to the bit.
#[test]
fn the_first_loading_wears_once_whatever_the_cycle_jump() {
    let worn_after_first = |jump: f64| {
        let mut spec = fretting(false, 0.6, 2, Increments::Fixed(4));
        let h = spec.history.as_mut().unwrap();
        h.wear = Some(Wear {
            jump,
            ..Wear::new(WearLaw::Archard { k: 1e-14 })
        });
        let out = solve(&spec);
        let h = history(&out);
        (
            h.steps[h.turning_steps[1]].worn_volume_m3,
            h.worn_volume_m3.unwrap(),
        )
    };
    let (first1, total1) = worn_after_first(1.0);
    let (first50, total50) = worn_after_first(50.0);
    assert!(first1 > 0.0);
    assert_eq!(first1.to_bits(), first50.to_bits());
    // The cycles do wear 50 times theirs (to the jump's own first-order
    // effect on the pressure).
    let ratio = (total50 - first50) / (total1 - first1);
    assert!((ratio / 50.0 - 1.0).abs() < 0.05, "{ratio}");
}

/// A path with no tangential load (#59 item 9): every increment converged
/// and every contact cell sticks, so the case is converged with its stick
/// zone the contact (it was `not_converged` with a stick radius of 0).
#[test]
fn a_path_without_tangential_load_converges_and_sticks_everywhere() {
    let mut spec = table_1a_fe(128, 2.0, false, 0.0);
    spec.history = Some(LoadHistory {
        tangential_ratios: vec![0.0],
        normal_forces_n: None,
        increments: auto(),
        sampling: LoopSampling::default(),
        shifts_m: None,
        wear: None,
    });
    let out = solve(&spec);
    assert!(out.scalars.converged);
    assert_eq!(out.scalars.stick_area_m2, out.scalars.contact_area_m2);
    // The stick zone's radius is the contact's (the friction reserve μp
    // weighs the cells as p does, to round-off).
    let (c, a) = (out.scalars.stick_radius_m, out.scalars.contact_radius_m);
    assert!(c > 0.0 && rel(c, a) < 1e-12, "c = {c:e}, a = {a:e}");
}

/// Impossible paths are errors that name the parameter (#59 items 2 and 5):
/// a wear coefficient above 0.1 mm³/(N·m), a shift beyond ten domains or
/// below a picometre.
#[test]
fn absurd_wear_and_shifts_are_refused_by_name() {
    let mut spec = fretting(false, 0.6, 1, auto());
    spec.history.as_mut().unwrap().wear = Some(Wear::new(WearLaw::Archard { k: 1e-7 }));
    let e = spec.validate().unwrap_err().to_string();
    assert!(e.contains("history.wear.k") && e.contains("0.1 mm³"), "{e}");
    for shift in [1e294, 1e-306] {
        let mut spec = table_1a_fe(128, 2.0, false, 0.0);
        spec.history = Some(LoadHistory {
            tangential_ratios: Vec::new(),
            normal_forces_n: None,
            increments: auto(),
            sampling: LoopSampling::default(),
            shifts_m: Some(vec![0.0, shift, -shift]),
            wear: None,
        });
        let e = spec.validate().unwrap_err().to_string();
        assert!(
            e.contains("history.shifts_m[1]") && e.contains("domain"),
            "{e}"
        );
    }
}
