//! The ray-tracing extensions of a device: which features it has, what is missing, and the loaded entry
//! points and limits (the layer below [`crate::device`], which enables them).

use ash::vk;
use std::ffi::CStr;

/// Which of the features ray tracing needs a physical device supports.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct RayTracingFeatures {
    /// `bufferDeviceAddress` (Vulkan 1.2).
    pub buffer_device_address: bool,
    /// `accelerationStructure`.
    pub acceleration_structure: bool,
    /// `rayTracingPipeline`.
    pub ray_tracing_pipeline: bool,
}

/// Names of the extensions and features ray tracing needs that a device lacks (empty: it has them all).
pub(crate) fn ray_tracing_missing(
    has_extension: impl Fn(&CStr) -> bool,
    features: RayTracingFeatures,
) -> Vec<&'static str> {
    let extensions = RayTracingDevice::EXTENSIONS
        .iter()
        .filter(|&&name| !has_extension(name))
        .map(|name| name.to_str().unwrap_or("(unnamed extension)"));
    let features = [
        (features.buffer_device_address, "bufferDeviceAddress"),
        (features.acceleration_structure, "accelerationStructure"),
        (features.ray_tracing_pipeline, "rayTracingPipeline"),
    ]
    .into_iter()
    .filter(|(present, _)| !present)
    .map(|(_, name)| name);
    extensions.chain(features).collect()
}

/// The ray-tracing limits the RHI honours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct RayTracingLimits {
    /// `shaderGroupHandleSize`.
    pub handle_size: u32,
    /// `shaderGroupHandleAlignment`: SBT record strides are multiples of it.
    pub handle_alignment: u32,
    /// `shaderGroupBaseAlignment`: every SBT region starts at a multiple of it.
    pub base_alignment: u32,
    /// `maxShaderGroupStride`.
    pub max_stride: u32,
    /// `maxRayDispatchInvocationCount`.
    pub max_invocations: u32,
    /// `minAccelerationStructureScratchOffsetAlignment`.
    pub scratch_alignment: u32,
}

/// The ray-tracing entry points and limits of a device created with ray tracing enabled.
pub(crate) struct RayTracingDevice {
    pub(crate) accel: ash::khr::acceleration_structure::Device,
    pub(crate) pipeline: ash::khr::ray_tracing_pipeline::Device,
    pub(crate) limits: RayTracingLimits,
}

impl RayTracingDevice {
    /// The device extensions ray tracing enables.
    pub(crate) const EXTENSIONS: [&'static CStr; 3] = [
        ash::khr::acceleration_structure::NAME,
        ash::khr::ray_tracing_pipeline::NAME,
        ash::khr::deferred_host_operations::NAME,
    ];

    /// Loads the entry points of `device`, which was created from `pd` with [`Self::EXTENSIONS`] and the
    /// features of [`RayTracingFeatures`] enabled, and reads the limits.
    pub(crate) fn new(
        instance: &ash::Instance,
        device: &ash::Device,
        pd: vk::PhysicalDevice,
    ) -> Self {
        let mut pipeline_props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut accel_props = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
        let mut props = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut pipeline_props)
            .push_next(&mut accel_props);
        // SAFETY: `pd` belongs to `instance` and has both extensions; the chain outlives the call.
        unsafe { instance.get_physical_device_properties2(pd, &mut props) };
        Self {
            accel: ash::khr::acceleration_structure::Device::new(instance, device),
            pipeline: ash::khr::ray_tracing_pipeline::Device::new(instance, device),
            limits: RayTracingLimits {
                handle_size: pipeline_props.shader_group_handle_size,
                handle_alignment: pipeline_props.shader_group_handle_alignment,
                base_alignment: pipeline_props.shader_group_base_alignment,
                max_stride: pipeline_props.max_shader_group_stride,
                max_invocations: pipeline_props.max_ray_dispatch_invocation_count,
                scratch_alignment: accel_props.min_acceleration_structure_scratch_offset_alignment,
            },
        }
    }
}

/// `value` rounded up to a multiple of `alignment` (a power of two, or 0/1 for none).
pub(crate) fn align_up(value: u64, alignment: u64) -> u64 {
    if alignment <= 1 {
        value
    } else {
        value.div_ceil(alignment) * alignment
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_features() -> RayTracingFeatures {
        RayTracingFeatures {
            buffer_device_address: true,
            acceleration_structure: true,
            ray_tracing_pipeline: true,
        }
    }

    #[test]
    fn nothing_missing_with_every_extension_and_feature() {
        assert!(ray_tracing_missing(|_| true, all_features()).is_empty());
    }

    #[test]
    fn mesa_22_lavapipe_lacks_everything() {
        // Mesa 22.3's lavapipe: bufferDeviceAddress (core 1.2) but no ray-tracing extensions.
        let features = RayTracingFeatures {
            buffer_device_address: true,
            ..RayTracingFeatures::default()
        };
        assert_eq!(
            ray_tracing_missing(|_| false, features),
            [
                "VK_KHR_acceleration_structure",
                "VK_KHR_ray_tracing_pipeline",
                "VK_KHR_deferred_host_operations",
                "accelerationStructure",
                "rayTracingPipeline",
            ]
        );
    }

    #[test]
    fn missing_names_only_what_is_absent() {
        let features = RayTracingFeatures {
            ray_tracing_pipeline: false,
            ..all_features()
        };
        let has = |n: &CStr| n != ash::khr::ray_tracing_pipeline::NAME;
        assert_eq!(
            ray_tracing_missing(has, features),
            ["VK_KHR_ray_tracing_pipeline", "rayTracingPipeline"]
        );
    }
}
