//! What the plugin takes from Bevy's main world: cameras made ready for it, Bevy's shadow shader replaced,
//! and each frame's meshes, instances and lights extracted into the render world.

use crate::HrtsShadowMode;
use bevy::camera::visibility::{
    CascadesVisibleEntities, CubemapVisibleEntities, VisibleMeshEntities,
};
use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass};
use bevy::light::NotShadowCaster;
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;
use bevy::render::{Extract, RenderApp};
use bevy::shader::Shader;
use std::collections::{HashMap, HashSet};

/// The source of the `bevy_pbr::shadows` module the plugin puts in place of Bevy's.
const SHADOWS_WGSL: &str = include_str!("shadows.wgsl");

/// The asset path of Bevy's own `bevy_pbr::shadows` module.
const BEVY_SHADOWS: &str = "embedded://bevy_pbr/render/shadows.wgsl";

/// The path the replacement module is known by.
const OUR_SHADOWS: &str = "bevy_hrts/shadows.wgsl";

/// A 3D camera the plugin shadows: its prepasses and single-sample target are in place.
#[derive(Component)]
pub(crate) struct HrtsCamera;

/// Gives every 3D camera what the plugin reads: depth and normal prepasses, one sample per pixel.
pub(crate) fn prepare_cameras(
    mut commands: Commands,
    cameras: Query<Entity, (With<Camera3d>, Without<HrtsCamera>)>,
) {
    for camera in &cameras {
        commands
            .entity(camera)
            .insert((DepthPrepass, NormalPrepass, Msaa::Off, HrtsCamera));
    }
}

/// Empties the casters Bevy found for each light's shadow maps, so that Bevy draws no mesh into maps its
/// shader no longer reads (the plugin's module answers every shadow fetch). Bevy still clears the maps.
pub(crate) fn drop_shadow_map_casters(
    mut suns: Query<&mut CascadesVisibleEntities, With<DirectionalLight>>,
    mut points: Query<&mut CubemapVisibleEntities, With<PointLight>>,
    mut spots: Query<&mut VisibleMeshEntities, With<SpotLight>>,
) {
    for mut cascades in &mut suns {
        if cascades
            .entities
            .values()
            .flatten()
            .any(|c| !c.entities.is_empty())
        {
            cascades
                .entities
                .values_mut()
                .flatten()
                .for_each(|c| c.entities.clear());
        }
    }
    for mut faces in &mut points {
        if faces.iter().any(|f| !f.entities.is_empty()) {
            faces.iter_mut().for_each(|f| f.entities.clear());
        }
    }
    for mut casters in &mut spots {
        if !casters.entities.is_empty() {
            casters.entities.clear();
        }
    }
}

/// Texels per side of the shadow maps Bevy still allocates and clears for shadowed lights, which its
/// shader no longer reads.
const UNREAD_SHADOW_MAP_SIZE: usize = 16;

/// Keeps Bevy's (unread) shadow maps at [`UNREAD_SHADOW_MAP_SIZE`]: Bevy clears every cascade and cube face
/// each frame.
pub(crate) fn shrink_shadow_maps(
    mut directional: ResMut<bevy::light::DirectionalLightShadowMap>,
    mut point: ResMut<bevy::light::PointLightShadowMap>,
) {
    if directional.size != UNREAD_SHADOW_MAP_SIZE {
        directional.size = UNREAD_SHADOW_MAP_SIZE;
    }
    if point.size != UNREAD_SHADOW_MAP_SIZE {
        point.size = UNREAD_SHADOW_MAP_SIZE;
    }
}

/// Bevy's shadow module's handle, kept so that the plugin's module stays in its place.
#[derive(Resource)]
struct ShadowModule(Handle<Shader>);

/// Puts the plugin's `bevy_pbr::shadows` in place of Bevy's, now and whenever Bevy's is (re)loaded.
pub(crate) fn replace_shadow_shader(app: &mut App) {
    let handle = app.world().resource::<AssetServer>().load(BEVY_SHADOWS);
    app.insert_resource(ShadowModule(handle))
        .add_systems(PostUpdate, keep_shadow_module);
    if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
        render_app
            .init_resource::<ExtractedScene>()
            .add_systems(ExtractSchedule, extract_scene);
    }
}

/// Replaces the loaded `bevy_pbr::shadows` by the plugin's whenever it is not the plugin's.
fn keep_shadow_module(module: Res<ShadowModule>, mut shaders: ResMut<Assets<Shader>>) {
    let ours = shaders
        .get(&module.0)
        .map(|shader| shader.path == OUR_SHADOWS);
    if ours == Some(false) {
        // The id is the loaded module's: inserting cannot fail.
        let _ = shaders.insert(&module.0, Shader::from_wgsl(SHADOWS_WGSL, OUR_SHADOWS));
    }
}

/// A mesh asset the plugin holds: object-space positions and triangle-list indices.
pub(crate) struct MeshData {
    pub(crate) id: AssetId<Mesh>,
    pub(crate) positions: Vec<glam::Vec3>,
    pub(crate) indices: Vec<u32>,
    /// Object-space bounds of the positions (min, max), taken once per extraction of the mesh.
    pub(crate) bounds: [glam::Vec3; 2],
}

/// A light the plugin shadows, as extracted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SceneLight {
    /// The main-world entity.
    pub(crate) entity: Entity,
    /// The light for the plugin.
    pub(crate) light: hrts::Light,
    /// Emitter radius (spot and point lights), 0 for a directional light.
    pub(crate) radius: f32,
    /// The mode asked for, if not the plugin's auto.
    pub(crate) mode: Option<hrts::ShadowMode>,
}

/// The frame's scene, extracted from the main world.
#[derive(Resource, Default)]
pub(crate) struct ExtractedScene {
    /// The meshes casting shadows, each once.
    pub(crate) meshes: Vec<MeshData>,
    /// Whether `meshes` or the draws' meshes changed this frame.
    pub(crate) geometry_changed: bool,
    /// Per caster entity: its mesh (index into `meshes`) and its transform.
    pub(crate) draws: Vec<(usize, glam::Mat4)>,
    /// The main-world entities and meshes of `draws`, to tell when they change.
    draw_keys: Vec<(Entity, AssetId<Mesh>)>,
    /// Meshes the plugin could not read (not triangle lists, no positions on the CPU), and why.
    pub(crate) skipped: Vec<(AssetId<Mesh>, &'static str)>,
    /// The lights with shadows enabled.
    pub(crate) lights: Vec<SceneLight>,
}

/// glam 0.32 (Bevy's) to the workspace's glam.
pub(crate) fn mat4(m: Mat4) -> glam::Mat4 {
    glam::Mat4::from_cols_array(&m.to_cols_array())
}

/// glam 0.32 (Bevy's) to the workspace's glam.
pub(crate) fn vec3(v: Vec3) -> glam::Vec3 {
    glam::Vec3::from_array(v.to_array())
}

type Casters<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Mesh3d,
        &'static GlobalTransform,
        &'static InheritedVisibility,
    ),
    Without<NotShadowCaster>,
>;

/// The lights of one kind, with their visibility (Bevy extracts none that is not visible).
type Lights<'w, 's, L> = Query<
    'w,
    's,
    (
        Entity,
        &'static L,
        &'static GlobalTransform,
        Option<&'static HrtsShadowMode>,
        Option<&'static ViewVisibility>,
    ),
>;

/// Extracts the shadow casters and the shadowed lights.
#[allow(clippy::type_complexity)]
fn extract_scene(
    mut scene: ResMut<ExtractedScene>,
    meshes: Extract<Res<Assets<Mesh>>>,
    casters: Extract<Casters>,
    directional: Extract<Lights<DirectionalLight>>,
    points: Extract<Lights<PointLight>>,
    spots: Extract<Lights<SpotLight>>,
) {
    // Hidden entities cast no shadow, as in Bevy.
    let mut keys: Vec<(Entity, AssetId<Mesh>, glam::Mat4)> = casters
        .iter()
        .filter(|(.., visible)| visible.get())
        .map(|(e, mesh, t, _)| (e, mesh.id(), mat4(t.to_matrix())))
        .collect();
    keys.sort_by_key(|&(e, ..)| e);
    let draw_keys: Vec<(Entity, AssetId<Mesh>)> = keys.iter().map(|&(e, id, _)| (e, id)).collect();
    // A mesh that was not loaded at the last extraction casts once it is.
    let known: HashSet<AssetId<Mesh>> = (scene.meshes.iter().map(|m| m.id))
        .chain(scene.skipped.iter().map(|&(id, _)| id))
        .collect();
    let newly_loaded = draw_keys
        .iter()
        .any(|&(_, id)| !known.contains(&id) && meshes.contains(id));
    scene.geometry_changed = draw_keys != scene.draw_keys || meshes.is_changed() || newly_loaded;
    if scene.geometry_changed {
        let mut unique: Vec<AssetId<Mesh>> = draw_keys.iter().map(|&(_, id)| id).collect();
        unique.sort();
        unique.dedup();
        scene.skipped.clear();
        let mut data = Vec::new();
        for id in unique {
            match meshes.get(id).map(mesh_data) {
                Some(Ok((positions, indices))) => data.push(MeshData {
                    id,
                    bounds: positions.iter().fold(
                        [glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY],
                        |[min, max], &p| [min.min(p), max.max(p)],
                    ),
                    positions,
                    indices,
                }),
                Some(Err(why)) => scene.skipped.push((id, why)),
                // Not loaded yet: its entities cast once it is.
                None => {}
            }
        }
        scene.meshes = data;
        scene.draw_keys = draw_keys;
    }
    let ExtractedScene { meshes, draws, .. } = &mut *scene;
    let index: HashMap<AssetId<Mesh>, usize> =
        meshes.iter().enumerate().map(|(i, m)| (m.id, i)).collect();
    *draws = keys
        .iter()
        .filter_map(|&(_, id, transform)| index.get(&id).map(|&mesh| (mesh, transform)))
        .collect();
    let mut lights = Vec::new();
    for (entity, light, t, mode, visible) in &directional {
        if light.shadow_maps_enabled && visible.is_none_or(|v| v.get()) {
            lights.push(SceneLight {
                entity,
                light: hrts::Light::Directional {
                    direction: vec3(t.forward().into()),
                    view_proj: None,
                },
                radius: 0.0,
                mode: mode.map(|m| m.0).filter(|&m| m != hrts::ShadowMode::Auto),
            });
        }
    }
    for (entity, light, t, mode, visible) in &points {
        if light.shadow_maps_enabled && visible.is_none_or(|v| v.get()) {
            lights.push(SceneLight {
                entity,
                light: hrts::Light::Point {
                    position: vec3(t.translation()),
                    range: Some(light.range),
                },
                radius: light.radius,
                mode: mode.map(|m| m.0).filter(|&m| m != hrts::ShadowMode::Auto),
            });
        }
    }
    for (entity, light, t, mode, visible) in &spots {
        if light.shadow_maps_enabled && visible.is_none_or(|v| v.get()) {
            lights.push(SceneLight {
                entity,
                light: hrts::Light::Spot {
                    position: vec3(t.translation()),
                    direction: vec3(t.forward().into()),
                    frustum: hrts::SpotFrustum::Fitted {
                        outer_cone: light.outer_angle.clamp(1e-3, std::f32::consts::FRAC_PI_2),
                    },
                    range: Some(light.range),
                },
                radius: light.radius,
                mode: mode.map(|m| m.0).filter(|&m| m != hrts::ShadowMode::Auto),
            });
        }
    }
    // A stable order (the layers follow it), within the plugin's limit.
    lights.sort_by_key(|l| l.entity);
    lights.truncate(hrts::HRTS_MAX_LIGHTS as usize);
    scene.lights = lights;
}

/// The positions and triangle-list indices of a mesh kept on the CPU.
fn mesh_data(mesh: &Mesh) -> Result<(Vec<glam::Vec3>, Vec<u32>), &'static str> {
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err("not a triangle list");
    }
    let Ok(VertexAttributeValues::Float32x3(positions)) =
        mesh.try_attribute(Mesh::ATTRIBUTE_POSITION)
    else {
        return Err(
            "no Float32x3 positions in the main world (RenderAssetUsages::MAIN_WORLD keeps them)",
        );
    };
    let positions: Vec<glam::Vec3> = positions
        .iter()
        .map(|&p| glam::Vec3::from_array(p))
        .collect();
    let indices = match mesh.try_indices() {
        Ok(Indices::U16(i)) => i.iter().map(|&i| u32::from(i)).collect(),
        Ok(Indices::U32(i)) => i.clone(),
        Err(_) => (0..positions.len() as u32).collect(),
    };
    Ok((positions, indices))
}
