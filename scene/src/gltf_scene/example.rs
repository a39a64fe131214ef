//! The example glTF scene: a ground plane, a few boxes and five lights of every kind and size.

use std::f32::consts::PI;
use std::path::Path;

use glam::{Mat3, Quat, Vec3};
use serde_json::{json, Value};

use super::writer::{self, GltfWriter};
use crate::scene::ground_square;
use crate::{Scene, SceneError};

/// Writes the example scene to `path`: binary glTF if the extension is `.glb`, else glTF JSON
/// with the buffer embedded as a base64 `data:` URI. The content is identical on every call.
///
/// Nodes (`hrts` extras in brackets), metres, +Y up:
/// - `"ground"`: a 12 m square at y = 0 \[static\];
/// - `"crate"`: a 1 m box on the ground at (-1.5, 0, 0.5) \[static\];
/// - `"tower"`: a 0.6 x 2 x 0.6 m box at (1.5, 0, -1), turned 30° about +Y \[static\];
/// - `"cart"`: a moving group at (0.3, 0, 1.6), turned -20° about +Y, with children
///   `"cart_body"` (a 1.2 x 0.6 x 0.8 m box), `"cart_load"` (a 0.4 m box on top, turned 45°) and
///   the point light `"cart_lamp"`; moved by an animation (there and back in 4 s), so it and
///   its children are not static;
/// - lights: `"sun"` (directional along (0.68, -1, 0.05), angular radius 0.01 rad) \[static\],
///   `"rim"` (directional, zero size: hard shadows) \[static\], `"spot"` (spot at (-3, 3.5, 2.5)
///   aimed at the crate, cones 0.25/0.45 rad, radius 0.05 m, range 15 m) \[static\],
///   `"cart_lamp"` (point 1.6 m above the cart, radius 0.1 m, range 6 m), `"fill"` (point at
///   (0, 4, -3), zero size) \[static, casts no shadows\];
/// - `"camera"`: a 45° perspective camera at (6, 4.5, 8) looking at (0, 0.8, 0).
///
/// # Errors
///
/// [`SceneError::Io`] if the file cannot be written.
pub fn write_example_scene(path: &Path) -> Result<(), SceneError> {
    let (document, bin) = example_document();
    writer::write(path, document, &bin).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })
}

/// A node with a name and a translation/rotation/scale transform.
fn node(name: &str, translation: Vec3, rotation: Quat, scale: Vec3) -> Value {
    json!({
        "name": name,
        "translation": translation.to_array(),
        "rotation": rotation.to_array(),
        "scale": scale.to_array(),
    })
}

/// `extras` with the given `hrts` settings.
fn hrts(settings: Value) -> Value {
    json!({ "hrts": settings })
}

/// The rotation that turns the node's -Z axis (where glTF lights and cameras look) to
/// `direction` and keeps its +Y axis as close to world +Y as possible.
fn look_along(direction: Vec3) -> Quat {
    let back = -direction.normalize();
    let right = Vec3::Y.cross(back).normalize();
    Quat::from_mat3(&Mat3::from_cols(right, back.cross(right), back))
}

/// The example's glTF JSON and buffer.
pub(super) fn example_document() -> (Value, Vec<u8>) {
    let mut w = GltfWriter::default();
    let ground = ground_square("ground", Vec3::ZERO, 12.0);
    let ground_mesh = w.mesh("ground", &ground.positions, &ground.indices);
    let unit_box = Scene::axis_box("box", Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 1.0, 0.5));
    let box_mesh = w.mesh("box", &unit_box.positions, &unit_box.indices);
    let is_static = || hrts(json!({ "static": true }));
    let turn = |degrees: f32| Quat::from_rotation_y(degrees.to_radians());

    let mut ground_node = node("ground", Vec3::ZERO, Quat::IDENTITY, Vec3::ONE);
    ground_node["mesh"] = ground_mesh.into();
    ground_node["extras"] = is_static();
    let mut crate_node = node(
        "crate",
        Vec3::new(-1.5, 0.0, 0.5),
        Quat::IDENTITY,
        Vec3::ONE,
    );
    crate_node["mesh"] = box_mesh.into();
    crate_node["extras"] = is_static();
    let mut tower = node(
        "tower",
        Vec3::new(1.5, 0.0, -1.0),
        turn(30.0),
        Vec3::new(0.6, 2.0, 0.6),
    );
    tower["mesh"] = box_mesh.into();
    tower["extras"] = is_static();
    for n in [ground_node, crate_node, tower] {
        let n = w.node(n);
        w.root(n);
    }

    let light = |name: &str, kind: &str, settings: Value| json!({ "name": name, "type": kind, "extras": hrts(settings) });
    let mut sun = light(
        "sun",
        "directional",
        json!({ "angular_radius": 0.01, "static": true }),
    );
    sun["intensity"] = 3.0.into();
    sun["color"] = json!([1.0, 0.95, 0.85]);
    let sun = w.light(sun);
    let mut rim = light("rim", "directional", json!({ "static": true }));
    rim["intensity"] = 0.5.into();
    rim["color"] = json!([0.7, 0.8, 1.0]);
    let rim = w.light(rim);
    let mut spot = light("spot", "spot", json!({ "radius": 0.05, "static": true }));
    spot["intensity"] = 200.0.into();
    spot["range"] = 15.0.into();
    spot["spot"] = json!({ "innerConeAngle": 0.25, "outerConeAngle": 0.45 });
    let spot = w.light(spot);
    let mut cart_lamp = light("cart_lamp", "point", json!({ "radius": 0.1 }));
    cart_lamp["intensity"] = 20.0.into();
    cart_lamp["range"] = 6.0.into();
    let cart_lamp = w.light(cart_lamp);
    let mut fill = light(
        "fill",
        "point",
        json!({ "casts_shadows": false, "static": true }),
    );
    fill["intensity"] = 10.0.into();
    let fill = w.light(fill);
    let with_light = |mut node: Value, light: usize| {
        node["extensions"] = json!({ "KHR_lights_punctual": { "light": light } });
        node
    };
    let spot_position = Vec3::new(-3.0, 3.5, 2.5);
    for n in [
        with_light(
            node(
                "sun",
                Vec3::new(0.0, 10.0, 0.0),
                look_along(Vec3::new(0.68, -1.0, 0.05)),
                Vec3::ONE,
            ),
            sun,
        ),
        with_light(
            node(
                "rim",
                Vec3::ZERO,
                look_along(Vec3::new(-0.4, -1.0, -0.6)),
                Vec3::ONE,
            ),
            rim,
        ),
        with_light(
            node(
                "spot",
                spot_position,
                look_along(Vec3::new(-1.5, 0.5, 0.5) - spot_position),
                Vec3::ONE,
            ),
            spot,
        ),
        with_light(
            node("fill", Vec3::new(0.0, 4.0, -3.0), Quat::IDENTITY, Vec3::ONE),
            fill,
        ),
    ] {
        let n = w.node(n);
        w.root(n);
    }

    let mut body = node(
        "cart_body",
        Vec3::ZERO,
        Quat::IDENTITY,
        Vec3::new(1.2, 0.6, 0.8),
    );
    body["mesh"] = box_mesh.into();
    let mut load = node(
        "cart_load",
        Vec3::new(0.0, 0.6, 0.0),
        turn(45.0),
        Vec3::splat(0.4),
    );
    load["mesh"] = box_mesh.into();
    let lamp = with_light(
        node(
            "cart_lamp",
            Vec3::new(0.0, 1.6, 0.0),
            Quat::IDENTITY,
            Vec3::ONE,
        ),
        cart_lamp,
    );
    let children = [w.node(body), w.node(load), w.node(lamp)];
    let mut cart = node("cart", Vec3::new(0.3, 0.0, 1.6), turn(-20.0), Vec3::ONE);
    cart["children"] = json!(children);
    let cart = w.node(cart);
    w.root(cart);
    w.translation_animation(
        cart,
        &[0.0, 2.0, 4.0],
        &[
            Vec3::new(0.3, 0.0, 1.6),
            Vec3::new(1.1, 0.0, 1.2),
            Vec3::new(0.3, 0.0, 1.6),
        ],
    );

    let camera = w.camera(json!({
        "name": "camera",
        "type": "perspective",
        "perspective": { "yfov": PI / 4.0, "znear": 0.05 },
    }));
    let eye = Vec3::new(6.0, 4.5, 8.0);
    let mut camera_node = node(
        "camera",
        eye,
        look_along(Vec3::new(0.0, 0.8, 0.0) - eye),
        Vec3::ONE,
    );
    camera_node["camera"] = camera.into();
    let camera_node = w.node(camera_node);
    w.root(camera_node);
    w.finish()
}
