//! The areal roughness parameters of a height map (ISO 25178 names): Sa,
//! Sq, Sz about the mean plane's height and the rms slope Sdq. Pure
//! arithmetic on heights and spacings; what the heights are is the
//! caller's.

use serde::{Deserialize, Serialize};

/// Roughness of a height map, m (Sdq dimensionless).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Roughness {
    /// Mean absolute height about the mean, m.
    pub sa: f64,
    /// Root-mean-square height about the mean, m.
    pub sq: f64,
    /// Highest minus lowest height, m.
    pub sz: f64,
    /// Root-mean-square slope: `sqrt(<(∂h/∂x)²> + <(∂h/∂y)²>)` with each
    /// derivative the difference of neighbouring points over their spacing,
    /// averaged over all neighbouring pairs along that axis.
    pub sdq: f64,
}

/// The roughness of `h` (`nx x ny`, row-major `[iy][ix]`, spacings `dx`,
/// `dy`); NaN points are left out (a pair with one is not a slope).
pub fn roughness(h: &[f64], nx: usize, ny: usize, dx: f64, dy: f64) -> Roughness {
    let known = || h.iter().copied().filter(|v| !v.is_nan());
    let count = known().count().max(1) as f64;
    let mean = known().sum::<f64>() / count;
    let sa = known().map(|v| (v - mean).abs()).sum::<f64>() / count;
    let sq = (known().map(|v| (v - mean).powi(2)).sum::<f64>() / count).sqrt();
    let (lo, hi) = known().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), v| {
        (l.min(v), u.max(v))
    });
    let mean_square = |pairs: &mut dyn Iterator<Item = (f64, f64)>, d: f64| {
        let (mut s, mut k) = (0.0, 0usize);
        for (a, b) in pairs {
            if !(a.is_nan() || b.is_nan()) {
                s += ((b - a) / d).powi(2);
                k += 1;
            }
        }
        if k > 0 {
            s / k as f64
        } else {
            0.0
        }
    };
    let mut along_x = (0..ny).flat_map(|iy| (0..nx - 1).map(move |ix| iy * nx + ix));
    let gx = mean_square(&mut along_x.by_ref().map(|i| (h[i], h[i + 1])), dx);
    let mut along_y = (0..ny - 1).flat_map(|iy| (0..nx).map(move |ix| iy * nx + ix));
    let gy = mean_square(&mut along_y.by_ref().map(|i| (h[i], h[i + nx])), dy);
    Roughness {
        sa,
        sq,
        sz: hi - lo,
        sdq: (gx + gy).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plane of slopes (a, b) has Sdq = sqrt(a² + b²) exactly and Sq the
    /// rms of a uniform ramp, (range)/sqrt(12) as the points grow; a
    /// square wave of ±A has Sa = Sq = A, Sz = 2A.
    #[test]
    fn roughness_of_a_plane_and_a_square_wave() {
        let (nx, ny, d) = (200, 100, 1e-6);
        let h: Vec<f64> = (0..nx * ny)
            .map(|i| 0.03 * (i % nx) as f64 * d - 0.04 * (i / nx) as f64 * d)
            .collect();
        let r = roughness(&h, nx, ny, d, d);
        assert!((r.sdq - 0.05).abs() < 1e-12, "{}", r.sdq);
        let wave: Vec<f64> = (0..nx * ny)
            .map(|i| if (i % nx) % 2 == 0 { 1e-6 } else { -1e-6 })
            .collect();
        let r = roughness(&wave, nx, ny, d, d);
        assert!((r.sa - 1e-6).abs() < 1e-18 && (r.sq - 1e-6).abs() < 1e-18);
        assert_eq!(r.sz, 2e-6);
        assert!((r.sdq - 2.0).abs() < 1e-12, "{}", r.sdq);
    }
}
