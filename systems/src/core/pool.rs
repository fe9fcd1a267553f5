//! The per-run rayon pool that parallel kernels (ray casting, particles, DE populations) run on.
//! Its size comes from `--threads`; results never depend on it (fixed chunking, ordered output).

use bevy_ecs::prelude::Resource;
use std::sync::Arc;

#[derive(Resource, Clone)]
pub struct KernelPool(pub Arc<rayon::ThreadPool>);

impl KernelPool {
    /// A pool with `threads` workers (0 = one per core).
    pub fn new(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("sim-kernel-{i}"))
            .build()?;
        Ok(KernelPool(Arc::new(pool)))
    }

    pub fn threads(&self) -> usize {
        self.0.current_num_threads()
    }

    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.0.install(f)
    }

    /// Runs `f` on every item with a scratch value from `init` (one per rayon task): in
    /// parallel on the pool when there are several items, on the calling thread when there is
    /// one — handing a single short job to a pool thread and waiting for it costs more than the
    /// job (two thread wake-ups, and the idle workers spin before they sleep), and a
    /// single-robot world does that several times a tick. `f` must not use the pool itself
    /// (it runs outside it for a single item). Results are the same either way.
    pub fn for_each_init<T: Send, S>(
        &self,
        items: &mut [T],
        init: impl Fn() -> S + Send + Sync,
        f: impl Fn(&mut S, &mut T) + Send + Sync,
    ) {
        use rayon::prelude::*;
        match items {
            [] => {}
            [one] => f(&mut init(), one),
            _ => self.install(|| items.par_iter_mut().for_each_init(init, f)),
        }
    }

    /// [`KernelPool::for_each_init`] without scratch.
    pub fn for_each<T: Send>(&self, items: &mut [T], f: impl Fn(&mut T) + Send + Sync) {
        self.for_each_init(items, || (), |_, item| f(item));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn for_each_visits_every_item_once_whatever_the_count() {
        let pool = KernelPool::new(2).unwrap();
        for n in [0, 1, 2, 7] {
            let mut items: Vec<usize> = (0..n).collect();
            pool.for_each_init(&mut items, || 10, |s, x| *x = *x * 2 + *s);
            assert_eq!(items, (0..n).map(|x| x * 2 + 10).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_single_item_runs_on_the_calling_thread() {
        let pool = KernelPool::new(2).unwrap();
        let caller = std::thread::current().id();
        let mut one = [None];
        pool.for_each(&mut one, |t| *t = Some(std::thread::current().id()));
        assert_eq!(one[0], Some(caller));
        let mut two = [None, None];
        pool.for_each(&mut two, |t| *t = Some(std::thread::current().id()));
        assert!(
            two.iter().all(|t| *t != Some(caller)),
            "several items go to the pool"
        );
    }
}
