//! Shared harness of the GPU integration tests: a validated device, rendering a view, and comparisons
//! against the exact CPU reference with mismatches reported as counts.

// Each test binary uses only part of the harness.
#![allow(dead_code, unused_imports)]

use demo_engine::{FrameImages, View};
use glam::Vec3;
pub use hrts_lab::accuracy::*;
pub use hrts_lab::frames::{PluginFrames, ViewInputs};
use passes::{FrameReport, PrimitiveMapConfig};
use rhi::{Device, DeviceDesc};
use scene::{Camera, DirectionalLight, Scene};
use std::path::PathBuf;
use test_support::ShadowRenderer;

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

/// A device with the validation layer and its synchronization validation on (through whichever of
/// `VK_EXT_layer_settings` and `VK_EXT_validation_features` the installed layer offers, printed). Fails
/// (never skips) without a Vulkan device, the layer or synchronization validation.
pub fn device() -> Device {
    let mut desc = DeviceDesc::from_env();
    desc.validation = true;
    desc.synchronization_validation = true;
    let device = Device::new_headless(&desc).unwrap_or_else(|e| {
        panic!("GPU tests need a Vulkan device with validation layers (CI installs mesa-vulkan-drivers and vulkan-validationlayers): {e}")
    });
    let sync = device
        .synchronization_validation()
        .expect("synchronization validation was asked for");
    println!(
        "validation layer on, synchronization validation through {}",
        sync.extension()
    );
    device
}

/// Fails the test if the validation layers reported any error or synchronization hazard.
pub fn assert_no_validation_errors(device: &Device) {
    let v = device.validation();
    assert_eq!(
        (v.errors(), v.hazards()),
        (0, 0),
        "Vulkan validation errors and synchronization hazards: {:#?}",
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
    let mut r = ShadowRenderer::new(device, view, config).expect("renderer");
    let report = r.render(device, &view.frame_inputs()).expect("render");
    let images = r.read_back(device, with_entries).expect("read back");
    (report, images)
}

/// A scene of named axis-aligned boxes `(name, min, max)`.
pub fn axis_boxes(boxes: &[(&str, Vec3, Vec3)]) -> Scene {
    let mut s = Scene::default();
    for &(name, min, max) in boxes {
        s.append(&Scene::axis_box(name, min, max));
    }
    s
}

/// The 6 m ground square, 5 cm thick, with its top at y = 0.
pub const GROUND: (&str, Vec3, Vec3) = (
    "ground",
    Vec3::new(-3.0, -0.05, -3.0),
    Vec3::new(3.0, 0.0, 3.0),
);

/// A ground plane, a thin horizontal plate 1.5 m above it and a box standing on it.
pub fn plate_and_box() -> Scene {
    let s = axis_boxes(&[
        GROUND,
        (
            "plate",
            Vec3::new(-2.0, 1.5, -0.6),
            Vec3::new(-0.8, 1.52, 0.6),
        ),
        ("box", Vec3::new(0.8, 0.0, -0.3), Vec3::new(1.4, 0.8, 0.3)),
    ]);
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

/// The turn of the strips scene ([`long_thin_strips`]): about no axis.
pub fn strips_turn() -> glam::Quat {
    glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.5)
}

/// A floor of long thin strips (triangles 200 m long and 20 cm wide, 6 m of them side by side) under a
/// table and a plate, the whole turned by [`strips_turn`]: a ray origin a hair above its own strip sees a
/// sliver reaching 100 m either way, whose orientation the rounding of an origin-relative determinant
/// gets wrong. The camera looks down at the table from 3.5 m.
pub fn long_thin_strips() -> (Scene, Camera) {
    let turn = strips_turn();
    let (half_length, width, strips) = (100.0f32, 0.2f32, 30u32);
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for i in 0..strips {
        let z0 = -3.0 + i as f32 * width;
        let base = positions.len() as u32;
        positions.extend([
            Vec3::new(-half_length, 0.0, z0),
            Vec3::new(half_length, 0.0, z0),
            Vec3::new(half_length, 0.0, z0 + width),
            Vec3::new(-half_length, 0.0, z0 + width),
        ]);
        indices.extend([base, base + 2, base + 1, base, base + 3, base + 2]);
    }
    let mut scene = Scene::single_object(positions, indices, "floor strips");
    scene.append(&axis_boxes(&[
        (
            "table",
            Vec3::new(-1.2, 0.7, -0.8),
            Vec3::new(0.4, 0.76, 0.6),
        ),
        (
            "plate",
            Vec3::new(-0.3, 2.2, 0.9),
            Vec3::new(0.9, 2.23, 1.9),
        ),
    ]));
    for p in &mut scene.positions {
        *p = turn * *p;
    }
    scene.validate().expect("valid test scene");
    let camera = Camera {
        position: turn * Vec3::new(2.4, 2.2, 2.6),
        target: turn * Vec3::new(-0.5, 0.0, -0.6),
        up: turn * Vec3::Y,
        fov_y_radians: 70f32.to_radians(),
        near: 0.05,
    };
    (scene, camera)
}

/// Asserts an area-shadow comparison with the exact reference of the same samples (`name` in messages):
/// every value a whole count, 0 mismatched counts on stable pixels, at least `min_penumbra` stable
/// penumbra pixels judged (a test that cannot fail is no test), at most `max_unstable_percent` of the
/// pixels unstable.
pub fn assert_exact_area(
    name: &str,
    c: &AreaComparison,
    min_penumbra: usize,
    max_unstable_percent: usize,
) {
    assert_eq!(c.non_finite, 0, "{name}: values that are no count");
    assert_eq!(
        c.mismatches, 0,
        "{name}: stable pixels whose visible count differs (x, y, reference, GPU): {:?}",
        c.examples
    );
    assert!(
        c.penumbra >= min_penumbra,
        "{name}: only {} stable penumbra pixels judged",
        c.penumbra
    );
    assert!(
        c.unstable * 100 <= c.pixels * max_unstable_percent,
        "{name}: {} of {} pixels unstable",
        c.unstable,
        c.pixels
    );
}

/// Asserts a visibility comparison with the exact reference: no NaN/Inf, 0 mismatches outside near-edge
/// pixels, a view with shadows in it (more than 2% of its pixels), and at most `max_near_edge_fraction`
/// of the pixels near an edge.
pub fn assert_exact_visibility(c: &VisibilityComparison, max_near_edge_fraction: f64) {
    assert_eq!(c.non_finite, 0, "NaN/Inf pixels: {c:?}");
    assert_eq!(
        c.mismatches, 0,
        "mismatching pixels (x, y, exact, gpu): {:?}",
        c.examples
    );
    assert!(
        c.shadowed > c.pixels / 50,
        "the view should contain shadows: {} of {} pixels",
        c.shadowed,
        c.pixels
    );
    let fraction = c.near_edge as f64 / c.pixels as f64;
    assert!(
        fraction <= max_near_edge_fraction,
        "near-edge pixels {:.3}% exceed the bound",
        fraction * 100.0
    );
}
