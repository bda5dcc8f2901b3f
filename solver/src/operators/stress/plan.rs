//! The plan of one material on one grid (its response, transforms and
//! image memo), the kernel of a depth plane (18 spectra of the padded
//! grid), and the traction spectra of a state that planes and slices
//! are applied to.

use std::collections::HashMap;
use std::sync::Arc;

use super::images::Coarse;
use super::near::{NEAR_ALIASES, SPLIT_FLOOR};
use super::response::Response;
use super::{check_depth, signed_frequency, sinc, C};
use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::model::material::Material;
use crate::operators::fft2::Fft2;

/// The stress response of one material on one grid: what every depth
/// plane and line of it is built from. Build once per (material, grid).
pub struct StressPlan {
    pub(super) grid: Grid,
    pub(super) response: Response,
    pub(super) dc: [C; 18],
    pub(super) fft: Fft2,
    pub(super) coarse: Coarse,
    /// The image spectra computed so far, by depth (bits) and lattices
    /// summed (`StressPlan::image_levels`): they depend on
    /// the material, the grid and the depth only, so the cases of a sweep
    /// share them through the plan a worker keeps.
    pub(super) images: HashMap<(u64, usize), Arc<Vec<[C; 18]>>>,
}

/// The spectra of a state's tractions on the padded grid (three forward
/// transforms), shared by every depth and line computed from that state.
pub struct TractionSpectra {
    /// `q̂x, q̂y, p̂`, natural order, `[kx][ky]` (see [`crate::operators::fft2`]).
    pub(super) spectra: [Vec<C>; 3],
    /// The same on the coarse grid of the images ([`Coarse::spread`]).
    pub(super) coarse: [Vec<C>; 3],
    /// `qx, qy, p` themselves (the stresses on the surface plane).
    pub(super) fields: [Vec<f64>; 3],
}

/// The kernel spectra of one depth plane (18 half spectra of the padded
/// grid: `6 x 3` stress components per traction component) and of its
/// periodic images on the coarse grid, applied to many states.
/// `18 · 16 · 2n(n + 1)` bytes: 151 MB at `n = 512`.
pub struct StressPlane {
    pub(super) depth_m: f64,
    pub(super) kernel: Vec<[C; 18]>,
    /// The images `E` on the coarse grid's padded spectrum (shared with
    /// the plan's memo, [`StressPlan::images_at`]).
    pub(super) images: Arc<Vec<[C; 18]>>,
}

impl StressPlane {
    /// The depth of the plane, m.
    pub fn depth_m(&self) -> f64 {
        self.depth_m
    }

    /// The bytes of its kernel (18 complex values a frequency of the
    /// padded grid's half spectrum, 576 a cell; its images' few more).
    pub fn bytes(&self) -> f64 {
        (self.kernel.len() * std::mem::size_of::<[C; 18]>()) as f64
    }
}

impl StressPlan {
    /// The plan for `material` on `grid` (tabulates the Stroh matrices of
    /// an anisotropic material, plans the transforms).
    pub fn new(material: &Material, grid: Grid) -> Result<Self, SolverError> {
        material.validate()?;
        let response = Response::of(material)?;
        let dc = response.mean_at_zero();
        Ok(StressPlan {
            grid,
            response,
            dc,
            fft: Fft2::new(grid.n),
            coarse: Coarse::new(grid.n),
            images: HashMap::new(),
        })
    }

    /// The grid.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// Stress per unit traction `σ̂ = M t̂` (6x3, rows [`COMPONENTS`],
    /// columns `qx, qy, p`) of the continuous half-space at wave vector
    /// `η = (ex, ey)` (1/m, transform `∫∫ f e^{iη·x} dA`) and depth `z`
    /// (m). For tests and documentation of the response itself.
    pub fn response(&self, ex: f64, ey: f64, z: f64) -> [[C; 3]; 6] {
        let m = self.response.at(ex, ey, z);
        std::array::from_fn(|i| std::array::from_fn(|j| m[3 * i + j]))
    }

    /// The discrete kernel spectrum (18 values) at padded-grid frequency
    /// `(kx, ky)`: the response times the cell's transform, times the
    /// split's weight when `split` (a shallow plane: its aliases and the
    /// rest are in its near field).
    fn kernel_at(&self, kx: usize, ky: usize, z: f64, split: bool) -> [C; 18] {
        let m = 2 * self.grid.n;
        if kx == 0 && ky == 0 {
            return self.dc;
        }
        let signed = |k: usize| signed_frequency(k, m);
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        let tau = 2.0 * std::f64::consts::PI;
        // The DFT `Σ f e^{−2πi k x/M}` is the transform at η = −2πk/(MΔ).
        let ex = -tau * signed(kx) / (m as f64 * dx);
        let ey = -tau * signed(ky) / (m as f64 * dy);
        // (before the sines: most of a deep plane's frequencies)
        if z > 0.0 && self.response.decayed((ex * ex + ey * ey).sqrt() * z) {
            return [C::default(); 18];
        }
        let mut b = sinc(0.5 * ex * dx) * sinc(0.5 * ey * dy);
        if split {
            b *= self.split(ex, ey);
            if b.abs() < SPLIT_FLOOR {
                return [C::default(); 18];
            }
        }
        self.response.at(ex, ey, z).map(|v| v * b)
    }

    /// The kernel of the plane at depth `depth_m` (m, ≥ 0): the response
    /// on the padded grid's frequencies, less the periodic images of the
    /// padded grid (see `StressPlan::images`). Within
    /// `ALIAS_FREE_DEPTH_CELLS` of the surface the response is split
    /// ([`StressPlan::split`]): the smooth part on the padded grid's
    /// frequencies, the rest (with the aliases) as a short real-space
    /// stencil ([`StressPlan::near_field`]) added through its transform.
    pub fn plane(&mut self, depth_m: f64) -> Result<StressPlane, SolverError> {
        self.plane_with(depth_m, NEAR_ALIASES)
    }

    /// [`StressPlan::plane`] with at most `cap` alias orders in its near field.
    pub(super) fn plane_with(
        &mut self,
        depth_m: f64,
        cap: i64,
    ) -> Result<StressPlane, SolverError> {
        check_depth(depth_m, &self.grid)?;
        let n = self.grid.n;
        let m = 2 * n;
        let h = m / 2 + 1;
        let aliases = self.aliases(depth_m, cap);
        let split = aliases > 0;
        // (collected, not zeroed first and overwritten: the 38 MB of a
        // 256² kernel were written twice)
        let mut kernel: Vec<[C; 18]> = {
            use rayon::prelude::*;
            let this = &*self;
            (0..h * m)
                .into_par_iter()
                .map(|i| this.kernel_at(i / m, i % m, depth_m, split))
                .collect()
        };
        if split {
            let near = self.near_field(depth_m, aliases);
            self.add_near(&near, &mut kernel);
        }
        let image_spectra = self.images_at(depth_m, self.image_levels(depth_m));
        Ok(StressPlane {
            depth_m,
            kernel,
            images: image_spectra,
        })
    }

    /// The three traction spectra of a state (`p`, `qx`, `qy` row major on
    /// the grid, Pa).
    pub fn tractions(&mut self, p: &[f64], qx: &[f64], qy: &[f64]) -> TractionSpectra {
        let len = self.fft.spectrum_len();
        let spectra = [qx, qy, p].map(|f| {
            let mut s = vec![C::default(); len];
            self.fft.forward_padded(f, &mut s);
            s
        });
        let clen = self.coarse.fft.spectrum_len();
        let coarse = [qx, qy, p].map(|f| {
            let mut s = vec![C::default(); clen];
            let nodes = self.coarse.spread(f);
            self.coarse.fft.forward_padded(&nodes, &mut s);
            s
        });
        TractionSpectra {
            spectra,
            coarse,
            fields: [qx.to_vec(), qy.to_vec(), p.to_vec()],
        }
    }
}
