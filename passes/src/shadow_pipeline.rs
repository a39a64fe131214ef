//! The engine-facing unit: the passes of one view of one light, chosen by the [`FramePlan`] from what the
//! configuration asks for, recorded into any command buffer. It reads the engine's depth and normal images
//! and writes one final visibility image (1 = lit): ray-traced, PCSS, hybrid or FXAA'd, whichever the
//! plan's final output is. The C ABI and the demo host both drive it.
//!
//! Linear order of the passes (each runs only if the plan keeps it):
//! prim buffer → shadow map → primitive map → occupancy → ray trace → classic shadow-map test → PCSS →
//! FXAA (on the ray-traced visibility) → lerp factor → hybrid blend | fill lit.

use crate::frame_plan::{
    FramePlan, HardEdge, PassId, PassStatus, PenumbraFilter, PlanRequest, ResourceId, ResourceSet,
    ShadowMode, SkipReason,
};
use crate::fxaa::FxaaPass;
use crate::gpu_types::{
    MapPush, MapState, MapStats, PcssConstants, RayTraceConstants, ShadowMapPush,
};
use crate::hybrid::{BlendPass, HybridConfig, LerpFactorPass};
use crate::light::{rebased, Light, LightFrame};
use crate::pcss::{PcssConfig, PcssInputs, PcssKind, PcssPass};
use crate::prim_buffer::{Geometry, PrimBufferClaim, SharedGeometry};
use crate::primitive_map::{
    choose_binning_path, BinningPath, FaceMode, PrimitiveMap, PrimitiveMapConfig,
    PrimitiveMapInputs,
};
use crate::ray_trace::{RayTraceInputs, RayTracePass, RAY_OFFSET_FLOAT_BOUND, RAY_OFFSET_PIXELS};
use crate::retire::{completed_before, RetireQueue};
use crate::screen_pass::visibility_image;
use crate::shadow_map::{ShadowMapConfig, ShadowMapPass};
use crate::PassError;
use bytemuck::Zeroable;
use glam::{DMat4, DVec3, Mat4, UVec4, Vec3, Vec4};
use rhi::{
    Barrier, BindGroup, Buffer, BufferUsage, Device, Encoder, GpuTimer, Image, MemoryLocation,
    PassTiming, ResourceState as S,
};
use std::sync::Arc;

/// Camera and light of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameInputs {
    /// World to view.
    pub view: Mat4,
    /// View to clip: reversed Z (depth 1 at the near plane, 0 at infinity), Vulkan conventions.
    pub proj: Mat4,
    /// Camera position in world space.
    pub camera_position: Vec3,
    /// The light.
    pub light: Light,
}

/// What the pipeline computes and how: the requested outputs (per light: none, hard, soft or hybrid;
/// antialiasing), what may be cached across frames, and the settings of each technique.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowConfig {
    /// The light's shadow mode (default hybrid).
    pub mode: ShadowMode,
    /// FXAA over the ray-traced visibility (default on; no effect without a ray-traced shadow).
    pub antialiasing: bool,
    /// The vertex and index buffers do not change between frames: the prim buffer is built once
    /// (default true). When false it is rebuilt every frame, and everything downstream with it.
    pub static_geometry: bool,
    /// The light does not move: with static geometry, the shadow map and the primitive map are kept from
    /// the frame that built them for as long as the frame's light equals that frame's (default false).
    pub static_light: bool,
    /// The deep primitive map.
    pub map: PrimitiveMapConfig,
    /// The shadow map.
    pub shadow_map: ShadowMapConfig,
    /// PCSS.
    pub pcss: PcssConfig,
    /// The hybrid blend.
    pub hybrid: HybridConfig,
    /// Resources to produce besides the final output (comparison views, debug images, a host G-buffer
    /// drawing the prim buffer). Empty by default.
    pub extra_outputs: ResourceSet,
    /// The most frames recorded and not yet completed on the GPU (1..=[`MAX_FRAMES_IN_FLIGHT`], default 3):
    /// when frame `f` is begun, every frame up to `f - frames_in_flight` has completed. Per-frame
    /// read-backs and timers are ring-buffered this deep, and replaced GPU objects are held as long.
    pub frames_in_flight: u32,
}

/// The most frames in flight a pipeline supports.
pub const MAX_FRAMES_IN_FLIGHT: u32 = 8;

impl Default for ShadowConfig {
    /// The talk's full technique: hybrid with FXAA, 1K×1K×32 primitive map, 3K shadow map, shrinking PCSS.
    fn default() -> Self {
        Self {
            mode: ShadowMode::Hybrid,
            antialiasing: true,
            static_geometry: true,
            static_light: false,
            map: PrimitiveMapConfig::default(),
            shadow_map: ShadowMapConfig::default(),
            pcss: PcssConfig::default(),
            hybrid: HybridConfig::default(),
            extra_outputs: ResourceSet::EMPTY,
            frames_in_flight: 3,
        }
    }
}

impl From<PrimitiveMapConfig> for ShadowConfig {
    /// A primitive-map configuration alone asks for ray-traced hard shadows without antialiasing: the
    /// output is the exact ray-traced visibility.
    fn from(map: PrimitiveMapConfig) -> Self {
        Self {
            mode: ShadowMode::Hard,
            antialiasing: false,
            map,
            ..Self::default()
        }
    }
}

impl ShadowConfig {
    /// The frame-plan request of this configuration.
    pub fn plan_request(&self) -> PlanRequest {
        PlanRequest {
            mode: self.mode,
            antialiasing: self.antialiasing,
            filter: self.pcss.filter,
            extra_outputs: self.extra_outputs,
        }
    }
}

/// Bytes a resource of the plan takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResourceReport {
    /// The resource.
    pub resource: ResourceId,
    /// Its size in bytes.
    pub bytes: u64,
}

/// What a frame did.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// GPU time per pass that ran this frame, in recording order.
    pub timings: Vec<PassTiming>,
    /// The binning path of the primitive map (the path the device would use when the plan has no
    /// primitive map; compute if it has none).
    pub binning_path: BinningPath,
    /// Statistics of the primitive map as last built (zero without a primitive map).
    pub stats: MapStats,
    /// The primitive map's fitted transform, frame coordinates to homogeneous texel space, as last built
    /// (zero without a primitive map).
    pub map_to_texels: Mat4,
    /// Every pass of the linear order: ran this frame, or skipped and why.
    pub passes: Vec<(PassId, PassStatus)>,
    /// Every resource the pipeline allocated, with its size.
    pub resources: Vec<ResourceReport>,
    /// The resource [`ShadowPipeline::output`] holds.
    pub output: ResourceId,
}

impl FrameReport {
    /// Whether `pass` ran this frame.
    pub fn ran(&self, pass: PassId) -> bool {
        self.passes.contains(&(pass, PassStatus::Ran))
    }

    /// Why `pass` was skipped this frame (`None` if it ran).
    pub fn status(&self, pass: PassId) -> Option<PassStatus> {
        self.passes
            .iter()
            .find(|(p, _)| *p == pass)
            .map(|&(_, s)| s)
    }

    /// Total bytes of the allocated resources.
    pub fn total_bytes(&self) -> u64 {
        self.resources.iter().map(|r| r.bytes).sum()
    }
}

/// The engine's images the pipeline reads, bound at creation.
pub struct ShadowInputs<'a> {
    /// Reversed-Z depth (`D32_SFLOAT`, sampled), `ShaderResource` state when the passes run.
    pub depth: &'a Image,
    /// World-space geometric normal facing the camera (xyz), w = 0 on background, `ShaderResource` state.
    pub normal: &'a Image,
}

/// Derived per-frame constants.
struct FrameConstants {
    light: LightFrame,
    map: MapPush,
    ray: RayTraceConstants,
    pcss: PcssConstants,
}

/// A frame begun and being recorded.
struct FrameState {
    constants: FrameConstants,
    light: Light,
    /// The frame's index and its slot in the ring.
    index: u64,
    slot: usize,
    /// Whether this pipeline records the shared prim buffer's build this frame.
    records_prims: bool,
    /// Index in the linear order of the first pass neither recorded nor passed over yet.
    next: usize,
    /// Whether a recording of this frame has reset and attached the GPU timer.
    timer_started: bool,
    /// Whether the frame's completion marker is recorded.
    marked: bool,
}

/// What the ring keeps of one frame in flight: its GPU timer, the map state read back, and its schedule.
struct FrameSlot {
    /// The frame whose recording last used this slot.
    frame: Option<u64>,
    timer: GpuTimer,
    stats_readback: Buffer,
    /// Whether the frame recorded the copy of the map state into `stats_readback`.
    map_state_recorded: bool,
    statuses: Vec<(PassId, PassStatus)>,
    /// Written by the GPU when the frame's last pass has run: the frame's index plus one.
    completion: Buffer,
}

/// What growing the primitive map replaced, held while frames in flight may still use it.
struct RetiredMapEntries {
    _entries: Buffer,
    _bin_group: BindGroup,
    _ray_group: Option<BindGroup>,
}

/// The passes of one view of one light, and the resources the plan allocates for them.
pub struct ShadowPipeline {
    config: ShadowConfig,
    plan: FramePlan,
    shared: Arc<SharedGeometry>,
    shadow_map: Option<ShadowMapPass>,
    map: Option<PrimitiveMap>,
    ray: Option<RayTracePass>,
    shadow_map_test: Option<PcssPass>,
    pcss: Option<PcssPass>,
    fxaa: Option<FxaaPass>,
    lerp: Option<LerpFactorPass>,
    blend: Option<BlendPass>,
    lit: Option<Image>,
    slots: Vec<FrameSlot>,
    binning_path: BinningPath,
    /// Resources whose contents are valid from an earlier recording.
    valid: ResourceSet,
    /// The light of the last recording that rendered the light-space maps.
    maps_light: Option<Light>,
    /// The frame being recorded (from `begin_frame` to the end of its linear order).
    frame: Option<FrameState>,
    /// The index of the last frame begun.
    last_frame: Option<u64>,
    /// List entries the newest completed map build needed (grows the map before the next build).
    needed_entries: u32,
    retired: RetireQueue<RetiredMapEntries>,
    /// Whether storage writes were recorded and not yet followed by a UAV barrier, and the plan's
    /// resources among what they wrote.
    pending_uav: Option<ResourceSet>,
    /// The schedule of the last frame begun, in linear order.
    statuses: Vec<(PassId, PassStatus)>,
    width: u32,
    height: u32,
}

impl ShadowPipeline {
    /// Creates the passes the plan of `config` needs over `geometry`, for the size of `inputs.depth`.
    /// `config` may be a [`ShadowConfig`] or, for ray-traced hard shadows alone, a
    /// [`PrimitiveMapConfig`].
    pub fn new(
        device: &Device,
        geometry: Geometry,
        inputs: &ShadowInputs<'_>,
        config: impl Into<ShadowConfig>,
    ) -> Result<Self, PassError> {
        let config = config.into();
        let shared = SharedGeometry::new(device, geometry, !config.static_geometry)?;
        Self::with_shared_geometry(device, shared, inputs, config)
    }

    /// Creates the passes of one light over geometry that other lights' pipelines share: the prim buffer is
    /// built by the first pipeline that begins a frame needing it, and `shared`'s dynamic flag (not
    /// `config.static_geometry`) decides whether it is rebuilt every frame. Begin and record the lights'
    /// frames in the same order, frame after frame.
    pub fn with_shared_geometry(
        device: &Device,
        shared: Arc<SharedGeometry>,
        inputs: &ShadowInputs<'_>,
        config: impl Into<ShadowConfig>,
    ) -> Result<Self, PassError> {
        let config = config.into();
        if !(1..=MAX_FRAMES_IN_FLIGHT).contains(&config.frames_in_flight) {
            return Err(PassError::InvalidConfig(format!(
                "frames_in_flight {} must be within 1..={MAX_FRAMES_IN_FLIGHT}",
                config.frames_in_flight
            )));
        }
        let geometry = shared.geometry();
        let (width, height) = (inputs.depth.width(), inputs.depth.height());
        if (inputs.normal.width(), inputs.normal.height()) != (width, height) {
            return Err(PassError::InvalidConfig(
                "depth and normal images differ in size".into(),
            ));
        }
        let caps = device.capabilities();
        config.map.validate(caps)?;
        config.shadow_map.validate(caps)?;
        config.pcss.validate()?;
        config.hybrid.validate()?;
        let plan = FramePlan::derive(config.plan_request());
        let runs = |p| plan.runs(p);

        let prims = runs(PassId::PrimBuffer).then(|| shared.prims());
        let need_prims = || {
            prims.ok_or_else(|| PassError::InvalidConfig("the plan lacks the prim buffer".into()))
        };
        let shadow_map = if runs(PassId::ShadowMap) {
            Some(ShadowMapPass::new(
                device,
                need_prims()?,
                config.shadow_map.size,
            )?)
        } else {
            None
        };
        let map = if runs(PassId::PrimitiveMap) {
            let map_inputs = PrimitiveMapInputs {
                prims: need_prims()?,
                triangles: geometry.triangle_count(),
                depth: inputs.depth,
                normal: inputs.normal,
                occupancy_view: plan.resources().contains(ResourceId::Occupancy),
            };
            Some(PrimitiveMap::new(device, &map_inputs, config.map)?)
        } else {
            None
        };
        let binning_path = match &map {
            Some(m) => m.path(),
            None => choose_binning_path(caps, config.map.binning).unwrap_or(BinningPath::Compute),
        };
        let ray = match (&map, runs(PassId::RayTrace)) {
            (Some(m), true) => Some(RayTracePass::new(
                device,
                &RayTraceInputs {
                    depth: inputs.depth,
                    normal: inputs.normal,
                    map: m,
                    prims: need_prims()?,
                },
                width,
                height,
            )?),
            _ => None,
        };
        let pcss_pass = |kind| -> Result<Option<PcssPass>, PassError> {
            let Some(sm) = &shadow_map else {
                return Ok(None);
            };
            let pcss_inputs = PcssInputs {
                depth: inputs.depth,
                normal: inputs.normal,
                shadow_map: &sm.depth,
                rt_visibility: ray.as_ref().map(|r| &r.visibility),
            };
            PcssPass::new(
                device,
                &pcss_inputs,
                kind,
                config.pcss.filter,
                width,
                height,
            )
            .map(Some)
        };
        let shadow_map_test = if runs(PassId::ShadowMapTest) {
            pcss_pass(PcssKind::ClassicTest)?
        } else {
            None
        };
        let edge = match (config.pcss.filter, plan.hard_edge()) {
            (PenumbraFilter::Shrinking, HardEdge::RayTrace) => HardEdge::RayTrace,
            _ => HardEdge::ShadowMap,
        };
        let pcss = if runs(PassId::Pcss) {
            pcss_pass(PcssKind::Pcss(edge))?
        } else {
            None
        };
        let fxaa = match (&ray, runs(PassId::Fxaa)) {
            (Some(r), true) => Some(FxaaPass::new(device, &r.visibility)?),
            _ => None,
        };
        let lerp = match (&ray, runs(PassId::LerpFactor)) {
            (Some(r), true) => Some(LerpFactorPass::new(device, &r.blocker_distance)?),
            _ => None,
        };
        let blend = if runs(PassId::Blend) {
            let rts = if config.antialiasing {
                fxaa.as_ref().map(|f| &f.output)
            } else {
                ray.as_ref().map(|r| &r.visibility)
            };
            match (rts, &pcss, &lerp) {
                (Some(rts), Some(p), Some(l)) => {
                    Some(BlendPass::new(device, rts, &p.output, &l.output)?)
                }
                _ => None,
            }
        } else {
            None
        };
        let lit = if runs(PassId::FillLit) {
            Some(visibility_image(device, "lit", width, height)?)
        } else {
            None
        };
        let slots = (0..config.frames_in_flight)
            .map(|_| {
                Ok(FrameSlot {
                    frame: None,
                    timer: device.create_timer(48)?,
                    stats_readback: device.create_buffer(
                        "map state read-back",
                        std::mem::size_of::<MapState>() as u64,
                        BufferUsage::COPY_DST,
                        MemoryLocation::GpuToCpu,
                    )?,
                    map_state_recorded: false,
                    statuses: Vec::new(),
                    completion: {
                        let mut b = device.create_buffer(
                            "frame completion",
                            8,
                            BufferUsage::COPY_DST,
                            MemoryLocation::GpuToCpu,
                        )?;
                        b.write(0, &0u64.to_le_bytes())?;
                        b
                    },
                })
            })
            .collect::<Result<Vec<_>, PassError>>()?;
        let pipeline = Self {
            config,
            plan,
            shared,
            shadow_map,
            map,
            ray,
            shadow_map_test,
            pcss,
            fxaa,
            lerp,
            blend,
            lit,
            slots,
            binning_path,
            valid: ResourceSet::EMPTY,
            maps_light: None,
            frame: None,
            last_frame: None,
            needed_entries: 0,
            retired: RetireQueue::default(),
            pending_uav: None,
            statuses: Vec::new(),
            width,
            height,
        };
        // Every resource of the plan exists (a missing one would be a bug in the wiring above).
        if let Some(r) = pipeline
            .plan
            .resources()
            .iter()
            .find(|&r| pipeline.resource_bytes(r).is_none())
        {
            return Err(PassError::InvalidConfig(format!(
                "the plan needs {} but it was not created",
                r.name()
            )));
        }
        Ok(pipeline)
    }

    /// The configuration.
    pub fn config(&self) -> &ShadowConfig {
        &self.config
    }

    /// The frame plan.
    pub fn plan(&self) -> &FramePlan {
        &self.plan
    }

    /// The final visibility image of the plan (`R32_SFLOAT`, 1 = lit), in `UnorderedAccess` state after
    /// [`ShadowPipeline::record`]. The engine may transition or copy it; the next `record` rewrites it.
    pub fn output(&self) -> &Image {
        match self.image(self.plan.final_output()) {
            Some(image) => image,
            // `new` returns an error rather than a pipeline whose plan's final output is not allocated.
            None => unreachable!("the final output is allocated by ShadowPipeline::new"),
        }
    }

    /// The image holding `resource`, if the plan allocated it (screen-space and light-space images).
    pub fn image(&self, resource: ResourceId) -> Option<&Image> {
        use ResourceId as R;
        match resource {
            R::ShadowMap => self.shadow_map.as_ref().map(|s| &s.depth),
            R::Occupancy => self.map.as_ref().and_then(PrimitiveMap::occupancy_view),
            R::RtVisibility => self.ray.as_ref().map(|r| &r.visibility),
            R::BlockerDistance => self.ray.as_ref().map(|r| &r.blocker_distance),
            R::ShadowMapVisibility => self.shadow_map_test.as_ref().map(|p| &p.output),
            R::Pcss => self.pcss.as_ref().map(|p| &p.output),
            R::RtAntialiased => self.fxaa.as_ref().map(|f| &f.output),
            R::LerpFactor => self.lerp.as_ref().map(|l| &l.output),
            R::Hybrid => self.blend.as_ref().map(|b| &b.output),
            R::Lit => self.lit.as_ref(),
            R::SceneGeometry
            | R::Light
            | R::Depth
            | R::Normal
            | R::PrimBuffer
            | R::PrimListOffsets
            | R::PrimListEntries => None,
        }
    }

    /// The buffer holding `resource`, if the plan allocated it: the primitive map's list offsets
    /// (N² + 1 `u32`: texel t's list is `entries[offsets[t] .. offsets[t + 1]]`) and list entries.
    pub fn buffer(&self, resource: ResourceId) -> Option<&Buffer> {
        match resource {
            ResourceId::PrimListOffsets => self.map.as_ref().map(|m| &m.offsets),
            ResourceId::PrimListEntries => self.map.as_ref().map(|m| &m.entries),
            ResourceId::PrimBuffer => self.prims(),
            _ => None,
        }
    }

    /// Bytes of `resource` if the pipeline allocated it.
    fn resource_bytes(&self, resource: ResourceId) -> Option<u64> {
        match resource {
            ResourceId::PrimListOffsets => self.map.as_ref().map(|m| {
                m.bytes() - m.entries.size() - m.occupancy_view().map_or(0, Image::byte_size)
            }),
            r => self
                .buffer(r)
                .map(Buffer::size)
                .or_else(|| self.image(r).map(Image::byte_size)),
        }
    }

    /// The prim buffer (triangles in frame coordinates), if the plan has it.
    pub fn prims(&self) -> Option<&Buffer> {
        self.plan
            .runs(PassId::PrimBuffer)
            .then(|| self.shared.prims())
    }

    /// The geometry.
    pub fn geometry(&self) -> &Geometry {
        self.shared.geometry()
    }

    /// The geometry and prim buffer this pipeline shares with other lights' pipelines.
    pub fn shared_geometry(&self) -> &Arc<SharedGeometry> {
        &self.shared
    }

    /// GPU objects replaced (by the map's growth) and held until the frames that used them completed.
    pub fn retired_objects(&self) -> usize {
        self.retired.len()
    }

    /// The primitive map, if the plan has it.
    pub fn primitive_map(&self) -> Option<&PrimitiveMap> {
        self.map.as_ref()
    }

    /// The ray-trace outputs, if the plan has them.
    pub fn ray_trace(&self) -> Option<&RayTracePass> {
        self.ray.as_ref()
    }

    /// Camera-relative view-projection and the camera in frame coordinates (for a host G-buffer that
    /// rasterizes the prim buffer).
    pub fn camera_in_frame(&self, inputs: &FrameInputs) -> Result<(Mat4, Vec3), PassError> {
        camera_in_frame(inputs, self.geometry().origin())
    }

    fn constants(&self, inputs: &FrameInputs) -> Result<FrameConstants, PassError> {
        let origin = self.geometry().origin();
        let (_, camera_frame) = camera_in_frame(inputs, origin)?;
        let inv_view_proj_rel = camera_relative(inputs).inverse().as_mat4();
        let light = LightFrame::new(&inputs.light, origin)?;
        if !inv_view_proj_rel.is_finite() {
            return Err(PassError::InvalidConfig(
                "camera matrices are not finite or invertible".into(),
            ));
        }
        let cfg = self.config.map;
        if light.position.is_some() && cfg.faces == FaceMode::FrontOnly {
            return Err(PassError::InvalidConfig(
                "a front-only primitive map needs a directional light: store both faces for a spot light"
                    .into(),
            ));
        }
        let radians_per_pixel = (2.0 / (inputs.proj.y_axis.y * self.height as f32)).abs();
        let front_only = u32::from(cfg.faces == FaceMode::FrontOnly);
        let dir = light.direction;
        let sm = self.config.shadow_map;
        let pc = self.config.pcss;
        Ok(FrameConstants {
            light,
            map: MapPush {
                light_view_proj: light.view_proj,
                to_light: (-dir).extend(if light.position.is_some() { 1.0 } else { 0.0 }),
                size: cfg.size,
                front_only,
                ..MapPush::zeroed()
            },
            ray: RayTraceConstants {
                inv_view_proj_rel,
                light_view_proj: light.view_proj,
                camera_pos: camera_frame.extend(1.0),
                light_dir: dir.extend(0.0),
                dims: UVec4::new(self.width, self.height, cfg.size, 0),
                offset: Vec4::new(
                    radians_per_pixel,
                    RAY_OFFSET_PIXELS,
                    RAY_OFFSET_FLOAT_BOUND,
                    0.0,
                ),
                misc: UVec4::new(front_only, self.geometry().triangle_count(), 0, 0),
                light_pos: light.position.map_or(Vec4::ZERO, |p| p.extend(1.0)),
            },
            pcss: PcssConstants {
                inv_view_proj_rel,
                camera_pos: camera_frame.extend(radians_per_pixel),
                dims: UVec4::new(self.width, self.height, sm.size, 0),
                taps: UVec4::new(pc.blocker_search_taps, pc.pcf_taps, 0, 0),
                radii: Vec4::new(
                    pc.max_search_radius,
                    pc.min_filter_radius,
                    pc.max_filter_radius,
                    0.0,
                ),
                bias: Vec4::new(
                    sm.constant_bias,
                    sm.slope_bias,
                    PLANE_TOLERANCE_TEXELS,
                    CONSTANT_TOLERANCE_TEXELS,
                ),
                light: light.gpu(sm.size, pc.light_size(light.position.is_some())),
            },
        })
    }

    /// Plans the next frame (its index one past the last begun, 0 at first): see
    /// [`ShadowPipeline::begin_frame_at`].
    pub fn begin_frame(&mut self, inputs: &FrameInputs) -> Result<(), PassError> {
        let index = self.last_frame.map_or(0, |f| f + 1);
        self.begin_frame_at(inputs, index)
    }

    /// Plans frame `index` (no commands): computes its constants and decides which passes run and which are
    /// skipped as up to date. Then [`ShadowPipeline::record_passes`] records them, in one call or several,
    /// in linear order.
    ///
    /// Frames in flight: indices increase from frame to frame (gaps are allowed), and beginning frame
    /// `index` states that the recordings of every frame up to `index - frames_in_flight` have completed on
    /// the GPU. Beginning the frame being recorded again (the same index) abandons it, as does beginning a
    /// later one before it was recorded to its end: the outputs of its unrecorded passes count as stale.
    pub fn begin_frame_at(&mut self, inputs: &FrameInputs, index: u64) -> Result<(), PassError> {
        let open = self.frame.as_ref().map(|f| (f.index, f.records_prims));
        let reopening = open.is_some_and(|(i, _)| i == index);
        if let Some(last) = self
            .last_frame
            .filter(|&last| index < last || (index == last && !reopening))
        {
            return Err(PassError::InvalidConfig(format!(
                "frame index {index} does not follow the last frame begun ({last}): frame indices must increase"
            )));
        }
        if index == u64::MAX {
            return Err(PassError::InvalidConfig(
                "frame index u64::MAX is reserved".into(),
            ));
        }
        let constants = self.constants(inputs)?;
        if let Some(open) = self.frame.take() {
            for &(pass, status) in &self.statuses[open.next..] {
                if status == PassStatus::Ran {
                    self.valid = self.valid.difference(self.plan.writes(pass));
                }
            }
        }
        let frames = self.config.frames_in_flight;
        self.retired
            .release_completed(completed_before(index, frames));
        let slot = (index % u64::from(frames)) as usize;
        if !reopening {
            // The newest completed frame's map state says how many list entries the map needed, which the
            // next build grows to: the frame that used this slot before has completed (the contract), and
            // a later one may have too (its completion marker says so).
            if let Some(state) = self.newest_completed_map_state(completed_before(index, frames))? {
                self.needed_entries = state.totals.y;
            }
        }
        let claim = match (self.plan.runs(PassId::PrimBuffer), open) {
            (false, _) => PrimBufferClaim::UpToDate,
            (true, Some((_, true))) if reopening => PrimBufferClaim::Record,
            (true, _) => self.shared.claim(index),
        };
        let mut changed = ResourceSet::of(&[ResourceId::Depth, ResourceId::Normal]);
        if claim != PrimBufferClaim::UpToDate {
            changed = changed.with(ResourceId::SceneGeometry);
        }
        if !self.config.static_light || self.maps_light != Some(inputs.light) {
            changed = changed.with(ResourceId::Light);
        }
        let prims = ResourceSet::of(&[ResourceId::PrimBuffer]);
        self.valid = if self.shared.is_built() {
            self.valid.union(prims)
        } else {
            self.valid.difference(prims)
        };
        self.statuses = self.plan.schedule(changed, self.valid);
        if claim == PrimBufferClaim::RebuiltByAnother {
            self.statuses[PassId::PrimBuffer as usize].1 = PassStatus::Skipped(SkipReason::Shared);
        }
        let s = &mut self.slots[slot];
        s.frame = Some(index);
        s.map_state_recorded = false;
        s.statuses = self.statuses.clone();
        self.last_frame = Some(index);
        self.frame = Some(FrameState {
            constants,
            light: inputs.light,
            index,
            slot,
            records_prims: claim == PrimBufferClaim::Record,
            next: 0,
            timer_started: false,
            marked: false,
        });
        Ok(())
    }

    /// The passes the current frame runs and has not recorded yet.
    pub fn passes_to_record(&self) -> Vec<PassId> {
        self.frame.as_ref().map_or_else(Vec::new, |f| {
            self.statuses[f.next..]
                .iter()
                .filter(|(_, s)| *s == PassStatus::Ran)
                .map(|&(p, _)| p)
                .collect()
        })
    }

    /// Records `passes` of the frame begun by [`ShadowPipeline::begin_frame`] (those the frame skips
    /// record nothing). Calls go forward through the linear order: every pass requested must come after
    /// those of earlier calls of the frame, and every pass the frame runs up to the last one requested
    /// must be requested. Calls may use different command buffers submitted in recording order; the
    /// first one resets the GPU timer, later ones (even with no pass) go on timing into it.
    ///
    /// States: depth and normal must be in `ShaderResource` state for the screen-space passes (ray trace,
    /// shadow-map test, PCSS); every image a pass writes is left in `UnorderedAccess` state (the shadow
    /// map in `ShaderResource`), [`ShadowPipeline::output`] included.
    ///
    /// Contract: the frames-in-flight rule of [`ShadowPipeline::begin_frame_at`] (constants go into the
    /// command buffer; read-backs have one slot per frame in flight), and every recording is submitted:
    /// passes skipped as up to date reuse what the recording that last ran them wrote.
    pub fn record_passes(
        &mut self,
        enc: &mut Encoder<'_>,
        passes: &[PassId],
    ) -> Result<(), PassError> {
        let Some(mut frame) = self.frame.take() else {
            return Err(PassError::InvalidConfig(
                "no frame: call begin_frame first".into(),
            ));
        };
        let outcome = self.record_forward(enc, &mut frame, passes);
        self.frame = Some(frame);
        outcome
    }

    /// Records every pass of a frame: [`ShadowPipeline::begin_frame`], then
    /// [`ShadowPipeline::record_passes`] of the whole linear order.
    pub fn record(&mut self, enc: &mut Encoder<'_>, inputs: &FrameInputs) -> Result<(), PassError> {
        self.begin_frame(inputs)?;
        self.record_passes(enc, PassId::ALL)
    }

    /// Makes the allocations the frame's recording of `passes` needs (the primitive map's lists growing
    /// to what earlier frames needed), so that [`ShadowPipeline::record_passes`] allocates nothing: a
    /// host that records several pipelines into one command buffer can fail before any of them records.
    pub fn prepare_record(&mut self, device: &Device, passes: &[PassId]) -> Result<(), PassError> {
        let index = match &self.frame {
            Some(frame) => frame.index,
            None => {
                return Err(PassError::InvalidConfig(
                    "no frame: call begin_frame first".into(),
                ))
            }
        };
        if passes.contains(&PassId::PrimitiveMap) && self.plan.runs(PassId::PrimitiveMap) {
            self.grow_map(device, index)?;
        }
        Ok(())
    }

    /// Whether [`ShadowPipeline::record_passes`] would accept `passes` now (without recording anything).
    pub fn check_record(&self, passes: &[PassId]) -> Result<(), PassError> {
        let frame = self
            .frame
            .as_ref()
            .ok_or_else(|| PassError::InvalidConfig("no frame: call begin_frame first".into()))?;
        self.check_forward(frame, passes)
    }

    /// The order checks of a recording call: passes after those already recorded, none that runs left out.
    fn check_forward(&self, frame: &FrameState, passes: &[PassId]) -> Result<(), PassError> {
        if let Some(&first) = passes.iter().min().filter(|&&p| (p as usize) < frame.next) {
            return Err(PassError::InvalidConfig(format!(
                "pass '{}' comes before a pass already recorded this frame: record passes in linear order",
                first.name()
            )));
        }
        let runs = |p: PassId| self.statuses[p as usize].1 == PassStatus::Ran;
        if let Some(last) = passes.iter().max() {
            if let Some(missing) = PassId::ALL[frame.next..=*last as usize]
                .iter()
                .find(|&&p| runs(p) && !passes.contains(&p))
            {
                return Err(PassError::InvalidConfig(format!(
                    "pass '{}' runs this frame: record it (it comes before '{}')",
                    missing.name(),
                    last.name()
                )));
            }
        }
        Ok(())
    }

    fn record_forward(
        &mut self,
        enc: &mut Encoder<'_>,
        frame: &mut FrameState,
        passes: &[PassId],
    ) -> Result<(), PassError> {
        self.check_forward(frame, passes)?;
        let last = passes.iter().max().copied();
        let statuses = self.statuses.clone();
        let runs = |p: PassId| statuses[p as usize].1 == PassStatus::Ran;
        // Checked: from here on the call records.
        let timer = &self.slots[frame.slot].timer;
        if frame.timer_started {
            enc.continue_timer(timer);
        } else {
            // The frame's first recording: separate it from the earlier frames in flight that used the same
            // resources (write-after-read and write-after-write across frames).
            enc.barriers(&[Barrier::Full]);
            enc.attach_timer(timer);
            frame.timer_started = true;
        }
        let Some(last) = last else {
            return self.mark_if_finished(enc, frame);
        };
        for &pass in &PassId::ALL[frame.next..=last as usize] {
            if runs(pass) {
                self.record_pass(enc, pass, frame)?;
                self.valid = self.valid.union(self.plan.writes(pass));
                if matches!(pass, PassId::ShadowMap | PassId::PrimitiveMap) {
                    self.maps_light = Some(frame.light);
                }
            }
            frame.next = pass as usize + 1;
        }
        self.flush_uav(enc);
        self.mark_if_finished(enc, frame)
    }

    /// Once no pass of the frame is left to record, has the GPU mark the slot with the frame after
    /// everything recorded before, so a report can tell whether the frame has completed without a fence.
    fn mark_if_finished(
        &mut self,
        enc: &mut Encoder<'_>,
        frame: &mut FrameState,
    ) -> Result<(), PassError> {
        let finished = self.statuses[frame.next..]
            .iter()
            .all(|&(_, s)| s != PassStatus::Ran);
        if !finished || frame.marked {
            return Ok(());
        }
        frame.marked = true;
        let marker = (frame.index + 1).to_le_bytes();
        enc.barriers(&[Barrier::Full]);
        enc.update_buffer(&self.slots[frame.slot].completion, 0, &marker)?;
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        Ok(())
    }

    /// Makes the storage writes of the passes recorded since the last UAV barrier visible.
    fn flush_uav(&mut self, enc: &mut Encoder<'_>) {
        if self.pending_uav.take().is_some() {
            enc.barriers(&[Barrier::Uav]);
        }
    }

    /// Discards the screen-space outputs of `pass` and makes them UAVs.
    fn outputs_to_uav(&self, enc: &mut Encoder<'_>, pass: PassId) {
        let to_uav: Vec<Barrier<'_>> = self
            .plan
            .writes(pass)
            .iter()
            .filter_map(|r| self.image(r))
            .map(|image| Barrier::Image {
                image,
                before: S::Undefined,
                after: S::UnorderedAccess,
            })
            .collect();
        enc.barriers(&to_uav);
    }

    /// Records one pass with the barriers around it. A UAV barrier precedes a pass that reads what
    /// earlier passes wrote since the last one; the screen-space passes that do not read each other's
    /// outputs (shadow-map test, PCSS, FXAA, lerp factor) share one after them.
    fn record_pass(
        &mut self,
        enc: &mut Encoder<'_>,
        pass: PassId,
        frame: &FrameState,
    ) -> Result<(), PassError> {
        let c = &frame.constants;
        let independent = matches!(
            pass,
            PassId::ShadowMapTest | PassId::Pcss | PassId::Fxaa | PassId::LerpFactor
        );
        let reads_pending = self
            .pending_uav
            .is_some_and(|written| self.plan.reads(pass).intersects(written));
        if !independent || reads_pending {
            self.flush_uav(enc);
        }
        let tris = self.geometry().triangle_count();
        match pass {
            PassId::PrimBuffer => {
                if frame.records_prims {
                    self.shared.record(enc)?;
                }
            }
            PassId::ShadowMap => {
                if let Some(sm) = &self.shadow_map {
                    let push = ShadowMapPush {
                        light_view_proj: c.light.view_proj,
                    };
                    sm.record(enc, &push, tris)?;
                }
            }
            PassId::PrimitiveMap => {
                self.grow_map(enc.device(), frame.index)?;
                if let Some(map) = self.map.as_mut() {
                    map.record(enc, &c.ray, &c.map)?;
                }
            }
            PassId::Occupancy => {
                if let Some(map) = &self.map {
                    let slot = &mut self.slots[frame.slot];
                    map.record_occupancy(enc, &slot.stats_readback)?;
                    slot.map_state_recorded = true;
                }
            }
            PassId::RayTrace => {
                self.outputs_to_uav(enc, pass);
                if let Some(ray) = self.ray.as_mut() {
                    ray.record(enc, &c.ray)?;
                }
            }
            PassId::ShadowMapTest => {
                self.outputs_to_uav(enc, pass);
                if let Some(p) = self.shadow_map_test.as_mut() {
                    p.record(enc, &c.pcss)?;
                }
            }
            PassId::Pcss => {
                self.outputs_to_uav(enc, pass);
                if let Some(p) = self.pcss.as_mut() {
                    p.record(enc, &c.pcss)?;
                }
            }
            PassId::Fxaa => {
                self.outputs_to_uav(enc, pass);
                if let Some(f) = &self.fxaa {
                    f.record(enc)?;
                }
            }
            PassId::LerpFactor => {
                self.outputs_to_uav(enc, pass);
                if let Some(l) = &self.lerp {
                    l.record(enc, &self.config.hybrid)?;
                }
            }
            PassId::Blend => {
                self.outputs_to_uav(enc, pass);
                if let Some(b) = &self.blend {
                    b.record(enc, &self.config.hybrid)?;
                }
            }
            PassId::FillLit => {
                if let Some(lit) = &self.lit {
                    record_fill_lit(enc, lit);
                }
            }
        }
        self.pending_uav = Some(
            self.pending_uav
                .unwrap_or(ResourceSet::EMPTY)
                .union(self.plan.writes(pass)),
        );
        Ok(())
    }

    /// Timings and statistics of the last frame begun, waiting for its GPU timestamps; call after its
    /// submission was made.
    pub fn report(&self) -> Result<FrameReport, PassError> {
        let slot = self.slot_of(self.last_frame)?;
        let timings = slot.timer.resolve()?;
        if !self
            .last_frame
            .is_some_and(|f| slot_completed(slot, f).unwrap_or(false))
        {
            return Err(PassError::InvalidConfig(
                "the last frame has not completed: report after its submission finished".into(),
            ));
        }
        self.report_with(slot, timings)
    }

    /// [`ShadowPipeline::report`] without waiting: `None` while the GPU has not finished the frame.
    pub fn try_report(&self) -> Result<Option<FrameReport>, PassError> {
        self.try_report_frame(self.last_frame.unwrap_or(u64::MAX))
    }

    /// The report of frame `index` if the GPU has finished it (`None` while not), from the ring of the last
    /// `frames_in_flight` frames begun; an error for a frame no longer (or never) in the ring.
    pub fn try_report_frame(&self, index: u64) -> Result<Option<FrameReport>, PassError> {
        let slot = self.slot_of(Some(index))?;
        if !slot_completed(slot, index)? {
            return Ok(None);
        }
        match slot.timer.try_resolve()? {
            Some(timings) => self.report_with(slot, timings).map(Some),
            None => Ok(None),
        }
    }

    fn slot_of(&self, index: Option<u64>) -> Result<&FrameSlot, PassError> {
        let frames = u64::from(self.config.frames_in_flight);
        index
            .and_then(|i| {
                self.slots
                    .get((i % frames) as usize)
                    .filter(|s| s.frame == Some(i))
            })
            .ok_or_else(|| {
                PassError::InvalidConfig(match (index, self.last_frame) {
                    (Some(i), Some(last)) => format!(
                        "frame {i} is not among the last {frames} frames begun (the last is {last})"
                    ),
                    _ => "no frame has been begun".into(),
                })
            })
    }

    /// The map state a slot's frame read back, once that frame has completed (the caller's contract).
    /// The map state of the newest frame in the ring that built the map and has completed: by the caller's
    /// contract (up to `completed`), or by its completion marker.
    fn newest_completed_map_state(
        &self,
        completed: Option<u64>,
    ) -> Result<Option<MapState>, PassError> {
        let mut newest: Option<(u64, &FrameSlot)> = None;
        for s in &self.slots {
            let Some(frame) = s.frame.filter(|_| s.map_state_recorded) else {
                continue;
            };
            let done = completed.is_some_and(|c| frame <= c) || slot_completed(s, frame)?;
            if done && newest.is_none_or(|(f, _)| frame > f) {
                newest = Some((frame, s));
            }
        }
        newest
            .map(|(_, s)| Ok(bytemuck::pod_read_unaligned(s.stats_readback.read()?)))
            .transpose()
    }

    /// Grows the primitive map's entries to what the newest completed build needed, and rebinds the ray
    /// trace to them; the replaced objects are held until the frames before `frame` completed.
    fn grow_map(&mut self, device: &Device, frame: u64) -> Result<(), PassError> {
        let Some(map) = self.map.as_mut() else {
            return Ok(());
        };
        if let Some((entries, bin_group)) = map.grow(device, self.needed_entries)? {
            let ray_group = match self.ray.as_mut() {
                Some(ray) => Some(ray.rebind_entries(device, map)?),
                None => None,
            };
            let retired = RetiredMapEntries {
                _entries: entries,
                _bin_group: bin_group,
                _ray_group: ray_group,
            };
            if let Some(last_user) = frame.checked_sub(1) {
                self.retired.retire(last_user, retired);
            }
        }
        Ok(())
    }

    fn report_with(
        &self,
        slot: &FrameSlot,
        timings: Vec<PassTiming>,
    ) -> Result<FrameReport, PassError> {
        let state = match slot.map_state_recorded {
            true => bytemuck::pod_read_unaligned(slot.stats_readback.read()?),
            false => MapState::zeroed(),
        };
        let resources = self
            .plan
            .resources()
            .iter()
            .filter_map(|r| {
                self.resource_bytes(r)
                    .map(|bytes| ResourceReport { resource: r, bytes })
            })
            .collect();
        Ok(FrameReport {
            timings,
            binning_path: self.binning_path,
            stats: MapStats::from_state(&state),
            map_to_texels: state.to_texels,
            passes: slot.statuses.clone(),
            resources,
            output: self.plan.final_output(),
        })
    }
}

/// Camera-relative view-projection (view translated to the camera in f64) and the camera position in
/// the coordinates of the frame whose origin is `origin`: what a G-buffer rasterizing the prim buffer
/// (triangles relative to `origin`) needs.
pub fn camera_in_frame(inputs: &FrameInputs, origin: DVec3) -> Result<(Mat4, Vec3), PassError> {
    let view_proj_rel = camera_relative(inputs).as_mat4();
    let camera_frame = (inputs.camera_position.as_dvec3() - origin).as_vec3();
    if !view_proj_rel.is_finite() || !camera_frame.is_finite() {
        return Err(PassError::InvalidConfig(
            "camera matrices are not finite".into(),
        ));
    }
    Ok((view_proj_rel, camera_frame))
}

/// The view-projection of coordinates relative to the camera, in f64.
fn camera_relative(inputs: &FrameInputs) -> DMat4 {
    inputs.proj.as_dmat4() * rebased(inputs.view, inputs.camera_position.as_dvec3())
}

/// Whether the GPU has run frame `frame`'s recording in `slot` to its end (its completion marker).
fn slot_completed(slot: &FrameSlot, frame: u64) -> Result<bool, PassError> {
    Ok(slot.completion.read_u64_volatile(0)? == frame.wrapping_add(1))
}

/// Fills the lit image (mode none) with 1 and leaves it in `UnorderedAccess` state.
fn record_fill_lit(enc: &mut Encoder<'_>, lit: &Image) {
    enc.begin_pass(PassId::FillLit.name());
    enc.barriers(&[Barrier::Image {
        image: lit,
        before: S::Undefined,
        after: S::CopyDest,
    }]);
    enc.clear_uint(lit, 1.0f32.to_bits());
    enc.barriers(&[Barrier::Image {
        image: lit,
        before: S::CopyDest,
        after: S::UnorderedAccess,
    }]);
    enc.end_pass();
}

/// PCSS receiver-plane tolerance, in texels of the receiver plane's depth slope: covers the rasterizer's
/// sub-texel vertex snapping (1/256 texel) with margin.
const PLANE_TOLERANCE_TEXELS: f32 = 1.0 / 16.0;
/// PCSS constant tolerance, in texels of world size at the receiver.
const CONSTANT_TOLERANCE_TEXELS: f32 = 1.0 / 32.0;
