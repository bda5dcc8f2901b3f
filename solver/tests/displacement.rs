//! Tangential loading under an imposed shift of the ball (issue #37): the
//! force follows Mindlin's first-loading curve under displacement control,
//! F(Δ) = μP [1 − (1 − Δ/δ*)^{3/2}], and beyond δ* the whole contact slides
//! at F = μP (PHYSICS.md §5c). Table 1(a) Fe, coupling off.
mod common;

use solver::normal::NormalProblem;
use solver::tangential::TangentialStart;
use solver::tangential_displacement::DisplacementProblem;
use solver::KernelCache;

const P: f64 = 20.0;
const MU: f64 = 0.28571;

/// δ* = 3μP(2 − ν)/(16 a G) with Hertz's a (Table 1a: E = 210 GPa, ν = 0.3).
fn delta_star() -> (f64, f64) {
    let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
    let a = (3.0 * P * r / (4.0 * e / (1.0 - nu * nu))).cbrt();
    let g = e / (2.0 * (1.0 + nu));
    (a, 3.0 * MU * P * (2.0 - nu) / (16.0 * a * g))
}

#[test]
fn imposed_shift_follows_mindlin_then_slides_at_mu_p() {
    let spec = common::table_1a_fe(128, 2.0, false, 0.0);
    let mut cache = KernelCache::new();
    let (res, _) = cache.resident(&spec).unwrap();
    let h0 = spec.initial_gap();
    let normal = res.solve_normal(&NormalProblem::new(&h0, P)).unwrap();
    let da = spec.grid.cell_area();
    let (a, ds) = delta_star();
    let mut last_deficit = f64::INFINITY;
    for ratio in [0.25, 0.5, 0.9, 1.5, 3.0] {
        let sol = res
            .solve_displacement(&DisplacementProblem {
                p: &normal.p,
                friction: MU,
                shift: [ratio * ds, 0.0],
                extra: None,
                tolerance: 1e-7,
                slip_floor: 0.0,
                max_iterations: 20_000,
                start: TangentialStart::Proportional,
            })
            .unwrap();
        let f: f64 = sol.qx.iter().sum::<f64>() * da;
        let fy: f64 = sol.qy.iter().sum::<f64>() * da;
        let expected = MU * P * (1.0 - (1.0 - ratio.min(1.0)).powf(1.5));
        let sticks = sol.stick.iter().filter(|&&s| s).count();
        println!(
            "Δ = {ratio} δ*: F/μP = {:.6} (Mindlin {:.6}, {:+.2e}), stick cells {sticks}, iterations {}, KKT {:.1e}",
            f / (MU * P),
            expected / (MU * P),
            f / expected - 1.0,
            sol.report.iterations,
            sol.report.change
        );
        assert!(sol.report.converged, "Δ = {ratio} δ*");
        assert!(fy.abs() < 1e-9 * MU * P);
        if ratio < 1.0 {
            assert!((f / expected - 1.0).abs() < 0.01, "Δ = {ratio} δ*");
            // The stick zone: c = a (1 − F/μP)^{1/3}, to a couple of cells.
            let c = (sticks as f64 * da / std::f64::consts::PI).sqrt();
            let c_m = a * (1.0 - f / (MU * P)).cbrt();
            assert!(
                (c - c_m).abs() < 2.0 * spec.grid.dx,
                "c = {c}, Mindlin {c_m}"
            );
        } else {
            // One step from rest: the tractions oppose the total slip, whose
            // Poisson part (C_xy) tilts them slightly off the shift, so F
            // approaches μP from below as the shift grows (an increment of
            // steady sliding has uniform slip and F = μP exactly).
            assert_eq!(sticks, 0, "gross slip leaves no stick cell");
            let deficit = 1.0 - f / (MU * P);
            assert!(
                deficit > 0.0 && deficit < 1e-3,
                "F = μP while sliding: {deficit:e}"
            );
            assert!(deficit < last_deficit, "F → μP as the shift grows");
            last_deficit = deficit;
        }
    }
}

/// Table 1a at 128² of 2 µm, coupling off, a displacement-controlled
/// fretting path 0 → +Δ → −Δ → +Δ (`cycles` full cycles), `steps` per segment.
fn fretting(amplitude: f64, cycles: usize, steps: usize) -> solver::CaseOutput {
    let mut spec = common::table_1a_fe(128, 2.0, false, 0.0);
    let mut shifts = vec![0.0, amplitude];
    for _ in 0..cycles {
        shifts.extend([-amplitude, amplitude]);
    }
    spec.history = Some(solver::LoadHistory {
        tangential_ratios: Vec::new(),
        normal_forces_n: None,
        increments: solver::Increments::Fixed(steps),
        sampling: Default::default(),
        shifts_m: Some(shifts),
        wear: None,
    });
    solver::solve_case(&spec, &mut KernelCache::new()).expect("the path solves")
}

/// Mindlin–Deresiewicz under displacement control, below δ*: the force
/// amplitude from δ(F*) = Δ, every branch and the energy per cycle.
#[test]
fn displacement_controlled_loop_below_delta_star_follows_mindlin_deresiewicz() {
    let (a, ds) = delta_star();
    let mp = MU * P;
    let amp = 0.5 * ds;
    let out = fretting(amp, 2, 20);
    let s = &out.scalars;
    let h = s.history.as_ref().unwrap();
    assert!(s.converged && h.steps.iter().all(|r| r.converged));
    let q_star = mp * (1.0 - (1.0 - amp / ds).powf(1.5));
    let first = |q: f64| ds * (1.0 - (1.0 - q / mp).powf(2.0 / 3.0));
    let unload = |q: f64| {
        ds * (2.0 * (1.0 - (q_star - q) / (2.0 * mp)).powf(2.0 / 3.0)
            - (1.0 - q_star / mp).powf(2.0 / 3.0)
            - 1.0)
    };
    let reload = |q: f64| -unload(-q);
    let mut worst: f64 = 0.0;
    for r in &h.steps {
        let (f, d) = (r.force_n[0], r.delta_t_m[0]);
        let closed = match r.segment {
            0 => continue,
            1 => first(f),
            k if k % 2 == 0 => unload(f),
            _ => reload(f),
        };
        worst = worst.max((d - closed).abs() / d.abs().max(0.1 * amp));
    }
    let f_star = h.force_amplitude_n.unwrap();
    let k = 2.0 * (2.0 - 0.3) * (1.0 + 0.3) / 210.0e9;
    let x = q_star / mp;
    let w = 9.0 * mp * mp * k / (10.0 * a)
        * (1.0 - (1.0 - x).powf(5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + (1.0 - x).powf(2.0 / 3.0)));
    let energy = h.dissipated_energy_per_cycle_j.unwrap();
    println!(
        "Δ = 0.5 δ*: F* = {:.6e} (MD {q_star:.6e}, {:+.2e}), worst branch error {worst:.2e}, energy {energy:.6e} (MD {w:.6e}, {:+.2e}), A = {:.4}, regime {:?}, δ* = {:.4e}",
        f_star,
        f_star / q_star - 1.0,
        energy / w - 1.0,
        h.energy_ratio.unwrap(),
        h.regime,
        h.shift_amplitude_m.unwrap()
    );
    assert!((f_star / q_star - 1.0).abs() < 0.01, "F*");
    assert!(worst < 0.01, "branches");
    assert!((energy / w - 1.0).abs() < 0.02, "energy per cycle");
    assert_eq!(h.regime.as_deref(), Some("partial"));
    assert!((h.shift_amplitude_m.unwrap() / amp - 1.0).abs() < 1e-12);
}

/// Beyond δ*: the whole contact slides at F = μP, and the energy per cycle
/// is W = 4μP(Δ − 0.8 δ*) (PHYSICS.md §5c).
#[test]
fn displacement_controlled_gross_slip_slides_at_mu_p_with_the_closed_form_energy() {
    let (_, ds) = delta_star();
    let mp = MU * P;
    for ratio in [1.5, 3.0] {
        let amp = ratio * ds;
        let out = fretting(amp, 1, 20);
        let s = &out.scalars;
        let h = s.history.as_ref().unwrap();
        assert!(s.converged && h.steps.iter().all(|r| r.converged));
        // The plateaus: increments where nothing sticks after the first
        // loading. Entering one, the increment's slip still carries the
        // elastic rest of the reversal, whose Poisson part tilts the
        // tractions (F/μP − 1 = −2.4e-4 at Δ = 1.5 δ*); with every sliding
        // increment of uniform slip the tilt decays, by about 3 per increment,
        // and F at a plateau's end is μP to 1e-6.
        let rows = &h.steps;
        let sliding = |r: &solver::HistoryStep| r.segment >= 2 && r.stick_area_m2 == 0.0;
        let mut ends = Vec::new();
        let mut worst: f64 = 0.0;
        for (k, r) in rows.iter().enumerate() {
            if !sliding(r) {
                continue;
            }
            let dev = r.force_n[0].abs() / mp - 1.0;
            worst = worst.max(dev.abs());
            if rows.get(k + 1).is_none_or(|n| n.segment != r.segment) {
                ends.push(dev);
            }
        }
        let energy = h.dissipated_energy_per_cycle_j.unwrap();
        let w = 4.0 * mp * (amp - 0.8 * ds);
        println!(
            "Δ = {ratio} δ*: plateau ends |F|/μP − 1 = {:?}, worst sliding {worst:.2e}, energy {energy:.6e} (closed form {w:.6e}, {:+.2e}), A = {:.4}, regime {:?}",
            ends.iter().map(|v| format!("{v:.1e}")).collect::<Vec<_>>(),
            energy / w - 1.0,
            h.energy_ratio.unwrap(),
            h.regime
        );
        assert!(ends.len() >= 2, "a plateau in each direction");
        assert!(
            ends.iter().all(|v| v.abs() < 1e-6),
            "F = μP at the plateaus' ends"
        );
        assert!(worst < 1e-3);
        assert!((energy / w - 1.0).abs() < 0.01, "energy per cycle");
        assert_eq!(h.regime.as_deref(), Some("gross"));
    }
}

/// The transition to gross slip: the smallest shift from rest at which no
/// cell sticks (bisection on one-step displacement-controlled solves; first
/// loading is path-independent) is δ*, and the loop at that amplitude has the
/// energy ratio A = 0.8 μP δ* / (4 μP δ*) = 0.2.
#[test]
fn transition_to_gross_slip_at_delta_star_with_energy_ratio_one_fifth() {
    let spec = common::table_1a_fe(128, 2.0, false, 0.0);
    let mut cache = KernelCache::new();
    let (res, _) = cache.resident(&spec).unwrap();
    let h0 = spec.initial_gap();
    let normal = res.solve_normal(&NormalProblem::new(&h0, P)).unwrap();
    let (_, ds) = delta_star();
    let mut slides = |ratio: f64| {
        let sol = res
            .solve_displacement(&DisplacementProblem {
                p: &normal.p,
                friction: MU,
                shift: [ratio * ds, 0.0],
                extra: None,
                tolerance: 1e-8,
                slip_floor: 0.0,
                max_iterations: 50_000,
                start: TangentialStart::Proportional,
            })
            .unwrap();
        assert!(sol.report.converged);
        !sol.stick.iter().any(|&s| s)
    };
    let (mut lo, mut hi) = (0.5, 1.5);
    assert!(!slides(lo) && slides(hi));
    for _ in 0..12 {
        let mid = 0.5 * (lo + hi);
        if slides(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let transition = 0.5 * (lo + hi);
    let out = fretting(transition * ds, 1, 20);
    let h = out.scalars.history.as_ref().unwrap();
    let ratio = h.energy_ratio.unwrap();
    println!(
        "transition at {transition:.5} δ* (bracket {lo:.5} – {hi:.5}); energy ratio there A = {ratio:.5}, regime {:?}",
        h.regime
    );
    assert!(
        (transition - 1.0).abs() < 0.01,
        "transition {transition} δ*"
    );
    assert!((ratio / 0.2 - 1.0).abs() < 0.02, "A = {ratio}");
}

/// The KKT residuals of a displacement-controlled solution, recomputed with
/// the whole grid's operator (the solver runs on a contact window): the
/// largest excess of a traction over its disc `|q|/μp − 1`, and relative to
/// `|δ|` the largest stick-cell slip `|C q + e − δ|` and slip-cell
/// misalignment `|w + |w| q/|q||` (`w` the slip: zero when the traction
/// opposes it), and the largest traction outside the contact.
fn kkt_on_grid(
    op: &mut solver::operator::Operator,
    p: &[f64],
    sol: &solver::tangential::TangentialSolution,
    shift: [f64; 2],
    extra: Option<(&[f64], &[f64])>,
) -> [f64; 4] {
    let n = p.len();
    let (mut sx, mut sy) = (vec![0.0; n], vec![0.0; n]);
    op.tangential(&sol.qx, &sol.qy, &mut sx, &mut sy);
    let scale = shift[0].hypot(shift[1]);
    let mut r = [0.0_f64; 4];
    for i in 0..n {
        let (qx, qy) = (sol.qx[i], sol.qy[i]);
        let q = qx.hypot(qy);
        if p[i] <= 0.0 {
            r[3] = r[3].max(q);
            continue;
        }
        let (ex, ey) = extra.map_or((0.0, 0.0), |(x, y)| (x[i], y[i]));
        let (wx, wy) = (sx[i] + ex - shift[0], sy[i] + ey - shift[1]);
        let b = MU * p[i];
        r[0] = r[0].max(q / b - 1.0);
        if q < (1.0 - 1e-9) * b {
            r[1] = r[1].max(wx.hypot(wy) / scale);
        } else {
            let w = wx.hypot(wy);
            r[2] = r[2].max((wx + w * qx / q).hypot(wy + w * qy / q) / scale);
        }
    }
    r
}

/// The previous state's displacement, negated: the extra term of an
/// increment from `sol`.
fn from_state(
    op: &mut solver::operator::Operator,
    sol: &solver::tangential::TangentialSolution,
) -> (Vec<f64>, Vec<f64>) {
    let n = sol.qx.len();
    let (mut ux, mut uy) = (vec![0.0; n], vec![0.0; n]);
    op.tangential(&sol.qx, &sol.qy, &mut ux, &mut uy);
    (
        ux.iter().map(|v| -v).collect(),
        uy.iter().map(|v| -v).collect(),
    )
}

/// The displacement-controlled solve meets its KKT conditions, checked on
/// its tractions independently of the solver (whole-grid operator, Table
/// 1a on a contact window): every traction within its disc, stick cells
/// without slip and slip cells' tractions opposing their slip, to the
/// tolerance relative to |δ|; from rest in partial and gross slip, and on
/// warm-started reversals from a partial-slip and a gross-slip state (the
/// increment's slip measured from the previous state, as a history does).
#[test]
fn displacement_solve_meets_the_kkt_conditions_on_the_whole_grid() {
    let tol = 1e-8;
    let (mut op, p) = common::hertz_fe(128, 3.7e-6);
    let mut windows = solver::window::WindowCache::default();
    let (_, ds) = delta_star();
    let problem = |shift: f64| DisplacementProblem {
        p: &p,
        friction: MU,
        shift: [shift, 0.0],
        extra: None,
        tolerance: tol,
        slip_floor: 0.0,
        max_iterations: 20_000,
        start: TangentialStart::Proportional,
    };
    let mut check = |op: &mut solver::operator::Operator,
                     prob: &DisplacementProblem,
                     what: &str| {
        let sol =
            solver::tangential_displacement::solve_displacement(op, &mut windows, prob).unwrap();
        let r = kkt_on_grid(op, &p, &sol, prob.shift, prob.extra);
        let sticks = sol.stick.iter().filter(|&&s| s).count();
        println!(
            "{what}: {} iterations ({} split updates), stick cells {sticks}, disc excess {:.1e}, stick slip {:.2e}, misalignment {:.2e} (reported {:.2e}, {:.2e})",
            sol.report.iterations,
            sol.report.split_updates,
            r[0],
            r[1],
            r[2],
            sol.report.stick_residual,
            sol.report.slip_residual
        );
        assert!(sol.report.converged, "{what}");
        assert!(r[0] <= 1e-12, "{what}: a traction over its disc");
        assert!(r[1] <= 1.01 * tol, "{what}: stick cells slip");
        assert!(r[2] <= 1.01 * tol, "{what}: slip against the traction");
        assert_eq!(r[3], 0.0, "{what}: traction outside the contact");
        sol
    };
    for ratio in [0.3, 0.9, 1.5] {
        let prev = check(
            &mut op,
            &problem(ratio * ds),
            &format!("{ratio} δ* from rest"),
        );
        // Reversal to −0.6 of the state's shift.
        let (ex, ey) = from_state(&mut op, &prev);
        let back = DisplacementProblem {
            extra: Some((&ex, &ey)),
            start: TangentialStart::Tractions(&prev.qx, &prev.qy),
            ..problem(-1.6 * ratio * ds)
        };
        check(&mut op, &back, &format!("{ratio} δ* → {} δ*", -0.6 * ratio));
    }
}

/// The force-controlled solver (projected CG, independent of the active set
/// but for the KKT test), given the force the displacement-controlled solve
/// returned, finds the imposed shift and the same tractions: from rest at
/// 0.5 δ* and on the warm-started reversal to −0.3 δ* (tolerance 1e-8 for
/// both: shifts within 1e-7, tractions within 1e-6 μ p_max).
#[test]
fn displacement_solve_agrees_with_the_force_solve_at_its_force() {
    use solver::tangential::{solve_tangential, TangentialMethod, TangentialProblem};
    let tol = 1e-8;
    let (mut op, p) = common::hertz_fe(128, 3.7e-6);
    let mut windows = solver::window::WindowCache::default();
    let da = op.grid().cell_area();
    let (_, ds) = delta_star();
    let compare = |op: &mut solver::operator::Operator,
                   windows: &mut solver::window::WindowCache,
                   prob: &DisplacementProblem,
                   what: &str| {
        let disp = solver::tangential_displacement::solve_displacement(op, windows, prob).unwrap();
        let force = [
            disp.qx.iter().sum::<f64>() * da,
            disp.qy.iter().sum::<f64>() * da,
        ];
        let forced = solve_tangential(
            op,
            windows,
            &TangentialProblem {
                p: &p,
                friction: MU,
                force,
                extra: prob.extra,
                tolerance: tol,
                slip_floor: 0.0,
                max_iterations: 20_000,
                start: prob.start,
                precondition: false,
                method: TangentialMethod::ConjugateGradient,
            },
        )
        .unwrap();
        let (dq, dt, stick) = common::tangential_difference(&disp, &forced, &p);
        println!(
            "{what}: F = {:.6e} N; displacement {} it, force {} it; max|Δq|/μp_max {dq:.2e}, Δδt/δt {dt:.2e}, stick cells differing {stick}",
            force[0], disp.report.iterations, forced.report.iterations
        );
        assert!(disp.report.converged && forced.report.converged, "{what}");
        assert!(dt < 1e-7, "{what}: the force's shift is the imposed one");
        assert!(dq < 1e-6, "{what}: the same tractions");
        assert!(stick <= 4, "{what}: the same stick zone");
        disp
    };
    let rest = DisplacementProblem {
        p: &p,
        friction: MU,
        shift: [0.5 * ds, 0.0],
        extra: None,
        tolerance: tol,
        slip_floor: 0.0,
        max_iterations: 20_000,
        start: TangentialStart::Proportional,
    };
    let prev = compare(&mut op, &mut windows, &rest, "0.5 δ* from rest");
    let (ex, ey) = from_state(&mut op, &prev);
    let back = DisplacementProblem {
        shift: [-0.8 * ds, 0.0],
        extra: Some((&ex, &ey)),
        start: TangentialStart::Tractions(&prev.qx, &prev.qy),
        ..rest
    };
    compare(&mut op, &mut windows, &back, "reversal 0.5 δ* → −0.3 δ*");
}
