//! Planes and slices: a plane's kernel applied to a state's tractions
//! (the whole plane, or one line of it), and a slice's rows at many
//! depths summed straight into their lines without planes.

use rustfft::FftPlanner;
use std::sync::Arc;

use super::near::{NearField, NEAR_ALIASES};
use super::response::{divided, divided_with, Node, DECAY_LIMIT};
use super::{
    check_depth, signed_frequency, sinc, Line, StressField, StressPlan, StressPlane,
    TractionSpectra, C,
};
use crate::error::SolverError;

/// Chunks of frequencies [`StressPlan::slice`] sums its partial transforms
/// in, each holding its own (a fixed number: the sums do not depend on the
/// threads).
const SLICE_CHUNKS: usize = 8;

/// Bytes of [`StressPlan::slice`]'s partial transforms for each state, on
/// an `n x n` grid with `rows` depths along `lines` lines: every chunk's
/// six components per row, line and frequency along it (2n). 3.9 MB a state
/// at 32² with 40 rows and two lines, 31 MB at 256² (a fretting history's
/// 2002 turning states at 32² took 8.7 GB in one call, issue #59), so
/// [`StressPlan::slice`] takes the states in batches of
/// [`SLICE_BATCH_BYTES`].
pub fn slice_state_bytes(n: usize, rows: usize, lines: usize) -> usize {
    SLICE_CHUNKS * lines * rows * 2 * n * std::mem::size_of::<[C; 6]>()
}

/// Most bytes of a slice's partial transforms held at once: 16 states a
/// batch at 32² (40 rows), 2 at 256², one at 512² and beyond. (Batches
/// of states computed apart cost the rows' frequency sweep each; the near
/// fields and images are made once a slice.)
pub const SLICE_BATCH_BYTES: usize = 64 << 20;

impl StressPlan {
    /// The stress on `plane` under `t` (18 spectral products, 6 inverse transforms).
    pub fn apply(&mut self, plane: &StressPlane, t: &TractionSpectra) -> StressField {
        let n = self.grid.n;
        let len = self.fft.spectrum_len();
        let mut spec = vec![C::default(); len];
        let components = std::array::from_fn(|c| {
            for (i, s) in spec.iter_mut().enumerate() {
                let k = &plane.kernel[i];
                *s = k[3 * c] * t.spectra[0][i]
                    + k[3 * c + 1] * t.spectra[1][i]
                    + k[3 * c + 2] * t.spectra[2][i];
            }
            let mut out = vec![0.0; n * n];
            self.fft.inverse_cropped(&mut spec, &mut out);
            out
        });
        let images = self.image_stresses(plane, t);
        let mut components: [Vec<f64>; 6] = components;
        for (out, g) in components.iter_mut().zip(&images) {
            for iy in 0..n {
                for ix in 0..n {
                    out[iy * n + ix] -= self.coarse.at(g, ix, iy);
                }
            }
        }
        let mut field = StressField {
            depth_m: plane.depth_m,
            components,
        };
        if plane.depth_m == 0.0 {
            surface_tractions_exact(&mut field, t);
        }
        field
    }

    /// The stress along one line of `plane` under `t`: the products and a
    /// partial inverse transform (a row of an x–z slice, a column of a y–z
    /// slice), without the full plane.
    pub fn apply_line(
        &mut self,
        plane: &StressPlane,
        t: &TractionSpectra,
        line: Line,
    ) -> StressField {
        let n = self.grid.n;
        let m = 2 * n;
        let h = m / 2 + 1;
        let tau = 2.0 * std::f64::consts::PI;
        // f(x, y) = (1/M²) Re Σ_{kx ≤ M/2} c_kx Σ_ky F e^{2πi(kx x + ky y)/M},
        // c = 1 at kx = 0 and M/2, 2 elsewhere.
        let weight = |kx: usize| if kx == 0 || kx == m / 2 { 1.0 } else { 2.0 };
        let product = |i: usize| -> [C; 6] {
            let k = &plane.kernel[i];
            std::array::from_fn(|c| {
                k[3 * c] * t.spectra[0][i]
                    + k[3 * c + 1] * t.spectra[1][i]
                    + k[3 * c + 2] * t.spectra[2][i]
            })
        };
        let mut sums = vec![[C::default(); 6]; m];
        match line {
            Line::Row(iy) => {
                // (the phases of a row once, not per frequency)
                let phases: Vec<C> = (0..m)
                    .map(|ky| C::from_polar(1.0, tau * (ky * iy % m) as f64 / m as f64))
                    .collect();
                for (kx, g) in sums.iter_mut().enumerate().take(h) {
                    for (ky, ph) in phases.iter().enumerate() {
                        let ph = ph * weight(kx);
                        for (a, v) in g.iter_mut().zip(product(kx * m + ky)) {
                            *a += v * ph;
                        }
                    }
                }
            }
            Line::Column(ix) => {
                for kx in 0..h {
                    let ph = C::from_polar(weight(kx), tau * (kx * ix % m) as f64 / m as f64);
                    for (ky, g) in sums.iter_mut().enumerate() {
                        for (a, v) in g.iter_mut().zip(product(kx * m + ky)) {
                            *a += v * ph;
                        }
                    }
                }
            }
        }
        let fft = FftPlanner::<f64>::new().plan_fft_inverse(m);
        let images = self.image_stresses(plane, t);
        let coarse = &self.coarse;
        let components = std::array::from_fn(|c| {
            let mut buf: Vec<C> = sums.iter().map(|g| g[c]).collect();
            fft.process(&mut buf);
            buf[..n]
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let e = match line {
                        Line::Row(iy) => coarse.at(&images[c], i, iy),
                        Line::Column(ix) => coarse.at(&images[c], ix, i),
                    };
                    v.re / (m * m) as f64 - e
                })
                .collect()
        });
        let mut field = StressField {
            depth_m: plane.depth_m,
            components,
        };
        if plane.depth_m == 0.0 {
            surface_tractions_on_line(&mut field, t, line, n);
        }
        field
    }

    /// The rows of slices at depths `depths_m` along `lines`, for every
    /// state of `states`: `[state][line][depth]`. No plane is built: each
    /// frequency's response is evaluated once for all depths (for an
    /// isotropic body `e^{−s}(A − isB)` with `A`, `B` shared by the depths)
    /// and its products with the tractions summed straight into the
    /// lines' partial transforms; a row within `ALIAS_FREE_DEPTH_CELLS` of
    /// the surface takes the split's smooth part there and adds its near
    /// field in real space along the line; the periodic images are
    /// subtracted as for a plane. The same numbers as
    /// [`StressPlan::plane`] and [`StressPlan::apply_line`] to round-off.
    pub fn slice(
        &mut self,
        depths_m: &[f64],
        states: &[TractionSpectra],
        lines: &[Line],
    ) -> Result<Vec<Vec<Vec<StressField>>>, SolverError> {
        for &z in depths_m {
            check_depth(z, &self.grid)?;
        }
        // Per row: its near field when it is shallow, and its images.
        let near: Vec<Option<NearField>> = depths_m
            .iter()
            .map(|&z| {
                let aliases = self.aliases(z, NEAR_ALIASES);
                (aliases > 0).then(|| self.near_field(z, aliases))
            })
            .collect();
        let images = self.row_images(depths_m);
        // The states in batches: the partial transforms of a batch are
        // held at once, and each state's rows are the same bits in any.
        let each = slice_state_bytes(self.grid.n, depths_m.len(), lines.len());
        let batch = (SLICE_BATCH_BYTES / each.max(1)).max(1);
        let mut out = Vec::with_capacity(states.len());
        for chunk in states.chunks(batch) {
            out.extend(self.slice_batch(depths_m, chunk, lines, &near, &images));
        }
        Ok(out)
    }

    /// [`StressPlan::slice`] of one batch of `states`, with each row's
    /// near field and image spectra.
    fn slice_batch(
        &mut self,
        depths_m: &[f64],
        states: &[TractionSpectra],
        lines: &[Line],
        near: &[Option<NearField>],
        row_images: &[Arc<Vec<[C; 18]>>],
    ) -> Vec<Vec<Vec<StressField>>> {
        let any_split = near.iter().any(Option::is_some);
        let n = self.grid.n;
        let m = 2 * n;
        let h = m / 2 + 1;
        let (rows, ns, nl) = (depths_m.len(), states.len(), lines.len());
        let tau = std::f64::consts::TAU;
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        let signed = |k: usize| signed_frequency(k, m);
        let weight = |kx: usize| if kx == 0 || kx == m / 2 { 1.0 } else { 2.0 };
        // Per line: the phase of each frequency along the other axis.
        let phases: Vec<Vec<C>> = lines
            .iter()
            .map(|line| {
                let at = match *line {
                    Line::Row(iy) => iy,
                    Line::Column(ix) => ix,
                };
                (0..m)
                    .map(|k| C::from_polar(1.0, tau * (k * at % m) as f64 / m as f64))
                    .collect()
            })
            .collect();
        // Partial transforms `[state][line][row][k][component]`, k the
        // frequency along the line; chunks of kx in a fixed number (the
        // sums do not depend on the threads) summed in order.
        let size = h.div_ceil(SLICE_CHUNKS);
        let at = |s: usize, l: usize, r: usize, k: usize| ((s * nl + l) * rows + r) * m + k;
        let this = &*self;
        let iso = self.response.isotropic;
        // Evenly spaced depths (a slice's): each root's exponential steps
        // from one depth to the next by one product instead of an
        // exponential (three a node and depth: most of a crystal's slice).
        let step = match depths_m {
            [first, second, ..] => {
                let dz = second - first;
                let even = depths_m.iter().enumerate().all(|(r, &z)| {
                    (z - (first + r as f64 * dz)).abs() <= 1e-12 * depths_m[rows - 1]
                });
                even.then_some(dz)
            }
            _ => None,
        };
        let partial = |chunk: usize| -> Vec<[C; 6]> {
            let mut sums = vec![[C::default(); 6]; ns * nl * rows * m];
            // Per state, node and matrix `Q_k`: `Q_k t̂` (6 values), formed
            // once per frequency and combined per depth with Putzer's
            // coefficients (for an isotropic body the nodes summed first).
            let mut qt = vec![[[[C::default(); 6]; 3]; 4]; ns];
            let mut prods = vec![[C::default(); 6]; ns];
            for kx in chunk * size..((chunk + 1) * size).min(h) {
                let ex = -tau * signed(kx) / (m as f64 * dx);
                let bx = sinc(0.5 * ex * dx);
                for ky in 0..m {
                    let i = kx * m + ky;
                    let tr =
                        |t: &TractionSpectra| [t.spectra[0][i], t.spectra[1][i], t.spectra[2][i]];
                    let mut add = |r: usize, prods: &[[C; 6]]| {
                        for (s, prod) in prods.iter().enumerate() {
                            for (l, line) in lines.iter().enumerate() {
                                let (slot, ph) = match line {
                                    Line::Row(_) => (kx, phases[l][ky] * weight(kx)),
                                    Line::Column(_) => (ky, phases[l][kx] * weight(kx)),
                                };
                                let acc = &mut sums[at(s, l, r, slot)];
                                for (a, v) in acc.iter_mut().zip(prod) {
                                    *a += v * ph;
                                }
                            }
                        }
                    };
                    if kx == 0 && ky == 0 {
                        for (p, t) in prods.iter_mut().zip(states) {
                            let t = tr(t);
                            *p = std::array::from_fn(|c| {
                                (0..3).map(|j| this.dc[3 * c + j] * t[j]).sum()
                            });
                        }
                        for r in 0..rows {
                            add(r, &prods);
                        }
                        continue;
                    }
                    let ey = -tau * signed(ky) / (m as f64 * dy);
                    let b = bx * sinc(0.5 * ey * dy);
                    let w = if any_split { this.split(ex, ey) } else { 1.0 };
                    let rho = (ex * ex + ey * ey).sqrt();
                    let nodes = this.response.nodes(ey.atan2(ex));
                    // The depth from which this direction has decayed.
                    let decay = this.response.decay(&nodes);
                    // A crystal's smooth stencil: one interpolated node.
                    let interp = if iso {
                        None
                    } else {
                        this.response.interpolated(&nodes)
                    };
                    let (count, refs, wts): (usize, [&Node; 4], [f64; 4]) = match &interp {
                        Some(node) => (1, [node; 4], [1.0, 0.0, 0.0, 0.0]),
                        None => (
                            4,
                            nodes.map(|(i, _)| &this.response.nodes[i]),
                            nodes.map(|(_, w)| w),
                        ),
                    };
                    let kinds = if iso { 2 } else { 3 };
                    for (q, t) in qt.iter_mut().zip(states) {
                        let t = tr(t);
                        for j in 0..count {
                            let (node, w) = (refs[j], wts[j]);
                            for (qk, mk) in q[j].iter_mut().zip(&node.q).take(kinds) {
                                *qk = std::array::from_fn(|c| {
                                    (mk[3 * c] * t[0] + mk[3 * c + 1] * t[1] + mk[3 * c + 2] * t[2])
                                        * (w * b)
                                });
                            }
                        }
                    }
                    if iso {
                        // One set of coefficients for the four nodes: sum them now.
                        for q in qt.iter_mut() {
                            let (first, rest) = q.split_at_mut(1);
                            for other in rest.iter() {
                                for (a, b) in first[0].iter_mut().zip(other).take(2) {
                                    for (x, y) in a.iter_mut().zip(b) {
                                        *x += y;
                                    }
                                }
                            }
                        }
                    }
                    let mut exps = [[C::default(); 3]; 4];
                    let mut steps = [[C::default(); 3]; 4];
                    if let (Some(dz), false) = (step, iso) {
                        let (x0, dx1) = (C::new(0.0, -rho * depths_m[0]), C::new(0.0, -rho * dz));
                        for j in 0..count {
                            let lam = &refs[j].lam;
                            exps[j] = lam.map(|l| (x0 * l).exp());
                            steps[j] = lam.map(|l| (dx1 * l).exp());
                        }
                    }
                    for (r, &z) in depths_m.iter().enumerate() {
                        let s = rho * z;
                        if r > 0 && step.is_some() && !iso {
                            for e in exps.iter_mut().take(count).zip(&steps) {
                                for (a, b) in e.0.iter_mut().zip(e.1) {
                                    *a *= b;
                                }
                            }
                        }
                        if decay * s > DECAY_LIMIT {
                            continue;
                        }
                        let mut gs = [[C::default(); 3]; 4];
                        if !iso {
                            for j in 0..count {
                                gs[j] = match step {
                                    Some(_) => divided_with(s, refs[j], &exps[j]),
                                    None => divided(s, refs[j]),
                                };
                            }
                        }
                        for (p, q) in prods.iter_mut().zip(&qt) {
                            *p = [C::default(); 6];
                            if iso {
                                // e^{−s} (A − isB) t̂
                                let (g0, g1) = ((-s).exp(), -s * (-s).exp());
                                for (c, v) in p.iter_mut().enumerate() {
                                    let (a0, a1) = (q[0][0][c], q[0][1][c]);
                                    *v = C::new(a0.re * g0 - a1.im * g1, a0.im * g0 + a1.re * g1);
                                }
                            } else {
                                for (j, g) in gs.iter().enumerate().take(count) {
                                    for (c, v) in p.iter_mut().enumerate() {
                                        *v += g[0] * q[j][0][c]
                                            + g[1] * q[j][1][c]
                                            + g[2] * q[j][2][c];
                                    }
                                }
                            }
                        }
                        if near[r].is_some() {
                            // (the smooth part of a shallow row)
                            for p in prods.iter_mut() {
                                for v in p.iter_mut() {
                                    *v *= w;
                                }
                            }
                        }
                        add(r, &prods);
                    }
                }
            }
            sums
        };
        let parts: Vec<Vec<[C; 6]>> = {
            use rayon::prelude::*;
            (0..SLICE_CHUNKS).into_par_iter().map(partial).collect()
        };
        let mut sums = vec![[C::default(); 6]; ns * nl * rows * m];
        for part in &parts {
            for (a, p) in sums.iter_mut().zip(part) {
                for (x, y) in a.iter_mut().zip(p) {
                    *x += y;
                }
            }
        }
        drop(parts);
        let fft = FftPlanner::<f64>::new().plan_fft_inverse(m);
        let mut out: Vec<Vec<Vec<StressField>>> = (0..ns)
            .map(|_| (0..nl).map(|_| Vec::with_capacity(rows)).collect())
            .collect();
        for (r, &z) in depths_m.iter().enumerate() {
            let images = StressPlane {
                depth_m: z,
                kernel: Vec::new(),
                images: row_images[r].clone(),
            };
            for (s, t) in states.iter().enumerate() {
                let e = self.image_stresses(&images, t);
                for (l, line) in lines.iter().enumerate() {
                    let coarse = &self.coarse;
                    let components = std::array::from_fn(|c| {
                        let mut buf: Vec<C> = (0..m).map(|k| sums[at(s, l, r, k)][c]).collect();
                        fft.process(&mut buf);
                        buf[..n]
                            .iter()
                            .enumerate()
                            .map(|(i, v)| {
                                let img = match *line {
                                    Line::Row(iy) => coarse.at(&e[c], i, iy),
                                    Line::Column(ix) => coarse.at(&e[c], ix, i),
                                };
                                v.re / (m * m) as f64 - img
                            })
                            .collect()
                    });
                    let mut field = StressField {
                        depth_m: z,
                        components,
                    };
                    if let Some(near) = &near[r] {
                        self.add_near_line(near, &t.fields, *line, &mut field.components);
                    }
                    if z == 0.0 {
                        surface_tractions_on_line(&mut field, t, *line, n);
                    }
                    out[s][l].push(field);
                }
            }
        }
        out
    }

    /// The image spectra of each row of a slice at `depths_m`.
    fn row_images(&mut self, depths_m: &[f64]) -> Vec<Arc<Vec<[C; 18]>>> {
        let rows = depths_m.len();
        let m = 2 * self.grid.n;
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        // The images vary slowly in z too (the nearest is T/2 away, T the
        // padded period): for many rows they are interpolated between
        // anchor depths on the lattice k T/32 (4-point Lagrange in z; T/16
        // apart left 2.1e-6 p0 on a Hertz slice, 64², against each row's
        // own), which the plan keeps for the next case's rows; their own
        // lattice sums cost more than a row's products otherwise.
        let (lo, hi) = depths_m
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &z| (a.min(z), b.max(z)));
        let period = (m as f64 * dx).max(m as f64 * dy);
        let da = period / 32.0;
        let first_anchor = ((lo / da).floor() as i64 - 1).max(0);
        let last_anchor = ((hi / da).ceil() as i64 + 1).max(first_anchor + 3);
        let anchors = (last_anchor - first_anchor + 1) as usize;
        // (every anchor with the lattices of the deepest: the images are
        // then smooth in z between anchors)
        let levels = self.image_levels(last_anchor as f64 * da);
        let anchored: Option<Vec<Arc<Vec<[C; 18]>>>> = (anchors < rows).then(|| {
            (first_anchor..=last_anchor)
                .map(|k| self.images_at(k as f64 * da, levels))
                .collect()
        });
        depths_m
            .iter()
            .map(|&z| match &anchored {
                // (not kept: a case's rows sit at depths of its own)
                None => Arc::new(self.image_spectra(z, self.image_levels(z))),
                Some(spectra) => {
                    let u = z / da - first_anchor as f64;
                    let first = (u.floor() as i64 - 1).clamp(0, anchors as i64 - 4) as usize;
                    // Lagrange weights on anchors first..first + 4.
                    let w: [f64; 4] = std::array::from_fn(|j| {
                        (0..4)
                            .filter(|&k| k != j)
                            .map(|k| (u - (first + k) as f64) / (j as f64 - k as f64))
                            .product()
                    });
                    let mut out = vec![[C::default(); 18]; spectra[0].len()];
                    for (j, wj) in w.iter().enumerate() {
                        for (o, v) in out.iter_mut().zip(spectra[first + j].iter()) {
                            for (a, b) in o.iter_mut().zip(v) {
                                *a += b * wj;
                            }
                        }
                    }
                    Arc::new(out)
                }
            })
            .collect()
    }
}

/// At the surface the stresses on the plane `z = 0` are the tractions
/// themselves: `σzz = −p`, `σxz = −qx`, `σyz = −qy` in each cell (z into
/// the body; the traction on the body is `−σ·e_z`). The transform of the
/// cell's step would converge to them only slowly.
fn surface_tractions_exact(field: &mut StressField, t: &TractionSpectra) {
    let [qx, qy, p] = &t.fields;
    for i in 0..field.len() {
        field.components[2][i] = -p[i];
        field.components[3][i] = -qy[i];
        field.components[4][i] = -qx[i];
    }
}

/// [`surface_tractions_exact`] along `line` of an `n x n` grid.
fn surface_tractions_on_line(field: &mut StressField, t: &TractionSpectra, line: Line, n: usize) {
    let [qx, qy, p] = &t.fields;
    let pick = |f: &[f64], i: usize| match line {
        Line::Row(iy) => f[iy * n + i],
        Line::Column(ix) => f[i * n + ix],
    };
    for i in 0..n {
        field.components[2][i] = -pick(p, i);
        field.components[3][i] = -pick(qy, i);
        field.components[4][i] = -pick(qx, i);
    }
}
