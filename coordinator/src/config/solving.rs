//! `[solver]`, `[run]` and `[output]`: how each case is solved (the
//! solver's `Numerics`, its defaults being the solver's own), how the sweep
//! runner treats its workers, and what it writes besides the tables.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use solver::Numerics;

/// `[solver]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverCfg {
    /// Normal–tangential coupling.
    #[serde(default = "yes")]
    pub coupling: bool,
    /// Normal solver: relative change of pressure.
    #[serde(default = "default_tol")]
    pub tolerance: f64,
    /// Tangential solver: KKT residual relative to |δt|.
    #[serde(default = "default_ttol")]
    pub tangential_tolerance: f64,
    /// Iteration budget of each inner solve.
    #[serde(default = "default_iter")]
    pub max_iterations: usize,
    /// Coupling loop: relative change of pressure.
    #[serde(default = "default_ctol")]
    pub coupling_tolerance: f64,
    /// Coupling loop budget.
    #[serde(default = "default_citer")]
    pub max_coupling_iterations: usize,
    /// Definition of the apparent radii of μa: `"moments"` (the default)
    /// or `"hull"` (the paper's, pinned by the configs that reproduce it).
    #[serde(default = "default_radii")]
    pub radii: solver::Radii,
    /// The tangential solve's iteration: `"cg"` (the default) or
    /// `"active-set"` (issue #48).
    #[serde(default = "default_method")]
    pub tangential_method: solver::TangentialMethod,
}

fn yes() -> bool {
    Numerics::default().coupling
}
// The defaults are the solver's (one place).
fn default_tol() -> f64 {
    Numerics::default().tolerance
}
fn default_ttol() -> f64 {
    Numerics::default().tangential_tolerance
}
fn default_iter() -> usize {
    Numerics::default().max_iterations
}
fn default_ctol() -> f64 {
    Numerics::default().coupling_tolerance
}
fn default_citer() -> usize {
    Numerics::default().max_coupling_iterations
}
fn default_radii() -> solver::Radii {
    Numerics::default().radii
}
fn default_method() -> solver::TangentialMethod {
    Numerics::default().tangential_method
}

impl Default for SolverCfg {
    fn default() -> Self {
        SolverCfg {
            coupling: true,
            tolerance: default_tol(),
            tangential_tolerance: default_ttol(),
            max_iterations: default_iter(),
            coupling_tolerance: default_ctol(),
            max_coupling_iterations: default_citer(),
            radii: default_radii(),
            tangential_method: default_method(),
        }
    }
}

/// `[output]`
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputCfg {
    /// Write `.npy` fields and PNG maps of every case of a sweep.
    #[serde(default)]
    pub save_fields: bool,
}

/// `[run]`: how the sweep runner treats its workers (not physics).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunCfg {
    /// Longest silence, s, of a worker with a case in flight: workers beat
    /// a few times a second while they compute (kernel builds and solver
    /// iterations included), so only a worker that says nothing for this
    /// long is hung; its case is taken from it (the worker is killed when
    /// this coordinator started it) and dispatched again. However long a
    /// case computes, it is never cut short.
    #[serde(default = "default_case_timeout")]
    pub case_timeout_s: f64,
}

fn default_case_timeout() -> f64 {
    60.0
}

impl Default for RunCfg {
    fn default() -> Self {
        RunCfg {
            case_timeout_s: default_case_timeout(),
        }
    }
}

impl RunCfg {
    pub(super) fn is_default(&self) -> bool {
        *self == RunCfg::default()
    }
}

impl SolverCfg {
    /// The solver's numerics of every case.
    pub(super) fn numerics(&self) -> Numerics {
        Numerics {
            coupling: self.coupling,
            tolerance: self.tolerance,
            tangential_tolerance: self.tangential_tolerance,
            max_iterations: self.max_iterations,
            coupling_tolerance: self.coupling_tolerance,
            max_coupling_iterations: self.max_coupling_iterations,
            radii: self.radii,
            tangential_method: self.tangential_method,
        }
    }
}

impl RunCfg {
    /// The timeout is a usable duration.
    pub(super) fn check(&self) -> Result<()> {
        let t = self.case_timeout_s;
        // 1e9 s (32 years) keeps the deadline within what a Duration holds.
        if !(t.is_finite() && t > 0.0 && t <= 1e9) {
            bail!("run.case_timeout_s = {t}: must be a positive number of seconds, at most 1e9");
        }
        Ok(())
    }
}

/// The config key of a solver numerics parameter.
pub(super) fn config_key(param: &str) -> Option<String> {
    param
        .strip_prefix("numerics.")
        .map(|rest| format!("solver.{rest}"))
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use super::super::Config;
    use solver::Radii;

    /// Issue #47: a config that says nothing gets the second moments, the
    /// solver's default; `radii = "hull"` (the paper configs) and `--set
    /// solver.radii=hull` get the hull, in every case and in the echo a
    /// resume compares.
    #[test]
    fn issue47_radii_default_to_moments_and_hull_stays_available() {
        let radii = |c: &Config| {
            let cases = c.cases().unwrap();
            assert!(cases
                .iter()
                .all(|(_, s)| s.numerics.radii == c.solver.radii));
            c.solver.radii
        };
        let default = Config::parse(BASE, &[]).unwrap();
        assert_eq!(radii(&default), Radii::Moments);
        assert_eq!(default.solver.radii, solver::Numerics::default().radii);
        assert!(default.to_toml().contains("radii = \"moments\""));
        let pinned = Config::parse(&format!("{BASE}\n[solver]\nradii = \"hull\"\n"), &[]).unwrap();
        assert_eq!(radii(&pinned), Radii::Hull);
        assert!(pinned.to_toml().contains("radii = \"hull\""));
        let set = Config::parse(BASE, &["solver.radii=hull".to_string()]).unwrap();
        assert_eq!(radii(&set), Radii::Hull);
    }

    #[test]
    fn issue20_item6_case_timeouts_are_bounded() {
        let e = err(&format!("{BASE}\n[run]\ncase_timeout_s = 1e20\n"), &[]);
        assert!(e.contains("run.case_timeout_s"), "{e}");
    }
}
