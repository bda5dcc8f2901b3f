//! The stresses of one solved case and the scalars read from them: which
//! states (the turning points of a load history, or the case's one
//! state), where (horizontal planes at chosen depths, two vertical slices
//! through the contact centre, the surface plane for the fatigue
//! parameter), and the maxima, Crossland's and Smith–Watson–Topper's
//! parameters. Shared by `mpcontact solve`, the Python module and the
//! sweep's workers, so the three give the same numbers to the bit. The
//! stresses themselves, and the criteria of one point's states, are
//! [`crate::operators::stress`].

use serde::{Deserialize, Serialize};

use crate::operators::stress::{
    crossland_at, principal, swt_point, tresca_of, von_mises, Line, StressField, StressPlan,
    StressPlane,
};
use crate::{CaseScalars, CaseSpec, Fields, Grid, Material, SolverError, TurningState};

/// How the Crossland parameter is formed from the states computed.
pub const CROSSLAND_DEFINITION: &str = "Crossland: sqrt(J2,a) + alpha * sigma_H,max at every point computed (planes and slices), J2,a of the deviatoric amplitude taken as half the largest difference between two states' deviators (exact for two states, the extremes of a fretting cycle; with more, the smallest enclosing sphere's radius exceeds it by at most 2/sqrt(3) for three states and sqrt(5/3) for more), sigma_H,max the largest hydrostatic stress over the states; needs at least two states (a load history)";

/// Where the maxima are sought.
pub const MAXIMA_DEFINITION: &str = "maxima over the points computed: every plane of stress.depths_um and the two slices (the grid row and column through the cell nearest the pressure centroid; 'along' is the one nearer the force direction); the surface peak is the stress along the force direction, sigma_tt = sxx c^2 + syy s^2 + 2 sxy s c, on the top row of the 'along' slice";

/// How the Smith–Watson–Topper parameter is formed.
pub const SWT_DEFINITION: &str = "Smith-Watson-Topper at the surface (z = 0, every cell of the grid): SWT = sigma_n,max * eps_a on the planes normal to the surface, their normal n = (cos t, sin t, 0) for t = 0, 1, ..., 179 degrees; sigma_n = n.sigma.n of each state, eps_n = n.eps.n with eps = C^-1 sigma (the substrate's compliance); over the states computed (a load history's turning points) sigma_n,max is the largest sigma_n and eps_a half the range of eps_n; a single state is taken as a cycle from the unloaded surface to that state and back (sigma_n,max = max(sigma_n, 0), eps_a = |eps_n| / 2); SWT = 0 where sigma_n,max <= 0; the critical plane is the t of the largest SWT";

/// What to compute (the solver's form of `[stress]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StressRequest {
    /// Depths of the horizontal planes, m.
    pub depths_m: Vec<f64>,
    /// The two vertical slices through the contact centre.
    pub slices: bool,
    /// Deepest row of the slices, m (`None`: twice the contact radius).
    pub slice_depth_m: Option<f64>,
    /// Rows of a slice (≥ 2), the surface included.
    pub slice_rows: usize,
    /// With a load history, the states computed.
    pub states: StressStates,
    /// Crossland's coefficient α.
    pub crossland_alpha: f64,
}

/// The states of a load history whose stresses are computed (a case
/// without a history has one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StressStates {
    /// Every turning point of the path, the start included: one state per
    /// segment, 2002 for 1000 fretting cycles (issue #59: 8.7 GB at 32²).
    Turning,
    /// The turning points of the last cycle, the last
    /// [`LAST_CYCLE_TURNING`] (+A → −A → +A of a fretting path): the
    /// states of the cycle Crossland's and SWT's parameters are read over.
    LastCycle,
    /// The final increment only.
    Final,
}

/// Turning points of one cycle: out, back and out again.
pub const LAST_CYCLE_TURNING: usize = 3;

impl StressStates {
    /// The turning points of a path's `turning` whose stresses are
    /// computed (none: the final increment is the one state).
    pub fn chosen<T>(self, turning: &[T]) -> &[T] {
        match self {
            StressStates::Turning => turning,
            StressStates::LastCycle => &turning[turning.len().saturating_sub(LAST_CYCLE_TURNING)..],
            StressStates::Final => &[],
        }
    }

    /// The states computed of a path of `turning` turning points (at
    /// least the one final state).
    pub fn count(self, turning: usize) -> usize {
        match self {
            StressStates::Turning => turning,
            StressStates::LastCycle => turning.min(LAST_CYCLE_TURNING),
            StressStates::Final => 1,
        }
        .max(1)
    }
}

/// A value and its place (m; z into the body).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct Located {
    /// The value, Pa.
    pub value_pa: f64,
    /// The value over the Hertz pressure p_H.
    pub over_p_h: f64,
    /// x, y, z of the point, m.
    pub at_m: [f64; 3],
}

/// The scalars of one state.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct StateScalars {
    /// Increment of the load history (None: the case's only state).
    pub step: Option<usize>,
    /// Largest von Mises stress.
    pub max_von_mises: Located,
    /// Largest Tresca (maximum shear) stress.
    pub max_tresca: Located,
    /// Largest principal stress.
    pub max_principal: Located,
    /// Peak surface stress along the force direction (with slices).
    // (no skip_serializing_if: the scalars also travel in bincode, which needs every field)
    #[serde(default)]
    pub surface_peak_along_force: Option<Located>,
}

/// The Smith–Watson–Topper parameter's largest value over the surface.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
pub struct SwtScalars {
    /// SWT = σn,max εa, Pa (strain dimensionless).
    pub value_pa: f64,
    /// The surface point (z = 0), m.
    pub at_m: [f64; 3],
    /// Angle of the critical plane's normal from x, degrees in [0, 180).
    pub plane_angle_deg: f64,
    /// σn,max on that plane, Pa.
    pub sigma_max_pa: f64,
    /// εa on that plane.
    pub strain_amplitude: f64,
}

/// The scalars of a case's stresses (`case.json`'s `stress`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct StressScalars {
    /// One entry per state computed.
    pub states: Vec<StateScalars>,
    /// Crossland's parameter over the states (two or more).
    // (no skip_serializing_if: the scalars also travel in bincode, which needs every field)
    #[serde(default)]
    pub crossland: Option<Located>,
    /// Crossland's α.
    pub crossland_alpha: f64,
    /// See [`CROSSLAND_DEFINITION`].
    pub crossland_definition: String,
    /// See [`MAXIMA_DEFINITION`].
    pub maxima_definition: String,
    /// Smith–Watson–Topper at the surface.
    pub swt: SwtScalars,
    /// See [`SWT_DEFINITION`].
    pub swt_definition: String,
    /// Depths of the slices' rows, m.
    pub slice_depths_m: Vec<f64>,
    /// The slice along the force: `x` (a grid row) or `y` (a column).
    pub slice_along: String,
    /// The cell centre the slices pass through (x, y), m.
    pub slice_through_m: [f64; 2],
}

impl StressScalars {
    /// Largest value of `f` over the states (the worst state of a cycle).
    pub fn worst(&self, f: impl Fn(&StateScalars) -> Option<Located>) -> Option<Located> {
        self.states
            .iter()
            .filter_map(f)
            .fold(None, |b: Option<Located>, l| match b {
                Some(b) if b.value_pa >= l.value_pa => Some(b),
                _ => Some(l),
            })
    }
}

/// One state's stresses on the planes and slices.
pub struct StateStress {
    /// Increment (None: the case's only state).
    pub step: Option<usize>,
    /// Pressure of the state (for the contact edge in the maps), Pa.
    pub p: Vec<f64>,
    /// One field per depth of the request.
    pub planes: Vec<StressField>,
    /// The slice along the force: one line per slice depth.
    pub along: Vec<StressField>,
    /// The slice across the force.
    pub across: Vec<StressField>,
}

/// The stresses of a case: its states, the derived fields and the scalars.
pub struct CaseStress {
    /// The states.
    pub states: Vec<StateStress>,
    /// The scalars.
    pub scalars: StressScalars,
    /// Crossland's parameter on each plane (with two states or more).
    pub crossland_planes: Vec<Vec<f64>>,
    /// Crossland's parameter on the slices (rows = depths).
    pub crossland_slices: Option<[Vec<f64>; 2]>,
    /// SWT over the surface (n x n, rows y), Pa.
    pub swt_surface: Vec<f64>,
    /// Grid row and column of the slices.
    pub centre: (usize, usize),
    /// The slice along the force is a grid row.
    pub along_is_row: bool,
    /// Depths of the planes, m.
    pub depths_m: Vec<f64>,
    /// The grid.
    pub grid: crate::Grid,
    /// Contact radius the maps are scaled with, m.
    pub contact_radius_m: f64,
    /// Hertz pressure, Pa.
    pub p_h: f64,
}

/// A state's increment (None: the case's only state) and its `p, qx, qy`.
type StateTractions<'a> = (Option<usize>, &'a [f64], &'a [f64], &'a [f64]);

/// Cell nearest the pressure centroid.
fn centroid(grid: &crate::Grid, p: &[f64]) -> (usize, usize) {
    let n = grid.n;
    let (mut w, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for iy in 0..n {
        for ix in 0..n {
            let v = p[iy * n + ix];
            w += v;
            sx += v * ix as f64;
            sy += v * iy as f64;
        }
    }
    if w <= 0.0 {
        return (n / 2, n / 2);
    }
    let r = |v: f64| (v / w).round().clamp(0.0, (n - 1) as f64) as usize;
    (r(sx), r(sy))
}

/// Bytes of depth kernels a worker keeps between cases, over all its
/// materials: 512 MiB, 13 planes at 256², 3 at 512² (576 B a cell, see
/// [`StressPlane::bytes`]); the current material's first plane (its
/// surface, which every case asks for) is kept beyond it.
pub const KEPT_PLANE_BYTES: f64 = 512.0 * 1024.0 * 1024.0;

/// Materials (with their grid) whose plans a worker keeps.
pub const KEPT_PLANS: usize = 4;

/// What the cases of a sweep share for their stresses, kept by a worker
/// from one case to the next: per material and grid (the last
/// [`KEPT_PLANS`] used) the plan, with its periodic images' spectra by
/// depth, and the depth planes its cases asked for, within
/// [`KEPT_PLANE_BYTES`] (a plane needed again by the current material
/// evicts the planes of the least recently used others first). All of it
/// depends on the material, the grid and the depth only: a plane is the one
/// a case would build itself, to the bit, so `solve` and a sweep agree.
#[derive(Default)]
pub struct StressCache {
    /// Least recently used first.
    entries: Vec<Kept>,
}

struct Kept {
    key: (Material, Grid),
    plan: StressPlan,
    planes: Vec<StressPlane>,
}

/// A plane for a case: one the cache keeps, or the case's own.
enum PlaneRef {
    Kept(usize),
    Own(Box<StressPlane>),
}

impl StressCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes the entry of `material` on `grid` the current (last) one,
    /// its plan made when missing (the least recently used entry leaves
    /// beyond [`KEPT_PLANS`]).
    fn prepare(&mut self, material: &Material, grid: Grid) -> Result<(), SolverError> {
        match self
            .entries
            .iter()
            .position(|k| &k.key.0 == material && k.key.1 == grid)
        {
            Some(i) => {
                let kept = self.entries.remove(i);
                self.entries.push(kept);
            }
            None => {
                let plan = StressPlan::new(material, grid)?;
                if self.entries.len() == KEPT_PLANS {
                    self.entries.remove(0);
                }
                self.entries.push(Kept {
                    key: (material.clone(), grid),
                    plan,
                    planes: Vec::new(),
                });
            }
        }
        Ok(())
    }

    fn current(&mut self) -> &mut Kept {
        self.entries.last_mut().expect("prepared")
    }

    /// The plane at `depth_m` of the current material: kept (built when
    /// missing and kept when the budget allows), else the case's own.
    fn plane(&mut self, depth_m: f64) -> Result<PlaneRef, SolverError> {
        let here = self.entries.len() - 1;
        if let Some(i) = self.entries[here]
            .planes
            .iter()
            .position(|p| p.depth_m().to_bits() == depth_m.to_bits())
        {
            return Ok(PlaneRef::Kept(i));
        }
        let plane = self.entries[here].plan.plane(depth_m)?;
        let bytes = plane.bytes();
        let held = |entries: &[Kept]| -> f64 {
            entries
                .iter()
                .flat_map(|k| k.planes.iter().map(StressPlane::bytes))
                .sum()
        };
        let mut older = 0;
        while held(&self.entries) + bytes > KEPT_PLANE_BYTES && older < here {
            self.entries[older].planes.clear();
            older += 1;
        }
        let first = self.entries[here].planes.is_empty();
        if first || held(&self.entries) + bytes <= KEPT_PLANE_BYTES {
            self.entries[here].planes.push(plane);
            Ok(PlaneRef::Kept(self.entries[here].planes.len() - 1))
        } else {
            Ok(PlaneRef::Own(Box::new(plane)))
        }
    }
}

/// The plane `r` refers to among the current material's `kept` planes.
fn resolve<'a>(r: &'a PlaneRef, kept: &'a [StressPlane]) -> &'a StressPlane {
    match r {
        PlaneRef::Kept(i) => &kept[*i],
        PlaneRef::Own(p) => p,
    }
}

/// Computes the stresses `req` asks for on the states of a solved case:
/// the turning points of its load history `req.states` chooses (or its
/// final state), else the case's one state; and the scalars.
pub fn compute(
    req: &StressRequest,
    spec: &CaseSpec,
    scalars: &CaseScalars,
    fields: &Fields,
    turning: &[TurningState],
) -> Result<CaseStress, SolverError> {
    compute_with(req, spec, scalars, fields, turning, &mut StressCache::new())
}

/// [`compute`] with the plan and the surface plane of `cache` (a sweep's
/// worker keeps one across its cases); the same numbers to the bit.
pub fn compute_with(
    req: &StressRequest,
    spec: &CaseSpec,
    scalars: &CaseScalars,
    fields: &Fields,
    turning: &[TurningState],
    cache: &mut StressCache,
) -> Result<CaseStress, SolverError> {
    let grid = spec.grid;
    let n = grid.n;
    let chosen = req.states.chosen(turning);
    let states: Vec<StateTractions> = if !chosen.is_empty() {
        chosen
            .iter()
            .map(|t| (Some(t.step), &t.p[..], &t.qx[..], &t.qy[..]))
            .collect()
    } else {
        vec![(None, &fields.p[..], &fields.qx[..], &fields.qy[..])]
    };
    cache.prepare(&spec.material, grid)?;
    // The planes first (the surface's, which SWT and the slices' top row
    // read, before the request's), then the plan and the kept planes.
    let surface_plane = cache.plane(0.0)?;
    let depths_m = req.depths_m.clone();
    let depth_planes = depths_m
        .iter()
        .map(|&z| cache.plane(z))
        .collect::<Result<Vec<_>, _>>()?;
    let Kept {
        plan, planes: kept, ..
    } = cache.current();
    let tractions: Vec<_> = states
        .iter()
        .map(|(_, p, qx, qy)| plan.tractions(p, qx, qy))
        .collect();
    let (ix0, iy0) = centroid(&grid, &fields.p);
    let psi = spec.load.angle_deg.to_radians();
    let along_is_row = psi.cos().abs() >= psi.sin().abs();
    let (along, across) = if along_is_row {
        (Line::Row(iy0), Line::Column(ix0))
    } else {
        (Line::Column(ix0), Line::Row(iy0))
    };
    let a = if scalars.contact_radius_m > 0.0 {
        scalars.contact_radius_m
    } else {
        scalars.hertz_radius_m
    };
    let slice_depths: Vec<f64> = if req.slices {
        let deepest = req.slice_depth_m.unwrap_or(2.0 * a);
        (0..req.slice_rows)
            .map(|k| deepest * k as f64 / (req.slice_rows - 1) as f64)
            .collect()
    } else {
        Vec::new()
    };
    let mut out: Vec<StateStress> = states
        .iter()
        .map(|(step, p, _, _)| StateStress {
            step: *step,
            p: p.to_vec(),
            planes: Vec::new(),
            along: Vec::new(),
            across: Vec::new(),
        })
        .collect();
    // One kernel per depth, applied to every state.
    // The slices: their top row (z = 0) from the surface plane kept for
    // SWT, the rows below it all at once (`StressPlan::slice`, no plane
    // built).
    if let Some((_, below)) = slice_depths.split_first() {
        let plane = resolve(&surface_plane, kept);
        for (s, t) in out.iter_mut().zip(&tractions) {
            s.along.push(plan.apply_line(plane, t, along));
            s.across.push(plan.apply_line(plane, t, across));
        }
        if !below.is_empty() {
            let rows = plan.slice(below, &tractions, &[along, across])?;
            for (s, lines) in out.iter_mut().zip(rows) {
                let [a, c]: [Vec<StressField>; 2] = lines.try_into().expect("two lines asked");
                s.along.extend(a);
                s.across.extend(c);
            }
        }
    }
    for r in &depth_planes {
        let plane = resolve(r, kept);
        for (s, t) in out.iter_mut().zip(&tractions) {
            s.planes.push(plan.apply(plane, t));
        }
    }
    // The surface plane for SWT: a plane of the request at z = 0, else its own.
    let on_surface = depths_m.iter().position(|&z| z == 0.0);
    let surface: Option<Vec<StressField>> = on_surface.is_none().then(|| {
        let plane = resolve(&surface_plane, kept);
        tractions.iter().map(|t| plan.apply(plane, t)).collect()
    });
    let surface_of = |k: usize| -> &StressField {
        match (&surface, on_surface) {
            (Some(s), _) => &s[k],
            (None, Some(j)) => &out[k].planes[j],
            (None, None) => unreachable!("a surface plane is computed above"),
        }
    };
    let p_h = scalars.hertz_pressure_pa;
    let at_line = |line: Line, i: usize, z: f64| match line {
        Line::Row(iy) => [grid.x(i), grid.y(iy), z],
        Line::Column(ix) => [grid.x(ix), grid.y(i), z],
    };
    let located = |v: f64, at: [f64; 3]| Located {
        value_pa: v,
        over_p_h: v / p_h,
        at_m: at,
    };
    // Every point computed of a state: (tensor, place).
    let points = |s: &StateStress| -> Vec<([f64; 6], [f64; 3])> {
        let mut pts = Vec::new();
        for (line, rows) in [(along, &s.along), (across, &s.across)] {
            for f in rows.iter() {
                for i in 0..f.len() {
                    pts.push((f.at(i), at_line(line, i, f.depth_m)));
                }
            }
        }
        for f in &s.planes {
            for i in 0..f.len() {
                pts.push((f.at(i), [grid.x(i % n), grid.y(i / n), f.depth_m]));
            }
        }
        pts
    };
    let best = |pts: &[([f64; 6], [f64; 3])], f: &dyn Fn(usize) -> f64| {
        let mut b = (f64::NEG_INFINITY, [0.0; 3]);
        for (i, (_, at)) in pts.iter().enumerate() {
            let v = f(i);
            if v > b.0 {
                b = (v, *at);
            }
        }
        located(b.0, b.1)
    };
    let (c, s) = (psi.cos(), psi.sin());
    let along_force = |t: [f64; 6]| t[0] * c * c + t[1] * s * s + 2.0 * t[5] * s * c;
    let mut state_scalars = Vec::new();
    for st in &out {
        let pts = points(st);
        let surface_peak = st.along.first().map(|top| {
            let vals = top.map(along_force);
            let pk = crate::operators::stress::peak(&vals).expect("a line has points");
            located(pk.value, at_line(along, pk.index, 0.0))
        });
        // The principal stresses once a point, for Tresca and σ₁ both (the
        // same values; twice, the eigenvalues took 7 % of a 256² case with
        // `[stress]`, perf).
        let principals: Vec<[f64; 3]> = pts.iter().map(|(t, _)| principal(*t)).collect();
        state_scalars.push(StateScalars {
            step: st.step,
            max_von_mises: best(&pts, &|i| von_mises(pts[i].0)),
            max_tresca: best(&pts, &|i| tresca_of(principals[i])),
            max_principal: best(&pts, &|i| principals[i][0]),
            surface_peak_along_force: surface_peak,
        });
    }
    // SWT over the surface.
    let compliance =
        spec.material
            .stiffness()
            .try_inverse()
            .ok_or_else(|| SolverError::Invalid {
                field: "material".into(),
                reason: "the stiffness matrix is singular (no compliance for SWT)".into(),
            })?;
    let mut swt_surface = vec![0.0; n * n];
    let mut swt = SwtScalars {
        value_pa: 0.0,
        at_m: [grid.x(ix0), grid.y(iy0), 0.0],
        plane_angle_deg: 0.0,
        sigma_max_pa: 0.0,
        strain_amplitude: 0.0,
    };
    for (i, cell) in swt_surface.iter_mut().enumerate() {
        let ts: Vec<[f64; 6]> = (0..out.len()).map(|k| surface_of(k).at(i)).collect();
        let pt = swt_point(&ts, &compliance);
        *cell = pt.value;
        if pt.value > swt.value_pa {
            swt = SwtScalars {
                value_pa: pt.value,
                at_m: [grid.x(i % n), grid.y(i / n), 0.0],
                plane_angle_deg: pt.angle_deg,
                sigma_max_pa: pt.sigma_max,
                strain_amplitude: pt.strain_amplitude,
            };
        }
    }
    // Crossland over the states.
    let alpha = req.crossland_alpha;
    let (mut crossland_planes, mut crossland_slices, mut crossland) = (Vec::new(), None, None);
    if out.len() >= 2 {
        let field_of = |get: &dyn Fn(&StateStress) -> &StressField| -> Vec<f64> {
            let len = get(&out[0]).len();
            (0..len)
                .map(|i| {
                    let ts: Vec<[f64; 6]> = out.iter().map(|s| get(s).at(i)).collect();
                    crossland_at(&ts, alpha)
                })
                .collect()
        };
        for k in 0..depths_m.len() {
            crossland_planes.push(field_of(&|s: &StateStress| &s.planes[k]));
        }
        let slice = |which: usize| -> Vec<f64> {
            (0..slice_depths.len())
                .flat_map(|r| {
                    if which == 0 {
                        field_of(&|s: &StateStress| &s.along[r])
                    } else {
                        field_of(&|s: &StateStress| &s.across[r])
                    }
                })
                .collect()
        };
        if !slice_depths.is_empty() {
            crossland_slices = Some([slice(0), slice(1)]);
        }
        let mut b = (f64::NEG_INFINITY, [0.0; 3]);
        for (k, f) in crossland_planes.iter().enumerate() {
            for (i, &v) in f.iter().enumerate() {
                if v > b.0 {
                    b = (v, [grid.x(i % n), grid.y(i / n), depths_m[k]]);
                }
            }
        }
        if let Some(sl) = &crossland_slices {
            for (line, vals) in [(along, &sl[0]), (across, &sl[1])] {
                for (i, &v) in vals.iter().enumerate() {
                    if v > b.0 {
                        b = (v, at_line(line, i % n, slice_depths[i / n]));
                    }
                }
            }
        }
        crossland = Some(located(b.0, b.1));
    }
    Ok(CaseStress {
        scalars: StressScalars {
            states: state_scalars,
            crossland,
            crossland_alpha: alpha,
            crossland_definition: CROSSLAND_DEFINITION.into(),
            maxima_definition: MAXIMA_DEFINITION.into(),
            swt,
            swt_definition: SWT_DEFINITION.into(),
            slice_depths_m: slice_depths,
            slice_along: if along_is_row { "x" } else { "y" }.into(),
            slice_through_m: [grid.x(ix0), grid.y(iy0)],
        },
        states: out,
        crossland_planes,
        crossland_slices,
        swt_surface,
        centre: (ix0, iy0),
        along_is_row,
        depths_m,
        grid,
        contact_radius_m: a,
        p_h,
    })
}
