//! Layer 6, what is computed from a solution: a case's scalars and fields
//! (radii, shifts, μa and its K_E), the stresses' summary over a case's
//! states, and the Hertzian indentation of an elastic ball.

pub mod indentation;
pub mod results;
pub mod stress_summary;
