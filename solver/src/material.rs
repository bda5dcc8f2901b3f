//! Elastic materials of the substrate: a general 6x6 stiffness in the surface
//! frame (SI, Voigt xx, yy, zz, yz, xz, xy; z into the body), plus the
//! isotropic-equivalent (E, ν) used to normalise results and in Mindlin's K_E.

use crate::error::SolverError;
use nalgebra::Matrix6;
use serde::{Deserialize, Serialize};

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
        crate::aniso::crystal::isotropic_stiffness(self.youngs, self.poisson)
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
    Anisotropic(#[serde(with = "matrix6_serde")] Matrix6<f64>),
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
}

impl Material {
    /// An isotropic material.
    pub fn isotropic(name: &str, youngs_pa: f64, poisson: f64) -> Result<Self, SolverError> {
        let iso = Isotropic::new(youngs_pa, poisson)?;
        Ok(Material {
            name: name.to_string(),
            elasticity: Elasticity::Isotropic(iso),
            equivalent: iso,
        })
    }

    /// An anisotropic material from its stiffness in the surface frame (Pa, Voigt)
    /// and the isotropic-equivalent constants used for normalisation.
    pub fn anisotropic(
        name: &str,
        stiffness: Matrix6<f64>,
        equivalent: Isotropic,
    ) -> Result<Self, SolverError> {
        check_stiffness(&stiffness)
            .map_err(|r| SolverError::invalid(&format!("materials.{name}.stiffness"), r))?;
        Ok(Material {
            name: name.to_string(),
            elasticity: Elasticity::Anisotropic(stiffness),
            equivalent,
        })
    }

    /// Stiffness in the surface frame (Pa, Voigt).
    pub fn stiffness(&self) -> Matrix6<f64> {
        match &self.elasticity {
            Elasticity::Isotropic(iso) => iso.stiffness(),
            Elasticity::Anisotropic(c) => *c,
        }
    }

    /// True when the closed-form isotropic kernels apply.
    pub fn is_isotropic(&self) -> bool {
        matches!(self.elasticity, Elasticity::Isotropic(_))
    }
}

/// Checks that a stiffness is finite, symmetric and positive definite; the message says what fails.
pub fn check_stiffness(c: &Matrix6<f64>) -> Result<(), String> {
    crate::aniso::crystal::check_positive_definite(c)
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
