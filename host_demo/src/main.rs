//! `host_demo`: the standalone demo of hybrid ray-traced shadows.

use anyhow::{bail, Context, Result};
use clap::{CommandFactory, Parser, Subcommand};
use demo_engine::{Device, View};
use glam::Vec3;
use host_demo::interior::Enclosure;
use host_demo::parse_vec3;
use host_demo::render::{
    parse_binning, parse_faces, render_to_folder, RenderOptions, SoftShadowArgs,
};
use host_demo::scene_plan::{load_and_plan, plan_file, PlanRequest, PlannedScene};
use host_demo::scene_render::render_scene_to_folder;
use hrts::{BinningPath, Faces, ShadowMode};
use reference::RefScene;
use scene::{Camera, DirectionalLight, LightSize, Scene, SceneLight};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    version,
    about = "Hybrid ray-traced shadows (deep primitive map) — standalone demo host"
)]
struct Cli {
    /// Vulkan device whose name contains this (e.g. llvmpipe, NVIDIA); default: the best GPU, else lavapipe.
    #[arg(long, global = true, env = "HRTS_DEVICE")]
    device: Option<String>,
    /// Enable Vulkan validation layers (also HRTS_VALIDATION=1); any validation error fails the run.
    #[arg(long, global = true)]
    validation: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render one view: G-buffer, primitive map, ray-traced shadows; writes EXR/PNG/JSON and prints GPU timings.
    /// With --scene, every light of a glTF scene as the scene's plan says (see `plan`).
    Render(RenderArgs),
    /// Print the plan of a glTF scene without rendering (no GPU): per light the shadow it gets (none, hard or
    /// hybrid) and why, the light as the plugin takes it (its frusta), configuration, passes and resources.
    Plan(PlanArgs),
    /// Write the example glTF scene (ground, boxes, a moving cart; a sized sun, a zero-size rim light, a
    /// sized spot light, a moving point lamp and a fill light that casts no shadows): binary glTF if FILE
    /// ends in .glb, else glTF JSON with the buffer embedded.
    ExampleScene {
        /// Where to write the scene.
        #[arg(long)]
        out: PathBuf,
    },
    /// What loading a glTF scene costs: load time and peak resident memory; or write generated test scenes
    /// (float, meshopt, quantized + meshopt) to measure it on.
    LoadReport(host_demo::load_report::LoadReportArgs),
}

#[derive(clap::Args)]
struct RenderArgs {
    /// glTF 2.0 scene (.gltf or .glb) whose lights (KHR_lights_punctual) decide the shadows: renders every
    /// light, writes the shaded image, each light's visibility (PNG and EXR) and scene_report.json, and
    /// prints the plan and each frame's per-light report.
    #[arg(long, conflicts_with_all = ["obj", "no_ground", "light_dir", "mode", "angular_radius"])]
    scene: Option<PathBuf>,
    /// OBJ file to load (default: the built-in procedural scene). A closed model (a room) is seen from
    /// inside and lit by a point light below its ceiling, rendered as --scene renders a scene's lights.
    #[arg(long)]
    obj: Option<PathBuf>,
    /// Do not add a ground plane under an OBJ model (a closed model never gets one).
    #[arg(long)]
    no_ground: bool,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    size: host_demo::cli::FrameSizeArgs,
    /// Direction the light travels, "x,y,z" (default: slanted, about 34° from vertical; inside a closed
    /// model, a point light below its ceiling).
    #[arg(long, value_parser = parse_vec3)]
    light_dir: Option<Vec3>,
    #[command(flatten)]
    camera: host_demo::cli::CameraArgs,
    /// Primitive map size N: texels per side of the light-space grid fitted to the visible receivers (moves
    /// cost, never exactness); 0: the plugin's choice (512 for hard and area shadows, 1024 for the hybrid).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=i64::from(host_demo::limits::MAP_SIZE)))]
    map_size: u32,
    /// Largest memory of the primitive map's list entries, in MiB (the lists grow to what frames need).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..))]
    map_budget_mb: u32,
    /// Faces stored: both (open geometry) or front (closed meshes only).
    #[arg(long, default_value = "both", value_parser = parse_faces)]
    faces: Faces,
    /// Binning path of the primitive map: auto (compute), compute, hw (hardware conservative raster) or
    /// sw (geometry-shader conservative raster).
    #[arg(long, default_value = "auto", value_parser = parse_binning)]
    binning: BinningPath,
    /// A texel whose list would pass this many entries keeps none: its pixels walk the BVH (0: the
    /// plugin's choice by mode; moves cost, never exactness).
    #[arg(long, default_value_t = hrts::Config::default().map_list_limit)]
    list_limit: u32,
    /// Bin items per pixel with a ray past which a frame builds no list and every pixel walks the BVH
    /// (0: always the BVH; inf: always lists; moves cost, never exactness).
    #[arg(long, default_value_t = hrts::Config::default().map_bin_budget)]
    bin_budget: f32,
    /// Area shadows: the nodes and triangles a pixel's walk of the BVH with a wide bundle of segments or
    /// rays may visit per 64 open samples (scaled by the bundle's width) before each open sample walks its
    /// own (0: each sample's own walk at once; 4294967295: the bundle always; moves cost, never exactness).
    #[arg(long, default_value_t = hrts::Config::default().area_walk_budget)]
    area_walk_budget: u32,
    /// Frames to render (timings are medians over all but the first; at least 2 with --scene, so that the
    /// second frame's report shows what was kept).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// Skip the primitive map's occupancy view (occupancy.png), a debug image: the frame as an engine
    /// runs it (the map's statistics are gathered anyway).
    #[arg(long)]
    no_occupancy: bool,
    /// With --scene: hold the scene still. The demo does not animate scenes; with --still every object and
    /// light counts as static, so the second frame reuses the prim buffer and every shadow map. Without it,
    /// what the scene marks as moving is re-rendered every frame.
    #[arg(long, requires = "scene")]
    still: bool,
    #[command(flatten)]
    soft: SoftShadowArgs,
}

#[derive(clap::Args)]
struct PlanArgs {
    /// glTF 2.0 scene (.gltf or .glb).
    #[arg(long)]
    scene: PathBuf,
    #[command(flatten)]
    size: host_demo::cli::FrameSizeArgs,
    #[command(flatten)]
    camera: host_demo::cli::CameraArgs,
    /// Primitive map size N; 0: the plugin's choice (512 for hard and area shadows, 1024 for the hybrid).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=i64::from(host_demo::limits::MAP_SIZE)))]
    map_size: u32,
    /// Shadow map size (square) of the sized lights.
    #[arg(long, default_value_t = 3072, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    shadow_map_size: u32,
    /// Turn off FXAA over the ray-traced shadows.
    #[arg(long)]
    no_antialiasing: bool,
    /// Hold the scene still: every object and light counts as static (see `render --still`).
    #[arg(long)]
    still: bool,
}

/// What `--still` prints.
const STILL: &str = "--still: every object and light of the scene counts as static";

fn plan(args: &PlanArgs) -> Result<()> {
    let soft = SoftShadowArgs {
        shadow_map_size: args.shadow_map_size,
        no_antialiasing: args.no_antialiasing,
        ..SoftShadowArgs::default()
    };
    let map = hrts::Config {
        map_size: args.map_size,
        ..hrts::Config::default()
    };
    let base = |world_space_scale| soft.config(map, world_space_scale);
    let request = PlanRequest {
        width: args.size.width,
        height: args.size.height,
        camera_position: args.camera.camera_pos,
        camera_target: args.camera.camera_target,
        still: args.still,
        base: &base,
    };
    let planned = load_and_plan(&args.scene, &request)?;
    if args.still {
        println!("{STILL}");
    }
    println!(
        "scene {}: {} triangles, {}x{} px, camera {}",
        args.scene.display(),
        planned.file.scene.triangle_count(),
        args.size.width,
        args.size.height,
        match (
            &planned.file.camera,
            args.camera.camera_pos.or(args.camera.camera_target)
        ) {
            (_, Some(_)) => "from the command line",
            (Some(_), None) => "from the file",
            (None, None) => "framed by the demo",
        }
    );
    print!("{}", planned.plan.describe());
    Ok(())
}

/// `render --scene`: the glTF file at `path` loaded and planned ([`load_and_plan`]), then rendered
/// ([`render_scene_to_folder`]).
fn render_scene(cli: &Cli, args: &RenderArgs, path: &Path) -> Result<()> {
    if args.frames < 2 {
        bail!("--frames must be at least 2 with --scene: the second frame's report shows what was kept");
    }
    let planned = load_and_plan(path, &scene_request(args, &render_base(args)))?;
    if args.still {
        println!("{STILL}");
    }
    render_planned(cli, args, path, &planned)
}

/// The base configuration of `render`'s command line for a scene of the given world-space scale.
fn render_base(args: &RenderArgs) -> impl Fn(f32) -> hrts::Config + '_ {
    move |world_space_scale| args.soft.config(map_config(args), world_space_scale)
}

/// The plan request of `render`'s command line, with the base configuration `base` ([`render_base`]).
fn scene_request<'a>(args: &RenderArgs, base: &'a dyn Fn(f32) -> hrts::Config) -> PlanRequest<'a> {
    PlanRequest {
        width: args.size.width,
        height: args.size.height,
        camera_position: args.camera.camera_pos,
        camera_target: args.camera.camera_target,
        still: args.still,
        base,
    }
}

/// Renders `planned` (read from `path`) into `--out` on the command line's device.
fn render_planned(cli: &Cli, args: &RenderArgs, path: &Path, planned: &PlannedScene) -> Result<()> {
    let device = device(cli)?;
    render_scene_to_folder(&device, path, planned, args.frames, &args.out)?;
    demo_engine::check_validation(&device)
}

fn render(cli: &Cli, args: &RenderArgs) -> Result<()> {
    if args.out.exists() && !args.out.is_dir() {
        bail!(
            "--out {} is a file, not a folder: name a folder (it is created if missing)",
            args.out.display()
        );
    }
    if let Some(path) = &args.scene {
        return render_scene(cli, args, path);
    }
    let explicit_camera = args.camera.camera_pos.is_some() || args.camera.camera_target.is_some();
    let mut interior_camera = None;
    let scene = match &args.obj {
        Some(path) => {
            let model = scene::load_obj(path)?;
            let closed = if explicit_camera && args.light_dir.is_some() {
                None
            } else {
                closed_interior(&model, args)?
            };
            match closed {
                Some(interior) if args.light_dir.is_none() => {
                    return render_closed(cli, args, path, model, interior);
                }
                Some(interior) => {
                    interior_camera = Some(interior.camera);
                    model
                }
                None if args.no_ground => model,
                None => model.with_ground_plane(),
            }
        }
        None => scene::procedural_default(),
    };
    let mut view = View::framed(scene, args.size.width, args.size.height);
    if let Some(camera) = interior_camera {
        view.camera = camera;
    }
    if let Some(d) = args.light_dir {
        view.light =
            DirectionalLight::new(d).context("--light-dir must be a non-zero finite vector")?;
    }
    view.camera = args.camera.apply(view.camera, &view.scene.bounds())?;
    let device = device(cli)?;
    let options = RenderOptions {
        map: map_config(args),
        frames: args.frames,
        soft: args.soft.clone(),
        occupancy_view: !args.no_occupancy,
    };
    render_to_folder(&device, &view, &options, &args.out)?;
    demo_engine::check_validation(&device)
}

/// The camera and light inside a closed model, as `render --obj` places them by default.
struct Interior {
    camera: Camera,
    light: SceneLight,
}

/// Whether `model` is a closed scene (see [`host_demo::interior`]), printed with what follows from it;
/// if it is, the camera and light inside it. `args` says which of them the command line sets.
fn closed_interior(model: &Scene, args: &RenderArgs) -> Result<Option<Interior>> {
    let reference = RefScene::new(model);
    let enclosure = Enclosure::probe(&reference, &model.bounds());
    let angular_radius = match args.soft.mode {
        ShadowMode::Hybrid | ShadowMode::Area => args.soft.angular_radius,
        _ => 0.0,
    };
    let aspect = args.size.width as f32 / args.size.height as f32;
    let inside = (
        enclosure.interior_camera(&reference, aspect),
        enclosure.interior_light(&reference, angular_radius),
    );
    let (true, (Some(camera), Some(mut light))) = (enclosure.is_closed(), inside) else {
        println!(
            "{}; the default view is from outside, lit by the sun",
            enclosure.describe()
        );
        return Ok(None);
    };
    let camera_text = if args.camera.camera_pos.is_some() || args.camera.camera_target.is_some() {
        "camera from the command line".to_owned()
    } else {
        format!(
            "camera inside at ({}) looking at ({})",
            xyz(camera.position),
            xyz(camera.target)
        )
    };
    let light_text = match (args.light_dir, light.kind.position()) {
        (None, Some(position)) => {
            match args.soft.mode {
                ShadowMode::Soft | ShadowMode::Area | ShadowMode::Auto => bail!(
                    "--mode {}: the point light inside a closed scene is shadowed hard or hybrid; pass \
                     --light-dir for a sun with soft shadows",
                    args.soft.mode.name()
                ),
                ShadowMode::None => light.casts_shadows = false,
                ShadowMode::Hard | ShadowMode::Hybrid => {}
            }
            let size = match light.size {
                LightSize::Radius(r) => format!("a sphere of radius {r:.3}"),
                _ => "zero size".to_owned(),
            };
            format!(
                "point light at ({}) below the ceiling, {size}",
                xyz(position)
            )
        }
        _ => "the sun of --light-dir".to_owned(),
    };
    println!(
        "{}; {camera_text}, {light_text}; no ground plane",
        enclosure.describe()
    );
    Ok(Some(Interior { camera, light }))
}

/// "x, y, z" with three decimals.
fn xyz(v: Vec3) -> String {
    format!("{:.3}, {:.3}, {:.3}", v.x, v.y, v.z)
}

/// Renders a closed model as a scene of one interior point light (see `render --scene`), seen from
/// the interior camera unless the command line places it.
fn render_closed(
    cli: &Cli,
    args: &RenderArgs,
    path: &Path,
    model: Scene,
    interior: Interior,
) -> Result<()> {
    let file = host_demo::interior::scene_file(model, interior.light, interior.camera);
    let planned = plan_file(file, &scene_request(args, &render_base(args)))
        .with_context(|| format!("planning {}", path.display()))?;
    render_planned(cli, args, path, &planned)
}

/// The primitive map the command line asks for.
fn map_config(args: &RenderArgs) -> hrts::Config {
    hrts::Config {
        map_size: args.map_size,
        faces: args.faces,
        binning_path: args.binning,
        map_entry_budget_kib: args.map_budget_mb.saturating_mul(1024),
        map_list_limit: args.list_limit,
        map_bin_budget: args.bin_budget,
        area_walk_budget: args.area_walk_budget,
        ..hrts::Config::default()
    }
}

/// The device chosen by the global options.
fn device(cli: &Cli) -> Result<Device> {
    demo_engine::open_device(cli.device.clone(), cli.validation)
}

/// The command line of [`Cli`], where every option of numbers takes negative ones as people type them
/// (`--camera-pos -5,2,3`, not only `--camera-pos=-5,2,3`).
fn command() -> clap::Command {
    host_demo::cli::negative_numbers(Cli::command())
}

fn main() -> ExitCode {
    host_demo::cli::main_of(command, |cli: &Cli| match &cli.command {
        Command::Render(args) => render(cli, args),
        Command::Plan(args) => plan(args),
        Command::ExampleScene { out } => scene::gltf_scene::write_example_scene(out)
            .map_err(anyhow::Error::from)
            .map(|()| println!("example scene written to {}", out.display())),
        Command::LoadReport(args) => host_demo::load_report::run_cli(args),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::error::ErrorKind;
    use clap::FromArgMatches;

    /// Every option of numbers of every subcommand takes a negative value as a separate argument.
    #[test]
    fn every_option_of_numbers_takes_negative_values() {
        let checked =
            host_demo::cli::check_negative_numbers(command).unwrap_or_else(|e| panic!("{e}"));
        for expected in [
            "render --camera-pos",
            "render --camera-target",
            "render --light-dir",
            "render --bin-budget",
            "render --angular-radius",
            "render --width",
            "plan --camera-pos",
            "plan --camera-target",
        ] {
            assert!(
                checked.iter().any(|c| c == expected),
                "{expected} not checked: {checked:?}"
            );
        }
    }

    /// Options of other values still refuse a value that looks like a flag; a vector option followed by a
    /// flag instead of its value is still refused (with the flag as its value, and what follows
    /// unexpected).
    #[test]
    fn other_options_keep_refusing_hyphen_values() {
        let e = command()
            .try_get_matches_from(["host_demo", "render", "--out", "-x"])
            .expect_err("--out -x is refused");
        assert_eq!(e.kind(), ErrorKind::UnknownArgument, "{e}");
        for args in [
            &["--camera-pos", "--camera-target", "0,0,0"][..],
            &["--camera-pos", "--camera-target=0,0,0"][..],
        ] {
            let parsed = command()
                .try_get_matches_from(["host_demo", "render"].iter().chain(args))
                .and_then(|m| Cli::from_arg_matches(&m));
            assert!(parsed.is_err(), "{args:?} accepted");
        }
    }
}
