//! `host_demo render`: one view of a scene through every pass, written to a folder.

use crate::output::{shade_preview, write_exr_rgba, write_exr_scalar, write_png};
use crate::View;
use anyhow::{Context, Result};
use passes::{FaceMode, FrameReport, PrimitiveMapConfig, RasterRequest, ShadowRenderer};
use rhi::Device;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Options of a render besides the view.
#[derive(Debug, Clone)]
pub struct RenderOptions {
    /// Primitive map configuration.
    pub map: PrimitiveMapConfig,
    /// Frames rendered; timings are medians over the frames after the first.
    pub frames: u32,
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
    depth: u32,
    faces: &'static str,
    raster_path: &'static str,
    tier: &'static str,
    overflowed_texels: u32,
    max_count: u32,
    occupied_texels: u32,
    stored_entries: u32,
    memory_bytes: u64,
}

#[derive(Serialize)]
struct DeviceJson {
    name: String,
    driver: String,
    api_version: String,
    device_type: String,
}

#[derive(Serialize)]
struct FrameJson {
    width: u32,
    height: u32,
    triangles: usize,
    camera: CameraJson,
    light: LightJson,
    primitive_map: MapJson,
    frames: u32,
    gpu_ms: BTreeMap<String, f64>,
    device: DeviceJson,
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
            samples.entry(t.name.clone()).or_default().push(t.ms);
        }
    }
    for t in reports
        .first()
        .map(|r| r.timings.as_slice())
        .unwrap_or_default()
    {
        samples.entry(t.name.clone()).or_insert_with(|| vec![t.ms]);
    }
    samples
        .into_iter()
        .map(|(name, mut v)| {
            v.sort_by(f64::total_cmp);
            (name, v[v.len() / 2])
        })
        .collect()
}

/// Renders `view`, writes every output into `out`, prints the timing table, and returns the last report.
pub fn render_to_folder(
    device: &Device,
    view: &View,
    options: &RenderOptions,
    out: &Path,
) -> Result<FrameReport> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let geometry = view.upload(device).context("uploading the scene")?;
    let mut renderer = ShadowRenderer::new(device, geometry, view.width, view.height, options.map)
        .context("creating the shadow passes")?;
    let inputs = view.frame_inputs();
    let mut reports = Vec::new();
    for _ in 0..options.frames.max(1) {
        reports.push(renderer.render(device, &inputs).context("rendering")?);
    }
    let images = renderer.read_back(device, false).context("reading back")?;
    let (w, h, n) = (view.width, view.height, options.map.size);
    write_exr_rgba(&out.join("position.exr"), w, h, &images.position)?;
    write_exr_rgba(&out.join("normal.exr"), w, h, &images.normal)?;
    write_exr_scalar(&out.join("rt_visibility.exr"), w, h, &images.visibility)?;
    write_exr_scalar(
        &out.join("blocker_distance.exr"),
        w,
        h,
        &images.blocker_distance,
    )?;
    write_png(&out.join("occupancy.png"), n, n, &images.occupancy)?;
    write_png(
        &out.join("preview.png"),
        w,
        h,
        &shade_preview(&images.normal, &images.visibility, -view.light.direction),
    )?;

    let report = reports.last().cloned().context("no frame rendered")?;
    let timings = median_timings(&reports);
    let caps = device.capabilities();
    let stats = report.stats;
    let json = FrameJson {
        width: w,
        height: h,
        triangles: view.scene.triangle_count(),
        camera: CameraJson {
            view: inputs.view.to_cols_array(),
            proj: inputs.proj.to_cols_array(),
            position: inputs.camera_position.to_array(),
        },
        light: LightJson {
            r#type: "directional",
            direction: inputs.light_direction.to_array(),
            view_proj: inputs.light_view_proj.to_cols_array(),
        },
        primitive_map: MapJson {
            size: n,
            depth: options.map.depth,
            faces: match options.map.faces {
                FaceMode::Both => "both",
                FaceMode::FrontOnly => "front",
            },
            raster_path: report.raster_path.name(),
            tier: report.raster_path.tier().name(),
            overflowed_texels: stats.overflowed_texels,
            max_count: stats.max_count,
            occupied_texels: stats.occupied_texels,
            stored_entries: stats.stored_entries,
            memory_bytes: options.map.memory_bytes(),
        },
        frames: options.frames.max(1),
        gpu_ms: timings.clone(),
        device: DeviceJson {
            name: caps.device_name.clone(),
            driver: caps.driver.clone(),
            api_version: caps.api_version.clone(),
            device_type: caps.device_type.clone(),
        },
    };
    let text = serde_json::to_string_pretty(&json)?;
    std::fs::write(out.join("frame.json"), text)
        .with_context(|| format!("writing {}/frame.json", out.display()))?;

    println!(
        "device: {} ({}, {})",
        caps.device_name, caps.device_type, caps.driver
    );
    println!(
        "scene: {} triangles, {}x{} px; primitive map {}x{}x{} ({} path, tier {}), {} overflowed texels, max count {}",
        view.scene.triangle_count(),
        w,
        h,
        n,
        n,
        options.map.depth,
        report.raster_path.name(),
        report.raster_path.tier().name(),
        stats.overflowed_texels,
        stats.max_count
    );
    println!("{:<28} {:>10}", "pass", "GPU ms");
    for (name, ms) in &timings {
        println!("{name:<28} {ms:>10.3}");
    }
    println!(
        "(medians over {} frames after the first; outputs in {})",
        options.frames.max(2) - 1,
        out.display()
    );
    Ok(report)
}

/// Parses the raster request of the command line.
pub fn parse_raster(s: &str) -> Result<RasterRequest, String> {
    match s {
        "auto" => Ok(RasterRequest::Auto),
        "hw" | "hardware" => Ok(RasterRequest::Hardware),
        "sw" | "software" => Ok(RasterRequest::Software),
        _ => Err(format!("unknown raster path '{s}' (auto, hw, sw)")),
    }
}

/// Parses the face mode of the command line.
pub fn parse_faces(s: &str) -> Result<FaceMode, String> {
    match s {
        "both" => Ok(FaceMode::Both),
        "front" => Ok(FaceMode::FrontOnly),
        _ => Err(format!("unknown face mode '{s}' (both, front)")),
    }
}
