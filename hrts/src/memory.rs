//! Host memory of the plugin: [`CountingAllocator`], the global allocator of the plugin's shared and static
//! libraries (the `hrts-capi` package installs it; this rlib does not, so a Rust program linking it keeps its
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
/// The allocator's state: [`INSTALLED`] once the engine's callbacks serve every allocation, else the
/// number of live allocations `System` serves. Installing succeeds only from 0 (compare-and-swap), so no
/// allocation can slip in between the check and the switch.
static STATE: AtomicU64 = AtomicU64::new(0);
const INSTALLED: u64 = 1 << 63;

/// Whether [`CountingAllocator`] is the process's global allocator (the plugin's shared or static
/// library), rather than this crate being linked as an rlib into a program with its own.
pub(crate) fn is_global_allocator() -> bool {
    let before = TOTAL_ALLOCATIONS.load(Ordering::SeqCst);
    drop(std::hint::black_box(Box::new(0u8)));
    TOTAL_ALLOCATIONS.load(Ordering::SeqCst) > before
}

/// Installs the engine's callbacks; false if the plugin holds memory (or callbacks are installed).
pub(crate) fn install(callbacks: Callbacks) -> bool {
    if STATE
        .compare_exchange(0, INSTALLED, Ordering::SeqCst, Ordering::SeqCst)
        .is_err()
    {
        return false;
    }
    // Allocations wait for this (see `callbacks`). The set cannot fail: only this winner gets here.
    CALLBACKS.set(callbacks).is_ok()
}

/// The engine's callbacks if they serve allocations, else `None` with one more live `System` allocation
/// reserved (released by [`System`]'s deallocation, or at once by a failed allocation).
fn callbacks_or_reserve_system() -> Option<&'static Callbacks> {
    loop {
        let state = STATE.load(Ordering::SeqCst);
        if state & INSTALLED != 0 {
            // Installed: the callbacks are set right after the switch.
            if let Some(c) = CALLBACKS.get() {
                return Some(c);
            }
            std::hint::spin_loop();
        } else if STATE
            .compare_exchange(state, state + 1, Ordering::SeqCst, Ordering::SeqCst)
            .is_ok()
        {
            return None;
        }
    }
}

// SAFETY: every method returns memory with the requested layout and frees it with the allocator that
// served it: callbacks are installed only while no `System` allocation is live (STATE), and serve every
// allocation after that.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        TOTAL_ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        let p = match callbacks_or_reserve_system() {
            // SAFETY: the engine's allocate returns `size` bytes aligned to `align`, or NULL.
            Some(c) => unsafe {
                (c.allocate)(c.user_data as *mut c_void, layout.size(), layout.align()) as *mut u8
            },
            None => {
                // SAFETY: forwarded unchanged.
                let p = unsafe { System.alloc(layout) };
                if p.is_null() {
                    STATE.fetch_sub(1, Ordering::SeqCst);
                }
                p
            }
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
            None => {
                // SAFETY: `ptr` came from `System` with this layout (no callbacks were installed then).
                unsafe { System.dealloc(ptr, layout) };
                STATE.fetch_sub(1, Ordering::SeqCst);
            }
        }
        LIVE_HOST_BYTES.fetch_sub(layout.size() as u64, Ordering::Relaxed);
        LIVE_ALLOCATIONS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Bytes of host memory the plugin holds now.
pub(crate) fn live_host_bytes() -> u64 {
    LIVE_HOST_BYTES.load(Ordering::Relaxed)
}
