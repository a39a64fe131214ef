//! Writing a [`SceneFile`] as glTF, with float, quantized or meshopt-compressed geometry.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat3, Quat, Vec3};
use serde_json::{json, Value};

use super::writer::{self, GltfWriter, Meshopt, Quantization};
use super::SceneFile;
use crate::{LightKind, LightSize, SceneError};

/// How [`write_scene`] stores geometry. The default is plain float positions and 32-bit
/// indices.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GltfEncoding {
    /// Positions as integers over each object's bounds, with a node translation and scale that
    /// dequantize them (`KHR_mesh_quantization`, required); `None`: floats.
    pub quantize: Option<Quantization>,
    /// Vertex and index buffer views compressed with `EXT_meshopt_compression` (required; the
    /// uncompressed fallback buffer is a placeholder without data), as `gltf-transform meshopt`
    /// writes them.
    pub meshopt: bool,
}

/// Writes `file` to `path` (binary glTF if the extension is `.glb`, else glTF JSON with the
/// buffer embedded): each object as a node with one mesh, each light as a `KHR_lights_punctual`
/// light on its own node, the camera, and the `hrts` extras (static flags, light sizes, shadow
/// casting) that [`load_gltf`](super::load_gltf) reads back.
///
/// Float positions are written in world space (identity nodes), so loading gives back exactly
/// the positions of `file`; quantized positions load as the nearest step of the integer type
/// over each object's bounds, per axis. Lights and the camera are oriented by node rotations, which load
/// back to within float rounding. The camera's up vector is the one closest to its `up` that is
/// perpendicular to its view direction.
///
/// # Errors
///
/// [`SceneError::Io`] if the file cannot be written.
pub fn write_scene(
    path: &Path,
    file: &SceneFile,
    encoding: GltfEncoding,
) -> Result<(), SceneError> {
    let (document, bin) = scene_document(file, encoding);
    writer::write(path, document, &bin).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })
}

/// The glTF JSON and buffer of `file`.
fn scene_document(file: &SceneFile, encoding: GltfEncoding) -> (Value, Vec<u8>) {
    let mut w = if encoding.meshopt {
        GltfWriter::compressed(Meshopt {
            extension: "EXT_meshopt_compression",
            exponential: false,
            triangles: true,
        })
    } else {
        GltfWriter::default()
    };
    let scene = &file.scene;
    for ((object, &is_static), &casts_shadows) in scene
        .objects
        .iter()
        .zip(&file.static_objects)
        .zip(&file.shadow_casters)
    {
        let first = object.first_triangle as usize * 3;
        let corners = &scene.indices[first..first + object.triangle_count as usize * 3];
        let mut remap = HashMap::new();
        let mut positions = Vec::new();
        let indices: Vec<u32> = corners
            .iter()
            .map(|&i| {
                *remap.entry(i).or_insert_with(|| {
                    positions.push(scene.positions[i as usize]);
                    positions.len() as u32 - 1
                })
            })
            .collect();
        let mut node = json!({
            "name": object.name,
            "extras": { "hrts": { "static": is_static } },
        });
        if !casts_shadows {
            node["extras"]["hrts"]["casts_shadows"] = false.into();
        }
        if let Some(quantization) = encoding.quantize {
            let (mesh, translation, scale) =
                w.quantized_mesh(&object.name, &positions, &indices, quantization);
            node["mesh"] = mesh.into();
            node["translation"] = json!(translation.to_array());
            node["scale"] = json!(scale.to_array());
        } else {
            node["mesh"] = w.mesh(&object.name, &positions, &indices).into();
        }
        let node = w.node(node);
        w.root(node);
    }
    for light in &file.lights {
        let mut hrts = json!({ "static": light.is_static, "casts_shadows": light.casts_shadows });
        match light.size {
            LightSize::Zero => {}
            LightSize::Radius(r) => hrts["radius"] = r.into(),
            LightSize::AngularRadius(a) => hrts["angular_radius"] = a.into(),
        }
        let mut definition = json!({
            "name": light.name,
            "color": light.color.to_array(),
            "intensity": light.intensity,
        });
        let (position, direction, range) = match light.kind {
            LightKind::Directional { direction } => {
                definition["type"] = "directional".into();
                (Vec3::ZERO, direction, None)
            }
            LightKind::Point { position, range } => {
                definition["type"] = "point".into();
                (position, Vec3::NEG_Z, range)
            }
            LightKind::Spot {
                position,
                direction,
                inner_cone,
                outer_cone,
                range,
            } => {
                definition["type"] = "spot".into();
                definition["spot"] =
                    json!({ "innerConeAngle": inner_cone, "outerConeAngle": outer_cone });
                (position, direction, range)
            }
        };
        if let Some(range) = range {
            definition["range"] = range.into();
        }
        let index = w.light(definition);
        let node = w.node(json!({
            "name": light.name,
            "translation": position.to_array(),
            "rotation": look_rotation(direction, Vec3::Y).to_array(),
            "extensions": { "KHR_lights_punctual": { "light": index } },
            "extras": { "hrts": hrts },
        }));
        w.root(node);
    }
    if let Some(camera) = &file.camera {
        let index = w.camera(json!({
            "type": "perspective",
            "perspective": { "yfov": camera.fov_y_radians, "znear": camera.near },
        }));
        let node = w.node(json!({
            "name": "camera",
            "camera": index,
            "translation": camera.position.to_array(),
            "rotation": look_rotation(camera.target - camera.position, camera.up).to_array(),
        }));
        w.root(node);
    }
    w.finish()
}

/// The rotation that turns a node's -Z axis (where glTF lights and cameras look) to `direction`
/// and its +Y axis as close to `up` as possible (to another axis where `up` is along
/// `direction`).
fn look_rotation(direction: Vec3, up: Vec3) -> Quat {
    let back = -direction.normalize_or(Vec3::NEG_Z);
    let right = [up, Vec3::Z, Vec3::X]
        .into_iter()
        .find_map(|up| up.cross(back).try_normalize())
        .unwrap_or(Vec3::X);
    Quat::from_mat3(&Mat3::from_cols(right, back.cross(right), back))
}
