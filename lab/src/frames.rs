//! The demo's frames in the passes' terms, for the tools and tests that drive the passes directly or
//! compare with them: a view's camera and light as [`FrameInputs`], its scene as the passes' [`Geometry`],
//! and the demo's plugin frame of such inputs. The demo itself speaks the plugin's public API alone
//! ([`View::camera_matrices`], [`View::plugin_light`], [`PluginRenderer::render_light`]).

use anyhow::Result;
use demo_engine::plugin::PluginRenderer;
use demo_engine::{frame_origin, CameraMatrices, View};
use glam::Mat4;
use passes::{Draw, FrameInputs, Geometry, Light, PassError};
use rhi::Device;
use scene::Scene;

/// A view as the passes take it.
pub trait ViewInputs {
    /// Camera and light matrices of the frame (the light's fitted to the scene's bounds, as
    /// [`View::plugin_light`] gives the plugin).
    fn frame_inputs(&self) -> FrameInputs;

    /// Uploads the scene ([`upload_scene`]).
    fn upload(&self, device: &Device) -> Result<Geometry, PassError>;
}

impl ViewInputs for View {
    fn frame_inputs(&self) -> FrameInputs {
        let camera = self.camera_matrices();
        FrameInputs {
            view: camera.view,
            proj: camera.proj,
            camera_position: camera.position,
            light: Light::Directional {
                direction: self.light.direction,
                view_proj: self.light.view_proj(&self.scene.bounds()),
            },
        }
    }

    fn upload(&self, device: &Device) -> Result<Geometry, PassError> {
        upload_scene(device, &self.scene)
    }
}

/// Uploads `scene` as the passes' geometry: one draw per object, identity transforms, frame origin at
/// the centre of its bounds ([`frame_origin`], as the demo gives the plugin its buffers).
pub fn upload_scene(device: &Device, scene: &Scene) -> Result<Geometry, PassError> {
    let positions: Vec<f32> = scene.positions.iter().flat_map(|p| p.to_array()).collect();
    let draws: Vec<Draw> = scene
        .objects
        .iter()
        .map(|o| Draw {
            first_index: o.first_triangle * 3,
            index_count: o.triangle_count * 3,
            model: Mat4::IDENTITY,
            base_vertex: 0,
        })
        .collect();
    Geometry::upload(
        device,
        &positions,
        &scene.indices,
        &draws,
        frame_origin(scene),
    )
}

/// The camera of `inputs`.
pub fn camera_of(inputs: &FrameInputs) -> CameraMatrices {
    CameraMatrices {
        view: inputs.view,
        proj: inputs.proj,
        position: inputs.camera_position,
    }
}

/// The plugin's light of a light of the passes: a spot light with its given matrix, a directional one
/// with its matrix.
pub fn plugin_light(light: &Light) -> hrts::Light {
    match *light {
        Light::Directional {
            direction,
            view_proj,
        } => hrts::Light::Directional {
            direction,
            view_proj: Some(view_proj),
        },
        Light::Spot {
            position,
            direction,
            view_proj,
        } => hrts::Light::Spot {
            position,
            direction,
            frustum: hrts::SpotFrustum::Given(view_proj),
            range: None,
        },
        Light::Point { position, range } => hrts::Light::Point { position, range },
    }
}

/// The demo's plugin frame of the passes' inputs.
pub trait PluginFrames {
    /// Renders one frame of one light ([`PluginRenderer::render_light`]) given as the passes take it.
    fn render(&mut self, device: &Device, inputs: &FrameInputs) -> Result<hrts::FrameReport>;
}

impl PluginFrames for PluginRenderer {
    fn render(&mut self, device: &Device, inputs: &FrameInputs) -> Result<hrts::FrameReport> {
        self.render_light(device, &camera_of(inputs), plugin_light(&inputs.light))
    }
}
