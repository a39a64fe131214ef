//! The shadow casters as the engine holds them: [`CpuGeometry`] (copied) or [`VulkanMesh`]es (read from the
//! engine's buffers), each with its [`Draw`]s.

use super::enums::IndexType;
use crate::types::{HrtsDraw, HrtsVulkanGeometry};
use glam::{Mat4, Vec3};

/// A world-space box (`min` ≤ `max` on every axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Bounds {
    /// The C box: min xyz, max xyz.
    pub(crate) fn to_c(self) -> [f32; 6] {
        let (min, max) = (self.min, self.max);
        [min.x, min.y, min.z, max.x, max.y, max.z]
    }
}

/// One draw of a mesh (`HrtsDraw`): a range of its indices placed in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draw {
    /// First index of the draw.
    pub first_index: u32,
    /// Index count (a multiple of 3).
    pub index_count: u32,
    /// Object-to-world transform.
    pub transform: Mat4,
    /// Added to every index of the draw before it addresses a vertex (may be negative), as
    /// `vkCmdDrawIndexed`'s `vertexOffset`.
    pub base_vertex: i32,
}

impl Draw {
    /// The C draw.
    pub(crate) fn to_c(self) -> HrtsDraw {
        HrtsDraw {
            first_index: self.first_index,
            index_count: self.index_count,
            transform: self.transform.to_cols_array(),
            base_vertex: self.base_vertex,
        }
    }
}

/// Geometry in CPU arrays, copied by [`Context::set_geometry_cpu`](crate::Context::set_geometry_cpu)
/// (`HrtsCpuGeometry`).
#[derive(Debug, Clone, Copy)]
pub struct CpuGeometry<'a> {
    /// Object-space positions.
    pub positions: &'a [Vec3],
    /// Triangle-list indices into `positions`.
    pub indices: &'a [u32],
    /// The draws over `indices`.
    pub draws: &'a [Draw],
}

/// One of the engine's meshes in its Vulkan buffers (`HrtsVulkanGeometry`), read, never written: the
/// buffers need `VK_BUFFER_USAGE_STORAGE_BUFFER_BIT`. The handles are raw Vulkan handles of the adopted
/// device.
#[derive(Debug, Clone, Copy)]
pub struct VulkanMesh<'a> {
    /// `VkBuffer` holding the positions (`vertex_format`).
    pub vertex_buffer: u64,
    /// Size of the vertex buffer in bytes.
    pub vertex_buffer_size: u64,
    /// Byte offset of vertex 0 (a multiple of 4).
    pub vertex_offset: u64,
    /// Bytes between vertices (at least the position's size; a multiple of 4).
    pub vertex_stride: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// `VkBuffer` holding the indices.
    pub index_buffer: u64,
    /// Size of the index buffer in bytes.
    pub index_buffer_size: u64,
    /// Byte offset of index 0 (a multiple of 4).
    pub index_offset: u64,
    /// 16- or 32-bit indices.
    pub index_type: IndexType,
    /// Number of indices.
    pub index_count: u32,
    /// The mesh's draws.
    pub draws: &'a [Draw],
    /// World-space bounds of every triangle the draws place (the shadow casters): the plugin culls lights
    /// by the union of every mesh's, and the frame origin is its centre.
    pub bounds: Bounds,
    /// `VkFormat` of a position: `VK_FORMAT_R32G32B32_SFLOAT` (or 0), or 16-bit
    /// `VK_FORMAT_R16G16B16A16_SFLOAT`, `_SNORM` or `_UNORM` (w ignored).
    pub vertex_format: u32,
    /// Dequantization: a stored position q (normalized for snorm and unorm formats) is the object-space
    /// point `q * position_scale + position_offset`; a scale of zero on every axis means no
    /// dequantization.
    pub position_scale: Vec3,
    /// See `position_scale`.
    pub position_offset: Vec3,
}

impl VulkanMesh<'_> {
    /// The C mesh, pointing at `draws` (this mesh's draws in C form).
    pub(crate) fn to_c(self, draws: &[HrtsDraw]) -> HrtsVulkanGeometry {
        HrtsVulkanGeometry {
            struct_size: size_of::<HrtsVulkanGeometry>() as u32,
            vertex_buffer: self.vertex_buffer,
            vertex_buffer_size: self.vertex_buffer_size,
            vertex_offset: self.vertex_offset,
            vertex_stride: self.vertex_stride,
            vertex_count: self.vertex_count,
            index_buffer: self.index_buffer,
            index_buffer_size: self.index_buffer_size,
            index_offset: self.index_offset,
            index_type: self.index_type as u32,
            index_count: self.index_count,
            draws: draws.as_ptr(),
            draw_count: draws.len() as u32,
            bounds: self.bounds.to_c(),
            vertex_format: self.vertex_format,
            position_scale: self.position_scale.to_array(),
            position_offset: self.position_offset.to_array(),
            draw_stride: size_of::<HrtsDraw>(),
        }
    }
}
