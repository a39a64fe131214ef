//! Per-pixel shadow rays through the deep primitive map: visibility (1 = lit) and blocker distance; or, for
//! area shadows, the visible fraction of the light's samples (`area_trace.glsl`, in a variant for
//! directional lights and one for spot and point lights).
//!
//! Where the map holds no complete list for a pixel (no list built this frame, a texel past the entry
//! capacity or the list limit), the pixel walks the BVH over the prim buffer instead (`crate::bvh`), with
//! the same test: the same answer.
//!
//! Reads: depth, normal, the primitive map (state, per-pixel texels, list offsets and entries), prim buffer
//! and its BVH, constants (and the light samples, area shadows). Writes: visibility, blocker distance (hard
//! rays only), the count of the walks in the map's state, and an area trace's tile history
//! ([`TILE_SKIP_FRAMES`]).

use crate::area::{
    area_edge_table, area_sample_bands, local_area_edge_table, local_sample_bands, WIDE_BUNDLE,
};
use crate::gpu_types::{constant_buffer, AreaSamples, RayTraceConstants};
use crate::primitive_map::PrimitiveMap;
use crate::shaders::{output_variant, shader};
use crate::PassError;
use rhi::{
    Barrier, BindGroup, BindingKind, Buffer, BufferUsage, ComputePipeline, Device, Encoder, Format,
    Image, ImageDesc, ImageUsage, Resource, ResourceState as S,
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

/// Binding of the visibility in `ray_trace.comp`.
const VISIBILITY_BINDING: u32 = 8;

/// The most frames for which an area trace's tile of 8×8 pixels skips its wide bundles once more than
/// [`TILE_GIVE_UPS`] of its pixels' bundles gave up their walk in a frame having decided less than half
/// their samples: its wide pixels then walk each sample at once (`area_trace.glsl`, the tile history),
/// since such a bundle cost its budget for little. A tile skips up to [`TILE_SKIP_STAGGER`] frames fewer,
/// by tile, so that a light's tiles do not all try their bundles again in the same frame; then it tries
/// them for a frame. The answer is the same either way; only the cost follows the history, which starts
/// again from nothing when the light's size or kind changes. (On an H200 at 1080p, point lights of 8 % of
/// the scene's extent traced 15-38 % faster, lights of 0.25-4 % up to 7 % slower.)
pub const TILE_SKIP_FRAMES: u32 = 16;

/// The most frames fewer than [`TILE_SKIP_FRAMES`] a tile skips, by tile.
pub const TILE_SKIP_STAGGER: u32 = 7;

/// The give-ups of a tile's 64 pixels past which it skips its wide bundles ([`TILE_SKIP_FRAMES`]).
pub const TILE_GIVE_UPS: u32 = 48;

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
    /// The linear BVH's nodes over the prim buffer, which the area trace's bundles walk
    /// ([`crate::bvh::SceneBvh::nodes`]).
    pub bvh: &'a Buffer,
    /// The rays' BVH's nodes, which single rays and segments walk ([`crate::bvh::SceneBvh::ray_nodes`]).
    pub ray_bvh: &'a Buffer,
}

/// What the ray trace computes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RayTraceKind {
    /// One shadow ray per pixel: hard visibility, and the blocker distance if `blocker_distance`.
    Hard {
        /// Whether the blocker distance is written.
        blocker_distance: bool,
    },
    /// The visible fraction of an area light's samples ([`crate::area`]).
    Area {
        /// The light's angular radius (radians).
        angular_radius: f32,
        /// Light samples per pixel.
        samples: u32,
    },
}

/// The buffers an area trace reads besides the map and the prim buffer.
struct AreaBuffers {
    /// The light's samples, updated each frame.
    samples: Buffer,
    /// A directional light's edge table, then a spot or point light's (each variant of `area_trace.glsl`
    /// reads its own).
    edge_tables: Buffer,
    /// Likewise for the BVH walk's sample bands.
    sample_bands: Buffer,
    /// One word per 8×8 tile ([`TILE_SKIP_FRAMES`]).
    tile_history: Buffer,
}

/// The ray-trace pass and its outputs.
pub struct RayTracePass {
    /// The trace's pipeline and bind group (an area trace's for directional lights).
    pipeline: ComputePipeline,
    group: BindGroup,
    /// An area trace's pipeline and bind group for spot lights, beside the directional one (a point light's
    /// cube map has the local variant as its one pipeline).
    local: Option<(ComputePipeline, BindGroup)>,
    /// An area trace's pipeline and bind group for the directional lights whose bundle is never wide (their
    /// angular bound at most [`WIDE_BUNDLE`]): without the samples' own walks, whose code and registers slow
    /// every pixel.
    narrow: Option<(ComputePipeline, BindGroup)>,
    constants: Buffer,
    /// The area trace's own buffers (area shadows only).
    area: Option<AreaBuffers>,
    /// The light's kind and size whose tile history the area trace holds (the bits of the constants' light
    /// position w and emitter radius, and of the samples' angular bound): a change clears it.
    history_of: Option<[u32; 3]>,
    /// `R32_SFLOAT` visibility, 1 = lit.
    pub visibility: Image,
    /// `R32_SFLOAT` distance from the ray origin to the nearest blocker; 0 where the receiver faces away
    /// from the light, -1 where lit or background. `None` when not asked for (the pass then stores none).
    pub blocker_distance: Option<Image>,
    /// A 1×1 image bound in place of the blocker distance when there is none (never written).
    unused_blocker: Option<Image>,
}

impl RayTracePass {
    /// Bytes of an area trace's own buffers besides its images: the light samples, the edge tables, the
    /// sample bands and the tile history (0 for a hard trace).
    pub fn area_buffer_bytes(&self) -> u64 {
        self.area.as_ref().map_or(0, |a| {
            a.samples.size() + a.edge_tables.size() + a.sample_bands.size() + a.tile_history.size()
        })
    }

    /// Creates `width` x `height` outputs: the visibility (`visibility` when given), and the blocker distance
    /// if `kind` asks for it.
    pub fn new(
        device: &Device,
        inputs: &RayTraceInputs<'_>,
        width: u32,
        height: u32,
        kind: RayTraceKind,
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
        let (blocker_distance, unused_blocker) = match kind {
            RayTraceKind::Area { .. } => (None, None),
            RayTraceKind::Hard {
                blocker_distance: true,
            } => (
                Some(device.create_image(&out("rt blocker distance"))?),
                None,
            ),
            RayTraceKind::Hard {
                blocker_distance: false,
            } => {
                let unused = ImageDesc {
                    width: 1,
                    height: 1,
                    ..out("rt blocker distance (not stored)")
                };
                (None, Some(device.create_image(&unused)?))
            }
        };
        let area = match kind {
            RayTraceKind::Area {
                angular_radius,
                samples,
            } => Some(AreaBuffers {
                samples: constant_buffer::<AreaSamples>(device, "area light samples")?,
                edge_tables: device.create_buffer_init(
                    "area edge tables",
                    bytemuck::cast_slice(
                        &[
                            area_edge_table(angular_radius, samples).gpu_words(),
                            local_area_edge_table(samples).gpu_words(),
                        ]
                        .concat(),
                    ),
                    BufferUsage::STORAGE,
                )?,
                sample_bands: device.create_buffer_init(
                    "area sample bands",
                    bytemuck::cast_slice(
                        &[
                            area_sample_bands(angular_radius, samples).gpu_words(),
                            local_sample_bands(samples).gpu_words(),
                        ]
                        .concat(),
                    ),
                    BufferUsage::STORAGE,
                )?,
                tile_history: device.create_buffer_init(
                    "area trace tile history",
                    &vec![0; 4 * width.div_ceil(8) as usize * height.div_ceil(8) as usize],
                    BufferUsage::STORAGE | BufferUsage::COPY_DST,
                )?,
            }),
            RayTraceKind::Hard { .. } => None,
        };
        let constants = constant_buffer::<RayTraceConstants>(device, "ray trace constants")?;
        let mut kinds = vec![
            BindingKind::UniformBuffer,
            BindingKind::SampledImage,
            BindingKind::SampledImage,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageImage,
        ];
        let b = Resource::Buffer;
        let mut resources = vec![
            b(&constants),
            Resource::Image(inputs.depth),
            Resource::Image(inputs.normal),
            b(&inputs.map.state),
            b(inputs.map.pixel_texels()),
            b(&inputs.map.offsets),
            b(&inputs.map.entries),
            b(inputs.prims),
            Resource::Image(&visibility),
        ];
        match (&area, &blocker_distance, &unused_blocker) {
            (Some(area), _, _) => {
                kinds.extend([BindingKind::UniformBuffer, BindingKind::StorageBuffer]);
                resources.extend([b(&area.samples), b(&area.edge_tables)]);
            }
            (None, Some(image), _) | (None, None, Some(image)) => {
                kinds.push(BindingKind::StorageImage);
                resources.push(Resource::Image(image));
            }
            (None, None, None) => {
                return Err(PassError::InvalidConfig("no blocker image".into()));
            }
        }
        kinds.push(BindingKind::StorageBuffer);
        if let Some(area) = &area {
            kinds.extend([BindingKind::StorageBuffer; 3]);
            resources.extend([
                b(inputs.bvh),
                b(&area.sample_bands),
                b(inputs.ray_bvh),
                b(&area.tile_history),
            ]);
        } else {
            resources.push(b(inputs.ray_bvh));
        }
        // A point light's cube map only ever traces a local light: the local variant is its one pipeline.
        let cube = inputs.map.config().cube;
        let (name, shader_name) = match kind {
            RayTraceKind::Area { .. } if cube => {
                ("area trace (point light)", "area_trace_local.comp")
            }
            RayTraceKind::Area { .. } => ("area trace (directional lights)", "area_trace.comp"),
            RayTraceKind::Hard { .. } => ("ray trace", "ray_trace.comp"),
        };
        let format = visibility.format();
        let variant = |name: &str, shader_name: &str| -> Result<_, PassError> {
            let pipeline = device.create_compute_pipeline(
                name,
                &shader(&output_variant(shader_name, format)?)?,
                &kinds,
                0,
            )?;
            let group = device.create_bind_group(pipeline.layout(), &resources)?;
            Ok((pipeline, group))
        };
        let (pipeline, group) = variant(name, shader_name)?;
        let (local, narrow) = match kind {
            RayTraceKind::Area { .. } if !cube => (
                Some(variant(
                    "area trace (spot and point lights)",
                    "area_trace_local.comp",
                )?),
                Some(variant(
                    "area trace (directional lights, never wide)",
                    "area_trace_narrow.comp",
                )?),
            ),
            _ => (None, None),
        };
        Ok(Self {
            pipeline,
            group,
            local,
            narrow,
            constants,
            area,
            history_of: None,
            visibility,
            blocker_distance,
            unused_blocker,
        })
    }

    /// Points the ray trace at the primitive map's entries after [`PrimitiveMap::grow`] reallocated them.
    /// Returns the bind groups it used before: frames in flight may still use them.
    pub fn rebind_entries(
        &mut self,
        device: &Device,
        map: &PrimitiveMap,
    ) -> Result<Vec<BindGroup>, PassError> {
        self.rebind(device, ENTRIES_BINDING, Resource::Buffer(&map.entries))
    }

    /// Has the ray trace write `visibility` (of the same size and format) in place of its visibility image
    /// from now on (nothing changes if it fails). Returns the image and the bind groups it used before:
    /// frames in flight may still use them.
    pub fn replace_visibility(
        &mut self,
        device: &Device,
        visibility: Image,
    ) -> Result<(Image, Vec<BindGroup>), PassError> {
        let groups = self.rebind(device, VISIBILITY_BINDING, Resource::Image(&visibility))?;
        Ok((std::mem::replace(&mut self.visibility, visibility), groups))
    }

    /// Rebinds `binding` of the trace's bind groups to `resource`, all or none of them; returns the groups
    /// used before.
    fn rebind(
        &mut self,
        device: &Device,
        binding: u32,
        resource: Resource<'_>,
    ) -> Result<Vec<BindGroup>, PassError> {
        let main = device.rebound(self.pipeline.layout(), &self.group, binding, resource)?;
        let rebound = |variant: &Option<(ComputePipeline, BindGroup)>| match variant {
            Some((pipeline, group)) => device
                .rebound(pipeline.layout(), group, binding, resource)
                .map(Some),
            None => Ok(None),
        };
        let local = rebound(&self.local)?;
        let narrow = rebound(&self.narrow)?;
        let mut old = vec![std::mem::replace(&mut self.group, main)];
        for (variant, new) in [(&mut self.local, local), (&mut self.narrow, narrow)] {
            if let (Some((_, group)), Some(new)) = (variant, new) {
                old.push(std::mem::replace(group, new));
            }
        }
        Ok(old)
    }

    /// Records the constants' update (into the command buffer) and the pass; an area trace also updates
    /// its light samples from `samples`.
    pub fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &RayTraceConstants,
        samples: Option<&AreaSamples>,
    ) -> Result<(), PassError> {
        let mut constants = *constants;
        if samples.is_none() {
            constants.misc.z = u32::from(self.blocker_distance.is_some());
        }
        enc.update_buffer(&self.constants, 0, bytemuck::bytes_of(&constants))?;
        match (&self.area, samples) {
            (Some(area), Some(samples)) => {
                enc.update_buffer(&area.samples, 0, bytemuck::bytes_of(samples))?;
                let light = [
                    constants.light_pos.w.to_bits(),
                    constants.light_dir.w.to_bits(),
                    samples.center.w.to_bits(),
                ];
                if self.history_of.is_some_and(|of| of != light) {
                    // What the tiles' bundles did under another light says nothing of this one's.
                    enc.barriers(&[Barrier::Global {
                        before: S::UnorderedAccess,
                        after: S::CopyDest,
                    }]);
                    enc.fill_buffer(&area.tile_history, 0);
                    enc.barriers(&[Barrier::Global {
                        before: S::CopyDest,
                        after: S::UnorderedAccess,
                    }]);
                }
                self.history_of = Some(light);
            }
            (None, None) => {}
            _ => {
                return Err(PassError::InvalidConfig(
                    "light samples are given to an area trace, and to it alone".into(),
                ))
            }
        }
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
        // An area trace of a spot or point light (the constants' light position) takes its own variant; one
        // of a directional light whose bundle is never wide, with a walk budget, the variant without the
        // samples' own walks (it gives the same answer: such a bundle never gives up).
        let never_wide =
            samples.is_some_and(|s| s.center.w <= WIDE_BUNDLE) && constants.misc.z != 0;
        let (pipeline, group) = match (&self.local, &self.narrow) {
            (Some((pipeline, group)), _) if constants.light_pos.w != 0.0 => (pipeline, group),
            (_, Some((pipeline, group))) if never_wide => (pipeline, group),
            _ => (&self.pipeline, &self.group),
        };
        enc.dispatch(pipeline, group, &[], groups)?;
        enc.end_pass();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tile_history_constants_are_the_shaders() {
        let source = include_str!("../shaders/area_trace.glsl");
        assert!(source.contains(&format!(
            "const uint TILE_SKIP_FRAMES = {TILE_SKIP_FRAMES}u;"
        )));
        assert!(source.contains(&format!("const uint TILE_GIVE_UPS = {TILE_GIVE_UPS}u;")));
        assert!(source.contains(&format!(
            "const uint TILE_SKIP_STAGGER = {TILE_SKIP_STAGGER}u;"
        )));
    }
}
