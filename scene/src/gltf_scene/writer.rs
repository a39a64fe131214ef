//! A minimal glTF 2.0 writer: triangle meshes, nodes, `KHR_lights_punctual` lights and cameras,
//! with one buffer written as a GLB binary chunk or a base64 `data:` URI.

use std::path::Path;

use glam::Vec3;
use serde_json::{json, Value};

/// `componentType` of 32-bit floats.
const FLOAT: u32 = 5126;
/// `componentType` of 32-bit unsigned integers.
const UNSIGNED_INT: u32 = 5125;
/// Buffer view targets.
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// A glTF document under construction; nodes and lights are given as glTF JSON.
#[derive(Debug, Default)]
pub(super) struct GltfWriter {
    bin: Vec<u8>,
    buffer_views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    nodes: Vec<Value>,
    lights: Vec<Value>,
    cameras: Vec<Value>,
    animations: Vec<Value>,
    roots: Vec<usize>,
}

impl GltfWriter {
    /// Appends `bytes` to the buffer as a new buffer view (for vertices or indices when `target` says
    /// so); returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let mut view = json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
        });
        if let Some(target) = target {
            view["target"] = target.into();
        }
        self.buffer_views.push(view);
        self.bin.extend_from_slice(bytes);
        self.buffer_views.len() - 1
    }

    /// Adds an indexed triangle mesh of one primitive; returns its index.
    pub(super) fn mesh(&mut self, name: &str, positions: &[Vec3], indices: &[u32]) -> usize {
        let position_bytes: Vec<u8> = positions
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        // POSITION needs its bounds; non-finite vertices (written by tests) are left out.
        let finite = || positions.iter().copied().filter(|p| p.is_finite());
        let min = finite().reduce(Vec3::min).unwrap_or(Vec3::ZERO);
        let max = finite().reduce(Vec3::max).unwrap_or(Vec3::ZERO);
        let view = self.view(&position_bytes, Some(ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": positions.len(),
            "type": "VEC3",
            "min": min.to_array(),
            "max": max.to_array(),
        }));
        let position_accessor = self.accessors.len() - 1;
        let index_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&index_bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": indices.len(),
            "type": "SCALAR",
        }));
        self.meshes.push(json!({
            "name": name,
            "primitives": [{
                "attributes": { "POSITION": position_accessor },
                "indices": self.accessors.len() - 1,
            }],
        }));
        self.meshes.len() - 1
    }

    /// Adds an animation that moves `node` through `translations` at `times` (seconds, increasing),
    /// interpolated linearly.
    pub(super) fn translation_animation(
        &mut self,
        node: usize,
        times: &[f32],
        translations: &[Vec3],
    ) {
        let time_bytes: Vec<u8> = times.iter().flat_map(|t| t.to_le_bytes()).collect();
        let view = self.view(&time_bytes, None);
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": times.len(),
            "type": "SCALAR",
            "min": [times.iter().copied().fold(f32::INFINITY, f32::min)],
            "max": [times.iter().copied().fold(f32::NEG_INFINITY, f32::max)],
        }));
        let input = self.accessors.len() - 1;
        let value_bytes: Vec<u8> = translations
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let view = self.view(&value_bytes, None);
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": translations.len(),
            "type": "VEC3",
        }));
        self.animations.push(json!({
            "channels": [{ "sampler": 0, "target": { "node": node, "path": "translation" } }],
            "samplers": [{ "input": input, "output": self.accessors.len() - 1, "interpolation": "LINEAR" }],
        }));
    }

    /// Adds a `KHR_lights_punctual` light definition; returns its index.
    pub(super) fn light(&mut self, light: Value) -> usize {
        self.lights.push(light);
        self.lights.len() - 1
    }

    /// Adds a camera; returns its index.
    pub(super) fn camera(&mut self, camera: Value) -> usize {
        self.cameras.push(camera);
        self.cameras.len() - 1
    }

    /// Adds a node (children are given by index in its JSON); returns its index.
    pub(super) fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    /// Makes `node` a root node of the scene.
    pub(super) fn root(&mut self, node: usize) {
        self.roots.push(node);
    }

    /// The glTF JSON, whose one buffer has no `uri` yet (as for a GLB), and the buffer's bytes.
    pub(super) fn finish(self) -> (Value, Vec<u8>) {
        let mut document = json!({
            "asset": { "version": "2.0", "generator": "hrts scene::gltf_scene" },
            "scene": 0,
            "scenes": [{ "nodes": self.roots }],
            "nodes": self.nodes,
            "buffers": [{ "byteLength": self.bin.len() }],
        });
        for (key, items) in [
            ("meshes", self.meshes),
            ("accessors", self.accessors),
            ("bufferViews", self.buffer_views),
            ("cameras", self.cameras),
            ("animations", self.animations),
        ] {
            if !items.is_empty() {
                document[key] = Value::Array(items);
            }
        }
        if !self.lights.is_empty() {
            document["extensionsUsed"] = json!(["KHR_lights_punctual"]);
            document["extensions"] = json!({ "KHR_lights_punctual": { "lights": self.lights } });
        }
        (document, self.bin)
    }
}

/// Writes `document` with its buffer `bin` to `path`: binary glTF if the extension is `glb`
/// (any case), else glTF JSON with the buffer embedded as a `data:` URI.
pub(super) fn write(path: &Path, mut document: Value, bin: &[u8]) -> std::io::Result<()> {
    let is_glb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let bytes = if is_glb {
        glb(&document, bin)
    } else {
        document["buffers"][0]["uri"] = data_uri(bin).into();
        to_json_bytes(&document)
    };
    std::fs::write(path, bytes)
}

/// Pretty-printed JSON.
pub(super) fn to_json_bytes(document: &Value) -> Vec<u8> {
    serde_json::to_vec_pretty(document).expect("a JSON value always serializes")
}

/// A GLB file: header, JSON chunk (space-padded), binary chunk (zero-padded) if `bin` is not
/// empty.
pub(super) fn glb(document: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(document).expect("a JSON value always serializes");
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let mut chunks = vec![(*b"JSON", json)];
    if !bin.is_empty() {
        chunks.push((*b"BIN\0", bin));
    }
    let length = 12 + chunks.iter().map(|(_, c)| 8 + c.len()).sum::<usize>();
    let mut out = Vec::with_capacity(length);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(length as u32).to_le_bytes());
    for (kind, chunk) in chunks {
        out.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
        out.extend_from_slice(&kind);
        out.extend_from_slice(&chunk);
    }
    out
}

/// `bytes` as a base64 `data:` URI.
pub(super) fn data_uri(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut uri = String::from("data:application/octet-stream;base64,");
    for chunk in bytes.chunks(3) {
        let word = chunk
            .iter()
            .enumerate()
            .fold(0u32, |w, (k, &b)| w | u32::from(b) << (16 - 8 * k));
        for k in 0..4 {
            uri.push(if k <= chunk.len() {
                char::from(ALPHABET[(word >> (18 - 6 * k)) as usize & 63])
            } else {
                '='
            });
        }
    }
    uri
}
