//! The same scene written as float, quantized (`KHR_mesh_quantization`) and meshopt-compressed
//! (`EXT_meshopt_compression`) glTF renders the same shadows on lavapipe: every light's visibility
//! identical pixel for pixel, and the float file's against the exact reference.

mod common;

use common::{
    assert_no_validation_errors, compare_with_reference, device, scene_visibility_params,
};
use glam::Vec3;
use host_demo::scene_plan::{plan_scene, PlanSettings};
use host_demo::scene_render::SceneRenderer;
use reference::{reference_visibility, RefScene};
use rhi::Device;
use scene::gltf_scene::{write_scene, GltfEncoding, Quantization, QuantizedComponent};
use scene::{Camera, LightKind, LightSize, SceneFile, SceneLight};
use std::path::{Path, PathBuf};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

/// Boxes on a ground, a sun and a spot light (both zero-size: exact hard shadows), a camera.
fn boxes_on_ground() -> SceneFile {
    let mut scene = scene::Scene::default();
    scene.append(&scene::Scene::axis_box(
        "ground",
        Vec3::new(-6.0, -0.2, -6.0),
        Vec3::new(6.0, 0.0, 6.0),
    ));
    for (name, min, max) in [
        (
            "crate",
            Vec3::new(-2.0, 0.0, -0.5),
            Vec3::new(-1.0, 1.0, 0.5),
        ),
        (
            "tower",
            Vec3::new(1.0, 0.0, -1.5),
            Vec3::new(1.6, 2.3, -0.9),
        ),
        ("slab", Vec3::new(-0.4, 0.6, 1.0), Vec3::new(1.3, 0.75, 2.2)),
    ] {
        scene.append(&scene::Scene::axis_box(name, min, max));
    }
    let light = |name: &str, kind: LightKind| SceneLight {
        name: name.into(),
        kind,
        color: Vec3::ONE,
        intensity: 3.0,
        size: LightSize::Zero,
        casts_shadows: true,
        is_static: true,
    };
    let spot_position = Vec3::new(-3.0, 4.0, 3.0);
    SceneFile {
        static_objects: vec![true; scene.objects.len()],
        shadow_casters: vec![true; scene.objects.len()],
        scene,
        lights: vec![
            light(
                "sun",
                LightKind::Directional {
                    direction: Vec3::new(0.5, -1.0, 0.3).normalize(),
                },
            ),
            light(
                "spot",
                LightKind::Spot {
                    position: spot_position,
                    direction: (Vec3::new(0.0, 0.0, 0.0) - spot_position).normalize(),
                    inner_cone: 0.5,
                    outer_cone: 0.7,
                    range: None,
                },
            ),
        ],
        camera: Some(Camera {
            position: Vec3::new(5.0, 5.0, 7.0),
            target: Vec3::new(0.0, 0.5, 0.0),
            up: Vec3::Y,
            fov_y_radians: 55f32.to_radians(),
            near: 0.05,
        }),
        skipped_primitives: 0,
    }
}

fn write_and_load(dir: &Path, name: &str, file: &SceneFile, encoding: GltfEncoding) -> SceneFile {
    let path = dir.join(name);
    write_scene(&path, file, encoding).expect("write the scene");
    scene::load_gltf(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Each light's visibility of `file` seen from its camera.
fn visibilities(device: &Device, file: &SceneFile) -> Vec<Vec<f32>> {
    let camera = file.camera.expect("the scene has a camera");
    let settings = PlanSettings {
        base: hrts::Config {
            antialiasing: false,
            map_size: 128,
            ..hrts::Config::default()
        },
        width: WIDTH,
        height: HEIGHT,
    };
    let plan = plan_scene(file, &camera, &settings).expect("plan");
    let mut renderer = SceneRenderer::new(device, file, WIDTH, HEIGHT).expect("renderer");
    renderer.render(device, &camera, &plan).expect("frame");
    renderer
        .read_back(device, &plan)
        .expect("read back")
        .visibility
}

#[test]
fn float_quantized_and_meshopt_files_cast_the_same_shadows() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("gltf_compressed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let original = boxes_on_ground();
    let float = write_and_load(&dir, "float.glb", &original, GltfEncoding::default());
    let meshopt = write_and_load(
        &dir,
        "meshopt.glb",
        &original,
        GltfEncoding {
            quantize: None,
            meshopt: true,
        },
    );
    let quantize = Some(Quantization {
        component: QuantizedComponent::U16,
        normalized: true,
    });
    let quantized = write_and_load(
        &dir,
        "quantized.gltf",
        &original,
        GltfEncoding {
            quantize,
            meshopt: false,
        },
    );
    let quantized_meshopt = write_and_load(
        &dir,
        "quantized-meshopt.glb",
        &original,
        GltfEncoding {
            quantize,
            meshopt: true,
        },
    );
    // The float file of the dequantized geometry: exactly the same triangles.
    let dequantized = write_and_load(&dir, "dequantized.glb", &quantized, GltfEncoding::default());
    assert_eq!(dequantized.scene, quantized.scene);
    assert_eq!(quantized_meshopt.scene.positions, quantized.scene.positions);
    // Float and meshopt files hold exactly the original triangles (meshopt's index codec may
    // rotate a triangle's corners, keeping its winding).
    for t in 0..original.scene.triangle_count() {
        let expected = original.scene.triangle(t);
        assert_eq!(float.scene.triangle(t), expected);
        let mut rotated = meshopt.scene.triangle(t);
        let turns = (0..3).find(|&r| {
            rotated.rotate_left(usize::from(r > 0));
            rotated == expected
        });
        assert!(turns.is_some(), "meshopt triangle {t}");
    }
    assert_ne!(
        quantized.scene.positions, original.scene.positions,
        "quantization moves vertices"
    );

    let device = device();
    let expected = visibilities(&device, &float);
    for (light, visibility) in float.lights.iter().zip(&expected) {
        let shadowed = visibility.iter().filter(|&&v| v < 0.5).count();
        assert!(
            shadowed > 50,
            "{}: only {shadowed} shadowed pixels",
            light.name
        );
    }
    // The float file against the exact reference (the sun: a directional reference light).
    let camera = float.camera.unwrap();
    let LightKind::Directional { direction } = float.lights[0].kind else {
        unreachable!("the first light is the sun")
    };
    let params = scene_visibility_params(
        &float.scene,
        &camera,
        WIDTH,
        HEIGHT,
        reference::Light::Directional {
            direction: direction.as_dvec3(),
        },
    );
    let exact = reference_visibility(&RefScene::new(&float.scene), &params);
    let c = compare_with_reference(&exact, &expected[0], None, None);
    assert_eq!(
        c.mismatches, 0,
        "sun against the exact reference: {:?}",
        c.examples
    );

    let differing = |a: &[Vec<f32>], b: &[Vec<f32>]| -> Vec<usize> {
        a.iter()
            .zip(b)
            .map(|(a, b)| a.iter().zip(b).filter(|(x, y)| x != y).count())
            .collect()
    };
    let lights = expected.len();
    assert_eq!(
        differing(&visibilities(&device, &meshopt), &expected),
        vec![0; lights],
        "meshopt"
    );
    let quantized_expected = visibilities(&device, &dequantized);
    for (name, file) in [
        ("quantized", &quantized),
        ("quantized + meshopt", &quantized_meshopt),
    ] {
        assert_eq!(
            differing(&visibilities(&device, file), &quantized_expected),
            vec![0; lights],
            "{name}"
        );
    }
    assert_no_validation_errors(&device);
    let _ = std::fs::remove_dir_all(&dir);
}
