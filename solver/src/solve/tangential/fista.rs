//! The momentum step of accelerated projected gradient (FISTA) with
//! gradient-based adaptive restart (O'Donoghue & Candès 2015), shared by the
//! force-controlled tangential solver's fallback phase and the
//! displacement-controlled solver: one definition of the arithmetic, so both
//! stay the method they say they are.

/// The gradient mapping of a FISTA step from `y` to its projection `p` on
/// `cells`: the largest |y − p| (a traction; divided by the step it is a
/// slip), and whether the step went against the last move `p − q`, which
/// restarts the momentum.
fn mapping(
    cells: &[usize],
    (yx, yy): (&[f64], &[f64]),
    (px, py): (&[f64], &[f64]),
    (qx, qy): (&[f64], &[f64]),
) -> (f64, bool) {
    let (mut res, mut restart_dot) = (0.0_f64, 0.0);
    for &i in cells {
        let (dx, dy) = (yx[i] - px[i], yy[i] - py[i]);
        res = res.max(dx.hypot(dy));
        restart_dot += dx * (px[i] - qx[i]) + dy * (py[i] - qy[i]);
    }
    (res, restart_dot > 0.0)
}

/// Nesterov's sequence t_k of a FISTA iteration.
pub(crate) struct Momentum(f64);

impl Momentum {
    /// t₁ = 1.
    pub(crate) fn new() -> Self {
        Momentum(1.0)
    }

    /// The end of a FISTA iteration that projected `y` to `p` with `step`:
    /// the gradient mapping (a slip) relative to `scale`, which it returns,
    /// then the momentum step ([`Momentum::advance`]) to the next `q`, `y`.
    pub(crate) fn finish(
        &mut self,
        cells: &[usize],
        (qx, qy): (&mut [f64], &mut [f64]),
        (px, py): (&[f64], &[f64]),
        (yx, yy): (&mut [f64], &mut [f64]),
        (step, scale): (f64, f64),
    ) -> f64 {
        let (res, restart) = mapping(cells, (yx, yy), (px, py), (qx, qy));
        self.advance(restart, cells, (qx, qy), (px, py), (yx, yy));
        res / step / scale
    }

    /// Takes the projected point `p` as the new iterate `q` and extrapolates
    /// `y = p + β (p − q_old)` on `cells`, with β = (t_k − 1)/t_{k+1}; a
    /// restart (the last step went against the gradient mapping) sets β = 0
    /// and t back to 1.
    pub(crate) fn advance(
        &mut self,
        restart: bool,
        cells: &[usize],
        (qx, qy): (&mut [f64], &mut [f64]),
        (px, py): (&[f64], &[f64]),
        (yx, yy): (&mut [f64], &mut [f64]),
    ) {
        let t_k = self.0;
        let t_next = if restart {
            1.0
        } else {
            0.5 * (1.0 + (1.0 + 4.0 * t_k * t_k).sqrt())
        };
        let mom = if restart { 0.0 } else { (t_k - 1.0) / t_next };
        self.0 = t_next;
        for &i in cells {
            let (ox, oy) = (qx[i], qy[i]);
            qx[i] = px[i];
            qy[i] = py[i];
            yx[i] = px[i] + mom * (px[i] - ox);
            yy[i] = py[i] + mom * (py[i] - oy);
        }
    }
}
