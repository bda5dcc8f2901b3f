//! What defines one contact case: material, surface, grid, load and the
//! numerical settings, and their validation. Errors name the case's
//! parameters (`load.normal_force_n`, `surface.pitch`, …), not config keys:
//! a front end maps them to its own names. Solves nothing.

use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::model::material::{Elasticity, Material};
pub use crate::model::radii::Radii;
use crate::model::surface::Surface;
use serde::{Deserialize, Serialize};

/// Largest grid accepted (cells per side): a bound on index arithmetic and
/// transform sizes only, far above what a machine holds (16384² needs about
/// 130 GiB). Whether a grid fits is one rule of the front end: the estimated
/// memory of the case against what the machine has available
/// (`coordinator::memory`, with the estimate in its message).
pub const MAX_GRID_POINTS: usize = 16384;

/// Smallest apparent contact or stick radius reported, in cells: what a
/// grid resolves. Part of a case's description because validation rejects a
/// case whose Hertz radius is below it before anything is solved; the
/// results apply the same bound to the solved radii.
pub const MIN_RESOLVED_CELLS: f64 = 2.0;

/// The sphere and what is applied to it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Load {
    /// Sphere radius R, m.
    pub indenter_radius_m: f64,
    /// Normal load P, N.
    pub normal_force_n: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// F = ratio · μ · P; 0 solves normal contact only.
    pub tangential_ratio: f64,
    /// Direction of the tangential force in the surface, degrees from x.
    pub angle_deg: f64,
}

impl Load {
    /// Tangential force vector, N.
    pub fn tangential_force(&self) -> [f64; 2] {
        let f = self.tangential_ratio * self.friction * self.normal_force_n;
        let a = self.angle_deg.to_radians();
        [f * a.cos(), f * a.sin()]
    }
}

/// The iteration of a tangential solve's first phase (both end, if they
/// have not converged, in the same projected-gradient phase and are judged
/// by the same KKT test).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TangentialMethod {
    /// The projected conjugate gradient over the stick cells' tractions
    /// and the slip cells' rotation on their discs (Jacobi-preconditioned;
    /// a load history's warm starts with the Fourier `|k|` multiplier on the
    /// stick cells).
    #[default]
    #[serde(rename = "cg")]
    ConjugateGradient,
    /// The active-set iteration of `crate::solve::tangential::active_set`: inner PCG
    /// on a frozen stick/slip split with the inverse of the compliance's
    /// circulant embedding as preconditioner (issue #48).
    #[serde(rename = "active-set")]
    ActiveSet,
}

/// Tolerances and budgets of the solvers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Numerics {
    /// Normal–tangential coupling on/off.
    pub coupling: bool,
    /// Normal solver: relative change of pressure between iterations.
    pub tolerance: f64,
    /// Tangential solver: KKT residual (gradient mapping) relative to |δt|.
    pub tangential_tolerance: f64,
    /// Iteration budget of each inner solve.
    pub max_iterations: usize,
    /// Relative-change tolerance of the coupling loop.
    pub coupling_tolerance: f64,
    /// Budget of coupling (normal ↔ tangential) iterations.
    pub max_coupling_iterations: usize,
    /// How the apparent radii a and c of μa (Eq. 19) are read from the
    /// solution.
    #[serde(default)]
    pub radii: Radii,
    /// The tangential solve's iteration (`solver.tangential_method`).
    #[serde(default)]
    pub tangential_method: TangentialMethod,
}

impl Default for Numerics {
    /// Coupled; tolerances normal 1e-10, tangential 1e-6, coupling 1e-7
    /// (docs/physics-choices.md says why); 5000 inner and 50 coupling
    /// iterations. The config's `[solver]` defaults are these.
    fn default() -> Self {
        Numerics {
            coupling: true,
            tolerance: 1e-10,
            tangential_tolerance: 1e-6,
            max_iterations: 5000,
            coupling_tolerance: 1e-7,
            max_coupling_iterations: 50,
            radii: Radii::default(),
            tangential_method: Default::default(),
        }
    }
}

/// Most increments a load history may ask for (all segments together): a
/// bound against a typo (`steps_per_segment = 1e6`), far above the few
/// hundred a fretting study needs. Auto increments stop subdividing there
/// too.
pub const MAX_HISTORY_STEPS: usize = 100_000;

/// How the segments of a load path are split into increments.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Increments {
    /// As few increments per segment as the path's error estimate accepts
    /// at `tolerance` (see `solve::history`): one where the end state does
    /// not depend on the path (a monotone segment at constant pressure),
    /// more where it does (coupling moving the contact's edge, a changing
    /// normal load, a cap that flows, wear).
    Auto {
        /// The relative error of the energy per cycle the increments aim
        /// at, and (×[`AUTO_LOAD_STEP`]) the largest relative change of the
        /// normal problem's data (the load, the worn depth against the
        /// approach) over one increment.
        tolerance: f64,
    },
    /// This many increments in every segment.
    Fixed(usize),
}

/// With [`Increments::Auto`] and a wear law, the largest depth one
/// increment may wear (its cycle jump included) is this many times the
/// tolerance, of the approach: 1e-4 of it at the default. The wear of a
/// jump is taken at the pressure it leaves, an implicit step whose error is
/// first order in it: Table 1(a) Fe at 128², k = 1e-5, 10⁴ cycles as 10
/// simulated (2.2e-4 of the approach a segment) wore 1.6e-3 less in one
/// increment a segment than in 20; as 100 simulated, 3.6e-4 more (the slip
/// directions' part).
pub const AUTO_WEAR_STEP: f64 = 0.1;

/// With [`Increments::Auto`] and coupling, the increments a segment that
/// moves the tangential load is expected to take (what `check` prices).
pub const AUTO_COUPLED_INCREMENTS: usize = 8;

/// Default tolerance of [`Increments::Auto`]: the energy per cycle within
/// 1e-3 of its converged value.
pub const AUTO_TOLERANCE: f64 = 1e-3;

/// With [`Increments::Auto`], the largest relative change of the normal
/// load (and of the worn depth against the approach) over one increment is
/// this many times the tolerance: 2.5 % at the default. Spence's normal
/// loading with friction (Table 1(a) Fe, μ = 0.3, coupled, 0.5 → 20 N)
/// reads its stick radius 0.45 % low when its last increments change P by
/// 2.4 % and 1.5 % low at 9.8 % (its error follows ΔP/P, ×0.19).
pub const AUTO_LOAD_STEP: f64 = 25.0;

impl Default for Increments {
    fn default() -> Self {
        Increments::Auto {
            tolerance: AUTO_TOLERANCE,
        }
    }
}

/// The cycles of a path someone looks at, and how finely their loops are
/// sampled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LoopSampling {
    /// The full cycles looked at: every this many simulated cycles and the
    /// last; 0: the last only. A wear law keeps its worn profiles at them.
    pub every: usize,
    /// Increments per segment on those cycles, whose force–shift loops
    /// (and history rows) are sampled at this resolution; 0: none (every
    /// segment in the path's own increments).
    pub increments: usize,
}

/// A load path: turning points of the normal load and of the tangential
/// force, joined by straight lines, each segment split into increments
/// (a fretting loop, a proportional loading). The state before the path
/// is frictionless normal contact under the first turning point's normal
/// load; if the first tangential ratio is not zero, the path starts with a
/// segment from zero force to it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoadHistory {
    /// Turning points of F/(μP) along the case's force direction (signed:
    /// negative is against it), P being the normal load at that point.
    pub tangential_ratios: Vec<f64>,
    /// Turning points of the normal load, N, one per tangential ratio;
    /// `None`: constant, the case's `load.normal_force_n`.
    pub normal_forces_n: Option<Vec<f64>>,
    /// How the segments between turning points are split.
    pub increments: Increments,
    /// The cycles looked at and their loops' resolution.
    #[serde(default)]
    pub sampling: LoopSampling,
    /// Displacement control (as fretting rigs run): the turning points of
    /// the ball's rigid tangential shift along the force direction, m
    /// (signed), measured from the end of the frictionless normal loading
    /// against the far field of the substrate. When given, they replace
    /// `tangential_ratios` (which must be empty), the force is a result, and
    /// the contact may slide as a whole (gross slip).
    #[serde(default)]
    pub shifts_m: Option<Vec<f64>>,
    /// The wear of the substrate along the path (PHYSICS.md §5d): each
    /// increment's worn depth joins the separation the next one sees.
    /// `None`: no wear.
    #[serde(default)]
    pub wear: Option<Wear>,
}

/// The wear of a load path (PHYSICS.md §5d): the law, the cycle jump and
/// the cycles whose worn profiles are kept.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Wear {
    /// The substrate's local law.
    pub law: WearLaw,
    /// The ball's, if it wears too (each body's worn depth is kept in its
    /// own frame: the substrate moves under the ball by its shift);
    /// `None`: it does not.
    #[serde(default)]
    pub ball: Option<WearLaw>,
    /// Cycle jumping: the physical cycles each simulated one stands for
    /// (each increment's wear of the cycles is applied this many times,
    /// implicitly in the pressure; the first loading's once; see
    /// `solve_history`), ≥ 1; 1: no jump.
    #[serde(default = "no_jump")]
    pub jump: f64,
}

fn no_jump() -> f64 {
    1.0
}

/// Largest cycle jump [`Wear::jump`] accepts: a bound against a typo,
/// far above the 10⁴–10⁶ physical cycles of a rig over tens of simulated ones.
pub const MAX_WEAR_JUMP: f64 = 1e9;

impl Wear {
    /// A law for the substrate only, without a jump, every profile but the
    /// last dropped.
    pub fn new(law: WearLaw) -> Self {
        Wear {
            law,
            ball: None,
            jump: 1.0,
        }
    }

    fn validate(&self) -> Result<(), SolverError> {
        self.law.validate()?;
        if let Some(ball) = &self.ball {
            ball.validate()?;
        }
        if !(self.jump.is_finite() && (1.0..=MAX_WEAR_JUMP).contains(&self.jump)) {
            return Err(SolverError::invalid(
                "history.wear.jump",
                format!(
                    "the physical cycles per simulated cycle must be 1 to {MAX_WEAR_JUMP:e}, got {}",
                    self.jump
                ),
            ));
        }
        Ok(())
    }
}

/// A local wear law (PHYSICS.md §5d): the substrate's worn depth per
/// increment of slip `ds` of a cell (the rigid shift's increment less the
/// surface's elastic displacement increment).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum WearLaw {
    /// Archard: `dh = k p |ds|`, `k` in m³/(N·m) (= 1/Pa).
    Archard {
        /// Wear coefficient k, m³/(N·m).
        k: f64,
    },
    /// Fouvry's dissipated-energy law: `dh = α |q · ds|`, `α` in m³/J
    /// (= 1/Pa); the worn volume is α times the dissipated energy.
    Energy {
        /// Energy wear coefficient α, m³/J.
        alpha: f64,
    },
}

impl WearLaw {
    /// The worn depth of a cell over an increment, m: pressure `p` and
    /// tractions `q` at the increment's end (where the implicit law of
    /// Coulomb friction in increments puts a slipping cell's traction,
    /// PHYSICS.md §5b) and slip increment `ds`.
    pub fn depth(&self, p: f64, q: [f64; 2], ds: [f64; 2]) -> f64 {
        match *self {
            WearLaw::Archard { k } => k * p.max(0.0) * ds[0].hypot(ds[1]),
            WearLaw::Energy { alpha } => alpha * (q[0] * ds[0] + q[1] * ds[1]).max(0.0),
        }
    }

    fn validate(&self) -> Result<(), SolverError> {
        let (name, v) = match *self {
            WearLaw::Archard { k } => ("history.wear.k", k),
            WearLaw::Energy { alpha } => ("history.wear.alpha", alpha),
        };
        if !(v.is_finite() && v >= 0.0) {
            return Err(SolverError::invalid(
                name,
                format!("the wear coefficient must be finite and ≥ 0, got {v}"),
            ));
        }
        if v > MAX_WEAR_COEFFICIENT {
            return Err(SolverError::invalid(
                name,
                format!("the wear coefficient {v:e} m³/J is above {MAX_WEAR_COEFFICIENT:e} m³/J (0.1 mm³/(N·m)), more than any measured wear: at that rate a contact wears through its own approach in a few slips"),
            ));
        }
        Ok(())
    }
}

/// The largest wear coefficient (Archard's k or the energy law's α) a path
/// accepts, m³/J (0.1 mm³/(N·m)): ten times the severe adhesive wear of
/// metals (k ≈ 1e-2 mm³/(N·m)); fretting measures 1e-6 to 1e-4. A k of
/// 1e308 gave a worn depth of 3e300 m, and 100 mm³/(N·m) wore 4.6 times the
/// approach in one cycle (#59 item 2).
pub const MAX_WEAR_COEFFICIENT: f64 = 1e-10;

/// A shift turning point (displacement control) may reach this many times
/// the domain's side, m/m: a rig's stroke beyond it slides the ball across
/// more than the domain, and 1e300 µm gave NaN forces (#59 item 5).
pub const MAX_SHIFT_DOMAINS: f64 = 10.0;

/// The smallest nonzero shift turning point, m: a picometre, below any
/// displacement a rig resolves (1e-300 µm gave a loop whose force
/// amplitude and energies were 0 and null).
pub const MIN_SHIFT_M: f64 = 1e-12;

impl LoadHistory {
    /// True when the turning points are shifts of the ball (`shifts_m`).
    pub fn displacement_controlled(&self) -> bool {
        self.shifts_m.is_some()
    }

    /// The number of turning points given.
    fn count(&self) -> usize {
        self.shifts_m
            .as_ref()
            .map_or(self.tangential_ratios.len(), Vec::len)
    }

    /// The turning points as (P in N, the tangential target along the force
    /// direction: F in N, or the ball's shift in m under displacement
    /// control), starting from zero tangential force (shift).
    pub fn turning_points(&self, load: &Load) -> Vec<(f64, f64)> {
        let normal = |j: usize| match &self.normal_forces_n {
            Some(v) => v[j],
            None => load.normal_force_n,
        };
        let mut pts: Vec<(f64, f64)> = (0..self.count())
            .map(|j| {
                let p = normal(j);
                match &self.shifts_m {
                    Some(d) => (p, d[j]),
                    None => (p, self.tangential_ratios[j] * load.friction * p),
                }
            })
            .collect();
        if let Some(&(p0, f0)) = pts.first() {
            if f0 != 0.0 {
                pts.insert(0, (p0, 0.0));
            }
        }
        pts
    }

    /// How segment `j` is split, the cycles looked at being `looked_at`
    /// ([`looked_at_segments`]): fixed increments split every segment alike
    /// (every loop is sampled); auto ones sample the loops of the cycles
    /// looked at in `sampling.increments` fixed increments.
    pub(crate) fn segment_increments(&self, j: usize, looked_at: &[usize]) -> Increments {
        match self.increments {
            Increments::Auto { .. } if self.sampling.increments > 0 && looked_at.contains(&j) => {
                Increments::Fixed(self.sampling.increments)
            }
            split => split,
        }
    }

    /// The increments the path is expected to take (what `check` prices):
    /// fixed ones exactly; auto ones as the error estimate chose them on
    /// Table 1(a) Fe (docs/performance.md, "Increments chosen by the
    /// path"): one per segment at a constant normal load uncoupled,
    /// [`AUTO_COUPLED_INCREMENTS`] coupled where the tangential load moves,
    /// as many as the normal load's change asks for ([`AUTO_LOAD_STEP`]),
    /// and with a wear law as many as its depth a segment `worn_segment`
    /// (relative to the approach, the cycle jump included) asks for; the
    /// cycles looked at in their sampled increments.
    pub fn expected_increments(&self, load: &Load, coupling: bool, worn_segment: f64) -> usize {
        let points = self.turning_points(load);
        let looked_at = looked_at_segments(&points, self.sampling.every);
        let cycles_from = full_cycles(&points).first().map_or(usize::MAX, |&t| t - 2);
        let total: usize = points
            .windows(2)
            .enumerate()
            .map(|(j, w)| match self.segment_increments(j, &looked_at) {
                Increments::Fixed(k) => k,
                Increments::Auto { tolerance } => {
                    let (a, b) = (w[0], w[1]);
                    let dp = (b.0 / a.0).ln().abs();
                    let by_load = (dp / (AUTO_LOAD_STEP * tolerance)).ceil() as usize;
                    let by_path = if coupling && a.1 != b.1 {
                        AUTO_COUPLED_INCREMENTS
                    } else {
                        1
                    };
                    let worn = if j >= cycles_from { worn_segment } else { 0.0 };
                    let by_wear = (worn / (AUTO_WEAR_STEP * tolerance)).ceil() as usize;
                    by_load.max(by_path).max(by_wear)
                }
            })
            .sum();
        total.max(1)
    }

    /// Rejects impossible paths, naming `history.<key>[index]`.
    pub fn validate(&self) -> Result<(), SolverError> {
        if let Some(w) = &self.wear {
            w.validate()?;
        }
        let n = self.count();
        let key = if self.displacement_controlled() {
            "history.shifts_m"
        } else {
            "history.tangential_ratios"
        };
        if n == 0 {
            return Err(SolverError::invalid(
                key,
                "needs at least one turning point",
            ));
        }
        if let Some(d) = &self.shifts_m {
            if !self.tangential_ratios.is_empty() {
                return Err(SolverError::invalid(
                    "history.shifts_m",
                    "give the turning points either as forces (tangential_ratios) or as shifts, not both",
                ));
            }
            for (j, &v) in d.iter().enumerate() {
                if !v.is_finite() {
                    return Err(SolverError::invalid(
                        &format!("history.shifts_m[{j}]"),
                        format!("must be finite, got {v} m"),
                    ));
                }
            }
        }
        for (j, &r) in self.tangential_ratios.iter().enumerate() {
            if !r.is_finite() {
                return Err(SolverError::invalid(
                    &format!("history.tangential_ratios[{j}]"),
                    format!("must be finite, got {r}"),
                ));
            }
            if r.abs() >= 1.0 {
                return Err(SolverError::invalid(
                    &format!("history.tangential_ratios[{j}]"),
                    format!(
                        "|F|/μP = {} reaches or exceeds the friction limit: the sphere slides as a whole (gross sliding); keep every turning point below 1 in magnitude",
                        r.abs()
                    ),
                ));
            }
        }
        if let Some(v) = &self.normal_forces_n {
            if v.len() != n {
                return Err(SolverError::invalid(
                    "history.normal_forces_n",
                    format!(
                        "has {} turning points but {key} has {n}; give one normal load per turning point",
                        v.len()
                    ),
                ));
            }
            for (j, &p) in v.iter().enumerate() {
                positive(
                    &format!("history.normal_forces_n[{j}]"),
                    p,
                    "the normal load",
                )?;
            }
        }
        match self.increments {
            Increments::Fixed(0) => {
                return Err(SolverError::invalid(
                    "history.steps_per_segment",
                    "must be at least 1 (or \"auto\")",
                ))
            }
            Increments::Fixed(k) => {
                let total = k.saturating_mul(n);
                if total > MAX_HISTORY_STEPS {
                    return Err(SolverError::invalid(
                        "history.steps_per_segment",
                        format!(
                            "{k} increments per segment over {n} turning points make {total} increments, more than {MAX_HISTORY_STEPS}"
                        ),
                    ));
                }
            }
            Increments::Auto { tolerance } => {
                if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 0.1) {
                    return Err(SolverError::invalid(
                        "history.tolerance",
                        format!("must be above 0 and below 0.1, got {tolerance}"),
                    ));
                }
            }
        }
        let sampled = self.sampling.increments.saturating_mul(2 * n);
        if sampled > MAX_HISTORY_STEPS {
            return Err(SolverError::invalid(
                "history.loop_increments",
                format!(
                    "{} increments per segment of the sampled cycles could make {sampled} increments, more than {MAX_HISTORY_STEPS}",
                    self.sampling.increments
                ),
            ));
        }
        Ok(())
    }
}

/// The segments (0-based) of the cycles someone looks at: those of every
/// `every`-th full cycle and of the last (`every` = 0: the last only); a
/// path without a full cycle (a loading, an unloading) is looked at whole.
pub(crate) fn looked_at_segments(points: &[(f64, f64)], every: usize) -> Vec<usize> {
    let ends = full_cycles(points);
    if ends.is_empty() {
        return (0..points.len().saturating_sub(1)).collect();
    }
    let mut out = Vec::new();
    for (c, &t) in ends.iter().enumerate() {
        let number = c + 1;
        if number == ends.len() || (every > 0 && number % every == 0) {
            out.extend([t - 2, t - 1]);
        }
    }
    out
}

/// Whether turning points `a` and `b` are the same (to 1e-12 of their size).
pub(crate) fn same_point(a: (f64, f64), b: (f64, f64)) -> bool {
    let scale = a.0.abs().max(b.0.abs());
    (a.0 - b.0).abs() <= 1e-12 * scale && (a.1 - b.1).abs() <= 1e-12 * scale
}

/// Whether reaching turning point `t` closes a full cycle: the two
/// segments before it return to the point they left.
pub(crate) fn closes_cycle(points: &[(f64, f64)], t: usize) -> bool {
    t >= 2
        && t < points.len()
        && same_point(points[t], points[t - 2])
        && !same_point(points[t], points[t - 1])
}

/// The turning points that close the path's full cycles, one after
/// another: 0 → +A → −A → +A → −A → +A closes two, at the second and the
/// third +A (the −A → +A → −A between them is not a third).
pub(crate) fn full_cycles(points: &[(f64, f64)]) -> Vec<usize> {
    let mut ends: Vec<usize> = Vec::new();
    for t in 0..points.len() {
        if closes_cycle(points, t) && ends.last().is_none_or(|&e| t >= e + 2) {
            ends.push(t);
        }
    }
    ends
}

/// Everything that defines one case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseSpec {
    /// Substrate material.
    pub material: Material,
    /// Surface topography.
    pub surface: Surface,
    /// The surface grid (square cells).
    pub grid: Grid,
    /// Sphere, loads and force direction.
    pub load: Load,
    /// Solver settings.
    pub numerics: Numerics,
    /// A load path (fretting, proportional loading); `None`: one monotonic
    /// step of the tangential force from zero at constant normal load.
    #[serde(default)]
    pub history: Option<LoadHistory>,
    /// The ball's material, its stiffness in the ball's own frame (normal
    /// pointing into the ball, x along the substrate's x, y = z × x, i.e.
    /// the substrate's frame turned 180° about x); `None`: a rigid ball.
    /// The contact compliance is the sum of the two bodies' (see
    /// [`crate::model::material::pair_influence`]).
    #[serde(default)]
    pub indenter: Option<Material>,
}

fn positive(param: &str, v: f64, what: &str) -> Result<(), SolverError> {
    crate::error::positive(param, v, what, "")
}

/// Prefixes the parameter of an `Invalid` error with `prefix.`.
fn within(prefix: &str, e: SolverError) -> SolverError {
    match e {
        SolverError::Invalid { field, reason } => {
            SolverError::invalid(&format!("{prefix}.{field}"), reason)
        }
        other => other,
    }
}

impl CaseSpec {
    /// Tangential force vector, N.
    pub fn tangential_force(&self) -> [f64; 2] {
        self.load.tangential_force()
    }

    /// True when μa needs K_E calibrated on the flat surface of the same
    /// material at the same angle (an anisotropic substrate or ball under a
    /// tangential load).
    pub fn needs_flat_calibration(&self) -> bool {
        let anisotropic = !self.material.is_isotropic()
            || self.indenter.as_ref().is_some_and(|m| !m.is_isotropic());
        anisotropic && self.load.tangential_ratio > 0.0
    }

    /// The solver settings as solved: with coupling off when the pair's
    /// normal–tangential coupling vanishes identically (an elastic ball of
    /// the substrate's own isotropic constants, Dundurs β = 0, or two
    /// incompressible isotropic bodies), where the coupling loop could only
    /// repeat its first pass. A rigid ball keeps the settings as given.
    pub fn numerics_in_effect(&self) -> Numerics {
        let mut num = self.numerics;
        if let (Some(ball), Elasticity::Isotropic(sub)) =
            (&self.indenter, &self.material.elasticity)
        {
            if let Elasticity::Isotropic(b) = &ball.elasticity {
                let identical = sub.youngs == b.youngs && sub.poisson == b.poisson;
                let incompressible = sub.poisson == 0.5 && b.poisson == 0.5;
                if identical || incompressible {
                    num.coupling = false;
                }
            }
        }
        num
    }

    /// The plastic limits of the interface: the substrate's, and with an
    /// elastic ball the smaller of the two bodies' (a rigid ball does not
    /// yield).
    pub fn limits(&self) -> crate::model::material::Limits {
        match &self.indenter {
            None => self.material.limits,
            Some(ball) => self.material.limits.softer(ball.limits),
        }
    }

    /// On an elastic interface (no hardness set): the body, substrate or
    /// ball, whose typical hardness as a preset
    /// ([`crate::presets::typical_hardness`]) the peak pressure `p_max_pa`
    /// exceeds (of the two, the softer), with that range; `None` when
    /// neither does, when a hardness caps the pressure, or for materials
    /// that are no presets (#59: worn flats and island edges reached
    /// 3.6–16 GPa, which no such surface carries).
    pub fn pressure_beyond_hardness(
        &self,
        p_max_pa: f64,
    ) -> Option<(&Material, crate::model::presets::HardnessRange)> {
        if self.limits().hardness.is_some() {
            return None;
        }
        std::iter::once(&self.material)
            .chain(self.indenter.as_ref())
            .filter_map(|m| Some((m, crate::model::presets::typical_hardness(m)?)))
            .filter(|(_, r)| p_max_pa > r.high_pa)
            .min_by(|a, b| a.1.high_pa.total_cmp(&b.1.high_pa))
    }

    /// The pressure whose μ-multiple bounds the shear traction of each
    /// cell: `p` itself, or with a shear limit τ_c `min(p, τ_c c / μ)`
    /// (`c` the cell's cover, 1 where whole), so that the bound is
    /// `min(μp, τ_c)` on the covered part. The tangential solvers, the
    /// stick zone's reserve and the slip rescaling all read it.
    pub fn friction_pressure<'a>(
        &self,
        p: &'a [f64],
        cover: Option<&[f64]>,
    ) -> std::borrow::Cow<'a, [f64]> {
        let mu = self.load.friction;
        match self.limits().shear_limit {
            Some(tau) if mu > 0.0 => std::borrow::Cow::Owned(
                crate::model::material::limit_per_cell(tau, cover, p.len())
                    .iter()
                    .zip(p)
                    .map(|(t, &v)| v.min(t / mu))
                    .collect(),
            ),
            _ => std::borrow::Cow::Borrowed(p),
        }
    }

    /// The contact modulus E* of the pair from the isotropic-equivalent
    /// constants, `1/E* = Σ (1 − νᵢ²)/Eᵢ` (the substrate's plane-strain
    /// modulus for a rigid ball): Hertz normalisation.
    pub fn contact_modulus(&self) -> f64 {
        let sub = self.material.equivalent.plane_strain();
        match &self.indenter {
            // As before balls existed (1/(1/E*) may differ from E* in the last bit).
            None => sub,
            Some(ball) => 1.0 / (1.0 / sub + 1.0 / ball.equivalent.plane_strain()),
        }
    }

    /// Mindlin's K_E of the pair, `16 / (3 Σ (2 − νᵢ)/Gᵢ)` from the
    /// isotropic-equivalent constants (the substrate's
    /// `8E / (3(1 + ν)(2 − ν))` for a rigid ball, computed as before).
    pub fn mindlin_k_e(&self) -> f64 {
        match &self.indenter {
            None => self.material.equivalent.mindlin_k_e(),
            Some(ball) => {
                let c = |m: &Material| (2.0 - m.equivalent.poisson) / m.equivalent.shear();
                16.0 / (3.0 * (c(&self.material) + c(ball)))
            }
        }
    }

    /// A rough estimate of the depth one segment of the path's cycles
    /// wears, relative to the approach, its cycle jump included (what
    /// `check` prices a wear path's auto increments by; 0 without wear):
    /// the law's rate at Hertz's peak pressure over the segment's slip (the
    /// loop's width 2δ(F*) = 2δ*(1 − (1 − F*/μP)^(2/3)), or 2Δ under
    /// displacement control), times 0.08, the share the slip annulus makes
    /// of it (fitted: Table 1(a) Fe at 128², k = 1e-5 mm³/(N·m), 10⁴
    /// cycles as 100 simulated wore 2.2e-5 of the approach a segment).
    pub fn worn_per_segment(&self) -> f64 {
        let Some(h) = &self.history else {
            return 0.0;
        };
        let Some(wear) = &h.wear else {
            return 0.0;
        };
        let load = &self.load;
        let (p, mu) = (load.normal_force_n, load.friction);
        let a = (3.0 * p * load.indenter_radius_m / (4.0 * self.contact_modulus())).cbrt();
        let approach = a * a / load.indenter_radius_m;
        let p_h = 3.0 * p / (2.0 * std::f64::consts::PI * a * a);
        let delta_star = mu * p / (a * self.mindlin_k_e());
        let slip = match &h.shifts_m {
            Some(d) => 2.0 * d.iter().fold(0.0_f64, |m, v| m.max(v.abs())),
            None => {
                let f = h
                    .tangential_ratios
                    .iter()
                    .fold(0.0_f64, |m, v| m.max(v.abs()));
                2.0 * delta_star * (1.0 - (1.0 - f.min(1.0)).powf(2.0 / 3.0))
            }
        };
        let rate = |law: &WearLaw| match *law {
            WearLaw::Archard { k } => k,
            WearLaw::Energy { alpha } => alpha * mu,
        };
        let rate = rate(&wear.law) + wear.ball.as_ref().map_or(0.0, rate);
        0.08 * rate * p_h * slip * wear.jump / approach
    }

    /// The increments this case's load path is expected to take (see
    /// [`LoadHistory::expected_increments`]); 1 without a path.
    pub fn expected_increments(&self) -> usize {
        self.history.as_ref().map_or(1, |h| {
            h.expected_increments(&self.load, self.numerics.coupling, self.worn_per_segment())
        })
    }

    /// The same case on the flat surface: the K_E calibration twin.
    pub fn flat_twin(&self) -> CaseSpec {
        CaseSpec {
            surface: Surface::Flat,
            ..self.clone()
        }
    }

    /// Initial separation between sphere (parabolic profile r²/2R) and
    /// surface at each cell, shifted so that its minimum is zero (δz is then
    /// the approach from first touch).
    pub fn initial_gap(&self) -> Vec<f64> {
        self.initial_gap_on(&self.surface.heights(&self.grid))
    }

    /// [`CaseSpec::initial_gap`] over the surface's `heights` (from
    /// [`crate::Surface::terrain`], made once per case).
    pub fn initial_gap_on(&self, heights: &[f64]) -> Vec<f64> {
        let grid = self.grid;
        let n = grid.n;
        let r = self.load.indenter_radius_m;
        let mut h: Vec<f64> = (0..grid.len())
            .map(|i| {
                let (x, y) = (grid.x(i % n), grid.y(i / n));
                (x * x + y * y) / (2.0 * r) - heights[i]
            })
            .collect();
        let min = h.iter().cloned().fold(f64::INFINITY, f64::min);
        h.iter_mut().for_each(|v| *v -= min);
        h
    }

    /// Rejects impossible inputs with the name of the offending parameter.
    pub fn validate(&self) -> Result<(), SolverError> {
        // The path first: its ratios set the case's own (the last one).
        if let Some(h) = &self.history {
            h.validate()?;
        }
        let grid = &self.grid;
        if grid.n < 8 || grid.n > MAX_GRID_POINTS {
            return Err(SolverError::invalid(
                "grid.n",
                format!(
                    "must be between 8 and {MAX_GRID_POINTS} cells per side, got {}",
                    grid.n
                ),
            ));
        }
        positive("grid.dx", grid.dx, "the cell size")?;
        if let Some(shifts) = self.history.as_ref().and_then(|h| h.shifts_m.as_ref()) {
            let side = grid.n as f64 * grid.dx;
            for (j, &v) in shifts.iter().enumerate() {
                if v != 0.0 && !(MIN_SHIFT_M..=MAX_SHIFT_DOMAINS * side).contains(&v.abs()) {
                    return Err(SolverError::invalid(
                        &format!("history.shifts_m[{j}]"),
                        format!(
                            "a shift of {:e} µm is outside {:e} µm to {:e} µm ({MAX_SHIFT_DOMAINS} times the domain's side of {:e} µm); give 0 or a shift in that range",
                            v * 1e6,
                            MIN_SHIFT_M * 1e6,
                            MAX_SHIFT_DOMAINS * side * 1e6,
                            side * 1e6
                        ),
                    ));
                }
            }
        }
        if grid.dy != grid.dx {
            return Err(SolverError::invalid(
                "grid.dy",
                format!("cells must be square, got {} x {} m", grid.dx, grid.dy),
            ));
        }
        let load = &self.load;
        positive(
            "load.indenter_radius_m",
            load.indenter_radius_m,
            "the indenter radius",
        )?;
        positive(
            "load.normal_force_n",
            load.normal_force_n,
            "the normal load",
        )?;
        if !(load.friction.is_finite() && load.friction >= 0.0) {
            return Err(SolverError::invalid(
                "load.friction",
                format!(
                    "the friction coefficient must be finite and ≥ 0, got {}",
                    load.friction
                ),
            ));
        }
        let ratio = load.tangential_ratio;
        if !(ratio.is_finite() && ratio >= 0.0) {
            return Err(SolverError::invalid(
                "load.tangential_ratio",
                format!("must be finite and ≥ 0, got {ratio}"),
            ));
        }
        if ratio >= 1.0 {
            return Err(SolverError::invalid(
                "load.tangential_ratio",
                format!(
                    "F = {ratio} μP reaches or exceeds the friction limit μP: the sphere slides as a whole (gross sliding); use a ratio below 1"
                ),
            ));
        }
        if ratio > 0.0 && load.friction == 0.0 {
            return Err(SolverError::invalid(
                "load.friction",
                "a tangential force needs a positive friction coefficient",
            ));
        }
        if !load.angle_deg.is_finite() {
            return Err(SolverError::invalid(
                "load.angle_deg",
                "the force angle must be finite",
            ));
        }
        let num = &self.numerics;
        positive("numerics.tolerance", num.tolerance, "the tolerance")?;
        positive(
            "numerics.tangential_tolerance",
            num.tangential_tolerance,
            "the tangential tolerance",
        )?;
        positive(
            "numerics.coupling_tolerance",
            num.coupling_tolerance,
            "the coupling tolerance",
        )?;
        if num.max_iterations == 0 {
            return Err(SolverError::invalid(
                "numerics.max_iterations",
                "must be at least 1",
            ));
        }
        if num.max_coupling_iterations == 0 {
            return Err(SolverError::invalid(
                "numerics.max_coupling_iterations",
                "must be at least 1",
            ));
        }
        self.material
            .validate()
            .map_err(|e| within("material", e))?;
        if let Some(ball) = &self.indenter {
            ball.validate().map_err(|e| within("indenter", e))?;
        }
        self.surface
            .validate(grid.n)
            .map_err(|e| within("surface", e))?;
        // A contact a few cells across cannot be solved meaningfully (a
        // 1e-300 m sphere gave δz = 4.6e296 m, #20 item 8). Hertz's radius
        // with the isotropic-equivalent constants is the scale; patterns
        // and anisotropy change it by tens of per cent, not by cells.
        // Under a load history the smallest normal load sets the smallest contact.
        let mut normal_min = load.normal_force_n;
        if let Some(h) = &self.history {
            if let Some(v) = &h.normal_forces_n {
                normal_min = v.iter().cloned().fold(f64::INFINITY, f64::min);
            }
            if h.tangential_ratios.iter().any(|&r| r != 0.0) && load.friction == 0.0 {
                return Err(SolverError::invalid(
                    "load.friction",
                    "a tangential force needs a positive friction coefficient",
                ));
            }
        }
        let a_hertz =
            (3.0 * normal_min * load.indenter_radius_m / (4.0 * self.contact_modulus())).cbrt();
        let min = MIN_RESOLVED_CELLS * grid.dx;
        if a_hertz < min {
            return Err(SolverError::ContactUnresolved {
                detail: format!(
                    "the Hertz contact radius {a_hertz:.3e} m spans fewer than {} cells of {:.3e} m",
                    MIN_RESOLVED_CELLS,
                    grid.dx
                ),
            });
        }
        self.check_hardness_fits()
    }

    /// A hardness H caps every cell's pressure, so the contact covers at
    /// least P/H under the largest normal load P of the case: a disc of
    /// radius √(P/(πH)) on a sphere's axisymmetric gap (flat or a lattice,
    /// whose contact's outline is wider still), anywhere on a height map.
    /// When that reaches the outermost ring of cells, which must stay free,
    /// no solve can carry the load: H = 0.01 GPa on Table 1(a) Fe at 64² of
    /// 5 µm (P/H twenty times the domain's area) came back `not_converged`
    /// with p_max = 505 H, and blamed friction under a tangential load
    /// (#59). The error names the body whose hardness caps the contact.
    fn check_hardness_fits(&self) -> Result<(), SolverError> {
        let Some(hardness) = self.limits().hardness else {
            return Ok(());
        };
        let body = if self.material.limits.hardness == Some(hardness) {
            "material.hardness"
        } else {
            "indenter.hardness"
        };
        let load = match self
            .history
            .as_ref()
            .and_then(|h| h.normal_forces_n.as_ref())
        {
            Some(v) => v.iter().cloned().fold(self.load.normal_force_n, f64::max),
            None => self.load.normal_force_n,
        };
        let grid = &self.grid;
        let area = load / hardness;
        // The cells inside the outermost ring.
        let inner = (grid.n as f64 - 2.0) * grid.dx;
        let (fits, room) = if matches!(
            self.surface,
            crate::model::surface::Surface::Heightmap { .. }
        ) {
            (
                area < inner * inner,
                format!("the domain's inner cells cover {:.3e} m²", inner * inner),
            )
        } else {
            let radius = (area / std::f64::consts::PI).sqrt();
            (
                radius < 0.5 * inner,
                format!(
                    "a disc of radius {radius:.3e} m, past the {:.3e} m the domain's inner cells reach from its centre",
                    0.5 * inner
                ),
            )
        };
        if fits {
            return Ok(());
        }
        Err(SolverError::invalid(
            body,
            format!(
                "the hardness {:.3e} GPa cannot carry the normal load {load} N inside the domain: the pressure capped at H needs a contact of at least P/H = {area:.3e} m², {room}; raise the hardness (or enlarge grid.points or grid.spacing_um)",
                hardness / 1e9
            ),
        ))
    }
}
