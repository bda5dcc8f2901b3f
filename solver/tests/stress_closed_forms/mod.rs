//! Closed forms for the stresses under a Hertz contact, used only by the
//! stress tests: Hamilton's (1983) explicit equations for the normal
//! (Hertz) pressure, and Huber's axis values (Johnson eq. 3.73 limit).
//! Coordinates in units of the contact radius, stresses in units of p0,
//! z into the body, tension positive, Voigt order xx, yy, zz, yz, xz, xy.
#![allow(dead_code)]

/// Stress at `(x, y, z)` (units of a) under the Hertz pressure
/// `p0 sqrt(1 − r²)`, Hamilton 1983's explicit form (a = 1).
pub fn hamilton_normal(x: f64, y: f64, z: f64, nu: f64) -> [f64; 6] {
    let r2 = x * x + y * y;
    let a_ = r2 + z * z - 1.0;
    let s = (a_ * a_ + 4.0 * z * z).sqrt();
    let m = (0.5 * (s + a_)).max(0.0).sqrt();
    let n = (0.5 * (s - a_)).max(0.0).sqrt();
    if r2 < 1e-24 {
        // On the axis (Huber): σr = σθ, no shear.
        let sr = (1.0 + nu) * (z * (1.0 / z).atan() - 1.0) + 1.0 / (2.0 * (1.0 + z * z));
        return [sr, sr, -1.0 / (1.0 + z * z), 0.0, 0.0, 0.0];
    }
    let phi = if m > 0.0 {
        (1.0 / m).atan()
    } else {
        std::f64::consts::FRAC_PI_2
    };
    let g = m * m - n * n + z * m - n;
    let h = 2.0 * m * n + m + z * n;
    let r4 = r2 * r2;
    let common =
        (1.0 - nu) * n * z * z - (1.0 - 2.0 * nu) / 3.0 * (n * s + 2.0 * a_ * n + 1.0) - nu * m * z;
    let mz_s = if s > 0.0 { m * z / s } else { 0.0 };
    let sxx = (1.0 + nu) * z * phi
        + ((y * y - x * x) / r2 * common - n * (x * x + 2.0 * nu * y * y) - x * x * mz_s) / r2;
    let syy = (1.0 + nu) * z * phi
        + ((x * x - y * y) / r2 * common - n * (y * y + 2.0 * nu * x * x) - y * y * mz_s) / r2;
    let szz = -n + mz_s;
    let gh = g * g + h * h;
    let shear = |c: f64| {
        if z == 0.0 {
            0.0
        } else {
            -z * (c * n / s - c * z * h / gh)
        }
    };
    let sxz = shear(x);
    let syz = shear(y);
    // (the last term carries z: zero at the surface, where s may vanish)
    let sxy = x * y * (1.0 - 2.0 * nu) / r4
        * (-n * r2 + 2.0 / 3.0 * n * (s + 2.0 * a_) - z * (z * n + m) + 2.0 / 3.0)
        + x * y * z / r4 * (-m * r2 / s - z * n + m);
    [sxx, syy, szz, syz, sxz, sxy]
}

/// Surface σxx at the trailing edge (x = −a, behind a traction q = f p
/// along +x) of a sliding Hertz contact, Hamilton 1983 (PHYSICS.md §5c).
pub fn trailing_edge_sxx(nu: f64, f: f64) -> f64 {
    (1.0 - 2.0 * nu) / 3.0 + std::f64::consts::PI * (4.0 + nu) * f / 8.0
}

/// Cerruti's point force: the stress at `(x, y, z)` (z into the body,
/// tension positive, Voigt order xx, yy, zz, yz, xz, xy) of a unit force
/// applied at the surface origin along +x (Johnson 1985, §3.3).
pub fn cerruti(x: f64, y: f64, z: f64, nu: f64) -> [f64; 6] {
    let r = (x * x + y * y + z * z).sqrt();
    let (r2, r3) = (r * r, r * r * r);
    let rz = r + z;
    let k = (1.0 - 2.0 * nu) / (rz * rz);
    let c = 1.0 / (2.0 * std::f64::consts::PI * r3);
    let sxx = c * x * (-3.0 * x * x / r2 + k * (r2 - y * y - 2.0 * r * y * y / rz));
    let syy = c * x * (-3.0 * y * y / r2 + k * (3.0 * r2 - x * x - 2.0 * r * x * x / rz));
    let sxy = c * y * (-3.0 * x * x / r2 + k * (-r2 + x * x + 2.0 * r * x * x / rz));
    let b = -3.0 * c / r2;
    [sxx, syy, b * x * z * z, b * x * y * z, b * x * x * z, sxy]
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut t = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, t);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * t * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (t * p1 - p0) / (t * t - 1.0);
                let dt = p1 / dp;
                t -= dt;
                if dt.abs() < 1e-16 {
                    break;
                }
            }
            (t, 2.0 / ((1.0 - t * t) * dp * dp))
        })
        .collect()
}

/// The stress at `(x, y, z)`, z > 0, of the sliding traction
/// `q = √(1 − r²)` along +x on the unit disc (units of a and of the
/// traction's peak f·p0): Cerruti's field integrated over the disc in
/// polar coordinates about the point's projection. Along each ray the
/// substitution `ρ = m + h sin t` removes the square-root edges of the
/// traction; the rays' lengths are cut at `z·2^k/8` so the kernel's peak
/// under the point is resolved; Gauss–Legendre on every piece, the
/// trapezoid rule over the ray angle for points above the disc (smooth and
/// periodic), Gauss–Legendre in `φ = φc + α sin s` for points beside it.
/// This is the integral Hamilton (1983) evaluated in closed form.
pub fn sliding_tangential(x: f64, y: f64, z: f64, nu: f64, rule: usize) -> [f64; 6] {
    assert!(z > 0.0, "the quadrature needs z > 0");
    let gl = gauss_legendre(rule);
    let d2 = x * x + y * y;
    let ray = |phi: f64| -> [f64; 6] {
        let (s, c) = phi.sin_cos();
        let b = x * c + y * s;
        let disc = b * b - (d2 - 1.0);
        let mut acc = [0.0; 6];
        if disc <= 0.0 {
            return acc;
        }
        let (rm, rp) = (-b - disc.sqrt(), -b + disc.sqrt());
        let lo = rm.max(0.0);
        if rp <= lo {
            return acc;
        }
        let (m, h) = (0.5 * (rm + rp), 0.5 * (rp - rm));
        let mut breaks = vec![lo];
        let mut k = 0;
        loop {
            let r = lo + z * 2f64.powi(k) / 8.0;
            if r >= rp {
                break;
            }
            breaks.push(r);
            k += 1;
        }
        breaks.push(rp);
        let t_of = |r: f64| ((r - m) / h).clamp(-1.0, 1.0).asin();
        for w in breaks.windows(2) {
            let (ta, tb) = (t_of(w[0]), t_of(w[1]));
            let (tm, th) = (0.5 * (ta + tb), 0.5 * (tb - ta));
            for &(u, wt) in &gl {
                let t = tm + th * u;
                let rho = m + h * t.sin();
                let ct = t.cos();
                // q dρ = (h cos t)(h cos t dt), times the polar Jacobian ρ.
                let weight = wt * th * h * h * ct * ct * rho;
                let k = cerruti(-rho * c, -rho * s, z, nu);
                for (a, v) in acc.iter_mut().zip(k) {
                    *a += weight * v;
                }
            }
        }
        acc
    };
    let mut total = [0.0; 6];
    if d2 < 1.0 {
        let n_phi = 16 * rule;
        let dphi = std::f64::consts::TAU / n_phi as f64;
        for j in 0..n_phi {
            let r = ray(j as f64 * dphi);
            for (a, v) in total.iter_mut().zip(r) {
                *a += dphi * v;
            }
        }
    } else {
        let centre = (-y).atan2(-x);
        let alpha = (1.0 / d2.sqrt()).asin();
        // s in [−π/2, π/2] in 8 pieces.
        for piece in 0..8 {
            let (sa, sb) = (
                -std::f64::consts::FRAC_PI_2 + piece as f64 * std::f64::consts::PI / 8.0,
                -std::f64::consts::FRAC_PI_2 + (piece + 1) as f64 * std::f64::consts::PI / 8.0,
            );
            let (sm, sh) = (0.5 * (sa + sb), 0.5 * (sb - sa));
            for &(u, wt) in &gl {
                let sv = sm + sh * u;
                let r = ray(centre + alpha * sv.sin());
                let w = wt * sh * alpha * sv.cos();
                for (a, v) in total.iter_mut().zip(r) {
                    *a += w * v;
                }
            }
        }
    }
    total
}

/// Boussinesq's point force: the stress at `(x, y, z)` (z into the body,
/// tension positive, Voigt order xx, yy, zz, yz, xz, xy) of a unit force
/// pressing the surface origin along +z (Johnson 1985, §3.2: σr, σθ, σz
/// and τrz turned to x, y).
pub fn boussinesq(x: f64, y: f64, z: f64, nu: f64) -> [f64; 6] {
    let r2 = x * x + y * y;
    let rho2 = r2 + z * z;
    let rho = rho2.sqrt();
    let rho3 = rho2 * rho;
    let rho5 = rho3 * rho2;
    let c = 1.0 / (2.0 * std::f64::consts::PI);
    let sz = -3.0 * c * z * z * z / rho5;
    let trz_over_r = -3.0 * c * z * z / rho5;
    // (1 − z/ρ)/r² = 1/(ρ(ρ + z)), without the cancellation on the axis
    let tail = 1.0 / (rho * (rho + z));
    let sr_iso = c * (1.0 - 2.0 * nu) * tail;
    let st = -c * (1.0 - 2.0 * nu) * (tail - z / rho3);
    // σr = sr_iso − 3 c z r²/ρ⁵: its r² part goes with cos², sin², sin cos.
    let b = -3.0 * c * z / rho5;
    // σxx = σr cos² + σθ sin² = (sr_iso x² + σθ y²)/r² + b x², and alike;
    // on the axis σr = σθ.
    let (cc, ss, sc) = if r2 > 0.0 {
        (x * x / r2, y * y / r2, x * y / r2)
    } else {
        (0.5, 0.5, 0.0)
    };
    let sxx = sr_iso * cc + st * ss + b * x * x;
    let syy = sr_iso * ss + st * cc + b * y * y;
    let sxy = (sr_iso - st) * sc + b * x * y;
    [sxx, syy, sz, trz_over_r * y, trz_over_r * x, sxy]
}
