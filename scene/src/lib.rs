//! Scene geometry for the hybrid ray-traced shadows demo.
//!
//! - [`Scene`]: a world-space triangle soup with shared vertices and named draw ranges
//!   ([`Object`]s), validated by [`Scene::validate`];
//! - [`load_obj`]: Wavefront OBJ loading that rejects malformed, non-finite and out-of-range
//!   content with a [`SceneError`] naming the file, and never panics;
//! - [`load_gltf`]: glTF 2.0 loading ([`gltf_scene`]): geometry, [`SceneLight`]s with sizes and
//!   static/shadow flags, static objects and the camera, as a [`SceneFile`];
//! - [`procedural_default`]: the built-in demo scene of shadow-mapping trouble makers;
//! - [`Camera`] and [`DirectionalLight`]: view and projection matrices that frame a scene;
//! - [`MeshBuilder`]: the builder of boxes, quads, triangles, spheres and lathes that every
//!   generated mesh is made with;
//! - [`SplitMix64`]: the small deterministic pseudo-random generator used wherever the workspace
//!   needs reproducible random numbers;
//! - [`hard_cases`]: the deterministic hard numerical cases ([`HardCase`]) of the shadow renderer.
//!
//! Conventions: right-handed world in metres with +Y up; triangles wind counter-clockwise seen
//! from their front side; a light direction is the unit vector along which the light travels;
//! projections follow Vulkan (depth range `[0, 1]`, no y flip in the matrices).

#![forbid(unsafe_code)]

pub use glam;

mod aabb;
mod camera;
mod error;
pub mod gltf_scene;
pub mod hard_cases;
mod light;
mod mesh_builder;
mod models;
mod obj;
mod procedural;
mod random;
mod scene;
mod scene_light;

pub use aabb::Aabb;
pub use camera::{Camera, CoincidentCamera};
pub use error::SceneError;
pub use gltf_scene::{load_gltf, SceneFile};
pub use hard_cases::HardCase;
pub use light::DirectionalLight;
pub use mesh_builder::MeshBuilder;
pub use models::{models_dir, models_folder, MODELS_ENV};
pub use obj::load_obj;
pub use procedural::procedural_default;
pub use random::SplitMix64;
pub use scene::{Object, Scene};
pub use scene_light::{LightKind, LightSize, SceneLight};
