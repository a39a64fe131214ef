//! Wavefront OBJ loading.
//!
//! The text is first normalised line by line into the small subset of OBJ that matters here
//! (positions, faces with absolute position indices, object/group names), with strict checks and
//! precise error messages. `tobj` then groups, fan-triangulates and single-indexes that subset.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use crate::{Object, Scene, SceneError};

/// Loads an OBJ file as a [`Scene`] with one [`Object`] per OBJ object/group that has faces.
///
/// Polygons are fan-triangulated; negative (relative) indices are supported; only positions are
/// used (texture coordinates, normals, materials, points and lines are ignored, and no `.mtl` file
/// is read). Comments may also follow statements on a line, and a leading byte-order mark is
/// skipped.
///
/// # Errors
///
/// All errors name the file:
/// - [`SceneError::Io`] if the file cannot be read,
/// - [`SceneError::Parse`] for text that is not UTF-8 or not well-formed OBJ (bad numbers, faces
///   with fewer than three vertices, index 0, relative indices before the first vertex, faces
///   referencing vertices not defined before them, ...), with the line and the corner as written,
/// - [`SceneError::NonFinite`] for NaN or infinite vertex coordinates (including overflow such as
///   `1e39`),
/// - [`SceneError::Empty`] if there is no triangle.
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    parse_obj(&bytes, path)
}

/// Parses OBJ content; `path` is only used in error messages.
pub(crate) fn parse_obj(bytes: &[u8], path: &Path) -> Result<Scene, SceneError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        SceneError::Parse {
            path: path.to_owned(),
            message: format!("line {line}: not UTF-8 text"),
        }
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let normalized = normalize(text).map_err(|e| e.into_scene_error(path))?;
    #[allow(
        clippy::needless_update,
        reason = "tobj features enabled elsewhere in the workspace may add fields"
    )]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut normalized.as_bytes(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| SceneError::Parse {
        path: path.to_owned(),
        message: e.to_string(),
    })?;

    let mut scene = Scene::default();
    for model in models {
        let mesh = model.mesh;
        if mesh.indices.len() < 3 {
            continue;
        }
        let positions = mesh
            .positions
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        let triangle_count = (mesh.indices.len() / 3) as u32;
        scene.append(&Scene {
            positions,
            indices: mesh.indices,
            objects: vec![Object {
                name: model.name,
                first_triangle: 0,
                triangle_count,
            }],
        });
    }
    scene.validate_as(path)?;
    Ok(scene)
}

/// A problem found while normalising, before the file path is attached.
#[derive(Debug)]
enum ObjError {
    Parse { line: usize, message: String },
    NonFinite { vertex: usize, value: f32 },
}

impl ObjError {
    fn into_scene_error(self, path: &Path) -> SceneError {
        let path = path.to_owned();
        match self {
            ObjError::Parse { line, message } => SceneError::Parse {
                path,
                message: format!("line {line}: {message}"),
            },
            ObjError::NonFinite { vertex, value } => SceneError::NonFinite {
                path,
                vertex,
                value,
            },
        }
    }
}

/// Rewrites OBJ text as `v x y z`, `f i j k ...` (absolute, 1-based, in range) and `o name` lines.
fn normalize(text: &str) -> Result<String, ObjError> {
    let mut out = String::with_capacity(text.len());
    let mut vertex_count = 0usize;
    let mut triangle_count = 0usize;
    for (line_index, raw) in text.lines().enumerate() {
        let line_no = line_index + 1;
        let parse_error = |message: String| ObjError::Parse {
            line: line_no,
            message,
        };
        let content = raw.split('#').next().unwrap_or_default();
        let mut tokens = content.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let p = parse_position(tokens).map_err(parse_error)?;
                if let Some(value) = p.to_array().into_iter().find(|c| !c.is_finite()) {
                    return Err(ObjError::NonFinite {
                        vertex: vertex_count,
                        value,
                    });
                }
                vertex_count += 1;
                // Writing to a String cannot fail.
                let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
            }
            Some("f") => {
                let corners = tokens.collect::<Vec<_>>();
                if corners.len() < 3 {
                    return Err(parse_error(format!(
                        "a face needs at least 3 vertices, found {}",
                        corners.len()
                    )));
                }
                let first_triangle = triangle_count;
                triangle_count += corners.len() - 2;
                out.push('f');
                for corner in corners {
                    let index = resolve_corner(corner, vertex_count).map_err(|e| match e {
                        CornerError::Malformed(message) => parse_error(message),
                        CornerError::OutOfRange => parse_error(format!(
                            "face corner '{corner}' (triangle {}) references a vertex that does not exist: \
                             {vertex_count} vertices are defined before it (OBJ indices start at 1; \
                             negative ones count back from the last vertex defined)",
                            first_triangle + 1
                        )),
                    })?;
                    let _ = write!(out, " {}", index + 1);
                }
                out.push('\n');
            }
            Some("o" | "g") => {
                let name = tokens.collect::<Vec<_>>().join(" ");
                let _ = writeln!(out, "o {name}");
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Parses the operands of a `v` statement: `x y z`, `x y z w` (homogeneous) or `x y z r g b`.
fn parse_position<'a>(tokens: impl Iterator<Item = &'a str>) -> Result<Vec3, String> {
    let values = tokens
        .map(|t| {
            t.parse::<f32>()
                .map_err(|_| format!("expected a number, found \"{t}\""))
        })
        .collect::<Result<Vec<_>, _>>()?;
    match *values.as_slice() {
        [x, y, z] | [x, y, z, _, _, _] => Ok(Vec3::new(x, y, z)),
        [_, _, _, 0.0] => Err("vertex has w = 0".to_owned()),
        [x, y, z, w] => Ok(Vec3::new(x, y, z) / w),
        _ => Err(format!(
            "a vertex needs 3 coordinates (optionally followed by w or r g b), found {} numbers",
            values.len()
        )),
    }
}

/// Why a face corner could not be resolved.
enum CornerError {
    Malformed(String),
    /// An index at or beyond the number of vertices defined so far.
    OutOfRange,
}

/// Resolves a face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` to a zero-based position index.
fn resolve_corner(corner: &str, vertex_count: usize) -> Result<usize, CornerError> {
    let malformed = || CornerError::Malformed(format!("malformed face vertex \"{corner}\""));
    let mut parts = corner.split('/');
    let position = parts.next().unwrap_or_default();
    let attributes = parts.collect::<Vec<_>>();
    if attributes.len() > 2
        || attributes
            .iter()
            .any(|a| !a.is_empty() && a.parse::<i64>().is_err())
    {
        return Err(malformed());
    }
    let index = position.parse::<i64>().map_err(|_| malformed())?;
    let count = vertex_count as u64;
    if index > 0 {
        let zero_based = index.unsigned_abs() - 1;
        if zero_based >= count {
            return Err(CornerError::OutOfRange);
        }
        Ok(zero_based as usize)
    } else if index < 0 {
        count
            .checked_sub(index.unsigned_abs())
            .map(|i| i as usize)
            .ok_or_else(|| {
                CornerError::Malformed(format!(
                    "relative vertex index {index} reaches before the first vertex \
                     ({vertex_count} defined so far)"
                ))
            })
    } else {
        Err(CornerError::Malformed(
            "vertex index 0 is invalid (OBJ indices start at 1)".to_owned(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;
    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::*;
    use crate::SplitMix64;

    /// A file in the system temporary directory, removed on drop.
    struct TempFile(PathBuf);

    impl TempFile {
        fn new(contents: &[u8]) -> Self {
            static NEXT: AtomicUsize = AtomicUsize::new(0);
            let name = format!(
                "scene-test-{}-{}.obj",
                std::process::id(),
                NEXT.fetch_add(1, Ordering::Relaxed)
            );
            let path = std::env::temp_dir().join(name);
            std::fs::write(&path, contents).unwrap();
            Self(path)
        }
    }

    impl Drop for TempFile {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    fn load_text(contents: &str) -> Result<Scene, SceneError> {
        let file = TempFile::new(contents.as_bytes());
        let result = load_obj(&file.0);
        if let Err(e) = &result {
            let path = file.0.display().to_string();
            assert!(e.to_string().contains(&path), "{e} does not name {path}");
        }
        result
    }

    fn kind(result: &Result<Scene, SceneError>) -> &'static str {
        match result {
            Ok(_) => "ok",
            Err(SceneError::Io { .. }) => "io",
            Err(SceneError::Parse { message, .. }) if message.contains("does not exist") => {
                "out-of-range"
            }
            Err(SceneError::Parse { .. }) => "parse",
            Err(SceneError::NonFinite { .. }) => "non-finite",
            Err(SceneError::Empty { .. }) => "empty",
            Err(_) => "other",
        }
    }

    fn model(name: &str) -> Scene {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/models")
            .join(name);
        load_obj(&path).unwrap_or_else(|e| panic!("{e}"))
    }

    const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

    #[test]
    fn stanford_bunny() {
        let scene = model("02_stanford_bunny_69k.obj");
        scene.validate().unwrap();
        assert_eq!(scene.triangle_count(), 69_451);
        assert_eq!(scene.objects.len(), 1);
        assert_eq!(scene.positions.len(), 35_947 - 1_113);
        let size = scene.bounds().size();
        assert!(
            size.min_element() > 0.01 && size.max_element() < 1.0,
            "{size}"
        );
    }

    #[test]
    fn cornell_box() {
        let scene = model("06_cornell_box/cornell_box.obj");
        scene.validate().unwrap();
        assert_eq!(scene.triangle_count(), 36);
        let names = scene
            .objects
            .iter()
            .map(|o| o.name.as_str())
            .collect::<Vec<_>>();
        assert_eq!(
            names,
            [
                "floor",
                "light",
                "ceiling",
                "back_wall",
                "green_wall",
                "red_wall",
                "short_block",
                "tall_block"
            ]
        );
        let counts = scene
            .objects
            .iter()
            .map(|o| o.triangle_count)
            .collect::<Vec<_>>();
        assert_eq!(counts, [6, 2, 2, 2, 2, 2, 10, 10]);
        let light = scene.objects[1].first_triangle as usize;
        for t in light..light + 2 {
            assert!(scene.triangle(t).iter().all(|p| p.y == 548.0));
        }
        assert_eq!(scene.bounds().max, Vec3::new(556.0, 548.8, 559.2));
    }

    #[test]
    fn veach_plates() {
        let scene = model("07_veach_mi_plates.obj");
        scene.validate().unwrap();
        assert_eq!(scene.triangle_count(), 14);
        assert_eq!(scene.objects.len(), 5);
    }

    #[test]
    fn small_models() {
        assert_eq!(model("01_scorpion_low_12k.obj").triangle_count(), 12_626);
        assert_eq!(model("08_smallpine_1650.obj").triangle_count(), 1_650);
    }

    #[test]
    fn large_models() {
        for (name, triangles) in [
            ("03_bunny_hr_x4_239k.obj", 238_656),
            ("04_dabrovic_sponza_66k.obj", 66_454),
            ("05_conference_clean_277k.obj", 276_505),
        ] {
            let scene = model(name);
            scene.validate().unwrap();
            assert_eq!(scene.triangle_count(), triangles, "{name}");
        }
    }

    #[test]
    fn polygons_are_fan_triangulated() {
        let scene =
            load_text("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n").unwrap();
        assert_eq!(scene.triangle_count(), 3);
        for t in 0..3 {
            let [a, b, c] = scene.triangle(t);
            assert_eq!(a, Vec3::ZERO);
            assert!((b - a).cross(c - a).z > 0.0);
        }
        assert_eq!(scene.triangle(2)[2], Vec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn accepted_syntax() {
        let text = "\u{feff}# header\r\n\
            mtllib missing.mtl\r\n\
            v 0 0 0 # origin\r\n\
            v 2 0 0 2\r\n\
            v 0 1 0 0.5 0.5 0.5\r\n\
            vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
            f 1 2 3\n\
            o second  object\n\
            usemtl nothing\n\
            s off\n\
            f 1/1 2/2 3/3\n\
            g\n\
            f 1//1 2//1 3//1\n\
            o empty\n\
            o last\n\
            l 1 2\n\
            p 3\n\
            f -3/1/1 -2/2/1 -1/3/1\n";
        let scene = load_text(text).unwrap();
        scene.validate().unwrap();
        let names = scene
            .objects
            .iter()
            .map(|o| o.name.as_str())
            .collect::<Vec<_>>();
        assert_eq!(
            names,
            ["unnamed_object", "second object", "unnamed_object", "last"]
        );
        for t in 0..4 {
            assert_eq!(scene.triangle(t), [Vec3::ZERO, Vec3::X, Vec3::Y]);
        }
    }

    #[test]
    fn malformed_content_is_rejected() {
        let cases = [
            (format!("{TRIANGLE}f 1 2 x\n"), "parse"),
            ("v 1.0 abc 2.0\n".to_owned(), "parse"),
            ("v 1 2\n".to_owned(), "parse"),
            ("v 1 2 3 4 5\n".to_owned(), "parse"),
            ("v 1 2 3 0\nv 0 0 0\nv 1 1 1\nf 1 2 3\n".to_owned(), "parse"),
            (format!("{TRIANGLE}f 1 2\n"), "parse"),
            (format!("{TRIANGLE}f\n"), "parse"),
            (format!("{TRIANGLE}f 0 1 2\n"), "parse"),
            (format!("{TRIANGLE}f 1/2/3/4 2 3\n"), "parse"),
            (format!("{TRIANGLE}f 1//x 2 3\n"), "parse"),
            (format!("{TRIANGLE}f 1 2 3.5\n"), "parse"),
            (format!("{TRIANGLE}f -4 -2 -1\n"), "parse"),
            (
                format!("{TRIANGLE}f 1 2 99999999999999999999999\n"),
                "parse",
            ),
            (format!("{TRIANGLE}f 1 2 /3\n"), "parse"),
            ("v nan 0 0\n".to_owned(), "non-finite"),
            ("v 0 NaN 0\n".to_owned(), "non-finite"),
            ("v 0 inf 0\n".to_owned(), "non-finite"),
            ("v 0 0 -infinity\n".to_owned(), "non-finite"),
            ("v 1e39 0 0\n".to_owned(), "non-finite"),
            ("v 1 1 1 1e-39\n".to_owned(), "non-finite"),
            (format!("{TRIANGLE}f 1 2 4\n"), "out-of-range"),
            (format!("{TRIANGLE}f 1 2 3\nf 1 2 3 4\n"), "out-of-range"),
            (format!("f 1 2 3\n{TRIANGLE}"), "out-of-range"),
            (format!("{TRIANGLE}f 1 2 4294967297\n"), "out-of-range"),
            (String::new(), "empty"),
            ("# nothing here\n\n   \n".to_owned(), "empty"),
            (TRIANGLE.to_owned(), "empty"),
            ("o a\ng b\n".to_owned(), "empty"),
            (format!("{TRIANGLE}l 1 2\np 3\n"), "empty"),
        ];
        for (text, expected) in cases {
            let result = load_text(&text);
            assert_eq!(kind(&result), expected, "{text:?} gave {result:?}");
        }
    }

    #[test]
    fn error_details() {
        let err = load_text("v 0 0 0\nv 0 nan 0\n").unwrap_err();
        assert!(matches!(err, SceneError::NonFinite { vertex: 1, value, .. } if value.is_nan()));
        let err = load_text(&format!("{TRIANGLE}f 1 2 3\nf 1 2 3 2 9\n")).unwrap_err();
        let message = err.to_string();
        assert!(matches!(err, SceneError::Parse { .. }), "{err:?}");
        assert!(
            message.contains("line 5") && message.contains("'9'") && message.contains("3 vertices"),
            "{message}"
        );
        let err = load_text(&format!("{TRIANGLE}\n\nf 1 2 x\n")).unwrap_err();
        assert!(err.to_string().contains("line 6"), "{err}");
        let missing = std::env::temp_dir().join("scene-test-does-not-exist.obj");
        let err = load_obj(&missing).unwrap_err();
        assert!(matches!(err, SceneError::Io { .. }));
        assert!(err.to_string().contains("scene-test-does-not-exist.obj"));
    }

    /// Deterministic byte soup.
    fn garbage(seed: u64, len: usize) -> Vec<u8> {
        let mut rng = SplitMix64::new(seed);
        (0..len).map(|_| (rng.next_u64() >> 56) as u8).collect()
    }

    #[test]
    fn random_bytes_are_rejected_without_panicking() {
        let file = TempFile::new(&garbage(7, 4096));
        assert!(matches!(
            load_obj(&file.0),
            Err(SceneError::Parse { .. } | SceneError::Empty { .. })
        ));
        for seed in 0..300 {
            let bytes = garbage(seed, (seed as usize * 37) % 2048);
            let result = parse_obj(&bytes, Path::new("garbage.obj"));
            assert!(
                matches!(kind(&result), "parse" | "empty"),
                "seed {seed}: {result:?}"
            );
        }
    }

    #[test]
    fn random_obj_like_text_never_panics() {
        const NUMBERS: [&str; 12] = [
            "0", "1", "-2.5", "0.5", "3e2", "-0", "7", "1e-3", "2", "nan", "1e39", "x",
        ];
        const CORNERS: [&str; 14] = [
            "1", "2", "3", "-1", "-2", "-3", "4", "1/1", "2//2", "3/1/1", "-1//1", "0", "5/x", "/",
        ];
        const WORDS: [&str; 10] = ["vt", "vn", "l", "#", "g", "usemtl", "1", "f", "v", "\t"];
        let mut outcomes = std::collections::HashSet::new();
        for seed in 0..2_000 {
            let (numbers, corners) = if seed % 2 == 0 {
                (&NUMBERS[..9], &CORNERS[..11])
            } else {
                (&NUMBERS[..], &CORNERS[..])
            };
            let noise = garbage(seed, 120);
            let mut text = String::new();
            for line in noise.chunks_exact(6) {
                let pick = |i: usize, words: &[&'static str]| words[line[i] as usize % words.len()];
                match line[0] % 8 {
                    0..=2 => {
                        text.push('v');
                        for i in 1..4 {
                            text.push(' ');
                            text.push_str(pick(i, numbers));
                        }
                    }
                    3..=5 => {
                        text.push('f');
                        for i in 1..3 + (line[5] as usize % 3) {
                            text.push(' ');
                            text.push_str(pick(i, corners));
                        }
                    }
                    6 => text.push_str("o part"),
                    _ => (1..6).for_each(|i| {
                        text.push_str(pick(i, &WORDS));
                        text.push(' ');
                    }),
                }
                text.push('\n');
            }
            let result = parse_obj(text.as_bytes(), Path::new("fuzz.obj"));
            if let Ok(scene) = &result {
                scene.validate().unwrap();
            }
            outcomes.insert(kind(&result));
        }
        for expected in ["ok", "parse", "non-finite", "out-of-range"] {
            assert!(outcomes.contains(expected), "{outcomes:?}");
        }
    }
}
