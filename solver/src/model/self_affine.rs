//! Random self-affine surfaces for users without a scan: Gaussian heights
//! whose isotropic power spectrum is flat below the long cutoff's
//! wavevector (the roll-off), falls as `q^(-2(1+H))` up to the short
//! cutoff's and is zero beyond, scaled to an rms height or an rms slope.
//! The same seed gives the same bits on any machine: the random stream is
//! ChaCha20 (a specified cipher, `rand_chacha`), its uniforms and normals
//! are formed here, and the transform is rustfft's scalar planner (no
//! run-time choice of SIMD code, whose rounding would differ by CPU).

use crate::error::SolverError;
use crate::model::scan::Scan;
use num_complex::Complex64;
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rustfft::FftPlannerScalar;

/// The largest side of a generated surface: its spectrum takes 16 bytes a
/// point (256 MB at 4096²).
pub const MAX_PIXELS: usize = 4096;

/// What sets the surface's amplitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Amplitude {
    /// Root-mean-square height, m.
    RmsHeight(f64),
    /// Root-mean-square slope (dimensionless).
    RmsSlope(f64),
}

/// A random self-affine surface: `pixels x pixels` square pixels of
/// `pixel` (m), periodic over its extent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfAffine {
    /// Pixels per side.
    pub pixels: usize,
    /// Pixel size, m.
    pub pixel: f64,
    /// Hurst exponent H, 0 < H ≤ 1.
    pub hurst: f64,
    /// The shortest wavelength present, m (at least two pixels).
    pub short_cutoff: f64,
    /// The wavelength above which the spectrum is flat, m (at most the
    /// extent).
    pub long_cutoff: f64,
    /// The rms height or the rms slope asked.
    pub amplitude: Amplitude,
    /// The random stream's seed.
    pub seed: u64,
}

impl SelfAffine {
    /// Checks the parameters, each error naming its parameter.
    pub fn validate(&self) -> Result<(), SolverError> {
        let SelfAffine {
            pixels,
            pixel,
            hurst,
            short_cutoff,
            long_cutoff,
            amplitude,
            ..
        } = *self;
        if !(8..=MAX_PIXELS).contains(&pixels) {
            return Err(SolverError::invalid(
                "pixels",
                format!("{pixels} pixels per side: 8 to {MAX_PIXELS}"),
            ));
        }
        crate::error::positive("pixel", pixel, "the pixel size", " m")?;
        if !(hurst > 0.0 && hurst <= 1.0) {
            return Err(SolverError::invalid(
                "hurst",
                format!("the Hurst exponent is {hurst}: it must lie in (0, 1]"),
            ));
        }
        let extent = pixels as f64 * pixel;
        if !(short_cutoff.is_finite() && short_cutoff >= 2.0 * pixel) {
            return Err(SolverError::invalid(
                "short_cutoff",
                format!(
                    "the short cutoff ({short_cutoff:e} m) must be at least two pixels ({:e} m)",
                    2.0 * pixel
                ),
            ));
        }
        if !(long_cutoff.is_finite() && long_cutoff > short_cutoff && long_cutoff <= extent) {
            return Err(SolverError::invalid(
                "long_cutoff",
                format!(
                    "the long cutoff ({long_cutoff:e} m) must lie above the short cutoff ({short_cutoff:e} m) and within the generated extent ({extent:e} m, pixels x pixel)"
                ),
            ));
        }
        let (name, v) = match amplitude {
            Amplitude::RmsHeight(v) => ("rms_height", v),
            Amplitude::RmsSlope(v) => ("rms_slope", v),
        };
        crate::error::positive(name, v, "the amplitude", "")
    }

    /// The spectrum's shape at wavevector magnitude `q` (1/m), 1 on the
    /// roll-off plateau.
    pub fn shape(&self, q: f64) -> f64 {
        let (q_long, q_short) = (
            2.0 * std::f64::consts::PI / self.long_cutoff,
            2.0 * std::f64::consts::PI / self.short_cutoff,
        );
        if q == 0.0 || q > q_short {
            0.0
        } else if q <= q_long {
            1.0
        } else {
            (q / q_long).powf(-2.0 * (1.0 + self.hurst))
        }
    }

    /// The surface: heights (m) whose Fourier coefficients `a_k` are
    /// independent complex normals (real on the self-conjugate
    /// wavevectors, `a_{-k} = conj a_k`) of variance `C0 shape(q_k) / L²`,
    /// with `C0` such that the expected rms height (`Σ E|a_k|²`) or rms
    /// slope (`Σ q_k² E|a_k|²`) over this grid's wavevectors is the one
    /// asked. The mean height is zero.
    pub fn generate(&self) -> Result<Scan, SolverError> {
        self.validate()?;
        let n = self.pixels;
        let step = 2.0 * std::f64::consts::PI / (n as f64 * self.pixel);
        let signed = |i: usize| {
            if i <= n / 2 {
                i as f64
            } else {
                i as f64 - n as f64
            }
        };
        let q = |kx: usize, ky: usize| step * signed(kx).hypot(signed(ky));
        let (mut heights2, mut slopes2) = (0.0, 0.0);
        for ky in 0..n {
            for kx in 0..n {
                let (qk, s) = (q(kx, ky), self.shape(q(kx, ky)));
                heights2 += s;
                slopes2 += qk * qk * s;
            }
        }
        let variance_scale = match self.amplitude {
            Amplitude::RmsHeight(h) => h * h / heights2,
            Amplitude::RmsSlope(g) => g * g / slopes2,
        };
        let mut rng = ChaCha20Rng::seed_from_u64(self.seed);
        let mut a = vec![Complex64::new(0.0, 0.0); n * n];
        for ky in 0..n {
            for kx in 0..n {
                let (cx, cy) = ((n - kx) % n, (n - ky) % n);
                if (ky, kx) > (cy, cx) {
                    continue; // set with its conjugate
                }
                let (g1, g2) = normal_pair(&mut rng);
                let var = variance_scale * self.shape(q(kx, ky));
                if (ky, kx) == (cy, cx) {
                    a[ky * n + kx] = Complex64::new(var.sqrt() * g1, 0.0);
                } else {
                    let s = (0.5 * var).sqrt();
                    let v = Complex64::new(s * g1, s * g2);
                    a[ky * n + kx] = v;
                    a[cy * n + cx] = v.conj();
                }
            }
        }
        // h(x_j) = Σ_k a_k exp(+i k·x_j): the unnormalised inverse DFT,
        // rows then columns.
        let fft = FftPlannerScalar::new().plan_fft_inverse(n);
        for row in a.chunks_exact_mut(n) {
            fft.process(row);
        }
        let mut column = vec![Complex64::new(0.0, 0.0); n];
        for ix in 0..n {
            for (iy, c) in column.iter_mut().enumerate() {
                *c = a[iy * n + ix];
            }
            fft.process(&mut column);
            for (iy, c) in column.iter().enumerate() {
                a[iy * n + ix] = *c;
            }
        }
        let heights = a.iter().map(|c| c.re).collect();
        Scan::new(n, n, self.pixel, self.pixel, heights)
    }
}

/// Two independent standard normals by Box–Muller from two uniforms of 53
/// bits each (the first in (0, 1], so its logarithm is finite).
fn normal_pair(rng: &mut ChaCha20Rng) -> (f64, f64) {
    let unit = 1.0 / (1u64 << 53) as f64;
    let u1 = ((rng.next_u64() >> 11) + 1) as f64 * unit;
    let u2 = (rng.next_u64() >> 11) as f64 * unit;
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (2.0 * std::f64::consts::PI * u2).sin_cos();
    (r * c, r * s)
}
