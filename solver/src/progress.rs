//! Liveness ticks from the solver's long loops (kernel builds, solver
//! iterations, coupling passes). A caller that must show it is alive while a
//! solve runs — the worker process, whose coordinator otherwise cannot tell
//! a long computation from a hang — installs a hook for its thread; the hook
//! decides how often it acts. Without a hook a tick is one thread-local read.
//! Changes no number.

use std::cell::RefCell;

/// A function called at every tick.
pub type TickHook = Box<dyn FnMut()>;

thread_local! {
    static HOOK: RefCell<Option<TickHook>> = const { RefCell::new(None) };
}

/// Installs `hook` for the calling thread (or removes it with `None`);
/// returns the previous one.
pub fn set_tick_hook(hook: Option<TickHook>) -> Option<TickHook> {
    HOOK.with(|h| std::mem::replace(&mut *h.borrow_mut(), hook))
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

    #[test]
    fn a_solve_ticks_in_its_kernel_build_and_iterations() {
        let count = Rc::new(std::cell::Cell::new(0usize));
        let c = count.clone();
        set_tick_hook(Some(Box::new(move || c.set(c.get() + 1))));
        let spec = crate::CaseSpec {
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
        };
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
