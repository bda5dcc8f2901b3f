//! `[history]`: a load path applied to every case (turning points or the
//! fretting shorthand), checked and turned into the solver's `LoadHistory`.

use super::Config;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use solver::{Increments, LoadHistory, Wear, WearLaw};

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
    /// Turning points of the ball's tangential shift along the case's force
    /// angle (signed), µm: displacement control (issue #37).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_um: Option<Vec<f64>>,
    /// Normal load at each turning point, N (default: `load.normal_n` throughout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_n: Option<Vec<f64>>,
    /// Increments per segment between turning points: `"auto"` (chosen by
    /// the path's error estimate) or a number.
    #[serde(default)]
    pub steps_per_segment: StepsCfg,
    /// The error of the energy per cycle auto increments aim at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// The full cycles someone looks at: every this many and the last
    /// (0: the last only); their loops are sampled at `loop_increments`
    /// and a wear law keeps its worn profiles at them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub save_every: Option<usize>,
    /// Increments per segment of the cycles looked at (0: no sampled
    /// loops). Default: [`SOLVE_LOOP_INCREMENTS`] in `solve`, 0 in sweeps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_increments: Option<usize>,
    /// Shorthand: 0 → +A → −A → +A … with `cycles` full cycles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fretting: Option<FrettingCfg>,
    /// The substrate's wear along the path (issue #49).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wear: Option<WearCfg>,
}

/// `history.wear`: a local wear law, its coefficient in the unit rigs
/// report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearCfg {
    /// The law.
    pub law: WearLawCfg,
    /// Archard's k, mm³/(N·m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_mm3_per_nm: Option<f64>,
    /// The energy law's α, mm³/J.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_mm3_per_j: Option<f64>,
    /// The ball's Archard k, mm³/(N·m), if it wears too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ball_k_mm3_per_nm: Option<f64>,
    /// The ball's energy-law α, mm³/J, if it wears too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ball_alpha_mm3_per_j: Option<f64>,
    /// The physical cycles the simulated ones stand for (cycle jumping;
    /// with the fretting shorthand, at least its `cycles`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub physical_cycles: Option<f64>,
    /// Keep the worn profiles every this many simulated cycles (and at the
    /// last).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub save_every: Option<usize>,
}

/// `history.wear.law`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WearLawCfg {
    /// dh = k p |ds|.
    Archard,
    /// dh = α |q · ds|.
    Energy,
}

impl WearCfg {
    /// The solver's laws of the substrate and of the ball (SI: 1 mm³/(N·m)
    /// = 1 mm³/J = 1e-9 m³/J).
    fn laws(&self) -> Result<(WearLaw, Option<WearLaw>)> {
        let law = match self.law {
            WearLawCfg::Archard => "archard",
            WearLawCfg::Energy => "energy",
        };
        let coefficient = |key: &str, v: f64| -> Result<f64> {
            if !(v.is_finite() && v >= 0.0) {
                bail!("history.wear.{key} = {v}: must be finite and ≥ 0");
            }
            if v * 1e-9 > solver::MAX_WEAR_COEFFICIENT {
                bail!("history.wear.{key} = {v}: above 0.1, more than any measured wear (fretting: 1e-6 to 1e-4; severe adhesive wear of metals about 1e-2); at that rate a contact wears through its own approach in a few slips");
            }
            Ok(v * 1e-9)
        };
        let (own, other, ball, other_ball, make): (_, _, _, _, fn(f64) -> WearLaw) = match self.law
        {
            WearLawCfg::Archard => (
                ("k_mm3_per_nm", self.k_mm3_per_nm),
                ("alpha_mm3_per_j", self.alpha_mm3_per_j),
                ("ball_k_mm3_per_nm", self.ball_k_mm3_per_nm),
                ("ball_alpha_mm3_per_j", self.ball_alpha_mm3_per_j),
                |k| WearLaw::Archard { k },
            ),
            WearLawCfg::Energy => (
                ("alpha_mm3_per_j", self.alpha_mm3_per_j),
                ("k_mm3_per_nm", self.k_mm3_per_nm),
                ("ball_alpha_mm3_per_j", self.ball_alpha_mm3_per_j),
                ("ball_k_mm3_per_nm", self.ball_k_mm3_per_nm),
                |alpha| WearLaw::Energy { alpha },
            ),
        };
        for (key, v) in [other, other_ball] {
            if v.is_some() {
                bail!(
                    "history.wear.{key}: belongs to the other law; law = \"{law}\" takes {} (and {} for the ball)",
                    own.0,
                    ball.0
                );
            }
        }
        let v = own.1.ok_or_else(|| {
            anyhow::anyhow!(
                "history.wear.{}: required with law = \"{law}\" (0 if only the ball wears)",
                own.0
            )
        })?;
        let substrate = make(coefficient(own.0, v)?);
        let ball = ball
            .1
            .map(|v| coefficient(ball.0, v))
            .transpose()?
            .map(make);
        Ok((substrate, ball))
    }
}

/// `history.fretting`: a fretting loop of force amplitude A =
/// `amplitude_ratio` μP, or of the ball's shift amplitude `displacement_um`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrettingCfg {
    /// Amplitude of the tangential force, as a fraction of μP (0 < A < 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_ratio: Option<f64>,
    /// Amplitude of the ball's tangential shift, µm (> 0): displacement
    /// control, into gross slip when it exceeds what the stick zone holds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement_um: Option<f64>,
    /// Full cycles after the first loading (+A → −A → +A each).
    #[serde(default = "one_cycle")]
    pub cycles: usize,
}

fn one_cycle() -> usize {
    1
}

/// `history.steps_per_segment`: `"auto"` or a number of increments.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum StepsCfg {
    /// A fixed number of increments per segment.
    Fixed(usize),
    /// `"auto"` (checked to be that word).
    Named(AutoWord),
}

impl Default for StepsCfg {
    fn default() -> Self {
        StepsCfg::Named(AutoWord::Auto)
    }
}

/// The one word `history.steps_per_segment` takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AutoWord {
    /// Increments chosen by the path's error estimate.
    Auto,
}

/// The increments per segment of the cycles looked at in `mpcontact
/// solve` (and Python's `solve`) when `history.loop_increments` is not
/// given: the loop drawn with 20 points a branch, as the fixed default of
/// before drew every cycle.
pub const SOLVE_LOOP_INCREMENTS: usize = 20;

/// Most fretting cycles a config may ask for (each is two segments).
pub const MAX_CYCLES: usize = 1000;

impl HistoryCfg {
    /// The solver's load path; errors name the config key.
    pub fn load_history(&self) -> Result<LoadHistory> {
        self.load_history_at(None)
    }

    /// The load path of one case of a fretting map: `amplitude_um` (the
    /// case's entry of `sweep.amplitudes_um`) is the displacement amplitude
    /// of `fretting = { cycles = N }`; `None` outside a map.
    pub fn load_history_at(&self, amplitude_um: Option<f64>) -> Result<LoadHistory> {
        let mut path = self.path_at(amplitude_um)?;
        path.increments = self.increments()?;
        path.sampling = solver::LoopSampling {
            every: self.save_every()?,
            increments: self.loop_increments.unwrap_or(0),
        };
        path.wear = match &self.wear {
            Some(w) => Some({
                let (law, ball) = w.laws()?;
                Wear {
                    law,
                    ball,
                    jump: self.wear_jump(w)?,
                }
            }),
            None => None,
        };
        Ok(path)
    }

    /// The solver's increments of `steps_per_segment` and `tolerance`.
    fn increments(&self) -> Result<Increments> {
        match self.steps_per_segment {
            StepsCfg::Fixed(k) => {
                if let Some(t) = self.tolerance {
                    bail!("history.tolerance = {t}: belongs to steps_per_segment = \"auto\" (here {k} increments per segment are fixed); leave one of them out");
                }
                Ok(Increments::Fixed(k))
            }
            StepsCfg::Named(AutoWord::Auto) => {
                let tolerance = self.tolerance.unwrap_or(solver::AUTO_TOLERANCE);
                if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 0.1) {
                    bail!("history.tolerance = {tolerance}: must be above 0 and below 0.1 (the relative error of the energy per cycle the increments aim at; default {:e})", solver::AUTO_TOLERANCE);
                }
                Ok(Increments::Auto { tolerance })
            }
        }
    }

    /// `history.save_every`, or its older place `history.wear.save_every`.
    fn save_every(&self) -> Result<usize> {
        let old = self.wear.as_ref().and_then(|w| w.save_every);
        match (self.save_every, old) {
            (Some(a), Some(b)) if a != b => bail!("history.save_every = {a} and history.wear.save_every = {b} name the cycles looked at twice: give history.save_every only (it keeps the worn profiles too)"),
            (a, b) => Ok(a.or(b).unwrap_or(0)),
        }
    }

    /// The cycle jump of `history.wear.physical_cycles`: the physical
    /// cycles per simulated fretting cycle (1 without the key).
    fn wear_jump(&self, w: &WearCfg) -> Result<f64> {
        let Some(physical) = w.physical_cycles else {
            return Ok(1.0);
        };
        let Some(f) = &self.fretting else {
            bail!("history.wear.physical_cycles: needs the fretting shorthand (fretting = {{ ..., cycles = N }}), whose N simulated cycles it spreads over");
        };
        if !(physical.is_finite() && physical >= f.cycles as f64) {
            bail!(
                "history.wear.physical_cycles = {physical}: must be at least the {} simulated cycles of history.fretting.cycles (each simulated cycle stands for physical_cycles / cycles physical ones)",
                f.cycles
            );
        }
        let jump = physical / f.cycles as f64;
        if jump > solver::MAX_WEAR_JUMP {
            bail!(
                "history.wear.physical_cycles = {physical}: {jump:e} physical cycles per simulated one, more than {:e}; simulate more cycles (history.fretting.cycles)",
                solver::MAX_WEAR_JUMP
            );
        }
        Ok(jump)
    }

    /// The turning points of [`HistoryCfg::load_history_at`], without wear.
    fn path_at(&self, amplitude_um: Option<f64>) -> Result<LoadHistory> {
        let given = [
            self.tangential_ratios.is_some(),
            self.tangential_um.is_some(),
            self.fretting.is_some(),
        ];
        if given.iter().filter(|&&g| g).count() > 1 {
            bail!(
                "history: give one of tangential_ratios, tangential_um or fretting = {{ amplitude_ratio | displacement_um, cycles }}, not several"
            );
        }
        if let Some(a) = amplitude_um {
            let Some(f) = self.fretting.as_ref().filter(|_| given[2]) else {
                bail!("sweep.amplitudes_um: needs [history] fretting = {{ cycles = N }} (displacement control; the axis gives each case's amplitude), not turning points");
            };
            if f.displacement_um.is_some() {
                bail!("history.fretting.displacement_um and sweep.amplitudes_um both set the displacement amplitude: leave displacement_um out (the axis gives each case's)");
            }
            if f.amplitude_ratio.is_some() {
                bail!("history.fretting.amplitude_ratio is force control, sweep.amplitudes_um displacement control: leave amplitude_ratio out");
            }
            let shifts = self.fretting_path(f, a * 1e-6)?;
            return Ok(LoadHistory {
                tangential_ratios: Vec::new(),
                normal_forces_n: None,
                increments: Increments::Fixed(1),
                sampling: Default::default(),
                shifts_m: Some(shifts),
                wear: None,
            });
        }
        if let Some(d) = &self.tangential_um {
            return Ok(LoadHistory {
                tangential_ratios: Vec::new(),
                normal_forces_n: self.normal_n.clone(),
                increments: Increments::Fixed(1),
                sampling: Default::default(),
                shifts_m: Some(d.iter().map(|v| v * 1e-6).collect()),
                wear: None,
            });
        }
        if let Some(f) = &self.fretting {
            if let Some(d) = f.displacement_um {
                if f.amplitude_ratio.is_some() {
                    bail!("history.fretting: give amplitude_ratio (force control) or displacement_um (displacement control), not both");
                }
                if !(d.is_finite() && d > 0.0) {
                    bail!("history.fretting.displacement_um = {d}: must be positive and finite (the amplitude of the ball's shift, µm)");
                }
                let shifts = self.fretting_path(f, d * 1e-6)?;
                return Ok(LoadHistory {
                    tangential_ratios: Vec::new(),
                    normal_forces_n: None,
                    increments: Increments::Fixed(1),
                    sampling: Default::default(),
                    shifts_m: Some(shifts),
                    wear: None,
                });
            }
        }
        let ratios = match (&self.tangential_ratios, &self.fretting) {
            (None, None) => bail!(
                "history: give the turning points (tangential_ratios = [0.0, 0.6, -0.6, 0.6], or tangential_um = [0.0, 1.5, -1.5, 1.5]) or fretting = {{ amplitude_ratio = 0.6, cycles = 2 }} (or {{ displacement_um = 1.5, cycles = 2 }})"
            ),
            (Some(r), _) => r.clone(),
            (None, Some(f)) => {
                let Some(a) = f.amplitude_ratio else {
                    bail!("history.fretting: give amplitude_ratio (a fraction of μP) or displacement_um (µm), or the amplitudes as sweep.amplitudes_um");
                };
                if !(a.is_finite() && a > 0.0 && a < 1.0) {
                    bail!("history.fretting.amplitude_ratio = {a}: must be above 0 and below 1 (the amplitude as a fraction of μP; at 1 the sphere slides)");
                }
                self.fretting_path(f, a)?
            }
        };
        Ok(LoadHistory {
            tangential_ratios: ratios,
            normal_forces_n: self.normal_n.clone(),
            increments: Increments::Fixed(1),
            sampling: Default::default(),
            shifts_m: None,
            wear: None,
        })
    }

    /// The fretting shorthand's path 0 → +a → −a → +a … of `f.cycles`
    /// full cycles (a a force ratio or a shift).
    fn fretting_path(&self, f: &FrettingCfg, a: f64) -> Result<Vec<f64>> {
        if !(1..=MAX_CYCLES).contains(&f.cycles) {
            bail!(
                "history.fretting.cycles = {}: must be 1 to {MAX_CYCLES}",
                f.cycles
            );
        }
        if self.normal_n.is_some() {
            bail!("history.normal_n: not with the fretting shorthand (its normal load is load.normal_n); give tangential_ratios or tangential_um instead");
        }
        let mut r = vec![0.0, a];
        for _ in 0..f.cycles {
            r.extend([-a, a]);
        }
        Ok(r)
    }
}

impl Config {
    /// The load path of `[history]`, if any. A malformed one gives `None`
    /// here; [`Config::check`] reports it by key before any case is made.
    pub fn load_history(&self) -> Option<LoadHistory> {
        self.load_history_at(self.sweep.amplitude_axis()[0])
    }

    /// The load path of a case at `amplitude_um` of `sweep.amplitudes_um`
    /// (`None` outside a fretting map).
    pub fn load_history_at(&self, amplitude_um: Option<f64>) -> Option<LoadHistory> {
        self.history
            .as_ref()
            .and_then(|h| h.load_history_at(amplitude_um).ok())
    }
}

/// The config key of a solver parameter of the load path.
pub(super) fn config_key(param: &str) -> Option<String> {
    if let Some(rest) = param.strip_prefix("history.shifts_m") {
        return Some(format!("history.tangential_um{rest}"));
    }
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
        // Auto increments by default, no sampled loop (a sweep's default;
        // `solve` samples the last cycle's, see `solve::CaseChoice`).
        assert_eq!(
            h.increments,
            solver::Increments::Auto {
                tolerance: solver::AUTO_TOLERANCE
            }
        );
        assert_eq!(h.sampling, solver::LoopSampling::default());
        let (_, spec) = &c.cases().unwrap()[0];
        assert_eq!(spec.history.as_ref(), Some(&h));
        assert_eq!(spec.load.tangential_ratio, 0.5, "the path's last ratio");
        // Without [history], no path.
        assert!(Config::parse(BASE, &[]).unwrap().cases().unwrap()[0]
            .1
            .history
            .is_none());
    }

    #[test]
    fn issue49_wear_keys_their_jump_and_their_errors() {
        let with = |h: &str| format!("{BASE}\n[history]\n{h}\n");
        let fretting = "fretting = { amplitude_ratio = 0.5, cycles = 4 }";
        let cases = [
            (
                format!("{fretting}\nwear = {{ law = \"archerd\", k_mm3_per_nm = 1e-5 }}"),
                "unknown variant `archerd`, expected `archard` or `energy`",
            ),
            (
                format!("{fretting}\nwear = {{ law = \"archard\" }}"),
                "history.wear.k_mm3_per_nm: required with law = \"archard\"",
            ),
            (
                format!("{fretting}\nwear = {{ law = \"archard\", k_mm3_per_nm = -1.0 }}"),
                "history.wear.k_mm3_per_nm = -1: must be finite and ≥ 0",
            ),
            (
                format!("{fretting}\nwear = {{ law = \"archard\", k_mm3_per_nm = 1e-5, physical_cycles = 3.0 }}"),
                "history.wear.physical_cycles = 3: must be at least the 4 simulated cycles",
            ),
            (
                format!("{fretting}\nwear = {{ law = \"archard\", k_mm3_per_nm = 1e-5, physical_cycles = 1e12 }}"),
                "physical cycles per simulated one, more than 1e9",
            ),
            (
                "tangential_ratios = [0.0, 0.5, -0.5, 0.5]\nwear = { law = \"archard\", k_mm3_per_nm = 1e-5, physical_cycles = 1e4 }".to_string(),
                "history.wear.physical_cycles: needs the fretting shorthand",
            ),
        ];
        for (h, expect) in cases {
            let e = err(&with(&h), &[]);
            assert!(e.contains(expect), "{h}: {e}");
        }
        // 1e4 physical cycles over 4 simulated: a jump of 2500.
        let c = Config::parse(
            &with(&format!("{fretting}\nwear = {{ law = \"energy\", alpha_mm3_per_j = 2e-5, physical_cycles = 1e4, save_every = 2 }}")),
            &[],
        )
        .unwrap();
        let h = c.load_history().unwrap();
        let w = h.wear.unwrap();
        assert_eq!(w.jump, 2500.0);
        // The older place of history.save_every.
        assert_eq!(h.sampling.every, 2);
        assert_eq!(w.law, solver::WearLaw::Energy { alpha: 2e-5 * 1e-9 });
        // The ball wears by the same law with its own coefficient.
        let c = Config::parse(
            &with(&format!("{fretting}\nwear = {{ law = \"archard\", k_mm3_per_nm = 0.0, ball_k_mm3_per_nm = 3e-6 }}")),
            &[],
        )
        .unwrap();
        let w = c.load_history().unwrap().wear.unwrap();
        assert_eq!(w.law, solver::WearLaw::Archard { k: 0.0 });
        assert_eq!(w.ball, Some(solver::WearLaw::Archard { k: 3e-6 * 1e-9 }));
        let e = err(
            &with(&format!("{fretting}\nwear = {{ law = \"archard\", k_mm3_per_nm = 1e-5, ball_alpha_mm3_per_j = 1e-6 }}")),
            &[],
        );
        assert!(
            e.contains("history.wear.ball_alpha_mm3_per_j: belongs to the other law"),
            "{e}"
        );
        // Without the key, no jump.
        let c = Config::parse(
            &with(&format!(
                "{fretting}\nwear = {{ law = \"archard\", k_mm3_per_nm = 1e-5 }}"
            )),
            &[],
        )
        .unwrap();
        assert_eq!(c.load_history().unwrap().wear.unwrap().jump, 1.0);
    }

    #[test]
    fn issue37_displacement_controlled_paths_and_their_errors() {
        let with = |h: &str| format!("{BASE}\n[history]\n{h}\n");
        let cases: [(&str, &str); 5] = [
            (
                "tangential_um = [0.0, 1.0]\ntangential_ratios = [0.0, 0.5]",
                "history: give one of tangential_ratios, tangential_um or fretting",
            ),
            (
                "fretting = { displacement_um = 1.0, amplitude_ratio = 0.5 }",
                "history.fretting: give amplitude_ratio (force control) or displacement_um",
            ),
            (
                "fretting = { displacement_um = -1.0 }",
                "history.fretting.displacement_um = -1: must be positive",
            ),
            (
                "tangential_um = [0.0, nan]",
                "invalid history.tangential_um[1]: must be finite",
            ),
            (
                "tangential_um = [0.0, 1.0]\nnormal_n = [20.0]",
                "history.normal_n: has 1 turning points but history.shifts_m has 2",
            ),
        ];
        for (h, expect) in cases {
            let e = err(&with(h), &[]);
            assert!(e.contains(expect), "{h}: {e}");
        }
        // The shorthand in µm expands to shifts in m; the force is a result,
        // so the case's own tangential ratio is 0.
        let c = Config::parse(
            &with("fretting = { displacement_um = 1.5, cycles = 1 }"),
            &[],
        )
        .unwrap();
        let h = c.load_history().unwrap();
        assert!(h.tangential_ratios.is_empty());
        let d = h.shifts_m.clone().unwrap();
        assert_eq!(d.len(), 4);
        assert!((d[1] - 1.5e-6).abs() < 1e-18 && (d[2] + 1.5e-6).abs() < 1e-18);
        let (_, spec) = &c.cases().unwrap()[0];
        assert_eq!(spec.load.tangential_ratio, 0.0);
        assert!(spec.history.as_ref().unwrap().displacement_controlled());
    }
}
