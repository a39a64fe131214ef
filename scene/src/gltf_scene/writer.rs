//! A minimal glTF 2.0 writer: triangle meshes (float or `KHR_mesh_quantization` positions,
//! optionally meshopt-compressed), nodes, `KHR_lights_punctual` lights and cameras, with one
//! buffer written as a GLB binary chunk or a base64 `data:` URI.

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

/// The integer type of quantized positions (`KHR_mesh_quantization`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QuantizedComponent {
    /// `BYTE`.
    I8,
    /// `UNSIGNED_BYTE`.
    U8,
    /// `SHORT`.
    I16,
    /// `UNSIGNED_SHORT`.
    U16,
}

/// Positions stored as integers: the type, and whether they are normalized (to `[0, 1]` or
/// `[-1, 1]`) or plain integers; the node transform maps them to the object's bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quantization {
    /// The integer type.
    pub component: QuantizedComponent,
    /// Whether the integers are normalized.
    pub normalized: bool,
}

impl QuantizedComponent {
    /// The glTF `componentType`, the size in bytes, the smallest and largest value used (the
    /// most negative one is left out: normalized, it would also mean -1).
    pub(super) fn layout(self) -> (u32, usize, i32, i32) {
        match self {
            QuantizedComponent::I8 => (5120, 1, -127, 127),
            QuantizedComponent::U8 => (5121, 1, 0, 255),
            QuantizedComponent::I16 => (5122, 2, -32767, 32767),
            QuantizedComponent::U16 => (5123, 2, 0, 65535),
        }
    }
}

/// Meshopt compression of the vertex and index buffer views a writer adds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Meshopt {
    /// `EXT_meshopt_compression` (attribute format 0) or `KHR_meshopt_compression` (format 1).
    pub(super) extension: &'static str,
    /// Float positions through the `EXPONENTIAL` filter (24-bit mantissas: not always exact).
    pub(super) exponential: bool,
    /// Indices as `TRIANGLES` (else `INDICES`).
    pub(super) triangles: bool,
}

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
    /// Compression of the vertex and index views.
    meshopt: Option<Meshopt>,
    /// Bytes of the placeholder buffer that compressed views stand in (their uncompressed size).
    fallback_length: usize,
    quantized: bool,
}

/// What a buffer view holds, for its target and its compression.
#[derive(Debug, Clone, Copy)]
enum ViewKind {
    /// Vertex attributes of `stride` bytes, to pass through the meshopt `filter`.
    Vertices { stride: usize, filter: &'static str },
    /// 32-bit triangle-list indices.
    Indices,
    /// Anything else (animation data), never compressed.
    Other,
}

impl GltfWriter {
    /// A writer that compresses vertex and index buffer views as `meshopt` says.
    pub(super) fn compressed(meshopt: Meshopt) -> Self {
        Self {
            meshopt: Some(meshopt),
            ..Self::default()
        }
    }

    /// Appends `bytes` as a new buffer view (meshopt-compressed if the writer compresses and
    /// `kind` is vertices or indices); returns its index.
    fn view(&mut self, bytes: &[u8], kind: ViewKind) -> usize {
        let target = match kind {
            ViewKind::Vertices { .. } => Some(ARRAY_BUFFER),
            ViewKind::Indices => Some(ELEMENT_ARRAY_BUFFER),
            ViewKind::Other => None,
        };
        let compressed = match (self.meshopt, kind) {
            (Some(meshopt), ViewKind::Vertices { stride, filter }) => {
                let version = i32::from(meshopt.extension == "KHR_meshopt_compression");
                let data = encode_attributes(bytes, stride, version);
                Some((meshopt, data, stride, "ATTRIBUTES", filter))
            }
            (Some(meshopt), ViewKind::Indices) => {
                let indices: Vec<u32> = bytes
                    .chunks_exact(4)
                    .map(|i| u32::from_le_bytes([i[0], i[1], i[2], i[3]]))
                    .collect();
                let vertex_count = indices.iter().max().map_or(0, |&m| m as usize + 1);
                let (data, mode) = if meshopt.triangles {
                    let data = meshopt::encode_index_buffer(&indices, vertex_count);
                    (data, "TRIANGLES")
                } else {
                    (
                        meshopt::encode_index_sequence(&indices, vertex_count),
                        "INDICES",
                    )
                };
                let data = data.expect("the meshopt encoders do not fail");
                Some((meshopt, data, 4, mode, "NONE"))
            }
            _ => None,
        };
        let mut view = match compressed {
            Some((meshopt, data, stride, mode, filter)) => {
                self.fallback_length = self.fallback_length.next_multiple_of(4);
                let mut view = json!({
                    "buffer": 1,
                    "byteOffset": self.fallback_length,
                    "byteLength": bytes.len(),
                    "extensions": { meshopt.extension: {
                        "buffer": 0,
                        "byteOffset": self.append(&data),
                        "byteLength": data.len(),
                        "byteStride": stride,
                        "count": bytes.len() / stride,
                        "mode": mode,
                    } },
                });
                if filter != "NONE" {
                    view["extensions"][meshopt.extension]["filter"] = filter.into();
                }
                self.fallback_length += bytes.len();
                view
            }
            None => json!({
                "buffer": 0,
                "byteOffset": self.append(bytes),
                "byteLength": bytes.len(),
            }),
        };
        if let Some(target) = target {
            view["target"] = target.into();
        }
        if let ViewKind::Vertices { stride, .. } = kind {
            view["byteStride"] = stride.into();
        }
        self.buffer_views.push(view);
        self.buffer_views.len() - 1
    }

    /// Appends `bytes` to the buffer, 4-byte aligned; returns their offset.
    fn append(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.bin.extend_from_slice(bytes);
        self.bin.len() - bytes.len()
    }

    /// Adds the index accessor and the mesh of one primitive over `position_accessor`; returns
    /// the mesh's index.
    fn primitive(&mut self, name: &str, position_accessor: usize, indices: &[u32]) -> usize {
        let index_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&index_bytes, ViewKind::Indices);
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

    /// Adds an indexed triangle mesh of one primitive with float positions; returns its index.
    pub(super) fn mesh(&mut self, name: &str, positions: &[Vec3], indices: &[u32]) -> usize {
        let exponential = self.meshopt.is_some_and(|m| m.exponential);
        let position_bytes: Vec<u8> = if exponential {
            let floats: Vec<[f32; 3]> = positions.iter().map(|p| p.to_array()).collect();
            meshopt::encode_filter_exp(&floats, 24, meshopt::EncodeExpMode::Separate)
                .iter()
                .flatten()
                .flat_map(|w| w.to_le_bytes())
                .collect()
        } else {
            positions
                .iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes)
                .collect()
        };
        // POSITION needs its bounds; non-finite vertices (written by tests) are left out.
        let finite = || positions.iter().copied().filter(|p| p.is_finite());
        let min = finite().reduce(Vec3::min).unwrap_or(Vec3::ZERO);
        let max = finite().reduce(Vec3::max).unwrap_or(Vec3::ZERO);
        let filter = if exponential { "EXPONENTIAL" } else { "NONE" };
        let view = self.view(&position_bytes, ViewKind::Vertices { stride: 12, filter });
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": positions.len(),
            "type": "VEC3",
            "min": min.to_array(),
            "max": max.to_array(),
        }));
        let position_accessor = self.accessors.len() - 1;
        self.primitive(name, position_accessor, indices)
    }

    /// Adds an indexed triangle mesh of one primitive whose positions are quantized as
    /// `quantization` says (`KHR_mesh_quantization`) over their bounds; returns the mesh's index
    /// and the node translation and scale that dequantize them.
    pub(super) fn quantized_mesh(
        &mut self,
        name: &str,
        positions: &[Vec3],
        indices: &[u32],
        quantization: Quantization,
    ) -> (usize, Vec3, Vec3) {
        let Quantization {
            component,
            normalized,
        } = quantization;
        let (component_type, size, lo, hi) = component.layout();
        let divisor = if normalized { hi as f32 } else { 1.0 };
        let min = positions
            .iter()
            .copied()
            .reduce(Vec3::min)
            .unwrap_or(Vec3::ZERO);
        let max = positions
            .iter()
            .copied()
            .reduce(Vec3::max)
            .unwrap_or(Vec3::ZERO);
        let extent = (max - min).max(Vec3::splat(f32::MIN_POSITIVE));
        let steps = (hi - lo) as f32;
        // local = q / divisor; world = translation + scale * local.
        let scale = extent / steps * divisor;
        let translation = min - extent * (lo as f32 / steps);
        let stride = (3 * size).next_multiple_of(4);
        let mut bytes = Vec::with_capacity(positions.len() * stride);
        let mut q_min = [hi; 3];
        let mut q_max = [lo; 3];
        for p in positions {
            let q = (lo as f32 + (*p - min) / extent * steps).round();
            for k in 0..3 {
                let q = (q[k] as i32).clamp(lo, hi);
                q_min[k] = q_min[k].min(q);
                q_max[k] = q_max[k].max(q);
                bytes.extend_from_slice(&q.to_le_bytes()[..size]);
            }
            bytes.resize(bytes.len().next_multiple_of(stride), 0);
        }
        let view = self.view(
            &bytes,
            ViewKind::Vertices {
                stride,
                filter: "NONE",
            },
        );
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": component_type,
            "normalized": normalized,
            "count": positions.len(),
            "type": "VEC3",
            "min": q_min,
            "max": q_max,
        }));
        self.quantized = true;
        let position_accessor = self.accessors.len() - 1;
        (
            self.primitive(name, position_accessor, indices),
            translation,
            scale,
        )
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
        let view = self.view(&time_bytes, ViewKind::Other);
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
        let view = self.view(&value_bytes, ViewKind::Other);
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
        let mut used = Vec::new();
        let mut required = Vec::new();
        if !self.lights.is_empty() {
            used.push("KHR_lights_punctual");
            document["extensions"] = json!({ "KHR_lights_punctual": { "lights": self.lights } });
        }
        if self.quantized {
            used.push("KHR_mesh_quantization");
            required.push("KHR_mesh_quantization");
        }
        if let Some(meshopt) = self.meshopt.filter(|_| self.fallback_length > 0) {
            used.push(meshopt.extension);
            required.push(meshopt.extension);
            if let Some(buffers) = document["buffers"].as_array_mut() {
                buffers.push(json!({
                    "byteLength": self.fallback_length,
                    "extensions": { meshopt.extension: { "fallback": true } },
                }));
            }
        }
        if !used.is_empty() {
            document["extensionsUsed"] = json!(used);
        }
        if !required.is_empty() {
            document["extensionsRequired"] = json!(required);
        }
        (document, self.bin)
    }
}

/// The attribute codec's stream for elements of `stride` (4, 8 or 12) bytes, in format
/// `version`.
pub(super) fn encode_attributes(bytes: &[u8], stride: usize, version: i32) -> Vec<u8> {
    fn encode<const N: usize>(bytes: &[u8], version: i32) -> Vec<u8> {
        let elements: Vec<[u8; N]> = bytes
            .chunks_exact(N)
            .map(|e| std::array::from_fn(|k| e[k]))
            .collect();
        meshopt::encode_vertex_buffer_level(&elements, 2, Some(version))
            .expect("the meshopt encoders do not fail")
    }
    match stride {
        4 => encode::<4>(bytes, version),
        8 => encode::<8>(bytes, version),
        12 => encode::<12>(bytes, version),
        other => unreachable!("the writer never writes vertices of {other} bytes"),
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
