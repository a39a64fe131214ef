//! A primitive map whose lists do not fit: nothing is written past the entry capacity (guard words stay
//! untouched), the texels that did not fit are counted and shown red, the documented fallback (those
//! texels traced against every triangle) keeps visibility exact, and the lists grow to fit the next frame
//! within the memory budget.

mod common;

use common::*;
use host_demo::{FrameImages, ShadowRenderer, View};
use passes::{
    FrameInputs, PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig, GUARD_VALUE,
    GUARD_WORDS, MIN_ENTRY_BUDGET,
};
use reference::RefScene;

fn frames(
    device: &rhi::Device,
    view: &View,
    config: PrimitiveMapConfig,
    count: usize,
) -> Vec<(passes::FrameReport, FrameImages)> {
    let geometry = view.upload(device).expect("upload");
    let mut config = ShadowConfig::from(config);
    config.extra_outputs = ResourceSet::of(&[ResourceId::Occupancy]);
    let mut r =
        ShadowRenderer::new(device, geometry, view.width, view.height, config).expect("renderer");
    let inputs: FrameInputs = view.frame_inputs();
    (0..count)
        .map(|_| {
            let report = r.render(device, &inputs).expect("render");
            (report, r.read_back(device, true).expect("read back"))
        })
        .collect()
}

fn assert_past_capacity_is_safe_and_exact(
    rs: &RefScene,
    view: &View,
    report: &passes::FrameReport,
    images: &FrameImages,
) {
    let st = report.stats;
    let texels = images.list_offsets.len() - 1;
    let capacity = st.capacity as usize;
    assert_eq!(images.list_entries.len(), capacity + GUARD_WORDS as usize);
    let written = images.list_entries[capacity..]
        .iter()
        .filter(|&&v| v != GUARD_VALUE)
        .count();
    assert_eq!(
        written, 0,
        "{written} guard words were written past the capacity"
    );
    // Past capacity: exactly the texels whose list ends beyond it, shown red.
    let past: Vec<usize> = (0..texels)
        .filter(|&t| {
            images.list_offsets[t + 1] as usize > capacity
                && images.list_offsets[t + 1] > images.list_offsets[t]
        })
        .collect();
    assert_eq!(st.texels_past_capacity as usize, past.len());
    for &t in &past {
        assert_eq!(images.occupancy[t], [255, 0, 0, 255], "texel {t}");
    }
    assert_eq!(st.entries, images.list_offsets[texels]);
    // The fallback keeps the ray-traced result exact.
    let v = compare_visibility(rs, view, images);
    println!(
        "{st:?}; mismatches {}, near-edge {}",
        v.mismatches, v.near_edge
    );
    assert_eq!(v.mismatches, 0, "{:?}", v.examples);
    assert_eq!(v.blocker_mismatches, 0, "{:?}", v.examples);
}

#[test]
fn lists_past_a_small_budget_stay_safe_and_exact() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 160, 120);
    let rs = RefScene::new(&view.scene);
    let config = PrimitiveMapConfig {
        size: 128,
        entry_budget: MIN_ENTRY_BUDGET + 4 * u64::from(GUARD_WORDS),
        guard: true,
        ..Default::default()
    };
    let runs = frames(&device, &view, config, 2);
    for (report, images) in &runs {
        let st = report.stats;
        assert_eq!(st.capacity, 1024, "the budget holds 1024 entries");
        assert!(st.entries > 10 * st.capacity, "{st:?}");
        assert!(st.texels_past_capacity > 100, "{st:?}");
        assert_past_capacity_is_safe_and_exact(&rs, &view, report, images);
    }
    assert_no_validation_errors(&device);
}

#[test]
fn lists_grow_to_fit_the_next_frame() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 160, 120);
    let rs = RefScene::new(&view.scene);
    let config = PrimitiveMapConfig {
        size: 128,
        initial_entries: 1000,
        guard: true,
        ..Default::default()
    };
    let runs = frames(&device, &view, config, 3);
    let (first, first_images) = &runs[0];
    assert_eq!(first.stats.capacity, 1000);
    assert!(first.stats.texels_past_capacity > 0, "{:?}", first.stats);
    assert_past_capacity_is_safe_and_exact(&rs, &view, first, first_images);
    for (report, images) in &runs[1..] {
        let st = report.stats;
        assert_eq!(st.texels_past_capacity, 0, "{st:?}");
        assert!(
            st.capacity >= st.entries && st.capacity <= st.entries * 5 / 4 + 1,
            "{st:?}"
        );
        assert_eq!(st.entries, first.stats.entries);
        assert_eq!(
            images.visibility, first_images.visibility,
            "growing changed the shadow"
        );
        assert_past_capacity_is_safe_and_exact(&rs, &view, report, images);
    }
    assert_no_validation_errors(&device);
}

/// Lists sized by what they occupy: a map whose starting estimate (two entries per texel of a 1024² map)
/// far exceeds what the view needs shrinks to half again the entries a frame needed, and stays exact.
#[test]
fn lists_shrink_to_what_they_occupy() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 160, 120);
    let rs = RefScene::new(&view.scene);
    let config = PrimitiveMapConfig {
        size: 1024,
        guard: true,
        ..Default::default()
    };
    let runs = frames(&device, &view, config, 3);
    let (first, first_images) = &runs[0];
    let needed = first.stats.entries;
    assert!(
        u64::from(needed) * 2 < u64::from(first.stats.capacity),
        "{:?}",
        first.stats
    );
    for (report, images) in &runs[1..] {
        let st = report.stats;
        assert_eq!(st.entries, needed);
        assert_eq!(st.texels_past_capacity, 0, "{st:?}");
        assert_eq!(
            st.capacity,
            (needed * 3 / 2).max(passes::MIN_FITTED_ENTRIES),
            "{st:?}"
        );
        assert_eq!(
            images.visibility, first_images.visibility,
            "shrinking changed the shadow"
        );
        assert_past_capacity_is_safe_and_exact(&rs, &view, report, images);
    }
    assert_no_validation_errors(&device);
}
