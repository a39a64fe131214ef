//! The ray-tracing-pipeline peer: what a user would pick instead of the deep primitive map. It traces the
//! same shadow rays as the primitive-map ray trace (`shadow_ray.glsl`, same constants, depth and normals)
//! through the GPU's ray-tracing pipeline, against acceleration structures the driver builds over the prim
//! buffer, with any-hit shadow rays; its area variant traces each of the area trace's N light samples of a
//! pixel as its own ray (`rt_peer_area.rgen`). Timed as two passes: "rt peer build" and "rt peer trace".
//!
//! Reads: prim buffer, depth, normal, constants (and the light samples). Writes: visibility.

use crate::gpu_types::{AreaSamples, GpuTriangle, RayTraceConstants};
use crate::light::{rebased, LightFrame};
use crate::ray_trace::{RAY_OFFSET_FLOAT_BOUND, RAY_OFFSET_PIXELS};
use crate::shaders::shader;
use crate::shadow_pipeline::{camera_in_frame, FrameInputs};
use crate::PassError;
use bytemuck::Zeroable;
use glam::{DVec3, UVec4, Vec4};
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, BufferUsage, Device, Encoder, Format, Image,
    ImageDesc, ImageUsage, RayTracingPipeline, RayTracingPipelineDesc, Resource,
    ResourceState as S, TopLevel, TriangleGeometry,
};

/// Bytes between the vertices of the prim buffer (`vec4` positions, w ignored).
const VERTEX_STRIDE: u64 = (std::mem::size_of::<GpuTriangle>() / 3) as u64;

/// Acceleration structures over the prim buffer, the peer's ray-tracing pipeline and its output.
pub struct RtPeerPass {
    top: TopLevel,
    pipeline: RayTracingPipeline,
    group: BindGroup,
    constants: Buffer,
    /// The light samples of the area variant.
    samples: Option<Buffer>,
    width: u32,
    height: u32,
    /// `R32_SFLOAT` visibility, 1 = lit, 0 = shadowed, the value the primitive-map ray trace writes:
    /// background and pixels outside the light's frustum lit, receivers facing away from the light 0.
    pub visibility: Image,
}

impl RtPeerPass {
    /// Creates the acceleration structures over the first `triangle_count` triangles of `prims` (created by
    /// [`crate::prim_buffer::PrimBufferPass`] on this device) and a `width` x `height` output. `depth` and
    /// `normal` are the images the primitive-map ray trace reads. Fails with
    /// [`PassError::Unsupported`], naming what is missing, on a device without ray tracing.
    pub fn new(
        device: &Device,
        prims: &Buffer,
        triangle_count: u32,
        depth: &Image,
        normal: &Image,
        width: u32,
        height: u32,
    ) -> Result<Self, PassError> {
        Self::with_variant(
            device,
            prims,
            triangle_count,
            (depth, normal),
            (width, height),
            false,
        )
    }

    /// The area variant of [`RtPeerPass::new`]: each of the area trace's light samples of a pixel traced as
    /// its own ray ([`RtPeerPass::record_area_trace`]); the visibility is the visible fraction.
    pub fn new_area(
        device: &Device,
        prims: &Buffer,
        triangle_count: u32,
        depth: &Image,
        normal: &Image,
        width: u32,
        height: u32,
    ) -> Result<Self, PassError> {
        Self::with_variant(
            device,
            prims,
            triangle_count,
            (depth, normal),
            (width, height),
            true,
        )
    }

    fn with_variant(
        device: &Device,
        prims: &Buffer,
        triangle_count: u32,
        (depth, normal): (&Image, &Image),
        (width, height): (u32, u32),
        area: bool,
    ) -> Result<Self, PassError> {
        device
            .ray_tracing_support()
            .map_err(|e| PassError::Unsupported(format!("the ray-tracing-pipeline peer: {e}")))?;
        let bottom = device.create_bottom_level(
            "rt peer scene",
            &TriangleGeometry {
                vertices: prims,
                stride: VERTEX_STRIDE,
                triangle_count,
            },
        )?;
        let top = device.create_top_level("rt peer instances", bottom)?;
        let visibility = device.create_image(&ImageDesc {
            name: "rt peer visibility",
            format: Format::R32Float,
            width,
            height,
            layers: 1,
            usage: ImageUsage::STORAGE | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
        })?;
        let constants = device.create_buffer_init(
            "rt peer constants",
            bytemuck::bytes_of(&RayTraceConstants::zeroed()),
            BufferUsage::UNIFORM,
        )?;
        let samples = area
            .then(|| {
                device.create_buffer_init(
                    "rt peer light samples",
                    bytemuck::bytes_of(&AreaSamples::zeroed()),
                    BufferUsage::UNIFORM,
                )
            })
            .transpose()?;
        let mut bindings = vec![
            BindingKind::UniformBuffer,
            BindingKind::SampledImage,
            BindingKind::SampledImage,
            BindingKind::AccelerationStructure,
            BindingKind::StorageImage,
        ];
        let mut resources = vec![
            Resource::Buffer(&constants),
            Resource::Image(depth),
            Resource::Image(normal),
            Resource::AccelerationStructure(&top),
            Resource::Image(&visibility),
        ];
        if let Some(samples) = &samples {
            bindings.push(BindingKind::UniformBuffer);
            resources.push(Resource::Buffer(samples));
        }
        let pipeline = device.create_ray_tracing_pipeline(&RayTracingPipelineDesc {
            name: if area { "rt peer (area)" } else { "rt peer" },
            raygen: &shader(if area {
                "rt_peer_area.rgen"
            } else {
                "rt_peer.rgen"
            })?,
            miss: &shader("rt_peer.rmiss")?,
            bindings: &bindings,
            push_constant_size: 0,
        })?;
        let group = device.create_bind_group(pipeline.layout(), &resources)?;
        Ok(Self {
            top,
            pipeline,
            group,
            constants,
            samples,
            width,
            height,
            visibility,
        })
    }

    /// Records the pass "rt peer build": full builds of the bottom level over the prim buffer (whose
    /// contents earlier commands may have written) and of the top level.
    pub fn record_build(&self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        enc.begin_pass("rt peer build");
        enc.build_bottom_level(self.top.bottom_level())?;
        enc.build_top_level(&self.top)?;
        enc.end_pass();
        Ok(())
    }

    /// Updates the constants (host-visible; call while no submitted frame uses them) and records the pass
    /// "rt peer trace" after [`RtPeerPass::record_build`]. Depth and normal are in `ShaderResource` state;
    /// the visibility is rewritten whole and left in `UnorderedAccess` state, its writes ordered before
    /// later barriers from that state.
    pub fn record_trace(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
    ) -> Result<(), PassError> {
        if self.samples.is_some() {
            return Err(PassError::InvalidConfig(
                "the area peer traces light samples: record_area_trace".into(),
            ));
        }
        self.record(enc, constants)
    }

    /// The area variant's [`RtPeerPass::record_trace`]: `constants` as the area trace has them (the light's
    /// size in `light_dir.w`, the samples per pixel in `misc.w`; `dims.w` 1 for a point light) and the
    /// light's `samples` (host-visible: call while no submitted frame uses them).
    pub fn record_area_trace(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
        samples: &AreaSamples,
    ) -> Result<(), PassError> {
        let Some(buffer) = self.samples.as_mut() else {
            return Err(PassError::InvalidConfig(
                "light samples are given to the area peer alone".into(),
            ));
        };
        if !(1..=crate::area::MAX_AREA_SAMPLES).contains(&constants.misc.w) {
            return Err(PassError::InvalidConfig(format!(
                "{} light samples per pixel: 1 to {} are traced",
                constants.misc.w,
                crate::area::MAX_AREA_SAMPLES
            )));
        }
        buffer.write(0, bytemuck::bytes_of(samples))?;
        self.record(enc, constants)
    }

    fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
    ) -> Result<(), PassError> {
        if (constants.dims.x, constants.dims.y) != (self.width, self.height) {
            return Err(PassError::InvalidConfig(format!(
                "constants for {}x{} pixels, the peer's output is {}x{}",
                constants.dims.x, constants.dims.y, self.width, self.height
            )));
        }
        self.constants.write(0, bytemuck::bytes_of(constants))?;
        enc.begin_pass("rt peer trace");
        enc.ray_tracing_barriers(&[
            Barrier::Global {
                before: S::ShaderResource,
                after: S::ShaderResource,
            },
            Barrier::Image {
                image: &self.visibility,
                before: S::Undefined,
                after: S::UnorderedAccess,
            },
        ])?;
        enc.trace_rays(
            &self.pipeline,
            &self.group,
            &[],
            [self.width, self.height, 1],
        )?;
        enc.ray_tracing_barriers(&[Barrier::Uav])?;
        enc.end_pass();
        Ok(())
    }
}

/// The shadow-ray constants of a `width` x `height` frame of `inputs` over geometry whose frame origin is
/// `origin`, as the shadow pipeline computes them: what a host that drives the pipeline through the C ABI
/// (and so never sees its constants) passes to [`RtPeerPass::record_trace`], for a float depth buffer (no
/// depth step in the offset) and world-space normals with coverage in w (the demo's G-buffer). The fields only the primitive-map passes read (map size, face mode, triangle
/// count) are zero.
pub fn shadow_ray_constants(
    inputs: &FrameInputs,
    origin: DVec3,
    width: u32,
    height: u32,
) -> Result<RayTraceConstants, PassError> {
    let (_, camera_frame) = camera_in_frame(inputs, origin)?;
    let camera_relative =
        inputs.proj.as_dmat4() * rebased(inputs.view, inputs.camera_position.as_dvec3());
    let inv_view_proj_rel = camera_relative.inverse().as_mat4();
    if !inv_view_proj_rel.is_finite() {
        return Err(PassError::InvalidConfig(
            "camera matrices are not finite or invertible".into(),
        ));
    }
    let light = LightFrame::new(&inputs.light, origin)?;
    let radians_per_pixel = (2.0 / (inputs.proj.y_axis.y * height as f32)).abs();
    Ok(RayTraceConstants {
        inv_view_proj_rel,
        light_view_proj: light.view_proj,
        camera_pos: camera_frame.extend(1.0),
        light_dir: light.direction.extend(0.0),
        dims: UVec4::new(width, height, 0, 0),
        offset: Vec4::new(
            radians_per_pixel,
            RAY_OFFSET_PIXELS,
            RAY_OFFSET_FLOAT_BOUND,
            0.0,
        ),
        misc: UVec4::ZERO,
        light_pos: light.position.map_or(Vec4::ZERO, |p| p.extend(1.0)),
        view_to_world: crate::surface::view_to_world(inputs.view),
        surface_mode: crate::surface::SurfaceInput::default().mode(rhi::Format::Rgba32Float),
        surface: crate::surface::surface_vector(inputs.proj, rhi::Format::D32Float, 0.0),
    })
}

/// [`shadow_ray_constants`] for the area variant ([`RtPeerPass::record_area_trace`]) of a light of size
/// `size` (a directional light's angular radius in radians, a spot or point light's emitter radius) and
/// `samples` samples per pixel, with the light's samples: the very ones the area trace takes
/// (`ShadowPipeline` derives its own the same way).
pub fn area_peer_constants(
    inputs: &FrameInputs,
    origin: DVec3,
    (width, height): (u32, u32),
    size: f32,
    samples: u32,
) -> Result<(RayTraceConstants, AreaSamples), PassError> {
    crate::AreaConfig {
        samples,
        ..crate::AreaConfig::default()
    }
    .validate_samples()?;
    let mut constants = shadow_ray_constants(inputs, origin, width, height)?;
    let direction = constants.light_dir.truncate();
    let area = if inputs.light.position().is_some() {
        if !(size > 0.0 && size.is_finite()) {
            return Err(PassError::InvalidConfig(format!(
                "an emitter radius must be finite and above 0, not {size}"
            )));
        }
        constants.light_dir.w = size;
        crate::area::local_area_samples(samples)
    } else {
        crate::area::check_angular_radius(size)?;
        constants.light_dir.w = size.tan();
        crate::area::area_samples(direction, size, samples)
    };
    constants.misc.w = samples;
    constants.dims.w = u32::from(matches!(inputs.light, crate::Light::Point { .. }));
    Ok((constants, area))
}
