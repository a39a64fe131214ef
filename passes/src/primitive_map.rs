//! The deep primitive map: an N×N count map (atomic), an N×N×d index map, filled by conservative
//! rasterization of the prim buffer in light space, and its occupancy view.
//!
//! Reads: prim buffer. Writes: count map, index map (raster); occupancy image, map statistics (occupancy).

use crate::gpu_types::{MapStats, OccupancyPush, PrimMapPush};
use crate::{shader, PassError};
use rhi::{
    BindGroup, BindingKind, Buffer, BufferUsage, Capabilities, ComputePipeline,
    ConservativeRasterTier, Device, Encoder, Format, GraphicsPipeline, GraphicsPipelineDesc, Image,
    ImageDesc, ImageUsage, MemoryLocation, Resource,
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

/// How the caller wants conservative rasterization done.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RasterRequest {
    /// Hardware where the device has a tier, else software.
    #[default]
    Auto,
    /// Force hardware (fails without `VK_EXT_conservative_rasterization`).
    Hardware,
    /// Force the geometry-shader path.
    Software,
    /// Hardware conservative raster made to behave like D3D12 Tier 1 (1/2 px uncertainty, post-snap
    /// degenerate triangles culled) on a device with a better tier: for tier-fallback tests.
    EmulateTier1,
}

/// The conservative-raster path in use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RasterPath {
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

impl RasterPath {
    /// "hardware" or "software".
    pub fn name(self) -> &'static str {
        match self {
            Self::Hardware(_) => "hardware",
            Self::Software => "software",
            Self::EmulatedTier1 { .. } => "hardware (tier-1 emulation)",
        }
    }
    /// The tier used ("none" for software).
    pub fn tier(self) -> ConservativeRasterTier {
        match self {
            Self::Hardware(t) => t,
            Self::Software => ConservativeRasterTier::NotSupported,
            Self::EmulatedTier1 { .. } => ConservativeRasterTier::Tier1,
        }
    }
}

/// Chooses the raster path from the device's capabilities (pure; unit-tested).
pub fn choose_raster_path(
    caps: &Capabilities,
    request: RasterRequest,
) -> Result<RasterPath, PassError> {
    let hw = caps.conservative_raster_tier;
    let sw_ok = caps.geometry_shader;
    match request {
        RasterRequest::Hardware if hw == ConservativeRasterTier::NotSupported => Err(PassError::Unsupported(
            "hardware conservative rasterization (VK_EXT_conservative_rasterization)".into(),
        )),
        RasterRequest::Hardware => Ok(RasterPath::Hardware(hw)),
        RasterRequest::Software if !sw_ok => {
            Err(PassError::Unsupported("geometry shaders (software conservative rasterization)".into()))
        }
        RasterRequest::Software => Ok(RasterPath::Software),
        RasterRequest::EmulateTier1 if hw == ConservativeRasterTier::NotSupported || !sw_ok => Err(PassError::Unsupported(
            "tier-1 emulation needs hardware conservative rasterization and geometry shaders".into(),
        )),
        RasterRequest::EmulateTier1 => Ok(RasterPath::EmulatedTier1 { native: hw }),
        RasterRequest::Auto if hw != ConservativeRasterTier::NotSupported => Ok(RasterPath::Hardware(hw)),
        RasterRequest::Auto if sw_ok => Ok(RasterPath::Software),
        RasterRequest::Auto => Err(PassError::Unsupported(
            "conservative rasterization: neither VK_EXT_conservative_rasterization nor geometry shaders".into(),
        )),
    }
}

/// Size and behaviour of the deep primitive map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PrimitiveMapConfig {
    /// N: texels per side.
    pub size: u32,
    /// d: triangle slots per texel.
    pub depth: u32,
    /// Faces stored.
    pub faces: FaceMode,
    /// Raster path request.
    pub raster: RasterRequest,
    /// Allocate one extra index layer past d, filled with `GUARD_VALUE` every frame, that no pass may
    /// write: tests read it back to prove overflow never writes out of bounds. Costs N² u32 and a clear.
    pub guard_layer: bool,
}

/// Value of every index slot cleared in guard mode (never a valid prim-buffer index).
pub const GUARD_VALUE: u32 = u32::MAX;

impl Default for PrimitiveMapConfig {
    /// The talk's 1K×1K×32.
    fn default() -> Self {
        Self {
            size: 1024,
            depth: 32,
            faces: FaceMode::Both,
            raster: RasterRequest::Auto,
            guard_layer: false,
        }
    }
}

impl PrimitiveMapConfig {
    /// Checks the configuration against the device limits.
    pub fn validate(&self, caps: &Capabilities) -> Result<(), PassError> {
        if self.size == 0 || self.size > caps.max_image_dimension_2d {
            return Err(PassError::InvalidConfig(format!(
                "primitive map size {} must be in 1..={}",
                self.size, caps.max_image_dimension_2d
            )));
        }
        if self.depth == 0 || self.depth + u32::from(self.guard_layer) > caps.max_image_array_layers
        {
            return Err(PassError::InvalidConfig(format!(
                "primitive map depth {} must be in 1..={}",
                self.depth, caps.max_image_array_layers
            )));
        }
        Ok(())
    }

    /// Bytes of the count map plus the index map.
    pub fn memory_bytes(&self) -> u64 {
        u64::from(self.size)
            * u64::from(self.size)
            * 4
            * (1 + u64::from(self.depth + u32::from(self.guard_layer)))
    }
}

/// The primitive map's resources and passes.
pub struct PrimitiveMap {
    config: PrimitiveMapConfig,
    path: RasterPath,
    raster: GraphicsPipeline,
    raster_group: BindGroup,
    occupancy_pipeline: ComputePipeline,
    occupancy_group: BindGroup,
    /// N×N `R32_UINT`: triangles touching each texel (may exceed d: overflow).
    pub count: Image,
    /// N×N×d `R32_UINT` array: prim-buffer indices, layer = slot.
    pub indices: Image,
    /// N×N `RGBA8` occupancy view.
    pub occupancy: Image,
    /// `MapStats`, GPU-written by the occupancy pass.
    pub stats: Buffer,
}

impl PrimitiveMap {
    /// Creates the map for `prims` with the path chosen from the device's capabilities.
    pub fn new(
        device: &Device,
        prims: &Buffer,
        config: PrimitiveMapConfig,
    ) -> Result<Self, PassError> {
        let caps = device.capabilities();
        config.validate(caps)?;
        if !caps.fragment_stores_and_atomics {
            return Err(PassError::Unsupported("fragmentStoresAndAtomics".into()));
        }
        let path = choose_raster_path(caps, config.raster)?;
        let n = config.size;
        let uint_image = |name, layers, usage| ImageDesc {
            name,
            format: Format::R32Uint,
            width: n,
            height: n,
            layers,
            usage,
        };
        let count = device.create_image(&uint_image(
            "prim count map",
            1,
            ImageUsage::STORAGE | ImageUsage::COPY_DST | ImageUsage::COPY_SRC,
        ))?;
        let indices = device.create_image(&uint_image(
            "prim index map",
            config.depth + u32::from(config.guard_layer),
            ImageUsage::STORAGE | ImageUsage::COPY_DST | ImageUsage::COPY_SRC,
        ))?;
        let occupancy = device.create_image(&ImageDesc {
            name: "prim map occupancy",
            format: Format::Rgba8Unorm,
            width: n,
            height: n,
            layers: 1,
            usage: ImageUsage::STORAGE | ImageUsage::COPY_SRC,
        })?;
        let stats = device.create_buffer(
            "prim map stats",
            std::mem::size_of::<MapStats>() as u64,
            BufferUsage::STORAGE | BufferUsage::COPY_DST | BufferUsage::COPY_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let (geometry, fragment, extra) = match path {
            RasterPath::Software => (
                Some(shader("prim_map_sw.geom")?),
                shader("prim_map_sw.frag")?,
                None,
            ),
            RasterPath::Hardware(_) => (None, shader("prim_map_hw.frag")?, Some(0.0)),
            RasterPath::EmulatedTier1 { .. } => {
                let extra = (0.5 - caps.primitive_overestimation_size)
                    .clamp(0.0, caps.max_extra_primitive_overestimation_size);
                (
                    Some(shader("prim_map_snap.geom")?),
                    shader("prim_map_hw.frag")?,
                    Some(extra),
                )
            }
        };
        let raster = device.create_graphics_pipeline(&GraphicsPipelineDesc {
            name: "primitive map",
            vertex: &shader("prim_map.vert")?,
            geometry: geometry.as_deref(),
            fragment: &fragment,
            bindings: &[
                BindingKind::StorageBuffer,
                BindingKind::StorageImage,
                BindingKind::StorageImage,
            ],
            push_constant_size: std::mem::size_of::<PrimMapPush>() as u32,
            color_formats: &[],
            depth: None,
            conservative_extra_overestimation: extra,
            depth_clamp: true,
        })?;
        let raster_group = device.create_bind_group(
            raster.layout(),
            &[
                Resource::Buffer(prims),
                Resource::Image(&count),
                Resource::Image(&indices),
            ],
        )?;
        let occupancy_pipeline = device.create_compute_pipeline(
            "occupancy",
            &shader("occupancy.comp")?,
            &[
                BindingKind::StorageImage,
                BindingKind::StorageImage,
                BindingKind::StorageBuffer,
            ],
            std::mem::size_of::<OccupancyPush>() as u32,
        )?;
        let occupancy_group = device.create_bind_group(
            occupancy_pipeline.layout(),
            &[
                Resource::Image(&count),
                Resource::Image(&occupancy),
                Resource::Buffer(&stats),
            ],
        )?;
        Ok(Self {
            config,
            path,
            raster,
            raster_group,
            occupancy_pipeline,
            occupancy_group,
            count,
            indices,
            occupancy,
            stats,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &PrimitiveMapConfig {
        &self.config
    }

    /// The raster path in use.
    pub fn path(&self) -> RasterPath {
        self.path
    }

    /// Clears the count map and the statistics (and, in guard mode, the index map to `GUARD_VALUE`);
    /// count and index maps must be in `CopyDest` state.
    pub fn record_clear(&self, enc: &mut Encoder<'_>) {
        enc.begin_pass("primitive map clear");
        enc.clear_uint(&self.count, 0);
        if self.config.guard_layer {
            enc.clear_uint(&self.indices, GUARD_VALUE);
        }
        enc.fill_buffer(&self.stats, 0);
        enc.end_pass();
    }

    /// Rasterizes `triangle_count` prim-buffer triangles; count and index maps in `UnorderedAccess` state.
    pub fn record_raster(
        &self,
        enc: &mut Encoder<'_>,
        push: &PrimMapPush,
        triangle_count: u32,
    ) -> Result<(), PassError> {
        let name = match self.path {
            RasterPath::Hardware(_) => "primitive map (HW CR)",
            RasterPath::Software => "primitive map (SW CR)",
            RasterPath::EmulatedTier1 { .. } => "primitive map (HW CR, tier-1 emulation)",
        };
        enc.begin_pass(name);
        enc.begin_rendering((self.config.size, self.config.size), &[], None);
        enc.draw(
            &self.raster,
            &self.raster_group,
            bytemuck::bytes_of(push),
            triangle_count * 3,
        )?;
        enc.end_rendering();
        enc.end_pass();
        Ok(())
    }

    /// Writes the occupancy view and the map statistics.
    pub fn record_occupancy(&self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        enc.begin_pass("occupancy");
        let n = self.config.size;
        let push = OccupancyPush {
            size: n,
            depth: self.config.depth,
        };
        enc.dispatch(
            &self.occupancy_pipeline,
            &self.occupancy_group,
            bytemuck::bytes_of(&push),
            [n.div_ceil(8), n.div_ceil(8), 1],
        )?;
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
        }
    }

    #[test]
    fn auto_prefers_hardware_then_software() {
        let t3 = caps(ConservativeRasterTier::Tier3, true);
        assert_eq!(
            choose_raster_path(&t3, RasterRequest::Auto).unwrap(),
            RasterPath::Hardware(ConservativeRasterTier::Tier3)
        );
        let lavapipe = caps(ConservativeRasterTier::NotSupported, true);
        assert_eq!(
            choose_raster_path(&lavapipe, RasterRequest::Auto).unwrap(),
            RasterPath::Software
        );
        let neither = caps(ConservativeRasterTier::NotSupported, false);
        assert!(matches!(
            choose_raster_path(&neither, RasterRequest::Auto),
            Err(PassError::Unsupported(_))
        ));
    }

    #[test]
    fn forced_paths_fail_clearly_without_the_feature() {
        let lavapipe = caps(ConservativeRasterTier::NotSupported, true);
        assert!(matches!(
            choose_raster_path(&lavapipe, RasterRequest::Hardware),
            Err(PassError::Unsupported(_))
        ));
        let no_gs = caps(ConservativeRasterTier::Tier1, false);
        assert!(matches!(
            choose_raster_path(&no_gs, RasterRequest::Software),
            Err(PassError::Unsupported(_))
        ));
        let t1 = caps(ConservativeRasterTier::Tier1, true);
        assert_eq!(
            choose_raster_path(&t1, RasterRequest::Software).unwrap(),
            RasterPath::Software
        );
    }

    #[test]
    fn tier1_emulation_needs_hardware_and_geometry_shaders() {
        let t3 = caps(ConservativeRasterTier::Tier3, true);
        assert_eq!(
            choose_raster_path(&t3, RasterRequest::EmulateTier1).unwrap(),
            RasterPath::EmulatedTier1 {
                native: ConservativeRasterTier::Tier3
            }
        );
        let lavapipe = caps(ConservativeRasterTier::NotSupported, true);
        assert!(matches!(
            choose_raster_path(&lavapipe, RasterRequest::EmulateTier1),
            Err(PassError::Unsupported(_))
        ));
        assert_eq!(
            RasterPath::EmulatedTier1 {
                native: ConservativeRasterTier::Tier3
            }
            .tier(),
            ConservativeRasterTier::Tier1
        );
    }

    #[test]
    fn config_limits() {
        let c = caps(ConservativeRasterTier::NotSupported, true);
        let ok = PrimitiveMapConfig::default();
        assert!(ok.validate(&c).is_ok());
        assert_eq!(ok.memory_bytes(), 1024 * 1024 * 4 * 33);
        assert!(PrimitiveMapConfig { depth: 0, ..ok }.validate(&c).is_err());
        assert!(PrimitiveMapConfig { size: 0, ..ok }.validate(&c).is_err());
        assert!(PrimitiveMapConfig { depth: 4096, ..ok }
            .validate(&c)
            .is_err());
    }
}
