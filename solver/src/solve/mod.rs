//! Layer 5, the solvers, in this order: the normal solver; the tangential
//! solve's types, its momentum step, coarse start, window, its active-set
//! iteration, the tangential solver and the imposed-shift variant; an
//! operator with the caches those solvers made for it (`resident`); one
//! load step with the coupling loop; the wear of a path; a load history of
//! steps.

pub mod active_set;
pub mod coarse_slip;
pub mod coupling;
pub mod fista;
pub mod history;
pub mod normal;
pub mod resident;
pub mod tangential;
pub mod tangential_displacement;
pub mod tangential_problem;
pub mod wear;
pub mod window;
