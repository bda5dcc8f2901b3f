//! Liveness ticks from the solver's long loops (kernel builds, solver
//! iterations, coupling passes). A caller that must show it is alive while a
//! solve runs — the worker process, whose coordinator otherwise cannot tell
//! a long computation from a hang — installs a hook for its thread; the hook
//! decides how often it acts. Without a hook a tick is one thread-local read.
//! A hook may also [`cancel`] the solve of its thread (the Python module does
//! on Ctrl-C): the iteration loops then return [`SolverError::Cancelled`].
//! Changes no number.

use std::cell::{Cell, RefCell};

use crate::error::SolverError;

/// A function called at every tick.
pub type TickHook = Box<dyn FnMut()>;

thread_local! {
    static HOOK: RefCell<Option<TickHook>> = const { RefCell::new(None) };
    static CANCELLED: Cell<bool> = const { Cell::new(false) };
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

/// A tick in a loop that may stop early: `Err(Cancelled)` after [`cancel`].
/// One more thread-local read than [`tick`]; changes no number.
#[inline]
pub(crate) fn tick_or_cancel() -> Result<(), SolverError> {
    tick();
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
            material: crate::presets::material("Fe").unwrap(),
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
}
