//! `hrts_lab tradeoff`: what accuracy costs in time, for the shadows users see. Every method and setting
//! the plugin offers (classic shadow maps, PCF, PCSS, ray-traced hard shadows, the hybrid, area shadows)
//! renders one view through the C ABI. Each result is compared with a ground-truth soft shadow: the visible fraction of the
//! light's extent per pixel, integrated on the CPU by stratified Monte Carlo over the exact f64 scene
//! (`reference::soft_visibility`). The sweep reports error metrics users know, GPU time and memory, and
//! writes CSV, JSON, an error-against-time plot with the Pareto front marked, and a strip of error maps.

use crate::accuracy::{view_reference, visibility_params};
use crate::frames::ViewInputs;
use crate::report::{model_view, render_frames};
use anyhow::{bail, Context, Result};
use demo_engine::View;
use host_demo::images::{write_png_compact, Canvas};
use host_demo::output::shade_preview;
use host_demo::render::median_timings;
use passes::{
    AreaConfig, HybridConfig, PcssConfig, PenumbraFilter, PrimitiveMapConfig, ResourceId,
    ResourceSet, ShadowConfig, ShadowMapConfig, ShadowMode,
};
use plotters::prelude::*;
use reference::{soft_visibility_with_progress, AreaLight, RefScene, SoftParams};
use rhi::Device;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `hrts_lab tradeoff`.
#[derive(Debug, Clone, clap::Args)]
pub struct TradeoffArgs {
    /// OBJ model, a ground plane added (default: the Stanford bunny of the models folder).
    #[arg(long, conflicts_with = "builtin")]
    pub obj: Option<PathBuf>,
    /// The demo's built-in procedural scene instead of a model.
    #[arg(long)]
    pub builtin: bool,
    /// Frame width.
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 360, value_parser = clap::value_parser!(u32).range(1..=i64::from(host_demo::limits::FRAME_SIDE)))]
    pub height: u32,
    /// Frames per method. Timings are medians over the second half: the first half lets a GPU that idled
    /// while the method's pipelines were created reach its clocks again.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Ground truth: n×n stratified light samples per penumbra pixel.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..))]
    pub strata: u32,
    /// Angular radius of the directional light in radians, for PCSS and the ground truth alike.
    #[arg(long, default_value_t = 0.02)]
    pub angular_radius: f32,
    /// Output folder (tradeoff.csv, tradeoff.json, pareto.svg, error_maps.png).
    #[arg(long, default_value = "out/tradeoff")]
    pub out: PathBuf,
}

/// What a method outputs, among the frame's images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    /// The plan's final output.
    Final,
    /// The classic single-tap shadow-map test (an extra output).
    ShadowMapTest,
}

/// One method and setting of the sweep.
#[derive(Debug, Clone)]
pub struct Method {
    /// Family: shadow map, PCF, PCSS, ray traced, hybrid.
    pub family: &'static str,
    /// Setting, e.g. "3072²".
    pub name: String,
    config: ShadowConfig,
    output: Output,
    /// Pass-name prefixes whose GPU time is the method's.
    passes: &'static [&'static str],
}

/// The method families, in the order of the plot's legend and the error maps.
const FAMILIES: [&str; 6] = ["shadow map", "PCF", "PCSS", "ray traced", "hybrid", "area"];

const SHADOW_MAP_PASSES: &[&str] = &["shadow map"];
const SOFT_PASSES: &[&str] = &["shadow map", "PCSS"];
const TRACED_PASSES: &[&str] = &["primitive map", "ray trace", "FXAA"];
const HYBRID_PASSES: &[&str] = &[
    "shadow map",
    "primitive map",
    "ray trace",
    "PCSS",
    "FXAA",
    "lerp factor",
    "hybrid blend",
];

/// The sweep: shadow maps 1K–8K with the classic test and with PCF, PCSS (standard and shrinking, two tap
/// counts, two map sizes), ray-traced hard shadows with and without FXAA, the hybrid over several WSS
/// and PHS, and area shadows with 16 to 128 light samples. `wss` is the scene's default world-space scale.
pub fn methods(angular_radius: f32, wss: f32) -> Vec<Method> {
    let pcss = |filter, search: u32, pcf: u32| PcssConfig {
        angular_radius,
        blocker_search_taps: search,
        pcf_taps: pcf,
        filter,
        ..PcssConfig::default()
    };
    let shadow_map = |size| ShadowMapConfig {
        size,
        ..ShadowMapConfig::default()
    };
    let base = ShadowConfig {
        mode: ShadowMode::Soft,
        antialiasing: false,
        pcss: pcss(PenumbraFilter::Standard, 16, 32),
        ..ShadowConfig::default()
    };
    let mut out = Vec::new();
    for size in [1024, 2048, 4096, 8192] {
        out.push(Method {
            family: "shadow map",
            name: format!("{size}²"),
            config: ShadowConfig {
                shadow_map: shadow_map(size),
                extra_outputs: ResourceSet::of(&[ResourceId::ShadowMapVisibility]),
                ..base
            },
            output: Output::ShadowMapTest,
            passes: SHADOW_MAP_PASSES,
        });
    }
    for size in [1024, 2048, 4096, 8192] {
        // PCF: PCSS with its filter radius pinned, 1.5 texels.
        out.push(Method {
            family: "PCF",
            name: format!("{size}², 1.5-texel radius"),
            config: ShadowConfig {
                shadow_map: shadow_map(size),
                pcss: PcssConfig {
                    min_filter_radius: 1.5,
                    max_filter_radius: 1.5,
                    ..pcss(PenumbraFilter::Standard, 4, 32)
                },
                ..base
            },
            output: Output::Final,
            passes: SOFT_PASSES,
        });
    }
    for (size, filter, search, pcf) in [
        (3072, PenumbraFilter::Standard, 8, 16),
        (3072, PenumbraFilter::Standard, 16, 32),
        (3072, PenumbraFilter::Standard, 32, 64),
        (3072, PenumbraFilter::Shrinking, 16, 32),
        (8192, PenumbraFilter::Standard, 16, 32),
    ] {
        out.push(Method {
            family: "PCSS",
            name: format!("{size}², {}, {search}+{pcf} taps", filter_name(filter)),
            config: ShadowConfig {
                shadow_map: shadow_map(size),
                pcss: pcss(filter, search, pcf),
                ..base
            },
            output: Output::Final,
            passes: SOFT_PASSES,
        });
    }
    for antialiasing in [false, true] {
        out.push(Method {
            family: "ray traced",
            name: format!(
                "hard, 1024² map{}",
                if antialiasing { ", FXAA" } else { "" }
            ),
            config: ShadowConfig {
                mode: ShadowMode::Hard,
                antialiasing,
                map: PrimitiveMapConfig {
                    size: 1024,
                    ..PrimitiveMapConfig::default()
                },
                ..base
            },
            output: Output::Final,
            passes: TRACED_PASSES,
        });
    }
    // L = saturate(BD / WSS * PHS) depends on PHS / WSS alone: one row per ratio and filter, WSS fixed.
    for (filter, phs) in [
        (PenumbraFilter::Shrinking, 0.25),
        (PenumbraFilter::Shrinking, 1.0),
        (PenumbraFilter::Shrinking, 4.0),
        (PenumbraFilter::Shrinking, 16.0),
        (PenumbraFilter::Shrinking, 64.0),
        (PenumbraFilter::Standard, 4.0),
        (PenumbraFilter::Standard, 16.0),
    ] {
        out.push(Method {
            family: "hybrid",
            name: format!("{}, WSS {:.3}, PHS {phs}", filter_name(filter), wss),
            config: ShadowConfig {
                mode: ShadowMode::Hybrid,
                antialiasing: true,
                pcss: pcss(filter, 16, 32),
                hybrid: HybridConfig {
                    world_space_scale: wss,
                    hard_shadow_percentage: phs,
                },
                ..base
            },
            output: Output::Final,
            passes: HYBRID_PASSES,
        });
    }
    // Exact soft shadows: the visible fraction of N fixed light samples, no filter.
    for samples in [16, 32, 64, 128] {
        out.push(Method {
            family: "area",
            name: format!("{samples} samples, 1024² map"),
            config: ShadowConfig {
                mode: ShadowMode::Area,
                map: PrimitiveMapConfig {
                    size: 1024,
                    ..PrimitiveMapConfig::default()
                },
                pcss: pcss(PenumbraFilter::Standard, 16, 32),
                area: AreaConfig {
                    samples,
                    ..AreaConfig::default()
                },
                ..base
            },
            output: Output::Final,
            passes: TRACED_PASSES,
        });
    }
    out
}

/// Ticks of a log axis from `lo` to `hi`: 1, 2 and 5 times the powers of ten in range, each once (the
/// plotting crate's own log ticks can repeat a decade, printing its label over itself).
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo) {
        return Vec::new();
    }
    let mut ticks = Vec::new();
    for exponent in (lo.log10().floor() as i32)..=(hi.log10().ceil() as i32) {
        for m in [1.0, 2.0, 5.0] {
            // Parsed from text so that 0.2 is 0.2, not 2 * 0.1 rounded.
            let tick: f64 = format!("{m}e{exponent}").parse().unwrap_or(0.0);
            if (lo..=hi).contains(&tick) {
                ticks.push(tick);
            }
        }
    }
    ticks
}

fn filter_name(filter: PenumbraFilter) -> &'static str {
    match filter {
        PenumbraFilter::Standard => "standard",
        PenumbraFilter::Shrinking => "shrinking",
    }
}

/// One method's measurements against the ground truth.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Family of the method.
    pub family: String,
    /// Setting.
    pub method: String,
    /// GPU ms of the method's passes (medians over the frames after the first).
    pub gpu_ms: f64,
    /// Bytes of every resource the plugin allocated for it.
    pub memory_bytes: u64,
    /// Mean absolute error of visibility per pixel of the true shadow: the sum of |method − truth| over
    /// every receiver pixel divided by the number of pixels the truth does not call fully lit (so fully
    /// lit pixels, most of a frame, do not dilute it, and every method shares the denominator).
    pub mean_abs_error: f64,
    /// 99th percentile of the absolute error over the pixels that the truth or the method does not call
    /// fully lit.
    pub p99_abs_error: f64,
    /// Mean absolute error over the contact pixels: those whose exact nearest blocker is closer than 5% of
    /// the scene's radius (where shadows harden and shadow maps leak).
    pub contact_abs_error: f64,
    /// Mean FLIP error of the shaded, tone-mapped image against the ground truth's.
    pub flip: f64,
    /// Pixels on the wrong side of ½: the method says mostly lit where the truth is clearly (beyond four
    /// standard-error bounds) mostly shadowed, or the reverse.
    pub wrong_side: usize,
    /// Whether no other method is both faster and more accurate (mean absolute error).
    pub pareto: bool,
}

/// The ground truth and the sweep's results.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// Device name.
    pub device: String,
    /// Scene label.
    pub scene: String,
    /// Frame size.
    pub width: u32,
    /// Frame size.
    pub height: u32,
    /// Light's angular radius (radians).
    pub angular_radius: f32,
    /// Ground truth: samples per sampled pixel.
    pub samples: u32,
    /// Ground truth: bound on one sampled pixel's standard error.
    pub standard_error_bound: f64,
    /// Ground truth: receiver pixels decided exactly without sampling.
    pub exact_pixels: usize,
    /// Ground truth: receiver pixels sampled.
    pub sampled_pixels: usize,
    /// Ground truth: CPU seconds (wall clock).
    pub ground_truth_seconds: f64,
    /// One row per method.
    pub rows: Vec<Row>,
    #[serde(skip)]
    truth: Vec<f64>,
    #[serde(skip)]
    error_maps: Vec<(String, Vec<f32>)>,
}

/// Renders every method of [`methods`] on `view` and measures it against the ground truth.
pub fn run_sweep(device: &Device, view: &View, scene: &str, args: &TradeoffArgs) -> Result<Sweep> {
    let wss = view.scene.world_space_scale();
    let methods = methods(args.angular_radius, wss);
    let bar = host_demo::progress(methods.len() as u64 + 1, "tradeoff");
    bar.set_message("ground truth");
    let rs = RefScene::new(&view.scene);
    let params = visibility_params(view);
    let started = Instant::now();
    let hard = view_reference(&rs, view);
    let light = AreaLight::Directional {
        direction: view.frame_inputs().light.direction().as_dvec3(),
        angular_radius: f64::from(args.angular_radius),
    };
    let rows = host_demo::progress::phase(
        format!("soft shadows, {}² samples", args.strata),
        u64::from(view.height),
    );
    let soft = soft_visibility_with_progress(
        &rs,
        &hard,
        &light,
        &SoftParams {
            strata: args.strata,
            seed: 0x5eed,
            camera_position: params.camera_position,
        },
        &|| rows.inc(1),
    )
    .map_err(anyhow::Error::msg)?;
    drop(rows);
    bar.inc(1);
    let ground_truth_seconds = started.elapsed().as_secs_f64();
    let contact_distance = 0.05 * f64::from(wss);
    let contact: Vec<bool> = hard
        .blocker_distance
        .iter()
        .map(|&d| d < contact_distance)
        .collect();
    let mut rows = Vec::new();
    let mut error_maps = Vec::new();
    for m in &methods {
        bar.set_message(format!("{} {}", m.family, m.name));
        let (images, reports) = render_frames(device, view, m.config, args.frames)
            .with_context(|| format!("{} {}", m.family, m.name))?;
        let visibility = match m.output {
            Output::Final => &images.output,
            Output::ShadowMapTest => &images.shadow_map_visibility,
        };
        if visibility.len() != soft.visibility.len() {
            bail!("{} {}: no visibility read back", m.family, m.name);
        }
        let timings = median_timings(&reports[reports.len() / 2..]);
        let memory_bytes = reports.last().map_or(0, |r| {
            host_demo::report_text::resource_bytes(r)
                .map(|(_, bytes)| bytes)
                .sum()
        });
        let shaded = |v: &[f32]| shade_preview(&images.normal, v, to_light(view));
        let truth32: Vec<f32> = soft
            .visibility
            .iter()
            .map(|&v| if v.is_nan() { 1.0 } else { v as f32 })
            .collect();
        let errors = errors(&soft.visibility, visibility);
        rows.push(Row {
            family: m.family.into(),
            method: m.name.clone(),
            gpu_ms: passes_ms(&timings, m.passes),
            memory_bytes,
            mean_abs_error: errors.iter().sum::<f64>()
                / shadow_region(&soft.visibility).max(1) as f64,
            p99_abs_error: percentile(&errors, 0.99),
            contact_abs_error: contact_error(&soft.visibility, visibility, &contact),
            flip: flip(
                view.width,
                view.height,
                &shaded(&truth32),
                &shaded(visibility),
            ),
            wrong_side: wrong_side(
                &soft.visibility,
                visibility,
                4.0 * soft.standard_error_bound,
            ),
            pareto: false,
        });
        error_maps.push((
            format!("{} {}", m.family, m.name),
            soft.visibility
                .iter()
                .zip(visibility)
                .map(|(&t, &v)| {
                    if t.is_nan() {
                        f32::NAN
                    } else {
                        (v - t as f32).abs()
                    }
                })
                .collect(),
        ));
        bar.inc(1);
    }
    bar.finish_and_clear();
    mark_pareto(&mut rows);
    Ok(Sweep {
        device: device.capabilities().device_name.clone(),
        scene: scene.into(),
        width: view.width,
        height: view.height,
        angular_radius: args.angular_radius,
        samples: soft.samples,
        standard_error_bound: soft.standard_error_bound,
        exact_pixels: soft.exact_pixels,
        sampled_pixels: soft.sampled_pixels,
        ground_truth_seconds,
        rows,
        truth: soft.visibility,
        error_maps,
    })
}

fn to_light(view: &View) -> glam::Vec3 {
    -view.frame_inputs().light.direction()
}

/// |method − truth| over the shadow region: receiver pixels (the truth is NaN on the background) that the
/// truth or the method does not call fully lit. Fully lit pixels, most of any frame, would otherwise
/// dilute every difference.
fn errors(truth: &[f64], method: &[f32]) -> Vec<f64> {
    truth
        .iter()
        .zip(method)
        .filter(|(t, v)| !t.is_nan() && (**t < 1.0 || **v < 1.0))
        .map(|(&t, &v)| (f64::from(v) - t).abs())
        .collect()
}

/// Mean |method − truth| over the pixels of `mask`.
fn contact_error(truth: &[f64], method: &[f32], mask: &[bool]) -> f64 {
    let (sum, n) = truth
        .iter()
        .zip(method)
        .zip(mask)
        .filter(|((t, _), &m)| m && !t.is_nan())
        .fold((0.0, 0usize), |(sum, n), ((&t, &v), _)| {
            (sum + (f64::from(v) - t).abs(), n + 1)
        });
    sum / n.max(1) as f64
}

/// Receiver pixels the truth does not call fully lit: the common denominator of every method's mean error.
fn shadow_region(truth: &[f64]) -> usize {
    truth.iter().filter(|t| !t.is_nan() && **t < 1.0).count()
}

/// The GPU ms of the passes whose names start with one of `prefixes` (absent passes count 0).
fn passes_ms(timings: &std::collections::BTreeMap<String, f64>, prefixes: &[&str]) -> f64 {
    timings
        .iter()
        .filter(|(name, _)| prefixes.iter().any(|p| name.starts_with(p)))
        .map(|(_, ms)| ms)
        .sum()
}

fn percentile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let at = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[at]
}

fn wrong_side(truth: &[f64], method: &[f32], margin: f64) -> usize {
    truth
        .iter()
        .zip(method)
        .filter(|(t, v)| {
            let t = **t;
            !t.is_nan() && (t - 0.5).abs() > margin && ((t >= 0.5) != (**v >= 0.5))
        })
        .count()
}

fn flip(width: u32, height: u32, reference: &[[u8; 4]], test: &[[u8; 4]]) -> f64 {
    let rgb = |p: &[[u8; 4]]| -> Vec<u8> { p.iter().flat_map(|c| [c[0], c[1], c[2]]).collect() };
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test));
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let pool = nv_flip::FlipPool::from_image(&error);
    f64::from(pool.mean())
}

/// Marks the rows no other row dominates: none is at most as slow and strictly more accurate, or strictly
/// faster and at most as inaccurate.
fn mark_pareto(rows: &mut [Row]) {
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r.gpu_ms, r.mean_abs_error)).collect();
    for (i, row) in rows.iter_mut().enumerate() {
        let (ms, err) = points[i];
        row.pareto = ms.is_finite()
            && !points
                .iter()
                .enumerate()
                .any(|(j, &(m, e))| j != i && m <= ms && e <= err && (m < ms || e < err));
    }
}

impl Sweep {
    /// Writes tradeoff.csv, tradeoff.json, pareto.svg and error_maps.png into `dir`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let mut csv = csv::Writer::from_path(dir.join("tradeoff.csv"))?;
        for row in &self.rows {
            csv.serialize(row)?;
        }
        csv.flush()?;
        std::fs::write(
            dir.join("tradeoff.json"),
            serde_json::to_string_pretty(self)?,
        )?;
        self.plot(&dir.join("pareto.svg"))?;
        self.error_strip(&dir.join("error_maps.png"))
    }

    /// Mean absolute error against GPU ms, one colour per family, the Pareto front joined.
    fn plot(&self, path: &Path) -> Result<()> {
        let finite: Vec<&Row> = self.rows.iter().filter(|r| r.gpu_ms > 0.0).collect();
        let (lo_ms, hi_ms) = finite.iter().fold((f64::MAX, f64::MIN), |(lo, hi), r| {
            (lo.min(r.gpu_ms), hi.max(r.gpu_ms))
        });
        let hi_err = finite.iter().map(|r| r.mean_abs_error).fold(0.0, f64::max);
        if finite.is_empty() {
            bail!("no timed method to plot");
        }
        let root = SVGBackend::new(path, (960, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!(
                    "{}: soft-shadow error against GPU time, {}×{}, {}",
                    self.scene, self.width, self.height, self.device
                ),
                ("sans-serif", 18),
            )
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(
                ((lo_ms * 0.7)..(hi_ms * 1.4))
                    .log_scale()
                    .with_key_points(log_ticks(lo_ms * 0.7, hi_ms * 1.4)),
                0.0..(hi_err * 1.1),
            )?;
        chart
            .configure_mesh()
            .x_label_formatter(&|ms| format!("{ms}"))
            .x_desc("GPU ms (log scale)")
            .y_desc("mean absolute error of visibility")
            .draw()?;
        let colours = [
            RGBColor(120, 120, 120),
            RGBColor(31, 119, 180),
            RGBColor(44, 160, 44),
            RGBColor(214, 39, 40),
            RGBColor(148, 103, 189),
            RGBColor(255, 127, 14),
        ];
        for (family, colour) in FAMILIES.iter().zip(colours) {
            let points: Vec<(f64, f64)> = finite
                .iter()
                .filter(|r| r.family == *family)
                .map(|r| (r.gpu_ms, r.mean_abs_error))
                .collect();
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 5, colour.filled())))?
                .label(*family)
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
        }
        let mut front: Vec<(f64, f64)> = finite
            .iter()
            .filter(|r| r.pareto)
            .map(|r| (r.gpu_ms, r.mean_abs_error))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front, BLACK.stroke_width(1)))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
        Ok(())
    }

    /// The shaded ground truth, then one error map per family's most accurate setting (black 0, white an
    /// error of ½ or more), each labelled.
    fn error_strip(&self, path: &Path) -> Result<()> {
        let scale = self.width.div_ceil(640).max(1);
        let (w, h) = (self.width / scale, self.height / scale);
        let mut picks: Vec<usize> = Vec::new();
        for family in FAMILIES {
            if let Some((i, _)) = self
                .rows
                .iter()
                .enumerate()
                .filter(|(_, r)| r.family == family)
                .min_by(|a, b| a.1.mean_abs_error.total_cmp(&b.1.mean_abs_error))
            {
                picks.push(i);
            }
        }
        let label_h = 28;
        let mut canvas = Canvas::new(
            w * (picks.len() as u32 + 1),
            h + label_h,
            [255, 255, 255, 255],
        );
        let mut panels: Vec<(String, Vec<[u8; 4]>)> = vec![(
            format!("GROUND TRUTH, {} SAMPLES", self.samples),
            self.truth
                .iter()
                .map(|&v| if v.is_nan() { SKY } else { grey(v as f32) })
                .collect(),
        )];
        for &i in &picks {
            let (name, map) = &self.error_maps[i];
            panels.push((
                name.to_uppercase(),
                map.iter()
                    .map(|&e| if e.is_nan() { SKY } else { grey(e * 2.0) })
                    .collect(),
            ));
        }
        for (k, (label, pixels)) in panels.iter().enumerate() {
            let small = downscale(pixels, self.width, self.height, scale);
            canvas.blit(&small, w, h, i64::from(w) * k as i64, i64::from(label_h));
            canvas.text(i64::from(w) * k as i64 + 6, 8, 1, label, [0, 0, 0, 255]);
        }
        write_png_compact(path, canvas.width, canvas.height, &canvas.pixels)
    }
}

const SKY: [u8; 4] = [150, 180, 215, 255];

fn grey(v: f32) -> [u8; 4] {
    let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    [g, g, g, 255]
}

fn downscale(pixels: &[[u8; 4]], width: u32, height: u32, scale: u32) -> Vec<[u8; 4]> {
    let (w, h) = (width / scale, height / scale);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| pixels[((y * scale) * width + x * scale) as usize])
        .collect()
}

/// `hrts_lab tradeoff`: loads the model, runs the sweep, writes the outputs and prints the table.
pub fn run_cli(device: &Device, args: &TradeoffArgs) -> Result<()> {
    let (view, label) = if args.builtin {
        (
            View::framed(scene::procedural_default(), args.width, args.height),
            "built-in scene".to_owned(),
        )
    } else {
        model_view(args.obj.as_deref(), args.width, args.height)?
    };
    let sweep = run_sweep(device, &view, &label, args)?;
    sweep.write(&args.out)?;
    println!("{}", sweep.table());
    println!("wrote {}", args.out.display());
    Ok(())
}

impl Sweep {
    /// The results as a Markdown table, with the ground truth's figures above it.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{} on {}, {}×{}, light angular radius {} rad. Ground truth: {} stratified samples per penumbra pixel \
             (standard error ≤ {:.4} per pixel), {} pixels exact without sampling, {} sampled, {:.1} s on the CPU.\n\n\
             | family | method | GPU ms | memory MiB | mean abs error | p99 abs error | contact error | FLIP | wrong side of ½ | Pareto |\n\
             |---|---|---:|---:|---:|---:|---:|---:|---:|:---:|\n",
            self.scene,
            self.device,
            self.width,
            self.height,
            self.angular_radius,
            self.samples,
            self.standard_error_bound,
            self.exact_pixels,
            self.sampled_pixels,
            self.ground_truth_seconds
        );
        for r in &self.rows {
            s += &format!(
                "| {} | {} | {:.3} | {:.1} | {:.4} | {:.3} | {:.4} | {:.4} | {} | {} |\n",
                r.family,
                r.method,
                r.gpu_ms,
                r.memory_bytes as f64 / f64::from(1u32 << 20),
                r.mean_abs_error,
                r.p99_abs_error,
                r.contact_abs_error,
                r.flip,
                r.wrong_side,
                if r.pareto { "●" } else { "" }
            );
        }
        s
    }

    /// The row of `family` with the smallest mean absolute error.
    pub fn best(&self, family: &str) -> Option<&Row> {
        self.rows
            .iter()
            .filter(|r| r.family == family)
            .min_by(|a, b| a.mean_abs_error.total_cmp(&b.mean_abs_error))
    }

    /// Rows of the sweep.
    pub fn rows(&self) -> &[Row] {
        &self.rows
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_distinct_and_in_range() {
        assert_eq!(
            log_ticks(0.15, 140.0),
            [0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        );
        assert_eq!(log_ticks(3.0, 4.0), Vec::<f64>::new());
        assert!(log_ticks(0.0, 1.0).is_empty());
    }

    /// The hybrid's lerp factor depends on PHS / WSS alone: no two hybrid rows share it with one filter.
    #[test]
    fn hybrid_rows_are_distinct() {
        let rows: Vec<(String, u32)> = methods(0.02, 0.8)
            .iter()
            .filter(|m| m.family == "hybrid")
            .map(|m| {
                let h = m.config.hybrid;
                let ratio = h.hard_shadow_percentage / h.world_space_scale;
                (
                    filter_name(m.config.pcss.filter).to_owned(),
                    ratio.to_bits(),
                )
            })
            .collect();
        let distinct: std::collections::BTreeSet<_> = rows.iter().collect();
        assert_eq!(distinct.len(), rows.len(), "{rows:?}");
    }
}
