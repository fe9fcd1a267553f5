//! Memory a system keeps from tick to tick for its list of jobs. A system that hands its query's
//! items to the kernel pool collects them into a vector first; those items borrow the tick's
//! world, so the vector cannot live in a `Local` between ticks, and collecting it anew costs an
//! allocation every tick. [`JobMemory`] keeps the vector's allocation (emptied) instead, and
//! gives it back as an empty vector of the next tick's items.

use std::alloc::{Layout, dealloc};
use std::mem::{ManuallyDrop, align_of, size_of};
use std::ptr::NonNull;

/// The allocation of an emptied vector, kept for the next vector of the same item type.
#[derive(Default)]
pub struct JobMemory {
    block: Option<(NonNull<u8>, Layout)>,
}

// SAFETY: a JobMemory owns a block of memory with no values in it; nothing else refers to it.
unsafe impl Send for JobMemory {}
// SAFETY: as for Send; a shared reference gives no access to the block.
unsafe impl Sync for JobMemory {}

impl JobMemory {
    /// An empty vector with the kept allocation, when it was made for items of `T`'s size and
    /// alignment; otherwise a new empty vector (and the kept block is freed).
    pub fn take<T>(&mut self) -> Vec<T> {
        let Some((ptr, layout)) = self.block.take() else {
            return Vec::new();
        };
        let size = size_of::<T>();
        if size != 0 && layout.align() == align_of::<T>() && layout.size() % size == 0 {
            // SAFETY: the block was allocated by the global allocator as a vector's buffer with
            // this alignment and layout.size() = capacity · size bytes (see `keep`); it holds no
            // values (length 0)
            unsafe { Vec::from_raw_parts(ptr.as_ptr().cast::<T>(), 0, layout.size() / size) }
        } else {
            // SAFETY: allocated by the global allocator with exactly this layout
            unsafe { dealloc(ptr.as_ptr(), layout) };
            Vec::new()
        }
    }

    /// Keeps `jobs`' allocation (its items are dropped) for the next [`JobMemory::take`].
    pub fn keep<T>(&mut self, mut jobs: Vec<T>) {
        jobs.clear();
        let size = jobs.capacity() * size_of::<T>();
        if size == 0 {
            return;
        }
        // a vector's buffer always has a valid layout and a non-null address; were it otherwise,
        // the vector would simply be dropped
        let Ok(layout) = Layout::from_size_align(size, align_of::<T>()) else {
            return;
        };
        let mut jobs = ManuallyDrop::new(jobs);
        let Some(ptr) = NonNull::new(jobs.as_mut_ptr().cast::<u8>()) else {
            return;
        };
        self.take::<u8>(); // frees a block kept before, if any
        self.block = Some((ptr, layout));
    }
}

impl Drop for JobMemory {
    fn drop(&mut self) {
        if let Some((ptr, layout)) = self.block.take() {
            // SAFETY: allocated by the global allocator with exactly this layout
            unsafe { dealloc(ptr.as_ptr(), layout) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vector of borrowed items comes back with the capacity of the last one, at the same
    /// address, and empty; items of another layout get a fresh vector.
    #[test]
    fn the_next_tick_s_jobs_reuse_the_last_tick_s_memory() {
        let mut memory = JobMemory::default();
        let mut values = [1u64, 2, 3, 4, 5];
        let mut address = None;
        for tick in 0..3 {
            let mut jobs: Vec<(&mut u64, usize)> = memory.take();
            if tick > 0 {
                assert!(jobs.is_empty());
                assert!(jobs.capacity() >= 5);
                assert_eq!(Some(jobs.as_ptr() as usize), address);
            }
            jobs.extend(values.iter_mut().zip(0..));
            for (v, i) in &mut jobs {
                **v += *i as u64;
            }
            address = Some(jobs.as_ptr() as usize);
            memory.keep(jobs);
        }
        // three ticks, each adding the index
        assert_eq!(values, [1, 5, 9, 13, 17]);
        // a single byte's alignment differs: a new vector, the old block freed
        let bytes: Vec<u8> = memory.take();
        assert_eq!(bytes.capacity(), 0);
        let fresh: Vec<u64> = memory.take();
        assert_eq!(fresh.capacity(), 0);
        // an empty vector keeps nothing
        memory.keep(Vec::<u32>::new());
        assert_eq!(memory.take::<u32>().capacity(), 0);
    }
}
