//! The engine-facing frame: prim buffer → primitive map → ray trace → occupancy, recorded into any
//! command buffer. It reads the engine's depth and normal images and writes visibility (1 = lit) and
//! blocker distance. The C ABI and the demo host both drive it.

use crate::gpu_types::{MapStats, PrimMapPush, RayTraceConstants};
use crate::prim_buffer::{Geometry, PrimBufferPass};
use crate::primitive_map::{FaceMode, PrimitiveMap, PrimitiveMapConfig, RasterPath};
use crate::ray_trace::{RayTraceInputs, RayTracePass, RAY_OFFSET_FLOAT_BOUND, RAY_OFFSET_PIXELS};
use crate::PassError;
use glam::{DMat4, DVec3, Mat4, UVec4, Vec3, Vec4};
use rhi::{
    Barrier, Buffer, BufferUsage, Device, Encoder, GpuTimer, Image, MemoryLocation, PassTiming,
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

/// What a frame did.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// GPU time per pass (the prim buffer pass appears only on frames that rebuilt it).
    pub timings: Vec<PassTiming>,
    /// The raster path used.
    pub raster_path: RasterPath,
    /// Primitive-map statistics (overflow, occupancy).
    pub stats: MapStats,
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
    view_proj_rel: Mat4,
    camera_frame: Vec3,
    map: PrimMapPush,
    ray: RayTraceConstants,
}

/// `m * translation(origin)` in f64: `m` applied to coordinates relative to `origin`.
fn rebased(m: Mat4, origin: DVec3) -> DMat4 {
    m.as_dmat4() * DMat4::from_translation(origin)
}

/// The passes of one view of one light, and the resources they own.
pub struct ShadowPipeline {
    geometry: Geometry,
    prim_buffer: PrimBufferPass,
    map: PrimitiveMap,
    ray: RayTracePass,
    timer: GpuTimer,
    stats_readback: Buffer,
    prims_built: bool,
    width: u32,
    height: u32,
}

impl ShadowPipeline {
    /// Creates every pass over `geometry` for the size of `inputs.depth`.
    pub fn new(
        device: &Device,
        geometry: Geometry,
        inputs: &ShadowInputs<'_>,
        map_config: PrimitiveMapConfig,
    ) -> Result<Self, PassError> {
        let (width, height) = (inputs.depth.width(), inputs.depth.height());
        if (inputs.normal.width(), inputs.normal.height()) != (width, height) {
            return Err(PassError::InvalidConfig(
                "depth and normal images differ in size".into(),
            ));
        }
        let prim_buffer = PrimBufferPass::new(device, &geometry)?;
        let map = PrimitiveMap::new(device, prim_buffer.prims(), map_config)?;
        let ray = RayTracePass::new(
            device,
            &RayTraceInputs {
                depth: inputs.depth,
                normal: inputs.normal,
                count: &map.count,
                indices: &map.indices,
                prims: prim_buffer.prims(),
            },
            width,
            height,
        )?;
        let timer = device.create_timer(32)?;
        let stats_readback = device.create_buffer(
            "stats read-back",
            std::mem::size_of::<MapStats>() as u64,
            BufferUsage::COPY_DST,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Self {
            geometry,
            prim_buffer,
            map,
            ray,
            timer,
            stats_readback,
            prims_built: false,
            width,
            height,
        })
    }

    /// The prim buffer (triangles in frame coordinates).
    pub fn prims(&self) -> &Buffer {
        self.prim_buffer.prims()
    }

    /// The geometry.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The primitive map.
    pub fn primitive_map(&self) -> &PrimitiveMap {
        &self.map
    }

    /// The ray-trace outputs.
    pub fn ray_trace(&self) -> &RayTracePass {
        &self.ray
    }

    /// Starts a frame: attaches the GPU timer (every pass recorded afterwards on `enc` is timed) and
    /// builds the prim buffer when the geometry is new.
    pub fn begin_frame(&mut self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        enc.attach_timer(&self.timer);
        if !self.prims_built {
            self.prim_buffer.record(enc, &self.geometry)?;
            enc.barriers(&[Barrier::Uav]);
            self.prims_built = true;
        }
        Ok(())
    }

    /// Camera-relative view-projection and the camera in frame coordinates (for a host G-buffer that
    /// rasterizes the prim buffer).
    pub fn camera_in_frame(&self, inputs: &FrameInputs) -> Result<(Mat4, Vec3), PassError> {
        let c = self.constants(inputs)?;
        Ok((c.view_proj_rel, c.camera_frame))
    }

    fn constants(&self, inputs: &FrameInputs) -> Result<FrameConstants, PassError> {
        let cam = inputs.camera_position.as_dvec3();
        let camera_rel = inputs.proj.as_dmat4() * rebased(inputs.view, cam);
        let view_proj_rel = camera_rel.as_mat4();
        let inv_view_proj_rel = camera_rel.inverse().as_mat4();
        let origin = self.geometry.origin();
        let light = rebased(inputs.light_view_proj, origin).as_mat4();
        let camera_frame = (cam - origin).as_vec3();
        let dir = inputs.light_direction.normalize();
        if !dir.is_finite()
            || !view_proj_rel.is_finite()
            || !inv_view_proj_rel.is_finite()
            || !light.is_finite()
        {
            return Err(PassError::InvalidConfig(
                "camera or light matrices are not finite or invertible".into(),
            ));
        }
        let radians_per_pixel = 2.0 / (inputs.proj.y_axis.y * self.height as f32);
        let cfg = *self.map.config();
        let front_only = u32::from(cfg.faces == FaceMode::FrontOnly);
        Ok(FrameConstants {
            view_proj_rel,
            camera_frame,
            map: PrimMapPush {
                light_view_proj: light,
                to_light: (-dir).extend(0.0),
                size: cfg.size,
                depth: cfg.depth,
                front_only,
                pad: 0,
            },
            ray: RayTraceConstants {
                inv_view_proj_rel,
                light_view_proj: light,
                camera_pos: camera_frame.extend(1.0),
                light_dir: dir.extend(0.0),
                dims: UVec4::new(self.width, self.height, cfg.size, cfg.depth),
                offset: Vec4::new(
                    radians_per_pixel,
                    RAY_OFFSET_PIXELS,
                    RAY_OFFSET_FLOAT_BOUND,
                    0.0,
                ),
                misc: UVec4::new(front_only, self.geometry.triangle_count(), 0, 0),
            },
        })
    }

    /// Records the shadow passes. Depth and normal must be in `ShaderResource` state; afterwards the
    /// visibility and blocker-distance images, count, index and occupancy maps are in `UnorderedAccess`.
    pub fn record(&mut self, enc: &mut Encoder<'_>, inputs: &FrameInputs) -> Result<(), PassError> {
        let c = self.constants(inputs)?;
        let (map, ray) = (&self.map, &mut self.ray);
        let undefined_to = |image, after| Barrier::Image {
            image,
            before: S::Undefined,
            after,
        };
        enc.barriers(&[
            undefined_to(&map.count, S::CopyDest),
            undefined_to(&map.indices, S::CopyDest),
            undefined_to(&map.occupancy, S::UnorderedAccess),
            undefined_to(&ray.visibility, S::UnorderedAccess),
            undefined_to(&ray.blocker_distance, S::UnorderedAccess),
        ]);
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
        map.record_raster(enc, &c.map, self.geometry.triangle_count())?;
        enc.barriers(&[Barrier::Uav]);
        ray.record(enc, &c.ray)?;
        map.record_occupancy(enc)?;
        enc.barriers(&[Barrier::Global {
            before: S::UnorderedAccess,
            after: S::CopySource,
        }]);
        enc.copy_buffer(&map.stats, &self.stats_readback)?;
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        Ok(())
    }

    /// Timings and statistics of the last recorded frame; call after its submission has completed.
    pub fn report(&self) -> Result<FrameReport, PassError> {
        let stats: MapStats = bytemuck::pod_read_unaligned(self.stats_readback.read()?);
        Ok(FrameReport {
            timings: self.timer.resolve()?,
            raster_path: self.map.path(),
            stats,
        })
    }
}
