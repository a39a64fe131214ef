//! Soft shadows and the hybrid on lavapipe: the blend against its formula (ray-traced at contact, PCSS far
//! from the blocker), containment of the shrinking PCSS in the ray-traced shadow, FXAA confined to
//! ray-traced edges, the frame plan's culling and caching on a GPU, spot lights against the exact
//! reference, and a FLIP-compared golden image.

mod common;

use common::{
    absolute_tolerance, assert_no_validation_errors, device, plate_and_box_view,
    tolerance_per_distance,
};
use demo_engine::{FrameImages, View};
use glam::{Mat4, Vec3};
use hrts_lab::frames::ViewInputs;
use passes::hybrid::{blend, lerp_factor};
use passes::{
    BinningRequest, FrameReport, HybridConfig, Light, PassId, PassStatus, PcssConfig,
    PenumbraFilter, PrimitiveMapConfig, ResourceId, ResourceSet, ShadowConfig, ShadowMapConfig,
    ShadowMode, SkipReason,
};
use reference::{reference_visibility, PixelClass, RefScene, VisibilityParams};
use rhi::Device;
use scene::DirectionalLight;
use std::path::PathBuf;
use test_support::ShadowRenderer;

const WSS: f32 = 1.0;
const PHS: f32 = 4.0;

fn config(mode: ShadowMode, antialiasing: bool, filter: PenumbraFilter) -> ShadowConfig {
    ShadowConfig {
        mode,
        antialiasing,
        map: PrimitiveMapConfig {
            size: 256,
            binning: BinningRequest::Software,
            ..PrimitiveMapConfig::default()
        },
        shadow_map: ShadowMapConfig {
            size: 1024,
            ..ShadowMapConfig::default()
        },
        pcss: PcssConfig {
            angular_radius: 0.08,
            filter,
            ..PcssConfig::default()
        },
        hybrid: HybridConfig {
            world_space_scale: WSS,
            hard_shadow_percentage: PHS,
        },
        extra_outputs: ResourceSet::of(&[
            ResourceId::RtVisibility,
            ResourceId::BlockerDistance,
            ResourceId::Pcss,
            ResourceId::LerpFactor,
        ]),
        ..ShadowConfig::default()
    }
}

fn render_frames(
    device: &Device,
    view: &View,
    config: ShadowConfig,
    inputs: &[passes::FrameInputs],
) -> (Vec<FrameReport>, FrameImages) {
    let mut r = ShadowRenderer::new(device, view, config).expect("renderer");
    let reports = inputs
        .iter()
        .map(|i| r.render(device, i).expect("render"))
        .collect();
    (reports, r.read_back(device, false).expect("read back"))
}

fn render_once(device: &Device, view: &View, config: ShadowConfig) -> FrameImages {
    render_frames(device, view, config, &[view.frame_inputs()]).1
}

#[test]
fn hybrid_is_ray_traced_at_contact_and_pcss_far_from_the_blocker() {
    let device = device();
    let view = plate_and_box_view(256, 176);
    let images = render_once(
        &device,
        &view,
        config(ShadowMode::Hybrid, true, PenumbraFilter::Shrinking),
    );
    let (mut far, mut contact, mut penumbra) = (0, 0, 0);
    for i in 0..images.hybrid.len() {
        let bd = images.blocker_distance[i];
        let l = lerp_factor(bd, WSS, PHS);
        assert!(
            (images.lerp_factor[i] - l).abs() <= 1e-6,
            "pixel {i}: L {} vs {l}",
            images.lerp_factor[i]
        );
        let rts = images.antialiased[i];
        let fs = images.hybrid[i];
        assert!(
            (fs - blend(rts, images.pcss[i], l)).abs() <= 1e-6,
            "pixel {i}"
        );
        assert_eq!(images.output[i], fs, "the final output is the hybrid");
        if bd >= WSS / PHS {
            // Far from the blocker L saturates: the result is exactly PCSS.
            assert_eq!(fs, images.pcss[i], "pixel {i} (BD {bd})");
            far += 1;
            if (0.05..0.95).contains(&fs) {
                penumbra += 1;
            }
        } else if bd > 0.0 && bd < 0.125 {
            // Near contact the ray-traced result dominates: |FS - RTS| <= L = BD / WSS * PHS -> 0.
            assert!((fs - rts).abs() <= l + 1e-6, "pixel {i} (BD {bd})");
            assert!(l <= 0.5);
            contact += 1;
        }
    }
    println!("far {far}, contact {contact}, soft far pixels {penumbra}");
    assert!(
        far > 300,
        "the plate's shadow should be far from its blocker"
    );
    assert!(contact > 10, "the box should have contact shadow pixels");
    assert!(penumbra > 20, "the plate's shadow should be soft");
    assert_no_validation_errors(&device);
}

#[test]
fn shrinking_pcss_stays_inside_the_ray_traced_shadow() {
    let device = device();
    for view in [
        plate_and_box_view(160, 112),
        View::framed(scene::procedural_default(), 160, 112),
    ] {
        let shrinking = render_once(
            &device,
            &view,
            config(ShadowMode::Hybrid, true, PenumbraFilter::Shrinking),
        );
        let standard = render_once(
            &device,
            &view,
            config(ShadowMode::Hybrid, true, PenumbraFilter::Standard),
        );
        let violations = |img: &FrameImages| {
            img.visibility
                .iter()
                .zip(&img.pcss)
                .filter(|(&rt, &pcss)| rt == 1.0 && pcss < 1.0)
                .count()
        };
        let shadowed = shrinking.visibility.iter().filter(|&&v| v == 0.0).count();
        let soft = shrinking
            .pcss
            .iter()
            .filter(|&&v| v > 0.0 && v < 1.0)
            .count();
        println!(
            "shadowed {shadowed}, shrinking soft {soft}, violations shrinking {} standard {}",
            violations(&shrinking),
            violations(&standard)
        );
        assert!(shadowed > 500 && soft > 50);
        assert_eq!(
            violations(&shrinking),
            0,
            "shrinking PCSS below 1 where the ray trace is lit"
        );
        // The standard filter spills half of its penumbra outside the hard shadow.
        assert!(violations(&standard) > 20);
    }
    assert_no_validation_errors(&device);
}

#[test]
fn fxaa_changes_only_pixels_near_ray_traced_edges() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 192, 128);
    let images = render_once(
        &device,
        &view,
        config(ShadowMode::Hard, true, PenumbraFilter::Shrinking),
    );
    let (w, h) = (view.width as i64, view.height as i64);
    let rt =
        |x: i64, y: i64| images.visibility[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
    let edge = |x: i64, y: i64| {
        let v = rt(x, y);
        [(1, 0), (-1, 0), (0, 1), (0, -1)]
            .iter()
            .any(|(dx, dy)| rt(x + dx, y + dy) != v)
    };
    let mut changed = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let aa = images.antialiased[i];
            assert!((0.0..=1.0).contains(&aa));
            if aa != images.visibility[i] {
                changed += 1;
                let near = (-2..=2).any(|dy| (-2..=2).any(|dx| edge(x + dx, y + dy)));
                assert!(near, "FXAA changed ({x}, {y}) far from any ray-traced edge");
            }
        }
    }
    assert_eq!(images.output, images.antialiased);
    println!("FXAA changed {changed} pixels");
    assert!(changed > 50, "FXAA should soften the ray-traced edges");
    assert_no_validation_errors(&device);
}

#[test]
fn plan_culls_by_mode_and_caches_static_light_space_passes() {
    let device = device();
    let view = plate_and_box_view(96, 64);
    let mut cfg = config(ShadowMode::Hybrid, true, PenumbraFilter::Shrinking);
    cfg.extra_outputs = ResourceSet::EMPTY;
    cfg.static_light = true;
    let first = view.frame_inputs();
    let mut moved_view = view.clone();
    moved_view.light = DirectionalLight::new(Vec3::new(-0.2, -1.0, 0.3)).expect("light");
    let moved = moved_view.frame_inputs();
    let (reports, _) = render_frames(&device, &view, cfg, &[first, first, moved]);
    let up_to_date = Some(PassStatus::Skipped(SkipReason::UpToDate));
    assert!(reports[0].ran(PassId::PrimBuffer));
    assert!(reports[0].ran(PassId::ShadowMap));
    assert_eq!(reports[1].status(PassId::ShadowMap), up_to_date);
    assert!(reports[2].ran(PassId::ShadowMap), "after the light moved");
    // The primitive map is fitted to the receivers the depth buffer shows: rebuilt every frame.
    for r in &reports {
        assert!(r.ran(PassId::PrimitiveMap) && r.ran(PassId::RayTrace));
    }
    assert_eq!(reports[1].status(PassId::PrimBuffer), up_to_date);
    assert_eq!(reports[2].status(PassId::PrimBuffer), up_to_date);
    for r in &reports {
        for p in [PassId::RayTrace, PassId::Pcss, PassId::Fxaa, PassId::Blend] {
            assert!(r.ran(p), "{p:?}");
        }
        assert_eq!(
            r.status(PassId::ShadowMapTest),
            Some(PassStatus::Skipped(SkipReason::NotRequested))
        );
        // Skipped passes are not timed.
        assert!(!r.timings.iter().any(|t| t.name == "shadow map test"));
    }
    assert!(!reports[1].timings.iter().any(|t| t.name == "shadow map"));
    // The cached maps still give the frame-one result: rendering frame two alone from scratch matches.
    let (_, cached) = render_frames(&device, &view, cfg, &[first, first]);
    let fresh = render_once(&device, &view, cfg);
    assert_eq!(cached.output, fresh.output);

    // Soft shadows never allocate the primitive map; hard shadows never the shadow map.
    let soft = ShadowConfig {
        mode: ShadowMode::Soft,
        extra_outputs: ResourceSet::EMPTY,
        ..cfg
    };
    let (reports, images) = render_frames(&device, &view, soft, &[first]);
    let has = |r: &FrameReport, res| r.resources.iter().any(|x| x.resource == res);
    assert!(!has(&reports[0], ResourceId::PrimListEntries));
    assert!(has(&reports[0], ResourceId::ShadowMap));
    assert_eq!(reports[0].output, ResourceId::Pcss);
    assert_eq!(images.output, images.pcss);
    assert!(images.visibility.is_empty());
    let hard = ShadowConfig {
        mode: ShadowMode::Hard,
        antialiasing: false,
        extra_outputs: ResourceSet::EMPTY,
        ..cfg
    };
    let (reports, images) = render_frames(&device, &view, hard, &[first]);
    assert!(!has(&reports[0], ResourceId::ShadowMap));
    assert!(has(&reports[0], ResourceId::PrimListEntries));
    assert_eq!(images.output, images.visibility);
    let none = ShadowConfig {
        mode: ShadowMode::None,
        extra_outputs: ResourceSet::EMPTY,
        ..cfg
    };
    let (reports, images) = render_frames(&device, &view, none, &[first]);
    assert!(images.output.iter().all(|&v| v == 1.0));
    assert!(reports[0]
        .resources
        .iter()
        .all(|r| matches!(r.resource, ResourceId::Lit | ResourceId::PrimBuffer)));
    assert_no_validation_errors(&device);
}

/// A spot light 3.5 m above the scene looking down, with its perspective frustum.
fn spot_light() -> Light {
    let position = Vec3::new(0.3, 3.5, 0.4);
    let direction = Vec3::new(-0.1, -1.0, -0.05).normalize();
    let view = Mat4::look_to_rh(position, direction, Vec3::Z);
    Light::Spot {
        position,
        direction,
        view_proj: Mat4::perspective_rh(120f32.to_radians(), 1.0, 0.1, 20.0) * view,
    }
}

#[test]
fn spot_light_ray_trace_matches_the_exact_reference() {
    let device = device();
    let view = plate_and_box_view(128, 96);
    let mut inputs = view.frame_inputs();
    inputs.light = spot_light();
    let cfg = config(ShadowMode::Hybrid, false, PenumbraFilter::Shrinking);
    let (_, images) = render_frames(&device, &view, cfg, &[inputs]);
    let rs = RefScene::new(&view.scene);
    let params = VisibilityParams {
        width: view.width,
        height: view.height,
        view_proj: inputs.proj.as_dmat4() * inputs.view.as_dmat4(),
        camera_position: inputs.camera_position.as_dvec3(),
        light: reference::Light::Point {
            position: spot_light().position().unwrap_or_default().as_dvec3(),
        },
        tolerance: absolute_tolerance(&view),
        tolerance_per_distance: tolerance_per_distance(&view),
        pixel_tolerance: 1.0 / 128.0,
    };
    let r = reference_visibility(&rs, &params);
    let (mut mismatches, mut shadowed, mut ambiguous) = (0, 0, 0);
    for (i, class) in r.class.iter().enumerate() {
        let expected = match class {
            PixelClass::Ambiguous => {
                ambiguous += 1;
                continue;
            }
            PixelClass::Background | PixelClass::Lit => 1.0,
            PixelClass::Shadowed => {
                shadowed += 1;
                0.0
            }
        };
        if images.visibility[i] != expected {
            mismatches += 1;
        }
    }
    println!("spot: shadowed {shadowed}, ambiguous {ambiguous}, mismatches {mismatches}");
    assert!(shadowed > 300);
    assert_eq!(mismatches, 0);
    // PCSS and the blend handle the perspective light too: finite, in range, contained.
    for (&rt, &p) in images.visibility.iter().zip(&images.pcss) {
        assert!((0.0..=1.0).contains(&p));
        assert!(rt == 0.0 || p == 1.0);
    }
    assert!(images.pcss.iter().any(|&p| p > 0.0 && p < 1.0));
    assert_no_validation_errors(&device);
}

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("golden")
}

fn write_rgb_png(path: &std::path::Path, w: u32, h: u32, rgb: &[u8]) {
    let file = std::fs::File::create(path).expect("create png");
    let mut e = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    e.write_header()
        .and_then(|mut wr| wr.write_image_data(rgb))
        .expect("write png");
}

fn read_rgb_png(path: &std::path::Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::fs::File::open(path).expect("open golden"));
    let mut reader = decoder.read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png data");
    assert_eq!(info.color_type, png::ColorType::Rgb, "golden must be RGB8");
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// Hybrid visibility of the procedural scene against `tests/golden/hybrid_procedural.png` with FLIP.
/// A missing golden fails; `HRTS_UPDATE_GOLDEN=1` writes it. On failure the actual picture and FLIP's
/// error map are written under the target directory.
#[test]
fn hybrid_matches_the_golden_image() {
    let device = device();
    let view = View::framed(scene::procedural_default(), 192, 128);
    let images = render_once(
        &device,
        &view,
        config(ShadowMode::Hybrid, true, PenumbraFilter::Shrinking),
    );
    let actual: Vec<u8> = images
        .output
        .iter()
        .flat_map(|&v| {
            let g = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            [g, g, g]
        })
        .collect();
    let (w, h) = (view.width, view.height);
    let golden = golden_dir().join("hybrid_procedural.png");
    if std::env::var("HRTS_UPDATE_GOLDEN").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(golden_dir()).expect("golden dir");
        write_rgb_png(&golden, w, h, &actual);
    }
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("golden-failures");
    std::fs::create_dir_all(&out).expect("failure dir");
    let actual_path = out.join("hybrid_procedural.actual.png");
    assert!(
        golden.exists(),
        "golden image {} is missing (run with HRTS_UPDATE_GOLDEN=1 to create it)",
        golden.display()
    );
    let (gw, gh, expected) = read_rgb_png(&golden);
    if (gw, gh) != (w, h) {
        write_rgb_png(&actual_path, w, h, &actual);
        panic!(
            "golden is {gw}x{gh}, the frame {w}x{h}; actual written to {}",
            actual_path.display()
        );
    }
    let reference = nv_flip::FlipImageRgb8::with_data(w, h, &expected);
    let test = nv_flip::FlipImageRgb8::with_data(w, h, &actual);
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mut pool = nv_flip::FlipPool::from_image(&error);
    let mean = pool.mean();
    let p99 = pool.get_percentile(0.99, false);
    println!("FLIP mean {mean:.5}, 99th percentile {p99:.5}");
    if mean > 0.01 || p99 > 0.25 {
        write_rgb_png(&actual_path, w, h, &actual);
        let diff = error.apply_color_lut(&nv_flip::magma_lut()).to_vec();
        let diff_path = out.join("hybrid_procedural.difference.png");
        write_rgb_png(&diff_path, w, h, &diff);
        panic!(
            "FLIP mean {mean} (max 0.01) or 99th percentile {p99} (max 0.25) too high; actual: {}, \
             difference: {}",
            actual_path.display(),
            diff_path.display()
        );
    }
    assert_no_validation_errors(&device);
}

#[test]
fn render_and_compare_write_the_soft_shadow_outputs() {
    let device = device();
    let dir = std::env::temp_dir().join(format!("hrts-soft-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let view = plate_and_box_view(96, 64);
    let options = host_demo::render::RenderOptions {
        map: hrts::Config {
            map_size: 128,
            ..hrts::Config::default()
        },
        frames: 2,
        soft: host_demo::render::SoftShadowArgs {
            shadow_map_size: 512,
            ..Default::default()
        },
        occupancy_view: true,
    };
    let render_dir = dir.join("render");
    host_demo::render::render_to_folder(&device, &view, &options, &render_dir).expect("render");
    for f in [
        "shadow_map.exr",
        "pcss.exr",
        "lerp_factor.exr",
        "lerp_factor.png",
        "hybrid.exr",
        "final.exr",
        "rt_fxaa.exr",
    ] {
        let len = render_dir.join(f).metadata().map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{f} missing or empty");
    }
    let json = std::fs::read_to_string(render_dir.join("frame.json")).expect("frame.json");
    for row in [
        "\"PCSS\"",
        "\"PCSS + Ray Trace\"",
        "\"FXAA\"",
        "\"ray trace\"",
    ] {
        assert!(json.contains(row), "gpu_ms lacks {row}");
    }
    assert!(json.contains("\"total_bytes\""));
    let compare = hrts_lab::compare::CompareArgs {
        out: dir.join("compare"),
        width: 64,
        height: 40,
        camera_pos: None,
        camera_target: None,
        close_up_pos: None,
        close_up_target: None,
        frames: 1,
    };
    hrts_lab::compare::compare_to_folder(&device, &compare).expect("compare");
    for f in [
        "compare.png",
        "caption.txt",
        "shadow_map_8k.png",
        "hybrid_shrinking.png",
    ] {
        assert!(compare.out.join(f).exists(), "{f} missing");
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert_no_validation_errors(&device);
}
