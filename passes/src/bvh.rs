//! A bounding volume hierarchy over the prim buffer, built on the GPU (a linear BVH, Karras 2012): the
//! triangles' box centres get 30-bit Morton codes, a stable radix sort orders them, each internal node
//! finds its range and split from the sorted codes, and the boxes are merged from the leaves up. It is
//! rebuilt whenever the prim buffer is, and kept while the geometry is static.
//!
//! The traces walk it (`bvh_traverse.glsl`) wherever a texel's list is missing or would cost more than a
//! traversal: a texel past the entry capacity, in a group whose offsets overflowed, whose list is longer
//! than the map's list limit, or every texel of a frame whose lists would take more than the map's bin
//! budget. A traversal tests exactly the triangles whose boxes meet the bundle of the pixel's rays or
//! segments, with the same exact test and samples as the lists: it gives the same answer, bit for bit.
//!
//! Reads: prim buffer. Writes: the hierarchy's nodes (and its build scratch).

use crate::scan::{PrefixScan, ScanPipeline};
use crate::shaders::shader;
use crate::PassError;
use bytemuck::{Pod, Zeroable};
use glam::Vec4;
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, BufferUsage, ComputePipeline, Device, Encoder,
    MemoryLocation, Resource,
};

/// An internal node of the hierarchy (`bvh.glsl`): its two children's boxes, each child another node's
/// index or, with [`BVH_LEAF`] set, a triangle's index in the prim buffer.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct BvhNode {
    /// The left child's box minimum (xyz); w: the left child (`u32` bits).
    pub left_lo: Vec4,
    /// The left child's box maximum (xyz).
    pub left_hi: Vec4,
    /// The right child's box minimum (xyz); w: the right child (`u32` bits).
    pub right_lo: Vec4,
    /// The right child's box maximum (xyz).
    pub right_hi: Vec4,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 64);

/// Marks a child that is a triangle (`BVH_LEAF` in `bvh.glsl`).
pub const BVH_LEAF: u32 = 0x8000_0000;

/// Pairs one workgroup of the radix sort orders (`radix_sort.comp`).
const SORT_BLOCK: u32 = 1024;

/// Digits of one radix-sort pass (4 bits).
const SORT_DIGITS: u32 = 16;

/// Push constants of `bvh_keys.comp` and `bvh_build.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BuildPush {
    triangles: u32,
    mode: u32,
}

/// Push constants of `radix_sort.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SortPush {
    n: u32,
    shift: u32,
    mode: u32,
    blocks: u32,
}

/// The hierarchy over one prim buffer, and what builds it.
pub struct SceneBvh {
    triangles: u32,
    keys_pipeline: ComputePipeline,
    sort_pipeline: ComputePipeline,
    build_pipeline: ComputePipeline,
    scan_pipeline: ScanPipeline,
    /// Internal nodes (`max(triangles - 1, 1)`).
    nodes: Buffer,
    header: Buffer,
    keys: [Buffer; 2],
    values: [Buffer; 2],
    parents: Buffer,
    arrivals: Buffer,
    digit_counts: Buffer,
    digit_scan: PrefixScan,
    keys_group: BindGroup,
    /// Sort passes from buffers 0 to 1, and from 1 to 0.
    sort_groups: [BindGroup; 2],
    build_group: BindGroup,
}

impl SceneBvh {
    /// Creates the hierarchy's buffers for the `triangles` triangles of `prims` (built by
    /// [`SceneBvh::record_build`]).
    pub fn new(device: &Device, prims: &Buffer, triangles: u32) -> Result<Self, PassError> {
        let n = u64::from(triangles.max(1));
        let storage = |name: &str, bytes: u64| -> Result<Buffer, PassError> {
            Ok(device.create_buffer(
                name,
                bytes.max(4),
                BufferUsage::STORAGE | BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                MemoryLocation::GpuOnly,
            )?)
        };
        let nodes = storage(
            "bvh nodes",
            n.saturating_sub(1).max(1) * std::mem::size_of::<BvhNode>() as u64,
        )?;
        let header = storage("bvh header", 32)?;
        let keys = [
            storage("bvh keys", n * 4)?,
            storage("bvh keys (sorting)", n * 4)?,
        ];
        let values = [
            storage("bvh values", n * 4)?,
            storage("bvh values (sorting)", n * 4)?,
        ];
        let parents = storage("bvh parents", (2 * n) * 4)?;
        let arrivals = storage("bvh arrivals", n * 4)?;
        let blocks = triangles.div_ceil(SORT_BLOCK).max(1);
        let digit_counts = storage("bvh digit counts", u64::from(SORT_DIGITS * blocks) * 4)?;
        let scan_pipeline = ScanPipeline::new(device)?;
        let digit_scan = PrefixScan::new(
            device,
            &scan_pipeline,
            &digit_counts,
            &digit_counts,
            SORT_DIGITS * blocks,
        )?;
        let build = std::mem::size_of::<BuildPush>() as u32;
        let keys_pipeline = device.create_compute_pipeline(
            "bvh keys",
            &shader("bvh_keys.comp")?,
            &[BindingKind::StorageBuffer; 4],
            build,
        )?;
        let sort_pipeline = device.create_compute_pipeline(
            "bvh sort",
            &shader("radix_sort.comp")?,
            &[BindingKind::StorageBuffer; 5],
            std::mem::size_of::<SortPush>() as u32,
        )?;
        let build_pipeline = device.create_compute_pipeline(
            "bvh build",
            &shader("bvh_build.comp")?,
            &[BindingKind::StorageBuffer; 6],
            build,
        )?;
        let keys_group = device.create_bind_group(
            keys_pipeline.layout(),
            &[
                Resource::Buffer(prims),
                Resource::Buffer(&header),
                Resource::Buffer(&keys[0]),
                Resource::Buffer(&values[0]),
            ],
        )?;
        let sort_group = |from: usize| {
            device.create_bind_group(
                sort_pipeline.layout(),
                &[
                    Resource::Buffer(&keys[from]),
                    Resource::Buffer(&values[from]),
                    Resource::Buffer(&keys[1 - from]),
                    Resource::Buffer(&values[1 - from]),
                    Resource::Buffer(&digit_counts),
                ],
            )
        };
        let sort_groups = [sort_group(0)?, sort_group(1)?];
        let build_group = device.create_bind_group(
            build_pipeline.layout(),
            &[
                Resource::Buffer(prims),
                Resource::Buffer(&keys[0]),
                Resource::Buffer(&values[0]),
                Resource::Buffer(&nodes),
                Resource::Buffer(&parents),
                Resource::Buffer(&arrivals),
            ],
        )?;
        Ok(Self {
            triangles,
            keys_pipeline,
            sort_pipeline,
            build_pipeline,
            scan_pipeline,
            nodes,
            header,
            keys,
            values,
            parents,
            arrivals,
            digit_counts,
            digit_scan,
            keys_group,
            sort_groups,
            build_group,
        })
    }

    /// The hierarchy's nodes ([`BvhNode`]; node 0 is the root).
    pub fn nodes(&self) -> &Buffer {
        &self.nodes
    }

    /// GPU bytes of the hierarchy and its build scratch.
    pub fn bytes(&self) -> u64 {
        [
            &self.nodes,
            &self.header,
            &self.keys[0],
            &self.keys[1],
            &self.values[0],
            &self.values[1],
            &self.parents,
            &self.arrivals,
            &self.digit_counts,
        ]
        .iter()
        .map(|b| b.size())
        .sum()
    }

    /// Records the build over the prim buffer, whose writes must be visible to storage reads (a UAV
    /// barrier); the nodes are visible to storage reads after the UAV barrier this records last.
    pub fn record_build(&self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        let n = self.triangles;
        if n == 0 {
            return Ok(());
        }
        let groups = [n.div_ceil(64), 1, 1];
        let empty: [u32; 8] = [u32::MAX, u32::MAX, u32::MAX, u32::MAX, 0, 0, 0, 0];
        enc.barriers(&[Barrier::Global {
            before: rhi::ResourceState::UnorderedAccess,
            after: rhi::ResourceState::CopyDest,
        }]);
        enc.update_buffer(&self.header, 0, bytemuck::cast_slice(&empty))?;
        enc.barriers(&[Barrier::Global {
            before: rhi::ResourceState::CopyDest,
            after: rhi::ResourceState::UnorderedAccess,
        }]);
        for mode in 0..2 {
            let push = BuildPush { triangles: n, mode };
            enc.dispatch(
                &self.keys_pipeline,
                &self.keys_group,
                bytemuck::bytes_of(&push),
                groups,
            )?;
            enc.barriers(&[Barrier::Uav]);
        }
        let blocks = n.div_ceil(SORT_BLOCK);
        // Eight passes of four bits: the sorted pairs end in the buffers they started in.
        for pass in 0..8u32 {
            let group = &self.sort_groups[(pass % 2) as usize];
            for mode in 0..2 {
                let push = SortPush {
                    n,
                    shift: pass * 4,
                    mode,
                    blocks,
                };
                enc.dispatch(
                    &self.sort_pipeline,
                    group,
                    bytemuck::bytes_of(&push),
                    [blocks, 1, 1],
                )?;
                enc.barriers(&[Barrier::Uav]);
                if mode == 0 {
                    self.digit_scan.record(enc, &self.scan_pipeline)?;
                }
            }
        }
        for mode in 0..2 {
            let push = BuildPush { triangles: n, mode };
            enc.dispatch(
                &self.build_pipeline,
                &self.build_group,
                bytemuck::bytes_of(&push),
                groups,
            )?;
            enc.barriers(&[Barrier::Uav]);
        }
        Ok(())
    }
}
