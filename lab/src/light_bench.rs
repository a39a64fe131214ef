//! `hrts_lab bench --lights`: what each kind of light costs inside whole scenes. The shared Sponza and
//! Conference models, seen from inside, each with one light at a time: the sun, a spot light inside and a
//! point light at three positions inside, planned as `render --scene` plans a glTF scene and drawn through
//! the plugin's C ABI (a point light given as a point light: the plugin builds its cube faces as one map);
//! with `--point-lights N`, N point lights in one context. Per light: frusta recorded of those built, GPU
//! ms of its passes (the median over the frames after the first of the per-frame sum over its frusta, and
//! the slowest frame), per pass, memory, and its lists (entries, mean and longest list, texels past
//! capacity or the list limit, whether the frame built lists at all, pixels that walked the BVH).
//! `--emitter-size` runs every light at each size given, sized lights with exact soft shadows, each also
//! traced by the ray-tracing-pipeline peer at equal samples (trace only).

use crate::bench_models::{keep_only, models_folder, BenchArgs};
use anyhow::{bail, Context, Result};
use demo_engine::gbuffer::GBufferLayout;
use demo_engine::plugin::{LightsFrame, PluginRenderer};
use demo_engine::CameraMatrices;
use glam::Vec3;
use host_demo::scene_plan::{plan_scene, PlanSettings};
use host_demo::scene_render::{median, SceneRenderer};
use hrts::passes_bridge;
use hrts::MapStats;
use passes::{
    directional_light_frustum, spot_light_frusta, FrameInputs, Light, PrimitiveMapConfig,
    ShadowConfig, ShadowMode,
};
use reference::RefScene;
use rhi::Device;
use scene::{Aabb, Camera, LightKind, LightSize, Scene, SceneFile, SceneLight};
use std::cell::OnceCell;
use std::fmt::Write as _;
use std::path::PathBuf;

/// A scene of the benchmark: a model of the models folder and, as fractions of its bounds, the camera's
/// position and target and the positions of the lights inside.
struct LightScene {
    file: &'static str,
    camera: (Vec3, Vec3),
    points: [Vec3; 3],
    spot: Vec3,
}

const SCENES: [LightScene; 2] = [
    LightScene {
        file: "04_dabrovic_sponza_66k.obj",
        camera: (Vec3::new(0.12, 0.2, 0.5), Vec3::new(0.8, 0.25, 0.45)),
        points: [
            Vec3::new(0.5, 0.35, 0.5),
            Vec3::new(0.25, 0.12, 0.3),
            Vec3::new(0.75, 0.7, 0.6),
        ],
        spot: Vec3::new(0.5, 0.8, 0.5),
    },
    LightScene {
        file: "05_conference_clean_277k.obj",
        camera: (Vec3::new(0.1, 0.6, 0.85), Vec3::new(0.75, 0.2, 0.25)),
        points: [
            Vec3::new(0.5, 0.6, 0.5),
            Vec3::new(0.25, 0.35, 0.3),
            Vec3::new(0.8, 0.85, 0.7),
        ],
        spot: Vec3::new(0.5, 0.9, 0.5),
    },
];

/// The scenes `--lights` measures (those `--only` keeps) and the folder that holds them.
pub struct LightScenes {
    folder: PathBuf,
    scenes: Vec<&'static LightScene>,
}

/// The scenes of `--lights` that `--only` keeps, in the models folder of `args`. Fails, naming the
/// shared models it needs and where it looked, when the folder lacks one of them, and when an `--only`
/// matches none of the scenes.
pub fn chosen_scenes(args: &BenchArgs) -> Result<LightScenes> {
    let scenes = keep_only(
        SCENES.iter().collect(),
        |s| s.file,
        &args.only,
        "scenes of --lights",
    )?;
    let (folder, how) = models_folder(args);
    let missing: Vec<&str> = scenes
        .iter()
        .map(|s| s.file)
        .filter(|file| !folder.join(file).is_file())
        .collect();
    if !missing.is_empty() {
        let needed: Vec<&str> = SCENES.iter().map(|s| s.file).collect();
        bail!(
            "bench --lights measures lights inside the shared models {}, framed for them; the models \
             folder {} ({how}) has no {}: name the project's shared models folder with --models DIR (or \
             HRTS_MODELS), or keep the scenes it has with --only",
            needed.join(" and "),
            folder.display(),
            missing.join(" nor ")
        );
    }
    Ok(LightScenes { folder, scenes })
}

/// The point `f` (fractions of each axis) of `bounds`.
fn at(bounds: &Aabb, f: Vec3) -> Vec3 {
    bounds.min + f * (bounds.max - bounds.min)
}

/// The sizes of the benchmark's lights: `None` for zero-size lights, else the sun's angular radius and the
/// spot and point lights' emitter radius (scene units).
type Sizes = Option<(f32, f32)>;

/// The light the plugin shadows for `light` (its first frustum for a spot light of one frustum), for the
/// ray-tracing-pipeline peer; `None` for a spot light of several frusta.
fn peer_light(light: &SceneLight, bounds: &Aabb) -> Result<Option<Light>> {
    Ok(match light.kind {
        LightKind::Directional { direction } => Some(directional_light_frustum(
            direction,
            [bounds.min, bounds.max],
        )?),
        LightKind::Spot {
            position,
            direction,
            outer_cone,
            range,
            ..
        } => match spot_light_frusta(position, direction, outer_cone, range).as_slice() {
            [one] => Some(*one),
            _ => None,
        },
        LightKind::Point { position, range } => Some(Light::Point { position, range }),
    })
}

/// A static, white, shadow-casting light of the benchmark.
fn bench_light(name: &str, kind: LightKind, size: LightSize) -> SceneLight {
    SceneLight {
        name: name.into(),
        kind,
        color: Vec3::ONE,
        intensity: 100.0,
        size,
        casts_shadows: true,
        is_static: true,
    }
}

/// The benchmark's lights for a scene whose bounds are `bounds`: name and light.
fn lights(scene: &LightScene, bounds: &Aabb, sizes: Sizes) -> Vec<(String, SceneLight)> {
    let light = |name: &str, kind: LightKind| {
        let size = match (sizes, &kind) {
            (None, _) => LightSize::Zero,
            (Some((angular, _)), LightKind::Directional { .. }) => {
                LightSize::AngularRadius(angular)
            }
            (Some((_, radius)), _) => LightSize::Radius(radius),
        };
        bench_light(name, kind, size)
    };
    let mut out = vec![(
        "sun".to_owned(),
        light(
            "sun",
            LightKind::Directional {
                direction: Vec3::new(0.35, -1.0, 0.6).normalize(),
            },
        ),
    )];
    out.push((
        "spot inside".to_owned(),
        light(
            "spot",
            LightKind::Spot {
                position: at(bounds, scene.spot),
                direction: Vec3::new(0.2, -1.0, 0.1).normalize(),
                inner_cone: 0.5,
                outer_cone: 0.7,
                range: None,
            },
        ),
    ));
    for (i, &p) in scene.points.iter().enumerate() {
        let name = format!("point {}", i + 1);
        out.push((
            name.clone(),
            light(
                &name,
                LightKind::Point {
                    position: at(bounds, p),
                    range: None,
                },
            ),
        ));
    }
    out
}

/// What one light cost.
struct LightCost {
    name: String,
    /// Frusta recorded in the last frame, and built.
    frusta: (u32, u32),
    gpu_ms: f64,
    /// The slowest frame's GPU ms (the first one included).
    max_ms: f64,
    map_ms: f64,
    trace_ms: f64,
    /// The ray-tracing-pipeline peer's trace-only ms at equal samples (sized lights with one frustum), and
    /// the pixels whose visible sample count differs between it and the plugin.
    peer: Option<PeerCost>,
    bytes: u64,
    entries: u64,
    mean_list: f64,
    longest: u32,
    past_capacity: u64,
    /// The last frame's routes, summed over the light's frusta.
    routes: Routes,
    /// Median ms of each pass (summed over the light's frusta), in the order first seen.
    passes: Vec<(String, f64)>,
    /// Bytes of the build scratch the context's lights share.
    scratch_bytes: u64,
}

/// Where a light's pixels found their triangles in the last frame, summed over its frusta.
#[derive(Default)]
struct Routes {
    /// Bin items of the footprints.
    bin_items: u64,
    /// Frusta that built no list (bin items past the budget).
    skipped: u32,
    /// Texels whose list passed the list limit.
    past_limit: u64,
    /// Pixels that walked the BVH.
    walked: u64,
    /// Area shadows: pixels whose bundle passed its walk budget, their samples walked one by one.
    per_sample: u64,
}

impl Routes {
    fn of<'a>(stats: impl IntoIterator<Item = &'a MapStats>) -> Self {
        stats.into_iter().fold(Self::default(), |r, st| Self {
            bin_items: r.bin_items + u64::from(st.bin_items),
            skipped: r.skipped + u32::from(st.frusta_without_lists > 0),
            past_limit: r.past_limit + u64::from(st.texels_past_limit),
            walked: r.walked + u64::from(st.pixels_walked),
            per_sample: r.per_sample + u64::from(st.pixels_walked_per_sample),
        })
    }
}

/// GPU ms of the passes of `frame`'s lights whose name passes `keep`.
fn frame_ms(frame: &LightsFrame, keep: impl Fn(&str) -> bool) -> f64 {
    frame
        .lights
        .iter()
        .flat_map(|l| &l.timings)
        .filter(|t| keep(&t.name))
        .map(|t| t.milliseconds)
        .sum()
}

/// Median over frames of each pass's ms, summed over `frames`' lights and frusta, in the order first seen.
fn pass_medians(frames: &[LightsFrame]) -> Vec<(String, f64)> {
    let mut names: Vec<String> = Vec::new();
    for t in frames
        .iter()
        .flat_map(|f| &f.lights)
        .flat_map(|l| &l.timings)
    {
        if !names.contains(&t.name) {
            names.push(t.name.clone());
        }
    }
    names
        .into_iter()
        .map(|name| {
            let ms = median(frames.iter().map(|f| frame_ms(f, |n| n == name)).collect());
            (name, ms)
        })
        .collect()
}

/// Medians over frames of every light's own passes (the shared prim buffer is not the light's), of its
/// primitive-map passes and of its ray trace.
fn medians(frames: &[LightsFrame]) -> (f64, f64, f64) {
    let of =
        |keep: &dyn Fn(&str) -> bool| median(frames.iter().map(|f| frame_ms(f, keep)).collect());
    (
        of(&|n| n != hrts::Pass::PrimBuffer.name()),
        of(&|n| n.starts_with("primitive map")),
        of(&|n| n == "ray trace"),
    )
}

/// What the ray-tracing-pipeline peer cost, and how its answer compares with the plugin's.
struct PeerCost {
    /// Trace-only GPU ms at equal samples.
    trace_ms: f64,
    /// Pixels whose visible sample count differs from the plugin's layer. Both test the same segments;
    /// they may differ only where a segment passes within rounding of a triangle's edge or plane.
    differing: usize,
    /// Of those, the pixels the exact reference of the same samples calls stable whose count differs from
    /// its count: the plugin's, then the peer's (`None` without the reference).
    wrong: Option<(usize, usize)>,
}

/// Of the pixels `differing` ([`differing_pixels`] of the plugin's image `ours` and the peer's `peer`,
/// visibility of `args.area_samples` samples), those the exact reference of the same samples of `light` of
/// size `size` (emitter radius, or angular radius) calls stable whose count differs from its count: the
/// plugin's, then the peer's. The reference runs on those pixels alone.
fn wrong_on_stable(
    scene: &SceneReference,
    camera: &Camera,
    (light, size): (&Light, f32),
    (ours, peer, differing): (&[f32], &[f32], &[usize]),
    args: &BenchArgs,
) -> (usize, usize) {
    let samples = args.area_samples;
    let lights: Vec<reference::Light> = match *light {
        Light::Directional { direction, .. } => {
            passes::area::area_sample_directions(direction, size, samples)
                .iter()
                .map(|w| reference::Light::Directional {
                    direction: -w.as_dvec3(),
                })
                .collect()
        }
        Light::Spot { position, .. } | Light::Point { position, .. } => {
            passes::area::local_area_offsets(samples)
                .iter()
                .map(|offset| reference::Light::DiscSample {
                    centre: position.as_dvec3(),
                    radius: f64::from(size),
                    offset: offset.as_dvec2(),
                })
                .collect()
        }
    };
    let Some(&first) = lights.first().filter(|_| !differing.is_empty()) else {
        return (0, 0);
    };
    let pixels: Vec<(u32, u32)> = differing
        .iter()
        .map(|&i| (i as u32 % args.width, i as u32 / args.width))
        .collect();
    let params = crate::accuracy::scene_visibility_params(
        scene.scene,
        camera,
        args.width,
        args.height,
        first,
    );
    let exact = reference::area_counts_at(scene.reference(), &params, &lights, &pixels);
    let wrong = |image: &[f32]| {
        differing
            .iter()
            .zip(&exact)
            .filter(|(&i, &(visible, stable))| {
                stable && sample_count(image[i], samples) != i64::from(visible)
            })
            .count()
    };
    (wrong(ours), wrong(peer))
}

/// A scene and its exact reference, built on first use: once per scene for the wrong-pixel checks of all
/// its lights.
struct SceneReference<'a> {
    scene: &'a Scene,
    reference: OnceCell<RefScene>,
}

impl<'a> SceneReference<'a> {
    fn new(scene: &'a Scene) -> Self {
        Self {
            scene,
            reference: OnceCell::new(),
        }
    }

    fn reference(&self) -> &RefScene {
        self.reference.get_or_init(|| RefScene::new(self.scene))
    }
}

/// The visible sample count of a visibility `v` of `samples` samples.
fn sample_count(v: f32, samples: u32) -> i64 {
    (v * samples as f32).round() as i64
}

/// The indices of the pixels of two visibility images of `samples` samples whose visible counts differ.
fn differing_pixels(a: &[f32], b: &[f32], samples: u32) -> Vec<usize> {
    (0..a.len().min(b.len()))
        .filter(|&i| sample_count(a[i], samples) != sample_count(b[i], samples))
        .collect()
}

/// The peer's trace-only ms for `light` of size `size` (angular radius or emitter radius) on the frame
/// `plugin` last rendered through `camera`, and the pixels where it differs from the plugin's layer of
/// that frame (`None` without ray tracing or without a light for it).
fn peer_cost(
    device: &Device,
    plugin: &PluginRenderer,
    scene: &SceneReference,
    camera: &Camera,
    light: Option<Light>,
    size: f32,
    args: &BenchArgs,
) -> Result<Option<PeerCost>> {
    let Some(light) = light.filter(|_| device.capabilities().ray_tracing_pipeline) else {
        return Ok(None);
    };
    let (_, layers) = plugin.read_frame(device)?;
    let layer = layers.first().context("the light's layer")?;
    let m = CameraMatrices::of_camera(camera, args.width, args.height);
    let inputs = FrameInputs {
        view: m.view,
        proj: m.proj,
        camera_position: m.position,
        light,
    };
    let run = crate::peer::run_area_peer(
        device,
        plugin,
        scene.scene,
        &inputs,
        size,
        args.area_samples,
        args.frames,
    )?;
    let differing = differing_pixels(layer, &run.visibility, args.area_samples);
    let wrong = (!args.no_reference).then(|| {
        wrong_on_stable(
            scene,
            camera,
            (&light, size),
            (layer, &run.visibility, &differing),
            args,
        )
    });
    Ok(Some(PeerCost {
        trace_ms: run.trace_ms,
        differing: differing.len(),
        wrong,
    }))
}

fn measure_light(
    device: &Device,
    (file, reference): (&SceneFile, &SceneReference),
    camera: &Camera,
    (name, peer): (&str, Option<(Light, f32)>),
    args: &BenchArgs,
) -> Result<LightCost> {
    let settings = PlanSettings {
        base: passes_bridge::config(&ShadowConfig {
            antialiasing: false,
            area: args.area(args.area_samples),
            map: PrimitiveMapConfig {
                size: args.map_size,
                ..args.map()
            },
            ..ShadowConfig::default()
        })?,
        width: args.width,
        height: args.height,
    };
    let plan = plan_scene(file, camera, &settings)?;
    let progress = host_demo::progress::phase("frames", u64::from(args.frames.max(2)));
    let mut renderer = SceneRenderer::new(device, file, args.width, args.height)?;
    renderer
        .plugin_mut()
        .set_output_format(args.output_format());
    if !args.copied_output {
        renderer.write_outputs_directly();
    }
    let mut frames = Vec::new();
    for _ in 0..args.frames.max(2) {
        frames.push(renderer.render(device, camera, &plan)?);
        progress.inc(1);
    }
    drop(progress);
    let (gpu_ms, map_ms, trace_ms) = medians(&frames[1..]);
    let max_ms = slowest(&frames);
    let last = frames.last().context("no frame rendered")?;
    let reports = &last.lights;
    let peer = match peer {
        Some((light, size)) => peer_cost(
            device,
            renderer.plugin(),
            reference,
            camera,
            Some(light),
            size,
            args,
        )?,
        None => None,
    };
    let entries: u64 = reports.iter().map(|r| u64::from(r.stats.entries)).sum();
    let texels: u64 = reports
        .iter()
        .map(|r| u64::from(r.stats.texels_with_list))
        .sum();
    Ok(LightCost {
        name: name.to_owned(),
        frusta: frusta_of(last),
        gpu_ms,
        max_ms,
        map_ms,
        trace_ms,
        peer,
        routes: Routes::of(reports.iter().map(|r| &r.stats)),
        bytes: reports
            .iter()
            .flat_map(|r| r.allocated_resources())
            .map(|(_, bytes)| bytes)
            .sum(),
        entries,
        mean_list: if texels == 0 {
            0.0
        } else {
            entries as f64 / texels as f64
        },
        longest: reports
            .iter()
            .map(|r| r.stats.longest_list)
            .max()
            .unwrap_or(0),
        past_capacity: reports
            .iter()
            .map(|r| u64::from(r.stats.texels_past_capacity))
            .sum(),
        passes: pass_medians(&frames[1..]),
        scratch_bytes: reports
            .iter()
            .map(|r| r.map_scratch_bytes)
            .max()
            .unwrap_or(0),
    })
}

/// The slowest of `frames`' GPU ms over their lights' own passes (the shared prim buffer excluded).
fn slowest(frames: &[LightsFrame]) -> f64 {
    frames
        .iter()
        .map(|f| frame_ms(f, |n| n != hrts::Pass::PrimBuffer.name()))
        .fold(0.0, f64::max)
}

/// Frusta of `frame`'s lights: recorded, and built (recorded or culled).
fn frusta_of(frame: &LightsFrame) -> (u32, u32) {
    frame.lights.iter().fold((0, 0), |(r, b), l| {
        (r + l.frusta, b + l.frusta + l.frusta_culled)
    })
}

/// The cost of point lights at `positions` given to the plugin as point lights (the C ABI's
/// `HRTS_LIGHT_TYPE_POINT`) in one context: the plugin builds each one's six cube faces as one map.
/// Statistics are those of the first light; time and memory are the sum over all.
fn measure_native_points(
    device: &Device,
    file: &SceneFile,
    camera: &Camera,
    positions: &[Vec3],
    name: String,
    args: &BenchArgs,
    emitter_radius: Option<f32>,
) -> Result<LightCost> {
    let progress = host_demo::progress::phase("frames", u64::from(args.frames.max(2)));
    let mut plugin = PluginRenderer::for_scene_casters(
        device,
        &file.scene,
        &file.shadow_casters,
        args.width,
        args.height,
        GBufferLayout::ANALYSIS,
    )?;
    plugin.set_output_format(args.output_format());
    if !args.copied_output {
        plugin.write_outputs_directly();
    }
    let mut config = ShadowConfig {
        mode: ShadowMode::Hard,
        antialiasing: false,
        map: PrimitiveMapConfig {
            size: args.map_size,
            ..args.map()
        },
        ..ShadowConfig::default()
    };
    if let Some(radius) = emitter_radius {
        config.mode = ShadowMode::Area;
        config.pcss.spot_radius = radius;
        config.area = args.area(args.area_samples);
    }
    plugin.configure_lights(
        device,
        &vec![passes_bridge::config(&config)?; positions.len()],
    )?;
    let matrices = CameraMatrices::of_camera(camera, args.width, args.height);
    let lights: Vec<_> = positions
        .iter()
        .map(|&position| hrts::Light::Point {
            position,
            range: None,
        })
        .collect();
    let mut frames = Vec::new();
    for _ in 0..args.frames.max(2) {
        frames.push(plugin.render_lights(device, &matrices, &lights)?);
        progress.inc(1);
    }
    drop(progress);
    let (_, map_ms, trace_ms) = medians(&frames[1..]);
    let frame_ms = |f: &LightsFrame| f.lights.iter().map(|l| l.gpu_milliseconds).sum::<f64>();
    let gpu_ms = median(frames[1..].iter().map(frame_ms).collect());
    let max_ms = frames.iter().map(frame_ms).fold(0.0, f64::max);
    let last = frames.last().context("no frame rendered")?;
    let light = last.lights.first().context("no light reported")?;
    let st = &light.stats;
    Ok(LightCost {
        name,
        frusta: frusta_of(last),
        gpu_ms,
        max_ms,
        map_ms,
        trace_ms,
        peer: None,
        routes: Routes::of(last.lights.iter().map(|l| &l.stats)),
        bytes: last
            .lights
            .iter()
            .flat_map(|l| l.allocated_resources())
            .map(|(_, bytes)| bytes)
            .sum(),
        entries: u64::from(st.entries),
        mean_list: st.mean_list(),
        longest: st.longest_list,
        past_capacity: u64::from(st.texels_past_capacity),
        passes: pass_medians(&frames[1..]),
        scratch_bytes: light.map_scratch_bytes,
    })
}

/// Runs the light benchmark on `scenes` ([`chosen_scenes`]) and returns its Markdown table.
pub fn run_light_bench(device: &Device, args: &BenchArgs, scenes: &LightScenes) -> Result<String> {
    let caps = device.capabilities();
    if let Some(bad) = args
        .emitter_size
        .iter()
        .find(|&&f| !(f.is_finite() && f >= 0.0))
    {
        anyhow::bail!("--emitter-size {bad}: give fractions of the scene's extent, 0 or more");
    }
    let sizes: Vec<f32> = if args.emitter_size.is_empty() {
        vec![0.0]
    } else {
        args.emitter_size.clone()
    };
    let sized = sizes.iter().any(|&f| f > 0.0);
    let mut out = format!(
        "Device: {} ({}); {}×{}, {}, primitive map N = {}, no FXAA; one light at a time, planned as \
         `render --scene` plans it; GPU ms = median over {} frames after the first of the light's passes \
         summed over its frusta (the shared prim buffer excluded), max = the slowest frame, the first \
         included; memory = the light's own resources ({}; the build scratch shared by all lights is listed \
         below); frusta = recorded / built (the plugin skips those holding no receiver in view).\n\n\
         | scene | light | emitter | frusta | GPU ms | max ms | × sun | map ms | ray trace ms | RT peer trace ms | \
         MiB | entries | mean list | longest | bin items | lists | past limit | past capacity | BVH pixels | \
         per-sample pixels | ≠ peer | wrong: ours / peer |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|\n",
        caps.device_name,
        caps.driver,
        args.width,
        args.height,
        if sized {
            format!(
                "exact soft shadows of sized lights (mode area, {} samples; emitter radius as a share of \
                 the scene's extent, the sun {} rad)",
                args.area_samples, args.angular_radius
            )
        } else {
            "hard shadows (zero-size lights)".to_owned()
        },
        match args.map_size {
            0 => format!(
                "{} (the plugin's choice for hard and area shadows)",
                passes::TRACED_MAP_SIZE
            ),
            n => n.to_string(),
        },
        args.frames.max(2) - 1,
        match (args.copied_output, args.output_format.to_uppercase()) {
            (true, format) if format == "R32F" =>
                "each light's layer is copied into an R32F output without storage usage".to_owned(),
            (true, format) => format!(
                "each light's layer is converted by a blit into an {format} output without storage usage"
            ),
            (false, format) =>
                format!("each light writes its layer of an {format} storage output directly"),
        }
    );
    let total: usize = scenes
        .scenes
        .iter()
        .map(|s| (2 + s.points.len() + usize::from(args.point_lights > 0)) * sizes.len())
        .sum();
    let bar = host_demo::progress(total as u64, "bench --lights");
    let mut sizes_line = String::new();
    let mut per_pass = String::from(
        "\nPer pass (median ms over the same frames, summed over the light's frusta):\n\n",
    );
    for &scene_case in &scenes.scenes {
        let path = scenes.folder.join(scene_case.file);
        bar.set_message(format!("{} loading", scene_case.file));
        let scene =
            scene::load_obj(&path).with_context(|| format!("loading {}", path.display()))?;
        let bounds = scene.bounds();
        let camera = Camera {
            position: at(&bounds, scene_case.camera.0),
            target: at(&bounds, scene_case.camera.1),
            up: Vec3::Y,
            fov_y_radians: 70f32.to_radians(),
            near: bounds.radius() * 1e-3,
        };
        let file_with = |lights: Vec<SceneLight>| SceneFile {
            static_objects: vec![true; scene.objects.len()],
            shadow_casters: vec![true; scene.objects.len()],
            scene: scene.clone(),
            lights,
            camera: Some(camera),
            skipped_primitives: 0,
        };
        let extent = (bounds.max - bounds.min).length();
        let reference = SceneReference::new(&scene);
        let mut sun = None;
        for &fraction in &sizes {
            let emitter_radius = (fraction > 0.0).then_some(fraction * extent);
            let size_cell =
                emitter_radius.map_or("0".to_owned(), |_| format!("{:.1} %", fraction * 100.0));
            if let Some(r) = emitter_radius {
                let _ = writeln!(
                    sizes_line,
                    "- {}: {} of the extent {extent:.3} = emitter radius {r:.4} (scene units)",
                    scene_case.file, size_cell
                );
            }
            let sizes_of = emitter_radius.map(|r| (args.angular_radius, r));
            let mut costs = Vec::new();
            for (name, light) in lights(scene_case, &bounds, sizes_of) {
                bar.set_message(format!("{} {name} {size_cell}", scene_case.file));
                let size = match (&light.size, sizes_of) {
                    (_, None) => None,
                    (scene::LightSize::AngularRadius(a), _) => Some(*a),
                    (_, Some((_, r))) => Some(r),
                };
                let peer = match size {
                    Some(size) => peer_light(&light, &bounds)?.map(|l| (l, size)),
                    None => None,
                };
                costs.push(measure_light(
                    device,
                    (&file_with(vec![light]), &reference),
                    &camera,
                    (&name, peer),
                    args,
                )?);
                bar.inc(1);
            }
            if args.point_lights > 0 {
                bar.set_message(format!(
                    "{} {} point lights {size_cell}",
                    scene_case.file, args.point_lights
                ));
                let n = args.point_lights;
                // On a ring around the interior's centre, alternating between two heights.
                let positions: Vec<Vec3> = (0..n)
                    .map(|i| {
                        let a = i as f32 / n as f32 * std::f32::consts::TAU;
                        let f = Vec3::new(
                            0.5 + 0.3 * a.cos(),
                            if i % 2 == 0 { 0.2 } else { 0.5 },
                            0.5 + 0.3 * a.sin(),
                        );
                        at(&bounds, f)
                    })
                    .collect();
                if let (Some(dir), Some(&first)) = (&args.write_scenes, sizes.first()) {
                    if fraction == first {
                        let lights = positions
                            .iter()
                            .enumerate()
                            .map(|(i, &position)| {
                                bench_light(
                                    &format!("point {}", i + 1),
                                    LightKind::Point {
                                        position,
                                        range: None,
                                    },
                                    emitter_radius.map_or(LightSize::Zero, LightSize::Radius),
                                )
                            })
                            .collect();
                        std::fs::create_dir_all(dir)
                            .with_context(|| format!("creating {}", dir.display()))?;
                        let path = dir.join(format!(
                            "{}_{n}_point_lights.glb",
                            scene_case.file.trim_end_matches(".obj")
                        ));
                        scene::gltf_scene::write_scene(
                            &path,
                            &file_with(lights),
                            scene::gltf_scene::GltfEncoding::default(),
                        )
                        .with_context(|| format!("writing {}", path.display()))?;
                        bar.suspend(|| eprintln!("wrote {}", path.display()));
                    }
                }
                costs.push(measure_native_points(
                    device,
                    &file_with(Vec::new()),
                    &camera,
                    &positions,
                    format!("{n} point lights, native, all together"),
                    args,
                    emitter_radius,
                )?);
                bar.inc(1);
            }
            let sun_ms = *sun.get_or_insert(costs[0].gpu_ms);
            for c in &costs {
                let _ = writeln!(
                    out,
                    "| {} | {} | {size_cell} | {} / {} | {:.3} | {:.3} | {:.1} | {:.3} | {:.3} | {} | {:.1} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    scene_case.file.trim_end_matches(".obj"),
                    c.name,
                    c.frusta.0,
                    c.frusta.1,
                    c.gpu_ms,
                    c.max_ms,
                    if sun_ms > 0.0 { c.gpu_ms / sun_ms } else { 0.0 },
                    c.map_ms,
                    c.trace_ms,
                    c.peer
                        .as_ref()
                        .map_or("—".to_owned(), |p| format!("{:.3}", p.trace_ms)),
                    c.bytes as f64 / f64::from(1 << 20),
                    c.entries,
                    c.mean_list,
                    c.longest,
                    c.routes.bin_items,
                    if c.routes.skipped > 0 {
                        format!("BVH ({} of {})", c.routes.skipped, c.frusta.0)
                    } else {
                        "built".to_owned()
                    },
                    c.routes.past_limit,
                    c.past_capacity,
                    c.routes.walked,
                    c.routes.per_sample,
                    c.peer
                        .as_ref()
                        .map_or("—".to_owned(), |p| p.differing.to_string()),
                    c.peer
                        .as_ref()
                        .and_then(|p| p.wrong)
                        .map_or("—".to_owned(), |(ours, peer)| format!("{ours} / {peer}")),
                );
                let passes: Vec<String> = c
                    .passes
                    .iter()
                    .map(|(name, ms)| format!("{name} {ms:.3}"))
                    .collect();
                let _ = writeln!(
                    per_pass,
                    "- {} {} {size_cell}: {}; shared build scratch {:.1} MiB",
                    scene_case.file.trim_end_matches(".obj"),
                    c.name,
                    passes.join(", "),
                    c.scratch_bytes as f64 / f64::from(1 << 20)
                );
            }
        }
    }
    bar.finish_and_clear();
    out.push_str(
        "\n× sun: against the first size's sun. lists: built, or BVH when the frame's bin items passed the \
         bin budget and every pixel walked the BVH; past limit: texels whose list passed the list limit (they \
         walk the BVH); BVH pixels: pixels that walked the BVH; per-sample pixels: those of them whose \
         bundle of segments or rays passed its walk budget, each open sample then walking its own; ≠ peer: pixels \
         whose visible sample count differs from the peer's (the same segments: they may differ only where \
         one passes within rounding of a triangle's edge or plane); wrong: of those, the stable pixels (every \
         sample decided beyond the tolerance by the exact f64 reference of the same samples) whose count \
         differs from the reference's, the plugin's then the peer's (— with --no-reference). RT peer: the same samples of every pixel as \
         any-hit rays through the driver's ray-tracing pipeline, trace only (— for hard shadows, a spot \
         light of several frusta, several lights at once, or a device without ray tracing).\n",
    );
    if !sizes_line.is_empty() {
        out.push_str("\nLight sizes:\n\n");
        out.push_str(&sizes_line);
    }
    out.push_str(&per_pass);
    Ok(out)
}
