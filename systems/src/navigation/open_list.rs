//! The A* open list: a priority queue split into buckets of f (a two-level bucket queue in the
//! spirit of Cherkassky, Goldberg & Radzik, "Shortest paths algorithms: theory and experimental
//! evaluation", Math. Programming 73, 1996). With a consistent heuristic f never decreases along
//! a search and a node's f exceeds its parent's by at most a bounded `spread`, so a ring of
//! buckets covering `spread` holds every entry (a spill list catches rounding surprises).
//! Buckets are plain vectors; when one becomes the lowest it is sorted once, and the few entries
//! pushed into it afterwards (about 8 % on the hospital queries: moves that keep f) go to a small
//! binary heap; a pop takes the lower of the two heads. Pops come out in exactly the order of a
//! single binary heap over the same keys, but each is a step along a sorted vector of a few dozen
//! entries instead of a pop from a heap of tens of thousands (sorting a bucket once rather than
//! heaping it: 21 -> 18 ms on the cross-building queries).
//!
//! A* pushes a node again whenever it finds a cheaper way there, leaving the old entry behind;
//! about half the entries end up stale. [`OpenList::pop`] takes a `live` test and drops the
//! entries that fail it when their bucket becomes the lowest, before it is sorted: almost
//! every stale entry is superseded by then, so they cost one test each instead of a heap push
//! and pop (cross-building hospital queries 30 -> 21 ms).
//!
//! The vectors are kept from one search to the next, and they change places as buckets come
//! up, so each would end up as large as the largest bucket of any search so far: a planner's
//! memory would creep up over a long run. [`OpenList::reset`] therefore keeps at most twice the
//! entries the search before pushed, so what is kept follows recent searches.

use std::collections::BinaryHeap;

/// An entry: `key` orders first (lower is popped first), then `idx` (lower first). The high 32
/// bits of `key` must be the bits of f (finite, ≥ 0), which buckets are taken from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    pub key: u64,
    pub idx: u32,
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        // reversed: BinaryHeap is a max-heap
        other.key.cmp(&self.key).then(other.idx.cmp(&self.idx))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

const RING: usize = 256;

#[derive(Clone, Debug, Default)]
pub struct OpenList {
    /// Buckets per unit of f.
    inv_width: f32,
    /// Number of the current bucket; lower-numbered entries go there too.
    base: u64,
    /// The current bucket as it was when it came up, sorted so that the lowest entry is last.
    sorted: Vec<Entry>,
    /// Entries pushed into the current bucket after it came up.
    late: BinaryHeap<Entry>,
    /// Bucket b (base < b < base + RING) is `ring[b % RING]`.
    ring: Vec<Vec<Entry>>,
    /// Entries beyond the ring (not expected with a consistent heuristic).
    spill: Vec<Entry>,
    /// Entries in `ring` and `spill`.
    pending: usize,
    /// Entries pushed since the last reset.
    pushed: usize,
}

/// Entries every vector may keep between searches, whatever the searches before.
const KEEP_AT_LEAST: usize = 64;

impl OpenList {
    /// Empties the list for a search whose f rises by at most `spread` per step and whose first
    /// entry has f = `f0`.
    pub fn reset(&mut self, spread: f32, f0: f32) {
        if self.ring.len() != RING {
            self.ring = vec![Vec::new(); RING];
        }
        // room for twice the last search's entries is kept (first come, first kept), every
        // other vector is trimmed to a small floor
        let mut budget = 2 * self.pushed;
        let mut trim = |v: &mut Vec<Entry>| {
            v.clear();
            if v.capacity() <= budget {
                budget -= v.capacity();
            } else if v.capacity() > KEEP_AT_LEAST {
                v.shrink_to(KEEP_AT_LEAST);
            }
        };
        trim(&mut self.sorted);
        trim(&mut self.spill);
        self.ring.iter_mut().for_each(&mut trim);
        self.late.clear();
        if self.late.capacity() > KEEP_AT_LEAST.max(budget) {
            self.late.shrink_to(KEEP_AT_LEAST.max(budget));
        }
        self.pending = 0;
        self.pushed = 0;
        let spread = if spread.is_finite() && spread > 0.0 {
            spread
        } else {
            1.0
        };
        self.inv_width = (RING - 2) as f32 / spread;
        self.base = self.bucket(f0);
    }

    fn bucket(&self, f: f32) -> u64 {
        (f * self.inv_width) as u64
    }

    pub fn push(&mut self, e: Entry) {
        self.pushed += 1;
        let b = self.bucket(f32::from_bits((e.key >> 32) as u32));
        if b <= self.base {
            self.late.push(e);
        } else if b - self.base < RING as u64 {
            self.ring[(b % RING as u64) as usize].push(e);
            self.pending += 1;
        } else {
            self.spill.push(e);
            self.pending += 1;
        }
    }

    /// The lowest entry. Entries for which `live` is false when their bucket becomes the lowest
    /// are dropped; `live` must stay false for an entry once it is (the caller still has to
    /// skip entries that died after their bucket came up).
    pub fn pop(&mut self, live: impl Fn(&Entry) -> bool) -> Option<Entry> {
        loop {
            // the lower of the two heads (`Entry`'s order is reversed: greater = popped first)
            match (self.sorted.last(), self.late.peek()) {
                (Some(a), Some(b)) if b > a => return self.late.pop(),
                (Some(_), _) => return self.sorted.pop(),
                (None, Some(_)) => return self.late.pop(),
                (None, None) => {}
            }
            if self.pending == 0 {
                return None;
            }
            let ring_empty = self.pending == self.spill.len();
            if ring_empty {
                // only spilled entries left: jump to the lowest of them
                let lowest = self.spill.iter().map(|e| e.key).min().unwrap_or(0);
                self.base = self.bucket(f32::from_bits((lowest >> 32) as u32));
            } else {
                self.base += 1;
            }
            let slot = (self.base % RING as u64) as usize;
            self.pending -= self.ring[slot].len();
            // the bucket's vector becomes `sorted`, the emptied `sorted` takes its place
            std::mem::swap(&mut self.sorted, &mut self.ring[slot]);
            self.sorted.retain(|e| live(e));
            self.sorted.sort_unstable();
            if !self.spill.is_empty() {
                // move spilled entries that now fall inside the ring
                let spill = std::mem::take(&mut self.spill);
                self.pending -= spill.len();
                for e in spill {
                    self.push(e);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Entries the list has room for without allocating.
    fn room(open: &OpenList) -> usize {
        open.sorted.capacity()
            + open.late.capacity()
            + open.spill.capacity()
            + open.ring.iter().map(Vec::capacity).sum::<usize>()
    }

    #[test]
    fn what_is_kept_between_searches_does_not_creep_up() {
        // every search puts 2000 entries into one bucket, a different one each time, and 100
        // into the others: kept whole, more and more vectors hold room for 2000 (room for
        // about 44 000 entries after 600 searches, and still rising)
        let mut open = OpenList::default();
        let mut most = 0;
        for search in 0..600u32 {
            open.reset(4.0, 0.0);
            let big = 0.1 + (search % 250) as f32 * 4.0 / 254.0;
            for i in 0..2000 {
                open.push(entry(big, 0.0, i));
            }
            for i in 0..100 {
                open.push(entry(i as f32 * 0.039, 1.0, i));
            }
            let mut popped = 0;
            while open.pop(|_| true).is_some() {
                popped += 1;
            }
            assert_eq!(popped, 2100);
            if search >= 10 {
                most = most.max(room(&open));
            }
        }
        // twice the 2100 entries of a search, the floor of every vector, and one growing bucket
        assert!(
            most <= 2 * 2100 + (RING + 3) * KEEP_AT_LEAST + 4096,
            "room for {most}"
        );
    }

    fn entry(f: f32, g: f32, idx: u32) -> Entry {
        Entry {
            key: (f.to_bits() as u64) << 32 | !g.to_bits() as u64,
            idx,
        }
    }

    #[test]
    fn pops_in_the_order_of_one_binary_heap() {
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as u32
        };
        let mut open = OpenList::default();
        open.reset(4.0, 10.0);
        let mut heap = BinaryHeap::new();
        let mut f_min = 10.0f32;
        let mut popped = 0;
        for round in 0..2000 {
            // pushes within the spread of the last pop, some far beyond it, ties in f
            for k in 0..3 {
                let f = match k {
                    0 => f_min + (next() % 400) as f32 / 100.0,
                    1 => f_min + (next() % 4) as f32,
                    _ if round % 97 == 0 => f_min + 50.0,
                    _ => f_min,
                };
                let e = entry(f, (next() % 50) as f32 / 7.0, next() % 1000);
                open.push(e);
                heap.push(e);
            }
            for _ in 0..2 {
                let (a, b) = (open.pop(|_| true), heap.pop());
                assert_eq!(a, b, "after {popped} pops");
                if let Some(e) = a {
                    f_min = f32::from_bits((e.key >> 32) as u32);
                    popped += 1;
                }
            }
        }
        while let Some(b) = heap.pop() {
            assert_eq!(open.pop(|_| true), Some(b));
        }
        assert_eq!(open.pop(|_| true), None);
    }

    #[test]
    fn dropping_dead_entries_keeps_the_order_of_the_live_ones() {
        let mut state = 11u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as u32
        };
        // an entry is dead if its index is a multiple of 3 (a fixed test, as A*'s "closed or
        // superseded" never comes back to life)
        let live = |e: &Entry| !e.idx.is_multiple_of(3);
        let mut open = OpenList::default();
        open.reset(4.0, 10.0);
        let mut heap = BinaryHeap::new();
        let mut f_min = 10.0f32;
        // the list may hand out dead entries whose bucket had already come up; skip those on both sides
        let next_live = |open: &mut OpenList, heap: &mut BinaryHeap<Entry>| {
            let a = std::iter::from_fn(|| open.pop(live)).find(live);
            let b = std::iter::from_fn(|| heap.pop()).find(live);
            (a, b)
        };
        let mut popped = 0;
        for _ in 0..3000 {
            for _ in 0..3 {
                let f = f_min + (next() % 400) as f32 / 100.0;
                let e = entry(f, (next() % 50) as f32 / 7.0, next() % 1000);
                open.push(e);
                heap.push(e);
            }
            for _ in 0..2 {
                let (a, b) = next_live(&mut open, &mut heap);
                assert!(a == b, "after {popped} live pops: {a:?} vs {b:?}");
                if let Some(e) = a {
                    f_min = f32::from_bits((e.key >> 32) as u32);
                    popped += 1;
                }
            }
        }
        loop {
            let (a, b) = next_live(&mut open, &mut heap);
            assert!(a == b, "after {popped} live pops: {a:?} vs {b:?}");
            if a.is_none() {
                break;
            }
            popped += 1;
        }
        assert!(popped > 3000, "{popped}");
    }
}
