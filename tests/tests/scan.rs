//! The GPU prefix scan behind the primitive map's list offsets equals the CPU's exclusive prefix sum: in two
//! dispatches up to 4096 blocks of 1024 elements (one, two, many blocks), and in three levels beyond, on
//! random data, in place and from one buffer into another; and where the sums pass 2^32, it saturates
//! (every sum below 2^32 exact, every larger one 0xFFFFFFFF) rather than wrapping.

mod common;

use common::*;
use passes::scan::{PrefixScan, ScanPipeline};
use rhi::{Barrier, BufferUsage, MemoryLocation, ResourceState as S};

#[test]
fn gpu_scan_equals_the_cpu_prefix_sum() {
    let device = device();
    let pipeline = ScanPipeline::new(&device).expect("scan pipeline");
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    // (elements, largest value): the last three sum past 2^32 within one block, within the flat scan's
    // block totals, and in the multi-level scan's.
    for (case, (n, largest)) in [
        (1u32, 300u64),
        (1000, 300),
        (1024, 300),
        (1025, 300),
        (300_000, 300),
        (1_100_000, 300),
        (4_194_304, 300),
        (5_000_000, 300),
        (1000, 1 << 32),
        (600_000, 1 << 14),
        (5_000_000, 1 << 11),
    ]
    .into_iter()
    .enumerate()
    {
        let in_place = case % 2 == 0;
        let data: Vec<u32> = (0..n)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state % largest) as u32
            })
            .collect();
        let buffer = device
            .create_buffer_init(
                "scan data",
                bytemuck::cast_slice(&data),
                BufferUsage::STORAGE | BufferUsage::COPY_SRC,
            )
            .expect("data");
        let output = device
            .create_buffer(
                "scan output",
                u64::from(n) * 4,
                BufferUsage::STORAGE | BufferUsage::COPY_SRC,
                MemoryLocation::GpuOnly,
            )
            .expect("output");
        let target = if in_place { &buffer } else { &output };
        let scan = PrefixScan::new(&device, &pipeline, &buffer, target, n).expect("scan");
        let readback = device
            .create_buffer(
                "scan read-back",
                u64::from(n) * 4,
                BufferUsage::COPY_DST,
                MemoryLocation::GpuToCpu,
            )
            .expect("read-back");
        device
            .submit_and_wait(|enc| {
                scan.record(enc, &pipeline).expect("record");
                enc.barriers(&[Barrier::Global {
                    before: S::UnorderedAccess,
                    after: S::CopySource,
                }]);
                enc.copy_buffer(target, &readback)?;
                enc.barriers(&[Barrier::Global {
                    before: S::CopyDest,
                    after: S::HostRead,
                }]);
                Ok(())
            })
            .expect("submit");
        let gpu: Vec<u32> = bytemuck::pod_collect_to_vec(readback.read().expect("read"));
        let mut running = 0u64;
        let cpu: Vec<u32> = data
            .iter()
            .map(|&v| {
                let before = running.min(u64::from(u32::MAX)) as u32;
                running += u64::from(v);
                before
            })
            .collect();
        if largest > 300 {
            assert!(running > u64::from(u32::MAX), "case {case} must pass 2^32");
        }
        let wrong = gpu.iter().zip(&cpu).filter(|(a, b)| a != b).count();
        assert_eq!(
            wrong, 0,
            "{n} elements (in place: {in_place}): {wrong} differ from the CPU prefix sum"
        );
    }
    assert_no_validation_errors(&device);
}
