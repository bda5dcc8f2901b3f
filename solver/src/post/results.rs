//! The results of one case: its scalars and fields, the definitions behind
//! them (zone and apparent radii, K_E, the pressure's distance from Hertz),
//! μa (paper Eq. 19) and its K_E calibration on the flat surface, and the
//! reduction of a solved contact state to them. Solves nothing.

use serde::{Deserialize, Serialize};

use crate::base::geometry::{covered_area, equivalent_radius, hull_area, radial_moments};
use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::model::radii::{apparent_radius, friction_reserve, zone_radius, Radii};
use crate::model::spec::{CaseSpec, Load, MIN_RESOLVED_CELLS};
use crate::model::surface::Terrain;
use crate::operators::operator::{Operator, X, Y, Z};
use crate::solve::coupling::ContactState;
use crate::solve::history::HistoryOutput;
use crate::solve::normal::NormalReport;
use crate::solve::tangential::{TangentialReport, TangentialSolution};

/// The scalars of one solved case.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseScalars {
    /// The contact zone's own radius, its outline under any
    /// `numerics.radii` ([`crate::ZONE_RADIUS_DEFINITION`]), m. (Before
    /// issue #59 this name held μa's apparent radius, now
    /// `mu_a_contact_radius_m`.)
    pub contact_radius_m: f64,
    /// The stick zone's own radius, the same for its level μp − |q| (0
    /// when nothing sticks), m.
    pub stick_radius_m: f64,
    /// μa's apparent contact radius a under the case's `numerics.radii`:
    /// from the second moment of the pressure (the default,
    /// [`crate::APPARENT_RADIUS_DEFINITION_MOMENTS`]) or the circle with the
    /// area of the convex hull of the contact boundary located between cell
    /// centres ([`crate::APPARENT_RADIUS_DEFINITION`]), m. Used for μa and
    /// K_E.
    pub mu_a_contact_radius_m: f64,
    /// μa's apparent stick radius c: the same for the stick zone (its
    /// level μp − |q|), m.
    pub mu_a_stick_radius_m: f64,
    /// How far the pressure is from its best Hertz fit
    /// ([`HERTZ_MISFIT_DEFINITION`]): 0 for Hertz, −1/15 for a uniform
    /// pressure, −0.16 for a flat punch; μa (Eq. 19, Hertz and Mindlin's
    /// formula) is flagged beyond [`HERTZ_MISFIT_LIMIT`] in magnitude.
    pub pressure_hertz_misfit: f64,
    /// The paper's a: circle with the area of the convex hull of the contact
    /// cells, each taken as its full square ([`crate::APPARENT_RADIUS_DEFINITION_CELLS`]), m.
    #[serde(default)]
    pub contact_radius_cells_m: f64,
    /// The paper's c: same for the stick cells, m.
    #[serde(default)]
    pub stick_radius_cells_m: f64,
    /// Rigid tangential shift δt projected on the force direction, m.
    pub delta_t_m: f64,
    /// Component of δt perpendicular to the force (left of it), m.
    pub delta_t_perp_m: f64,
    /// Rigid-body approach δz, m.
    pub delta_z_m: f64,
    /// Peak pressure, Pa.
    pub p_max_pa: f64,
    /// Peak shear traction magnitude, Pa.
    pub q_max_pa: f64,
    /// Contact area (cells with p > 0), m².
    pub contact_area_m2: f64,
    /// Stick area, m².
    pub stick_area_m2: f64,
    /// True when any contact cell lies off the island tops (patterned surfaces).
    pub base_contact: bool,
    /// Apparent friction coefficient from Eq. 19 with a and c (None without tangential load).
    pub mu_a: Option<f64>,
    /// K_E used for μa, Pa.
    pub k_e: f64,
    /// μa from Eq. 19 with the paper's radii (`*_cells_m`) and `k_e_cells`.
    #[serde(default)]
    pub mu_a_cells: Option<f64>,
    /// K_E used for `mu_a_cells` (differs from `k_e` only when calibrated on
    /// the flat surface, with the paper's radii), Pa.
    #[serde(default)]
    pub k_e_cells: f64,
    /// Where K_E came from: "isotropic" (formula with E, ν) or "flat-calibrated".
    pub k_e_source: String,
    /// Hertz contact radius with the isotropic-equivalent constants, m.
    pub hertz_radius_m: f64,
    /// Hertz peak pressure with the isotropic-equivalent constants, Pa.
    pub hertz_pressure_pa: f64,
    /// Total normal force recovered from the pressure, N.
    pub normal_force_n: f64,
    /// Total tangential force recovered from the tractions (x, y), N.
    pub tangential_force_n: [f64; 2],
    /// All loops converged.
    pub converged: bool,
    /// Normal CG iterations, summed over coupling iterations, with those
    /// of the contact from rest even when the worker reused it from an
    /// earlier case ([`crate::solve::normal::solve_normal_from_rest`]): the same
    /// count whichever worker ran the case.
    pub normal_iterations: usize,
    /// Tangential iterations, summed over coupling iterations.
    pub tangential_iterations: usize,
    /// Coupling iterations (1 when uncoupled).
    pub coupling_iterations: usize,
    /// Final relative change of p between the last two coupling iterations.
    pub coupling_change: f64,
    /// Report of the last normal solve.
    pub normal: NormalReport,
    /// Report of the last tangential solve.
    pub tangential: TangentialReport,
    /// Wall time of the solve (operator build excluded), s.
    pub seconds: f64,
    /// Wall time spent building or loading the operator for this case
    /// (0 when it was already resident), s.
    #[serde(default)]
    pub kernel_seconds: f64,
    /// The load path's table and reductions, for a case with a history
    /// (the other scalars then describe the path's final state).
    #[serde(default)]
    pub history: Option<HistoryOutput>,
    /// The plastic zone, on a surface with a hardness (`None`: elastic).
    #[serde(default)]
    pub plastic: Option<PlasticScalars>,
}

/// The plastic zone of a case on an elastic–perfectly plastic surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlasticScalars {
    /// The interface's hardness H (the softer body's), Pa.
    pub hardness_pa: f64,
    /// Area of the cells whose pressure is at the hardness in the final
    /// state (their covered part on cut cells), m².
    pub plastic_area_m2: f64,
    /// Equivalent radius of that area, `sqrt(A/π)`, m.
    pub plastic_radius_m: f64,
    /// Largest permanent plastic penetration (the dent; after a load
    /// path, accumulated over it), m.
    pub penetration_max_m: f64,
    /// Volume of the dent, `ΔA Σ w`, m³.
    pub dent_volume_m3: f64,
}

/// Surface fields of a solved case, each `n x n`, row-major `[iy][ix]` (y rows, x columns).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fields {
    /// Cells per side.
    pub n: usize,
    /// Pressure, Pa.
    pub p: Vec<f64>,
    /// Shear traction x, Pa.
    pub qx: Vec<f64>,
    /// Shear traction y, Pa.
    pub qy: Vec<f64>,
    /// Slip x, m.
    pub sx: Vec<f64>,
    /// Slip y, m.
    pub sy: Vec<f64>,
    /// 1 on stick cells, 0 elsewhere.
    pub stick: Vec<f64>,
    /// Surface displacement x, m.
    pub ux: Vec<f64>,
    /// Surface displacement y, m.
    pub uy: Vec<f64>,
    /// Surface displacement z (into the body), m.
    pub uz: Vec<f64>,
    /// Permanent plastic penetration (the dent), m; empty on an elastic
    /// surface. Not one of [`Fields::named`]: sweeps do not carry it.
    pub plastic: Vec<f64>,
    /// The substrate's worn depth over a load path with a wear law, in its
    /// own frame (the grid's cells at the path's start: at the ball's
    /// shift δt the point under cell x is the one at x + δt), m; empty
    /// without one. Not one of [`Fields::named`] either.
    pub wear: Vec<f64>,
    /// The ball's worn depth per cell (the grid is the ball's frame: its
    /// apex at the centre), m; empty unless the ball wears. Not one of
    /// [`Fields::named`].
    pub ball_wear: Vec<f64>,
    /// The substrate's worn depth at the cycles a wear law saves
    /// (`Wear::save_every` and the last), with their numbers, m; written by
    /// `solve` as `wear_cycle_K.npy`. Not one of [`Fields::named`].
    pub wear_saved: Vec<(usize, Vec<f64>)>,
}

impl Fields {
    /// Every field the case has with its file name: [`Fields::named`],
    /// then `plastic` on a surface with a hardness and `wear` after a path
    /// with a wear law.
    pub fn present(&self) -> Vec<(&'static str, &Vec<f64>)> {
        let mut all = self.named().to_vec();
        for (name, v) in [
            ("plastic", &self.plastic),
            ("wear", &self.wear),
            ("ball_wear", &self.ball_wear),
        ] {
            if !v.is_empty() {
                all.push((name, v));
            }
        }
        all
    }

    /// The fields with their file names, in a fixed order.
    pub fn named(&self) -> [(&'static str, &Vec<f64>); 9] {
        [
            ("p", &self.p),
            ("qx", &self.qx),
            ("qy", &self.qy),
            ("sx", &self.sx),
            ("sy", &self.sy),
            ("stick", &self.stick),
            ("ux", &self.ux),
            ("uy", &self.uy),
            ("uz", &self.uz),
        ]
    }
}

/// Scalars and fields of one case.
#[derive(Clone, Debug)]
pub struct CaseOutput {
    /// Scalars.
    pub scalars: CaseScalars,
    /// Fields.
    pub fields: Fields,
    /// With a load history: the tractions at its turning points (empty
    /// without one).
    pub turning: Vec<crate::solve::history::TurningState>,
}

/// How K_E in μa is obtained.
pub const K_E_DEFINITION: &str = "isotropic: K_E = 8E/(3(1+nu)(2-nu)) (paper Eq. 19); anisotropic: K_E(psi) = mu P (a^2 - c^2)/(delta_F a^3) calibrated on the flat surface of the same material at the same force angle";

/// `k_e_source` of a K_E from Mindlin's isotropic formula.
pub const K_E_ISOTROPIC: &str = "isotropic";
/// `k_e_source` of a K_E calibrated on the flat surface.
pub const K_E_FLAT_CALIBRATED: &str = "flat-calibrated";

/// How `pressure_hertz_misfit` is defined.
pub const HERTZ_MISFIT_DEFINITION: &str = "<r^4> / <r^4>_fit - 1: the pressure's fourth radial moment about its centroid over that of its best Hertz fit, the (elliptical) Hertz pressure with the same load, centroid and second-moment tensor M, <r^4>_fit = (5/7)(3 tr(M)^2 - 4 det M); 0 for Hertz, -1/15 for a uniform pressure, -0.16 for a flat punch, < 0 where the load moved outwards (capped, worn), > 0 where it is more peaked; moments of the sampled pressure, so a pattern's islands sample the envelope";

/// The |`pressure_hertz_misfit`| beyond which μa is flagged
/// (`mu_a_non_hertz`). Measured (docs/validation.md, "μa on a pressure that
/// is not Hertz's"): below 1e-4 on flat surfaces; +0.009 to +0.022 on the
/// paper's four patterns (128² to 384²), up to +0.048 on sparse lattices
/// off the apex (flagged); yielded Table 1(a) Fe −0.006 at H = 0.8 GPa
/// (μa +2 %), −0.035 at 0.7 (μa +17 %), −1/15 fully capped; partial-slip
/// wear +0.006 to −0.084 (Ciavarella–Hills's limit −0.082), which crosses 0
/// on its way (μa 20–50 % off there, not flagged: a radial moment cannot
/// tell it from a pattern's sampling).
pub const HERTZ_MISFIT_LIMIT: f64 = 0.03;

/// [`HERTZ_MISFIT_DEFINITION`] of the pressure `p` over the contact
/// `contact` (0 for a zero pressure).
pub(crate) fn hertz_misfit(grid: &Grid, contact: &[bool], p: &[f64]) -> f64 {
    let Some(m) = radial_moments(grid, contact, p) else {
        return 0.0;
    };
    let [xx, xy, yy] = m.second;
    let (trace, det) = (xx + yy, xx * yy - xy * xy);
    m.fourth / (5.0 / 7.0 * (3.0 * trace * trace - 4.0 * det)) - 1.0
}

/// Paper Eq. 19: μa = δF a³ K_E / (P (a² − c²)), with the radii `[a, c]`.
fn eq19(delta_t: f64, [a, c]: [f64; 2], normal_force_n: f64, k_e: f64) -> f64 {
    delta_t * a.powi(3) * k_e / (normal_force_n * (a * a - c * c))
}

/// Eq. 19 solved for K_E so that it returns `friction`.
fn eq19_k_e(delta_t: f64, [a, c]: [f64; 2], normal_force_n: f64, friction: f64) -> f64 {
    friction * normal_force_n * (a * a - c * c) / (delta_t * a.powi(3))
}

impl CaseScalars {
    /// μa's a and c (under the case's `numerics.radii`).
    pub fn radii(&self) -> [f64; 2] {
        [self.mu_a_contact_radius_m, self.mu_a_stick_radius_m]
    }

    /// Whether μa is flagged: the pressure is further from Hertz's than
    /// [`HERTZ_MISFIT_LIMIT`], where Eq. 19 (Hertz and Mindlin's formula)
    /// no longer measures the friction it was derived for. `None` without μa.
    pub fn mu_a_non_hertz(&self) -> Option<bool> {
        self.mu_a
            .map(|_| self.pressure_hertz_misfit.abs() > HERTZ_MISFIT_LIMIT)
    }

    /// The paper's a and c ([`crate::APPARENT_RADIUS_DEFINITION_CELLS`]).
    pub fn radii_cells(&self) -> [f64; 2] {
        [self.contact_radius_cells_m, self.stick_radius_cells_m]
    }
}

/// Paper Eq. 19: μa = δF a³ K_E / (P (a² − c²)), with a and c.
pub fn mu_apparent(s: &CaseScalars, normal_force_n: f64, k_e: f64) -> f64 {
    eq19(s.delta_t_m, s.radii(), normal_force_n, k_e)
}

/// K_E calibrated from a flat-surface case so that Eq. 19 (with a and c)
/// returns μ there.
pub fn calibrate_k_e(flat: &CaseScalars, friction: f64, normal_force_n: f64) -> f64 {
    eq19_k_e(flat.delta_t_m, flat.radii(), normal_force_n, friction)
}

/// μa from Eq. 19 with the paper's radii, when they leave a slip annulus.
fn mu_apparent_cells(s: &CaseScalars, normal_force_n: f64, k_e: f64) -> Option<f64> {
    let [a, c] = s.radii_cells();
    (c < a).then(|| eq19(s.delta_t_m, [a, c], normal_force_n, k_e))
}

/// The μa of a case of an anisotropic material: K_E(ψ) calibrated on the
/// scalars `flat` of its flat twin (the same material, grid, load and angle
/// on the flat surface; `s` itself for a flat case), and μa (Eq. 19) with
/// it. Sets `k_e`, `k_e_source` and `mu_a` of `s`. The one place both a
/// single solve and a sweep calibrate (see [`crate::CaseSpec::needs_flat_calibration`]).
pub fn calibrate_on_flat(s: &mut CaseScalars, flat: &CaseScalars, load: &Load) {
    let k_e = calibrate_k_e(flat, load.friction, load.normal_force_n);
    s.k_e = k_e;
    s.k_e_source = K_E_FLAT_CALIBRATED.into();
    s.mu_a = Some(mu_apparent(s, load.normal_force_n, k_e));
    // Each definition is calibrated with its own radii, so that both return
    // μ on the flat surface.
    s.k_e_cells = eq19_k_e(
        flat.delta_t_m,
        flat.radii_cells(),
        load.normal_force_n,
        load.friction,
    );
    s.mu_a_cells = mu_apparent_cells(s, load.normal_force_n, s.k_e_cells);
}

/// The fields and scalars of a solved case: total displacements from all
/// tractions, radii, shifts, forces and μa with the isotropic-equivalent K_E.
/// `started` is when the solve began (for `seconds`). With a load path's
/// `history`, a final state without a resolved slip annulus (everything
/// sticks, as under proportional loading) is a result, with μa `None`; so is
/// the state of an unconverged solve (flagged by `converged`), whose radii
/// are not checked against the grid.
pub(crate) fn reduce(
    spec: &CaseSpec,
    terrain: &Terrain,
    op: &mut Operator,
    state: ContactState,
    started: std::time::Instant,
    kernel_seconds: f64,
    history: Option<HistoryOutput>,
) -> Result<CaseOutput, SolverError> {
    let is_history = history.is_some();
    let ContactState {
        p,
        approach,
        plastic,
        tangential,
        normal_report,
        normal_iterations,
        tangential_iterations,
        coupling_iterations,
        coupling_change,
        coupling_converged,
    } = state;
    let grid = spec.grid;
    let (n, len, da) = (grid.n, grid.len(), grid.cell_area());
    let load = spec.load.normal_force_n;
    let force = spec.load.tangential_force();
    let fnorm = force[0].hypot(force[1]);
    let TangentialSolution {
        qx,
        qy,
        sx,
        sy,
        stick,
        shift,
        report: tan_report,
    } = tangential;
    // Total displacements from all tractions.
    let (mut ux, mut uy, mut uz) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    op.apply(
        &[(X, &qx), (Y, &qy), (Z, &p)],
        &mut [(X, &mut ux), (Y, &mut uy), (Z, &mut uz)],
    );

    let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
    let stick_in_contact: Vec<bool> = (0..len).map(|i| contact[i] && stick[i]).collect();
    // A cut cell contributes its covered part.
    let cover = terrain.cover.as_deref();
    let contact_area = covered_area(&contact, cover, da);
    let stick_area = covered_area(&stick_in_contact, cover, da);
    // The paper's radii (whole cells) decide what the grid resolves, as
    // before the sub-cell radii existed; the two differ by less than a cell.
    let a = equivalent_radius(hull_area(&grid, &contact));
    // A history's state has a stick set at any force (at F = 0 the tractions
    // of Spence's normal loading with friction, or those locked in after
    // unloading); a monotonic case without force has none.
    let has_stick_set = fnorm > 0.0 || is_history;
    let c = if has_stick_set {
        equivalent_radius(hull_area(&grid, &stick_in_contact))
    } else {
        a
    };
    // A zone a few cells across has no radius worth reporting: μa from
    // it is grid noise (a stick zone of a few cells gave μa = 434, #20 item 8).
    let min_radius = MIN_RESOLVED_CELLS * grid.dx.max(grid.dy);
    // An unconverged solve is flagged as such: its radii are those of an
    // intermediate iterate, and calling it unresolved would send the user to
    // refine a grid that was not the problem.
    let converged = normal_report.converged && tan_report.converged && coupling_converged;
    if converged && a < min_radius {
        return Err(SolverError::ContactUnresolved {
            detail: format!(
                "a = {a:.3e} m spans fewer than {MIN_RESOLVED_CELLS} cells of {:.3e} m",
                grid.dx
            ),
        });
    }
    if converged && fnorm > 0.0 && c < min_radius && !is_history {
        return Err(SolverError::SlipUnresolved {
            detail: format!(
                "the stick zone, c = {c:.3e} m, spans fewer than {MIN_RESOLVED_CELLS} cells of {:.3e} m (F/μP = {} leaves almost no stick)",
                grid.dx, spec.load.tangential_ratio
            ),
        });
    }
    let dir = if fnorm > 0.0 {
        [force[0] / fnorm, force[1] / fnorm]
    } else {
        [1.0, 0.0]
    };
    let heights = &terrain.heights;
    let top = heights.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let base_contact = !matches!(spec.surface, crate::model::surface::Surface::Flat)
        && (0..len).any(|i| contact[i] && heights[i] < top);
    let hertz_radius =
        (3.0 * load * spec.load.indenter_radius_m / (4.0 * spec.contact_modulus())).cbrt();
    // The radii of μa (`solver.radii`): by default the second moments of p
    // and of μp − |q|, or the sub-cell hulls of the same two levels (p falls
    // to zero like the root of the distance at a Hertzian edge, and μp − |q|
    // does at a Mindlin stick edge).
    let friction = spec.load.friction;
    let radii = spec.numerics.radii;
    // The zones' own radii are their outlines, the hull's (the same as μa's
    // under `radii = "hull"`, computed once then).
    let reserve = has_stick_set.then(|| {
        let bound = spec.friction_pressure(&p, cover);
        friction_reserve(friction, &bound, (&qx, &qy))
    });
    let zone_a = zone_radius(&grid, &contact, &p, terrain);
    let zone_c = match &reserve {
        Some(reserve) => zone_radius(&grid, &stick_in_contact, reserve, terrain),
        None => zone_a,
    };
    let (a_app, c_app) = match radii {
        Radii::Hull => (zone_a, zone_c),
        Radii::Moments => {
            let a_app = apparent_radius(radii, &grid, &contact, &p, terrain);
            let c_app = match &reserve {
                Some(reserve) => apparent_radius(radii, &grid, &stick_in_contact, reserve, terrain),
                None => a_app,
            };
            (a_app, c_app)
        }
    };
    let mut s = CaseScalars {
        contact_radius_m: zone_a,
        stick_radius_m: zone_c,
        mu_a_contact_radius_m: a_app,
        mu_a_stick_radius_m: c_app,
        pressure_hertz_misfit: hertz_misfit(&grid, &contact, &p),
        contact_radius_cells_m: a,
        stick_radius_cells_m: c,
        delta_t_m: shift[0] * dir[0] + shift[1] * dir[1],
        delta_t_perp_m: -shift[0] * dir[1] + shift[1] * dir[0],
        delta_z_m: approach,
        p_max_pa: p.iter().cloned().fold(0.0, f64::max),
        q_max_pa: (0..len).map(|i| qx[i].hypot(qy[i])).fold(0.0, f64::max),
        contact_area_m2: contact_area,
        stick_area_m2: stick_area,
        base_contact,
        mu_a: None,
        k_e: spec.mindlin_k_e(),
        mu_a_cells: None,
        k_e_cells: spec.mindlin_k_e(),
        k_e_source: K_E_ISOTROPIC.into(),
        hertz_radius_m: hertz_radius,
        hertz_pressure_pa: 3.0 * load / (2.0 * std::f64::consts::PI * hertz_radius * hertz_radius),
        normal_force_n: p.iter().sum::<f64>() * da,
        tangential_force_n: [qx.iter().sum::<f64>() * da, qy.iter().sum::<f64>() * da],
        converged,
        normal_iterations,
        tangential_iterations,
        coupling_iterations: coupling_iterations.max(1),
        coupling_change,
        normal: normal_report,
        tangential: tan_report,
        seconds: started.elapsed().as_secs_f64(),
        kernel_seconds,
        history,
        plastic: None,
    };
    if let Some(hardness) = spec.limits().hardness {
        let area = crate::model::material::area_at_cap(hardness, cover, &p, da);
        s.plastic = Some(PlasticScalars {
            hardness_pa: hardness,
            plastic_area_m2: area,
            plastic_radius_m: (area / std::f64::consts::PI).sqrt(),
            penetration_max_m: plastic.iter().cloned().fold(0.0, f64::max),
            dent_volume_m3: plastic.iter().sum::<f64>() * da,
        });
    }
    let annulus = c < a && c_app < a_app && c >= min_radius;
    if fnorm > 0.0 && (is_history || !converged) {
        if annulus {
            s.mu_a = Some(mu_apparent(&s, load, s.k_e));
            s.mu_a_cells = mu_apparent_cells(&s, load, s.k_e_cells);
        }
    } else if fnorm > 0.0 {
        if c >= a {
            let slipping = contact_area - stick_area;
            return Err(SolverError::SlipUnresolved {
                detail: if slipping > 0.0 {
                    format!(
                        "the {} slipping cells lie inside the stick zone's outline, so a = c = {a:.4e} m",
                        (slipping / da).round()
                    )
                } else {
                    format!(
                        "all {} contact cells stick under F = {:.4e} N, so a = c = {a:.4e} m",
                        (contact_area / da).round(),
                        fnorm
                    )
                },
            });
        }
        if c_app >= a_app {
            return Err(SolverError::SlipUnresolved {
                detail: format!(
                    "the stick zone's boundary reaches the contact boundary, c = a = {a_app:.4e} m"
                ),
            });
        }
        s.mu_a = Some(mu_apparent(&s, load, s.k_e));
        s.mu_a_cells = mu_apparent_cells(&s, load, s.k_e_cells);
    }
    let fields = Fields {
        n,
        stick: stick_in_contact
            .iter()
            .map(|&b| if b { 1.0 } else { 0.0 })
            .collect(),
        p,
        qx,
        qy,
        sx,
        sy,
        ux,
        uy,
        uz,
        plastic,
        wear: Vec::new(),
        ball_wear: Vec::new(),
        wear_saved: Vec::new(),
    };
    Ok(CaseOutput {
        scalars: s,
        fields,
        turning: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(1 − ρ²)^γ` on an ellipse of semi-axes `a`, `b` (cells) turned by
    /// `turn` (rad) about the point `(x0, y0)` (cells), on a 400² grid of
    /// unit cells: the pressure and its contact.
    fn power_law(
        gamma: f64,
        (a, b, turn): (f64, f64, f64),
        (x0, y0): (f64, f64),
    ) -> (Grid, Vec<bool>, Vec<f64>) {
        let grid = Grid::square(400, 1.0);
        let n = grid.n;
        let (c, s) = (turn.cos(), turn.sin());
        let p: Vec<f64> = (0..n * n)
            .map(|i| {
                let (x, y) = (grid.x(i % n) - x0, grid.y(i / n) - y0);
                let (u, v) = ((c * x + s * y) / a, (-s * x + c * y) / b);
                let q = 1.0 - u * u - v * v;
                if q > 0.0 {
                    q.powf(gamma)
                } else {
                    0.0
                }
            })
            .collect();
        let contact = p.iter().map(|&v| v > 0.0).collect();
        (grid, contact, p)
    }

    /// The misfit of the family `(1 − ρ²)^γ` in closed form: its radial
    /// moments are Beta functions, `⟨ρ²⟩ = 1/(γ + 2)`,
    /// `⟨ρ⁴⟩ = 2/((γ + 2)(γ + 3))`, against Hertz's (γ = 1/2) `⟨r⁴⟩ =
    /// (10/7)⟨r²⟩²` at the same second moment: `1.4 (γ + 2)/(γ + 3) − 1`
    /// (0 for Hertz, −1/15 uniform, +0.05 paraboloidal), the same on any
    /// ellipse (the fit is the elliptical Hertz of the same second-moment
    /// tensor).
    #[test]
    fn issue59_hertz_misfit_of_sampled_power_law_pressures_matches_the_closed_form() {
        for gamma in [0.0, 0.5, 1.0] {
            let exact = 1.4 * (gamma + 2.0) / (gamma + 3.0) - 1.0;
            for shape in [(120.0, 120.0, 0.0), (150.0, 100.0, 0.5)] {
                let (grid, contact, p) = power_law(gamma, shape, (3.3, -7.1));
                let m = hertz_misfit(&grid, &contact, &p);
                eprintln!("γ = {gamma}, axes {shape:?}: misfit {m:.5}, closed form {exact:.5}");
                assert!(
                    (m - exact).abs() < 2e-3,
                    "γ = {gamma} {shape:?}: {m} vs {exact}"
                );
            }
        }
    }
}
