//! Random self-affine surfaces (issue #61): the generated heights have the
//! rms height, the rms slope and the spectral slope `-2(1 + H)` that were
//! asked (averaged over seeds, within 2 %), measured on the heights alone
//! with a forward transform of their own; the same seed gives the same
//! bits (pinned values), another seed another surface.

use num_complex::Complex64;
use rustfft::FftPlanner;
use solver::{roughness, Amplitude, SelfAffine};

const PIXELS: usize = 256;
const PIXEL: f64 = 1e-6;

fn surface(amplitude: Amplitude, hurst: f64, seed: u64) -> SelfAffine {
    SelfAffine {
        pixels: PIXELS,
        pixel: PIXEL,
        hurst,
        short_cutoff: 8e-6,
        long_cutoff: 64e-6,
        amplitude,
        seed,
    }
}

/// `|ĥ_k|² / n⁴` of heights `h` (n x n) and each wavevector's magnitude:
/// Parseval gives `<h²> = Σ |ĥ_k|² / n⁴` and `<|∇h|²> = Σ q² |ĥ_k|² / n⁴`.
fn spectrum(h: &[f64], n: usize, pixel: f64) -> Vec<(f64, f64)> {
    let mut a: Vec<Complex64> = h.iter().map(|&v| Complex64::new(v, 0.0)).collect();
    let fft = FftPlanner::new().plan_fft_forward(n);
    for row in a.chunks_exact_mut(n) {
        fft.process(row);
    }
    let mut col = vec![Complex64::new(0.0, 0.0); n];
    for ix in 0..n {
        for iy in 0..n {
            col[iy] = a[iy * n + ix];
        }
        fft.process(&mut col);
        for iy in 0..n {
            a[iy * n + ix] = col[iy];
        }
    }
    let step = 2.0 * std::f64::consts::PI / (n as f64 * pixel);
    let signed = |i: usize| {
        if i <= n / 2 {
            i as f64
        } else {
            i as f64 - n as f64
        }
    };
    let n4 = (n as f64).powi(4);
    (0..n * n)
        .map(|i| {
            let q = step * signed(i % n).hypot(signed(i / n));
            (q, a[i].norm_sqr() / n4)
        })
        .collect()
}

#[test]
fn self_affine_rms_height_slope_and_spectral_slope_within_2pct_over_seeds() {
    let seeds = 0..12u64;
    for hurst in [0.3, 0.8] {
        // The rms height asked.
        let asked_h = 1.0e-6;
        let mut h2 = 0.0;
        for seed in seeds.clone() {
            let s = surface(Amplitude::RmsHeight(asked_h), hurst, seed)
                .generate()
                .unwrap();
            h2 += s.heights.iter().map(|v| v * v).sum::<f64>() / s.heights.len() as f64;
        }
        let rms_h = (h2 / seeds.clone().count() as f64).sqrt();
        // The rms slope asked; the spectral slope from the same surfaces.
        let asked_g = 0.1;
        let (mut g2, mut sdq2) = (0.0, 0.0);
        let bins = 12;
        let spec = surface(Amplitude::RmsSlope(asked_g), hurst, 0);
        let (q_lo, q_hi) = (
            1.5 * 2.0 * std::f64::consts::PI / spec.long_cutoff,
            2.0 * std::f64::consts::PI / spec.short_cutoff / 1.5,
        );
        let mut binned = vec![(0.0, 0usize); bins];
        for seed in seeds.clone() {
            let s = surface(Amplitude::RmsSlope(asked_g), hurst, seed)
                .generate()
                .unwrap();
            let spectrum = spectrum(&s.heights, PIXELS, PIXEL);
            g2 += spectrum.iter().map(|(q, c)| q * q * c).sum::<f64>();
            sdq2 += roughness(&s.heights, PIXELS, PIXELS, PIXEL, PIXEL)
                .sdq
                .powi(2);
            for (q, c) in spectrum {
                if q >= q_lo && q < q_hi {
                    let b = ((q / q_lo).ln() / (q_hi / q_lo).ln() * bins as f64) as usize;
                    binned[b].0 += c;
                    binned[b].1 += 1;
                }
            }
        }
        let count = seeds.clone().count() as f64;
        let rms_g = (g2 / count).sqrt();
        let sdq = (sdq2 / count).sqrt();
        // Least-squares slope of log C against log q over the bins' centres.
        let points: Vec<(f64, f64)> = binned
            .iter()
            .enumerate()
            .filter(|(_, (_, k))| *k > 0)
            .map(|(b, (c, k))| {
                let q = q_lo * (q_hi / q_lo).powf((b as f64 + 0.5) / bins as f64);
                (q.ln(), (c / *k as f64).ln())
            })
            .collect();
        let m = points.len() as f64;
        let (sx, sy) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
        let (sxx, sxy) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x * x, b + x * y));
        let slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
        let expected = -2.0 * (1.0 + hurst);
        println!(
            "H = {hurst}: rms height {:.4} µm (asked {:.4}, {:+.2} %), rms slope {rms_g:.5} (asked {asked_g}, {:+.2} %; Sdq by differences {sdq:.5}), PSD slope {slope:.4} (expected {expected}, {:+.2} %)",
            rms_h * 1e6,
            asked_h * 1e6,
            100.0 * (rms_h / asked_h - 1.0),
            100.0 * (rms_g / asked_g - 1.0),
            100.0 * (slope / expected - 1.0)
        );
        assert!((rms_h / asked_h - 1.0).abs() < 0.02, "rms height {rms_h:e}");
        assert!((rms_g / asked_g - 1.0).abs() < 0.02, "rms slope {rms_g}");
        assert!((slope / expected - 1.0).abs() < 0.02, "PSD slope {slope}");
        // Differences see a little less slope than the spectrum (at most
        // 10 % on the shortest wavelength, 8 pixels).
        assert!(sdq < rms_g && sdq > 0.9 * rms_g, "{sdq} {rms_g}");
    }
}

#[test]
fn self_affine_same_seed_same_bits_other_seed_other_surface() {
    let a = surface(Amplitude::RmsHeight(1e-6), 0.8, 42)
        .generate()
        .unwrap();
    let b = surface(Amplitude::RmsHeight(1e-6), 0.8, 42)
        .generate()
        .unwrap();
    let c = surface(Amplitude::RmsHeight(1e-6), 0.8, 43)
        .generate()
        .unwrap();
    assert_eq!(a.heights, b.heights);
    assert_ne!(a.heights, c.heights);
    // Pinned bits: a change of the stream, the normals or the transform
    // shows here (ChaCha20 seeded by 42; rustfft's scalar planner).
    let pins: Vec<u64> = [0, 1, 12345, 65535]
        .iter()
        .map(|&i| a.heights[i].to_bits())
        .collect();
    println!("{pins:?}");
    assert_eq!(pins, PINS);
}

const PINS: [u64; 4] = [
    13742686182292151842,
    13741968988818953130,
    4517874412395644448,
    13742282115102407898,
];
