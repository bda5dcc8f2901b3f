//! The tangential problem's inputs and outputs: what a partial-slip solve at
//! fixed pressure is asked ([`TangentialProblem`], [`TangentialStart`]) and
//! what it returns ([`TangentialSolution`], [`TangentialReport`]). Below both
//! the tangential solver and its coarse-to-fine start (`coarse_slip`), which
//! speak these types; `tangential` re-exports them. Solves nothing.

pub use crate::model::spec::TangentialMethod;

/// Convergence report of one tangential solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TangentialReport {
    /// Iterations used.
    pub iterations: usize,
    /// Final KKT residual: max over cells of the free / reduced gradient,
    /// relative to the scale `max(|δt|, slip_floor)` of
    /// [`TangentialProblem::slip_floor`].
    pub change: f64,
    /// max over stick cells of |s_i| / scale (slip must vanish there).
    pub stick_residual: f64,
    /// max over slip cells of |w_i + |w_i| e_i| / scale, with e_i = q_i/|q_i|
    /// and w_i the slip: zero when the traction opposes the slip exactly.
    pub slip_residual: f64,
    /// |ΔA Σ q − F| / |F| (/ μP at F = 0).
    pub force_error: f64,
    /// True when the KKT residual fell below the tolerance within the budget.
    pub converged: bool,
    /// Of `iterations`, those of the projected conjugate-gradient phase; the
    /// rest (if any) are accelerated projected-gradient iterations.
    pub cg_iterations: usize,
    /// Operator applications (tangential block) used by the iterations.
    pub applications: usize,
    /// Energy products `⟨t, C t⟩` (two forward transforms each) used by the
    /// conjugate-gradient step lengths.
    #[serde(default)]
    pub energy_products: usize,
    /// Preconditioner applications of the active-set iteration (inverse
    /// circulants of the tangential block, each an operator application's
    /// transforms).
    #[serde(default)]
    pub preconditioner_applications: usize,
    /// Outer updates of the active-set iteration that changed the stick/slip
    /// split.
    #[serde(default)]
    pub split_updates: usize,
    /// Iterations on the coarse levels of a coarse-to-fine start (each costs
    /// a quarter, a sixteenth, … of a fine one); not part of `iterations`.
    #[serde(default)]
    pub coarse_iterations: usize,
}

/// Solution of a tangential problem.
#[derive(Clone, Debug)]
pub struct TangentialSolution {
    /// Shear tractions, Pa.
    pub qx: Vec<f64>,
    /// Shear tractions, Pa.
    pub qy: Vec<f64>,
    /// Slip of the substrate relative to the sphere, m (zero on stick cells).
    pub sx: Vec<f64>,
    /// Slip, m.
    pub sy: Vec<f64>,
    /// 1 on stick cells, 0 elsewhere.
    pub stick: Vec<bool>,
    /// Rigid tangential shift of the sphere δt, m.
    pub shift: [f64; 2],
    /// Convergence.
    pub report: TangentialReport,
}

/// Where the iteration of a tangential solve starts: the explicit starting
/// state of the solver. A load history (fretting) starts each increment from
/// the previous increment's tractions and measures the slip of the increment
/// by passing the previous state's tangential displacement, negated, in
/// [`TangentialProblem::extra`]; one monotonic step from rest uses
/// [`TangentialStart::Proportional`].
#[derive(Clone, Copy, Debug, Default)]
pub enum TangentialStart<'a> {
    /// From rest: tractions proportional to the pressure, `q = F p / P`.
    #[default]
    Proportional,
    /// From given tractions `(qx, qy)`, Pa (e.g. the previous pass of the
    /// coupling loop, or the previous increment of a load history).
    Tractions(&'a [f64], &'a [f64]),
}

/// Inputs of a tangential solve.
#[derive(Clone, Copy, Debug)]
pub struct TangentialProblem<'a> {
    /// Pressure (fixed), Pa.
    pub p: &'a [f64],
    /// Friction coefficient μ.
    pub friction: f64,
    /// Total tangential force (N), components x and y.
    pub force: [f64; 2],
    /// Extra tangential displacement added to the slip (coupling term
    /// `ut(p) − ut(p0)`), m, x and y; `None` for no coupling.
    pub extra: Option<(&'a [f64], &'a [f64])>,
    /// Relative-change tolerance: the KKT residual is measured relative to
    /// `max(|δt|, slip_floor)`.
    pub tolerance: f64,
    /// Floor of the KKT residual's scale, m (0: none). The residual is a slip
    /// relative to the rigid shift δt, which vanishes when the increment's
    /// force does (a normal load ramp with friction and coupling at F = 0,
    /// Spence's problem): relative to |δt| alone such a solve cannot
    /// converge (11 100 iterations, unconverged, on Table 1(a) at 128²). The
    /// caller sets the floor from the slip the increment is driven by.
    pub slip_floor: f64,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Starting state of the iteration.
    pub start: TangentialStart<'a>,
    /// Precondition the conjugate gradient's stick cells with the Fourier
    /// inverse of the compliance (a load history's increments, which start
    /// next to their solution), on grids or windows of side up to
    /// [`crate::solve::tangential::FOURIER_STICK_MAX_SIDE`]; false (or a larger
    /// side): the diagonal (Jacobi) preconditioner.
    pub precondition: bool,
    /// The first phase's iteration.
    pub method: TangentialMethod,
}
