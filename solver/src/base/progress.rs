//! Liveness ticks from the solver's long loops (kernel builds, solver
//! iterations, coupling passes, load increments), and the phase they are in.
//! A caller that must show it is alive while a solve runs — the worker
//! process, whose coordinator otherwise cannot tell a long computation from a
//! hang, or `mpcontact solve` on a terminal — installs a hook for its thread;
//! the hook decides how often it acts and may read [`phase`] to say what the
//! solve is doing. Without a hook a tick is one thread-local read (and an
//! iteration one more write). A hook may also [`cancel`] the solve of its
//! thread (the Python module does on Ctrl-C): the iteration loops then return
//! [`SolverError::Cancelled`]. Changes no number.

use std::cell::{Cell, RefCell};

use crate::error::SolverError;

/// A function called at every tick.
pub type TickHook = Box<dyn FnMut()>;

/// What the solve on a thread is iterating on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Stage {
    /// No solve has reported anything yet.
    #[default]
    Starting,
    /// Building (or loading) the kernel: the operator and the solvers' caches.
    Kernel,
    /// Normal contact (the pressure).
    Normal,
    /// Partial slip at fixed pressure (the shear tractions), with its coarse levels.
    Tangential,
}

/// Where the solve on a thread is, as the solver last reported it: read by a
/// tick hook (through [`phase`]) to show progress. Reset when a case starts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Phase {
    /// The segment of a load history being solved (1-based) and how many
    /// the path has (a segment's increments are chosen as it goes); `None`
    /// for a case without a history.
    pub segment: Option<(usize, usize)>,
    /// The coupling loop's pass (1-based) in the current step; `None` before
    /// it starts and when coupling is off (one uncoupled pass is no loop).
    pub pass: Option<usize>,
    /// What is being iterated on.
    pub stage: Stage,
    /// Iterations of the current stage's solve so far.
    pub iterations: usize,
}

thread_local! {
    static HOOK: RefCell<Option<TickHook>> = const { RefCell::new(None) };
    static CANCELLED: Cell<bool> = const { Cell::new(false) };
    static PHASE: Cell<Phase> = const {
        Cell::new(Phase {
            segment: None,
            pass: None,
            stage: Stage::Starting,
            iterations: 0,
        })
    };
}

/// Installs `hook` for the calling thread (or removes it with `None`);
/// returns the previous one. Clears a [`cancel`] of this thread.
pub fn set_tick_hook(hook: Option<TickHook>) -> Option<TickHook> {
    CANCELLED.with(|c| c.set(false));
    HOOK.with(|h| std::mem::replace(&mut *h.borrow_mut(), hook))
}

/// Asks the solve running on the calling thread to stop: the next iteration
/// of its normal, tangential or coupling loop returns
/// [`SolverError::Cancelled`] (a kernel being built is finished first: its
/// loop cannot return early without leaving a partial operator). Meant to be
/// called from a tick hook; stays in force, for every later solve of this
/// thread, until [`set_tick_hook`] is called again.
pub fn cancel() {
    CANCELLED.with(|c| c.set(true));
}

/// The phase of the solve on the calling thread (what a hook shows).
pub fn phase() -> Phase {
    PHASE.with(Cell::get)
}

/// Changes this thread's phase with `f`.
#[inline]
fn update(f: impl FnOnce(&mut Phase)) {
    PHASE.with(|c| {
        let mut ph = c.get();
        f(&mut ph);
        c.set(ph);
    });
}

/// A case starts: nothing of the previous one's phase remains.
pub(crate) fn start_case() {
    PHASE.with(|c| c.set(Phase::default()));
}

/// A solve of `stage` starts (its iterations count from zero).
pub(crate) fn stage(stage: Stage) {
    update(|ph| {
        ph.stage = stage;
        ph.iterations = 0;
    });
}

/// Segment `k` of `of` of a load history starts: a tick that may stop early.
pub(crate) fn segment(k: usize, of: usize) -> Result<(), SolverError> {
    update(|ph| {
        ph.segment = Some((k, of));
        ph.pass = None;
    });
    tick();
    cancelled()
}

/// Pass `k` of the coupling loop starts (`None` uncoupled): a tick that may
/// stop early.
pub(crate) fn pass(k: Option<usize>) -> Result<(), SolverError> {
    update(|ph| ph.pass = k);
    tick();
    cancelled()
}

/// An iteration of the current stage's loop, a tick that may stop early:
/// `Err(Cancelled)` after [`cancel`]. Changes no number.
#[inline]
pub(crate) fn tick_or_cancel() -> Result<(), SolverError> {
    update(|ph| ph.iterations += 1);
    tick();
    cancelled()
}

/// `Err(Cancelled)` after [`cancel`] on this thread.
#[inline]
fn cancelled() -> Result<(), SolverError> {
    if CANCELLED.with(Cell::get) {
        return Err(SolverError::Cancelled);
    }
    Ok(())
}

/// One step of a long loop is done.
#[inline]
pub(crate) fn tick() {
    HOOK.with(|h| {
        // A hook that ticks itself would borrow twice: that tick is skipped.
        if let Ok(mut h) = h.try_borrow_mut() {
            if let Some(f) = h.as_mut() {
                f();
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::rc::Rc;

    #[test]
    fn ticks_reach_the_hook_of_this_thread_only() {
        let count = Rc::new(std::cell::Cell::new(0));
        let c = count.clone();
        assert!(set_tick_hook(Some(Box::new(move || c.set(c.get() + 1)))).is_none());
        tick();
        tick();
        std::thread::spawn(tick).join().unwrap();
        assert_eq!(count.get(), 2);
        assert!(set_tick_hook(None).is_some());
        tick();
        assert_eq!(count.get(), 2);
    }

    fn small_case() -> crate::CaseSpec {
        crate::CaseSpec {
            material: crate::model::presets::material("Fe").unwrap(),
            surface: crate::Surface::Flat,
            grid: crate::Grid::square(32, 16e-6),
            load: crate::Load {
                indenter_radius_m: 18e-3,
                normal_force_n: 20.0,
                friction: 0.3,
                tangential_ratio: 0.6,
                angle_deg: 0.0,
            },
            numerics: crate::Numerics::default(),
            history: None,
            indenter: None,
        }
    }

    #[test]
    fn a_cancel_from_the_hook_stops_the_solve_and_leaves_later_solves_bit_identical() {
        let spec = small_case();
        let mut cache = crate::KernelCache::new();
        let plain = crate::solve_case(&spec, &mut cache).unwrap();
        // Cancel after the kernel rows (64) and a few iterations.
        let count = Rc::new(std::cell::Cell::new(0usize));
        let c = count.clone();
        set_tick_hook(Some(Box::new(move || {
            c.set(c.get() + 1);
            if c.get() == 70 {
                cancel();
            }
        })));
        let e = crate::solve_case(&spec, &mut crate::KernelCache::new()).unwrap_err();
        assert_eq!(e, crate::SolverError::Cancelled);
        // A cancelled thread stays cancelled for the next solve, until the
        // hook is set again.
        let again = crate::solve_case(&spec, &mut cache).unwrap_err();
        assert_eq!(again, crate::SolverError::Cancelled);
        set_tick_hook(None);
        let after = crate::solve_case(&spec, &mut cache).unwrap();
        let strip = |mut s: crate::CaseScalars| {
            (s.seconds, s.kernel_seconds) = (0.0, 0.0);
            s
        };
        assert_eq!(strip(after.scalars), strip(plain.scalars));
        assert_eq!(after.fields, plain.fields);
    }

    #[test]
    fn a_solve_ticks_in_its_kernel_build_and_iterations() {
        let count = Rc::new(std::cell::Cell::new(0usize));
        let c = count.clone();
        set_tick_hook(Some(Box::new(move || c.set(c.get() + 1))));
        let spec = small_case();
        let out = crate::solve_case(&spec, &mut crate::KernelCache::new()).unwrap();
        set_tick_hook(None);
        let s = &out.scalars;
        // At least one tick per kernel row (2N) and per fine iteration.
        let least = 64 + s.normal_iterations + s.tangential_iterations;
        assert!(
            count.get() >= least,
            "{} ticks, expected ≥ {least}",
            count.get()
        );
    }

    /// Every phase the hook sees during a solve of `spec` (from a new cache,
    /// so the kernel is built), and the solve's scalars.
    fn phases_of(spec: &crate::CaseSpec) -> (Vec<Phase>, crate::CaseScalars) {
        let seen = Rc::new(RefCell::new(Vec::new()));
        let s = seen.clone();
        set_tick_hook(Some(Box::new(move || s.borrow_mut().push(phase()))));
        let out = crate::solve_case(spec, &mut crate::KernelCache::new()).unwrap();
        set_tick_hook(None);
        let seen = seen.borrow().clone();
        (seen, out.scalars)
    }

    #[test]
    fn a_history_reports_each_segment_in_order_with_its_passes_and_iterations() {
        // Fretting, half a cycle out and back (0 → 0.6 → −0.6 of μP), 2
        // increments per segment: 2 segments, coupled.
        let spec = crate::CaseSpec {
            history: Some(crate::LoadHistory {
                tangential_ratios: vec![0.6, -0.6],
                normal_forces_n: None,
                increments: crate::Increments::Fixed(2),
                sampling: Default::default(),
                shifts_m: None,
                wear: None,
            }),
            ..small_case()
        };
        let (seen, scalars) = phases_of(&spec);
        assert_eq!(seen[0].stage, Stage::Kernel);
        assert_eq!(seen[0].segment, None);
        // The segments as the hook saw them: 1..=2 of 2, in order, none skipped.
        let mut segments: Vec<(usize, usize)> = seen.iter().filter_map(|p| p.segment).collect();
        segments.dedup();
        assert_eq!(segments, vec![(1, 2), (2, 2)]);
        // Coupled: every segment runs pass 1 of the coupling loop, and
        // the passes counted add up to the case's coupling iterations
        // (each increment's passes count up from 1).
        for k in 1..=2 {
            assert!(seen
                .iter()
                .any(|p| p.segment == Some((k, 2)) && p.pass == Some(1)));
        }
        let mut passes: Vec<usize> = seen.iter().filter_map(|p| p.pass).collect();
        passes.dedup();
        assert_eq!(passes.len(), scalars.coupling_iterations);
        // Iterations count up within a stage: a normal and a tangential
        // solve were seen at work.
        for stage in [Stage::Normal, Stage::Tangential] {
            assert!(seen.iter().any(|p| p.stage == stage && p.iterations > 1));
        }
    }

    #[test]
    fn an_uncoupled_single_step_reports_no_pass_and_no_segment() {
        let mut spec = small_case();
        spec.numerics.coupling = false;
        let (seen, scalars) = phases_of(&spec);
        assert!(seen.iter().all(|p| p.pass.is_none() && p.segment.is_none()));
        // The most iterations seen in the tangential stage are the solve's
        // (a tick comes at the start of each; 32² has no coarse levels,
        // whose iterations would count too).
        let most = seen
            .iter()
            .filter(|p| p.stage == Stage::Tangential)
            .map(|p| p.iterations)
            .max()
            .unwrap();
        assert_eq!(most, scalars.tangential_iterations);
        // A new case starts from a clean phase.
        start_case();
        assert_eq!(phase(), Phase::default());
    }
}
