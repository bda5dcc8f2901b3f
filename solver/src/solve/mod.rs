//! Layer 5, the solvers, in this order: the normal solver; the tangential
//! solves (`tangential`: the force- and shift-controlled problems and their
//! methods, one file each); an
//! operator with the caches those solvers made for it (`resident`); one
//! load step with the coupling loop; the wear of a path; a load history of
//! steps.

pub mod coupling;
pub mod history;
pub mod normal;
pub mod resident;
pub mod tangential;
pub mod wear;
