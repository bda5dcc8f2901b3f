//! Elastic materials of the substrate: a general 6x6 stiffness in the surface
//! frame (SI, Voigt xx, yy, zz, yz, xz, xy; z into the body), plus the
//! isotropic-equivalent (E, ν) used to normalise results and in Mindlin's K_E.
//! Each kind of elasticity is an [`ElasticModel`]: what the operator build,
//! the kernel store and the listings need of it. The one place that checks
//! constants (positive definite stiffness, E and ν ranges).

use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::green::influence::{isotropic_cell, Block};
use nalgebra::{Matrix3, Matrix6};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// The cell-influence function `K(x, y)` of a material on a grid: the
/// displacement at offset `(x, y)` from a uniformly loaded cell, per unit traction.
pub type CellInfluence = Box<dyn Fn(f64, f64) -> Block>;

/// A model of the elastic half-space: yields the cell influence
/// coefficients the DC-FFT operator is built from, and says what a caller
/// needs to know about them.
pub trait ElasticModel {
    /// The cell-influence function on `grid`.
    fn cell_influence(&self, grid: Grid) -> CellInfluence;
    /// True when building its tables is expensive enough to persist them
    /// (numerical Green's functions), false for closed forms.
    fn persist_tables(&self) -> bool;
    /// True when its cell influence is exactly (to the bit) even or odd in x
    /// and in y with the parities of [`crate::green::influence::mirror_sign`], so
    /// that a kernel build may evaluate one quadrant and mirror it.
    fn mirror_symmetric(&self) -> bool {
        false
    }
    /// Stiffness in the surface frame (Pa, Voigt).
    fn stiffness(&self) -> Matrix6<f64>;
    /// Checks the constants; errors name the parameter (`youngs`, `poisson`, `stiffness`).
    fn validate(&self) -> Result<(), SolverError>;
    /// `isotropic` or `anisotropic`, for listings.
    fn kind(&self) -> &'static str;
    /// The constants in GPa, for listings.
    fn describe(&self) -> String;
}

/// Isotropic constants (SI).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Isotropic {
    /// Young's modulus, Pa.
    pub youngs: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

impl Isotropic {
    /// Validated constructor: `E > 0`, finite, `-1 < ν ≤ 0.5`.
    pub fn new(youngs: f64, poisson: f64) -> Result<Self, SolverError> {
        if !youngs.is_finite() || youngs <= 0.0 {
            return Err(SolverError::invalid(
                "youngs",
                format!("Young's modulus must be positive and finite, got {youngs} Pa"),
            ));
        }
        if !poisson.is_finite() || poisson <= -1.0 || poisson > 0.5 {
            return Err(SolverError::invalid(
                "poisson",
                format!("Poisson's ratio must lie in (-1, 0.5], got {poisson}"),
            ));
        }
        Ok(Isotropic { youngs, poisson })
    }

    /// Shear modulus G = E / (2(1 + ν)).
    pub fn shear(&self) -> f64 {
        self.youngs / (2.0 * (1.0 + self.poisson))
    }

    /// Plane-strain modulus for a rigid indenter, E* = E / (1 − ν²).
    pub fn plane_strain(&self) -> f64 {
        self.youngs / (1.0 - self.poisson * self.poisson)
    }

    /// Mindlin's tangential stiffness constant K_E = 8E / (3(1 + ν)(2 − ν)) (paper Eq. 19).
    pub fn mindlin_k_e(&self) -> f64 {
        8.0 * self.youngs / (3.0 * (1.0 + self.poisson) * (2.0 - self.poisson))
    }

    /// 6x6 Voigt stiffness (Pa).
    pub fn stiffness(&self) -> Matrix6<f64> {
        crate::green::aniso::crystal::isotropic_stiffness(self.youngs, self.poisson)
    }
}

impl ElasticModel for Isotropic {
    fn cell_influence(&self, grid: Grid) -> CellInfluence {
        let (g, nu, dx, dy) = (self.shear(), self.poisson, grid.dx, grid.dy);
        Box::new(move |x, y| isotropic_cell(g, nu, x, y, dx, dy))
    }
    fn persist_tables(&self) -> bool {
        false
    }
    fn mirror_symmetric(&self) -> bool {
        true
    }
    fn stiffness(&self) -> Matrix6<f64> {
        Isotropic::stiffness(self)
    }
    fn validate(&self) -> Result<(), SolverError> {
        Isotropic::new(self.youngs, self.poisson).map(|_| ())
    }
    fn kind(&self) -> &'static str {
        "isotropic"
    }
    fn describe(&self) -> String {
        format!("E = {:.2}, nu = {}", self.youngs / 1e9, self.poisson)
    }
}

/// A general anisotropic stiffness in the surface frame (Pa, Voigt): kernels
/// from the Stroh / Barnett–Lothe Green's function by ray integration.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Anisotropic(#[serde(with = "matrix6_serde")] pub Matrix6<f64>);

impl ElasticModel for Anisotropic {
    fn cell_influence(&self, grid: Grid) -> CellInfluence {
        let (dx, dy) = (grid.dx, grid.dy);
        let kernel = crate::green::aniso::AngularKernel::new(&self.0);
        Box::new(move |x, y| {
            let k = crate::green::aniso::cell_influence(&kernel, x, y, dx, dy);
            std::array::from_fn(|i| std::array::from_fn(|j| k[(i, j)]))
        })
    }
    fn persist_tables(&self) -> bool {
        true
    }
    fn stiffness(&self) -> Matrix6<f64> {
        self.0
    }
    fn validate(&self) -> Result<(), SolverError> {
        check_stiffness(&self.0).map_err(|r| SolverError::invalid("stiffness", r))
    }
    fn kind(&self) -> &'static str {
        "anisotropic"
    }
    fn describe(&self) -> String {
        let mut parts = Vec::new();
        for i in 0..6 {
            for j in i..6 {
                if self.0[(i, j)] != 0.0 {
                    parts.push(format!("C{}{} = {}", i + 1, j + 1, self.0[(i, j)] / 1e9));
                }
            }
        }
        parts.join(", ")
    }
}

/// How the half-space responds: closed forms exist only for the isotropic case.
// A material is built once per case; the size difference of the variants is irrelevant.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Elasticity {
    /// Isotropic: closed-form influence coefficients.
    Isotropic(Isotropic),
    /// General anisotropic stiffness in the surface frame (Pa, Voigt).
    Anisotropic(Anisotropic),
}

impl Elasticity {
    /// The model behind this elastic law.
    pub fn model(&self) -> &dyn ElasticModel {
        match self {
            Elasticity::Isotropic(iso) => iso,
            Elasticity::Anisotropic(c) => c,
        }
    }
}

/// A substrate material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Display name (preset or config key).
    pub name: String,
    /// The elastic law.
    pub elasticity: Elasticity,
    /// Isotropic-equivalent constants: normalisation (Hertz a, p_H) and Mindlin K_E.
    /// Equal to the constants themselves for an isotropic material.
    pub equivalent: Isotropic,
    /// The surface's plastic limits (none: elastic).
    #[serde(default)]
    pub limits: Limits,
}

/// The plastic limits of a body's surface, an elastic–perfectly plastic
/// interface: the pressure cannot exceed the hardness (the material below
/// flows and keeps the penetration), the shear traction cannot exceed the
/// shear limit. `None`: no such limit (elastic).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// Hardness H, Pa.
    pub hardness: Option<f64>,
    /// Shear limit τ_c, Pa.
    pub shear_limit: Option<f64>,
}

/// A surface limit on each of `len` cells: `limit` on the covered part of
/// the cell, `limit × cover` (a cell's traction is its mean over the whole
/// cell and sits on the covered part, #34), `limit` where whole. The one
/// place a hardness or a shear limit meets the cut cells.
pub fn limit_per_cell(limit: f64, cover: Option<&[f64]>, len: usize) -> Vec<f64> {
    match cover {
        Some(cover) => cover.iter().map(|c| limit * c).collect(),
        None => vec![limit; len],
    }
}

/// The area of the cells whose pressure `p` is at the cap `hardness`
/// ([`limit_per_cell`]), their covered part on cut cells, m²: the
/// normal solver's plastic zone to the bit. One place for a case's and a
/// load history's increments' plastic area.
pub fn area_at_cap(hardness: f64, cover: Option<&[f64]>, p: &[f64], da: f64) -> f64 {
    let caps = limit_per_cell(hardness, cover, p.len());
    let capped: Vec<bool> = p
        .iter()
        .zip(&caps)
        .map(|(&v, &c)| v > 0.0 && v >= c)
        .collect();
    crate::base::geometry::covered_area(&capped, cover, da)
}

impl Limits {
    /// The limits of the interface between two bodies: the smaller of each
    /// (the softer surface yields first).
    pub fn softer(self, other: Limits) -> Limits {
        let min = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(x), Some(y)) => Some(x.min(y)),
            (x, None) => x,
            (None, y) => y,
        };
        Limits {
            hardness: min(self.hardness, other.hardness),
            shear_limit: min(self.shear_limit, other.shear_limit),
        }
    }

    /// Checks that each limit given is positive and finite; errors name it
    /// (`hardness`, `shear_limit`).
    pub fn validate(&self) -> Result<(), SolverError> {
        for (name, v) in [
            ("hardness", self.hardness),
            ("shear_limit", self.shear_limit),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return Err(SolverError::invalid(
                        name,
                        format!("must be positive and finite, got {v} Pa"),
                    ));
                }
            }
        }
        Ok(())
    }
}

impl Material {
    /// An isotropic material.
    pub fn isotropic(name: &str, youngs_pa: f64, poisson: f64) -> Result<Self, SolverError> {
        let iso = Isotropic::new(youngs_pa, poisson)?;
        Ok(Material {
            name: name.to_string(),
            elasticity: Elasticity::Isotropic(iso),
            equivalent: iso,
            limits: Limits::default(),
        })
    }

    /// An anisotropic material from its stiffness in the surface frame (Pa, Voigt)
    /// and the isotropic-equivalent constants used for normalisation.
    pub fn anisotropic(
        name: &str,
        stiffness: Matrix6<f64>,
        equivalent: Isotropic,
    ) -> Result<Self, SolverError> {
        let m = Material {
            name: name.to_string(),
            elasticity: Elasticity::Anisotropic(Anisotropic(stiffness)),
            equivalent,
            limits: Limits::default(),
        };
        m.validate()?;
        Ok(m)
    }

    /// A cubic crystal (constants in Pa) whose surface normal `normal` and
    /// in-plane x direction `x_dir` are given in crystal axes; the
    /// isotropic-equivalent constants are `equivalent` or, without them, the
    /// Hill average of the stiffness.
    pub fn cubic(
        name: &str,
        [c11, c12, c44]: [f64; 3],
        normal: [f64; 3],
        x_dir: [f64; 3],
        equivalent: Option<Isotropic>,
    ) -> Result<Self, SolverError> {
        let c = crate::green::aniso::crystal::cubic_stiffness_rotated(c11, c12, c44, normal, x_dir)
            .map_err(|r| SolverError::invalid("orientation", r))?;
        Self::with_stiffness(name, c, equivalent)
    }

    /// An anisotropic material from its stiffness (Pa, Voigt, surface frame);
    /// the isotropic-equivalent constants are `equivalent` or, without them,
    /// the Hill average.
    pub fn with_stiffness(
        name: &str,
        stiffness: Matrix6<f64>,
        equivalent: Option<Isotropic>,
    ) -> Result<Self, SolverError> {
        Anisotropic(stiffness).validate()?;
        let equivalent = match equivalent {
            Some(e) => e,
            None => hill_average(&stiffness)
                .ok_or_else(|| SolverError::invalid("stiffness", "singular stiffness"))?,
        };
        Self::anisotropic(name, stiffness, equivalent)
    }

    /// The same material with the plastic limits `limits`.
    pub fn with_limits(mut self, limits: Limits) -> Result<Self, SolverError> {
        limits.validate()?;
        self.limits = limits;
        Ok(self)
    }

    /// The elastic model of this material.
    pub fn model(&self) -> &dyn ElasticModel {
        self.elasticity.model()
    }

    /// Stiffness in the surface frame (Pa, Voigt).
    pub fn stiffness(&self) -> Matrix6<f64> {
        self.model().stiffness()
    }

    /// Surface compliance `H(θ)` (1/Pa) of the Fourier-domain surface Green's
    /// function along in-plane direction `theta` (rad), Stroh / Barnett–Lothe.
    pub fn surface_compliance(&self, theta: f64) -> Matrix3<Complex64> {
        crate::green::aniso::stroh::surface_compliance(&self.stiffness(), theta)
    }

    /// Checks the constants: the model's, and for an anisotropic material
    /// the isotropic-equivalent ones (E > 0, |ν| < 1). Errors name the
    /// parameter (`youngs`, `poisson`, `stiffness`, `equivalent`).
    pub fn validate(&self) -> Result<(), SolverError> {
        self.model().validate()?;
        self.limits.validate()?;
        if !self.is_isotropic() {
            // The isotropic-equivalent constants only normalise; the paper's
            // Cu(111) has ν = 0.503, so only E > 0 and |ν| < 1 are required.
            let e = &self.equivalent;
            if !(e.youngs.is_finite() && e.youngs > 0.0 && e.poisson.abs() < 1.0) {
                return Err(SolverError::invalid(
                    "equivalent",
                    format!(
                        "needs E > 0 and -1 < ν < 1, got E = {} Pa, ν = {}",
                        e.youngs, e.poisson
                    ),
                ));
            }
        }
        Ok(())
    }

    /// True when the closed-form isotropic kernels apply.
    pub fn is_isotropic(&self) -> bool {
        matches!(self.elasticity, Elasticity::Isotropic(_))
    }
}

/// The cell influence of a contact pair: the relative displacement of the
/// substrate's surface against the ball's, `u_sub − u_ball`, per unit traction
/// on the substrate (the ball carries the opposite traction).
///
/// The ball's own frame is the substrate's turned 180° about x,
/// `R = diag(1, −1, −1)` (its normal points into the ball, its x along the
/// substrate's x). A traction `t` on the substrate is `−t` on the ball, which
/// is `−R t` in the ball's frame, and the ball's displacement there at
/// `(x, −y)` is turned back by `R`: `u_ball = −R K_ball(x, −y) R t`. So
///
/// `K_pair(x, y) = K_sub(x, y) + R K_ball(x, −y) R`:
///
/// normal–normal and tangential–tangential compliances add, the
/// normal–tangential entries of the ball enter with the opposite sign (for
/// isotropic bodies `K_xz(x, −y) = K_xz(x, y)`, negated by R), so two
/// identical isotropic bodies give zero coupling (Dundurs β = 0).
pub fn pair_influence(substrate: CellInfluence, ball: CellInfluence) -> CellInfluence {
    // R K R flips the sign of the entries with exactly one index in {y, z}.
    const SIGN: [[f64; 3]; 3] = [[1.0, -1.0, -1.0], [-1.0, 1.0, 1.0], [-1.0, 1.0, 1.0]];
    Box::new(move |x, y| {
        let a = substrate(x, y);
        let b = ball(x, -y);
        std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + SIGN[i][j] * b[i][j]))
    })
}

/// Checks that a stiffness is finite, symmetric and positive definite; the message says what fails.
fn check_stiffness(c: &Matrix6<f64>) -> Result<(), String> {
    crate::green::aniso::crystal::check_positive_definite(c)
}

/// Hill average of a stiffness (mean of the Voigt and Reuss bounds of the
/// bulk and shear moduli): isotropic constants for normalisation. `None`
/// for a singular stiffness.
pub fn hill_average(c: &Matrix6<f64>) -> Option<Isotropic> {
    let s = c.try_inverse()?;
    let kv = (c[(0, 0)] + c[(1, 1)] + c[(2, 2)] + 2.0 * (c[(0, 1)] + c[(0, 2)] + c[(1, 2)])) / 9.0;
    let gv = (c[(0, 0)] + c[(1, 1)] + c[(2, 2)] - (c[(0, 1)] + c[(0, 2)] + c[(1, 2)])
        + 3.0 * (c[(3, 3)] + c[(4, 4)] + c[(5, 5)]))
        / 15.0;
    let kr = 1.0 / (s[(0, 0)] + s[(1, 1)] + s[(2, 2)] + 2.0 * (s[(0, 1)] + s[(0, 2)] + s[(1, 2)]));
    let gr = 15.0
        / (4.0 * (s[(0, 0)] + s[(1, 1)] + s[(2, 2)]) - 4.0 * (s[(0, 1)] + s[(0, 2)] + s[(1, 2)])
            + 3.0 * (s[(3, 3)] + s[(4, 4)] + s[(5, 5)]));
    let (k, g) = (0.5 * (kv + kr), 0.5 * (gv + gr));
    Some(Isotropic {
        youngs: 9.0 * k * g / (3.0 * k + g),
        poisson: (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)),
    })
}

mod matrix6_serde {
    use nalgebra::Matrix6;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(m: &Matrix6<f64>, s: S) -> Result<S::Ok, S::Error> {
        let rows: Vec<[f64; 6]> = (0..6).map(|i| std::array::from_fn(|j| m[(i, j)])).collect();
        rows.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Matrix6<f64>, D::Error> {
        let rows: Vec<[f64; 6]> = Vec::deserialize(d)?;
        if rows.len() != 6 {
            return Err(serde::de::Error::custom("stiffness must have 6 rows"));
        }
        Ok(Matrix6::from_fn(|i, j| rows[i][j]))
    }
}
