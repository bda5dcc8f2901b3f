//! The fatigue criteria of one point's states: Smith–Watson–Topper on the
//! planes normal to the surface and Crossland's parameter. Stress tensors
//! in, a number out; where the points are and which states is
//! `crate::post::stress_summary`'s.
//!
//! ```
//! use solver::stress::swt_point;
//! // Uniaxial σxx = ±σa on an isotropic surface: SWT = σa²/E on the plane
//! // whose normal is x.
//! let (e, nu, sa) = (200e9, 0.3, 100e6);
//! let c = solver::Isotropic::new(e, nu).unwrap().stiffness();
//! let s = c.try_inverse().unwrap();
//! let at = swt_point(&[[sa, 0.0, 0.0, 0.0, 0.0, 0.0], [-sa, 0.0, 0.0, 0.0, 0.0, 0.0]], &s);
//! assert!((at.value / (sa * sa / e) - 1.0).abs() < 1e-12);
//! assert_eq!(at.angle_deg, 0.0);
//! ```

use nalgebra::Matrix6;

/// Directions of the critical-plane search (one per degree over a half turn).
pub const SWT_DIRECTIONS: usize = 180;

/// SWT at one surface point over its states: the critical plane's value,
/// angle, σn,max and εa (`solver::stress_summary::SWT_DEFINITION` says it in words). `compliance` is `C⁻¹`
/// in Voigt order xx, yy, zz, yz, xz, xy with engineering shear strains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwtPoint {
    /// SWT, Pa.
    pub value: f64,
    /// Normal of the critical plane from x, degrees.
    pub angle_deg: f64,
    /// σn,max, Pa.
    pub sigma_max: f64,
    /// εa.
    pub strain_amplitude: f64,
}

/// SWT of the states `states` at one point (`solver::stress_summary::SWT_DEFINITION` says it in words).
pub fn swt_point(states: &[[f64; 6]], compliance: &Matrix6<f64>) -> SwtPoint {
    let strains: Vec<[f64; 6]> = states
        .iter()
        .map(|s| {
            let v = compliance * nalgebra::Vector6::from_column_slice(s);
            [v[0], v[1], v[2], v[3], v[4], v[5]]
        })
        .collect();
    swt_of_strains(states, &strains)
}

/// `(cos² t, sin² t, sin t cos t)` of the SWT planes' normals, made once
/// (a sine and cosine per direction and cell were a tenth of a sweep's
/// time with `[stress]`).
fn swt_directions() -> &'static [(f64, f64, f64); SWT_DIRECTIONS] {
    static TABLE: std::sync::OnceLock<[(f64, f64, f64); SWT_DIRECTIONS]> =
        std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|k| {
            let deg = k as f64 * 180.0 / SWT_DIRECTIONS as f64;
            let (s, c) = deg.to_radians().sin_cos();
            (c * c, s * s, s * c)
        })
    })
}

fn swt_of_strains(states: &[[f64; 6]], strains: &[[f64; 6]]) -> SwtPoint {
    let mut best = SwtPoint {
        value: 0.0,
        angle_deg: 0.0,
        sigma_max: 0.0,
        strain_amplitude: 0.0,
    };
    let single = states.len() == 1;
    for (k, &(cc, ss, sc)) in swt_directions().iter().enumerate() {
        let deg = k as f64 * 180.0 / SWT_DIRECTIONS as f64;
        let (mut smax, mut emax, mut emin) = (f64::NEG_INFINITY, f64::NEG_INFINITY, f64::INFINITY);
        for (t, e) in states.iter().zip(strains) {
            smax = smax.max(t[0] * cc + t[1] * ss + 2.0 * t[5] * sc);
            // engineering shear strain: ε_n = εxx c² + εyy s² + γxy s c
            let en = e[0] * cc + e[1] * ss + e[5] * sc;
            emax = emax.max(en);
            emin = emin.min(en);
        }
        let (sigma_max, amp) = if single {
            (smax.max(0.0), 0.5 * emax.abs())
        } else {
            (smax, 0.5 * (emax - emin))
        };
        let value = if sigma_max > 0.0 {
            sigma_max * amp
        } else {
            0.0
        };
        if value > best.value {
            best = SwtPoint {
                value,
                angle_deg: deg,
                sigma_max,
                strain_amplitude: amp,
            };
        }
    }
    best
}

/// Crossland's parameter of a point's states (`solver::stress_summary::CROSSLAND_DEFINITION` says it in words).
pub fn crossland_at(ts: &[[f64; 6]], alpha: f64) -> f64 {
    let dev = |t: &[f64; 6]| {
        let m = (t[0] + t[1] + t[2]) / 3.0;
        [t[0] - m, t[1] - m, t[2] - m, t[3], t[4], t[5]]
    };
    let mut amp: f64 = 0.0;
    for i in 0..ts.len() {
        for j in i + 1..ts.len() {
            let (a, b) = (dev(&ts[i]), dev(&ts[j]));
            let d: [f64; 6] = std::array::from_fn(|k| 0.5 * (a[k] - b[k]));
            let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
                + d[3] * d[3]
                + d[4] * d[4]
                + d[5] * d[5];
            amp = amp.max(j2.sqrt());
        }
    }
    let sh = ts
        .iter()
        .map(|t| (t[0] + t[1] + t[2]) / 3.0)
        .fold(f64::NEG_INFINITY, f64::max);
    amp + alpha * sh
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compliance(e: f64, nu: f64) -> Matrix6<f64> {
        crate::Isotropic::new(e, nu)
            .unwrap()
            .stiffness()
            .try_inverse()
            .unwrap()
    }

    /// Uniaxial cyclic surface stress σxx = ±σa: by hand, on the plane of
    /// normal (cos t, sin t), σn = σ cos²t and εn = σ (cos²t − ν sin²t)/E;
    /// σn,max εa = σa² cos²t (cos²t − ν sin²t)/E, largest at t = 0: σa²/E.
    #[test]
    fn uniaxial_cycle_gives_sigma_a_squared_over_e_on_the_plane_normal_to_x() {
        let (e, nu, sa) = (210e9, 0.3, 300e6);
        let s = compliance(e, nu);
        let at = swt_point(&[[sa, 0., 0., 0., 0., 0.], [-sa, 0., 0., 0., 0., 0.]], &s);
        assert!((at.value / (sa * sa / e) - 1.0).abs() < 1e-12, "{at:?}");
        assert_eq!(at.angle_deg, 0.0);
        assert!((at.sigma_max / sa - 1.0).abs() < 1e-12);
        assert!((at.strain_amplitude / (sa / e) - 1.0).abs() < 1e-12);
        // The same state turned by 30° about z: the critical plane turns with it.
        let (sn, cs) = 30f64.to_radians().sin_cos();
        let r = [sa * cs * cs, sa * sn * sn, 0., 0., 0., sa * sn * cs];
        let m = r.map(|v| -v);
        let at = swt_point(&[r, m], &s);
        assert!((at.value / (sa * sa / e) - 1.0).abs() < 1e-12);
        assert!((at.angle_deg - 30.0).abs() < 1e-9, "{at:?}");
    }

    /// One state: the cycle from the unloaded surface to it and back,
    /// σn,max = σ, εa = σ/(2E) on the plane normal to x.
    #[test]
    fn a_single_state_cycles_from_the_unloaded_surface() {
        let (e, nu, sg) = (200e9, 0.25, 100e6);
        let at = swt_point(&[[sg, 0., 0., 0., 0., 0.]], &compliance(e, nu));
        assert!((at.value / (sg * sg / (2.0 * e)) - 1.0).abs() < 1e-12);
        // Pure compression never opens a crack: 0.
        let at = swt_point(&[[-sg, -sg, -sg, 0., 0., 0.]], &compliance(e, nu));
        assert_eq!(at.value, 0.0);
    }

    /// A mean tension shifts σmax, not εa: σxx between σm − σa and σm + σa
    /// gives (σm + σa) σa / E.
    #[test]
    fn a_mean_stress_raises_sigma_max_only() {
        let (e, nu, sm, sa) = (150e9, 0.33, 80e6, 120e6);
        let at = swt_point(
            &[
                [sm + sa, 0., 0., 0., 0., 0.],
                [sm, 0., 0., 0., 0., 0.],
                [sm - sa, 0., 0., 0., 0., 0.],
            ],
            &compliance(e, nu),
        );
        assert!(
            (at.value / ((sm + sa) * sa / e) - 1.0).abs() < 1e-12,
            "{at:?}"
        );
    }
}
