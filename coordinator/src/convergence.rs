//! Grid-convergence estimates from a ladder of solves of one case on
//! refined grids of the same domain: the best value and its error bar.
//! Pure arithmetic on (cell size, value) pairs; knows no physics and no
//! files.
//!
//! How an estimate is formed (docs/validation.md, "Convergence ladders"):
//! - one level: the value, no error (`single`);
//! - two levels: the finer value, error = the change between the two
//!   (`spread`: two values give no order, so nothing is extrapolated);
//! - three or more: the finest three. If their two changes have the same
//!   sign, shrink, and give an observed order p in [`MIN_ORDER`, `MAX_ORDER`],
//!   the value is Richardson-extrapolated with that p and the error is
//!   1.25 × |extrapolated − finest| (Roache's grid convergence index with
//!   its safety factor for an observed order, `richardson`). Otherwise the
//!   sequence is not in its asymptotic range: the value is the finest and the
//!   error the spread (max − min) of the finest three (`spread`) — never a
//!   made-up extrapolation.
//! - values equal on every level (K_E from the isotropic formula): that
//!   value, error 0 (`exact`).

use serde::Serialize;

/// How an error bar is formed, in words (summary.json).
pub const ERROR_ESTIMATE: &str = "1 level: none; 2 levels: finest value, error = |change|; 3+ levels: if the finest three change monotonically with an observed order p in [0.5, 4], Richardson extrapolation with p and error = 1.25 |extrapolated - finest| (GCI), else finest value with error = max - min of the finest three";

/// Smallest observed order accepted for extrapolation.
pub const MIN_ORDER: f64 = 0.5;
/// Largest observed order accepted for extrapolation.
pub const MAX_ORDER: f64 = 4.0;
/// Roache's safety factor for a three-grid observed order.
pub const SAFETY: f64 = 1.25;

/// How an [`Estimate`] was formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// One grid: no error estimate.
    Single,
    /// Equal on every grid.
    Exact,
    /// Richardson extrapolation with the observed order.
    Richardson,
    /// The finest value with the spread of the finest levels.
    Spread,
}

impl Method {
    /// The text written to files.
    pub fn as_str(self) -> &'static str {
        match self {
            Method::Single => "single",
            Method::Exact => "exact",
            Method::Richardson => "richardson",
            Method::Spread => "spread",
        }
    }
}

/// The best value of a ladder and its error bar.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Best value.
    pub value: f64,
    /// Error estimate (None with one level).
    pub err: Option<f64>,
    /// How it was formed.
    pub method: Method,
    /// Observed order of convergence (Richardson only).
    pub order: Option<f64>,
}

/// The estimate from `levels`: (cell size, value), coarsest first, cell
/// sizes strictly decreasing. None for an empty ladder.
pub fn estimate(levels: &[(f64, f64)]) -> Option<Estimate> {
    let (&(_, finest), rest) = levels.split_last()?;
    let single = Estimate {
        value: finest,
        err: None,
        method: Method::Single,
        order: None,
    };
    let spread = |vals: &[(f64, f64)]| {
        let (lo, hi) = vals
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &(_, v)| {
                (l.min(v), h.max(v))
            });
        Estimate {
            value: finest,
            err: Some(hi - lo),
            method: Method::Spread,
            order: None,
        }
    };
    if rest.is_empty() {
        return Some(single);
    }
    if levels.iter().all(|&(_, v)| v == finest) {
        return Some(Estimate {
            value: finest,
            err: Some(0.0),
            method: Method::Exact,
            order: None,
        });
    }
    if levels.len() == 2 {
        return Some(spread(levels));
    }
    let last3 = &levels[levels.len() - 3..];
    let [(h1, f1), (h2, f2), (h3, f3)] = [last3[0], last3[1], last3[2]];
    let (d1, d2) = (f2 - f1, f3 - f2);
    let monotone = d1 * d2 > 0.0 && d2.abs() < d1.abs();
    let order = if monotone {
        observed_order(d1 / d2, [h1, h2, h3])
    } else {
        None
    };
    Some(match order {
        Some(p) => {
            let value = f3 + d2 * h3.powf(p) / (h2.powf(p) - h3.powf(p));
            Estimate {
                value,
                err: Some(SAFETY * (value - f3).abs()),
                method: Method::Richardson,
                order: Some(p),
            }
        }
        None => spread(last3),
    })
}

/// The order p with (h1^p − h2^p)/(h2^p − h3^p) = `ratio` (> 1), within
/// [MIN_ORDER, MAX_ORDER]: the ratio grows with p, so bisection.
fn observed_order(ratio: f64, [h1, h2, h3]: [f64; 3]) -> Option<f64> {
    let g = |p: f64| (h1.powf(p) - h2.powf(p)) / (h2.powf(p) - h3.powf(p)) - ratio;
    let (mut lo, mut hi) = (MIN_ORDER, MAX_ORDER);
    if g(lo) > 0.0 || g(hi) < 0.0 {
        return None;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if g(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ladder(f: impl Fn(f64) -> f64, hs: &[f64]) -> Vec<(f64, f64)> {
        hs.iter().map(|&h| (h, f(h))).collect()
    }

    #[test]
    fn richardson_recovers_the_limit_and_order_of_a_power_law() {
        // f = 0.3 + 0.05 h^1.7 on h, h/√2 (rounded as the ladder rounds), h/2.
        let hs = [1.0, 384.0 / 540.0, 0.5];
        let e = estimate(&ladder(|h| 0.3 + 0.05 * h.powf(1.7), &hs)).unwrap();
        assert_eq!(e.method, Method::Richardson);
        assert!((e.order.unwrap() - 1.7).abs() < 1e-9, "{e:?}");
        assert!((e.value - 0.3).abs() < 1e-12, "{e:?}");
        // The error bar covers the distance from the finest value to the limit.
        let finest = 0.3 + 0.05 * 0.5f64.powf(1.7);
        assert!((e.err.unwrap() - 1.25 * (finest - 0.3)).abs() < 1e-12);
    }

    #[test]
    fn a_non_monotone_ladder_reports_the_spread_not_an_extrapolation() {
        // The μa of square-A at 0° (issue #15's table, 20 / 15 / 10 µm) rises then falls.
        let e = estimate(&[(20.0, 0.4805), (15.0, 0.4842), (10.0, 0.4809)]).unwrap();
        assert_eq!(e.method, Method::Spread);
        assert_eq!(e.value, 0.4809);
        assert!((e.err.unwrap() - (0.4842 - 0.4805)).abs() < 1e-15);
        assert!(e.order.is_none());
        // Monotone but diverging (changes grow): not asymptotic either.
        let e = estimate(&[(1.0, 0.30), (0.7, 0.31), (0.5, 0.33)]).unwrap();
        assert_eq!(e.method, Method::Spread);
        // Monotone, shrinking, but so slowly that the order is below 0.5.
        let e = estimate(&[(1.0, 0.30), (0.5, 0.31), (0.25, 0.3195)]).unwrap();
        assert_eq!(e.method, Method::Spread, "{e:?}");
    }

    #[test]
    fn one_two_and_constant_ladders() {
        assert!(estimate(&[]).is_none());
        let e = estimate(&[(1.0, 0.4)]).unwrap();
        assert_eq!((e.method, e.err), (Method::Single, None));
        let e = estimate(&[(1.0, 0.4), (0.7, 0.41)]).unwrap();
        assert_eq!(e.method, Method::Spread);
        assert_eq!(e.value, 0.41);
        assert!((e.err.unwrap() - 0.01).abs() < 1e-15);
        let e = estimate(&[(1.0, 2e11), (0.7, 2e11), (0.5, 2e11)]).unwrap();
        assert_eq!((e.method, e.err, e.value), (Method::Exact, Some(0.0), 2e11));
    }

    #[test]
    fn a_longer_ladder_uses_its_finest_three() {
        // A wild coarsest level does not matter.
        let hs = [2.0, 1.0, 0.7, 0.5];
        let mut l = ladder(|h| 1.0 - 0.2 * h * h, &hs);
        l[0].1 = 5.0;
        let e = estimate(&l).unwrap();
        assert_eq!(e.method, Method::Richardson);
        assert!((e.value - 1.0).abs() < 1e-12 && (e.order.unwrap() - 2.0).abs() < 1e-9);
    }
}
