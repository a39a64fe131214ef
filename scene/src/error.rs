//! The error type shared by OBJ loading and scene validation.

use std::path::PathBuf;

/// Path reported in errors about scenes that were not loaded from a file.
pub(crate) const MEMORY_PATH: &str = "<memory>";

/// Why a scene could not be loaded or failed [`Scene::validate`](crate::Scene::validate).
///
/// Every variant names the offending file; scenes built in memory use the path `<memory>`.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
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
}
