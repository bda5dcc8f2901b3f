//! What a fatigue or yield check reads of a stress tensor: the tensor of
//! a Voigt vector, its principal stresses, von Mises, Tresca, and the peak
//! of a field. No grid, no material.

use nalgebra::Matrix3;

/// The symmetric tensor of a Voigt 6-vector.
pub fn tensor(s: [f64; 6]) -> Matrix3<f64> {
    Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2])
}

/// Principal stresses, largest first (nalgebra's symmetric eigenvalues).
///
/// The trigonometric closed form of the cubic (Smith 1961): a tenth of
/// nalgebra's iterative `symmetric_eigenvalues` per point (which took 4 %
/// of a sweep with `[stress]`); it agrees with it to 1e-8 of the tensor's
/// size where two principal stresses nearly coincide (the `acos` of a
/// value near ±1) and to round-off elsewhere
/// (`closed_form_principal_stresses_equal_nalgebras`).
pub fn principal(s: [f64; 6]) -> [f64; 3] {
    let [xx, yy, zz, yz, xz, xy] = s;
    let off = yz * yz + xz * xz + xy * xy;
    if off == 0.0 {
        let mut v = [xx, yy, zz];
        v.sort_by(|a, b| b.total_cmp(a));
        return v;
    }
    let q = (xx + yy + zz) / 3.0;
    let (a, b, c) = (xx - q, yy - q, zz - q);
    let p = ((a * a + b * b + c * c + 2.0 * off) / 6.0).sqrt();
    // det(A − qI) / (2p³), the cosine of 3φ
    let det = a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz);
    let r = (det / (2.0 * p * p * p)).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let first = q + 2.0 * p * phi.cos();
    let third = q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos();
    [first, 3.0 * q - first - third, third]
}

/// Von Mises equivalent stress.
pub fn von_mises(s: [f64; 6]) -> f64 {
    let [xx, yy, zz, yz, xz, xy] = s;
    (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2))
        + 3.0 * (yz * yz + xz * xz + xy * xy))
        .sqrt()
}

/// Tresca: the maximum shear stress `(σ₁ − σ₃)/2`.
pub fn tresca(s: [f64; 6]) -> f64 {
    tresca_of(principal(s))
}

/// The largest principal stress `σ₁`.
pub fn max_principal(s: [f64; 6]) -> f64 {
    principal(s)[0]
}

/// Tresca of the principal stresses `[σ₁, σ₂, σ₃]` (largest first).
pub fn tresca_of([a, _, c]: [f64; 3]) -> f64 {
    0.5 * (a - c)
}

/// A maximum of a field: its value and index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peak {
    /// The value.
    pub value: f64,
    /// The index of the point in its field.
    pub index: usize,
}

/// The largest value of `values` and where it is (the first of equals).
pub fn peak(values: &[f64]) -> Option<Peak> {
    values
        .iter()
        .enumerate()
        .fold(None, |best: Option<Peak>, (i, &v)| match best {
            Some(b) if b.value >= v => Some(b),
            _ if v.is_nan() => best,
            _ => Some(Peak { value: v, index: i }),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form principal stresses against nalgebra's symmetric
    /// eigenvalues: random tensors, tensors with two or three equal
    /// principal stresses turned by random rotations, and diagonal ones.
    #[test]
    fn closed_form_principal_stresses_equal_nalgebras() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let voigt = |m: &Matrix3<f64>| {
            [
                m[(0, 0)],
                m[(1, 1)],
                m[(2, 2)],
                m[(1, 2)],
                m[(0, 2)],
                m[(0, 1)],
            ]
        };
        let mut worst: [f64; 2] = [0.0; 2];
        for k in 0..20000 {
            let m = if k % 2 == 0 {
                tensor(std::array::from_fn(|_| 1e9 * uniform()))
            } else {
                // two (or, every fourth, three) equal principal stresses
                let d = 1e9 * uniform();
                let e = if k % 4 == 1 { d } else { 1e9 * uniform() };
                let axis = nalgebra::Vector3::new(uniform(), uniform(), uniform());
                let rot = nalgebra::Rotation3::from_scaled_axis(axis * 3.0);
                rot.matrix()
                    * Matrix3::from_diagonal(&nalgebra::Vector3::new(d, d, e))
                    * rot.matrix().transpose()
            };
            let s = voigt(&m);
            let e = m.symmetric_eigenvalues();
            let mut want = [e[0], e[1], e[2]];
            want.sort_by(|a, b| b.total_cmp(a));
            let got = principal(s);
            let size = m.norm();
            let err = (0..3).map(|i| (got[i] - want[i]).abs()).fold(0.0, f64::max) / size;
            worst[k % 2] = worst[k % 2].max(err);
        }
        let diag = principal([3.0, -1.0, 2.0, 0.0, 0.0, 0.0]);
        assert_eq!(diag, [3.0, 2.0, -1.0]);
        eprintln!(
            "principal stresses against nalgebra: random {:.1e}, repeated {:.1e} of |σ|",
            worst[0], worst[1]
        );
        assert!(worst[0] < 1e-13 && worst[1] < 1e-7, "{worst:?}");
    }
}
