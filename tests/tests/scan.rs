//! The GPU prefix scan behind the primitive map's list offsets equals the CPU's exclusive prefix sum: in two
//! dispatches up to 4096 blocks of 1024 elements (one, two, many blocks), and in three levels beyond, on
//! random data, in place and from one buffer into another.

mod common;

use common::*;
use passes::scan::{PrefixScan, ScanPipeline};
use rhi::{Barrier, BufferUsage, MemoryLocation, ResourceState as S};

#[test]
fn gpu_scan_equals_the_cpu_prefix_sum() {
    let device = device();
    let pipeline = ScanPipeline::new(&device).expect("scan pipeline");
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    for (case, n) in [
        1u32, 1000, 1024, 1025, 300_000, 1_100_000, 4_194_304, 5_000_000,
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
                (state % 300) as u32
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
        let mut running = 0u32;
        let cpu: Vec<u32> = data
            .iter()
            .map(|&v| {
                let before = running;
                running += v;
                before
            })
            .collect();
        let wrong = gpu.iter().zip(&cpu).filter(|(a, b)| a != b).count();
        assert_eq!(
            wrong, 0,
            "{n} elements (in place: {in_place}): {wrong} differ from the CPU prefix sum"
        );
    }
    assert_no_validation_errors(&device);
}
