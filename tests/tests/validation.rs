//! The validation the GPU tests run under: the Khronos layer with synchronization validation, whose
//! hazards count as errors.

mod common;

use common::device;
use rhi::{Barrier, BufferUsage, MemoryLocation};

/// Two fills of one 256-byte buffer named `name`, with a full barrier between them or none.
fn two_fills(device: &rhi::Device, name: &str, ordered: bool) {
    let buffer = device
        .create_buffer(name, 256, BufferUsage::COPY_DST, MemoryLocation::GpuOnly)
        .expect("buffer");
    device
        .submit_and_wait(|enc| {
            enc.fill_buffer(&buffer, 1);
            if ordered {
                enc.barriers(&[Barrier::Full]);
            }
            enc.fill_buffer(&buffer, 2);
            Ok(())
        })
        .expect("submission");
}

/// Two fills of one buffer with no barrier between them are a write-after-write hazard: synchronization
/// validation reports it, and the log counts it as an error and as a hazard. (A suite that ran without
/// synchronization validation, or that did not count its hazards, fails here.)
#[test]
fn synchronization_hazards_are_reported_and_counted_as_errors() {
    let device = device();
    two_fills(&device, "hazard", false);
    let v = device.validation();
    assert!(v.hazards() >= 1, "no hazard reported: {:#?}", v.messages());
    assert!(v.errors() >= v.hazards(), "hazards not counted as errors");
    assert!(
        v.messages()
            .iter()
            .any(|m| m.contains("SYNC-HAZARD-WRITE-AFTER-WRITE")),
        "{:#?}",
        v.messages()
    );
}

/// The same two fills ordered by a barrier are no hazard.
#[test]
fn ordered_writes_are_no_hazard() {
    let device = device();
    two_fills(&device, "ordered", true);
    common::assert_no_validation_errors(&device);
}

/// A recording that fails half-way leaves `submit_and_wait`'s command buffer recording; the next
/// submission, which reuses it, must still be valid.
#[test]
fn a_failed_recording_leaves_the_next_submission_valid() {
    let device = device();
    let buffer = device
        .create_buffer("after", 256, BufferUsage::COPY_DST, MemoryLocation::GpuOnly)
        .expect("buffer");
    let failed = device.submit_and_wait(|enc| {
        enc.fill_buffer(&buffer, 1);
        Err::<(), _>(rhi::RhiError::InvalidArgument("stop".into()))
    });
    assert!(failed.is_err());
    device
        .submit_and_wait(|enc| {
            enc.fill_buffer(&buffer, 2);
            Ok(())
        })
        .expect("the next submission");
    common::assert_no_validation_errors(&device);
}
