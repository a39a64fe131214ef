//! `hrts_lab bench --area`: what exact soft shadows cost, per model of the benchmark. Area shadows at
//! `--area-samples` light samples against PCSS with an 8K shadow map (the most accurate PCSS setting of
//! `tradeoff` on the held-out models), with the primitive map's lists and memory; then how the cost grows
//! with the light's size and with the samples.
//!
//! GPU timestamps around every pass; medians over the frames after the first.

use crate::accuracy::compare_area;
use crate::bench_models::{frames_of, median_of, view_of, BenchArgs, BenchModel};
use crate::frames::ViewInputs;
use anyhow::{Context, Result};
use demo_engine::View;
use host_demo::render::{map_bytes, median_timings};
use hrts::FrameReport;
use passes::{PcssConfig, PenumbraFilter, ShadowConfig, ShadowMapConfig, ShadowMode};
use reference::RefScene;
use rhi::Device;
use std::collections::BTreeMap;

/// Angular radii of the light-size sweep (radians).
const RADII: [f32; 3] = [0.005, 0.02, 0.05];
/// Sample counts of the sample sweep.
const SAMPLES: [u32; 4] = [16, 32, 64, 128];
/// The PCSS compared with: an 8K shadow map, standard penumbra, 16 + 32 taps.
const PCSS_MAP: u32 = 8192;

fn area_config(args: &BenchArgs, angular_radius: f32, samples: u32) -> ShadowConfig {
    ShadowConfig {
        mode: ShadowMode::Area,
        antialiasing: false,
        map: args.map(),
        pcss: PcssConfig {
            angular_radius,
            ..PcssConfig::default()
        },
        area: args.area(samples),
        ..ShadowConfig::default()
    }
}

fn pcss_config(angular_radius: f32) -> ShadowConfig {
    ShadowConfig {
        mode: ShadowMode::Soft,
        antialiasing: false,
        shadow_map: ShadowMapConfig {
            size: PCSS_MAP,
            ..ShadowMapConfig::default()
        },
        pcss: PcssConfig {
            angular_radius,
            filter: PenumbraFilter::Standard,
            ..PcssConfig::default()
        },
        ..ShadowConfig::default()
    }
}

/// One configuration's medians and last report.
struct Run {
    times: BTreeMap<String, f64>,
    report: FrameReport,
}

fn run(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: u32,
) -> Result<(demo_engine::plugin::PluginRenderer, Run)> {
    let (renderer, reports) = frames_of(device, view, config, frames)?;
    let times = median_timings(&reports);
    let report = reports.last().cloned().context("no frame")?;
    Ok((renderer, Run { times, report }))
}

fn area_ms(r: &Run) -> (f64, f64) {
    (
        median_of(&r.times, &["primitive map"]).unwrap_or(f64::NAN),
        median_of(&r.times, &["ray trace"]).unwrap_or(f64::NAN),
    )
}

/// The median trace-only GPU ms of the ray-tracing-pipeline peer on the frame `renderer` last rendered
/// (`None` on a device without ray tracing).
fn peer_trace_ms(
    device: &Device,
    renderer: &demo_engine::plugin::PluginRenderer,
    view: &View,
    angular_radius: f32,
    samples: u32,
    frames: u32,
) -> Result<Option<f64>> {
    if !device.capabilities().ray_tracing_pipeline {
        return Ok(None);
    }
    let inputs = view.frame_inputs();
    let run = crate::peer::run_area_peer(
        device,
        renderer,
        &view.scene,
        &inputs,
        angular_radius,
        samples,
        frames,
    )?;
    Ok(Some(run.trace_ms))
}

/// Runs the area benchmark over `models` and returns its Markdown tables.
pub(crate) fn run_area_bench(
    device: &Device,
    args: &BenchArgs,
    models: &[BenchModel],
) -> Result<String> {
    let caps = device.capabilities();
    let (r, n) = (args.angular_radius, args.area_samples);
    let mut main = format!(
        "Device: {} ({}); {}×{}; directional light of angular radius {r}; medians of {} frames after the \
         first (GPU timestamps, ms).\n\n\
         | model | triangles | area map build ms | area trace ms | area ms | PCSS {PCSS_MAP}² ms | area / PCSS | \
         RT peer trace ms | area / peer | entries | mean list | longest list | texels past capacity | \
         pixels walking the BVH | map MiB | wrong px (unstable) |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        caps.device_name,
        caps.driver,
        args.width,
        args.height,
        args.frames.max(2) - 1,
    );
    let mut sweep = format!(
        "\nArea ms (map build + trace) by light size at {n} samples, and by samples at angular radius {r}:\n\n\
         | model | r {} | r {} | r {} | {} samples | {} samples | {} samples | {} samples |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
        RADII[0], RADII[1], RADII[2], SAMPLES[0], SAMPLES[1], SAMPLES[2], SAMPLES[3]
    );
    let bar = host_demo::progress(
        models.len() as u64 * (2 + (RADII.len() + SAMPLES.len()) as u64),
        "bench --area",
    );
    for model in models {
        bar.set_message(format!("{} area", model.name));
        let view = view_of(model, args)?;
        let (renderer, area) = run(device, &view, area_config(args, r, n), args.frames)?;
        let peer = peer_trace_ms(device, &renderer, &view, r, n, args.frames)?;
        bar.inc(1);
        let wrong = if args.no_reference {
            "—".to_owned()
        } else {
            bar.set_message(format!("{} CPU reference", model.name));
            let images = renderer.read_back(device, false)?;
            let rs = RefScene::new(&view.scene);
            let c = compare_area(&rs, &view, r, n, &images.output);
            format!("{} ({})", c.mismatches + c.non_finite, c.unstable)
        };
        drop(renderer);
        bar.set_message(format!("{} PCSS", model.name));
        let (_, pcss) = run(device, &view, pcss_config(r), args.frames)?;
        bar.inc(1);
        let (build, trace) = area_ms(&area);
        let pcss_ms = median_of(&pcss.times, &["shadow map", "PCSS"]).unwrap_or(f64::NAN);
        let st = &area.report.stats;
        let (peer_cell, ratio_cell) = match peer {
            Some(ms) => (format!("{ms:.3}"), format!("{:.2}", (build + trace) / ms)),
            None => ("—".to_owned(), "—".to_owned()),
        };
        main.push_str(&format!(
            "| {} | {} | {build:.3} | {trace:.3} | {:.3} | {pcss_ms:.3} | {:.2} | {peer_cell} | {ratio_cell} | {} | {:.1} | {} | {} | {} | {:.1} | {wrong} |\n",
            model.name,
            view.scene.triangle_count(),
            build + trace,
            (build + trace) / pcss_ms,
            st.entries,
            st.mean_list(),
            st.longest_list,
            st.texels_past_capacity,
            st.pixels_walked,
            map_bytes(&area.report) as f64 / f64::from(1 << 20),
        ));
        let mut cells = Vec::new();
        for (radius, samples) in RADII
            .iter()
            .map(|&radius| (radius, n))
            .chain(SAMPLES.iter().map(|&samples| (r, samples)))
        {
            bar.set_message(format!("{} r {radius}, {samples} samples", model.name));
            let (_, point) = run(
                device,
                &view,
                area_config(args, radius, samples),
                args.frames,
            )?;
            let (build, trace) = area_ms(&point);
            cells.push(format!(
                "{:.3} ({:.1})",
                build + trace,
                point.report.stats.mean_list()
            ));
            bar.inc(1);
        }
        sweep.push_str(&format!("| {} | {} |\n", model.name, cells.join(" | ")));
    }
    bar.finish_and_clear();
    main.push_str(&format!(
        "\narea map build = every `primitive map:` pass and the statistics; area trace = the pass that tests \
         the {n} samples; PCSS = shadow map + PCSS (standard penumbra, 16 + 32 taps); RT peer trace = the same \
         {n} samples of every pixel as {n} any-hit rays through the driver's ray-tracing pipeline, trace only \
         (— on a device without ray tracing). Wrong px: pixels whose \
         visible sample count differs from the exact reference of the same samples, outside the pixels with a \
         sample within the reference's tolerance of an edge (unstable).\n"
    ));
    sweep.push_str("\nIn brackets: the mean list length.\n");
    Ok(main + &sweep)
}
