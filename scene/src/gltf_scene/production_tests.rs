//! glTF as production tools write it (`KHR_mesh_quantization`, meshopt compression, Draco,
//! required extensions) and as the specification allows it (textures without `source`,
//! accessors without `bufferView`, sparse positions).

use glam::Vec3;
use serde_json::{json, Value};

use super::compression::{self, Compression};
use super::tests::{load, random, with_triangle, TempDir, TRIANGLE};
use super::writer::{glb, GltfWriter, Meshopt, Quantization, QuantizedComponent};
use super::*;

/// Vertices of a closed, finely tessellated shape (more than one 256-element codec block) and
/// its triangles.
fn bumpy_sphere() -> (Vec<Vec3>, Vec<u32>) {
    let (rings, segments) = (24u32, 40u32);
    let mut positions = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let radius = 2.0 + 0.1 * (5.0 * phi).sin() * theta.sin();
            positions.push(
                Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ) * radius
                    + Vec3::new(10.0, -3.0, 0.5),
            );
        }
    }
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let a = r * segments + s;
            let b = r * segments + (s + 1) % segments;
            let (c, d) = (a + segments, b + segments);
            indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    (positions, indices)
}

/// A document with one mesh of `positions` and `indices` on a node with `node` fields, written
/// by `writer`.
fn one_mesh(mut writer: GltfWriter, positions: &[Vec3], indices: &[u32]) -> (Value, Vec<u8>) {
    let mesh = writer.mesh("shape", positions, indices);
    let node = writer.node(json!({ "name": "shape", "mesh": mesh }));
    writer.root(node);
    writer.finish()
}

/// `file` with each triangle's corners rotated so that its smallest index comes first: the
/// meshopt `TRIANGLES` codec may rotate triangles (keeping their winding).
fn without_rotations(mut file: SceneFile) -> SceneFile {
    for t in file.scene.indices.chunks_exact_mut(3) {
        let first = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        t.rotate_left(first);
    }
    file
}

/// Whether triangle `a` is `b` with its corners rotated, each corner within `tolerance`.
fn same_triangle(a: [Vec3; 3], b: [Vec3; 3], tolerance: f32) -> bool {
    (0..3).any(|r| (0..3).all(|k| a[(k + r) % 3].abs_diff_eq(b[k], tolerance)))
}

const EXT: &str = "EXT_meshopt_compression";
const KHR: &str = "KHR_meshopt_compression";

fn meshopt(extension: &'static str, exponential: bool, triangles: bool) -> GltfWriter {
    GltfWriter::compressed(Meshopt {
        extension,
        exponential,
        triangles,
    })
}

/// Quantized positions of every integer type, normalized or not, under a node translation and
/// scale, load exactly as the float file of the dequantized values (the spec's `c / 32767` etc.,
/// correctly rounded) under the same node transform, and within rounding of the grid points they
/// encode.
#[test]
fn quantized_positions_load_as_their_float_file() {
    let dir = TempDir::new();
    let min = Vec3::new(-3.0, 0.5, 10.0);
    let extent = Vec3::new(4.0, 2.0, 0.25);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for component in [
        QuantizedComponent::I8,
        QuantizedComponent::U8,
        QuantizedComponent::I16,
        QuantizedComponent::U16,
    ] {
        for normalized in [false, true] {
            let (_, _, lo, hi) = component.layout();
            let steps = (hi - lo) as u64;
            // Grid steps from the bounds, with both extremes on every axis.
            let mut grid: Vec<[u64; 3]> = vec![[0, 0, 0], [steps, steps, steps]];
            grid.extend((0..58).map(|_| std::array::from_fn(|_| random(&mut state) % (steps + 1))));
            let positions: Vec<Vec3> = grid
                .iter()
                .map(|k| min + Vec3::from_array(k.map(|k| k as f32)) * extent / steps as f32)
                .collect();
            let indices: Vec<u32> = (0..positions.len() as u32).collect();
            let quantization = Quantization {
                component,
                normalized,
            };
            let mut w = GltfWriter::default();
            let (mesh, translation, scale) =
                w.quantized_mesh("q", &positions, &indices, quantization);
            let transform =
                json!({ "translation": translation.to_array(), "scale": scale.to_array() });
            let node = w.node(json!({ "name": "q", "mesh": mesh, "translation": transform["translation"], "scale": transform["scale"] }));
            w.root(node);
            let (document, bin) = w.finish();
            assert_eq!(
                document["extensionsRequired"],
                json!(["KHR_mesh_quantization"])
            );
            let quantized = dir
                .load_embedded("quantized.gltf", &document, &bin)
                .unwrap_or_else(|e| panic!("{quantization:?}: {e}"));

            // The spec's dequantization of the integers the grid steps encode.
            let dequantize = |c: i32| {
                let c = c as f32;
                match (normalized, lo < 0) {
                    (false, _) => c,
                    (true, true) => (c / hi as f32).max(-1.0),
                    (true, false) => c / hi as f32,
                }
            };
            let local: Vec<Vec3> = grid
                .iter()
                .map(|k| Vec3::from_array(k.map(|k| dequantize(lo + k as i32))))
                .collect();
            let mut w = GltfWriter::default();
            let mesh = w.mesh("q", &local, &indices);
            let node = w.node(json!({ "name": "q", "mesh": mesh, "translation": transform["translation"], "scale": transform["scale"] }));
            w.root(node);
            let (document, bin) = w.finish();
            let float = dir.load_embedded("float.gltf", &document, &bin).unwrap();
            assert_eq!(quantized, float, "{quantization:?}");
            // The grid points come back to within float rounding of the node transform.
            for (loaded, original) in quantized.scene.positions.iter().zip(&positions) {
                assert!(
                    loaded.abs_diff_eq(*original, 1e-5 * 16.0),
                    "{quantization:?}: {loaded} is not {original}"
                );
            }
        }
    }
}

/// The same mesh written uncompressed and with meshopt (both extensions, both index modes, the
/// exponential filter, quantized positions, GLB and glTF containers) loads identically.
#[test]
fn meshopt_files_load_as_their_uncompressed_files() {
    let dir = TempDir::new();
    let (positions, indices) = bumpy_sphere();
    assert!(positions.len() > 256 * 3);
    let plain = one_mesh(GltfWriter::default(), &positions, &indices);
    let expected = dir.load_embedded("plain.gltf", &plain.0, &plain.1).unwrap();
    for (extension, triangles) in [(EXT, true), (EXT, false), (KHR, true), (KHR, false)] {
        let (document, bin) = one_mesh(meshopt(extension, false, triangles), &positions, &indices);
        assert_eq!(document["extensionsRequired"], json!([extension]));
        let views = document["bufferViews"].as_array().unwrap();
        let modes: Vec<&str> = views
            .iter()
            .map(|v| v["extensions"][extension]["mode"].as_str().unwrap())
            .collect();
        let index_mode = if triangles { "TRIANGLES" } else { "INDICES" };
        assert_eq!(modes, ["ATTRIBUTES", index_mode]);
        assert!(
            bin.len() * 2 < plain.1.len(),
            "{extension}: {} compressed bytes for {} plain ones",
            bin.len(),
            plain.1.len()
        );
        assert_eq!(
            document["buffers"][1]["extensions"][extension]["fallback"],
            true
        );
        let embedded = dir.load_embedded("meshopt.gltf", &document, &bin).unwrap();
        let binary = load(&dir.write("meshopt.glb", &glb(&document, &bin))).unwrap();
        assert_eq!(embedded, binary, "{extension} {index_mode}");
        if triangles {
            assert!(
                without_rotations(binary) == without_rotations(expected.clone()),
                "{extension} {index_mode}"
            );
        } else {
            assert!(binary == expected, "{extension} {index_mode}: exact");
        }
    }

    // The exponential filter keeps 24-bit signed mantissas: the reference is meshoptimizer's own
    // round trip of the positions.
    let floats: Vec<[f32; 3]> = positions.iter().map(|p| p.to_array()).collect();
    let mut words = meshopt::encode_filter_exp(&floats, 24, meshopt::EncodeExpMode::Separate);
    meshopt::decode_filter_exp(&mut words);
    let filtered: Vec<Vec3> = words
        .iter()
        .map(|w| Vec3::from_array(w.map(f32::from_bits)))
        .collect();
    let plain = one_mesh(GltfWriter::default(), &filtered, &indices);
    let expected = dir.load_embedded("plain.gltf", &plain.0, &plain.1).unwrap();
    let (document, bin) = one_mesh(meshopt(EXT, true, true), &positions, &indices);
    assert_eq!(
        document["bufferViews"][0]["extensions"][EXT]["filter"],
        "EXPONENTIAL"
    );
    let file = dir
        .load_embedded("exponential.gltf", &document, &bin)
        .unwrap();
    assert!(without_rotations(file.clone()) == without_rotations(expected));
    for (loaded, original) in file.scene.positions.iter().zip(&positions) {
        assert!(
            loaded.abs_diff_eq(*original, 1e-6 * 16.0),
            "{loaded} {original}"
        );
    }

    // Quantized positions (4- and 8-byte elements) compressed.
    for component in [QuantizedComponent::U8, QuantizedComponent::I16] {
        let quantization = Quantization {
            component,
            normalized: true,
        };
        let write = |mut w: GltfWriter| {
            let (mesh, t, s) = w.quantized_mesh("q", &positions, &indices, quantization);
            let node =
                w.node(json!({ "mesh": mesh, "translation": t.to_array(), "scale": s.to_array() }));
            w.root(node);
            w.finish()
        };
        let (document, bin) = write(GltfWriter::default());
        let expected = dir.load_embedded("q.gltf", &document, &bin).unwrap();
        let (document, bin) = write(meshopt(EXT, false, true));
        assert_eq!(
            document["extensionsRequired"],
            json!(["KHR_mesh_quantization", EXT])
        );
        let file = load(&dir.write("q.glb", &glb(&document, &bin))).unwrap();
        assert!(
            without_rotations(file) == without_rotations(expected),
            "{component:?}"
        );
    }
}

/// The decode filters give what meshoptimizer's own filters give on the decoded stream.
#[test]
fn meshopt_filters_decode_as_meshoptimizer() {
    let mut state = 7u64;
    let unit = |state: &mut u64| {
        let mut c = || (random(state) % 2001) as f32 / 1000.0 - 1.0;
        Vec3::new(c(), c(), c()).normalize_or(Vec3::X)
    };
    let vectors: Vec<[f32; 4]> = (0..300)
        .map(|_| unit(&mut state).extend(1.0).to_array())
        .collect();
    let quaternions: Vec<[f32; 4]> = (0..300)
        .map(|_| {
            let axis = unit(&mut state);
            glam::Quat::from_axis_angle(axis, (random(&mut state) % 628) as f32 / 100.0).to_array()
        })
        .collect();
    let colors: Vec<[f32; 4]> = vectors.iter().map(|v| v.map(|c| c.abs())).collect();

    fn bytes<T: Copy, const K: usize>(data: &[[T; K]], le: fn(T) -> Vec<u8>) -> Vec<u8> {
        data.iter().flatten().flat_map(|&c| le(c)).collect()
    }
    let oct8 = meshopt::encode_filter_oct::<i8>(&vectors, 8);
    let mut oct8_expected = oct8.clone();
    meshopt::decode_filter_oct(&mut oct8_expected);
    let oct16 = meshopt::encode_filter_oct::<i16>(&vectors, 16);
    let mut oct16_expected = oct16.clone();
    meshopt::decode_filter_oct(&mut oct16_expected);
    let quat = meshopt::encode_filter_quat(&quaternions, 12);
    let mut quat_expected = quat.clone();
    meshopt::decode_filter_quat(&mut quat_expected);
    let color = meshopt::encode_filter_color::<u8>(&colors, 8);
    let mut color_expected = color.clone();
    meshopt::decode_filter_color(&mut color_expected);
    let i8_le = |c: i8| c.to_le_bytes().to_vec();
    let i16_le = |c: i16| c.to_le_bytes().to_vec();
    let u8_le = |c: u8| vec![c];
    let cases = [
        (
            "OCTAHEDRAL",
            4,
            bytes(&oct8, i8_le),
            bytes(&oct8_expected, i8_le),
        ),
        (
            "OCTAHEDRAL",
            8,
            bytes(&oct16, i16_le),
            bytes(&oct16_expected, i16_le),
        ),
        (
            "QUATERNION",
            8,
            bytes(&quat, i16_le),
            bytes(&quat_expected, i16_le),
        ),
        (
            "COLOR",
            4,
            bytes(&color, u8_le),
            bytes(&color_expected, u8_le),
        ),
    ];
    for (filter, stride, raw, expected) in cases {
        assert_ne!(raw, expected, "{filter}: the filter changes the data");
        let compressed = super::writer::encode_attributes(&raw, stride, 1);
        let compression = Compression {
            buffer: 0,
            byte_offset: 0,
            byte_length: compressed.len(),
            byte_stride: stride,
            count: raw.len() / stride,
            mode: "ATTRIBUTES".into(),
            filter: filter.into(),
        };
        let decoded = compression::decode(&compression, raw.len(), None, &compressed).unwrap();
        assert_eq!(decoded, expected, "{filter} {stride}");
        // A stride the filter does not take is an error, not a decoder assertion.
        let wrong = Compression {
            byte_stride: 12,
            count: raw.len() / 12,
            ..compression
        };
        let error = compression::decode(&wrong, wrong.count * 12, None, &compressed).unwrap_err();
        assert!(error.contains("needs a byteStride"), "{error}");
    }
}

/// Truncated, byte-flipped or oversized compressed streams are errors naming the file; none
/// panics, and no size is allocated before it is checked.
#[test]
fn corrupt_meshopt_streams_are_errors() {
    let dir = TempDir::new();
    let (positions, indices) = bumpy_sphere();
    let (document, bin) = one_mesh(meshopt(EXT, false, true), &positions, &indices);
    let expected = load(&dir.write("good.glb", &glb(&document, &bin))).unwrap();
    let with = |f: &dyn Fn(&mut Value)| {
        let mut d = document.clone();
        f(&mut d);
        glb(&d, &bin)
    };
    let ext =
        |d: &mut Value, view: usize| -> Value { d["bufferViews"][view]["extensions"][EXT].take() };
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "truncated vertices",
            with(&|d| {
                let mut e = ext(d, 0);
                e["byteLength"] = (e["byteLength"].as_u64().unwrap() - 40).into();
                d["bufferViews"][0]["extensions"][EXT] = e;
            }),
            "corrupt ATTRIBUTES stream",
        ),
        (
            "truncated indices",
            with(&|d| {
                let mut e = ext(d, 1);
                e["byteLength"] = (e["byteLength"].as_u64().unwrap() / 2).into();
                d["bufferViews"][1]["extensions"][EXT] = e;
            }),
            "TRIANGLES",
        ),
        (
            "huge count",
            with(&|d| {
                let mut e = ext(d, 0);
                e["count"] = (1u64 << 40).into();
                d["bufferViews"][0]["byteLength"] = (12u64 << 40).into();
                d["buffers"][1]["byteLength"] = (12u64 << 40).into();
                d["accessors"][0]["count"] = (1u64 << 40).into();
                d["bufferViews"][0]["extensions"][EXT] = e;
            }),
            "cannot hold",
        ),
        (
            "count and byteLength disagree",
            with(&|d| {
                let mut e = ext(d, 1);
                e["count"] = (e["count"].as_u64().unwrap() - 3).into();
                d["bufferViews"][1]["extensions"][EXT] = e;
            }),
            "byteLength",
        ),
        (
            "stride",
            with(&|d| {
                let mut e = ext(d, 0);
                e["byteStride"] = 6.into();
                d["bufferViews"][0]["byteStride"] = 6.into();
                e["count"] = (positions.len() * 2).into();
                d["bufferViews"][0]["extensions"][EXT] = e;
            }),
            "divisible by 4",
        ),
        (
            "outside the buffer",
            with(&|d| {
                let mut e = ext(d, 0);
                e["byteOffset"] = 1_000_000.into();
                d["bufferViews"][0]["extensions"][EXT] = e;
            }),
            "exceed buffer 0",
        ),
        (
            "not an object",
            with(&|d| d["bufferViews"][0]["extensions"][EXT] = json!(3)),
            "EXT_meshopt_compression",
        ),
    ];
    for (name, bytes, expected_message) in cases {
        let error = load(&dir.write("bad.glb", &bytes)).unwrap_err();
        assert!(matches!(error, SceneError::Gltf { .. }), "{name}: {error}");
        assert!(
            error.to_string().contains(expected_message),
            "{name}: {error}"
        );
    }

    // Each compressed byte flipped in turn (a sample of them): the header bytes always give an
    // error; other bytes an error or other geometry that passes every check, never a panic.
    let streams: Vec<(usize, usize)> = (0..2)
        .map(|v| {
            let e = &document["bufferViews"][v]["extensions"][EXT];
            (
                e["byteOffset"].as_u64().unwrap() as usize,
                e["byteLength"].as_u64().unwrap() as usize,
            )
        })
        .collect();
    let mut errors = 0;
    let mut tried = 0;
    for &(offset, length) in &streams {
        for at in (0..length).step_by(length / 97 + 1).chain([0]) {
            let mut flipped = bin.clone();
            flipped[offset + at] ^= 0xa5;
            tried += 1;
            match load(&dir.write("flipped.glb", &glb(&document, &flipped))) {
                Err(_) => errors += 1,
                Ok(file) => {
                    assert_ne!(at, 0, "a flipped header byte must be an error");
                    file.scene.validate().unwrap();
                    assert_eq!(file.scene.triangle_count(), expected.scene.triangle_count());
                }
            }
        }
    }
    assert!(
        errors > 0 && tried > 150,
        "{errors} errors in {tried} flips"
    );
}

/// Every required extension that is not supported is named in one error; extensions that only
/// change materials and textures are accepted; Draco gets advice.
#[test]
fn unsupported_required_extensions_in_one_error() {
    let dir = TempDir::new();
    let (mut document, bin) = with_triangle().finish();
    document["extensionsRequired"] = json!([
        "KHR_mesh_quantization",
        "EXT_mesh_gpu_instancing",
        "KHR_texture_basisu",
        "KHR_draco_mesh_compression",
        "KHR_materials_clearcoat",
        "EXT_future",
    ]);
    document["extensionsUsed"] = document["extensionsRequired"].clone();
    let error = dir
        .load_embedded("required.gltf", &document, &bin)
        .unwrap_err();
    assert!(matches!(error, SceneError::Gltf { .. }), "{error}");
    let text = error.to_string();
    assert!(
        text.contains(
            "does not support: EXT_mesh_gpu_instancing, KHR_draco_mesh_compression, EXT_future ("
        ),
        "{text}"
    );
    assert!(text.contains("gltf-transform meshopt"), "{text}");
    assert!(!text.contains("Missing"), "{text}");

    document["extensionsRequired"] = json!(["KHR_texture_basisu", "KHR_materials_clearcoat"]);
    dir.load_embedded("textures.gltf", &document, &bin).unwrap();
}

/// A Draco primitive whose accessors have no data is an error that names Draco (not "missing
/// data"); one that keeps uncompressed fallback accessors loads them.
#[test]
fn draco_primitives() {
    let dir = TempDir::new();
    let (mut document, bin) = with_triangle().finish();
    document["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    document["meshes"][0]["primitives"][0]["extensions"] = json!({
        "KHR_draco_mesh_compression": { "bufferView": 0, "attributes": { "POSITION": 0 } }
    });
    let fallback = dir.load_embedded("fallback.gltf", &document, &bin).unwrap();
    assert_eq!(fallback.scene.triangle(0), TRIANGLE);

    for accessor in [0, 1] {
        let mut compressed = document.clone();
        compressed["accessors"][accessor]
            .as_object_mut()
            .unwrap()
            .remove("bufferView");
        let error = dir
            .load_embedded("draco.gltf", &compressed, &bin)
            .unwrap_err();
        let text = error.to_string();
        assert!(matches!(error, SceneError::Gltf { .. }), "{text}");
        assert!(
            text.contains("mesh 0 \"triangle\" primitive 0")
                && text.contains("only in KHR_draco_mesh_compression")
                && text.contains("gltf-transform meshopt"),
            "{text}"
        );
        assert!(!text.contains("Missing"), "{text}");
        compressed["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
        let error = dir
            .load_embedded("draco.gltf", &compressed, &bin)
            .unwrap_err();
        assert!(
            error
                .to_string()
                .contains("KHR_draco_mesh_compression: Draco"),
            "{error}"
        );
    }
}

/// A texture whose image an extension supplies (no `source`) and an unused accessor without a
/// buffer view are legal and ignored.
#[test]
fn texture_without_source_and_accessor_without_view() {
    let dir = TempDir::new();
    let (mut document, bin) = with_triangle().finish();
    document["extensionsUsed"] = json!(["KHR_texture_basisu", "EXT_texture_webp"]);
    document["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    document["images"] = json!([{ "uri": "albedo.ktx2" }, { "uri": "albedo.webp" }]);
    document["textures"] = json!([
        { "extensions": { "KHR_texture_basisu": { "source": 0 } } },
        { "extensions": { "EXT_texture_webp": { "source": 1 } } },
    ]);
    document["materials"] =
        json!([{ "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } }]);
    document["meshes"][0]["primitives"][0]["material"] = 0.into();
    document["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "componentType": 5126, "count": 5, "type": "VEC3" }));
    let file = dir.load_embedded("basisu.gltf", &document, &bin).unwrap();
    assert_eq!(file.scene.triangle(0), TRIANGLE);
    assert_eq!(file.scene.triangle_count(), 1);
}

/// Sparse `POSITION` accessors, with and without a buffer view, load with their displaced
/// vertices; a POSITION accessor without buffer view and without sparse is all zeros.
#[test]
fn sparse_positions() {
    let dir = TempDir::new();
    let (document, mut bin) = with_triangle().finish();
    // Sparse data after the buffer: indices 1 and 2 (u16), then two displaced positions.
    let sparse_offset = bin.len();
    for i in [1u16, 2] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let displaced = [Vec3::new(2.0, 0.0, 1.0), Vec3::new(0.0, 3.0, -1.0)];
    for c in displaced.iter().flat_map(|p| p.to_array()) {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    let mut document = document;
    document["buffers"][0]["byteLength"] = bin.len().into();
    let views = document["bufferViews"].as_array_mut().unwrap();
    views.push(json!({ "buffer": 0, "byteOffset": sparse_offset, "byteLength": 4 }));
    views.push(json!({ "buffer": 0, "byteOffset": sparse_offset + 4, "byteLength": 24 }));
    let (index_view, value_view) = (views.len() - 2, views.len() - 1);
    document["accessors"][0]["sparse"] = json!({
        "count": 2,
        "indices": { "bufferView": index_view, "componentType": 5123 },
        "values": { "bufferView": value_view },
    });
    document["accessors"][0]["max"] = json!([2.0, 3.0, 1.0]);
    document["accessors"][0]["min"] = json!([0.0, 0.0, -1.0]);
    let with_view = dir.load_embedded("sparse.gltf", &document, &bin).unwrap();
    assert_eq!(
        with_view.scene.triangle(0),
        [Vec3::ZERO, displaced[0], displaced[1]]
    );

    let mut without_view = document.clone();
    let accessor = without_view["accessors"][0].as_object_mut().unwrap();
    accessor.remove("bufferView");
    accessor["sparse"]["indices"]["byteOffset"] = 0.into();
    let file = dir
        .load_embedded("sparse-zeros.gltf", &without_view, &bin)
        .unwrap();
    assert_eq!(
        file.scene.triangle(0),
        [Vec3::ZERO, displaced[0], displaced[1]]
    );

    // No sparse either: all zeros, legal, a degenerate triangle.
    let accessor = without_view["accessors"][0].as_object_mut().unwrap();
    accessor.remove("sparse");
    let file = dir
        .load_embedded("zeros.gltf", &without_view, &bin)
        .unwrap();
    assert_eq!(file.scene.triangle(0), [Vec3::ZERO; 3]);
}

/// [`write_scene`] writes what [`load_gltf`] reads back: float and meshopt geometry exactly,
/// quantized geometry to within its steps; lights, flags and the camera to within float
/// rounding.
#[test]
fn written_scenes_load_back() {
    let dir = TempDir::new();
    let example = dir.0.join("example.glb");
    write_example_scene(&example).unwrap();
    let original = load(&example).unwrap();
    let extent = original.scene.bounds().size().max_element();
    let quantize = Some(Quantization {
        component: QuantizedComponent::U16,
        normalized: true,
    });
    for (encoding, tolerance) in [
        (GltfEncoding::default(), 0.0),
        (
            GltfEncoding {
                quantize: None,
                meshopt: true,
            },
            0.0,
        ),
        (
            GltfEncoding {
                quantize,
                meshopt: false,
            },
            extent / 65535.0,
        ),
        (
            GltfEncoding {
                quantize,
                meshopt: true,
            },
            extent / 65535.0,
        ),
    ] {
        for name in ["scene.gltf", "scene.glb"] {
            let path = dir.0.join(name);
            write_scene(&path, &original, encoding).unwrap();
            let file = load(&path).unwrap();
            let scene = &file.scene;
            assert_eq!(scene.objects, original.scene.objects, "{encoding:?}");
            assert_eq!(file.static_objects, original.static_objects);
            for t in 0..scene.triangle_count() {
                let (a, b) = (scene.triangle(t), original.scene.triangle(t));
                assert!(same_triangle(a, b, tolerance), "{encoding:?}: {a:?} {b:?}");
            }
            assert_eq!(file.lights.len(), original.lights.len());
            for (a, b) in file.lights.iter().zip(&original.lights) {
                assert_eq!(
                    (&a.name, a.size, a.casts_shadows, a.is_static),
                    (&b.name, b.size, b.casts_shadows, b.is_static)
                );
                let close = |x: Option<Vec3>, y: Option<Vec3>| match (x, y) {
                    (Some(x), Some(y)) => x.abs_diff_eq(y, 1e-5),
                    (x, y) => x == y,
                };
                assert!(close(a.kind.position(), b.kind.position()), "{a:?} {b:?}");
                assert!(close(a.kind.direction(), b.kind.direction()), "{a:?} {b:?}");
            }
            let (a, b) = (file.camera.unwrap(), original.camera.unwrap());
            assert!(a.position.abs_diff_eq(b.position, 1e-5));
            assert!((a.target - a.position).abs_diff_eq(b.target - b.position, 1e-5));
        }
    }
}
