//! Shared harness of the GPU integration tests: a validated device, rendering a view, and comparisons
//! against the exact CPU reference with mismatches reported as counts.

// Each test binary uses only part of the harness.
#![allow(dead_code, unused_imports)]

pub use host_demo::accuracy::*;
use host_demo::View;
use passes::{FrameImages, FrameReport, PrimitiveMapConfig, ShadowRenderer};
use rhi::{Device, DeviceDesc};
use std::path::PathBuf;

/// The models folder (`HRTS_MODELS`, else `../shared/models` beside the checkout); fails the test with
/// a message saying where it looked when the models are missing.
pub fn models() -> PathBuf {
    scene::models_dir().unwrap_or_else(|e| panic!("{e}"))
}

/// A model of the models folder; fails the test if it is missing.
pub fn model(name: &str) -> PathBuf {
    let p = models().join(name);
    assert!(p.exists(), "test model {} is missing", p.display());
    p
}

/// A device with validation layers on. Fails (never skips) without a Vulkan device.
pub fn device() -> Device {
    let mut desc = DeviceDesc::from_env();
    desc.validation = true;
    Device::new_headless(&desc).unwrap_or_else(|e| {
        panic!("GPU tests need a Vulkan device with validation layers (CI installs mesa-vulkan-drivers and vulkan-validationlayers): {e}")
    })
}

/// Fails the test if the validation layers reported any error.
pub fn assert_no_validation_errors(device: &Device) {
    let v = device.validation();
    assert_eq!(
        v.errors(),
        0,
        "Vulkan validation errors: {:#?}",
        v.messages()
    );
}

/// Renders `view` once and reads everything back.
pub fn render(
    device: &Device,
    view: &View,
    config: PrimitiveMapConfig,
    with_entries: bool,
) -> (FrameReport, FrameImages) {
    let geometry = view.upload(device).expect("upload");
    let mut r =
        ShadowRenderer::new(device, geometry, view.width, view.height, config).expect("renderer");
    let report = r.render(device, &view.frame_inputs()).expect("render");
    let images = r.read_back(device, with_entries).expect("read back");
    (report, images)
}
