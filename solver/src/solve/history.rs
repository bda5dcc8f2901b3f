//! Load histories (fretting): a case's load path solved increment by
//! increment, each from the previous increment's tractions and displacement
//! (Coulomb friction in increments, PHYSICS.md §5b), and what a fretting study
//! reads from it: the path's table, the energy dissipated per cycle, the
//! stiffness after a reversal and the residual shift. Knows the solvers only
//! through `coupling::solve_step`; writes no files.

use serde::{Deserialize, Serialize};

use crate::base::geometry::covered_area;
use crate::error::SolverError;
use crate::model::material::area_at_cap;
use crate::model::radii::{friction_reserve, zone_radius};
use crate::model::spec::{
    closes_cycle, full_cycles, looked_at_segments, same_point, CaseSpec, Increments, LoadHistory,
    AUTO_LOAD_STEP, AUTO_WEAR_STEP, MAX_HISTORY_STEPS,
};
use crate::model::surface::Terrain;
use crate::operators::operator::{X, Y, Z};
use crate::solve::coupling::{solve_step, ContactState, Previous, Step, Target};
use crate::solve::normal::{NormalProblem, NormalSolution};
use crate::solve::resident::Resident;
use crate::solve::tangential::TangentialSolution;
use crate::solve::wear::{CycleRows, Wearing};
pub use crate::solve::wear::{WearCycle, SCAR_DEFINITION, WEAR_JUMP_LIMIT};

/// How the dissipated energy is computed.
pub const DISSIPATION_DEFINITION: &str = "energy dissipated by slip, sum over increments and cells of max(0, q . (delta_t increment - u increment)) dA, q the shear tractions at the increment's end and u the total tangential surface displacement (Coulomb friction in increments puts a slipping cell's traction on its friction disc at the increment's end, opposite to its slip increment: exact at any increment size while the friction bound and the slip directions stay fixed); a cell that enters or leaves contact during the increment carries a third of its end (start) bound's work, mu p |ds| / 3; per cycle: over the last two segments that return to the same turning point";

/// One row of a load history: the state at the end of an increment.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HistoryStep {
    /// Increment number; 0 is the state after frictionless normal loading.
    pub step: usize,
    /// Segment of the path the increment belongs to (0 for step 0).
    pub segment: usize,
    /// Normal load recovered from the pressure, N.
    pub normal_force_n: f64,
    /// Tangential force recovered from the tractions, x and y, N.
    pub force_n: [f64; 2],
    /// Rigid tangential shift δt of the sphere from the start of the path, x and y, m.
    pub delta_t_m: [f64; 2],
    /// Rigid-body approach δz, m.
    pub delta_z_m: f64,
    /// Contact area (cells with p > 0), m².
    pub contact_area_m2: f64,
    /// Stick area (contact cells with |q| < μp), m².
    pub stick_area_m2: f64,
    /// The stick zone's own radius, its outline ([`crate::ZONE_RADIUS_DEFINITION`]), m.
    pub stick_radius_m: f64,
    /// Energy dissipated in this increment ([`DISSIPATION_DEFINITION`]), J.
    pub dissipated_j: f64,
    /// Worn volume from the start of the path to this increment, m³ (0
    /// without a wear law).
    #[serde(default)]
    pub worn_volume_m3: f64,
    /// With a hardness: the area of the cells whose pressure is at the cap
    /// (their covered part on cut cells), m² (`None`: elastic).
    #[serde(default)]
    pub plastic_area_m2: Option<f64>,
    /// With a hardness: the largest plastic penetration of the dent from
    /// the start of the path to this increment (it is permanent), m.
    #[serde(default)]
    pub plastic_penetration_max_m: Option<f64>,
    /// The increment's solves converged.
    pub converged: bool,
    /// How many increments the row's segment took (auto increments: what
    /// the path's error estimate chose; 0 for step 0).
    #[serde(default)]
    pub segment_increments: usize,
}

/// A solved load history and the quantities a fretting study reads from it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HistoryOutput {
    /// Unit vector of the case's force direction (positive tangential ratios).
    pub direction: [f64; 2],
    /// The state after every increment, step 0 first.
    pub steps: Vec<HistoryStep>,
    /// Step index of every turning point (the path's start first).
    pub turning_steps: Vec<usize>,
    /// Energy dissipated over the last full cycle (two segments that return
    /// to the same turning point), J; `None` if the path has no cycle.
    pub dissipated_energy_per_cycle_j: Option<f64>,
    /// Area of the same cycle's loop, ∮ F · dδt (trapezoidal rule over its
    /// rows), J: the independent check of `dissipated_energy_per_cycle_j`,
    /// only where that cycle's loop is sampled (`history.loop_increments`,
    /// or fixed increments); `None` elsewhere (a loop of a few increments
    /// is a polygon, not the loop).
    pub loop_area_per_cycle_j: Option<f64>,
    /// Secant tangential stiffness of the first increment after the last
    /// reversal of the tangential force, along the force direction, N/m.
    pub reversal_stiffness_n_per_m: Option<f64>,
    /// δt along the force direction where F crosses zero on the last
    /// unloading from a positive force (linear between increments), m.
    pub residual_delta_t_m: Option<f64>,
    /// Largest |ΔA Σq − F| over the increments, relative to μP.
    pub force_error_max: f64,
    /// Dissipated energy summed over the whole path, J.
    pub dissipated_total_j: f64,
    /// The energy dissipated over every full cycle, the first first, J.
    #[serde(default)]
    pub dissipated_per_cycle_j: Vec<f64>,
    /// The increments each segment took, the first segment first.
    #[serde(default)]
    pub increments_per_segment: Vec<usize>,
    /// The segments (0-based) whose rows sample the force–shift loop at a
    /// fixed resolution (`history.loop_increments`, or every segment with
    /// fixed increments); the others hold the increments auto chose, a few
    /// points of their loop.
    #[serde(default)]
    pub sampled_segments: Vec<usize>,
    /// With auto increments: the increments the error estimate solved and
    /// turned down for a smaller one (their solves are the estimate's cost).
    #[serde(default)]
    pub auto_rejected: Option<usize>,
    /// With auto increments: every increment met the tolerance (false: some
    /// reached the smallest increment, 1/4096 of a segment, or the path's
    /// limit of increments, and were taken above it).
    #[serde(default)]
    pub auto_tolerance_met: Option<bool>,
    /// The last full cycle's force amplitude F*: the largest |F| along the
    /// force direction over it, N.
    #[serde(default)]
    pub force_amplitude_n: Option<f64>,
    /// The last full cycle's shift amplitude δ*: the largest |δt| along the
    /// force direction over it, m.
    #[serde(default)]
    pub shift_amplitude_m: Option<f64>,
    /// The energy ratio A = W / (4 F* δ*) of the last full cycle (Fouvry's
    /// criterion: 0.2 at the transition to gross slip for a sphere).
    #[serde(default)]
    pub energy_ratio: Option<f64>,
    /// The slip regime over the path's full cycles ([`SLIP_REGIME_DEFINITION`]):
    /// `partial`, `gross`, or `mixed` when it changes between cycles.
    #[serde(default)]
    pub regime: Option<String>,
    /// With a wear law: the volume worn over the whole path, m³.
    #[serde(default)]
    pub worn_volume_m3: Option<f64>,
    /// With a wear law: the volume worn over the last full cycle, per
    /// physical cycle (with a cycle jump M, the simulated cycle's over
    /// M), m³.
    #[serde(default)]
    pub worn_volume_per_cycle_m3: Option<f64>,
    /// With a wear law: the largest worn depth, m.
    #[serde(default)]
    pub worn_depth_max_m: Option<f64>,
    /// With a wear law: every simulated full cycle's wear and loop, the
    /// first first (empty without a wear law or a full cycle).
    #[serde(default)]
    pub wear_cycles: Vec<WearCycle>,
    /// With a wear law and a full cycle: the largest depth a simulated
    /// cycle wore (with its jump), relative to the approach of the path's
    /// start. Above [`WEAR_JUMP_LIMIT`] the jump is too coarse for the
    /// profile's transient.
    #[serde(default)]
    pub wear_jump_ratio: Option<f64>,
    /// With a wear law for the ball: its worn volume over the whole path, m³.
    #[serde(default)]
    pub ball_worn_volume_m3: Option<f64>,
}

/// How [`HistoryOutput::regime`] is decided.
pub const SLIP_REGIME_DEFINITION: &str = "a full cycle is in gross slip when at some increment of it no contact cell sticks (every traction on its friction disc: the whole contact slides), in partial slip otherwise; the path is `partial` or `gross` when all its full cycles are, `mixed` when they differ";

/// The tractions of the state at a turning point of the path (what the
/// stresses below the surface of a load history are computed from).
#[derive(Clone, Debug, PartialEq)]
pub struct TurningState {
    /// The increment (a row of [`HistoryOutput::steps`]).
    pub step: usize,
    /// Pressure, Pa (row major, as [`crate::Fields`]).
    pub p: Vec<f64>,
    /// Shear traction x, Pa.
    pub qx: Vec<f64>,
    /// Shear traction y, Pa.
    pub qy: Vec<f64>,
}

impl TurningState {
    fn of(step: usize, state: &ContactState) -> Self {
        TurningState {
            step,
            p: state.p.clone(),
            qx: state.tangential.qx.clone(),
            qy: state.tangential.qy.clone(),
        }
    }
}

/// Sums of the solves over all increments.
pub(crate) struct HistoryState {
    /// The state after the last increment (iteration counts summed over all).
    pub last: ContactState,
    /// Every increment converged.
    pub converged: bool,
    /// The path's table and its reductions.
    pub output: HistoryOutput,
    /// The states at the turning points, the start first.
    pub turning: Vec<TurningState>,
    /// The worn depth per cell over the path, m (empty without wear).
    pub worn: Vec<f64>,
    /// The ball's worn depth in its own frame, m (empty unless it wears).
    pub ball_worn: Vec<f64>,
    /// The substrate's worn depth at the saved cycles (their numbers), m.
    pub worn_saved: Vec<(usize, Vec<f64>)>,
}

/// With coupling, the normal surface displacement `uz(q)` of the tractions
/// of `tangential` (a normal solve's extra gap); empty without.
fn traction_gap(res: &mut Resident, coupling: bool, tangential: &TangentialSolution) -> Vec<f64> {
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
fn displacement(
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

/// Smallest increment auto increments take, as a fraction of its segment:
/// where the estimate still asks for less, the increment is taken and the
/// path says the tolerance was not met ([`HistoryOutput::auto_tolerance_met`]).
const AUTO_MIN_FRACTION: f64 = 1.0 / 4096.0;

/// The load (P, tangential target) at fraction `t` of the segment from `a`
/// to `b` (`b` itself at `t = 1`).
fn along_segment(a: (f64, f64), b: (f64, f64), t: f64) -> (f64, f64) {
    if t >= 1.0 {
        b
    } else {
        (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
    }
}

/// What an increment's end state cannot tell about the path inside it,
/// from that state and the one before (the embedded estimate of auto
/// increments; PHYSICS.md §5b and docs/physics-choices.md, "Increments
/// chosen by the path").
#[derive(Clone, Copy, Debug, Default)]
struct PathEstimate {
    /// A bound on the error of the increment's dissipation, J: half the
    /// work whose friction bound changed over it (cells slipping at its end
    /// whose μp moved, those that came into contact during it, those that
    /// left it), and the chord-for-arc defect of slip cells whose
    /// direction turned.
    error_j: f64,
    /// The increment's dissipation, J.
    work_j: f64,
    /// The largest depth the increment wore (its cycle jump included), m.
    worn_m: f64,
}

/// Inside an auto segment, the coupling loop's and the tangential solves'
/// tolerances are this many times the path's (1e-4 at the default, against
/// the configured 1e-7 and 1e-6): a pressure or a slip 1e-4 off moves an
/// increment's work by about that, a tenth of what the path accepts; the
/// segment's last increment, a turning point, is solved to the configured
/// tolerances.
const INTERIOR_COUPLING: f64 = 0.1;

/// How the estimate weighs the work of the cells the contact's edge swept
/// over during an increment (the third of [`CellKind`]'s rule is a model):
/// on Table 1(a) Fe, coupled, at 256², the rule leaves the energy per
/// cycle −0.43 % and +0.04 % of the converged value at 1 and 2 increments
/// per segment, where the swept cells hold 9.3 % and 2.7 % of the work:
/// 0.046 and 0.015 of it.
const EDGE_UNCERTAINTY: f64 = 0.05;

/// How a cell took part in an increment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum CellKind {
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
struct CellIncrement {
    i: usize,
    kind: CellKind,
    /// The pressure and the traction its work and wear are taken at, Pa.
    p: f64,
    q: [f64; 2],
    /// Its slip increment (the sphere's relative to the substrate), m.
    ds: [f64; 2],
    /// Its friction bound's pressure at the start and the end, Pa.
    bound: (f64, f64),
}

/// A solved increment not yet taken into the path.
struct Trial {
    /// Its load (P, tangential target).
    load: (f64, f64),
    /// Its tangential force (force control) or shift (displacement control) vector.
    goal: [f64; 2],
    state: ContactState,
    /// The total tangential surface displacement at its end.
    v: (Vec<f64>, Vec<f64>),
    estimate: PathEstimate,
}

/// A load path as it is solved: the state after the last increment taken
/// and what the path has gathered so far.
struct Walk<'a> {
    spec: &'a CaseSpec,
    terrain: &'a Terrain,
    h0: &'a [f64],
    /// The pressure after the frictionless normal loading.
    p0: Vec<f64>,
    dir: [f64; 2],
    displacement_control: bool,
    last: ContactState,
    /// The total tangential surface displacement after the last increment.
    u: (Vec<f64>, Vec<f64>),
    /// δt from the start of the path; its largest |·|; the last |Δδt|.
    delta_t: [f64; 2],
    delta_t_max: f64,
    last_increment: f64,
    /// The permanent plastic penetration (with a hardness), m.
    dent: Vec<f64>,
    /// The separation h0 + dent + worn depths (`None`: h0 itself).
    dented: Option<Vec<f64>>,
    wearing: Option<Wearing>,
    /// With a wear law: the normal contact on the surface the last
    /// increment wore, which the next starts from (and its tractions'
    /// normal displacement).
    worn_normal: Option<(NormalSolution, Vec<f64>)>,
    /// The load of the last increment taken.
    load: (f64, f64),
    normal_iterations: usize,
    tangential_iterations: usize,
    coupling_iterations: usize,
    converged: bool,
    rows: Vec<HistoryStep>,
    force_error_max: f64,
}

impl<'a> Walk<'a> {
    /// The separation the next increment sees.
    fn separation(&self) -> &[f64] {
        self.dented.as_deref().unwrap_or(self.h0)
    }

    /// The pressure the next increment starts from: on the surface the last
    /// increment wore, or the last increment's.
    fn start_pressure(&self) -> &[f64] {
        match &self.worn_normal {
            Some((n, _)) => &n.p,
            None => &self.last.p,
        }
    }

    /// With a hardness, the dent's deepest cell (the dent only grows).
    fn deepest(&self) -> Option<f64> {
        self.spec
            .limits()
            .hardness
            .map(|_| self.dent.iter().cloned().fold(0.0, f64::max))
    }

    /// Solves the increment from the last state to `load` without taking it.
    fn trial(
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
        })
    }

    /// Calls `f` with what every cell in contact at the start or the end
    /// of the increment to `state` (whose total tangential surface
    /// displacement is `v`) did over it ([`CellIncrement`]).
    fn each_cell(
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
    fn accept(
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
            v: (mut vx, mut vy),
            estimate,
        } = trial;
        let shift = state.tangential.shift;
        // With a wear law, each cell wears by its slip increment with the
        // pressure and traction its dissipation is taken at (PHYSICS.md
        // §5d; `each_cell`).
        if self.wearing.is_some() {
            let mut depths = Vec::with_capacity(len);
            let v = (vx, vy);
            self.each_cell(&state, &v, |c| depths.push(c));
            (vx, vy) = v;
            if let Some(w) = &mut self.wearing {
                w.clear_increment();
                for c in depths {
                    w.wear_cell(c.i, c.p, c.q, c.ds);
                }
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
    fn hold(&mut self, segment: usize) {
        let mut r = self.rows[self.rows.len() - 1].clone();
        r.step = self.rows.len();
        r.segment = segment + 1;
        r.dissipated_j = 0.0;
        self.rows.push(r);
    }
}

/// Auto increments along a path: the step-size control of each segment
/// from the path's estimate ([`PathEstimate`]), and what it keeps from one
/// segment to the next.
#[derive(Debug)]
struct AutoSteps {
    /// The approach of the path's start (the worn depth's scale), m.
    approach0: f64,
    /// The dissipation of the last segment, J: the scale of the next one's
    /// energy tolerance.
    last_segment_work: f64,
    /// The mean fraction of its segment the last auto segment's increments
    /// took: the next segment's first try, and with it the size its
    /// increments grow to at most (a fretting path repeats its reversals:
    /// larger tries were turned down 4 times a reversal on Table 1(a) Fe,
    /// coupled, 256²).
    mean_span: f64,
    /// Increments solved and turned down.
    rejected: usize,
    /// Every increment met the tolerance.
    tolerance_met: bool,
}

impl Default for AutoSteps {
    fn default() -> Self {
        AutoSteps {
            approach0: 0.0,
            last_segment_work: 0.0,
            mean_span: 1.0,
            rejected: 0,
            tolerance_met: true,
        }
    }
}

impl AutoSteps {
    /// Solves the segment from load `a` to `b` (the path's `segment`) in
    /// as few increments as the estimate accepts at `tolerance`.
    fn segment(
        &mut self,
        walk: &mut Walk,
        res: &mut Resident,
        (a, b): ((f64, f64), (f64, f64)),
        segment: usize,
        tolerance: f64,
        check: &impl Fn(&[f64]) -> Result<(), SolverError>,
    ) -> Result<(), SolverError> {
        // The normal load may change by κ·tol of itself per increment (a
        // bound known before solving).
        let load_step = AUTO_LOAD_STEP * tolerance;
        // The largest increment from fraction t: ΔP within κ·tol of the
        // smaller load at its ends (a ramp 0.5 → 20 N takes 148 increments
        // in geometric progression, not 1560 of the smallest).
        let dp = (b.0 - a.0).abs();
        let most = |t: f64| {
            if dp > 0.0 {
                let p_t = a.0 + t * (b.0 - a.0);
                // Unloading, the smaller end is the increment's own.
                let smaller = if b.0 < a.0 {
                    p_t * (1.0 - load_step)
                } else {
                    p_t
                };
                (load_step * smaller / dp).min(1.0)
            } else {
                1.0
            }
        };
        let mut h = self.mean_span.min(most(0.0));
        let taken_before = walk.rows.len();
        let mut t = 0.0;
        // The segment's dissipation as its first trial sees it.
        let mut whole: Option<f64> = None;
        let moves = a.1 != b.1;
        while t < 1.0 {
            let t1 = if t + h >= 1.0 - 1e-9 { 1.0 } else { t + h };
            let load = along_segment(a, b, t1);
            if load == walk.load {
                walk.hold(segment);
                t = t1;
                continue;
            }
            // Inside the segment the coupling loop need only be as tight as
            // the path's tolerance can see; its last increment (a turning
            // point) is solved to the configured one.
            let interior = (t1 < 1.0).then_some(INTERIOR_COUPLING * tolerance);
            let trial = walk.trial(res, load, interior, check)?;
            let e = trial.estimate;
            let span = t1 - t;
            // The energy's share: its error against the tolerance's part of
            // the segment's dissipation (the last segment's, or the first
            // trial's over the whole segment: an increment of a first
            // loading dissipates as Q³ and is not held to its own share);
            // only where the tangential load moves.
            let whole = *whole.get_or_insert(e.work_j / span);
            let scale = self.last_segment_work.max(whole) * span;
            let energy = if moves && e.error_j > 0.0 {
                e.error_j / (tolerance * scale.max(f64::MIN_POSITIVE))
            } else {
                0.0
            };
            let pressure = (load.0 - walk.load.0).abs() / load.0.min(walk.load.0);
            let worn = e.worn_m / self.approach0.abs().max(f64::MIN_POSITIVE);
            let ratio = energy
                .max(pressure / load_step)
                .max(worn / (AUTO_WEAR_STEP * tolerance));
            let room = walk.rows.len() < MAX_HISTORY_STEPS;
            if ratio > 1.0 && span > AUTO_MIN_FRACTION && room {
                self.rejected += 1;
                h = (span * (0.9 / ratio).max(0.2)).max(AUTO_MIN_FRACTION);
                continue;
            }
            self.tolerance_met &= ratio <= 1.0;
            walk.accept(res, trial, segment, check)?;
            t = t1;
            // The estimate's error is second order in the increment, its
            // budget first order: the ratio grows as the increment.
            let grow = if ratio > 0.0 {
                (0.8 / ratio).min(1.5)
            } else {
                1.5
            };
            h = (span * grow).max(AUTO_MIN_FRACTION).min(most(t));
        }
        self.mean_span = 1.0 / (walk.rows.len() - taken_before).max(1) as f64;
        Ok(())
    }
}

/// How a segment is split into increments.
#[derive(Clone, Copy, Debug)]
enum Split {
    Fixed(usize),
    Auto(f64),
}

/// Solves the load path `history` of `spec` from the frictionless normal
/// solution `normal0` (under the first turning point's normal load) of the
/// separation `h0`. `check` is applied to every increment's pressure (the
/// contact must stay inside the domain).
pub(crate) fn solve_history(
    res: &mut Resident,
    spec: &CaseSpec,
    history: &LoadHistory,
    (h0, terrain): (&[f64], &Terrain),
    normal0: NormalSolution,
    check: impl Fn(&[f64]) -> Result<(), SolverError>,
) -> Result<HistoryState, SolverError> {
    let grid = spec.grid;
    let len = grid.len();
    let angle = spec.load.angle_deg.to_radians();
    let dir = [angle.cos(), angle.sin()];
    let points = history.turning_points(&spec.load);
    let cycle_ends = full_cycles(&points);
    let cycles_total = cycle_ends.len();
    let looked_at = looked_at_segments(&points, history.sampling.every);

    // On a surface with a hardness, the plastic penetration is permanent:
    // every increment's adds to the dent, and the separation the next
    // increment sees is the initial one plus the dent (unloading leaves it).
    // Worn depth likewise, with a wear law (the surface recedes).
    let dent = normal0.plastic.clone();
    let wearing = history.wear.map(|w| Wearing::new(w, grid));
    let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0);
    let dented: Option<Vec<f64>> = (!dent.is_empty() || wearing.is_some())
        .then(|| (0..len).map(|i| h0[i] + at(&dent, i)).collect());
    let converged = normal0.report.converged;
    // The state after frictionless normal loading: no tractions, every
    // contact cell sticks (solved: nothing was asked of it).
    let last = ContactState {
        p: normal0.p,
        approach: normal0.approach,
        plastic: normal0.plastic,
        tangential: TangentialSolution {
            qx: vec![0.0; len],
            qy: vec![0.0; len],
            sx: vec![0.0; len],
            sy: vec![0.0; len],
            stick: vec![true; len],
            shift: [0.0; 2],
            report: crate::solve::tangential::TangentialReport {
                converged: true,
                ..Default::default()
            },
        },
        normal_report: normal0.report,
        normal_iterations: normal0.report.iterations,
        tangential_iterations: 0,
        coupling_iterations: 0,
        coupling_change: 0.0,
        coupling_converged: true,
    };
    let mut walk = Walk {
        spec,
        terrain,
        h0,
        p0: last.p.clone(),
        dir,
        displacement_control: history.displacement_controlled(),
        u: (vec![0.0; len], vec![0.0; len]),
        delta_t: [0.0; 2],
        delta_t_max: 0.0,
        last_increment: 0.0,
        dent,
        dented,
        wearing,
        worn_normal: None,
        load: points[0],
        normal_iterations: last.normal_iterations,
        tangential_iterations: 0,
        coupling_iterations: 0,
        converged,
        rows: Vec::new(),
        force_error_max: 0.0,
        last,
    };
    let mut first = row(
        spec,
        terrain,
        &walk.last,
        &StepSums {
            step: 0,
            segment: 0,
            delta_t: [0.0; 2],
            dissipated: 0.0,
            converged,
        },
    );
    first.stick_area_m2 = first.contact_area_m2;
    first.plastic_penetration_max_m = walk.deepest();
    walk.rows.push(first);
    let approach0 = walk.last.approach;
    let mut turning_steps = vec![0];
    let mut turning = vec![TurningState::of(0, &walk.last)];
    let mut increments_per_segment = Vec::with_capacity(points.len() - 1);
    let mut sampled_segments = Vec::new();
    // The first segment of the first full cycle: the segments before it
    // (the first loading) happen once whatever the wear's cycle jump.
    let cycles_from = cycle_ends.first().map_or(usize::MAX, |&t| t - 2);
    let mut auto = AutoSteps {
        approach0,
        ..Default::default()
    };
    let segments = points.len() - 1;

    for (segment, pair) in points.windows(2).enumerate() {
        crate::base::progress::segment(segment + 1, segments)?;
        let (a, b) = (pair[0], pair[1]);
        if let Some(w) = walk.wearing.as_mut() {
            w.set_cycles(segment >= cycles_from);
        }
        // Fixed increments split every segment alike (every loop is
        // sampled); auto ones sample the loops of the cycles looked at.
        let split = match history.increments {
            Increments::Fixed(k) => Split::Fixed(k),
            Increments::Auto { .. }
                if history.sampling.increments > 0 && looked_at.contains(&segment) =>
            {
                Split::Fixed(history.sampling.increments)
            }
            Increments::Auto { tolerance } => Split::Auto(tolerance),
        };
        if let Split::Fixed(_) = split {
            sampled_segments.push(segment);
        }
        let rows_before = walk.rows.len();
        let work_before: f64 = walk.rows.iter().map(|r| r.dissipated_j).sum();
        match split {
            Split::Fixed(k) => {
                for m in 1..=k {
                    let load = along_segment(a, b, m as f64 / k as f64);
                    if load == walk.load {
                        walk.hold(segment);
                        continue;
                    }
                    let trial = walk.trial(res, load, None, &check)?;
                    walk.accept(res, trial, segment, &check)?;
                }
            }
            Split::Auto(tolerance) => {
                auto.segment(&mut walk, res, (a, b), segment, tolerance, &check)?;
            }
        }
        let taken = walk.rows.len() - rows_before;
        increments_per_segment.push(taken);
        for r in &mut walk.rows[rows_before..] {
            r.segment_increments = taken;
        }
        auto.last_segment_work =
            walk.rows.iter().map(|r| r.dissipated_j).sum::<f64>() - work_before;
        turning_steps.push(walk.rows.len() - 1);
        turning.push(TurningState::of(walk.rows.len() - 1, &walk.last));
        let t = segment + 1;
        if let (Some(w), true) = (&mut walk.wearing, cycle_ends.contains(&t)) {
            let number = w.cycles.len() + 1;
            let save = number == cycles_total || looked_at.contains(&segment);
            let looped = cycle_rows(&walk.rows, (turning_steps[t - 2], turning_steps[t]), dir);
            w.record(terrain, &walk.last.p, &looped, save);
        }
    }
    let Walk {
        mut last,
        delta_t,
        dent,
        wearing,
        rows,
        normal_iterations,
        tangential_iterations,
        coupling_iterations,
        converged,
        force_error_max,
        ..
    } = walk;
    // The final state's shift is δt from the start of the path, not the
    // last increment's.
    last.tangential.shift = delta_t;
    // The final state's plastic penetration is the whole path's dent.
    last.plastic = dent;
    last.normal_iterations = normal_iterations;
    last.tangential_iterations = tangential_iterations;
    last.coupling_iterations = coupling_iterations;
    let mut wearing = wearing;
    let wear = wearing.as_ref().map(|w| (&w.worn[..], w.settings().jump));
    let sampled_last = cycle_ends
        .last()
        .is_some_and(|&t| looked_at.contains(&(t - 1)) && history.sampling.increments > 0)
        || matches!(history.increments, Increments::Fixed(_));
    let mut output = reduce_history(
        dir,
        rows,
        &points,
        turning_steps,
        force_error_max,
        wear,
        sampled_last,
    );
    output.increments_per_segment = increments_per_segment;
    output.sampled_segments = sampled_segments;
    if let Increments::Auto { .. } = history.increments {
        output.auto_rejected = Some(auto.rejected);
        output.auto_tolerance_met = Some(auto.tolerance_met);
    }
    if let Some(w) = wearing.as_mut() {
        output.wear_jump_ratio = w
            .cycles
            .iter()
            .map(|c| c.depth_increment_max_m / approach0.abs().max(f64::MIN_POSITIVE))
            .reduce(f64::max);
        output.ball_worn_volume_m3 = w.settings().ball.map(|_| w.ball_volume);
        output.wear_cycles = std::mem::take(&mut w.cycles);
    }
    let (worn, ball_worn, worn_saved) = match wearing {
        Some(w) => (w.worn, w.ball, w.saved),
        None => (Vec::new(), Vec::new(), Vec::new()),
    };
    Ok(HistoryState {
        last,
        converged,
        output,
        turning,
        worn,
        ball_worn,
        worn_saved,
    })
}

/// What the rows of a full cycle (turning steps `s0` to `s1`) say.
fn cycle_rows(steps: &[HistoryStep], (s0, s1): (usize, usize), dir: [f64; 2]) -> CycleRows {
    let along = |v: [f64; 2]| v[0] * dir[0] + v[1] * dir[1];
    let rows = &steps[s0..=s1];
    CycleRows {
        dissipated: rows[1..].iter().map(|r| r.dissipated_j).sum(),
        force_amplitude: rows
            .iter()
            .map(|r| along(r.force_n).abs())
            .fold(0.0, f64::max),
        shift_amplitude: rows
            .iter()
            .map(|r| along(r.delta_t_m).abs())
            .fold(0.0, f64::max),
        gross: rows[1..]
            .iter()
            .any(|r| r.stick_area_m2 == 0.0 && r.contact_area_m2 > 0.0),
        stick_radius_min: rows[1..]
            .iter()
            .map(|r| r.stick_radius_m)
            .fold(f64::INFINITY, f64::min),
        worn_volume: (steps[s0].worn_volume_m3, steps[s1].worn_volume_m3),
    }
}

/// The energy a cell dissipates over an increment per unit area, J/m²: its
/// end-of-increment traction `q` against its slip increment `ds` (the
/// sphere's relative to the substrate), never below 0 (see the increment
/// loop of [`solve_history`]).
pub(crate) fn cell_work(q: [f64; 2], ds: [f64; 2]) -> f64 {
    (q[0] * ds[0] + q[1] * ds[1]).max(0.0)
}

/// What a row needs besides the contact state.
struct StepSums {
    step: usize,
    segment: usize,
    delta_t: [f64; 2],
    dissipated: f64,
    converged: bool,
}

/// The table row of a solved increment on the surface's `terrain`.
fn row(spec: &CaseSpec, terrain: &Terrain, state: &ContactState, sums: &StepSums) -> HistoryStep {
    let grid = spec.grid;
    let (len, da) = (grid.len(), grid.cell_area());
    let p = &state.p;
    let tan = &state.tangential;
    let mu = spec.load.friction;
    let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
    let stick: Vec<bool> = (0..len).map(|i| contact[i] && tan.stick[i]).collect();
    let count = |v: &[bool]| covered_area(v, terrain.cover.as_deref(), da);
    let stick_radius = if stick.iter().any(|&b| b) {
        let bound = spec.friction_pressure(p, terrain.cover.as_deref());
        let reserve = friction_reserve(mu, &bound, (&tan.qx, &tan.qy));
        zone_radius(&grid, &stick, &reserve, terrain)
    } else {
        0.0
    };
    HistoryStep {
        step: sums.step,
        segment: sums.segment,
        normal_force_n: p.iter().sum::<f64>() * da,
        force_n: [
            tan.qx.iter().sum::<f64>() * da,
            tan.qy.iter().sum::<f64>() * da,
        ],
        delta_t_m: sums.delta_t,
        delta_z_m: state.approach,
        contact_area_m2: count(&contact),
        stick_area_m2: count(&stick),
        stick_radius_m: stick_radius,
        dissipated_j: sums.dissipated,
        worn_volume_m3: 0.0,
        plastic_area_m2: spec
            .limits()
            .hardness
            .map(|hardness| area_at_cap(hardness, terrain.cover.as_deref(), p, da)),
        plastic_penetration_max_m: None,
        converged: sums.converged,
        segment_increments: 0,
    }
}

/// The cycle, reversal and residual-shift reductions of a solved path, and
/// with a wear law (`wear`: the worn depth and the cycle jump) its wear.
fn reduce_history(
    dir: [f64; 2],
    steps: Vec<HistoryStep>,
    points: &[(f64, f64)],
    turning_steps: Vec<usize>,
    force_error_max: f64,
    wear: Option<(&[f64], f64)>,
    sampled_last: bool,
) -> HistoryOutput {
    let along = |v: [f64; 2]| v[0] * dir[0] + v[1] * dir[1];
    // The last full cycle: segments j, j+1 that return to turning point j.
    let cycle = (0..points.len().saturating_sub(2))
        .rev()
        .find(|&j| closes_cycle(points, j + 2))
        .map(|j| (turning_steps[j], turning_steps[j + 2]));
    let (dissipated, loop_area) = match cycle {
        Some((s0, s1)) if !sampled_last => {
            (Some(cycle_rows(&steps, (s0, s1), dir).dissipated), None)
        }
        Some((s0, s1)) => {
            let d = cycle_rows(&steps, (s0, s1), dir).dissipated;
            let area: f64 = (s0 + 1..=s1)
                .map(|k| {
                    let (a, b) = (&steps[k - 1], &steps[k]);
                    (0..2)
                        .map(|c| {
                            0.5 * (a.force_n[c] + b.force_n[c]) * (b.delta_t_m[c] - a.delta_t_m[c])
                        })
                        .sum::<f64>()
                })
                .sum();
            (Some(d), Some(area))
        }
        None => (None, None),
    };
    // The last reversal: a turning point where F along the direction turns back.
    let reversal = (1..points.len().saturating_sub(1)).rev().find(|&j| {
        let (d0, d1) = (points[j].1 - points[j - 1].1, points[j + 1].1 - points[j].1);
        d0 * d1 < 0.0
    });
    let reversal_stiffness = reversal.and_then(|j| {
        let s = turning_steps[j];
        let (a, b) = (steps.get(s)?, steps.get(s + 1)?);
        let dd = along(b.delta_t_m) - along(a.delta_t_m);
        (dd != 0.0).then(|| (along(b.force_n) - along(a.force_n)) / dd)
    });
    // The last unloading from a positive force through zero.
    let residual = (0..points.len().saturating_sub(1))
        .rev()
        .find(|&j| points[j].1 > 0.0 && points[j + 1].1 < 0.0)
        .and_then(|j| {
            (turning_steps[j] + 1..=turning_steps[j + 1]).find_map(|k| {
                let (a, b) = (&steps[k - 1], &steps[k]);
                let (fa, fb) = (along(a.force_n), along(b.force_n));
                (fa > 0.0 && fb <= 0.0).then(|| {
                    let t = fa / (fa - fb);
                    along(a.delta_t_m) + t * (along(b.delta_t_m) - along(a.delta_t_m))
                })
            })
        });
    let dissipated_total_j = steps.iter().map(|r| r.dissipated_j).sum();
    let dissipated_per_cycle_j = full_cycles(points)
        .iter()
        .map(|&t| cycle_rows(&steps, (turning_steps[t - 2], turning_steps[t]), dir).dissipated)
        .collect();
    // Amplitudes and the energy ratio of the last cycle.
    let (force_amplitude_n, shift_amplitude_m, energy_ratio) = match (cycle, dissipated) {
        (Some((s0, s1)), Some(w)) => {
            let rows = cycle_rows(&steps, (s0, s1), dir);
            let (f, d) = (rows.force_amplitude, rows.shift_amplitude);
            let ratio = (f > 0.0 && d > 0.0).then(|| w / (4.0 * f * d));
            (Some(f), Some(d), ratio)
        }
        _ => (None, None, None),
    };
    // The regime of every full cycle, from the last one back.
    let mut regimes = Vec::new();
    let mut j = cycle.map(|(s0, _)| turning_steps.iter().position(|&t| t == s0));
    while let Some(Some(k)) = j {
        if k + 2 >= points.len() || !same_point(points[k], points[k + 2]) {
            break;
        }
        let (s0, s1) = (turning_steps[k], turning_steps[k + 2]);
        regimes.push(cycle_rows(&steps, (s0, s1), dir).gross);
        j = (k >= 2).then(|| Some(k - 2));
    }
    // The rows carry the volume worn so far.
    // Per physical cycle: a simulated one stands for `jump`.
    let worn_volume = wear.and(steps.last().map(|r| r.worn_volume_m3));
    let worn_per_cycle = wear
        .zip(cycle)
        .map(|((_, jump), (s0, s1))| (steps[s1].worn_volume_m3 - steps[s0].worn_volume_m3) / jump);
    let worn_depth_max = wear.map(|(worn, _)| worn.iter().cloned().fold(0.0, f64::max));
    let regime = (!regimes.is_empty()).then(|| {
        if regimes.iter().all(|&g| g) {
            "gross".to_string()
        } else if regimes.iter().all(|&g| !g) {
            "partial".to_string()
        } else {
            "mixed".to_string()
        }
    });
    HistoryOutput {
        direction: dir,
        steps,
        turning_steps,
        dissipated_energy_per_cycle_j: dissipated,
        loop_area_per_cycle_j: loop_area,
        reversal_stiffness_n_per_m: reversal_stiffness,
        residual_delta_t_m: residual,
        force_error_max,
        dissipated_total_j,
        dissipated_per_cycle_j,
        increments_per_segment: Vec::new(),
        sampled_segments: Vec::new(),
        auto_rejected: None,
        auto_tolerance_met: None,
        force_amplitude_n,
        shift_amplitude_m,
        energy_ratio,
        regime,
        worn_volume_m3: worn_volume,
        worn_volume_per_cycle_m3: worn_per_cycle,
        worn_depth_max_m: worn_depth_max,
        wear_cycles: Vec::new(),
        wear_jump_ratio: None,
        ball_worn_volume_m3: None,
    }
}
