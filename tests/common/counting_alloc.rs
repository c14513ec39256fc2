//! A counting global allocator for the no-allocation tests: it counts the allocations
//! (and reallocations) made by the calling thread, so that tests running in parallel do
//! not disturb each other. Include it with
//! `#[path = "common/counting_alloc.rs"] mod counting_alloc;` in a test file that wants
//! it: declaring it installs it as that test binary's global allocator.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The allocator: the system allocator plus a per-thread count.
struct Counting;

thread_local! {
    /// Allocations made by this thread (the test harness's own threads allocate while a
    /// test measures: printing results, starting the next test).
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
}

/// Allocations made so far by the calling thread.
pub fn allocs() -> usize {
    ALLOCS.with(|c| c.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;
