//! A small deferred renderer on `wgpu`, not shaped around the plugin, that adds the plugin's shadows:
//! wgpu's own device (opened with two extra Vulkan 1.3 features), depth format, normal target and mesh
//! buffers handed over as they are through wgpu-hal's Vulkan interop, and the plugin's passes recorded into
//! a wgpu command encoder. Everything plugin-specific is in [`hrts_wgpu`].

pub mod conventions;
pub mod meshes;
pub mod renderer;
pub mod validation;

pub use conventions::{Conventions, DepthDirection, IndexType, NormalTarget};
pub use renderer::{Frame, Gpu, Renderer};
