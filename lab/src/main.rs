//! `hrts_lab`: the lab's command line: benchmarks, hard cases, accuracy and trade-off reports, the talk's
//! side-by-sides, the conservative-raster tier matrix and ray dumps.

use anyhow::{bail, Context, Result};
use clap::{CommandFactory, Parser, Subcommand};
use demo_engine::View;
use glam::Vec3;
use host_demo::cli::CameraArgs;
use host_demo::parse_vec3;
use host_demo::render::{render_to_folder, RenderOptions, SoftShadowArgs};
use hrts_lab::frames::ViewInputs;
use rhi::Device;
use scene::DirectionalLight;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    version,
    about = "Hybrid ray-traced shadows (deep primitive map) — the lab: benchmarks, hard cases, accuracy"
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
    /// The talk's timing tables (~10K/65K/240K triangles, 1920x1080, shadow map 3072², primitive map 1024²
    /// fitted to the receivers, lists of their own length) next to its GTX 980 column, and every model of
    /// the models folder: GPU timestamps, medians over frames. With --lights: local lights inside scenes.
    Bench {
        #[command(flatten)]
        args: hrts_lab::bench::BenchArgs,
        /// Also write the Markdown tables to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run the hard numerical cases against the exact reference and print a table; fails if any case fails.
    Hardcases(hrts_lab::hardcases::HardcasesArgs),
    /// What accuracy costs in time: shadow maps and primitive maps of growing size against the exact
    /// reference, with GPU times and memory (Markdown).
    Accuracy(hrts_lab::report::AccuracyArgs),
    /// What accuracy costs in time for soft shadows: every method and setting against a ground-truth soft
    /// shadow, with GPU time and memory; CSV, JSON, a Pareto plot and error maps.
    Tradeoff(hrts_lab::tradeoff::TradeoffArgs),
    /// The talk's side-by-sides on one view (shadow map 3K/8K, ray traced with primitive maps 1K/256, PCSS
    /// 3K, hybrid standard and shrinking, the lerp factor): labelled composite PNG, the individual pictures
    /// and a caption file.
    Compare(hrts_lab::compare::CompareArgs),
    /// The conservative-raster tier matrix: every raster path of the device against exact binning (Markdown).
    Tiers {
        /// Folder with the test models (default: `HRTS_MODELS`, else `../shared/models` beside the
        /// checkout).
        #[arg(long)]
        models: Option<PathBuf>,
    },
    /// Render a view's ray-traced hard shadow of a sun (as `host_demo render --mode hard
    /// --no-antialiasing --no-occupancy` writes it) and write its shadow rays and triangles beside it
    /// (rays.f32, triangles.f32, ray_near_edge.u8, rays.json), for scripts/embree_compare.py.
    RayDump(RayDumpArgs),
}

#[derive(clap::Args)]
struct RayDumpArgs {
    /// OBJ file to load, on a ground plane (default: the built-in procedural scene).
    #[arg(long)]
    obj: Option<PathBuf>,
    /// Do not add a ground plane under the OBJ model.
    #[arg(long, requires = "obj")]
    no_ground: bool,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[command(flatten)]
    size: host_demo::cli::FrameSizeArgs,
    /// Direction the sun's light travels, "x,y,z" (default: slanted, about 34° from vertical).
    #[arg(long, value_parser = parse_vec3)]
    light_dir: Option<Vec3>,
    #[command(flatten)]
    camera: CameraArgs,
    /// Frames to render (the timings in frame.json are medians over all but the first).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
}

/// Renders the view `args` describe in hard mode and writes its ray dump.
fn ray_dump(device: &Device, args: &RayDumpArgs) -> Result<()> {
    let scene = match &args.obj {
        Some(path) if args.no_ground => scene::load_obj(path)?,
        Some(path) => scene::load_obj(path)?.with_ground_plane(),
        None => scene::procedural_default(),
    };
    let mut view = View::framed(scene, args.size.width, args.size.height);
    if let Some(d) = args.light_dir {
        view.light =
            DirectionalLight::new(d).context("--light-dir must be a non-zero finite vector")?;
    }
    view.camera = args.camera.apply(view.camera, &view.scene.bounds())?;
    let options = RenderOptions {
        map: hrts::Config::default(),
        frames: args.frames,
        soft: SoftShadowArgs {
            mode: hrts::ShadowMode::Hard,
            no_antialiasing: true,
            ..SoftShadowArgs::default()
        },
        occupancy_view: false,
    };
    render_to_folder(device, &view, &options, &args.out)?;
    let bar = host_demo::progress(1, "ray dump");
    bar.set_message("the frame's shadow rays");
    let dump = hrts_lab::ray_dump::write_ray_dump(&view, &view.frame_inputs(), &args.out)?;
    drop(bar);
    println!("ray dump: {dump:?}");
    Ok(())
}

/// The command line of [`Cli`], where every option of numbers takes negative ones as people type them.
fn command() -> clap::Command {
    host_demo::cli::negative_numbers(Cli::command())
}

fn run(cli: &Cli) -> Result<()> {
    let device = || demo_engine::open_device(cli.device.clone(), cli.validation);
    match &cli.command {
        Command::Hardcases(args) => {
            hrts_lab::hardcases::run_cli(cli.device.clone(), cli.validation, args)
        }
        Command::Compare(args) => {
            hrts_lab::compare::run_cli(cli.device.clone(), cli.validation, args)
        }
        Command::Bench { args, out } => {
            hrts_lab::bench::run_cli(cli.device.clone(), cli.validation, args, out.as_deref())
        }
        Command::Tradeoff(args) => hrts_lab::tradeoff::run_cli(&device()?, args),
        Command::Accuracy(args) => {
            println!("{}", hrts_lab::report::run_report(&device()?, args)?);
            Ok(())
        }
        Command::Tiers { models } => {
            let d = device()?;
            let models = match models {
                Some(dir) => dir.clone(),
                None => scene::models_dir().map_err(anyhow::Error::msg)?,
            };
            let rows =
                hrts_lab::tiers::tier_matrix(&d, &hrts_lab::tiers::standard_scenes(&models)?, 256)?;
            println!("{}", hrts_lab::tiers::markdown(&d, &rows));
            if rows.iter().all(|r| r.passed()) {
                Ok(())
            } else {
                bail!("a binning path missed triangles of the exact conservative set")
            }
        }
        Command::RayDump(args) => {
            let d = device()?;
            ray_dump(&d, args)?;
            demo_engine::check_validation(&d)
        }
    }
}

fn main() -> ExitCode {
    host_demo::cli::main_of(command, run)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every option of numbers of every subcommand takes a negative value as a separate argument.
    #[test]
    fn every_option_of_numbers_takes_negative_values() {
        let checked =
            host_demo::cli::check_negative_numbers(command).unwrap_or_else(|e| panic!("{e}"));
        for expected in [
            "compare --camera-pos",
            "compare --camera-target",
            "compare --close-up-pos",
            "compare --close-up-target",
            "bench --emitter-size",
            "bench --angular-radius",
            "tradeoff --angular-radius",
            "ray-dump --camera-pos",
            "ray-dump --light-dir",
        ] {
            assert!(
                checked.iter().any(|c| c == expected),
                "{expected} not checked: {checked:?}"
            );
        }
    }
}
