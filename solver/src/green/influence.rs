//! Influence coefficients: displacement at a point due to a uniform unit traction
//! over one rectangular surface cell. Closed forms for the isotropic half-space
//! (Love for normal–normal, integrated Cerruti/Boussinesq for the rest).
//! No FFTs here; `operator` turns these into kernel spectra.
//!
//! Convention (docs/physics-choices.md, Geometry): z points into the body, traction `t = (qx, qy, p)`,
//! result `k[i][j]` = displacement component i per unit traction component j (m/Pa).

use std::f64::consts::PI;

/// 3x3 influence block, `k[i][j]`: displacement i (x, y, z) per traction j (qx, qy, p).
pub type Block = [[f64; 3]; 3];

/// The four-corner combination `F(x+a, y+b) - F(x-a, y+b) - F(x+a, y-b) + F(x-a, y-b)`.
fn corners(x: f64, y: f64, a: f64, b: f64, f: impl Fn(f64, f64) -> f64) -> f64 {
    f(x + a, y + b) - f(x - a, y + b) - f(x + a, y - b) + f(x - a, y - b)
}

/// `ln(u + r)` with `r = sqrt(u² + v²)`, stable when `u < 0` and `|v| << |u|`.
fn ln_u_plus_r(u: f64, v: f64) -> f64 {
    let r = u.hypot(v);
    if u >= 0.0 {
        (u + r).ln()
    } else {
        // u + r = v² / (r - u)
        (v * v).ln() - (r - u).ln()
    }
}

/// Closed-form influence block for an isotropic half-space (shear modulus `g`,
/// Poisson ratio `nu`): displacement at `(x, y)` relative to the centre of a cell
/// of size `dx x dy` carrying unit uniform traction.
///
/// The observation point must not lie on a cell edge line (`|x| = dx/2` or
/// `|y| = dy/2`); grid cell centres never do.
///
/// The block is evaluated at `(|x|, |y|)` and mirrored with the parity of each
/// component ([`mirror_sign`]), so that it is exactly (to the bit) even or odd
/// in x and y: evaluated directly at negative offsets, the corner sums round
/// differently (about a fifth of the entries of a 64² quadrant differed in
/// their last bits), and the symmetric kernel build
/// ([`crate::Operator::build_mirrored`]) could not equal the direct one.
pub fn isotropic_cell(g: f64, nu: f64, x: f64, y: f64, dx: f64, dy: f64) -> Block {
    let k = isotropic_quadrant(g, nu, x.abs(), y.abs(), dx, dy);
    if x >= 0.0 && y >= 0.0 {
        return k;
    }
    std::array::from_fn(|i| std::array::from_fn(|j| mirror_sign(i, j, x < 0.0, y < 0.0) * k[i][j]))
}

/// The sign of influence component `(i, j)` (0, 1, 2 = x, y, z) at `(±x, ±y)`
/// relative to `(|x|, |y|)` for a half-space symmetric under `x → −x` and
/// `y → −y` (isotropic, among others): a component is odd in x when exactly
/// one of its indices is x (`K_xy`, `K_xz`, `K_zx`, …), likewise in y.
pub fn mirror_sign(i: usize, j: usize, neg_x: bool, neg_y: bool) -> f64 {
    let odd_x = neg_x && ((i == 0) != (j == 0));
    let odd_y = neg_y && ((i == 1) != (j == 1));
    if odd_x != odd_y {
        -1.0
    } else {
        1.0
    }
}

/// [`isotropic_cell`] evaluated as written (any sign of `x`, `y`).
fn isotropic_quadrant(g: f64, nu: f64, x: f64, y: f64, dx: f64, dy: f64) -> Block {
    let a = 0.5 * dx;
    let b = 0.5 * dy;
    // ∫∫ 1/r: X ln(Y + r) + Y ln(X + r)
    let x_ln_y = corners(x, y, a, b, |u, v| u * ln_u_plus_r(v, u));
    let y_ln_x = corners(x, y, a, b, |u, v| v * ln_u_plus_r(u, v));
    // ∫∫ XY/r³: -r
    let xy = corners(x, y, a, b, |u, v| -u.hypot(v));
    // ∫∫ X/r²: Y ln r + X atan(Y/X);  ∫∫ Y/r²: X ln r + Y atan(X/Y)
    let x_r2 = corners(x, y, a, b, |u, v| v * u.hypot(v).ln() + u * (v / u).atan());
    let y_r2 = corners(x, y, a, b, |u, v| u * u.hypot(v).ln() + v * (u / v).atan());

    let c1 = 1.0 / (2.0 * PI * g);
    let c2 = (1.0 - 2.0 * nu) / (4.0 * PI * g);
    let kzz = (1.0 - nu) * c1 * (x_ln_y + y_ln_x);
    let kxx = c1 * ((1.0 - nu) * x_ln_y + y_ln_x);
    let kyy = c1 * (x_ln_y + (1.0 - nu) * y_ln_x);
    let kxy = nu * c1 * xy;
    // u_x under pressure points toward the load: G_xz = -(1-2ν) x / (4πG r²)
    let kxz = -c2 * x_r2;
    let kyz = -c2 * y_r2;
    [[kxx, kxy, kxz], [kxy, kyy, kyz], [-kxz, -kyz, kzz]]
}

/// Point-force surface Green's function of the isotropic half-space (m/N),
/// `G[i][j]` at offset `(x, y)` from the force. Used for far-field checks.
pub fn isotropic_point(g: f64, nu: f64, x: f64, y: f64) -> Block {
    let r = x.hypot(y);
    let c1 = 1.0 / (2.0 * PI * g);
    let c2 = (1.0 - 2.0 * nu) / (4.0 * PI * g);
    let r3 = r * r * r;
    let gxx = c1 * ((1.0 - nu) / r + nu * x * x / r3);
    let gyy = c1 * ((1.0 - nu) / r + nu * y * y / r3);
    let gxy = c1 * nu * x * y / r3;
    let gxz = -c2 * x / (r * r);
    let gyz = -c2 * y / (r * r);
    let gzz = c1 * (1.0 - nu) / r;
    [[gxx, gxy, gxz], [gxy, gyy, gyz], [-gxz, -gyz, gzz]]
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 80.0e9;
    const NU: f64 = 0.3;
    const D: f64 = 1.0e-6;

    fn max_abs(k: &Block) -> f64 {
        k.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn love_centre_displacement_of_a_square_matches_timoshenko_factor() {
        // Centre of a uniformly loaded square of side B: w = 1.122 (1-ν²) p B / E
        // (exact factor (4/π) ln(1+√2) = 1.12219...).
        let k = isotropic_cell(G, NU, 0.0, 0.0, D, D);
        let e = 2.0 * G * (1.0 + NU);
        let factor = 4.0 / PI * (1.0 + 2f64.sqrt()).ln();
        let expected = factor * (1.0 - NU * NU) * D / e;
        assert!(
            (k[2][2] / expected - 1.0).abs() < 1e-13,
            "{} vs {}",
            k[2][2],
            expected
        );
    }

    /// The block is even or odd in x and y to the bit, and at negative
    /// offsets equals the formula evaluated there as written to round-off.
    #[test]
    fn mirror_symmetry_is_exact_and_the_mirrored_values_are_the_formula_s() {
        let (dx, dy) = (D, 1.3 * D);
        let scale = isotropic_cell(G, NU, 0.0, 0.0, dx, dy)[2][2];
        let mut worst = 0.0_f64;
        for j in 0..40 {
            for i in 0..40 {
                let (x, y) = (i as f64 * dx, j as f64 * dy);
                let k = isotropic_cell(G, NU, x, y, dx, dy);
                for (sx, sy) in [(1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                    let (xm, ym) = (sx * x, sy * y);
                    let km = isotropic_cell(G, NU, xm, ym, dx, dy);
                    let direct = isotropic_quadrant(G, NU, xm, ym, dx, dy);
                    for r in 0..3 {
                        for c in 0..3 {
                            let sign = mirror_sign(r, c, xm < 0.0, ym < 0.0);
                            assert_eq!(km[r][c].to_bits(), (sign * k[r][c]).to_bits());
                            worst = worst.max((km[r][c] - direct[r][c]).abs() / scale);
                        }
                    }
                }
            }
        }
        // Measured 7.7e-14: the corner sums cancel (large terms, small
        // result) far from the cell, so either evaluation carries this round-off.
        assert!(
            worst < 1e-12,
            "mirrored vs direct evaluation: {worst:e} of K_zz(0)"
        );
    }

    #[test]
    fn betti_reciprocity_k_ij_at_x_equals_k_ji_at_minus_x() {
        let scale = isotropic_cell(G, NU, 0.0, 0.0, D, 1.3 * D)[2][2];
        for &(i, j) in &[(0, 0), (1, 0), (3, 2), (-2, 5), (7, -4), (0, 9)] {
            let (x, y) = (i as f64 * D, j as f64 * 1.3 * D);
            let k = isotropic_cell(G, NU, x, y, D, 1.3 * D);
            let km = isotropic_cell(G, NU, -x, -y, D, 1.3 * D);
            for r in 0..3 {
                for c in 0..3 {
                    assert!(
                        (k[r][c] - km[c][r]).abs() < 1e-13 * scale,
                        "K[{r}][{c}]({i},{j}) = {} but K[{c}][{r}](-x) = {}",
                        k[r][c],
                        km[c][r]
                    );
                }
            }
        }
    }

    #[test]
    fn far_field_equals_point_load_times_area_within_1e3_at_20_cells() {
        for &(i, j) in &[(20, 0), (0, 20), (14, 14), (-20, 3), (12, -16)] {
            let (x, y) = (i as f64 * D, j as f64 * D);
            let k = isotropic_cell(G, NU, x, y, D, D);
            let p = isotropic_point(G, NU, x, y);
            let scale = max_abs(&p) * D * D;
            for r in 0..3 {
                for c in 0..3 {
                    let err = (k[r][c] - p[r][c] * D * D).abs() / scale;
                    assert!(err < 1e-3, "({i},{j}) K[{r}][{c}] rel err {err}");
                }
            }
        }
    }

    #[test]
    fn pressure_pulls_surface_radially_toward_the_load() {
        // u_x at +x is negative, u_y at +y is negative, and it matches Boussinesq's
        // u_r = -(1-2ν) P / (4πG r) far away.
        let k = isotropic_cell(G, NU, 30.0 * D, 0.0, D, D);
        assert!(k[0][2] < 0.0);
        let ur = -(1.0 - 2.0 * NU) * D * D / (4.0 * PI * G * 30.0 * D);
        assert!((k[0][2] / ur - 1.0).abs() < 1e-3);
        let k = isotropic_cell(G, NU, 0.0, 25.0 * D, D, D);
        assert!(k[1][2] < 0.0);
    }

    #[test]
    fn numerical_quadrature_of_point_solution_matches_closed_form_off_cell() {
        // Independent check of every component at a near neighbour by Gauss–Legendre
        // quadrature of the point solution (smooth there).
        let (x, y) = (2.0 * D, 1.0 * D);
        let k = isotropic_cell(G, NU, x, y, D, D);
        let (gx, gw) = gauss_legendre_20();
        let mut acc = [[0.0; 3]; 3];
        for (xi, wi) in gx.iter().zip(&gw) {
            for (yj, wj) in gx.iter().zip(&gw) {
                let xs = 0.5 * D * xi;
                let ys = 0.5 * D * yj;
                let p = isotropic_point(G, NU, x - xs, y - ys);
                for r in 0..3 {
                    for c in 0..3 {
                        acc[r][c] += p[r][c] * wi * wj * 0.25 * D * D;
                    }
                }
            }
        }
        let scale = max_abs(&k);
        for r in 0..3 {
            for c in 0..3 {
                assert!((acc[r][c] - k[r][c]).abs() < 1e-9 * scale, "K[{r}][{c}]");
            }
        }
    }

    /// 20-point Gauss–Legendre nodes and weights on [-1, 1] by Newton iteration.
    fn gauss_legendre_20() -> (Vec<f64>, Vec<f64>) {
        let n = 20;
        let mut xs = Vec::new();
        let mut ws = Vec::new();
        for i in 0..n {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let legendre = |x: f64| {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
            };
            for _ in 0..60 {
                let (p, dp) = legendre(x);
                x -= p / dp;
            }
            let (_, dp) = legendre(x);
            xs.push(x);
            ws.push(2.0 / ((1.0 - x * x) * dp * dp));
        }
        (xs, ws)
    }
}
