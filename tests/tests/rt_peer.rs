//! The ray-tracing-pipeline peer (`hrts_lab::peer`) traces the primitive-map ray trace's shadow rays
//! through acceleration structures the driver builds and the GPU's ray-tracing pipeline. Its visibility
//! equals the exact f64 reference on every pixel whose exact shadow ray does not pass within a tiny
//! tolerance of a triangle edge; those near-edge pixels are counted and bounded.
//!
//! A device without ray tracing (Mesa before 24.1, e.g. Debian 12's 22.3 lavapipe) fails the test with
//! what to install: it never passes without testing.

mod common;

use common::*;
use demo_engine::plugin::PluginRenderer;
use demo_engine::{FrameImages, View};
use hrts_lab::peer::{run_area_peer, run_peer};
use passes::{AreaConfig, PassError, PcssConfig, PrimitiveMapConfig, ShadowConfig, ShadowMode};
use reference::RefScene;
use rhi::Device;

/// Fails the test: the device cannot run the peer.
fn not_run(device: &Device, why: &str) -> ! {
    let caps = device.capabilities();
    panic!(
        "the peer needs ray tracing: {why}; device '{}' ({}); on Debian 12, scripts/setup.sh installs \
         Mesa 25's lavapipe, which has ray tracing, from bookworm-backports",
        caps.device_name, caps.driver
    );
}

fn check(view: &View, max_near_edge_fraction: f64) {
    let device = device();
    let config = hrts::Config {
        mode: hrts::ShadowMode::Hard,
        antialiasing: false,
        map_size: 256,
        ..hrts::Config::default()
    };
    let mut renderer = PluginRenderer::new(&device, view, config).expect("renderer");
    let inputs = view.frame_inputs();
    renderer.render(&device, &inputs).expect("render");
    let peer = match run_peer(&device, &renderer, &view.scene, &inputs, 3) {
        Ok(peer) => peer,
        Err(e) => match e.downcast_ref::<PassError>() {
            Some(PassError::Unsupported(why)) => not_run(&device, why),
            _ => panic!("the peer failed: {e:#}"),
        },
    };
    let ours = renderer.read_back(&device, false).expect("read back");
    let pixels = peer.visibility.len();
    assert_eq!(pixels, (view.width * view.height) as usize);
    // The peer has no blocker distance: only visibility is compared.
    let images = FrameImages {
        visibility: peer.visibility.clone(),
        blocker_distance: vec![0.0; pixels],
        ..FrameImages::default()
    };
    let rs = RefScene::new(&view.scene);
    let c = compare_visibility(&rs, view, &images);
    let differ_from_ours = (0..pixels)
        .filter(|&i| !c.near_edge_mask[i] && peer.visibility[i] != ours.visibility[i])
        .count();
    println!(
        "{}x{}, {} triangles: {} pixels, {} near-edge (not compared), {} mismatches, {} shadowed, \
         {} non-finite; {differ_from_ours} outside near-edge differ from the primitive-map trace; \
         build {:.3} ms, trace {:.3} ms ({})",
        view.width,
        view.height,
        view.scene.triangle_count(),
        c.pixels,
        c.near_edge,
        c.mismatches,
        c.shadowed,
        c.non_finite,
        peer.build_ms,
        peer.trace_ms,
        device.capabilities().driver
    );
    assert_exact_visibility(&c, max_near_edge_fraction);
    // Both traces are exact, so they agree wherever the reference decides (timings are the benchmark's).
    assert_eq!(
        differ_from_ours, 0,
        "the peer and the primitive-map trace disagree outside near-edge pixels"
    );
    assert_no_validation_errors(&device);
}

#[test]
fn procedural_scene_matches_exact_visibility() {
    let view = View::framed(scene::procedural_default(), 240, 160);
    check(&view, 0.02);
}

/// At 200x160 the bunny's 69K triangles are about a pixel across, so the near-edge band covers several
/// percent of its surface: those pixels are counted, not compared.
#[test]
fn stanford_bunny_matches_exact_visibility() {
    let bunny = scene::load_obj(&model("02_stanford_bunny_69k.obj")).expect("bunny loads");
    let view = View::framed(bunny.with_ground_plane(), 200, 160);
    check(&view, 0.10);
}

/// Area shadows: the peer traces each of the area trace's light samples of a pixel as its own any-hit ray.
/// Equal samples give equal answers: on every pixel the exact reference of the same samples calls stable,
/// the peer's visible count equals the plugin's (and the reference's), whether the plugin walked its lists
/// or the BVH.
#[test]
fn area_peer_counts_equal_the_plugins_on_stable_pixels() {
    let device = device();
    let view = plate_and_box_view(96, 72);
    let (radius, samples) = (0.1, 32);
    let rs = RefScene::new(&view.scene);
    let inputs = view.frame_inputs();
    let directions: Vec<glam::DVec3> =
        passes::area::area_sample_directions(view.light.direction, radius, samples)
            .iter()
            .map(|w| w.as_dvec3())
            .collect();
    let r = reference::area_reference(&rs, &visibility_params(&view), &directions);
    for bin_budget in [passes::primitive_map::DEFAULT_BIN_BUDGET, 0.0] {
        let config = ShadowConfig {
            mode: ShadowMode::Area,
            antialiasing: false,
            map: PrimitiveMapConfig {
                size: 128,
                bin_budget,
                ..PrimitiveMapConfig::default()
            },
            pcss: PcssConfig {
                angular_radius: radius,
                ..PcssConfig::default()
            },
            area: AreaConfig {
                samples,
                ..AreaConfig::default()
            },
            ..ShadowConfig::default()
        };
        let config = hrts::passes_bridge::config(&config).expect("a configuration of the C ABI");
        let mut renderer = PluginRenderer::new(&device, &view, config).expect("renderer");
        renderer.render(&device, &inputs).expect("render");
        let ours = renderer
            .read_back(&device, false)
            .expect("read back")
            .output;
        let peer = match run_area_peer(&device, &renderer, &view.scene, &inputs, radius, samples, 3)
        {
            Ok(peer) => peer,
            Err(e) => match e.downcast_ref::<PassError>() {
                Some(PassError::Unsupported(why)) => not_run(&device, why),
                _ => panic!("the peer failed: {e:#}"),
            },
        };
        let c = compare_area_counts(&r, &peer.visibility, None);
        let differ = (0..ours.len())
            .filter(|&i| r.stable[i] && ours[i] != peer.visibility[i])
            .count();
        println!(
            "bin budget {bin_budget}: {} px, {} unstable, {} penumbra, {} mismatches against the \
             reference, {differ} stable pixels differ from the plugin; trace {:.3} ms",
            c.pixels, c.unstable, c.penumbra, c.mismatches, peer.trace_ms
        );
        assert_exact_area("area peer", &c, 50, 25);
        assert_eq!(
            differ, 0,
            "the peer's counts differ from the plugin's on stable pixels"
        );
    }
    assert_no_validation_errors(&device);
}
