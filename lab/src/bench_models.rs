//! The benchmarks' options and models: `BenchArgs`, the shared models and how each is framed, the models a
//! run chooses (`--models`, `--obj`, `--only`), their views, and the frames rendered of them. `bench`,
//! `bench --area` and `bench --lights` share them.

use crate::frames::{PluginFrames, ViewInputs};
use anyhow::{bail, Context, Result};
use demo_engine::gbuffer::GBufferLayout;
use demo_engine::plugin::PluginRenderer;
use demo_engine::View;
use glam::Vec3;
use host_demo::progress::phase;
use hrts::passes_bridge;
use hrts::FrameReport;
use passes::{AreaConfig, PrimitiveMapConfig, ShadowConfig};
use rhi::{Device, Format};
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
    #[arg(long, default_value_t = 1920, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 1080, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
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
    #[arg(long, default_value_t = hrts::Config::default().area_samples)]
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
    #[arg(long, default_value_t = hrts::Config::default().map_list_limit)]
    pub list_limit: u32,
    /// Bin items per pixel with a ray past which a frame builds no list and every pixel walks the BVH
    /// (0: always the BVH; inf: always lists).
    #[arg(long, default_value_t = hrts::Config::default().map_bin_budget)]
    pub bin_budget: f32,
    /// Area shadows: the nodes and triangles a pixel's walk of the BVH with a wide bundle of segments or
    /// rays may visit per 64 open samples (scaled by the bundle's width) before each open sample walks its
    /// own (0: each sample's own walk at once; 4294967295: the bundle always).
    #[arg(long, default_value_t = hrts::Config::default().area_walk_budget)]
    pub area_walk_budget: u32,
    /// With --lights: give the plugin an R32F output without storage usage, as an engine whose output the
    /// lights cannot write: each light's layer is copied in ("output copy" in the per-pass split). Default:
    /// a storage output each light writes directly.
    #[arg(long, requires = "lights")]
    pub copied_output: bool,
    /// With --lights: the output's format, as an engine's shadow mask: r32f, r16f (R16_SFLOAT) or r8
    /// (R8_UNORM). With storage usage each light writes its layer in this format directly; with
    /// --copied-output each layer is copied (r32f) or converted by a blit.
    #[arg(long, default_value = "r32f", requires = "lights", value_parser = ["r32f", "r16f", "r8"])]
    pub output_format: String,
    /// With --lights and --point-lights: also write each scene with its point lights (the first emitter
    /// size) as glTF into this folder (`MODEL_N_point_lights.glb`), so that `render --scene` renders what
    /// the bench measured, through the scene's plan.
    #[arg(long, requires = "point_lights")]
    pub write_scenes: Option<std::path::PathBuf>,
    /// With --lights: the primitive map's N (texels per side; a point light's cube faces share N²); 0: the
    /// plugin's choice (512 for hard and area shadows, 1024 for the hybrid).
    #[arg(long, default_value_t = hrts::Config::default().map_size, requires = "lights", value_parser = clap::value_parser!(u32).range(0..=i64::from(u16::MAX)))]
    pub map_size: u32,
}

impl BenchArgs {
    /// The output's format (`--output-format`).
    pub fn output_format(&self) -> Format {
        match self.output_format.as_str() {
            "r16f" => Format::R16Float,
            "r8" => Format::R8Unorm,
            _ => Format::R32Float,
        }
    }

    /// The primitive map the benchmark's configurations take: the default with the given list limit and
    /// bin budget (and, for --lights, N).
    /// The area settings of these options, with `samples` light samples per pixel.
    pub fn area(&self, samples: u32) -> AreaConfig {
        AreaConfig {
            samples,
            bundle_walk_budget: self.area_walk_budget,
        }
    }

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
    /// The talk's GTX 980 column for this model (`TALK_ROWS`), if the talk measured it.
    pub(crate) gtx980: Option<[f64; 6]>,
}

pub(crate) const TALK_ROWS: [&str; 6] = [
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
    pub(crate) framing: &'static Framing,
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

pub(crate) fn frames_with_layout(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: u32,
    layout: GBufferLayout,
) -> Result<(PluginRenderer, Vec<FrameReport>)> {
    let frames = frames.max(2);
    let progress = phase("frames", u64::from(frames));
    let mut renderer =
        PluginRenderer::with_layout(device, view, passes_bridge::config(&config)?, layout)?;
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
