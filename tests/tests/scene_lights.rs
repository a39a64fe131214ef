//! A glTF scene's lights through the plugin, as the scene's plan says (`host_demo::scene_plan`), on
//! lavapipe: every shadowed light against the exact reference of the scene's shadow casters (a point light
//! given to the plugin as a point light, hard or sized: its six cube faces built as one map; a ground that
//! casts no shadows receiving one cast from behind the camera; blockers on the edges between cube faces),
//! a scene whose lights need nothing records no plugin pass, and changing one light reruns only that
//! light's passes. Sized spot and point lights with area shadows: every sample of every stable pixel as the
//! exact reference of the same emitter samples decides it (a lamp inside a closed room, spot lights of one
//! and five frusta, emitters next to geometry).

mod common;

use common::{
    assert_exact_area, assert_exact_visibility, assert_no_validation_errors,
    compare_with_reference, device, scene_visibility_params,
};
use demo_engine::plugin::{LightsFrame, PluginRenderer};
use demo_engine::CameraMatrices;
use glam::Vec3;
use host_demo::scene_plan::{
    plan_scene, scene_camera, LightDecision, NoPassReason, PlanSettings, ScenePlan,
};
use host_demo::scene_render::SceneRenderer;
use hrts::{Config, ShadowMode};
use hrts_lab::accuracy::{compare_area_counts, AreaComparison};
use reference::{local_area_reference, reference_visibility, RefScene};
use rhi::Device;
use scene::{Camera, LightKind, LightSize, SceneFile, SceneLight};
use std::path::PathBuf;

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

/// The example scene of the `scene` crate (five lights: a sized sun, a zero-size rim light, a sized spot
/// light, a fill light casting no shadows, a moving sized point lamp), written and loaded.
fn example() -> SceneFile {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scene_lights");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(format!("example-{}.gltf", std::process::id()));
    scene::gltf_scene::write_example_scene(&path).expect("write the example");
    let file = scene::load_gltf(&path).expect("load the example");
    let _ = std::fs::remove_file(&path);
    file
}

fn settings(antialiasing: bool) -> PlanSettings {
    PlanSettings {
        base: Config {
            antialiasing,
            map_size: 256,
            shadow_map_size: 512,
            ..Config::default()
        },
        width: WIDTH,
        height: HEIGHT,
    }
}

fn camera(file: &SceneFile) -> Camera {
    scene_camera(file, WIDTH as f32 / HEIGHT as f32)
}

fn plan(file: &SceneFile, antialiasing: bool) -> ScenePlan {
    plan_scene(file, &camera(file), &settings(antialiasing)).expect("plan")
}

/// Whether the light reaches `p` well inside its cone and range (pixels near the edge of its influence,
/// where it gives almost no light, are not compared: a spot frustum ends just beyond the cone).
fn well_inside_reach(light: &SceneLight, p: glam::DVec3) -> bool {
    let within = |at: Vec3, range: Option<f32>| {
        range.is_none_or(|r| p.distance(at.as_dvec3()) < f64::from(r) * 0.98)
    };
    match light.kind {
        LightKind::Directional { .. } => true,
        LightKind::Point { position, range } => within(position, range),
        LightKind::Spot {
            position,
            direction,
            outer_cone,
            range,
            ..
        } => {
            let to_p = (p - position.as_dvec3()).normalize();
            within(position, range)
                && to_p.dot(direction.as_dvec3()).acos() < f64::from(outer_cone) * 0.98
        }
    }
}

/// `plan` with every shadowed light in mode hard: what the plugin writes is then the ray-traced visibility
/// itself (for a light of several frusta, the minimum over those it recorded). The lights' planned passes
/// and resources, which rendering does not read, stay those of their own modes.
fn all_hard(plan: &ScenePlan) -> ScenePlan {
    let mut hard = plan.clone();
    for light in &mut hard.lights {
        if let LightDecision::Shadowed(s) = &mut light.decision {
            // Hard shadows ignore the light's size, and take only sizes above 0 (0 is mode auto's).
            s.config.mode = ShadowMode::Hard;
            s.mode = ShadowMode::Hard;
            s.config.pcss_angular_radius = Config::default().pcss_angular_radius;
            s.config.pcss_spot_radius = Config::default().pcss_spot_radius;
        }
    }
    hard
}

/// Renders `file` from `camera` as its plan says, checks the resources each light's mode allocates, then
/// renders it with every light hard and compares every shadowed light's ray-traced visibility with the
/// exact reference: 0 mismatches outside near-edge pixels, at least `min_shadowed` shadowed pixels
/// compared, fewer than `max_near_edge_percent` of the pixels near an edge. Lights without a pass must be
/// `expected_unshadowed`, with visibility 1. Returns the plan.
fn assert_lights_match_reference(
    device: &Device,
    file: &SceneFile,
    camera: &Camera,
    min_shadowed: usize,
    max_near_edge_percent: usize,
    expected_unshadowed: &[&str],
) -> ScenePlan {
    let plan = plan_scene(file, camera, &settings(false)).expect("plan");
    let plugin_lights = plan.plugin_lights();
    let mut renderer = SceneRenderer::new(device, file, WIDTH, HEIGHT).expect("renderer");
    let frame = renderer.render(device, camera, &plan).expect("frame");
    assert_eq!(frame.lights.len(), plugin_lights.len());
    for (light, report) in plugin_lights.iter().zip(&frame.lights) {
        let name = &plan.lights[light.scene_light].light.name;
        let has = |r: hrts::Resource| report.resource_bytes(r) > 0;
        let sized = light.shadowed.resolved_config().mode == ShadowMode::Hybrid;
        assert_eq!(has(hrts::Resource::ShadowMap), sized, "{name}: shadow map");
        assert_eq!(has(hrts::Resource::Pcss), sized, "{name}: PCSS");
        assert!(
            has(hrts::Resource::PrimListEntries),
            "{name}: primitive map"
        );
        assert_eq!(
            report.frusta + report.frusta_culled,
            light.shadowed.frusta.len() as u32,
            "{name}: {}",
            report.decision_reason
        );
    }
    let hard = all_hard(&plan);
    let frame = renderer.render(device, camera, &hard).expect("hard frame");
    let images = renderer.read_back(device, &hard).expect("read back");
    let rs = RefScene::with_casters(&file.scene, &file.shadow_casters);
    let reports = hard.plugin_lights();
    for (i, light) in hard.lights.iter().enumerate() {
        let name = &light.light.name;
        let Some(shadowed) = light.shadowed() else {
            assert!(
                expected_unshadowed.contains(&name.as_str()),
                "{name}: {:?}",
                light.decision
            );
            assert!(images.visibility[i].iter().all(|&v| v == 1.0));
            continue;
        };
        let k = reports
            .iter()
            .position(|l| l.scene_light == i)
            .expect("a plugin light");
        let report = &frame.lights[k];
        assert_eq!(
            report.stats.texels_past_capacity, 0,
            "{name}: {:?}",
            report.stats
        );
        let reference_light = match light.light.kind {
            LightKind::Directional { direction } => reference::Light::Directional {
                direction: direction.as_dvec3(),
            },
            LightKind::Spot { position, .. } | LightKind::Point { position, .. } => {
                reference::Light::Point {
                    position: position.as_dvec3(),
                }
            }
        };
        let params = scene_visibility_params(&file.scene, camera, WIDTH, HEIGHT, reference_light);
        let r = reference_visibility(&rs, &params);
        let considered: Vec<bool> = r
            .position
            .iter()
            .map(|p| !p.is_finite() || well_inside_reach(&light.light, *p))
            .collect();
        let c = compare_with_reference(&r, &images.visibility[i], None, Some(&considered));
        println!(
            "{name} ({} of {} frusta recorded: {}; planned {}): {} pixels compared, {} shadowed, {} near an edge, {} mismatches",
            report.frusta,
            shadowed.frusta.len(),
            report.decision_reason,
            plan.lights[i]
                .shadowed()
                .map_or("-", |s| s.resolved_config().mode.name()),
            c.pixels,
            c.shadowed,
            c.near_edge,
            c.mismatches
        );
        assert_eq!(c.non_finite, 0, "{name}");
        assert_eq!(
            c.mismatches, 0,
            "{name}: mismatching pixels (x, y, exact, gpu): {:?}",
            c.examples
        );
        assert!(
            c.shadowed >= min_shadowed,
            "{name}: too few shadowed pixels to compare ({})",
            c.shadowed
        );
        assert!(
            c.near_edge * 100 < c.pixels * max_near_edge_percent,
            "{name}: {} of {} pixels near an edge",
            c.near_edge,
            c.pixels
        );
    }
    assert_no_validation_errors(device);
    plan
}

/// Every shadowed light of the example (a sized sun, a zero-size rim light, a sized spot light, a point
/// lamp whose faces the plugin fits and culls) matches the exact shadow; the fill light, casting no
/// shadows, gets no pass and visibility 1. (The rim light comes from behind the camera: its shadows are
/// mostly hidden.)
#[test]
fn every_light_of_the_example_matches_the_exact_reference() {
    let device = device();
    let file = example();
    let plan = assert_lights_match_reference(&device, &file, &camera(&file), 10, 5, &["fill"]);
    assert_eq!(plan.plugin_lights().len(), 4, "{}", plan.describe());
}

fn point_light(name: &str, position: Vec3) -> SceneLight {
    SceneLight {
        name: name.into(),
        kind: LightKind::Point {
            position,
            range: None,
        },
        color: Vec3::ONE,
        intensity: 50.0,
        size: LightSize::Zero,
        casts_shadows: true,
        is_static: true,
    }
}

/// A scene of boxes, held still, with `lights` and a camera at `eye` looking at `target`.
fn boxes_scene(
    boxes: &[(&str, Vec3, Vec3)],
    lights: Vec<SceneLight>,
    eye: Vec3,
    target: Vec3,
) -> SceneFile {
    let mut scene = scene::Scene::default();
    for &(name, min, max) in boxes {
        scene.append(&scene::Scene::axis_box(name, min, max));
    }
    scene.validate().expect("valid scene");
    SceneFile {
        static_objects: vec![true; scene.objects.len()],
        shadow_casters: vec![true; scene.objects.len()],
        scene,
        lights,
        camera: Some(Camera {
            position: eye,
            target,
            up: Vec3::Y,
            fov_y_radians: 70f32.to_radians(),
            near: 0.05,
        }),
        skipped_primitives: 0,
    }
}

/// `file` written as glTF and loaded back (its `hrts` extras, `casts_shadows` on mesh nodes included).
fn written_and_loaded(file: &SceneFile, name: &str) -> SceneFile {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scene_lights");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(format!("{name}-{}.gltf", std::process::id()));
    scene::gltf_scene::write_scene(&path, file, scene::gltf_scene::GltfEncoding::default())
        .expect("write the scene");
    let loaded = scene::load_gltf(&path).expect("load the scene");
    let _ = std::fs::remove_file(&path);
    loaded
}

/// Travel direction of the low sun of [`pillar_behind_the_camera`]: about 16° above the horizon, from
/// behind the camera.
const LOW_SUN: Vec3 = Vec3::new(0.15, -0.3, -1.0);

/// A ground (a 10 cm slab) that casts shadows or not, a 5 m pillar behind the camera, out of view, and a
/// zero-size low sun from behind both: the pillar's shadow runs some 15 m across the ground in view.
fn pillar_behind_the_camera(ground_casts: bool) -> SceneFile {
    let sun = SceneLight {
        name: "sun".into(),
        kind: LightKind::Directional {
            direction: LOW_SUN.normalize(),
        },
        color: Vec3::ONE,
        intensity: 3.0,
        size: LightSize::Zero,
        casts_shadows: true,
        is_static: true,
    };
    let mut file = boxes_scene(
        &[
            (
                "ground",
                Vec3::new(-20.0, -0.1, -40.0),
                Vec3::new(20.0, 0.0, 10.0),
            ),
            (
                "pillar",
                Vec3::new(-0.4, 0.0, 2.6),
                Vec3::new(0.4, 5.0, 3.4),
            ),
        ],
        vec![sun],
        Vec3::new(0.0, 1.6, 0.0),
        Vec3::new(0.0, 0.3, -6.0),
    );
    file.shadow_casters[0] = ground_casts;
    file
}

/// A ground whose glTF node casts no shadows (`extras.hrts.casts_shadows` false: the plugin is given the
/// pillar alone, behind the camera) still receives the pillar's shadow of a low sun from behind the camera:
/// the plugin keeps the light (a caster out of view shadows receivers in view), the same pixels are
/// shadowed as when the ground casts (within 2 %), and both match the exact reference of their casters.
#[test]
fn a_ground_that_casts_no_shadows_receives_a_shadow_cast_from_behind_the_camera() {
    let device = device();
    let mut shadowed = Vec::new();
    for ground_casts in [true, false] {
        let file = written_and_loaded(
            &pillar_behind_the_camera(ground_casts),
            if ground_casts {
                "casting-ground"
            } else {
                "receiving-ground"
            },
        );
        assert_eq!(file.shadow_casters, [ground_casts, true]);
        let camera = camera(&file);
        let plan = plan_scene(&file, &camera, &settings(false)).expect("plan");
        let shadowed_light = plan.lights[0].shadowed().expect("the sun is shadowed");
        assert_eq!(shadowed_light.resolved_config().mode, ShadowMode::Hard);
        let mut renderer = SceneRenderer::new(&device, &file, WIDTH, HEIGHT).expect("renderer");
        let frame = renderer.render(&device, &camera, &plan).expect("frame");
        let images = renderer.read_back(&device, &plan).expect("read back");
        let report = &frame.lights[0];
        let rs = RefScene::with_casters(&file.scene, &file.shadow_casters);
        let params = scene_visibility_params(
            &file.scene,
            &camera,
            WIDTH,
            HEIGHT,
            reference::Light::Directional {
                direction: LOW_SUN.normalize().as_dvec3(),
            },
        );
        let r = reference_visibility(&rs, &params);
        let c = compare_with_reference(&r, &images.visibility[0], None, None);
        let gpu_shadowed = images.visibility[0].iter().filter(|&&v| v == 0.0).count();
        println!(
            "ground {}: {} frusta recorded, {} culled ({}); {} pixels compared, {} shadowed, {} near an edge, \
             {} mismatches; {gpu_shadowed} shadowed by the plugin",
            if ground_casts { "casting" } else { "casting nothing" },
            report.frusta,
            report.frusta_culled,
            report.decision_reason,
            c.pixels,
            c.shadowed,
            c.near_edge,
            c.mismatches
        );
        assert_eq!(c.non_finite, 0);
        assert_eq!(
            c.mismatches, 0,
            "mismatching pixels (x, y, exact, gpu): {:?}",
            c.examples
        );
        assert_eq!(
            (report.frusta, report.frusta_culled),
            (1, 0),
            "{}",
            report.decision_reason
        );
        assert!(c.shadowed > 1000, "{} shadowed pixels", c.shadowed);
        assert!(
            c.near_edge * 100 < c.pixels * 5,
            "{} near an edge",
            c.near_edge
        );
        shadowed.push(gpu_shadowed);
    }
    let (casting, receiving) = (shadowed[0] as f64, shadowed[1] as f64);
    assert!(
        (casting - receiving).abs() <= 0.02 * casting,
        "{casting} pixels shadowed with a casting ground, {receiving} with a ground that casts nothing"
    );
    assert_no_validation_errors(&device);
}

/// A point light inside a closed room (every wall, floor and ceiling triangle crosses the plane of some cube
/// face: each face keeps exactly the part in front of the light), with a table, a pillar and a floating
/// plate casting shadows on the floor and walls, seen from inside. Every triangle behind a face's plane is
/// culled, and none is binned into the whole map.
#[test]
fn a_point_light_inside_a_closed_room_matches_the_exact_reference() {
    let device = device();
    let file = closed_room(Vec3::new(0.15, 2.5, 0.1));
    let plan = assert_lights_match_reference(&device, &file, &camera(&file), 200, 5, &[]);
    assert_eq!(plan.plugin_lights().len(), 1, "{}", plan.describe());
}

/// Blockers on the edges between a point light's cube faces, where the setup's cheap pyramid test
/// (`map_setup.comp`, `meets_face_pyramid`: a face lists only triangles meeting its pyramid |u| <= T d,
/// T = 1.02) decides whether a face lists them at all; a tangent T below 1 loses whatever lies in the gap
/// it leaves between the faces' pyramids.
///
/// Small blocks on the diagonals, 1 m from the lamp in the closed room: every vertex lies within a few
/// degrees of the edge between two faces (a tangent of 0.9 loses their shadows). And thin strips facing a
/// lamp above a floor, one on each edge between its down face and a side face, 1 mm wide at 1 m: each
/// straddles the plane between the two faces with every vertex within 1e-3 of it (|u| / d within 1e-3 of
/// 1), so any tangent below 0.999 lists it in neither face. Their shadows are lines 4 mm wide on the floor,
/// which close-up views of the floor (a millimetre a pixel) see as hundreds of shadowed pixels.
#[test]
fn blockers_on_the_edges_between_cube_faces_match_the_exact_reference() {
    let device = device();
    let lamp = Vec3::new(0.15, 2.5, 0.1);
    let mut file = closed_room(lamp);
    let half = Vec3::splat(0.025);
    for (i, direction) in [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(0.0, -1.0, -1.0),
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
    ]
    .into_iter()
    .enumerate()
    {
        let centre = lamp + direction.normalize();
        file.scene.append(&scene::Scene::axis_box(
            &format!("die {i}"),
            centre - half,
            centre + half,
        ));
        file.static_objects.push(true);
        file.shadow_casters.push(true);
    }
    file.scene.validate().expect("valid scene");
    assert_lights_match_reference(&device, &file, &camera(&file), 200, 5, &[]);

    let lamp = Vec3::new(0.1, 2.0, -0.05);
    let file = floor_with_edge_strips(lamp);
    // Each strip's shadow: the line where the plane between the two faces meets the floor, 2 m out from
    // the lamp's foot, seen from 0.8 m above through a 6° field of view.
    for outward in [Vec3::X, Vec3::NEG_X, Vec3::Z, Vec3::NEG_Z] {
        let target = Vec3::new(lamp.x, 0.0, lamp.z) + outward * lamp.y;
        let close_up = Camera {
            position: target + outward * 0.25 + Vec3::Y * 0.8,
            target,
            up: Vec3::Y,
            fov_y_radians: 6f32.to_radians(),
            near: 0.05,
        };
        println!("close-up of the strip's shadow at {target}:");
        assert_lights_match_reference(&device, &file, &close_up, 60, 5, &[]);
    }
}

/// A 5 m floor and a point lamp 2 m above it at `lamp` with, on each edge between the lamp's down cube face
/// and a side face, a strip 1 mm wide and 30 cm long, 1 m from the lamp: its long axis lies in the plane
/// between the two faces, across the direction from the lamp, and it faces the lamp.
fn floor_with_edge_strips(lamp: Vec3) -> SceneFile {
    let mut file = boxes_scene(
        &[(
            "floor",
            Vec3::new(-2.5, -0.1, -2.5),
            Vec3::new(2.5, 0.0, 2.5),
        )],
        vec![point_light("lamp", lamp)],
        Vec3::new(3.0, 3.0, 3.0),
        lamp,
    );
    let (distance, width, length) = (1.0, 1e-3, 0.3);
    for (name, outward) in [
        ("strip +X", Vec3::X),
        ("strip -X", Vec3::NEG_X),
        ("strip +Z", Vec3::Z),
        ("strip -Z", Vec3::NEG_Z),
    ] {
        // The plane between the side face and the down face holds `outward - Y` and the third axis.
        let radial = (outward - Vec3::Y).normalize();
        let across = (outward + Vec3::Y).normalize();
        let along = radial.cross(across);
        let centre = lamp + radial * distance;
        let (w, l) = (across * width * 0.5, along * length * 0.5);
        let corners = vec![
            centre - w - l,
            centre + w - l,
            centre + w + l,
            centre - w + l,
        ];
        // Triangles (0, 2, 1) and (0, 3, 2): their normal (along x across) points back at the lamp.
        let strip = scene::Scene::single_object(corners, vec![0, 2, 1, 0, 3, 2], name);
        file.scene.append(&strip);
        file.static_objects.push(true);
        file.shadow_casters.push(true);
    }
    file.scene.validate().expect("valid scene");
    file
}

/// The closed room of [`a_point_light_inside_a_closed_room_matches_the_exact_reference`] with its lamp.
fn closed_room(lamp: Vec3) -> SceneFile {
    let boxes = [
        // Walls 10 cm thick around a 6 x 3 x 6 m room.
        (
            "floor",
            Vec3::new(-3.1, -0.1, -3.1),
            Vec3::new(3.1, 0.0, 3.1),
        ),
        (
            "ceiling",
            Vec3::new(-3.1, 3.0, -3.1),
            Vec3::new(3.1, 3.1, 3.1),
        ),
        (
            "wall -x",
            Vec3::new(-3.1, 0.0, -3.1),
            Vec3::new(-3.0, 3.0, 3.1),
        ),
        (
            "wall +x",
            Vec3::new(3.0, 0.0, -3.1),
            Vec3::new(3.1, 3.0, 3.1),
        ),
        (
            "wall -z",
            Vec3::new(-3.0, 0.0, -3.1),
            Vec3::new(3.0, 3.0, -3.0),
        ),
        (
            "wall +z",
            Vec3::new(-3.0, 0.0, 3.0),
            Vec3::new(3.0, 3.0, 3.1),
        ),
        (
            "table",
            Vec3::new(-1.2, 0.7, -0.8),
            Vec3::new(0.4, 0.76, 0.6),
        ),
        (
            "pillar",
            Vec3::new(1.2, 0.0, -1.6),
            Vec3::new(1.6, 3.0, -1.2),
        ),
        (
            "plate",
            Vec3::new(-0.3, 2.2, 0.9),
            Vec3::new(0.9, 2.23, 1.9),
        ),
    ];
    boxes_scene(
        &boxes,
        vec![point_light("lamp", lamp)],
        Vec3::new(2.4, 2.2, 2.6),
        Vec3::new(-0.5, 0.6, -0.6),
    )
}

/// The closed room's lamp given to the plugin as a point light (the C ABI's `HRTS_LIGHT_TYPE_POINT`, no
/// matrix) under `config`, rendered `frames` times: per frame, its map statistics and its layer against the
/// exact reference.
fn native_point_frames(
    device: &Device,
    lamp: Vec3,
    config: Config,
    frames: usize,
) -> Vec<(hrts::MapStats, common::VisibilityComparison)> {
    let file = closed_room(lamp);
    let camera = camera(&file);
    let mut plugin = plugin_for(device, &file);
    plugin
        .configure_lights(device, &[config])
        .expect("configure");
    let matrices = CameraMatrices::of_camera(&camera, WIDTH, HEIGHT);
    let rs = RefScene::new(&file.scene);
    let params = point_light_params(&file, &camera, lamp);
    let r = reference_visibility(&rs, &params);
    (0..frames)
        .map(|_| {
            let frame = plugin
                .render_lights(device, &matrices, &[plugin_point_light(lamp)])
                .expect("frame");
            let report = &frame.lights[0];
            let (_, layers) = plugin.read_frame(device).expect("read back");
            let c = compare_with_reference(&r, &layers[0], None, None);
            println!(
                "native point light: {} pixels, {} shadowed, {} near an edge, {} mismatches; {}; {:?}",
                c.pixels, c.shadowed, c.near_edge, c.mismatches, frame.lights[0].decision_reason, report.stats
            );
            assert_eq!(c.non_finite, 0);
            assert_eq!(c.mismatches, 0, "(x, y, exact, gpu): {:?}", c.examples);
            (report.stats, c)
        })
        .collect()
}

/// A hard point light given to the plugin as a point light: the plugin builds its six cube faces as one
/// map and writes the light's one layer, which matches the exact reference.
#[test]
fn a_native_point_light_matches_the_exact_reference() {
    let device = device();
    let config = Config {
        mode: ShadowMode::Hard,
        antialiasing: false,
        ..settings(false).base
    };
    let frames = native_point_frames(&device, Vec3::new(0.15, 2.5, 0.1), config, 2);
    let (stats, c) = &frames[1];
    assert_eq!(stats.texels_past_capacity, 0);
    assert!(stats.receiver_pixels > 0);
    assert!(
        stats.bin_pairs > 0 && stats.bin_pairs <= stats.bin_pair_capacity,
        "{stats:?}"
    );
    assert!(c.shadowed >= 200, "{} shadowed pixels", c.shadowed);
    assert_no_validation_errors(&device);
}

/// A point light's cube map that keeps more (triangle, face) pairs than it holds: that frame traces the
/// light's rays exhaustively and stays exact, and the pairs grow to fit from the next frame on.
#[test]
fn a_cube_map_outgrowing_its_pairs_stays_exact_and_grows() {
    let device = device();
    let mut config = Config {
        mode: ShadowMode::Hard,
        antialiasing: false,
        static_light: false,
        ..settings(false).base
    };
    config.map_initial_pairs = 8;
    let frames = native_point_frames(&device, Vec3::new(0.15, 2.5, 0.1), config, 3);
    let (first, _) = &frames[0];
    assert_eq!(first.bin_pair_capacity, 8);
    assert!(first.bin_pairs > 8, "{first:?}");
    for (stats, c) in &frames[1..] {
        assert!(stats.bin_pair_capacity >= stats.bin_pairs, "{stats:?}");
        assert_eq!(stats.bin_pairs, first.bin_pairs, "{stats:?}");
        assert!(c.shadowed >= 200);
    }
    assert_no_validation_errors(&device);
}

/// An 8 m ground square with a 1 m crate at the origin and a low block beside it.
const GROUND_CRATE_BLOCK: [(&str, Vec3, Vec3); 3] = [
    (
        "ground",
        Vec3::new(-4.0, -0.1, -4.0),
        Vec3::new(4.0, 0.0, 4.0),
    ),
    (
        "crate",
        Vec3::new(-0.5, 0.0, -0.5),
        Vec3::new(0.5, 1.0, 0.5),
    ),
    ("block", Vec3::new(1.0, 0.0, 0.6), Vec3::new(1.6, 0.5, 1.4)),
];

/// Lights lying on geometry: a point light exactly in the plane of a box's top (the top's triangles are
/// edge-on to it, and the box's sides straddle its faces' planes), and a point light touching a wall
/// (every triangle of the wall lies in the light's plane of the face looking along it, or behind another).
#[test]
fn lights_in_a_triangles_plane_match_the_exact_reference() {
    let device = device();
    let [ground, crate_box, block] = GROUND_CRATE_BLOCK;
    let boxes = [
        ground,
        crate_box,
        block,
        (
            "wall",
            Vec3::new(-4.0, 0.0, -2.6),
            Vec3::new(4.0, 2.5, -2.5),
        ),
    ];
    let file = boxes_scene(
        &boxes,
        vec![
            point_light("on the crate's plane", Vec3::new(0.2, 1.0, 0.9)),
            point_light("on the wall", Vec3::new(-1.0, 1.2, -2.5)),
        ],
        Vec3::new(3.5, 3.0, 4.5),
        Vec3::new(0.0, 0.3, -0.5),
    );
    // The light on the wall grazes it: the wall's own pixels are near an edge for the reference (their
    // rays run along the wall), about 37% of the view.
    assert_lights_match_reference(&device, &file, &camera(&file), 100, 45, &[]);
}

/// A scene whose lights need nothing (one casts no shadow, a spot light points at the sky, a sun emits
/// nothing) gives the plugin no light: no plugin pass is recorded, and every visibility is 1.
#[test]
fn lights_that_need_nothing_get_no_pass() {
    let device = device();
    let mut file = example();
    let fill = file
        .lights
        .iter()
        .find(|l| l.name == "fill")
        .cloned()
        .expect("fill light");
    let skyward = SceneLight {
        name: "skyward".into(),
        kind: LightKind::Spot {
            position: Vec3::new(0.0, 3.0, 0.0),
            direction: Vec3::Y,
            inner_cone: 0.2,
            outer_cone: 0.4,
            range: Some(20.0),
        },
        color: Vec3::ONE,
        intensity: 50.0,
        size: LightSize::Radius(0.1),
        casts_shadows: true,
        is_static: true,
    };
    let dark_sun = SceneLight {
        name: "dark sun".into(),
        kind: LightKind::Directional {
            direction: Vec3::NEG_Y,
        },
        intensity: 0.0,
        size: LightSize::Zero,
        ..skyward.clone()
    };
    file.lights = vec![fill, skyward, dark_sun];
    let plan = plan(&file, true);
    let reasons: Vec<LightDecision> = plan.lights.iter().map(|l| l.decision.clone()).collect();
    assert_eq!(
        reasons,
        [
            LightDecision::NoPass(NoPassReason::CastsNoShadows),
            LightDecision::NoPass(NoPassReason::OutOfView),
            LightDecision::NoPass(NoPassReason::EmitsNothing),
        ]
    );
    let mut renderer = SceneRenderer::new(&device, &file, WIDTH, HEIGHT).expect("renderer");
    for _ in 0..2 {
        let frame = renderer
            .render(&device, &camera(&file), &plan)
            .expect("frame");
        assert!(frame.lights.is_empty());
    }
    assert_eq!(renderer.plugin().frames_with_plugin_passes(), 0);
    let images = renderer.read_back(&device, &plan).expect("read back");
    assert!(images.layers.is_empty());
    assert_eq!(images.visibility.len(), 3);
    assert!(images.visibility.iter().flatten().all(|&v| v == 1.0));
    // The G-buffer was drawn: the scene is in view.
    assert!(images.gbuffer.normal.iter().any(|n| n[3] == 1.0));
    assert_no_validation_errors(&device);
}

fn status(report: &hrts::FrameReport, pass: hrts::Pass) -> hrts::PassStatus {
    report.status(pass)
}

/// The name of every plugin light of `plan`.
fn labels(plan: &ScenePlan) -> Vec<String> {
    plan.plugin_lights()
        .iter()
        .map(|l| plan.lights[l.scene_light].light.name.clone())
        .collect()
}

/// Checks a frame after a change to the lights of `changed` (plugin lights): their builds are as in
/// `builds`; every other light was not rebuilt, reused the prim buffer and, if static with a shadow map,
/// its shadow map.
fn assert_only_changed_reran(
    plan: &ScenePlan,
    frame: &LightsFrame,
    before: &LightsFrame,
    changed: &[usize],
    what: &str,
) {
    let names = labels(plan);
    for (k, (report, light)) in frame.lights.iter().zip(plan.plugin_lights()).enumerate() {
        let name = &names[k];
        let earlier = before.lights[k].light_builds;
        assert_eq!(
            status(report, hrts::Pass::PrimBuffer),
            hrts::PassStatus::UpToDate,
            "{what}: {name}'s prim buffer (static geometry)"
        );
        if changed.contains(&k) {
            continue;
        }
        assert_eq!(report.light_builds, earlier, "{what}: {name} was rebuilt");
        let expected = match (
            light.shadowed.resolved_config().mode,
            light.shadowed.config.static_light,
        ) {
            (ShadowMode::Hard | ShadowMode::Area, _) => hrts::PassStatus::NotInPlan,
            (_, true) => hrts::PassStatus::UpToDate,
            (_, false) => hrts::PassStatus::Ran,
        };
        assert_eq!(
            status(report, hrts::Pass::ShadowMap),
            expected,
            "{what}: {name}'s shadow map"
        );
    }
}

/// With static geometry, the second frame reuses every static light's light-space passes; changing one
/// light's size rebuilds that light's passes only, and moving the moving lamp reruns only its own
/// light-space passes: the others' stay up to date and are not rebuilt, and their visibility is unchanged.
#[test]
fn changing_one_light_reruns_only_its_passes() {
    let device = device();
    let mut file = example();
    // The cart is parked: all geometry static. The lamp on it still counts as a moving light.
    file.static_objects.iter_mut().for_each(|s| *s = true);
    let camera = camera(&file);
    let mut plan = plan(&file, true);
    assert!(!plan.dynamic_geometry);
    let mut renderer = SceneRenderer::new(&device, &file, WIDTH, HEIGHT).expect("renderer");
    let render = |renderer: &mut SceneRenderer, device: &Device, plan: &ScenePlan| {
        renderer.render(device, &camera, plan).expect("frame")
    };
    let first = render(&mut renderer, &device, &plan);
    assert!(first.lights.iter().all(|l| l.light_builds == 1));
    assert!(first
        .lights
        .iter()
        .all(|l| status(l, hrts::Pass::ShadowMap) != hrts::PassStatus::UpToDate));
    let second = render(&mut renderer, &device, &plan);
    let lamp: Vec<usize> = labels(&plan)
        .iter()
        .enumerate()
        .filter(|(_, l)| *l == "cart_lamp")
        .map(|(k, _)| k)
        .collect();
    assert_eq!(lamp.len(), 1);
    assert_only_changed_reran(&plan, &second, &first, &[], "second frame");
    let still = renderer.read_back(&device, &plan).expect("read back");

    // A larger spot light: only its passes are rebuilt.
    let spot = file
        .lights
        .iter()
        .position(|l| l.name == "spot")
        .expect("spot");
    file.lights[spot].size = LightSize::Radius(0.2);
    plan = plan_scene(&file, &camera, &settings(true)).expect("plan");
    let spot_k = labels(&plan)
        .iter()
        .position(|l| l == "spot")
        .expect("spot light");
    let resized = render(&mut renderer, &device, &plan);
    assert_eq!(resized.lights[spot_k].light_builds, 2);
    assert_eq!(
        status(&resized.lights[spot_k], hrts::Pass::PrimitiveMap),
        hrts::PassStatus::Ran
    );
    assert_only_changed_reran(&plan, &resized, &second, &[spot_k], "spot resized");

    // The lamp moves 20 cm: no rebuild, only its light-space passes rerun.
    let cart_lamp = file
        .lights
        .iter()
        .position(|l| l.name == "cart_lamp")
        .expect("lamp");
    let LightKind::Point { position, range } = file.lights[cart_lamp].kind else {
        panic!("the cart lamp is a point light");
    };
    file.lights[cart_lamp].kind = LightKind::Point {
        position: position + Vec3::new(0.2, 0.0, 0.0),
        range,
    };
    let before_labels = labels(&plan);
    plan = plan_scene(&file, &camera, &settings(true)).expect("plan");
    assert_eq!(labels(&plan), before_labels, "the lamp keeps its place");
    let moved = render(&mut renderer, &device, &plan);
    for &k in &lamp {
        assert_eq!(moved.lights[k].light_builds, 1, "the lamp is not rebuilt");
        assert_eq!(
            status(&moved.lights[k], hrts::Pass::PrimitiveMap),
            hrts::PassStatus::Ran
        );
    }
    assert_only_changed_reran(&plan, &moved, &resized, &lamp, "lamp moved");
    assert_eq!(moved.lights[spot_k].light_builds, 2);
    let after = renderer.read_back(&device, &plan).expect("read back");
    for name in ["sun", "rim"] {
        let i = file.lights.iter().position(|l| l.name == name).expect(name);
        assert_eq!(after.visibility[i], still.visibility[i], "{name} changed");
    }
    let lamp_changed = after.visibility[cart_lamp]
        .iter()
        .zip(&still.visibility[cart_lamp])
        .filter(|(a, b)| a != b)
        .count();
    assert!(lamp_changed > 0, "the lamp's shadows did not follow it");
    assert_no_validation_errors(&device);
}

/// Renders `light` (given natively, as the C ABI takes it) over `file` in area mode, with an emitter of
/// `radius` around `centre` and `samples` samples, and compares its layer with the exact reference of the
/// same samples (a spot light's `cone`, axis and half-angle: on the pixels well inside it): 0 mismatched
/// counts on stable pixels, at least `min_penumbra` stable penumbra pixels judged, at most
/// `max_unstable_percent` of the pixels unstable. Returns the comparison and the light's map statistics.
fn check_local_area(
    device: &Device,
    name: &str,
    file: &SceneFile,
    light: hrts::Light,
    (centre, radius, samples): (Vec3, f32, u32),
    cone: Option<(Vec3, f32)>,
    (min_penumbra, max_unstable_percent): (usize, usize),
) -> (AreaComparison, hrts::MapStats) {
    let camera = camera(file);
    let rs = RefScene::new(&file.scene);
    let params = point_light_params(file, &camera, centre);
    let offsets: Vec<glam::DVec2> = passes::area::local_area_offsets(samples)
        .iter()
        .map(|o| o.as_dvec2())
        .collect();
    let r = local_area_reference(&rs, &params, centre.as_dvec3(), f64::from(radius), &offsets);
    // A spot light's pixels well inside its cone (its frustum ends just beyond the cone; the engine's cone
    // falloff darkens the rest).
    let considered: Option<Vec<bool>> = cone.map(|(axis, half_angle)| {
        let limit = (half_angle - 2f32.to_radians()).cos() as f64;
        r_positions(&rs, &params)
            .iter()
            .map(|p| {
                !p.is_finite()
                    || (*p - centre.as_dvec3())
                        .normalize()
                        .dot(axis.as_dvec3().normalize())
                        > limit
            })
            .collect()
    });
    let base = settings(false).base;
    // The plugin's own choice of lists and BVH, then every pixel through the BVH: with the whole bundle of
    // its segments, with each sample's own, and with the bundle giving up after one step (wide bundles
    // then weigh one sample's walk against the bundle's): the same counts.
    let mut first: Option<(AreaComparison, hrts::MapStats, Vec<f32>)> = None;
    let routes = [
        ("default", base.map_bin_budget, base.area_walk_budget),
        ("BVH", 0.0, u32::MAX),
        ("BVH, each sample", 0.0, 0),
        ("BVH, bundle of one step", 0.0, 1),
    ];
    for (route, bin_budget, area_walk_budget) in routes {
        let mut config = Config {
            mode: ShadowMode::Area,
            antialiasing: false,
            area_samples: samples,
            ..base
        };
        config.map_bin_budget = bin_budget;
        config.area_walk_budget = area_walk_budget;
        config.pcss_spot_radius = radius;
        let mut plugin = plugin_for(device, file);
        plugin
            .configure_lights(device, &[config])
            .expect("configure");
        let matrices = CameraMatrices::of_camera(&camera, WIDTH, HEIGHT);
        // The second frame: the first one's lists grow to what it needed. A bundle of one step gives up
        // in most pixels, so that from the second frame most tiles skip their bundles (the tile history,
        // passes::ray_trace::TILE_SKIP_FRAMES): the third frame is compared.
        let frames = if area_walk_budget == 1 { 3 } else { 2 };
        let mut frame = None;
        for _ in 0..frames {
            frame = Some(
                plugin
                    .render_lights(device, &matrices, &[light])
                    .expect("frame"),
            );
        }
        let frame = frame.expect("two frames");
        let report = &frame.lights[0];
        let (_, mut layers) = plugin.read_frame(device).expect("read back");
        let c = compare_area_counts(&r, &layers[0], considered.as_deref());
        let st = report.stats;
        println!(
            "{name} ({route}): R {radius}, {samples} samples: {} px, {} unstable, {} penumbra, {} umbra, {} mismatches; {}; map {} entries, mean list {:.1}, longest {}, {} texels past capacity, {} past the limit, {} pixels walked the BVH, {} of them each sample",
            c.pixels, c.unstable, c.penumbra, c.umbra, c.mismatches, frame.lights[0].decision_reason,
            st.entries, st.mean_list(), st.longest_list, st.texels_past_capacity,
            st.texels_past_limit, st.pixels_walked, st.pixels_walked_per_sample
        );
        assert_exact_area(
            &format!("{name} ({route})"),
            &c,
            min_penumbra,
            max_unstable_percent,
        );
        assert_eq!(st.walks_unfinished, 0, "{name} ({route})");
        assert_no_validation_errors(device);
        match &first {
            None => first = Some((c, st, layers.swap_remove(0))),
            Some((_, _, default)) => {
                assert!(
                    st.frusta_without_lists > 0 && st.pixels_walked > 0,
                    "{name}: {st:?}"
                );
                match area_walk_budget {
                    u32::MAX => assert_eq!(st.pixels_walked_per_sample, 0, "{name}: {st:?}"),
                    0 => assert!(st.pixels_walked_per_sample > 0, "{name}: {st:?}"),
                    _ => {}
                }
                assert!(
                    &layers[0] == default,
                    "{name}: the BVH's counts differ from the default route's"
                );
            }
        }
    }
    let (c, st, _) = first.expect("the default route ran");
    (c, st)
}

/// A sized point lamp inside the closed room, as one cube map: every sample of every stable pixel as the
/// reference decides it, for emitters of 0.3 and 0.6 m and 16 to 64 samples.
#[test]
fn a_sized_point_light_inside_a_closed_room_matches_the_reference_sample_for_sample() {
    let device = device();
    let lamp = Vec3::new(0.15, 2.5, 0.1);
    let file = closed_room(lamp);
    for (radius, samples, min_penumbra) in [(0.3, 16, 200), (0.6, 32, 200), (0.3, 64, 50)] {
        let (_, stats) = check_local_area(
            &device,
            "point lamp in a closed room",
            &file,
            plugin_point_light(lamp),
            (lamp, radius, samples),
            None,
            (min_penumbra, 25),
        );
        assert_eq!(stats.texels_past_capacity, 0);
    }
}

/// The floor of long thin strips ([`common::long_thin_strips`]) lit by a sized lamp: the sign of the
/// trace's D = a.(b x c) must come from each strip's own edges (N.a): from the vertices relative to the
/// origin it rounds by more than D itself, which turns the strip's test around and blocks the samples
/// towards the lamp.
#[test]
fn a_floor_of_long_thin_strips_matches_the_reference_sample_for_sample() {
    let device = device();
    let lamp = common::strips_turn() * Vec3::new(0.15, 2.5, 0.1);
    let (scene, camera) = common::long_thin_strips();
    let file = SceneFile {
        static_objects: vec![true; scene.objects.len()],
        shadow_casters: vec![true; scene.objects.len()],
        scene,
        lights: vec![point_light("lamp", lamp)],
        camera: Some(camera),
        skipped_primitives: 0,
    };
    check_local_area(
        &device,
        "point lamp over long thin strips",
        &file,
        plugin_point_light(lamp),
        (lamp, 0.3, 16),
        None,
        (100, 25),
    );
}

/// Sized spot lights in the closed room: a cone of 50° (one frustum) and one of 75° (the five cube faces
/// around its axis, each exact for its own receivers, and their minimum).
#[test]
fn sized_spot_lights_match_the_reference_sample_for_sample() {
    let device = device();
    let lamp = Vec3::new(-0.4, 2.6, 0.3);
    let file = closed_room(lamp);
    let down = Vec3::new(0.2, -1.0, -0.1);
    for cone in [50f32, 75.0] {
        check_local_area(
            &device,
            &format!("spot of {cone}°"),
            &file,
            plugin_spot_light(lamp, down, cone.to_radians()),
            (lamp, 0.25, 16),
            Some((down, cone.to_radians())),
            (100, 25),
        );
    }
}

/// Emitters on and against geometry: a lamp just over a table (its triangles lie within the light's near
/// radius and are listed in every texel), and one 5 cm from a wall's face (its disc reaching into the
/// wall).
#[test]
fn emitters_touching_geometry_match_the_reference_sample_for_sample() {
    let device = device();
    let over_table = Vec3::new(-0.4, 0.9, -0.1);
    let file = closed_room(over_table);
    check_local_area(
        &device,
        "lamp just over the table",
        &file,
        plugin_point_light(over_table),
        (over_table, 0.1, 32),
        None,
        (40, 25),
    );
    let on_wall = Vec3::new(-2.95, 1.6, 0.4);
    let file = closed_room(on_wall);
    check_local_area(
        &device,
        "lamp on a wall",
        &file,
        plugin_point_light(on_wall),
        (on_wall, 0.2, 16),
        None,
        (200, 40),
    );
}

/// Boxes on open ground seen from above, with no light of their own (the tests give theirs natively).
fn open_boxes() -> SceneFile {
    let [ground, crate_box, block] = GROUND_CRATE_BLOCK;
    let boxes = [
        ground,
        crate_box,
        block,
        (
            "shelf",
            Vec3::new(-2.0, 1.2, 0.8),
            Vec3::new(-0.8, 1.25, 1.8),
        ),
    ];
    boxes_scene(
        &boxes,
        Vec::new(),
        Vec3::new(3.5, 3.5, 4.5),
        Vec3::new(0.0, 0.3, 0.0),
    )
}

/// The sun of [`open_boxes`].
fn sun_direction() -> Vec3 {
    Vec3::new(0.45, -1.0, 0.25).normalize()
}

/// The plugin's point light at `position`, of unlimited range.
fn plugin_point_light(position: Vec3) -> hrts::Light {
    hrts::Light::Point {
        position,
        range: None,
    }
}

/// The plugin's spot light at `position` along `direction`, of unlimited range, whose frusta the plugin
/// fits to the cone of half-angle `outer_cone`.
fn plugin_spot_light(position: Vec3, direction: Vec3, outer_cone: f32) -> hrts::Light {
    hrts::Light::Spot {
        position,
        direction,
        frustum: hrts::SpotFrustum::Fitted { outer_cone },
        range: None,
    }
}

/// The plugin's directional light along `direction`, with the host's `view_proj` or (`None`) fitted by
/// the plugin.
fn plugin_directional_light(direction: Vec3, view_proj: Option<glam::Mat4>) -> hrts::Light {
    hrts::Light::Directional {
        direction,
        view_proj,
    }
}

/// Every light's layer of `file` from its camera after `frames` frames of `lights` under `configs`, and
/// each light's report of the last frame.
fn native_frame(
    device: &Device,
    file: &SceneFile,
    configs: &[Config],
    lights: Vec<hrts::Light>,
    frames: usize,
) -> (Vec<hrts::FrameReport>, Vec<Vec<f32>>) {
    native_frame_to(device, file, (configs, lights), frames, false)
}

/// [`native_frame`], each light writing its layer of the output directly where `direct`
/// ([`PluginRenderer::write_outputs_directly`]).
fn native_frame_to(
    device: &Device,
    file: &SceneFile,
    (configs, lights): (&[Config], Vec<hrts::Light>),
    frames: usize,
    direct: bool,
) -> (Vec<hrts::FrameReport>, Vec<Vec<f32>>) {
    let mut plugin = plugin_for(device, file);
    if direct {
        plugin.write_outputs_directly();
    }
    plugin.configure_lights(device, configs).expect("configure");
    let matrices = CameraMatrices::of_camera(&camera(file), WIDTH, HEIGHT);
    let mut reports = Vec::new();
    for _ in 0..frames {
        reports = plugin
            .render_lights(device, &matrices, &lights)
            .expect("frame")
            .lights;
    }
    let (_, layers) = plugin.read_frame(device).expect("read back");
    (reports, layers)
}

/// The frustum the plugin fits to a directional light given without a matrix is, bit for bit, the host's
/// own (`scene::DirectionalLight::view_proj`) for the same bounds, far from the origin and flat ones too:
/// both wrap `light_fit::directional_view_proj`.
#[test]
fn the_plugins_directional_fit_is_the_scenes() {
    let near = scene::procedural_default();
    let far = near.translated(Vec3::new(300.0, -20.0, 1e3));
    let flat = scene::Scene::axis_box("flat", Vec3::new(-2.0, 1.0, -3.0), Vec3::new(4.0, 1.0, 1.0));
    for s in [&near, &far, &flat] {
        let bounds = s.bounds();
        for direction in [
            Vec3::new(0.3, -1.0, 0.2).normalize(),
            Vec3::NEG_Y,
            Vec3::new(0.001, -1.0, 0.0),
            Vec3::new(-1.0, -0.05, 0.2),
        ] {
            let host = scene::DirectionalLight { direction }.view_proj(&bounds);
            let plugin = passes::directional_light_frustum(direction, [bounds.min, bounds.max])
                .expect("fitted");
            assert_eq!(
                plugin.view_proj().to_cols_array().map(f32::to_bits),
                host.to_cols_array().map(f32::to_bits),
                "{direction}"
            );
        }
    }
}

/// A sun given without a matrix (`view_proj: None`, the C ABI's directional light with `view_proj` all
/// zeros): the plugin fits its frustum to the frame's bounds, and its visibility is the same, pixel for
/// pixel, as the same sun's given the host's own fitted matrix (`scene::DirectionalLight::view_proj` of the
/// same bounds); both are the exact shadow.
#[test]
fn a_sun_fitted_by_the_plugin_shadows_as_the_hosts_matrix_does() {
    let device = device();
    let file = open_boxes();
    let direction = sun_direction();
    let host = scene::DirectionalLight { direction }.view_proj(&file.scene.bounds());
    let config = Config {
        mode: ShadowMode::Hard,
        antialiasing: false,
        ..settings(false).base
    };
    let (reports, layers) = native_frame(
        &device,
        &file,
        &[config, config],
        vec![
            plugin_directional_light(direction, Some(host)),
            plugin_directional_light(direction, None),
        ],
        1,
    );
    let params = scene_visibility_params(
        &file.scene,
        &camera(&file),
        WIDTH,
        HEIGHT,
        reference::Light::Directional {
            direction: direction.as_dvec3(),
        },
    );
    let r = reference_visibility(&RefScene::new(&file.scene), &params);
    for (name, (layer, report)) in ["host's matrix", "fitted by the plugin"]
        .iter()
        .zip(layers.iter().zip(&reports))
    {
        let c = compare_with_reference(&r, layer, None, None);
        println!(
            "sun, {name}: {} pixels, {} shadowed, {} near an edge, {} mismatches; {}",
            c.pixels, c.shadowed, c.near_edge, c.mismatches, report.decision_reason
        );
        assert_exact_visibility(&c, 0.05);
        assert_eq!(
            report.decision_reason,
            "directional light: its frustum holds receivers in view"
        );
    }
    let differing = layers[0]
        .iter()
        .zip(&layers[1])
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(differing, 0, "pixels where the fitted sun differs");
    assert_no_validation_errors(&device);
}

/// One configuration in mode auto for two lights of no angular radius and an emitter radius of 0.2 m: the
/// sun (its size the angular radius, 0) gets exact hard shadows, the point lamp (its size the emitter's
/// radius) exact area shadows as one cube map; each report says which and why, and each layer is exact.
#[test]
fn mode_auto_shadows_a_zero_size_sun_hard_and_a_sized_lamp_area() {
    let device = device();
    let file = open_boxes();
    let direction = sun_direction();
    let lamp = Vec3::new(0.6, 2.2, 0.9);
    let (radius, samples) = (0.2, 16);
    let mut config = Config {
        mode: ShadowMode::Auto,
        antialiasing: false,
        area_samples: samples,
        ..settings(false).base
    };
    config.pcss_angular_radius = 0.0;
    config.pcss_spot_radius = radius;
    // The second frame: the first one's lists grow to what it needed. Each light's layer copied into the
    // output, or written into it directly.
    let frame = |direct| {
        let lights = vec![
            plugin_directional_light(direction, None),
            plugin_point_light(lamp),
        ];
        native_frame_to(&device, &file, (&[config, config], lights), 2, direct)
    };
    let (reports, layers) = frame(false);
    let (sun, lamp_report) = (&reports[0], &reports[1]);
    println!(
        "sun: {}\nlamp: {}",
        sun.decision_reason, lamp_report.decision_reason
    );
    assert!(
        sun.decision_reason
            .ends_with("; auto: hard (zero-size light)"),
        "{}",
        sun.decision_reason
    );
    assert!(
        lamp_report.decision_reason.contains("cube")
            && lamp_report
                .decision_reason
                .ends_with("; auto: area (sized light)"),
        "{}",
        lamp_report.decision_reason
    );
    // The visibility's bytes: its R32F image, and for the area trace its own buffers too (light samples,
    // edge tables, sample bands and one word per 8x8 tile of history).
    let image = u64::from(WIDTH * HEIGHT) * 4;
    let tiles = u64::from(WIDTH.div_ceil(8) * HEIGHT.div_ceil(8)) * 4;
    assert_eq!(sun.resource_bytes(hrts::Resource::RtVisibility), image);
    let area_buffers = lamp_report.resource_bytes(hrts::Resource::RtVisibility) - image;
    assert!(area_buffers > tiles, "{area_buffers}");
    // Written directly, the layers are the engine's: the same visibility, and the area trace's buffers
    // alone in the lamp's count.
    let (direct_reports, direct_layers) = frame(true);
    assert!(direct_reports.iter().all(|r| r.output_direct));
    assert!(
        direct_layers == layers,
        "direct output differs from the copy"
    );
    let direct_bytes = |r: &hrts::FrameReport| r.resource_bytes(hrts::Resource::RtVisibility);
    assert_eq!(direct_bytes(&direct_reports[0]), 0);
    assert_eq!(direct_bytes(&direct_reports[1]), area_buffers);
    for report in &reports {
        let has = |r: hrts::Resource| report.resource_bytes(r) > 0;
        assert!(has(hrts::Resource::RtVisibility) && !has(hrts::Resource::ShadowMap));
        assert!(!has(hrts::Resource::RtAntialiased));
    }
    let rs = RefScene::new(&file.scene);
    let camera = camera(&file);
    let params = scene_visibility_params(
        &file.scene,
        &camera,
        WIDTH,
        HEIGHT,
        reference::Light::Directional {
            direction: direction.as_dvec3(),
        },
    );
    let c = compare_with_reference(&reference_visibility(&rs, &params), &layers[0], None, None);
    println!(
        "sun (hard): {} pixels, {} shadowed, {} near an edge, {} mismatches",
        c.pixels, c.shadowed, c.near_edge, c.mismatches
    );
    assert_exact_visibility(&c, 0.05);
    let offsets: Vec<glam::DVec2> = passes::area::local_area_offsets(samples)
        .iter()
        .map(|o| o.as_dvec2())
        .collect();
    let r = local_area_reference(
        &rs,
        &point_light_params(&file, &camera, lamp),
        lamp.as_dvec3(),
        f64::from(radius),
        &offsets,
    );
    let c = compare_area_counts(&r, &layers[1], None);
    println!(
        "lamp (area, R {radius}, {samples} samples): {} px, {} unstable, {} penumbra, {} umbra, {} mismatches",
        c.pixels, c.unstable, c.penumbra, c.umbra, c.mismatches
    );
    assert_exact_area("auto lamp", &c, 100, 25);
    assert_no_validation_errors(&device);
}

/// The receiver points of `params`' view (NaN where the camera ray hits nothing).
fn r_positions(rs: &RefScene, params: &reference::VisibilityParams) -> Vec<glam::DVec3> {
    reference_visibility(rs, params).position
}

/// The sized lamp in the closed room, everything moved 1e4 from the origin (the passes work relative to the
/// geometry's centre): the same exact counts on stable pixels.
#[test]
fn a_sized_point_light_1e4_from_the_origin_matches_the_reference() {
    let device = device();
    let offset = Vec3::new(1e4, 0.0, -1e4);
    let lamp = Vec3::new(0.15, 2.5, 0.1) + offset;
    let mut file = closed_room(Vec3::new(0.15, 2.5, 0.1));
    file.scene = file.scene.translated(offset);
    let camera = file.camera.as_mut().expect("a camera");
    camera.position += offset;
    camera.target += offset;
    check_local_area(
        &device,
        "point lamp 1e4 from the origin",
        &file,
        plugin_point_light(lamp),
        (lamp, 0.3, 16),
        None,
        (200, 25),
    );
}

/// The plugin over `file`'s static geometry at the test size, with the analysis G-buffer.
fn plugin_for(device: &Device, file: &SceneFile) -> PluginRenderer {
    PluginRenderer::for_scene(
        device,
        &file.scene,
        WIDTH,
        HEIGHT,
        demo_engine::gbuffer::GBufferLayout::ANALYSIS,
    )
    .expect("plugin")
}

/// The exact reference's view of `file` from `camera` at the test size, lit by a point light at `position`.
fn point_light_params(
    file: &SceneFile,
    camera: &Camera,
    position: Vec3,
) -> reference::VisibilityParams {
    scene_visibility_params(
        &file.scene,
        camera,
        WIDTH,
        HEIGHT,
        reference::Light::Point {
            position: position.as_dvec3(),
        },
    )
}
