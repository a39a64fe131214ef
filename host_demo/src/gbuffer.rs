//! G-buffer for the demo host: world position, camera-facing geometric normal, reversed-Z depth.
//!
//! Reads: the pipeline's prim buffer. Writes: position, normal, depth. Shaders: `gbuffer.vert` and
//! `gbuffer.frag` in `host_demo/shaders/`.

use crate::{shader, CameraMatrices};
use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec3, Mat4, Vec4};
use passes::PassError;
use rhi::{
    BindGroup, BindingKind, Buffer, ColorTarget, DepthState, DepthTarget, Device, Encoder, Format,
    GraphicsPipeline, GraphicsPipelineDesc, Image, ImageDesc, ImageUsage, Resource,
};

/// Push constants of the G-buffer (`gbuffer_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GBufferPush {
    /// proj * view with the camera at the origin.
    pub view_proj_rel: Mat4,
    /// Camera position in frame coordinates (xyz).
    pub camera_pos: Vec4,
}

const _: () = assert!(std::mem::size_of::<GBufferPush>() == 80);

impl GBufferPush {
    /// The constants of `camera` for a prim buffer relative to `origin`: the view-projection of
    /// coordinates relative to the camera, composed in f64 as the plugin composes its own
    /// (`passes::camera_in_frame`), so that the G-buffer and the plugin agree on every pixel's ray.
    pub fn for_camera(camera: &CameraMatrices, origin: DVec3) -> Result<Self, PassError> {
        let relative_view =
            camera.view.as_dmat4() * DMat4::from_translation(camera.position.as_dvec3());
        let view_proj_rel = (camera.proj.as_dmat4() * relative_view).as_mat4();
        let camera_frame = (camera.position.as_dvec3() - origin).as_vec3();
        if !view_proj_rel.is_finite() || !camera_frame.is_finite() {
            return Err(PassError::InvalidConfig(
                "camera matrices are not finite".into(),
            ));
        }
        Ok(Self {
            view_proj_rel,
            camera_pos: camera_frame.extend(1.0),
        })
    }
}

/// The G-buffer's images.
pub struct GBufferTargets {
    /// World position in frame coordinates (xyz), w = 1 on geometry, 0 on background.
    pub position: Image,
    /// Geometric normal facing the camera (xyz), w = 1 on geometry.
    pub normal: Image,
    /// Reversed-Z depth (1 near, 0 far/background).
    pub depth: Image,
}

impl GBufferTargets {
    /// Creates `width` x `height` targets.
    pub fn new(device: &Device, width: u32, height: u32) -> Result<Self, PassError> {
        let color = |name| ImageDesc {
            name,
            format: Format::Rgba32Float,
            width,
            height,
            layers: 1,
            usage: ImageUsage::COLOR_TARGET | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
        };
        Ok(Self {
            position: device.create_image(&color("gbuffer position"))?,
            normal: device.create_image(&color("gbuffer normal"))?,
            depth: device.create_image(&ImageDesc {
                name: "gbuffer depth",
                format: Format::D32Float,
                width,
                height,
                layers: 1,
                usage: ImageUsage::DEPTH_TARGET | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
            })?,
        })
    }
}

/// The G-buffer pass over the prim buffer.
pub struct GBufferPass {
    pipeline: GraphicsPipeline,
    group: BindGroup,
}

impl GBufferPass {
    /// Creates the pass rasterizing `prims` into targets of [`GBufferTargets`].
    pub fn new(device: &Device, prims: &Buffer) -> Result<Self, PassError> {
        let pipeline = device.create_graphics_pipeline(&GraphicsPipelineDesc {
            name: "gbuffer",
            vertex: &shader("gbuffer.vert")?,
            geometry: None,
            fragment: &shader("gbuffer.frag")?,
            bindings: &[BindingKind::StorageBuffer],
            push_constant_size: std::mem::size_of::<GBufferPush>() as u32,
            color_formats: &[Format::Rgba32Float, Format::Rgba32Float],
            depth: Some(DepthState {
                format: Format::D32Float,
                write: true,
                greater: true,
            }),
            conservative_extra_overestimation: None,
            depth_clamp: false,
        })?;
        let group = device.create_bind_group(pipeline.layout(), &[Resource::Buffer(prims)])?;
        Ok(Self { pipeline, group })
    }

    /// Records the pass; targets must be in `RenderTarget` / `DepthWrite` state.
    pub fn record(
        &self,
        enc: &mut Encoder<'_>,
        targets: &GBufferTargets,
        push: &GBufferPush,
        triangle_count: u32,
    ) -> Result<(), PassError> {
        enc.begin_pass("gbuffer");
        enc.begin_rendering(
            (targets.position.width(), targets.position.height()),
            &[
                ColorTarget {
                    image: &targets.position,
                    clear: [0.0; 4],
                },
                ColorTarget {
                    image: &targets.normal,
                    clear: [0.0; 4],
                },
            ],
            Some(DepthTarget {
                image: &targets.depth,
                clear: 0.0,
            }),
        );
        enc.draw(
            &self.pipeline,
            &self.group,
            bytemuck::bytes_of(push),
            triangle_count * 3,
        )?;
        enc.end_rendering();
        enc.end_pass();
        Ok(())
    }
}
