//! The demo drives the plugin through its C ABI (`demo_engine::plugin::PluginRenderer`). Its frames equal,
//! bit for bit, the frames of the Rust passes driven directly (`test_support::ShadowRenderer`), for every
//! output both produce, and its report says the same: what the demo shows is what integrators get.

mod common;

use common::*;
use demo_engine::plugin::PluginRenderer;
use demo_engine::{FrameImages, View};
use passes::{
    BinningRequest, FrameReport, PassId, PassStatus, PrimitiveMapConfig, ResourceId, ResourceSet,
    ShadowConfig, ShadowMode, SkipReason,
};
use rhi::Device;
use test_support::ShadowRenderer;

/// Elements that differ in their bits, per output (outputs empty on both sides are skipped).
fn differences(a: &FrameImages, b: &FrameImages) -> Vec<(&'static str, usize)> {
    fn bits<T: Copy>(v: &[T]) -> Vec<u8> {
        // SAFETY: plain numbers and arrays of numbers, read as their bytes.
        unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
            .to_vec()
    }
    fn count(a: Vec<u8>, b: Vec<u8>, size: usize) -> usize {
        if a.len() != b.len() {
            return usize::MAX;
        }
        a.chunks(size)
            .zip(b.chunks(size))
            .filter(|(x, y)| x != y)
            .count()
    }
    vec![
        ("position", count(bits(&a.position), bits(&b.position), 16)),
        ("normal", count(bits(&a.normal), bits(&b.normal), 16)),
        ("depth", count(bits(&a.depth), bits(&b.depth), 4)),
        (
            "visibility",
            count(bits(&a.visibility), bits(&b.visibility), 4),
        ),
        (
            "blocker distance",
            count(bits(&a.blocker_distance), bits(&b.blocker_distance), 4),
        ),
        (
            "occupancy",
            count(bits(&a.occupancy), bits(&b.occupancy), 4),
        ),
        (
            "list offsets",
            count(
                bits(&a.list_offsets.offsets),
                bits(&b.list_offsets.offsets),
                4,
            ),
        ),
        ("lists", list_differences(a, b)),
        (
            "shadow-map visibility",
            count(
                bits(&a.shadow_map_visibility),
                bits(&b.shadow_map_visibility),
                4,
            ),
        ),
        ("pcss", count(bits(&a.pcss), bits(&b.pcss), 4)),
        (
            "antialiased",
            count(bits(&a.antialiased), bits(&b.antialiased), 4),
        ),
        (
            "lerp factor",
            count(bits(&a.lerp_factor), bits(&b.lerp_factor), 4),
        ),
        ("hybrid", count(bits(&a.hybrid), bits(&b.hybrid), 4)),
        ("output", count(bits(&a.output), bits(&b.output), 4)),
    ]
}

/// Texels whose list differs as a set. Atomics may reach a texel in any order on a GPU, so the order
/// within a list is not deterministic; the lists must hold the same triangles. Lists past the capacity
/// (unused by the exact fallback) are not compared.
fn list_differences(a: &FrameImages, b: &FrameImages) -> usize {
    if a.list_offsets != b.list_offsets || a.list_entries.len() != b.list_entries.len() {
        return usize::MAX;
    }
    let capacity = a.list_entries.len();
    let list = |images: &FrameImages, range: std::ops::Range<usize>| {
        let mut l = images.list_entries[range].to_vec();
        l.sort_unstable();
        l
    };
    (0..a.list_offsets.overflowed.len())
        .filter_map(|t| a.list_offsets.range(t).filter(|r| r.end <= capacity))
        .filter(|r| list(a, r.clone()) != list(b, r.clone()))
        .count()
}

fn both(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    frames: usize,
    with_indices: bool,
) -> ((FrameReport, FrameImages), (hrts::FrameReport, FrameImages)) {
    let inputs = view.frame_inputs();
    let mut direct = ShadowRenderer::new(device, view, config).expect("Rust renderer");
    let plugin_config = hrts::passes_bridge::config(&config).expect("a configuration of the C ABI");
    let mut plugin = PluginRenderer::new(device, view, plugin_config).expect("plugin renderer");
    let mut last_direct = None;
    let mut last_plugin = None;
    for _ in 0..frames {
        last_direct = Some(direct.render(device, &inputs).expect("Rust frame"));
        last_plugin = Some(plugin.render(device, &inputs).expect("plugin frame"));
    }
    (
        (
            last_direct.expect("a frame"),
            direct.read_back(device, with_indices).expect("read back"),
        ),
        (
            last_plugin.expect("a frame"),
            plugin.read_back(device, with_indices).expect("read back"),
        ),
    )
}

/// The statistics of the Rust passes' report for `config`, in the order of the plugin's
/// [`hrts::MapStats`].
fn direct_stats(r: &FrameReport, config: &ShadowConfig) -> hrts::MapStats {
    let st = &r.stats;
    hrts::MapStats {
        receiver_pixels: st.receiver_pixels,
        receiver_texels: st.receiver_texels,
        triangles_binned: st.triangles_binned,
        texels_with_list: st.texels_with_list,
        longest_list: st.longest_list,
        entries: st.entries,
        entry_capacity: st.capacity,
        texels_past_capacity: st.texels_past_capacity,
        bin_pairs: st.pairs,
        bin_pair_capacity: st.pair_capacity,
        texels_past_limit: st.texels_past_limit,
        bin_items: st.bin_items,
        frusta_without_lists: u32::from(st.lists_skipped),
        pixels_walked: st.pixels_walked,
        walks_unfinished: st.walks_unfinished,
        pixels_walked_per_sample: st.pixels_walked_per_sample,
        map_size: config.built_map().map_or(0, |m| m.size),
    }
}

/// The C name of a Rust pass status.
fn status_name(status: PassStatus) -> &'static str {
    match status {
        PassStatus::Ran => hrts::PassStatus::Ran.name(),
        PassStatus::Skipped(SkipReason::UpToDate) => hrts::PassStatus::UpToDate.name(),
        PassStatus::Skipped(SkipReason::Shared) => hrts::PassStatus::Shared.name(),
        PassStatus::Skipped(SkipReason::NotRequested) => hrts::PassStatus::NotInPlan.name(),
        PassStatus::Skipped(SkipReason::Culled) => hrts::PassStatus::Culled.name(),
    }
}

fn check(name: &str, view: &View, config: ShadowConfig, frames: usize, with_indices: bool) {
    let device = device();
    let ((direct_report, direct), (plugin_report, plugin)) =
        both(&device, view, config, frames, with_indices);
    let diffs = differences(&direct, &plugin);
    println!("{name}: differing elements per output {diffs:?}");
    assert!(
        diffs.iter().all(|&(_, n)| n == 0),
        "{name}: the C ABI path differs from the Rust path: {diffs:?}"
    );
    assert!(!plugin.output.is_empty() && !plugin.depth.is_empty());
    assert_eq!(
        direct_report.binning_path.name(),
        plugin_report.binning_path.name(),
        "{name}"
    );
    assert_eq!(
        direct_stats(&direct_report, &config),
        plugin_report.stats,
        "{name}"
    );
    // The Rust demo renderer keeps the prim buffer for its G-buffer in every mode; the plugin builds it
    // only when a pass of its plan reads it (the demo, as an engine, draws from its own buffers). The
    // output copy is the plugin's own.
    let direct_passes: Vec<(&str, &str)> = direct_report
        .passes
        .iter()
        .filter(|(p, _)| *p != PassId::PrimBuffer)
        .map(|&(p, s)| (p.name(), status_name(s)))
        .collect();
    let plugin_passes: Vec<(&str, &str)> = hrts::PassMask::ALL
        .iter()
        .filter(|&p| p != hrts::Pass::PrimBuffer && p != hrts::Pass::OutputCopy)
        .map(|p| (p.name(), plugin_report.status(p).name()))
        .collect();
    assert_eq!(direct_passes, plugin_passes, "{name}");
    if config.mode == ShadowMode::None {
        assert!(
            plugin_passes
                .iter()
                .all(|&(p, s)| (s == "RAN") == (p == PassId::FillLit.name())),
            "{name}: the plugin runs only the fill: {plugin_passes:?}"
        );
    }
    assert_eq!(
        direct_report.output.name(),
        plugin_report.output_resource.name(),
        "{name}"
    );
    let direct_images: Vec<(&str, u64)> = direct_report
        .resources
        .iter()
        .filter(|r| r.resource != ResourceId::PrimBuffer)
        .map(|r| (r.resource.name(), r.bytes))
        .collect();
    let plugin_images: Vec<(&str, u64)> = plugin_report
        .allocated_resources()
        .map(|(r, bytes)| (r.name(), bytes))
        .collect();
    assert_eq!(direct_images, plugin_images, "{name}");
    for pass in ["ray trace", "gbuffer", "output copy"] {
        assert!(
            !config.mode.eq(&ShadowMode::Hybrid)
                || plugin_report.timings.iter().any(|t| t.name == pass),
            "{name}: no GPU time for '{pass}' in {:?}",
            plugin_report.timings
        );
    }
    assert_no_validation_errors(&device);
}

#[test]
fn hybrid_with_comparison_outputs_matches_bit_for_bit() {
    let view = View::framed(scene::procedural_default(), 200, 140);
    let config = ShadowConfig {
        map: PrimitiveMapConfig {
            size: 512,
            binning: BinningRequest::Software,
            ..PrimitiveMapConfig::default()
        },
        extra_outputs: ResourceSet::of(&[
            ResourceId::ShadowMapVisibility,
            ResourceId::RtVisibility,
            ResourceId::LerpFactor,
            ResourceId::Occupancy,
        ]),
        ..ShadowConfig::default()
    };
    // Two frames: the second skips the up-to-date prim buffer on both paths.
    check("hybrid, procedural scene", &view, config, 2, false);
}

#[test]
fn hard_shadows_of_a_real_mesh_match_bit_for_bit_with_the_lists() {
    let bunny = scene::load_obj(&model("02_stanford_bunny_69k.obj")).expect("bunny loads");
    let view = View::framed(bunny.with_ground_plane(), 160, 120);
    // A budget the lists pass: the exhaustive fallback runs on both paths.
    let mut config = ShadowConfig::from(PrimitiveMapConfig {
        size: 256,
        entry_budget: 64 << 10,
        ..PrimitiveMapConfig::default()
    });
    config.extra_outputs = ResourceSet::of(&[ResourceId::Occupancy]);
    check(
        "hard, bunny past the entry capacity",
        &view,
        config,
        1,
        true,
    );
}

#[test]
fn soft_and_none_modes_match() {
    let view = View::framed(scene::procedural_default(), 128, 96);
    for mode in [ShadowMode::Soft, ShadowMode::None] {
        let config = ShadowConfig {
            mode,
            ..ShadowConfig::default()
        };
        check(mode.name(), &view, config, 1, false);
    }
}

/// The demo's compact G-buffer (D24S8 depth, octahedral RG16F view-space normals), as `render` keeps it: its
/// read-back rebuilds the analysis G-buffer's world normals and positions (same coverage, normals within the
/// encoding's tilt, positions within the depth's precision), and the hard shadow it gives is exact.
#[test]
fn compact_gbuffer_reads_back_as_the_analysis_one_and_shadows_exactly() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 192, 108);
    let config = hrts::Config {
        mode: hrts::ShadowMode::Hard,
        antialiasing: false,
        ..hrts::Config::default()
    };
    let layouts = [
        demo_engine::gbuffer::GBufferLayout::ANALYSIS,
        demo_engine::gbuffer::GBufferLayout::compact(&device),
    ];
    let images: Vec<FrameImages> = layouts
        .iter()
        .map(|&layout| {
            let mut r =
                PluginRenderer::with_layout(&device, &view, config, layout).expect("renderer");
            r.render(&device, &view.frame_inputs()).expect("render");
            r.read_back(&device, false).expect("read back")
        })
        .collect();
    let (full, compact) = (&images[0], &images[1]);
    let radius = f64::from(view.scene.bounds().radius());
    let (mut coverage, mut tilt, mut shift) = (0, 0.0f64, 0.0f64);
    for i in 0..full.normal.len() {
        let (a, b) = (full.normal[i], compact.normal[i]);
        if (a[3] != 0.0) != (b[3] != 0.0) {
            coverage += 1;
            continue;
        }
        if a[3] == 0.0 {
            continue;
        }
        let (na, nb) = (
            glam::Vec3::from_slice(&a).as_dvec3(),
            glam::Vec3::from_slice(&b).as_dvec3(),
        );
        tilt = tilt.max(na.angle_between(nb).to_degrees());
        let (pa, pb) = (
            glam::Vec3::from_slice(&full.position[i]).as_dvec3(),
            glam::Vec3::from_slice(&compact.position[i]).as_dvec3(),
        );
        shift = shift.max(pa.distance(pb) / radius);
    }
    println!("compact G-buffer: {coverage} px of other coverage, normals within {tilt:.4}°, positions within {shift:.2e} of the scene's radius");
    assert_eq!(coverage, 0, "coverage differs");
    assert!(tilt < 0.1, "normals tilted by {tilt}°");
    assert!(shift < 1e-3, "positions moved by {shift} radii");
    let c = compare_visibility(&reference::RefScene::new(&view.scene), &view, compact);
    assert_eq!(
        c.mismatches, 0,
        "compact G-buffer vs reference: {:?}",
        c.examples
    );
    assert_no_validation_errors(&device);
}
