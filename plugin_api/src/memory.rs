//! Host memory of the plugin: the library's global allocator counts the bytes the plugin holds, so an
//! engine (and the C host test) can see exactly what the plugin owns apart from what the Vulkan driver
//! keeps; and it forwards to the engine's allocation callbacks when they were installed first.

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::c_void;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::OnceLock;

/// `System`, or the engine's callbacks, with a count of live bytes.
pub(crate) struct CountingAllocator;

/// The engine's host allocation functions.
#[derive(Clone, Copy)]
pub(crate) struct Callbacks {
    pub(crate) user_data: usize,
    pub(crate) allocate: unsafe extern "C" fn(*mut c_void, usize, usize) -> *mut c_void,
    pub(crate) free: unsafe extern "C" fn(*mut c_void, *mut c_void, usize, usize),
}

static LIVE_HOST_BYTES: AtomicU64 = AtomicU64::new(0);
static EVER_ALLOCATED: AtomicBool = AtomicBool::new(false);
static CALLBACKS: OnceLock<Callbacks> = OnceLock::new();

/// Installs the engine's callbacks; false if the plugin already allocated (or callbacks are installed).
pub(crate) fn install(callbacks: Callbacks) -> bool {
    !EVER_ALLOCATED.load(Ordering::SeqCst) && CALLBACKS.set(callbacks).is_ok()
}

// SAFETY: every method returns memory from one allocator for the whole process (callbacks can only be
// installed before the first allocation) with the requested layout, and frees it with the same one.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        EVER_ALLOCATED.store(true, Ordering::Relaxed);
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
    }
}

/// Bytes of host memory the plugin holds now.
pub(crate) fn live_host_bytes() -> u64 {
    LIVE_HOST_BYTES.load(Ordering::Relaxed)
}
