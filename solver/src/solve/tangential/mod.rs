//! Partial slip at fixed pressure: shear tractions on the contact cells
//! within their friction discs, one file per problem and one per method.
//!
//! * Problems: the tangential force imposed ([`force`]: `ΔA Σq = F`, the
//!   rigid shift δt the result) and the rigid shift imposed
//!   ([`displacement`]: the force the result), with their inputs and
//!   outputs in [`problem`].
//! * Methods: the projected conjugate gradient over the stick cells'
//!   tractions and the slip cells' rotation on their rims (`cg`, the
//!   default), the active-set iteration with the compliance's circulant
//!   inverse ([`active_set`], `solver.tangential_method = "active-set"`),
//!   and accelerated projected gradient ([`fista`]), the fallback of both
//!   and of the displacement problem.
//! * Shared: the coarse-to-fine start ([`coarse_slip`]) and the contact
//!   window the solves run on ([`window`]).

pub mod problem;

pub mod fista;

pub mod coarse_slip;

pub mod window;

pub mod active_set;

mod cg;

pub mod force;

pub mod displacement;

pub use cg::FOURIER_STICK_MAX_SIDE;
pub(crate) use force::solve_tangential_taking;
pub use force::{solve_nested, solve_tangential, solve_tangential_on_grid};
pub use problem::{
    TangentialMethod, TangentialProblem, TangentialReport, TangentialSolution, TangentialStart,
};
