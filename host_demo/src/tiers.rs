//! The conservative-raster tier matrix: every raster path the device offers — the software
//! geometry-shader path everywhere; on devices with `VK_EXT_conservative_rasterization` the native
//! hardware tier and a Tier-1 emulation (1/2 px uncertainty, post-snap degenerate triangles culled) —
//! builds primitive maps that are compared with the exact conservative binning.

use crate::accuracy::{compare_map_excusing, MapComparison, EXTRA_MARGIN_TEXELS};
use crate::plugin::PluginRenderer;
use crate::View;
use anyhow::Result;
use glam::DVec4;
use passes::{choose_raster_path, FaceMode, PrimitiveMapConfig, RasterRequest};
use reference::{FaceSelection, RefScene};
use rhi::Device;

/// One row of the matrix.
#[derive(Debug)]
pub struct TierRow {
    /// Scene name.
    pub scene: String,
    /// Raster path name with the tier used.
    pub path: String,
    /// Texel comparison against the exact sets.
    pub map: MapComparison,
    /// GPU milliseconds of the primitive-map pass.
    pub ms: f64,
}

impl TierRow {
    /// Whether every compared texel kept every required triangle the path may not drop, and no texel
    /// stored garbage. Overflowed texels (count > d) cannot hold their full set by design; they are
    /// counted apart, and the ray trace treats them exhaustively.
    pub fn passed(&self) -> bool {
        self.map.missing == 0 && self.map.garbage == 0
    }
}

/// The raster requests the device can run.
pub fn available_requests(device: &Device) -> Vec<RasterRequest> {
    [
        RasterRequest::Software,
        RasterRequest::Hardware,
        RasterRequest::EmulateTier1,
    ]
    .into_iter()
    .filter(|r| choose_raster_path(device.capabilities(), *r).is_ok())
    .collect()
}

/// Triangles that are degenerate after snapping their light-space vertices to 1/256 texel, as D3D12
/// Tier 1 hardware (and the Tier-1 emulation) may cull them.
fn snap_degenerate(rs: &RefScene, view: &View, n: u32) -> Vec<bool> {
    let m = view.frame_inputs().light.view_proj().as_dmat4();
    (0..rs.triangle_count())
        .map(|i| {
            let q: Vec<[i64; 2]> = rs
                .triangle(i)
                .iter()
                .map(|v| {
                    let c = m * DVec4::new(v.x, v.y, v.z, 1.0);
                    let t = (c.truncate().truncate() / c.w * 0.5 + 0.5) * f64::from(n) * 256.0;
                    [t.x.round() as i64, t.y.round() as i64]
                })
                .collect();
            let (a, b) = (
                [q[1][0] - q[0][0], q[1][1] - q[0][1]],
                [q[2][0] - q[0][0], q[2][1] - q[0][1]],
            );
            i128::from(a[0]) * i128::from(b[1]) - i128::from(a[1]) * i128::from(b[0]) == 0
        })
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

/// Runs every available path on every scene.
pub fn tier_matrix(
    device: &Device,
    scenes: &[(&str, View)],
    size: u32,
    depth: u32,
) -> Result<Vec<TierRow>> {
    let mut rows = Vec::new();
    for (name, view) in scenes {
        let rs = RefScene::new(&view.scene);
        let culled_by_snap = snap_degenerate(&rs, view, size);
        for request in available_requests(device) {
            let config = PrimitiveMapConfig {
                size,
                depth,
                faces: FaceMode::Both,
                raster: request,
                guard_layer: false,
            };
            let mut renderer = PluginRenderer::new(device, view, config)?;
            let report = renderer.render(device, &view.frame_inputs())?;
            let images = renderer.read_back(device, true)?;
            let tier1 = request == RasterRequest::EmulateTier1;
            let excused = |t: u32| tier1 && culled_by_snap[t as usize];
            let margin = if tier1 {
                0.5 + EXTRA_MARGIN_TEXELS
            } else {
                EXTRA_MARGIN_TEXELS
            };
            let map = compare_map_excusing(
                &rs,
                &view.frame_inputs(),
                &config,
                &images,
                FaceSelection::Both,
                margin,
                &excused,
            );
            let ms = report
                .timings
                .iter()
                .filter(|t| t.name.starts_with("primitive map"))
                .map(|t| t.ms)
                .sum();
            let path = format!(
                "{} ({})",
                report.raster_path.name(),
                report.raster_path.tier().name()
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
        "Device: {} — conservative-raster tier {} (overestimation {} px).\n\n| scene | path | texels compared | overflowed (not compared) | missing | dropped by Tier-1 snap | extra (within the path's margin: 1/256 texel, Tier 1: 1/2) | garbage | GPU ms | result |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
        caps.device_name,
        caps.conservative_raster_tier.name(),
        caps.primitive_overestimation_size
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {} |\n",
            r.scene,
            r.path,
            r.map.texels,
            r.map.overflowed,
            r.map.missing,
            r.map.missing_excused,
            r.map.extra_within_margin,
            r.map.garbage,
            r.ms,
            if r.passed() { "pass" } else { "FAIL" }
        ));
    }
    s
}
