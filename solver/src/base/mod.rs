//! Layer 1, foundations (no physics): the tick hook and the phase the long
//! loops report, the thread pool of one case, the cell grid, and the areas of
//! cell sets and of shapes inside a cell.

pub mod cover;
pub mod geometry;
pub mod grid;
pub mod parallel;
pub mod progress;
