//! The plan of a glTF scene: which shadow each light gets, derived from what the scene declares (its
//! lights' kinds, sizes and flags, which objects move) and from what the camera sees. Pure: no GPU. The
//! plan hands each shadowed light to the plugin as it takes it ([`hrts::Light`]), so the demo is a thin
//! caller of what the plugin does for every engine.
//!
//! Per light, in this order:
//! - a light that casts no shadow, emits nothing (zero colour or intensity), or whose influence (its cone
//!   and range) misses every receiver in view gets **no pass**: it is not given to the plugin, and its
//!   visibility is 1. These decisions stay with the host: a light the plugin is never given costs
//!   nothing;
//! - every other light is given in mode **auto** with its size: its angular radius (directional) as
//!   `pcss_angular_radius`, its radius (spot, point) as `pcss_spot_radius`, 0 for a zero-size light. The
//!   plugin chooses ([`hrts::LightPlan::mode`]): a **zero-size** light gets exact ray-traced hard
//!   shadows (mode hard: no shadow map and no PCSS are allocated), a **sized** light exact soft shadows
//!   (mode area). The plan describes the passes of the mode the plugin resolves, as the plugin plans them.
//!
//! A shadowed light is one light of the plugin, given as a light, without a matrix:
//! - a directional light by its direction (`HRTS_LIGHT_TYPE_DIRECTIONAL` with no matrix): the plugin
//!   fits one orthographic frustum enclosing the scene's bounds every frame
//!   (`light_fit::directional_view_proj`, which `scene::DirectionalLight::view_proj` calls too);
//! - a spot light by its position, axis, cone and range (`HRTS_LIGHT_TYPE_SPOT` with no matrix): the
//!   plugin fits one perspective frustum to a cone up to 60°, the five cube faces around its axis to a
//!   wider one;
//! - a point light by its position and range (`HRTS_LIGHT_TYPE_POINT`): the plugin builds the six faces
//!   of a cube around it as one primitive map (hard shadows, or area shadows of a sized lamp).
//!
//! Every frame the plugin records only the frusta (a wide spot light's faces, or a light's one frustum or
//! cube map) where a caster may shadow a receiver in view within the light's range, and writes the
//! minimum over a wide spot light's faces to its layer; its frame report says which it culled and why.
//!
//! The plan gives no pass to a light none of whose frusta the plugin would record: it asks the plugin
//! ([`hrts::plan_lights`], with the shadow casters' bounds), so the plan and the frames decide alike.
//! "Nothing in view" means none of the scene's triangles is in view (not entirely outside one plane of
//! the camera frustum; occlusion is not considered).
//!
//! Shadow casters: the plugin is given the objects that cast shadows (`SceneFile::shadow_casters`); an
//! object that casts none (a floor, terrain) is drawn and receives shadows, and is a receiver in view like
//! any other.
//!
//! Caching: a light marked static sets `static_light`; any shadow caster that is not static makes the
//! geometry dynamic for every light (the plugin shares one prim buffer between its lights).

use anyhow::{bail, Context, Result};
use glam::{DVec4, Vec3};
use hrts::{Config, Faces, ShadowMode};
use hrts::{SpotFrustum, HRTS_MAX_LIGHTS};
use scene::{Camera, LightKind, LightSize, SceneFile, SceneLight};
use std::fmt::Write as _;
use std::path::Path;

/// What the plan needs besides the scene and the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanSettings {
    /// The configuration every shadowed light starts from: primitive map, shadow map size, PCSS taps and
    /// filter, hybrid blend, antialiasing. The plan sets mode auto, the light size, `static_light` and
    /// `dynamic_geometry` (and both faces in the primitive map of spot and point lights).
    pub base: Config,
    /// Frame width in pixels (with the height, the aspect of the camera's frustum).
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
}

/// Why a light gets no pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoPassReason {
    /// The scene says it casts no shadows.
    CastsNoShadows,
    /// Its colour or intensity is zero.
    EmitsNothing,
    /// No receiver is in view at all.
    NothingInView,
    /// No frustum of it may shadow a receiver in view within its range: the plugin's own culling
    /// ([`hrts::plan_lights`]), which would record nothing for it.
    OutOfView,
}

impl NoPassReason {
    /// A phrase for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Self::CastsNoShadows => "casts no shadows",
            Self::EmitsNothing => "emits nothing (zero colour or intensity)",
            Self::NothingInView => "no receiver in view",
            Self::OutOfView => "no caster may shadow a receiver in view within its range",
        }
    }
}

/// The passes of a light the plugin shadows.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowedLight {
    /// The light's configuration as the plugin is given it (mode auto, and the light's size).
    pub config: Config,
    /// The mode the plugin runs for the light: auto resolved by the light's size ([`hrts::LightPlan::mode`]).
    pub mode: ShadowMode,
    /// The passes of the light's plan, as the plugin plans them ([`hrts::LightPlan::passes`]) for the
    /// configuration it resolves ([`ShadowedLight::resolved_config`]).
    pub passes: hrts::PassMask,
    /// The resources of the light's plan, as the plugin plans them ([`hrts::LightPlan::resources`]).
    pub resources: hrts::ResourceSet,
    /// N of its primitive map, as the plugin chooses it ([`hrts::LightPlan::map_size`]; 0 without one).
    pub map_size: u32,
    /// The light as the plugin takes it.
    pub light: hrts::Light,
    /// The frusta the plugin shadows it through, by name: "whole" for one, else cube faces ("+X" ...
    /// "-Z" for a point light; "front", "right", "left", "up", "down" around a wide spot light's axis).
    pub frusta: &'static [&'static str],
}

impl ShadowedLight {
    /// Whether the plugin is given a directional light.
    pub fn is_directional(&self) -> bool {
        matches!(self.light, hrts::Light::Directional { .. })
    }

    /// The configuration the plugin builds the light's passes with: mode auto resolved by the light's size
    /// ([`ShadowedLight::mode`]).
    pub fn resolved_config(&self) -> Config {
        Config {
            mode: self.mode,
            ..self.config
        }
    }
}

/// What the plan does with a light.
#[derive(Debug, Clone, PartialEq)]
pub enum LightDecision {
    /// No pass: the light is not given to the plugin and its visibility is 1.
    NoPass(NoPassReason),
    /// Shadowed by the plugin.
    Shadowed(Box<ShadowedLight>),
}

/// The plan of one light of the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct LightPlan {
    /// The light as the scene declares it.
    pub light: SceneLight,
    /// What the plan does with it.
    pub decision: LightDecision,
}

impl LightPlan {
    /// The shadowed light, if the plugin shadows it.
    pub fn shadowed(&self) -> Option<&ShadowedLight> {
        match &self.decision {
            LightDecision::Shadowed(s) => Some(s),
            LightDecision::NoPass(_) => None,
        }
    }

    /// The decision and its reason, as a phrase: "hard (zero-size light: ...)", "no pass (...)": the mode
    /// the plugin resolves for the light, and what it computes.
    pub fn describe_decision(&self) -> String {
        let shadowed = match &self.decision {
            LightDecision::NoPass(reason) => {
                return format!("no pass ({}): visibility 1", reason.describe())
            }
            LightDecision::Shadowed(shadowed) => shadowed,
        };
        let config = shadowed.resolved_config();
        let samples = config.area_samples;
        match (config.mode, self.light.kind) {
            (ShadowMode::Hard, _) => "hard (zero-size light: exact ray-traced hard shadows; no shadow map, no PCSS)".to_owned(),
            (ShadowMode::Area, LightKind::Directional { .. }) => format!(
                "area (sized sun: exact soft shadows, the visible fraction of {samples} light samples within {} rad, each tested against the exact triangles; no shadow map)",
                config.pcss_angular_radius
            ),
            (ShadowMode::Area, kind) => format!(
                "area (sized {} light: exact soft shadows, the visible fraction of {samples} samples of its emitter of radius {} m, each tested against the exact triangles; no shadow map{})",
                if kind.direction().is_some() { "spot" } else { "point" },
                config.pcss_spot_radius,
                if shadowed.frusta.len() > 1 { ", per frustum" } else { "" }
            ),
            (mode, _) => mode.name().to_owned(),
        }
    }
}

/// One light of the plugin: a shadowed scene light.
#[derive(Debug, Clone, Copy)]
pub struct PluginLight<'a> {
    /// Index of the scene light.
    pub scene_light: usize,
    /// The light as the plugin takes it, its configuration and frusta.
    pub shadowed: &'a ShadowedLight,
}

/// The plan of a scene seen by a camera.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenePlan {
    /// Whether any shadow caster moves: the prim buffer is rebuilt every frame (and so every light-space
    /// pass).
    pub dynamic_geometry: bool,
    /// The shadow casters that are not static.
    pub moving_objects: Vec<String>,
    /// The objects that cast no shadows (drawn, receiving shadows, not given to the plugin).
    pub receivers_only: Vec<String>,
    /// Triangles of the scene in view (receivers).
    pub receivers_in_view: usize,
    /// Triangles of the scene.
    pub triangles: usize,
    /// One plan per scene light, in the scene's order.
    pub lights: Vec<LightPlan>,
}

impl ScenePlan {
    /// The plugin's lights: every shadowed light, in scene order.
    pub fn plugin_lights(&self) -> Vec<PluginLight<'_>> {
        self.lights
            .iter()
            .enumerate()
            .filter_map(|(scene_light, l)| {
                l.shadowed().map(|shadowed| PluginLight {
                    scene_light,
                    shadowed,
                })
            })
            .collect()
    }

    /// The configuration of each plugin light ([`ScenePlan::plugin_lights`] order).
    pub fn plugin_configs(&self) -> Vec<Config> {
        self.plugin_lights()
            .iter()
            .map(|l| l.shadowed.config)
            .collect()
    }

    /// The light of each plugin light for a frame, as the plugin takes it ([`ScenePlan::plugin_lights`]
    /// order).
    pub fn plugin_frame_lights(&self) -> Vec<hrts::Light> {
        self.plugin_lights()
            .iter()
            .map(|l| l.shadowed.light)
            .collect()
    }

    /// The plan as text: the geometry's caching, then per light its declaration, decision, frusta, the
    /// passes the plugin runs and the resources it allocates.
    pub fn describe(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "geometry: {}",
            if self.dynamic_geometry {
                format!(
                    "dynamic (not static: {}): the prim buffer is rebuilt, and every shadow map re-rendered, each frame",
                    self.moving_objects.join(", ")
                )
            } else {
                "static: the prim buffer is built once, and the shadow maps of static lights are kept".to_owned()
            }
        );
        if !self.receivers_only.is_empty() {
            let _ = writeln!(
                s,
                "casting no shadows (drawn and shadowed, not given to the plugin): {}",
                self.receivers_only.join(", ")
            );
        }
        let _ = writeln!(
            s,
            "receivers in view: {} of {} triangles; the primitive map of every frustum is refitted to them every frame",
            self.receivers_in_view, self.triangles
        );
        let plugin_lights = self.plugin_lights();
        let _ = writeln!(
            s,
            "lights: {}, {} shadowed by the plugin",
            self.lights.len(),
            plugin_lights.len(),
        );
        for (i, plan) in self.lights.iter().enumerate() {
            let _ = writeln!(
                s,
                "  [{i}] {}: {}",
                plan.light.name,
                describe_light(&plan.light)
            );
            let _ = writeln!(s, "      -> {}", plan.describe_decision());
            let Some(shadowed) = plan.shadowed() else {
                continue;
            };
            let index = plugin_lights
                .iter()
                .position(|l| l.scene_light == i)
                .unwrap_or_default();
            let _ = match shadowed.frusta {
                ["cube"] => writeln!(
                    s,
                    "      plugin light {index}: one cube map (its six faces built as one primitive map by the plugin; faces without a receiver in view get no grid)"
                ),
                [_] => writeln!(s, "      plugin light {index}: one frustum"),
                faces => writeln!(
                    s,
                    "      plugin light {index}: {} frusta fitted by the plugin ({}); each frame it records those holding a receiver in view within range",
                    faces.len(),
                    faces.join(", ")
                ),
            };
            let c = &shadowed.resolved_config();
            let _ = writeln!(
                s,
                "      config: {}, FXAA {}, static_light {}, dynamic_geometry {}, primitive map {}, shadow map {}",
                match (shadowed.config.mode, c.mode) {
                    (ShadowMode::Auto, ShadowMode::Area) => "auto: area (sized light)".to_owned(),
                    (ShadowMode::Auto, _) => "auto: hard (zero-size light)".to_owned(),
                    (_, mode) => format!("mode {}", mode.name()),
                },
                if shadowed.passes.contains(hrts::Pass::Fxaa) {
                    "on"
                } else {
                    "off"
                },
                c.static_light,
                c.dynamic_geometry,
                match (shadowed.map_size, c.map_size) {
                    (0, _) => "none".to_owned(),
                    (n, 0) => format!("{n}x{n} (the plugin's choice)"),
                    (n, _) => format!("{n}x{n}"),
                },
                if shadowed.resources.contains(hrts::Resource::ShadowMap) {
                    format!("{0}x{0}", c.shadow_map_size)
                } else {
                    "none".to_owned()
                }
            );
            let passes: Vec<&str> = shadowed.passes.iter().map(hrts::Pass::name).collect();
            let _ = writeln!(s, "      passes: {}", passes.join(", "));
            let resources: Vec<&str> = shadowed
                .resources
                .iter()
                .map(hrts::Resource::name)
                .collect();
            let _ = writeln!(s, "      resources: {}", resources.join(", "));
        }
        s
    }
}

/// "spot at (x, y, z) along (..), cones 0.25/0.45 rad, range 15 m, radius 0.05 m, static".
pub fn describe_light(light: &SceneLight) -> String {
    let v = |v: Vec3| format!("({:.2}, {:.2}, {:.2})", v.x, v.y, v.z);
    let range = |r: Option<f32>| r.map_or("unlimited range".to_owned(), |r| format!("range {r} m"));
    let kind = match light.kind {
        LightKind::Directional { direction } => format!("directional along {}", v(direction)),
        LightKind::Spot {
            position,
            direction,
            inner_cone,
            outer_cone,
            range: r,
        } => format!(
            "spot at {} along {}, cones {inner_cone}/{outer_cone} rad, {}",
            v(position),
            v(direction),
            range(r)
        ),
        LightKind::Point { position, range: r } => {
            format!("point at {}, {}", v(position), range(r))
        }
    };
    let size = match light.size {
        LightSize::Zero => "zero size".to_owned(),
        LightSize::AngularRadius(a) => format!("angular radius {a} rad"),
        LightSize::Radius(r) => format!("radius {r} m"),
    };
    format!(
        "{kind}, {size}, {}{}",
        if light.is_static { "static" } else { "moving" },
        if light.casts_shadows {
            ""
        } else {
            ", casts no shadows"
        }
    )
}

/// What `render --scene`, `plan --scene` and `render --obj` of a closed model ask of a scene: the frame, the
/// configuration, the camera the command line places, and whether to hold the scene still.
pub struct PlanRequest<'a> {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Where the command line places the camera (else the file's camera, else one framing the objects).
    pub camera_position: Option<Vec3>,
    /// Where the command line points the camera.
    pub camera_target: Option<Vec3>,
    /// Hold the scene still ([`held_still`]).
    pub still: bool,
    /// The configuration every shadowed light starts from ([`PlanSettings::base`]), given the scene's
    /// world-space scale ([`scene::Scene::world_space_scale`]).
    pub base: &'a dyn Fn(f32) -> Config,
}

/// A scene ready to render: the file as loaded (held still if asked), the camera it is seen through and
/// its plan through that camera.
#[derive(Debug, Clone)]
pub struct PlannedScene {
    /// The scene, its lights and flags.
    pub file: SceneFile,
    /// The camera.
    pub camera: Camera,
    /// The settings the plan was made with (frame size and base configuration).
    pub settings: PlanSettings,
    /// The plan of every light.
    pub plan: ScenePlan,
}

/// Loads the glTF 2.0 scene at `path` ([`scene::load_gltf`]) and plans it as `request` asks
/// ([`plan_file`]).
///
/// # Errors
///
/// An OBJ file (the demo loads those with `--obj`), what the loader refuses, or what [`plan_file`]
/// refuses.
pub fn load_and_plan(path: &Path, request: &PlanRequest) -> Result<PlannedScene> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
    {
        bail!(
            "{}: --scene takes a glTF 2.0 scene (.gltf or .glb); load an OBJ model with --obj",
            path.display()
        );
    }
    let file = scene::load_gltf(path)?;
    plan_file(file, request).with_context(|| format!("planning {}", path.display()))
}

/// Plans `file` as `request` asks: held still if asked ([`held_still`]), seen through the request's
/// camera or the scene's own ([`plan_view`]), with the base configuration for the scene's world-space
/// scale.
///
/// # Errors
///
/// A frame size of zero, a camera position equal to its target, or what [`plan_scene`] refuses.
pub fn plan_file(file: SceneFile, request: &PlanRequest) -> Result<PlannedScene> {
    if request.width == 0 || request.height == 0 {
        bail!("--width and --height must be positive");
    }
    let file = if request.still {
        held_still(&file)
    } else {
        file
    };
    let settings = PlanSettings {
        base: (request.base)(file.scene.world_space_scale()),
        width: request.width,
        height: request.height,
    };
    let (camera, plan) = plan_view(
        &file,
        &settings,
        request.camera_position,
        request.camera_target,
    )?;
    Ok(PlannedScene {
        file,
        camera,
        settings,
        plan,
    })
}

/// `file` held still: every object and light marked static. The demo does not animate its scenes, so
/// rendering a scene held still shows what a scene that does not move keeps from frame to frame.
pub fn held_still(file: &SceneFile) -> SceneFile {
    let mut still = file.clone();
    still.static_objects.iter_mut().for_each(|s| *s = true);
    still.lights.iter_mut().for_each(|l| l.is_static = true);
    still
}

/// The camera of a scene: the file's, else one framing its objects (the ground aside) as the demo frames
/// every scene.
pub fn scene_camera(file: &SceneFile, aspect: f32) -> Camera {
    file.camera
        .unwrap_or_else(|| Camera::frame(&file.scene.focus_bounds(), aspect))
}

/// The camera `file` is seen through (its own, else one framing its objects; moved to `position` and
/// looking at `target` where given) and the plan of the scene through it ([`plan_scene`]).
///
/// # Errors
///
/// A camera position equal to its target, or what [`plan_scene`] refuses.
pub fn plan_view(
    file: &SceneFile,
    settings: &PlanSettings,
    position: Option<Vec3>,
    target: Option<Vec3>,
) -> Result<(Camera, ScenePlan)> {
    let aspect = settings.width as f32 / settings.height.max(1) as f32;
    let camera = scene_camera(file, aspect).placed(&file.scene.bounds(), position, target)?;
    let plan = plan_scene(file, &camera, settings)?;
    Ok((camera, plan))
}

/// Derives the plan of `file` seen through `camera`.
///
/// # Errors
///
/// A frame size of zero, `static_objects` or `shadow_casters` not matching the objects, no object casting
/// shadows, or more shadowed lights than the plugin shades ([`HRTS_MAX_LIGHTS`]).
pub fn plan_scene(file: &SceneFile, camera: &Camera, settings: &PlanSettings) -> Result<ScenePlan> {
    if settings.width == 0 || settings.height == 0 {
        bail!("the frame size must be positive");
    }
    let objects = file.scene.objects.len();
    for (flags, what) in [
        (&file.static_objects, "static"),
        (&file.shadow_casters, "shadow-caster"),
    ] {
        if flags.len() != objects {
            bail!(
                "the scene has {objects} objects but {} {what} flags",
                flags.len()
            );
        }
    }
    if !file.shadow_casters.iter().any(|&c| c) {
        bail!("no object of the scene casts shadows: the plugin needs at least one caster");
    }
    let objects_where = |keep: &dyn Fn(bool, bool) -> bool| -> Vec<String> {
        file.scene
            .objects
            .iter()
            .zip(file.static_objects.iter().zip(&file.shadow_casters))
            .filter(|(_, (&is_static, &casts))| keep(is_static, casts))
            .map(|(o, _)| o.name.clone())
            .collect()
    };
    let moving_objects = objects_where(&|is_static, casts| casts && !is_static);
    let receivers_only = objects_where(&|_, casts| !casts);
    let dynamic_geometry = !moving_objects.is_empty();
    let aspect = settings.width as f32 / settings.height as f32;
    let receivers_in_view = receivers_in_view(file, camera, aspect);
    let candidates: Vec<Result<(hrts::Light, Config), NoPassReason>> = file
        .lights
        .iter()
        .map(|light| candidate(light, receivers_in_view, settings, dynamic_geometry))
        .collect();
    let (plugin_lights, configs): (Vec<hrts::Light>, Vec<Config>) =
        candidates.iter().flatten().copied().unzip();
    let casters = file.scene.objects_bounds(&file.shadow_casters);
    let view = hrts::PlanView {
        view: camera.view(),
        proj: camera.proj(aspect),
        camera_position: camera.position,
        casters: Some(hrts::Bounds {
            min: casters.min,
            max: casters.max,
        }),
    };
    // The plugin plans at most as many lights at once as one context shades.
    let chunk = HRTS_MAX_LIGHTS as usize;
    let mut planned = Vec::new();
    for (configs, lights) in configs.chunks(chunk).zip(plugin_lights.chunks(chunk)) {
        planned.extend(hrts::plan_lights(configs, lights, &view)?);
    }
    let mut planned = planned.into_iter();
    let lights: Vec<LightPlan> = file
        .lights
        .iter()
        .zip(candidates)
        .map(|(light, candidate)| {
            let decision = match candidate {
                Err(reason) => LightDecision::NoPass(reason),
                Ok((plugin_light, config)) => match planned.next() {
                    Some(p) if p.decision == hrts::LightDecision::OutOfView => {
                        LightDecision::NoPass(NoPassReason::OutOfView)
                    }
                    Some(p) => shadowed(config, plugin_light, &p),
                    None => bail!("the plugin planned fewer lights than it was given"),
                },
            };
            Ok(LightPlan {
                light: light.clone(),
                decision,
            })
        })
        .collect::<Result<_>>()?;
    let plan = ScenePlan {
        dynamic_geometry,
        moving_objects,
        receivers_only,
        receivers_in_view,
        triangles: file.scene.triangle_count(),
        lights,
    };
    let shadowed = plan.plugin_lights().len();
    if shadowed > HRTS_MAX_LIGHTS as usize {
        bail!(
            "the scene has {shadowed} shadowed lights, but the plugin shades at most {HRTS_MAX_LIGHTS} lights per context"
        );
    }
    Ok(plan)
}

/// How many of the scene's triangles are not entirely outside one plane of the camera frustum: the
/// receivers in view (none: no light needs a pass).
fn receivers_in_view(file: &SceneFile, camera: &Camera, aspect: f32) -> usize {
    let m = camera.proj(aspect).as_dmat4() * camera.view().as_dmat4();
    let (r0, r1, r2, r3) = (m.row(0), m.row(1), m.row(2), m.row(3));
    // Inside: -w <= x <= w, -w <= y <= w, 0 <= z <= w (reversed Z: z > w is nearer than the near plane).
    let planes: [DVec4; 6] = [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2];
    (0..file.scene.triangle_count())
        .filter(|&t| {
            let corners = file.scene.triangle(t).map(|v| v.as_dvec3().extend(1.0));
            !planes
                .iter()
                .any(|p| corners.iter().all(|c| p.dot(*c) < 0.0))
        })
        .count()
}

/// A light the plugin is to plan (as it takes the light, with its configuration), or why it gets no pass
/// before the plugin's culling: it casts no shadows, emits nothing, or nothing is in view at all.
fn candidate(
    light: &SceneLight,
    receivers_in_view: usize,
    settings: &PlanSettings,
    dynamic_geometry: bool,
) -> Result<(hrts::Light, Config), NoPassReason> {
    if !light.casts_shadows {
        return Err(NoPassReason::CastsNoShadows);
    }
    if light.intensity == 0.0 || light.color == Vec3::ZERO {
        return Err(NoPassReason::EmitsNothing);
    }
    if receivers_in_view == 0 {
        return Err(NoPassReason::NothingInView);
    }
    let plugin_light = match light.kind {
        // No matrix: the plugin fits the frustum to the casters' bounds.
        LightKind::Directional { direction } => hrts::Light::Directional {
            direction,
            view_proj: None,
        },
        LightKind::Spot {
            position,
            direction,
            outer_cone,
            range,
            ..
        } => hrts::Light::Spot {
            position,
            direction,
            frustum: SpotFrustum::Fitted { outer_cone },
            range,
        },
        LightKind::Point { position, range } => hrts::Light::Point { position, range },
    };
    Ok((
        plugin_light,
        light_config(light, settings, dynamic_geometry),
    ))
}

/// A light's configuration: the settings' base, mode auto with the light's size (the plugin chooses by
/// the size: hard shadows for no size, exact soft shadows (area) for a size), and its flags.
fn light_config(light: &SceneLight, settings: &PlanSettings, dynamic_geometry: bool) -> Config {
    let mut config = settings.base;
    config.dynamic_geometry = dynamic_geometry;
    config.static_light = light.is_static;
    config.mode = ShadowMode::Auto;
    let directional = matches!(light.kind, LightKind::Directional { .. });
    match light.size {
        LightSize::Zero if directional => config.pcss_angular_radius = 0.0,
        LightSize::Zero => config.pcss_spot_radius = 0.0,
        LightSize::AngularRadius(a) => config.pcss_angular_radius = a,
        LightSize::Radius(r) => config.pcss_spot_radius = r,
    }
    if !directional {
        // A front-only primitive map needs a directional light.
        config.faces = Faces::Both;
    }
    config
}

/// A light the plugin shadows as it planned it (`plan`).
fn shadowed(config: Config, plugin_light: hrts::Light, plan: &hrts::LightPlan) -> LightDecision {
    LightDecision::Shadowed(Box::new(ShadowedLight {
        config,
        mode: plan.mode,
        passes: plan.passes,
        resources: plan.resources,
        map_size: plan.map_size,
        light: plugin_light,
        frusta: plan.frustum_names,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use hrts::{Pass, Resource};
    use scene::Scene;

    /// A 10 m ground square at y = 0 and a 1 m box on it at the origin, both static.
    fn ground_and_box(lights: Vec<SceneLight>) -> SceneFile {
        let mut scene = Scene::axis_box(
            "ground",
            Vec3::new(-5.0, -0.1, -5.0),
            Vec3::new(5.0, 0.0, 5.0),
        );
        scene.append(&Scene::axis_box(
            "box",
            Vec3::new(-0.5, 0.0, -0.5),
            Vec3::new(0.5, 1.0, 0.5),
        ));
        SceneFile {
            static_objects: vec![true; scene.objects.len()],
            shadow_casters: vec![true; scene.objects.len()],
            scene,
            lights,
            camera: Some(Camera {
                position: Vec3::new(4.0, 4.0, 6.0),
                target: Vec3::ZERO,
                up: Vec3::Y,
                fov_y_radians: 0.8,
                near: 0.05,
            }),
            skipped_primitives: 0,
        }
    }

    fn light(name: &str, kind: LightKind, size: LightSize) -> SceneLight {
        let light = SceneLight {
            name: name.into(),
            kind,
            color: Vec3::ONE,
            intensity: 1.0,
            size,
            casts_shadows: true,
            is_static: true,
        };
        light.validate().expect("valid test light");
        light
    }

    fn sun(size: LightSize) -> SceneLight {
        light(
            "sun",
            LightKind::Directional {
                direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
            },
            size,
        )
    }

    fn spot(position: Vec3, direction: Vec3, outer_cone: f32, range: Option<f32>) -> SceneLight {
        light(
            "spot",
            LightKind::Spot {
                position,
                direction: direction.normalize(),
                inner_cone: outer_cone * 0.5,
                outer_cone,
                range,
            },
            LightSize::Radius(0.05),
        )
    }

    fn settings() -> PlanSettings {
        PlanSettings {
            base: Config::default(),
            width: 160,
            height: 120,
        }
    }

    fn plan(file: &SceneFile) -> ScenePlan {
        plan_scene(file, &file.camera.expect("camera"), &settings()).expect("plan")
    }

    fn only(file: SceneFile) -> LightPlan {
        let mut p = plan(&file);
        assert_eq!(p.lights.len(), 1);
        p.lights.remove(0)
    }

    #[test]
    fn a_zero_size_light_gets_hard_shadows_without_shadow_map_or_pcss() {
        let p = only(ground_and_box(vec![sun(LightSize::Zero)]));
        let s = p.shadowed().expect("shadowed");
        // Given in mode auto with no size: the plugin resolves hard shadows.
        assert_eq!(s.config.mode, ShadowMode::Auto);
        assert_eq!(s.config.pcss_angular_radius, 0.0);
        assert_eq!(s.resolved_config().mode, ShadowMode::Hard);
        assert_eq!(s.frusta, ["whole"]);
        // No matrix: the plugin fits the sun's frustum to the scene's bounds.
        assert!(
            matches!(
                s.light,
                hrts::Light::Directional {
                    view_proj: None,
                    ..
                }
            ),
            "{:?}",
            s.light
        );
        for r in [Resource::ShadowMap, Resource::Pcss] {
            assert!(!s.resources.contains(r), "{r:?}");
        }
        assert!(!s.passes.contains(Pass::ShadowMap) && !s.passes.contains(Pass::Pcss));
        assert!(s.passes.contains(Pass::RayTrace));
        assert!(p.describe_decision().starts_with("hard"));
        let file = ground_and_box(vec![sun(LightSize::Zero)]);
        let text = plan(&file).describe();
        assert!(
            text.contains("config: auto: hard (zero-size light), FXAA on"),
            "{text}"
        );
    }

    #[test]
    fn sized_suns_and_spot_lights_get_area_shadows() {
        let p = only(ground_and_box(vec![sun(LightSize::AngularRadius(0.03))]));
        let s = p.shadowed().expect("shadowed");
        assert_eq!(s.config.mode, ShadowMode::Auto);
        assert_eq!(s.resolved_config().mode, ShadowMode::Area);
        assert_eq!(s.config.pcss_angular_radius, 0.03);
        assert!(s.passes.contains(Pass::RayTrace) && !s.passes.contains(Pass::ShadowMap));
        assert!(p.describe_decision().starts_with("area"));
        let p = only(ground_and_box(vec![spot(
            Vec3::new(0.0, 4.0, 0.0),
            Vec3::NEG_Y,
            0.5,
            Some(10.0),
        )]));
        let s = p.shadowed().expect("shadowed");
        assert_eq!(s.resolved_config().mode, ShadowMode::Area);
        assert_eq!(s.config.pcss_spot_radius, 0.05);
        assert!(p.describe_decision().starts_with("area (sized spot light"));
        assert_eq!(s.config.faces, Faces::Both);
        // A fitted spot light: no matrix; the plugin fits one frustum to its cone and range.
        assert_eq!(s.frusta, ["whole"]);
        assert_eq!(
            s.light,
            hrts::Light::Spot {
                position: Vec3::new(0.0, 4.0, 0.0),
                direction: Vec3::NEG_Y,
                frustum: SpotFrustum::Fitted { outer_cone: 0.5 },
                range: Some(10.0),
            }
        );
    }

    #[test]
    fn a_light_without_shadows_or_emission_gets_no_pass() {
        let dark = SceneLight {
            casts_shadows: false,
            ..sun(LightSize::Zero)
        };
        let p = only(ground_and_box(vec![dark]));
        assert_eq!(
            p.decision,
            LightDecision::NoPass(NoPassReason::CastsNoShadows)
        );
        assert!(p.describe_decision().contains("visibility 1"));
        let black = SceneLight {
            color: Vec3::ZERO,
            ..sun(LightSize::Zero)
        };
        let p = only(ground_and_box(vec![black]));
        assert_eq!(
            p.decision,
            LightDecision::NoPass(NoPassReason::EmitsNothing)
        );
    }

    #[test]
    fn a_spot_light_missing_every_receiver_gets_no_pass() {
        // Pointing at the sky.
        let away = spot(Vec3::new(0.0, 3.0, 0.0), Vec3::Y, 0.4, None);
        let p = only(ground_and_box(vec![away]));
        assert_eq!(p.decision, LightDecision::NoPass(NoPassReason::OutOfView));
        // Pointing down, but its range ends 1 m short of the box.
        let short = spot(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y, 0.4, Some(1.0));
        let p = only(ground_and_box(vec![short]));
        assert_eq!(p.decision, LightDecision::NoPass(NoPassReason::OutOfView));
        // Pointing at ground out of view (behind the camera).
        let behind = spot(Vec3::new(4.0, 3.0, 30.0), Vec3::NEG_Y, 0.2, None);
        let mut file = ground_and_box(vec![behind]);
        file.scene.append(&Scene::axis_box(
            "far ground",
            Vec3::new(0.0, -0.1, 25.0),
            Vec3::new(8.0, 0.0, 35.0),
        ));
        file.static_objects.push(true);
        file.shadow_casters.push(true);
        let p = only(file);
        assert_eq!(p.decision, LightDecision::NoPass(NoPassReason::OutOfView));
        // Reaching the box: shadowed.
        let reaching = spot(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y, 0.4, Some(2.5));
        assert!(only(ground_and_box(vec![reaching])).shadowed().is_some());
    }

    #[test]
    fn a_camera_looking_away_leaves_nothing_in_view() {
        let mut file = ground_and_box(vec![sun(LightSize::Zero)]);
        let camera = Camera {
            position: Vec3::new(0.0, 2.0, 0.0),
            target: Vec3::new(0.0, 3.0, 0.0),
            up: Vec3::Z,
            ..file.camera.expect("camera")
        };
        file.camera = Some(camera);
        let p = plan(&file);
        assert_eq!(p.receivers_in_view, 0);
        assert_eq!(
            p.lights[0].decision,
            LightDecision::NoPass(NoPassReason::NothingInView)
        );
        assert!(p.plugin_lights().is_empty());
    }

    #[test]
    fn a_point_light_is_given_to_the_plugin_as_a_point_light() {
        let lamp = light(
            "lamp",
            LightKind::Point {
                position: Vec3::new(2.0, 1.5, 2.0),
                range: Some(20.0),
            },
            LightSize::Radius(0.1),
        );
        let p = only(ground_and_box(vec![lamp]));
        let s = p.shadowed().expect("shadowed");
        assert_eq!(
            s.light,
            hrts::Light::Point {
                position: Vec3::new(2.0, 1.5, 2.0),
                range: Some(20.0),
            }
        );
        // Area shadows of a point light: its six faces as one cube map.
        assert_eq!(s.frusta, ["cube"]);
        assert_eq!(s.resolved_config().mode, ShadowMode::Area);
        assert_eq!(s.config.pcss_spot_radius, 0.1);
        assert!(p.describe_decision().starts_with("area (sized point light"));
        // A zero-size lamp: no emitter radius, which the plugin resolves to hard shadows (one cube map).
        let small = light(
            "lamp",
            LightKind::Point {
                position: Vec3::new(2.0, 1.5, 2.0),
                range: Some(20.0),
            },
            LightSize::Zero,
        );
        let p = only(ground_and_box(vec![small]));
        let s = p.shadowed().expect("shadowed");
        assert_eq!(
            (s.config.mode, s.config.pcss_spot_radius),
            (ShadowMode::Auto, 0.0)
        );
        assert_eq!(s.resolved_config().mode, ShadowMode::Hard);
        assert_eq!(s.frusta, ["cube"]);
        assert!(p.describe_decision().starts_with("hard (zero-size light"));
        // A wide spot light: the front face and the four across its axis, no back face.
        let wide = spot(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y, 1.3, None);
        let p = only(ground_and_box(vec![wide]));
        let s = p.shadowed().expect("shadowed");
        assert_eq!(s.frusta, ["front", "right", "left", "up", "down"]);
        assert!(
            matches!(s.light, hrts::Light::Spot { range: None, .. }),
            "{:?}",
            s.light
        );
        // A lamp whose range reaches no receiver in view gets no pass.
        let far_lamp = light(
            "lamp",
            LightKind::Point {
                position: Vec3::new(0.0, 4.0, 0.0),
                range: Some(2.0),
            },
            LightSize::Zero,
        );
        let p = only(ground_and_box(vec![far_lamp]));
        assert_eq!(p.decision, LightDecision::NoPass(NoPassReason::OutOfView));
    }

    #[test]
    fn static_flags_decide_the_caching() {
        let moving = SceneLight {
            is_static: false,
            ..sun(LightSize::Zero)
        };
        let mut file = ground_and_box(vec![sun(LightSize::Zero), moving]);
        let p = plan(&file);
        assert!(!p.dynamic_geometry && p.moving_objects.is_empty());
        let configs = p.plugin_configs();
        assert_eq!(configs.len(), 2);
        assert!(configs[0].static_light && !configs[1].static_light);
        assert!(configs.iter().all(|c| !c.dynamic_geometry));
        file.static_objects[1] = false;
        let p = plan(&file);
        assert!(p.dynamic_geometry);
        assert_eq!(p.moving_objects, ["box"]);
        assert!(p.plugin_configs().iter().all(|c| c.dynamic_geometry));
        assert!(p.describe().contains("dynamic (not static: box)"));
        let p = plan(&held_still(&file));
        assert!(!p.dynamic_geometry);
        assert!(p
            .plugin_configs()
            .iter()
            .all(|c| !c.dynamic_geometry && c.static_light));
    }

    #[test]
    fn the_example_scene_plan() {
        let dir = std::env::temp_dir().join(format!("hrts-plan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("example.gltf");
        scene::gltf_scene::write_example_scene(&path).expect("write example");
        let file = scene::load_gltf(&path).expect("load example");
        let p = plan_scene(&file, &scene_camera(&file, 4.0 / 3.0), &settings()).expect("plan");
        let decisions: Vec<(&str, Option<ShadowMode>, usize)> = p
            .lights
            .iter()
            .map(|l| {
                (
                    l.light.name.as_str(),
                    l.shadowed().map(|s| s.resolved_config().mode),
                    l.shadowed().map_or(0, |s| s.frusta.len()),
                )
            })
            .collect();
        assert_eq!(
            decisions,
            [
                ("sun", Some(ShadowMode::Area), 1),
                ("rim", Some(ShadowMode::Hard), 1),
                ("spot", Some(ShadowMode::Area), 1),
                ("fill", None, 0),
                ("cart_lamp", Some(ShadowMode::Area), 1),
            ]
        );
        assert!(p.dynamic_geometry);
        assert_eq!(p.plugin_lights().len(), 4);
        let text = p.describe();
        assert!(text.contains("fill: point"), "{text}");
        assert!(text.contains("no pass (casts no shadows)"), "{text}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn more_lights_than_the_plugin_shades_is_an_error() {
        // A point light counts once.
        let lamps: Vec<SceneLight> = (0..=HRTS_MAX_LIGHTS)
            .map(|i| {
                light(
                    &format!("lamp{i}"),
                    LightKind::Point {
                        position: Vec3::new(i as f32 * 0.04 - 1.5, 0.5, 1.5),
                        range: None,
                    },
                    LightSize::Zero,
                )
            })
            .collect();
        let file = ground_and_box(lamps);
        let error = plan_scene(&file, &file.camera.expect("camera"), &settings())
            .expect_err("too many lights")
            .to_string();
        assert!(
            error.contains(&format!("at most {HRTS_MAX_LIGHTS}")),
            "{error}"
        );
        let mut mismatched = ground_and_box(Vec::new());
        mismatched.static_objects.pop();
        assert!(plan_scene(
            &mismatched,
            &mismatched.camera.expect("camera"),
            &settings()
        )
        .is_err());
        let mut mismatched = ground_and_box(Vec::new());
        mismatched.shadow_casters.pop();
        let error = plan_scene(
            &mismatched,
            &mismatched.camera.expect("camera"),
            &settings(),
        )
        .expect_err("a flag missing")
        .to_string();
        assert!(error.contains("1 shadow-caster flags"), "{error}");
    }

    #[test]
    fn objects_that_cast_no_shadows_are_receivers_only() {
        let mut file = ground_and_box(vec![sun(LightSize::Zero)]);
        file.shadow_casters[0] = false;
        // The ground casts nothing: it moving does not make the plugin's geometry dynamic, and it still
        // receives (the sun is shadowed).
        file.static_objects[0] = false;
        let p = plan(&file);
        assert!(!p.dynamic_geometry && p.moving_objects.is_empty());
        assert_eq!(p.receivers_only, ["ground"]);
        assert!(p.lights[0].shadowed().is_some());
        let text = p.describe();
        assert!(
            text.contains(
                "casting no shadows (drawn and shadowed, not given to the plugin): ground"
            ),
            "{text}"
        );
        file.shadow_casters[1] = false;
        let error = plan_scene(&file, &file.camera.expect("camera"), &settings())
            .expect_err("no caster")
            .to_string();
        assert!(
            error.contains("no object of the scene casts shadows"),
            "{error}"
        );
    }
}
