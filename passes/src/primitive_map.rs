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
//!    counted per texel, the counts are prefix-summed into list offsets, and the lists are filled. Memory
//!    is proportional to the entries; nothing is ever dropped. Texels whose list would pass the entry
//!    capacity are traced exhaustively (exact, slower), reported, and the capacity grows for the next frame
//!    within the memory budget.
//!
//! The count and fill run in a compute shader (load-balanced over tiles) or, for the tier-fallback paths,
//! through the rasterizer: hardware conservative raster at the device's tier, the geometry-shader software
//! path, or tier-1 emulation. Every path applies the same exact test and builds the same lists.
//!
//! Reads: prim buffer, depth, normal. Writes: receiver map, per-pixel texels, list offsets, list entries,
//! map state (fit, statistics); occupancy image (occupancy pass).

use crate::gpu_types::{constant_buffer, MapConstants, MapPush, MapState, RayTraceConstants};
use crate::scan::{PrefixScan, ScanPipeline};
use crate::{shader, PassError};
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, BufferUsage, Capabilities, ComputePipeline,
    ConservativeRasterTier, Device, Encoder, Format, GraphicsPipeline, GraphicsPipelineDesc, Image,
    ImageDesc, ImageUsage, MemoryLocation, Resource, ResourceState as S,
};

/// Which faces of the scene are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FaceMode {
    /// Both faces: correct for open geometry (planes, cards, plates). The default.
    #[default]
    Both,
    /// Only faces whose counter-clockwise normal points towards the light: half the entries, correct for
    /// closed meshes only (a shadow ray leaving a closed blocker crosses a light-facing face). Visibility
    /// is unchanged; the blocker distance is measured to the blocker's far (light-facing) side, longer
    /// than the true distance by the blocker's thickness along the ray.
    FrontOnly,
}

/// How the caller wants the (triangle, texel) pairs found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BinningRequest {
    /// The compute path: fastest on every device measured (an NVIDIA H100 and lavapipe).
    #[default]
    Auto,
    /// Force the compute path.
    Compute,
    /// Hardware conservative raster (fails without `VK_EXT_conservative_rasterization`).
    Hardware,
    /// The geometry-shader software conservative raster.
    Software,
    /// Hardware conservative raster made to behave like D3D12 Tier 1 (1/2 px uncertainty, post-snap
    /// degenerate triangles culled) on a device with a better tier: for tier-fallback tests.
    EmulateTier1,
}

/// The binning path in use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinningPath {
    /// Compute-shader binning over 4×4-texel tiles of each triangle's bounding box.
    Compute,
    /// `VK_EXT_conservative_rasterization` overestimation at the device's tier.
    Hardware(ConservativeRasterTier),
    /// Geometry-shader dilation + exact per-texel overlap test (GPU Gems 2, ch. 42).
    Software,
    /// Hardware conservative raster on a device of tier `native`, emulating Tier 1.
    EmulatedTier1 {
        /// The device's own tier.
        native: ConservativeRasterTier,
    },
}

impl BinningPath {
    /// "compute", "hardware", "software" or "hardware (tier-1 emulation)".
    pub fn name(self) -> &'static str {
        match self {
            Self::Compute => "compute",
            Self::Hardware(_) => "hardware",
            Self::Software => "software",
            Self::EmulatedTier1 { .. } => "hardware (tier-1 emulation)",
        }
    }

    /// Short label of the path in pass names: "compute", "HW CR", "SW CR", "HW CR tier-1".
    pub fn label(self) -> &'static str {
        match self {
            Self::Compute => "compute",
            Self::Hardware(_) => "HW CR",
            Self::Software => "SW CR",
            Self::EmulatedTier1 { .. } => "HW CR tier-1",
        }
    }

    /// The conservative-raster tier used ("none" for the software and compute paths).
    pub fn tier(self) -> ConservativeRasterTier {
        match self {
            Self::Hardware(t) => t,
            Self::Compute | Self::Software => ConservativeRasterTier::NotSupported,
            Self::EmulatedTier1 { .. } => ConservativeRasterTier::Tier1,
        }
    }
}

/// Chooses the binning path from the device's capabilities (pure; unit-tested).
pub fn choose_binning_path(
    caps: &Capabilities,
    request: BinningRequest,
) -> Result<BinningPath, PassError> {
    if !caps.compute_subgroup_arithmetic {
        return Err(PassError::Unsupported(
            "subgroup arithmetic in compute shaders (the primitive map's reductions and prefix scan)"
                .into(),
        ));
    }
    let hw = caps.conservative_raster_tier;
    let gs = caps.geometry_shader;
    let fragment_atomics = caps.fragment_stores_and_atomics;
    let raster = |path| {
        if fragment_atomics {
            Ok(path)
        } else {
            Err(PassError::Unsupported(
                "fragmentStoresAndAtomics (raster binning writes from fragment shaders)".into(),
            ))
        }
    };
    match request {
        BinningRequest::Auto | BinningRequest::Compute => Ok(BinningPath::Compute),
        BinningRequest::Hardware if hw == ConservativeRasterTier::NotSupported => {
            Err(PassError::Unsupported(
                "hardware conservative rasterization (VK_EXT_conservative_rasterization)".into(),
            ))
        }
        BinningRequest::Hardware => raster(BinningPath::Hardware(hw)),
        BinningRequest::Software if !gs => Err(PassError::Unsupported(
            "geometry shaders (software conservative rasterization)".into(),
        )),
        BinningRequest::Software => raster(BinningPath::Software),
        BinningRequest::EmulateTier1 if hw == ConservativeRasterTier::NotSupported || !gs => {
            Err(PassError::Unsupported(
                "tier-1 emulation needs hardware conservative rasterization and geometry shaders"
                    .into(),
            ))
        }
        BinningRequest::EmulateTier1 => raster(BinningPath::EmulatedTier1 { native: hw }),
    }
}

/// Size and behaviour of the primitive map. No setting trades exactness: every one only moves cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PrimitiveMapConfig {
    /// N: texels per side of the light-space grid fitted to the receivers (default 1024).
    pub size: u32,
    /// Faces stored.
    pub faces: FaceMode,
    /// Binning path request.
    pub binning: BinningRequest,
    /// Largest memory the list entries may take, in bytes (default 256 MiB, capped by the device's largest
    /// storage buffer). The entries start small and grow to what frames need; past the budget, texels
    /// that do not fit are traced exhaustively (exact) and counted in the report.
    pub entry_budget: u64,
    /// Entries the lists start with (0: estimated from the grid and the triangles). An engine that knows
    /// its scene can size them up front and avoid the one exhaustive frame of a growth.
    pub initial_entries: u32,
    /// Bin only into texels holding ray origins, and skip triangles wholly behind all of a texel's origins
    /// (default true). Off, every texel of the fitted grid gets every triangle overlapping it: a debug mode
    /// whose lists tests compare with exact conservative binning.
    pub receiver_culling: bool,
    /// Debug: `GUARD_WORDS` words after the entry capacity, filled with `GUARD_VALUE` every frame, that no
    /// pass may write: tests read them back to prove the fill never writes out of bounds.
    pub guard: bool,
    /// A point light's map: its six cube faces built together, their grids sharing N² texels (plus a
    /// minimum grid each) in proportion to the rays each face holds, with one setup, count, scan, fill and
    /// ray trace for the whole light. Needs compute binning.
    pub cube: bool,
    /// (Triangle, face) pairs a cube map starts with (0: two per triangle, at least 1024). A frame that
    /// keeps more traces the light's rays exhaustively (exact, slower, reported) and the pairs grow for the
    /// next, up to six per triangle.
    pub initial_pairs: u32,
}

/// Value of every guard word (never a valid prim-buffer index).
pub const GUARD_VALUE: u32 = u32::MAX;

/// Guard words after the entries in guard mode.
pub const GUARD_WORDS: u32 = 4096;

/// Default [`PrimitiveMapConfig::entry_budget`].
pub const DEFAULT_ENTRY_BUDGET: u64 = 256 << 20;

/// Smallest [`PrimitiveMapConfig::entry_budget`]: 1024 entries.
pub const MIN_ENTRY_BUDGET: u64 = 4096;

/// Threads of the compute binning dispatch (a grid-stride loop over the bin items).
const BIN_THREADS: u32 = 64 * 4096;

/// Smallest grid side a frustum with receivers gets (`map_fit.comp`).
const MIN_GRID: u32 = 16;

/// Bytes of one bin triangle (`BinTri` in `map_bin.glsl`).
const BIN_TRI_BYTES: u64 = 64;

impl Default for PrimitiveMapConfig {
    fn default() -> Self {
        Self {
            size: 1024,
            faces: FaceMode::Both,
            binning: BinningRequest::Auto,
            entry_budget: DEFAULT_ENTRY_BUDGET,
            initial_entries: 0,
            receiver_culling: true,
            guard: false,
            cube: false,
            initial_pairs: 0,
        }
    }
}

impl PrimitiveMapConfig {
    /// Checks the configuration against the device limits.
    pub fn validate(&self, caps: &Capabilities) -> Result<(), PassError> {
        let max = caps.max_image_dimension_2d.min(u32::from(u16::MAX));
        if self.size == 0 || self.size > max {
            return Err(PassError::InvalidConfig(format!(
                "primitive map size {} must be in 1..={max}",
                self.size
            )));
        }
        let grid = u64::from(self.size) * u64::from(self.size) * 4 + 4;
        if grid > caps.max_storage_buffer_range {
            return Err(PassError::InvalidConfig(format!(
                "primitive map size {}: its {} bytes of list offsets exceed the device's largest storage \
                 buffer ({} bytes)",
                self.size, grid, caps.max_storage_buffer_range
            )));
        }
        if self.cube && !matches!(self.binning, BinningRequest::Auto | BinningRequest::Compute) {
            return Err(PassError::InvalidConfig(
                "a point light's cube map is binned in compute: request auto or compute binning"
                    .into(),
            ));
        }
        if self.cube && self.faces == FaceMode::FrontOnly {
            return Err(PassError::InvalidConfig(
                "a front-only primitive map needs a directional light, not a point light's cube"
                    .into(),
            ));
        }
        if self.entry_budget < MIN_ENTRY_BUDGET {
            return Err(PassError::InvalidConfig(format!(
                "primitive map entry budget {} bytes is below the minimum of {MIN_ENTRY_BUDGET} bytes",
                self.entry_budget
            )));
        }
        Ok(())
    }

    /// Frusta the map holds: 6 for a point light's cube, else 1.
    pub fn frusta(&self) -> u32 {
        if self.cube {
            6
        } else {
            1
        }
    }

    /// Texels of the map's grids together: N², and for a cube the minimum grid of each face besides.
    pub fn texels(&self) -> u64 {
        let n2 = u64::from(self.size) * u64::from(self.size);
        if self.cube {
            let min_grid = u64::from(MIN_GRID.min(self.size)) + 1;
            n2 + 6 * min_grid * min_grid
        } else {
            n2
        }
    }

    /// Bin triangles a map over `triangles` triangles starts with: one per triangle, or for a cube
    /// [`PrimitiveMapConfig::initial_pairs`] (it grows to what frames keep).
    pub fn starting_pairs(&self, triangles: u32) -> u32 {
        match (self.cube, self.initial_pairs) {
            (false, _) => triangles,
            (true, 0) => triangles.saturating_mul(2).max(1024),
            (true, given) => given,
        }
    }

    /// Most entries the budget and the device allow.
    pub fn max_entries(&self, caps: &Capabilities) -> u32 {
        let guard = if self.guard {
            u64::from(GUARD_WORDS)
        } else {
            0
        };
        let bytes = self.entry_budget.min(caps.max_storage_buffer_range);
        (bytes / 4)
            .saturating_sub(guard)
            .min(u64::from(u32::MAX - GUARD_WORDS)) as u32
    }

    /// The entry capacity a map starts with for `triangles`: [`PrimitiveMapConfig::initial_entries`], else
    /// two entries per texel (a ground plane under everything) plus four per triangle; within the budget.
    pub fn starting_entries(&self, caps: &Capabilities, triangles: u32) -> u32 {
        let n2 = u64::from(self.size) * u64::from(self.size);
        let estimate = match self.initial_entries {
            0 => (2 * n2 + 4 * u64::from(triangles)).max(65536),
            given => u64::from(given),
        };
        estimate.min(u64::from(self.max_entries(caps))).max(1) as u32
    }
}

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
    /// Whether the occupancy pass draws the N×N occupancy view, besides the statistics it always
    /// gathers.
    pub occupancy_view: bool,
    /// Where the map takes its build scratch from (one pool per geometry).
    pub scratch: &'a MapScratchPool,
}

/// A GPU-only storage buffer of `bytes` (at least 4) with `usage` besides storage.
fn storage_buffer(
    device: &Device,
    name: &str,
    bytes: u64,
    usage: BufferUsage,
) -> Result<Buffer, rhi::RhiError> {
    device.create_buffer(
        name,
        bytes.max(4),
        BufferUsage::STORAGE | usage,
        MemoryLocation::GpuOnly,
    )
}

/// The buffers a map uses only while it is built (bin triangles, their tile offsets and owners, per-texel
/// counts), shared by every map over the same geometry: the builds are recorded one after another with
/// barriers between them (each clears the counts first), so one set serves every light and frustum.
pub struct MapScratch {
    bin_tris: Buffer,
    tile_offsets: Buffer,
    pair_owners: Buffer,
    counts: Buffer,
    /// The texels the counts hold.
    texels: u64,
    /// The bin triangles the buffers hold.
    bins: u32,
    /// The (triangle, face) owners held (0 until a point light's map asked for some).
    owners: u32,
}

impl MapScratch {
    /// GPU bytes of the scratch.
    pub fn bytes(&self) -> u64 {
        [
            &self.bin_tris,
            &self.tile_offsets,
            &self.pair_owners,
            &self.counts,
        ]
        .iter()
        .map(|b| b.size())
        .sum()
    }
}

/// The scratch shared by the maps over one geometry: it grows to the largest map asked for; a map keeps
/// the scratch it was created with until it needs a larger one (the pool's newer, larger one serves the
/// maps created or grown after).
#[derive(Default)]
pub struct MapScratchPool {
    current: std::sync::Mutex<Option<std::sync::Arc<MapScratch>>>,
    /// The receiver map (one `u32` per texel) shared by the maps that draw no occupancy view.
    receivers: std::sync::Mutex<Option<std::sync::Arc<Buffer>>>,
    /// The pixel texels (one `u32` per screen pixel) shared by the maps, with the id of the map that last
    /// recorded a write of them.
    pixel_texels: std::sync::Mutex<Option<SharedTexels>>,
}

/// Screen-size pixel texels shared by the maps over one geometry, and which map last recorded their write.
#[derive(Clone)]
pub struct SharedTexels {
    buffer: std::sync::Arc<Buffer>,
    writer: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

/// Source of [`PrimitiveMap`] ids (0 marks pixel texels no map wrote yet).
static NEXT_MAP_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

/// The value in `slot` if `fits` accepts it, else `make`'s from the value there (if any), which then
/// takes the slot.
fn shared_in<T: Clone>(
    slot: &std::sync::Mutex<Option<T>>,
    fits: impl Fn(&T) -> bool,
    make: impl FnOnce(Option<&T>) -> Result<T, PassError>,
) -> Result<T, PassError> {
    let mut current = slot
        .lock()
        .map_err(|_| PassError::InvalidConfig("map scratch pool poisoned".into()))?;
    if let Some(value) = current.as_ref().filter(|v| fits(v)) {
        return Ok(value.clone());
    }
    let value = make(current.as_ref())?;
    *current = Some(value.clone());
    Ok(value)
}

/// `bytes` of the value in `slot` (0 when empty).
fn bytes_in<T>(slot: &std::sync::Mutex<Option<T>>, bytes: impl Fn(&T) -> u64) -> u64 {
    slot.lock()
        .ok()
        .and_then(|v| v.as_ref().map(&bytes))
        .unwrap_or(0)
}

impl MapScratchPool {
    /// Scratch with counts for `texels` texels, `bins` bin triangles and `owners` (triangle, face) owners:
    /// the pool's, or a new one as large as the largest asked for so far.
    pub fn get(
        &self,
        device: &Device,
        texels: u64,
        bins: u32,
        owners: u32,
    ) -> Result<std::sync::Arc<MapScratch>, PassError> {
        let fits = |s: &std::sync::Arc<MapScratch>| {
            s.texels >= texels && s.bins >= bins && s.owners >= owners
        };
        shared_in(&self.current, fits, |old| {
            let (texels, bins, owners) = old.map_or((texels, bins, owners), |s| {
                (s.texels.max(texels), s.bins.max(bins), s.owners.max(owners))
            });
            let storage = |name, bytes, usage| storage_buffer(device, name, bytes, usage);
            Ok(std::sync::Arc::new(MapScratch {
                bin_tris: storage(
                    "primitive map bin triangles",
                    u64::from(bins) * BIN_TRI_BYTES,
                    BufferUsage::default(),
                )?,
                tile_offsets: storage(
                    "primitive map tile offsets",
                    (u64::from(bins) + 1) * 4,
                    BufferUsage::default(),
                )?,
                pair_owners: storage(
                    "primitive map pair owners",
                    u64::from(owners) * 4,
                    BufferUsage::default(),
                )?,
                counts: storage(
                    "primitive map counts",
                    (texels + 1) * 4,
                    BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                )?,
                texels,
                bins,
                owners,
            }))
        })
    }

    /// A receiver map of at least `texels` texels: the pool's, or a new one as large.
    pub fn receivers(
        &self,
        device: &Device,
        texels: u64,
    ) -> Result<std::sync::Arc<Buffer>, PassError> {
        shared_in(
            &self.receivers,
            |r| r.size() >= texels * 4,
            |_| {
                Ok(std::sync::Arc::new(storage_buffer(
                    device,
                    "primitive map receivers",
                    texels * 4,
                    BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                )?))
            },
        )
    }

    /// Pixel texels for `pixels` pixels: the pool's, or new ones as large.
    fn pixel_texels(&self, device: &Device, pixels: u64) -> Result<SharedTexels, PassError> {
        shared_in(
            &self.pixel_texels,
            |t| t.buffer.size() >= pixels * 4,
            |_| {
                Ok(SharedTexels {
                    buffer: std::sync::Arc::new(storage_buffer(
                        device,
                        "primitive map pixel texels",
                        pixels * 4,
                        BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
                    )?),
                    writer: std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0)),
                })
            },
        )
    }

    /// GPU bytes of the pool's current scratch, receiver map and pixel texels (0 before any map asked for
    /// them).
    pub fn bytes(&self) -> u64 {
        bytes_in(&self.current, |s| s.bytes())
            + bytes_in(&self.receivers, |r| r.size())
            + bytes_in(&self.pixel_texels, |t| t.buffer.size())
    }
}

/// What a map binds of its scratch: replaced together when a point light's map outgrows its pairs.
pub struct ScratchBindings {
    scratch: std::sync::Arc<MapScratch>,
    setup_group: BindGroup,
    bin_group: BindGroup,
    tile_scan: PrefixScan,
    offset_scan: PrefixScan,
}

/// The binning pipelines of the path in use.
enum Binner {
    Compute(ComputePipeline),
    Raster(GraphicsPipeline),
}

/// The map's pipelines.
struct MapPipelines {
    fit: ComputePipeline,
    receivers: ComputePipeline,
    setup: ComputePipeline,
    scan: ScanPipeline,
    binner: Binner,
    occupancy: ComputePipeline,
}

/// The buffers the scratch bindings pair with the scratch.
struct BindTargets<'a> {
    prims: &'a Buffer,
    state: &'a Buffer,
    receivers: &'a Buffer,
    offsets: &'a Buffer,
    entries: &'a Buffer,
}

impl ScratchBindings {
    /// Binds `scratch` for a map of `texels` texels and `bins` bin triangles.
    fn new(
        device: &Device,
        pipes: &MapPipelines,
        scratch: std::sync::Arc<MapScratch>,
        t: &BindTargets<'_>,
        (texels, bins): (u64, u32),
    ) -> Result<Self, PassError> {
        let b = Resource::Buffer;
        let s = &*scratch;
        let setup_group = device.create_bind_group(
            pipes.setup.layout(),
            &[
                b(t.prims),
                b(t.state),
                b(&s.bin_tris),
                b(&s.tile_offsets),
                b(&s.pair_owners),
            ],
        )?;
        let bin_group = match &pipes.binner {
            Binner::Compute(p) => device.create_bind_group(
                p.layout(),
                &[
                    b(&s.bin_tris),
                    b(&s.tile_offsets),
                    b(t.receivers),
                    b(&s.counts),
                    b(t.offsets),
                    b(t.entries),
                    b(t.state),
                    b(&s.pair_owners),
                ],
            )?,
            Binner::Raster(p) => device.create_bind_group(
                p.layout(),
                &[
                    b(&s.bin_tris),
                    b(t.receivers),
                    b(&s.counts),
                    b(t.offsets),
                    b(t.entries),
                ],
            )?,
        };
        let tile_scan = PrefixScan::new(
            device,
            &pipes.scan,
            &s.tile_offsets,
            &s.tile_offsets,
            bins + 1,
        )?;
        let offset_scan = PrefixScan::new(
            device,
            &pipes.scan,
            &s.counts,
            t.offsets,
            (texels + 1) as u32,
        )?;
        Ok(Self {
            scratch,
            setup_group,
            bin_group,
            tile_scan,
            offset_scan,
        })
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
    /// largest depth key of the texel's origins. Shared by the maps over the same geometry (the pool's),
    /// unless the map draws an occupancy view, which reads it after the build.
    receivers: std::sync::Arc<Buffer>,
    /// One `u32` per screen pixel: the texel of its ray origin (or a no-ray / outside marker). Shared by
    /// the maps over the same geometry (the pool's): see [`PrimitiveMap::record_pixel_texels`].
    pixel_texels: SharedTexels,
    /// This map's mark in the pixel texels' record of their last writer.
    id: u64,
    /// The push constants of the last build recorded (its pixel texels are rewritten from them).
    last_push: Option<MapPush>,
    /// One `u32` per texel, plus one: texel t's list is `entries[offsets[t] .. offsets[t + 1]]`.
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
            std::sync::Arc::new(storage("primitive map receivers", texels * 4, copy)?)
        } else {
            inputs.scratch.receivers(device, texels)?
        };
        let pixel_texels = inputs
            .scratch
            .pixel_texels(device, u64::from(width) * u64::from(height))?;
        let offsets = storage("primitive map list offsets", (texels + 1) * 4, copy)?;
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
            scan: ScanPipeline::new(device)?,
            binner: match path {
                BinningPath::Compute => Binner::Compute(device.create_compute_pipeline(
                    "map bin",
                    &shader("map_bin.comp")?,
                    &buffers(8),
                    push,
                )?),
                raster => Binner::Raster(Self::raster_pipeline(device, raster)?),
            },
            occupancy: device.create_compute_pipeline(
                "occupancy",
                &shader("occupancy.comp")?,
                &[
                    BindingKind::StorageBuffer,
                    BindingKind::StorageBuffer,
                    BindingKind::StorageImage,
                    BindingKind::StorageBuffer,
                ],
                std::mem::size_of::<[u32; 3]>() as u32,
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

    /// The occupancy pass's image (1×1 and never written without the view), for its barriers.
    pub fn occupancy_target(&self) -> &Image {
        &self.occupancy
    }

    /// Grows the entry capacity to hold `needed` entries (with a quarter to spare, within the budget), when a
    /// frame needed more than it had. When the entries were reallocated it returns the buffer and bind group
    /// they replaced (frames in flight may still use them: drop them once those completed), and whatever
    /// else reads [`PrimitiveMap::entries`] must be rebound.
    pub fn grow(
        &mut self,
        device: &Device,
        needed: u32,
    ) -> Result<Option<(Buffer, BindGroup)>, PassError> {
        let max = self.config.max_entries(device.capabilities());
        if needed <= self.capacity || self.capacity >= max {
            return Ok(None);
        }
        let capacity = (u64::from(needed) * 5 / 4).min(u64::from(max)) as u32;
        let entries = Self::create_entries(device, &self.config, capacity)?;
        let (layout, binding) = match &self.pipes.binner {
            Binner::Compute(p) => (p.layout(), 5),
            Binner::Raster(p) => (p.layout(), 4),
        };
        let group = device.rebound(layout, &self.bound.bin_group, binding, &entries)?;
        self.capacity = capacity;
        Ok(Some((
            std::mem::replace(&mut self.entries, entries),
            std::mem::replace(&mut self.bound.bin_group, group),
        )))
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
        let texels = self.config.texels();
        let scratch = pool.get(device, texels, bins, bins)?;
        let targets = BindTargets {
            prims,
            state: &self.state,
            receivers: &self.receivers,
            offsets: &self.offsets,
            entries: &self.entries,
        };
        let bound = ScratchBindings::new(device, &self.pipes, scratch, &targets, (texels, bins))?;
        self.bins = bins;
        Ok(Some(std::mem::replace(&mut self.bound, bound)))
    }

    /// Records the build of the lists for this frame's receivers, through the light's `frusta`
    /// view-projections in frame coordinates (one, or a cube's six). Depth and normal must be in
    /// `ShaderResource` state; the map's buffers are visible to storage reads afterwards.
    pub fn record(
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
        enc.update_buffer(&self.constants, 0, bytemuck::bytes_of(&map_constants))?;
        let n = self.config.size;
        let cube = self.config.cube;
        let push = MapPush {
            size: n,
            triangles: self.triangles,
            capacity: self.capacity,
            tile_threads: BIN_THREADS,
            guard: u32::from(self.config.guard),
            cull: u32::from(self.config.receiver_culling),
            faces: self.config.frusta(),
            pairs: if cube { self.bins } else { 0 },
            texels: self.config.texels() as u32,
            ..*push
        };
        let with_mode = |mode| MapPush { mode, ..push };
        // Each invocation of the receiver pass places a 2x2 quad; a workgroup covers 16x16 pixels.
        let pixels = [self.screen.0.div_ceil(16), self.screen.1.div_ceil(16), 1];

        enc.begin_pass("primitive map: fit");
        enc.barriers(&[Barrier::Global {
            before: S::UnorderedAccess,
            after: S::CopyDest,
        }]);
        enc.fill_buffer(&self.receivers, 0);
        enc.fill_buffer(&self.bound.scratch.counts, 0);
        if self.config.guard {
            enc.fill_buffer(&self.entries, GUARD_VALUE);
        }
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::UnorderedAccess,
        }]);
        let fit = |enc: &mut Encoder<'_>, mode| {
            enc.dispatch(
                &self.pipes.fit,
                &self.fit_group,
                bytemuck::bytes_of(&with_mode(mode)),
                [1, 1, 1],
            )
        };
        fit(enc, 0)?;
        enc.barriers(&[Barrier::Uav]);
        enc.dispatch(
            &self.pipes.receivers,
            &self.receivers_group,
            bytemuck::bytes_of(&with_mode(0)),
            pixels,
        )?;
        enc.barriers(&[Barrier::Uav]);
        fit(enc, 1)?;
        enc.barriers(&[Barrier::Uav]);
        enc.end_pass();

        self.last_push = Some(push);
        self.pixel_texels
            .writer
            .store(self.id, std::sync::atomic::Ordering::Relaxed);
        enc.begin_pass("primitive map: receivers");
        enc.dispatch(
            &self.pipes.receivers,
            &self.receivers_group,
            bytemuck::bytes_of(&with_mode(1)),
            pixels,
        )?;
        enc.barriers(&[Barrier::Uav]);
        enc.end_pass();

        enc.begin_pass("primitive map: setup");
        enc.dispatch(
            &self.pipes.setup,
            &self.bound.setup_group,
            bytemuck::bytes_of(&push),
            [(self.triangles + 1).div_ceil(64), 1, 1],
        )?;
        enc.barriers(&[Barrier::Uav]);
        self.bound.tile_scan.record(enc, &self.pipes.scan)?;
        enc.end_pass();

        let label = self.path.label();
        enc.begin_pass(&format!("primitive map: count ({label})"));
        self.record_bin(enc, &with_mode(0))?;
        enc.end_pass();

        enc.begin_pass("primitive map: scan");
        self.bound.offset_scan.record(enc, &self.pipes.scan)?;
        enc.end_pass();

        enc.begin_pass(&format!("primitive map: fill ({label})"));
        self.record_bin(enc, &with_mode(1))?;
        enc.end_pass();
        Ok(())
    }

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
        enc.dispatch(
            &self.pipes.receivers,
            &self.receivers_group,
            bytemuck::bytes_of(&MapPush { mode: 2, ..push }),
            [self.screen.0.div_ceil(16), self.screen.1.div_ceil(16), 1],
        )?;
        enc.barriers(&[Barrier::Uav]);
        enc.end_pass();
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
        enc.barriers(&[Barrier::Uav]);
        Ok(())
    }

    /// Writes the map statistics into the state, and the occupancy view when the map draws one, and copies
    /// the state into `state_readback` (host-readable once the frame completed; as large as the state).
    pub fn record_occupancy(
        &self,
        enc: &mut Encoder<'_>,
        state_readback: &Buffer,
    ) -> Result<(), PassError> {
        enc.begin_pass("occupancy");
        enc.barriers(&[Barrier::Image {
            image: &self.occupancy,
            before: S::Undefined,
            after: S::UnorderedAccess,
        }]);
        let n = self.config.size;
        let texels = self.config.texels();
        let push = [n, u32::from(self.occupancy_view), texels as u32];
        // Each invocation tallies a 2x2 quad of texels, in rows of N.
        let rows = texels.div_ceil(u64::from(n)) as u32;
        enc.dispatch(
            &self.pipes.occupancy,
            &self.occupancy_group,
            bytemuck::cast_slice(&push),
            [n.div_ceil(16), rows.div_ceil(16), 1],
        )?;
        enc.barriers(&[Barrier::Global {
            before: S::UnorderedAccess,
            after: S::CopySource,
        }]);
        enc.copy_buffer(&self.state, state_readback)?;
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        enc.end_pass();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn caps(tier: ConservativeRasterTier, gs: bool) -> Capabilities {
        Capabilities {
            device_name: "test".into(),
            driver: "test".into(),
            api_version: "1.3.0".into(),
            device_type: "CPU".into(),
            conservative_raster_tier: tier,
            primitive_overestimation_size: 0.0,
            max_extra_primitive_overestimation_size: 0.0,
            geometry_shader: gs,
            fragment_stores_and_atomics: true,
            depth_clamp: true,
            shader_float64: false,
            fragment_shader_interlock: false,
            ray_query: false,
            ray_tracing_pipeline: false,
            timestamps: true,
            timestamp_period_ns: 1.0,
            max_storage_buffer_range: 1 << 27,
            max_image_dimension_2d: 16384,
            max_image_array_layers: 2048,
            max_compute_work_group_count: [65535; 3],
            compute_subgroup_arithmetic: true,
        }
    }

    #[test]
    fn every_path_needs_subgroup_arithmetic() {
        let none = Capabilities {
            compute_subgroup_arithmetic: false,
            ..caps(ConservativeRasterTier::Tier3, true)
        };
        for request in [
            BinningRequest::Auto,
            BinningRequest::Compute,
            BinningRequest::Hardware,
            BinningRequest::Software,
            BinningRequest::EmulateTier1,
        ] {
            assert!(matches!(
                choose_binning_path(&none, request),
                Err(PassError::Unsupported(what)) if what.contains("subgroup")
            ));
        }
    }

    #[test]
    fn auto_is_compute_everywhere() {
        for tier in [
            ConservativeRasterTier::Tier3,
            ConservativeRasterTier::NotSupported,
        ] {
            for gs in [true, false] {
                assert_eq!(
                    choose_binning_path(&caps(tier, gs), BinningRequest::Auto).unwrap(),
                    BinningPath::Compute
                );
            }
        }
    }

    #[test]
    fn forced_paths_fail_clearly_without_the_feature() {
        let lavapipe = caps(ConservativeRasterTier::NotSupported, true);
        assert!(matches!(
            choose_binning_path(&lavapipe, BinningRequest::Hardware),
            Err(PassError::Unsupported(_))
        ));
        let no_gs = caps(ConservativeRasterTier::Tier1, false);
        assert!(matches!(
            choose_binning_path(&no_gs, BinningRequest::Software),
            Err(PassError::Unsupported(_))
        ));
        let t1 = caps(ConservativeRasterTier::Tier1, true);
        assert_eq!(
            choose_binning_path(&t1, BinningRequest::Software).unwrap(),
            BinningPath::Software
        );
        assert_eq!(
            choose_binning_path(&t1, BinningRequest::Hardware).unwrap(),
            BinningPath::Hardware(ConservativeRasterTier::Tier1)
        );
        let no_atomics = Capabilities {
            fragment_stores_and_atomics: false,
            ..t1.clone()
        };
        assert!(matches!(
            choose_binning_path(&no_atomics, BinningRequest::Software),
            Err(PassError::Unsupported(_))
        ));
        assert_eq!(
            choose_binning_path(&no_atomics, BinningRequest::Compute).unwrap(),
            BinningPath::Compute
        );
    }

    #[test]
    fn tier1_emulation_needs_hardware_and_geometry_shaders() {
        let t3 = caps(ConservativeRasterTier::Tier3, true);
        assert_eq!(
            choose_binning_path(&t3, BinningRequest::EmulateTier1).unwrap(),
            BinningPath::EmulatedTier1 {
                native: ConservativeRasterTier::Tier3
            }
        );
        let lavapipe = caps(ConservativeRasterTier::NotSupported, true);
        assert!(matches!(
            choose_binning_path(&lavapipe, BinningRequest::EmulateTier1),
            Err(PassError::Unsupported(_))
        ));
        assert_eq!(
            BinningPath::EmulatedTier1 {
                native: ConservativeRasterTier::Tier3
            }
            .tier(),
            ConservativeRasterTier::Tier1
        );
    }

    #[test]
    fn a_cube_map_shares_n_squared_texels_and_bins_in_compute() {
        let c = caps(ConservativeRasterTier::Tier3, true);
        let cube = PrimitiveMapConfig {
            cube: true,
            ..PrimitiveMapConfig::default()
        };
        assert!(cube.validate(&c).is_ok());
        assert_eq!(cube.frusta(), 6);
        assert_eq!(cube.texels(), 1024 * 1024 + 6 * 17 * 17);
        assert_eq!(PrimitiveMapConfig::default().texels(), 1024 * 1024);
        // Two (triangle, face) pairs per triangle, at least 1024, unless given.
        assert_eq!(cube.starting_pairs(10_000), 20_000);
        assert_eq!(cube.starting_pairs(10), 1024);
        let given = PrimitiveMapConfig {
            initial_pairs: 8,
            ..cube
        };
        assert_eq!(given.starting_pairs(10_000), 8);
        assert_eq!(PrimitiveMapConfig::default().starting_pairs(10_000), 10_000);
        for binning in [
            BinningRequest::Hardware,
            BinningRequest::Software,
            BinningRequest::EmulateTier1,
        ] {
            assert!(PrimitiveMapConfig { binning, ..cube }.validate(&c).is_err());
        }
        let front = PrimitiveMapConfig {
            faces: FaceMode::FrontOnly,
            ..cube
        };
        assert!(front.validate(&c).is_err());
    }

    #[test]
    fn config_limits() {
        let c = caps(ConservativeRasterTier::NotSupported, true);
        let ok = PrimitiveMapConfig::default();
        assert!(ok.validate(&c).is_ok());
        assert!(PrimitiveMapConfig { size: 0, ..ok }.validate(&c).is_err());
        // 8192² offsets need 256 MiB: more than this device's 128 MiB storage buffers.
        assert!(PrimitiveMapConfig { size: 8192, ..ok }
            .validate(&c)
            .is_err());
        assert!(PrimitiveMapConfig {
            entry_budget: 1024,
            ..ok
        }
        .validate(&c)
        .is_err());
        // The budget is capped by the largest storage buffer, less the guard words.
        assert_eq!(ok.max_entries(&c), (1 << 27) / 4);
        let guarded = PrimitiveMapConfig { guard: true, ..ok };
        assert_eq!(guarded.max_entries(&c), (1 << 27) / 4 - GUARD_WORDS);
        // Two entries per texel plus four per triangle, at least 64K, within the budget.
        assert_eq!(ok.starting_entries(&c, 1000), 2 * 1024 * 1024 + 4000);
        let small = PrimitiveMapConfig { size: 16, ..ok };
        assert_eq!(small.starting_entries(&c, 10), 65536);
        let tight = PrimitiveMapConfig {
            entry_budget: 1 << 20,
            ..ok
        };
        assert_eq!(tight.starting_entries(&c, 1_000_000), (1 << 20) / 4);
        let sized = PrimitiveMapConfig {
            initial_entries: 1000,
            ..ok
        };
        assert_eq!(sized.starting_entries(&c, 1_000_000), 1000);
    }
}
