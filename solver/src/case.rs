//! One contact case end to end: validate the inputs, build (or reuse) the
//! operator, solve normal contact, then partial-slip tangential contact with
//! optional normal–tangential coupling, and reduce the fields to the scalars a
//! sweep reports (radii, shifts, μa). The identity of a kernel lives here.

use crate::error::SolverError;
use crate::geometry::{equivalent_radius, hull_area};
use crate::influence::isotropic_cell;
use crate::influence::Block;
use crate::material::{Elasticity, Material};
use crate::normal::{solve_normal, NormalReport};
use crate::operator::{Grid, Operator, Spectra, X, Y, Z};
use crate::surface::Surface;
use crate::tangential::{solve_tangential, TangentialProblem, TangentialReport};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Largest grid accepted (cells per side): 4096² needs ~10 GiB of kernel spectra.
pub const MAX_GRID_POINTS: usize = 4096;

/// Everything that defines one case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseSpec {
    /// Substrate material.
    pub material: Material,
    /// Surface topography.
    pub surface: Surface,
    /// Cells per side (the grid is `n x n`).
    pub grid_points: usize,
    /// Cell size, m (square cells).
    pub spacing_m: f64,
    /// Sphere radius, m.
    pub indenter_radius_m: f64,
    /// Normal load P, N.
    pub normal_force_n: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// F = ratio · μ · P; 0 solves normal contact only.
    pub tangential_ratio: f64,
    /// Direction of the tangential force in the surface, degrees from x.
    pub angle_deg: f64,
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
}

impl CaseSpec {
    /// The solver grid.
    pub fn grid(&self) -> Grid {
        Grid {
            n: self.grid_points,
            dx: self.spacing_m,
            dy: self.spacing_m,
        }
    }

    /// Identity of the operator this case needs: material constants and grid.
    pub fn kernel_key(&self) -> String {
        let c = self.material.stiffness();
        let consts: Vec<String> = c.iter().map(|v| format!("{v:.9e}")).collect();
        format!(
            "{}|{}|{:.9e}|{}",
            self.material.name,
            self.grid_points,
            self.spacing_m,
            consts.join(",")
        )
    }

    /// Tangential force vector, N.
    pub fn tangential_force(&self) -> [f64; 2] {
        let f = self.tangential_ratio * self.friction * self.normal_force_n;
        let a = self.angle_deg.to_radians();
        [f * a.cos(), f * a.sin()]
    }

    /// Rejects impossible inputs with the name of the offending field.
    pub fn validate(&self) -> Result<(), SolverError> {
        let pos = |field: &str, v: f64, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(SolverError::invalid(
                    field,
                    format!("{what} must be positive and finite, got {v}"),
                ))
            }
        };
        if self.grid_points < 8 || self.grid_points > MAX_GRID_POINTS {
            return Err(SolverError::invalid(
                "grid.points",
                format!(
                    "must be between 8 and {MAX_GRID_POINTS} cells per side, got {}",
                    self.grid_points
                ),
            ));
        }
        pos("grid.spacing_um", self.spacing_m, "the cell size")?;
        pos(
            "indenter.radius_mm",
            self.indenter_radius_m,
            "the indenter radius",
        )?;
        pos("load.normal_n", self.normal_force_n, "the normal load")?;
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(SolverError::invalid(
                "load.friction",
                format!(
                    "the friction coefficient must be finite and ≥ 0, got {}",
                    self.friction
                ),
            ));
        }
        if !(self.tangential_ratio.is_finite() && self.tangential_ratio >= 0.0) {
            return Err(SolverError::invalid(
                "load.tangential_ratio",
                format!("must be finite and ≥ 0, got {}", self.tangential_ratio),
            ));
        }
        if self.tangential_ratio >= 1.0 {
            return Err(SolverError::invalid(
                "load.tangential_ratio",
                format!(
                    "F = {} μP reaches or exceeds the friction limit μP: the sphere slides as a whole (gross sliding); use a ratio below 1",
                    self.tangential_ratio
                ),
            ));
        }
        if self.tangential_ratio > 0.0 && self.friction == 0.0 {
            return Err(SolverError::invalid(
                "load.friction",
                "a tangential force needs a positive friction coefficient",
            ));
        }
        if !self.angle_deg.is_finite() {
            return Err(SolverError::invalid(
                "sweep.angles_deg",
                "the force angle must be finite",
            ));
        }
        pos("solver.tolerance", self.tolerance, "the tolerance")?;
        pos(
            "solver.tangential_tolerance",
            self.tangential_tolerance,
            "the tangential tolerance",
        )?;
        pos(
            "solver.coupling_tolerance",
            self.coupling_tolerance,
            "the coupling tolerance",
        )?;
        if self.max_iterations == 0 {
            return Err(SolverError::invalid(
                "solver.max_iterations",
                "must be at least 1",
            ));
        }
        if self.max_coupling_iterations == 0 {
            return Err(SolverError::invalid(
                "solver.max_coupling_iterations",
                "must be at least 1",
            ));
        }
        let e = &self.material.equivalent;
        let name = &self.material.name;
        match &self.material.elasticity {
            Elasticity::Isotropic(iso) => {
                crate::material::Isotropic::new(iso.youngs, iso.poisson).map_err(
                    |err| match err {
                        SolverError::Invalid { field, reason } => {
                            SolverError::invalid(&format!("materials.{name}.{field}"), reason)
                        }
                        other => other,
                    },
                )?;
            }
            Elasticity::Anisotropic(_) => {
                // The isotropic-equivalent constants only normalise; the paper's
                // Cu(111) has ν = 0.503, so only E > 0 and |ν| < 1 are required.
                if !(e.youngs.is_finite() && e.youngs > 0.0 && e.poisson.abs() < 1.0) {
                    return Err(SolverError::invalid(
                        &format!("materials.{name}.equivalent"),
                        format!(
                            "needs E > 0 and -1 < ν < 1, got E = {} Pa, ν = {}",
                            e.youngs, e.poisson
                        ),
                    ));
                }
            }
        }
        if let Elasticity::Anisotropic(c) = &self.material.elasticity {
            crate::material::check_stiffness(c).map_err(|r| {
                SolverError::invalid(&format!("materials.{}.stiffness", self.material.name), r)
            })?;
        }
        self.surface.validate(self.grid_points)?;
        Ok(())
    }
}

/// Persistent storage of kernel spectra (e.g. files), so that a new process
/// does not pay an expensive anisotropic kernel build again.
pub trait KernelStore {
    /// The spectra stored under `key`, if present and of `len` values each
    /// (see [`Spectra::len_for`]).
    fn load(&self, key: &str, len: usize) -> Option<Spectra>;
    /// Stores the spectra under `key` (best effort).
    fn save(&self, key: &str, spectra: &Spectra);
}

/// Resident operators, keyed by [`CaseSpec::kernel_key`].
#[derive(Default)]
pub struct KernelCache {
    ops: HashMap<String, Operator>,
    builds: usize,
    loads: usize,
    store: Option<Box<dyn KernelStore>>,
}

impl KernelCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty cache backed by a persistent store for anisotropic kernels.
    pub fn with_store(store: Box<dyn KernelStore>) -> Self {
        KernelCache {
            store: Some(store),
            ..Self::default()
        }
    }

    /// Number of operators made resident so far (built or loaded).
    pub fn builds(&self) -> usize {
        self.builds + self.loads
    }

    /// Of those, how many came from the persistent store.
    pub fn loads(&self) -> usize {
        self.loads
    }

    /// The operator for `spec`, built (or loaded) on first use; the second
    /// value is the time that took (0 when it was already resident).
    pub fn operator(&mut self, spec: &CaseSpec) -> Result<(&mut Operator, f64), SolverError> {
        let key = spec.kernel_key();
        let mut took = 0.0;
        if !self.ops.contains_key(&key) {
            let start = std::time::Instant::now();
            let grid = spec.grid();
            let len = Spectra::len_for(grid.n);
            let persistent = !spec.material.is_isotropic();
            let stored = match (&self.store, persistent) {
                (Some(store), true) => store.load(&key, len),
                _ => None,
            };
            let op = match stored.and_then(|s| Operator::from_spectra(grid, s)) {
                Some(op) => {
                    self.loads += 1;
                    op
                }
                None => {
                    let op = build_operator(&spec.material, grid);
                    if let (Some(store), true) = (&self.store, persistent) {
                        store.save(&key, op.spectra());
                    }
                    self.builds += 1;
                    op
                }
            };
            took = start.elapsed().as_secs_f64();
            self.ops.insert(key.clone(), op);
        }
        // Only the operator in use keeps a contact-window operator: the
        // others' are rebuilt from their spectra (tens of ms) when needed.
        for (k, op) in self.ops.iter_mut() {
            if *k != key {
                op.drop_window();
            }
        }
        Ok((self.ops.get_mut(&key).expect("inserted above"), took))
    }
}

/// The cell-influence function `K(x, y)` of a material on a grid (offsets of
/// the observation point from the loaded cell).
pub(crate) fn cell_influence(material: &Material, grid: Grid) -> Box<dyn Fn(f64, f64) -> Block> {
    let (dx, dy) = (grid.dx, grid.dy);
    match &material.elasticity {
        Elasticity::Isotropic(iso) => {
            let (g, nu) = (iso.shear(), iso.poisson);
            Box::new(move |x, y| isotropic_cell(g, nu, x, y, dx, dy))
        }
        Elasticity::Anisotropic(c) => {
            let kernel = crate::aniso::AngularKernel::new(c);
            Box::new(move |x, y| {
                let k = crate::aniso::cell_influence(&kernel, x, y, dx, dy);
                std::array::from_fn(|i| std::array::from_fn(|j| k[(i, j)]))
            })
        }
    }
}

/// The operator of a material on a grid, built row by row (see [`Operator::build`]).
pub fn build_operator(material: &Material, grid: Grid) -> Operator {
    Operator::build(grid, cell_influence(material, grid))
}

/// The scalars of one solved case.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseScalars {
    /// Apparent contact radius: circle with the area of the convex hull of the contact cells, m.
    pub contact_radius_m: f64,
    /// Apparent stick radius: same for the stick cells, m.
    pub stick_radius_m: f64,
    /// Rigid tangential shift δt projected on the force direction, m.
    pub delta_t_m: f64,
    /// Component of δt perpendicular to the force (left of it), m.
    pub delta_t_perp_m: f64,
    /// Rigid-body approach δz, m.
    pub delta_z_m: f64,
    /// Peak pressure, Pa.
    pub p_max_pa: f64,
    /// Peak shear traction magnitude, Pa.
    pub q_max_pa: f64,
    /// Contact area (cells with p > 0), m².
    pub contact_area_m2: f64,
    /// Stick area, m².
    pub stick_area_m2: f64,
    /// True when any contact cell lies off the island tops (patterned surfaces).
    pub base_contact: bool,
    /// Apparent friction coefficient from Eq. 19 (None without tangential load).
    pub mu_a: Option<f64>,
    /// K_E used for μa, Pa.
    pub k_e: f64,
    /// Where K_E came from: "isotropic" (formula with E, ν) or "flat-calibrated".
    pub k_e_source: String,
    /// Hertz contact radius with the isotropic-equivalent constants, m.
    pub hertz_radius_m: f64,
    /// Hertz peak pressure with the isotropic-equivalent constants, Pa.
    pub hertz_pressure_pa: f64,
    /// Total normal force recovered from the pressure, N.
    pub normal_force_n: f64,
    /// Total tangential force recovered from the tractions (x, y), N.
    pub tangential_force_n: [f64; 2],
    /// All loops converged.
    pub converged: bool,
    /// Normal CG iterations, summed over coupling iterations.
    pub normal_iterations: usize,
    /// Tangential iterations, summed over coupling iterations.
    pub tangential_iterations: usize,
    /// Coupling iterations (1 when uncoupled).
    pub coupling_iterations: usize,
    /// Final relative change of p between the last two coupling iterations.
    pub coupling_change: f64,
    /// Report of the last normal solve.
    pub normal: NormalReport,
    /// Report of the last tangential solve.
    pub tangential: TangentialReport,
    /// Wall time of the solve (operator build excluded), s.
    pub seconds: f64,
    /// Wall time spent building or loading the operator for this case
    /// (0 when it was already resident), s.
    #[serde(default)]
    pub kernel_seconds: f64,
}

/// Surface fields of a solved case, each `n x n`, row-major `[iy][ix]` (y rows, x columns).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fields {
    /// Cells per side.
    pub n: usize,
    /// Pressure, Pa.
    pub p: Vec<f64>,
    /// Shear traction x, Pa.
    pub qx: Vec<f64>,
    /// Shear traction y, Pa.
    pub qy: Vec<f64>,
    /// Slip x, m.
    pub sx: Vec<f64>,
    /// Slip y, m.
    pub sy: Vec<f64>,
    /// 1 on stick cells, 0 elsewhere.
    pub stick: Vec<f64>,
    /// Surface displacement x, m.
    pub ux: Vec<f64>,
    /// Surface displacement y, m.
    pub uy: Vec<f64>,
    /// Surface displacement z (into the body), m.
    pub uz: Vec<f64>,
}

impl Fields {
    /// The fields with their file names, in a fixed order.
    pub fn named(&self) -> [(&'static str, &Vec<f64>); 9] {
        [
            ("p", &self.p),
            ("qx", &self.qx),
            ("qy", &self.qy),
            ("sx", &self.sx),
            ("sy", &self.sy),
            ("stick", &self.stick),
            ("ux", &self.ux),
            ("uy", &self.uy),
            ("uz", &self.uz),
        ]
    }
}

/// Scalars and fields of one case.
#[derive(Clone, Debug)]
pub struct CaseOutput {
    /// Scalars.
    pub scalars: CaseScalars,
    /// Fields.
    pub fields: Fields,
}

/// How the apparent radii a and c of every result are defined.
pub const APPARENT_RADIUS_DEFINITION: &str =
    "radius of the circle with the area of the convex hull of the contact (stick) cells, each cell taken as its full square";

/// How K_E in μa is obtained.
pub const K_E_DEFINITION: &str = "isotropic: K_E = 8E/(3(1+nu)(2-nu)) (paper Eq. 19); anisotropic: K_E(psi) = mu P (a^2 - c^2)/(delta_F a^3) calibrated on the flat surface of the same material at the same force angle";

/// Paper Eq. 19: μa = δF a³ K_E / (P (a² − c²)).
pub fn mu_apparent(s: &CaseScalars, normal_force_n: f64, k_e: f64) -> f64 {
    let (a, c) = (s.contact_radius_m, s.stick_radius_m);
    s.delta_t_m * a.powi(3) * k_e / (normal_force_n * (a * a - c * c))
}

/// K_E calibrated from a flat-surface case so that Eq. 19 returns μ there.
pub fn calibrate_k_e(flat: &CaseScalars, friction: f64, normal_force_n: f64) -> f64 {
    let (a, c) = (flat.contact_radius_m, flat.stick_radius_m);
    friction * normal_force_n * (a * a - c * c) / (flat.delta_t_m * a.powi(3))
}

/// Initial separation between sphere (parabolic profile r²/2R) and surface,
/// shifted so that its minimum is zero (δz is then the approach from first touch).
pub fn initial_gap(spec: &CaseSpec, heights: &[f64]) -> Vec<f64> {
    let grid = spec.grid();
    let n = grid.n;
    let r = spec.indenter_radius_m;
    let mut h: Vec<f64> = (0..grid.len())
        .map(|i| {
            let (x, y) = (grid.x(i % n), grid.y(i / n));
            (x * x + y * y) / (2.0 * r) - heights[i]
        })
        .collect();
    // Zero at the first point of contact, so δz is the approach from first touch.
    let min = h.iter().cloned().fold(f64::INFINITY, f64::min);
    h.iter_mut().for_each(|v| *v -= min);
    h
}

fn touches_edge(n: usize, active: impl Fn(usize) -> bool) -> bool {
    (0..n).any(|k| active(k) || active((n - 1) * n + k) || active(k * n) || active(k * n + n - 1))
}

/// History depth of the Anderson mixing of the coupling loop.
const ANDERSON_DEPTH: usize = 3;

/// Anderson acceleration (type II) of a fixed point `x = G(x)`: given
/// `g = G(x_prev)`, replaces it by `g − ΔG γ` with `γ` minimising
/// `|f − ΔF γ|`, `f = g − x_prev`, over the last `depth` differences.
struct Anderson {
    depth: usize,
    x_prev: Vec<f64>,
    last: Option<(Vec<f64>, Vec<f64>)>,
    dg: std::collections::VecDeque<Vec<f64>>,
    df: std::collections::VecDeque<Vec<f64>>,
}

impl Anderson {
    fn new(depth: usize, len: usize) -> Self {
        Anderson {
            depth,
            x_prev: vec![0.0; len],
            last: None,
            dg: Default::default(),
            df: Default::default(),
        }
    }

    fn reset(&mut self) {
        self.last = None;
        self.dg.clear();
        self.df.clear();
    }

    /// `g` holds G(x_prev) on entry and the next iterate on return.
    fn mix(&mut self, g: &mut [f64]) {
        let f: Vec<f64> = g.iter().zip(&self.x_prev).map(|(a, b)| a - b).collect();
        if let Some((g_old, f_old)) = self.last.take() {
            if self.dg.len() == self.depth {
                self.dg.pop_front();
                self.df.pop_front();
            }
            self.dg
                .push_back(g.iter().zip(&g_old).map(|(a, b)| a - b).collect());
            self.df
                .push_back(f.iter().zip(&f_old).map(|(a, b)| a - b).collect());
        }
        let next_last = (g.to_vec(), f.clone());
        let m = self.df.len();
        if m > 0 {
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            let a = nalgebra::DMatrix::from_fn(m, m, |i, j| dot(&self.df[i], &self.df[j]));
            let b = nalgebra::DVector::from_fn(m, |i, _| dot(&self.df[i], &f));
            let reg = 1e-12 * a.trace().max(f64::MIN_POSITIVE);
            let a = a + nalgebra::DMatrix::identity(m, m) * reg;
            if let Some(gamma) = a.cholesky().map(|c| c.solve(&b)) {
                if gamma.iter().all(|v| v.is_finite()) {
                    for (j, dgj) in self.dg.iter().enumerate() {
                        for (gi, d) in g.iter_mut().zip(dgj) {
                            *gi -= gamma[j] * d;
                        }
                    }
                }
            }
        }
        self.last = Some(next_last);
        self.x_prev.copy_from_slice(g);
    }
}

/// Solves one case. The operator comes from (and stays in) `cache`.
pub fn solve_case(spec: &CaseSpec, cache: &mut KernelCache) -> Result<CaseOutput, SolverError> {
    spec.validate()?;
    let (op, kernel_seconds) = cache.operator(spec)?;
    let start = std::time::Instant::now();
    let grid = spec.grid();
    let n = grid.n;
    let len = grid.len();
    let da = grid.cell_area();
    let h0 = initial_gap(spec, &spec.surface.heights(&grid));
    let load = spec.normal_force_n;
    let tol = spec.tolerance;

    let normal0 = solve_normal(op, &h0, None, load, tol, spec.max_iterations, None)?;
    if touches_edge(n, |i| normal0.p[i] > 0.0) {
        return Err(SolverError::DomainTooSmall {
            detail: "pressure is non-zero on the outermost cells".into(),
        });
    }
    let mut normal_iterations = normal0.report.iterations;
    let mut normal_report = normal0.report;
    let mut approach = normal0.approach;
    let mut p = normal0.p;
    drop(normal0.uz);
    let force = spec.tangential_force();
    let fnorm = force[0].hypot(force[1]);

    let (mut qx, mut qy) = (vec![0.0; len], vec![0.0; len]);
    let (mut sx, mut sy) = (vec![0.0; len], vec![0.0; len]);
    let mut stick: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
    let mut shift = [0.0; 2];
    let mut tangential_iterations = 0;
    let mut tan_report = TangentialReport {
        converged: true,
        ..Default::default()
    };
    let mut coupling_iterations = 0;
    let mut coupling_change = 0.0;
    let mut coupling_converged = true;

    if fnorm > 0.0 {
        let (mut ex, mut ey) = (vec![0.0; len], vec![0.0; len]);
        let mut hq = vec![0.0; len];
        // The pressure before tangential loading: the coupling term is the
        // tangential displacement of the pressure's change since then.
        let p0 = if spec.coupling { p.clone() } else { Vec::new() };
        coupling_converged = !spec.coupling;
        let mut have_q = false;
        // Inexact inner solves while the coupling loop is far from converged:
        // each inner tolerance follows the last change of p, and the final
        // passes use the configured tolerances.
        let mut prev_change: f64 = 1e-2;
        let mut anderson = Anderson::new(ANDERSON_DEPTH, len);
        for k in 1..=spec.max_coupling_iterations {
            coupling_iterations = k;
            let exact_pass = !spec.coupling || prev_change < 10.0 * spec.coupling_tolerance;
            // In the final passes the tangential residual must not show as a
            // change of p above the coupling tolerance: with the default
            // coupling tolerance the KKT tolerance stays as configured; a
            // tighter coupling tolerance tightens it (p moves by about 1e-2 of
            // the tangential residual per pass).
            let (tan_tol, normal_tol) = if exact_pass {
                (
                    spec.tangential_tolerance
                        .min(100.0 * spec.coupling_tolerance)
                        .max(1e-12),
                    tol,
                )
            } else {
                (
                    spec.tangential_tolerance.max(0.1 * prev_change),
                    tol.max(1e-2 * prev_change),
                )
            };
            if spec.coupling {
                // hq is free until uz(q) is computed below.
                for ((d, a), b) in hq.iter_mut().zip(&p).zip(&p0) {
                    *d = a - b;
                }
                op.apply(&[(Z, &hq)], &mut [(X, &mut ex), (Y, &mut ey)]);
            }
            // The previous pass's slip is not an input: free it meanwhile.
            drop((std::mem::take(&mut sx), std::mem::take(&mut sy)));
            let sol = solve_tangential(
                op,
                &TangentialProblem {
                    p: &p,
                    friction: spec.friction,
                    force,
                    extra: spec.coupling.then_some((&ex[..], &ey[..])),
                    tolerance: tan_tol,
                    max_iterations: spec.max_iterations,
                    q_init: have_q.then_some((&qx[..], &qy[..])),
                },
            )?;
            have_q = true;
            tangential_iterations += sol.report.iterations;
            tan_report = sol.report;
            qx = sol.qx;
            qy = sol.qy;
            sx = sol.sx;
            sy = sol.sy;
            stick = sol.stick;
            shift = sol.shift;
            if !spec.coupling || coupling_converged {
                break;
            }
            op.apply(&[(X, &qx), (Y, &qy)], &mut [(Z, &mut hq)]);
            // Anderson mixing of the coupling gap uz(q) while the loop is far
            // from converged; plain (Picard) passes at the end, so the
            // convergence test below is the fixed-point test of the plain loop.
            if exact_pass {
                anderson.reset();
            } else {
                anderson.mix(&mut hq);
            }
            let nsol = solve_normal(
                op,
                &h0,
                Some(&hq),
                load,
                normal_tol,
                spec.max_iterations,
                Some(&p),
            )?;
            normal_iterations += nsol.report.iterations;
            normal_report = nsol.report;
            coupling_change = p
                .iter()
                .zip(&nsol.p)
                .map(|(a, b)| (a - b).abs())
                .sum::<f64>()
                * da
                / load;
            p = nsol.p;
            approach = nsol.approach;
            // One more tangential solve at the updated pressure closes the loop.
            if coupling_change < spec.coupling_tolerance && exact_pass {
                coupling_converged = true;
            }
            prev_change = coupling_change;
        }
    }
    if touches_edge(n, |i| p[i] > 0.0) {
        return Err(SolverError::DomainTooSmall {
            detail: "pressure is non-zero on the outermost cells".into(),
        });
    }

    // Total displacements from all tractions.
    let (mut ux, mut uy, mut uz) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    op.apply(
        &[(X, &qx), (Y, &qy), (Z, &p)],
        &mut [(X, &mut ux), (Y, &mut uy), (Z, &mut uz)],
    );

    let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
    let stick_in_contact: Vec<bool> = (0..len).map(|i| contact[i] && stick[i]).collect();
    let contact_area = contact.iter().filter(|&&b| b).count() as f64 * da;
    let stick_area = stick_in_contact.iter().filter(|&&b| b).count() as f64 * da;
    let a = equivalent_radius(hull_area(&grid, &contact));
    let c = if fnorm > 0.0 {
        equivalent_radius(hull_area(&grid, &stick_in_contact))
    } else {
        a
    };
    let dir = if fnorm > 0.0 {
        [force[0] / fnorm, force[1] / fnorm]
    } else {
        [1.0, 0.0]
    };
    // Recomputed here rather than held through the solve (one field less at
    // the memory peak; a cheap pass over the cells).
    let heights = spec.surface.heights(&grid);
    let top = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let base_contact = !matches!(spec.surface, crate::surface::Surface::Flat)
        && (0..len).any(|i| contact[i] && heights[i] < top);
    let eq = spec.material.equivalent;
    let hertz_radius = (3.0 * load * spec.indenter_radius_m / (4.0 * eq.plane_strain())).cbrt();
    let mut s = CaseScalars {
        contact_radius_m: a,
        stick_radius_m: c,
        delta_t_m: shift[0] * dir[0] + shift[1] * dir[1],
        delta_t_perp_m: -shift[0] * dir[1] + shift[1] * dir[0],
        delta_z_m: approach,
        p_max_pa: p.iter().cloned().fold(0.0, f64::max),
        q_max_pa: (0..len).map(|i| qx[i].hypot(qy[i])).fold(0.0, f64::max),
        contact_area_m2: contact_area,
        stick_area_m2: stick_area,
        base_contact,
        mu_a: None,
        k_e: eq.mindlin_k_e(),
        k_e_source: "isotropic".into(),
        hertz_radius_m: hertz_radius,
        hertz_pressure_pa: 3.0 * load / (2.0 * std::f64::consts::PI * hertz_radius * hertz_radius),
        normal_force_n: p.iter().sum::<f64>() * da,
        tangential_force_n: [qx.iter().sum::<f64>() * da, qy.iter().sum::<f64>() * da],
        converged: normal_report.converged && tan_report.converged && coupling_converged,
        normal_iterations,
        tangential_iterations,
        coupling_iterations: coupling_iterations.max(1),
        coupling_change,
        normal: normal_report,
        tangential: tan_report,
        seconds: start.elapsed().as_secs_f64(),
        kernel_seconds,
    };
    if fnorm > 0.0 {
        if c >= a {
            let slipping = contact_area - stick_area;
            return Err(SolverError::SlipUnresolved {
                detail: if slipping > 0.0 {
                    format!(
                        "the {} slipping cells lie inside the stick zone's outline, so a = c = {a:.4e} m",
                        (slipping / da).round()
                    )
                } else {
                    format!(
                        "all {} contact cells stick under F = {:.4e} N, so a = c = {a:.4e} m",
                        (contact_area / da).round(),
                        fnorm
                    )
                },
            });
        }
        s.mu_a = Some(mu_apparent(&s, load, s.k_e));
    }
    let fields = Fields {
        n,
        stick: stick_in_contact
            .iter()
            .map(|&b| if b { 1.0 } else { 0.0 })
            .collect(),
        p,
        qx,
        qy,
        sx,
        sy,
        ux,
        uy,
        uz,
    };
    Ok(CaseOutput { scalars: s, fields })
}
