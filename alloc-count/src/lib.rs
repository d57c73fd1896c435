//! The one counting allocator of the workspace's allocation tests (STYLE rule 4: per-step code
//! does not allocate).
//!
//! A test binary installs it once and counts what a closure allocates on the calling thread:
//!
//! ```
//! #[global_allocator]
//! static GLOBAL: alloc_count::Counting = alloc_count::Counting;
//!
//! let mut buf = Vec::with_capacity(8);
//! let (_, n) = alloc_count::count(|| buf.push(1.0)); // within capacity
//! assert_eq!(n, 0);
//! let (_, n) = alloc_count::count(|| vec![0.0; 4]);
//! assert_eq!(n, 1);
//! ```
//!
//! Only the calling thread's allocations count, and only inside [`count`]: libtest's main
//! thread bookkeeping and other tests running in parallel allocate concurrently, and counting
//! them made such tests fail now and then under load. Reallocations count as allocations;
//! deallocations do not. Work done on other threads (rayon) is not seen: allocation tests run
//! their loops on one thread.
//!
//! Written by hand: a global allocator that counts per thread is a dozen lines, less than a
//! dependency's surface.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    if COUNTING.try_with(Cell::get).unwrap_or(false) {
        let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
    }
}

/// The system allocator, counting the allocations a [`count`] closure makes on its thread.
pub struct Counting;

// SAFETY: every call forwards to the system allocator with the caller's arguments; counting
// touches thread-locals only (`try_with`, so never during a thread's teardown) and never
// allocates.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Run `f` and return its result with the number of heap allocations (and reallocations) it
/// made on this thread. Needs [`Counting`] installed as the `#[global_allocator]`; without it
/// the count is always 0, so a test should first check that a known allocation is counted.
pub fn count<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let before = ALLOCATIONS.with(Cell::get);
    let was = COUNTING.with(|c| c.replace(true));
    let r = f();
    COUNTING.with(|c| c.set(was));
    (r, ALLOCATIONS.with(Cell::get) - before)
}
