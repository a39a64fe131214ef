//! The deep primitive map, with no fixed depth: exact variable-length per-texel lists of the triangles
//! that may shadow each texel's ray origins, in a light-space grid fitted to what the camera sees.
//!
//! Per frame, all on the GPU (no host round trip):
//! 1. receivers: every pixel's shadow-ray origin is placed in light space; the map is fitted to their
//!    bounds, and each texel records whether it holds ray origins and how deep the deepest one lies;
//! 2. setup: each triangle is culled (zero area with two equal vertices, back-facing in front-only mode,
//!    outside every receiver texel, or farther from the light than every ray origin) or projected, with a
//!    rigorous bound on its projection error, and split into 4×4-texel tiles of its bounding box;
//! 3. count, scan, fill: the (triangle, texel) pairs that pass the exact conservative overlap test are
//!    counted per texel, the counts are prefix-summed in place, packed into the map's list offsets
//!    ([`packed_offset_words`]: 2.25 bytes per texel) and then serve as the fill's cursors. Memory is
//!    proportional to the entries; nothing is ever dropped. Texels whose list would pass the entry
//!    capacity (or whose group of 16 texels holds 65536 entries or more) are traced exhaustively (exact,
//!    slower), reported, and the capacity grows for the next frame within the memory budget.
//!
//! The count and fill run in a compute shader (load-balanced over tiles) or, for the tier-fallback paths,
//! through the rasterizer: hardware conservative raster at the device's tier, the geometry-shader software
//! path, or tier-1 emulation. Every path applies the same exact test and builds the same lists.
//!
//! Reads: prim buffer, depth, normal. Writes: receiver map, per-pixel texels, list offsets, list entries,
//! map state (fit, statistics); occupancy image (occupancy pass).

use crate::gpu_types::{constant_buffer, MapConstants, MapPush, MapState, RayTraceConstants};
use crate::scan::ScanPipeline;
use crate::shaders::shader;
use crate::PassError;
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, BufferUsage, Device, Encoder, Format,
    GraphicsPipeline, GraphicsPipelineDesc, Image, ImageDesc, ImageUsage, MemoryLocation, Resource,
    ResourceState as S,
};

mod config;
mod offsets;
mod pipelines;
mod scratch;

pub use config::{
    choose_binning_path, BinningPath, BinningRequest, FaceMode, PrimitiveMapConfig,
    DEFAULT_BIN_BUDGET, DEFAULT_ENTRY_BUDGET, DEFAULT_LIST_LIMIT, GUARD_VALUE, GUARD_WORDS,
    MIN_ENTRY_BUDGET, NEAREST_HIT_MAP_SIZE, PLUGINS_CHOICE_SIZE, TRACED_MAP_SIZE,
};
pub use offsets::{
    packed_offset_words, packed_texels, unpack_list_offsets, ListOffsets, OFFSET_GROUP,
    OFFSET_GROUP_OVERFLOW, OFFSET_GROUP_WORDS,
};
use pipelines::{Binner, MapPipelines};
use scratch::{receiver_words, storage_buffer, BindTargets, SharedTexels, PAIR_BYTES};
pub use scratch::{MapScratch, MapScratchPool, ScratchBindings};

/// Orders earlier storage reads and transfer reads (a read-back's copy) of a buffer before transfer writes
/// into it (an update or a fill).
const BEFORE_TRANSFER_WRITES: [Barrier<'static>; 2] = [
    Barrier::Global {
        before: S::UnorderedAccess,
        after: S::CopyDest,
    },
    Barrier::Global {
        before: S::CopySource,
        after: S::CopyDest,
    },
];

/// Threads of the compute binning dispatch (a grid-stride loop over the bin items).
const BIN_THREADS: u32 = 64 * 4096;

/// Source of [`PrimitiveMap`] ids (0 marks pixel texels no map wrote yet).
static NEXT_MAP_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

/// The fewest entries [`PrimitiveMap::fit_entries`] shrinks a map's lists to (256 KiB).
pub const MIN_FITTED_ENTRIES: u32 = 65536;

/// What the map's passes read from outside it.
pub struct PrimitiveMapInputs<'a> {
    /// The prim buffer.
    pub prims: &'a Buffer,
    /// Triangles in the prim buffer.
    pub triangles: u32,
    /// Depth (`ShaderResource` state when the map is built).
    pub depth: &'a Image,
    /// Camera-facing geometric normal, w = 0 on background (`ShaderResource` state).
    pub normal: &'a Image,
    /// Whether the occupancy pass draws the N×N occupancy view, besides reading back the statistics.
    pub occupancy_view: bool,
    /// Where the map takes its build scratch from (one of its geometry's scratch sets).
    pub scratch: &'a MapScratchPool,
}

/// A phase of the fit of a primitive map's grid ([`PrimitiveMap::record_fit_phase`]), in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitPhase {
    /// The frame's constants and the state reset (transfers).
    Reset,
    /// The receivers' light-space bounds (storage writes).
    Bounds,
    /// The grid fitted to the bounds (storage writes).
    Grid,
}

impl FitPhase {
    /// The phases in their order.
    pub const ALL: [FitPhase; 3] = [FitPhase::Reset, FitPhase::Bounds, FitPhase::Grid];

    /// The barrier that makes the phase's writes visible to the next (and the fit to storage reads).
    pub fn barrier_after(self) -> Barrier<'static> {
        match self {
            FitPhase::Reset => Barrier::Global {
                before: S::CopyDest,
                after: S::UnorderedAccess,
            },
            FitPhase::Bounds | FitPhase::Grid => Barrier::Uav,
        }
    }
}

/// A step of the lists' build ([`PrimitiveMap::record_list_step`]), in the order of
/// [`PrimitiveMap::list_steps`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ListStep {
    /// The receiver map, the counts and the capped bits cleared (transfers).
    Clear,
    /// The receivers marked in the map and each pixel's texel written.
    Receivers,
    /// The triangles culled, projected and split into tiles.
    Setup,
    /// A dispatch of the tiles' prefix scan.
    TileScan(usize),
    /// The bin walk's search index (compute binning).
    SearchIndex,
    /// The (triangle, texel) pairs counted per texel.
    Count,
    /// A dispatch of the counts' prefix scan.
    OffsetScan(usize),
    /// The scanned counts packed into the list offsets (mode 0), then the cursors of the lists not kept
    /// (mode 1).
    Pack(u32),
    /// The lists filled.
    Fill,
}

impl ListStep {
    /// The barrier that makes the step's writes visible to the next step.
    pub fn barrier_after(self) -> Barrier<'static> {
        match self {
            ListStep::Clear => Barrier::Global {
                before: S::CopyDest,
                after: S::UnorderedAccess,
            },
            _ => Barrier::Uav,
        }
    }

    /// The timed pass this step opens, when it is the first of one.
    fn pass_name(self, path: BinningPath) -> Option<String> {
        match self {
            ListStep::Clear => Some("primitive map: receivers".into()),
            ListStep::Setup => Some("primitive map: setup".into()),
            ListStep::Count => Some(format!("primitive map: count ({})", path.label())),
            ListStep::OffsetScan(0) => Some("primitive map: scan".into()),
            ListStep::Fill => Some(format!("primitive map: fill ({})", path.label())),
            _ => None,
        }
    }
}

/// The primitive map's resources and passes.
pub struct PrimitiveMap {
    config: PrimitiveMapConfig,
    path: BinningPath,
    triangles: u32,
    screen: (u32, u32),
    capacity: u32,
    /// Bin triangles the scratch bindings hold: the triangles, or a cube's (triangle, face) pairs.
    bins: u32,
    pipes: MapPipelines,
    fit_group: BindGroup,
    receivers_group: BindGroup,
    occupancy_group: BindGroup,
    bound: ScratchBindings,
    constants: Buffer,
    /// The map's per-frame state: one [`MapState`] per frustum (fitted transform and grid; the totals and
    /// statistics in the first).
    pub state: Buffer,
    /// One `u32` per texel, used while the map is built: 0 where no ray origin lies, else the ordered
    /// largest depth key of the texel's origins. Shared by the maps of the same scratch set (the pool's),
    /// unless the map draws an occupancy view, which reads it after the build.
    receivers: std::sync::Arc<Buffer>,
    /// One `u32` per screen pixel: the texel of its ray origin (or a no-ray / outside marker). Shared by
    /// the maps of the same scratch set (the pool's): see [`PrimitiveMap::record_pixel_texels`].
    pixel_texels: SharedTexels,
    /// This map's mark in the pixel texels' record of their last writer.
    id: u64,
    /// The push constants of the last build recorded (its pixel texels are rewritten from them).
    last_push: Option<MapPush>,
    /// The lists' offsets, packed ([`packed_offset_words`]: a `u32` per 16 texels, a `u16` per texel).
    pub offsets: Buffer,
    /// The lists' triangle indices (capacity `u32`, plus the guard words in guard mode).
    pub entries: Buffer,
    /// `RGBA8` occupancy view: N×N, or 1×1 and never written without `occupancy_view`.
    occupancy: Image,
    occupancy_view: bool,
}

impl PrimitiveMap {
    /// Creates the map for `inputs`, with the binning path chosen from the device's capabilities.
    pub fn new(
        device: &Device,
        inputs: &PrimitiveMapInputs<'_>,
        config: PrimitiveMapConfig,
    ) -> Result<Self, PassError> {
        let caps = device.capabilities();
        config.validate(caps)?;
        let config = config.with_size_for(false);
        let path = choose_binning_path(caps, config.binning)?;
        let n = config.size;
        let texels = config.texels();
        let (width, height) = (inputs.depth.width(), inputs.depth.height());
        let storage = |name, bytes, usage| storage_buffer(device, name, bytes, usage);
        let copy = BufferUsage::COPY_DST | BufferUsage::COPY_SRC;
        let constants = constant_buffer::<MapConstants>(device, "primitive map constants")?;
        let state = storage(
            "primitive map state",
            u64::from(config.frusta()) * std::mem::size_of::<MapState>() as u64,
            copy,
        )?;
        let receivers = if inputs.occupancy_view {
            std::sync::Arc::new(storage(
                "primitive map receivers",
                receiver_words(texels) * 4,
                copy,
            )?)
        } else {
            inputs.scratch.receivers(device, texels)?
        };
        let pixel_texels = inputs
            .scratch
            .pixel_texels(device, u64::from(width) * u64::from(height))?;
        let offsets = storage(
            "primitive map list offsets",
            packed_offset_words(texels) * 4,
            copy,
        )?;
        let capacity = config.starting_entries(caps, inputs.triangles);
        let entries = Self::create_entries(device, &config, capacity)?;
        let view_size = if inputs.occupancy_view { n } else { 1 };
        let occupancy = device.create_image(&ImageDesc {
            name: "primitive map occupancy",
            format: Format::Rgba8Unorm,
            width: view_size,
            height: view_size,
            layers: 1,
            usage: ImageUsage::STORAGE | ImageUsage::COPY_SRC,
        })?;
        let pipes = Self::pipelines(device, path)?;
        let fit_group = device.create_bind_group(
            pipes.fit.layout(),
            &[Resource::Buffer(&state), Resource::Buffer(&constants)],
        )?;
        let receivers_group = device.create_bind_group(
            pipes.receivers.layout(),
            &[
                Resource::Buffer(&constants),
                Resource::Image(inputs.depth),
                Resource::Image(inputs.normal),
                Resource::Buffer(&state),
                Resource::Buffer(&receivers),
                Resource::Buffer(&pixel_texels.buffer),
            ],
        )?;
        let occupancy_group = device.create_bind_group(
            pipes.occupancy.layout(),
            &[
                Resource::Buffer(&offsets),
                Resource::Buffer(&receivers),
                Resource::Image(&occupancy),
                Resource::Buffer(&state),
            ],
        )?;
        let bins = config.starting_pairs(inputs.triangles);
        let owners = if config.cube { bins } else { 0 };
        let scratch = inputs.scratch.get(device, texels, bins, owners)?;
        let targets = BindTargets {
            prims: inputs.prims,
            state: &state,
            receivers: &receivers,
            offsets: &offsets,
            entries: &entries,
            pool: inputs.scratch,
            entry_capacity: capacity,
        };
        let bound = ScratchBindings::new(device, &pipes, scratch, &targets, (texels, bins))?;
        Ok(Self {
            config,
            path,
            triangles: inputs.triangles,
            screen: (width, height),
            capacity,
            bins,
            pipes,
            fit_group,
            receivers_group,
            occupancy_group,
            bound,
            constants,
            state,
            receivers,
            pixel_texels,
            id: NEXT_MAP_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            last_push: None,
            offsets,
            entries,
            occupancy,
            occupancy_view: inputs.occupancy_view,
        })
    }

    fn pipelines(device: &Device, path: BinningPath) -> Result<MapPipelines, PassError> {
        let push = std::mem::size_of::<MapPush>() as u32;
        let buffers = |count| vec![BindingKind::StorageBuffer; count];
        Ok(MapPipelines {
            fit: device.create_compute_pipeline(
                "map fit",
                &shader("map_fit.comp")?,
                &[BindingKind::StorageBuffer, BindingKind::UniformBuffer],
                push,
            )?,
            receivers: device.create_compute_pipeline(
                "map receivers",
                &shader("map_receivers.comp")?,
                &[
                    BindingKind::UniformBuffer,
                    BindingKind::SampledImage,
                    BindingKind::SampledImage,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                ],
                push,
            )?,
            setup: device.create_compute_pipeline(
                "map setup",
                &shader("map_setup.comp")?,
                &buffers(5),
                push,
            )?,
            index: device.create_compute_pipeline(
                "map index",
                &shader("map_index.comp")?,
                &buffers(3),
                push,
            )?,
            scan: ScanPipeline::new(device)?,
            binner: match path {
                BinningPath::Compute => Binner::Compute(device.create_compute_pipeline(
                    "map bin",
                    &shader("map_bin.comp")?,
                    &buffers(10),
                    push,
                )?),
                raster => Binner::Raster(Self::raster_pipeline(device, raster)?),
            },
            pack: device.create_compute_pipeline(
                "map pack",
                &shader("map_pack.comp")?,
                &buffers(4),
                std::mem::size_of::<[u32; 2]>() as u32,
            )?,
            occupancy: device.create_compute_pipeline(
                "occupancy",
                &shader("occupancy.comp")?,
                &[
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageImage,
                    BindingKind::StorageBuffer,
                ],
                std::mem::size_of::<[u32; 2]>() as u32,
            )?,
        })
    }

    fn create_entries(
        device: &Device,
        config: &PrimitiveMapConfig,
        capacity: u32,
    ) -> Result<Buffer, PassError> {
        let guard = if config.guard { GUARD_WORDS } else { 0 };
        Ok(device.create_buffer(
            "primitive map list entries",
            (u64::from(capacity) + u64::from(guard)) * 4,
            BufferUsage::STORAGE | BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
            MemoryLocation::GpuOnly,
        )?)
    }

    fn raster_pipeline(device: &Device, path: BinningPath) -> Result<GraphicsPipeline, PassError> {
        let caps = device.capabilities();
        let (geometry, extra) = match path {
            BinningPath::Software => (Some(shader("prim_map_sw.geom")?), None),
            BinningPath::EmulatedTier1 { .. } => {
                let extra = (0.5 - caps.primitive_overestimation_size)
                    .clamp(0.0, caps.max_extra_primitive_overestimation_size);
                (Some(shader("prim_map_snap.geom")?), Some(extra))
            }
            _ => (None, Some(0.0)),
        };
        Ok(device.create_graphics_pipeline(&GraphicsPipelineDesc {
            name: "primitive map raster",
            vertex: &shader("prim_map.vert")?,
            geometry: geometry.as_deref(),
            fragment: &shader("prim_map_raster.frag")?,
            bindings: &[BindingKind::StorageBuffer; 5],
            push_constant_size: std::mem::size_of::<MapPush>() as u32,
            color_formats: &[],
            depth: None,
            conservative_extra_overestimation: extra,
            depth_clamp: false,
        })?)
    }

    /// The configuration.
    pub fn config(&self) -> &PrimitiveMapConfig {
        &self.config
    }

    /// The binning path in use.
    pub fn path(&self) -> BinningPath {
        self.path
    }

    /// Entries the lists can hold now.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Bytes the map holds on the GPU (the scratch it shares with the other maps over its geometry aside:
    /// see [`MapScratchPool::bytes`]).
    pub fn bytes(&self) -> u64 {
        [&self.state, &self.offsets, &self.entries]
            .iter()
            .map(|b| b.size())
            .sum::<u64>()
            + self
                .occupancy_view()
                .map_or(0, |v| v.byte_size() + self.receivers.size())
    }

    /// The occupancy view, when the map draws one.
    pub fn occupancy_view(&self) -> Option<&Image> {
        self.occupancy_view.then_some(&self.occupancy)
    }

    /// Sizes the entry capacity by what the lists occupy: grows it to hold `needed` entries (with a quarter
    /// to spare, within the budget) when a frame needed more than it had; shrinks it to half again what a
    /// frame needed (at least [`MIN_FITTED_ENTRIES`], and the entries the configuration starts with when
    /// it gives them) when that frame used under half of it, so that a
    /// light holds what its lists need rather than the starting estimate, and a changing view does not
    /// reallocate every frame. `needed` 0 (no completed frame, or one without receivers) changes nothing.
    /// The pair list is taken from `pool` for the new capacity and the prim buffer `prims` bound anew. When
    /// the entries were reallocated it returns the buffer and bindings they replaced (frames in flight may
    /// still use them: drop them once those completed), and whatever else reads [`PrimitiveMap::entries`]
    /// must be rebound.
    pub fn fit_entries(
        &mut self,
        device: &Device,
        pool: &MapScratchPool,
        prims: &Buffer,
        needed: u32,
    ) -> Result<Option<(Buffer, ScratchBindings)>, PassError> {
        let max = self.config.max_entries(device.capabilities());
        let capacity = if needed > self.capacity && self.capacity < max {
            (u64::from(needed) * 5 / 4).min(u64::from(max)) as u32
        } else if needed > 0 && u64::from(needed) * 2 < u64::from(self.capacity) {
            let floor = MIN_FITTED_ENTRIES.max(self.config.initial_entries);
            (u64::from(needed) * 3 / 2).max(u64::from(floor)) as u32
        } else {
            return Ok(None);
        };
        if capacity == self.capacity {
            return Ok(None);
        }
        let entries = Self::create_entries(device, &self.config, capacity)?;
        let old = std::mem::replace(&mut self.entries, entries);
        self.capacity = capacity;
        let bound = self.rebind(device, pool, prims, self.bound.scratch.clone())?;
        Ok(Some((old, bound)))
    }

    /// Binds `scratch` (and a pair list for the entry capacity) anew; returns the bindings replaced.
    fn rebind(
        &mut self,
        device: &Device,
        pool: &MapScratchPool,
        prims: &Buffer,
        scratch: std::sync::Arc<MapScratch>,
    ) -> Result<ScratchBindings, PassError> {
        let targets = BindTargets {
            prims,
            state: &self.state,
            receivers: &self.receivers,
            offsets: &self.offsets,
            entries: &self.entries,
            pool,
            entry_capacity: self.capacity,
        };
        let sizes = (self.config.texels(), self.bins);
        let bound = ScratchBindings::new(device, &self.pipes, scratch, &targets, sizes)?;
        Ok(std::mem::replace(&mut self.bound, bound))
    }

    /// Grows a cube map's (triangle, face) pairs to hold `needed` (with a quarter to spare, at most six per
    /// triangle), when a frame kept more than it held, taking larger scratch from `pool` and binding the
    /// prim buffer `prims` anew. Returns the bindings replaced (frames in flight may still use them: drop
    /// them once those completed).
    pub fn grow_pairs(
        &mut self,
        device: &Device,
        pool: &MapScratchPool,
        prims: &Buffer,
        needed: u32,
    ) -> Result<Option<ScratchBindings>, PassError> {
        let most = self.triangles.saturating_mul(6);
        if !self.config.cube || needed <= self.bins || self.bins >= most {
            return Ok(None);
        }
        let bins = (u64::from(needed) * 5 / 4).min(u64::from(most)) as u32;
        let scratch = pool.get(device, self.config.texels(), bins, bins)?;
        self.bins = bins;
        self.rebind(device, pool, prims, scratch).map(Some)
    }

    /// Records the build of the lists for this frame's receivers, through the light's `frusta`
    /// view-projections in frame coordinates (one, or a cube's six): the fit ([`FitPhase::ALL`]), then
    /// [`PrimitiveMap::record_lists`]. Depth and normal must be in `ShaderResource` state; the map's buffers
    /// are visible to storage reads afterwards.
    pub fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
        push: &MapPush,
        frusta: &[glam::Mat4],
    ) -> Result<(), PassError> {
        enc.begin_pass("primitive map: fit");
        let fitted: Result<(), PassError> = FitPhase::ALL.into_iter().try_for_each(|phase| {
            self.record_fit_phase(enc, phase, constants, push, frusta)?;
            enc.barriers(&[phase.barrier_after()]);
            Ok(())
        });
        enc.end_pass();
        fitted?;
        self.record_lists(enc)
    }

    /// Records one phase of the fit of the map's grid to this frame's receivers. The phases touch only the
    /// map's own buffers (never the scratch the maps over one geometry share), so several maps' phases may
    /// be recorded together, each phase of every map followed by one [`FitPhase::barrier_after`]. The frame's
    /// constants, push constants and frusta are read by [`FitPhase::Reset`], which must come first.
    pub fn record_fit_phase(
        &mut self,
        enc: &mut Encoder<'_>,
        phase: FitPhase,
        constants: &RayTraceConstants,
        push: &MapPush,
        frusta: &[glam::Mat4],
    ) -> Result<(), PassError> {
        match phase {
            FitPhase::Reset => self.record_fit_reset(enc, constants, push, frusta),
            FitPhase::Bounds => {
                let push = self.fit_push()?;
                self.dispatch_receivers(enc, &push, 0)
            }
            FitPhase::Grid => {
                let push = self.fit_push()?;
                enc.dispatch(
                    &self.pipes.fit,
                    &self.fit_group,
                    bytemuck::bytes_of(&push),
                    [1, 1, 1],
                )?;
                Ok(())
            }
        }
    }

    /// The push constants of the frame whose fit was reset.
    fn fit_push(&self) -> Result<MapPush, PassError> {
        self.last_push.ok_or_else(|| {
            PassError::InvalidConfig("the map's fit was not reset this frame".into())
        })
    }

    /// Writes the frame's constants and resets the map's state (and the guard over its entries).
    fn record_fit_reset(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
        push: &MapPush,
        frusta: &[glam::Mat4],
    ) -> Result<(), PassError> {
        if frusta.len() != self.config.frusta() as usize {
            return Err(PassError::InvalidConfig(format!(
                "the primitive map holds {} frusta, the light gave {}",
                self.config.frusta(),
                frusta.len()
            )));
        }
        let mut all = [frusta[0]; 6];
        all[..frusta.len()].copy_from_slice(frusta);
        let map_constants = MapConstants {
            ray: *constants,
            frusta: all,
        };
        let cube = self.config.cube;
        let push = MapPush {
            size: self.config.size,
            triangles: self.triangles,
            capacity: self.capacity,
            tile_threads: BIN_THREADS,
            guard: u32::from(self.config.guard),
            cull: u32::from(self.config.receiver_culling),
            faces: self.config.frusta(),
            pairs: if cube { self.bins } else { 0 },
            texels: self.config.texels() as u32,
            list_capacity: self.bound.pair_list.as_ref().map_or(0, |l| {
                (l.size() / PAIR_BYTES).min(u64::from(u32::MAX)) as u32
            }),
            list_limit: self
                .config
                .list_limit_for(push.penumbra > 0.0 || push.emitter_radius > 0.0),
            bin_budget: self.config.bin_budget,
            count_scale: self.config.debug_count_scale,
            ..*push
        };
        let reset: Vec<MapState> = (0..self.config.frusta() as usize)
            .map(|f| MapState::reset(f, push.capacity, push.pairs))
            .collect();
        // The state's last read was the previous build's copy into its read-back (a transfer).
        enc.barriers(&BEFORE_TRANSFER_WRITES);
        enc.update_buffer(&self.constants, 0, bytemuck::bytes_of(&map_constants))?;
        enc.update_buffer(&self.state, 0, bytemuck::cast_slice(&reset))?;
        if self.config.guard {
            enc.fill_buffer(&self.entries, GUARD_VALUE);
        }
        self.last_push = Some(push);
        Ok(())
    }

    /// Records the lists' build after the fit ([`PrimitiveMap::record_fit_phase`]): the receivers marked,
    /// the setup, the count, the scan and the fill, through the map's scratch (cleared first), each step
    /// followed by its barrier.
    pub fn record_lists(&mut self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        // The scratch's last use was the previous build's storage reads (or a read-back's copy).
        enc.barriers(&BEFORE_TRANSFER_WRITES);
        let mut open = false;
        for step in self.list_steps() {
            if let Some(name) = step.pass_name(self.path) {
                if open {
                    enc.end_pass();
                }
                enc.begin_pass(&name);
                open = true;
            }
            self.record_list_step(enc, step)?;
            enc.barriers(&[step.barrier_after()]);
        }
        if open {
            enc.end_pass();
        }
        Ok(())
    }

    /// The steps of [`PrimitiveMap::record_lists`], in order.
    pub fn list_steps(&self) -> Vec<ListStep> {
        let compute = matches!(self.pipes.binner, Binner::Compute(_));
        let mut steps = vec![ListStep::Clear, ListStep::Receivers, ListStep::Setup];
        steps.extend((0..self.bound.tile_scan.steps()).map(ListStep::TileScan));
        steps.extend(compute.then_some(ListStep::SearchIndex));
        steps.push(ListStep::Count);
        steps.extend((0..self.bound.offset_scan.steps()).map(ListStep::OffsetScan));
        steps.extend([ListStep::Pack(0), ListStep::Pack(1), ListStep::Fill]);
        steps
    }

    /// Records one step of the lists' build ([`PrimitiveMap::list_steps`]) without the barrier after it.
    /// The steps touch the map's own buffers and its scratch, so the steps of maps over different scratch
    /// sets may be interleaved, each round followed by the barriers of its steps
    /// ([`ListStep::barrier_after`]), the first preceded by [`PrimitiveMap::BEFORE_LISTS`].
    pub fn record_list_step(
        &mut self,
        enc: &mut Encoder<'_>,
        step: ListStep,
    ) -> Result<(), PassError> {
        let push = self.fit_push()?;
        let with_mode = |mode| MapPush { mode, ..push };
        match step {
            ListStep::Clear => {
                self.pixel_texels
                    .writer
                    .store(self.id, std::sync::atomic::Ordering::Relaxed);
                enc.fill_buffer(&self.receivers, 0);
                enc.fill_buffer(&self.bound.scratch.counts, 0);
                enc.fill_buffer(&self.bound.scratch.capped, 0);
            }
            ListStep::Receivers => self.dispatch_receivers(enc, &push, 1)?,
            ListStep::Setup => enc.dispatch(
                &self.pipes.setup,
                &self.bound.setup_group,
                bytemuck::bytes_of(&push),
                [(self.triangles + 1).div_ceil(64), 1, 1],
            )?,
            ListStep::TileScan(i) => {
                self.bound
                    .tile_scan
                    .record_step(enc, &self.pipes.scan, u32::MAX, i)?
            }
            ListStep::SearchIndex => enc.dispatch(
                &self.pipes.index,
                &self.bound.index_group,
                bytemuck::bytes_of(&push),
                [scratch::SEARCH_INDEX_WORDS.div_ceil(64) as u32, 1, 1],
            )?,
            ListStep::Count => self.record_bin(enc, &with_mode(0))?,
            ListStep::OffsetScan(i) => {
                self.bound
                    .offset_scan
                    .record_step(enc, &self.pipes.scan, push.list_limit, i)?
            }
            // The offsets and statistics, then the cursors of the lists not kept.
            ListStep::Pack(mode) => {
                let groups = self.config.texels().div_ceil(OFFSET_GROUP as u64) + 1;
                enc.dispatch(
                    &self.pipes.pack,
                    &self.bound.pack_group,
                    bytemuck::cast_slice(&[self.config.texels() as u32, mode]),
                    [groups.div_ceil(64) as u32, 1, 1],
                )?
            }
            ListStep::Fill => self.record_bin(enc, &with_mode(1))?,
        }
        Ok(())
    }

    /// The barriers before the first step of a lists' build: the scratch's last use was an earlier build's
    /// storage reads (or a read-back's copy).
    pub const BEFORE_LISTS: [Barrier<'static>; 2] = BEFORE_TRANSFER_WRITES;

    /// The buffer of the pixel texels the ray trace reads (one `u32` per screen pixel).
    pub fn pixel_texels(&self) -> &Buffer {
        &self.pixel_texels.buffer
    }

    /// Before a ray trace through this map: when another map over the same geometry recorded a write of
    /// the shared pixel texels since this map's build (an engine that records every light's map before
    /// every light's ray trace), rewrites this map's pixel texels exactly as its build wrote them (the
    /// receivers pass in its texels-only mode). Nothing otherwise, the usual case of lights recorded one
    /// after another.
    pub fn record_pixel_texels(&mut self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        let Some(push) = self.last_push else {
            return Ok(());
        };
        let writer = &self.pixel_texels.writer;
        if writer.load(std::sync::atomic::Ordering::Relaxed) == self.id {
            return Ok(());
        }
        writer.store(self.id, std::sync::atomic::Ordering::Relaxed);
        enc.begin_pass("primitive map: pixel texels");
        enc.barriers(&[Barrier::Uav]);
        self.dispatch_receivers(enc, &push, 2)?;
        enc.barriers(&[Barrier::Uav]);
        enc.end_pass();
        Ok(())
    }

    /// Records the receivers pass over the screen in `mode` (0: bounds, 1: mark, 2: pixel texels alone).
    fn dispatch_receivers(
        &self,
        enc: &mut Encoder<'_>,
        push: &MapPush,
        mode: u32,
    ) -> Result<(), PassError> {
        // Each invocation places a 2x2 quad; a workgroup covers 16x16 pixels.
        enc.dispatch(
            &self.pipes.receivers,
            &self.receivers_group,
            bytemuck::bytes_of(&MapPush { mode, ..*push }),
            [self.screen.0.div_ceil(16), self.screen.1.div_ceil(16), 1],
        )?;
        Ok(())
    }

    fn record_bin(&self, enc: &mut Encoder<'_>, push: &MapPush) -> Result<(), PassError> {
        match &self.pipes.binner {
            Binner::Compute(p) => {
                enc.dispatch(
                    p,
                    &self.bound.bin_group,
                    bytemuck::bytes_of(push),
                    [BIN_THREADS / 64, 1, 1],
                )?;
            }
            Binner::Raster(p) => {
                enc.begin_rendering((self.config.size, self.config.size), &[], None);
                enc.draw(
                    p,
                    &self.bound.bin_group,
                    bytemuck::bytes_of(push),
                    self.triangles * 3,
                )?;
                enc.end_rendering();
            }
        }
        Ok(())
    }

    /// Draws the occupancy view when the map has one.
    pub fn record_occupancy(&self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        let Some(view) = self.occupancy_view() else {
            return Ok(());
        };
        enc.begin_pass("occupancy");
        enc.barriers(&[Barrier::Image {
            image: view,
            before: S::Undefined,
            after: S::UnorderedAccess,
        }]);
        let n = self.config.size;
        let push = [n, self.config.texels() as u32];
        // Each invocation draws a 2x2 quad of the first N rows of texels.
        enc.dispatch(
            &self.pipes.occupancy,
            &self.occupancy_group,
            bytemuck::cast_slice(&push),
            [n.div_ceil(16), n.div_ceil(16), 1],
        )?;
        enc.end_pass();
        Ok(())
    }

    /// Copies the state, with the statistics the build tallied and the walks the ray trace counted, into
    /// `state_readback` (host-readable once the frame completed; as large as the state).
    pub fn record_state_readback(
        &self,
        enc: &mut Encoder<'_>,
        state_readback: &Buffer,
    ) -> Result<(), PassError> {
        enc.barriers(&[Barrier::Global {
            before: S::UnorderedAccess,
            after: S::CopySource,
        }]);
        enc.copy_buffer(&self.state, state_readback)?;
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        Ok(())
    }
}
