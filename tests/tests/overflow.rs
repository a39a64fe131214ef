//! Overflow of the deep primitive map: with a small d nothing is written past slot d (a guard layer stays
//! untouched), the overflow count is right, the occupancy image is red exactly where counts exceed d, and
//! the documented fallback (exhaustive trace of overflowed texels) keeps visibility exact.

mod common;

use common::*;
use host_demo::View;
use passes::{PrimitiveMapConfig, RasterRequest, GUARD_VALUE};
use reference::RefScene;

#[test]
fn small_depth_overflows_safely_and_visibly() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 160, 120);
    let small = PrimitiveMapConfig {
        size: 128,
        depth: 2,
        raster: RasterRequest::Software,
        guard_layer: true,
        ..Default::default()
    };
    let large = PrimitiveMapConfig {
        depth: 512,
        guard_layer: false,
        ..small
    };
    let (report, images) = render(&device, &view, small, true);
    let (_, reference_counts) = render(&device, &view, large, false);

    // Counts do not depend on d: the atomic keeps counting past it.
    assert_eq!(
        images.counts, reference_counts.counts,
        "count map differs between d=2 and d=512"
    );
    let d = small.depth;
    let expected_overflow = images.counts.iter().filter(|&&c| c > d).count() as u32;
    assert!(
        expected_overflow > 100,
        "the scene should overflow d=2 in many texels"
    );
    assert_eq!(report.stats.overflowed_texels, expected_overflow);
    assert_eq!(report.stats.max_count, *images.counts.iter().max().unwrap());

    // Nothing was written past slot d: the guard layer still holds its clear value everywhere.
    let plane = (small.size * small.size) as usize;
    let guard = &images.indices[d as usize * plane..(d as usize + 1) * plane];
    let written = guard.iter().filter(|&&v| v != GUARD_VALUE).count();
    assert_eq!(written, 0, "{written} texels were written past slot d");

    // Occupancy: red exactly where count > d, white where count == d, black where empty.
    for (i, (&c, px)) in images.counts.iter().zip(&images.occupancy).enumerate() {
        let expected = if c > d {
            [255, 0, 0, 255]
        } else {
            let g = (c as f32 / d as f32 * 255.0).round() as u8;
            [g, g, g, 255]
        };
        assert_eq!(*px, expected, "texel {i} with count {c}");
    }

    // Stored entries of overflowed texels are still valid, distinct triangles of that texel.
    let rs = RefScene::new(&view.scene);
    let c = compare_map(&rs, &view, &small, &images, reference::FaceSelection::Both);
    assert_eq!(c.garbage, 0, "{c:?}");
    assert_eq!(c.missing, 0, "{c:?}");

    // The fallback keeps the ray-traced result exact.
    let v = compare_visibility(&rs, &view, &images);
    println!("overflowed {expected_overflow} texels; {c:?}; {v:?}");
    assert_eq!(v.mismatches, 0, "{:?}", v.examples);
    assert_eq!(v.blocker_mismatches, 0, "{:?}", v.examples);
    assert_no_validation_errors(&device);
}
