//! Ray-traced visibility equals the exact f64 reference on every pixel whose exact shadow ray does not pass
//! within a tiny tolerance of a triangle edge; those near-edge pixels are counted and bounded.

mod common;

use common::*;
use demo_engine::View;
use passes::{choose_binning_path, BinningRequest, PrimitiveMapConfig};
use reference::RefScene;

/// Checks `view` with each binning path of `paths`; a path the device lacks fails the test (the hardware
/// path has its own test, ignored unless run with `--ignored` on a device that has it).
fn check_paths(view: &View, size: u32, max_near_edge_fraction: f64, paths: &[BinningRequest]) {
    let device = device();
    let rs = RefScene::new(&view.scene);
    for &binning in paths {
        if let Err(e) = choose_binning_path(device.capabilities(), binning) {
            panic!("{binning:?} binning is not on this device: {e}");
        }
        let config = PrimitiveMapConfig {
            size,
            binning,
            ..Default::default()
        };
        check_config(&device, &rs, view, config, max_near_edge_fraction);
    }
}

fn check_config(
    device: &rhi::Device,
    rs: &RefScene,
    view: &View,
    config: PrimitiveMapConfig,
    max_near_edge_fraction: f64,
) {
    let (report, images) = render(device, view, config, false);
    let c = compare_visibility(rs, view, &images);
    println!(
        "{}x{} map {}² {:?}: {c:?}, stats {:?}",
        view.width, view.height, config.size, report.binning_path, report.stats
    );
    assert_eq!(report.stats.texels_past_capacity, 0);
    assert!(report.stats.entries > 0 && report.stats.receiver_pixels > 0);
    assert_exact_visibility(&c, max_near_edge_fraction);
    assert_eq!(
        c.blocker_mismatches, 0,
        "blocker distance off by up to {}",
        c.max_blocker_error
    );
    assert_no_validation_errors(device);
}

fn check(view: &View, size: u32, max_near_edge_fraction: f64) {
    check_paths(
        view,
        size,
        max_near_edge_fraction,
        &[BinningRequest::Compute, BinningRequest::Software],
    );
}

/// Hardware conservative rasterization: lavapipe has none, so this runs with `--ignored` on a GPU.
#[test]
#[ignore = "needs hardware conservative rasterization: run with --ignored on a GPU that has it"]
fn hardware_binning_matches_exact_visibility() {
    let view = View::framed(scene::procedural_default(), 240, 160);
    check_paths(&view, 256, 0.02, &[BinningRequest::Hardware]);
}

#[test]
fn procedural_scene_matches_exact_visibility() {
    let view = View::framed(scene::procedural_default(), 240, 160);
    check(&view, 256, 0.02);
    // A coarse grid: long lists, the same exact shadow.
    check(&view, 32, 0.02);
}

/// At 200x160 the bunny's 69K triangles are about a pixel across, so the 1/16-pixel band around every
/// edge covers several percent of its surface: those pixels are counted, not compared.
#[test]
fn stanford_bunny_matches_exact_visibility() {
    let bunny = scene::load_obj(&model("02_stanford_bunny_69k.obj")).expect("bunny loads");
    let view = View::framed(bunny.with_ground_plane(), 200, 160);
    check(&view, 256, 0.10);
}
