use std::f32::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};

use super::writer::{data_uri, glb, to_json_bytes, GltfWriter};
use super::*;

/// A fresh directory in the system temporary directory, removed on drop.
pub(super) struct TempDir(pub(super) PathBuf);

impl TempDir {
    pub(super) fn new() -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let path = std::env::temp_dir().join(format!(
            "scene-gltf-test-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&path).unwrap();
        Self(path)
    }

    pub(super) fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    /// Writes `document` as glTF JSON with `bin` embedded as a `data:` URI, and loads it.
    pub(super) fn load_embedded(
        &self,
        name: &str,
        document: &Value,
        bin: &[u8],
    ) -> Result<SceneFile, SceneError> {
        load(&self.write(name, &embedded(document, bin)))
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// [`load_gltf`], checking that every error names the file.
pub(super) fn load(path: &Path) -> Result<SceneFile, SceneError> {
    let result = load_gltf(path);
    if let Err(e) = &result {
        let name = path.display().to_string();
        assert!(e.to_string().contains(&name), "{e} does not name {name}");
    }
    result
}

fn embedded(document: &Value, bin: &[u8]) -> Vec<u8> {
    let mut document = document.clone();
    document["buffers"][0]["uri"] = data_uri(bin).into();
    to_json_bytes(&document)
}

fn assert_near(actual: Vec3, expected: Vec3) {
    assert!(
        actual.abs_diff_eq(expected, 1e-5),
        "{actual} is not {expected}"
    );
}

fn trs(translation: Vec3, rotation: Quat, scale: Vec3) -> Value {
    json!({
        "translation": translation.to_array(),
        "rotation": rotation.to_array(),
        "scale": scale.to_array(),
    })
}

/// `node` with the extra fields of `fields` (an object).
fn with(mut node: Value, fields: Value) -> Value {
    for (key, value) in fields.as_object().unwrap() {
        node[key] = value.clone();
    }
    node
}

fn light_ref(light: usize) -> Value {
    json!({ "KHR_lights_punctual": { "light": light } })
}

pub(super) const TRIANGLE: [Vec3; 3] = [Vec3::ZERO, Vec3::X, Vec3::Y];

/// A writer holding one root node with a unit triangle, so that every document has geometry.
pub(super) fn with_triangle() -> GltfWriter {
    let mut w = GltfWriter::default();
    let mesh = w.mesh("triangle", &TRIANGLE, &[0, 1, 2]);
    let node = w.node(json!({ "name": "triangle", "mesh": mesh }));
    w.root(node);
    w
}

/// A document with one light definition `light` on a root node with extras `node_extras`.
fn one_light(light: Value, node_extras: Value) -> (Value, Vec<u8>) {
    let mut w = with_triangle();
    let light = w.light(light);
    let node = w.node(json!({
        "name": "lamp",
        "translation": [0.0, 2.0, 0.0],
        "extensions": light_ref(light),
        "extras": node_extras,
    }));
    w.root(node);
    w.finish()
}

fn light_error(light: Value, node_extras: Value) -> SceneError {
    let dir = TempDir::new();
    let (document, bin) = one_light(light, node_extras);
    dir.load_embedded("light.gltf", &document, &bin)
        .expect_err("the light is invalid")
}

#[test]
fn four_lights_in_world_space() {
    let mut w = with_triangle();
    let sun = w.light(json!({
        "name": "sun-def", "type": "directional", "intensity": 4.0, "color": [1.0, 0.5, 0.25],
        "extras": { "hrts": { "angular_radius": 0.01, "static": false } },
    }));
    let hard = w.light(json!({
        "type": "directional",
        "extras": { "hrts": { "static": true }, "other_tool": { "x": 1 } },
    }));
    let spot = w.light(json!({
        "type": "spot", "range": 20.0,
        "spot": { "innerConeAngle": 0.1, "outerConeAngle": 0.4 },
        "extras": { "hrts": { "radius": 0.05 } },
    }));
    let point = w.light(json!({
        "name": "bulb", "type": "point",
        "extras": { "hrts": { "casts_shadows": false, "radius": 0.2 } },
    }));
    // Root: a directional light given by a matrix, 2 * rotation of -90° about X: local -Z
    // becomes world -Y, and the scale must not matter.
    let m = Mat4::from_scale(Vec3::splat(2.0)) * Mat4::from_rotation_x(-FRAC_PI_2);
    let hard_node = w.node(json!({
        "name": "hard", "matrix": m.to_cols_array(), "extensions": light_ref(hard),
    }));
    w.root(hard_node);
    // A static parent at (10, 0, 0) turned 90° about +Y: (x, y, z) -> (z, y, -x).
    let sun_node = w.node(with(
        trs(
            Vec3::new(0.0, 5.0, 0.0),
            Quat::from_rotation_x(-FRAC_PI_2 / 2.0),
            Vec3::ONE,
        ),
        json!({ "name": "sun", "extensions": light_ref(sun) }),
    ));
    let spot_node = w.node(with(
        trs(Vec3::new(0.0, 3.0, 2.0), Quat::IDENTITY, Vec3::splat(5.0)),
        json!({
            "name": "spot", "extensions": light_ref(spot),
            "extras": { "hrts": { "radius": 0.07, "static": false } },
        }),
    ));
    let bulb_node = w.node(with(
        trs(Vec3::new(0.0, 0.0, 1.0), Quat::IDENTITY, Vec3::ONE),
        json!({ "extensions": light_ref(point) }),
    ));
    let arm = w.node(with(
        trs(Vec3::X, Quat::IDENTITY, Vec3::ONE),
        json!({ "name": "arm", "children": [bulb_node] }),
    ));
    let parent = w.node(with(
        trs(
            Vec3::new(10.0, 0.0, 0.0),
            Quat::from_rotation_y(FRAC_PI_2),
            Vec3::ONE,
        ),
        json!({
            "name": "rig", "children": [sun_node, spot_node, arm],
            "extras": { "hrts": { "static": true } },
        }),
    ));
    w.root(parent);
    let (document, bin) = w.finish();
    let dir = TempDir::new();
    let file = dir.load_embedded("lights.gltf", &document, &bin).unwrap();
    assert_eq!(file.lights.len(), 4);
    assert_eq!(file.skipped_primitives, 0);
    assert!(file.camera.is_none());

    let hard = &file.lights[0];
    assert_eq!(hard.name, "hard");
    let LightKind::Directional { direction } = hard.kind else {
        panic!("{hard:?}")
    };
    assert_near(direction, Vec3::NEG_Y);
    assert_eq!(hard.size, LightSize::Zero);
    assert!(hard.size.is_zero());
    assert!(hard.casts_shadows);
    assert!(hard.is_static, "from the light definition");
    assert_eq!(
        (hard.color, hard.intensity),
        (Vec3::ONE, 1.0),
        "glTF defaults"
    );

    let sun = &file.lights[1];
    assert_eq!(sun.name, "sun", "the node's name comes first");
    let LightKind::Directional { direction } = sun.kind else {
        panic!("{sun:?}")
    };
    // Local -Z turned -45° about X is (0, -1, -1) / sqrt 2; the parent maps it to (-1, -1, 0).
    assert_near(direction, Vec3::new(-FRAC_1_SQRT_2, -FRAC_1_SQRT_2, 0.0));
    assert_eq!(sun.size, LightSize::AngularRadius(0.01));
    assert_eq!((sun.color, sun.intensity), (Vec3::new(1.0, 0.5, 0.25), 4.0));
    assert!(
        !sun.is_static,
        "the light definition's value beats the ancestor's"
    );

    let spot = &file.lights[2];
    let LightKind::Spot {
        position,
        direction,
        inner_cone,
        outer_cone,
        range,
    } = spot.kind
    else {
        panic!("{spot:?}")
    };
    assert_near(position, Vec3::new(12.0, 3.0, 0.0));
    assert_near(direction, Vec3::NEG_X);
    assert_eq!((inner_cone, outer_cone, range), (0.1, 0.4, Some(20.0)));
    assert_eq!(
        spot.size,
        LightSize::Radius(0.07),
        "the node's value beats the light's"
    );
    assert!(!spot.is_static);
    assert!(spot.casts_shadows);

    let bulb = &file.lights[3];
    assert_eq!(bulb.name, "bulb", "the light's name when the node has none");
    let LightKind::Point { position, range } = bulb.kind else {
        panic!("{bulb:?}")
    };
    // arm: (10, 0, 0) + R(1, 0, 0) = (10, 0, -1); bulb: + R(0, 0, 1) = (11, 0, -1).
    assert_near(position, Vec3::new(11.0, 0.0, -1.0));
    assert_eq!(range, None);
    assert_eq!(bulb.size, LightSize::Radius(0.2));
    assert!(!bulb.casts_shadows);
    assert!(bulb.is_static, "inherited from the rig");
    for light in &file.lights {
        light.validate().unwrap();
    }
}

/// Four corner positions of a unit square in the XY plane, counter-clockwise seen from +Z.
const SQUARE: [Vec3; 4] = [
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(1.0, 1.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
];

fn normal(t: [Vec3; 3]) -> Vec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize()
}

#[test]
fn mesh_hierarchy_and_primitive_modes() {
    let mut w = GltfWriter::default();
    let square = w.mesh("square", &SQUARE, &[0, 1, 2, 0, 2, 3]);
    let root = w.node(with(
        trs(Vec3::new(0.0, 0.0, 5.0), Quat::IDENTITY, Vec3::splat(2.0)),
        json!({ "name": "root", "mesh": square, "extras": { "hrts": { "static": true } } }),
    ));
    // Child: translated by (1, 0, 0) in the parent's frame, turned 90° about +Y by a matrix.
    let m = Mat4::from_translation(Vec3::X) * Mat4::from_rotation_y(FRAC_PI_2);
    let child = w.node(json!({ "name": "child", "mesh": square, "matrix": m.to_cols_array() }));
    // A mirrored grandchild (negative determinant) marked dynamic.
    let mirrored = w.node(with(
        trs(Vec3::ZERO, Quat::IDENTITY, Vec3::new(-1.0, 1.0, 1.0)),
        json!({ "mesh": square, "extras": { "hrts": { "static": false } } }),
    ));
    let modes = w.node(json!({ "name": "modes", "mesh": square, "translation": [0.0, 10.0, 0.0] }));
    let empty = w.node(json!({ "name": "no triangles", "mesh": square }));
    w.root(root);
    let (mut document, bin) = w.finish();
    document["nodes"][root]["children"] = json!([child]);
    document["nodes"][child]["children"] = json!([mirrored]);
    document["scenes"][0]["nodes"] = json!([root, modes, empty]);
    // Meshes 1 and 2: the same vertices as a strip, a fan, lines and points (non-indexed).
    let primitive = |mode: u32| json!({ "attributes": { "POSITION": 0 }, "mode": mode });
    document["meshes"] = json!([
        document["meshes"][0].clone(),
        { "name": "modes", "primitives": [primitive(5), primitive(6), primitive(1), primitive(0)] },
        { "primitives": [primitive(3), primitive(2)] },
    ]);
    document["nodes"][modes]["mesh"] = 1.into();
    document["nodes"][empty]["mesh"] = 2.into();
    let dir = TempDir::new();
    let file = dir
        .load_embedded("hierarchy.gltf", &document, &bin)
        .unwrap();
    let scene = &file.scene;
    scene.validate().unwrap();
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["root", "child", "square", "modes"]);
    // "modes" says nothing and no animation moves it: static.
    assert_eq!(file.static_objects, [true, true, false, true]);
    assert_eq!(
        file.skipped_primitives, 4,
        "lines, points, line loop, line strip"
    );
    let counts: Vec<u32> = scene.objects.iter().map(|o| o.triangle_count).collect();
    assert_eq!(counts, [2, 2, 2, 4], "strip and fan give 2 each");

    // Root: scaled by 2, moved to z = 5.
    assert_eq!(
        scene.triangle(0),
        [
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::new(2.0, 0.0, 5.0),
            Vec3::new(2.0, 2.0, 5.0)
        ]
    );
    assert_near(normal(scene.triangle(0)), Vec3::Z);
    // Child: local (x, y, z) -> turned (z, y, -x) + (1, 0, 0), then the root transform.
    let child_world = |p: Vec3| Vec3::new(2.0 * (p.z + 1.0), 2.0 * p.y, 5.0 - 2.0 * p.x);
    for (k, &i) in [0, 1, 2].iter().enumerate() {
        assert_near(scene.triangle(2)[k], child_world(SQUARE[i]));
    }
    assert_near(normal(scene.triangle(2)), Vec3::X);
    // Mirrored: x negated first; the winding is reversed so the front still faces +X.
    let t = scene.triangle(4);
    assert_near(t[0], child_world(SQUARE[0]));
    assert_near(t[1], child_world(SQUARE[2] * Vec3::new(-1.0, 1.0, 1.0)));
    assert_near(t[2], child_world(SQUARE[1] * Vec3::new(-1.0, 1.0, 1.0)));
    assert_near(normal(t), Vec3::X);
    // Strip over 0 1 2 3: (0 1 2), (1 3 2); fan: (1 2 0), (2 3 0).
    let up = Vec3::new(0.0, 10.0, 0.0);
    let expected = [[0, 1, 2], [1, 3, 2], [1, 2, 0], [2, 3, 0]];
    for (k, corners) in expected.iter().enumerate() {
        let t = scene.triangle(6 + k);
        for c in 0..3 {
            assert_near(t[c], SQUARE[corners[c]] + up);
        }
    }
    // (1 3 2) of a square given in ring order winds the other way; the others face +Z.
    for (k, facing) in [(6, Vec3::Z), (7, Vec3::NEG_Z), (8, Vec3::Z), (9, Vec3::Z)] {
        assert_near(normal(scene.triangle(k)), facing);
    }
}

#[test]
fn containers_load_the_same_scene() {
    let dir = TempDir::new();
    let (document, bin) = one_light(
        json!({ "type": "point", "extras": { "hrts": { "radius": 0.1 } } }),
        json!({ "hrts": { "static": true } }),
    );
    let from_embedded = dir.load_embedded("embedded.gltf", &document, &bin).unwrap();
    let from_glb = load(&dir.write("binary.glb", &glb(&document, &bin))).unwrap();
    let mut separate = document.clone();
    separate["buffers"][0]["uri"] = "data%20file.bin".into();
    dir.write("data file.bin", &bin);
    let from_separate = load(&dir.write("separate.gltf", &to_json_bytes(&separate))).unwrap();
    assert_eq!(from_embedded, from_glb);
    assert_eq!(from_embedded, from_separate);
    assert_eq!(from_glb.scene.triangle(0), TRIANGLE);
    assert_eq!(from_glb.lights.len(), 1);
    assert_eq!(
        from_glb.lights[0].kind.position(),
        Some(Vec3::new(0.0, 2.0, 0.0))
    );
    assert!(from_glb.lights[0].is_static);
}

#[test]
fn example_scene() {
    let dir = TempDir::new();
    let gltf_path = dir.0.join("example.gltf");
    let glb_path = dir.0.join("example.GLB");
    write_example_scene(&gltf_path).unwrap();
    write_example_scene(&glb_path).unwrap();
    assert!(std::fs::read(&glb_path).unwrap().starts_with(b"glTF"));
    assert!(std::fs::read(&gltf_path).unwrap().starts_with(b"{"));
    let file = load(&gltf_path).unwrap();
    assert_eq!(file, load(&glb_path).unwrap());

    let names: Vec<&str> = file.scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        ["ground", "crate", "tower", "cart_body", "cart_load"]
    );
    assert_eq!(file.static_objects, [true, true, true, false, false]);
    assert_eq!(file.scene.triangle_count(), 2 + 4 * 12);
    let bounds = file.scene.bounds();
    assert_eq!((bounds.min.y, bounds.max.y), (0.0, 2.0));

    let lights: Vec<(&str, bool, bool)> = file
        .lights
        .iter()
        .map(|l| (l.name.as_str(), l.casts_shadows, l.is_static))
        .collect();
    assert_eq!(
        lights,
        [
            ("sun", true, true),
            ("rim", true, true),
            ("spot", true, true),
            ("fill", false, true),
            ("cart_lamp", true, false),
        ]
    );
    let sizes: Vec<LightSize> = file.lights.iter().map(|l| l.size).collect();
    assert_eq!(
        sizes,
        [
            LightSize::AngularRadius(0.01),
            LightSize::Zero,
            LightSize::Radius(0.05),
            LightSize::Zero,
            LightSize::Radius(0.1),
        ]
    );
    assert_near(
        file.lights[0].kind.direction().unwrap(),
        crate::DirectionalLight::slanted().direction,
    );
    let spot_direction = file.lights[2].kind.direction().unwrap();
    let spot_position = file.lights[2].kind.position().unwrap();
    assert_near(spot_position, Vec3::new(-3.0, 3.5, 2.5));
    assert_near(
        spot_direction,
        (Vec3::new(-1.5, 0.5, 0.5) - spot_position).normalize(),
    );
    // The lamp rides 1.6 m above the cart's origin.
    assert_near(
        file.lights[4].kind.position().unwrap(),
        Vec3::new(0.3, 1.6, 1.6),
    );

    let camera = file.camera.expect("the example has a camera");
    assert_near(camera.position, Vec3::new(6.0, 4.5, 8.0));
    assert_near(
        (camera.target - camera.position).normalize(),
        (Vec3::new(0.0, 0.8, 0.0) - camera.position).normalize(),
    );
    assert!(camera.up.y > 0.5);
    assert!((camera.fov_y_radians - std::f32::consts::FRAC_PI_4).abs() < 1e-6);
    assert_eq!(camera.near, 0.05);
}

#[test]
fn malformed_containers_and_buffers() {
    let dir = TempDir::new();
    let (document, bin) = with_triangle().finish();

    for (name, bytes) in [
        ("text.gltf", &b"hello"[..]),
        ("empty.gltf", &b""[..]),
        ("object.gltf", &b"{}"[..]),
    ] {
        let error = load(&dir.write(name, bytes)).unwrap_err();
        assert!(matches!(error, SceneError::Gltf { .. }), "{name}: {error}");
        assert!(
            error.to_string().contains("neither GLB nor glTF JSON"),
            "{error}"
        );
    }
    // A schema error says where in the file it is.
    let mut typo = document.clone();
    typo["asset"]["version"] = 2.into();
    let error = dir.load_embedded("typo.gltf", &typo, &bin).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("invalid type: integer `2`, expected a string at line ")
            && message.contains(" column "),
        "{error}"
    );
    let mut old = document.clone();
    old["asset"]["version"] = "1.0".into();
    let error = dir.load_embedded("old.gltf", &old, &bin).unwrap_err();
    assert!(error.to_string().contains("only glTF 2.x"), "{error}");

    let whole = glb(&document, &bin);
    for length in [4, 11, 12, 20, 40, whole.len() - 4, whole.len() - 1] {
        let error = load(&dir.write("cut.glb", &whole[..length])).unwrap_err();
        assert!(
            matches!(error, SceneError::Gltf { .. }),
            "{length}: {error}"
        );
        assert!(
            error.to_string().contains("truncated GLB"),
            "{length}: {error}"
        );
    }
    let mut wrong_length = whole.clone();
    wrong_length[8..12].copy_from_slice(&4u32.to_le_bytes());
    let error = load(&dir.write("short-header.glb", &wrong_length)).unwrap_err();
    assert!(error.to_string().contains("too short"), "{error}");
    let mut bad_chunk = whole.clone();
    bad_chunk[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    let error = load(&dir.write("bad-chunk.glb", &bad_chunk)).unwrap_err();
    assert!(error.to_string().contains("malformed GLB"), "{error}");
    let no_bin = glb(&document, &[]);
    let error = load(&dir.write("no-bin.glb", &no_bin)).unwrap_err();
    assert!(
        matches!(error, SceneError::GltfBuffer { buffer: 0, .. }),
        "{error}"
    );

    let mut missing = document.clone();
    missing["buffers"][0]["uri"] = "missing.bin".into();
    let error = load(&dir.write("missing.gltf", &to_json_bytes(&missing))).unwrap_err();
    assert!(
        matches!(error, SceneError::GltfBuffer { buffer: 0, .. }),
        "{error}"
    );
    assert!(error.to_string().contains("\"missing.bin\""), "{error}");
    let mut bad_utf8 = document.clone();
    bad_utf8["buffers"][0]["uri"] = "%ff.bin".into();
    let error = load(&dir.write("bad-uri.gltf", &to_json_bytes(&bad_utf8))).unwrap_err();
    assert!(error.to_string().contains("UTF-8"), "{error}");
    let mut bad_base64 = document.clone();
    bad_base64["buffers"][0]["uri"] = "data:application/octet-stream;base64,!!".into();
    let error = load(&dir.write("bad-base64.gltf", &to_json_bytes(&bad_base64))).unwrap_err();
    assert!(matches!(error, SceneError::GltfBuffer { .. }), "{error}");
    let error = dir
        .load_embedded("short.gltf", &document, &bin[..bin.len() - 8])
        .unwrap_err();
    assert!(
        matches!(error, SceneError::GltfBuffer { buffer: 0, .. }),
        "{error}"
    );
    assert!(error.to_string().contains("byteLength"), "{error}");
}

#[test]
fn malformed_geometry() {
    let dir = TempDir::new();
    let geometry = |positions: &[Vec3], indices: &[u32]| {
        let mut w = GltfWriter::default();
        let mesh = w.mesh("bad", positions, indices);
        let node = w.node(json!({ "name": "thing", "mesh": mesh }));
        w.root(node);
        w.finish()
    };

    let (document, bin) = geometry(&TRIANGLE, &[0, 1, 2, 0, 2, 5]);
    let error = dir
        .load_embedded("index.gltf", &document, &bin)
        .unwrap_err();
    let SceneError::GltfIndexOutOfRange {
        primitive,
        triangle: 1,
        index: 5,
        count: 3,
        ..
    } = &error
    else {
        panic!("{error}")
    };
    assert_eq!(primitive, "mesh 0 \"bad\" primitive 0 at node 0 \"thing\"");

    let (document, bin) = geometry(
        &[Vec3::ZERO, Vec3::new(1.0, f32::NAN, 0.0), Vec3::Y],
        &[0, 1, 2],
    );
    let error = dir.load_embedded("nan.gltf", &document, &bin).unwrap_err();
    assert!(
        matches!(error, SceneError::GltfNonFinite { vertex: 1, value, .. } if value.is_nan()),
        "{error}"
    );
    let (document, bin) = geometry(
        &[Vec3::ZERO, Vec3::X, Vec3::splat(f32::INFINITY)],
        &[0, 1, 2],
    );
    let error = dir.load_embedded("inf.gltf", &document, &bin).unwrap_err();
    assert!(
        matches!(error, SceneError::GltfNonFinite { vertex: 2, value, .. } if value.is_infinite()),
        "{error}"
    );
    // Finite in the file, infinite after a huge scale.
    let (mut document, bin) = geometry(&[Vec3::ZERO, Vec3::X * 1e30, Vec3::Y], &[0, 1, 2]);
    document["nodes"][0]["scale"] = json!([1e30, 1.0, 1.0]);
    let error = dir
        .load_embedded("overflow.gltf", &document, &bin)
        .unwrap_err();
    assert!(
        matches!(error, SceneError::GltfNonFinite { vertex: 1, .. }),
        "{error}"
    );

    let (document, bin) = geometry(&TRIANGLE, &[0, 1, 2]);
    let mutated = |f: &dyn Fn(&mut Value)| {
        let mut d = document.clone();
        f(&mut d);
        d
    };
    let cases: [(&str, Value, &str); 10] = [
        (
            "count",
            mutated(&|d| d["accessors"][0]["count"] = 4.into()),
            "exceed buffer view",
        ),
        (
            "offset",
            mutated(&|d| d["accessors"][1]["byteOffset"] = 8.into()),
            "exceed buffer view",
        ),
        (
            "view",
            mutated(&|d| d["bufferViews"][0]["byteLength"] = 1000.into()),
            "exceeds buffer 0",
        ),
        (
            "type",
            mutated(&|d| d["accessors"][0]["type"] = "VEC2".into()),
            "VEC3 of FLOAT",
        ),
        (
            "index type",
            mutated(&|d| d["accessors"][1]["componentType"] = 5126.into()),
            "UNSIGNED_BYTE",
        ),
        (
            "zero count",
            mutated(&|d| d["accessors"][1]["count"] = 0.into()),
            "count is 0",
        ),
        (
            "whole triangles",
            mutated(&|d| d["accessors"][1]["count"] = 2.into()),
            "whole triangles",
        ),
        (
            "accessor index",
            mutated(&|d| d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99.into()),
            "accessor 99",
        ),
        (
            "cycle",
            mutated(&|d| d["nodes"][0]["children"] = json!([0])),
            "must be a tree",
        ),
        (
            "transform",
            mutated(&|d| d["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 0.0])),
            "non-finite world transform",
        ),
    ];
    for (name, document, expected) in cases {
        let error = dir.load_embedded("case.gltf", &document, &bin).unwrap_err();
        assert!(matches!(error, SceneError::Gltf { .. }), "{name}: {error}");
        assert!(error.to_string().contains(expected), "{name}: {error}");
    }

    // Nothing but a light: no triangles.
    let mut w = GltfWriter::default();
    let light = w.light(json!({ "type": "point" }));
    let node = w.node(json!({ "extensions": light_ref(light) }));
    w.root(node);
    let (document, bin) = w.finish();
    let error = dir
        .load_embedded("lights-only.gltf", &document, &bin)
        .unwrap_err();
    assert!(matches!(error, SceneError::Empty { .. }), "{error}");

    let (mut document, bin) = with_triangle().finish();
    document["cameras"] =
        json!([{ "type": "perspective", "perspective": { "yfov": 0.0, "znear": 0.1 } }]);
    document["nodes"][0]["camera"] = 0.into();
    let error = dir
        .load_embedded("camera.gltf", &document, &bin)
        .unwrap_err();
    assert!(error.to_string().contains("yfov"), "{error}");
}

#[test]
fn malformed_lights_and_extras() {
    let spot = |inner: f32, outer: f32| json!({ "type": "spot", "spot": { "innerConeAngle": inner, "outerConeAngle": outer } });
    for (inner, outer, expected) in [
        (0.1, 1.6, "outer cone angle 1.6"),
        (0.5, 0.4, "inner cone angle 0.5"),
        (0.4, 0.4, "inner cone angle 0.4"),
    ] {
        let error = light_error(spot(inner, outer), Value::Null);
        assert!(matches!(error, SceneError::InvalidLight { .. }), "{error}");
        let text = error.to_string();
        assert!(text.contains(expected), "{text}");
        assert!(
            text.contains("KHR_lights_punctual light 0 at node 1 \"lamp\""),
            "{text}"
        );
    }
    let error = light_error(
        json!({ "type": "point" }),
        json!({ "hrts": { "radius": -0.1 } }),
    );
    assert!(matches!(error, SceneError::InvalidLight { .. }), "{error}");
    assert!(error.to_string().contains("negative size -0.1"), "{error}");
    let error = light_error(
        json!({ "type": "directional", "extras": { "hrts": { "angular_radius": -0.01 } } }),
        Value::Null,
    );
    assert!(error.to_string().contains("negative size"), "{error}");
    let error = light_error(json!({ "type": "point", "range": 0.0 }), Value::Null);
    assert!(error.to_string().contains("range 0"), "{error}");

    let error = light_error(
        json!({ "type": "point" }),
        json!({ "hrts": { "radius": 0.1, "shadow_bias": 2 } }),
    );
    let SceneError::UnknownExtrasKey { key, owner, .. } = &error else {
        panic!("{error}")
    };
    assert_eq!(
        (key.as_str(), owner.as_str()),
        ("shadow_bias", "node 1 \"lamp\"")
    );
    assert!(
        error.to_string().contains("unknown key \"shadow_bias\""),
        "{error}"
    );
    let error = light_error(
        json!({ "name": "def", "type": "point", "extras": { "hrts": { "Static": true } } }),
        Value::Null,
    );
    assert!(
        matches!(&error, SceneError::UnknownExtrasKey { key, owner, .. }
            if key == "Static" && owner == "KHR_lights_punctual light 0 \"def\""),
        "{error}"
    );

    for (light, node_extras, expected) in [
        (
            json!({ "type": "point" }),
            json!({ "hrts": { "static": "yes" } }),
            "true or false",
        ),
        (
            json!({ "type": "point" }),
            json!({ "hrts": { "radius": "big" } }),
            "finite number",
        ),
        (
            json!({ "type": "point" }),
            json!({ "hrts": 3 }),
            "must be an object",
        ),
        (
            json!({ "type": "directional" }),
            json!({ "hrts": { "radius": 0.1 } }),
            "take \"angular_radius\"",
        ),
        (
            json!({ "type": "spot" , "spot": {} }),
            json!({ "hrts": { "angular_radius": 0.1 } }),
            "take \"radius\"",
        ),
    ] {
        let error = light_error(light, node_extras);
        assert!(matches!(error, SceneError::InvalidExtras { .. }), "{error}");
        assert!(error.to_string().contains(expected), "{error}");
    }
    // A light's size on a node without a light.
    let dir = TempDir::new();
    let (mut document, bin) = with_triangle().finish();
    document["nodes"][0]["extras"] = json!({ "hrts": { "static": true, "radius": 0.1 } });
    let error = dir.load_embedded("mesh.gltf", &document, &bin).unwrap_err();
    assert!(matches!(error, SceneError::InvalidExtras { .. }), "{error}");
    assert!(
        error.to_string().contains("\"radius\" applies to lights"),
        "{error}"
    );
    // Shadow casting on a node with neither a mesh nor a light.
    let mut w = with_triangle();
    let group =
        w.node(json!({ "name": "group", "extras": { "hrts": { "casts_shadows": false } } }));
    w.root(group);
    let (document, bin) = w.finish();
    let error = dir
        .load_embedded("group.gltf", &document, &bin)
        .unwrap_err();
    assert!(matches!(error, SceneError::InvalidExtras { .. }), "{error}");
    assert!(
        error
            .to_string()
            .contains("\"casts_shadows\" applies to mesh and light nodes"),
        "{error}"
    );
    let (mut document, bin) = with_triangle().finish();
    // Extras that are not hrts objects are someone else's business.
    document["nodes"][0]["extras"] = json!(["anything", 1]);
    dir.load_embedded("mesh.gltf", &document, &bin).unwrap();
}

/// Deterministic pseudo-random numbers (xorshift64*).
pub(super) fn random(state: &mut u64) -> u64 {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    state.wrapping_mul(0x2545_f491_4f6c_dd1d)
}

/// The number of numbers in `value`.
fn count_numbers(value: &Value) -> usize {
    match value {
        Value::Number(_) => 1,
        Value::Array(items) => items.iter().map(count_numbers).sum(),
        Value::Object(map) => map.values().map(count_numbers).sum(),
        _ => 0,
    }
}

/// Replaces the `n`th number (depth first) in `value` by `replacement`; counts `n` down.
fn replace_number(value: &mut Value, n: &mut usize, replacement: f64) {
    match value {
        Value::Number(_) => {
            if *n == 0 {
                *value = json!(replacement);
            }
            *n = n.wrapping_sub(1);
        }
        Value::Array(items) => items
            .iter_mut()
            .for_each(|v| replace_number(v, n, replacement)),
        Value::Object(map) => map
            .values_mut()
            .for_each(|v| replace_number(v, n, replacement)),
        _ => {}
    }
}

#[test]
fn malformed_input_never_panics() {
    let dir = TempDir::new();
    let example = dir.0.join("example.glb");
    write_example_scene(&example).unwrap();
    let whole = std::fs::read(&example).unwrap();
    for length in (0..whole.len()).step_by(7) {
        let path = dir.write("cut.glb", &whole[..length]);
        assert!(load(&path).is_err(), "{length}");
    }
    let mut state = 0x1234_5678_9abc_def1u64;
    for _ in 0..50 {
        let bytes: Vec<u8> = (0..random(&mut state) % 512)
            .map(|_| (random(&mut state) >> 56) as u8)
            .collect();
        assert!(load(&dir.write("noise.gltf", &bytes)).is_err());
    }
    let (document, bin) = super::example::example_document();
    let numbers = count_numbers(&document) as u64;
    let mut outcomes = std::collections::BTreeSet::new();
    for _ in 0..400 {
        const NUMBERS: [f64; 10] = [
            0.0,
            -1.0,
            1.0,
            2.0,
            3.0,
            7.0,
            5126.0,
            1e9,
            4294967296.0,
            0.5,
        ];
        let mut d = document.clone();
        for _ in 0..1 + random(&mut state) % 2 {
            let mut n = (random(&mut state) % numbers) as usize;
            let replacement = NUMBERS[(random(&mut state) % NUMBERS.len() as u64) as usize];
            replace_number(&mut d, &mut n, replacement);
        }
        // Also set a random byte of the buffer to 0xff (a NaN, a huge index, or harmless).
        let mut b = bin.clone();
        let at = (random(&mut state) % b.len() as u64) as usize;
        b[at] = 0xff;
        let glb_path = dir.write("mutated.glb", &glb(&d, &b));
        let result = load(&glb_path);
        if let Ok(file) = &result {
            file.scene.validate().unwrap();
            assert_eq!(file.static_objects.len(), file.scene.objects.len());
            file.lights.iter().for_each(|l| l.validate().unwrap());
        }
        outcomes.insert(match result {
            Ok(_) => "ok".to_owned(),
            Err(e) => format!("{e:?}")
                .split([' ', '{'])
                .next()
                .unwrap()
                .to_owned(),
        });
    }
    assert!(
        outcomes.contains("ok") && outcomes.len() > 3,
        "{outcomes:?}"
    );
}

/// A file without animations is static; an animation makes the node it targets and that node's children
/// move; `extras.hrts.static` still overrides.
#[test]
fn animations_decide_what_moves() {
    let mut w = GltfWriter::default();
    let square = w.mesh("square", &SQUARE, &[0, 1, 2, 0, 2, 3]);
    let still = w.node(json!({ "name": "still", "mesh": square }));
    let cart = w.node(json!({ "name": "cart", "mesh": square }));
    let wheel = w.node(json!({ "name": "wheel", "mesh": square }));
    let pinned = w.node(json!({
        "name": "pinned", "mesh": square, "extras": { "hrts": { "static": true } }
    }));
    w.root(still);
    w.root(cart);
    let (mut document, bin) = w.finish();
    document["nodes"][cart]["children"] = json!([wheel, pinned]);
    let dir = TempDir::new();
    let file = dir.load_embedded("still.gltf", &document, &bin).unwrap();
    assert_eq!(file.static_objects, [true, true, true, true]);
    document["animations"] = json!([{
        "channels": [{ "sampler": 0, "target": { "node": cart, "path": "translation" } }],
        "samplers": [{ "input": 0, "output": 0 }],
    }]);
    let file = dir.load_embedded("moving.gltf", &document, &bin).unwrap();
    let names: Vec<&str> = file.scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["still", "cart", "wheel", "pinned"]);
    assert_eq!(file.static_objects, [true, false, false, true]);
}

/// A mesh node with `casts_shadows: false` (a floor an engine leaves out of the shadow casters) is loaded
/// as an object that casts no shadows; its siblings cast them, and writing the scene keeps the flag.
#[test]
fn a_mesh_node_may_cast_no_shadows() {
    let mut w = GltfWriter::default();
    let square = w.mesh("square", &SQUARE, &[0, 1, 2, 0, 2, 3]);
    let floor = w.node(json!({
        "name": "floor", "mesh": square, "extras": { "hrts": { "casts_shadows": false } },
    }));
    let pillar =
        w.node(json!({ "name": "pillar", "mesh": square, "translation": [0.0, 1.0, 0.0] }));
    let plate = w.node(json!({
        "name": "plate", "mesh": square, "translation": [0.0, 2.0, 0.0],
        "extras": { "hrts": { "casts_shadows": true } },
    }));
    for node in [floor, pillar, plate] {
        w.root(node);
    }
    let (document, bin) = w.finish();
    let dir = TempDir::new();
    let file = dir.load_embedded("floor.gltf", &document, &bin).unwrap();
    let names: Vec<&str> = file.scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["floor", "pillar", "plate"]);
    assert_eq!(file.shadow_casters, [false, true, true]);
    assert_eq!(file.static_objects, [true, true, true]);
    let path = dir.0.join("written.gltf");
    write_scene(&path, &file, GltfEncoding::default()).unwrap();
    let written = load(&path).unwrap();
    assert_eq!(written.shadow_casters, file.shadow_casters);
    assert_eq!(written.scene, file.scene);
}
