//! A Bevy app on the Vulkan device the tests run on (lavapipe in CI), headless: a ground, a box above it,
//! a sun and a point light, shadowed by `HrtsShadowsPlugin` with its one line. The visibility Bevy's PBR
//! lighting reads equals the exact CPU reference on every stable pixel, for both lights, before and after
//! the box moves.

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
            ..default()
        },
        Transform::from_xyz(3.0, 8.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.spawn((
        PointLight {
            shadow_maps_enabled: true,
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

/// The camera's image, read back: one brightness (R + G + B) per pixel, row by row from the top.
fn rendered_brightness(app: &mut App) -> Vec<u32> {
    let target = app.world().resource::<Target>().0.clone();
    let data: Arc<Mutex<Option<Vec<u8>>>> = Arc::default();
    let sink = data.clone();
    app.world_mut().spawn(Readback::texture(target)).observe(
        move |readback: On<ReadbackComplete>| {
            *sink.lock().unwrap() = Some(readback.data.clone());
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
                        .map(|p| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]))
                })
                .collect();
        }
    }
    panic!("no image read back in 8 updates");
}

/// Checks that Bevy's lighting darkens exactly the ground pixels (`ground`) the plugin shadows: every one in
/// the shadow of both lights is darker than every one lit by either.
fn check_lighting(brightness: &[u32], visibility: &HrtsVisibility, ground: &[bool]) {
    let (sun, point) = (&visibility.layers[0], &visibility.layers[1]);
    let class = |i: usize| (sun[i] == 1.0) as usize * 2 + (point[i] == 1.0) as usize;
    let mut range = [(u32::MAX, 0u32); 4];
    for (i, &b) in brightness.iter().enumerate().filter(|&(i, _)| ground[i]) {
        let r = &mut range[class(i)];
        *r = (r.0.min(b), r.1.max(b));
    }
    println!(
        "ground brightness (min, max) in the shadow of both lights, lit by the point light, by the sun, by \
         both: {range:?}"
    );
    assert!(
        range.iter().all(|&(min, _)| min != u32::MAX),
        "a class of pixels is missing: {range:?}"
    );
    assert!(
        range[1..].iter().all(|&(min, _)| min > range[0].1),
        "{range:?}"
    );
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
    let brightness = rendered_brightness(&mut app);
    check_lighting(&brightness, &first, &ground);

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
