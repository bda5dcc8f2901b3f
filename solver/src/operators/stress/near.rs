//! A shallow plane's near field: the split of its response into a smooth
//! part sampled on the padded grid and the rest, with the aliases the grid
//! cannot resolve, as a short real-space stencil (within
//! `ALIAS_FREE_DEPTH_CELLS` of the surface).

use super::{signed_frequency, sinc, Line, StressPlan, C};

/// Depth (in cells, of the larger side) from which the aliases of the
/// response are dropped: beyond it they weigh `e^{−πz/Δ}`, below 2e-7.
pub(super) const ALIAS_FREE_DEPTH_CELLS: f64 = 5.0;

/// At depth `z` the alias orders beyond `NEAR_DECAY_CELLS Δ / z` weigh
/// below `e^{−2π NEAR_DECAY_CELLS}` = 6.5e-9 and are left out.
const NEAR_DECAY_CELLS: f64 = 3.0;

/// Most aliases summed per axis and side in a shallow plane's near field
/// (at the surface itself the series is truncated here).
pub(super) const NEAR_ALIASES: i64 = 16;

/// The split's radius in units of the grid's Nyquist wave numbers (see
/// [`StressPlan::split`]).
const SPLIT_RADIUS: f64 = 0.5;

/// The split's order: `w = exp(−(|u|/SPLIT_RADIUS)^(2 SPLIT_POWER))`.
const SPLIT_POWER: i32 = 3;

/// Below this weight a frequency's smooth part is left out (0 to round-off).
pub(super) const SPLIT_FLOOR: f64 = 1e-20;

/// Frequencies per axis of the coarse grid a near field is summed on (its
/// period in cells).
const NEAR_PERIOD: usize = 41;

/// Cells either side of the source a near field reaches.
pub(super) const NEAR_REACH: usize = 16;

/// A shallow plane's near field: real-space coefficients of the stress at
/// offset `o` from a cell of unit traction, on `[−NEAR_REACH, NEAR_REACH]²`.
pub(super) struct NearField {
    /// `[oy][ox]`, 18 values (rows [`COMPONENTS`], columns `qx, qy, p`).
    pub(super) values: Vec<[f64; 18]>,
}

impl NearField {
    pub(super) fn at(&self, ox: i64, oy: i64) -> &[f64; 18] {
        let r = NEAR_REACH as i64;
        let width = 2 * NEAR_REACH + 1;
        &self.values[(oy + r) as usize * width + (ox + r) as usize]
    }
}

impl StressPlan {
    /// The alias orders summed at depth `z` for the near field
    /// ([`StressPlan::near_field`]), at most `cap`; 0 from
    /// `ALIAS_FREE_DEPTH_CELLS` down, where the response is band-limited.
    pub(super) fn aliases(&self, z: f64, cap: i64) -> i64 {
        let d = self.grid.dx.max(self.grid.dy);
        if z >= ALIAS_FREE_DEPTH_CELLS * d {
            0
        } else if z <= 0.0 {
            cap
        } else {
            ((NEAR_DECAY_CELLS * d / z).ceil() as i64).min(cap)
        }
    }

    /// The weight `w` of the split of a shallow plane's response at wave
    /// vector `(ex, ey)`: `exp(−(|u|/SPLIT_RADIUS)^(2 SPLIT_POWER))`, `u`
    /// the wave vector in units of the grid's Nyquist numbers `π/Δ`. It is
    /// 1 to 1e-3 up to `|u| = 0.16` and below 1e-27 from `|u| = 1` on, so
    /// `wF` has no aliases; `1 − w` vanishes to sixth order at `η = 0`
    /// (where `F` is not smooth), so `(1 − w)F` is smooth and its stencil
    /// short (powers 8 and 4 left longer stencils at 0.3 to 4 cells deep).
    pub(super) fn split(&self, ex: f64, ey: f64) -> f64 {
        (-self.split_exponent(ex, ey)).exp()
    }

    /// `(|u|/SPLIT_RADIUS)^(2 SPLIT_POWER)`: `w = e^{−x}` and, without
    /// cancellation near `η = 0`, `1 − w = −expm1(−x)`.
    fn split_exponent(&self, ex: f64, ey: f64) -> f64 {
        let ux = ex * self.grid.dx / std::f64::consts::PI;
        let uy = ey * self.grid.dy / std::f64::consts::PI;
        ((ux * ux + uy * uy) / (SPLIT_RADIUS * SPLIT_RADIUS)).powi(SPLIT_POWER)
    }

    /// `(1 − w)F` at depth `z` summed over `aliases` orders (the last
    /// counted half) on the near field's coarse frequencies, `[ky][kx]`.
    fn near_spectrum(&self, z: f64, aliases: i64) -> Vec<[C; 18]> {
        use rayon::prelude::*;
        let mc = NEAR_PERIOD;
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        let tau = std::f64::consts::TAU;
        let end = |j: i64| {
            if aliases > 0 && j.abs() == aliases {
                0.5
            } else {
                1.0
            }
        };
        // The real kernel's spectrum is Hermitian: the rows ky ≤ mc/2 are
        // summed, the others are their conjugates.
        let rows = mc / 2 + 1;
        let mut spec: Vec<[C; 18]> = (0..rows * mc)
            .into_par_iter()
            .map(|i| {
                let (ky, kx) = (i / mc, i % mc);
                let ex0 = -tau * signed_frequency(kx, mc) / (mc as f64 * dx);
                let ey0 = -tau * signed_frequency(ky, mc) / (mc as f64 * dy);
                // (the x factors once, not per y order)
                let along_x: Vec<(f64, f64)> = (-aliases..=aliases)
                    .map(|jx| {
                        let ex = ex0 + tau * jx as f64 / dx;
                        (ex, sinc(0.5 * ex * dx) * end(jx))
                    })
                    .collect();
                let mut acc = [C::default(); 18];
                for jy in -aliases..=aliases {
                    let ey = ey0 + tau * jy as f64 / dy;
                    let by = sinc(0.5 * ey * dy) * end(jy);
                    for &(ex, bx) in &along_x {
                        // 1 − w
                        let b = bx * by * -(-self.split_exponent(ex, ey)).exp_m1();
                        if b == 0.0 {
                            continue;
                        }
                        for (a, v) in acc.iter_mut().zip(self.response.at(ex, ey, z)) {
                            *a += v * b;
                        }
                    }
                }
                acc
            })
            .collect();
        spec.resize(mc * mc, [C::default(); 18]);
        for ky in rows..mc {
            for kx in 0..mc {
                let mirror = ((mc - ky) % mc) * mc + (mc - kx) % mc;
                spec[ky * mc + kx] = spec[mirror].map(|v| v.conj());
            }
        }
        spec
    }

    /// The near field of a shallow plane at depth `z`: the kernel's part
    /// the split leaves out, `(1 − w)F` summed over `aliases` orders (the
    /// last counted half: the series of the odd parts alternate with terms
    /// ~1/j at the surface, and the mean of two partial sums leaves ~1/J²),
    /// as real-space coefficients on the cells within `NEAR_REACH` of the
    /// source. `(1 − w)F` is smooth, so its coefficients decay fast and are
    /// found from a coarse grid of `NEAR_PERIOD` frequencies per axis
    /// (its period is `NEAR_PERIOD` cells, odd so that the stencil keeps
    /// the load's symmetries; the stencil's outer ring is below 5e-6 of
    /// the surface stencil's largest coefficient at every depth,
    /// `the_surface_near_field_converges_in_its_aliases`).
    pub(super) fn near_field(&self, z: f64, aliases: i64) -> NearField {
        let mc = NEAR_PERIOD;
        let spec = if z == 0.0 {
            // The surface's series converges as c₁/J + c₂/J² + …:
            // Richardson twice, (8 S_J − 6 S_{J/2} + S_{J/4})/3 (the change
            // from J = 16 to 32 falls from 8e-4 p0 to 2e-5,
            // `the_surface_near_field_converges_in_its_aliases`).
            let [quarter, half, full] =
                [aliases / 4, aliases / 2, aliases].map(|j| self.near_spectrum(z, j));
            (0..full.len())
                .map(|i| {
                    std::array::from_fn(|c| {
                        (8.0 * full[i][c] - 6.0 * half[i][c] + quarter[i][c]) / 3.0
                    })
                })
                .collect()
        } else {
            self.near_spectrum(z, aliases)
        };
        let tau = std::f64::consts::TAU;
        // C(o) = (1/mc²) Re Σ_k S_k e^{2πi k·o/mc}, o in [−L, L]², by axes.
        let reach = NEAR_REACH as i64;
        let width = 2 * NEAR_REACH + 1;
        let phase = |k: usize, o: i64| {
            C::from_polar(
                1.0,
                tau * ((k as i64 * o).rem_euclid(mc as i64)) as f64 / mc as f64,
            )
        };
        let mut along_x = vec![[C::default(); 18]; mc * width];
        for ky in 0..mc {
            for (ox, row) in (-reach..=reach).zip(along_x[ky * width..].iter_mut()) {
                for kx in 0..mc {
                    let ph = phase(kx, ox);
                    for (a, v) in row.iter_mut().zip(&spec[ky * mc + kx]) {
                        *a += v * ph;
                    }
                }
            }
        }
        let scale = 1.0 / (mc * mc) as f64;
        let mut values = vec![[0.0; 18]; width * width];
        for (oy, out) in (-reach..=reach).zip(values.chunks_mut(width)) {
            for (ox, v) in out.iter_mut().enumerate() {
                let mut acc = [C::default(); 18];
                for ky in 0..mc {
                    let ph = phase(ky, oy);
                    for (a, s) in acc.iter_mut().zip(&along_x[ky * width + ox]) {
                        *a += s * ph;
                    }
                }
                *v = acc.map(|a| a.re * scale);
            }
        }
        NearField { values }
    }

    /// Adds the transform of the stencil `near` to a plane's kernel
    /// (`K_k += Σ_o C(o) e^{−2πi k·o/M}`, 18 transforms of the padded grid).
    pub(super) fn add_near(&mut self, near: &NearField, kernel: &mut [[C; 18]]) {
        let m = 2 * self.grid.n;
        let reach = NEAR_REACH as i64;
        let mut real = vec![0.0; m * m];
        let mut spec = vec![C::default(); self.fft.spectrum_len()];
        let wrap = |o: i64| o.rem_euclid(m as i64) as usize;
        for c in 0..18 {
            for oy in -reach..=reach {
                for ox in -reach..=reach {
                    real[wrap(oy) * m + wrap(ox)] = near.at(ox, oy)[c];
                }
            }
            self.fft.forward_full(&real, &mut spec);
            for (k, s) in kernel.iter_mut().zip(&spec) {
                k[c] += s;
            }
        }
    }

    /// The near field `near` applied along `line` to the traction fields
    /// `[qx, qy, p]` (a real-space sum over the stencil: `σ(x) = Σ_o C(o)
    /// t(x − o)`), added to `components`.
    pub(super) fn add_near_line(
        &self,
        near: &NearField,
        fields: &[Vec<f64>; 3],
        line: Line,
        components: &mut [Vec<f64>; 6],
    ) {
        let n = self.grid.n as i64;
        let reach = NEAR_REACH as i64;
        for i in 0..n {
            let (ix, iy) = match line {
                Line::Row(iy) => (i, iy as i64),
                Line::Column(ix) => (ix as i64, i),
            };
            let mut acc = [0.0; 6];
            for oy in -reach..=reach {
                let sy = iy - oy;
                if sy < 0 || sy >= n {
                    continue;
                }
                for ox in -reach..=reach {
                    let sx = ix - ox;
                    if sx < 0 || sx >= n {
                        continue;
                    }
                    let s = (sy * n + sx) as usize;
                    let t = [fields[0][s], fields[1][s], fields[2][s]];
                    if t == [0.0; 3] {
                        continue;
                    }
                    let v = near.at(ox, oy);
                    for (c, a) in acc.iter_mut().enumerate() {
                        *a += v[3 * c] * t[0] + v[3 * c + 1] * t[1] + v[3 * c + 2] * t[2];
                    }
                }
            }
            for (comp, a) in components.iter_mut().zip(acc) {
                comp[i as usize] += a;
            }
        }
    }
}
