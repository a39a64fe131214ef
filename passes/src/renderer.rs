//! The demo host's frame: prim buffer → G-buffer → [`ShadowPipeline`], submitted and waited for, with
//! read-back of every output the plan produced.

use crate::frame_plan::{PassId, ResourceId};
use crate::gbuffer::{GBufferPass, GBufferTargets};
use crate::gpu_types::GBufferPush;
use crate::prim_buffer::Geometry;
use crate::shadow_pipeline::{
    FrameInputs, FrameReport, ShadowConfig, ShadowInputs, ShadowPipeline,
};
use crate::PassError;
use glam::DVec3;
use rhi::{Barrier, BufferUsage, Device, Image, MemoryLocation, ResourceState as S};

/// Everything the frame produced, read back to the host. Row-major, y = 0 at the top. Outputs the plan
/// did not produce are empty.
pub struct FrameImages {
    /// World position (frame origin added back in f64), w = 1 on geometry.
    pub position: Vec<[f32; 4]>,
    /// Camera-facing normal, w = 1 on geometry.
    pub normal: Vec<[f32; 4]>,
    /// Reversed-Z depth.
    pub depth: Vec<f32>,
    /// Ray-traced visibility (1 = lit).
    pub visibility: Vec<f32>,
    /// Blocker distance (see [`crate::ray_trace::RayTracePass::blocker_distance`]).
    pub blocker_distance: Vec<f32>,
    /// Occupancy view, N×N RGBA8.
    pub occupancy: Vec<[u8; 4]>,
    /// Count map, N×N.
    pub counts: Vec<u32>,
    /// Index map, layer-major: `indices[(slot * N + y) * N + x]`; empty unless requested.
    pub indices: Vec<u32>,
    /// Classic single-tap shadow-map visibility.
    pub shadow_map_visibility: Vec<f32>,
    /// PCSS visibility.
    pub pcss: Vec<f32>,
    /// Ray-traced visibility after FXAA.
    pub antialiased: Vec<f32>,
    /// Hybrid lerp factor.
    pub lerp_factor: Vec<f32>,
    /// Hybrid visibility.
    pub hybrid: Vec<f32>,
    /// The pipeline's final output ([`ShadowPipeline::output`]).
    pub output: Vec<f32>,
}

/// The demo frame: a G-buffer of its own plus the engine-facing [`ShadowPipeline`].
pub struct ShadowRenderer {
    targets: GBufferTargets,
    gbuffer: GBufferPass,
    pipeline: ShadowPipeline,
}

impl ShadowRenderer {
    /// Creates every pass for a `width` x `height` frame over `geometry`. The plan of `config` also keeps
    /// the prim buffer, which this G-buffer rasterizes.
    pub fn new(
        device: &Device,
        geometry: Geometry,
        width: u32,
        height: u32,
        config: impl Into<ShadowConfig>,
    ) -> Result<Self, PassError> {
        if width == 0 || height == 0 {
            return Err(PassError::InvalidConfig(
                "frame size must be non-zero".into(),
            ));
        }
        let mut config = config.into();
        config.extra_outputs = config.extra_outputs.with(ResourceId::PrimBuffer);
        let targets = GBufferTargets::new(device, width, height)?;
        let inputs = ShadowInputs {
            depth: &targets.depth,
            normal: &targets.normal,
        };
        let pipeline = ShadowPipeline::new(device, geometry, &inputs, config)?;
        let prims = pipeline.prims().ok_or_else(|| {
            PassError::InvalidConfig("the demo G-buffer needs the prim buffer".into())
        })?;
        let gbuffer = GBufferPass::new(device, prims)?;
        Ok(Self {
            targets,
            gbuffer,
            pipeline,
        })
    }

    /// The engine-facing pipeline.
    pub fn pipeline(&self) -> &ShadowPipeline {
        &self.pipeline
    }

    /// Renders one frame and waits for it.
    pub fn render(
        &mut self,
        device: &Device,
        inputs: &FrameInputs,
    ) -> Result<FrameReport, PassError> {
        let (view_proj_rel, camera_frame) = self.pipeline.camera_in_frame(inputs)?;
        let push = GBufferPush {
            view_proj_rel,
            camera_pos: camera_frame.extend(1.0),
        };
        let tris = self.pipeline.geometry().triangle_count();
        let Self {
            targets,
            gbuffer,
            pipeline,
        } = self;
        pipeline.begin_frame(inputs)?;
        device.submit_and_wait(|enc| {
            let (prim_buffer, rest) = PassId::ALL.split_at(1);
            pipeline.record_passes(enc, prim_buffer).map_err(into_rhi)?;
            enc.barriers(&[
                Barrier::Image {
                    image: &targets.position,
                    before: S::Undefined,
                    after: S::RenderTarget,
                },
                Barrier::Image {
                    image: &targets.normal,
                    before: S::Undefined,
                    after: S::RenderTarget,
                },
                Barrier::Image {
                    image: &targets.depth,
                    before: S::Undefined,
                    after: S::DepthWrite,
                },
            ]);
            gbuffer
                .record(enc, targets, &push, tris)
                .map_err(into_rhi)?;
            enc.barriers(&[
                Barrier::Image {
                    image: &targets.normal,
                    before: S::RenderTarget,
                    after: S::ShaderResource,
                },
                Barrier::Image {
                    image: &targets.depth,
                    before: S::DepthWrite,
                    after: S::ShaderResource,
                },
            ]);
            pipeline.record_passes(enc, rest).map_err(into_rhi)
        })?;
        self.pipeline.report()
    }

    /// Reads back the last frame's outputs (the index map only if `with_indices`).
    pub fn read_back(&self, device: &Device, with_indices: bool) -> Result<FrameImages, PassError> {
        let g = &self.targets;
        let p = &self.pipeline;
        let uav = |r: ResourceId| p.image(r).map(|image| (image, S::UnorderedAccess));
        let mut wanted: Vec<(Option<(&Image, S)>, Slot)> = vec![
            (Some((&g.position, S::RenderTarget)), Slot::Position),
            (Some((&g.normal, S::ShaderResource)), Slot::Normal),
            (Some((&g.depth, S::ShaderResource)), Slot::Depth),
            (uav(ResourceId::RtVisibility), Slot::Visibility),
            (uav(ResourceId::BlockerDistance), Slot::BlockerDistance),
            (uav(ResourceId::Occupancy), Slot::Occupancy),
            (uav(ResourceId::PrimCountMap), Slot::Counts),
            (
                uav(ResourceId::ShadowMapVisibility),
                Slot::ShadowMapVisibility,
            ),
            (uav(ResourceId::Pcss), Slot::Pcss),
            (uav(ResourceId::RtAntialiased), Slot::Antialiased),
            (uav(ResourceId::LerpFactor), Slot::LerpFactor),
            (uav(ResourceId::Hybrid), Slot::Hybrid),
            (Some((p.output(), S::UnorderedAccess)), Slot::Output),
        ];
        if with_indices {
            wanted.push((uav(ResourceId::PrimIndexMap), Slot::Indices));
        }
        let list: Vec<(&Image, S, Slot)> = wanted
            .into_iter()
            .filter_map(|(found, slot)| found.map(|(image, state)| (image, state, slot)))
            .collect();
        let buffers = list
            .iter()
            .map(|(img, _, _)| {
                device.create_buffer(
                    "read-back",
                    img.byte_size(),
                    BufferUsage::COPY_DST,
                    MemoryLocation::GpuToCpu,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        // The final output is one of the images above: transition each image once.
        let mut distinct: Vec<(&Image, S)> = Vec::new();
        for &(image, state, _) in &list {
            if !distinct.iter().any(|(i, _)| std::ptr::eq(*i, image)) {
                distinct.push((image, state));
            }
        }
        device.submit_and_wait(|enc| {
            let to_copy: Vec<Barrier<'_>> = distinct
                .iter()
                .map(|&(image, before)| Barrier::Image {
                    image,
                    before,
                    after: S::CopySource,
                })
                .collect();
            enc.barriers(&to_copy);
            for ((img, _, _), buf) in list.iter().zip(&buffers) {
                enc.copy_image_to_buffer(img, buf)?;
            }
            let back: Vec<Barrier<'_>> = distinct
                .iter()
                .map(|&(image, after)| Barrier::Image {
                    image,
                    before: S::CopySource,
                    after,
                })
                .collect();
            enc.barriers(&back);
            enc.barriers(&[Barrier::Global {
                before: S::CopyDest,
                after: S::HostRead,
            }]);
            Ok(())
        })?;
        let mut images = FrameImages {
            position: Vec::new(),
            normal: Vec::new(),
            depth: Vec::new(),
            visibility: Vec::new(),
            blocker_distance: Vec::new(),
            occupancy: Vec::new(),
            counts: Vec::new(),
            indices: Vec::new(),
            shadow_map_visibility: Vec::new(),
            pcss: Vec::new(),
            antialiased: Vec::new(),
            lerp_factor: Vec::new(),
            hybrid: Vec::new(),
            output: Vec::new(),
        };
        let origin = p.geometry().origin();
        for ((_, _, slot), buffer) in list.iter().zip(&buffers) {
            let bytes = buffer.read()?;
            let floats = || bytemuck::pod_collect_to_vec::<u8, f32>(bytes);
            match slot {
                Slot::Position => {
                    images.position = to_world(bytemuck::pod_collect_to_vec(bytes), origin)
                }
                Slot::Normal => images.normal = bytemuck::pod_collect_to_vec(bytes),
                Slot::Depth => images.depth = floats(),
                Slot::Visibility => images.visibility = floats(),
                Slot::BlockerDistance => images.blocker_distance = floats(),
                Slot::Occupancy => images.occupancy = bytemuck::pod_collect_to_vec(bytes),
                Slot::Counts => images.counts = bytemuck::pod_collect_to_vec(bytes),
                Slot::Indices => images.indices = bytemuck::pod_collect_to_vec(bytes),
                Slot::ShadowMapVisibility => images.shadow_map_visibility = floats(),
                Slot::Pcss => images.pcss = floats(),
                Slot::Antialiased => images.antialiased = floats(),
                Slot::LerpFactor => images.lerp_factor = floats(),
                Slot::Hybrid => images.hybrid = floats(),
                Slot::Output => images.output = floats(),
            }
        }
        Ok(images)
    }
}

/// Where a read-back image goes in [`FrameImages`].
#[derive(Clone, Copy)]
enum Slot {
    Position,
    Normal,
    Depth,
    Visibility,
    BlockerDistance,
    Occupancy,
    Counts,
    Indices,
    ShadowMapVisibility,
    Pcss,
    Antialiased,
    LerpFactor,
    Hybrid,
    Output,
}

fn into_rhi(e: PassError) -> rhi::RhiError {
    match e {
        PassError::Rhi(r) => r,
        other => rhi::RhiError::InvalidArgument(other.to_string()),
    }
}

fn to_world(mut frame: Vec<[f32; 4]>, origin: DVec3) -> Vec<[f32; 4]> {
    for p in frame.iter_mut().filter(|p| p[3] != 0.0) {
        let w = DVec3::new(p[0].into(), p[1].into(), p[2].into()) + origin;
        [p[0], p[1], p[2]] = w.as_vec3().to_array();
    }
    frame
}
