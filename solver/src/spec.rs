//! What defines one contact case: material, surface, grid, load and the
//! numerical settings, and their validation. Errors name the case's
//! parameters (`load.normal_force_n`, `surface.pitch`, …), not config keys:
//! a front end maps them to its own names. Solves nothing.

use crate::error::SolverError;
use crate::grid::Grid;
use crate::material::Material;
use crate::surface::Surface;
use serde::{Deserialize, Serialize};

/// Largest grid accepted (cells per side): a bound on index arithmetic and
/// transform sizes only, far above what a machine holds (16384² needs about
/// 130 GiB). Whether a grid fits is one rule of the front end: the estimated
/// memory of the case against what the machine has available
/// (`coordinator::memory`, with the estimate in its message).
pub const MAX_GRID_POINTS: usize = 16384;

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
        }
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
    /// material at the same angle (anisotropic material under a tangential load).
    pub fn needs_flat_calibration(&self) -> bool {
        !self.material.is_isotropic() && self.load.tangential_ratio > 0.0
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
        let heights = self.surface.heights(&self.grid);
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
        self.surface
            .validate(grid.n)
            .map_err(|e| within("surface", e))?;
        // A contact a few cells across cannot be solved meaningfully (a
        // 1e-300 m sphere gave δz = 4.6e296 m, #20 item 8). Hertz's radius
        // with the isotropic-equivalent constants is the scale; patterns
        // and anisotropy change it by tens of per cent, not by cells.
        let a_hertz = (3.0 * load.normal_force_n * load.indenter_radius_m
            / (4.0 * self.material.equivalent.plane_strain()))
        .cbrt();
        let min = crate::results::MIN_RESOLVED_CELLS * grid.dx;
        if a_hertz < min {
            return Err(SolverError::ContactUnresolved {
                detail: format!(
                    "the Hertz contact radius {a_hertz:.3e} m spans fewer than {} cells of {:.3e} m",
                    crate::results::MIN_RESOLVED_CELLS,
                    grid.dx
                ),
            });
        }
        Ok(())
    }
}
