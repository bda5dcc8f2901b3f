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
