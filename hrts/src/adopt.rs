//! The context's device: the engine's, adopted after checking what the plugin needs, or one of the
//! plugin's own.

use crate::error::{check_aligned, invalid, ApiError, ApiResult};
use crate::types::*;
use rhi::Device;

/// The device `info` asks for.
pub(crate) fn device(info: &HrtsContextCreateInfo) -> ApiResult<Device> {
    if info.vulkan.is_null() {
        let filter = if info.device_name_filter.is_null() {
            None
        } else {
            // SAFETY: a non-NULL filter is a NUL-terminated string (documented contract).
            let s = unsafe { std::ffi::CStr::from_ptr(info.device_name_filter) };
            Some(
                s.to_str()
                    .map_err(|_| invalid("device_name_filter is not UTF-8"))?
                    .to_owned(),
            )
        };
        return Ok(Device::new_headless(&rhi::DeviceDesc {
            validation: info.enable_validation != 0,
            synchronization_validation: false,
            device_filter: filter,
            ..rhi::DeviceDesc::from_env()
        })?);
    }
    let v = &crate::version::read(info.vulkan, "vulkan")?;
    let gipa = v.get_instance_proc_addr.ok_or_else(|| {
        ApiError::new(
            HrtsResult::ErrorNullPointer,
            "get_instance_proc_addr is NULL",
        )
    })?;
    if v.instance == 0 || v.physical_device == 0 || v.device == 0 {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            "instance, physical_device and device must be non-NULL",
        ));
    }
    let desc = rhi::AdoptDesc {
        get_instance_proc_addr: gipa,
        instance: v.instance,
        physical_device: v.physical_device,
        device: v.device,
        queue_family_index: v.queue_family_index,
        queue_index: v.queue_index,
        enabled_extensions: extension_names(v)?,
        enabled_features: rhi::EnabledFeatures {
            geometry_shader: v.geometry_shader != 0,
            fragment_stores_and_atomics: v.fragment_stores_and_atomics != 0,
            depth_clamp: v.depth_clamp != 0,
            shader_float64: false,
        },
        debug_utils: v.debug_utils != 0,
    };
    // SAFETY: the caller guarantees the handles are valid, belong together and outlive the context;
    // `adopt` checks the physical device for what the plugin needs and for what the engine claims.
    Ok(unsafe { Device::adopt(desc) }?)
}

/// The device extensions the engine says it enabled.
fn extension_names(v: &HrtsVulkanDevice) -> ApiResult<Vec<String>> {
    if v.enabled_extension_count == 0 {
        return Ok(Vec::new());
    }
    if v.enabled_extensions.is_null() {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            "enabled_extensions is NULL but its count is not 0",
        ));
    }
    check_aligned(v.enabled_extensions, "enabled_extensions")?;
    // SAFETY: aligned; the caller guarantees `enabled_extension_count` valid C strings.
    let names = unsafe {
        std::slice::from_raw_parts(v.enabled_extensions, v.enabled_extension_count as usize)
    };
    names
        .iter()
        .map(|&n| {
            if n.is_null() {
                return Err(ApiError::new(
                    HrtsResult::ErrorNullPointer,
                    "an enabled extension name is NULL",
                ));
            }
            // SAFETY: non-NULL NUL-terminated string.
            Ok(unsafe { std::ffi::CStr::from_ptr(n) }
                .to_string_lossy()
                .into_owned())
        })
        .collect()
}
