//! Any glTF scene through Bevy's own loader, its lights shadowed by the plugin, written as one PNG frame:
//!
//! ```sh
//! cargo run --release -p bevy_hrts --example scene -- PATH.glb --out frame.png
//! ```
//!
//! The view is the scene's first camera's place (with Bevy's default projection), else one in front of the
//! scene's bounds looking at their centre; its `KHR_lights_punctual` lights get shadows (a scene without
//! lights gets a sun). Options: `--width W --height H` (default 1280×720), `--frames N` (frames rendered
//! before the capture, default 8), `--sun` (a sun added to the scene's lights), `--shadows hrts|bevy|none`
//! (the plugin's shadows, the default; Bevy's own shadow maps; no shadows: to compare their costs),
//! `--prepass` (the camera the plugin needs with Bevy's shadows or none too: depth and normal prepasses,
//! `Msaa::Off`).
//!
//! It prints the median GPU milliseconds of Bevy's whole frame (all cameras' render schedules, timestamps
//! around them), of the plugin's passes, and of the plugin's span in the frame (its first pass to the end
//! of the copy Bevy's shader reads), over the frames of the second half.

mod gpu_timer;

use bevy::app::ScheduleRunnerPlugin;
use bevy::camera::primitives::MeshAabb;
use bevy::camera::{Exposure, RenderTarget};
use bevy::core_pipeline::prepass::{DepthPrepass, NormalPrepass};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy_hrts::{HrtsShadowsPlugin, HrtsStatus};
use gpu_timer::{FrameTimerPlugin, FrameTimes};
use std::path::PathBuf;
use std::time::Duration;

/// The command line.
#[derive(Resource, Clone)]
struct Args {
    scene: PathBuf,
    out: PathBuf,
    width: u32,
    height: u32,
    frames: u64,
    sun: bool,
    shadows: Shadows,
    prepass: bool,
}

/// Whose shadows the lights get.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Shadows {
    /// The plugin's.
    Hrts,
    /// Bevy's own shadow maps.
    Bevy,
    /// None: the lights' shadows are off.
    Off,
}

fn parse_args() -> Result<Args, String> {
    let mut args = std::env::args().skip(1);
    let mut parsed = Args {
        scene: PathBuf::new(),
        out: PathBuf::from("frame.png"),
        width: 1280,
        height: 720,
        frames: 8,
        sun: false,
        shadows: Shadows::Hrts,
        prepass: false,
    };
    let number = |flag: &str, value: Option<String>| -> Result<u64, String> {
        value
            .and_then(|v| v.parse().ok())
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("{flag} takes a positive integer"))
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--out" => parsed.out = args.next().ok_or("--out takes a path")?.into(),
            "--width" => parsed.width = number("--width", args.next())?.min(16384) as u32,
            "--height" => parsed.height = number("--height", args.next())?.min(16384) as u32,
            "--frames" => parsed.frames = number("--frames", args.next())?,
            "--sun" => parsed.sun = true,
            "--prepass" => parsed.prepass = true,
            "--shadows" => {
                parsed.shadows = match args.next().as_deref() {
                    Some("hrts") => Shadows::Hrts,
                    Some("bevy") => Shadows::Bevy,
                    Some("none") => Shadows::Off,
                    _ => return Err("--shadows takes hrts, bevy or none".into()),
                }
            }
            flag if flag.starts_with("--") => return Err(format!("unknown option {flag}")),
            path => parsed.scene = path.into(),
        }
    }
    if parsed.scene.as_os_str().is_empty() {
        return Err(
            "usage: scene PATH.glb [--out frame.png] [--width W] [--height H] [--frames N] [--sun] \
             [--shadows hrts|bevy|none] [--prepass]"
                .into(),
        );
    }
    Ok(parsed)
}

fn main() {
    let args = match parse_args() {
        Ok(args) => args,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let scene = std::fs::canonicalize(&args.scene).unwrap_or_else(|e| {
        eprintln!("{}: {e}", args.scene.display());
        std::process::exit(1);
    });
    let folder = scene.parent().map(PathBuf::from).unwrap_or_default();
    let mut app = App::new();
    if args.shadows == Shadows::Hrts {
        app.add_plugins(HrtsShadowsPlugin::default());
    }
    let times = FrameTimes::default();
    app.add_plugins(bevy_hrts::headless_default_plugins().set(AssetPlugin {
        file_path: folder.to_string_lossy().into_owned(),
        ..default()
    }))
    // No window: the app loops until the capture exits it.
    .add_plugins((
        ScheduleRunnerPlugin::run_loop(Duration::ZERO),
        FrameTimerPlugin(times.clone()),
    ))
    .insert_resource(times)
    .insert_resource(Args { scene, ..args })
    .init_resource::<HrtsStatus>()
    .init_resource::<Placed>()
    .add_systems(Startup, load)
    .add_systems(Update, (shadow_lights, place_camera, capture))
    .run();
}

/// The image the camera renders into.
#[derive(Resource)]
struct Target(Handle<Image>);

fn load(
    mut commands: Commands,
    args: Res<Args>,
    assets: Res<AssetServer>,
    mut images: ResMut<Assets<Image>>,
) {
    let name = args
        .scene
        .file_name()
        .map(PathBuf::from)
        .unwrap_or_default();
    commands.spawn(WorldAssetRoot(
        assets.load(GltfAssetLabel::Scene(0).from_asset(name)),
    ));
    let mut image =
        Image::new_target_texture(args.width, args.height, TextureFormat::Rgba8UnormSrgb, None);
    // Read back after rendering.
    image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
    let target = images.add(image);
    commands.insert_resource(Target(target));
}

/// Gives every light of the scene shadows (or none, with `--shadows none`).
fn shadow_lights(
    args: Res<Args>,
    mut suns: Query<&mut DirectionalLight, Added<DirectionalLight>>,
    mut points: Query<&mut PointLight, Added<PointLight>>,
    mut spots: Query<&mut SpotLight, Added<SpotLight>>,
) {
    let on = args.shadows != Shadows::Off;
    suns.iter_mut().for_each(|mut l| l.shadow_maps_enabled = on);
    points
        .iter_mut()
        .for_each(|mut l| l.shadow_maps_enabled = on);
    spots
        .iter_mut()
        .for_each(|mut l| l.shadow_maps_enabled = on);
}

/// Once the scene is loaded: points its first camera (or a new one) at the image target, and adds a sun if
/// the scene has no light or `--sun` asks for one.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn place_camera(
    mut commands: Commands,
    args: Res<Args>,
    target: Res<Target>,
    mut placed: ResMut<Placed>,
    cameras: Query<(Entity, &GlobalTransform), With<Camera3d>>,
    lights: Query<(), Or<(With<DirectionalLight>, With<PointLight>, With<SpotLight>)>>,
    suns: Query<&DirectionalLight>,
    meshes: Query<(&Mesh3d, &GlobalTransform)>,
    mesh_assets: Res<Assets<Mesh>>,
    roots: Query<Option<&Children>, With<WorldAssetRoot>>,
) {
    // Once the scene is spawned (its root has children): its cameras and lights exist then.
    if placed.0 || roots.iter().any(|children| children.is_none()) || meshes.is_empty() {
        return;
    }
    placed.0 = true;
    // Exposed for the brightest sun as an incident-light meter would (EV100 = log2(E · 100 / 250), 15.3 for
    // 100,000 lux, Bevy's `Exposure::SUNLIGHT` is 15), else for an interior; Reinhard, since Bevy's default tone curve needs its `tonemapping_luts` feature.
    let added_sun = (lights.is_empty() || args.sun).then(|| DirectionalLight {
        shadow_maps_enabled: args.shadows != Shadows::Off,
        ..default()
    });
    let exposure = (suns.iter().chain(&added_sun))
        .map(|s| s.illuminance)
        .reduce(f32::max)
        .map_or(Exposure::INDOOR, |lux| Exposure {
            ev100: (lux.max(1e-3) * 100.0 / 250.0).log2(),
        });
    let target = (
        RenderTarget::Image(target.0.clone().into()),
        Tonemapping::ReinhardLuminance,
        exposure,
    );
    // The scene's first camera gives the view (it is turned off: a camera of the example's own renders into
    // the image), else one in front of the scene's bounds looking at their centre.
    let scene_camera = cameras.iter().next().map(|(entity, transform)| {
        commands.entity(entity).insert(Camera {
            is_active: false,
            ..default()
        });
        Transform::from_matrix(transform.to_matrix())
    });
    let transform = scene_camera.unwrap_or_else(|| {
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (mesh, transform) in &meshes {
            if let Some(aabb) = mesh_assets.get(&mesh.0).and_then(|m| m.compute_aabb()) {
                for corner in [aabb.min(), aabb.max()] {
                    let p = transform.transform_point(corner.into());
                    (min, max) = (min.min(p), max.max(p));
                }
            }
        }
        let centre = (min + max) / 2.0;
        let radius = (max - min).length() / 2.0;
        Transform::from_translation(centre + Vec3::new(0.6, 0.5, 1.0).normalize() * radius * 2.2)
            .looking_at(centre, Vec3::Y)
    });
    let mut camera = commands.spawn((Camera3d::default(), target, transform));
    if args.prepass {
        camera.insert((DepthPrepass, NormalPrepass, Msaa::Off));
    }
    if let Some(sun) = added_sun {
        commands.spawn((
            sun,
            Transform::from_xyz(0.3, 1.0, 0.2).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    }
}

/// Whether the camera is placed, and the frames Bevy ran since.
#[derive(Resource, Default)]
struct Placed(bool, u64);

/// After `--frames` frames (of the plugin's, with its shadows), prints the GPU times, reads the image back,
/// writes it and exits.
#[allow(clippy::too_many_arguments)]
fn capture(
    mut commands: Commands,
    args: Res<Args>,
    status: Res<HrtsStatus>,
    target: Res<Target>,
    times: Res<FrameTimes>,
    mut placed: ResMut<Placed>,
    mut plugin_ms: Local<(Vec<f64>, Vec<f64>, u64)>,
    mut requested: Local<bool>,
) {
    if let Some(error) = &status.error {
        eprintln!("the plugin could not shadow the frame: {error}");
    }
    if !placed.0 || *requested {
        return;
    }
    placed.1 += 1;
    // Timed from the second half of the frames on: the scene and its pipelines are ready by then.
    let timed = placed.1 > args.frames / 2;
    if placed.1 == args.frames / 2 + 1 {
        times.0.lock().unwrap_or_else(|e| e.into_inner()).clear();
    }
    if timed && status.frames != plugin_ms.2 {
        plugin_ms.0.extend(status.gpu_milliseconds);
        plugin_ms.1.extend(status.gpu_span_milliseconds);
    }
    plugin_ms.2 = status.frames;
    let frames = match args.shadows {
        Shadows::Hrts => status.frames,
        Shadows::Bevy | Shadows::Off => placed.1,
    };
    if frames < args.frames {
        return;
    }
    *requested = true;
    println!(
        "{frames} frames, shadows {:?}: {} lights shadowed by the plugin",
        args.shadows,
        status.lights.len()
    );
    let frame_ms = times.0.lock().unwrap_or_else(|e| e.into_inner()).clone();
    for (what, ms) in [
        ("Bevy's whole frame", &frame_ms),
        ("the plugin's passes", &plugin_ms.0),
        (
            "the plugin's span (its passes, the waits between them, the copy into depth)",
            &plugin_ms.1,
        ),
    ] {
        if let Some(median) = median(ms) {
            println!(
                "GPU ms, {what}: median {median:.3} over {} frames of the second half",
                ms.len()
            );
        }
    }
    let (out, width, height) = (args.out.clone(), args.width, args.height);
    commands.spawn(Readback::texture(target.0.clone())).observe(
        move |readback: On<ReadbackComplete>,
              mut commands: Commands,
              mut exit: MessageWriter<AppExit>| {
            // One image: the read-back repeats every frame while its entity lives.
            commands.entity(readback.entity).despawn();
            let written = write_png(&out, width, height, &readback.data);
            match written {
                Ok(()) => println!("wrote {}", out.display()),
                Err(e) => eprintln!("writing {}: {e}", out.display()),
            }
            exit.write(AppExit::Success);
        },
    );
}

/// The median of `values` (`None` for none).
fn median(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.get(sorted.len() / 2).copied()
}

/// Writes RGBA8 rows (of `width` texels, each row possibly padded) as a PNG.
fn write_png(path: &std::path::Path, width: u32, height: u32, data: &[u8]) -> std::io::Result<()> {
    let row = width as usize * 4;
    let stride = data.len() / height.max(1) as usize;
    let pixels: Vec<u8> = data
        .chunks(stride.max(row))
        .take(height as usize)
        .flat_map(|r| r[..row].iter().copied())
        .collect();
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&pixels))
        .map_err(std::io::Error::other)
}
