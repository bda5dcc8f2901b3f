//! `[history]`: a load path applied to every case (turning points or the
//! fretting shorthand), checked and turned into the solver's `LoadHistory`.

use super::Config;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use solver::LoadHistory;

/// `[history]`: a load path applied to every case (fretting loops,
/// proportional loading), PHYSICS.md §5b. Either the turning points
/// (`tangential_ratios`, optionally `normal_n`) or the `fretting` shorthand.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HistoryCfg {
    /// Turning points of F/(μP) along the case's force angle (signed),
    /// joined by straight lines.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_ratios: Option<Vec<f64>>,
    /// Normal load at each turning point, N (default: `load.normal_n` throughout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_n: Option<Vec<f64>>,
    /// Increments per segment between turning points.
    #[serde(default = "default_steps")]
    pub steps_per_segment: usize,
    /// Shorthand: 0 → +A → −A → +A … with `cycles` full cycles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fretting: Option<FrettingCfg>,
}

/// `history.fretting`: a fretting loop of amplitude A = `amplitude_ratio` μP.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrettingCfg {
    /// Amplitude of the tangential force, as a fraction of μP (0 < A < 1).
    pub amplitude_ratio: f64,
    /// Full cycles after the first loading (+A → −A → +A each).
    #[serde(default = "one_cycle")]
    pub cycles: usize,
}

fn one_cycle() -> usize {
    1
}

fn default_steps() -> usize {
    20
}

/// Most fretting cycles a config may ask for (each is two segments).
pub const MAX_CYCLES: usize = 1000;

impl HistoryCfg {
    /// The solver's load path; errors name the config key.
    pub fn load_history(&self) -> Result<LoadHistory> {
        let ratios = match (&self.tangential_ratios, &self.fretting) {
            (Some(_), Some(_)) => bail!(
                "history: give either tangential_ratios or fretting = {{ amplitude_ratio, cycles }}, not both"
            ),
            (None, None) => bail!(
                "history: give the turning points (tangential_ratios = [0.0, 0.6, -0.6, 0.6]) or fretting = {{ amplitude_ratio = 0.6, cycles = 2 }}"
            ),
            (Some(r), None) => r.clone(),
            (None, Some(f)) => {
                let a = f.amplitude_ratio;
                if !(a.is_finite() && a > 0.0 && a < 1.0) {
                    bail!("history.fretting.amplitude_ratio = {a}: must be above 0 and below 1 (the amplitude as a fraction of μP; at 1 the sphere slides)");
                }
                if !(1..=MAX_CYCLES).contains(&f.cycles) {
                    bail!("history.fretting.cycles = {}: must be 1 to {MAX_CYCLES}", f.cycles);
                }
                if self.normal_n.is_some() {
                    bail!("history.normal_n: not with the fretting shorthand (its normal load is load.normal_n); give tangential_ratios instead");
                }
                let mut r = vec![0.0, a];
                for _ in 0..f.cycles {
                    r.extend([-a, a]);
                }
                r
            }
        };
        Ok(LoadHistory {
            tangential_ratios: ratios,
            normal_forces_n: self.normal_n.clone(),
            steps_per_segment: self.steps_per_segment,
        })
    }
}

impl Config {
    /// The load path of `[history]`, if any. A malformed one gives `None`
    /// here; [`Config::check`] reports it by key before any case is made.
    pub fn load_history(&self) -> Option<LoadHistory> {
        self.history.as_ref().and_then(|h| h.load_history().ok())
    }
}

/// The config key of a solver parameter of the load path.
pub(super) fn config_key(param: &str) -> Option<String> {
    param
        .strip_prefix("history.normal_forces_n")
        .map(|rest| format!("history.normal_n{rest}"))
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use crate::config::Config;

    #[test]
    fn issue16_bad_histories_name_their_key() {
        let with = |h: &str| format!("{BASE}\n[history]\n{h}\n");
        let cases: [(&str, &str); 10] = [
            (
                "tangential_ratios = [0.0, 0.6, nan]",
                "history.tangential_ratios[2]: must be finite",
            ),
            (
                "tangential_ratios = [0.0, 1.0]",
                "history.tangential_ratios[1]",
            ),
            ("tangential_ratios = [0.0, -1.5]", "friction limit"),
            (
                "tangential_ratios = [0.0, 0.5]\nnormal_n = [20.0]",
                "history.normal_n: has 1 turning points",
            ),
            (
                "tangential_ratios = [0.0, 0.5]\nnormal_n = [20.0, -1.0]",
                "history.normal_n[1]",
            ),
            (
                "tangential_ratios = [0.0, 0.5]\nsteps_per_segment = 0",
                "history.steps_per_segment: must be at least 1",
            ),
            (
                "tangential_ratios = []",
                "history.tangential_ratios: needs at least one",
            ),
            (
                "fretting = { amplitude_ratio = 1.0 }",
                "history.fretting.amplitude_ratio = 1",
            ),
            (
                "fretting = { amplitude_ratio = 0.5, cycles = 0 }",
                "history.fretting.cycles = 0",
            ),
            ("steps_per_segment = 5", "history: give the turning points"),
        ];
        for (h, expect) in cases {
            let e = err(&with(h), &[]);
            assert!(e.contains(expect), "{h}: {e}");
        }
        // The shorthand expands to 0 → +A → (−A → +A) × cycles.
        let c = Config::parse(
            &with("fretting = { amplitude_ratio = 0.5, cycles = 2 }"),
            &[],
        )
        .unwrap();
        let h = c.load_history().unwrap();
        assert_eq!(h.tangential_ratios, vec![0.0, 0.5, -0.5, 0.5, -0.5, 0.5]);
        assert_eq!(h.steps_per_segment, 20);
        let (_, spec) = &c.cases().unwrap()[0];
        assert_eq!(spec.history.as_ref(), Some(&h));
        assert_eq!(spec.load.tangential_ratio, 0.5, "the path's last ratio");
        // Without [history], no path.
        assert!(Config::parse(BASE, &[]).unwrap().cases().unwrap()[0]
            .1
            .history
            .is_none());
    }
}
