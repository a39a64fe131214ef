//! Hand-checkable visibility scenes.

use glam::{DVec3, Mat4, Vec3, Vec4Swizzles};
use scene::MeshBuilder;

use super::add_heightfield;
use crate::{
    reference_visibility, Light, PixelClass, RefScene, VisibilityParams, VisibilityReference,
};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

/// Floor `[-10, 10]^2` at y = 0 (triangles 0 and 1, split along x = -z) and the box
/// `[-1, 1] x [1, 2] x [-1, 1]` floating above it (triangles 2..14).
fn box_over_plane() -> RefScene {
    let mut mesh = MeshBuilder::new();
    let corners = [(-10.0, -10.0), (10.0, -10.0), (10.0, 10.0), (-10.0, 10.0)]
        .map(|(x, z)| mesh.vertex(Vec3::new(x, 0.0, z)));
    mesh.connect_triangle([corners[0], corners[3], corners[1]]);
    mesh.connect_triangle([corners[1], corners[3], corners[2]]);
    mesh.add_box(Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 2.0, 1.0));
    RefScene::new(&mesh.into_scene("mesh"))
}

fn params(camera: Vec3, light: Light) -> VisibilityParams {
    let proj = Mat4::perspective_infinite_reverse_rh(
        60f32.to_radians(),
        WIDTH as f32 / HEIGHT as f32,
        0.1,
    );
    let view = Mat4::look_at_rh(camera, Vec3::new(0.0, 0.5, 0.0), Vec3::Y);
    VisibilityParams {
        width: WIDTH,
        height: HEIGHT,
        view_proj: proj.as_dmat4() * view.as_dmat4(),
        camera_position: camera.as_dvec3(),
        light,
        tolerance: 1e-4,
        tolerance_per_distance: 0.0,
        pixel_tolerance: 1.0 / 64.0,
    }
}

/// Index of the pixel whose centre is nearest to the projection of `p`.
fn pixel_of(params: &VisibilityParams, p: Vec3) -> usize {
    let clip = params.view_proj * p.as_dvec3().extend(1.0);
    let ndc = clip.xy() / clip.w;
    let x = ((ndc.x + 1.0) * 0.5 * f64::from(WIDTH) - 0.5).round() as usize;
    let y = ((ndc.y + 1.0) * 0.5 * f64::from(HEIGHT) - 0.5).round() as usize;
    assert!(
        x < WIDTH as usize && y < HEIGHT as usize,
        "{p} is off screen"
    );
    y * WIDTH as usize + x
}

fn oblique_light() -> Light {
    Light::Directional {
        direction: DVec3::new(1.0, -1.0, 0.0).normalize(),
    }
}

fn check_invariants(result: &VisibilityReference) {
    let count = (WIDTH * HEIGHT) as usize;
    assert_eq!(result.class.len(), count);
    assert_eq!(result.blocker_distance.len(), count);
    assert_eq!(result.position.len(), count);
    assert_eq!(result.receiver.len(), count);
    for i in 0..count {
        let has_receiver = result.receiver[i] != u32::MAX;
        assert_eq!(has_receiver, result.position[i].is_finite(), "pixel {i}");
        match result.class[i] {
            PixelClass::Background => assert!(!has_receiver),
            PixelClass::Lit => assert!(has_receiver && result.blocker_distance[i].is_nan()),
            PixelClass::Shadowed => {
                let d = result.blocker_distance[i];
                assert!(has_receiver && (d.is_nan() || d >= 0.0));
            }
            PixelClass::Ambiguous => assert!(result.blocker_distance[i].is_nan()),
        }
    }
}

#[test]
fn box_over_plane_with_directional_light() {
    let scene = box_over_plane();
    let params = params(Vec3::new(6.0, 10.0, 8.0), oblique_light());
    let result = reference_visibility(&scene, &params);
    check_invariants(&result);
    let class_at = |p: Vec3| result.class[pixel_of(&params, p)];

    // Floor far from the shadow: lit, received by a floor triangle.
    for p in [
        Vec3::new(-4.0, 0.0, 2.0),
        Vec3::new(5.0, 0.0, 3.0),
        Vec3::new(6.0, 0.0, -4.0),
    ] {
        let i = pixel_of(&params, p);
        assert_eq!(result.class[i], PixelClass::Lit, "{p}");
        assert!(result.receiver[i] < 2);
        assert!(result.position[i].y.abs() < 1e-9);
    }
    // Floor in the shadow: light enters the box through its +x face, so the nearest
    // blocker is at (x - 1) * sqrt(2) for floor points with 2 < x < 3, |z| < 1.
    for p in [
        Vec3::new(2.5, 0.0, 0.0),
        Vec3::new(2.6, 0.0, 0.5),
        Vec3::new(2.3, 0.0, -0.4),
    ] {
        let i = pixel_of(&params, p);
        assert_eq!(result.class[i], PixelClass::Shadowed, "{p}");
        let q = result.position[i];
        let expected = (q.x - 1.0) * std::f64::consts::SQRT_2;
        assert!((result.blocker_distance[i] - expected).abs() < 1e-9, "{p}");
    }
    // Box top: lit by the oblique light.
    assert_eq!(class_at(Vec3::new(0.0, 2.0, 0.0)), PixelClass::Lit);
    let top = pixel_of(&params, Vec3::new(0.0, 2.0, 0.0));
    assert!((2..14).contains(&(result.receiver[top] as usize)));
    // +x face of the box faces the camera but not the light.
    let side = pixel_of(&params, Vec3::new(1.0, 1.5, 0.0));
    assert_eq!(result.class[side], PixelClass::Shadowed);
    assert_eq!(result.blocker_distance[side], 0.0);
    // +z face is exactly parallel to the light: grazing, ambiguous.
    assert_eq!(class_at(Vec3::new(0.3, 1.5, 1.0)), PixelClass::Ambiguous);
    // Beyond the end of the floor: nothing is hit.
    for p in [Vec3::new(-15.0, 0.0, -20.0), Vec3::new(-13.0, 0.0, -22.0)] {
        let i = pixel_of(&params, p);
        assert_eq!(result.class[i], PixelClass::Background, "{p}");
        assert!(result.position[i].is_nan());
    }
    let count = |c: PixelClass| result.class.iter().filter(|k| **k == c).count();
    // Only a thin set of pixels (edges, the grazing face) is ambiguous.
    assert!(count(PixelClass::Ambiguous) < (WIDTH * HEIGHT / 10) as usize);
    assert!(count(PixelClass::Shadowed) > 100 && count(PixelClass::Lit) > 1000);
}

/// The floor and the box of [`box_over_plane`] as two objects, floor first, the box casting shadows or not.
fn floor_and_box_objects(box_casts: bool, floor_casts: bool) -> RefScene {
    let mut scene = scene::Scene::single_object(
        [(-10.0, -10.0), (10.0, -10.0), (10.0, 10.0), (-10.0, 10.0)]
            .map(|(x, z)| Vec3::new(x, 0.0, z))
            .to_vec(),
        vec![0, 3, 1, 1, 3, 2],
        "floor",
    );
    scene.append(&scene::Scene::axis_box(
        "box",
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, 2.0, 1.0),
    ));
    RefScene::with_casters(&scene, &[floor_casts, box_casts])
}

/// An object that casts no shadows is still seen and still receives them, but blocks no shadow ray: the
/// floor under a box that casts nothing is lit, and a floor that casts nothing changes nothing above it.
#[test]
fn objects_that_cast_no_shadows_only_receive() {
    let params = params(Vec3::new(6.0, 10.0, 8.0), oblique_light());
    let all = reference_visibility(&box_over_plane(), &params);
    let floor_receives_only = reference_visibility(&floor_and_box_objects(true, false), &params);
    assert_eq!(floor_receives_only.class, all.class);
    let box_receives_only = reference_visibility(&floor_and_box_objects(false, true), &params);
    check_invariants(&box_receives_only);
    for p in [
        Vec3::new(2.5, 0.0, 0.0),
        Vec3::new(2.6, 0.0, 0.5),
        Vec3::new(2.3, 0.0, -0.4),
    ] {
        let i = pixel_of(&params, p);
        assert_eq!(all.class[i], PixelClass::Shadowed, "{p}");
        assert_eq!(box_receives_only.class[i], PixelClass::Lit, "{p}");
    }
    // The box is still seen: its top is lit, its +x face (away from the light) in its own shadow.
    let top = pixel_of(&params, Vec3::new(0.0, 2.0, 0.0));
    assert!((2..14).contains(&(box_receives_only.receiver[top] as usize)));
    assert_eq!(box_receives_only.class[top], PixelClass::Lit);
    let side = pixel_of(&params, Vec3::new(1.0, 1.5, 0.0));
    assert_eq!(box_receives_only.class[side], PixelClass::Shadowed);
    let shadowed = |r: &VisibilityReference| {
        r.class
            .iter()
            .filter(|&&c| c == PixelClass::Shadowed)
            .count()
    };
    assert!(shadowed(&box_receives_only) < shadowed(&all) / 2);
}

#[test]
fn light_from_below_the_receiver_shadows_it() {
    let scene = box_over_plane();
    let light = Light::Directional {
        direction: DVec3::new(0.3, 1.0, 0.2).normalize(),
    };
    let result = reference_visibility(&scene, &params(Vec3::new(6.0, 10.0, 8.0), light));
    check_invariants(&result);
    // The floor is seen from above but lit from below: its visible side faces away
    // from the light (except for ambiguous pixels along edges).
    for (i, class) in result.class.iter().enumerate() {
        if result.receiver[i] < 2 {
            assert!(matches!(
                class,
                PixelClass::Shadowed | PixelClass::Ambiguous
            ));
            if *class == PixelClass::Shadowed {
                assert_eq!(result.blocker_distance[i], 0.0);
            }
        }
    }
}

#[test]
fn point_light_respects_light_distance() {
    let scene = box_over_plane();
    let above = Light::Point {
        position: DVec3::new(0.0, 5.0, 0.0),
    };
    let camera = Vec3::new(6.0, 10.0, 8.0);
    let params_above = params(camera, above);
    let result = reference_visibility(&scene, &params_above);
    check_invariants(&result);
    // Segment (1.5, 0, 0.2) -> light crosses x = 1 at y = 5/3: blocked by the box.
    let i = pixel_of(&params_above, Vec3::new(1.6, 0.0, 0.2));
    assert_eq!(result.class[i], PixelClass::Shadowed);
    let p = result.position[i];
    let to_light = DVec3::new(0.0, 5.0, 0.0) - p;
    let s = (p.x - 1.0) / -to_light.x; // fraction of the way to the light at x = 1
    assert!((result.blocker_distance[i] - s * to_light.length()).abs() < 1e-9);
    // Segment (3, 0, 0) -> light passes outside the box.
    assert_eq!(
        result.class[pixel_of(&params_above, Vec3::new(3.0, 0.0, 0.0))],
        PixelClass::Lit
    );

    // A light between the floor and the box: the box is beyond the light.
    let between = Light::Point {
        position: DVec3::new(0.0, 0.5, 0.0),
    };
    let params_between = params(camera, between);
    let result = reference_visibility(&scene, &params_between);
    check_invariants(&result);
    for p in [
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(1.6, 0.0, 0.2),
        Vec3::new(-3.0, 0.0, 2.0),
    ] {
        assert_eq!(
            result.class[pixel_of(&params_between, p)],
            PixelClass::Lit,
            "{p}"
        );
    }
    // The bottom of the box faces the light but is hidden from the camera; its top
    // faces away from the light.
    assert_eq!(
        result.class[pixel_of(&params_between, Vec3::new(0.0, 2.0, 0.0))],
        PixelClass::Shadowed
    );
}

#[test]
fn coplanar_duplicate_receivers_are_ambiguous() {
    let mut mesh = MeshBuilder::new();
    mesh.add_triangle([
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
    ]);
    mesh.add_triangle([
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
    ]);
    // A second copy of a patch of the floor (z-fighting).
    mesh.add_triangle([
        Vec3::new(-2.0, 0.0, -2.0),
        Vec3::new(-2.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 2.0),
    ]);
    let scene = RefScene::new(&mesh.into_scene("mesh"));
    let params = params(Vec3::new(0.0, 8.0, 6.0), oblique_light());
    let result = reference_visibility(&scene, &params);
    check_invariants(&result);
    assert_eq!(
        result.class[pixel_of(&params, Vec3::new(-1.0, 0.0, 1.5))],
        PixelClass::Ambiguous
    );
    assert_eq!(
        result.class[pixel_of(&params, Vec3::new(1.0, 0.0, -1.5))],
        PixelClass::Lit
    );
    assert_eq!(
        result.class[pixel_of(&params, Vec3::new(-5.0, 0.0, 3.0))],
        PixelClass::Lit
    );
}

#[test]
fn receivers_next_to_blocker_edges_are_ambiguous() {
    // A box standing on the floor: floor points along its base touch its edges.
    let mut mesh = MeshBuilder::new();
    add_heightfield(&mut mesh, (-10.0, -10.0), (10.0, 10.0), 1, |_, _| 0.0);
    mesh.add_box(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0));
    let scene = RefScene::new(&mesh.into_scene("mesh"));
    let params = VisibilityParams {
        tolerance: 0.05,
        tolerance_per_distance: 0.0,
        ..params(Vec3::new(6.0, 10.0, 8.0), oblique_light())
    };
    let result = reference_visibility(&scene, &params);
    check_invariants(&result);
    // Within 0.05 of the box's base edge on the floor.
    let i = pixel_of(&params, Vec3::new(1.02, 0.0, 0.3));
    assert_eq!(
        result.class[i],
        PixelClass::Ambiguous,
        "{}",
        result.position[i]
    );
    // Shadow of a standing box: x in (1, 3) for |z| < 1.
    assert_eq!(
        result.class[pixel_of(&params, Vec3::new(2.0, 0.0, 0.3))],
        PixelClass::Shadowed
    );
}

#[test]
fn camera_rays_through_edges_are_ambiguous_even_when_missing() {
    let camera = Vec3::new(0.0, 0.0, 5.0);
    let params = VisibilityParams {
        view_proj: Mat4::perspective_infinite_reverse_rh(
            60f32.to_radians(),
            WIDTH as f32 / HEIGHT as f32,
            0.1,
        )
        .as_dmat4()
            * Mat4::look_at_rh(camera, Vec3::ZERO, Vec3::Y).as_dmat4(),
        camera_position: camera.as_dvec3(),
        light: Light::Directional {
            direction: -DVec3::Z,
        },
        ..params(camera, oblique_light())
    };
    // The camera ray through the centre of pixel (80, 60), as the reference builds it.
    let inverse = params.view_proj.inverse();
    let ndc_x = (80.5 / f64::from(WIDTH)) * 2.0 - 1.0;
    let ndc_y = (60.5 / f64::from(HEIGHT)) * 2.0 - 1.0;
    let near = inverse.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
    let dir = (near - camera.as_dvec3()).normalize();
    // A triangle with an edge crossing that ray 4 units away, extending towards +y.
    let p = camera.as_dvec3() + dir * 4.0;
    let across = dir.cross(DVec3::Y).normalize();
    let up = across.cross(dir).normalize();
    let mut mesh = MeshBuilder::new();
    mesh.add_triangle([
        (p - across).as_vec3(),
        (p + across).as_vec3(),
        (p + up).as_vec3(),
    ]);
    let scene = RefScene::new(&mesh.into_scene("mesh"));
    let result = reference_visibility(&scene, &params);
    check_invariants(&result);
    let at = |x: usize, y: usize| result.class[y * WIDTH as usize + x];
    assert_eq!(at(80, 60), PixelClass::Ambiguous);
    // World up is NDC +y, i.e. larger rows (no flip).
    assert_eq!(at(80, 65), PixelClass::Lit);
    assert_eq!(at(80, 55), PixelClass::Background);
}

#[test]
fn uncertain_nearer_events_hide_the_blocker_distance() {
    let mut mesh = MeshBuilder::new();
    add_heightfield(&mut mesh, (-10.0, -10.0), (10.0, 10.0), 1, |_, _| 0.0);
    // Large roof at y = 2 (triangles 2, 3) and a smaller one at y = 1 (triangle 4)
    // whose edge x = 0.5 runs above the floor point (0.5, 0, 0.3).
    add_heightfield(&mut mesh, (-3.0, -3.0), (3.0, 3.0), 1, |_, _| 2.0);
    mesh.add_triangle([
        Vec3::new(-2.0, 1.0, -1.0),
        Vec3::new(0.5, 1.0, -1.0),
        Vec3::new(0.5, 1.0, 1.5),
    ]);
    let scene = RefScene::new(&mesh.into_scene("mesh"));
    let camera = Vec3::new(12.0, 1.5, 0.0);
    let params = VisibilityParams {
        tolerance: 0.2,
        tolerance_per_distance: 0.0,
        light: Light::Directional {
            direction: -DVec3::Y,
        },
        ..params(camera, oblique_light())
    };
    let result = reference_visibility(&scene, &params);
    check_invariants(&result);
    let under_edge = pixel_of(&params, Vec3::new(0.5, 0.0, 0.3));
    assert!(
        result.receiver[under_edge] < 2,
        "{}",
        result.position[under_edge]
    );
    assert_eq!(result.class[under_edge], PixelClass::Shadowed);
    assert!(result.blocker_distance[under_edge].is_nan());
    let under_small = pixel_of(&params, Vec3::new(-0.2, 0.0, -0.5));
    assert_eq!(result.class[under_small], PixelClass::Shadowed);
    assert!((result.blocker_distance[under_small] - 1.0).abs() < 1e-9);
    assert_eq!(
        result.class[pixel_of(&params, Vec3::new(5.0, 0.0, 0.0))],
        PixelClass::Lit
    );
}

/// The disc's axes are orthonormal and across the direction, everywhere but the pole.
#[test]
fn disc_basis_is_orthonormal_across_the_direction() {
    use crate::disc_basis;
    for n in [
        DVec3::Y,
        DVec3::X,
        DVec3::new(0.3, -0.9, 0.2),
        DVec3::new(-0.2, -0.98, 0.05),
    ] {
        let n = n.normalize();
        let (t1, t2) = disc_basis(n);
        for (a, b) in [(t1, t2), (t1, n), (t2, n)] {
            assert!(a.dot(b).abs() < 1e-12, "{n}");
        }
        assert!((t1.length() - 1.0).abs() < 1e-12 && (t2.length() - 1.0).abs() < 1e-12);
    }
    assert_eq!(disc_basis(DVec3::NEG_Y), (DVec3::X, DVec3::NEG_Z));
}

/// The progress variants call back once per row (per row of each sample for area shadows, per row for
/// soft shadows) and compute what the plain functions compute.
#[test]
fn progress_variants_count_every_row_and_agree() {
    use crate::{
        area_reference, area_reference_with_progress, reference_visibility_with_progress,
        soft_visibility, soft_visibility_with_progress, AreaLight, SoftParams,
    };
    use std::sync::atomic::{AtomicU32, Ordering};
    let scene = box_over_plane();
    let params = params(Vec3::new(6.0, 10.0, 8.0), oblique_light());
    let rows = AtomicU32::new(0);
    let count = || {
        rows.fetch_add(1, Ordering::Relaxed);
    };
    let hard = reference_visibility_with_progress(&scene, &params, &count);
    assert_eq!(rows.swap(0, Ordering::Relaxed), HEIGHT);
    let plain = reference_visibility(&scene, &params);
    assert_eq!(hard.class, plain.class);
    let bits = |v: &[f64]| v.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&hard.blocker_distance), bits(&plain.blocker_distance));

    let towards = [DVec3::new(-1.0, 1.0, 0.0), DVec3::new(-1.0, 1.2, 0.1)].map(|w| w.normalize());
    let area = area_reference_with_progress(&scene, &params, &towards, &count);
    assert_eq!(rows.swap(0, Ordering::Relaxed), HEIGHT * 2);
    assert_eq!(area, area_reference(&scene, &params, &towards));

    let light = AreaLight::Directional {
        direction: DVec3::new(1.0, -1.0, 0.0).normalize(),
        angular_radius: 0.05,
    };
    let soft_params = SoftParams {
        strata: 2,
        seed: 1,
        camera_position: params.camera_position,
    };
    let soft = soft_visibility_with_progress(&scene, &hard, &light, &soft_params, &count)
        .expect("valid light");
    assert_eq!(rows.load(Ordering::Relaxed), HEIGHT);
    let plain = soft_visibility(&scene, &hard, &light, &soft_params).expect("valid light");
    assert_eq!(bits(&soft.visibility), bits(&plain.visibility));
}
