//! What a crystal's orientation does to a contact, from its surface
//! compliance alone (issue #39): the indentation modulus of Vlassak and Nix,
//! the ratio of tangential to normal compliance, and Willis's elliptical
//! Hertz contact. No grid, no solve: these are the continuum's values, the
//! references a solved case is compared with.
//!
//! `H(θ)` is the Fourier-domain surface compliance (`û = H t̂ / |k|` along
//! the in-plane direction θ); `H33` is real and π-periodic, so every mean
//! over θ is a trapezoid sum over [0, π), exact to round-off for this smooth
//! periodic integrand well before [`ANGLES`] samples (512 and 2048 samples
//! agree to 1e-15 on Cu[1 2 3]).

use crate::model::material::Material;
use std::f64::consts::PI;

/// Samples of H(θ) over [0, π) for the in-plane means.
pub const ANGLES: usize = 512;

/// Samples over [0, 2π) of the Willis contact's angular integrals.
pub const WILLIS_ANGLES: usize = 4096;

/// The in-plane means of the surface compliance, 1/Pa, from one pass over
/// [`ANGLES`] directions of [0, π) (trapezoid rule): `⟨H33⟩` and the
/// tangential `⟨(H11 + H22)/2⟩` (real parts).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InPlaneMeans {
    /// ⟨H33⟩.
    pub normal: f64,
    /// ⟨(H11 + H22)/2⟩.
    pub tangential: f64,
}

impl InPlaneMeans {
    /// The means of `m`'s surface compliance.
    pub fn of(m: &Material) -> Self {
        let (mut normal, mut tangential) = (0.0, 0.0);
        for k in 0..ANGLES {
            let h = m.surface_compliance(PI * k as f64 / ANGLES as f64);
            normal += h[(2, 2)].re;
            tangential += 0.5 * (h[(0, 0)].re + h[(1, 1)].re);
        }
        InPlaneMeans {
            normal: normal / ANGLES as f64,
            tangential: tangential / ANGLES as f64,
        }
    }

    /// The indentation modulus M, Pa, of Vlassak and Nix (1993, 1994): the
    /// modulus of the isotropic half-space whose point-load displacement
    /// has the same mean over in-plane directions, `M = 1/(π ⟨g33⟩)` for
    /// the real-space Green's function `u3 = g33(φ) P / r`, equivalently
    /// `M = 2/⟨H33⟩` in Fourier space (the mean is the zeroth angular
    /// harmonic, which the transform of a function homogeneous of degree
    /// −1 keeps up to the factor 2π). An isotropic half-space gives
    /// `E/(1 − ν²)`. Substrate alone: an elastic ball adds its own
    /// compliance (see [`willis_contact`]).
    pub fn indentation_modulus(&self) -> f64 {
        2.0 / self.normal
    }

    /// The ratio of tangential to normal surface compliance, each averaged
    /// over in-plane directions: `⟨(H11 + H22)/2⟩ / ⟨H33⟩`. An isotropic
    /// half-space gives `(2 − ν)/(2(1 − ν))`, 1.214 at ν = 0.3; a larger
    /// ratio means a softer tangential response for the same normal one (a
    /// smaller stick zone and more energy per fretting cycle at the same
    /// force).
    pub fn compliance_ratio(&self) -> f64 {
        self.tangential / self.normal
    }
}

/// [`InPlaneMeans::indentation_modulus`] of `m`, Pa.
pub fn indentation_modulus(m: &Material) -> f64 {
    InPlaneMeans::of(m).indentation_modulus()
}

/// Willis's frictionless contact of a sphere on an anisotropic half-space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WillisContact {
    /// Long semi-axis, m.
    pub long_m: f64,
    /// Short semi-axis, m.
    pub short_m: f64,
    /// Direction of the long axis from x, rad, in [0, π).
    pub long_angle_rad: f64,
    /// Peak pressure `3P/(2π a b)`, Pa.
    pub p_max_pa: f64,
    /// Approach of the sphere, m.
    pub approach_m: f64,
}

/// Willis's solution (Willis 1966) of a sphere of radius `radius` (m)
/// pressed with `load` (N) into a half-space of normal compliance `h33(θ)`
/// (1/Pa; the sum of both bodies' for an elastic ball): the pressure is
/// `p₀ √(1 − xᵀAx)` on an ellipse, and the normal displacement it makes
/// inside the ellipse is `(ab p₀/8) ∫ h33(θ)/s(θ) [1 − (n·x)²/s(θ)²] dθ`,
/// `n = (cos θ, sin θ)`, `s(θ) = |L n|` with `L` the semi-axes (the Fourier
/// transform of the half-ellipsoid integrated along each direction).
/// Matching the sphere's profile makes `M = ∫ h33 n nᵀ/s³ dθ` a multiple of
/// the identity, which fixes the axes ratio and orientation (solved by
/// Newton's method); `a³`, `p₀` and the approach (the displacement at the
/// centre) follow from the load.
pub fn willis_contact(h33: &dyn Fn(f64) -> f64, load: f64, radius: f64) -> WillisContact {
    let m = WILLIS_ANGLES;
    let table: Vec<(f64, f64)> = (0..m)
        .map(|k| {
            let th = 2.0 * PI * k as f64 / m as f64;
            (th, h33(th))
        })
        .collect();
    let d = 2.0 * PI / m as f64;
    // s(θ) for semi-axes (1, e), the first along φ.
    let s_of = |th: f64, e: f64, phi: f64| {
        let (s, c) = (th - phi).sin_cos();
        (c * c + e * e * s * s).sqrt()
    };
    let moment = |e: f64, phi: f64| {
        let mut mm = [0.0; 3];
        for &(th, h) in &table {
            let sv = s_of(th, e, phi);
            let w = h / (sv * sv * sv);
            let (s, c) = th.sin_cos();
            mm[0] += w * c * c;
            mm[1] += w * s * s;
            mm[2] += w * c * s;
        }
        [mm[0] * d, mm[1] * d, mm[2] * d]
    };
    let residual = |e: f64, phi: f64| {
        let mm = moment(e, phi);
        let t = mm[0] + mm[1];
        [(mm[0] - mm[1]) / t, 2.0 * mm[2] / t]
    };
    // Newton in (ln e, φ) with a finite-difference Jacobian, from an
    // ellipse (at e = 1 the orientation is undetermined and the Jacobian
    // singular), steps limited to 0.2. A circular contact (isotropic in the
    // plane) stops at the first residual below 1e-14.
    let (mut le, mut phi) = (-0.05_f64, 0.1_f64);
    for _ in 0..60 {
        let f = residual(le.exp(), phi);
        if f[0].hypot(f[1]) < 1e-14 {
            break;
        }
        let h = 1e-6;
        let fe = residual((le + h).exp(), phi);
        let fp = residual(le.exp(), phi + h);
        let j = [
            [(fe[0] - f[0]) / h, (fp[0] - f[0]) / h],
            [(fe[1] - f[1]) / h, (fp[1] - f[1]) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let dl = (j[1][1] * f[0] - j[0][1] * f[1]) / det;
        let dp = (j[0][0] * f[1] - j[1][0] * f[0]) / det;
        let scale = (0.2 / dl.abs().max(dp.abs())).min(1.0);
        le -= scale * dl;
        phi -= scale * dp;
    }
    let e = le.exp();
    let mm = moment(e, phi);
    let mt = 0.5 * (mm[0] + mm[1]);
    // (a b p₀/8) M/a³ = I/(2R) with p₀ = 3P/(2π a b): a³ = 3 P R mt/(8π).
    let a = (3.0 * load * radius * mt / (8.0 * PI)).cbrt();
    let b = e * a;
    let p0 = 3.0 * load / (2.0 * PI * a * b);
    // At the centre: δ = (a b p₀/8) ∫ h33/s dθ, s for semi-axes (a, b).
    let centre: f64 = table.iter().map(|&(th, h)| h / s_of(th, e, phi)).sum();
    let approach = a * b * p0 / 8.0 * centre * d / a;
    let (long, short, mut dir) = if a >= b {
        (a, b, phi)
    } else {
        (b, a, phi + 0.5 * PI)
    };
    dir = dir.rem_euclid(PI);
    WillisContact {
        long_m: long,
        short_m: short,
        long_angle_rad: dir,
        p_max_pa: p0,
        approach_m: approach,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isotropic_half_space_gives_its_plane_strain_modulus_and_hertz() {
        let (e, nu) = (210e9, 0.3);
        let m = Material::isotropic("Fe", e, nu).unwrap();
        let es = e / (1.0 - nu * nu);
        let means = InPlaneMeans::of(&m);
        assert!((means.indentation_modulus() / es - 1.0).abs() < 1e-12);
        let ratio = (2.0 - nu) / (2.0 * (1.0 - nu));
        assert!((means.compliance_ratio() / ratio - 1.0).abs() < 1e-12);
        // Hertz: a³ = 3PR/(4E*), p₀ = 3P/(2πa²), δ = a²/R.
        let (p, r) = (20.0, 18e-3);
        let h = 2.0 / es;
        let w = willis_contact(&|_| h, p, r);
        let a = (3.0 * p * r / (4.0 * es)).cbrt();
        assert!((w.long_m / a - 1.0).abs() < 1e-12, "{} vs {a}", w.long_m);
        assert!((w.short_m / a - 1.0).abs() < 1e-12);
        assert!((w.p_max_pa / (3.0 * p / (2.0 * PI * a * a)) - 1.0).abs() < 1e-12);
        assert!((w.approach_m / (a * a / r) - 1.0).abs() < 1e-12);
    }
}
