//! A measured (or generated) topography on its own pixels — heights, pixel
//! sizes that need not be square, missing points — and its preparation for
//! contact: missing points refused or filled, the form levelled away.
//! Reads no file (the coordinator does) and knows no case grid
//! ([`crate::model::resample`] puts a scan on one).

use crate::error::SolverError;
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// The highest degree of a levelling polynomial: its normal equations are
/// formed in coordinates scaled to [-1, 1], whose powers up to 2 × 8 stay
/// well conditioned in f64; a higher form is a filter's job, not a fit's.
pub const MAX_LEVELLING_DEGREE: usize = 8;

/// A height map on a regular grid of `nx x ny` pixels of `dx x dy`.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// Pixels along x (columns).
    pub nx: usize,
    /// Pixels along y (rows).
    pub ny: usize,
    /// Pixel size along x, m.
    pub dx: f64,
    /// Pixel size along y, m.
    pub dy: f64,
    /// Heights, m, row-major `[iy][ix]`, positive towards the ball; NaN
    /// where the instrument measured nothing.
    pub heights: Arc<Vec<f64>>,
}

/// How the form (tilt, curvature) of a scan is removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Levelling {
    /// Heights as measured.
    None,
    /// The least-squares polynomial of this degree in x and y (all terms
    /// `x^i y^j`, `i + j <= degree`) subtracted: 1 is the mean plane.
    Polynomial {
        /// The polynomial's degree, 1 to [`MAX_LEVELLING_DEGREE`].
        degree: usize,
    },
}

impl Levelling {
    /// The name used in configs and outputs.
    pub fn name(self) -> String {
        match self {
            Levelling::None => "none".into(),
            Levelling::Polynomial { degree: 1 } => "plane".into(),
            Levelling::Polynomial { degree } => format!("polynomial of degree {degree}"),
        }
    }
}

/// What is done with the points an instrument did not measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Missing {
    /// A scan with any missing point is refused, with their count.
    Refuse,
    /// Each missing point gets the mean of its measured (or already
    /// filled) neighbours, ring by ring from the edge of the hole inwards.
    Fill,
}

impl Scan {
    /// A scan of `nx x ny` pixels, checked: a 2-D map (at least 2 pixels
    /// each way), positive finite pixel sizes, one height per pixel, no
    /// infinite height (NaN marks a missing point).
    pub fn new(
        nx: usize,
        ny: usize,
        dx: f64,
        dy: f64,
        heights: Vec<f64>,
    ) -> Result<Scan, SolverError> {
        if nx < 2 || ny < 2 {
            return Err(SolverError::invalid(
                "scan",
                format!(
                    "a 1-D profile ({nx} x {ny} points): contact needs a 2-D map of heights (at least 2 x 2 points)"
                ),
            ));
        }
        for (name, v) in [("pixel x", dx), ("pixel y", dy)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(SolverError::invalid(
                    "scan",
                    format!("the {name} size is {v:e} m: it must be positive and finite"),
                ));
            }
        }
        if heights.len() != nx * ny {
            return Err(SolverError::invalid(
                "scan",
                format!(
                    "{} heights for {nx} x {ny} pixels ({} expected)",
                    heights.len(),
                    nx * ny
                ),
            ));
        }
        if let Some(i) = heights.iter().position(|h| h.is_infinite()) {
            return Err(SolverError::invalid(
                "scan",
                format!(
                    "the height at row {}, column {} is infinite",
                    i / nx,
                    i % nx
                ),
            ));
        }
        Ok(Scan {
            nx,
            ny,
            dx,
            dy,
            heights: Arc::new(heights),
        })
    }

    /// The scan's extent `(x, y)`, m: its pixels' footprints, `n` pixel
    /// sizes each way.
    pub fn extent(&self) -> (f64, f64) {
        (self.nx as f64 * self.dx, self.ny as f64 * self.dy)
    }

    /// The number of missing points and the first one's `(row, column)`.
    pub fn missing(&self) -> (usize, Option<(usize, usize)>) {
        let count = self.heights.iter().filter(|h| h.is_nan()).count();
        let first = self
            .heights
            .iter()
            .position(|h| h.is_nan())
            .map(|i| (i / self.nx, i % self.nx));
        (count, first)
    }

    /// The scan ready for contact: missing points refused or filled, then
    /// the form subtracted. The form is fitted to the measured points only,
    /// so a filled hole does not pull it.
    pub fn prepared(&self, missing: Missing, levelling: Levelling) -> Result<Scan, SolverError> {
        let (count, first) = self.missing();
        if count == self.heights.len() {
            return Err(SolverError::invalid(
                "missing",
                "every point of the scan is missing",
            ));
        }
        if count > 0 && missing == Missing::Refuse {
            let (r, c) = first.unwrap_or_default();
            return Err(SolverError::invalid(
                "missing",
                format!(
                    "the scan has {count} missing points of {} (the first at row {r}, column {c}): fill them (missing = \"fill\") or measure again",
                    self.heights.len()
                ),
            ));
        }
        let mut h = self.heights.as_ref().clone();
        if let Levelling::Polynomial { degree } = levelling {
            if !(1..=MAX_LEVELLING_DEGREE).contains(&degree) {
                return Err(SolverError::invalid(
                    "degree",
                    format!(
                        "a levelling polynomial of degree {degree}: 1 (the plane) to {MAX_LEVELLING_DEGREE}"
                    ),
                ));
            }
            let form = self.fit(degree)?;
            self.subtract(&mut h, &form, degree);
        }
        if count > 0 {
            fill(&mut h, self.nx, self.ny);
        }
        Ok(Scan {
            heights: Arc::new(h),
            ..*self
        })
    }

    /// Scaled coordinates in [-1, 1] of column `ix` and row `iy`.
    fn scaled(&self) -> (impl Fn(usize) -> f64, impl Fn(usize) -> f64) {
        let (hx, hy) = (0.5 * (self.nx - 1) as f64, 0.5 * (self.ny - 1) as f64);
        (
            move |ix: usize| (ix as f64 - hx) / hx,
            move |iy: usize| (iy as f64 - hy) / hy,
        )
    }

    /// The least-squares polynomial of `degree` through the measured
    /// points: its coefficients of `x^i y^j` (scaled coordinates), in the
    /// order of [`terms`]. The normal equations need only the moments
    /// `Σ x^p y^q` and `Σ x^p y^q h` (p, q ≤ 2·degree), summed row by row:
    /// a pass over the scan whatever the degree.
    fn fit(&self, degree: usize) -> Result<Vec<f64>, SolverError> {
        let m = 2 * degree + 1;
        let (sx, sy) = self.scaled();
        let mut moments = vec![0.0; m * m];
        let mut weighted = vec![0.0; m * m];
        let mut row = vec![0.0; m];
        let mut row_h = vec![0.0; m];
        for iy in 0..self.ny {
            row.iter_mut().for_each(|v| *v = 0.0);
            row_h.iter_mut().for_each(|v| *v = 0.0);
            let line = &self.heights[iy * self.nx..(iy + 1) * self.nx];
            for (ix, &h) in line.iter().enumerate() {
                if h.is_nan() {
                    continue;
                }
                let x = sx(ix);
                let mut power = 1.0;
                for p in 0..m {
                    row[p] += power;
                    row_h[p] += power * h;
                    power *= x;
                }
            }
            let y = sy(iy);
            let mut power = 1.0;
            for q in 0..m {
                for p in 0..m {
                    moments[p * m + q] += row[p] * power;
                    weighted[p * m + q] += row_h[p] * power;
                }
                power *= y;
            }
        }
        let terms = terms(degree);
        let k = terms.len();
        let a = DMatrix::from_fn(k, k, |r, c| {
            let ((i, j), (p, q)) = (terms[r], terms[c]);
            moments[(i + p) * m + (j + q)]
        });
        let b = DVector::from_fn(k, |r, _| {
            let (i, j) = terms[r];
            weighted[i * m + j]
        });
        let coefficients = a.lu().solve(&b).ok_or_else(|| {
            SolverError::invalid(
                "degree",
                format!(
                    "too few measured points to fit a polynomial of degree {degree} ({k} terms)"
                ),
            )
        })?;
        Ok(coefficients.iter().copied().collect())
    }

    /// `h` minus the polynomial `form` of `degree` (measured points only).
    fn subtract(&self, h: &mut [f64], form: &[f64], degree: usize) {
        let (sx, sy) = self.scaled();
        let terms = terms(degree);
        let mut ypow = vec![0.0; degree + 1];
        let mut xpow = vec![0.0; degree + 1];
        for iy in 0..self.ny {
            powers(sy(iy), &mut ypow);
            for ix in 0..self.nx {
                let v = &mut h[iy * self.nx + ix];
                if v.is_nan() {
                    continue;
                }
                powers(sx(ix), &mut xpow);
                let z: f64 = terms
                    .iter()
                    .zip(form)
                    .map(|(&(i, j), c)| c * xpow[i] * ypow[j])
                    .sum();
                *v -= z;
            }
        }
    }
}

/// `x^0 ..= x^(len-1)` into `out`.
fn powers(x: f64, out: &mut [f64]) {
    let mut p = 1.0;
    for v in out {
        *v = p;
        p *= x;
    }
}

/// The terms `(i, j)` of `x^i y^j` of a polynomial of `degree`, by total
/// degree then by the power of y.
fn terms(degree: usize) -> Vec<(usize, usize)> {
    (0..=degree)
        .flat_map(|d| (0..=d).map(move |j| (d - j, j)))
        .collect()
}

/// Fills the NaN points of `h` (`nx x ny`) ring by ring: each pass gives
/// every missing point with a known 4-neighbour the mean of those
/// neighbours, until none is missing. Deterministic (a pass reads only the
/// points known before it); a hole r pixels across takes about r/2 passes.
fn fill(h: &mut [f64], nx: usize, ny: usize) {
    let mut todo: Vec<usize> = (0..h.len()).filter(|&i| h[i].is_nan()).collect();
    while !todo.is_empty() {
        let mut filled = Vec::new();
        let mut left = Vec::new();
        for &i in &todo {
            let (iy, ix) = (i / nx, i % nx);
            let mut sum = 0.0;
            let mut k = 0;
            let mut take = |j: usize| {
                if !h[j].is_nan() {
                    sum += h[j];
                    k += 1;
                }
            };
            if ix > 0 {
                take(i - 1);
            }
            if ix + 1 < nx {
                take(i + 1);
            }
            if iy > 0 {
                take(i - nx);
            }
            if iy + 1 < ny {
                take(i + nx);
            }
            if k > 0 {
                filled.push((i, sum / k as f64));
            } else {
                left.push(i);
            }
        }
        for (i, v) in filled {
            h[i] = v;
        }
        todo = left;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan_of(nx: usize, ny: usize, f: impl Fn(f64, f64) -> f64) -> Scan {
        let (dx, dy) = (1e-6, 2e-6);
        let h = (0..nx * ny)
            .map(|i| f((i % nx) as f64 * dx, (i / nx) as f64 * dy))
            .collect();
        Scan::new(nx, ny, dx, dy, h).unwrap()
    }

    /// A tilted plane plus a bump levelled by the plane keeps the bump's
    /// shape: the residual is the bump minus its own least-squares plane,
    /// and a pure plane levels to round-off.
    #[test]
    fn plane_levelling_removes_a_tilt_to_round_off() {
        let plane = |x: f64, y: f64| 3e-6 + 0.02 * x - 0.05 * y;
        let s = scan_of(40, 30, plane);
        let l = s
            .prepared(Missing::Refuse, Levelling::Polynomial { degree: 1 })
            .unwrap();
        let worst = l.heights.iter().fold(0.0f64, |m, h| m.max(h.abs()));
        println!("plane levelled: largest residual {worst:e} m");
        assert!(worst < 1e-18, "{worst:e}");
        // A quadratic form is removed by degree 2, not by the plane.
        let bowl = |x: f64, y: f64| 1e-6 + 40.0 * (x - 2e-5).powi(2) + 10.0 * x * y;
        let s = scan_of(40, 30, bowl);
        let two = s
            .prepared(Missing::Refuse, Levelling::Polynomial { degree: 2 })
            .unwrap();
        let one = s
            .prepared(Missing::Refuse, Levelling::Polynomial { degree: 1 })
            .unwrap();
        let rms = |s: &Scan| {
            (s.heights.iter().map(|h| h * h).sum::<f64>() / s.heights.len() as f64).sqrt()
        };
        println!(
            "bowl: rms after degree 2 {:e}, after the plane {:e}",
            rms(&two),
            rms(&one)
        );
        assert!(rms(&two) < 1e-18 && rms(&one) > 1e-10);
    }

    /// Missing points: refused with their count and the first one's place,
    /// or filled; the form is fitted to the measured points only, so a
    /// plane with a hole levels to round-off, hole filled included.
    #[test]
    fn missing_points_are_refused_with_their_count_or_filled() {
        let mut h: Vec<f64> = (0..20 * 10).map(|i| (i % 20) as f64 * 1e-7).collect();
        for i in [45, 46, 65, 66, 67] {
            h[i] = f64::NAN;
        }
        let s = Scan::new(20, 10, 1e-6, 1e-6, h).unwrap();
        let e = s
            .prepared(Missing::Refuse, Levelling::None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("5 missing points of 200") && e.contains("row 2, column 5"),
            "{e}"
        );
        let f = s
            .prepared(Missing::Fill, Levelling::Polynomial { degree: 1 })
            .unwrap();
        let worst = f.heights.iter().fold(0.0f64, |m, h| m.max(h.abs()));
        assert!(worst < 1e-18, "{worst:e}");
        // Unlevelled, a filled point of a linear ramp lies between its
        // neighbours' heights.
        let f = s.prepared(Missing::Fill, Levelling::None).unwrap();
        assert!(f.heights.iter().all(|h| h.is_finite()));
        assert!((f.heights[45] - 5e-7).abs() < 2e-7, "{}", f.heights[45]);
    }

    #[test]
    fn a_profile_is_not_a_map() {
        let e = Scan::new(100, 1, 1e-6, 1e-6, vec![0.0; 100])
            .unwrap_err()
            .to_string();
        assert!(e.contains("1-D profile (100 x 1 points)"), "{e}");
    }
}
