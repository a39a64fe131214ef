//! A primitive map whose lists do not fit: nothing is written past the entry capacity (guard words stay
//! untouched), the texels that did not fit are counted and shown red, the documented fallback (those
//! texels' pixels walk the BVH) keeps visibility exact, no count, sum or offset wraps even past 2^32
//! entries, and the lists grow to fit the next frame within the memory budget.

mod common;

use common::*;
use demo_engine::{FrameImages, View};
use passes::{
    FrameInputs, PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig, GUARD_VALUE,
    GUARD_WORDS, MIN_ENTRY_BUDGET,
};
use reference::RefScene;
use test_support::ShadowRenderer;

fn frames(
    device: &rhi::Device,
    view: &View,
    config: PrimitiveMapConfig,
    count: usize,
) -> Vec<(passes::FrameReport, FrameImages)> {
    let mut config = ShadowConfig::from(config);
    config.extra_outputs = ResourceSet::of(&[ResourceId::Occupancy]);
    let mut r = ShadowRenderer::new(device, view, config).expect("renderer");
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
    let offsets = &images.list_offsets;
    let texels = offsets.overflowed.len();
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
    // Past capacity: exactly the texels whose list ends beyond it, shown red (no group of 16 texels holds
    // 65536 entries here, so every list's bounds are kept).
    assert!(offsets.overflowed.iter().all(|&o| !o));
    let past: Vec<usize> = (0..texels)
        .filter(|&t| {
            offsets
                .range(t)
                .is_some_and(|r| r.end > capacity && !r.is_empty())
        })
        .collect();
    assert_eq!(st.texels_past_capacity as usize, past.len());
    for &t in &past {
        assert_eq!(images.occupancy[t], [255, 0, 0, 255], "texel {t}");
    }
    assert_eq!(st.entries, offsets.total());
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

/// 4,500 stacked triangles above a ground square, turned a little each, all covering a disc of radius 0.5:
/// every texel of its shadow lists all of them.
fn stacked_fan() -> scene::Scene {
    let mut fan = scene::MeshBuilder::new();
    let blades = 4500;
    for i in 0..blades {
        let a = i as f32 / blades as f32 * std::f32::consts::TAU;
        let y = 1.0 + i as f32 * 1e-4;
        let corner = |k: f32| {
            let b = a + k * std::f32::consts::TAU / 3.0;
            glam::Vec3::new(b.cos(), y, b.sin())
        };
        fan.add_triangle([corner(0.0), corner(1.0), corner(2.0)]);
    }
    let mut fan = fan.into_scene("fan");
    fan.append(&scene::Scene::axis_box(
        "ground",
        glam::Vec3::new(-4.0, -0.1, -4.0),
        glam::Vec3::new(4.0, 0.0, 4.0),
    ));
    fan
}

/// Lists so long that a group of 16 texels holds 32768 entries or more: the packed offsets cannot keep the
/// group's 15-bit local offsets, so its texels are reported past the capacity and walk the BVH, and the
/// shadow stays exact. The lists are built whatever their length (no list limit, no bin budget), over the
/// stacked fan.
#[test]
fn groups_of_lists_past_15_bit_offsets_stay_exact() {
    let device = device();
    let view = View::framed(stacked_fan(), 96, 72);
    let rs = RefScene::new(&view.scene);
    // Every texel the triangles overlap is binned (no receiver culling), so that the 16 texels of a group
    // all hold lists: the fan's shadow spans about 30 texels of the 256² grid.
    let config = PrimitiveMapConfig {
        size: 256,
        guard: true,
        receiver_culling: false,
        list_limit: u32::MAX,
        bin_budget: f32::INFINITY,
        ..Default::default()
    };
    let runs = frames(&device, &view, config, 2);
    let (report, images) = &runs[1];
    let st = report.stats;
    assert!(!st.lists_skipped, "{st:?}");
    assert_eq!(st.walks_unfinished, 0, "{st:?}");
    let overflowed = images
        .list_offsets
        .overflowed
        .iter()
        .filter(|&&o| o)
        .count();
    println!("{st:?}; {overflowed} texels in overflowed groups");
    assert!(st.longest_list > 4096, "{st:?}");
    assert!(overflowed >= 16, "no group overflowed: {st:?}");
    assert_eq!(st.texels_past_capacity as usize, overflowed, "{st:?}");
    for (t, _) in images
        .list_offsets
        .overflowed
        .iter()
        .enumerate()
        .filter(|(_, &o)| o)
    {
        assert_eq!(images.occupancy[t], [255, 0, 0, 255], "texel {t}");
    }
    let v = compare_visibility(&rs, &view, images);
    println!("mismatches {}, near-edge {}", v.mismatches, v.near_edge);
    assert_eq!(v.mismatches, 0, "{:?}", v.examples);
    assert_eq!(v.blocker_mismatches, 0, "{:?}", v.examples);
    assert_no_validation_errors(&device);
}

/// Lists whose entries sum past 2^32: each pair of the stacked fan counts 2^16 entries (the map's debug
/// count scale), so the texels' counts, about 3 x 10^8 each, sum to about 10^10. The saturating scan keeps
/// every offset below 2^32 exact and marks the rest, nothing wraps: the report counts the entries as
/// saturated, the texels past the capacity (every group past 2^31 entries among them) walk the BVH, no guard
/// word is written, and the shadow stays exact.
#[test]
fn list_entries_past_2_pow_32_never_wrap_and_stay_exact() {
    let device = device();
    let view = View::framed(stacked_fan(), 96, 72);
    let rs = RefScene::new(&view.scene);
    let config = PrimitiveMapConfig {
        size: 256,
        guard: true,
        list_limit: u32::MAX,
        bin_budget: f32::INFINITY,
        debug_count_scale: 1 << 16,
        ..Default::default()
    };
    let runs = frames(&device, &view, config, 2);
    for (report, images) in &runs {
        let st = report.stats;
        println!("{st:?}");
        assert!(!st.lists_skipped, "{st:?}");
        assert_eq!(st.entries, u32::MAX, "the entries' sum saturates: {st:?}");
        assert!(st.texels_past_capacity > 0, "{st:?}");
        assert!(st.pixels_walked > 0, "{st:?}");
        assert_eq!(st.walks_unfinished, 0, "{st:?}");
        let capacity = st.capacity as usize;
        let written = images.list_entries[capacity..]
            .iter()
            .filter(|&&v| v != GUARD_VALUE)
            .count();
        assert_eq!(
            written, 0,
            "{written} guard words were written past the capacity"
        );
        // Past the capacity: the texels of overflowed groups and those whose list ends beyond it.
        let offsets = &images.list_offsets;
        let past = (0..offsets.overflowed.len())
            .filter(|&t| {
                offsets
                    .range(t)
                    .is_none_or(|r| !r.is_empty() && r.end > capacity)
            })
            .count();
        assert_eq!(past, st.texels_past_capacity as usize, "{st:?}");
        let v = compare_visibility(&rs, &view, images);
        println!("mismatches {}, near-edge {}", v.mismatches, v.near_edge);
        assert_eq!(v.mismatches, 0, "{:?}", v.examples);
        assert_eq!(v.blocker_mismatches, 0, "{:?}", v.examples);
    }
    assert_no_validation_errors(&device);
}
