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
