//! Acceleration structures as objects: their storage, what they hold, and their destruction (the layer
//! below [`crate::pipeline`], which binds them). Building them is [`crate::raytracing`]'s.

use crate::device::Shared;
use crate::resources::Buffer;
use ash::vk;
use std::sync::Arc;

/// An acceleration structure with its storage and its own build scratch memory.
pub(crate) struct AccelerationStructure {
    pub(crate) shared: Arc<Shared>,
    pub(crate) raw: vk::AccelerationStructureKHR,
    /// Device address of the structure (what a top-level instance references).
    pub(crate) address: u64,
    /// Device address of the scratch memory, aligned as the device requires.
    pub(crate) scratch_address: u64,
    // Keep the memory alive until the structure is destroyed (Drop runs before the fields drop).
    pub(crate) _storage: Buffer,
    pub(crate) _scratch: Buffer,
}

impl Drop for AccelerationStructure {
    fn drop(&mut self) {
        if let Ok(rt) = &self.shared.ray_tracing {
            // SAFETY: created by this device; GPU work using it has completed before the owner drops it.
            unsafe { rt.accel.destroy_acceleration_structure(self.raw, None) };
        }
    }
}

/// A bottom-level acceleration structure over one [`TriangleGeometry`], built for fast tracing.
pub struct BottomLevel {
    pub(crate) inner: AccelerationStructure,
    pub(crate) vertices: u64,
    pub(crate) stride: u64,
    pub(crate) triangle_count: u32,
}

impl BottomLevel {
    pub(crate) fn geometry(&self) -> vk::AccelerationStructureGeometryKHR<'static> {
        triangles(self.vertices, self.stride, self.triangle_count)
    }
}

pub(crate) fn triangles(
    vertices: u64,
    stride: u64,
    triangle_count: u32,
) -> vk::AccelerationStructureGeometryKHR<'static> {
    let data = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
        .vertex_format(vk::Format::R32G32B32_SFLOAT)
        .vertex_data(vk::DeviceOrHostAddressConstKHR {
            device_address: vertices,
        })
        .vertex_stride(stride)
        .max_vertex((triangle_count * 3).saturating_sub(1))
        .index_type(vk::IndexType::NONE_KHR);
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { triangles: data })
        .flags(vk::GeometryFlagsKHR::OPAQUE)
}

/// A top-level acceleration structure with one instance (identity transform) of the bottom level it owns.
pub struct TopLevel {
    pub(crate) inner: AccelerationStructure,
    // Holds the instance record the builds read.
    pub(crate) _instances: Buffer,
    pub(crate) instances_address: u64,
    pub(crate) bottom: BottomLevel,
}

impl TopLevel {
    /// The instanced bottom level.
    pub fn bottom_level(&self) -> &BottomLevel {
        &self.bottom
    }
}
