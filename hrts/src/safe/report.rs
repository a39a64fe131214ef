//! What the plugin tells: the device's [`Capabilities`], a light's [`FrameReport`], a resource's
//! [`ResourceInfo`] and the process's [`MemoryStats`].

use super::enums::{decode, BinningPath, CEnum, LightDecision, Pass, PassStatus, Resource};
use super::error::{c_chars, Result};
use crate::types::*;
use glam::Mat4;

/// What the device can do (`HrtsCapabilities`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Capabilities {
    /// D3D12 conservative-raster tier: 0 none, 1..3.
    pub conservative_raster_tier: u32,
    /// The path [`BinningPath::Auto`] resolves to.
    pub default_binning_path: BinningPath,
    /// Geometry shaders available (software path possible).
    pub geometry_shader: bool,
    /// Timestamp queries available (per-pass GPU times in the report).
    pub timestamps: bool,
    /// `VK_KHR_ray_query` present.
    pub ray_query: bool,
    /// `VK_KHR_ray_tracing_pipeline` present.
    pub ray_tracing_pipeline: bool,
    /// `VK_EXT_fragment_shader_interlock` present.
    pub fragment_shader_interlock: bool,
    /// Largest primitive map size N.
    pub max_map_size: u32,
    /// Largest primitive-map entry budget in KiB.
    pub max_map_entry_budget_kib: u32,
    /// `maxStorageBufferRange` in bytes.
    pub max_storage_buffer_range: u64,
    /// Device name.
    pub device_name: String,
}

impl Capabilities {
    /// The capabilities of the C ones `call` wrote.
    pub(crate) fn from_c(call: &'static str, c: &HrtsCapabilities) -> Result<Self> {
        Ok(Self {
            conservative_raster_tier: c.conservative_raster_tier,
            default_binning_path: decode(call, "default_binning_path", c.default_binning_path)?,
            geometry_shader: c.geometry_shader != 0,
            timestamps: c.timestamps != 0,
            ray_query: c.ray_query != 0,
            ray_tracing_pipeline: c.ray_tracing_pipeline != 0,
            fragment_shader_interlock: c.fragment_shader_interlock != 0,
            max_map_size: c.max_map_size,
            max_map_entry_budget_kib: c.max_map_entry_budget_kib,
            max_storage_buffer_range: c.max_storage_buffer_range,
            device_name: c_chars(&c.device_name),
        })
    }
}

/// GPU time of one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    /// The pass's name (for a light of several frusta, with the frustum's).
    pub name: String,
    /// Milliseconds.
    pub milliseconds: f64,
}

/// The primitive map's statistics of one light in one frame, summed over its frusta (the longest list is
/// the longest of any). Each field is the `HrtsFrameReport` field of the same name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MapStats {
    /// Pixels that traced a shadow ray.
    pub receiver_pixels: u32,
    /// Texels holding at least one ray origin.
    pub receiver_texels: u32,
    /// Triangles binned (not culled as degenerate, back-facing, outside or behind every receiver).
    pub triangles_binned: u32,
    /// Texels holding at least one triangle.
    pub texels_with_list: u32,
    /// Longest list of any texel.
    pub longest_list: u32,
    /// Entries (texel, triangle) the frame needed.
    pub entries: u32,
    /// Entries the lists could hold this frame (they grow to fit from the next frame on).
    pub entry_capacity: u32,
    /// Texels whose pixels walked the BVH because their lists did not fit the capacity or the packed
    /// offsets.
    pub texels_past_capacity: u32,
    /// A point light's cube map: the (triangle, face) pairs its setup kept (0 for other lights).
    pub bin_pairs: u32,
    /// The (triangle, face) pairs the cube map held.
    pub bin_pair_capacity: u32,
    /// Texels whose list passed the configuration's `map_list_limit`: their pixels walked the BVH.
    pub texels_past_limit: u32,
    /// Bin items (4x4-texel tiles of the footprints) of the frame's lists (saturated).
    pub bin_items: u32,
    /// Frusta whose bin items passed `map_bin_budget`: they built no list, every pixel walked the BVH.
    pub frusta_without_lists: u32,
    /// Pixels that walked the BVH rather than a list.
    pub pixels_walked: u32,
    /// BVH walks that could not finish (0 on a conforming device).
    pub walks_unfinished: u32,
    /// Area shadows: pixels whose bundle passed the configuration's `area_walk_budget`, or whose tile
    /// skipped it since most of its bundles gave up in an earlier frame, so that each of their open samples
    /// walked the BVH on its own.
    pub pixels_walked_per_sample: u32,
    /// N of the light's primitive map ([`Config::map_size`](crate::Config::map_size), or the plugin's
    /// choice for the light's trace); 0 if its passes have none.
    pub map_size: u32,
}

impl MapStats {
    /// Mean list length over the texels holding a list (0 without any).
    pub fn mean_list(&self) -> f64 {
        if self.texels_with_list == 0 {
            0.0
        } else {
            f64::from(self.entries) / f64::from(self.texels_with_list)
        }
    }
}

/// What one light's passes did in one frame (`hrts_get_frame_report`).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// The binning path used.
    pub binning_path: BinningPath,
    /// Conservative-raster tier used (0 for the compute and software paths).
    pub tier: u32,
    /// Per-pass GPU times.
    pub timings: Vec<PassTiming>,
    /// The status of each pass this frame, indexed by `Pass as usize` ([`FrameReport::status`]).
    pub pass_status: [PassStatus; HRTS_PASS_COUNT],
    /// Bytes of each resource the plugin allocated (0: not allocated), indexed by `Resource as usize`
    /// ([`FrameReport::resource_bytes`]), with the buffers that serve it (the list offsets count the
    /// primitive map's other buffers, the ray-traced visibility an area trace's own).
    pub resource_bytes: [u64; HRTS_RESOURCE_COUNT],
    /// The resource copied into the output image (or written into it directly: `output_direct`).
    pub output_resource: Resource,
    /// Whether the light's last pass wrote its layer of the output image directly, with no copy.
    pub output_direct: bool,
    /// Bytes of the prim buffer, shared by the context's lights (0 if the plan has none).
    pub prim_buffer_bytes: u64,
    /// Bytes of the primitive map's scratch, shared by the maps of the context's lights and frusta.
    pub map_scratch_bytes: u64,
    /// The primitive map's statistics.
    pub stats: MapStats,
    /// The primitive map's fit: frame coordinates (world minus the geometry's origin) to homogeneous
    /// texel space, of the first frustum recorded.
    pub map_to_texels: Mat4,
    /// How many times the light's passes were built since the context was created.
    pub light_builds: u32,
    /// Frusta the light was shadowed through this frame.
    pub frusta: u32,
    /// Frusta of the light skipped this frame: they can shadow no receiver in view within its range.
    pub frusta_culled: u32,
    /// What the plugin decided for the light.
    pub decision: LightDecision,
    /// Why, in words: the frusta recorded and culled, and under
    /// [`ShadowMode::Auto`](crate::ShadowMode::Auto) the mode chosen.
    pub decision_reason: String,
    /// GPU milliseconds of all the light's passes in the frame.
    pub gpu_milliseconds: f64,
    /// Triangles whose prim-buffer slots the frame rewrote (0 when the prim buffer was up to date).
    pub prim_triangles_rebuilt: u32,
}

impl FrameReport {
    /// What the frame did with `pass`.
    pub fn status(&self, pass: Pass) -> PassStatus {
        self.pass_status[pass as usize]
    }

    /// Bytes of `resource` (0: not allocated).
    pub fn resource_bytes(&self, resource: Resource) -> u64 {
        self.resource_bytes[resource as usize]
    }

    /// The resources the plugin allocated for the light, with their bytes, in value order.
    pub fn allocated_resources(&self) -> impl Iterator<Item = (Resource, u64)> + '_ {
        Resource::ALL
            .iter()
            .map(|&r| (r, self.resource_bytes(r)))
            .filter(|&(_, bytes)| bytes > 0)
    }

    /// The report of the C one `call` wrote.
    pub(crate) fn from_c(call: &'static str, r: &HrtsFrameReport) -> Result<Self> {
        let timings = r.passes[..(r.pass_count as usize).min(HRTS_MAX_REPORTED_PASSES)]
            .iter()
            .map(|p| PassTiming {
                name: c_chars(&p.name),
                milliseconds: p.milliseconds,
            })
            .collect();
        let mut pass_status = [PassStatus::NotInPlan; HRTS_PASS_COUNT];
        for (status, &value) in pass_status.iter_mut().zip(&r.pass_status) {
            *status = decode(call, "pass_status", value)?;
        }
        Ok(Self {
            binning_path: decode(call, "binning_path", r.binning_path)?,
            tier: r.tier,
            timings,
            pass_status,
            resource_bytes: r.resource_bytes,
            output_resource: decode(call, "output_resource", r.output_resource)?,
            output_direct: r.output_direct != 0,
            prim_buffer_bytes: r.prim_buffer_bytes,
            map_scratch_bytes: r.map_scratch_bytes,
            stats: MapStats {
                receiver_pixels: r.receiver_pixels,
                receiver_texels: r.receiver_texels,
                triangles_binned: r.triangles_binned,
                texels_with_list: r.texels_with_list,
                longest_list: r.longest_list,
                entries: r.entries,
                entry_capacity: r.entry_capacity,
                texels_past_capacity: r.texels_past_capacity,
                bin_pairs: r.bin_pairs,
                bin_pair_capacity: r.bin_pair_capacity,
                texels_past_limit: r.texels_past_limit,
                bin_items: r.bin_items,
                frusta_without_lists: r.frusta_without_lists,
                pixels_walked: r.pixels_walked,
                walks_unfinished: r.walks_unfinished,
                pixels_walked_per_sample: r.pixels_walked_per_sample,
                map_size: r.map_size,
            },
            map_to_texels: Mat4::from_cols_array(&r.map_to_texels),
            light_builds: r.light_builds,
            frusta: r.frusta,
            frusta_culled: r.frusta_culled,
            decision: decode(call, "decision", r.decision)?,
            decision_reason: c_chars(&r.decision_reason),
            gpu_milliseconds: r.gpu_milliseconds,
            prim_triangles_rebuilt: r.prim_triangles_rebuilt,
        })
    }
}

/// The shape of an allocated plugin resource, for reading it back (`HrtsResourceInfo`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResourceInfo {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Array layers.
    pub layers: u32,
    /// `VkFormat`.
    pub format: i32,
    /// Bytes of a tightly packed read-back of all layers (layer-major, rows top to bottom).
    pub bytes: u64,
}

/// Memory the plugin holds, over all contexts of the process (`hrts_get_memory_stats`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryStats {
    /// Host bytes allocated by the plugin and not freed: counted by the plugin's shared and static
    /// libraries only (`None` in a Rust program linking the `hrts` rlib, which keeps its own allocator).
    pub host_bytes: Option<u64>,
    /// GPU bytes allocated by the plugin and not freed (not what the Vulkan driver keeps internally).
    pub gpu_bytes: u64,
}

/// A primitive map's list offsets, unpacked from a read-back of
/// [`Resource::PrimListOffsets`](crate::Resource::PrimListOffsets) ([`unpack_list_offsets`]): texel `t`'s
/// list is `entries[range(t)]` of a read-back of [`Resource::PrimListEntries`](crate::Resource::PrimListEntries).
pub use passes::ListOffsets;

/// Unpacks a read-back of [`Resource::PrimListOffsets`] (its `u32` words, the packed groups `hrts.h`
/// describes) into every texel's list bounds, and whether its list was kept.
///
/// ```
/// // One group of 16 texels whose lists hold nothing, and the final group: no entries.
/// let offsets = hrts::unpack_list_offsets(&[0; 18])?;
/// assert_eq!((offsets.total(), offsets.range(3)), (0, Some(0..0)));
/// # Ok::<(), hrts::Error>(())
/// ```
pub fn unpack_list_offsets(words: &[u32]) -> Result<ListOffsets> {
    passes::unpack_list_offsets(words, passes::packed_texels(words.len())).map_err(|message| {
        super::error::Error::new(
            "hrts::unpack_list_offsets",
            HrtsResult::ErrorInvalidArgument,
            message,
        )
    })
}
