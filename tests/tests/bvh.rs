//! The BVH over the prim buffer (`passes::bvh`), built on the GPU, and the traces' walk of it.
//!
//! The hierarchy is read back and checked on the CPU: every triangle is one leaf, every node is reached
//! once, each child's box is exactly the bounds of its subtree's vertices, and no path is 64 deep — over a
//! real model, over triangles whose box centres all coincide (equal Morton codes throughout), and over one
//! and two triangles: the linear BVH and the rays' BVH, built by clustering (which costs less than the
//! linear one by surface area) and as the linear one's copy (for geometry rebuilt every frame).
//!
//! A walk of it gives the same answer as the lists, bit for bit: the same view traced with lists only, with
//! the BVH only (a bin budget of 0) and with short lists (a list limit of 2, the longer ones walked) gives
//! equal visibility, blocker distances and area counts, and equals the exact reference.

mod common;

use common::*;
use demo_engine::{FrameImages, View};
use glam::Vec3;
use passes::area::{DEFAULT_BUNDLE_WALK_BUDGET, WIDE_BUNDLE};
use passes::bvh::{BvhBuilder, BvhNode, BVH_LEAF};
use passes::gpu_types::GpuTriangle;
use passes::{
    AreaConfig, BinningRequest, FrameReport, PcssConfig, PrimitiveMapConfig, ShadowConfig,
    ShadowMode,
};
use reference::RefScene;
use rhi::{Barrier, Buffer, BufferUsage, Device, MemoryLocation, ResourceState as S};
use test_support::with_blocker_distance;
use test_support::ShadowRenderer;

/// Copies `buffer` to the host.
fn read_buffer<T: bytemuck::Pod>(device: &Device, buffer: &Buffer) -> Vec<T> {
    let readback = device
        .create_buffer(
            "read-back",
            buffer.size(),
            BufferUsage::COPY_DST,
            MemoryLocation::GpuToCpu,
        )
        .expect("read-back buffer");
    device
        .submit_and_wait(|enc| {
            enc.barriers(&[Barrier::Global {
                before: S::UnorderedAccess,
                after: S::CopySource,
            }]);
            enc.copy_buffer(buffer, &readback)?;
            enc.barriers(&[Barrier::Global {
                before: S::CopyDest,
                after: S::HostRead,
            }]);
            Ok(())
        })
        .expect("copy");
    bytemuck::pod_collect_to_vec(readback.read().expect("read"))
}

/// Renders `view` once with `config` and reads everything back.
fn render_with(device: &Device, view: &View, config: ShadowConfig) -> (FrameReport, FrameImages) {
    let mut r = ShadowRenderer::new(device, view, config).expect("renderer");
    let report = r.render(device, &view.frame_inputs()).expect("render");
    (report, r.read_back(device, false).expect("read back"))
}

/// Checks hierarchy `nodes` against `triangles`: every triangle one leaf, every node reached once, every
/// box exact, no path 64 deep. Returns its depth and cost: the surface areas of its internal nodes' boxes
/// over the root's (what a walk of rays in every direction visits).
fn check_nodes(triangles: &[GpuTriangle], nodes: &[BvhNode]) -> (usize, f64) {
    let n = triangles.len();
    let bounds = |t: &GpuTriangle| {
        let [a, b, c] = t.v.map(|v| v.truncate());
        (a.min(b).min(c), a.max(b).max(c))
    };
    let root = nodes[0];
    if n == 1 {
        assert_eq!(root.left_lo.w.to_bits(), BVH_LEAF);
        assert_eq!(root.right_lo.w.to_bits(), BVH_LEAF);
        assert_eq!(
            (root.left_lo.truncate(), root.left_hi.truncate()),
            bounds(&triangles[0])
        );
        return (0, 1.0);
    }
    let children = |node: &BvhNode| {
        [
            (
                node.left_lo.w.to_bits(),
                (node.left_lo.truncate(), node.left_hi.truncate()),
            ),
            (
                node.right_lo.w.to_bits(),
                (node.right_lo.truncate(), node.right_hi.truncate()),
            ),
        ]
    };
    let mut leaves = vec![0u32; n];
    let mut reached = vec![0u32; nodes.len()];
    reached[0] = 1;
    // (child, its box as stored in the parent, depth)
    let mut pending: Vec<(u32, (Vec3, Vec3), usize)> = Vec::new();
    for (child, stored) in children(&root) {
        pending.push((child, stored, 1));
    }
    let mut deepest = 0;
    let mut order = Vec::new();
    while let Some((child, stored, depth)) = pending.pop() {
        deepest = deepest.max(depth);
        if child & BVH_LEAF != 0 {
            let t = (child & !BVH_LEAF) as usize;
            assert!(t < n, "leaf {t} past {n} triangles");
            leaves[t] += 1;
            assert_eq!(stored, bounds(&triangles[t]), "triangle {t}'s box");
        } else {
            let i = child as usize;
            assert!(i < nodes.len(), "node {i} past {} nodes", nodes.len());
            reached[i] += 1;
            order.push((i, stored));
            for (grandchild, box_) in children(&nodes[i]) {
                pending.push((grandchild, box_, depth + 1));
            }
        }
    }
    assert!(deepest < 64, "a path {deepest} deep");
    let twice = leaves.iter().filter(|&&c| c != 1).count();
    assert_eq!(twice, 0, "{twice} triangles not exactly once in the leaves");
    let unreached = reached.iter().filter(|&&c| c != 1).count();
    assert_eq!(unreached, 0, "{unreached} nodes not reached exactly once");
    // Each internal node's box as its parent stores it is the union of its children's boxes.
    let area = |(lo, hi): (Vec3, Vec3)| {
        let d = (hi - lo).as_dvec3();
        d.x * d.y + d.y * d.z + d.z * d.x
    };
    let union = |node: &BvhNode| {
        let [(_, l), (_, r)] = children(node);
        (l.0.min(r.0), l.1.max(r.1))
    };
    let root_area = area(union(&root));
    let mut cost = 1.0;
    for (i, stored) in order {
        assert_eq!(stored, union(&nodes[i]), "node {i}'s box");
        cost += area(stored) / root_area;
    }
    (deepest, cost)
}

/// Builds the BVHs of `view`'s scene (a frame of hard shadows), rebuilds them with the rays' by `builder`,
/// and checks both against the triangles; returns the linear one's cost and the rays' one's.
fn check_hierarchies(device: &Device, view: &View, builder: BvhBuilder) -> (f64, f64) {
    let mut r = ShadowRenderer::new(
        device,
        view,
        ShadowConfig {
            mode: ShadowMode::Hard,
            ..ShadowConfig::default()
        },
    )
    .expect("renderer");
    r.render(device, &view.frame_inputs()).expect("render");
    let shared = r.pipeline().shared_geometry();
    device
        .submit_and_wait(|enc| {
            enc.barriers(&[Barrier::Uav]);
            shared
                .bvh()
                .record_build(enc, builder)
                .expect("record the build");
            Ok(())
        })
        .expect("rebuild");
    let triangles: Vec<GpuTriangle> = read_buffer(device, shared.prims());
    assert_eq!(triangles.len(), shared.geometry().triangle_count() as usize);
    let linear: Vec<BvhNode> = read_buffer(device, shared.bvh().nodes());
    let rays: Vec<BvhNode> = read_buffer(device, shared.bvh().ray_nodes());
    let (linear_depth, linear_cost) = check_nodes(&triangles, &linear);
    let (ray_depth, ray_cost) = check_nodes(&triangles, &rays);
    let copy =
        bytemuck::cast_slice::<BvhNode, u8>(&rays) == bytemuck::cast_slice::<BvhNode, u8>(&linear);
    if builder == BvhBuilder::Linear || triangles.len() < 2 {
        assert!(copy, "the rays' hierarchy is not the linear one's copy");
    } else if triangles.len() > 2 {
        assert!(!copy, "the clustering did not build the rays' hierarchy");
        // Depth first: each node's left child, where it is a node, right after it.
        for (i, node) in rays.iter().enumerate() {
            let left = node.left_lo.w.to_bits();
            assert!(
                left & BVH_LEAF != 0 || left as usize == i + 1,
                "node {i}'s left child is node {left}"
            );
        }
    }
    println!(
        "{} triangles, rays' hierarchy {builder:?}: linear depth {linear_depth}, cost {linear_cost:.1}; \
         rays' depth {ray_depth}, cost {ray_cost:.1}",
        triangles.len()
    );
    assert_no_validation_errors(device);
    (linear_cost, ray_cost)
}

#[test]
fn the_bvh_holds_every_triangle_once_in_exact_boxes() {
    let device = device();
    let bunny = scene::load_obj(&model("02_stanford_bunny_69k.obj")).expect("bunny loads");
    let bunny = View::framed(bunny.with_ground_plane(), 64, 48);
    check_hierarchies(&device, &bunny, BvhBuilder::Linear);
    let (linear, clustered) = check_hierarchies(&device, &bunny, BvhBuilder::Clustered);
    // The clustering builds a better hierarchy than the linear build (its copy did not take its place).
    assert!(
        clustered < 0.9 * linear,
        "cost {clustered:.1} clustered, {linear:.1} linear"
    );
    // 3,000 triangles around one centre: every Morton code equal, the split by position alone.
    let mut star = scene::MeshBuilder::new();
    for i in 0..3000 {
        let a = i as f32 * 0.618;
        let u = Vec3::new(a.cos(), 0.3, a.sin());
        star.add_triangle([u, -u, Vec3::new(0.0, 1.0 + i as f32 * 1e-3, 0.0)]);
    }
    let star = View::framed(star.into_scene("star"), 32, 24);
    for builder in [BvhBuilder::Clustered, BvhBuilder::Linear] {
        check_hierarchies(&device, &star, builder);
    }
    for count in [1, 2] {
        let mut few = scene::MeshBuilder::new();
        for i in 0..count {
            let y = i as f32;
            few.add_triangle([
                Vec3::new(0.0, y, 0.0),
                Vec3::new(1.0, y, 0.0),
                Vec3::new(0.0, y, 1.0),
            ]);
        }
        let few = View::framed(few.into_scene("few"), 16, 16);
        for builder in [BvhBuilder::Clustered, BvhBuilder::Linear] {
            check_hierarchies(&device, &few, builder);
        }
    }
}

/// Lists only, the BVH only, and short lists (the longer walked): the three routes of a frame.
fn routes(map: PrimitiveMapConfig) -> [(&'static str, PrimitiveMapConfig); 3] {
    [
        (
            "lists",
            PrimitiveMapConfig {
                list_limit: u32::MAX,
                bin_budget: f32::INFINITY,
                ..map
            },
        ),
        (
            "BVH",
            PrimitiveMapConfig {
                bin_budget: 0.0,
                ..map
            },
        ),
        (
            "lists of 2 at most",
            PrimitiveMapConfig {
                list_limit: 2,
                bin_budget: f32::INFINITY,
                ..map
            },
        ),
    ]
}

/// Asserts where a route's pixels went.
fn assert_route(name: &str, report: &FrameReport) {
    let st = report.stats;
    assert_eq!(st.walks_unfinished, 0, "{name}: {st:?}");
    match name {
        "lists" => assert!(st.pixels_walked == 0 && !st.lists_skipped, "{name}: {st:?}"),
        "BVH" => assert!(
            st.lists_skipped && st.pixels_walked > 0 && st.entries == 0,
            "{name}: {st:?}"
        ),
        _ => assert!(
            st.texels_past_limit > 0 && st.pixels_walked > 0 && st.entries > 0,
            "{name}: {st:?}"
        ),
    }
}

#[test]
fn hard_shadows_through_the_bvh_equal_the_lists_bit_for_bit() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 160, 120);
    let rs = RefScene::new(&view.scene);
    let map = PrimitiveMapConfig {
        size: 128,
        binning: BinningRequest::Compute,
        ..PrimitiveMapConfig::default()
    };
    let mut first: Option<FrameImages> = None;
    for (name, map) in routes(map) {
        let mut config = with_blocker_distance(ShadowConfig::from(map));
        config.mode = ShadowMode::Hard;
        let (report, images) = render_with(&device, &view, config);
        assert_route(name, &report);
        let c = compare_visibility(&rs, &view, &images);
        println!(
            "{name}: {} mismatches, {} near-edge, {:?}",
            c.mismatches, c.near_edge, report.stats
        );
        assert_exact_visibility(&c, 0.04);
        assert_eq!(c.blocker_mismatches, 0, "{name}: blocker distances");
        match &first {
            None => first = Some(images),
            Some(lists) => {
                assert!(
                    images.visibility == lists.visibility,
                    "{name}: visibility differs from the lists'"
                );
                assert!(
                    images.blocker_distance == lists.blocker_distance,
                    "{name}: blocker distances differ from the lists'"
                );
            }
        }
    }
    assert_no_validation_errors(&device);
}

/// Area shadows of a sun of `radius` with `samples` samples through `map`, with the bundles' walk budget
/// `bundle_walk_budget`, without antialiasing.
fn area_config(
    map: PrimitiveMapConfig,
    radius: f32,
    samples: u32,
    bundle_walk_budget: u32,
) -> ShadowConfig {
    ShadowConfig {
        mode: ShadowMode::Area,
        antialiasing: false,
        map,
        pcss: PcssConfig {
            angular_radius: radius,
            ..PcssConfig::default()
        },
        area: AreaConfig {
            samples,
            bundle_walk_budget,
        },
        ..ShadowConfig::default()
    }
}

#[test]
fn area_shadows_through_the_bvh_equal_the_lists_bit_for_bit() {
    let device = device();
    let view = plate_and_box_view(96, 72);
    let rs = RefScene::new(&view.scene);
    let map = PrimitiveMapConfig {
        size: 128,
        binning: BinningRequest::Compute,
        ..PrimitiveMapConfig::default()
    };
    // 64 samples: masks of two words, against the lists bit for bit.
    // (Finer samples leave fewer pixels stable against the reference: 36 penumbra pixels at 64.)
    // Each route walks the BVH with the whole bundle of a pixel's segments, then with each sample's own;
    // a sun of 0.09 rad, never wide, also with the default budget (the trace's variant without the
    // samples' own walks).
    let walks = [
        ("bundle", u32::MAX),
        ("each sample", 0),
        ("default", DEFAULT_BUNDLE_WALK_BUDGET),
    ];
    for (radius, samples, min_penumbra) in [(0.1, 32, 50), (0.1, 64, 30), (0.09, 64, 25)] {
        let mut first: Option<Vec<f32>> = None;
        for (name, map) in routes(map) {
            for (walk, bundle_walk_budget) in walks {
                let config = area_config(map, radius, samples, bundle_walk_budget);
                let (report, images) = render_with(&device, &view, config);
                assert_route(name, &report);
                let st = report.stats;
                let per_sample = st.pixels_walked_per_sample;
                match (walk, st.pixels_walked) {
                    ("bundle", _) | (_, 0) => assert_eq!(per_sample, 0, "{name}, {walk}: {st:?}"),
                    // Only a sun past WIDE_BUNDLE may give up its bundle.
                    ("default", _) => assert!(
                        radius > WIDE_BUNDLE || per_sample == 0,
                        "{name}, {walk}: {st:?}"
                    ),
                    _ => assert!(
                        per_sample > 0 && per_sample <= st.pixels_walked,
                        "{name}, {walk}: {st:?}"
                    ),
                }
                let c = compare_area(&rs, &view, radius, samples, &images.output);
                println!("{name}, {walk}, {radius} rad, {samples} samples: {c:?}, {st:?}");
                assert_exact_area(name, &c, min_penumbra, 25);
                match &first {
                    None => first = Some(images.output),
                    Some(lists) => assert!(
                        &images.output == lists,
                        "{name}, {walk}, {radius} rad, {samples} samples: area counts differ from the lists'"
                    ),
                }
            }
        }
    }
    assert_no_validation_errors(&device);
}

/// A tile of pixels most of whose bundles gave up in the last frame skips them (the tile history,
/// `passes::ray_trace::TILE_SKIP_FRAMES`): its pixels walk each sample at once, and the counts stay those
/// of the lists and the reference. A tile skips 9 to 16 frames, by tile, then tries its bundles again for a
/// frame: the skipping pixels dip in frames 10 to 17, never all at once, and are back in frame 18. A spot
/// light given to the same pipeline next clears the history: its first frame skips nothing, its second
/// skips where its own bundles gave up, and both count as its lists do.
#[test]
fn area_tiles_whose_bundles_gave_up_skip_them_with_the_same_counts() {
    let device = device();
    let view = plate_and_box_view(96, 72);
    let rs = RefScene::new(&view.scene);
    let (radius, samples) = (0.15, 64);
    let config = |map, budget| ShadowConfig {
        pcss: PcssConfig {
            // The spot light's emitter, a quarter of its distance to the plate: its bundles are wide.
            spot_radius: 1.0,
            ..area_config(map, radius, samples, budget).pcss
        },
        ..area_config(map, radius, samples, budget)
    };
    let [(_, lists), (_, bvh), _] = routes(PrimitiveMapConfig {
        size: 128,
        binning: BinningRequest::Compute,
        ..PrimitiveMapConfig::default()
    });
    let (_, listed) = render_with(&device, &view, config(lists, DEFAULT_BUNDLE_WALK_BUDGET));
    // Every pixel walks the BVH, and a bundle gives up after a few steps: the second frame skips.
    let mut r = ShadowRenderer::new(&device, &view, config(bvh, 1)).expect("renderer");
    let mut skipping = Vec::new();
    for frame in 0..19 {
        let st = r
            .render(&device, &view.frame_inputs())
            .expect("render")
            .stats;
        let images = r.read_back(&device, false).expect("read back");
        let c = compare_area(&rs, &view, radius, samples, &images.output);
        println!("frame {frame}: {c:?}, {st:?}");
        assert_exact_area("tile history", &c, 30, 25);
        assert_eq!(st.walks_unfinished, 0, "frame {frame}: {st:?}");
        assert!(
            st.pixels_walked_per_sample > 0
                && st.pixels_skipping_bundle <= st.pixels_walked_per_sample,
            "frame {frame}: {st:?}"
        );
        assert!(
            images.output == listed.output,
            "frame {frame}: the counts differ from the lists'"
        );
        skipping.push(st.pixels_skipping_bundle);
    }
    let all = skipping[1];
    assert!(skipping[0] == 0 && all > 0, "{skipping:?}");
    assert!(skipping[1..=9].iter().all(|&s| s == all), "{skipping:?}");
    assert!(
        skipping[10..=17].iter().all(|&s| s > 0) && skipping[10..=17].iter().any(|&s| s < all),
        "{skipping:?}"
    );
    assert_eq!(skipping[18], all, "{skipping:?}");
    let mut spot_inputs = view.frame_inputs();
    spot_inputs.light =
        passes::spot_light_frusta(Vec3::new(0.0, 4.0, 0.4), Vec3::NEG_Y, 0.8, None)[0];
    let mut spot_lists =
        ShadowRenderer::new(&device, &view, config(lists, DEFAULT_BUNDLE_WALK_BUDGET))
            .expect("renderer");
    spot_lists.render(&device, &spot_inputs).expect("render");
    let spot_listed = spot_lists.read_back(&device, false).expect("read back");
    let mut spot_skipping = Vec::new();
    for frame in 0..2 {
        let st = r.render(&device, &spot_inputs).expect("render").stats;
        println!("spot frame {frame}: {st:?}");
        assert!(
            st.pixels_walked_per_sample > 0,
            "spot frame {frame}: {st:?}"
        );
        let images = r.read_back(&device, false).expect("read back");
        assert!(
            images.output == spot_listed.output,
            "spot frame {frame}: the counts differ from the lists'"
        );
        spot_skipping.push(st.pixels_skipping_bundle);
    }
    assert!(
        spot_skipping[0] == 0 && spot_skipping[1] > 0,
        "the sun's tile history was not cleared: {spot_skipping:?}"
    );
    assert_no_validation_errors(&device);
}
