//! # mpcontact solver
//!
//! Frictional contact of a rigid sphere on an elastic half-space: materials,
//! influence coefficients, the DC-FFT operator, normal (Polonsky–Keer) and
//! partial-slip tangential solvers with normal–tangential coupling, and the
//! per-case scalars (contact/stick radii, shifts, apparent friction μa).
//! No IPC, no files, no CLI.

pub mod aniso;
pub mod case;
pub mod error;
pub mod fft2;
pub mod geometry;
pub mod influence;
pub mod material;
pub mod multilevel;
pub mod normal;
pub mod operator;
pub mod presets;
pub mod surface;
pub mod tangential;

pub use error::SolverError;
