//! Shared harness of the GPU integration tests: a validated device, rendering a view, and comparisons
//! against the exact CPU reference with mismatches reported as counts.

// Each test binary uses only part of the harness.
#![allow(dead_code, unused_imports)]

use glam::Vec3;
pub use host_demo::accuracy::*;
use host_demo::View;
use passes::{FrameImages, FrameReport, PrimitiveMapConfig, ShadowRenderer};
use rhi::{Device, DeviceDesc};
use scene::{Camera, DirectionalLight, Object, Scene};
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

/// Appends an axis-aligned box (12 triangles, counter-clockwise seen from outside) as object `name`.
pub fn add_box(scene: &mut Scene, name: &str, min: Vec3, max: Vec3) {
    let base = scene.positions.len() as u32;
    let first_triangle = scene.triangle_count() as u32;
    for i in 0..8u32 {
        scene.positions.push(Vec3::new(
            if i & 1 != 0 { max.x } else { min.x },
            if i & 2 != 0 { max.y } else { min.y },
            if i & 4 != 0 { max.z } else { min.z },
        ));
    }
    // Faces as corner quads (a, b, c, d) counter-clockwise from outside.
    let faces = [
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
    ];
    for [a, b, c, d] in faces {
        scene
            .indices
            .extend([a, b, c, a, c, d].map(|k: u32| base + k));
    }
    scene.objects.push(Object {
        name: name.into(),
        first_triangle,
        triangle_count: 12,
    });
}

/// A ground plane, a thin horizontal plate 1.5 m above it and a box standing on it.
pub fn plate_and_box() -> Scene {
    let mut s = Scene::default();
    add_box(
        &mut s,
        "ground",
        Vec3::new(-3.0, -0.05, -3.0),
        Vec3::new(3.0, 0.0, 3.0),
    );
    add_box(
        &mut s,
        "plate",
        Vec3::new(-2.0, 1.5, -0.6),
        Vec3::new(-0.8, 1.52, 0.6),
    );
    add_box(
        &mut s,
        "box",
        Vec3::new(0.8, 0.0, -0.3),
        Vec3::new(1.4, 0.8, 0.3),
    );
    s.validate().expect("valid test scene");
    s
}

pub fn plate_and_box_view(width: u32, height: u32) -> View {
    let mut view = View::framed(plate_and_box(), width, height);
    view.camera = Camera {
        position: Vec3::new(0.0, 4.5, 4.5),
        target: Vec3::new(0.0, 0.0, 0.4),
        up: Vec3::Y,
        fov_y_radians: 45f32.to_radians(),
        near: 0.05,
    };
    view.light = DirectionalLight::new(Vec3::new(0.35, -1.0, 0.6)).expect("light");
    view
}
