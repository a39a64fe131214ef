//! The error type shared by OBJ and glTF loading and scene validation.

use std::path::PathBuf;

/// Path reported in errors about scenes that were not loaded from a file.
pub(crate) const MEMORY_PATH: &str = "<memory>";

/// Why a scene could not be loaded or failed [`Scene::validate`](crate::Scene::validate).
///
/// Every variant names the offending file; scenes built in memory use the path `<memory>`.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The content is not well-formed OBJ (or, for in-memory scenes, the index or object layout
    /// is inconsistent). `message` says what is wrong and, for files, on which line.
    #[error("{path}: malformed OBJ: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error(
        "{path}: vertex {vertex} has a non-finite coordinate ({value}); NaN/Inf geometry is rejected"
    )]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// Zero-based index of the vertex (in file order for OBJ files).
        vertex: usize,
        /// The offending coordinate.
        value: f32,
    },
    /// A triangle references a vertex that does not exist.
    #[error("{path}: triangle {triangle} references vertex {index}, but there are only {count} vertices")]
    IndexOutOfRange {
        /// The file.
        path: PathBuf,
        /// Zero-based index of the triangle (after fan triangulation).
        triangle: usize,
        /// Zero-based index of the missing vertex (saturated to `u32::MAX`).
        index: u32,
        /// Number of vertices available (for OBJ files: defined before the face).
        count: usize,
    },
    /// There is nothing to draw.
    #[error("{path}: contains no triangles")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The file is not a usable glTF 2.0 asset: not glTF at all, a truncated or malformed GLB,
    /// invalid JSON or glTF schema, a bad accessor, a node hierarchy that is not a tree, a
    /// non-finite transform, an invalid camera. `message` says what is wrong and where.
    #[error("{path}: not a valid glTF 2.0 asset: {message}")]
    Gltf {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A glTF buffer cannot be loaded (missing or unreadable file, bad `data:` URI, missing GLB
    /// binary chunk) or holds fewer bytes than its `byteLength`.
    #[error("{path}: buffer {buffer}: {message}")]
    GltfBuffer {
        /// The glTF file.
        path: PathBuf,
        /// Index of the buffer.
        buffer: usize,
        /// What is wrong.
        message: String,
    },
    /// A vertex of a glTF mesh primitive has a NaN or infinite coordinate, in the file or after
    /// the node transform.
    #[error("{path}: {primitive}: vertex {vertex} has a non-finite coordinate ({value}); NaN/Inf geometry is rejected")]
    GltfNonFinite {
        /// The file.
        path: PathBuf,
        /// Which primitive of which mesh of which node.
        primitive: String,
        /// Zero-based index of the vertex in the primitive's `POSITION` accessor.
        vertex: usize,
        /// The offending coordinate.
        value: f32,
    },
    /// A triangle of a glTF mesh primitive references a vertex that does not exist.
    #[error("{path}: {primitive}: triangle {triangle} references vertex {index}, but there are only {count} vertices")]
    GltfIndexOutOfRange {
        /// The file.
        path: PathBuf,
        /// Which primitive of which mesh of which node.
        primitive: String,
        /// Zero-based index of the triangle in the primitive (after strip/fan triangulation).
        triangle: usize,
        /// The missing vertex.
        index: u32,
        /// Number of vertices in the primitive's `POSITION` accessor.
        count: usize,
    },
    /// A light has invalid parameters (spot cone angles, negative size, range, colour, ...).
    #[error("{path}: {light}: {message}")]
    InvalidLight {
        /// The file (`<memory>` for [`SceneLight::validate`](crate::SceneLight::validate)).
        path: PathBuf,
        /// Which light (and, for glTF, which node).
        light: String,
        /// What is wrong.
        message: String,
    },
    /// An `extras.hrts` object of a glTF node or light holds a key the loader does not know.
    #[error("{path}: {owner}: unknown key \"{key}\" in extras.hrts (known keys: static, casts_shadows, radius, angular_radius)")]
    UnknownExtrasKey {
        /// The file.
        path: PathBuf,
        /// The node or light whose extras hold the key.
        owner: String,
        /// The unknown key.
        key: String,
    },
    /// An `extras.hrts` value of a glTF node or light has the wrong type or does not apply to
    /// its owner (a light size on a node without a light, a radius on a directional light, ...).
    #[error("{path}: {owner}: extras.hrts: {message}")]
    InvalidExtras {
        /// The file.
        path: PathBuf,
        /// The node or light whose extras are wrong.
        owner: String,
        /// What is wrong.
        message: String,
    },
}
