//! Mindlin–Deresiewicz's closed forms for Table 1a (PHYSICS.md §5b): the
//! branches of a fretting loop and its energy per cycle, with coupling off.

use super::{LOAD_1A as P, MU_1A as MU};

/// Mindlin–Deresiewicz closed forms for Table 1a (Hertz radius a).
pub struct Md {
    /// Hertz radius, m.
    pub a: f64,
    /// δ* = 3μPK/(16a), m.
    pub delta_star: f64,
    /// K = (2 − ν)/G, 1/Pa.
    pub k: f64,
}

impl Md {
    pub fn new() -> Md {
        let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
        let a = (3.0 * P * r / (4.0 * e / (1.0 - nu * nu))).cbrt();
        let g = e / (2.0 * (1.0 + nu));
        let k = (2.0 - nu) / g;
        Md {
            a,
            delta_star: 3.0 * MU * P * k / (16.0 * a),
            k,
        }
    }

    /// First loading 0 → Q.
    pub fn first(&self, q: f64) -> f64 {
        self.delta_star * (1.0 - (1.0 - q / (MU * P)).powf(2.0 / 3.0))
    }

    /// Unloading from Q* to Q.
    pub fn unload(&self, q_star: f64, q: f64) -> f64 {
        let mp = MU * P;
        self.delta_star
            * (2.0 * (1.0 - (q_star - q) / (2.0 * mp)).powf(2.0 / 3.0)
                - (1.0 - q_star / mp).powf(2.0 / 3.0)
                - 1.0)
    }

    /// Reloading from −Q* to Q.
    pub fn reload(&self, q_star: f64, q: f64) -> f64 {
        -self.unload(q_star, -q)
    }

    /// Energy per full cycle of amplitude Q*.
    pub fn energy(&self, q_star: f64) -> f64 {
        let mp = MU * P;
        let x = q_star / mp;
        9.0 * mp * mp * self.k / (10.0 * self.a)
            * (1.0 - (1.0 - x).powf(5.0 / 3.0) - 5.0 * x / 6.0 * (1.0 + (1.0 - x).powf(2.0 / 3.0)))
    }
}
