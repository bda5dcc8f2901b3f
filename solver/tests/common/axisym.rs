//! Axisymmetric closed forms of the ring-element references (Spence's
//! problem, the elastic–plastic sphere): complete elliptic integrals and the
//! surface displacements of a uniformly loaded disc. No FFT, no 3-D kernel.

use std::f64::consts::PI;

/// Complete elliptic integrals K(m), E(m) of the parameter m = k² < 1, by
/// the arithmetic–geometric mean.
pub fn elliptic_ke(m: f64) -> (f64, f64) {
    elliptic_ke_split(m, 1.0 - m)
}

/// [`elliptic_ke`] with the complementary parameter `m1 = 1 − m` given
/// exactly (near m = 1, where K grows like ln(16/m1)/2, 1 − m would keep
/// only the digits m1 has beyond m's rounding).
pub fn elliptic_ke_split(m: f64, m1: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0_f64, m1.sqrt());
    let mut sum = 0.5 * m; // Σ 2^{n−1} c_n², c_0² = m
    let mut pow = 0.5;
    for _ in 0..60 {
        let c = 0.5 * (a - b);
        let an = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = an;
        pow *= 2.0;
        sum += pow * c * c;
        if c.abs() < 1e-17 * a {
            break;
        }
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// Uniform pressure p on a disc of radius b (Johnson §3.4): normal and radial
/// surface displacement at radius r per unit pressure, m/Pa.
pub fn disc_pressure(b: f64, r: f64, g: f64, nu: f64) -> (f64, f64) {
    let cz = 2.0 * (1.0 - nu) / (PI * g); // 4(1 − ν²)/(πE)
    let uz = if r <= b {
        cz * b * elliptic_ke((r / b) * (r / b)).1
    } else {
        let m = (b / r) * (b / r);
        let (k, e) = elliptic_ke(m);
        cz * r * (e - (1.0 - m) * k)
    };
    let ur = -(1.0 - 2.0 * nu) / (4.0 * g) * if r <= b { r } else { b * b / r };
    (uz, ur)
}
