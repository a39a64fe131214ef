//! The standalone demo host as a library: scene setup shared by the `host_demo` binary, the lab
//! (`hrts_lab`) and the integration tests, so that what the tests check is what the demo shows.
//!
//! The demo is an engine in miniature on the plugin's public API ([`hrts`]): its own device (through
//! `rhi`, as an engine has its own), scene buffers ([`scene_buffers`]) and G-buffer ([`gbuffer`], shaders
//! in `host_demo/shaders/` embedded at build time), and the plugin driven through the safe Rust API over
//! the C ABI ([`plugin`]). It names nothing of the passes: the tools that look inside them are the lab's,
//! and the frame that drives one pipeline of the passes directly, which the tests compare the plugin
//! with, is the `test_support` crate's.
//!
//! A glTF scene's lights decide its shadows: [`scene_plan`] derives, without a GPU, which shadow each
//! light gets and through which frusta; [`scene_render`] renders them through the plugin and reports per
//! light what ran, what was kept and why; [`shading`] sums the lights into the shaded image.

pub mod cli;
pub mod gbuffer;
pub mod images;
pub mod interior;

/// Limits of the command line's options, checked before any GPU work.
pub mod limits {
    /// Largest frame (or shadow map) side in pixels.
    pub const FRAME_SIDE: u32 = 16384;
    /// Largest primitive map size N (texel coordinates are packed in 16 bits).
    pub const MAP_SIZE: u32 = u16::MAX as u32;
}
pub mod load_report;
pub mod output;
pub mod plugin;
pub mod progress;
pub mod render;
pub mod renderer;
pub mod scene_buffers;
pub mod scene_plan;
pub mod scene_render;
pub mod shading;

use glam::{DVec3, Mat4, Vec3};
use rhi::Device;
use scene::{Aabb, Camera, DirectionalLight, Scene};

pub use progress::progress;
pub use renderer::{read_images, FrameImages, FrameOutput};

mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

/// SPIR-V words of the demo's embedded shader `name` (file name in `host_demo/shaders/`).
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

/// Parses "x,y,z" into a vector.
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected x,y,z (three numbers, such as -5,2,3) but got '{s}'"
        ));
    };
    let f = |v: &str| {
        v.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{v}' is not a finite number"))
    };
    Ok(Vec3::new(f(x)?, f(y)?, f(z)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_vectors() {
        assert_eq!(parse_vec3("1, 2,3").unwrap(), Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(
            parse_vec3("-5,-0.5,-1e2").unwrap(),
            Vec3::new(-5.0, -0.5, -100.0)
        );
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,nan,2").is_err());
        assert!(parse_vec3("a,b,c").is_err());
    }

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
