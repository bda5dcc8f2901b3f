//! What a load path reports: its table (`HistoryStep`, one row an
//! increment, and `row`, which makes one from a solved state), its
//! reductions (`HistoryOutput`), the turning points' states and the
//! definitions the outputs name.

use serde::{Deserialize, Serialize};

use crate::base::geometry::covered_area;
use crate::model::material::area_at_cap;
use crate::model::radii::{friction_reserve, zone_radius};
use crate::model::spec::CaseSpec;
use crate::model::surface::Terrain;
use crate::solve::coupling::ContactState;
use crate::solve::wear::WearCycle;

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
    pub(super) fn of(step: usize, state: &ContactState) -> Self {
        TurningState {
            step,
            p: state.p.clone(),
            qx: state.tangential.qx.clone(),
            qy: state.tangential.qy.clone(),
        }
    }
}

/// What a row needs besides the contact state.
pub(super) struct StepSums {
    pub(super) step: usize,
    pub(super) segment: usize,
    pub(super) delta_t: [f64; 2],
    pub(super) dissipated: f64,
    pub(super) converged: bool,
}

/// The table row of a solved increment on the surface's `terrain`.
pub(super) fn row(
    spec: &CaseSpec,
    terrain: &Terrain,
    state: &ContactState,
    sums: &StepSums,
) -> HistoryStep {
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
