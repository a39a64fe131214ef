//! The device Bevy creates, with the plugin's two Vulkan 1.3 features added.

use ash::vk;
use bevy::prelude::*;
use bevy::render::renderer::raw_vulkan_init::RawVulkanInitSettings;
use hrts_wgpu::EnabledFeatures;
use std::sync::{Arc, Mutex};

/// The core features of the device Bevy created, once it has (`None` before, or on a device not created
/// through Vulkan 1.3).
pub(crate) type SharedFeatures = Arc<Mutex<Option<EnabledFeatures>>>;

/// Registers the callback that adds `synchronization2` and `dynamicRendering` to the device Bevy's
/// `RenderPlugin` creates, and returns where it leaves the core features the device has.
pub(crate) fn request_plugin_features(app: &mut App) -> SharedFeatures {
    let enabled = SharedFeatures::default();
    let seen = enabled.clone();
    let mut settings = app
        .world_mut()
        .get_resource_or_init::<RawVulkanInitSettings>();
    // SAFETY: the callback adds two features every Vulkan 1.3 device supports, to Vulkan 1.3 devices only,
    // and removes nothing.
    unsafe {
        settings.add_create_device_callback(move |args, adapter, _additional| {
            // An older device is created as Bevy asks; the plugin then reports that it cannot adopt it.
            let version = adapter
                .physical_device_capabilities()
                .properties()
                .api_version;
            if version < vk::API_VERSION_1_3 {
                return;
            }
            *seen.lock().unwrap_or_else(|e| e.into_inner()) =
                Some(EnabledFeatures::of(&args.device_features.get_core()));
            // The create info is read after this callback returns: the two structs live as long as the
            // program (two small structs per device Bevy creates).
            let sync2 = Box::leak(Box::new(
                vk::PhysicalDeviceSynchronization2Features::default().synchronization2(true),
            ));
            let dynamic_rendering = Box::leak(Box::new(
                vk::PhysicalDeviceDynamicRenderingFeatures::default().dynamic_rendering(true),
            ));
            let info = std::mem::take(args.create_info);
            *args.create_info = info.push_next(sync2).push_next(dynamic_rendering);
        });
    }
    enabled
}
