//! `hrts_lab bench`: what the exact shadow costs, per model, with default settings.
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
pub use crate::bench_models::BenchArgs;
use crate::bench_models::{
    chosen_models, frames_of, frames_with_layout, median_of, view_of, BenchModel, TALK_ROWS,
};
use crate::frames::{PluginFrames, ViewInputs};
use crate::peer::run_peer;
use anyhow::{Context, Result};
use demo_engine::gbuffer::GBufferLayout;
use demo_engine::View;
use host_demo::progress::phase;
use host_demo::render::{map_bytes, median_timings};
use hrts::FrameReport;
use passes::{BinningRequest, PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig};
use reference::RefScene;
use rhi::Device;
use std::collections::BTreeMap;
use std::path::Path;

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
        let run = run_peer(device, &renderer, &view.scene, &inputs, args.frames)?;
        let wrong = match &reference {
            Some(r) => {
                let images = demo_engine::FrameImages {
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
    let bar = host_demo::progress(models.len() as u64, "bench");
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
        PrimitiveMapConfig::default().for_nearest_hit().size,
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
    let bar = host_demo::progress(models.len() as u64 * 2, "bench --gbuffer");
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
                    k.as_str() != "gbuffer" && k.as_str() != demo_engine::plugin::SCREEN_SPACE_WALL
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

/// Renders the built-in scene at the benchmark's size for two seconds of frames (and at least
/// [`WARM_UP_FRAMES`]) once its pipelines exist, so that the first configuration measured does not pay for
/// a GPU still clocking up (seen on an H100: the first light 4x slower than the same light measured later;
/// on an H200 freshly started, the first light 4x slower while the clock ran from before the pipelines
/// were built).
fn warm_up(device: &Device, args: &BenchArgs) -> Result<()> {
    let bar = host_demo::progress(1, "bench warm-up");
    bar.set_message(format!(
        "the built-in scene at {}×{}",
        args.width, args.height
    ));
    let view = View::framed(scene::procedural_default(), args.width, args.height);
    let (mut renderer, _) = frames_of(device, &view, ShadowConfig::default(), 2)?;
    let inputs = view.frame_inputs();
    let started = std::time::Instant::now();
    let mut frames = 0;
    while frames < WARM_UP_FRAMES || started.elapsed() < std::time::Duration::from_secs(2) {
        renderer.render(device, &inputs)?;
        frames += 1;
    }
    Ok(())
}

/// The fewest frames of the benchmark's warm-up ([`warm_up`]).
const WARM_UP_FRAMES: u32 = 20;

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
    let device = demo_engine::open_device(device_filter, validation)?;
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
    demo_engine::check_validation(&device)
}

/// What `bench` measures.
enum Work {
    /// `--lights`: the light scenes.
    Lights(crate::light_bench::LightScenes),
    /// The models (the shadow table, `--gbuffer` or `--area`).
    Models(Vec<BenchModel>),
}
