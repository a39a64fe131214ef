//! The conventional shadow map: depth of the prim buffer from the light, for PCSS (and for the classic
//! single-tap test shown for comparison).
//!
//! Reads: prim buffer, light. Writes: shadow map (`D32_SFLOAT`, size²).

use crate::gpu_types::ShadowMapPush;
use crate::shaders::shader;
use crate::PassError;
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, Capabilities, DepthState, DepthTarget, Device,
    Encoder, Format, GraphicsPipeline, GraphicsPipelineDesc, Image, ImageDesc, ImageUsage,
    Resource, ResourceState as S,
};

/// Size of the shadow map and the bias of the classic single-tap test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowMapConfig {
    /// Texels per side. Default 3072, the talk's "3K x 3K (36 MB)".
    pub size: u32,
    /// Classic test only: constant depth bias in texels of world size (default 1).
    pub constant_bias: f32,
    /// Classic test only: slope-scaled depth bias in texels per unit of tan(angle to the light), with the
    /// tangent clamped to 10 (default 1). PCSS does not use either bias: it compares against the
    /// receiver's plane at each texel centre.
    pub slope_bias: f32,
}

impl Default for ShadowMapConfig {
    fn default() -> Self {
        Self {
            size: 3072,
            constant_bias: 1.0,
            slope_bias: 1.0,
        }
    }
}

impl ShadowMapConfig {
    /// Checks the configuration against the device limits.
    pub fn validate(&self, caps: &Capabilities) -> Result<(), PassError> {
        if self.size == 0 || self.size > caps.max_image_dimension_2d {
            return Err(PassError::InvalidConfig(format!(
                "shadow map size {} must be in 1..={}",
                self.size, caps.max_image_dimension_2d
            )));
        }
        if !(self.constant_bias.is_finite() && self.slope_bias.is_finite())
            || self.constant_bias < 0.0
            || self.slope_bias < 0.0
        {
            return Err(PassError::InvalidConfig(
                "shadow map biases must be finite and non-negative".into(),
            ));
        }
        Ok(())
    }

    /// Bytes of the depth image.
    pub fn memory_bytes(&self) -> u64 {
        u64::from(self.size) * u64::from(self.size) * 4
    }
}

/// The shadow-map pass and its depth image.
pub struct ShadowMapPass {
    pipeline: GraphicsPipeline,
    group: BindGroup,
    /// Light-space depth, standard (near 0, far 1), cleared to 1.
    pub depth: Image,
}

impl ShadowMapPass {
    /// Creates a `size`² map rasterizing `prims`.
    pub fn new(device: &Device, prims: &Buffer, size: u32) -> Result<Self, PassError> {
        let depth = device.create_image(&ImageDesc {
            name: "shadow map",
            format: Format::D32Float,
            width: size,
            height: size,
            layers: 1,
            usage: ImageUsage::DEPTH_TARGET | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
        })?;
        let pipeline = device.create_graphics_pipeline(&GraphicsPipelineDesc {
            name: "shadow map",
            vertex: &shader("shadow_map.vert")?,
            geometry: None,
            fragment: &shader("shadow_map.frag")?,
            bindings: &[BindingKind::StorageBuffer],
            push_constant_size: std::mem::size_of::<ShadowMapPush>() as u32,
            color_formats: &[],
            depth: Some(DepthState {
                format: Format::D32Float,
                write: true,
                greater: false,
            }),
            conservative_extra_overestimation: None,
            depth_clamp: true,
        })?;
        let group = device.create_bind_group(pipeline.layout(), &[Resource::Buffer(prims)])?;
        Ok(Self {
            pipeline,
            group,
            depth,
        })
    }

    /// Records the pass: discards the depth image, renders it and leaves it in `ShaderResource` state.
    pub fn record(
        &self,
        enc: &mut Encoder<'_>,
        push: &ShadowMapPush,
        triangle_count: u32,
    ) -> Result<(), PassError> {
        let size = self.depth.width();
        let vertices = triangle_count
            .checked_mul(3)
            .ok_or_else(|| PassError::InvalidGeometry("too many triangles to draw".into()))?;
        enc.begin_pass("shadow map");
        enc.barriers(&[Barrier::Image {
            image: &self.depth,
            before: S::Undefined,
            after: S::DepthWrite,
        }]);
        enc.begin_rendering(
            (size, size),
            &[],
            Some(DepthTarget {
                image: &self.depth,
                clear: 1.0,
            }),
        );
        let drawn = enc.draw(
            &self.pipeline,
            &self.group,
            bytemuck::bytes_of(push),
            vertices,
        );
        enc.end_rendering();
        enc.barriers(&[Barrier::Image {
            image: &self.depth,
            before: S::DepthWrite,
            after: S::ShaderResource,
        }]);
        enc.end_pass();
        drawn?;
        Ok(())
    }
}
