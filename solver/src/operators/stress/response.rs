//! The half-space's response at depth to a surface traction of one wave
//! vector, `σ̂ = P exp(−isW) H t̂`: per tabulated direction in Putzer's
//! form ([`Node`]), between directions interpolated. Knows a material,
//! no grid.

use nalgebra::Matrix6;

use super::{C, M3, M63};
use crate::error::SolverError;
use crate::green::aniso::stroh::{
    contract, surface_compliance_tensor, voigt_index, voigt_to_tensor,
};
use crate::model::material::{Elasticity, Material};

/// Directions tabulated over `[0, 2π)` (closed forms for an isotropic
/// material, Stroh otherwise); `P`, `W` and `H` are interpolated between
/// them (4-point Lagrange).
/// 2048 nodes keep the interpolation error below 1e-9 of the entries
/// (`interpolated_directions_equal_direct_evaluation`).
pub const STROH_DIRECTIONS: usize = 2048;

/// The decay `e^{−DECAY_LIMIT}` below which a response is left out
/// ([`Response::decayed`]).
pub(super) const DECAY_LIMIT: f64 = 36.0;

/// `P`, `W`, `H` of one in-plane direction θ: `σ̂ = P exp(−isW) H t̂`.
#[derive(Clone, Copy, Debug)]
struct Direction {
    pub(super) p: M63,
    pub(super) w: M3,
    pub(super) h: M3,
    /// `P H`: the response on the surface itself.
    pub(super) ph: M63,
}

impl Direction {
    /// From the stiffness tensor and the surface compliance `H(θ)`.
    pub(super) fn new(
        t: &crate::green::aniso::stroh::Tensor4,
        cv: &Matrix6<f64>,
        theta: f64,
        h: M3,
    ) -> Self {
        let n = [theta.cos(), theta.sin(), 0.0];
        let m = [0.0, 0.0, 1.0];
        let tt = contract(t, &m, &m);
        let r = contract(t, &n, &m);
        let ti = tt
            .try_inverse()
            .expect("stiffness checked positive definite");
        let n1 = (-ti * r.transpose()).map(|v| C::new(v, 0.0));
        let n2 = ti.map(|v| C::new(v, 0.0));
        let hi = h.try_inverse().expect("H(θ) is positive definite");
        let w = n1 - n2 * hi * C::new(0.0, 1.0);
        // ∂_l u_k → −iρ n_l û_k in-plane, −iρ (W û)_k along z.
        let mut cn = M63::zeros();
        let mut cm = M63::zeros();
        for big in 0..6 {
            for k in 0..3 {
                let along: f64 = (0..2).map(|l| cv[(big, voigt_index(k, l))] * n[l]).sum();
                cn[(big, k)] = C::new(along, 0.0);
                cm[(big, k)] = C::new(cv[(big, voigt_index(k, 2))], 0.0);
            }
        }
        let p = (cn + cm * w) * C::new(0.0, -1.0);
        Direction { p, w, h, ph: p * h }
    }
}

/// How a material responds at depth, tabulated over the directions: at
/// each node the response in Putzer's form ([`Node`]), exact for any
/// `s = ρz`; between nodes the responses of the four nearest are combined
/// (4-point Lagrange in θ).
pub(super) struct Response {
    /// Isotropic: every node has the triple root `−i` and `Q₂ = 0`
    /// (`(W + iI)² = 0`), so the four nodes share one set of coefficients.
    pub(super) isotropic: bool,
    pub(super) nodes: Vec<Node>,
    /// Per stencil (its first node): the roots and matrices of a crystal
    /// vary smoothly over its four nodes, so that they may be interpolated
    /// themselves and one node's exponentials serve a frequency (the roots
    /// of consecutive nodes are ordered alike; a stencil through a
    /// crossing of roots, or where the ordering wraps at 2π, is not).
    pub(super) smooth: Vec<bool>,
    /// The slowest decay of the roots over every direction,
    /// `min −Im λ` (1 for an isotropic body): a response at `s = ρz` is
    /// below `e^{−slowest·s}` of the surface's.
    pub(super) slowest: f64,
    /// `P`, `W`, `H` of the nodes: the construction before issue #51
    /// (interpolate them, then `exp(−isW)` per frequency), kept as the
    /// tests' oracle.
    #[cfg(test)]
    table: Vec<Direction>,
}

/// Series of [`phi1`] and [`divided`] below this `|x|·spread`: 16 terms
/// leave below `0.5¹⁶/17!`, and the difference quotients above it lose at
/// most a factor `1/0.5` to cancellation.
const CLUSTER: f64 = 0.5;

/// `φ₁(u) = (eᵘ − 1)/u` for `|u| < CLUSTER` (series).
fn phi1(u: C) -> C {
    let (mut sum, mut term) = (C::new(0.0, 0.0), C::new(1.0, 0.0));
    for k in 1..=16 {
        term /= k as f64;
        sum += term;
        term *= u;
    }
    sum
}

/// One tabulated direction θ in Putzer's form: with `λ₁, λ₂, λ₃` the
/// eigenvalues of `W` (the Stroh roots) and `g(λ) = e^{−isλ}`,
/// `P exp(−isW) H = g[λ₁] Q₀ + g[λ₁,λ₂] Q₁ + g[λ₁,λ₂,λ₃] Q₂` with
/// `Q₀ = PH`, `Q₁ = P(W − λ₁)H`, `Q₂ = P(W − λ₁)(W − λ₂)H` and `g[…]`
/// divided differences (Cayley–Hamilton: exact for any `W`, defective or
/// not, which an eigenvector route is not). Per depth it costs three
/// exponentials and 54 products instead of a matrix exponential.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    pub(super) lam: [C; 3],
    /// The slowest decay of its roots, `min −Im λ`.
    pub(super) decay: f64,
    /// Largest distance between two roots.
    pub(super) spread: f64,
    /// The pairs `(0, 1), (0, 2), (1, 2)`: `|λⱼ − λᵢ|` and `1/(λⱼ − λᵢ)`
    /// (0 for equal roots, never used then).
    gap: [f64; 3],
    inv: [C; 3],
    /// The pair `(p, q)` farthest apart (an index into [`PAIRS`]) and the
    /// pairs `(r, q)`, `(r, p)` of the third root `r` with it.
    pub(super) far: usize,
    ends: [usize; 2],
    /// `Q₀, Q₁, Q₂`, each 6x3 row major (`[3·row + column]`).
    pub(super) q: [[C; 18]; 3],
}

/// The root pairs of [`Node::gap`] and the root outside each.
const PAIRS: [(usize, usize, usize); 3] = [(0, 1, 2), (0, 2, 1), (1, 2, 0)];

pub(super) fn flat(m: &M63) -> [C; 18] {
    std::array::from_fn(|c| m[(c / 3, c % 3)])
}

impl Node {
    /// The node of direction `d`, its roots in the order nearest `prev`'s
    /// (the previous node's) when given.
    fn new(d: &Direction, isotropic: bool, prev: Option<&[C; 3]>) -> Result<Self, SolverError> {
        let i = M3::identity();
        let (lam, q) = if isotropic {
            let nil = d.w + i * C::new(0.0, 1.0);
            let q = [flat(&d.ph), flat(&(d.p * nil * d.h)), [C::default(); 18]];
            ([C::new(0.0, -1.0); 3], q)
        } else {
            let ev = d.w.eigenvalues().ok_or_else(|| {
                SolverError::invalid(
                    "material",
                    "the Stroh matrix of a direction has no eigenvalues (stresses below the surface)",
                )
            })?;
            let mut lam = [ev[0], ev[1], ev[2]];
            if let Some(prev) = prev {
                const ORDERS: [[usize; 3]; 6] = [
                    [0, 1, 2],
                    [0, 2, 1],
                    [1, 0, 2],
                    [1, 2, 0],
                    [2, 0, 1],
                    [2, 1, 0],
                ];
                let cost =
                    |o: &[usize; 3]| -> f64 { (0..3).map(|k| (lam[o[k]] - prev[k]).norm()).sum() };
                let best = ORDERS
                    .iter()
                    .min_by(|a, b| cost(a).total_cmp(&cost(b)))
                    .expect("six orders");
                lam = best.map(|k| lam[k]);
            }
            let a = d.w - i * lam[0];
            let b = a * (d.w - i * lam[1]);
            let q = [flat(&d.ph), flat(&(d.p * a * d.h)), flat(&(d.p * b * d.h))];
            (lam, q)
        };
        Ok(Node::with(lam, q))
    }

    /// The node of roots `lam` and matrices `q`.
    pub(super) fn with(lam: [C; 3], q: [[C; 18]; 3]) -> Self {
        let gap = PAIRS.map(|(a, b, _)| (lam[b] - lam[a]).norm());
        let inv = PAIRS.map(|(a, b, _)| {
            let d = lam[b] - lam[a];
            if d.norm_sqr() > 0.0 {
                d.inv()
            } else {
                C::default()
            }
        });
        let far = (0..3)
            .max_by(|&a, &b| gap[a].total_cmp(&gap[b]))
            .expect("three pairs");
        let (p, q2, r) = PAIRS[far];
        let index = |a: usize, b: usize| {
            PAIRS
                .iter()
                .position(|&(i, j, _)| (i, j) == (a.min(b), a.max(b)))
                .expect("a pair of distinct roots")
        };
        Node {
            lam,
            decay: lam.iter().map(|l| -l.im).fold(f64::INFINITY, f64::min),
            spread: gap[far],
            gap,
            inv,
            far,
            ends: [index(r, q2), index(r, p)],
            q,
        }
    }
}

/// Putzer's coefficients `g[λ₁], g[λ₁,λ₂], g[λ₁,λ₂,λ₃]` of
/// `g(λ) = e^{−isλ}` (divided differences) at `node`, stable for close and
/// equal roots: a series where the roots are within `CLUSTER/s` of each
/// other, difference quotients of exponentials that all decay (no
/// overflow) elsewhere.
pub(super) fn divided(s: f64, node: &Node) -> [C; 3] {
    let x = C::new(0.0, -s);
    divided_with(s, node, &node.lam.map(|l| (x * l).exp()))
}

/// [`divided`] from the exponentials `e^{−isλ}` of the three roots (a
/// slice's rows step them by one product each).
pub(super) fn divided_with(s: f64, node: &Node, e: &[C; 3]) -> [C; 3] {
    let x = C::new(0.0, -s);
    let lam = &node.lam;
    let e1 = e[0];
    if s * node.spread < CLUSTER {
        // g[λ₁,λ₂] = e^{xλ₁} x φ₁(u), g[λ₁,λ₂,λ₃] = e^{xλ₁} x² Σ h_k(u,v)/(k+2)!,
        // u = x(λ₂ − λ₁), v = x(λ₃ − λ₁), h_k the complete symmetric polynomial.
        let (u, v) = (x * (lam[1] - lam[0]), x * (lam[2] - lam[0]));
        let (mut h, mut vk, mut fact) = (C::new(1.0, 0.0), C::new(1.0, 0.0), 2.0);
        let mut psi = C::new(0.0, 0.0);
        for k in 0..16 {
            psi += h / fact;
            vk *= v;
            h = u * h + vk;
            fact *= (k + 3) as f64;
        }
        return [e1, e1 * x * phi1(u), e1 * x * x * psi];
    }
    // g[λᵢ, λⱼ] of pair k.
    let two = |k: usize| {
        let (i, j, _) = PAIRS[k];
        if s * node.gap[k] < CLUSTER {
            e[i] * x * phi1(x * (lam[j] - lam[i]))
        } else {
            (e[j] - e[i]) * node.inv[k]
        }
    };
    // The third from the pair farthest apart (s·|λq − λp| ≥ CLUSTER):
    // g[λr, λp, λq] = (g[λr, λq] − g[λr, λp]) / (λq − λp).
    let [rq, rp] = node.ends;
    [e1, two(0), (two(rq) - two(rp)) * node.inv[node.far]]
}

/// The isotropic surface compliance of PHYSICS.md §3.
fn isotropic_h(g: f64, nu: f64, theta: f64) -> M3 {
    let (s, c) = theta.sin_cos();
    let r = |v: f64| C::new(v / g, 0.0);
    let i = |v: f64| C::new(0.0, v / g);
    let k = 0.5 * (1.0 - 2.0 * nu);
    M3::new(
        r(1.0 - nu * c * c),
        r(-nu * c * s),
        i(-k * c),
        r(-nu * c * s),
        r(1.0 - nu * s * s),
        i(-k * s),
        i(k * c),
        i(k * s),
        r(1.0 - nu),
    )
}

/// `exp(x)` of a 3x3 complex matrix: scaling and squaring of a 14-term
/// Taylor series (the scaled norm is at most 1/2, so the truncation is
/// below 3e-17). Exact for defective matrices, which an eigenvector route is not.
/// The tests' oracle for [`Node`]'s exponential.
#[cfg(test)]
fn expm3(x: &M3) -> M3 {
    let norm = (0..3)
        .map(|j| (0..3).map(|i| x[(i, j)].norm()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale *= 0.5;
        squarings += 1;
    }
    let a = x * C::new(scale, 0.0);
    let mut term = M3::identity();
    let mut sum = M3::identity();
    for k in 1..=14 {
        term = term * a * C::new(1.0 / k as f64, 0.0);
        sum += term;
    }
    for _ in 0..squarings {
        sum = sum * sum;
    }
    sum
}

/// Largest fourth difference of a node's roots and matrices, relative to
/// their size, below which a stencil counts as smooth: 4-point Lagrange
/// then errs by about `3/128` of it, 2e-8 (at 4e-8, for an error of 1e-9,
/// only 65 % of Fe(111)'s stencils qualified: a harmonic of order 6 in θ
/// alone has a fourth difference of 1e-7 at 2048 nodes; a crossing of
/// roots or their order wrapping at 2π gives one of order 1).
const SMOOTH_DIFFERENCE: f64 = 1e-6;

/// [`Response::smooth`] of a crystal's nodes: every value of each of the
/// four nodes of a stencil (with two more either side) has a small fourth
/// difference.
fn smooth_stencils(nodes: &[Node]) -> Vec<bool> {
    let k = nodes.len() as i64;
    let at = |i: i64| &nodes[i.rem_euclid(k) as usize];
    // Fourth difference centred on node i, relative.
    let rough: Vec<bool> = (0..k)
        .map(|i| {
            let w = [1.0, -4.0, 6.0, -4.0, 1.0];
            let diff = |f: &dyn Fn(&Node) -> C| -> C {
                (0..5).map(|j| f(at(i - 2 + j as i64)) * w[j]).sum()
            };
            let scale_l = at(i).lam.iter().map(|v| v.norm()).fold(0.0, f64::max);
            let lam_rough =
                (0..3).any(|r| diff(&|n: &Node| n.lam[r]).norm() > SMOOTH_DIFFERENCE * scale_l);
            let q_rough = (0..3).any(|kk| {
                let scale = at(i).q[kk].iter().map(|v| v.norm()).fold(0.0, f64::max);
                (0..18).any(|c| {
                    diff(&|n: &Node| n.q[kk][c]).norm() > SMOOTH_DIFFERENCE * scale.max(1e-300)
                })
            });
            lam_rough || q_rough
        })
        .collect();
    (0..k)
        .map(|s| (0..4).all(|j| !rough[(s + j).rem_euclid(k) as usize]))
        .collect()
}

impl Response {
    /// One node interpolated between the four of a smooth stencil (its
    /// roots and matrices), or `None` off a smooth stencil.
    pub(super) fn interpolated(&self, nodes: &[(usize, f64); 4]) -> Option<Node> {
        if self.isotropic || !self.smooth[nodes[0].0] {
            return None;
        }
        let mut lam = [C::default(); 3];
        let mut q = [[C::default(); 18]; 3];
        for &(i, w) in nodes {
            let n = &self.nodes[i];
            for (a, b) in lam.iter_mut().zip(&n.lam) {
                *a += b * w;
            }
            for (qa, qb) in q.iter_mut().zip(&n.q) {
                for (a, b) in qa.iter_mut().zip(qb) {
                    *a += b * w;
                }
            }
        }
        Some(Node::with(lam, q))
    }
}

impl Response {
    pub(super) fn of(material: &Material) -> Result<Self, SolverError> {
        let cv = material.stiffness();
        let t = voigt_to_tensor(&cv);
        let theta = |k: usize| 2.0 * std::f64::consts::PI * k as f64 / STROH_DIRECTIONS as f64;
        let (isotropic, table): (bool, Vec<Direction>) = match &material.elasticity {
            Elasticity::Isotropic(iso) => {
                if iso.poisson >= 0.5 {
                    return Err(SolverError::invalid(
                        "poisson",
                        "stresses below the surface need ν < 0.5 (the stiffness of an incompressible solid is unbounded)",
                    ));
                }
                let (g, nu) = (iso.shear(), iso.poisson);
                let table = (0..STROH_DIRECTIONS)
                    .map(|k| Direction::new(&t, &cv, theta(k), isotropic_h(g, nu, theta(k))))
                    .collect();
                (true, table)
            }
            Elasticity::Anisotropic(_) => {
                let table = (0..STROH_DIRECTIONS)
                    .map(|k| {
                        let h = surface_compliance_tensor(
                            &t,
                            theta(k),
                            crate::green::aniso::stroh::DEFAULT_OMEGA_POINTS,
                        );
                        Direction::new(&t, &cv, theta(k), h)
                    })
                    .collect();
                (false, table)
            }
        };
        let mut nodes: Vec<Node> = Vec::with_capacity(table.len());
        for d in &table {
            let prev = nodes.last().map(|n| n.lam);
            nodes.push(Node::new(d, isotropic, prev.as_ref())?);
        }
        let smooth = if isotropic {
            vec![false; nodes.len()]
        } else {
            smooth_stencils(&nodes)
        };
        let slowest = nodes
            .iter()
            .flat_map(|n| n.lam.iter().map(|l| -l.im))
            .fold(f64::INFINITY, f64::min);
        Ok(Response {
            isotropic,
            nodes,
            smooth,
            slowest,
            #[cfg(test)]
            table,
        })
    }

    /// The nodes and 4-point Lagrange weights of direction θ.
    pub(super) fn nodes(&self, theta: f64) -> [(usize, f64); 4] {
        let k = self.nodes.len();
        let u =
            theta.rem_euclid(2.0 * std::f64::consts::PI) / (2.0 * std::f64::consts::PI) * k as f64;
        let i0 = u.floor() as i64;
        let f = u - i0 as f64;
        let wts = [
            -f * (f - 1.0) * (f - 2.0) / 6.0,
            (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
            -(f + 1.0) * f * (f - 2.0) / 2.0,
            (f + 1.0) * f * (f - 1.0) / 6.0,
        ];
        std::array::from_fn(|j| ((i0 - 1 + j as i64).rem_euclid(k as i64) as usize, wts[j]))
    }

    /// `P H` along θ: the response at `s = 0`.
    pub(super) fn surface(&self, theta: f64) -> [C; 18] {
        let mut ph = [C::default(); 18];
        for (i, wt) in self.nodes(theta) {
            for (a, q) in ph.iter_mut().zip(&self.nodes[i].q[0]) {
                *a += q * wt;
            }
        }
        ph
    }

    /// Stress per unit traction `σ̂ = M t̂` (6x3 row major) at wave vector
    /// `(ex, ey)` and depth `z`.
    pub(super) fn at(&self, ex: f64, ey: f64, z: f64) -> [C; 18] {
        if z == 0.0 {
            return self.surface(ey.atan2(ex));
        }
        // (not `hypot`: its care for overflow took 13 % of a plane's time)
        let s = (ex * ex + ey * ey).sqrt() * z;
        let mut acc = [C::default(); 18];
        if self.decayed(s) {
            return acc;
        }
        let theta = ey.atan2(ex);
        if self.isotropic {
            // One set of coefficients for the four nodes (their roots are
            // all −i): g[λ] = e^{−s}, g[λ, λ] = −is e^{−s}.
            let decay = (-s).exp();
            for (i, wt) in self.nodes(theta) {
                let (r, m) = (decay * wt, -s * decay * wt);
                let q = &self.nodes[i].q;
                for (c, a) in acc.iter_mut().enumerate() {
                    // q₀ r + q₁ (i m)
                    a.re += q[0][c].re * r - q[1][c].im * m;
                    a.im += q[0][c].im * r + q[1][c].re * m;
                }
            }
        } else {
            let nodes = self.nodes(theta);
            // (this direction's own decay: a crystal's slowest root over
            // all directions decays slower than most)
            if self.decay(&nodes) * s > DECAY_LIMIT {
                return acc;
            }
            match self.interpolated(&nodes) {
                // One node's exponentials where the roots interpolate.
                Some(node) => {
                    let g = divided(s, &node);
                    for (c, a) in acc.iter_mut().enumerate() {
                        *a = node.q[0][c] * g[0] + node.q[1][c] * g[1] + node.q[2][c] * g[2];
                    }
                }
                None => {
                    for (i, wt) in nodes {
                        let node = &self.nodes[i];
                        let g = divided(s, node).map(|v| v * wt);
                        for (c, a) in acc.iter_mut().enumerate() {
                            *a += node.q[0][c] * g[0] + node.q[1][c] * g[1] + node.q[2][c] * g[2];
                        }
                    }
                }
            }
        }
        acc
    }

    /// True when the response at `s = ρz` has decayed below round-off of
    /// the surface's (`e^{−DECAY_LIMIT}` = 2.3e-16, times the divided
    /// differences' powers of `s`; 45 instead cost a 256² plane 15 % more): a deep plane's or row's high
    /// frequencies are left out (at 25 cells deep, 80 % of them).
    pub(super) fn decayed(&self, s: f64) -> bool {
        self.slowest * s > DECAY_LIMIT
    }

    /// The slowest decay of the roots of a direction's four `nodes`: its
    /// response has decayed (as in [`Response::decayed`]) from
    /// `s = DECAY_LIMIT / decay` on.
    pub(super) fn decay(&self, nodes: &[(usize, f64); 4]) -> f64 {
        nodes
            .iter()
            .map(|&(i, _)| self.nodes[i].decay)
            .fold(f64::INFINITY, f64::min)
    }

    /// The response at `η = 0`: its limit depends on the direction; the
    /// mean over directions (the in-plane rows; the `z` rows are `−I` along
    /// every direction).
    pub(super) fn mean_at_zero(&self) -> [C; 18] {
        let k = 64;
        let mut acc = [C::default(); 18];
        for i in 0..k {
            let s = self.surface(2.0 * std::f64::consts::PI * i as f64 / k as f64);
            for (a, v) in acc.iter_mut().zip(s) {
                *a += v / k as f64;
            }
        }
        acc
    }
}

/// The construction before issue #51 (interpolate `P`, `W`, `H`, then the
/// exponential per frequency): the oracle of the tests.
#[cfg(test)]
impl Response {
    /// `P`, `W`, `H` along θ.
    fn direction(&self, theta: f64) -> Direction {
        let mut d = Direction {
            p: M63::zeros(),
            w: M3::zeros(),
            h: M3::zeros(),
            ph: M63::zeros(),
        };
        for (i, wt) in self.nodes(theta) {
            let node = &self.table[i];
            let c = C::new(wt, 0.0);
            d.p += node.p * c;
            d.w += node.w * c;
            d.h += node.h * c;
            d.ph += node.ph * c;
        }
        d
    }

    /// `exp(−isW)`.
    fn propagator(&self, d: &Direction, s: f64) -> M3 {
        if s == 0.0 {
            return M3::identity();
        }
        if self.isotropic {
            let nil = d.w + M3::identity() * C::new(0.0, 1.0);
            (M3::identity() - nil * C::new(0.0, s)) * C::new((-s).exp(), 0.0)
        } else {
            expm3(&(d.w * C::new(0.0, -s)))
        }
    }

    /// `σ̂ = M t̂` the old way.
    pub(super) fn reference_at(&self, ex: f64, ey: f64, z: f64) -> M63 {
        let d = self.direction(ey.atan2(ex));
        if z == 0.0 {
            return d.ph;
        }
        d.p * self.propagator(&d, ex.hypot(ey) * z) * d.h
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::green::aniso::stroh::{surface_compliance_tensor, voigt_to_tensor};
    use crate::model::material::Elasticity;

    #[test]
    fn expm3_of_a_jordan_block_is_exact() {
        // exp(λI + N) with N² = 0 is e^λ (I + N).
        let lam = C::new(-3.0, 0.7);
        let mut n = M3::zeros();
        n[(0, 2)] = C::new(2.5, -1.0);
        n[(1, 2)] = C::new(0.3, 0.2);
        let x = M3::identity() * lam + n;
        let want = (M3::identity() + n) * lam.exp();
        assert!((expm3(&x) - want).camax() < 1e-14 * want.camax());
    }

    #[test]
    fn isotropic_w_has_the_triple_root_minus_i_and_a_nilpotent_part() {
        let fe = crate::model::presets::material("Fe").unwrap();
        let (cv, iso) = (fe.stiffness(), fe.equivalent);
        let t = voigt_to_tensor(&cv);
        for th in [0.0, 0.3, 1.2, 2.5, 4.0] {
            let d = Direction::new(&t, &cv, th, isotropic_h(iso.shear(), iso.poisson, th));
            let nil = d.w + M3::identity() * C::new(0.0, 1.0);
            let scale = d.w.camax();
            assert!(
                (nil * nil).camax() < 1e-12 * scale * scale,
                "(W + iI)² at θ = {th}"
            );
        }
    }

    /// Interpolation between the tabulated directions against direct
    /// evaluation halfway between nodes (the worst place).
    #[test]
    fn interpolated_directions_equal_direct_evaluation() {
        for name in ["Fe", "Cu(111)"] {
            let mat = crate::model::presets::material(name).unwrap();
            let r = Response::of(&mat).unwrap();
            let cv = mat.stiffness();
            let t = voigt_to_tensor(&cv);
            let mut worst: f64 = 0.0;
            for k in 0..40 {
                let th = (k as f64 * 51.0 + 0.5) * std::f64::consts::TAU / STROH_DIRECTIONS as f64;
                let h = match &mat.elasticity {
                    Elasticity::Isotropic(i) => isotropic_h(i.shear(), i.poisson, th),
                    Elasticity::Anisotropic(_) => surface_compliance_tensor(
                        &t,
                        th,
                        crate::green::aniso::stroh::DEFAULT_OMEGA_POINTS,
                    ),
                };
                let exact = Direction::new(&t, &cv, th, h);
                let d = r.direction(th);
                let rel = |a: M63, b: M63| (a - b).camax() / b.camax();
                worst = worst
                    .max(rel(d.p, exact.p))
                    .max(rel(M63::from_row_slice(&r.surface(th)), exact.ph));
                worst = worst.max((d.w - exact.w).camax() / exact.w.camax());
                worst = worst.max((d.h - exact.h).camax() / exact.h.camax());
            }
            assert!(worst < 1e-9, "{name}: {worst:e}");
        }
    }

    #[test]
    fn stroh_roots_decay_into_the_body() {
        let cu = crate::model::presets::material("Cu(111)").unwrap();
        let r = Response::of(&cu).unwrap();
        for k in 0..16 {
            let d = r.direction(k as f64 * 0.4);
            for p in d.w.eigenvalues().expect("eigenvalues").iter() {
                assert!(p.im < -0.1, "root {p} does not decay");
            }
        }
    }

    /// Putzer's form at a node against `P expm(−isW) H` (the matrix
    /// exponential by scaling and squaring), from the surface to where the
    /// response has decayed, for an isotropic body and two crystals.
    #[test]
    fn putzer_nodes_equal_the_matrix_exponential() {
        for name in ["Fe", "Cu(111)", "Fe(111)", "Cu"] {
            let mat = crate::model::presets::material(name).unwrap();
            let r = Response::of(&mat).unwrap();
            let mut worst: f64 = 0.0;
            for k in (0..STROH_DIRECTIONS).step_by(97) {
                let (d, node) = (&r.table[k], &r.nodes[k]);
                let scale = d.ph.camax();
                for s in [1e-6, 0.01, 0.3, 1.0, 2.7, 8.0, 30.0] {
                    let want = d.p * expm3(&(d.w * C::new(0.0, -s))) * d.h;
                    let g = divided(s, node);
                    let got: [C; 18] = std::array::from_fn(|c| {
                        node.q[0][c] * g[0] + node.q[1][c] * g[1] + node.q[2][c] * g[2]
                    });
                    worst = worst.max(largest_difference(&got, &want) / scale);
                }
            }
            eprintln!("{name}: Putzer against expm {worst:e} of max |PH|");
            assert!(worst < 1e-11, "{name}: {worst:e}");
        }
    }

    /// The divided differences through a root pair that closes up: the
    /// series and the difference quotients agree where they meet.
    #[test]
    fn divided_differences_are_continuous_across_the_cluster_threshold() {
        let x = C::new(0.0, -2.0);
        let base = [C::new(0.1, -1.0), C::new(0.1, -1.0), C::new(-0.3, -0.7)];
        for gap in [1e-9, 1e-4, 0.2, 0.249, 0.251, 0.3] {
            let lam = [base[0], base[1] + C::new(gap, 0.0), base[2]];
            let g = divided(2.0, &Node::with(lam, [[C::default(); 18]; 3]));
            // Reference: the divided differences by the exponential of the
            // companion-free bidiagonal matrix (Opitz: exp of the matrix
            // with λ on the diagonal and ones above carries them).
            let mut a = M3::zeros();
            for i in 0..3 {
                a[(i, i)] = lam[i] * x;
                if i < 2 {
                    a[(i, i + 1)] = x;
                }
            }
            let e = expm3(&a);
            let want = [e[(0, 0)], e[(0, 1)], e[(0, 2)]];
            for j in 0..3 {
                assert!(
                    (g[j] - want[j]).norm() < 1e-13 * want[0].norm().max(1.0),
                    "gap {gap}, g[{j}] {} against {}",
                    g[j],
                    want[j]
                );
            }
        }
    }

    /// The per-frequency response against the construction before issue
    /// #51 (P, W, H interpolated, then the exponential): both interpolate
    /// in θ between the same nodes, so they differ by the interpolation
    /// error only.
    #[test]
    fn fast_response_equals_the_interpolated_matrix_exponential() {
        // (the crystals twice: their roots interpolated where the stencil
        // is smooth, and every node's own exponentials everywhere)
        for (name, interpolate) in [
            ("Fe", true),
            ("Fe(111)", true),
            ("Cu(111)", true),
            ("Cu(111)", false),
        ] {
            let mat = crate::model::presets::material(name).unwrap();
            let mut r = Response::of(&mat).unwrap();
            if !interpolate {
                r.smooth.iter_mut().for_each(|b| *b = false);
            }
            let mut worst: f64 = 0.0;
            for k in 0..200 {
                let th = 0.37 + k as f64 * 0.0313;
                let (ex, ey) = (th.cos(), th.sin());
                let scale = r.reference_at(ex, ey, 0.0).camax();
                for z in [0.0, 0.02, 0.4, 1.0, 3.5, 12.0] {
                    let want = r.reference_at(ex, ey, z);
                    let got = r.at(ex, ey, z);
                    worst = worst.max(largest_difference(&got, &want) / scale);
                }
            }
            eprintln!("{name} (roots interpolated: {interpolate}): fast against interpolated expm {worst:e} of max |PH|");
            assert!(worst < 1e-8, "{name}: {worst:e}");
        }
    }

    /// max over the 18 entries of `|got − want|` (`got` in the row-major
    /// order of the 6x3 response).
    fn largest_difference(got: &[C; 18], want: &M63) -> f64 {
        (0..18)
            .map(|c| (got[c] - want[(c / 3, c % 3)]).norm())
            .fold(0.0, f64::max)
    }

    /// The crystals' stencils whose roots and matrices interpolate (one
    /// node's exponentials a frequency): nearly all of them, the rest near
    /// crossings of roots or where their order wraps at 2π.
    #[test]
    fn most_crystal_stencils_interpolate_their_roots() {
        for name in ["Fe(111)", "Cu(111)", "Ni(111)"] {
            let mat = crate::model::presets::material(name).unwrap();
            let r = Response::of(&mat).unwrap();
            let share = r.smooth.iter().filter(|&&b| b).count() as f64 / r.smooth.len() as f64;
            eprintln!(
                "{name}: {:.1} % of the stencils interpolate their roots",
                100.0 * share
            );
            assert!(share > 0.9, "{name}: {share}");
        }
    }
}
