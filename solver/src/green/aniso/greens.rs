//! Real-space surface Green's function `G(x) = g(φ)/r` of the half-space: the angular
//! kernel `g(φ)` (3x3 real, 1/Pa) from `H(θ)` by the regularised principal-value
//! formula, tabulated once per material and interpolated (8-point Lagrange).

use crate::green::aniso::stroh::{
    surface_compliance_tensor, voigt_to_tensor, Tensor4, DEFAULT_OMEGA_POINTS,
};
use nalgebra::{Matrix3, Matrix6};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Default table resolution: angles per π (spacing π/1024 ≈ 0.18°).
pub const DEFAULT_ANGLES_PER_PI: usize = 1024;
const LAGRANGE_POINTS: usize = 8;

/// `H` sampled on the uniform half-grid θ_m = m π/(2K), m ∈ ℤ (stored for m < 2K,
/// the rest from `H(θ+π) = conj H(θ)`).
struct HTable {
    k: usize,
    h: Vec<Matrix3<Complex64>>,
}

impl HTable {
    fn new(t: &Tensor4, k: usize) -> Self {
        let h = (0..2 * k)
            .map(|m| {
                surface_compliance_tensor(t, m as f64 * PI / (2 * k) as f64, DEFAULT_OMEGA_POINTS)
            })
            .collect();
        HTable { k, h }
    }

    fn get(&self, idx: i64) -> Matrix3<Complex64> {
        let n2 = 2 * self.k as i64;
        let i = idx.rem_euclid(2 * n2);
        if i < n2 {
            self.h[i as usize]
        } else {
            self.h[(i - n2) as usize].map(|z| z.conj())
        }
    }
}

/// `g(φ)` from a function returning `H` at `φ + π/2` (first) and at the midpoint nodes
/// `φ + ψ_k`, `ψ_k = −π/2 + (k + ½)π/K` (second), K nodes.
///
/// `g = Re H(φ+π/2)/(2π) + (1/2π²) PV∫_{−π/2}^{π/2} Im H(φ+ψ)/cos ψ dψ`. The integrand is
/// π-periodic in ψ with one simple pole at ψ = ±π/2 (same point of the period);
/// `Im H(φ+π/2)·tan ψ` has the same pole and zero principal value, so subtracting it
/// leaves a smooth periodic integrand, integrated by the midpoint rule.
fn g_from_samples(
    h_perp: &Matrix3<Complex64>,
    k: usize,
    node: impl Fn(usize) -> Matrix3<Complex64>,
) -> Matrix3<f64> {
    let im_perp = h_perp.map(|z| z.im);
    let dpsi = PI / k as f64;
    let mut acc = Matrix3::<f64>::zeros();
    for j in 0..k {
        let psi = -0.5 * PI + (j as f64 + 0.5) * dpsi;
        let (s, c) = psi.sin_cos();
        let imh = node(j).map(|z| z.im);
        acc += (imh - im_perp * s) / c;
    }
    h_perp.map(|z| z.re) / (2.0 * PI) + acc * (dpsi / (2.0 * PI * PI))
}

/// Direct evaluation of `g(φ)` (no table), with `n_psi` midpoint nodes for the PV
/// integral. Slow; used as a reference.
pub fn g_direct(c: &Matrix6<f64>, phi: f64, n_psi: usize) -> Matrix3<f64> {
    let t = voigt_to_tensor(c);
    let hp = surface_compliance_tensor(&t, phi + 0.5 * PI, DEFAULT_OMEGA_POINTS);
    g_from_samples(&hp, n_psi, |j| {
        let psi = -0.5 * PI + (j as f64 + 0.5) * PI / n_psi as f64;
        surface_compliance_tensor(&t, phi + psi, DEFAULT_OMEGA_POINTS)
    })
}

/// Tabulated angular kernel: `G(x) = g(φ)/r`, φ = angle of x, rows = displacement,
/// columns = traction (qx, qy, p).
#[derive(Clone, Debug)]
pub struct AngularKernel {
    /// Table over [0, 2π): `n` entries at spacing `2π/n`, each row-major 3x3.
    table: Vec<[f64; 9]>,
    n: usize,
    inv_h: f64,
}

impl AngularKernel {
    /// Tabulate with the default resolution (1024 angles per π).
    pub fn new(c: &Matrix6<f64>) -> Self {
        Self::with_resolution(c, DEFAULT_ANGLES_PER_PI)
    }

    /// Tabulate with `k` angles per π (`k` ≥ 16).
    pub fn with_resolution(c: &Matrix6<f64>, k: usize) -> Self {
        assert!(k >= 16, "angles per π must be ≥ 16");
        let t = voigt_to_tensor(c);
        let ht = HTable::new(&t, k);
        let ki = k as i64;
        // φ_j = j π/K → half-grid index 2j; φ_j + π/2 → 2j + K; φ_j + ψ_l → 2j + 2l + 1 − K.
        let table: Vec<[f64; 9]> = (0..2 * k)
            .map(|j| {
                let j = j as i64;
                let g = g_from_samples(&ht.get(2 * j + ki), k, |l| {
                    ht.get(2 * j + 2 * l as i64 + 1 - ki)
                });
                let mut a = [0.0; 9];
                for r in 0..3 {
                    for s in 0..3 {
                        a[3 * r + s] = g[(r, s)];
                    }
                }
                a
            })
            .collect();
        let n = 2 * k;
        AngularKernel {
            table,
            n,
            inv_h: n as f64 / (2.0 * PI),
        }
    }

    /// Interpolated `g(φ)` as a row-major array (fast path).
    #[inline]
    pub fn g_array(&self, phi: f64) -> [f64; 9] {
        let t = phi * self.inv_h;
        let fl = t.floor();
        let u = t - fl;
        let base = fl as i64 - (LAGRANGE_POINTS as i64 / 2 - 1);
        let n = self.n as i64;
        if u == 0.0 {
            return self.table[(fl as i64).rem_euclid(n) as usize];
        }
        // Lagrange weights on nodes at offsets d_k = k − 3 (k = 0..7) for fraction u.
        const DEN: [f64; LAGRANGE_POINTS] =
            [-5040.0, 720.0, -240.0, 144.0, -144.0, 240.0, -720.0, 5040.0];
        let mut left = [1.0; LAGRANGE_POINTS];
        let mut right = [1.0; LAGRANGE_POINTS];
        for k in 1..LAGRANGE_POINTS {
            left[k] = left[k - 1] * (u - (k as f64 - 4.0));
        }
        for k in (0..LAGRANGE_POINTS - 1).rev() {
            right[k] = right[k + 1] * (u - (k as f64 - 2.0));
        }
        let mut out = [0.0; 9];
        let start = base.rem_euclid(n) as usize;
        for k in 0..LAGRANGE_POINTS {
            let w = left[k] * right[k] / DEN[k];
            let mut idx = start + k;
            if idx >= self.n {
                idx -= self.n;
            }
            let row = &self.table[idx];
            for (o, v) in out.iter_mut().zip(row.iter()) {
                *o += w * v;
            }
        }
        out
    }

    /// Interpolated `g(φ)` (1/Pa).
    pub fn g(&self, phi: f64) -> Matrix3<f64> {
        let a = self.g_array(phi);
        Matrix3::from_row_slice(&a)
    }
}
