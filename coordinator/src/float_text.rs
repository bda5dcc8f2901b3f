//! The text of a number in every table the coordinator writes
//! (`results.csv`, `curves.csv`, `history.csv`, …) and in the names the
//! config makes (an orientation's `[1 1 1]`). A foundation below both
//! `config` and `output` (not inside `output`, which `config` must not
//! import): one format for both.

/// Deterministic float text: shortest round-trip digits, exponent form
/// outside [1e-3, 1e7).
pub fn fmt_f64(v: f64) -> String {
    if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e7) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The text of a number that may be missing: empty when it is.
pub fn fmt_opt(v: Option<f64>) -> String {
    v.map(fmt_f64).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_text_is_shortest_round_trip() {
        for v in [0.0, 0.3, 1.0 / 3.0, 1.5e-5, 6.02e23, -2.5e-12, 1234.5] {
            let t = fmt_f64(v);
            assert_eq!(t.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{t}");
        }
        assert_eq!(fmt_f64(1.5e-5), "1.5e-5");
        assert_eq!(fmt_f64(15.0), "15");
    }
}
