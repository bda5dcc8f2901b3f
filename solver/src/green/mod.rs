//! Layer 2, Green's functions: the surface displacement of a unit traction on
//! one cell — isotropic closed forms and anisotropic (Stroh) compliance.

pub mod aniso;
pub mod influence;
