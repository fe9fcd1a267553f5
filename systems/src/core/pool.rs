//! The per-run rayon pool that parallel kernels (ray casting, particles, DE populations) run on.
//! Its size comes from `--threads`; results never depend on it (fixed chunking, ordered output).
//!
//! Between parallel sections the pool keeps all but one of its workers spinning for a short
//! while (see [`KernelPool::install`]): a tick alternates parallel kernels with about a
//! millisecond of serial work (the rapier2d step), long enough for rayon's idle workers to go to
//! sleep, and waking a sleeping worker costs a fraction of a millisecond per parallel section
//! (sim/docs/benchmarks.md, "Swarm").

use bevy_ecs::prelude::Resource;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The most workers a pool may have: far more than any machine's cores (results do not depend
/// on the count), few enough to start in well under a second.
pub const MAX_THREADS: usize = 1024;

/// Why a [`KernelPool`] could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PoolError {
    #[error("{0} threads is more than the {MAX_THREADS} a pool may have")]
    TooMany(usize),
    #[error(transparent)]
    Build(#[from] rayon::ThreadPoolBuildError),
}

/// How long workers stay awake after a parallel section, waiting for the next one.
const STAY_AWAKE: Duration = Duration::from_millis(3);

#[derive(Resource, Clone)]
pub struct KernelPool {
    /// None: an inline pool, running every section on the calling thread.
    pool: Option<Arc<rayon::ThreadPool>>,
    /// Workers kept awake after a parallel section: at most one less than the cores, so the
    /// calling thread's serial work keeps a core of its own.
    awake: usize,
    /// Bumped at the start and end of every parallel section; a waiting worker stops as soon as
    /// it changes (the next section needs it) or after [`STAY_AWAKE`].
    section: Arc<AtomicU64>,
    /// Waiting jobs queued so far.
    queued: Arc<AtomicU64>,
}

impl KernelPool {
    /// A pool with `threads` workers (0 = one per core); an error, not a panic, when there are
    /// more than [`MAX_THREADS`] or a worker cannot be started.
    pub fn new(threads: usize) -> Result<Self, PoolError> {
        if threads > MAX_THREADS {
            return Err(PoolError::TooMany(threads));
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("sim-kernel-{i}"))
            .build()?;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let awake = pool.current_num_threads().min(cores).saturating_sub(1);
        Ok(KernelPool {
            pool: Some(Arc::new(pool)),
            awake,
            section: Arc::new(AtomicU64::new(0)),
            queued: Arc::new(AtomicU64::new(0)),
        })
    }

    /// A pool without threads of its own: every section runs on the calling thread, and
    /// rayon's parallel iterators in it on the pool the caller runs in (rayon's global pool
    /// outside any). For worlds stepped side by side on another pool's workers: each world's
    /// kernels stay on the worker stepping it, with no hand-over to a thread of its own.
    pub fn inline() -> Self {
        KernelPool {
            pool: None,
            awake: 0,
            section: Arc::new(AtomicU64::new(0)),
            queued: Arc::new(AtomicU64::new(0)),
        }
    }

    pub fn threads(&self) -> usize {
        self.pool.as_ref().map_or(1, |p| p.current_num_threads())
    }

    /// Runs `f` inside the pool (rayon's parallel iterators in it use the pool's workers). Any
    /// worker still waiting from the previous section is released first, and afterwards some
    /// wait for the next section (for `STAY_AWAKE` at most).
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.section.fetch_add(1, Ordering::AcqRel);
        let Some(pool) = &self.pool else {
            return f();
        };
        let r = pool.install(f);
        self.stay_awake();
        r
    }

    /// Queues `awake` jobs that spin until the next section starts or [`STAY_AWAKE`] passes.
    /// Not from inside the pool (a nested `install`): a waiting job queued there would hold a
    /// worker that the enclosing section still needs.
    fn stay_awake(&self) {
        let Some(pool) = &self.pool else {
            return;
        };
        if self.awake == 0 || pool.current_thread_index().is_some() {
            return;
        }
        let this = self.section.fetch_add(1, Ordering::AcqRel) + 1;
        self.queued.fetch_add(self.awake as u64, Ordering::Relaxed);
        for _ in 0..self.awake {
            let section = self.section.clone();
            pool.spawn(move || {
                let since = Instant::now();
                let mut spins = 0u32;
                while section.load(Ordering::Acquire) == this {
                    std::hint::spin_loop();
                    spins = spins.wrapping_add(1);
                    if spins.is_multiple_of(256) {
                        if since.elapsed() > STAY_AWAKE {
                            break;
                        }
                        // a thread of another run waiting for this core gets it (batch runs
                        // with several threads each); the core itself stays awake
                        std::thread::yield_now();
                    }
                }
            });
        }
    }

    /// Runs `f` on every item with a scratch value from `init` (one per rayon task): in
    /// parallel on the pool when there are several items and several workers, on the calling
    /// thread otherwise — handing short jobs to a single pool thread and waiting for it costs
    /// more than the jobs (two thread wake-ups), and a single-robot world does that several
    /// times a tick. `f` must not use the pool itself (it may run outside it). Results are the
    /// same either way.
    pub fn for_each_init<T: Send, S>(
        &self,
        items: &mut [T],
        init: impl Fn() -> S + Send + Sync,
        f: impl Fn(&mut S, &mut T) + Send + Sync,
    ) {
        use rayon::prelude::*;
        if items.len() < 2 || self.threads() < 2 {
            let mut scratch = init();
            items.iter_mut().for_each(|item| f(&mut scratch, item));
        } else {
            self.install(|| items.par_iter_mut().for_each_init(init, f));
        }
    }

    /// [`KernelPool::for_each_init`] with scratch the caller keeps from call to call (a system's
    /// `Local`), so that a tick allocates none: the items are cut into at most four runs per
    /// worker, each run with its own scratch (made by `S::default()` the first time).
    pub fn for_each_with<T: Send, S: Default + Send>(
        &self,
        items: &mut [T],
        scratch: &mut Vec<S>,
        f: impl Fn(&mut S, &mut T) + Send + Sync,
    ) {
        use rayon::prelude::*;
        let runs = if self.threads() < 2 {
            1
        } else {
            items.len().min(4 * self.threads()).max(1)
        };
        if scratch.len() < runs {
            scratch.resize_with(runs, S::default);
        }
        if runs == 1 {
            items.iter_mut().for_each(|item| f(&mut scratch[0], item));
        } else {
            let run = items.len().div_ceil(runs);
            self.install(|| {
                items
                    .par_chunks_mut(run)
                    .zip(scratch.par_iter_mut())
                    .for_each(|(run, s)| run.iter_mut().for_each(|item| f(s, item)))
            });
        }
    }

    /// [`KernelPool::for_each`] for short jobs: in parallel only from `min_items` items on. A
    /// parallel section costs a few microseconds of hand-over and wake-up, more than a handful of
    /// jobs of a microsecond or less save (a physics step's per-robot arithmetic, a wander
    /// behaviour). Results are the same either way.
    pub fn for_each_from<T: Send>(
        &self,
        min_items: usize,
        items: &mut [T],
        f: impl Fn(&mut T) + Send + Sync,
    ) {
        if items.len() < min_items {
            items.iter_mut().for_each(f);
        } else {
            self.for_each(items, f);
        }
    }

    /// Runs `f` on every item, each worker taking first the items of its own share: of `n`
    /// items over `t` workers, worker `w` owns items `w·n/t .. (w+1)·n/t`, the same ones at
    /// every call, so an item whose state is large (a whole world of a vectorized simulation)
    /// finds it in the caches of the core that last ran it, and in the allocator's arena of the
    /// thread that made it. A worker done with its share takes what is left of the others', so
    /// one slow item does not hold the rest. Results are the same as a loop over the items.
    pub fn for_each_pinned<T: Send>(&self, items: &mut [T], f: impl Fn(&mut T) + Send + Sync) {
        let threads = self.threads();
        let Some(pool) = self
            .pool
            .as_ref()
            .filter(|p| threads > 1 && items.len() > 1 && p.current_thread_index().is_none())
        else {
            return self.install(|| items.iter_mut().for_each(f));
        };
        let n = items.len();
        let start = |w: usize| w * n / threads;
        let cursors: Vec<AtomicUsize> = (0..threads).map(|w| AtomicUsize::new(start(w))).collect();
        // each item is taken by one worker only (the cursors hand every index out once), so its
        // lock is never contended; it makes the shared slice's items reachable from every worker
        let cells: Vec<Mutex<&mut T>> = items.iter_mut().map(Mutex::new).collect();
        self.section.fetch_add(1, Ordering::AcqRel);
        pool.broadcast(|ctx| {
            for k in 0..threads {
                let w = (ctx.index() + k) % threads;
                loop {
                    let i = cursors[w].fetch_add(1, Ordering::Relaxed);
                    if i >= start(w + 1) {
                        break;
                    }
                    let mut item = cells[i].lock().unwrap_or_else(|e| e.into_inner());
                    f(&mut item);
                }
            }
        });
        self.stay_awake();
    }

    /// Runs `f` on every item, the dearest first: the items are ordered by `cost` (highest
    /// first, ties in slice order) and each worker takes the next one as soon as it is free,
    /// so the cheap items fill the gaps at the end instead of one worker finishing a dear item
    /// alone (longest-processing-time-first list scheduling [Graham 1969]). For a few jobs of
    /// unequal cost that changes slowly from call to call (a tick's localizers, each costed by
    /// its recent updates). The items run inside the pool, so their own parallel kernels use it,
    /// also when there is a single item. Results are the same as a loop over the items.
    pub fn for_each_dearest_first<T: Send>(
        &self,
        items: &mut [T],
        cost: impl Fn(&T) -> f64,
        f: impl Fn(&mut T) + Send + Sync,
    ) {
        let threads = self.threads();
        let parallel = threads > 1 && items.len() > 1;
        let mut queue: Vec<(f64, &mut T)> = items.iter_mut().map(|t| (cost(&*t), t)).collect();
        queue.sort_by(|a, b| b.0.total_cmp(&a.0)); // stable: ties keep slice order
        let Some(pool) = self
            .pool
            .as_ref()
            .filter(|p| parallel && p.current_thread_index().is_none())
        else {
            return self.install(|| queue.into_iter().for_each(|(_, t)| f(t)));
        };
        // each item is taken by one worker only (the cursor hands every index out once), so its
        // lock is never contended; it makes the shared slice's items reachable from every worker
        let cells: Vec<Mutex<&mut T>> = queue.into_iter().map(|(_, t)| Mutex::new(t)).collect();
        let next = AtomicUsize::new(0);
        self.section.fetch_add(1, Ordering::AcqRel);
        pool.broadcast(|_| {
            while let Some(cell) = cells.get(next.fetch_add(1, Ordering::Relaxed)) {
                let mut item = cell.lock().unwrap_or_else(|e| e.into_inner());
                f(&mut item);
            }
        });
        self.stay_awake();
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
    fn more_threads_than_the_limit_is_an_error_before_any_starts() {
        for n in [MAX_THREADS + 1, 1 << 32] {
            let e = KernelPool::new(n).err().expect("too many threads accepted");
            assert!(matches!(e, PoolError::TooMany(t) if t == n), "{e}");
            assert!(e.to_string().contains("1024"), "{e}");
        }
    }

    /// An inline pool runs its sections on the calling thread, as a pool of one thread would
    /// run them (the same items, in order), and its parallel iterators on the caller's pool.
    #[test]
    fn an_inline_pool_runs_on_the_calling_thread() {
        let inline = KernelPool::inline();
        assert_eq!(inline.threads(), 1);
        let caller = std::thread::current().id();
        assert_eq!(inline.install(|| std::thread::current().id()), caller);
        let outer = KernelPool::new(2).unwrap();
        let (on_outer, sum) = outer.install(|| {
            inline.install(|| {
                use rayon::prelude::*;
                let sum: u64 = (0..1000u64).into_par_iter().map(|x| x * x).sum();
                (rayon::current_thread_index().is_some(), sum)
            })
        });
        assert!(on_outer, "ran on the outer pool's worker");
        assert_eq!(sum, (0..1000u64).map(|x| x * x).sum::<u64>());
        let one = KernelPool::new(1).unwrap();
        let (mut a, mut b): (Vec<u32>, Vec<u32>) = ((0..50).collect(), (0..50).collect());
        let (mut sa, mut sb) = (Vec::<Vec<u32>>::new(), Vec::<Vec<u32>>::new());
        inline.for_each_with(&mut a, &mut sa, |s, x| {
            s.push(*x);
            *x += 1;
        });
        one.for_each_with(&mut b, &mut sb, |s, x| {
            s.push(*x);
            *x += 1;
        });
        assert_eq!((a, sa), (b, sb));
    }

    /// Every item once, whatever the count and the threads; the scratch is made once per run
    /// and kept for the next call.
    #[test]
    fn for_each_with_visits_every_item_once_and_keeps_its_scratch() {
        for threads in [1, 2, 3] {
            let pool = KernelPool::new(threads).unwrap();
            let mut scratch: Vec<Vec<usize>> = Vec::new();
            for n in [0, 1, 2, 7, 100] {
                let mut items: Vec<usize> = (0..n).collect();
                pool.for_each_with(&mut items, &mut scratch, |s, x| {
                    s.push(*x);
                    *x *= 2;
                });
                assert_eq!(items, (0..n).map(|x| x * 2).collect::<Vec<_>>());
                assert!(scratch.len() <= 4 * threads);
            }
            // each item went through exactly one run's scratch, in all calls together
            let mut seen: Vec<usize> = scratch.concat();
            seen.sort_unstable();
            let mut expected: Vec<usize> = [0, 1, 2, 7, 100].iter().flat_map(|&n| 0..n).collect();
            expected.sort_unstable();
            assert_eq!(seen, expected);
        }
    }

    /// Every item once, whatever the count and the threads, on the pool's workers (where a dear
    /// item's own parallel kernels run); with one worker, the dearest first, ties in slice order.
    #[test]
    fn the_dearest_first_runs_every_item_once_dearest_first() {
        for threads in [1, 2, 3] {
            let pool = KernelPool::new(threads).unwrap();
            for n in [0, 1, 2, 5, 64] {
                let mut items: Vec<(usize, u32, bool)> = (0..n).map(|i| (i, 0, false)).collect();
                pool.for_each_dearest_first(
                    &mut items,
                    |&(i, _, _)| (i % 7) as f64,
                    |(_, runs, in_pool)| {
                        *runs += 1;
                        *in_pool = rayon::current_thread_index().is_some();
                    },
                );
                assert!(items.iter().all(|&(_, runs, _)| runs == 1), "{items:?}");
                assert!(items.iter().all(|&(_, _, in_pool)| in_pool), "{items:?}");
            }
        }
        let one = KernelPool::new(1).unwrap();
        let mut items: Vec<(usize, f64)> =
            [1.0, 5.0, 2.0, 5.0, 0.5].into_iter().enumerate().collect();
        let order = Mutex::new(Vec::new());
        one.for_each_dearest_first(
            &mut items,
            |&(_, c)| c,
            |&mut (i, _)| order.lock().unwrap().push(i),
        );
        assert_eq!(order.into_inner().unwrap(), [1, 3, 2, 0, 4]);
    }

    /// Every item once, whatever the count, the threads and how slow some items are; each
    /// worker starts with its own share, the same items at every call.
    #[test]
    fn pinned_items_are_each_run_once_and_stay_on_their_worker() {
        for threads in [1, 2, 3] {
            let pool = KernelPool::new(threads).unwrap();
            for n in [0, 1, 2, 5, 64] {
                let mut items: Vec<(usize, u32)> = (0..n).map(|i| (i, 0)).collect();
                pool.for_each_pinned(&mut items, |(i, runs)| {
                    *runs += 1;
                    if *i == 0 {
                        // one slow item: the other workers take over the rest of its share
                        std::thread::sleep(Duration::from_millis(5));
                    }
                });
                assert!(items.iter().all(|&(_, runs)| runs == 1), "{items:?}");
            }
        }
        // the first item of each share waits until both workers have started theirs, so
        // neither can finish its share early and take the other's: item 0 runs on worker 0,
        // item 4 on worker 1, at every call
        let pool = KernelPool::new(2).unwrap();
        let both = std::sync::Barrier::new(2);
        for _ in 0..3 {
            let mut items: Vec<(usize, Option<usize>)> = (0..8).map(|i| (i, None)).collect();
            pool.for_each_pinned(&mut items, |(i, worker)| {
                if *i % 4 == 0 {
                    both.wait();
                }
                *worker = rayon::current_thread_index();
            });
            assert_eq!((items[0].1, items[4].1), (Some(0), Some(1)), "{items:?}");
        }
    }

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

    #[test]
    fn only_sections_started_outside_the_pool_leave_workers_waiting() {
        // an install inside an install must not queue waiting jobs on the pool's own workers
        // (the enclosing section still needs them); a top-level one queues one per core but one
        let pool = KernelPool::new(2).unwrap();
        let queued = || pool.queued.load(Ordering::Relaxed);
        pool.install(|| {
            pool.install(|| ());
            assert_eq!(queued(), 0, "a nested section queued waiting jobs");
        });
        assert_eq!(queued(), pool.awake as u64);
        let one = KernelPool::new(1).unwrap();
        one.install(|| ());
        assert_eq!(
            one.queued.load(Ordering::Relaxed),
            0,
            "one worker never waits"
        );
    }

    #[test]
    fn a_one_thread_pool_runs_items_on_the_calling_thread() {
        let pool = KernelPool::new(1).unwrap();
        let caller = std::thread::current().id();
        let mut items = [None; 5];
        pool.for_each(&mut items, |t| *t = Some(std::thread::current().id()));
        assert!(items.iter().all(|t| *t == Some(caller)));
    }

    #[test]
    fn sections_after_a_waiting_spell_use_every_worker() {
        // the workers left waiting after one section take part in the next: both halves of a
        // join meet at a barrier, which needs two workers at once
        let pool = KernelPool::new(2).unwrap();
        for _ in 0..3 {
            let mut items = vec![0u32; 64];
            pool.for_each(&mut items, |x| *x += 1);
            assert!(items.iter().all(|&x| x == 1));
            let barrier = std::sync::Barrier::new(2);
            let (a, b) = pool.install(|| {
                rayon::join(|| barrier.wait().is_leader(), || barrier.wait().is_leader())
            });
            assert!(a != b, "exactly one leader");
        }
    }
}
