//! The demo host's frame: prim buffer → G-buffer → primitive map → ray trace → occupancy, with GPU
//! timings, map statistics and read-back of every output.

use crate::gbuffer::GBufferPass;
use crate::gpu_types::{GBufferPush, MapStats, PrimMapPush, RayTraceConstants};
use crate::prim_buffer::{Geometry, PrimBufferPass};
use crate::primitive_map::{FaceMode, PrimitiveMap, PrimitiveMapConfig, RasterPath};
use crate::ray_trace::{RayTraceInputs, RayTracePass, RAY_OFFSET_FLOAT_BOUND, RAY_OFFSET_PIXELS};
use crate::PassError;
use glam::{DMat4, DVec3, Mat4, UVec4, Vec3, Vec4};
use rhi::{
    Barrier, Buffer, BufferUsage, Device, GpuTimer, Image, MemoryLocation, PassTiming,
    ResourceState as S,
};

/// Camera and light of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameInputs {
    /// World to view.
    pub view: Mat4,
    /// View to clip: reversed Z (depth 1 at the near plane, 0 at infinity), Vulkan conventions.
    pub proj: Mat4,
    /// Camera position in world space.
    pub camera_position: Vec3,
    /// Direction the light travels (unit).
    pub light_direction: Vec3,
    /// Orthographic light view-projection enclosing the scene (world coordinates).
    pub light_view_proj: Mat4,
}

/// What the frame did.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// GPU time per pass (the prim buffer pass appears only on frames that rebuilt it).
    pub timings: Vec<PassTiming>,
    /// The raster path used.
    pub raster_path: RasterPath,
    /// Primitive-map statistics (overflow, occupancy).
    pub stats: MapStats,
}

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
    /// Blocker distance (see [`RayTracePass::blocker_distance`]).
    pub blocker_distance: Vec<f32>,
    /// Occupancy view, N×N RGBA8.
    pub occupancy: Vec<[u8; 4]>,
    /// Count map, N×N.
    pub counts: Vec<u32>,
    /// Index map, layer-major: `indices[(slot * N + y) * N + x]`; empty unless requested.
    pub indices: Vec<u32>,
}

/// Owns the passes and resources of the demo frame.
pub struct ShadowRenderer {
    geometry: Geometry,
    prim_buffer: PrimBufferPass,
    gbuffer: GBufferPass,
    map: PrimitiveMap,
    ray: RayTracePass,
    timer: GpuTimer,
    stats_readback: Buffer,
    prims_built: bool,
    width: u32,
    height: u32,
}

/// `m * translation(origin)` in f64: `m` applied to coordinates relative to `origin`.
fn rebased(m: Mat4, origin: DVec3) -> DMat4 {
    m.as_dmat4() * DMat4::from_translation(origin)
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
        let prim_buffer = PrimBufferPass::new(device, &geometry)?;
        let gbuffer = GBufferPass::new(device, prim_buffer.prims(), width, height)?;
        let map = PrimitiveMap::new(device, prim_buffer.prims(), map_config)?;
        let ray = RayTracePass::new(
            device,
            &RayTraceInputs {
                depth: &gbuffer.depth,
                normal: &gbuffer.normal,
                count: &map.count,
                indices: &map.indices,
                prims: prim_buffer.prims(),
            },
            width,
            height,
        )?;
        let timer = device.create_timer(16)?;
        let stats_readback = device.create_buffer(
            "stats read-back",
            std::mem::size_of::<MapStats>() as u64,
            BufferUsage::COPY_DST,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Self {
            geometry,
            prim_buffer,
            gbuffer,
            map,
            ray,
            timer,
            stats_readback,
            prims_built: false,
            width,
            height,
        })
    }

    /// The primitive map.
    pub fn primitive_map(&self) -> &PrimitiveMap {
        &self.map
    }

    /// Renders one frame and waits for it.
    pub fn render(
        &mut self,
        device: &Device,
        inputs: &FrameInputs,
    ) -> Result<FrameReport, PassError> {
        let cam = inputs.camera_position.as_dvec3();
        let camera_rel = inputs.proj.as_dmat4() * rebased(inputs.view, cam);
        let view_proj_rel = camera_rel.as_mat4();
        let inv_view_proj_rel = camera_rel.inverse().as_mat4();
        let origin = self.geometry.origin();
        let light_rel = rebased(inputs.light_view_proj, origin).as_mat4();
        let camera_frame = (cam - origin).as_vec3();
        let dir = inputs.light_direction.normalize();
        if !dir.is_finite()
            || !view_proj_rel.is_finite()
            || !inv_view_proj_rel.is_finite()
            || !light_rel.is_finite()
        {
            return Err(PassError::InvalidConfig(
                "camera or light matrices are not finite or invertible".into(),
            ));
        }
        let radians_per_pixel = 2.0 / (inputs.proj.y_axis.y * self.height as f32);
        let cfg = *self.map.config();
        let map_push = PrimMapPush {
            light_view_proj: light_rel,
            to_light: (-dir).extend(0.0),
            size: cfg.size,
            depth: cfg.depth,
            front_only: u32::from(cfg.faces == FaceMode::FrontOnly),
            pad: 0,
        };
        let rt = RayTraceConstants {
            inv_view_proj_rel,
            light_view_proj: light_rel,
            camera_pos: camera_frame.extend(1.0),
            light_dir: dir.extend(0.0),
            dims: UVec4::new(self.width, self.height, cfg.size, cfg.depth),
            offset: Vec4::new(
                radians_per_pixel,
                RAY_OFFSET_PIXELS,
                RAY_OFFSET_FLOAT_BOUND,
                0.0,
            ),
            misc: UVec4::new(map_push.front_only, self.geometry.triangle_count(), 0, 0),
        };
        let gpush = GBufferPush {
            view_proj_rel,
            camera_pos: camera_frame.extend(1.0),
        };
        let tris = self.geometry.triangle_count();
        let build_prims = !self.prims_built;
        let Self {
            geometry,
            prim_buffer,
            gbuffer,
            map,
            ray,
            timer,
            stats_readback,
            ..
        } = self;
        device.submit_and_wait(|enc| {
            enc.attach_timer(timer);
            if build_prims {
                prim_buffer.record(enc, geometry).map_err(into_rhi)?;
                enc.barriers(&[Barrier::Uav]);
            }
            enc.barriers(&[
                Barrier::Image {
                    image: &gbuffer.position,
                    before: S::Undefined,
                    after: S::RenderTarget,
                },
                Barrier::Image {
                    image: &gbuffer.normal,
                    before: S::Undefined,
                    after: S::RenderTarget,
                },
                Barrier::Image {
                    image: &gbuffer.depth,
                    before: S::Undefined,
                    after: S::DepthWrite,
                },
                Barrier::Image {
                    image: &map.count,
                    before: S::Undefined,
                    after: S::CopyDest,
                },
                Barrier::Image {
                    image: &map.indices,
                    before: S::Undefined,
                    after: S::CopyDest,
                },
                Barrier::Image {
                    image: &map.occupancy,
                    before: S::Undefined,
                    after: S::UnorderedAccess,
                },
                Barrier::Image {
                    image: &ray.visibility,
                    before: S::Undefined,
                    after: S::UnorderedAccess,
                },
                Barrier::Image {
                    image: &ray.blocker_distance,
                    before: S::Undefined,
                    after: S::UnorderedAccess,
                },
            ]);
            gbuffer.record(enc, &gpush, tris).map_err(into_rhi)?;
            map.record_clear(enc);
            enc.barriers(&[
                Barrier::Image {
                    image: &map.count,
                    before: S::CopyDest,
                    after: S::UnorderedAccess,
                },
                Barrier::Image {
                    image: &map.indices,
                    before: S::CopyDest,
                    after: S::UnorderedAccess,
                },
                Barrier::Global {
                    before: S::CopyDest,
                    after: S::UnorderedAccess,
                },
            ]);
            map.record_raster(enc, &map_push, tris).map_err(into_rhi)?;
            enc.barriers(&[
                Barrier::Uav,
                Barrier::Image {
                    image: &gbuffer.normal,
                    before: S::RenderTarget,
                    after: S::ShaderResource,
                },
                Barrier::Image {
                    image: &gbuffer.depth,
                    before: S::DepthWrite,
                    after: S::ShaderResource,
                },
            ]);
            ray.record(enc, &rt).map_err(into_rhi)?;
            map.record_occupancy(enc).map_err(into_rhi)?;
            enc.barriers(&[Barrier::Global {
                before: S::UnorderedAccess,
                after: S::CopySource,
            }]);
            enc.copy_buffer(&map.stats, stats_readback)?;
            enc.barriers(&[Barrier::Global {
                before: S::CopyDest,
                after: S::HostRead,
            }]);
            Ok(())
        })?;
        self.prims_built = true;
        let stats: MapStats = bytemuck::pod_read_unaligned(self.stats_readback.read()?);
        Ok(FrameReport {
            timings: self.timer.resolve()?,
            raster_path: self.map.path(),
            stats,
        })
    }

    /// Reads back the last frame's outputs (the index map only if `with_indices`).
    pub fn read_back(&self, device: &Device, with_indices: bool) -> Result<FrameImages, PassError> {
        let g = &self.gbuffer;
        let m = &self.map;
        let r = &self.ray;
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
        Ok(FrameImages {
            position: to_world(
                bytemuck::pod_collect_to_vec(bytes(0)?),
                self.geometry.origin(),
            ),
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
