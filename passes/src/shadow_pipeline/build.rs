//! Creating a pipeline: the passes and resources its frame plan needs.

use super::{FrameSlot, ShadowConfig, ShadowInputs, ShadowPipeline};
use crate::frame_plan::{
    FramePlan, HardEdge, PassId, PenumbraFilter, ResourceId, ResourceSet, ShadowMode,
};
use crate::fxaa::FxaaPass;
use crate::gpu_types::MapState;
use crate::hybrid::{BlendPass, LerpFactorPass};
use crate::pcss::{PcssInputs, PcssKind, PcssPass};
use crate::prim_buffer::{Geometry, SharedGeometry};
use crate::primitive_map::{choose_binning_path, BinningPath, PrimitiveMap, PrimitiveMapInputs};
use crate::ray_trace::{RayTraceInputs, RayTraceKind, RayTracePass};
use crate::retire::RetireQueue;
use crate::retire::MAX_FRAMES_IN_FLIGHT;
use crate::screen_pass::visibility_image;
use crate::shadow_map::ShadowMapPass;
use crate::surface::NormalEncoding;
use crate::PassError;
use rhi::{BufferUsage, Device, MemoryLocation};
use std::sync::Arc;

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
        let derived = inputs.surface.encoding == NormalEncoding::FromDepth;
        if !derived && (inputs.normal.width(), inputs.normal.height()) != (width, height) {
            return Err(PassError::InvalidConfig(
                "depth and normal images differ in size".into(),
            ));
        }
        if derived && crate::surface::view_z_precision(inputs.depth.format()) > 0.0 {
            return Err(PassError::InvalidConfig(
                "normals derived from depth need the projection's depth, not a view-Z image: give the engine's normals"
                    .into(),
            ));
        }
        if !inputs.surface.accepts(inputs.normal.format()) {
            return Err(PassError::InvalidConfig(format!(
                "a normal image of {:?} cannot hold {:?} normals",
                inputs.normal.format(),
                inputs.surface.encoding
            )));
        }
        if config.mode == ShadowMode::Auto {
            return Err(PassError::InvalidConfig(
                "mode auto is chosen per light by its size: build the pipeline for the light's resolved \
                 configuration (ShadowConfig::resolved)"
                    .into(),
            ));
        }
        let caps = device.capabilities();
        config.map.validate(caps)?;
        config.shadow_map.validate(caps)?;
        if config.mode == ShadowMode::Area {
            // The light's size is checked per frame: a directional light's angular radius, a spot or
            // point light's emitter radius.
            config.area.validate_samples()?;
            if choose_binning_path(caps, config.map.binning)? != BinningPath::Compute {
                return Err(PassError::InvalidConfig(
                    "area shadows widen each triangle's footprint per texel, which compute binning does: \
                     request BinningRequest::Compute or Auto"
                        .into(),
                ));
            }
        }
        config.pcss.validate()?;
        config.hybrid.validate()?;
        let plan = FramePlan::derive(config.plan_request());
        let runs = |p| plan.runs(p);
        // The final visibility goes into the engine's layer when it is written directly (not when the
        // configuration also asks to read it back: that reads the pipeline's own image).
        let final_output = plan.final_output();
        if inputs.direct_output.is_some() && config.extra_outputs.contains(final_output) {
            return Err(PassError::InvalidConfig(format!(
                "the final output ({}) is written into the engine's image directly and cannot also be read back",
                final_output.name()
            )));
        }
        let mut direct = inputs
            .direct_output
            .map(|image| direct_output(image, width, height))
            .transpose()?;
        let mut direct_for = |resource: ResourceId| {
            if resource == final_output {
                direct.take()
            } else {
                None
            }
        };

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
        let scratch_set = inputs.scratch_set % crate::MAP_SCRATCH_SETS;
        let map = if let Some(map_config) = config.built_map() {
            let map_inputs = PrimitiveMapInputs {
                prims: need_prims()?,
                triangles: geometry.triangle_count(),
                depth: inputs.depth,
                normal: inputs.normal,
                occupancy_view: plan.resources().contains(ResourceId::Occupancy),
                scratch: shared.map_scratch(scratch_set),
            };
            Some(PrimitiveMap::new(device, &map_inputs, map_config)?)
        } else {
            None
        };
        let binning_path = match &map {
            Some(m) => m.path(),
            None => choose_binning_path(caps, config.map.binning).unwrap_or(BinningPath::Compute),
        };
        // A ray trace whose visibility only the light's FXAA reads (hard or area shadows antialiased, not
        // read back) writes an image the lights share instead of one of its own, while each recording call
        // holds both passes ([`ShadowPipeline::is_shared`]).
        let rt_readers: Vec<PassId> = PassId::ALL
            .iter()
            .copied()
            .filter(|&p| runs(p) && plan.reads(p).contains(ResourceId::RtVisibility))
            .collect();
        let rt_shared = rt_readers == [PassId::Fxaa]
            && final_output != ResourceId::RtVisibility
            && !config.extra_outputs.contains(ResourceId::RtVisibility);
        let ray_visibility = if rt_shared {
            let image = shared.antialias_source(device, width, height)?;
            Some(rhi::Image::alias_shared(&image)?)
        } else {
            direct_for(ResourceId::RtVisibility)
        };
        let ray = match (&map, runs(PassId::RayTrace)) {
            (Some(m), true) => Some(RayTracePass::new(
                device,
                &RayTraceInputs {
                    depth: inputs.depth,
                    normal: inputs.normal,
                    map: m,
                    prims: need_prims()?,
                    bvh: shared.bvh().nodes(),
                    ray_bvh: shared.bvh().ray_nodes(),
                },
                width,
                height,
                if config.mode == ShadowMode::Area {
                    RayTraceKind::Area {
                        angular_radius: config.pcss.angular_radius,
                        samples: config.area.samples,
                    }
                } else {
                    RayTraceKind::Hard {
                        blocker_distance: plan
                            .writes(PassId::RayTrace)
                            .contains(ResourceId::BlockerDistance),
                    }
                },
                ray_visibility,
            )?),
            _ => None,
        };
        let pcss_pass = |kind, output| -> Result<Option<PcssPass>, PassError> {
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
                (width, height),
                output,
            )
            .map(Some)
        };
        let shadow_map_test = if runs(PassId::ShadowMapTest) {
            pcss_pass(
                PcssKind::ClassicTest,
                direct_for(ResourceId::ShadowMapVisibility),
            )?
        } else {
            None
        };
        let edge = match (config.pcss.filter, plan.hard_edge()) {
            (PenumbraFilter::Shrinking, HardEdge::RayTrace) => HardEdge::RayTrace,
            _ => HardEdge::ShadowMap,
        };
        let pcss = if runs(PassId::Pcss) {
            pcss_pass(PcssKind::Pcss(edge), direct_for(ResourceId::Pcss))?
        } else {
            None
        };
        let fxaa = match (&ray, runs(PassId::Fxaa)) {
            (Some(r), true) => Some(FxaaPass::new(
                device,
                &r.visibility,
                direct_for(ResourceId::RtAntialiased),
            )?),
            _ => None,
        };
        let lerp = match (&ray, runs(PassId::LerpFactor)) {
            (
                Some(RayTracePass {
                    blocker_distance: Some(blocker),
                    ..
                }),
                true,
            ) => Some(LerpFactorPass::new(device, blocker)?),
            _ => None,
        };
        let blend = if runs(PassId::Blend) {
            let rts = if config.antialiasing {
                fxaa.as_ref().map(|f| &f.output)
            } else {
                ray.as_ref().map(|r| &r.visibility)
            };
            match (rts, &pcss, &lerp) {
                (Some(rts), Some(p), Some(l)) => Some(BlendPass::new(
                    device,
                    rts,
                    &p.output,
                    &l.output,
                    direct_for(ResourceId::Hybrid),
                )?),
                _ => None,
            }
        } else {
            None
        };
        let lit = if runs(PassId::FillLit) {
            match direct_for(ResourceId::Lit) {
                Some(image) => Some(image),
                None => Some(visibility_image(device, "lit", width, height)?),
            }
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
                        u64::from(config.map.frusta()) * std::mem::size_of::<MapState>() as u64,
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
            needed_pairs: 0,
            retired: RetireQueue::default(),
            pending_uav: None,
            statuses: Vec::new(),
            width,
            height,
            depth_format: inputs.depth.format(),
            surface_mode: inputs.surface.mode(inputs.normal.format()),
            normal_precision: inputs.surface.normal_precision(inputs.normal.format()),
            rt_shared,
            scratch_set,
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
}

/// The pipeline's own handle on the engine's image its final pass writes, checked against what that pass
/// writes.
fn direct_output(image: &rhi::Image, width: u32, height: u32) -> Result<rhi::Image, PassError> {
    let written = [
        rhi::Format::R32Float,
        rhi::Format::R16Float,
        rhi::Format::R8Unorm,
    ];
    if !written.contains(&image.format())
        || image.layers() != 1
        || (image.width(), image.height()) != (width, height)
        || !image.usage().contains(rhi::ImageUsage::STORAGE)
    {
        return Err(PassError::InvalidConfig(format!(
            "an output written directly must be one R32_SFLOAT, R16_SFLOAT or R8_UNORM layer of {width}x{height} with storage usage, not {:?} {}x{}x{}",
            image.format(),
            image.width(),
            image.height(),
            image.layers()
        )));
    }
    Ok(image.alias()?)
}
