//! Exact areas of simple shapes inside an axis-aligned rectangle (a grid
//! cell): a disc, a half-plane, another axis-aligned rectangle. Closed forms,
//! no sampling, so that a cell's covered fraction moves continuously with the
//! shape and the grid (what the sub-cell island geometry of `surface` needs).
//! No physics.

/// An axis-aligned rectangle `[x0, x1] x [y0, y1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x0: f64,
    /// Right edge.
    pub x1: f64,
    /// Lower edge.
    pub y0: f64,
    /// Upper edge.
    pub y1: f64,
}

impl Rect {
    /// The square of side `side` centred on `(x, y)`.
    pub fn square(x: f64, y: f64, side: f64) -> Self {
        Rect::cell(x, y, side, side)
    }

    /// The rectangle `dx x dy` centred on `(x, y)`.
    pub fn cell(x: f64, y: f64, dx: f64, dy: f64) -> Self {
        Rect {
            x0: x - 0.5 * dx,
            x1: x + 0.5 * dx,
            y0: y - 0.5 * dy,
            y1: y + 0.5 * dy,
        }
    }

    /// Area.
    pub fn area(&self) -> f64 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }

    /// This rectangle moved by `(-x, -y)`.
    fn shifted(&self, x: f64, y: f64) -> Rect {
        Rect {
            x0: self.x0 - x,
            x1: self.x1 - x,
            y0: self.y0 - y,
            y1: self.y1 - y,
        }
    }
}

/// Area of the overlap of two axis-aligned rectangles.
pub fn rect_in_rect(a: &Rect, b: &Rect) -> f64 {
    let w = (a.x1.min(b.x1) - a.x0.max(b.x0)).max(0.0);
    let h = (a.y1.min(b.y1) - a.y0.max(b.y0)).max(0.0);
    w * h
}

/// Area of the disc of radius `r` centred on `(cx, cy)` inside `rect`.
///
/// The integral over x of the chord's length clipped to `[y0, y1]`, split at
/// the abscissae where the circle crosses `y = y0` and `y = y1`; on each piece
/// both ends are either a rectangle edge (linear in x) or the circle (the
/// antiderivative `(x s + r² asin(x/r)) / 2`, `s = √(r² − x²)`).
pub fn disc_in_rect(cx: f64, cy: f64, r: f64, rect: &Rect) -> f64 {
    let Rect { x0, x1, y0, y1 } = rect.shifted(cx, cy);
    let (lo, hi) = (x0.max(-r), x1.min(r));
    if lo >= hi || y0 >= r || y1 <= -r {
        return 0.0;
    }
    let half_chord = |x: f64| (r * r - x * x).max(0.0).sqrt();
    let big_f = |x: f64| {
        let x = x.clamp(-r, r);
        0.5 * (x * half_chord(x) + r * r * (x / r).asin())
    };
    let mut cuts = [lo, hi, lo, lo, lo, lo];
    let mut k = 2;
    for y in [y0, y1] {
        if y.abs() < r {
            let s = half_chord(y);
            for b in [-s, s] {
                if b > lo && b < hi {
                    cuts[k] = b;
                    k += 1;
                }
            }
        }
    }
    let cuts = &mut cuts[..k];
    cuts.sort_by(f64::total_cmp);
    let mut area = 0.0;
    for w in cuts.windows(2) {
        let (u, v) = (w[0], w[1]);
        if v <= u {
            continue;
        }
        let s = half_chord(0.5 * (u + v));
        // On this piece the upper end is y1 or the circle, the lower y0 or
        // the circle, the same all along (no crossing inside).
        if y1 <= -s || y0 >= s {
            continue;
        }
        let arc = big_f(v) - big_f(u);
        let top = if y1 < s { y1 * (v - u) } else { arc };
        let bottom = if y0 > -s { y0 * (v - u) } else { -arc };
        area += top - bottom;
    }
    area.clamp(0.0, rect.area())
}

/// Area of `rect` on the side `nx x + ny y ≤ c` of a line (`(nx, ny)` a unit
/// normal): the rectangle clipped by the half-plane, by the shoelace formula.
pub fn half_plane_in_rect(nx: f64, ny: f64, c: f64, rect: &Rect) -> f64 {
    let corners = [
        (rect.x0, rect.y0),
        (rect.x1, rect.y0),
        (rect.x1, rect.y1),
        (rect.x0, rect.y1),
    ];
    let side = |p: (f64, f64)| nx * p.0 + ny * p.1 - c;
    let mut poly: [(f64, f64); 8] = [(0.0, 0.0); 8];
    let mut k = 0;
    for i in 0..4 {
        let (p, q) = (corners[i], corners[(i + 1) % 4]);
        let (sp, sq) = (side(p), side(q));
        if sp <= 0.0 {
            poly[k] = p;
            k += 1;
        }
        if (sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0) {
            let t = sp / (sp - sq);
            poly[k] = (p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1));
            k += 1;
        }
    }
    let poly = &poly[..k];
    let mut s = 0.0;
    for i in 0..k {
        let (a, b) = (poly[i], poly[(i + 1) % k]);
        s += a.0 * b.1 - b.0 * a.1;
    }
    (0.5 * s.abs()).clamp(0.0, rect.area())
}

/// Area of `rect` inside the strip `|nx x + ny y − c| ≤ w/2`.
pub fn strip_in_rect(nx: f64, ny: f64, c: f64, w: f64, rect: &Rect) -> f64 {
    (half_plane_in_rect(nx, ny, c + 0.5 * w, rect) - half_plane_in_rect(nx, ny, c - 0.5 * w, rect))
        .max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Midpoint-rule area of `inside` over `rect` with `k x k` samples.
    fn sampled(rect: &Rect, k: usize, inside: impl Fn(f64, f64) -> bool) -> f64 {
        let (dx, dy) = (
            (rect.x1 - rect.x0) / k as f64,
            (rect.y1 - rect.y0) / k as f64,
        );
        let mut hits = 0usize;
        for j in 0..k {
            for i in 0..k {
                let (x, y) = (
                    rect.x0 + (i as f64 + 0.5) * dx,
                    rect.y0 + (j as f64 + 0.5) * dy,
                );
                hits += inside(x, y) as usize;
            }
        }
        hits as f64 * dx * dy
    }

    #[test]
    fn a_disc_inside_one_cell_and_a_cell_inside_a_disc() {
        let cell = Rect::square(0.3, -0.2, 4.0);
        let pi = std::f64::consts::PI;
        assert!((disc_in_rect(0.1, 0.0, 1.0, &cell) - pi).abs() < 1e-13);
        assert!((disc_in_rect(0.0, 0.0, 10.0, &cell) - 16.0).abs() < 1e-12);
        assert_eq!(disc_in_rect(10.0, 0.0, 1.0, &cell), 0.0);
        // A quarter disc: centre on a corner of a larger cell.
        let corner = Rect {
            x0: 0.0,
            x1: 5.0,
            y0: 0.0,
            y1: 5.0,
        };
        assert!((disc_in_rect(0.0, 0.0, 2.0, &corner) - pi).abs() < 1e-13);
    }

    #[test]
    fn cut_cells_match_fine_sampling() {
        // Cells crossing a circle's edge at several places and slopes.
        for (i, &(cx, cy)) in [(0.93, 0.1), (0.65, 0.72), (0.0, -1.02), (-0.5, 0.9)]
            .iter()
            .enumerate()
        {
            let cell = Rect::square(cx, cy, 0.3);
            let exact = disc_in_rect(0.0, 0.0, 1.0, &cell);
            let approx = sampled(&cell, 2000, |x, y| x.hypot(y) <= 1.0);
            assert!(
                (exact - approx).abs() < 1e-4 * cell.area(),
                "cell {i}: {exact} vs {approx}"
            );
            let (nx, ny) = (0.6, 0.8);
            let strip = strip_in_rect(nx, ny, 0.5 * (cx + cy), 0.2, &cell);
            let approx = sampled(&cell, 2000, |x, y| {
                (nx * x + ny * y - 0.5 * (cx + cy)).abs() <= 0.1
            });
            assert!(
                (strip - approx).abs() < 1e-4 * cell.area(),
                "strip {i}: {strip} vs {approx}"
            );
        }
    }

    #[test]
    fn half_planes_split_a_cell_into_complementary_parts() {
        let cell = Rect::square(0.2, 0.4, 1.0);
        for &(nx, ny, c) in &[(1.0, 0.0, 0.3), (0.6, -0.8, 0.1), (0.0, 1.0, 2.0)] {
            let a = half_plane_in_rect(nx, ny, c, &cell);
            let b = half_plane_in_rect(-nx, -ny, -c, &cell);
            assert!((a + b - 1.0).abs() < 1e-14, "{a} + {b}");
        }
        let a = Rect::square(0.0, 0.0, 2.0);
        let b = Rect::square(1.5, 0.5, 2.0);
        assert!((rect_in_rect(&a, &b) - 0.5 * 1.5).abs() < 1e-15);
    }
}
