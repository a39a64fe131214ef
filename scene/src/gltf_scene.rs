//! glTF 2.0 scene loading: geometry, `KHR_lights_punctual` lights with their sizes, static
//! flags and the camera, as a [`SceneFile`].
//!
//! # What is read
//!
//! - The default scene (`scene`), else the first of `scenes`, else every node that is no other
//!   node's child. The node hierarchy must be a tree (no cycles, no node reached twice).
//! - Node transforms (`matrix`, or `translation`/`rotation`/`scale` with the rotation
//!   normalised), composed down the hierarchy; a non-finite world transform is an error.
//! - Every mesh primitive of mode `TRIANGLES`, `TRIANGLE_STRIP` or `TRIANGLE_FAN` (strips and
//!   fans are triangulated as the glTF specification orders their vertices), positions only.
//!   Primitives of mode `POINTS`, `LINES`, `LINE_LOOP` or `LINE_STRIP` are skipped and counted
//!   in [`SceneFile::skipped_primitives`]. Triangles keep the counter-clockwise front-face
//!   convention: under a node transform with a negative determinant their winding is reversed,
//!   as glTF prescribes. Degenerate triangles are kept, as [`load_obj`](crate::load_obj) does.
//! - Each node with a mesh becomes one [`Object`] holding all its triangle primitives, named
//!   after the node, else the mesh, else `node<index>`; nodes whose mesh has no triangle add none.
//! - `KHR_lights_punctual` lights, in world space: a light sits at its node's origin and shines
//!   down the node's local -Z axis (node scale is ignored for the direction, as glTF says).
//! - The first perspective camera in hierarchy order (depth first, children in order), as a
//!   [`Camera`]: position at the node's origin, looking down local -Z, up along local +Y, target
//!   1 m ahead. Orthographic cameras are ignored.
//!
//! Buffers may be external files (relative to the glTF file), `data:` URIs or the GLB binary
//! chunk. Images, textures, materials, normals, skins, animations and morph targets are not read
//! (a texture without `source` is fine); an accessor without `bufferView` is all zeros, or what
//! its `sparse` values put there.
//!
//! # Extensions
//!
//! - `KHR_mesh_quantization`: `POSITION` may be `BYTE`, `UNSIGNED_BYTE`, `SHORT` or
//!   `UNSIGNED_SHORT`, normalized or not, dequantized exactly as the specification says and then
//!   transformed like float positions.
//! - `EXT_meshopt_compression` and `KHR_meshopt_compression`: buffer views are decoded with
//!   meshoptimizer's decoders, every size checked first (see `compression`); placeholder
//!   fallback buffers without data are not loaded.
//! - `KHR_draco_mesh_compression` is not decoded: a Draco primitive without uncompressed
//!   fallback accessors is an error that says how to write the file without Draco.
//! - A required extension that is none of these, `KHR_lights_punctual`, nor one that changes only
//!   materials, textures or images is an error; one error lists them all.
//!
//! # The `hrts` extras
//!
//! Renderer-specific settings live in the `extras` of nodes and of `KHR_lights_punctual` light
//! definitions, under the key `"hrts"`. Other `extras` content is left alone.
//!
//! ```json
//! "extras": { "hrts": { "static": true, "casts_shadows": false,
//!                       "radius": 0.05, "angular_radius": 0.00465 } }
//! ```
//!
//! | key | type | applies to | meaning | default |
//! |---|---|---|---|---|
//! | `static` | bool | any node; lights | never moves or changes | inherited from the nearest ancestor node that sets it; otherwise `true` unless an animation targets the node or an ancestor (or, for a skinned mesh, the file has any animation) |
//! | `casts_shadows` | bool | mesh and light nodes; lights | a light node's light, or a light: it casts shadows. A mesh node's mesh: it blocks light (it is drawn and receives shadows either way) | `true` |
//! | `radius` | number, metres, ≥ 0 | spot/point light nodes; lights | radius of the spherical light | `0` |
//! | `angular_radius` | number, radians, in `[0, pi/2)` | directional light nodes; lights | angular radius of the light's disc | `0` |
//!
//! A size of 0 gives [`LightSize::Zero`] (a zero-size light: hard shadows). A light takes each
//! value from its node's extras, else from the light definition's extras, else (`static`) from
//! the nearest ancestor node that sets it, else the default. A mesh node is static when it or
//! its nearest ancestor that says so sets `static: true`, or, when none says, when no animation
//! moves it ([`SceneFile::static_objects`]): a file without animations is static. A mesh node
//! casts shadows unless its own extras set `casts_shadows: false` ([`SceneFile::shadow_casters`]:
//! engines leave floors, terrain or decals out of the casters); on a node with both a mesh and a
//! light the key applies to both.
//!
//! # Errors
//!
//! Malformed input gives a [`SceneError`] naming the file and what is wrong: unknown keys in
//! `hrts` ([`SceneError::UnknownExtrasKey`]), wrong types or a size on the wrong kind of light
//! or on a node without a light ([`SceneError::InvalidExtras`]), invalid light parameters such as
//! spot cones with `outer > pi/2` or `inner >= outer`, or a negative size
//! ([`SceneError::InvalidLight`]), missing or short buffers ([`SceneError::GltfBuffer`]),
//! out-of-range vertex indices ([`SceneError::GltfIndexOutOfRange`]), NaN or infinite vertices
//! ([`SceneError::GltfNonFinite`]), anything else that is not valid glTF 2.0
//! ([`SceneError::Gltf`]), and no triangle at all ([`SceneError::Empty`]).

use std::f32::consts::PI;
use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use gltf::json::validation::Validate as _;
use gltf::khr_lights_punctual::Kind;
use gltf::mesh::Mode;
use gltf::scene::Transform;

use crate::{Camera, LightKind, LightSize, Object, Scene, SceneError, SceneLight};

mod accessor;
mod compression;
mod example;
mod export;
mod extras;
mod writer;

#[cfg(test)]
mod production_tests;
#[cfg(test)]
mod tests;

pub use example::write_example_scene;
pub use export::{write_scene, GltfEncoding};
pub use writer::{Quantization, QuantizedComponent};

/// A scene loaded from a glTF file: geometry, lights, which objects are static and which cast
/// shadows, the camera.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneFile {
    /// World-space geometry, one [`Object`] per node with triangles, in hierarchy order.
    pub scene: Scene,
    /// For each object of [`scene`](SceneFile::scene) (same order and length): whether it is
    /// static, i.e. never moves or deforms.
    pub static_objects: Vec<bool>,
    /// For each object of [`scene`](SceneFile::scene) (same order and length): whether it casts
    /// shadows. An object that casts none (`casts_shadows: false` on its node) is still drawn and
    /// still receives shadows, but is not given to the shadow renderer as a caster.
    pub shadow_casters: Vec<bool>,
    /// The lights, in hierarchy order.
    pub lights: Vec<SceneLight>,
    /// The first perspective camera, if the file has one on a node.
    pub camera: Option<Camera>,
    /// Number of mesh primitives skipped because they are points or lines.
    pub skipped_primitives: usize,
}

/// Loads a glTF 2.0 file (`.gltf` with external or `data:` buffers, or binary `.glb`).
///
/// See the [module documentation](self) for what is read, the `hrts` extras and their
/// defaults.
///
/// # Errors
///
/// [`SceneError::Io`] if the file cannot be read; otherwise the errors listed in the
/// [module documentation](self#errors), all naming the file. Never panics on malformed input.
pub fn load_gltf(path: &Path) -> Result<SceneFile, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    let base = path.parent().unwrap_or_else(|| Path::new("."));
    let (document, blob) = parse_document(&bytes, path)?;
    let buffers = load_buffers(&document, blob, base, path)?;
    let data = accessor::BufferData::new(buffers, document.views().len());
    Loader {
        path,
        data: &data,
        file: SceneFile::default(),
    }
    .load(&document)
}

/// Parses and validates the JSON (of a `.gltf` file or of the GLB JSON chunk); also returns the
/// GLB binary chunk.
fn parse_document(
    bytes: &[u8],
    path: &Path,
) -> Result<(gltf::Document, Option<Vec<u8>>), SceneError> {
    let error = |message: String| SceneError::Gltf {
        path: path.to_owned(),
        message,
    };
    let is_glb = bytes.starts_with(b"glTF");
    if is_glb {
        check_glb_header(bytes).map_err(error)?;
    }
    let (json, blob) = if is_glb {
        let glb = gltf::binary::Glb::from_slice(bytes)
            .map_err(|e| error(format!("malformed GLB: {e}")))?;
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes.to_vec(), None)
    };
    let deserialize = |e: serde_json::Error| {
        error(if is_glb {
            format!("GLB JSON chunk: {e}")
        } else {
            format!("neither GLB nor glTF JSON: {e}")
        })
    };
    let mut value: serde_json::Value = serde_json::from_slice(&json).map_err(deserialize)?;
    without_unread_parts(&mut value);
    let root: gltf::json::Root = serde_json::from_value(value).map_err(|e| {
        // The same problem in the file's own text gives its line and column.
        let whole = serde_json::from_slice::<gltf::json::Root>(&json).err();
        deserialize(
            whole
                .filter(|w| w.to_string().starts_with(&e.to_string()))
                .unwrap_or(e),
        )
    })?;
    let version = &root.asset.version;
    if version.split('.').next() != Some("2") {
        return Err(error(format!(
            "asset.version is \"{version}\"; only glTF 2.x is supported"
        )));
    }
    // The validation of the gltf crate indexes `accessors` with each POSITION attribute without
    // checking the index first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= root.accessors.len() {
                    return Err(error(format!(
                        "meshes[{m}].primitives[{p}].attributes.{} is accessor {}, but there are {} accessors",
                        semantic.to_string(),
                        accessor.value(),
                        root.accessors.len()
                    )));
                }
            }
        }
    }
    check_required_extensions(&root.extensions_required).map_err(error)?;
    let mut problems = Vec::new();
    root.validate(&root, gltf::json::Path::new, &mut |path, problem| {
        let path = path();
        if !tolerated(&path, problem) {
            problems.push(format!("{path}: {problem}"));
        }
    });
    if !problems.is_empty() {
        return Err(error(format!("invalid glTF: {}", problems.join("; "))));
    }
    Ok((gltf::Document::from_json_without_validation(root), blob))
}

/// Removes what is not read and that the gltf crate's schema would refuse although a file may hold it
/// (a texture without `source`, whose image an extension gives): images, textures, samplers, materials
/// and each primitive's material.
fn without_unread_parts(value: &mut serde_json::Value) {
    let Some(root) = value.as_object_mut() else {
        return;
    };
    for key in ["images", "textures", "samplers", "materials"] {
        root.remove(key);
    }
    let meshes = root.get_mut("meshes").and_then(|m| m.as_array_mut());
    for mesh in meshes.into_iter().flatten() {
        let primitives = mesh.get_mut("primitives").and_then(|p| p.as_array_mut());
        for primitive in primitives.into_iter().flatten() {
            if let Some(primitive) = primitive.as_object_mut() {
                primitive.remove("material");
            }
        }
    }
}

/// Extensions whose content is read.
const READ_EXTENSIONS: [&str; 4] = [
    "KHR_lights_punctual",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// Whether a required extension changes only what is not read (materials, textures, images).
fn changes_nothing_read(extension: &str) -> bool {
    extension.starts_with("KHR_materials_")
        || [
            "KHR_texture_transform",
            "KHR_texture_basisu",
            "EXT_texture_webp",
            "EXT_texture_avif",
            "MSFT_texture_dds",
        ]
        .contains(&extension)
}

/// The extension of Draco-compressed primitives, which is not decoded.
const DRACO: &str = "KHR_draco_mesh_compression";

/// What to do about a Draco-compressed file.
const DRACO_ADVICE: &str = "Draco-compressed geometry is not decoded (no maintained Rust decoder); write the file without Draco, e.g. `gltf-transform meshopt IN OUT` (EXT_meshopt_compression, which is read) or your exporter with Draco compression off";

/// One error listing every required extension that is neither read nor irrelevant to what is read.
fn check_required_extensions(required: &[String]) -> Result<(), String> {
    let unsupported: Vec<&str> = required
        .iter()
        .map(String::as_str)
        .filter(|e| !READ_EXTENSIONS.contains(e) && !changes_nothing_read(e))
        .collect();
    if unsupported.is_empty() {
        return Ok(());
    }
    let mut message = format!(
        "extensionsRequired lists {} that this loader does not support: {} (supported: {}, and extensions that only change materials, textures or images)",
        if unsupported.len() == 1 { "an extension" } else { "extensions" },
        unsupported.join(", "),
        READ_EXTENSIONS.join(", ")
    );
    if unsupported.contains(&DRACO) {
        message += &format!(". {DRACO}: {DRACO_ADVICE}");
    }
    Err(message)
}

/// Whether a problem found by the gltf crate's validation is legal glTF that the loader handles
/// itself: required extensions (checked by [`check_required_extensions`]) and accessors without a
/// buffer view (all zeros, or filled by `sparse` or an extension).
fn tolerated(path: &gltf::json::Path, problem: gltf::json::validation::Error) -> bool {
    let path = path.as_str();
    let accessor_view = path.strip_prefix("accessors[").and_then(|rest| {
        rest.strip_suffix("].bufferView")
            .filter(|index| index.bytes().all(|b| b.is_ascii_digit()))
    });
    match problem {
        gltf::json::validation::Error::Missing => accessor_view.is_some(),
        gltf::json::validation::Error::Unsupported => path.starts_with("extensionsRequired["),
        _ => false,
    }
}

/// Checks the 12-byte GLB header against the file length, before the gltf crate (which would
/// overflow on a declared length below 12) reads it.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .and_then(|b| b.try_into().ok())
            .map(u32::from_le_bytes)
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(format!(
            "truncated GLB: {} bytes, less than the 12-byte header",
            bytes.len()
        ));
    };
    if version != 2 {
        return Err(format!(
            "GLB container version {version}; only 2 is supported"
        ));
    }
    if (length as usize) < 12 + 8 {
        return Err(format!(
            "the GLB header declares a total length of {length} bytes, too short for a JSON chunk"
        ));
    }
    if length as usize > bytes.len() {
        return Err(format!(
            "truncated GLB: the header declares {length} bytes but the file has {}",
            bytes.len()
        ));
    }
    Ok(())
}

/// The bytes of every buffer, cut to its `byteLength`; `None` for a buffer without data that only
/// meshopt-compressed buffer views use (their uncompressed fallback, left out of the file).
fn load_buffers(
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    base: &Path,
    path: &Path,
) -> Result<Vec<Option<Vec<u8>>>, SceneError> {
    let mut placeholder = vec![false; document.buffers().len()];
    for view in document.views() {
        if compression::compression(&view).is_some() {
            placeholder[view.buffer().index()] = true;
        }
    }
    document
        .buffers()
        .map(|buffer| {
            let error = |message: String| SceneError::GltfBuffer {
                path: path.to_owned(),
                buffer: buffer.index(),
                message,
            };
            let (source, data) = match buffer.source() {
                gltf::buffer::Source::Bin if blob.is_none() && placeholder[buffer.index()] => {
                    return Ok(None);
                }
                gltf::buffer::Source::Bin => (
                    "the GLB binary chunk".to_owned(),
                    blob.take()
                        .ok_or_else(|| "the GLB has no binary chunk".to_owned()),
                ),
                gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                    ("its data: URI".to_owned(), data_uri_bytes(uri))
                }
                gltf::buffer::Source::Uri(uri) if uri.contains(':') => {
                    return Err(error(format!(
                        "URI \"{uri}\": only data: URIs and relative file paths are read"
                    )));
                }
                gltf::buffer::Source::Uri(uri) => {
                    let Some(relative) = percent_decode(uri) else {
                        return Err(error(format!(
                            "URI \"{uri}\" does not percent-decode to UTF-8"
                        )));
                    };
                    let file = base.join(relative);
                    let source = format!("\"{uri}\" (relative to {})", base.display());
                    let data = std::fs::read(&file)
                        .map_err(|e| format!("cannot read {}: {e}", file.display()));
                    (source, data)
                }
            };
            let data = data.map_err(|m| error(format!("cannot load {source}: {m}")))?;
            let mut data = data;
            if data.len() < buffer.length() {
                return Err(error(format!(
                    "{source} holds {} bytes, but byteLength is {}",
                    data.len(),
                    buffer.length()
                )));
            }
            data.truncate(buffer.length());
            Ok(Some(data))
        })
        .collect()
}

/// `uri` with its `%XX` escapes decoded, if that is valid UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let escape = bytes
            .get(i + 1..i + 3)
            .filter(|hex| bytes[i] == b'%' && hex.iter().all(u8::is_ascii_hexdigit))
            .and_then(|hex| std::str::from_utf8(hex).ok())
            .and_then(|hex| u8::from_str_radix(hex, 16).ok());
        match escape {
            Some(byte) => {
                decoded.push(byte);
                i += 3;
            }
            None => {
                decoded.push(bytes[i]);
                i += 1;
            }
        }
    }
    String::from_utf8(decoded).ok()
}

/// The bytes of a `data:[<mediatype>];base64,<data>` URI.
fn data_uri_bytes(uri: &str) -> Result<Vec<u8>, String> {
    use base64::Engine as _;
    let (header, payload) = uri
        .split_once(',')
        .ok_or_else(|| "the data: URI has no ',' before its data".to_owned())?;
    if !header.ends_with(";base64") {
        return Err("the data: URI is not base64-encoded".into());
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| format!("the data: URI is not valid base64: {e}"))
}

/// `node 3 "name"`, or `node 3` without a name.
fn describe(what: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(name) => format!("{what} {index} \"{name}\""),
        None => format!("{what} {index}"),
    }
}

/// The first NaN or infinite coordinate of `p`.
fn non_finite(p: Vec3) -> Option<f32> {
    p.to_array().into_iter().find(|c| !c.is_finite())
}

/// The triangles of a primitive of `mode` over `indices`; `Ok(None)` for points and lines.
fn triangles(mode: Mode, indices: &[u32]) -> Result<Option<Vec<[u32; 3]>>, String> {
    Ok(Some(match mode {
        Mode::Triangles => {
            let triangles = indices.chunks_exact(3);
            if !triangles.remainder().is_empty() {
                return Err(format!(
                    "{} corners do not form whole triangles",
                    indices.len()
                ));
            }
            triangles.map(|t| [t[0], t[1], t[2]]).collect()
        }
        // Triangle i is (v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]).
        Mode::TriangleStrip => indices
            .windows(3)
            .enumerate()
            .map(|(i, v)| {
                if i % 2 == 0 {
                    [v[0], v[1], v[2]]
                } else {
                    [v[0], v[2], v[1]]
                }
            })
            .collect(),
        // Triangle i is (v[i + 1], v[i + 2], v[0]).
        Mode::TriangleFan => indices
            .get(1..)
            .unwrap_or_default()
            .windows(2)
            .map(|v| [v[0], v[1], indices[0]])
            .collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return Ok(None),
    }))
}

/// A node's local transform; the rotation of a TRS transform is normalised.
fn local_transform(node: &gltf::Node) -> Mat4 {
    match node.transform() {
        Transform::Matrix { matrix } => Mat4::from_cols_array_2d(&matrix),
        Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => Mat4::from_scale_rotation_translation(
            scale.into(),
            Quat::from_array(rotation).normalize(),
            translation.into(),
        ),
    }
}

/// The state of one load.
struct Loader<'a> {
    path: &'a Path,
    data: &'a accessor::BufferData,
    file: SceneFile,
}

impl Loader<'_> {
    fn gltf_error(&self, message: String) -> SceneError {
        SceneError::Gltf {
            path: self.path.to_owned(),
            message,
        }
    }

    fn load(mut self, document: &gltf::Document) -> Result<SceneFile, SceneError> {
        let roots: Vec<gltf::Node> = match document
            .default_scene()
            .or_else(|| document.scenes().next())
        {
            Some(scene) => scene.nodes().collect(),
            None => {
                let mut is_child = vec![false; document.nodes().len()];
                for child in document.nodes().flat_map(|n| n.children()) {
                    is_child[child.index()] = true;
                }
                document.nodes().filter(|n| !is_child[n.index()]).collect()
            }
        };
        let mut visited = vec![false; document.nodes().len()];
        // Nodes an animation moves or deforms (any channel: translation, rotation, scale, weights).
        let mut animated = vec![false; document.nodes().len()];
        for channel in document.animations().flat_map(|a| a.channels()) {
            animated[channel.target().node().index()] = true;
        }
        let any_animation = document.animations().next().is_some();
        // Per node on the stack: its parent's world transform, the nearest explicit `static` above it, and
        // whether an animation moves it or an ancestor.
        let mut stack: Vec<(gltf::Node, Mat4, Option<bool>, bool)> = roots
            .into_iter()
            .rev()
            .map(|node| (node, Mat4::IDENTITY, None, false))
            .collect();
        while let Some((node, parent, parent_explicit, parent_animated)) = stack.pop() {
            let name = describe("node", node.index(), node.name());
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(self.gltf_error(format!(
                    "{name} is reached twice from the scene's root nodes; the node hierarchy must be a tree"
                )));
            }
            let world = parent * local_transform(&node);
            if !world.is_finite() {
                return Err(self.gltf_error(format!("{name} has a non-finite world transform")));
            }
            let hrts = extras::parse(node.extras(), self.path, &name)?;
            let moves = parent_animated || animated[node.index()];
            // A skinned mesh deforms with its joints: moving whenever the file animates anything.
            let deforms = node.skin().is_some() && any_animation;
            let explicit = hrts.is_static.or(parent_explicit);
            let is_static = explicit.unwrap_or(!(moves || deforms));
            let parent_static = parent_explicit.unwrap_or(!moves);
            if let Some(mesh) = node.mesh() {
                let casts_shadows = hrts.casts_shadows.unwrap_or(true);
                self.add_mesh(&node, &mesh, world, is_static, casts_shadows)?;
            }
            match node.light() {
                Some(light) => {
                    let light = self.light(&node, &light, world, hrts, parent_static)?;
                    self.file.lights.push(light);
                }
                None => hrts
                    .reject_light_keys(node.mesh().is_some())
                    .map_err(|message| SceneError::InvalidExtras {
                        path: self.path.to_owned(),
                        owner: name.clone(),
                        message,
                    })?,
            }
            if let Some(camera) = node.camera() {
                let camera = perspective_camera(&camera, world).map_err(|message| {
                    self.gltf_error(format!(
                        "{} at {name}: {message}",
                        describe("camera", camera.index(), camera.name())
                    ))
                })?;
                if self.file.camera.is_none() {
                    self.file.camera = camera;
                }
            }
            let first_child = stack.len();
            stack.extend(node.children().map(|child| (child, world, explicit, moves)));
            stack[first_child..].reverse();
        }
        self.file.scene.validate_as(self.path)?;
        Ok(self.file)
    }

    /// Appends the triangle primitives of `mesh` at `node` as one object, static or not and casting
    /// shadows or not.
    fn add_mesh(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        world: Mat4,
        is_static: bool,
        casts_shadows: bool,
    ) -> Result<(), SceneError> {
        let flip = world.determinant() < 0.0;
        let first_triangle = self.file.scene.triangle_count();
        for primitive in mesh.primitives() {
            let what = format!(
                "{} primitive {} at {}",
                describe("mesh", mesh.index(), mesh.name()),
                primitive.index(),
                describe("node", node.index(), node.name())
            );
            let Some(position_accessor) = primitive.get(&gltf::Semantic::Positions) else {
                // Rejected by validation; nothing to draw either way.
                self.file.skipped_primitives += 1;
                continue;
            };
            // Draco primitives without required Draco keep uncompressed accessors as fallback;
            // without them there is nothing to read.
            let unbacked = |a: &gltf::Accessor| a.view().is_none() && a.sparse().is_none();
            if primitive.extension_value(DRACO).is_some()
                && (unbacked(&position_accessor)
                    || primitive.indices().is_some_and(|i| unbacked(&i)))
            {
                return Err(self.gltf_error(format!(
                    "{what}: its geometry is only in {DRACO}. {DRACO_ADVICE}"
                )));
            }
            let accessor_error = |accessor: &gltf::Accessor, message: String| {
                self.gltf_error(format!("{what}: accessor {}: {message}", accessor.index()))
            };
            let local = accessor::read_positions(&position_accessor, self.data)
                .map_err(|m| accessor_error(&position_accessor, m))?;
            let indices = match primitive.indices() {
                Some(indices) => accessor::read_indices(&indices, self.data)
                    .map_err(|m| accessor_error(&indices, m))?,
                None => (0..local.len() as u32).collect(),
            };
            let Some(triangles) = triangles(primitive.mode(), &indices)
                .map_err(|m| self.gltf_error(format!("{what}: {m}")))?
            else {
                self.file.skipped_primitives += 1;
                continue;
            };
            for (triangle, corners) in triangles.iter().enumerate() {
                if let Some(&index) = corners.iter().find(|&&i| i as usize >= local.len()) {
                    return Err(SceneError::GltfIndexOutOfRange {
                        path: self.path.to_owned(),
                        primitive: what,
                        triangle,
                        index,
                        count: local.len(),
                    });
                }
            }
            let mut positions = Vec::with_capacity(local.len());
            for (vertex, &p) in local.iter().enumerate() {
                let w = world.transform_point3(p);
                if let Some(value) = non_finite(p).or_else(|| non_finite(w)) {
                    return Err(SceneError::GltfNonFinite {
                        path: self.path.to_owned(),
                        primitive: what,
                        vertex,
                        value,
                    });
                }
                positions.push(w);
            }
            let scene = &mut self.file.scene;
            let base = scene.positions.len();
            let fits = |n: usize| u32::try_from(n).is_ok();
            if !fits(base + positions.len()) || !fits(scene.indices.len() + 3 * triangles.len()) {
                return Err(self.gltf_error(format!(
                    "{what}: the scene exceeds 2^32 vertices or indices"
                )));
            }
            scene.positions.extend(positions);
            scene.indices.extend(
                triangles
                    .iter()
                    .flat_map(|&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
                    .map(|i| i + base as u32),
            );
        }
        let triangle_count = self.file.scene.triangle_count() - first_triangle;
        if triangle_count > 0 {
            let name = node
                .name()
                .or(mesh.name())
                .map_or_else(|| format!("node{}", node.index()), str::to_owned);
            self.file.scene.objects.push(Object {
                name,
                first_triangle: first_triangle as u32,
                triangle_count: triangle_count as u32,
            });
            self.file.static_objects.push(is_static);
            self.file.shadow_casters.push(casts_shadows);
        }
        Ok(())
    }

    /// The light `light` placed at `node`, with its `hrts` settings resolved.
    fn light(
        &self,
        node: &gltf::Node,
        light: &gltf::khr_lights_punctual::Light,
        world: Mat4,
        node_hrts: extras::Hrts,
        parent_static: bool,
    ) -> Result<SceneLight, SceneError> {
        let light_name = describe("KHR_lights_punctual light", light.index(), light.name());
        let owner = format!(
            "{light_name} at {}",
            describe("node", node.index(), node.name())
        );
        let hrts = node_hrts.or(extras::parse(light.extras(), self.path, &light_name)?);
        let position = world.transform_point3(Vec3::ZERO);
        let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        let kind = match light.kind() {
            Kind::Directional => LightKind::Directional { direction },
            Kind::Point => LightKind::Point {
                position,
                range: light.range(),
            },
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => LightKind::Spot {
                position,
                direction,
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
                range: light.range(),
            },
        };
        let size: LightSize = hrts
            .size(&kind)
            .map_err(|message| SceneError::InvalidExtras {
                path: self.path.to_owned(),
                owner: owner.clone(),
                message,
            })?;
        let scene_light = SceneLight {
            name: node
                .name()
                .or(light.name())
                .map_or_else(|| format!("light{}", light.index()), str::to_owned),
            kind,
            color: light.color().into(),
            intensity: light.intensity(),
            size,
            casts_shadows: hrts.casts_shadows.unwrap_or(true),
            is_static: hrts.is_static.unwrap_or(parent_static),
        };
        scene_light
            .check()
            .map_err(|message| SceneError::InvalidLight {
                path: self.path.to_owned(),
                light: owner,
                message,
            })?;
        Ok(scene_light)
    }
}

/// The camera at a node with world transform `world`; `None` for an orthographic camera.
fn perspective_camera(camera: &gltf::Camera, world: Mat4) -> Result<Option<Camera>, String> {
    let gltf::camera::Projection::Perspective(perspective) = camera.projection() else {
        return Ok(None);
    };
    let (fov_y_radians, near) = (perspective.yfov(), perspective.znear());
    let fov_valid = fov_y_radians > 0.0 && fov_y_radians < PI;
    if !fov_valid {
        return Err(format!("yfov {fov_y_radians} rad is not in (0, pi)"));
    }
    let near_valid = near > 0.0 && near.is_finite();
    if !near_valid {
        return Err(format!("znear {near} is not positive and finite"));
    }
    let position = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).try_normalize();
    let up = world.transform_vector3(Vec3::Y).try_normalize();
    let (Some(forward), Some(up)) = (forward, up) else {
        return Err("the node transform collapses the view direction".into());
    };
    Ok(Some(Camera {
        position,
        target: position + forward,
        up,
        fov_y_radians,
        near,
    }))
}
