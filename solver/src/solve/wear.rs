//! Wear along a load path (PHYSICS.md §5d): the worn depths of the
//! substrate and of the ball, each in its own frame (the grid is the
//! ball's: its apex stays at the centre, while the substrate's surface
//! point under a cell moves by its slip δt − u, zero in the stick zone),
//! the increment's wear taken explicitly or, with a cycle jump,
//! implicitly in the pressure (a compliant layer on the normal solve), and
//! the record of every simulated cycle. `history` drives it; it knows
//! no solver.

use serde::{Deserialize, Serialize};

use crate::base::geometry::covered_area;
use crate::base::grid::Grid;
use crate::model::radii::zone_radius;
use crate::model::spec::Wear;
use crate::model::surface::Terrain;

/// The largest depth one simulated cycle may wear, with its jump, as a
/// fraction of the approach of the path's start, before
/// `HistoryOutput::wear_jump_ratio` flags the jump. The error of a jump
/// is first order in it; the MDR reference (bench/references) measured ~5 %
/// on a worn partial-slip profile's transient at 1.5 % of the approach per
/// cycle, and half that at half the jump.
pub const WEAR_JUMP_LIMIT: f64 = 0.02;

/// How a wear scar is delimited.
pub const SCAR_DEFINITION: &str = "the cells worn deeper than 1 % of the largest worn depth; its area is their covered area, its extent along x (y) the distance between the outer edges of its outermost cells";

/// Fraction of the largest worn depth that delimits the scar ([`SCAR_DEFINITION`]).
const SCAR_FRACTION: f64 = 0.01;

/// One simulated full cycle of a path with a wear law: the wear so far
/// and the cycle's loop.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WearCycle {
    /// Simulated full cycles so far (1 for the first).
    pub cycle: usize,
    /// Physical cycles so far (`cycle` × the jump).
    pub physical_cycles: f64,
    /// Worn volume from the start of the path, m³.
    pub worn_volume_m3: f64,
    /// Volume worn per physical cycle over this simulated one, m³.
    pub worn_volume_per_cycle_m3: f64,
    /// Largest worn depth, m.
    pub depth_max_m: f64,
    /// Where it is (the cell's centre, x and y from the grid's centre), m.
    pub depth_max_at_m: [f64; 2],
    /// Largest depth worn over this simulated cycle (with its jump), m.
    pub depth_increment_max_m: f64,
    /// Area of the scar ([`SCAR_DEFINITION`]), m².
    pub scar_area_m2: f64,
    /// Extent of the scar along x and y, m.
    pub scar_extent_m: [f64; 2],
    /// The contact zone's own radius at the cycle's end ([`crate::ZONE_RADIUS_DEFINITION`]), m.
    pub contact_radius_m: f64,
    /// Smallest stick zone radius over the cycle (the rows'), m (0 in gross slip).
    pub stick_radius_m: f64,
    /// Force amplitude F* of the cycle, N.
    pub force_amplitude_n: f64,
    /// Shift amplitude δ* of the cycle, m.
    pub shift_amplitude_m: f64,
    /// Energy dissipated over the cycle, J.
    pub dissipated_j: f64,
    /// `partial` or `gross` (`SLIP_REGIME_DEFINITION`).
    pub regime: String,
    /// Cells of a pattern's islands worn deeper than the island stands
    /// above the base (worn through: the pattern, and a cut cell's load on
    /// its upper part, no longer describe them); 0 on a flat surface.
    pub worn_through_cells: usize,
    /// The ball's worn volume from the start of the path, m³ (0 when it
    /// does not wear).
    pub ball_worn_volume_m3: f64,
    /// The ball's largest worn depth, m.
    pub ball_depth_max_m: f64,
    /// The worn depth along x through the contact's centre (the row
    /// through it, the mean of the two next to it on an even grid; point i
    /// at the grid's x(i)), m; only on saved cycles (`Wear::save_every` and
    /// the last), else empty.
    pub profile_x_m: Vec<f64>,
    /// The same along y.
    pub profile_y_m: Vec<f64>,
}

/// What a full cycle's rows say.
pub(crate) struct CycleRows {
    /// Energy dissipated over it, J.
    pub dissipated: f64,
    /// The largest |F| and |δt| along the force direction, N and m.
    pub force_amplitude: f64,
    pub shift_amplitude: f64,
    /// At some increment no contact cell sticks.
    pub gross: bool,
    /// The smallest apparent stick radius over it, m.
    pub stick_radius_min: f64,
    /// The worn volume at its start and its end, m³.
    pub worn_volume: (f64, f64),
}

/// The wear of a path as it goes.
pub(crate) struct Wearing {
    wear: Wear,
    grid: Grid,
    /// The cycle jump of the current segment: the wear's own within the
    /// full cycles, 1 on the first loading (which happens once).
    jump_now: f64,
    /// The substrate's worn depth in its own frame (the grid's cells at
    /// the path's start; the point under cell x after a slip s = δt − u
    /// there is the one at x + s), m.
    pub worn: Vec<f64>,
    /// The ball's worn depth per cell of the grid (the ball's frame), m;
    /// empty when the ball does not wear.
    pub ball: Vec<f64>,
    /// The increment's worn depth per cell (with a jump, per Pa), substrate
    /// and ball.
    dh: Vec<f64>,
    dh_ball: Vec<f64>,
    /// With a jump: the layer's compliance, m/Pa.
    layer: Vec<f64>,
    /// The worn volumes so far, m³.
    pub volume: f64,
    pub ball_volume: f64,
    /// The substrate's worn depth at the current cycle's start.
    start: Vec<f64>,
    /// The simulated cycles' records.
    pub cycles: Vec<WearCycle>,
    /// The substrate's worn depth at the saved cycles (their numbers).
    pub saved: Vec<(usize, Vec<f64>)>,
}

impl Wearing {
    /// Nothing worn yet, on `grid`.
    pub fn new(wear: Wear, grid: Grid) -> Self {
        let len = grid.len();
        let ball_len = if wear.ball.is_some() { len } else { 0 };
        Wearing {
            wear,
            grid,
            jump_now: 1.0,
            worn: vec![0.0; len],
            ball: vec![0.0; ball_len],
            dh: vec![0.0; len],
            dh_ball: vec![0.0; ball_len],
            layer: Vec::new(),
            volume: 0.0,
            ball_volume: 0.0,
            start: vec![0.0; len],
            cycles: Vec::new(),
            saved: Vec::new(),
        }
    }

    /// The path's wear settings.
    pub fn settings(&self) -> Wear {
        self.wear
    }

    /// Forgets the last increment's depths (a cell out of contact over the
    /// whole increment wears nothing and is not visited).
    pub fn clear_increment(&mut self) {
        self.dh.iter_mut().for_each(|d| *d = 0.0);
        self.dh_ball.iter_mut().for_each(|d| *d = 0.0);
    }

    /// Cell `i`'s wear over an increment: the pressure `p` and tractions
    /// `q` its dissipation is taken at (the end's, by the implicit law of
    /// PHYSICS.md §5b), slip increment `ds`.
    pub fn wear_cell(&mut self, i: usize, p: f64, q: [f64; 2], ds: [f64; 2]) {
        let depth = |law: crate::model::spec::WearLaw| {
            if p > 0.0 {
                law.depth(p, q, ds)
            } else {
                0.0
            }
        };
        self.dh[i] = depth(self.wear.law);
        if let Some(ball) = self.wear.ball {
            self.dh_ball[i] = depth(ball);
        }
    }

    /// The segments that follow are part of the full cycles (`true`: their
    /// wear is applied the cycle jump's times) or come before them (the
    /// first loading, worn once).
    pub fn set_cycles(&mut self, cycles: bool) {
        self.jump_now = if cycles { self.wear.jump } else { 1.0 };
    }

    /// True with a cycle jump in the current segment: the wear is taken at
    /// the pressure it leaves.
    pub fn implicit(&self) -> bool {
        self.jump_now != 1.0
    }

    /// The depth a cell's increment wears, substrate and ball together,
    /// the current cycle jump included, m, from its end pressure `p`,
    /// tractions `q` and slip increment `ds` (what [`Wearing::wear_cell`]
    /// records, without recording it).
    pub fn depth_law(&self) -> impl Fn(f64, [f64; 2], [f64; 2]) -> f64 + '_ {
        move |p, q, ds| {
            if p > 0.0 {
                let ball = self.wear.ball.map_or(0.0, |b| b.depth(p, q, ds));
                (self.wear.law.depth(p, q, ds) + ball) * self.jump_now
            } else {
                0.0
            }
        }
    }

    /// After an increment's cells (pressure `p` at its end, which their
    /// depths were taken at; `slip_mid` the cells' slip δt − u halfway
    /// through it, m, which places the substrate's wear in its frame):
    /// without a jump the wear is applied now; with one, the layer
    /// [`Wearing::layer`] is made for the normal solve and
    /// [`Wearing::commit`] applies it.
    pub fn prepare(&mut self, p: &[f64], slip_mid: Slip) {
        if !self.implicit() {
            self.apply(slip_mid);
            return;
        }
        let jump = self.jump_now;
        let rate = |d: &mut f64, p: f64| *d = if p > 0.0 { jump * *d / p } else { 0.0 };
        for (i, d) in self.dh.iter_mut().enumerate() {
            rate(d, p[i]);
        }
        for (i, d) in self.dh_ball.iter_mut().enumerate() {
            rate(d, p[i]);
        }
        self.layer.clear();
        self.layer.extend_from_slice(&self.dh);
        for (c, &b) in self.layer.iter_mut().zip(&self.dh_ball) {
            *c += b;
        }
    }

    /// With a jump, the compliant layer of the normal solve on the worn
    /// surface ([`Wearing::prepare`]).
    pub fn layer(&self) -> Option<&[f64]> {
        self.implicit().then_some(&self.layer[..])
    }

    /// With a jump, applies the wear at the pressure `p` the layered normal
    /// solve left (the substrate's placed by `slip_mid`, as in
    /// [`Wearing::prepare`]).
    pub fn commit(&mut self, p: &[f64], slip_mid: Slip) {
        if !self.implicit() {
            return;
        }
        for (d, &pi) in self.dh.iter_mut().zip(p) {
            *d *= pi;
        }
        for (d, &pi) in self.dh_ball.iter_mut().zip(p) {
            *d *= pi;
        }
        self.apply(slip_mid);
    }

    /// Adds the increment's depths `dh` (the substrate's placed by
    /// `slip_mid`) and `dh_ball` to the worn depths and volumes.
    fn apply(&mut self, slip_mid: Slip) {
        let da = self.grid.cell_area();
        for &d in &self.dh {
            self.volume += d * da;
        }
        deposit(&mut self.worn, self.grid, slip_mid, &self.dh);
        for (w, &d) in self.ball.iter_mut().zip(&self.dh_ball) {
            *w += d;
            self.ball_volume += d * da;
        }
    }

    /// Adds to `h` the worn depths the separation sees after the cells'
    /// slips `slip` (δt − u, m): the ball's, and the substrate's at the
    /// points that now lie under each cell.
    pub fn add_gap(&self, slip: Slip, h: &mut [f64]) {
        for (v, w) in h.iter_mut().zip(shifted(&self.worn, self.grid, slip)) {
            *v += w;
        }
        for (v, &w) in h.iter_mut().zip(&self.ball) {
            *v += w;
        }
    }

    /// Records the full cycle that ended with pressure `p` (its rows'
    /// reductions `looped`), keeping its profiles if `save`.
    pub fn record(&mut self, terrain: &Terrain, p: &[f64], looped: &CycleRows, save: bool) {
        let grid = self.grid;
        let n = grid.n;
        let worn = &self.worn;
        let jump = self.wear.jump;
        let (mut deepest, mut depth_max) = (0, 0.0);
        for (i, &d) in worn.iter().enumerate() {
            if d > depth_max {
                (deepest, depth_max) = (i, d);
            }
        }
        let increment = worn
            .iter()
            .zip(&self.start)
            .map(|(a, b)| a - b)
            .fold(0.0, f64::max);
        let scar: Vec<bool> = worn
            .iter()
            .map(|&d| depth_max > 0.0 && d > SCAR_FRACTION * depth_max)
            .collect();
        let extent = |coord: &dyn Fn(usize) -> f64, spacing: f64| {
            let (lo, hi) = (0..grid.len())
                .filter(|&i| scar[i])
                .map(coord)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                });
            if hi >= lo {
                hi - lo + spacing
            } else {
                0.0
            }
        };
        let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
        let base = terrain
            .heights
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min);
        let worn_through_cells = terrain
            .heights
            .iter()
            .zip(worn)
            .filter(|&(&z, &d)| z > base && d > z - base)
            .count();
        // The cuts through the centre: the middle row (column), or the mean
        // of the two next to the centre on an even grid.
        let (lo, hi) = ((n - 1) / 2, n / 2);
        let (profile_x_m, profile_y_m) = if save {
            (
                (0..n)
                    .map(|ix| 0.5 * (worn[lo * n + ix] + worn[hi * n + ix]))
                    .collect(),
                (0..n)
                    .map(|iy| 0.5 * (worn[iy * n + lo] + worn[iy * n + hi]))
                    .collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        let cycle = self.cycles.len() + 1;
        let (v0, v1) = looped.worn_volume;
        let record = WearCycle {
            cycle,
            physical_cycles: cycle as f64 * jump,
            worn_volume_m3: v1,
            worn_volume_per_cycle_m3: (v1 - v0) / jump,
            depth_max_m: depth_max,
            // (Nothing worn: the centre.)
            depth_max_at_m: if depth_max > 0.0 {
                [grid.x(deepest % n), grid.y(deepest / n)]
            } else {
                [0.0; 2]
            },
            depth_increment_max_m: increment,
            // (+ 0.0: an empty sum is −0.)
            scar_area_m2: covered_area(&scar, terrain.cover.as_deref(), grid.cell_area()) + 0.0,
            scar_extent_m: [
                extent(&|i| grid.x(i % n), grid.dx),
                extent(&|i| grid.y(i / n), grid.dy),
            ],
            contact_radius_m: zone_radius(&grid, &contact, p, terrain),
            stick_radius_m: if looped.gross {
                0.0
            } else {
                looped.stick_radius_min
            },
            force_amplitude_n: looped.force_amplitude,
            shift_amplitude_m: looped.shift_amplitude,
            dissipated_j: looped.dissipated,
            regime: if looped.gross { "gross" } else { "partial" }.to_string(),
            worn_through_cells,
            ball_worn_volume_m3: self.ball_volume,
            ball_depth_max_m: self.ball.iter().cloned().fold(0.0, f64::max),
            profile_x_m,
            profile_y_m,
        };
        self.cycles.push(record);
        if save {
            self.saved.push((cycle, self.worn.clone()));
        }
        self.start.clone_from(&self.worn);
    }
}

/// The cells' slips δt − u along x and along y, m: the substrate's surface
/// point under cell x is the one that was under x + s at the path's start.
pub(crate) type Slip<'a> = (&'a [f64], &'a [f64]);

/// The cells (along one axis) of the substrate's frame that face cell `k`
/// of the grid after a slip of `s` cells, with their weights (0 off the
/// grid): the point at `k + s` between its two neighbours.
fn facing(k: usize, s: f64, n: usize) -> [(usize, f64); 2] {
    let xi = k as f64 + s;
    let i0 = xi.floor();
    let f = xi - i0;
    let at = |i: f64, w: f64| {
        if i >= 0.0 && i < n as f64 {
            (i as usize, w)
        } else {
            (0, 0.0)
        }
    };
    [at(i0, 1.0 - f), at(i0 + 1.0, f)]
}

/// The substrate-frame field `w` seen from the grid's cells after the
/// cells' slips `slip`: bilinear between the frame's cells, zero off them.
fn shifted(w: &[f64], grid: Grid, (sx, sy): Slip) -> Vec<f64> {
    let n = grid.n;
    let mut out = vec![0.0; n * n];
    for iy in 0..n {
        for ix in 0..n {
            let i = iy * n + ix;
            let (xs, ys) = (
                facing(ix, sx[i] / grid.dx, n),
                facing(iy, sy[i] / grid.dy, n),
            );
            let mut v = 0.0;
            for &(jy, wy) in &ys {
                for &(jx, wx) in &xs {
                    if wx * wy != 0.0 {
                        v += wx * wy * w[jy * n + jx];
                    }
                }
            }
            out[i] = v;
        }
    }
    out
}

/// Adds the depths `d` worn on the grid's cells to the substrate-frame
/// field `w` after the cells' slips `slip`: the transpose of [`shifted`],
/// so the volume is kept (but what falls off the frame's grid).
fn deposit(w: &mut [f64], grid: Grid, (sx, sy): Slip, d: &[f64]) {
    let n = grid.n;
    for iy in 0..n {
        for ix in 0..n {
            let i = iy * n + ix;
            let v = d[i];
            if v == 0.0 {
                continue;
            }
            let (xs, ys) = (
                facing(ix, sx[i] / grid.dx, n),
                facing(iy, sy[i] / grid.dy, n),
            );
            for &(jy, wy) in &ys {
                for &(jx, wx) in &xs {
                    w[jy * n + jx] += wx * wy * v;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slip_by_whole_cells_moves_the_field_and_deposit_is_its_transpose() {
        let grid = Grid::square(4, 1e-6);
        let w: Vec<f64> = (0..16).map(|i| i as f64).collect();
        let uniform = |s: [f64; 2]| (vec![s[0]; 16], vec![s[1]; 16]);
        // A slip of +1 cell in x: cell (ix) faces the frame's (ix + 1).
        let (sx, sy) = uniform([1e-6, 0.0]);
        let s = shifted(&w, grid, (&sx, &sy));
        assert_eq!(&s[0..4], &[1.0, 2.0, 3.0, 0.0]);
        // Half a cell: the mean of two neighbours; no slip: the field.
        let (sx, sy) = uniform([0.5e-6, 0.0]);
        assert_eq!(shifted(&w, grid, (&sx, &sy))[5], 0.5 * (5.0 + 6.0));
        let (sx, sy) = uniform([0.0, 0.0]);
        assert_eq!(shifted(&w, grid, (&sx, &sy)), w);
        // <shifted(w), d> = <w, deposit(d)> for any w, d and slips (the
        // transpose).
        let d: Vec<f64> = (0..16).map(|i| ((i * 7) % 5) as f64).collect();
        let sx: Vec<f64> = (0..16).map(|i| 0.3e-6 * (i % 3) as f64).collect();
        let sy: Vec<f64> = (0..16).map(|i| -0.7e-6 * (i % 2) as f64).collect();
        let lhs: f64 = shifted(&w, grid, (&sx, &sy))
            .iter()
            .zip(&d)
            .map(|(a, b)| a * b)
            .sum();
        let mut back = vec![0.0; 16];
        deposit(&mut back, grid, (&sx, &sy), &d);
        let rhs: f64 = back.iter().zip(&w).map(|(a, b)| a * b).sum();
        assert!((lhs - rhs).abs() < 1e-12 * lhs.abs());
        // Deposited inside the grid, the volume is kept.
        let mut one = vec![0.0; 16];
        let mut d = vec![0.0; 16];
        d[5] = 2.0;
        let (sx, sy) = uniform([0.25e-6, 0.6e-6]);
        deposit(&mut one, grid, (&sx, &sy), &d);
        assert!((one.iter().sum::<f64>() - 2.0).abs() < 1e-15);
    }
}
