//! Surface compliance `H(θ)` of an anisotropic elastic half-space (z into the body),
//! computed with the Barnett–Lothe integral formalism, plus Voigt → tensor conversion.
//! Owns the sign conventions of `Ĝ(η) = H(θ)/ρ` (see `surface_compliance`).

use nalgebra::{Matrix3, Matrix6};
use num_complex::Complex64;

/// Full fourth-order stiffness tensor `C_ijkl` (Pa).
pub type Tensor4 = [[[[f64; 3]; 3]; 3]; 3];

/// Default number of trapezoid points over the ω-period [0, π) of the
/// Barnett–Lothe integrals. The integrand is smooth and periodic, so the rule
/// converges geometrically; 128 points reach ~1e-14 for cubic metals.
pub const DEFAULT_OMEGA_POINTS: usize = 128;

/// Engineering Voigt index (0-based) of the tensor index pair (i, j):
/// xx→0, yy→1, zz→2, yz→3, xz→4, xy→5.
pub fn voigt_index(i: usize, j: usize) -> usize {
    match (i, j) {
        (0, 0) => 0,
        (1, 1) => 1,
        (2, 2) => 2,
        (1, 2) | (2, 1) => 3,
        (0, 2) | (2, 0) => 4,
        _ => 5,
    }
}

/// Expand a 6x6 engineering-Voigt stiffness (σ = C ε, ε₄ = 2ε_yz, …) into `C_ijkl`.
pub fn voigt_to_tensor(c: &Matrix6<f64>) -> Tensor4 {
    let mut t = [[[[0.0; 3]; 3]; 3]; 3];
    for (i, ti) in t.iter_mut().enumerate() {
        for (j, tij) in ti.iter_mut().enumerate() {
            for (k, tijk) in tij.iter_mut().enumerate() {
                for (l, v) in tijk.iter_mut().enumerate() {
                    *v = c[(voigt_index(i, j), voigt_index(k, l))];
                }
            }
        }
    }
    t
}

/// `X_ik = C_ijks a_j b_s` for two direction vectors.
pub fn contract(t: &Tensor4, a: &[f64; 3], b: &[f64; 3]) -> Matrix3<f64> {
    let mut out = Matrix3::zeros();
    for i in 0..3 {
        for k in 0..3 {
            let mut s = 0.0;
            for j in 0..3 {
                for l in 0..3 {
                    s += t[i][j][k][l] * a[j] * b[l];
                }
            }
            out[(i, k)] = s;
        }
    }
    out
}

/// Barnett–Lothe matrices for the plane spanned by `n = (cos θ, sin θ, 0)` and
/// `m = (0, 0, 1)`: `S = (1/π)∫N₁`, `H = (1/π)∫N₂`, `L = −(1/π)∫N₃` over ω ∈ [0, π),
/// with `n(ω) = n cos ω + m sin ω`, `m(ω) = −n sin ω + m cos ω`,
/// `N₁ = −T⁻¹Rᵀ`, `N₂ = T⁻¹`, `N₃ = R T⁻¹ Rᵀ − Q`.
#[derive(Clone, Debug)]
pub struct BarnettLothe {
    pub s: Matrix3<f64>,
    pub h: Matrix3<f64>,
    pub l: Matrix3<f64>,
}

/// Compute the Barnett–Lothe matrices S, H, L (trapezoid rule, `n_omega` points).
pub fn barnett_lothe(t: &Tensor4, theta: f64, n_omega: usize) -> BarnettLothe {
    let n = [theta.cos(), theta.sin(), 0.0];
    let m = [0.0, 0.0, 1.0];
    let q0 = contract(t, &n, &n);
    let r0 = contract(t, &n, &m);
    let t0 = contract(t, &m, &m);
    let r0t = r0.transpose();
    let rsym = r0 + r0t;
    let mut s = Matrix3::zeros();
    let mut h = Matrix3::zeros();
    let mut l = Matrix3::zeros();
    for k in 0..n_omega {
        let w = std::f64::consts::PI * k as f64 / n_omega as f64;
        let (sw, cw) = w.sin_cos();
        // Q, R, T are quadratic forms in (n(ω), m(ω)).
        let q = q0 * (cw * cw) + rsym * (cw * sw) + t0 * (sw * sw);
        let r = q0 * (-cw * sw) + r0 * (cw * cw) - r0t * (sw * sw) + t0 * (cw * sw);
        let tt = q0 * (sw * sw) - rsym * (cw * sw) + t0 * (cw * cw);
        let ti = tt
            .try_inverse()
            .expect("acoustic tensor T(ω) singular: stiffness not positive definite");
        let ti = (ti + ti.transpose()) * 0.5;
        let rt = r.transpose();
        s -= ti * rt;
        h += ti;
        l -= r * ti * rt - q;
    }
    let f = 1.0 / n_omega as f64;
    BarnettLothe {
        s: s * f,
        h: h * f,
        l: l * f,
    }
}

/// `H(θ)` from a precomputed tensor with an explicit number of ω points.
///
/// `H(θ) = (I + i S) L⁻¹`, equivalently `(I + i S)(I + S²)⁻¹ H_BL`
/// (Barnett–Lothe identity `H_BL L = I + S²`). Note: this is *not*
/// `H_BL ± i S H_BL` — that form differs by the non-scalar factor `(I + S²)⁻¹`.
pub fn surface_compliance_tensor(t: &Tensor4, theta: f64, n_omega: usize) -> Matrix3<Complex64> {
    let bl = barnett_lothe(t, theta, n_omega);
    let li =
        bl.l.try_inverse()
            .expect("Barnett–Lothe L singular: stiffness not positive definite");
    let li = (li + li.transpose()) * 0.5;
    let sli = bl.s * li;
    // S L⁻¹ is antisymmetric in exact arithmetic; project to keep H exactly Hermitian.
    let sli = (sli - sli.transpose()) * 0.5;
    Matrix3::from_fn(|i, j| Complex64::new(li[(i, j)], sli[(i, j)]))
}

/// Surface compliance `H(θ)` (1/Pa): `Ĝ(η) = H(θ)/ρ` with `f̂(η) = ∫∫ f e^{iη·x} dA`,
/// `η = ρ(cos θ, sin θ)`, rows = displacement (x, y, z), columns = traction
/// (qx, qy, p), z into the body. Hermitian positive definite, `H(θ+π) = conj H(θ)`.
pub fn surface_compliance(c: &Matrix6<f64>, theta: f64) -> Matrix3<Complex64> {
    surface_compliance_tensor(&voigt_to_tensor(c), theta, DEFAULT_OMEGA_POINTS)
}

/// Independent (sextic eigenvalue) route, valid only for materials with three
/// distinct Stroh roots: `H = −i A B⁻¹` built from the roots with `Im p < 0`
/// (displacement `a e^{−iρ(n·x + p z)}` decays into z > 0). Used as a test oracle.
pub fn surface_compliance_sextic(c: &Matrix6<f64>, theta: f64) -> Matrix3<Complex64> {
    // Work with C / max|C| so the 6x6 eigenproblem is well balanced.
    let scale = c.amax();
    let t = voigt_to_tensor(&(c / scale));
    let n = [theta.cos(), theta.sin(), 0.0];
    let m = [0.0, 0.0, 1.0];
    let q = contract(&t, &n, &n);
    let r = contract(&t, &n, &m);
    let tt = contract(&t, &m, &m);
    let ti = tt.try_inverse().expect("T singular");
    let n1 = -ti * r.transpose();
    let n3 = r * ti * r.transpose() - q;
    let mut big = Matrix6::zeros();
    big.fixed_view_mut::<3, 3>(0, 0).copy_from(&n1);
    big.fixed_view_mut::<3, 3>(0, 3).copy_from(&ti);
    big.fixed_view_mut::<3, 3>(3, 0).copy_from(&n3);
    big.fixed_view_mut::<3, 3>(3, 3).copy_from(&n1.transpose());
    let eig = big.complex_eigenvalues();
    let roots: Vec<Complex64> = eig.iter().copied().filter(|p| p.im < 0.0).collect();
    assert_eq!(roots.len(), 3, "expected three roots with Im p < 0");
    let cq = q.map(|v| Complex64::new(v, 0.0));
    let cr = r.map(|v| Complex64::new(v, 0.0));
    let ct = tt.map(|v| Complex64::new(v, 0.0));
    let mut a = Matrix3::<Complex64>::zeros();
    let mut b = Matrix3::<Complex64>::zeros();
    for (k, &p) in roots.iter().enumerate() {
        let mm = cq + (cr + cr.transpose()) * p + ct * (p * p);
        let svd = mm.svd(false, true);
        let vt = svd.v_t.expect("v_t");
        let (imin, _) =
            svd.singular_values
                .iter()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |acc, (i, &s)| if s < acc.1 { (i, s) } else { acc },
                );
        let av = vt.row(imin).transpose().map(|z| z.conj());
        let bv = (cr.transpose() + ct * p) * av;
        a.set_column(k, &av);
        b.set_column(k, &bv);
    }
    let bi = b.try_inverse().expect("B singular");
    a * bi * Complex64::new(0.0, -1.0 / scale)
}
