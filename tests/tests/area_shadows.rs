//! Area shadows (exact soft shadows of a sized directional light) on lavapipe, against the exact
//! reference of the same light samples: every sample of every stable pixel decided as the reference decides
//! it (0 mismatched counts), on contact, thin plates and a fence of slats, foliage cards, overlapping
//! occluders, a closed mesh through shared edges, the demo scene translated 1e4 from the origin, and tiny
//! and large lights. Each comparison must see penumbra pixels (a test that cannot fail is no test). The
//! output is deterministic bit for bit, and invalid light sizes and sample counts are rejected with a
//! clear error.

mod common;

use common::{
    assert_exact_area, assert_no_validation_errors, axis_boxes, device, plate_and_box_view, GROUND,
};
use demo_engine::{FrameImages, View};
use glam::Vec3;
use hrts_lab::accuracy::{compare_area, AreaComparison};
use hrts_lab::frames::ViewInputs;
use passes::{
    AreaConfig, BinningRequest, FaceMode, FrameReport, PcssConfig, PrimitiveMapConfig,
    ShadowConfig, ShadowMode,
};
use reference::RefScene;
use rhi::Device;
use scene::hard_cases::{family, Family, HardCase};
use scene::{Camera, DirectionalLight};
use test_support::ShadowRenderer;

/// Test frames are downscaled from the hard cases' 193x145 so that the reference's N passes stay short.
const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

fn area_config(angular_radius: f32, samples: u32, faces: FaceMode) -> ShadowConfig {
    ShadowConfig {
        mode: ShadowMode::Area,
        antialiasing: false,
        map: PrimitiveMapConfig {
            size: 128,
            faces,
            binning: BinningRequest::Compute,
            ..PrimitiveMapConfig::default()
        },
        pcss: PcssConfig {
            angular_radius,
            ..PcssConfig::default()
        },
        area: AreaConfig {
            samples,
            ..AreaConfig::default()
        },
        ..ShadowConfig::default()
    }
}

fn render(device: &Device, view: &View, config: ShadowConfig) -> (FrameReport, FrameImages) {
    let mut r = ShadowRenderer::new(device, view, config).expect("renderer");
    let report = r.render(device, &view.frame_inputs()).expect("render");
    (report, r.read_back(device, false).expect("read back"))
}

/// Renders `view` in area mode and compares it with the reference; asserts exactness, at least
/// `min_penumbra` stable penumbra pixels to judge, and at most a quarter of the frame unstable.
fn check(
    device: &Device,
    name: &str,
    view: &View,
    (angular_radius, samples): (f32, u32),
    faces: FaceMode,
    min_penumbra: usize,
) -> AreaComparison {
    let config = area_config(angular_radius, samples, faces);
    let (report, images) = render(device, view, config);
    let rs = RefScene::new(&view.scene);
    let c = compare_area(&rs, view, angular_radius, samples, &images.output);
    println!(
        "{name}: r {angular_radius}, {samples} samples: {} px, {} unstable, {} penumbra, {} umbra, {} mismatches; map {} entries, longest list {}, {} texels past capacity",
        c.pixels, c.unstable, c.penumbra, c.umbra, c.mismatches, report.stats.entries,
        report.stats.longest_list, report.stats.texels_past_capacity
    );
    assert_exact_area(name, &c, min_penumbra, 25);
    assert_no_validation_errors(device);
    c
}

/// The hard case `name` of family `f`, framed as `hrts_lab hardcases` frames it at the test size, checked
/// with a light of `angular_radius` and `samples` samples (at least 20 stable penumbra pixels).
fn check_hard_case(f: Family, name: &str, (angular_radius, samples): (f32, u32)) {
    let case: HardCase = family(f, &common::models())
        .into_iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no hard case named {name}"));
    let mut view = View::framed(case.scene.expect("scene"), WIDTH, HEIGHT);
    view.light = DirectionalLight::new(case.light_direction).expect("light");
    if let Some(camera) = case.camera {
        view.camera = camera;
    }
    let faces = if case.map.front_faces_only {
        FaceMode::FrontOnly
    } else {
        FaceMode::Both
    };
    check(&device(), name, &view, (angular_radius, samples), faces, 20);
}

#[test]
fn contact_shadows_match_the_reference_sample_for_sample() {
    check_hard_case(Family::Contact, "contact 80°", (0.1, 32));
}

#[test]
fn thin_plates_fence_slats_and_foliage_cards() {
    check_hard_case(Family::ThinGeometry, "thin closed plates", (0.1, 32));
    check_hard_case(Family::ThinGeometry, "foliage cards", (0.1, 32));
}

/// The sphere is closed and stored front faces only: a sample through a shared edge must still be blocked.
#[test]
fn a_closed_mesh_leaks_no_sample_through_its_shared_edges() {
    check_hard_case(
        Family::SharedEdges,
        "closed UV sphere (front faces only)",
        (0.1, 32),
    );
}

/// Two plates overlapping as seen from the light at different heights: where both cover parts of the
/// light, the samples they block together (occluder fusion) are counted once.
#[test]
fn overlapping_occluders_fuse() {
    let device = device();
    let scene = axis_boxes(&[
        GROUND,
        (
            "low plate",
            Vec3::new(-1.0, 0.6, -0.8),
            Vec3::new(0.2, 0.62, 0.4),
        ),
        (
            "high plate",
            Vec3::new(-0.3, 1.2, -0.3),
            Vec3::new(0.9, 1.22, 0.9),
        ),
    ]);
    let mut view = plate_and_box_view(WIDTH, HEIGHT);
    view.scene = scene;
    check(
        &device,
        "overlapping plates",
        &view,
        (0.1, 64),
        FaceMode::Both,
        20,
    );
}

#[test]
fn tiny_and_large_lights() {
    let device = device();
    let mut view = plate_and_box_view(WIDTH, HEIGHT);
    let large = check(
        &device,
        "large light",
        &view,
        (0.2, 128),
        FaceMode::Both,
        20,
    );
    // A penumbra 15 mm wide, the plate's shadow edge seen from half a metre (6 mm pixels).
    view.camera = Camera {
        position: Vec3::new(-0.275, 0.5, 1.3),
        target: Vec3::new(-0.275, 0.0, 0.9),
        up: Vec3::Y,
        fov_y_radians: 45f32.to_radians(),
        near: 0.01,
    };
    let tiny = check(
        &device,
        "tiny light",
        &view,
        (0.005, 16),
        FaceMode::Both,
        20,
    );
    assert!(large.penumbra > 0 && tiny.penumbra > 0);
}

/// Suns over the floor of long thin strips ([`common::long_thin_strips`]): of 0.1 rad (the trace without
/// the samples' own walks) and 0.2 rad (with them), each strip oriented by its own edges.
#[test]
fn suns_over_a_floor_of_long_thin_strips() {
    let device = device();
    let (scene, camera) = common::long_thin_strips();
    let mut view = View::framed(scene, WIDTH, HEIGHT);
    view.camera = camera;
    view.light =
        DirectionalLight::new(common::strips_turn() * Vec3::new(0.3, -1.0, 0.2)).expect("light");
    for radius in [0.1, 0.2] {
        check(
            &device,
            &format!("sun of {radius} rad over long thin strips"),
            &view,
            (radius, 32),
            FaceMode::Both,
            20,
        );
    }
}

#[test]
fn the_demo_scene_1e4_from_the_origin() {
    check_hard_case(Family::Scale, "translated by 1e4", (0.3, 32));
}

#[test]
fn the_same_input_gives_the_same_output_bit_for_bit() {
    let device = device();
    let view = plate_and_box_view(WIDTH, HEIGHT);
    let config = area_config(0.05, 64, FaceMode::Both);
    let a = render(&device, &view, config).1.output;
    let b = render(&device, &view, config).1.output;
    assert!(a.iter().any(|&v| v > 0.0 && v < 1.0), "no penumbra");
    assert_eq!(
        a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    assert_no_validation_errors(&device);
}

#[test]
fn invalid_light_sizes_and_sample_counts_are_rejected() {
    let device = device();
    let view = plate_and_box_view(32, 24);
    // The sample count (and any size that is no number) is checked when the pipeline is built, a
    // directional light's angular radius when a frame gives one (a spot or point light's emitter has a
    // radius instead).
    for (radius, samples, what) in [
        (0.0, 32, "angular radius"),
        (f32::NAN, 32, "finite"),
        (2.0, 32, "angular radius"),
        (0.02, 0, "light samples"),
        (0.02, 129, "light samples"),
    ] {
        let config = area_config(radius, samples, FaceMode::Both);
        let err = match ShadowRenderer::new(&device, &view, config) {
            Err(e) => e,
            Ok(mut r) => r
                .render(&device, &view.frame_inputs())
                .expect_err(&format!("r {radius}, {samples} samples accepted")),
        }
        .to_string();
        assert!(err.contains(what), "{err}");
    }
    // Area shadows need compute binning.
    let mut config = area_config(0.02, 32, FaceMode::Both);
    config.map.binning = BinningRequest::Software;
    let err = ShadowRenderer::new(&device, &view, config)
        .err()
        .expect("software binning accepted")
        .to_string();
    assert!(err.contains("compute binning"), "{err}");
    // A spot light needs an emitter of some size, and a frustum it can widen footprints in.
    let position = Vec3::new(0.0, 4.0, 0.0);
    let narrow = passes::spot_light_frusta(position, Vec3::NEG_Y, 0.5, Some(10.0))[0];
    let wide = passes::Light::Spot {
        position,
        direction: Vec3::NEG_Y,
        view_proj: glam::Mat4::perspective_infinite_rh(176f32.to_radians(), 1.0, 0.01)
            * glam::Mat4::look_to_rh(position, Vec3::NEG_Y, Vec3::Z),
    };
    for (spot_radius, light, what) in [
        (0.0, narrow, "emitter radius"),
        (0.05, wide, "narrower than 174°"),
    ] {
        let mut config = area_config(0.02, 32, FaceMode::Both);
        config.pcss.spot_radius = spot_radius;
        let mut r = ShadowRenderer::new(&device, &view, config).expect("renderer");
        let mut inputs = view.frame_inputs();
        inputs.light = light;
        let err = r
            .render(&device, &inputs)
            .expect_err("spot light accepted")
            .to_string();
        assert!(err.contains(what), "{err}");
    }
    assert_no_validation_errors(&device);
}
