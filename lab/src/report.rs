//! `hrts_lab accuracy`: what accuracy costs in time. For one view, the classic shadow map at growing
//! sizes and the ray-traced primitive map at growing N, each with its GPU time, memory, and
//! the pixels it gets wrong against the exact f64 reference (near-edge pixels counted apart).

use crate::accuracy::{compare_visibility_to, view_reference};
use crate::bench_models::median_of;
use crate::frames::{PluginFrames, ViewInputs};
use anyhow::{Context, Result};
use demo_engine::plugin::PluginRenderer;
use demo_engine::View;
use host_demo::render::{map_bytes, median_timings};
use hrts::passes_bridge;
use passes::{
    PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig, ShadowMapConfig, ShadowMode,
};
use reference::RefScene;
use rhi::Device;
use std::path::PathBuf;

/// Options of the report.
#[derive(Debug, Clone, clap::Args)]
pub struct AccuracyArgs {
    /// OBJ model, a ground plane added (default: the Stanford bunny of the models folder, `HRTS_MODELS`
    /// or `../shared/models` beside the checkout).
    #[arg(long)]
    pub obj: Option<PathBuf>,
    /// Frame width.
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 360, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub height: u32,
    /// Frames per configuration (timings are medians over all but the first).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
}

struct Row {
    method: String,
    memory: u64,
    ms: f64,
    wrong: usize,
    near_edge: usize,
}

fn render(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: u32,
) -> Result<(
    demo_engine::FrameImages,
    std::collections::BTreeMap<String, f64>,
    u64,
)> {
    let (images, reports) = render_frames(device, view, config, frames)?;
    let memory = reports.last().map_or(0, map_bytes);
    Ok((images, median_timings(&reports), memory))
}

/// Renders `frames` frames (at least 2) of `view` through the C ABI and reads the last one back.
pub fn render_frames(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: u32,
) -> Result<(demo_engine::FrameImages, Vec<hrts::FrameReport>)> {
    let progress = host_demo::progress::phase("frames", u64::from(frames.max(2)));
    let mut r = PluginRenderer::new(device, view, passes_bridge::config(&config)?)?;
    let inputs = view.frame_inputs();
    let mut reports = Vec::new();
    for _ in 0..frames.max(2) {
        reports.push(r.render(device, &inputs)?);
        progress.inc(1);
    }
    Ok((r.read_back(device, false)?, reports))
}

/// The view of an OBJ model on a ground plane, framed automatically, and its file name; the Stanford bunny
/// of the models folder without `obj`.
pub fn model_view(
    obj: Option<&std::path::Path>,
    width: u32,
    height: u32,
) -> Result<(View, String)> {
    let obj = match obj {
        Some(path) => path.to_path_buf(),
        None => scene::models_dir()
            .map_err(anyhow::Error::msg)?
            .join("02_stanford_bunny_69k.obj"),
    };
    let scene = scene::load_obj(&obj)
        .with_context(|| format!("loading {}", obj.display()))?
        .with_ground_plane();
    let label = obj
        .file_name()
        .map_or_else(|| "scene".into(), |n| n.to_string_lossy().into_owned());
    Ok((View::framed(scene, width, height), label))
}

/// Builds the report as Markdown.
pub fn run_report(device: &Device, args: &AccuracyArgs) -> Result<String> {
    let bar = host_demo::progress(8, "accuracy");
    bar.set_message("the exact reference");
    let (view, label) = model_view(args.obj.as_deref(), args.width, args.height)?;
    // One reference for every configuration: the same view.
    let reference = view_reference(&RefScene::new(&view.scene), &view);
    bar.inc(1);
    let sum = |t: &std::collections::BTreeMap<String, f64>, names: &[&str]| {
        median_of(t, names).unwrap_or(f64::NAN)
    };
    let mut rows = Vec::new();
    for size in [1024u32, 3072, 8192] {
        bar.set_message(format!("shadow map {size}²"));
        let config = ShadowConfig {
            mode: ShadowMode::Hard,
            antialiasing: false,
            map: PrimitiveMapConfig {
                size: 256,
                ..PrimitiveMapConfig::default()
            },
            shadow_map: ShadowMapConfig {
                size,
                ..ShadowMapConfig::default()
            },
            extra_outputs: ResourceSet::of(&[ResourceId::ShadowMapVisibility]),
            ..ShadowConfig::default()
        };
        let (mut images, t, _) = render(device, &view, config, args.frames)?;
        images.visibility = std::mem::take(&mut images.shadow_map_visibility);
        let c = compare_visibility_to(&reference, &view, &images);
        rows.push(Row {
            method: format!("shadow map {size}² (classic test, constant + slope bias)"),
            memory: u64::from(size) * u64::from(size) * 4,
            ms: sum(&t, &["shadow map"]),
            wrong: c.mismatches,
            near_edge: c.near_edge,
        });
        bar.inc(1);
    }
    for size in [256u32, 512, 1024, 2048] {
        bar.set_message(format!("primitive map {size}²"));
        let map = PrimitiveMapConfig {
            size,
            ..PrimitiveMapConfig::default()
        };
        let (images, t, memory) = render(device, &view, ShadowConfig::from(map), args.frames)?;
        let c = compare_visibility_to(&reference, &view, &images);
        rows.push(Row {
            method: format!("ray traced, primitive map {size}² (fitted, exact lists)"),
            memory,
            ms: sum(&t, &["primitive map", "ray trace"]),
            wrong: c.mismatches,
            near_edge: c.near_edge,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    let caps = device.capabilities();
    let mut s = format!(
        "{} ({} triangles with the ground plane), {}×{} px on {}; wrong = pixels whose lit/shadowed value differs from the exact f64 reference outside near-edge pixels; GPU ms are medians over {} frames.\n\n| method | memory | GPU ms | wrong pixels | near-edge (not compared) |\n|---|---:|---:|---:|---:|\n",
        label,
        view.scene.triangle_count(),
        args.width,
        args.height,
        caps.device_name,
        args.frames.max(2) - 1
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {:.1} MiB | {:.3} | {} | {} |\n",
            r.method,
            r.memory as f64 / (1024.0 * 1024.0),
            r.ms,
            r.wrong,
            r.near_edge,
        ));
    }
    Ok(s)
}
