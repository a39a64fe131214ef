//! `host_demo render`: one view of a scene through every pass its plan runs, written to a folder.

use crate::images::lerp_factor_preview;
use crate::output::{shade_preview, write_exr_rgba, write_exr_scalar, write_png};
use crate::report_text::{resource_bytes, routes_line, tier_name};
use anyhow::{Context, Result};
use demo_engine::gbuffer::GBufferLayout;
use demo_engine::plugin::PluginRenderer;
use demo_engine::{Device, DeviceSummary, View};
use hrts::{
    BinningPath, Faces, FrameReport, Pass, PassStatus, PenumbraFilter, Resource, ResourceSet,
    ShadowMode,
};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Soft-shadow and hybrid options of the command line (defaults: the talk's hybrid with FXAA, 3K shadow
/// map, shrinking PCSS).
#[derive(Debug, Clone, clap::Args)]
pub struct SoftShadowArgs {
    /// Shadow mode of the light: none, hard (ray traced), soft (PCSS), hybrid, or area (exact soft shadows:
    /// the visible fraction of `--area-samples` light samples per pixel).
    #[arg(long, default_value = "hybrid", value_parser = parse_mode)]
    pub mode: ShadowMode,
    /// Turn off FXAA over the ray-traced shadow.
    #[arg(long)]
    pub no_antialiasing: bool,
    /// Shadow map size (square).
    #[arg(long, default_value_t = 3072, value_parser = clap::value_parser!(u32).range(1..=i64::from(crate::limits::FRAME_SIDE)))]
    pub shadow_map_size: u32,
    /// PCSS penumbra filter: shrinking or standard.
    #[arg(long, default_value = "shrinking", value_parser = parse_filter)]
    pub filter: PenumbraFilter,
    /// Angular radius of the directional light in radians (the light size of PCSS, the hybrid and area
    /// shadows); inside a closed model, the
    /// point light is a sphere this wide seen from the floor below it.
    #[arg(long, default_value_t = 0.02)]
    pub angular_radius: f32,
    /// PCSS blocker-search taps.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..))]
    pub search_taps: u32,
    /// PCSS PCF taps.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..))]
    pub pcf_taps: u32,
    /// Hybrid WSS, world-space scale (default: the bounding radius of the scene's objects, ground aside).
    #[arg(long)]
    pub wss: Option<f32>,
    /// Hybrid PHS, percentage of hard shadow.
    #[arg(long, default_value_t = 4.0)]
    pub phs: f32,
    /// Area shadows: light samples per pixel (1 to 128).
    #[arg(long, default_value_t = hrts::Config::default().area_samples)]
    pub area_samples: u32,
}

impl Default for SoftShadowArgs {
    fn default() -> Self {
        Self {
            mode: ShadowMode::Hybrid,
            no_antialiasing: false,
            shadow_map_size: 3072,
            filter: PenumbraFilter::Shrinking,
            angular_radius: 0.02,
            search_taps: 16,
            pcf_taps: 32,
            wss: None,
            phs: 4.0,
            area_samples: hrts::Config::default().area_samples,
        }
    }
}

/// Options of a render besides the view.
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// The plugin configuration the primitive-map options set (`map_size`, `map_entry_budget_kib`,
    /// `faces`, `binning_path`, `map_list_limit`, `map_bin_budget`, `area_walk_budget`);
    /// [`RenderOptions::soft`] sets the rest.
    pub map: hrts::Config,
    /// Frames rendered; timings are medians over the frames after the first.
    pub frames: u32,
    /// Shadow mode, shadow map, PCSS and hybrid settings.
    pub soft: SoftShadowArgs,
    /// Draw the primitive map's occupancy view (a debug image; the statistics are gathered anyway).
    pub occupancy_view: bool,
}

impl SoftShadowArgs {
    /// The configuration these options describe over the primitive-map settings of `map`, with the
    /// hybrid's WSS `default_world_space_scale` unless `--wss` sets it; static geometry, a moving light, no
    /// extra output.
    pub fn config(&self, map: hrts::Config, default_world_space_scale: f32) -> hrts::Config {
        hrts::Config {
            mode: self.mode,
            antialiasing: !self.no_antialiasing,
            dynamic_geometry: false,
            static_light: false,
            shadow_map_size: self.shadow_map_size,
            pcss_angular_radius: self.angular_radius,
            pcss_blocker_search_taps: self.search_taps,
            pcss_pcf_taps: self.pcf_taps,
            pcss_filter: self.filter,
            hybrid_world_space_scale: self.wss.unwrap_or(default_world_space_scale),
            hybrid_hard_shadow_percentage: self.phs,
            area_samples: self.area_samples,
            extra_outputs: ResourceSet::EMPTY,
            ..map
        }
    }
}

impl RenderOptions {
    /// The pipeline configuration: the plan's final output plus every intermediate the demo writes. Every
    /// frame re-renders the light-space maps (a moving light), so that their timings are medians too.
    pub fn config(&self, view: &View) -> hrts::Config {
        hrts::Config {
            extra_outputs: demo_outputs(self.soft.mode, self.occupancy_view),
            ..self.soft.config(self.map, view.scene.world_space_scale())
        }
    }
}

/// What the demo writes for a mode: the ray trace and its blocker distance wherever the mode has them (and
/// the occupancy view if asked), the shadow-map views wherever it has a shadow map, the hybrid's parts in
/// hybrid mode.
fn demo_outputs(mode: ShadowMode, occupancy_view: bool) -> ResourceSet {
    use Resource as R;
    let of = |resources: &[Resource]| resources.iter().copied().collect::<ResourceSet>();
    let outputs = match mode {
        ShadowMode::None => ResourceSet::EMPTY,
        ShadowMode::Hard => of(&[R::RtVisibility, R::BlockerDistance]),
        // Auto, until resolved per light, has what hard and area shadows share.
        ShadowMode::Area | ShadowMode::Auto => of(&[R::RtVisibility]),
        ShadowMode::Soft => of(&[R::ShadowMapVisibility, R::Pcss]),
        ShadowMode::Hybrid => of(&[
            R::RtVisibility,
            R::BlockerDistance,
            R::ShadowMapVisibility,
            R::Pcss,
            R::LerpFactor,
            R::Hybrid,
        ]),
    };
    if mode.traces_rays() && occupancy_view {
        outputs.with(R::Occupancy)
    } else {
        outputs
    }
}

#[derive(Serialize)]
struct CameraJson {
    view: [f32; 16],
    proj: [f32; 16],
    position: [f32; 3],
}

#[derive(Serialize)]
struct LightJson {
    r#type: &'static str,
    direction: [f32; 3],
    view_proj: [f32; 16],
}

#[derive(Serialize)]
struct MapJson {
    size: u32,
    faces: &'static str,
    binning_path: &'static str,
    tier: &'static str,
    /// Frame coordinates to homogeneous texel space, fitted to the receivers (16 floats, column-major).
    map_to_texels: [f32; 16],
    receiver_pixels: u32,
    receiver_texels: u32,
    triangles_binned: u32,
    texels_with_list: u32,
    entries: u32,
    mean_list: f64,
    longest_list: u32,
    entry_capacity: u32,
    texels_past_capacity: u32,
    texels_past_limit: u32,
    bin_items: u32,
    lists_skipped: bool,
    pixels_walked: u32,
    walks_unfinished: u32,
    memory_bytes: u64,
}

#[derive(Serialize)]
struct SoftJson {
    mode: &'static str,
    antialiasing: bool,
    shadow_map_size: u32,
    filter: &'static str,
    angular_radius: f32,
    blocker_search_taps: u32,
    pcf_taps: u32,
    world_space_scale: f32,
    hard_shadow_percentage: f32,
}

#[derive(Serialize)]
struct PassJson {
    pass: &'static str,
    ran: bool,
    reason: Option<&'static str>,
}

#[derive(Serialize)]
struct ResourceJson {
    resource: &'static str,
    bytes: u64,
}

#[derive(Serialize)]
struct PlanJson {
    output: &'static str,
    passes: Vec<PassJson>,
    resources: Vec<ResourceJson>,
    total_bytes: u64,
}

#[derive(Serialize)]
struct FrameJson {
    width: u32,
    height: u32,
    triangles: usize,
    camera: CameraJson,
    light: LightJson,
    primitive_map: MapJson,
    shadows: SoftJson,
    plan: PlanJson,
    frames: u32,
    gpu_ms: BTreeMap<String, f64>,
    gpu_ms_notes: BTreeMap<String, &'static str>,
    device: DeviceSummary,
}

/// Median GPU milliseconds per pass over `reports` (the first frame alone for passes that ran once).
pub fn median_timings(reports: &[FrameReport]) -> BTreeMap<String, f64> {
    let mut samples: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let steady = if reports.len() > 1 {
        &reports[1..]
    } else {
        reports
    };
    for r in steady {
        for t in &r.timings {
            samples
                .entry(t.name.clone())
                .or_default()
                .push(t.milliseconds);
        }
    }
    for t in reports
        .first()
        .map(|r| r.timings.as_slice())
        .unwrap_or_default()
    {
        samples
            .entry(t.name.clone())
            .or_insert_with(|| vec![t.milliseconds]);
    }
    samples
        .into_iter()
        .map(|(name, mut v)| {
            v.sort_by(f64::total_cmp);
            (name, v[v.len() / 2])
        })
        .collect()
}

/// Name of the derived timing row of the talk's tables.
pub const PCSS_PLUS_RAY_TRACE: &str = "PCSS + Ray Trace";

/// Adds the talk's derived row: "PCSS + Ray Trace" is the sum of the medians of the two passes (they are
/// separate dispatches), present when both ran. Returns the notes explaining derived rows.
pub fn add_derived_rows(timings: &mut BTreeMap<String, f64>) -> BTreeMap<String, &'static str> {
    let mut notes = BTreeMap::new();
    if let (Some(p), Some(r)) = (timings.get("PCSS"), timings.get("ray trace")) {
        let sum = p + r;
        timings.insert(PCSS_PLUS_RAY_TRACE.to_owned(), sum);
        notes.insert(
            PCSS_PLUS_RAY_TRACE.to_owned(),
            "sum of the medians of the PCSS and ray trace passes",
        );
    }
    notes
}

/// Renders `view`, writes every output into `out`, prints the timing table, and returns the last report.
pub fn render_to_folder(
    device: &Device,
    view: &View,
    options: &RenderOptions,
    out: &Path,
) -> Result<FrameReport> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let config = options.config(view);
    // The demo's G-buffer as engines keep one (D24S8 depth, octahedral RG16F normals); its read-back
    // rebuilds positions and world normals for the outputs below.
    let layout = GBufferLayout::compact(device);
    let frames = options.frames.max(1);
    // Steps: the passes' creation, each frame, the outputs.
    let bar = crate::progress(u64::from(frames) + 2, "render");
    bar.set_message("creating the shadow passes");
    let mut renderer = PluginRenderer::with_layout(device, view, config, layout)
        .context("creating the shadow passes")?;
    bar.inc(1);
    let camera = view.camera_matrices();
    let light = view.plugin_light();
    let mut reports = Vec::new();
    for frame in 1..=frames {
        bar.set_message(format!("frame {frame} of {frames}"));
        reports.push(
            renderer
                .render_light(device, &camera, light)
                .context("rendering")?,
        );
        bar.inc(1);
    }
    bar.set_message("reading back and writing the outputs");
    let images = renderer.read_back(device, false).context("reading back")?;
    let last = reports.last().context("no frame rendered")?;
    let (w, h, n) = (view.width, view.height, last.stats.map_size);
    write_exr_rgba(&out.join("position.exr"), w, h, &images.position)?;
    write_exr_rgba(&out.join("normal.exr"), w, h, &images.normal)?;
    let scalars = [
        ("rt_visibility.exr", &images.visibility),
        ("blocker_distance.exr", &images.blocker_distance),
        ("rt_fxaa.exr", &images.antialiased),
        ("shadow_map.exr", &images.shadow_map_visibility),
        ("pcss.exr", &images.pcss),
        ("lerp_factor.exr", &images.lerp_factor),
        ("hybrid.exr", &images.hybrid),
        ("final.exr", &images.output),
    ];
    for (name, values) in scalars {
        if !values.is_empty() {
            write_exr_scalar(&out.join(name), w, h, values)?;
        }
    }
    if !images.occupancy.is_empty() {
        write_png(&out.join("occupancy.png"), n, n, &images.occupancy)?;
    }
    if !images.lerp_factor.is_empty() {
        write_png(
            &out.join("lerp_factor.png"),
            w,
            h,
            &lerp_factor_preview(&images.normal, &images.lerp_factor, &images.visibility),
        )?;
    }
    let to_light = -view.light.direction;
    write_png(
        &out.join("preview.png"),
        w,
        h,
        &shade_preview(&images.normal, &images.output, to_light),
    )?;

    let report = reports.last().cloned().context("no frame rendered")?;
    let mut timings = median_timings(&reports);
    let notes = add_derived_rows(&mut timings);
    let stats = report.stats;
    let s = &options.soft;
    let json = FrameJson {
        width: w,
        height: h,
        triangles: view.scene.triangle_count(),
        camera: CameraJson {
            view: camera.view.to_cols_array(),
            proj: camera.proj.to_cols_array(),
            position: camera.position.to_array(),
        },
        light: LightJson {
            r#type: "directional",
            direction: view.light.direction.to_array(),
            view_proj: view.light.view_proj(&view.scene.bounds()).to_cols_array(),
        },
        primitive_map: MapJson {
            size: n,
            faces: match options.map.faces {
                Faces::Both => "both",
                Faces::FrontOnly => "front",
            },
            binning_path: report.binning_path.name(),
            tier: tier_name(&report),
            map_to_texels: report.map_to_texels.to_cols_array(),
            receiver_pixels: stats.receiver_pixels,
            receiver_texels: stats.receiver_texels,
            triangles_binned: stats.triangles_binned,
            texels_with_list: stats.texels_with_list,
            entries: stats.entries,
            mean_list: stats.mean_list(),
            longest_list: stats.longest_list,
            entry_capacity: stats.entry_capacity,
            texels_past_capacity: stats.texels_past_capacity,
            texels_past_limit: stats.texels_past_limit,
            bin_items: stats.bin_items,
            lists_skipped: stats.frusta_without_lists > 0,
            pixels_walked: stats.pixels_walked,
            walks_unfinished: stats.walks_unfinished,
            memory_bytes: map_bytes(&report),
        },
        shadows: SoftJson {
            mode: s.mode.name(),
            antialiasing: !s.no_antialiasing,
            shadow_map_size: s.shadow_map_size,
            filter: filter_name(s.filter),
            angular_radius: s.angular_radius,
            blocker_search_taps: s.search_taps,
            pcf_taps: s.pcf_taps,
            world_space_scale: config.hybrid_world_space_scale,
            hard_shadow_percentage: config.hybrid_hard_shadow_percentage,
        },
        plan: plan_json(&report),
        frames: options.frames.max(1),
        gpu_ms: timings.clone(),
        gpu_ms_notes: notes.clone(),
        device: DeviceSummary::of(device),
    };
    let text = serde_json::to_string_pretty(&json)?;
    std::fs::write(out.join("frame.json"), text)
        .with_context(|| format!("writing {}/frame.json", out.display()))?;
    bar.inc(1);
    bar.finish_and_clear();

    println!("{}", demo_engine::device::device_banner(device));
    if report.status(Pass::PrimitiveMap) == PassStatus::NotInPlan {
        println!(
            "scene: {} triangles, {}x{} px; no primitive map (the plan does not need one)",
            view.scene.triangle_count(),
            w,
            h
        );
    } else {
        println!(
            "scene: {} triangles, {}x{} px; primitive map {n}x{n} fitted to {} receiver texels ({} binning, tier {}): \
             {} of {} triangles binned, {} entries in {} lists (mean {:.1}, longest {}), {:.1} MiB",
            view.scene.triangle_count(),
            w,
            h,
            stats.receiver_texels,
            report.binning_path.name(),
            tier_name(&report),
            stats.triangles_binned,
            view.scene.triangle_count(),
            stats.entries,
            stats.texels_with_list,
            stats.mean_list(),
            stats.longest_list,
            map_bytes(&report) as f64 / f64::from(1 << 20)
        );
        println!("{}", routes_line(&stats, &timings));
    }
    // Only the settings of the passes the mode runs.
    let fxaa = format!("FXAA {}", if s.no_antialiasing { "off" } else { "on" });
    let soft = format!(
        "shadow map {0}x{0}, PCSS {1} filter {2}+{3} taps",
        s.shadow_map_size,
        filter_name(s.filter),
        s.search_taps,
        s.pcf_taps
    );
    let settings = match s.mode {
        ShadowMode::None => "nothing to compute: every pixel lit".to_owned(),
        ShadowMode::Hard => fxaa,
        ShadowMode::Area => format!(
            "{} light samples per pixel, angular radius {}",
            config.area_samples, config.pcss_angular_radius
        ),
        ShadowMode::Soft => soft,
        ShadowMode::Hybrid => format!(
            "{fxaa}, {soft}, WSS {:.3}, PHS {}",
            config.hybrid_world_space_scale, config.hybrid_hard_shadow_percentage
        ),
        ShadowMode::Auto => "hard or area, by the light's size".to_owned(),
    };
    println!("shadows: {} ({settings})", s.mode.name());
    print_plan(&report);
    println!("{:<28} {:>10}", "pass", "GPU ms");
    for (name, ms) in &timings {
        let note = notes
            .get(name)
            .map(|n| format!("  ({n})"))
            .unwrap_or_default();
        println!("{name:<28} {ms:>10.3}{note}");
    }
    println!(
        "(medians over {} frames after the first; outputs in {})",
        options.frames.max(2) - 1,
        out.display()
    );
    Ok(report)
}

fn plan_json(report: &FrameReport) -> PlanJson {
    PlanJson {
        output: report.output_resource.name(),
        passes: plan_passes(report)
            .map(|(pass, status)| PassJson {
                pass: pass.name(),
                ran: status == PassStatus::Ran,
                reason: status.reason(),
            })
            .collect(),
        resources: resource_bytes(report)
            .map(|(resource, bytes)| ResourceJson { resource, bytes })
            .collect(),
        total_bytes: resource_bytes(report).map(|(_, bytes)| bytes).sum(),
    }
}

/// The passes of the light's pipeline with their status this frame, in recording order (the output copy,
/// the context's own, aside: the timings give it).
fn plan_passes(report: &FrameReport) -> impl Iterator<Item = (Pass, PassStatus)> + '_ {
    hrts::PassMask::ALL
        .iter()
        .filter(|&p| p != Pass::OutputCopy)
        .map(|p| (p, report.status(p)))
}

/// Prints which passes ran in the last frame, which were skipped and why, and the memory of each
/// resource.
pub fn print_plan(report: &FrameReport) {
    println!(
        "frame plan (last frame), output: {}",
        report.output_resource.name()
    );
    for (pass, status) in plan_passes(report) {
        match status.reason() {
            None => println!("  ran      {}", pass.name()),
            Some(reason) => println!("  skipped  {} ({reason})", pass.name()),
        }
    }
    for (resource, bytes) in resource_bytes(report) {
        println!(
            "  {:<24} {:>10.2} MB",
            resource,
            bytes as f64 / (1024.0 * 1024.0)
        );
    }
    println!(
        "  {:<24} {:>10.2} MB",
        "total",
        resource_bytes(report).map(|(_, bytes)| bytes).sum::<u64>() as f64 / (1024.0 * 1024.0)
    );
}

/// "standard" or "shrinking".
pub fn filter_name(f: PenumbraFilter) -> &'static str {
    match f {
        PenumbraFilter::Standard => "standard",
        PenumbraFilter::Shrinking => "shrinking",
    }
}

/// Bytes of the primitive map's resources in a frame report.
pub fn map_bytes(report: &FrameReport) -> u64 {
    [
        Resource::PrimListOffsets,
        Resource::PrimListEntries,
        Resource::Occupancy,
    ]
    .into_iter()
    .map(|r| report.resource_bytes(r))
    .sum()
}

/// Parses the binning request of the command line.
pub fn parse_binning(s: &str) -> Result<BinningPath, String> {
    match s {
        "auto" => Ok(BinningPath::Auto),
        "compute" => Ok(BinningPath::Compute),
        "hw" | "hardware" => Ok(BinningPath::Hardware),
        "sw" | "software" => Ok(BinningPath::Software),
        _ => Err(format!(
            "unknown binning path '{s}' (auto, compute, hw, sw)"
        )),
    }
}

/// Parses the face mode of the command line.
pub fn parse_faces(s: &str) -> Result<Faces, String> {
    match s {
        "both" => Ok(Faces::Both),
        "front" => Ok(Faces::FrontOnly),
        _ => Err(format!("unknown face mode '{s}' (both, front)")),
    }
}

/// Parses a shadow mode.
pub fn parse_mode(s: &str) -> Result<ShadowMode, String> {
    match s {
        "none" => Ok(ShadowMode::None),
        "hard" => Ok(ShadowMode::Hard),
        "soft" => Ok(ShadowMode::Soft),
        "hybrid" => Ok(ShadowMode::Hybrid),
        "area" => Ok(ShadowMode::Area),
        _ => Err(format!(
            "unknown shadow mode '{s}' (none, hard, soft, hybrid, area)"
        )),
    }
}

/// Parses a penumbra filter.
pub fn parse_filter(s: &str) -> Result<PenumbraFilter, String> {
    match s {
        "standard" => Ok(PenumbraFilter::Standard),
        "shrinking" => Ok(PenumbraFilter::Shrinking),
        _ => Err(format!(
            "unknown penumbra filter '{s}' (standard, shrinking)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_modes_and_filters() {
        assert_eq!(parse_mode("soft").unwrap(), ShadowMode::Soft);
        assert!(parse_mode("medium").is_err());
        assert_eq!(parse_filter("standard").unwrap(), PenumbraFilter::Standard);
        assert!(parse_filter("wide").is_err());
    }

    #[test]
    fn derived_row_is_the_sum() {
        let mut t = BTreeMap::from([("PCSS".to_owned(), 1.5), ("ray trace".to_owned(), 0.25)]);
        let notes = add_derived_rows(&mut t);
        assert_eq!(t[PCSS_PLUS_RAY_TRACE], 1.75);
        assert!(notes.contains_key(PCSS_PLUS_RAY_TRACE));
        let mut only = BTreeMap::from([("ray trace".to_owned(), 0.25)]);
        assert!(add_derived_rows(&mut only).is_empty());
    }
}
