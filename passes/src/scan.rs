//! Exclusive prefix sum of a `u32` buffer on the GPU, in place (`scan.comp`), saturating: a sum that reaches
//! 2^32 reads `u32::MAX` rather than wrapping, every smaller one is exact. Up to [`FLAT_BLOCKS`] blocks of
//! 1024 it takes two dispatches: the blocks' totals, then each block scanned from the sum of the totals
//! before it, which its workgroup adds up itself. Larger scans take one level per 1024-fold reduction,
//! then the scanned block totals added back down.
//!
//! Reads and writes: the data buffer. Owns: the block-total buffers of each level.

use crate::shaders::shader;
use crate::PassError;
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, BufferUsage, ComputePipeline, Device, Encoder,
    MemoryLocation, Resource,
};

/// Elements one workgroup scans.
const BLOCK: u64 = 1024;

/// The most blocks a scan takes in two dispatches (4M elements): each workgroup of the second reads the
/// totals of the blocks before it.
pub const FLAT_BLOCKS: u64 = 4096;

/// Push constants of `scan.comp`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ScanPush {
    n: u32,
    mode: u32,
    /// Input values above this are read as 0.
    cap: u32,
    pad: u32,
}

/// The scan pipeline, shared by every [`PrefixScan`] of a device.
pub struct ScanPipeline(ComputePipeline);

impl ScanPipeline {
    /// Creates the pipeline.
    pub fn new(device: &Device) -> Result<Self, PassError> {
        Ok(Self(device.create_compute_pipeline(
            "prefix scan",
            &shader("scan.comp")?,
            &[
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
            ],
            std::mem::size_of::<ScanPush>() as u32,
        )?))
    }
}

/// An exclusive scan of the first `n` elements of an input buffer into an output buffer (the same
/// buffer for a scan in place): after it, output element i holds the sum of the input elements before i.
pub struct PrefixScan {
    /// (bind group of level data + its block totals, elements of the level), from the data upwards: one
    /// level for a flat scan.
    levels: Vec<(BindGroup, u32)>,
    /// Whether the scan takes two dispatches over one level ([`FLAT_BLOCKS`]; one block takes one).
    flat: bool,
    _sums: Vec<Buffer>,
}

impl PrefixScan {
    /// Prepares the scan of the first `n` `u32` of `input` into `data` (storage buffers; they may be
    /// the same buffer).
    pub fn new(
        device: &Device,
        pipeline: &ScanPipeline,
        input: &Buffer,
        data: &Buffer,
        n: u32,
    ) -> Result<Self, PassError> {
        let mut sums: Vec<Buffer> = Vec::new();
        let mut counts = vec![n];
        let flat = (2..=FLAT_BLOCKS).contains(&u64::from(n).div_ceil(BLOCK));
        loop {
            let blocks = u64::from(*counts.last().unwrap_or(&1))
                .div_ceil(BLOCK)
                .max(1);
            sums.push(device.create_buffer(
                "scan block totals",
                blocks * 4,
                BufferUsage::STORAGE,
                MemoryLocation::GpuOnly,
            )?);
            if blocks == 1 || flat {
                break;
            }
            counts.push(blocks as u32);
        }
        let mut levels = Vec::with_capacity(counts.len());
        for (level, &count) in counts.iter().enumerate() {
            let (read, write) = if level == 0 {
                (input, data)
            } else {
                (&sums[level - 1], &sums[level - 1])
            };
            let group = device.create_bind_group(
                pipeline.0.layout(),
                &[
                    Resource::Buffer(read),
                    Resource::Buffer(write),
                    Resource::Buffer(&sums[level]),
                ],
            )?;
            levels.push((group, count));
        }
        Ok(Self {
            levels,
            flat,
            _sums: sums,
        })
    }

    /// Records the scan; the data buffer's earlier writes must be visible (UAV barrier) and its scanned
    /// values are visible to later storage accesses after the UAV barrier this records last.
    pub fn record(&self, enc: &mut Encoder<'_>, pipeline: &ScanPipeline) -> Result<(), PassError> {
        self.record_capped(enc, pipeline, u32::MAX)
    }

    /// [`PrefixScan::record`], reading every input value above `cap` as 0.
    pub fn record_capped(
        &self,
        enc: &mut Encoder<'_>,
        pipeline: &ScanPipeline,
        cap: u32,
    ) -> Result<(), PassError> {
        for step in 0..self.steps() {
            self.record_step(enc, pipeline, cap, step)?;
            enc.barriers(&[Barrier::Uav]);
        }
        Ok(())
    }

    /// The dispatches the scan takes, each to be followed by a UAV barrier before the next.
    pub fn steps(&self) -> usize {
        if self.flat {
            2 * self.levels.len()
        } else {
            2 * self.levels.len() - 1
        }
    }

    /// Records dispatch `step` (of [`PrefixScan::steps`]) of [`PrefixScan::record_capped`] alone, without
    /// the barrier after it: the steps of scans over different buffers may be interleaved, each round of
    /// steps followed by one UAV barrier.
    pub fn record_step(
        &self,
        enc: &mut Encoder<'_>,
        pipeline: &ScanPipeline,
        cap: u32,
        step: usize,
    ) -> Result<(), PassError> {
        let levels = self.levels.len();
        let (level, mode) = if self.flat {
            // The blocks' totals (mode 2), then each block from the totals before it (mode 3).
            (step / 2, 2 + (step % 2) as u32)
        } else if step < levels {
            // Up the levels scanning each block (mode 0)…
            (step, 0)
        } else {
            // …then down adding the block totals (mode 1).
            (2 * levels - 2 - step, 1)
        };
        let Some((group, n)) = self.levels.get(level) else {
            return Err(PassError::InvalidConfig(format!(
                "scan step {step} of {}",
                self.steps()
            )));
        };
        let push = ScanPush {
            n: *n,
            mode,
            // Only the input's values are capped (the levels above hold block totals).
            cap: if level == 0 { cap } else { u32::MAX },
            pad: 0,
        };
        enc.dispatch(
            &pipeline.0,
            group,
            bytemuck::bytes_of(&push),
            [u64::from(*n).div_ceil(BLOCK).max(1) as u32, 1, 1],
        )?;
        Ok(())
    }
}
