//! `[convergence]`: grid-convergence ladders, the finer grids of each case
//! on the same domain (docs/validation.md). The estimate made from them is
//! `crate::convergence`.

use super::Config;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use solver::Grid;

/// `[convergence]`: grid-convergence ladders (docs/validation.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceCfg {
    /// Grids per case: 1 (the config's grid only), 2 or 3 … up to
    /// [`MAX_LEVELS`]; level k has about 2^(k/2) times the config's points
    /// per side on the same domain (cell sizes h, h/√2, h/2, …).
    #[serde(default = "one_level")]
    pub levels: usize,
}

fn one_level() -> usize {
    1
}

/// Most levels a ladder may have (the finest grid has 2^((L−1)/2) times
/// the points per side, 2.8× at 4: 22× the cost of level 0).
pub const MAX_LEVELS: usize = 4;

impl Default for ConvergenceCfg {
    fn default() -> Self {
        ConvergenceCfg { levels: 1 }
    }
}

impl ConvergenceCfg {
    pub(super) fn is_default(&self) -> bool {
        *self == ConvergenceCfg::default()
    }

    /// The ladder's length (its surfaces are checked where they are
    /// resolved, in [`Config::cases`]).
    pub(super) fn check(&self) -> Result<()> {
        let levels = self.levels;
        if !(1..=MAX_LEVELS).contains(&levels) {
            bail!("convergence.levels = {levels}: must be 1 (no ladder) to {MAX_LEVELS}");
        }
        Ok(())
    }
}

/// Points per side of ladder level `level` on a grid of `n`: n·2^(level/2),
/// odd levels rounded to the nearest 5-smooth number (2^a 3^b 5^c: fast
/// FFT sizes; 384 → 540, 256 → 360), so the cell-size ratio is √2 to
/// within 0.5 %; the spacing follows from the fixed domain.
pub fn ladder_points(n: usize, level: usize) -> usize {
    let base = n << (level / 2);
    if level.is_multiple_of(2) {
        return base;
    }
    let target = base as f64 * std::f64::consts::SQRT_2;
    let smooth = |mut m: usize| {
        for f in [2, 3, 5] {
            while m.is_multiple_of(f) {
                m /= f;
            }
        }
        m == 1
    };
    let t = target.round() as usize;
    (0..t)
        .flat_map(|d| [t + d, t - d])
        .find(|&m| m > 0 && smooth(m))
        .unwrap_or(t)
}

impl Config {
    /// The grid of ladder level `level` (level 0: `[grid]` itself).
    pub fn level_grid(&self, level: usize) -> Grid {
        let spacing = self.grid.spacing_um * 1e-6;
        // Level 0 is the spacing as given, not spacing · n / n, which can
        // differ in the last bit and would change every result without a ladder.
        if level == 0 {
            return Grid::square(self.grid.points, spacing);
        }
        let n = ladder_points(self.grid.points, level);
        Grid::square(n, spacing * self.grid.points as f64 / n as f64)
    }

    /// Points per side of the finest grid the sweep solves on.
    pub fn finest_points(&self) -> usize {
        self.level_grid(self.convergence.levels - 1).n
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use super::*;

    #[test]
    fn ladder_levels_and_grids() {
        for bad in ["0", "5"] {
            let e = err(BASE, &[&format!("convergence.levels={bad}")]);
            assert!(
                e.contains(&format!("convergence.levels = {bad}: must be 1")),
                "{e}"
            );
        }
        // h, h/√2 (5-smooth), h/2, h/(2√2) on one domain; level 0 as given.
        assert_eq!(
            (0..4).map(|k| ladder_points(384, k)).collect::<Vec<_>>(),
            vec![384, 540, 768, 1080]
        );
        let c = Config::parse(BASE, &["convergence.levels=3".into()]).unwrap();
        assert_eq!(c.level_grid(0).dx, c.grid.spacing_um * 1e-6);
        assert_eq!(c.finest_points(), 2 * c.grid.points);
        let cases = c.cases().unwrap();
        assert_eq!(
            cases.len(),
            3 * Config::parse(BASE, &[]).unwrap().cases().unwrap().len()
        );
        let (k0, s0) = &cases[0];
        let (k1, s1) = &cases[1];
        assert_eq!((k0.level, k1.level), (0, 1));
        let domain = |g: &Grid| g.n as f64 * g.dx;
        assert!((domain(&s1.grid) / domain(&s0.grid) - 1.0).abs() < 1e-12);
    }
}
