//! A tick of a running world allocates nothing of its own: every system keeps its
//! scratch space and its list of jobs from tick to tick, so a small world's tick is not paid in
//! `malloc`. This binary's global allocator sees every allocation made during the counted ticks
//! (after the first ones, which size the scratch space and let each sensor fire) and sorts it by
//! its call stack. Two kinds are not ours to remove and are counted apart: rapier's (its step
//! takes the list of modified bodies and makes its solver's per-island buffers anew every step),
//! and, with worker threads, rayon's: the job that keeps a worker spinning for the next parallel
//! section (`KernelPool::install`, one small box per section and waiting worker) and the blocks
//! of rayon's job queue.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static RAPIER: AtomicUsize = AtomicUsize::new(0);
static POOL: AtomicUsize = AtomicUsize::new(0);
static OTHERS: Mutex<Vec<String>> = Mutex::new(Vec::new());

thread_local! {
    /// Set while an allocation is being sorted (the backtrace allocates too).
    static SORTING: Cell<bool> = const { Cell::new(false) };
}

/// Sorts one allocation made while counting, by the frames of its call stack.
fn sort_allocation() {
    if !COUNTING.load(Ordering::Relaxed) || SORTING.with(|s| s.replace(true)) {
        return;
    }
    let stack = std::backtrace::Backtrace::force_capture().to_string();
    if stack.contains("rapier2d::") {
        RAPIER.fetch_add(1, Ordering::Relaxed);
    } else if stack.contains("rayon_core::") {
        // the only rayon spawn in the workspace is KernelPool's job that keeps a worker
        // spinning; rayon's queue of jobs takes a new block every 63 jobs
        POOL.fetch_add(1, Ordering::Relaxed);
    } else if let Ok(mut others) = OTHERS.lock() {
        others.push(stack);
    }
    SORTING.with(|s| s.set(false));
}

// SAFETY: every call is passed on to the system allocator unchanged
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        sort_allocation();
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        sort_allocation();
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        sort_allocation();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations by `ticks` ticks of `world` after `warm_up` ticks: (rapier's, rayon's, the call
/// stacks of all others).
fn allocations(
    world: &mut sim::build::SimWorld,
    warm_up: usize,
    ticks: usize,
) -> (usize, usize, Vec<String>) {
    for _ in 0..warm_up {
        world.step();
    }
    RAPIER.store(0, Ordering::SeqCst);
    POOL.store(0, Ordering::SeqCst);
    OTHERS.lock().unwrap().clear();
    COUNTING.store(true, Ordering::SeqCst);
    for _ in 0..ticks {
        world.step();
    }
    COUNTING.store(false, Ordering::SeqCst);
    let others = std::mem::take(&mut *OTHERS.lock().unwrap());
    (
        RAPIER.load(Ordering::SeqCst),
        POOL.load(Ordering::SeqCst),
        others,
    )
}

/// The swarm benchmark's worlds (wandering robots with 180-beam lasers at 10 Hz on the tiled
/// hospital), with one robot and with ten, on one thread and on two.
#[test]
fn a_tick_of_a_wandering_swarm_allocates_nothing_of_its_own() {
    let grid = sim::bench::swarm::swarm_world().expect("the swarm map loads");
    for (robots, threads) in [(1, 1), (10, 1), (10, 2)] {
        let sc =
            sim::bench::swarm::swarm_scenario(&grid, robots, 180, 60.0).expect("the robots fit");
        let mut world = sim::build::build_world(&sc, threads).expect("the world builds");
        let ticks = 200;
        let (rapier, spin, others) = allocations(&mut world, 100, ticks);
        assert!(
            others.is_empty(),
            "{robots} robots on {threads} threads: {} allocations in {ticks} ticks besides \
             rapier's and rayon's; the first:\n{}",
            others.len(),
            others[0]
        );
        // the sorting sees allocations at all: rapier's step makes some every step
        assert!(
            rapier >= ticks,
            "{robots} robots: {rapier} allocations by rapier"
        );
        if threads == 1 {
            assert_eq!(spin, 0);
        }
    }
}
