//! The files a run or a solve writes, and nothing else: tables, arrays,
//! figures. Above `config` and the foundations (`case`, `convergence`,
//! `float_text`), below `solve` and `run`, which call it and which it never
//! imports: a sweep's cases reach it as plain [`sweep::Row`]s.
//!
//! Its modules import only the ones listed before them (no circles;
//! `tests/tests/layers.rs` checks it from the sources):
//! `atomic` (every file whole or not at all) → `npy` (arrays) → `plot` (one
//! figure on PNG or SVG, frames, colours, the colour bar) → `maps` (field
//! maps of a case, [`maps::Heat`]) → `wear` (a worn path's table and
//! profiles) → `history` (a load history's table and loop) → `stress` (`[stress]` of a case: arrays and maps) → `sweep`
//! (`results.csv`, `curves.csv`, the μa figure, `fields/<case>/`) →
//! `fretting_map`, `orientation_map` (a sweep's maps over its axes).

pub mod atomic;
pub(crate) mod fretting_map;
pub mod history;
pub mod maps;
pub mod npy;
pub(crate) mod orientation_map;
pub mod plot;
pub mod stress;
pub(crate) mod sweep;
pub mod wear;
