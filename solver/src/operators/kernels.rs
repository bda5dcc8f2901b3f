//! A kernel's identity (material constants and grid), the persistent
//! [`KernelStore`] port a caller may supply (the worker's files), and how an
//! operator is obtained: loaded from the store, waited for while another
//! process sharing the store builds it, or built. Solves nothing; the
//! solvers' caches kept with an operator are `solve::resident`'s.

use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::model::material::Material;
use crate::model::spec::CaseSpec;
use crate::operators::operator::{Operator, Spectra};

/// Identity of a kernel: material name and constants, cells per side and
/// cell size. Its text (`name|n|dx|C11,…`) names an entry of a store.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct KernelKey(String);

impl KernelKey {
    /// The kernel a case needs.
    pub fn of(spec: &CaseSpec) -> Self {
        let consts = |m: &Material| {
            let c: Vec<String> = m.stiffness().iter().map(|v| format!("{v:.9e}")).collect();
            c.join(",")
        };
        let mut key = format!(
            "{}|{}|{:.9e}|{}",
            spec.material.name,
            spec.grid.n,
            spec.grid.dx,
            consts(&spec.material)
        );
        // An elastic ball makes another kernel; a rigid one keeps the key
        // (and the stored kernels) of before balls existed.
        if let Some(ball) = &spec.indenter {
            key.push_str(&format!("|ball {}|{}", ball.name, consts(ball)));
        }
        KernelKey(key)
    }

    /// The key as text (what a store writes and compares).
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for KernelKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Persistent storage of kernel spectra (e.g. files), so that a new process
/// does not pay an expensive anisotropic kernel build again.
pub trait KernelStore {
    /// The spectra stored under `key`, if present and of `len` values each
    /// (see [`Spectra::len_for`]).
    fn load(&self, key: &KernelKey, len: usize) -> Option<Spectra>;
    /// Stores the spectra under `key` (best effort).
    fn save(&self, key: &KernelKey, spectra: &Spectra);
    /// Tries to take the right to build `key` (so that processes sharing the
    /// store build each kernel once): [`BuildLock::Held`] until the guard is
    /// dropped, [`BuildLock::Busy`] while another holder builds it. The lock
    /// must end with its holder, also when the holder dies (e.g. `flock`).
    /// The default: no locking.
    fn try_lock(&self, _key: &KernelKey) -> BuildLock {
        BuildLock::Unsupported
    }
}

/// What [`KernelStore::try_lock`] found.
pub enum BuildLock {
    /// Ours until this guard is dropped.
    Held(Box<dyn std::any::Any>),
    /// Someone else holds it: wait, then look in the store again.
    Busy,
    /// The store does not lock (or cannot now): build without.
    Unsupported,
}

/// How often a process waiting for another's kernel build looks again
/// (the build it waits for takes seconds; 0.6 s for a 384² Cu(111) kernel).
const LOCK_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// The operator of a material on a grid, built row by row (see
/// [`Operator::build`]); from one quadrant of offsets when the material's
/// influence is mirror symmetric (see [`Operator::build_mirrored`]).
pub fn build_operator(material: &Material, grid: Grid) -> Operator {
    build_pair_operator(material, None, grid)
}

/// The operator of a substrate pressed by a ball of material `indenter`
/// (`None`: rigid, [`build_operator`]): the two bodies' compliances summed
/// ([`crate::model::material::pair_influence`]); mirrored from one quadrant when
/// both influences are mirror symmetric (R K(x, −y) R keeps the parities).
pub fn build_pair_operator(
    material: &Material,
    indenter: Option<&Material>,
    grid: Grid,
) -> Operator {
    let model = material.model();
    let (influence, mirror) = match indenter {
        None => (model.cell_influence(grid), model.mirror_symmetric()),
        Some(ball) => (
            crate::model::material::pair_influence(
                model.cell_influence(grid),
                ball.model().cell_influence(grid),
            ),
            model.mirror_symmetric() && ball.model().mirror_symmetric(),
        ),
    };
    if mirror {
        Operator::build_mirrored(grid, influence)
    } else {
        Operator::build(grid, influence)
    }
}

/// True when a case's kernel is expensive enough to persist (a numerical
/// Green's function on either body).
pub fn persists(spec: &CaseSpec) -> bool {
    spec.material.model().persist_tables()
        || spec
            .indenter
            .as_ref()
            .is_some_and(|m| m.model().persist_tables())
}

/// Where [`obtain_operator`] took an operator from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Obtained {
    /// Built in this process (and saved to the store when worth persisting).
    Built,
    /// Loaded from the store.
    Loaded,
}

/// The operator `spec` needs (`key` is [`KernelKey::of`] it): loaded from
/// `store` when the kernel is worth persisting ([`persists`]) and the store
/// holds it, waiting while another process sharing the store builds it;
/// otherwise built (and then saved to the store when worth persisting).
pub fn obtain_operator(
    store: Option<&dyn KernelStore>,
    key: &KernelKey,
    spec: &CaseSpec,
) -> Result<(Operator, Obtained), SolverError> {
    let grid = spec.grid;
    let len = Spectra::len_for(grid.n);
    let persistent = persists(spec);
    let load = |store: &dyn KernelStore| {
        store
            .load(key, len)
            .and_then(|s| Operator::from_spectra(grid, s))
    };
    let mut loaded = None;
    // Held while this process builds the kernel, so that others
    // sharing the store wait for it and load it instead.
    let mut _guard = None;
    if let (Some(store), true) = (store, persistent) {
        loaded = load(store);
        while loaded.is_none() {
            match store.try_lock(key) {
                BuildLock::Held(g) => {
                    // Built by the previous holder while we waited?
                    loaded = load(store);
                    _guard = Some(g);
                    break;
                }
                BuildLock::Busy => {
                    // A waiting worker still shows it is alive, and
                    // a cancel still stops it.
                    crate::base::progress::tick_or_cancel()?;
                    std::thread::sleep(LOCK_POLL);
                    loaded = load(store);
                }
                BuildLock::Unsupported => break,
            }
        }
    }
    let obtained = match loaded {
        Some(op) => (op, Obtained::Loaded),
        None => {
            let mut op = build_pair_operator(&spec.material, spec.indenter.as_ref(), grid);
            if let (Some(store), true) = (store, persistent) {
                op.with_spectra(|s| store.save(key, s));
            }
            (op, Obtained::Built)
        }
    };
    drop(_guard);
    Ok(obtained)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::green::influence::isotropic_cell;

    fn bits(s: &Spectra) -> Vec<u64> {
        let re = s.diag.iter().flatten().map(|v| v.to_bits());
        let cx = s
            .off
            .iter()
            .flatten()
            .flat_map(|z| [z.re.to_bits(), z.im.to_bits()]);
        re.chain(cx).collect()
    }

    /// The quadrant-and-mirror build hands the transforms the rows of the
    /// direct build, so the spectra are equal to the bit.
    #[test]
    fn mirrored_build_equals_the_direct_build_to_the_bit() {
        for (n, dx, dy) in [(48, 1.0e-6, 1.3e-6), (33, 2.0e-6, 2.0e-6)] {
            let grid = Grid { n, dx, dy };
            let (g, nu) = (80.0e9, 0.29);
            let cell = |x, y| isotropic_cell(g, nu, x, y, dx, dy);
            let direct = Operator::build(grid, cell).with_spectra(bits);
            let mirrored = Operator::build_mirrored(grid, cell).with_spectra(bits);
            assert!(direct == mirrored, "n = {n}");
        }
    }

    /// Isotropic materials take the mirrored build.
    #[test]
    fn isotropic_materials_are_mirror_symmetric_and_crystals_are_not() {
        let fe = crate::model::presets::material("Fe").unwrap();
        assert!(fe.model().mirror_symmetric());
        let cu111 = crate::model::presets::material("Cu(111)").unwrap();
        assert!(!cu111.model().mirror_symmetric());
    }
}
