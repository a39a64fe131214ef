//! Speed of the reference on a scene of the target size (timings are printed;
//! run with `--nocapture` to see them).

use std::time::Instant;

use glam::{DVec3, Mat4, Vec3};
use scene::MeshBuilder;

use super::add_heightfield;
use crate::{
    conservative_texel_sets, reference_visibility, FaceSelection, Light, PixelClass, RefScene,
    VisibilityParams,
};

/// About 70K triangles: a bumpy terrain, boxes and spheres.
fn big_scene() -> scene::Scene {
    let mut mesh = MeshBuilder::new();
    add_heightfield(&mut mesh, (-20.0, -20.0), (20.0, 20.0), 180, |x, z| {
        0.3 * (x * 0.7).sin() * (z * 0.5).cos()
    });
    for i in 0..6 {
        let x = -12.0 + 5.0 * i as f32;
        mesh.add_box(
            Vec3::new(x, 0.5, -2.0),
            Vec3::new(x + 2.0, 3.0 + i as f32, 1.0),
        );
        mesh.add_sphere(Vec3::new(x + 1.0, 2.5, 5.0), 1.2, 24, 32);
    }
    mesh.into_scene("mesh")
}

#[test]
fn target_size_runs_fast() {
    let scene = big_scene();
    let start = Instant::now();
    let reference = RefScene::new(&scene);
    let build = start.elapsed();
    assert!(
        reference.triangle_count() >= 70_000,
        "{}",
        reference.triangle_count()
    );

    let camera = Vec3::new(0.0, 12.0, 22.0);
    let params = VisibilityParams {
        width: 320,
        height: 240,
        view_proj: Mat4::perspective_infinite_reverse_rh(50f32.to_radians(), 320.0 / 240.0, 0.1)
            .as_dmat4()
            * Mat4::look_at_rh(camera, Vec3::ZERO, Vec3::Y).as_dmat4(),
        camera_position: camera.as_dvec3(),
        light: Light::Directional {
            direction: DVec3::new(0.4, -1.0, -0.3).normalize(),
        },
        tolerance: 1e-4,
        tolerance_per_distance: 0.0,
        pixel_tolerance: 1.0 / 64.0,
    };
    let start = Instant::now();
    let visibility = reference_visibility(&reference, &params);
    let shade = start.elapsed();
    let count = |c: PixelClass| visibility.class.iter().filter(|k| **k == c).count();
    assert!(count(PixelClass::Lit) > 10_000 && count(PixelClass::Shadowed) > 1_000);

    let light_proj = Mat4::orthographic_rh(-25.0, 25.0, -25.0, 25.0, 0.1, 100.0)
        * Mat4::look_at_rh(Vec3::new(-16.0, 40.0, 12.0), Vec3::ZERO, Vec3::Y);
    let start = Instant::now();
    let sets = conservative_texel_sets(
        &reference,
        light_proj.as_dmat4(),
        Vec3::new(0.4, -1.0, -0.3).normalize(),
        256,
        FaceSelection::Both,
    );
    let binning = start.elapsed();
    assert!(sets.triangles.len() > reference.triangle_count());

    println!(
        "{} triangles: BVH build {build:?}; visibility 320x240 {shade:?} (lit {}, shadowed {}, ambiguous {}, background {}); \
         texel sets n=256 {binning:?} ({} entries)",
        reference.triangle_count(),
        count(PixelClass::Lit),
        count(PixelClass::Shadowed),
        count(PixelClass::Ambiguous),
        count(PixelClass::Background),
        sets.triangles.len(),
    );
}
