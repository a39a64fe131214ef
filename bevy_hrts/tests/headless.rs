//! A Bevy app on the Vulkan device the tests run on (lavapipe in CI), headless: a ground, a box above it,
//! a sun and a point light, shadowed by `HrtsShadowsPlugin` with its one line. The visibility Bevy's PBR
//! lighting reads equals the exact CPU reference on every stable pixel, for both lights, before and after
//! the box moves. The sun is red and the point light green: the image's red channel shows the sun's
//! shadow and its green channel the point light's, so each light is seen to read its own layer.

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::mesh::{Indices, VertexAttributeValues};
use bevy::prelude::*;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy_hrts::{HrtsCapture, HrtsShadowsPlugin, HrtsStatus, HrtsVisibility};
use glam::{DMat4, DVec3};
use hrts_lab::accuracy::compare_with_reference;
use reference::{reference_visibility, Light, RefScene, VisibilityParams};
use std::sync::{Arc, Mutex};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

/// The box that moves.
#[derive(Component)]
struct Caster;

/// The image the camera renders into.
#[derive(Resource)]
struct Target(Handle<Image>);

fn app() -> App {
    let mut app = App::new();
    app.add_plugins((
        // Hard shadows as the rays give them, without FXAA: exact per pixel.
        HrtsShadowsPlugin {
            config: Some(hrts::Config {
                antialiasing: false,
                ..hrts::Config::default()
            }),
        },
        bevy_hrts::headless_default_plugins(),
    ))
    .add_systems(Startup, setup);
    app
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
) {
    let material = materials.add(StandardMaterial::default());
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(12.0, 12.0))),
        MeshMaterial3d(material.clone()),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Cuboid::new(1.0, 1.0, 1.0))),
        MeshMaterial3d(material),
        Transform::from_xyz(0.3, 1.2, -0.4).with_rotation(Quat::from_rotation_y(0.5)),
        Caster,
    ));
    commands.spawn((
        DirectionalLight {
            shadow_maps_enabled: true,
            color: Color::srgb(1.0, 0.0, 0.0),
            ..default()
        },
        Transform::from_xyz(3.0, 8.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        PointLight {
            shadow_maps_enabled: true,
            color: Color::srgb(0.0, 1.0, 0.0),
            range: 30.0,
            ..default()
        },
        Transform::from_xyz(-2.0, 3.5, 1.5),
    ));
    let mut image = Image::new_target_texture(WIDTH, HEIGHT, TextureFormat::Rgba8UnormSrgb, None);
    // Read back after rendering.
    image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    let target = images.add(image);
    commands.insert_resource(Target(target.clone()));
    commands.spawn((
        Camera3d::default(),
        // Linear and clamped: no tone curve between the lighting and the image.
        Tonemapping::None,
        RenderTarget::Image(target.into()),
        Transform::from_xyz(0.0, 5.0, 9.0).looking_at(Vec3::new(0.0, 0.5, 0.0), Vec3::Y),
    ));
}

/// Updates `app` until the plugin has recorded `frames` more frames, then reads back the visibility of one.
fn run_frames(app: &mut App, frames: u64) -> HrtsVisibility {
    let start = app.world().resource::<HrtsStatus>().frames;
    let capture = app.world().resource::<HrtsCapture>().clone();
    for _ in 0..400 {
        app.update();
        let status = app.world().resource::<HrtsStatus>();
        assert_eq!(status.error, None, "the plugin failed");
        if status.frames >= start + frames {
            capture.request();
            for _ in 0..8 {
                app.update();
                if let Some(visibility) = capture.take() {
                    return visibility.expect("read back");
                }
            }
            panic!("no read-back in 8 updates");
        }
    }
    panic!("the plugin recorded no frames in 400 updates");
}

/// The scene's triangles in world space, as the main world holds them.
fn world_scene(app: &mut App) -> scene::Scene {
    let mut query = app.world_mut().query::<(&Mesh3d, &GlobalTransform)>();
    let world = app.world();
    let meshes = world.resource::<Assets<Mesh>>();
    let mut out = scene::Scene::default();
    for (mesh, transform) in query.iter(world) {
        let mesh = meshes.get(&mesh.0).expect("a loaded mesh");
        let Some(VertexAttributeValues::Float32x3(positions)) =
            mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            panic!("positions");
        };
        let indices: Vec<u32> = match mesh.indices() {
            Some(Indices::U16(i)) => i.iter().map(|&i| u32::from(i)).collect(),
            Some(Indices::U32(i)) => i.clone(),
            None => (0..positions.len() as u32).collect(),
        };
        let m = transform.to_matrix();
        let positions = positions
            .iter()
            .map(|&p| glam::Vec3::from_array(m.transform_point3(Vec3::from_array(p)).to_array()))
            .collect();
        out.append(&scene::Scene::single_object(positions, indices, "mesh"));
    }
    out
}

fn dmat4(m: Mat4) -> DMat4 {
    glam::Mat4::from_cols_array(&m.to_cols_array()).as_dmat4()
}

/// Mismatches of each shadowed light's visibility against the exact reference, with the stable pixels
/// compared.
fn mismatches(
    app: &mut App,
    visibility: &HrtsVisibility,
) -> (Vec<(String, usize, usize)>, Vec<bool>) {
    let scene = world_scene(app);
    let rs = RefScene::new(&scene);
    let lights = app.world().resource::<HrtsStatus>().lights.clone();
    let view = dmat4(visibility.view);
    let proj = dmat4(visibility.proj);
    let bounds = scene.bounds();
    let camera_position = view.inverse().transform_point3(DVec3::ZERO);
    let magnitude =
        f64::from(bounds.radius()).max((camera_position - bounds.center().as_dvec3()).length());
    // 1 / tan(fov_y / 2) is the projection's [1][1].
    let pixel_angle = 2.0 / proj.y_axis.y.abs() / f64::from(visibility.height);
    let mut ground = Vec::new();
    let counts = lights
        .iter()
        .zip(&visibility.layers)
        .map(|(&entity, layer)| {
            let world = app.world();
            let (name, light) = if let Some(t) = world
                .get::<DirectionalLight>(entity)
                .and(world.get::<GlobalTransform>(entity))
            {
                let d = t.forward();
                (
                    "sun",
                    Light::Directional {
                        direction: DVec3::new(d.x.into(), d.y.into(), d.z.into()),
                    },
                )
            } else {
                let p = world
                    .get::<GlobalTransform>(entity)
                    .expect("a light")
                    .translation();
                (
                    "point light",
                    Light::Point {
                        position: DVec3::new(p.x.into(), p.y.into(), p.z.into()),
                    },
                )
            };
            let params = VisibilityParams {
                width: visibility.width,
                height: visibility.height,
                view_proj: proj * view,
                camera_position,
                light,
                tolerance: 64.0 * f64::from(f32::EPSILON) * magnitude,
                tolerance_per_distance: pixel_angle / 16.0,
                pixel_tolerance: 1.0 / 128.0,
            };
            let r = reference_visibility(&rs, &params);
            // The ground is the plane y = 0.
            ground = r.position.iter().map(|p| p.y.abs() < 1e-4).collect();
            let c = compare_with_reference(&r, layer, None, None);
            let stable = r
                .class
                .iter()
                .filter(|&&c| c != reference::PixelClass::Ambiguous)
                .count();
            println!(
                "{name}: {} mismatches of {stable} stable pixels ({} lit, {} shadowed)",
                c.mismatches,
                layer.iter().filter(|&&v| v == 1.0).count(),
                layer.iter().filter(|&&v| v == 0.0).count()
            );
            (name.to_owned(), c.mismatches, stable)
        })
        .collect();
    (counts, ground)
}

/// The camera's image, read back: RGB per pixel, row by row from the top.
fn rendered_image(app: &mut App) -> Vec<[u8; 3]> {
    let target = app.world().resource::<Target>().0.clone();
    let data: Arc<Mutex<Option<Vec<u8>>>> = Arc::default();
    let sink = data.clone();
    app.world_mut().spawn(Readback::texture(target)).observe(
        move |readback: On<ReadbackComplete>, mut commands: Commands| {
            *sink.lock().unwrap() = Some(readback.data.clone());
            commands.entity(readback.entity).despawn();
        },
    );
    for _ in 0..8 {
        app.update();
        if let Some(bytes) = data.lock().unwrap().take() {
            let stride = bytes.len() / HEIGHT as usize;
            return bytes
                .chunks(stride)
                .flat_map(|row| {
                    row[..WIDTH as usize * 4]
                        .chunks(4)
                        .map(|p| [p[0], p[1], p[2]])
                })
                .collect();
        }
    }
    panic!("no image read back in 8 updates");
}

/// Checks that Bevy's lighting darkens exactly the ground pixels (`ground`) each light's layer shadows, in
/// that light's colour channel: red for the sun, green for the point light (`names`, in layer order, say
/// which layer is which). Every shadowed ground pixel is darker in the channel than every lit one.
fn check_lighting(
    image: &[[u8; 3]],
    visibility: &HrtsVisibility,
    names: &[String],
    ground: &[bool],
) {
    for (name, layer) in names.iter().zip(&visibility.layers) {
        let channel = match name.as_str() {
            "sun" => 0,
            "point light" => 1,
            other => panic!("no colour for {other}"),
        };
        // (min, max) of the channel over the shadowed and over the lit ground pixels.
        let mut range = [(u8::MAX, 0u8); 2];
        for (i, pixel) in image.iter().enumerate().filter(|&(i, _)| ground[i]) {
            let r = &mut range[usize::from(layer[i] == 1.0)];
            *r = (r.0.min(pixel[channel]), r.1.max(pixel[channel]));
        }
        println!("{name}: ground channel (min, max), shadowed then lit: {range:?}");
        let [shadowed, lit] = range;
        assert!(
            shadowed.0 <= shadowed.1 && lit.0 <= lit.1,
            "{name}: a class of pixels is missing: {range:?}"
        );
        assert!(lit.0 > shadowed.1, "{name}: {range:?}");
    }
}

/// The meshes Bevy would draw into its own shadow maps of the sun and the point light (whose casters Bevy
/// found; the plugin empties them, since its module answers every shadow fetch).
fn bevy_shadow_map_casters(app: &mut App) -> usize {
    use bevy::camera::visibility::{CascadesVisibleEntities, CubemapVisibleEntities};
    let world = app.world_mut();
    let sun_lists = world
        .query::<&CascadesVisibleEntities>()
        .iter(world)
        .count();
    let point_lists = world.query::<&CubemapVisibleEntities>().iter(world).count();
    assert_eq!((sun_lists, point_lists), (1, 1), "Bevy's caster lists");
    let suns: usize = world
        .query::<&CascadesVisibleEntities>()
        .iter(world)
        .flat_map(|c| c.entities.values().flatten())
        .map(|c| c.entities.len())
        .sum();
    let points: usize = world
        .query::<&CubemapVisibleEntities>()
        .iter(world)
        .flat_map(|c| c.iter())
        .map(|c| c.entities.len())
        .sum();
    suns + points
}

#[test]
fn bevy_lights_get_the_exact_shadow_where_their_shadow_maps_were_read() {
    let mut app = app();
    app.finish();
    app.cleanup();
    let first = run_frames(&mut app, 3);
    assert_eq!((first.width, first.height), (WIDTH, HEIGHT));
    assert_eq!(first.layers.len(), 2, "a sun and a point light");
    let (counts, ground) = mismatches(&mut app, &first);
    let names: Vec<String> = counts.iter().map(|(name, ..)| name.clone()).collect();
    for (name, wrong, stable) in counts {
        assert!(
            stable > WIDTH as usize * HEIGHT as usize / 2,
            "{name}: {stable} stable pixels"
        );
        assert_eq!(wrong, 0, "{name}");
    }
    // Both lights cast a shadow of the box on the ground, and Bevy's lighting shows it.
    for layer in &first.layers {
        assert!(layer.contains(&0.0) && layer.contains(&1.0));
    }
    let image = rendered_image(&mut app);
    check_lighting(&image, &first, &names, &ground);
    assert_eq!(bevy_shadow_map_casters(&mut app), 0);

    let mut caster = app
        .world_mut()
        .query_filtered::<&mut Transform, With<Caster>>();
    caster
        .single_mut(app.world_mut())
        .expect("the box")
        .translation += Vec3::new(-1.5, 0.4, 0.8);
    let moved = run_frames(&mut app, 3);
    for (name, wrong, _) in mismatches(&mut app, &moved).0 {
        assert_eq!(wrong, 0, "{name}, the box moved");
    }
    assert_ne!(first.layers, moved.layers, "the shadows moved with the box");
}
