//! The demo's engine in miniature, as an engine has its own before it adds the plugin: a Vulkan device
//! (through `rhi`, [`device`]), the scene's vertex and index buffers ([`scene_buffers`]), a G-buffer drawn
//! by its own shaders ([`gbuffer`], in `demo_engine/shaders/`, embedded at build time) and read-backs
//! ([`frame_images`]). [`plugin`] adds the shadows the way an integrator does: through the plugin's safe
//! Rust API over its C ABI ([`hrts`]), naming nothing of its passes.
//!
//! The demo program (`host_demo`: command line, images, reports), the lab (`hrts_lab`) and the tests
//! render through this crate, so what the tests check is what the demo shows.

pub mod device;
pub mod frame_images;
pub mod gbuffer;
pub mod plugin;
pub mod scene_buffers;
pub mod view;

pub use device::{check_validation, open_device, Device, DeviceSummary};
pub use frame_images::{read_images, FrameImages, FrameOutput};
pub use view::{frame_origin, CameraMatrices, View};
