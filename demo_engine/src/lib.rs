//! The demo's engine in miniature, as an engine has its own before it adds the plugin: a Vulkan device
//! (through `rhi`), the scene's vertex and index buffers ([`scene_buffers`]), a G-buffer drawn by its own
//! shaders ([`gbuffer`], in `demo_engine/shaders/`, embedded at build time) and read-backs
//! ([`frame_images`]). [`plugin`] adds the shadows the way an integrator does: through the plugin's safe
//! Rust API over its C ABI ([`hrts`]), naming nothing of its passes.
//!
//! The demo program (`host_demo`: command line, images, reports), the lab (`hrts_lab`) and the tests
//! render through this crate, so what the tests check is what the demo shows.

pub mod frame_images;
pub mod gbuffer;
pub mod plugin;
pub mod scene_buffers;

use glam::{DVec3, Mat4, Vec3};
use scene::{Aabb, Camera, DirectionalLight, Scene};

pub use frame_images::{read_images, FrameImages, FrameOutput};
/// The engine's GPU device: the RHI's, opened by [`open_device`].
pub use rhi::Device;

mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

/// SPIR-V words of the engine's embedded shader `name` (file name in `demo_engine/shaders/`).
pub fn shader(name: &str) -> Result<Vec<u32>, rhi::RhiError> {
    shaders::spirv(name)
        .ok_or_else(|| rhi::RhiError::InvalidArgument(format!("no embedded shader named {name}")))
}

/// A scene with its camera and light, ready to render.
#[derive(Debug, Clone)]
pub struct View {
    /// The geometry.
    pub scene: Scene,
    /// The camera.
    pub camera: Camera,
    /// The light.
    pub light: DirectionalLight,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
}

impl View {
    /// Frames `scene` automatically: the camera looks at its objects (the ground plane aside) from a slanted
    /// elevated direction, and a slanted directional light shines on it.
    pub fn framed(scene: Scene, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        let camera = Camera::frame(&focus_bounds(&scene), aspect);
        Self {
            scene,
            camera,
            light: DirectionalLight::slanted(),
            width,
            height,
        }
    }

    /// The camera of the frame.
    pub fn camera_matrices(&self) -> CameraMatrices {
        CameraMatrices::of_camera(&self.camera, self.width, self.height)
    }

    /// The light as the plugin takes it: the directional light with its matrix fitted to the scene's
    /// bounds.
    pub fn plugin_light(&self) -> hrts::Light {
        hrts::Light::Directional {
            direction: self.light.direction,
            view_proj: Some(self.light.view_proj(&self.scene.bounds())),
        }
    }

    /// The frame origin of the scene ([`frame_origin`]).
    pub fn frame_origin(&self) -> DVec3 {
        frame_origin(&self.scene)
    }
}

/// The frame origin of `scene`: the centre of its bounds in f32, as the plugin derives it from the bounds
/// an engine passes (`HrtsVulkanGeometry::bounds`).
pub fn frame_origin(scene: &Scene) -> DVec3 {
    scene.bounds().center().as_dvec3()
}

/// The camera of a frame as the engine hands it to the plugin and draws its G-buffer with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraMatrices {
    /// World to view.
    pub view: Mat4,
    /// View to clip: reversed Z, Vulkan conventions.
    pub proj: Mat4,
    /// Camera position in world space.
    pub position: Vec3,
}

impl CameraMatrices {
    /// The matrices of `camera` for a `width` x `height` frame.
    pub fn of_camera(camera: &Camera, width: u32, height: u32) -> Self {
        Self {
            view: camera.view(),
            proj: camera.proj(width as f32 / height.max(1) as f32),
            position: camera.position,
        }
    }
}

/// Bounds of every object but one named "ground" (all of the scene if that is all there is).
pub fn focus_bounds(scene: &Scene) -> Aabb {
    let mut b = Aabb::empty();
    for o in scene.objects.iter().filter(|o| o.name != GROUND) {
        for t in o.first_triangle..o.first_triangle + o.triangle_count {
            for v in scene.triangle(t as usize) {
                b.extend(v);
            }
        }
    }
    if b.min.cmple(b.max).all() {
        b
    } else {
        scene.bounds()
    }
}

const GROUND: &str = "ground";

/// Opens the device the command line asks for: a name filter (else `HRTS_DEVICE`), validation layers if
/// `validation` (or `HRTS_VALIDATION=1`), with their synchronization validation, whose hazards count as
/// validation errors.
pub fn open_device(filter: Option<String>, validation: bool) -> anyhow::Result<Device> {
    let mut desc = rhi::DeviceDesc::from_env();
    desc.validation |= validation;
    desc.synchronization_validation = desc.validation;
    if filter.is_some() {
        desc.device_filter = filter;
    }
    Ok(Device::new_headless(&desc)?)
}

/// Fails if the validation layers reported errors on `device`.
pub fn check_validation(device: &Device) -> anyhow::Result<()> {
    let errors = device.validation().errors();
    if errors > 0 {
        anyhow::bail!(
            "{errors} Vulkan validation errors (first: {:?})",
            device.validation().messages().first()
        );
    }
    Ok(())
}

/// What a device is, as the demo's reports name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeviceSummary {
    /// The device's name ("llvmpipe (LLVM 19.1.7, 256 bits)", "NVIDIA H100 80GB HBM3").
    pub name: String,
    /// The driver's name and version.
    pub driver: String,
    /// The Vulkan version the device offers.
    pub api_version: String,
    /// CPU, integrated, discrete…
    pub device_type: String,
}

impl DeviceSummary {
    /// The summary of `device`.
    pub fn of(device: &Device) -> Self {
        let caps = device.capabilities();
        Self {
            name: caps.device_name.clone(),
            driver: caps.driver.clone(),
            api_version: caps.api_version.clone(),
            device_type: caps.device_type.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--validation` (and `HRTS_VALIDATION=1`) brings synchronization validation along.
    #[test]
    fn a_validated_device_has_synchronization_validation() {
        let device = open_device(None, true).expect("a device with validation layers");
        assert!(device.synchronization_validation().is_some());
        assert_eq!(device.validation().errors(), 0);
    }

    #[test]
    fn every_demo_shader_is_embedded_spirv() {
        let names: Vec<&str> = shaders::ALL.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "gbuffer.frag",
                "gbuffer.vert",
                "gbuffer_compact.frag",
                "gbuffer_encoded.frag"
            ]
        );
        for n in names {
            let words = shader(n).unwrap();
            assert!(words.len() > 5, "{n} is too short for a SPIR-V module");
            assert_eq!(words[0], 0x0723_0203, "{n} lacks the SPIR-V magic number");
        }
        assert!(shader("gbuffer.comp").is_err());
    }
}
