//! The wgpu renderer's shadows on lavapipe, with validation on: the same visibility as host_demo's on the
//! same scene and light, under every convention the renderer may pick, and with instances that move, all
//! against the exact CPU reference (mismatches as counts).

use demo_engine::View;
use glam::{Mat4, Vec3};
use hrts::{FrameReport, ShadowMode};
use hrts_lab::accuracy::{compare_with_reference, scene_visibility_params};
use hrts_lab::frames::ViewInputs;
use passes::PrimitiveMapConfig;
use reference::{reference_visibility, Light, PixelClass, RefScene, VisibilityReference};
use scene::{Camera, DirectionalLight, Scene};
use test_support::ShadowRenderer;
use wgpu::TextureFormat as F;
use wgpu_host::meshes::world_scene;
use wgpu_host::{validation, Conventions, DepthDirection, Gpu, IndexType, NormalTarget, Renderer};

const WIDTH: u32 = 192;
const HEIGHT: u32 = 108;

fn gpu() -> Gpu {
    validation::install();
    assert!(
        validation::layer_installed(),
        "the wgpu host's tests need the Khronos validation layer (scripts/setup.sh installs it)"
    );
    Gpu::new(true).unwrap_or_else(|e| {
        panic!("GPU tests need a Vulkan device with validation layers (scripts/setup.sh installs lavapipe): {e:#}")
    })
}

fn assert_validation_silent() {
    let errors = validation::errors();
    assert!(errors.is_empty(), "validation errors: {errors:#?}");
}

/// The built-in scene framed as host_demo frames it.
fn host_demo_view() -> View {
    View::framed(scene::procedural_default(), WIDTH, HEIGHT)
}

/// The exact reference of `scene` through `camera`, its tolerance widened by `depth_error` (world units):
/// the distance by which the depth format may move a receiver along its camera ray.
fn reference(
    scene: &Scene,
    camera: &Camera,
    light: &DirectionalLight,
    depth_error: f64,
) -> VisibilityReference {
    let mut params = scene_visibility_params(
        scene,
        camera,
        WIDTH,
        HEIGHT,
        Light::Directional {
            direction: light.direction.as_dvec3(),
        },
    );
    params.tolerance = params.tolerance.max(depth_error);
    reference_visibility(&RefScene::new(scene), &params)
}

/// How far the depth image's precision moves the farthest receiver along its ray. A step of a depth value at
/// view distance z is `quantum · z² / near` for every projection here (reversed or not, finite far plane
/// or not), with a quantum of 2^-16 for D16 and 2^-24 for 24-bit and float depth near 1; a view-Z image
/// holds z within its relative precision (2^-23 for R32Float, 2^-10 for R16Float).
fn depth_error(conventions: &Conventions, scene: &Scene, camera: &Camera) -> f64 {
    let far = scene
        .bounds()
        .corners()
        .iter()
        .map(|c| f64::from(c.distance(camera.position)))
        .fold(0.0, f64::max);
    match conventions.view_z {
        Some(F::R16Float) => 2.0 * 2f64.powi(-10) * far,
        Some(_) => 2.0 * 2f64.powi(-23) * far,
        None => {
            let quantum = match conventions.depth_format {
                F::Depth16Unorm => 2f64.powi(-16),
                _ => 2f64.powi(-24),
            };
            2.0 * quantum * far * far / f64::from(camera.near)
        }
    }
}

/// The instances' transforms for the second frame of a render, from the renderer's meshes.
type MoveInstances<'a> = &'a dyn Fn(&Renderer) -> Vec<Mat4>;

fn stable(class: PixelClass) -> bool {
    class != PixelClass::Ambiguous
}

/// Renders the built-in scene with `conventions` in hard mode; returns the visibility and the scene the
/// renderer drew (its meshes' world positions as the GPU computes them).
fn render(
    gpu: &Gpu,
    conventions: Conventions,
    view: &View,
    transforms: Option<MoveInstances<'_>>,
) -> (Vec<f32>, Scene, FrameReport) {
    let mut r = Renderer::new(
        gpu,
        &view.scene,
        conventions,
        WIDTH,
        HEIGHT,
        ShadowMode::Hard,
    )
    .expect("renderer");
    let rest: Vec<Mat4> = r.meshes().iter().map(|m| m.rest).collect();
    let mut drawn = rest.clone();
    if let Some(moved) = transforms {
        r.render(gpu, &view.camera, &view.light)
            .expect("first frame");
        drawn = moved(&r);
        r.move_instances(&drawn).expect("move");
    }
    let frame = r.render(gpu, &view.camera, &view.light).expect("frame");
    let meshes: Vec<_> = r.meshes().into_iter().cloned().collect();
    (frame.visibility, world_scene(&meshes, &drawn), frame.report)
}

#[test]
fn same_visibility_as_host_demo() {
    let gpu = gpu();
    let view = host_demo_view();
    let (wgpu_vis, drawn, report) = render(
        &gpu,
        Conventions {
            shadow_format: F::R32Float,
            ..Conventions::default()
        },
        &view,
        None,
    );
    let wgpu_ref = reference(
        &drawn,
        &view.camera,
        &view.light,
        depth_error(&Conventions::default(), &drawn, &view.camera),
    );
    let c = compare_with_reference(&wgpu_ref, &wgpu_vis, None, None);
    assert_eq!(c.mismatches, 0, "wgpu_host vs reference: {:?}", c.examples);
    assert!(
        report.output_direct,
        "an R32Float shadow image with storage usage is written directly"
    );

    let device = rhi::Device::new_headless(&rhi::DeviceDesc {
        validation: true,
        ..rhi::DeviceDesc::from_env()
    })
    .expect("device");
    let mut demo =
        ShadowRenderer::new(&device, &view, PrimitiveMapConfig::default()).expect("renderer");
    demo.render(&device, &view.frame_inputs()).expect("render");
    let demo_vis = demo
        .read_back(&device, false)
        .expect("read back")
        .visibility;
    let demo_ref = reference(&view.scene, &view.camera, &view.light, 0.0);
    let d = compare_with_reference(&demo_ref, &demo_vis, None, None);
    assert_eq!(d.mismatches, 0, "host_demo vs reference: {:?}", d.examples);

    let mut compared = 0;
    let mut differing = Vec::new();
    for i in 0..wgpu_vis.len() {
        if stable(wgpu_ref.class[i]) && stable(demo_ref.class[i]) {
            compared += 1;
            if wgpu_vis[i] != demo_vis[i] {
                differing.push((i as u32 % WIDTH, i as u32 / WIDTH));
            }
        }
    }
    println!(
        "wgpu_host vs host_demo: {compared} stable pixels compared, {} differ",
        differing.len()
    );
    assert!(
        compared > wgpu_vis.len() * 9 / 10,
        "only {compared} stable pixels"
    );
    assert!(
        differing.is_empty(),
        "differing pixels: {:?}",
        &differing[..differing.len().min(8)]
    );
    assert_eq!(
        device.validation().errors(),
        0,
        "{:#?}",
        device.validation().messages()
    );
    assert_validation_silent();
}

#[test]
fn every_convention_gives_the_same_visibility() {
    let gpu = gpu();
    let view = host_demo_view();
    let mut depth_formats = vec![
        F::Depth32Float,
        F::Depth24Plus,
        F::Depth24PlusStencil8,
        F::Depth16Unorm,
    ];
    if gpu
        .device
        .features()
        .contains(wgpu::Features::DEPTH32FLOAT_STENCIL8)
    {
        depth_formats.push(F::Depth32FloatStencil8);
    }
    let shadow_formats = [F::R8Unorm, F::R16Float, F::R32Float];
    let mut baseline: Option<(Vec<f32>, VisibilityReference)> = None;
    let mut combinations = Vec::new();
    for &depth_format in &depth_formats {
        for depth in DepthDirection::ALL {
            for normals in NormalTarget::ALL {
                for index in [IndexType::U16, IndexType::U32] {
                    combinations.push(Conventions {
                        depth_format,
                        depth,
                        normals,
                        index,
                        shadow_format: shadow_formats[combinations.len() % shadow_formats.len()],
                        view_z: None,
                    });
                }
            }
        }
    }
    // Linear view Z instead of the depth buffer.
    for view_z in [F::R32Float, F::R16Float] {
        for depth in [
            DepthDirection::ReversedInfinite,
            DepthDirection::ForwardFinite,
        ] {
            for normals in NormalTarget::ALL {
                combinations.push(Conventions {
                    depth,
                    normals,
                    view_z: Some(view_z),
                    ..Conventions::default()
                });
            }
        }
    }
    let n = combinations.len();
    for conventions in combinations {
        let (vis, drawn, _) = render(&gpu, conventions, &view, None);
        let r = reference(
            &drawn,
            &view.camera,
            &view.light,
            depth_error(&conventions, &drawn, &view.camera),
        );
        let c = compare_with_reference(&r, &vis, None, None);
        let (base_vis, base_ref) = baseline.get_or_insert_with(|| (vis.clone(), r.clone()));
        let mut compared = 0;
        let mut differing = 0;
        for i in 0..vis.len() {
            if stable(r.class[i]) && stable(base_ref.class[i]) {
                compared += 1;
                differing += usize::from(vis[i] != base_vis[i]);
            }
        }
        println!("{conventions:?}: {} mismatches against the reference ({} near an edge), {differing} of {compared} stable pixels differ from the first", c.mismatches, c.near_edge);
        assert_eq!(
            c.mismatches, 0,
            "{conventions:?} vs reference: {:?}",
            c.examples
        );
        assert_eq!(
            differing, 0,
            "{conventions:?} differs from {:?}",
            depth_formats[0]
        );
        assert!(
            compared > vis.len() / 2,
            "{conventions:?}: only {compared} stable pixels"
        );
    }
    println!("{n} combinations");
    assert_validation_silent();
}

#[test]
fn moving_instances_move_their_shadows() {
    let gpu = gpu();
    let view = host_demo_view();
    let shift = Vec3::new(-0.6, 0.0, 0.3);
    let move_sphere = |r: &Renderer| -> Vec<Mat4> {
        r.meshes()
            .iter()
            .map(|m| {
                if m.name == "sphere" {
                    Mat4::from_translation(shift) * m.rest
                } else {
                    m.rest
                }
            })
            .collect()
    };
    let (still, _, _) = render(&gpu, Conventions::default(), &view, None);
    let (moved, drawn, report) = render(&gpu, Conventions::default(), &view, Some(&move_sphere));
    let r = reference(
        &drawn,
        &view.camera,
        &view.light,
        depth_error(&Conventions::default(), &drawn, &view.camera),
    );
    let c = compare_with_reference(&r, &moved, None, None);
    assert_eq!(
        c.mismatches, 0,
        "moved scene vs reference: {:?}",
        c.examples
    );
    let sphere = view
        .scene
        .objects
        .iter()
        .find(|o| o.name == "sphere")
        .expect("a sphere");
    println!(
        "moved the sphere: {} triangles rebuilt (the sphere has {}), {} mismatches",
        report.prim_triangles_rebuilt, sphere.triangle_count, c.mismatches
    );
    assert_eq!(
        report.prim_triangles_rebuilt, sphere.triangle_count,
        "only the moved instance is rebuilt"
    );
    let changed = still.iter().zip(&moved).filter(|(a, b)| a != b).count();
    assert!(
        changed > 50,
        "moving the sphere changed only {changed} pixels"
    );
    assert_validation_silent();
}
