//! `host_demo bench`: the talk's timing tables — Primitive Map + HW CR / + SW CR, Ray Trace, PCSS,
//! PCSS + Ray Trace, FXAA — for ~10K, ~65K and ~240K triangles at 1920×1080, shadow map 3K×3K and
//! primitive map 1K×1K×32/64, next to the talk's GTX 980 column. GPU timestamps, medians over frames.

use crate::plugin::PluginRenderer;
use crate::render::{median_timings, RenderOptions, SoftShadowArgs};
use crate::View;
use anyhow::{Context, Result};
use passes::{FaceMode, PrimitiveMapConfig, RasterRequest, ShadowMode};
use rhi::{ConservativeRasterTier, Device};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Options of the benchmark.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// Folder with the test models (01_scorpion_low_12k.obj, 02_stanford_bunny_69k.obj, 03_bunny_hr_x4_239k.obj).
    #[arg(long, default_value = "../shared/models")]
    pub models: PathBuf,
    /// Frames per configuration; medians over all but the first.
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
    /// Frame width.
    #[arg(long, default_value_t = 1920)]
    pub width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 1080)]
    pub height: u32,
    /// Shadow map size.
    #[arg(long, default_value_t = 3072)]
    pub shadow_map_size: u32,
    /// Primitive map size N.
    #[arg(long, default_value_t = 1024)]
    pub map_size: u32,
}

/// One model of the talk's tables with its primitive map depth and the talk's GTX 980 times (ms).
struct Case {
    file: &'static str,
    depth: u32,
    gtx980: [Option<f64>; 6],
}

const ROWS: [&str; 6] = [
    "Primitive Map + HW CR",
    "Primitive Map + SW CR",
    "Ray Trace",
    "PCSS",
    "PCSS + Ray Trace",
    "FXAA",
];

const CASES: [Case; 3] = [
    Case {
        file: "01_scorpion_low_12k.obj",
        depth: 32,
        gtx980: [
            Some(0.4),
            Some(0.5),
            Some(0.4),
            Some(1.3),
            Some(1.8),
            Some(0.2),
        ],
    },
    Case {
        file: "02_stanford_bunny_69k.obj",
        depth: 64,
        gtx980: [
            Some(0.5),
            Some(0.7),
            Some(0.7),
            Some(1.3),
            Some(2.8),
            Some(0.2),
        ],
    },
    Case {
        file: "03_bunny_hr_x4_239k.obj",
        depth: 64,
        gtx980: [
            Some(3.4),
            Some(4.1),
            Some(1.0),
            Some(1.3),
            Some(3.4),
            Some(0.2),
        ],
    },
];

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

fn run(
    device: &Device,
    view: &View,
    args: &BenchArgs,
    depth: u32,
    raster: RasterRequest,
) -> Result<(BTreeMap<String, f64>, u32)> {
    let options = RenderOptions {
        map: PrimitiveMapConfig {
            size: args.map_size,
            depth,
            faces: FaceMode::Both,
            raster,
            guard_layer: false,
        },
        frames: args.frames,
        soft: SoftShadowArgs {
            mode: ShadowMode::Hybrid,
            shadow_map_size: args.shadow_map_size,
            ..SoftShadowArgs::default()
        },
    };
    let mut config = options.shadow_config(view);
    config.extra_outputs = passes::ResourceSet::EMPTY;
    let mut renderer = PluginRenderer::new(device, view, config)?;
    let inputs = view.frame_inputs();
    let mut reports = Vec::new();
    for _ in 0..args.frames.max(2) {
        reports.push(renderer.render(device, &inputs)?);
    }
    let overflow = reports.last().map_or(0, |r| r.stats.overflowed_texels);
    Ok((median_timings(&reports), overflow))
}

/// Runs every case and returns the Markdown tables.
pub fn run_bench(device: &Device, args: &BenchArgs) -> Result<String> {
    let caps = device.capabilities();
    let hw = caps.conservative_raster_tier != ConservativeRasterTier::NotSupported;
    let mut out = format!(
        "Device: {} ({}); {}×{}, shadow map {}², primitive map {}²×d; medians of {} frames after the first (GPU timestamps, ms).\n",
        caps.device_name,
        caps.driver,
        args.width,
        args.height,
        args.shadow_map_size,
        args.map_size,
        args.frames.max(2) - 1
    );
    for case in &CASES {
        let path = args.models.join(case.file);
        let scene = scene::load_obj(&path)
            .with_context(|| format!("loading {}", path.display()))?
            .with_ground_plane();
        let triangles = scene.triangle_count();
        let view = View::framed(scene, args.width, args.height);
        let (sw, sw_overflow) = run(device, &view, args, case.depth, RasterRequest::Software)?;
        let hw_times = if hw {
            Some(run(device, &view, args, case.depth, RasterRequest::Hardware)?.0)
        } else {
            None
        };
        let main = hw_times.as_ref().unwrap_or(&sw);
        let ours = [
            hw_times
                .as_ref()
                .and_then(|t| median_of(t, &["primitive map"])),
            median_of(&sw, &["primitive map"]),
            median_of(main, &["ray trace"]),
            median_of(main, &["PCSS"]),
            median_of(main, &["PCSS", "ray trace", "lerp factor", "hybrid blend"]),
            median_of(main, &["FXAA"]),
        ];
        out.push_str(&format!(
            "\n**{}**: {} triangles (with the ground plane), primitive map {}²×{}, {} overflowed texels; shadow map render {} ms.\n\n",
            case.file,
            triangles,
            args.map_size,
            case.depth,
            sw_overflow,
            median_of(main, &["shadow map"]).map_or("—".into(), |v| format!("{v:.3}"))
        ));
        out.push_str(&format!(
            "| | NV GTX 980 (talk) | {} |\n|---|---:|---:|\n",
            caps.device_name
        ));
        for ((row, talk), ours) in ROWS.iter().zip(case.gtx980).zip(ours) {
            let fmt = |v: Option<f64>| v.map_or("—".to_owned(), |v| format!("{v:.3}"));
            out.push_str(&format!("| {row} | {} | {} |\n", fmt(talk), fmt(ours)));
        }
    }
    out.push_str("\nPCSS + Ray Trace = PCSS + ray trace + lerp factor + hybrid blend passes.\n");
    Ok(out)
}

/// Entry point of the subcommand: prints the tables and writes them to `out` if given.
pub fn run_cli(device: &Device, args: &BenchArgs, out: Option<&Path>) -> Result<()> {
    let tables = run_bench(device, args)?;
    println!("{tables}");
    if let Some(path) = out {
        std::fs::write(path, &tables).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
