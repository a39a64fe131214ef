//! What a primitive map is asked for: its size, faces, binning path and budgets, checked against the
//! device (pure; unit-tested without a GPU).

use crate::PassError;
use rhi::{Capabilities, ConservativeRasterTier};

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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrimitiveMapConfig {
    /// N: texels per side of the light-space grid fitted to the receivers. 0 (the default,
    /// [`PLUGINS_CHOICE_SIZE`]): the plugin's choice by trace, [`TRACED_MAP_SIZE`] for hard and area
    /// shadows, [`NEAREST_HIT_MAP_SIZE`] for the hybrid (through [`PrimitiveMapConfig::for_nearest_hit`]).
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
    /// keeps more walks every ray through the BVH (exact, reported) and the pairs grow for the next, up to
    /// six per triangle.
    pub initial_pairs: u32,
    /// A texel whose list would hold more than this many entries keeps none: its pixels walk the BVH over
    /// the prim buffer (`crate::bvh`), which then costs less than the list. 0 (the default): the plugin's
    /// choice, [`HARD_LIST_LIMIT`] for hard shadows, [`NEAREST_HIT_LIST_LIMIT`] for the hybrid (through
    /// [`PrimitiveMapConfig::for_nearest_hit`]), [`AREA_LIST_LIMIT`] for area shadows (each measured for
    /// its own trace); `u32::MAX`: no limit.
    pub list_limit: u32,
    /// Bin items (4×4-texel tiles of the triangles' footprints, widened by their penumbrae for area
    /// shadows) per pixel with a shadow ray, past which a frame builds no list and every pixel walks the
    /// BVH: a large light's footprints cover most of the map, and the walk's cost follows the pixel's
    /// segments instead (default [`DEFAULT_BIN_BUDGET`]; infinite: always lists; 0: always the BVH).
    pub bin_budget: f32,
    /// Debug: entries each (triangle, texel) pair counts (default 1), so that a test can push the sums of
    /// list entries past 2^32 with a small scene. The fill still stores one entry per pair: the rest of an
    /// inflated list holds what the entries held before (guard mode: [`GUARD_VALUE`], an index past every
    /// triangle, which the traces skip), and nothing changes what the traces decide.
    pub debug_count_scale: u32,
}

/// Default [`PrimitiveMapConfig::list_limit`]: the plugin's choice by mode.
pub const DEFAULT_LIST_LIMIT: u32 = 0;

/// Default [`PrimitiveMapConfig::size`]: the plugin's choice by trace.
pub const PLUGINS_CHOICE_SIZE: u32 = 0;

/// N for traces that stop at a ray's first blocker (hard and area shadows) under [`PLUGINS_CHOICE_SIZE`].
/// On an H200 at 1080p, against 1024: 16 hard point lights 15 % faster in Sponza and 6 % in the conference
/// room (64 lights 14 and 4 %), each single hard light as fast or faster with 40-60 % less memory, an area
/// sun 7-19 % faster, sized point lights either way (16 of them 19 and 6 % faster, one of 11.7 m in the
/// conference room 8 % slower); at 4K, 16 point lights 6 % faster and 1 % slower (docs/h200/map_size,
/// docs/h200/map_choice).
pub const TRACED_MAP_SIZE: u32 = 512;

/// N for traces that find each ray's nearest blocker (the hybrid's blocker distance) under
/// [`PLUGINS_CHOICE_SIZE`]: their longer lists gain from the finer grid (on an H200 at 1080p the hybrid's
/// sun and hard shadows with the blocker distance took up to 2 % and 7 % longer at 512).
pub const NEAREST_HIT_MAP_SIZE: u32 = 1024;

/// The list limit of hard shadows (a ray's first blocker decides it) under [`DEFAULT_LIST_LIMIT`]. On an
/// H200 at 1080p with the rays' BVH (`crate::bvh`), the conference room's point lights traced 5-33 % faster
/// at 256 than at 1024 (the lists of up to 846 entries around its chairs walk the BVH instead), the trace
/// of 16 of them 11 % faster (the frame 7 %); Sponza did not change; 128 was slower in both.
pub const HARD_LIST_LIMIT: u32 = 256;

/// The list limit of traces that find each ray's nearest blocker (the hybrid's blocker distance) under
/// [`DEFAULT_LIST_LIMIT`]: a nearest-hit walk of the BVH costs more than long lists (on an H200 at 1080p
/// the conference room's sun in the hybrid traced 0.318 ms at 1024 and 0.370 ms at 256, in two runs).
pub const NEAREST_HIT_LIST_LIMIT: u32 = 1024;

/// The list limit of area shadows under [`DEFAULT_LIST_LIMIT`] (on an H100, the 240K bunny's area sun
/// took 7.2 ms and 6.9 MiB at 256, 7.6 ms and 42 MiB at 1024).
pub const AREA_LIST_LIMIT: u32 = 256;

/// Default [`PrimitiveMapConfig::bin_budget`].
pub const DEFAULT_BIN_BUDGET: f32 = 8.0;

/// Value of every guard word (never a valid prim-buffer index).
pub const GUARD_VALUE: u32 = u32::MAX;

/// Guard words after the entries in guard mode.
pub const GUARD_WORDS: u32 = 4096;

/// Default [`PrimitiveMapConfig::entry_budget`].
pub const DEFAULT_ENTRY_BUDGET: u64 = 256 << 20;

/// Smallest [`PrimitiveMapConfig::entry_budget`]: 1024 entries.
pub const MIN_ENTRY_BUDGET: u64 = 4096;

/// Smallest grid side a frustum with receivers gets (`map_fit.comp`).
const MIN_GRID: u32 = 16;

impl Default for PrimitiveMapConfig {
    fn default() -> Self {
        Self {
            size: PLUGINS_CHOICE_SIZE,
            faces: FaceMode::Both,
            binning: BinningRequest::Auto,
            entry_budget: DEFAULT_ENTRY_BUDGET,
            initial_entries: 0,
            receiver_culling: true,
            guard: false,
            cube: false,
            initial_pairs: 0,
            list_limit: DEFAULT_LIST_LIMIT,
            bin_budget: DEFAULT_BIN_BUDGET,
            debug_count_scale: 1,
        }
    }
}

impl PrimitiveMapConfig {
    /// Checks the configuration against the device limits (under [`PLUGINS_CHOICE_SIZE`], the sizes the
    /// plugin may choose).
    pub fn validate(&self, caps: &Capabilities) -> Result<(), PassError> {
        let max = caps.max_image_dimension_2d.min(u32::from(u16::MAX));
        if self.size > max {
            return Err(PassError::InvalidConfig(format!(
                "primitive map size {} must be in 1..={max}, or 0 for the plugin's choice",
                self.size
            )));
        }
        for chosen in [self.with_size_for(false), self.with_size_for(true)] {
            let grid = (chosen.texels() + 1) * 4;
            if grid > caps.max_storage_buffer_range {
                return Err(PassError::InvalidConfig(format!(
                    "primitive map size {}: its {} bytes of list offsets exceed the device's largest \
                     storage buffer ({} bytes)",
                    chosen.size, grid, caps.max_storage_buffer_range
                )));
            }
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
        if self.debug_count_scale == 0 {
            return Err(PassError::InvalidConfig(
                "primitive map debug count scale must be at least 1".into(),
            ));
        }
        if self.bin_budget.is_nan() || self.bin_budget < 0.0 {
            return Err(PassError::InvalidConfig(format!(
                "primitive map bin budget {} must be a number of bin items per pixel, 0 or more",
                self.bin_budget
            )));
        }
        if self.entry_budget < MIN_ENTRY_BUDGET {
            return Err(PassError::InvalidConfig(format!(
                "primitive map entry budget {} bytes is below the minimum of {MIN_ENTRY_BUDGET} bytes",
                self.entry_budget
            )));
        }
        Ok(())
    }

    /// This configuration for a map whose trace finds each ray's nearest blocker (the hybrid's blocker
    /// distance): the plugin's choices of list limit and N are then [`NEAREST_HIT_LIST_LIMIT`] and
    /// [`NEAREST_HIT_MAP_SIZE`].
    pub fn for_nearest_hit(self) -> Self {
        let list_limit = match self.list_limit {
            DEFAULT_LIST_LIMIT => NEAREST_HIT_LIST_LIMIT,
            limit => limit,
        };
        Self {
            list_limit,
            ..self.with_size_for(true)
        }
    }

    /// This configuration with N resolved: under [`PLUGINS_CHOICE_SIZE`], [`NEAREST_HIT_MAP_SIZE`] for a
    /// trace that finds each ray's `nearest_hit`, else [`TRACED_MAP_SIZE`]; a given N is kept.
    pub fn with_size_for(self, nearest_hit: bool) -> Self {
        let size = match (self.size, nearest_hit) {
            (PLUGINS_CHOICE_SIZE, true) => NEAREST_HIT_MAP_SIZE,
            (PLUGINS_CHOICE_SIZE, false) => TRACED_MAP_SIZE,
            (size, _) => size,
        };
        Self { size, ..self }
    }

    /// The list limit in effect for hard shadows, or for area shadows if `area`.
    pub fn list_limit_for(&self, area: bool) -> u32 {
        match (self.list_limit, area) {
            (0, false) => HARD_LIST_LIMIT,
            (0, true) => AREA_LIST_LIMIT,
            (limit, _) => limit,
        }
    }

    /// Frusta the map holds: 6 for a point light's cube, else 1.
    pub fn frusta(&self) -> u32 {
        if self.cube {
            6
        } else {
            1
        }
    }

    /// Texels of the map's grids together: N², and for a cube the minimum grid of each face besides (N as
    /// [`PrimitiveMapConfig::with_size_for`] a first-blocker trace resolves it).
    pub fn texels(&self) -> u64 {
        let n = self.with_size_for(false).size;
        let n2 = u64::from(n) * u64::from(n);
        if self.cube {
            let min_grid = u64::from(MIN_GRID.min(n)) + 1;
            n2 + 6 * min_grid * min_grid
        } else {
            n2
        }
    }

    /// Bin triangles a map over `triangles` triangles starts with: one per triangle, or for a cube
    /// [`PrimitiveMapConfig::initial_pairs`], at most six per triangle (it grows to what frames keep).
    pub fn starting_pairs(&self, triangles: u32) -> u32 {
        match (self.cube, self.initial_pairs) {
            (false, _) => triangles,
            (true, 0) => triangles.saturating_mul(2).max(1024),
            (true, given) => given.min(triangles.saturating_mul(6)).max(1),
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
        let n = self.with_size_for(false).size;
        let n2 = u64::from(n) * u64::from(n);
        let estimate = match self.initial_entries {
            0 => (2 * n2 + 4 * u64::from(triangles)).max(65536),
            given => u64::from(given),
        };
        estimate.min(u64::from(self.max_entries(caps))).max(1) as u32
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
    fn each_trace_gets_its_size_unless_one_is_given() {
        let default = PrimitiveMapConfig::default();
        assert_eq!(default.size, PLUGINS_CHOICE_SIZE);
        assert_eq!(default.with_size_for(false).size, TRACED_MAP_SIZE);
        assert_eq!(default.for_nearest_hit().size, NEAREST_HIT_MAP_SIZE);
        let given = PrimitiveMapConfig {
            size: 300,
            ..default
        };
        assert_eq!(given.with_size_for(false).size, 300);
        assert_eq!(given.for_nearest_hit().size, 300);
        let c = caps(ConservativeRasterTier::Tier3, true);
        assert!(default.validate(&c).is_ok());
        let too_big = PrimitiveMapConfig {
            size: c.max_image_dimension_2d + 1,
            ..default
        };
        assert!(matches!(
            too_big.validate(&c),
            Err(PassError::InvalidConfig(_))
        ));
    }

    #[test]
    fn each_trace_gets_its_list_limit() {
        let default = PrimitiveMapConfig::default();
        assert_eq!(default.list_limit_for(false), HARD_LIST_LIMIT);
        assert_eq!(default.list_limit_for(true), AREA_LIST_LIMIT);
        assert_eq!(
            default.for_nearest_hit().list_limit_for(false),
            NEAREST_HIT_LIST_LIMIT
        );
        let chosen = PrimitiveMapConfig {
            list_limit: 7,
            ..default
        };
        assert_eq!(chosen.for_nearest_hit().list_limit_for(false), 7);
        assert_eq!(chosen.list_limit_for(true), 7);
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
            size: 1024,
            ..PrimitiveMapConfig::default()
        };
        assert!(cube.validate(&c).is_ok());
        assert_eq!(cube.frusta(), 6);
        assert_eq!(cube.texels(), 1024 * 1024 + 6 * 17 * 17);
        assert_eq!(
            PrimitiveMapConfig::default().texels(),
            u64::from(TRACED_MAP_SIZE).pow(2)
        );
        // Two (triangle, face) pairs per triangle, at least 1024, unless given.
        assert_eq!(cube.starting_pairs(10_000), 20_000);
        assert_eq!(cube.starting_pairs(10), 1024);
        let given = PrimitiveMapConfig {
            initial_pairs: 8,
            ..cube
        };
        assert_eq!(given.starting_pairs(10_000), 8);
        let huge = PrimitiveMapConfig {
            initial_pairs: u32::MAX,
            ..cube
        };
        assert_eq!(huge.starting_pairs(10_000), 60_000);
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
        let ok = PrimitiveMapConfig {
            size: 1024,
            ..PrimitiveMapConfig::default()
        };
        assert!(ok.validate(&c).is_ok());
        assert!(PrimitiveMapConfig::default().validate(&c).is_ok());
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
