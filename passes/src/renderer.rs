//! The demo host's frame: prim buffer → G-buffer → [`ShadowPipeline`], submitted and waited for, with
//! read-back of every output.

use crate::gbuffer::{GBufferPass, GBufferTargets};
use crate::gpu_types::GBufferPush;
use crate::prim_buffer::Geometry;
use crate::primitive_map::PrimitiveMapConfig;
use crate::shadow_pipeline::{FrameInputs, FrameReport, ShadowInputs, ShadowPipeline};
use crate::PassError;
use glam::DVec3;
use rhi::{Barrier, BufferUsage, Device, Image, MemoryLocation, ResourceState as S};

/// Everything the frame produced, read back to the host. Row-major, y = 0 at the top.
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
}

/// The demo frame: a G-buffer of its own plus the engine-facing [`ShadowPipeline`].
pub struct ShadowRenderer {
    targets: GBufferTargets,
    gbuffer: GBufferPass,
    pipeline: ShadowPipeline,
}

impl ShadowRenderer {
    /// Creates every pass for a `width` x `height` frame over `geometry`.
    pub fn new(
        device: &Device,
        geometry: Geometry,
        width: u32,
        height: u32,
        map_config: PrimitiveMapConfig,
    ) -> Result<Self, PassError> {
        if width == 0 || height == 0 {
            return Err(PassError::InvalidConfig(
                "frame size must be non-zero".into(),
            ));
        }
        let targets = GBufferTargets::new(device, width, height)?;
        let inputs = ShadowInputs {
            depth: &targets.depth,
            normal: &targets.normal,
        };
        let pipeline = ShadowPipeline::new(device, geometry, &inputs, map_config)?;
        let gbuffer = GBufferPass::new(device, pipeline.prims())?;
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
        device.submit_and_wait(|enc| {
            pipeline.begin_frame(enc).map_err(into_rhi)?;
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
            pipeline.record(enc, inputs).map_err(into_rhi)
        })?;
        self.pipeline.report()
    }

    /// Reads back the last frame's outputs (the index map only if `with_indices`).
    pub fn read_back(&self, device: &Device, with_indices: bool) -> Result<FrameImages, PassError> {
        let g = &self.targets;
        let m = self.pipeline.primitive_map();
        let r = self.pipeline.ray_trace();
        let mut list: Vec<(&Image, S)> = vec![
            (&g.position, S::RenderTarget),
            (&g.normal, S::ShaderResource),
            (&g.depth, S::ShaderResource),
            (&r.visibility, S::UnorderedAccess),
            (&r.blocker_distance, S::UnorderedAccess),
            (&m.occupancy, S::UnorderedAccess),
            (&m.count, S::UnorderedAccess),
        ];
        if with_indices {
            list.push((&m.indices, S::UnorderedAccess));
        }
        let buffers = list
            .iter()
            .map(|(img, _)| {
                device.create_buffer(
                    "read-back",
                    img.byte_size(),
                    BufferUsage::COPY_DST,
                    MemoryLocation::GpuToCpu,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        device.submit_and_wait(|enc| {
            let to_copy: Vec<Barrier<'_>> = list
                .iter()
                .map(|&(image, before)| Barrier::Image {
                    image,
                    before,
                    after: S::CopySource,
                })
                .collect();
            enc.barriers(&to_copy);
            for ((img, _), buf) in list.iter().zip(&buffers) {
                enc.copy_image_to_buffer(img, buf)?;
            }
            let back: Vec<Barrier<'_>> = list
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
        let bytes = |i: usize| buffers[i].read();
        let origin = self.pipeline.geometry().origin();
        Ok(FrameImages {
            position: to_world(bytemuck::pod_collect_to_vec(bytes(0)?), origin),
            normal: bytemuck::pod_collect_to_vec(bytes(1)?),
            depth: bytemuck::pod_collect_to_vec(bytes(2)?),
            visibility: bytemuck::pod_collect_to_vec(bytes(3)?),
            blocker_distance: bytemuck::pod_collect_to_vec(bytes(4)?),
            occupancy: bytemuck::pod_collect_to_vec(bytes(5)?),
            counts: bytemuck::pod_collect_to_vec(bytes(6)?),
            indices: if with_indices {
                bytemuck::pod_collect_to_vec(bytes(7)?)
            } else {
                Vec::new()
            },
        })
    }
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
