//! Anisotropic half-space: Stroh / Barnett–Lothe surface compliance H(θ), the
//! real-space angular kernel g(φ), influence coefficients by ray integration,
//! cubic crystals rotated to a surface frame, and the paper's (111) presets.
//! Physics only; the operator and solvers consume `cell_influence`.

pub mod crystal;
pub mod greens;
pub mod influence;
pub mod presets;
pub mod stroh;

pub use greens::AngularKernel;
pub use influence::cell_influence;
