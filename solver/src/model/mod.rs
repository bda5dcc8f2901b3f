//! Layer 3, the description of a case: materials, surfaces, the paper's
//! presets, the case itself (`CaseSpec`: grid, load, numerics, history), and
//! what the model means by an apparent radius.

pub mod material;
pub mod presets;
pub mod radii;
pub mod spec;
pub mod surface;
