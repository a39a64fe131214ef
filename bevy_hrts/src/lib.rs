//! Exact ray-traced shadows in Bevy's own PBR lighting, in place of its shadow maps.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_hrts::HrtsShadowsPlugin;
//!
//! App::new()
//!     // Before DefaultPlugins: the plugin adds two Vulkan 1.3 features to the device Bevy creates.
//!     .add_plugins((HrtsShadowsPlugin::default(), DefaultPlugins))
//!     .run();
//! ```
//!
//! Every `DirectionalLight`, `PointLight` and `SpotLight` whose `shadow_maps_enabled` is set is shadowed by
//! the plugin: hard shadows for a light of no size, exact soft (area) shadows for a point or spot light with
//! a `radius` (the plugin's mode auto; [`HrtsShadowMode`] chooses per light). Bevy's PBR shader reads each
//! light's visibility where it read its shadow map; materials are unchanged.
//!
//! What the plugin takes from Bevy, as Bevy holds it:
//! - the device Bevy creates (through `RawVulkanInitSettings`, with `synchronization2` and
//!   `dynamicRendering` added);
//! - the camera's depth and normal prepasses (the plugin adds `DepthPrepass`, `NormalPrepass` and
//!   `Msaa::Off` to every 3D camera: its passes read single-sample depth and normals);
//! - the meshes' positions and indices from their `Mesh` assets, and each entity's `GlobalTransform`
//!   every frame (a moved entity moves its shadow).
//!
//! Limits of this version: one camera (of the 3D cameras with the prepasses and no `Viewport`, the one with
//! the lowest `Camera::order`; the others read these lights as unshadowed); skinned and morphed meshes
//! cast their rest pose; Bevy draws no mesh into its own shadow maps of these lights, but still allocates
//! (at 16² texels) and clears them; volumetric fog is not lit by these lights.

mod device;
mod extract;
mod render;

pub use render::{HrtsCapture, HrtsVisibility};

use bevy::prelude::*;

/// How the plugin shadows one light, in place of [`hrts::ShadowMode::Auto`] (hard for a light of no size,
/// area for a sized one): add it to a light entity.
#[derive(Component, Debug, Clone, Copy, PartialEq)]
pub struct HrtsShadowMode(pub hrts::ShadowMode);

/// The plugin: add it before `DefaultPlugins` (it adds to the device Bevy creates).
#[derive(Debug, Clone, Default)]
pub struct HrtsShadowsPlugin {
    /// The configuration every light starts from (`mode` and the light's size are set per light).
    pub config: Option<hrts::Config>,
}

/// What the plugin did in the last frame it recorded, for hosts and tests: readable in the main world.
#[derive(Resource, Debug, Clone, Default)]
pub struct HrtsStatus {
    /// Frames the plugin recorded.
    pub frames: u64,
    /// The lights it shadowed in the last one, in layer order: the main-world light entities.
    pub lights: Vec<Entity>,
    /// The last error, if the plugin could not shadow a frame (its lights are then lit).
    pub error: Option<String>,
    /// GPU milliseconds of the plugin's passes (all lights) in the last frame the GPU completed and the
    /// plugin could read the timings of (`None` before, or on a device without timestamp queries).
    pub gpu_milliseconds: Option<f64>,
    /// GPU milliseconds from a timestamp before the plugin's first pass to one after the copy into the
    /// depth array Bevy's shader reads, in the last frame timed: the passes, the waits between them and
    /// the copy (the first timestamp also waits for the GPU work before it). `None` before, or on a
    /// device that writes no timestamps inside command encoders.
    pub gpu_span_milliseconds: Option<f64>,
    /// Meshes that cast no shadow because the plugin could not read them (not a triangle list, or no
    /// positions kept in the main world), and why.
    pub skipped_meshes: Vec<String>,
}

/// Bevy's `DefaultPlugins` set to render without a window on Vulkan (into images, as headless tests and
/// captures do), each pipeline compiled before the frame that needs it.
pub fn headless_default_plugins() -> bevy::app::PluginGroupBuilder {
    use bevy::render::settings::{Backends, RenderCreation, WgpuSettings};
    DefaultPlugins
        .set(WindowPlugin {
            primary_window: None,
            exit_condition: bevy::window::ExitCondition::DontExit,
            close_when_requested: false,
            ..default()
        })
        .set(bevy::render::RenderPlugin {
            render_creation: RenderCreation::Automatic(Box::new(WgpuSettings {
                backends: Some(Backends::VULKAN),
                ..default()
            })),
            synchronous_pipeline_compilation: true,
            ..default()
        })
}

impl Plugin for HrtsShadowsPlugin {
    fn build(&self, app: &mut App) {
        assert!(
            !app.is_plugin_added::<bevy::render::RenderPlugin>(),
            "add HrtsShadowsPlugin before DefaultPlugins (or RenderPlugin): it adds two Vulkan 1.3 \
             features to the device Bevy creates"
        );
        let enabled = device::request_plugin_features(app);
        let status = render::SharedStatus::default();
        app.insert_resource(HrtsStatus::default())
            .insert_resource(HrtsCapture::default())
            .insert_resource(render::PluginSettings {
                config: self.config.unwrap_or_default(),
                enabled,
                status: status.clone(),
            })
            .add_systems(
                PostUpdate,
                (
                    extract::prepare_cameras,
                    render::publish_status(status),
                    extract::drop_shadow_map_casters
                        .after(bevy::light::SimulationLightSystems::CheckLightVisibility),
                    extract::shrink_shadow_maps,
                ),
            );
    }

    fn finish(&self, app: &mut App) {
        extract::replace_shadow_shader(app);
        render::add_render_systems(app);
    }
}
