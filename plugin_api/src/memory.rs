//! Host memory of the plugin: [`CountingAllocator`], the global allocator of the plugin's shared and static
//! libraries (the `hrts` package installs it; this rlib does not, so a Rust program linking it keeps its
//! own allocator), counts the bytes the plugin holds, so an engine (and the C host test) can see exactly
//! what the plugin owns apart from what the Vulkan driver keeps; and it forwards to the engine's
//! allocation callbacks when they were installed first.

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::c_void;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// `System`, or the engine's callbacks, with a count of live bytes and allocations.
pub struct CountingAllocator;

/// The engine's host allocation functions.
#[derive(Clone, Copy)]
pub(crate) struct Callbacks {
    pub(crate) user_data: usize,
    pub(crate) allocate: unsafe extern "C" fn(*mut c_void, usize, usize) -> *mut c_void,
    pub(crate) free: unsafe extern "C" fn(*mut c_void, *mut c_void, usize, usize),
}

static LIVE_HOST_BYTES: AtomicU64 = AtomicU64::new(0);
static LIVE_ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
static TOTAL_ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
static CALLBACKS: OnceLock<Callbacks> = OnceLock::new();

/// Whether [`CountingAllocator`] is the process's global allocator (the plugin's shared or static
/// library), rather than this crate being linked as an rlib into a program with its own.
pub(crate) fn is_global_allocator() -> bool {
    let before = TOTAL_ALLOCATIONS.load(Ordering::SeqCst);
    drop(std::hint::black_box(Box::new(0u8)));
    TOTAL_ALLOCATIONS.load(Ordering::SeqCst) > before
}

/// Installs the engine's callbacks; false if the plugin holds memory (or callbacks are installed).
pub(crate) fn install(callbacks: Callbacks) -> bool {
    LIVE_ALLOCATIONS.load(Ordering::SeqCst) == 0 && CALLBACKS.set(callbacks).is_ok()
}

// SAFETY: every method returns memory from one allocator for the whole process (callbacks can only be
// installed before the first allocation) with the requested layout, and frees it with the same one.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        TOTAL_ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        let p = match CALLBACKS.get() {
            // SAFETY: the engine's allocate returns `size` bytes aligned to `align`, or NULL.
            Some(c) => unsafe {
                (c.allocate)(c.user_data as *mut c_void, layout.size(), layout.align()) as *mut u8
            },
            // SAFETY: forwarded unchanged.
            None => unsafe { System.alloc(layout) },
        };
        if !p.is_null() {
            LIVE_HOST_BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
            LIVE_ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        match CALLBACKS.get() {
            // SAFETY: `ptr` came from the same callbacks with this layout.
            Some(c) => unsafe {
                (c.free)(
                    c.user_data as *mut c_void,
                    ptr as *mut c_void,
                    layout.size(),
                    layout.align(),
                )
            },
            // SAFETY: forwarded unchanged.
            None => unsafe { System.dealloc(ptr, layout) },
        }
        LIVE_HOST_BYTES.fetch_sub(layout.size() as u64, Ordering::Relaxed);
        LIVE_ALLOCATIONS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Bytes of host memory the plugin holds now.
pub(crate) fn live_host_bytes() -> u64 {
    LIVE_HOST_BYTES.load(Ordering::Relaxed)
}
