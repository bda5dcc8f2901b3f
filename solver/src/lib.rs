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
//! The modules live in one folder per layer. A module imports only from its
//! own layer (from a module listed before it) or the layers before it, never
//! in a circle; a type two layers need lives in the lower one. The public
//! module paths (`solver::normal`, `solver::operator`, …) are re-exports.
//!
//! 0. `error` (every layer's `SolverError`)
//! 1. `base/`, foundations, no physics: `progress`, `parallel`, `grid`,
//!    `geometry`, `cover`
//! 2. `green/`, Green's functions: `influence`, `aniso`
//! 3. `model/`, the description of a case: `material`, `surface`,
//!    `roughness` (Sa, Sq, Sz, Sdq of a height map), `scan` (a measured
//!    topography and its levelling), `resample` (a scan on a case's
//!    grid), `self_affine` (random surfaces), `presets`, `radii` (what an
//!    apparent radius is), `spec`
//! 4. `operators/`, kernels and operators: `fft2`, `operator`, `multilevel`
//!    (coarse tables), `stress` (a folder: the stresses below the surface,
//!    their depth kernels and the criteria of a point's states), `kernels`
//!    (a kernel's identity, store and build)
//! 5. `solve/`, the solvers: `normal`; `tangential_problem` (the tangential
//!    solve's inputs and outputs) and `fista` (the shared momentum step) →
//!    `coarse_slip` → `window` → `tangential`, `tangential_displacement`
//!    (the shift imposed instead of the force) → `resident` (an operator
//!    with the caches those solvers made for it) → `coupling` (one load
//!    step, the coupling loop) → `history` (a load path of steps)
//! 6. `post/`, computed from a solution: `results` (scalars and fields),
//!    `stress_summary` (a case's stresses and their scalars), `indentation`
//! 7. `case`, the driver (`solve_case`)
//!
//! The workspace's `tests/tests/layers.rs` checks the order and the absence
//! of circles.

mod base;
mod case;
mod error;
mod green;
mod model;
mod operators;
mod post;
mod solve;

#[doc(hidden)]
pub use base::cover;
#[doc(hidden)]
pub use base::geometry;
pub use green::aniso;
#[doc(hidden)]
pub use green::influence;
pub use model::presets;
#[doc(hidden)]
pub use operators::fft2;
#[doc(hidden)]
pub use operators::multilevel;
pub use operators::operator;
pub use operators::stress;
pub use post::indentation;
pub use post::stress_summary;
pub use solve::normal;
pub use solve::tangential;
pub use solve::tangential::coarse_slip;
pub use solve::tangential::displacement as tangential_displacement;
pub use solve::tangential::window;

pub use base::grid::Grid;
pub use base::parallel::Threads;
pub use base::progress::{cancel, phase, set_tick_hook, Phase, Stage, TickHook};
pub use case::{preflight, solve_case, Preflight};
pub use error::SolverError;
pub use model::material::{
    hill_average, pair_influence, Anisotropic, ElasticModel, Elasticity, Isotropic, Limits,
    Material,
};
pub use model::radii::{
    Radii, APPARENT_RADIUS_DEFINITION, APPARENT_RADIUS_DEFINITION_CELLS,
    APPARENT_RADIUS_DEFINITION_MOMENTS, ZONE_RADIUS_DEFINITION,
};
pub use model::resample::{resample, resample_two_level};
pub use model::roughness::{roughness, Roughness};
pub use model::scan::{Levelling, Missing, Scan, MAX_LEVELLING_DEGREE};
pub use model::self_affine::{Amplitude, SelfAffine};
pub use model::spec::{
    CaseSpec, Increments, Load, LoadHistory, LoopSampling, Numerics, TangentialMethod, Wear,
    WearLaw, AUTO_LOAD_STEP, AUTO_TOLERANCE, MAX_GRID_POINTS, MAX_HISTORY_STEPS, MAX_SHIFT_DOMAINS,
    MAX_WEAR_COEFFICIENT, MAX_WEAR_JUMP, MIN_SHIFT_M,
};
pub use model::surface::{
    Island, LatticeKind, Sampling, Surface, Terrain, MIN_COVER, RESOLVED_CELLS_PER_PITCH,
};
pub use operators::kernels::{
    build_operator, build_pair_operator, persists, BuildLock, KernelKey, KernelStore,
};
pub use operators::operator::{Operator, Spectra};
pub use post::results::{
    calibrate_k_e, calibrate_on_flat, mu_apparent, CaseOutput, CaseScalars, Fields, PlasticScalars,
    HERTZ_MISFIT_DEFINITION, HERTZ_MISFIT_LIMIT, K_E_DEFINITION, K_E_FLAT_CALIBRATED,
    K_E_ISOTROPIC,
};
pub use solve::history::{
    HistoryOutput, HistoryStep, TurningState, WearCycle, DISSIPATION_DEFINITION, SCAR_DEFINITION,
    SLIP_REGIME_DEFINITION, WEAR_JUMP_LIMIT,
};
pub use solve::resident::{KernelCache, Resident};
