//! One increment of a load path: a trial solve from the last accepted
//! state (`Walk::trial`), its dissipation cell by cell from the end
//! tractions (`cell_work`, `CellKind`) and the estimate of what the end
//! state cannot tell about the path inside it (`PathEstimate`), then its
//! acceptance into the path's rows, wear and dent (`Walk::accept`).

use super::output::{row, HistoryStep, StepSums};
use crate::error::SolverError;
use crate::model::spec::CaseSpec;
use crate::model::surface::Terrain;
use crate::operators::operator::{X, Y, Z};
use crate::solve::coupling::{solve_step, ContactState, Previous, Step, Target};
use crate::solve::normal::{NormalProblem, NormalSolution};
use crate::solve::resident::Resident;
use crate::solve::tangential::TangentialSolution;
use crate::solve::wear::Wearing;

/// With coupling, the normal surface displacement `uz(q)` of the tractions
/// of `tangential` (a normal solve's extra gap); empty without.
pub(super) fn traction_gap(
    res: &mut Resident,
    coupling: bool,
    tangential: &TangentialSolution,
) -> Vec<f64> {
    let mut hq = Vec::new();
    if coupling {
        hq = vec![0.0; tangential.qx.len()];
        res.operator.apply(
            &[(X, &tangential.qx), (Y, &tangential.qy)],
            &mut [(Z, &mut hq)],
        );
    }
    hq
}

/// Total tangential surface displacement `ut(q) + [ut(p) − ut(p⁰)]` (the
/// bracket only with coupling).
pub(super) fn displacement(
    res: &mut Resident,
    coupling: bool,
    (qx, qy): (&[f64], &[f64]),
    p: &[f64],
    p0: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let len = qx.len();
    let (mut ux, mut uy) = (vec![0.0; len], vec![0.0; len]);
    if coupling {
        let dp: Vec<f64> = p.iter().zip(p0).map(|(a, b)| a - b).collect();
        res.operator.apply(
            &[(X, qx), (Y, qy), (Z, &dp)],
            &mut [(X, &mut ux), (Y, &mut uy)],
        );
    } else {
        res.operator
            .apply(&[(X, qx), (Y, qy)], &mut [(X, &mut ux), (Y, &mut uy)]);
    }
    (ux, uy)
}

/// What an increment's end state cannot tell about the path inside it,
/// from that state and the one before (the embedded estimate of auto
/// increments; PHYSICS.md §5b and docs/physics-choices.md, "Increments
/// chosen by the path").
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PathEstimate {
    /// A bound on the error of the increment's dissipation, J: half the
    /// work whose friction bound changed over it (cells slipping at its end
    /// whose μp moved, those that came into contact during it, those that
    /// left it), and the chord-for-arc defect of slip cells whose
    /// direction turned.
    pub(super) error_j: f64,
    /// The increment's dissipation, J.
    pub(super) work_j: f64,
    /// The largest depth the increment wore (its cycle jump included), m.
    pub(super) worn_m: f64,
}

/// Inside an auto segment, the coupling loop's and the tangential solves'
/// tolerances are this many times the path's (1e-4 at the default, against
/// the configured 1e-7 and 1e-6): a pressure or a slip 1e-4 off moves an
/// increment's work by about that, a tenth of what the path accepts; the
/// segment's last increment, a turning point, is solved to the configured
/// tolerances.
pub(super) const INTERIOR_COUPLING: f64 = 0.1;

/// How the estimate weighs the work of the cells the contact's edge swept
/// over during an increment (the third of [`CellKind`]'s rule is a model):
/// on Table 1(a) Fe, coupled, at 256², the rule leaves the energy per
/// cycle −0.43 % and +0.04 % of the converged value at 1 and 2 increments
/// per segment, where the swept cells hold 9.3 % and 2.7 % of the work:
/// 0.046 and 0.015 of it.
pub(super) const EDGE_UNCERTAINTY: f64 = 0.05;

/// How a cell took part in an increment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum CellKind {
    /// In contact at both ends: its end traction does the work of its
    /// slip increment (the implicit law).
    Held,
    /// Came into contact during the increment. Its slip increment includes
    /// the relative motion before it touched, which dissipates nothing, and
    /// its bound rose from 0 at the contact's edge: it carries a third of
    /// its end traction's work, the mean over entry times spread evenly
    /// through the increment of `(1 − t_e)` times the mean of a bound that
    /// grows from the edge as the square root of the distance, 2/3 (as a
    /// contact's pressure does). With coupling the edge moves by a few
    /// cells as the tangential load reverses (Table 1(a) Fe at 256²: 788
    /// cells enter and 788 leave in a reversal); counted whole, their end
    /// traction's work made the energy per cycle 1.14 % high at one
    /// increment per segment and 0.50 % at two, against −0.43 % and
    /// +0.04 % with the third.
    Entered,
    /// Left contact during the increment: the same third of the work its
    /// start bound would do over its slip increment (its end traction is 0).
    Left,
}

/// What one cell did over an increment.
#[derive(Clone, Copy, Debug)]
pub(super) struct CellIncrement {
    pub(super) i: usize,
    pub(super) kind: CellKind,
    /// The pressure and the traction its work and wear are taken at, Pa.
    pub(super) p: f64,
    pub(super) q: [f64; 2],
    /// Its slip increment (the sphere's relative to the substrate), m.
    pub(super) ds: [f64; 2],
    /// Its friction bound's pressure at the start and the end, Pa.
    pub(super) bound: (f64, f64),
}

/// A solved increment not yet taken into the path.
pub(super) struct Trial {
    /// Its load (P, tangential target).
    pub(super) load: (f64, f64),
    /// Its tangential force (force control) or shift (displacement control) vector.
    pub(super) goal: [f64; 2],
    pub(super) state: ContactState,
    /// The total tangential surface displacement at its end.
    pub(super) v: (Vec<f64>, Vec<f64>),
    pub(super) estimate: PathEstimate,
    /// With a wear law, what each cell did over it (`each_cell`), which
    /// its acceptance wears by; empty without.
    pub(super) cells: Vec<CellIncrement>,
}

/// A load path as it is solved: the state after the last increment taken
/// and what the path has gathered so far.
pub(super) struct Walk<'a> {
    pub(super) spec: &'a CaseSpec,
    pub(super) terrain: &'a Terrain,
    pub(super) h0: &'a [f64],
    /// The pressure after the frictionless normal loading.
    pub(super) p0: Vec<f64>,
    pub(super) dir: [f64; 2],
    pub(super) displacement_control: bool,
    pub(super) last: ContactState,
    /// The total tangential surface displacement after the last increment.
    pub(super) u: (Vec<f64>, Vec<f64>),
    /// δt from the start of the path; its largest |·|; the last |Δδt|.
    pub(super) delta_t: [f64; 2],
    pub(super) delta_t_max: f64,
    pub(super) last_increment: f64,
    /// The permanent plastic penetration (with a hardness), m.
    pub(super) dent: Vec<f64>,
    /// The separation h0 + dent + worn depths (`None`: h0 itself).
    pub(super) dented: Option<Vec<f64>>,
    pub(super) wearing: Option<Wearing>,
    /// With a wear law: the normal contact on the surface the last
    /// increment wore, which the next starts from (and its tractions'
    /// normal displacement).
    pub(super) worn_normal: Option<(NormalSolution, Vec<f64>)>,
    /// The load of the last increment taken.
    pub(super) load: (f64, f64),
    pub(super) normal_iterations: usize,
    pub(super) tangential_iterations: usize,
    pub(super) coupling_iterations: usize,
    pub(super) converged: bool,
    pub(super) rows: Vec<HistoryStep>,
    pub(super) force_error_max: f64,
}

impl<'a> Walk<'a> {
    /// The separation the next increment sees.
    pub(super) fn separation(&self) -> &[f64] {
        self.dented.as_deref().unwrap_or(self.h0)
    }

    /// The pressure the next increment starts from: on the surface the last
    /// increment wore, or the last increment's.
    pub(super) fn start_pressure(&self) -> &[f64] {
        match &self.worn_normal {
            Some((n, _)) => &n.p,
            None => &self.last.p,
        }
    }

    /// With a hardness, the dent's deepest cell (the dent only grows).
    pub(super) fn deepest(&self) -> Option<f64> {
        self.spec
            .limits()
            .hardness
            .map(|_| self.dent.iter().cloned().fold(0.0, f64::max))
    }

    /// Solves the increment from the last state to `load` without taking it.
    pub(super) fn trial(
        &self,
        res: &mut Resident,
        load: (f64, f64),
        interior: Option<f64>,
        check: &impl Fn(&[f64]) -> Result<(), SolverError>,
    ) -> Result<Trial, SolverError> {
        let spec = self.spec;
        let num = spec.numerics_in_effect();
        let da = spec.grid.cell_area();
        let mu = spec.load.friction;
        let (p_k, f_k) = load;
        let h_now = self.separation();
        // The normal solve at the new load, from the last pressure (with
        // coupling, under the last tractions' normal displacement). With a
        // wear law, the pressure on the surface the last increment wore
        // (the last state is the one its tractions were solved with).
        let normal = if p_k == self.load.0 {
            let (p, approach) = match &self.worn_normal {
                Some((n, _)) => (n.p.clone(), n.approach),
                None => (self.last.p.clone(), self.last.approach),
            };
            NormalSolution {
                p,
                uz: Vec::new(),
                approach,
                // Nothing new flows at an unchanged load.
                plastic: Vec::new(),
                report: crate::solve::normal::NormalReport {
                    iterations: 0,
                    ..self.last.normal_report
                },
            }
        } else {
            // (The wear's normal solve made it for the same tractions.)
            let made;
            let hq = match &self.worn_normal {
                Some((_, hq)) => hq,
                None => {
                    made = traction_gap(res, num.coupling, &self.last.tangential);
                    &made
                }
            };
            res.solve_normal(&NormalProblem {
                extra_gap: num.coupling.then_some(&hq[..]),
                tolerance: num.tolerance,
                max_iterations: num.max_iterations,
                p_init: Some(&self.last.p),
                hardness: spec.limits().hardness,
                ..NormalProblem::new(h_now, p_k)
            })?
        };
        // Force control: the force at the increment's end; displacement
        // control: the shift still to impose to reach the target, the force
        // a result.
        let goal = [f_k * self.dir[0], f_k * self.dir[1]];
        let target = if self.displacement_control {
            Target::Shift([goal[0] - self.delta_t[0], goal[1] - self.delta_t[1]])
        } else {
            Target::Force(goal)
        };
        // The KKT tolerance relative to the loop's δt (see Step::tolerance_scale),
        // with the last increment's |Δδt| as the estimate of this one's.
        let tolerance_scale = if self.last_increment > 0.0 {
            (self.delta_t_max / self.last_increment).max(1.0)
        } else {
            1.0
        };
        // Inside an auto segment (`interior`: its looser tolerance) the
        // coupling loop stops at it, and the tangential solves at it
        // relative to the increment's own shift (not the loop's: an
        // increment of a tenth of the loop solved to 1e-4 of the loop's δt
        // left 1e-3 of its own work, and 76 of them 8e-3 of a cycle's).
        let (coupling_tolerance, tangential_tolerance) = match interior {
            Some(loose) => (
                num.coupling_tolerance.max(loose),
                num.tangential_tolerance.max(loose / tolerance_scale),
            ),
            None => (num.coupling_tolerance, num.tangential_tolerance),
        };
        // The previous tractions; the projection shifts them onto the new
        // force. (Adding the force increment spread like the pressure cost
        // 7–9 % more iterations on Table 1a at 128².)
        let state = solve_step(
            res,
            spec,
            h_now,
            normal,
            &Step {
                normal_force_n: p_k,
                target,
                previous: Some(Previous {
                    start: (&self.last.tangential.qx, &self.last.tangential.qy),
                    u: (&self.u.0, &self.u.1),
                    p0: &self.p0,
                }),
                tolerance_scale,
                coupling_tolerance,
                tangential_tolerance,
            },
        )?;
        check(&state.p)?;
        let v = displacement(
            res,
            num.coupling,
            (&state.tangential.qx, &state.tangential.qy),
            &state.p,
            &self.p0,
        );
        // Dissipation (`cell_work` of each cell's [`CellIncrement`]):
        // q_end · ds, ds = dδt − du the slip increment of the sphere
        // relative to the substrate (q opposes the substrate's slip).
        // Coulomb friction in increments puts a slipping cell's traction on
        // its disc at the increment's end, opposite to its slip increment
        // (PHYSICS.md §5b, "Which traction does the work"), so this is
        // μp|ds| in slip cells and 0 in stick cells: exact at any
        // increment size while the friction bound and the slip directions
        // stay fixed, where the trapezoid (q_prev + q)/2 · ds lost 26 % of
        // the energy per cycle at 2 increments per segment (Table 1(a) Fe,
        // 256²). A cell the contact's edge sweeps over during the
        // increment carries a third of it (see `CellKind`).
        let wear = self.wearing.as_ref().map(|w| w.depth_law());
        let (mut work, mut worn) = (0.0, 0.0_f64);
        // The estimate's parts: the signed change of the bound under slip,
        // the work of the cells the contact's edge swept, the direction
        // term (see `PathEstimate`).
        let (mut bound, mut swept, mut turned) = (0.0, 0.0, 0.0);
        let (q0x, q0y) = (&self.last.tangential.qx, &self.last.tangential.qy);
        let mut cells = Vec::new();
        self.each_cell(&state, &v, |c| {
            let w = cell_work(c.q, c.ds);
            work += w;
            let slip = c.ds[0].hypot(c.ds[1]);
            match c.kind {
                CellKind::Entered | CellKind::Left => swept += 3.0 * w,
                CellKind::Held if w > 0.0 => {
                    // Slipping at the start too, the same way: it slipped
                    // through the increment, under a bound that moved from
                    // μb0 to μb1, along a direction that may have turned
                    // (the chord the end state sees for the arc: 1 −
                    // sin(θ/2)/(θ/2) ≈ θ²/24 of it). A cell that began to
                    // slip inside the increment slipped late in it, near
                    // its end bound: charged for it, the coupled 64²
                    // contact of configs/fretting-map.toml asked for 76
                    // increments a reversal where 5 are within 1.2e-4.
                    let q0 = [q0x[c.i], q0y[c.i]];
                    let n0 = q0[0].hypot(q0[1]);
                    let dot = q0[0] * c.q[0] + q0[1] * c.q[1];
                    if n0 >= (1.0 - 1e-6) * mu * c.bound.0 && dot > 0.0 {
                        bound += 0.5 * mu * (c.bound.1 - c.bound.0) * slip;
                        let cross = q0[0] * c.q[1] - q0[1] * c.q[0];
                        let theta = cross.atan2(dot);
                        turned += w * theta * theta / 24.0;
                    }
                }
                CellKind::Held => {}
            }
            if let Some(law) = &wear {
                worn = worn.max(law(c.p, c.q, c.ds));
                cells.push(c);
            }
        });
        Ok(Trial {
            load,
            goal,
            state,
            v,
            estimate: PathEstimate {
                error_j: (bound.abs() + EDGE_UNCERTAINTY * swept + turned) * da,
                work_j: work * da,
                worn_m: worn,
            },
            cells,
        })
    }

    /// Calls `f` with what every cell in contact at the start or the end
    /// of the increment to `state` (whose total tangential surface
    /// displacement is `v`) did over it ([`CellIncrement`]).
    pub(super) fn each_cell(
        &self,
        state: &ContactState,
        v: &(Vec<f64>, Vec<f64>),
        mut f: impl FnMut(CellIncrement),
    ) {
        let spec = self.spec;
        let mu = spec.load.friction;
        let cover = self.terrain.cover.as_deref();
        let p_start = self.start_pressure();
        let b0 = spec.friction_pressure(p_start, cover);
        let b1 = spec.friction_pressure(&state.p, cover);
        let shift = state.tangential.shift;
        let (qx, qy) = (&state.tangential.qx, &state.tangential.qy);
        for i in 0..state.p.len() {
            if b0[i] <= 0.0 && b1[i] <= 0.0 {
                continue;
            }
            let ds = [
                shift[0] - (v.0[i] - self.u.0[i]),
                shift[1] - (v.1[i] - self.u.1[i]),
            ];
            let (kind, p, q) = if b1[i] <= 0.0 {
                // Left contact during the increment: it slipped under a
                // bound falling to 0 at the edge, along its slip.
                let slip = ds[0].hypot(ds[1]);
                let t = if slip > 0.0 {
                    mu * b0[i] / (3.0 * slip)
                } else {
                    0.0
                };
                (CellKind::Left, p_start[i] / 3.0, [t * ds[0], t * ds[1]])
            } else if b0[i] <= 0.0 {
                // Came into contact during it.
                (
                    CellKind::Entered,
                    state.p[i] / 3.0,
                    [qx[i] / 3.0, qy[i] / 3.0],
                )
            } else {
                (CellKind::Held, state.p[i], [qx[i], qy[i]])
            };
            f(CellIncrement {
                i,
                kind,
                p,
                q,
                ds,
                bound: (b0[i], b1[i]),
            });
        }
    }

    /// Takes the solved increment `trial` into the path, as an increment of
    /// `segment` (0-based): its dissipation, wear and dent, its row.
    pub(super) fn accept(
        &mut self,
        res: &mut Resident,
        trial: Trial,
        segment: usize,
        check: &impl Fn(&[f64]) -> Result<(), SolverError>,
    ) -> Result<(), SolverError> {
        let spec = self.spec;
        let num = spec.numerics_in_effect();
        let len = spec.grid.len();
        let mu = spec.load.friction;
        let h0 = self.h0;
        let Trial {
            load: (p_k, f_k),
            goal,
            state,
            v: (vx, vy),
            estimate,
            cells,
        } = trial;
        let shift = state.tangential.shift;
        // With a wear law, each cell wears by its slip increment with the
        // pressure and traction its dissipation is taken at (PHYSICS.md
        // §5d; the trial's `each_cell`).
        if let Some(w) = &mut self.wearing {
            w.clear_increment();
            for c in cells {
                w.wear_cell(c.i, c.p, c.q, c.ds);
            }
        }
        // With a wear law, the cells' slips δt − u halfway through the
        // increment and at its end (where the substrate's worn points are).
        let (ux, uy) = (&self.u.0, &self.u.1);
        let delta_t = self.delta_t;
        let slips = self.wearing.as_ref().map(|_| {
            let mid = |d: f64, s: f64, u0: &[f64], u1: &[f64]| -> Vec<f64> {
                (0..len)
                    .map(|i| d + 0.5 * s - 0.5 * (u0[i] + u1[i]))
                    .collect()
            };
            let end = |d: f64, u1: &[f64]| -> Vec<f64> { u1.iter().map(|u| d - u).collect() };
            (
                (
                    mid(delta_t[0], shift[0], ux, &vx),
                    mid(delta_t[1], shift[1], uy, &vy),
                ),
                (
                    end(delta_t[0] + shift[0], &vx),
                    end(delta_t[1] + shift[1], &vy),
                ),
            )
        });
        self.delta_t = [delta_t[0] + shift[0], delta_t[1] + shift[1]];
        self.last_increment = shift[0].hypot(shift[1]);
        self.delta_t_max = self.delta_t_max.max(self.delta_t[0].hypot(self.delta_t[1]));
        let mut step_converged = state.normal_report.converged
            && state.tangential.report.converged
            && state.coupling_converged;
        self.normal_iterations += state.normal_iterations;
        self.tangential_iterations += state.tangential_iterations;
        self.coupling_iterations += state.coupling_iterations;
        self.u = (vx, vy);
        self.worn_normal = None;
        // Whether the separation must be rewritten below: the dent grew,
        // or (with a wear law, whose substrate moves with the slips) always.
        let mut moved = !state.plastic.is_empty();
        if moved {
            self.dent
                .iter_mut()
                .zip(&state.plastic)
                .for_each(|(d, w)| *d += w);
        }
        // The separation of what follows: h0 + dent + the worn depths (the
        // substrate's at the points the slips brought under the cells).
        let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0);
        let rewrite = |dented: &mut Option<Vec<f64>>, dent: &[f64], wearing: &Option<Wearing>| {
            if let Some(h) = dented {
                for (i, v) in h.iter_mut().enumerate() {
                    *v = h0[i] + at(dent, i);
                }
                if let (Some(w), Some((_, (sx, sy)))) = (wearing, &slips) {
                    w.add_gap((sx, sy), h);
                }
            }
        };
        if let (Some(w), Some(((mx, my), _))) = (&mut self.wearing, &slips) {
            // The increment's wear, and the pressure on the worn surface
            // (the next increment starts from it; at a constant load no
            // other solve would see the wear without coupling). Without a
            // jump the depth is explicit, at the increment's end (the worn
            // volume is α times the energy to round-off). With a jump of M
            // cycles it is taken at the pressure it leaves, `M (dh/p) p'`:
            // a compliant layer in the normal solve, stable for any M
            // (applied explicitly, M dh oscillates from cell to cell once
            // cells are finer than ~0.03a, PHYSICS.md §5d).
            w.prepare(&state.p, (mx, my));
        }
        if self.wearing.is_some() {
            rewrite(&mut self.dented, &self.dent, &self.wearing);
            moved = false;
        }
        if let (Some(w), Some(((mx, my), _))) = (&mut self.wearing, &slips) {
            let hq = traction_gap(res, num.coupling, &state.tangential);
            let solved = res.solve_normal(&NormalProblem {
                extra_gap: num.coupling.then_some(&hq[..]),
                tolerance: num.tolerance,
                max_iterations: num.max_iterations,
                p_init: Some(&state.p),
                hardness: spec.limits().hardness,
                layer: w.layer(),
                ..NormalProblem::new(self.dented.as_deref().unwrap_or(h0), p_k)
            })?;
            check(&solved.p)?;
            w.commit(&solved.p, (mx, my));
            moved = w.implicit() || !solved.plastic.is_empty();
            if !solved.plastic.is_empty() {
                self.dent
                    .iter_mut()
                    .zip(&solved.plastic)
                    .for_each(|(d, w)| *d += w);
            }
            self.normal_iterations += solved.report.iterations;
            step_converged &= solved.report.converged;
            self.worn_normal = Some((solved, hq));
        }
        if moved {
            rewrite(&mut self.dented, &self.dent, &self.wearing);
        }
        self.converged &= step_converged;
        // The row: the state the increment solved (with a wear law, before
        // its own wear, which the next increment starts from).
        let mut r = row(
            spec,
            self.terrain,
            &state,
            &StepSums {
                step: self.rows.len(),
                segment: segment + 1,
                delta_t: self.delta_t,
                dissipated: estimate.work_j,
                converged: step_converged,
            },
        );
        if !self.displacement_control {
            let ferr = (r.force_n[0] - goal[0]).hypot(r.force_n[1] - goal[1]) / (mu * p_k);
            self.force_error_max = self.force_error_max.max(ferr);
        }
        r.worn_volume_m3 = self.wearing.as_ref().map_or(0.0, |w| w.volume);
        r.plastic_penetration_max_m = self.deepest();
        self.rows.push(r);
        self.last = state;
        self.load = (p_k, f_k);
        Ok(())
    }

    /// A hold (the load does not change): the last row again.
    pub(super) fn hold(&mut self, segment: usize) {
        let mut r = self.rows[self.rows.len() - 1].clone();
        r.step = self.rows.len();
        r.segment = segment + 1;
        r.dissipated_j = 0.0;
        self.rows.push(r);
    }
}

/// The energy a cell dissipates over an increment per unit area, J/m²: its
/// end-of-increment traction `q` against its slip increment `ds` (the
/// sphere's relative to the substrate), never below 0 (see the increment
/// loop of [`solve_history`]).
pub(crate) fn cell_work(q: [f64; 2], ds: [f64; 2]) -> f64 {
    (q[0] * ds[0] + q[1] * ds[1]).max(0.0)
}
