//! # mpcontact solver
//!
//! Frictional contact of a rigid sphere on an elastic — isotropic or
//! anisotropic, flat or micropatterned — half-space: materials, influence
//! coefficients, the DC-FFT operator, normal (Polonsky–Keer) and partial-slip
//! tangential solvers with normal–tangential coupling, and the per-case
//! scalars (contact/stick radii, shifts, apparent friction μa).
//! No IPC, no files, no CLI.
//!
//! The curated API is re-exported at the crate root:
//!
//! ```no_run
//! use solver::{presets, solve_case, CaseSpec, Grid, KernelCache, Load, Numerics};
//! let spec = CaseSpec {
//!     material: presets::material("Cu(111)").unwrap(),
//!     surface: presets::surface("circle-A").unwrap(),
//!     grid: Grid::square(256, 30e-6),
//!     load: Load {
//!         indenter_radius_m: 0.2,
//!         normal_force_n: 6000.0,
//!         friction: 0.3,
//!         tangential_ratio: 0.6,
//!         angle_deg: 30.0,
//!     },
//!     numerics: Numerics::default(),
//!     history: None,
//!     indenter: None,
//! };
//! let mut cache = KernelCache::new(); // keeps the kernel for the next case
//! let out = solve_case(&spec, &mut cache).unwrap();
//! println!("μa = {:?}", out.scalars.mu_a);
//! ```
//!
//! The operator and the two solvers are public too (modules `operator`,
//! `normal`, `tangential`, `window`), for problems other than a case: the
//! model / operator / solver split of Tamaas. Modules marked hidden are
//! public only for this crate's own tests, benches and examples.
//!
//! ## Layers
//!
//! Each module imports only from its own layer or those before it in this
//! list, never in a circle; a type two layers need lives in the lower one:
//!
//! 1. foundations: `error`, `progress`, `parallel`, `grid`, `geometry`, `cover`
//! 2. Green's functions: `influence`, `aniso`
//! 3. description of a case: `material`, `surface`, `presets`, `spec`
//! 4. the operator: `fft2`, `operator`, `multilevel` (coarse tables);
//!    `stress` (stresses below the surface, its own spectral kernels)
//! 5. single-field solvers: `normal`; `tangential_problem` (the tangential
//!    solve's inputs and outputs) and `fista` (the shared momentum step) →
//!    `coarse_slip` → `window` → `tangential`, `tangential_displacement`
//!    (the shift imposed instead of the force)
//! 6. resident kernels: `kernels` (an operator with the caches the solvers
//!    of layer 5 made for it, hence after them)
//! 7. load steps: `coupling` (one step, the coupling loop), `history` (a
//!    load path of steps)
//! 8. results: `results` (scalars and fields of a solved state)
//! 9. the driver: `case` (`solve_case`)

pub mod aniso;
mod case;
pub mod coarse_slip;
mod coupling;
#[doc(hidden)]
pub mod cover;
mod error;
#[doc(hidden)]
pub mod fft2;
mod fista;
#[doc(hidden)]
pub mod geometry;
mod grid;
mod history;
pub mod indentation;
#[doc(hidden)]
pub mod influence;
mod kernels;
mod material;
#[doc(hidden)]
pub mod multilevel;
pub mod normal;
pub mod operator;
mod parallel;
pub mod presets;
mod progress;
mod results;
mod spec;
pub mod stress;
pub mod stress_summary;
mod surface;
pub mod tangential;
pub mod tangential_displacement;
mod tangential_problem;
pub mod window;

pub use case::solve_case;
pub use error::SolverError;
pub use grid::Grid;
pub use history::{
    HistoryOutput, HistoryStep, TurningState, DISSIPATION_DEFINITION, SLIP_REGIME_DEFINITION,
};
pub use kernels::{
    build_operator, build_pair_operator, persists, BuildLock, KernelCache, KernelKey, KernelStore,
    Resident,
};
pub use material::{
    hill_average, pair_influence, Anisotropic, ElasticModel, Elasticity, Isotropic, Material,
};
pub use operator::{Operator, Spectra};
pub use parallel::Threads;
pub use progress::{cancel, phase, set_tick_hook, Phase, Stage, TickHook};
pub use results::{
    calibrate_k_e, calibrate_on_flat, mu_apparent, CaseOutput, CaseScalars, Fields,
    APPARENT_RADIUS_DEFINITION, APPARENT_RADIUS_DEFINITION_CELLS,
    APPARENT_RADIUS_DEFINITION_MOMENTS, K_E_DEFINITION, K_E_FLAT_CALIBRATED, K_E_ISOTROPIC,
};
pub use spec::{CaseSpec, Load, LoadHistory, Numerics, Radii, MAX_GRID_POINTS, MAX_HISTORY_STEPS};
pub use surface::{Island, LatticeKind, Sampling, Surface, Terrain, MIN_COVER};
