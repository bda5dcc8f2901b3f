//! Where a padded transform pair's time goes, per grid side (issue #22):
//! `cargo run --release -p mpcontact-solver --example fft_stages -- 512 1024 2048`.
//!
//! For each side `N` it prints, in ns per cell and field (median of 15), the
//! row stage of a forward transform (`Fft2::forward_rows_padded`), a column
//! pass that transforms each column forward and back (`Fft2::column_pass`,
//! with the plans `Fft2::new` chose), and the inverse row stage
//! (`Fft2::inverse_rows_cropped`); then the µs of one column's forward and
//! inverse transform (best of 7), whole (one length-`2N` transform) and
//! split (two length-`N` transforms and the factors, see `solver::fft2`):
//! the measurement behind `SPLIT_SIDES`.

use num_complex::Complex64;
use rustfft::FftPlanner;
use solver::fft2::Fft2;
use std::time::Instant;

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("grid sides"))
        .collect();
    println!("n,rows_ns,columns_ns,inverse_ns,column_whole_us,column_split_us");
    for n in sizes {
        let (rows, columns, inverse) = stages(n);
        let (whole, split) = column_pair(n);
        println!("{n},{rows:.2},{columns:.2},{inverse:.2},{whole:.2},{split:.2}");
    }
}

/// Median ns per cell and field of the three stages of a transform pair.
fn stages(n: usize) -> (f64, f64, f64) {
    let reps = 15;
    let mut fft = Fft2::new(n);
    let t: Vec<f64> = (0..n * n).map(|i| ((i * 7) % 13) as f64).collect();
    let mut w0 = vec![Complex64::default(); fft.compact_len()];
    let mut w1 = w0.clone();
    let mut values = vec![0.0; fft.padded_len() / 2 + 1];
    let mut u = vec![0.0; n * n];
    let mut times: [Vec<f64>; 3] = Default::default();
    for _ in 0..reps {
        let s = Instant::now();
        fft.forward_rows_padded(&t, &mut w0);
        fft.forward_rows_padded(&t, &mut w1);
        times[0].push(s.elapsed().as_secs_f64());
        let s = Instant::now();
        fft.column_pass(
            (&mut w0, &mut w1),
            (true, true),
            &mut values,
            |_, c0, c1, cols| {
                cols.forward(c0);
                cols.forward(c1);
                cols.inverse(c0);
                cols.inverse(c1);
                0.0
            },
        );
        times[1].push(s.elapsed().as_secs_f64());
        let s = Instant::now();
        fft.inverse_rows_cropped(&w0, &mut u, false);
        fft.inverse_rows_cropped(&w1, &mut u, true);
        times[2].push(s.elapsed().as_secs_f64());
    }
    let [a, b, c] = times.map(|mut v| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2] * 1e9 / (2 * n * n) as f64
    });
    (a, b, c)
}

/// Best µs of a column's forward and inverse transform, whole and split.
fn column_pair(n: usize) -> (f64, f64) {
    let m = 2 * n;
    let mut planner = FftPlanner::<f64>::new();
    let (fwd, inv) = (planner.plan_fft_forward(m), planner.plan_fft_inverse(m));
    let (hf, hi) = (planner.plan_fft_forward(n), planner.plan_fft_inverse(n));
    let twiddles: Vec<Complex64> = (0..n)
        .map(|k| Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * k as f64 / m as f64))
        .collect();
    let mut col: Vec<Complex64> = (0..m).map(|i| Complex64::new(i as f64, 0.5)).collect();
    let mut scratch = vec![Complex64::default(); 2 * m];
    let count = ((1 << 22) / m).max(1);
    let scale = 1.0 / m as f64;
    let best = |f: &mut dyn FnMut()| {
        (0..7)
            .map(|_| {
                let s = Instant::now();
                for _ in 0..count {
                    f();
                }
                s.elapsed().as_secs_f64() * 1e6 / count as f64
            })
            .fold(f64::INFINITY, f64::min)
    };
    let whole = best(&mut || {
        col[n..].fill(Complex64::default());
        fwd.process_with_scratch(&mut col, &mut scratch);
        inv.process_with_scratch(&mut col, &mut scratch);
        col.iter_mut().for_each(|v| *v *= scale);
    });
    let split = best(&mut || {
        let (lo, hi_) = col.split_at_mut(n);
        for ((h, l), t) in hi_.iter_mut().zip(lo.iter()).zip(&twiddles) {
            *h = l * t;
        }
        hf.process_with_scratch(lo, &mut scratch);
        hf.process_with_scratch(hi_, &mut scratch);
        hi.process_with_scratch(lo, &mut scratch);
        hi.process_with_scratch(hi_, &mut scratch);
        for ((l, h), t) in lo.iter_mut().zip(hi_.iter()).zip(&twiddles) {
            *l += h * t.conj();
        }
        lo.iter_mut().for_each(|v| *v *= scale);
    });
    (whole, split)
}
