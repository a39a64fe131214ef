//! Per-pixel shadow rays through the deep primitive map: visibility (1 = lit) and blocker distance.
//!
//! Reads: depth, normal, the primitive map (state, per-pixel texels, list offsets and entries), prim buffer,
//! constants. Writes: visibility, blocker distance.

use crate::gpu_types::{constant_buffer, RayTraceConstants};
use crate::primitive_map::PrimitiveMap;
use crate::{shader, PassError};
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, ComputePipeline, Device, Encoder, Format, Image,
    ImageDesc, ImageUsage, Resource, ResourceState as S,
};

/// Ray-origin offset along the receiver's normal, in pixels of footprint at the receiver's distance.
/// Depth interpolation and the rasterizer's sub-pixel vertex snapping move the rebuilt point by well under
/// this, and an offset below a pixel can never show as peter-panning.
pub const RAY_OFFSET_PIXELS: f32 = 1.0 / 64.0;

/// Relative float bound added to the offset, times the largest frame coordinate of the receiver: covers
/// the rounding of camera + reconstructed offset, and of the stored vertices (4 ulps).
pub const RAY_OFFSET_FLOAT_BOUND: f32 = 4.0 * f32::EPSILON;

/// Binding of the list entries in `ray_trace.comp`.
const ENTRIES_BINDING: u32 = 6;

/// Inputs of the ray trace.
pub struct RayTraceInputs<'a> {
    /// Depth (`ShaderResource` state).
    pub depth: &'a Image,
    /// Camera-facing geometric normal, w = 0 on background (`ShaderResource` state).
    pub normal: &'a Image,
    /// The primitive map built this frame.
    pub map: &'a PrimitiveMap,
    /// Prim buffer.
    pub prims: &'a Buffer,
}

/// The ray-trace pass and its outputs.
pub struct RayTracePass {
    pipeline: ComputePipeline,
    group: BindGroup,
    constants: Buffer,
    /// `R32_SFLOAT` visibility, 1 = lit.
    pub visibility: Image,
    /// `R32_SFLOAT` distance from the ray origin to the nearest blocker; 0 where the receiver faces away
    /// from the light, -1 where lit or background. `None` when not asked for (the pass then stores none).
    pub blocker_distance: Option<Image>,
    /// A 1×1 image bound in place of the blocker distance when there is none (never written).
    unused_blocker: Option<Image>,
}

impl RayTracePass {
    /// Creates `width` x `height` outputs: the visibility (`visibility` when given), and the blocker distance
    /// if `blocker_distance`.
    pub fn new(
        device: &Device,
        inputs: &RayTraceInputs<'_>,
        width: u32,
        height: u32,
        blocker_distance: bool,
        visibility: Option<Image>,
    ) -> Result<Self, PassError> {
        let out = |name| ImageDesc {
            name,
            format: Format::R32Float,
            width,
            height,
            layers: 1,
            usage: ImageUsage::STORAGE | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
        };
        let visibility = match visibility {
            Some(image) => image,
            None => device.create_image(&out("rt visibility"))?,
        };
        let (blocker_distance, unused_blocker) = if blocker_distance {
            (
                Some(device.create_image(&out("rt blocker distance"))?),
                None,
            )
        } else {
            let unused = ImageDesc {
                width: 1,
                height: 1,
                ..out("rt blocker distance (not stored)")
            };
            (None, Some(device.create_image(&unused)?))
        };
        let blocker_binding = blocker_distance
            .as_ref()
            .or(unused_blocker.as_ref())
            .ok_or_else(|| PassError::InvalidConfig("no blocker image".into()))?;
        let constants = constant_buffer::<RayTraceConstants>(device, "ray trace constants")?;
        let pipeline = device.create_compute_pipeline(
            "ray trace",
            &shader("ray_trace.comp")?,
            &[
                BindingKind::UniformBuffer,
                BindingKind::SampledImage,
                BindingKind::SampledImage,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageBuffer,
                BindingKind::StorageImage,
                BindingKind::StorageImage,
            ],
            0,
        )?;
        let b = Resource::Buffer;
        let group = device.create_bind_group(
            pipeline.layout(),
            &[
                b(&constants),
                Resource::Image(inputs.depth),
                Resource::Image(inputs.normal),
                b(&inputs.map.state),
                b(inputs.map.pixel_texels()),
                b(&inputs.map.offsets),
                b(&inputs.map.entries),
                b(inputs.prims),
                Resource::Image(&visibility),
                Resource::Image(blocker_binding),
            ],
        )?;
        Ok(Self {
            pipeline,
            group,
            constants,
            visibility,
            blocker_distance,
            unused_blocker,
        })
    }

    /// Points the ray trace at the primitive map's entries after [`PrimitiveMap::grow`] reallocated them.
    /// Returns the bind group it used before: frames in flight may still use it.
    pub fn rebind_entries(
        &mut self,
        device: &Device,
        map: &PrimitiveMap,
    ) -> Result<BindGroup, PassError> {
        let group = device.rebound(
            self.pipeline.layout(),
            &self.group,
            ENTRIES_BINDING,
            &map.entries,
        )?;
        Ok(std::mem::replace(&mut self.group, group))
    }

    /// Records the constants' update (into the command buffer) and the pass.
    pub fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
    ) -> Result<(), PassError> {
        let mut constants = *constants;
        constants.misc.z = u32::from(self.blocker_distance.is_some());
        enc.update_buffer(&self.constants, 0, bytemuck::bytes_of(&constants))?;
        enc.begin_pass("ray trace");
        if let Some(unused) = &self.unused_blocker {
            // Bound as a storage image, so in the storage layout, though never written.
            enc.barriers(&[Barrier::Image {
                image: unused,
                before: S::Undefined,
                after: S::UnorderedAccess,
            }]);
        }
        let groups = [
            constants.dims.x.div_ceil(8),
            constants.dims.y.div_ceil(8),
            1,
        ];
        enc.dispatch(&self.pipeline, &self.group, &[], groups)?;
        enc.end_pass();
        Ok(())
    }
}
