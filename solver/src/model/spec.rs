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
    /// The active-set iteration of `crate::solve::active_set`: inner PCG
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
/// hundred a fretting study needs.
pub const MAX_HISTORY_STEPS: usize = 100_000;

/// A load path: turning points of the normal load and of the tangential
/// force, joined by straight lines, each segment split into
/// `steps_per_segment` increments (a fretting loop, a proportional
/// loading). The state before the path is frictionless normal contact under
/// the first turning point's normal load; if the first tangential ratio is
/// not zero, the path starts with a segment from zero force to it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoadHistory {
    /// Turning points of F/(μP) along the case's force direction (signed:
    /// negative is against it), P being the normal load at that point.
    pub tangential_ratios: Vec<f64>,
    /// Turning points of the normal load, N, one per tangential ratio;
    /// `None`: constant, the case's `load.normal_force_n`.
    pub normal_forces_n: Option<Vec<f64>>,
    /// Increments per segment between turning points.
    pub steps_per_segment: usize,
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
    /// (each increment's wear is applied this many times, implicitly in
    /// the pressure; see `solve_history`), ≥ 1; 1: no jump.
    #[serde(default = "no_jump")]
    pub jump: f64,
    /// The worn profiles through the contact's centre are kept every this
    /// many simulated full cycles, and at the last; 0: at the last only.
    #[serde(default)]
    pub save_every: usize,
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
            save_every: 0,
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
    /// tractions `q` (each the mean of the increment's two ends, the
    /// trapezoidal rule of the dissipation) and slip increment `ds`.
    pub fn depth(&self, p: f64, q: [f64; 2], ds: [f64; 2]) -> f64 {
        match *self {
            WearLaw::Archard { k } => k * p.max(0.0) * ds[0].hypot(ds[1]),
            WearLaw::Energy { alpha } => alpha * (q[0] * ds[0] + q[1] * ds[1]).abs(),
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
        Ok(())
    }
}

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
        if self.steps_per_segment == 0 {
            return Err(SolverError::invalid(
                "history.steps_per_segment",
                "must be at least 1",
            ));
        }
        let total = self.steps_per_segment.saturating_mul(n);
        if total > MAX_HISTORY_STEPS {
            return Err(SolverError::invalid(
                "history.steps_per_segment",
                format!(
                    "{} increments per segment over {n} turning points make {total} increments, more than {MAX_HISTORY_STEPS}",
                    self.steps_per_segment
                ),
            ));
        }
        Ok(())
    }
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
