//! What a frame shows: the scene, the camera and the sun ([`View`]), and the camera's matrices as the
//! engine draws its G-buffer with them and hands them to the plugin ([`CameraMatrices`]).

use glam::{DVec3, Mat4, Vec3};
use scene::{Camera, DirectionalLight, Scene};

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
        let camera = Camera::frame(&scene.focus_bounds(), aspect);
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
