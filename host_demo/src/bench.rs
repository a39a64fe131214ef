//! `host_demo bench`: what the exact shadow costs, per model, with default settings.
//! - The talk's timing tables for its three models (~10K, ~65K, ~240K triangles on a ground plane):
//!   primitive map with each binning path (compute, hardware and software conservative raster), ray
//!   trace, PCSS, PCSS + ray trace, FXAA, next to the talk's GTX 980 column.
//! - Every model of `../shared/models`, whole scenes included: primitive-map build and ray-trace ms,
//!   memory, entries, list lengths, wrong pixels against the exact f64 reference, and the same shadow rays
//!   traced through the GPU's ray-tracing pipeline (build + trace ms, wrong pixels), with our time over
//!   its time, where the device has ray tracing.
//!
//! GPU timestamps around every pass; medians over the frames after the first.

use crate::accuracy::{compare_visibility_to, view_reference};
use crate::gbuffer::GBufferLayout;
use crate::peer::run_peer;
use crate::plugin::PluginRenderer;
use crate::progress::phase;
use crate::render::{map_bytes, median_timings};
use crate::View;
use anyhow::{bail, Context, Result};
use glam::Vec3;
use passes::{
    BinningRequest, FrameReport, PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig,
};
use reference::RefScene;
use rhi::Device;
use scene::{Camera, DirectionalLight};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Options of the benchmark.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// Folder of the models: every .obj file in it and its subfolders, in sorted order (default:
    /// `HRTS_MODELS`, else `../shared/models` beside the checkout). A file named as a shared model keeps
    /// that model's framing; any other is framed automatically on a ground plane, lit by the demo's sun.
    #[arg(long, value_name = "DIR")]
    pub models: Option<PathBuf>,
    /// These OBJ files instead of a folder's, each measured as a model (framed as in --models).
    #[arg(long, value_name = "FILE", num_args = 1.., conflicts_with_all = ["models", "lights"])]
    pub obj: Vec<PathBuf>,
    /// Frames per configuration; medians over all but the first.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Frame width.
    #[arg(long, default_value_t = 1920, value_parser = clap::value_parser!(u32).range(1..=i64::from(crate::limits::FRAME_SIDE)))]
    pub width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 1080, value_parser = clap::value_parser!(u32).range(1..=i64::from(crate::limits::FRAME_SIDE)))]
    pub height: u32,
    /// Only the models whose name (the path in the models folder, or the file as given to --obj; with
    /// --lights, the scene's file) contains one of these (comma-separated; default all). One that matches
    /// none is an error that lists the names.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// Skip the exact CPU reference (wrong-pixel counts): minutes on two cores at 1080p.
    #[arg(long)]
    pub no_reference: bool,
    /// Instead of the models: what each kind of light costs inside Sponza and the conference room (the
    /// sun, a spot light and point lights inside), with GPU ms, memory and lists per light.
    #[arg(long)]
    pub lights: bool,
    /// With --lights: also this many point lights at once, given to the plugin as point lights (one
    /// context, spread over each scene's interior; at most the plugin's light limit). 0: none.
    #[arg(long, default_value_t = 0, requires = "lights")]
    pub point_lights: u32,
    /// Instead of the shadow table: the demo's G-buffer as the plugin first required it (RGBA32F world
    /// normals and positions, D32 depth) against a compact one (D24S8 depth, octahedral RG16F view-space
    /// normals), with the G-buffer's and the plugin's GPU ms on each model.
    #[arg(long, conflicts_with = "lights")]
    pub gbuffer: bool,
    /// Instead of the shadow table: exact soft shadows (mode area) against PCSS with an 8K shadow map on
    /// each model, with lists and memory, and how their cost grows with the light's size and samples.
    #[arg(long, conflicts_with_all = ["lights", "gbuffer"])]
    pub area: bool,
    /// With --area: the light's angular radius in radians (with --lights --emitter-size: the sun's).
    #[arg(long, default_value_t = 0.02)]
    pub angular_radius: f32,
    /// With --area, or --lights --emitter-size: light samples per pixel.
    #[arg(long, default_value_t = passes::DEFAULT_AREA_SAMPLES)]
    pub area_samples: u32,
    /// With --lights: sized lights with exact soft shadows (mode area) instead of hard ones, one run per
    /// size (comma-separated): spot and point lights get a spherical emitter whose radius is this fraction
    /// of the scene's extent (the diagonal of its bounds), the sun --angular-radius; each sized light is
    /// also traced by the ray-tracing-pipeline peer at equal samples. 0: zero-size lights (hard shadows).
    /// Default: hard shadows alone.
    #[arg(long, value_delimiter = ',', requires = "lights")]
    pub emitter_size: Vec<f32>,
    /// A texel whose list would pass this many entries keeps none: its pixels walk the BVH (0: the
    /// plugin's choice by mode).
    #[arg(long, default_value_t = passes::primitive_map::DEFAULT_LIST_LIMIT)]
    pub list_limit: u32,
    /// Bin items per pixel with a ray past which a frame builds no list and every pixel walks the BVH
    /// (0: always the BVH; inf: always lists).
    #[arg(long, default_value_t = passes::primitive_map::DEFAULT_BIN_BUDGET)]
    pub bin_budget: f32,
    /// With --lights: the primitive map's N (texels per side; a point light's cube faces share N²).
    #[arg(long, default_value_t = passes::PrimitiveMapConfig::DEFAULT_SIZE, requires = "lights", value_parser = clap::value_parser!(u32).range(1..=i64::from(u16::MAX)))]
    pub map_size: u32,
}

impl BenchArgs {
    /// The primitive map the benchmark's configurations take: the default with the given list limit and
    /// bin budget (and, for --lights, N).
    pub fn map(&self) -> PrimitiveMapConfig {
        PrimitiveMapConfig {
            list_limit: self.list_limit,
            bin_budget: self.bin_budget,
            ..PrimitiveMapConfig::default()
        }
    }
}

/// How a model of the benchmark is shown: the own framing of a shared model (matched by file name), or
/// [`DEFAULT_FRAMING`] for any other file; with the talk's GTX 980 times (ms) for its three models.
pub(crate) struct Framing {
    /// File name of the shared model ("" for the default).
    file: &'static str,
    /// Whether a ground plane is added under the model.
    ground: bool,
    /// Camera position and target (default: framed).
    camera: Option<(Vec3, Vec3)>,
    /// Light direction (default: the demo's slanted sun).
    light: Option<Vec3>,
    gtx980: Option<[f64; 6]>,
}

const TALK_ROWS: [&str; 6] = [
    "Primitive Map + HW CR",
    "Primitive Map + SW CR",
    "Ray Trace",
    "PCSS",
    "PCSS + Ray Trace",
    "FXAA",
];

/// The framing of a file that is none of the shared models: on a ground plane, the camera framing it, the
/// demo's slanted sun.
const DEFAULT_FRAMING: Framing = Framing {
    file: "",
    ground: true,
    camera: None,
    light: None,
    gtx980: None,
};

/// The shared models' framings.
const SHARED_MODELS: [Framing; 8] = [
    Framing {
        file: "01_scorpion_low_12k.obj",
        ground: true,
        camera: None,
        light: None,
        gtx980: Some([0.4, 0.5, 0.4, 1.3, 1.8, 0.2]),
    },
    Framing {
        file: "02_stanford_bunny_69k.obj",
        ground: true,
        camera: None,
        light: None,
        gtx980: Some([0.5, 0.7, 0.7, 1.3, 2.8, 0.2]),
    },
    Framing {
        file: "03_bunny_hr_x4_239k.obj",
        ground: true,
        camera: None,
        light: None,
        gtx980: Some([3.4, 4.1, 1.0, 1.3, 3.4, 0.2]),
    },
    Framing {
        file: "04_dabrovic_sponza_66k.obj",
        ground: false,
        camera: Some((Vec3::new(-12.0, 2.5, 0.5), Vec3::new(4.0, 4.0, -1.0))),
        light: Some(Vec3::new(0.3, -1.0, 0.12)),
        gtx980: None,
    },
    Framing {
        file: "05_conference_clean_277k.obj",
        ground: false,
        camera: Some((
            Vec3::new(-900.0, 400.0, 550.0),
            Vec3::new(400.0, 80.0, -300.0),
        )),
        light: Some(Vec3::new(0.35, -1.0, 0.25)),
        gtx980: None,
    },
    Framing {
        file: "cornell_box.obj",
        ground: false,
        camera: Some((
            Vec3::new(278.0, 273.0, -800.0),
            Vec3::new(278.0, 273.0, 280.0),
        )),
        light: Some(Vec3::new(0.35, -0.45, 1.0)),
        gtx980: None,
    },
    Framing {
        file: "07_veach_mi_plates.obj",
        ground: false,
        camera: None,
        light: None,
        gtx980: None,
    },
    Framing {
        file: "08_smallpine_1650.obj",
        ground: true,
        camera: None,
        light: None,
        gtx980: None,
    },
];

/// A model of the benchmark: an OBJ file, its name (in the tables, and for `--only`) and how it is
/// shown.
pub(crate) struct BenchModel {
    path: PathBuf,
    /// The path in the models folder (with `/`), or the file as given to `--obj`.
    pub(crate) name: String,
    framing: &'static Framing,
}

impl BenchModel {
    /// The model of the file at `path`, named `name`, framed as the shared model of its file name if any.
    fn new(path: PathBuf, name: String) -> Self {
        let file = path
            .file_name()
            .and_then(|f| f.to_str())
            .unwrap_or_default();
        let framing = SHARED_MODELS
            .iter()
            .find(|f| f.file == file)
            .unwrap_or(&DEFAULT_FRAMING);
        Self {
            path,
            name,
            framing,
        }
    }
}

/// What one model measured with default settings.
struct Measured {
    name: String,
    triangles: usize,
    report: FrameReport,
    times: BTreeMap<String, f64>,
    /// (wrong pixels, near-edge pixels) against the exact reference.
    wrong: Option<(usize, usize)>,
    peer: Option<PeerMeasured>,
    /// Primitive-map build ms with the hardware and software raster binning paths.
    raster_build: [Option<f64>; 2],
}

struct PeerMeasured {
    build_ms: f64,
    trace_ms: f64,
    wrong: Option<usize>,
}

/// Sum of the medians of the passes whose names start with each of `prefixes` (None if one has none).
pub fn median_of(t: &BTreeMap<String, f64>, prefixes: &[&str]) -> Option<f64> {
    prefixes
        .iter()
        .map(|p| {
            let mut matching = t.iter().filter(|(name, _)| name.starts_with(p)).peekable();
            matching.peek()?;
            Some(matching.map(|(_, ms)| ms).sum::<f64>())
        })
        .sum()
}

/// The models folder of `args` and how it was chosen, for messages: `--models`, else `HRTS_MODELS`, else
/// the shared folder beside the checkout ([`scene::models_folder`]).
pub(crate) fn models_folder(args: &BenchArgs) -> (PathBuf, String) {
    match &args.models {
        Some(dir) => (dir.clone(), "named by --models".to_owned()),
        None => scene::models_folder(),
    }
}

/// The models to measure: the `--obj` files, else every .obj file of the models folder in sorted order;
/// those `--only` keeps. Fails, saying what it expected, on a missing file or folder, a folder without
/// .obj files, or an `--only` that matches none of them.
pub(crate) fn chosen_models(args: &BenchArgs) -> Result<Vec<BenchModel>> {
    let (models, what) = if args.obj.is_empty() {
        let (dir, how) = models_folder(args);
        let to_do =
            "bench measures every .obj file of the models folder and its subfolders; name a \
                     folder of OBJ files with --models DIR, or the files with --obj FILE…";
        if !dir.is_dir() {
            bail!(
                "the models folder {} ({how}) is not a folder: {to_do}",
                dir.display()
            );
        }
        let files = obj_files(&dir)?;
        if files.is_empty() {
            bail!("no .obj file in {} ({how}): {to_do}", dir.display());
        }
        let models = files
            .into_iter()
            .map(|name| BenchModel::new(dir.join(&name), name))
            .collect();
        (models, format!("models in {} ({how})", dir.display()))
    } else {
        let mut models = Vec::new();
        for path in &args.obj {
            if !path.is_file() {
                bail!("--obj {}: no such file", path.display());
            }
            models.push(BenchModel::new(path.clone(), path.display().to_string()));
        }
        (models, "files of --obj".to_owned())
    };
    keep_only(models, |m| &m.name, &args.only, &what)
}

/// The .obj files (of any case) in `dir` and its subfolders (links to folders are not followed), as
/// paths relative to `dir` with `/` between folders, sorted.
fn obj_files(dir: &Path) -> Result<Vec<String>> {
    let mut files = Vec::new();
    let mut folders = vec![(dir.to_path_buf(), String::new())];
    while let Some((folder, prefix)) = folders.pop() {
        let entries =
            std::fs::read_dir(&folder).with_context(|| format!("listing {}", folder.display()))?;
        for entry in entries {
            let entry = entry.with_context(|| format!("listing {}", folder.display()))?;
            let name = format!("{prefix}{}", entry.file_name().to_string_lossy());
            let path = entry.path();
            if entry.file_type().is_ok_and(|t| t.is_dir()) {
                folders.push((path, format!("{name}/")));
            } else if path.is_file()
                && path
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
            {
                files.push(name);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// The `items` whose name contains one of `only` (all of them when it is empty). An entry of `only` that
/// matches none is an error that lists the names of the `what`.
pub(crate) fn keep_only<T>(
    items: Vec<T>,
    name: impl Fn(&T) -> &str,
    only: &[String],
    what: &str,
) -> Result<Vec<T>> {
    if let Some(unmatched) = only
        .iter()
        .find(|o| !items.iter().any(|i| name(i).contains(o.as_str())))
    {
        let names: Vec<&str> = items.iter().map(&name).collect();
        bail!(
            "--only {unmatched} matches none of the {what}: {}",
            names.join(", ")
        );
    }
    Ok(items
        .into_iter()
        .filter(|i| only.is_empty() || only.iter().any(|o| name(i).contains(o.as_str())))
        .collect())
}

/// The view of `model` at the benchmark's size, as its framing shows it.
pub(crate) fn view_of(model: &BenchModel, args: &BenchArgs) -> Result<View> {
    let framing = model.framing;
    let mut scene = scene::load_obj(&model.path)
        .with_context(|| format!("loading {}", model.path.display()))?;
    if framing.ground {
        scene = scene.with_ground_plane();
    }
    let mut view = View::framed(scene, args.width, args.height);
    if let Some((position, target)) = framing.camera {
        view.camera = Camera {
            position,
            target,
            up: Vec3::Y,
            fov_y_radians: 45f32.to_radians(),
            near: 0.01 * (target - position).length(),
        };
    }
    if let Some(direction) = framing.light {
        view.light = DirectionalLight::new(direction).context("unusable light direction")?;
    }
    Ok(view)
}

pub(crate) fn frames_of(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: u32,
) -> Result<(PluginRenderer, Vec<FrameReport>)> {
    frames_with_layout(device, view, config, frames, GBufferLayout::ANALYSIS)
}

fn frames_with_layout(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: u32,
    layout: GBufferLayout,
) -> Result<(PluginRenderer, Vec<FrameReport>)> {
    let frames = frames.max(2);
    let progress = phase("frames", u64::from(frames));
    let mut renderer = PluginRenderer::with_layout(device, view, config, layout)?;
    let inputs = view.frame_inputs();
    let reports = (0..frames)
        .map(|_| {
            let report = renderer.render(device, &inputs);
            progress.inc(1);
            report
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((renderer, reports))
}

fn measure(device: &Device, model: &BenchModel, args: &BenchArgs) -> Result<Measured> {
    let view = view_of(model, args)?;
    let config = ShadowConfig {
        extra_outputs: ResourceSet::of(&[ResourceId::RtVisibility]),
        ..ShadowConfig::default()
    };
    let (renderer, reports) = frames_of(device, &view, config, args.frames)?;
    let times = median_timings(&reports);
    let report = reports.last().cloned().context("no frame")?;
    let inputs = view.frame_inputs();
    // One reference for our frame and the peer's.
    let reference =
        (!args.no_reference).then(|| view_reference(&RefScene::new(&view.scene), &view));
    let wrong = match &reference {
        Some(r) => {
            let images = renderer.read_back(device, false)?;
            let c = compare_visibility_to(r, &view, &images);
            Some((c.mismatches, c.near_edge))
        }
        None => None,
    };
    let peer = if device.capabilities().ray_tracing_pipeline {
        let run = run_peer(device, &renderer, &inputs, args.frames)?;
        let wrong = match &reference {
            Some(r) => {
                let images = crate::FrameImages {
                    visibility: run.visibility,
                    ..renderer.read_back(device, false)?
                };
                Some(compare_visibility_to(r, &view, &images).mismatches)
            }
            None => None,
        };
        Some(PeerMeasured {
            build_ms: run.build_ms,
            trace_ms: run.trace_ms,
            wrong,
        })
    } else {
        None
    };
    let mut raster_build = [None, None];
    if model.framing.gtx980.is_some() {
        for ((slot, request), path) in raster_build
            .iter_mut()
            .zip([BinningRequest::Hardware, BinningRequest::Software])
            .zip(["hardware", "software"])
        {
            if passes::choose_binning_path(device.capabilities(), request).is_err() {
                continue;
            }
            let config = ShadowConfig {
                map: PrimitiveMapConfig {
                    binning: request,
                    ..args.map()
                },
                ..ShadowConfig::default()
            };
            let _binning = phase(format!("{path} conservative raster binning"), 1);
            let (_, reports) = frames_of(device, &view, config, args.frames)?;
            *slot = median_of(&median_timings(&reports), &["primitive map"]);
        }
    }
    Ok(Measured {
        name: model.name.clone(),
        triangles: view.scene.triangle_count(),
        report,
        times,
        wrong,
        peer,
        raster_build,
    })
}

fn fmt(v: Option<f64>) -> String {
    v.map_or("—".to_owned(), |v| format!("{v:.3}"))
}

fn talk_table(m: &Measured, gtx980: &[f64; 6], device: &str) -> String {
    let t = &m.times;
    let ours = [
        m.raster_build[0],
        m.raster_build[1],
        median_of(t, &["ray trace"]),
        median_of(t, &["PCSS"]),
        median_of(t, &["PCSS", "ray trace", "lerp factor", "hybrid blend"]),
        median_of(t, &["FXAA"]),
    ];
    let mut s = format!(
        "\n**{}** ({} triangles with the ground plane)\n\n| | NV GTX 980 (talk) | {device} |\n|---|---:|---:|\n| Primitive Map + compute (default) | — | {} |\n",
        m.name,
        m.triangles,
        fmt(median_of(t, &["primitive map"]))
    );
    for ((row, talk), ours) in TALK_ROWS.iter().zip(gtx980).zip(ours) {
        s.push_str(&format!("| {row} | {talk:.3} | {} |\n", fmt(ours)));
    }
    s
}

fn scene_row(m: &Measured) -> String {
    let st = &m.report.stats;
    let build = median_of(&m.times, &["primitive map"]).unwrap_or(f64::NAN);
    let trace = median_of(&m.times, &["ray trace"]).unwrap_or(f64::NAN);
    let (wrong, near) = m.wrong.map_or(("—".into(), "—".into()), |(w, n)| {
        (w.to_string(), n.to_string())
    });
    let peer = m.peer.as_ref();
    let peer_wrong = peer
        .and_then(|p| p.wrong)
        .map_or("—".into(), |w| w.to_string());
    let ratio = |ours: f64, theirs: f64| format!("{:.2}", ours / theirs);
    format!(
        "| {} | {} | {} | {:.3} | {:.3} | {:.1} | {} | {:.1} | {} | {} | {} ({near}) | {} | {} | {} | {} | {} |\n",
        m.name,
        m.triangles,
        st.triangles_binned,
        build,
        trace,
        map_bytes(&m.report) as f64 / f64::from(1 << 20),
        st.entries,
        st.mean_list(),
        st.longest_list,
        st.texels_past_capacity,
        wrong,
        peer.map_or("—".into(), |p| format!("{:.3}", p.build_ms)),
        peer.map_or("—".into(), |p| format!("{:.3}", p.trace_ms)),
        peer_wrong,
        peer.map_or("—".into(), |p| ratio(build + trace, p.build_ms + p.trace_ms)),
        peer.map_or("—".into(), |p| ratio(trace, p.trace_ms)),
    )
}

/// Measures `models` and returns the Markdown tables.
fn run_bench(device: &Device, args: &BenchArgs, models: &[BenchModel]) -> Result<String> {
    let caps = device.capabilities();
    let bar = crate::progress(models.len() as u64, "bench");
    let mut measured = Vec::new();
    for model in models {
        bar.set_message(&model.name);
        measured.push((model, measure(device, model, args)?));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mut out = format!(
        "Device: {} ({}); {}×{}, default settings (hybrid, primitive map {}² fitted to the receivers, \
         compute binning, shadow map {}²); medians of {} frames after the first (GPU timestamps, ms).\n",
        caps.device_name,
        caps.driver,
        args.width,
        args.height,
        PrimitiveMapConfig::default().size,
        passes::ShadowMapConfig::default().size,
        args.frames.max(2) - 1
    );
    out.push_str(
        "\n| model | triangles | binned | map build ms | ray trace ms | map MiB | entries | mean list | \
         longest list | texels past capacity | wrong px (near-edge) | RT-pipeline build ms | \
         RT-pipeline trace ms | RT-pipeline wrong px | ours / RT (build + trace) | ours / RT (trace) |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for (_, m) in &measured {
        out.push_str(&scene_row(m));
    }
    out.push_str(
        "\nmap build = every `primitive map:` pass (fit, receivers, setup, count, scan, fill); RT pipeline = \
         the same shadow rays through VK_KHR_ray_tracing_pipeline over driver-built acceleration \
         structures (any-hit, terminate on first hit), \"—\" where the device has none.\n",
    );
    for (model, m) in &measured {
        if let Some(gtx980) = &model.framing.gtx980 {
            out.push_str(&talk_table(m, gtx980, &caps.device_name));
        }
    }
    out.push_str("\nPCSS + Ray Trace = PCSS + ray trace + lerp factor + hybrid blend passes.\n");
    Ok(out)
}

/// The G-buffer table: per model of `models`, the demo's G-buffer pass and the plugin's passes (medians,
/// ms) with the analysis G-buffer and with a compact one.
fn run_gbuffer_bench(device: &Device, args: &BenchArgs, models: &[BenchModel]) -> Result<String> {
    let caps = device.capabilities();
    let compact = GBufferLayout::compact(device);
    let mut out = format!(
        "Device: {} ({}); {}×{}, default settings (hybrid); medians of {} frames after the first (GPU \
         timestamps, ms). G-buffer as first required: position and world normal RGBA32F, D32 depth (32 bytes \
         a pixel written); compact: {:?} depth and octahedral view-space normals in {:?} (8 bytes a pixel).\n\n\
         | model | G-buffer | G-buffer ms | plugin ms | map build ms | ray trace ms | PCSS ms | blend ms |\n\
         |---|---|---:|---:|---:|---:|---:|---:|\n",
        caps.device_name,
        caps.driver,
        args.width,
        args.height,
        args.frames.max(2) - 1,
        compact.depth,
        compact.normal,
    );
    let bar = crate::progress(models.len() as u64 * 2, "bench --gbuffer");
    for model in models {
        bar.set_message(&model.name);
        let view = view_of(model, args)?;
        for (name, layout) in [
            ("as first required", GBufferLayout::ANALYSIS),
            ("compact", compact),
        ] {
            bar.set_message(format!("{} ({name})", model.name));
            let (_, reports) =
                frames_with_layout(device, &view, ShadowConfig::default(), args.frames, layout)?;
            let times = median_timings(&reports);
            let sum = |prefix: &str| -> f64 {
                times
                    .iter()
                    .filter(|(k, _)| k.starts_with(prefix))
                    .fold(0.0, |total, (_, v)| total + v)
            };
            let plugin: f64 = times
                .iter()
                .filter(|(k, _)| {
                    k.as_str() != "gbuffer" && k.as_str() != crate::plugin::SCREEN_SPACE_WALL
                })
                .fold(0.0, |total, (_, v)| total + v);
            out.push_str(&format!(
                "| {} | {name} | {:.3} | {plugin:.3} | {:.3} | {:.3} | {:.3} | {:.3} |\n",
                model.name,
                sum("gbuffer"),
                sum("primitive map"),
                sum("ray trace"),
                sum("PCSS"),
                sum("hybrid blend"),
            ));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    out.push_str(
        "\nplugin ms = every pass the plugin timed (the shared prim buffer included), map build = every \
         `primitive map:` pass.\n",
    );
    Ok(out)
}

/// Renders the built-in scene at the benchmark's size for about a second of GPU work, so that the first
/// configuration measured does not pay for a GPU still clocking up (seen on an H100: the first light 4x
/// slower than the same light measured later).
fn warm_up(device: &Device, args: &BenchArgs) -> Result<()> {
    let bar = crate::progress(1, "bench warm-up");
    bar.set_message(format!(
        "the built-in scene at {}×{}",
        args.width, args.height
    ));
    let view = View::framed(scene::procedural_default(), args.width, args.height);
    let started = std::time::Instant::now();
    let (mut renderer, _) = frames_of(device, &view, ShadowConfig::default(), 2)?;
    let inputs = view.frame_inputs();
    while started.elapsed() < std::time::Duration::from_secs(1) {
        renderer.render(device, &inputs)?;
    }
    Ok(())
}

/// Entry point of the subcommand on the device the command line names (a name filter, validation
/// layers): prints the tables and writes them to `out` if given. What to measure is settled first, so
/// that a wrong folder, file or `--only` fails before any GPU work.
pub fn run_cli(
    device_filter: Option<String>,
    validation: bool,
    args: &BenchArgs,
    out: Option<&Path>,
) -> Result<()> {
    let work = if args.lights {
        Work::Lights(crate::light_bench::chosen_scenes(args)?)
    } else {
        Work::Models(chosen_models(args)?)
    };
    let device = crate::open_device(device_filter, validation)?;
    warm_up(&device, args)?;
    let tables = match &work {
        Work::Lights(scenes) => crate::light_bench::run_light_bench(&device, args, scenes)?,
        Work::Models(models) if args.gbuffer => run_gbuffer_bench(&device, args, models)?,
        Work::Models(models) if args.area => {
            crate::area_bench::run_area_bench(&device, args, models)?
        }
        Work::Models(models) => run_bench(&device, args, models)?,
    };
    println!("{tables}");
    if let Some(path) = out {
        std::fs::write(path, &tables).with_context(|| format!("writing {}", path.display()))?;
    }
    crate::check_validation(&device)
}

/// What `bench` measures.
enum Work {
    /// `--lights`: the light scenes.
    Lights(crate::light_bench::LightScenes),
    /// The models (the shadow table, `--gbuffer` or `--area`).
    Models(Vec<BenchModel>),
}
