//! The software conservative-raster path stores, in every texel, the exact conservative set of triangles
//! (missing: 0) and nothing else beyond a 1/256-texel margin (garbage: 0), on lavapipe with validation on.

mod common;

use common::*;
use host_demo::View;
use passes::{FaceMode, PrimitiveMapConfig, RasterRequest};
use reference::{FaceSelection, RefScene};

fn check(view: &View, size: u32, depth: u32, faces: FaceMode) {
    let device = device();
    let config = PrimitiveMapConfig {
        size,
        depth,
        faces,
        raster: RasterRequest::Software,
        guard_layer: false,
    };
    let (report, images) = render(&device, view, config, true);
    assert_eq!(report.raster_path, passes::RasterPath::Software);
    let rs = RefScene::new(&view.scene);
    let selection = match faces {
        FaceMode::Both => FaceSelection::Both,
        FaceMode::FrontOnly => FaceSelection::FrontOnly,
    };
    let c = compare_map(&rs, view, &config, &images, selection);
    println!(
        "{size}x{size}x{depth} {faces:?}: {c:?}, stats {:?}",
        report.stats
    );
    assert_eq!(
        c.overflowed, 0,
        "choose d so that no texel overflows: {:?}",
        report.stats
    );
    assert_eq!(c.texels, (size * size) as usize);
    assert_eq!(c.missing, 0, "{c:?}");
    assert_eq!(c.garbage, 0, "{c:?}");
    assert!(
        c.extra_within_margin * 100 <= report.stats.stored_entries as usize,
        "margin extras above 1%: {c:?}"
    );
    assert_no_validation_errors(&device);
}

#[test]
fn procedural_scene_software_path_is_exact() {
    let view = View::framed(scene::procedural_default(), 64, 64);
    check(&view, 128, 512, FaceMode::Both);
}

#[test]
fn procedural_scene_front_faces_only_is_exact() {
    let view = View::framed(scene::procedural_default(), 64, 64);
    check(&view, 96, 256, FaceMode::FrontOnly);
}

#[test]
fn stanford_bunny_software_path_is_exact() {
    let bunny = scene::load_obj(&model("02_stanford_bunny_69k.obj")).expect("bunny loads");
    let view = View::framed(bunny.with_ground_plane(), 64, 64);
    check(&view, 192, 1024, FaceMode::Both);
}
