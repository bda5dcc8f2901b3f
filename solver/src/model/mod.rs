//! Layer 3, the description of a case: materials, surfaces (patterns and
//! height maps; measured scans prepared, resampled onto a grid and
//! described by their roughness; random self-affine surfaces), the paper's
//! presets, the case itself (`CaseSpec`: grid, load, numerics, history),
//! and what the model means by an apparent radius.

pub mod material;
pub mod presets;
pub mod radii;
pub mod resample;
pub mod roughness;
pub mod scan;
pub mod self_affine;
pub mod spec;
pub mod surface;
