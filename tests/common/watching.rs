//! A counting allocator for the hostile-input tests: the system allocator, remembering the
//! largest single request, so that a test can assert no input made kiln ask for more than its
//! bounds allow. Included with `#[path]` by each test that installs it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, remembering the largest single request.
pub struct Watching;

/// The largest single allocation or reallocation asked for since the last [`reset`].
pub static LARGEST: AtomicUsize = AtomicUsize::new(0);

/// Forgets the largest request so far.
pub fn reset() {
    LARGEST.store(0, Ordering::Relaxed);
}

/// The largest request since the last [`reset`].
pub fn largest() -> usize {
    LARGEST.load(Ordering::Relaxed)
}

// SAFETY: forwards to the system allocator unchanged; only records the size asked for.
unsafe impl GlobalAlloc for Watching {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract is the system allocator's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        // SAFETY: as above.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Watching = Watching;
