//! A full-screen compute pass (one invocation per pixel, 8x8 groups) and the visibility images the
//! screen-space passes write.

use crate::shaders::shader;
use crate::PassError;
use rhi::{
    BindGroup, BindingKind, ComputePipeline, Device, Encoder, Format, Image, ImageDesc, ImageUsage,
    Resource,
};

/// A compute pipeline with its bound resources, dispatched over a `width` x `height` image.
pub(crate) struct ScreenPass {
    name: &'static str,
    pipeline: ComputePipeline,
    group: BindGroup,
}

impl ScreenPass {
    /// Creates the pass `name` from the embedded shader `shader_name`, binding `resources` in order.
    pub fn new(
        device: &Device,
        name: &'static str,
        shader_name: &str,
        bindings: &[BindingKind],
        resources: &[Resource<'_>],
        push_constant_size: u32,
    ) -> Result<Self, PassError> {
        let pipeline = device.create_compute_pipeline(
            name,
            &shader(shader_name)?,
            bindings,
            push_constant_size,
        )?;
        let group = device.create_bind_group(pipeline.layout(), resources)?;
        Ok(Self {
            name,
            pipeline,
            group,
        })
    }

    /// A bind group of the pass with `binding` bound to `resource` (of the kind bound there), the others
    /// as they are, for [`ScreenPass::use_group`].
    pub fn rebound(
        &self,
        device: &Device,
        binding: u32,
        resource: Resource<'_>,
    ) -> Result<BindGroup, PassError> {
        Ok(device.rebound(self.pipeline.layout(), &self.group, binding, resource)?)
    }

    /// Dispatches with `group` (from [`ScreenPass::rebound`]) from now on; returns the group used before:
    /// frames in flight may still use it.
    pub fn use_group(&mut self, group: BindGroup) -> BindGroup {
        std::mem::replace(&mut self.group, group)
    }

    /// Records one timed dispatch covering `width` x `height` pixels.
    pub fn record(
        &self,
        enc: &mut Encoder<'_>,
        push: &[u8],
        width: u32,
        height: u32,
    ) -> Result<(), PassError> {
        enc.begin_pass(self.name);
        let dispatched = enc.dispatch(
            &self.pipeline,
            &self.group,
            push,
            [width.div_ceil(8), height.div_ceil(8), 1],
        );
        enc.end_pass();
        dispatched?;
        Ok(())
    }
}

/// An `R32_SFLOAT` screen-size image a pass writes as a UAV (also sampled, copied and cleared).
pub(crate) fn visibility_image(
    device: &Device,
    name: &str,
    width: u32,
    height: u32,
) -> Result<Image, PassError> {
    Ok(device.create_image(&ImageDesc {
        name,
        format: Format::R32Float,
        width,
        height,
        layers: 1,
        usage: ImageUsage::STORAGE
            | ImageUsage::SAMPLED
            | ImageUsage::COPY_SRC
            | ImageUsage::COPY_DST,
    })?)
}
