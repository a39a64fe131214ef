//! The binning matrix: every binning path the device offers — compute and the software geometry-shader
//! raster everywhere; on devices with `VK_EXT_conservative_rasterization` the native hardware tier and a
//! Tier-1 emulation (1/2 px uncertainty, post-snap degenerate triangles culled) — builds primitive maps
//! without receiver culling, compared with the exact conservative binning of the fitted grid. Every path
//! makes the same exact overlap test, so each must hold exactly the same lists: missing 0, garbage 0.
//! Triangles too thin to survive Tier-1 snapping are binned as segments through their bounding box, so
//! no path may drop any (nothing is excused).

use crate::accuracy::{compare_map, fitted_light_matrix, MapComparison};
use crate::frames::{PluginFrames, ViewInputs};
use anyhow::Result;
use demo_engine::plugin::PluginRenderer;
use demo_engine::View;
use hrts::passes_bridge;
use passes::{choose_binning_path, BinningRequest, FaceMode, PrimitiveMapConfig};
use reference::{FaceSelection, RefScene};
use rhi::Device;

/// One row of the matrix.
#[derive(Debug)]
pub struct TierRow {
    /// Scene name.
    pub scene: String,
    /// Binning path name with the tier used.
    pub path: String,
    /// Texel comparison against the exact sets.
    pub map: MapComparison,
    /// GPU milliseconds of the primitive-map pass.
    pub ms: f64,
}

impl TierRow {
    /// Whether every compared texel kept every required triangle and no texel stored garbage.
    pub fn passed(&self) -> bool {
        self.map.missing == 0 && self.map.garbage == 0
    }
}

/// The binning requests the device can run.
pub fn available_requests(device: &Device) -> Vec<BinningRequest> {
    [
        BinningRequest::Compute,
        BinningRequest::Software,
        BinningRequest::Hardware,
        BinningRequest::EmulateTier1,
    ]
    .into_iter()
    .filter(|r| choose_binning_path(device.capabilities(), *r).is_ok())
    .collect()
}

/// The matrix's scenes: the procedural default scene and the Stanford bunny on a ground plane.
pub fn standard_scenes(models: &std::path::Path) -> Result<Vec<(&'static str, View)>> {
    let bunny = scene::load_obj(&models.join("02_stanford_bunny_69k.obj"))?.with_ground_plane();
    Ok(vec![
        (
            "procedural",
            View::framed(scene::procedural_default(), 64, 64),
        ),
        ("stanford bunny 69K", View::framed(bunny, 64, 64)),
    ])
}

/// Runs every available path on every scene, with an `size`² grid.
pub fn tier_matrix(device: &Device, scenes: &[(&str, View)], size: u32) -> Result<Vec<TierRow>> {
    let mut rows = Vec::new();
    for (name, view) in scenes {
        let rs = RefScene::new(&view.scene);
        for request in available_requests(device) {
            // Every list kept whatever its length, to compare with exact binning.
            let config = PrimitiveMapConfig {
                size,
                faces: FaceMode::Both,
                binning: request,
                receiver_culling: false,
                list_limit: u32::MAX,
                bin_budget: f32::INFINITY,
                ..PrimitiveMapConfig::default()
            };
            let mut renderer =
                PluginRenderer::new(device, view, passes_bridge::config(&config.into())?)?;
            let inputs = view.frame_inputs();
            let report = renderer.render(device, &inputs)?;
            let images = renderer.read_back(device, true)?;
            let light = fitted_light_matrix(report.map_to_texels, renderer.scene().origin(), size);
            let map = compare_map(
                &rs,
                light,
                inputs.light.direction(),
                &config,
                &images,
                FaceSelection::Both,
            );
            let ms = report
                .timings
                .iter()
                .filter(|t| t.name.starts_with("primitive map"))
                .map(|t| t.milliseconds)
                .sum();
            let path = format!(
                "{} ({})",
                report.binning_path.name(),
                host_demo::report_text::tier_name(&report)
            );
            rows.push(TierRow {
                scene: (*name).to_owned(),
                path,
                map,
                ms,
            });
        }
    }
    Ok(rows)
}

/// The matrix as a Markdown table.
pub fn markdown(device: &Device, rows: &[TierRow]) -> String {
    let caps = device.capabilities();
    let mut s = format!(
        "Device: {} — conservative-raster tier {} (overestimation {} px).\n\n| scene | path | texels compared | missing | zero-area (culled) | extra (within 1/256 texel) | garbage | GPU ms | result |\n|---|---|---:|---:|---:|---:|---:|---:|---|\n",
        caps.device_name,
        caps.conservative_raster_tier.name(),
        caps.primitive_overestimation_size
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.3} | {} |\n",
            r.scene,
            r.path,
            r.map.texels,
            r.map.missing,
            r.map.missing_degenerate,
            r.map.extra_within_margin,
            r.map.garbage,
            r.ms,
            if r.passed() { "pass" } else { "FAIL" }
        ));
    }
    s
}
