//! What a device can do, read once at device creation and reported by the frame report.

use crate::conv::{conservative_raster_tier, ConservativeRasterTier};
use ash::vk;
use std::ffi::CStr;

/// Capabilities and limits that matter to the shadow passes.
#[derive(Debug, Clone)]
pub struct Capabilities {
    /// `deviceName`.
    pub device_name: String,
    /// Driver name and info (e.g. "llvmpipe / Mesa 22.3.6 (LLVM 15.0.6)").
    pub driver: String,
    /// Vulkan API version as "major.minor.patch".
    pub api_version: String,
    /// Physical device type (discrete, integrated, cpu, ...).
    pub device_type: String,
    /// D3D12 conservative-raster tier derived from the Vulkan properties.
    pub conservative_raster_tier: ConservativeRasterTier,
    /// `primitiveOverestimationSize` in pixels (0 without the extension).
    pub primitive_overestimation_size: f32,
    /// `maxExtraPrimitiveOverestimationSize` in pixels (0 without the extension).
    pub max_extra_primitive_overestimation_size: f32,
    /// Geometry shaders (needed by the software conservative-raster path).
    pub geometry_shader: bool,
    /// UAV writes and atomics from fragment shaders (needed by the primitive map).
    pub fragment_stores_and_atomics: bool,
    /// Depth clamp (keeps the primitive-map raster from clipping at the light's near/far planes).
    pub depth_clamp: bool,
    /// 64-bit floats in shaders.
    pub shader_float64: bool,
    /// `VK_EXT_fragment_shader_interlock` (D3D12 rasterizer-ordered views).
    pub fragment_shader_interlock: bool,
    /// `VK_KHR_ray_query` (DXR 1.1 inline ray tracing).
    pub ray_query: bool,
    /// `VK_KHR_ray_tracing_pipeline` (DXR 1.0 pipelines).
    pub ray_tracing_pipeline: bool,
    /// Timestamp queries on the graphics/compute queue.
    pub timestamps: bool,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f32,
    /// `maxStorageBufferRange` in bytes (lavapipe: 128 MiB).
    pub max_storage_buffer_range: u64,
    /// `maxImageDimension2D`.
    pub max_image_dimension_2d: u32,
    /// `maxImageArrayLayers` (bounds the primitive map depth d).
    pub max_image_array_layers: u32,
    /// `maxComputeWorkGroupCount[0..2]`.
    pub max_compute_work_group_count: [u32; 3],
    /// Subgroup arithmetic (`subgroupAdd`, `subgroupInclusiveAdd`, min/max) in compute shaders.
    pub compute_subgroup_arithmetic: bool,
}

impl Capabilities {
    /// Whether hardware conservative rasterization is usable.
    pub fn hardware_conservative_raster(&self) -> bool {
        self.conservative_raster_tier != ConservativeRasterTier::NotSupported
    }
}

/// Extension names of a physical device.
pub(crate) fn device_extensions(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Vec<String> {
    // SAFETY: `pd` was enumerated from `instance`, which is alive.
    unsafe { instance.enumerate_device_extension_properties(pd) }
        .unwrap_or_default()
        .iter()
        .filter_map(|e| {
            e.extension_name_as_c_str()
                .ok()
                .map(|s| s.to_string_lossy().into_owned())
        })
        .collect()
}

pub(crate) fn has_extension(exts: &[String], name: &CStr) -> bool {
    let name = name.to_string_lossy();
    exts.iter().any(|e| *e == name)
}

/// Reads the capabilities of `pd`, given the extensions and core features that are enabled on the device.
pub(crate) fn read_capabilities(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    enabled_extensions: &[String],
    features: &vk::PhysicalDeviceFeatures,
    queue_timestamp_bits: u32,
) -> Capabilities {
    let has = |n: &CStr| has_extension(enabled_extensions, n);
    let mut cr = vk::PhysicalDeviceConservativeRasterizationPropertiesEXT::default();
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut driver)
        .push_next(&mut subgroup);
    let has_cr = has(ash::ext::conservative_rasterization::NAME);
    if has_cr {
        props2 = props2.push_next(&mut cr);
    }
    // SAFETY: the chained structs live until the call returns; `pd` belongs to `instance`.
    unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
    let p = props2.properties;
    let cr_props = has_cr.then_some(&cr);
    let tier = conservative_raster_tier(cr_props);
    let cstr = |s: &[std::ffi::c_char]| {
        // SAFETY: Vulkan guarantees these fixed-size strings are NUL-terminated.
        unsafe { CStr::from_ptr(s.as_ptr()) }
            .to_string_lossy()
            .into_owned()
    };
    let v = p.api_version;
    Capabilities {
        device_name: cstr(&p.device_name),
        driver: format!(
            "{} / {}",
            cstr(&driver.driver_name),
            cstr(&driver.driver_info)
        ),
        api_version: format!(
            "{}.{}.{}",
            vk::api_version_major(v),
            vk::api_version_minor(v),
            vk::api_version_patch(v)
        ),
        device_type: device_type_name(p.device_type).to_owned(),
        conservative_raster_tier: tier,
        primitive_overestimation_size: cr_props.map_or(0.0, |c| c.primitive_overestimation_size),
        max_extra_primitive_overestimation_size: cr_props
            .map_or(0.0, |c| c.max_extra_primitive_overestimation_size),
        geometry_shader: features.geometry_shader == vk::TRUE,
        fragment_stores_and_atomics: features.fragment_stores_and_atomics == vk::TRUE,
        depth_clamp: features.depth_clamp == vk::TRUE,
        shader_float64: features.shader_float64 == vk::TRUE,
        fragment_shader_interlock: has(ash::ext::fragment_shader_interlock::NAME),
        ray_query: has(ash::khr::ray_query::NAME),
        ray_tracing_pipeline: has(ash::khr::ray_tracing_pipeline::NAME),
        timestamps: p.limits.timestamp_compute_and_graphics == vk::TRUE && queue_timestamp_bits > 0,
        timestamp_period_ns: p.limits.timestamp_period,
        max_storage_buffer_range: u64::from(p.limits.max_storage_buffer_range),
        max_image_dimension_2d: p.limits.max_image_dimension2_d,
        max_image_array_layers: p.limits.max_image_array_layers,
        max_compute_work_group_count: p.limits.max_compute_work_group_count,
        compute_subgroup_arithmetic: subgroup
            .supported_stages
            .contains(vk::ShaderStageFlags::COMPUTE)
            && subgroup
                .supported_operations
                .contains(vk::SubgroupFeatureFlags::BASIC | vk::SubgroupFeatureFlags::ARITHMETIC),
    }
}

/// Human-readable device type.
pub fn device_type_name(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
        vk::PhysicalDeviceType::CPU => "CPU",
        _ => "other",
    }
}
