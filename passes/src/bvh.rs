//! Two bounding volume hierarchies over the prim buffer, built on the GPU from the triangles sorted by the
//! 30-bit Morton codes of their box centres (a stable radix sort):
//! - the linear BVH (Karras 2012), which the area traces' bundles of segments or rays walk: each internal
//!   node finds its range and split from the sorted codes, and the boxes are merged from the leaves up;
//! - the rays' BVH, which single rays and segments walk (the hard trace, the area trace's samples walked
//!   one by one): the sorted triangles merged bottom-up by locally-ordered clustering (PLOC, Meister and
//!   Bittner 2018: each cluster's nearest neighbour by the surface area of their union, among the 16 on
//!   either side in Morton order; mutual neighbours merge), then laid out depth first. Its boxes cost
//!   about half the linear BVH's by surface area, and single rays walk it faster; the bundles, whose
//!   sample masks prune the Morton-ordered subtrees better, walk the linear one (the Sponza spot light's
//!   bundles met half the triangles there). Where the clustering cannot build the whole hierarchy within
//!   its iterations and depth (one triangle, or a pathological input), or for geometry rebuilt every
//!   frame ([`BvhBuilder::Linear`]: the clustering costs several times the linear build), it is a copy of
//!   the linear one.
//!
//! Both are rebuilt whenever the prim buffer is, and kept while the geometry is static.
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

/// Clusters that one workgroup merges in iterations of its own (`TAIL` in `bvh_ploc.comp`).
const TAIL_CLUSTERS: u32 = 1024;

/// Iterations of the clustering (`bvh_ploc.comp`) over the whole buffer for `triangles` triangles, until
/// [`TAIL_CLUSTERS`] or fewer are left: each leaves at most about 0.85 of the clusters (66K triangles of
/// Sponza needed 21 to 24, 277K of the conference room 33 to 40), with 8 to spare. Past them, what is
/// left merges in pairs.
fn cluster_iterations(triangles: u32) -> u32 {
    if triangles <= TAIL_CLUSTERS {
        return 0;
    }
    let ratio = f64::from(triangles) / f64::from(TAIL_CLUSTERS);
    (ratio.ln() / -(0.85f64.ln())).ceil() as u32 + 8
}

/// Iterations after those that merge what is left in pairs (up to 2^15 clusters; none are left in real
/// scenes).
const PAIRING_ITERATIONS: u32 = 15;

/// How a build makes the rays' hierarchy ([`SceneBvh::ray_nodes`]) of a [`SceneBvh`] with a clustering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BvhBuilder {
    /// By clustering; a copy of the linear BVH where the clustering cannot build it.
    Clustered,
    /// A copy of the linear BVH (for geometry rebuilt every frame).
    Linear,
}

/// Push constants of `bvh_ploc.comp`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ClusterPush {
    triangles: u32,
    mode: u32,
    parity: u32,
    forced: u32,
}

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

/// The rays' hierarchy and what the clustering builds it with ([`BvhBuilder::Clustered`]).
struct Clustering {
    pipeline: ComputePipeline,
    /// Internal nodes of the rays' BVH.
    ray_nodes: Buffer,
    /// The clustering's counts, nodes made, depth and whether it failed.
    state: Buffer,
    /// The clusters of even and odd iterations.
    clusters: [Buffer; 2],
    neighbours: Buffer,
    keep: Buffer,
    positions: Buffer,
    keep_scan: PrefixScan,
    /// Per node made: its parent and its subtree's size.
    links: Buffer,
    /// The iterations from clusters 0 to 1, and from 1 to 0.
    groups: [BindGroup; 2],
}

/// The hierarchies over one prim buffer, and what builds them.
pub struct SceneBvh {
    triangles: u32,
    keys_pipeline: ComputePipeline,
    sort_pipeline: ComputePipeline,
    build_pipeline: ComputePipeline,
    scan_pipeline: ScanPipeline,
    /// Internal nodes of the linear BVH (`max(triangles - 1, 1)`).
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
    /// None where the rays' hierarchy is always the linear one.
    clustering: Option<Clustering>,
}

/// A GPU-only storage buffer of at least 4 bytes.
fn storage(device: &Device, name: &str, bytes: u64) -> Result<Buffer, PassError> {
    Ok(device.create_buffer(
        name,
        bytes.max(4),
        BufferUsage::STORAGE | BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
        MemoryLocation::GpuOnly,
    )?)
}

/// Bytes of a hierarchy's nodes over `n` triangles.
fn node_bytes(n: u64) -> u64 {
    n.saturating_sub(1).max(1) * std::mem::size_of::<BvhNode>() as u64
}

impl Clustering {
    /// The clustering's buffers and pipeline over the triangles of `prims` sorted into `values`, making its
    /// nodes in `nodes` (the linear BVH's, free until its build).
    fn new(
        device: &Device,
        scan_pipeline: &ScanPipeline,
        [prims, values, nodes]: [&Buffer; 3],
        triangles: u32,
    ) -> Result<Self, PassError> {
        let n = u64::from(triangles.max(1));
        let ray_nodes = storage(device, "bvh nodes (rays)", node_bytes(n))?;
        let state = storage(device, "bvh clustering", 32)?;
        let clusters = [
            storage(device, "bvh clusters", n * 32)?,
            storage(device, "bvh clusters (next)", n * 32)?,
        ];
        let neighbours = storage(device, "bvh neighbours", n * 4)?;
        let keep = storage(device, "bvh keep", n * 4)?;
        let positions = storage(device, "bvh positions", n * 4)?;
        let links = storage(device, "bvh links", n * 8)?;
        let keep_scan = PrefixScan::new(device, scan_pipeline, &keep, &positions, triangles)?;
        let pipeline = device.create_compute_pipeline(
            "bvh clustering",
            &shader("bvh_ploc.comp")?,
            &[BindingKind::StorageBuffer; 11],
            std::mem::size_of::<ClusterPush>() as u32,
        )?;
        let group = |from: usize| {
            device.create_bind_group(
                pipeline.layout(),
                &[
                    Resource::Buffer(prims),
                    Resource::Buffer(values),
                    Resource::Buffer(nodes),
                    Resource::Buffer(&state),
                    Resource::Buffer(&clusters[from]),
                    Resource::Buffer(&clusters[1 - from]),
                    Resource::Buffer(&neighbours),
                    Resource::Buffer(&positions),
                    Resource::Buffer(&keep),
                    Resource::Buffer(&links),
                    Resource::Buffer(&ray_nodes),
                ],
            )
        };
        let groups = [group(0)?, group(1)?];
        Ok(Self {
            pipeline,
            ray_nodes,
            state,
            clusters,
            neighbours,
            keep,
            positions,
            keep_scan,
            links,
            groups,
        })
    }

    /// GPU bytes of the rays' hierarchy and the clustering's scratch.
    fn bytes(&self) -> u64 {
        [
            &self.ray_nodes,
            &self.state,
            &self.clusters[0],
            &self.clusters[1],
            &self.neighbours,
            &self.keep,
            &self.positions,
            &self.links,
        ]
        .iter()
        .map(|b| b.size())
        .sum()
    }
}

impl SceneBvh {
    /// Creates the hierarchies' buffers for the `triangles` triangles of `prims` (built by
    /// [`SceneBvh::record_build`]). Without `clustered`, the rays' hierarchy is always the linear one (for
    /// geometry rebuilt every frame), and the clustering's buffers are not allocated.
    pub fn new(
        device: &Device,
        prims: &Buffer,
        triangles: u32,
        clustered: bool,
    ) -> Result<Self, PassError> {
        let n = u64::from(triangles.max(1));
        let nodes = storage(device, "bvh nodes", node_bytes(n))?;
        let header = storage(device, "bvh header", 32)?;
        let keys = [
            storage(device, "bvh keys", n * 4)?,
            storage(device, "bvh keys (sorting)", n * 4)?,
        ];
        let values = [
            storage(device, "bvh values", n * 4)?,
            storage(device, "bvh values (sorting)", n * 4)?,
        ];
        let parents = storage(device, "bvh parents", (2 * n) * 4)?;
        let arrivals = storage(device, "bvh arrivals", n * 4)?;
        let blocks = triangles.div_ceil(SORT_BLOCK).max(1);
        let digit_counts = storage(
            device,
            "bvh digit counts",
            u64::from(SORT_DIGITS * blocks) * 4,
        )?;
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
        let clustering = clustered
            .then(|| {
                Clustering::new(
                    device,
                    &scan_pipeline,
                    [prims, &values[0], &nodes],
                    triangles,
                )
            })
            .transpose()?;
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
            clustering,
        })
    }

    /// The linear BVH's nodes ([`BvhNode`]; node 0 is the root), which bundles walk.
    pub fn nodes(&self) -> &Buffer {
        &self.nodes
    }

    /// The rays' BVH's nodes ([`BvhNode`]; node 0 is the root), which single rays and segments walk: the
    /// linear BVH's own where the hierarchy has no clustering.
    pub fn ray_nodes(&self) -> &Buffer {
        self.clustering
            .as_ref()
            .map_or(&self.nodes, |c| &c.ray_nodes)
    }

    /// GPU bytes of the hierarchies and their build scratch.
    pub fn bytes(&self) -> u64 {
        let clustering = self.clustering.as_ref().map_or(0, Clustering::bytes);
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
        .sum::<u64>()
            + clustering
    }

    /// Records the build of the hierarchies over the prim buffer, the rays' by `builder` where it has a
    /// clustering (else the linear one is the rays'). The prim buffer's writes must be visible to storage
    /// reads (a UAV barrier); the nodes are visible to storage reads after the UAV barrier this records
    /// last.
    pub fn record_build(
        &self,
        enc: &mut Encoder<'_>,
        builder: BvhBuilder,
    ) -> Result<(), PassError> {
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
        // The clustering makes its nodes in the linear hierarchy's buffer, then orders them into the
        // rays'; the linear build follows, and the rays' takes its copy where the clustering failed.
        if let Some(c) = &self.clustering {
            self.record_clustering(enc, c, builder)?;
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
        match &self.clustering {
            Some(c) => self.record_cluster_step(enc, c, [0, 7], false, groups),
            None => Ok(()),
        }
    }

    /// Records the clustering over the sorted triangles, whether it built the whole hierarchy, and if so
    /// the rays' nodes, the clustered ones in depth-first order.
    fn record_clustering(
        &self,
        enc: &mut Encoder<'_>,
        c: &Clustering,
        builder: BvhBuilder,
    ) -> Result<(), PassError> {
        let groups = [self.triangles.div_ceil(64), 1, 1];
        self.record_cluster_step(enc, c, [0, 0], false, groups)?;
        let clustering = cluster_iterations(self.triangles);
        let iterations = if builder == BvhBuilder::Clustered && self.triangles > 1 {
            clustering + PAIRING_ITERATIONS
        } else {
            0
        };
        for iteration in 0..iterations {
            let parity = iteration % 2;
            let pairing = iteration >= clustering;
            if iteration == clustering {
                self.record_cluster_step(enc, c, [parity, 4], false, [1, 1, 1])?;
            }
            self.record_cluster_step(enc, c, [parity, 1], pairing, groups)?;
            self.record_cluster_step(enc, c, [parity, 2], pairing, groups)?;
            c.keep_scan.record(enc, &self.scan_pipeline)?;
            self.record_cluster_step(enc, c, [parity, 3], pairing, groups)?;
        }
        let linear = builder == BvhBuilder::Linear;
        let parity = iterations % 2;
        self.record_cluster_step(enc, c, [parity, 5], linear, [1, 1, 1])?;
        self.record_cluster_step(enc, c, [parity, 6], false, groups)
    }

    /// Records one dispatch of `bvh_ploc.comp` (its iteration's parity and mode) and a UAV barrier.
    fn record_cluster_step(
        &self,
        enc: &mut Encoder<'_>,
        c: &Clustering,
        [parity, mode]: [u32; 2],
        forced: bool,
        groups: [u32; 3],
    ) -> Result<(), PassError> {
        let push = ClusterPush {
            triangles: self.triangles,
            mode,
            parity,
            forced: u32::from(forced),
        };
        enc.dispatch(
            &c.pipeline,
            &c.groups[parity as usize],
            bytemuck::bytes_of(&push),
            groups,
        )?;
        enc.barriers(&[Barrier::Uav]);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clustering_iterates_by_the_triangles() {
        assert_eq!(cluster_iterations(1), 0);
        assert_eq!(cluster_iterations(TAIL_CLUSTERS), 0);
        assert_eq!(cluster_iterations(TAIL_CLUSTERS + 1), 9);
        // Measured: Sponza left 728 clusters after 24 iterations, the conference room 325 after 40.
        assert!(cluster_iterations(66_454) >= 24);
        assert!(cluster_iterations(276_505) >= 40);
    }

    #[test]
    fn the_tail_is_the_shaders() {
        let source = include_str!("../shaders/bvh_ploc.comp");
        assert!(source.contains(&format!("const uint TAIL = {TAIL_CLUSTERS}u;")));
    }
}
