//! What a frame records: the engine's images ([`Targets`]), its camera and lights ([`Frame`], [`Light`]),
//! and copies of the plugin's resources ([`ResourceReadback`]).

use super::enums::{NormalEncoding, NormalSpace, Resource};
use super::geometry::Bounds;
use crate::types::*;
use glam::{Mat4, Vec3};

/// One light of a frame (`HrtsLight`), in the order of the configurations given to
/// [`Context::configure_lights`](crate::Context::configure_lights). Ranges: `None` (or 0) is unlimited.
///
/// ```
/// use hrts::glam::Vec3;
/// use hrts::{Light, SpotFrustum};
///
/// let sun = Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2), view_proj: None };
/// let lamp = Light::Point { position: Vec3::new(0.0, 2.5, 0.0), range: Some(10.0) };
/// let spot = Light::Spot {
///     position: Vec3::new(1.0, 3.0, 0.0),
///     direction: Vec3::NEG_Y,
///     frustum: SpotFrustum::Fitted { outer_cone: 0.6 },
///     range: None,
/// };
/// # let _ = (sun, lamp, spot);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Parallel light travelling along `direction`.
    Directional {
        /// Direction the light travels (need not be normalised; non-zero).
        direction: Vec3,
        /// The engine's orthographic view-projection enclosing casters and receivers, or `None` for the
        /// frustum the plugin fits to the shadow casters' bounds every frame.
        view_proj: Option<Mat4>,
    },
    /// Spot light at `position` pointing along `direction`.
    Spot {
        /// Emitter position in world space.
        position: Vec3,
        /// The spot's axis (need not be normalised; non-zero).
        direction: Vec3,
        /// The engine's frustum, or the cone the plugin fits frusta to.
        frustum: SpotFrustum,
        /// Distance beyond which the light has no effect.
        range: Option<f32>,
    },
    /// Point light at `position`, shining in every direction within `range`.
    Point {
        /// Emitter position in world space.
        position: Vec3,
        /// Distance beyond which the light has no effect.
        range: Option<f32>,
    },
}

/// How a spot light's frustum is known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpotFrustum {
    /// The engine's perspective view-projection with its eye at the light's position.
    Given(Mat4),
    /// Frusta the plugin fits to a cone of half-angle `outer_cone` radians, in (0, π/2] (up to π/3 one
    /// frustum, wider cones the five cube faces around the axis).
    Fitted {
        /// Half-angle of the cone in radians.
        outer_cone: f32,
    },
}

impl Light {
    /// The C light.
    pub(crate) fn to_c(self) -> HrtsLight {
        let none = HrtsLight {
            light_type: HrtsLightType::Directional as u32,
            position: [0.0; 3],
            direction: [0.0; 3],
            view_proj: [0.0; 16],
            range: 0.0,
            outer_cone: 0.0,
        };
        match self {
            Light::Directional {
                direction,
                view_proj,
            } => HrtsLight {
                direction: direction.to_array(),
                view_proj: view_proj.unwrap_or(Mat4::ZERO).to_cols_array(),
                ..none
            },
            Light::Spot {
                position,
                direction,
                frustum,
                range,
            } => {
                let (view_proj, outer_cone) = match frustum {
                    SpotFrustum::Given(view_proj) => (view_proj, 0.0),
                    SpotFrustum::Fitted { outer_cone } => (Mat4::ZERO, outer_cone),
                };
                HrtsLight {
                    light_type: HrtsLightType::Spot as u32,
                    position: position.to_array(),
                    direction: direction.to_array(),
                    view_proj: view_proj.to_cols_array(),
                    range: range.unwrap_or(0.0),
                    outer_cone,
                }
            }
            Light::Point { position, range } => HrtsLight {
                light_type: HrtsLightType::Point as u32,
                position: position.to_array(),
                range: range.unwrap_or(0.0),
                ..none
            },
        }
    }
}

/// One of the engine's images: a raw `VkImage` of the adopted device with the usage and format it was
/// created with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TargetImage {
    /// The `VkImage`.
    pub image: u64,
    /// `VkImageUsageFlags` it was created with.
    pub usage: u32,
    /// Its `VkFormat` (0: the default the field of [`Targets`] states).
    pub format: u32,
}

/// The engine's images the plugin reads and writes (`HrtsTargets`): 2D, one mip, the same size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Targets {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Depth as the engine's projection writes it (D16, D24, D32 with or without stencil; 0: D32), or a
    /// linear view-Z image (R32 or R16 float); usage includes SAMPLED.
    pub depth: TargetImage,
    /// Normals as `normal_encoding` says (0 format: RGBA32 float); ignored with [`NormalEncoding::None`].
    pub normal: TargetImage,
    /// How the normal image encodes the normal.
    pub normal_encoding: NormalEncoding,
    /// The space of the normals.
    pub normal_space: NormalSpace,
    /// The visibility image the plugin writes (1 = lit), light `i` to layer `i`: R32 float (0 too), R16
    /// float or R8 unorm; with STORAGE usage each light writes its layer directly, else it is copied in
    /// (R32) or converted by a blit.
    pub output: TargetImage,
    /// Array layers of the output image: at least the number of lights when a frame is recorded.
    pub output_layers: u32,
}

impl Targets {
    /// The C targets.
    pub(crate) fn to_c(self) -> HrtsTargets {
        HrtsTargets {
            struct_size: size_of::<HrtsTargets>() as u32,
            width: self.width,
            height: self.height,
            depth_image: self.depth.image,
            depth_usage: self.depth.usage,
            depth_format: self.depth.format,
            normal_image: self.normal.image,
            normal_usage: self.normal.usage,
            normal_format: self.normal.format,
            normal_encoding: self.normal_encoding as u32,
            normal_space: self.normal_space as u32,
            output_image: self.output.image,
            output_usage: self.output.usage,
            output_layers: self.output_layers,
            output_format: self.output.format,
        }
    }
}

/// Where one mesh's positions are in one frame (`HrtsMeshVertices`): a vertex buffer of that frame.
pub use crate::types::HrtsMeshVertices as MeshVertices;

/// One frame to record (`HrtsFrame`, less the command buffer, which each recording call takes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame<'a> {
    /// The engine's frame counter: it increases from frame to frame (gaps allowed) and stays the same
    /// across the calls that record one frame pass by pass. Recording frame `f` states that every frame up
    /// to `f - frames_in_flight` has completed on the GPU.
    pub frame_index: u64,
    /// World to view.
    pub view: Mat4,
    /// View to clip in Vulkan's conventions (depth 0..1), the projection that wrote the depth image:
    /// reversed or standard Z, finite or infinite far plane.
    pub proj: Mat4,
    /// Camera position in world space.
    pub camera_position: Vec3,
    /// One light per configured light, in configuration order.
    pub lights: &'a [Light],
    /// `VkImageLayout` of the depth image when the commands run (restored after).
    pub depth_layout: i32,
    /// `VkImageLayout` of the normal image when the commands run (restored after).
    pub normal_layout: i32,
    /// `VkImageLayout` of the output image before the plugin writes it (its contents are discarded).
    pub output_layout_before: i32,
    /// `VkImageLayout` the output image is left in.
    pub output_layout_after: i32,
    /// World-space bounds of the shadow casters this frame, when the geometry moved or deformed: the
    /// plugin culls lights by them (and fits directional lights without a matrix to them).
    pub bounds: Option<Bounds>,
    /// The meshes deformed this frame (read by the call that begins the frame).
    pub deformed: &'a [MeshVertices],
}

impl Frame<'_> {
    /// The C frame recorded into `command_buffer`, pointing at `lights` (this frame's lights in C form).
    pub(crate) fn to_c(self, command_buffer: u64, lights: &[HrtsLight]) -> HrtsFrame {
        HrtsFrame {
            struct_size: size_of::<HrtsFrame>() as u32,
            command_buffer,
            frame_index: self.frame_index,
            view: self.view.to_cols_array(),
            proj: self.proj.to_cols_array(),
            camera_position: self.camera_position.to_array(),
            lights: lights.as_ptr(),
            light_count: lights.len() as u32,
            depth_layout: self.depth_layout,
            normal_layout: self.normal_layout,
            output_layout_before: self.output_layout_before,
            output_layout_after: self.output_layout_after,
            bounds: self.bounds.map_or([0.0; 6], Bounds::to_c),
            has_bounds: self.bounds.is_some().into(),
            deformed: if self.deformed.is_empty() {
                std::ptr::null()
            } else {
                self.deformed.as_ptr()
            },
            deformed_count: self.deformed.len() as u32,
            light_stride: size_of::<HrtsLight>(),
            deformed_stride: size_of::<HrtsMeshVertices>(),
        }
    }
}

/// A copy of one of a light's resources, as the last complete frame left it, into an engine buffer
/// (`HrtsResourceReadback`, less the command buffer).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResourceReadback {
    /// The resource (allocated by the light's configuration: see
    /// [`Context::resource_info`](crate::Context::resource_info)).
    pub resource: Resource,
    /// The light whose resource to copy.
    pub light: u32,
    /// Destination `VkBuffer` (usage includes TRANSFER_DST).
    pub buffer: u64,
    /// Size of the destination buffer in bytes.
    pub buffer_size: u64,
    /// Byte offset of the copy in the buffer (a multiple of 4).
    pub offset: u64,
}

impl ResourceReadback {
    /// The C read-back recorded into `command_buffer`.
    pub(crate) fn to_c(self, command_buffer: u64) -> HrtsResourceReadback {
        HrtsResourceReadback {
            struct_size: size_of::<HrtsResourceReadback>() as u32,
            command_buffer,
            resource: self.resource as u32,
            light: self.light,
            buffer: self.buffer,
            buffer_size: self.buffer_size,
            offset: self.offset,
        }
    }
}
