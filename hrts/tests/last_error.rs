//! The last error of a context read from one thread while another makes failing calls on it, through
//! `hrts_last_error` and `hrts_get_last_error`: every message read is whole, one the failing calls give.

use hrts::*;
use std::collections::HashSet;
use std::ffi::CStr;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// A context on the plugin's own device (no GPU work is recorded).
fn context() -> *mut HrtsContext {
    let info = HrtsContextCreateInfo {
        struct_size: size_of::<HrtsContextCreateInfo>() as u32,
        api_version: HRTS_API_VERSION,
        vulkan: std::ptr::null(),
        device_name_filter: std::ptr::null(),
        enable_validation: 0,
        frames_in_flight: 0,
    };
    let mut ctx = std::ptr::null_mut();
    // SAFETY: valid pointers.
    let r = unsafe { hrts_context_create(&info, &mut ctx) };
    assert_eq!(r, HrtsResult::Ok, "hrts_context_create");
    ctx
}

/// Failing call `i % 3` on the context: each fails with a message of its own length.
fn fail(ctx: *mut HrtsContext, i: usize) -> HrtsResult {
    // SAFETY: a live context; NULL or valid pointers.
    unsafe {
        match i % 3 {
            0 => hrts_set_targets(ctx, std::ptr::null()),
            1 => hrts_configure(ctx, std::ptr::null()),
            _ => {
                let mut report: HrtsFrameReport = std::mem::zeroed();
                report.struct_size = size_of::<HrtsFrameReport>() as u32;
                hrts_get_frame_report(ctx, 0, 0, &mut report)
            }
        }
    }
}

/// The context's last error through `hrts_last_error`, copied out after the thread let others run (as an
/// engine logs it later).
fn last_error(ctx: *const HrtsContext) -> Vec<u8> {
    // SAFETY: a live context.
    let message = unsafe { hrts_last_error(ctx) };
    std::thread::yield_now();
    // SAFETY: `hrts_last_error` returns a NUL-terminated string valid until this thread calls it again.
    unsafe { CStr::from_ptr(message) }.to_bytes().to_vec()
}

/// The context's last error through `hrts_get_last_error` into a buffer of `capacity` bytes: the bytes
/// copied before the NUL, and the size the function says the whole message needs.
fn copied_error(ctx: *const HrtsContext, capacity: usize) -> (Vec<u8>, usize) {
    let mut buffer = vec![0x55u8; capacity];
    // SAFETY: a live context; `buffer` holds `capacity` bytes.
    let needed = unsafe { hrts_get_last_error(ctx, buffer.as_mut_ptr().cast(), capacity) };
    let copied = buffer
        .iter()
        .position(|&b| b == 0)
        .map_or(buffer.clone(), |n| buffer[..n].to_vec());
    (copied, needed)
}

#[test]
fn last_error_is_whole_while_another_thread_fails_calls() {
    let ctx = context();
    let messages: HashSet<Vec<u8>> = (0..3)
        .map(|i| {
            assert_ne!(fail(ctx, i), HrtsResult::Ok);
            let message = last_error(ctx);
            assert_eq!(copied_error(ctx, 512), (message.clone(), message.len() + 1));
            message
        })
        .collect();
    assert_eq!(
        messages.len(),
        3,
        "three messages of their own: {messages:?}"
    );
    // Asking for the size, and a copy truncated to what fits.
    let whole = last_error(ctx);
    // SAFETY: a live context; a NULL buffer is allowed.
    let needed = unsafe { hrts_get_last_error(ctx, std::ptr::null_mut(), 0) };
    assert_eq!(needed, whole.len() + 1);
    assert_eq!(copied_error(ctx, 6), (whole[..5].to_vec(), whole.len() + 1));
    let handle = ctx as usize;
    let done = AtomicBool::new(false);
    let reads = AtomicUsize::new(0);
    let (read, torn) = std::thread::scope(|s| {
        let reader = s.spawn(|| {
            let ctx = handle as *const HrtsContext;
            let (mut read, mut torn) = (0usize, Vec::new());
            while !done.load(Ordering::Relaxed) {
                let (copied, needed) = copied_error(ctx, 512);
                for message in [last_error(ctx), copied] {
                    read += 1;
                    reads.fetch_add(1, Ordering::Relaxed);
                    if !messages.contains(&message) && torn.len() < 4 {
                        torn.push(String::from_utf8_lossy(&message).into_owned());
                    }
                }
                if !(needed > 1 && needed <= 512) && torn.len() < 4 {
                    torn.push(format!("hrts_get_last_error needs {needed} bytes"));
                }
            }
            (read, torn)
        });
        // At least 300,000 failed calls, and on until the reader has read 20,000 messages during them (a
        // loaded machine may start the reader late), within a minute.
        let started = std::time::Instant::now();
        let mut calls = 0usize;
        while calls < 300_000
            || (reads.load(Ordering::Relaxed) < 20_000 && started.elapsed().as_secs() < 60)
        {
            fail(handle as *mut HrtsContext, calls);
            calls += 1;
        }
        done.store(true, Ordering::Relaxed);
        reader.join().expect("the reading thread panicked")
    });
    println!("{read} messages read while the other thread failed calls");
    assert!(torn.is_empty(), "messages read that no call gave: {torn:?}");
    assert!(
        read > 1000,
        "only {read} messages read: the case was not tested"
    );
    // SAFETY: a live context, used by no other thread now.
    assert_eq!(unsafe { hrts_context_destroy(ctx) }, HrtsResult::Ok);
}
