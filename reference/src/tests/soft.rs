//! Soft-shadow ground truth against analytic penumbrae.
//!
//! The main scene is a ground quad at y = 0 and a large occluder quad at height
//! `OCCLUDER_HEIGHT` covering x < 0 (its edge is the line x = 0 at that height). The
//! camera sits between the two, at y = 0.5 above the origin, looking straight down,
//! so it sees the ground on both sides of the occluder's edge.

use std::f64::consts::{FRAC_PI_2, PI};
use std::time::Instant;

use glam::{DVec3, Mat4, Vec3};
use scene::{MeshBuilder, SplitMix64};

use super::{add_heightfield, in_cube, random_direction};
use crate::soft::{cone_may_meet_triangle, soft_visibility_with, ExactShortcuts};
use crate::{
    reference_visibility, soft_visibility, AreaLight, Light, RefScene, SoftParams, SoftReference,
    VisibilityParams, VisibilityReference,
};

const SIZE: u32 = 64;
const OCCLUDER_HEIGHT: f64 = 1.0;
const CAMERA: Vec3 = Vec3::new(0.0, 0.5, 0.0);

/// Ground `[-50, 50]²` at y = 0 (triangles 0 and 1) and, with `occluder`, the quad
/// `[-20, 0] x [-20, 20]` at y = `OCCLUDER_HEIGHT` (triangles 2 and 3).
fn ground_scene(occluder: bool) -> RefScene {
    let mut mesh = MeshBuilder::new();
    let quad = |mesh: &mut MeshBuilder, x: (f32, f32), z: (f32, f32), y: f32| {
        let c = [(x.0, z.0), (x.1, z.0), (x.1, z.1), (x.0, z.1)]
            .map(|(x, z)| mesh.vertex(Vec3::new(x, y, z)));
        mesh.connect_triangle([c[0], c[3], c[1]]);
        mesh.connect_triangle([c[1], c[3], c[2]]);
    };
    quad(&mut mesh, (-50.0, 50.0), (-50.0, 50.0), 0.0);
    if occluder {
        quad(
            &mut mesh,
            (-20.0, 0.0),
            (-20.0, 20.0),
            OCCLUDER_HEIGHT as f32,
        );
    }
    RefScene::new(&mesh.into_scene("mesh"))
}

/// Hard reference from `CAMERA` looking straight down (90° field of view), so the
/// ground in `[-0.5, 0.5]²` fills the image.
fn hard_reference(scene: &RefScene) -> VisibilityReference {
    let proj = Mat4::perspective_infinite_reverse_rh(FRAC_PI_2 as f32, 1.0, 0.1);
    let view = Mat4::look_at_rh(CAMERA, CAMERA - Vec3::Y, Vec3::NEG_Z);
    let params = VisibilityParams {
        width: SIZE,
        height: SIZE,
        view_proj: proj.as_dmat4() * view.as_dmat4(),
        camera_position: CAMERA.as_dvec3(),
        light: Light::Directional {
            direction: DVec3::NEG_Y,
        },
        tolerance: 1e-6,
        tolerance_per_distance: 0.0,
        pixel_tolerance: 1.0 / 64.0,
    };
    let hard = reference_visibility(scene, &params);
    assert!(hard.position.iter().all(|p| p.is_finite()));
    hard
}

fn soft_params(strata: u32) -> SoftParams {
    SoftParams {
        camera_position: CAMERA.as_dvec3(),
        strata,
        seed: 0x5eed,
    }
}

fn soft(
    scene: &RefScene,
    hard: &VisibilityReference,
    light: AreaLight,
    strata: u32,
) -> SoftReference {
    let start = Instant::now();
    let result = soft_visibility(scene, hard, &light, &soft_params(strata)).expect("valid light");
    println!(
        "{strata}x{strata} strata: {:?} ({} exact, {} sampled)",
        start.elapsed(),
        result.exact_pixels,
        result.sampled_pixels
    );
    result
}

/// Fraction of a spherical cap of half-angle `radius` lying on the positive side of
/// a great circle (a plane through the cap's apex) at signed angular distance
/// `alpha` from the cap's centre (positive: centre on the positive side).
///
/// On the ring at polar angle θ a direction is on the negative side when
/// `cos θ sin α + sin θ cos α cos φ < 0`, i.e. `cos φ < -tan α / tan θ`; the rings
/// are integrated uniformly in `1 - cos θ` (uniform in solid angle) by the midpoint
/// rule.
fn cap_fraction_above_great_circle(alpha: f64, radius: f64) -> f64 {
    const STEPS: usize = 4_000;
    let h = 1.0 - radius.cos();
    let blocked: f64 = (0..STEPS)
        .map(|k| {
            let theta = (1.0 - h * (k as f64 + 0.5) / STEPS as f64).acos();
            let limit = -alpha.tan() / theta.tan();
            if limit >= 1.0 {
                1.0
            } else if limit <= -1.0 {
                0.0
            } else {
                1.0 - limit.acos() / PI
            }
        })
        .sum();
    1.0 - blocked / STEPS as f64
}

/// Fraction of a disk of unit radius on the side `x > t` of a chord (clamped).
fn disk_fraction_beyond(t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    (t.acos() - t * (1.0 - t * t).sqrt()) / PI
}

/// Signed angle of the straight-down light's axis (+y) from the plane through `p`
/// and the occluder's edge (positive: `p` is outside the occluder's shadow).
fn edge_angle(p: DVec3) -> f64 {
    p.x.atan2(OCCLUDER_HEIGHT - p.y)
}

const CAP_RADIUS: f64 = 0.1;

fn straight_down_cap() -> AreaLight {
    AreaLight::Directional {
        direction: DVec3::NEG_Y,
        angular_radius: CAP_RADIUS,
    }
}

fn check_shape(result: &SoftReference, hard: &VisibilityReference) {
    let count = (SIZE * SIZE) as usize;
    assert_eq!(result.visibility.len(), count);
    assert_eq!(result.exact.len(), count);
    let receivers = hard.receiver.iter().filter(|r| **r != u32::MAX).count();
    assert_eq!(result.exact_pixels + result.sampled_pixels, receivers);
    assert_eq!(
        result.exact.iter().filter(|e| **e).count(),
        result.exact_pixels
    );
    assert_eq!(
        result.standard_error_bound,
        0.5 / f64::from(result.samples).sqrt()
    );
    for (v, p) in result.visibility.iter().zip(&hard.position) {
        assert_eq!(v.is_nan(), p.is_nan());
        assert!(v.is_nan() || (0.0..=1.0).contains(v));
    }
}

#[test]
fn directional_penumbra_matches_half_plane_occluder() {
    let scene = ground_scene(true);
    let hard = hard_reference(&scene);
    let result = soft(&scene, &hard, straight_down_cap(), 16);
    check_shape(&result, &hard);
    assert_eq!(result.samples, 256);
    let tolerance = 4.0 * result.standard_error_bound;
    let (mut lit, mut umbra, mut penumbra) = (0, 0, 0);
    let mut worst: f64 = 0.0;
    for (i, p) in hard.position.iter().enumerate() {
        let alpha = edge_angle(*p);
        let value = result.visibility[i];
        if alpha > CAP_RADIUS + 0.01 {
            // Far from the occluder's shadow: provably lit, not sampled.
            assert_eq!(value, 1.0, "pixel {i} at {p}");
            assert!(result.exact[i], "pixel {i} at {p}");
            lit += 1;
        } else if alpha < -CAP_RADIUS - 0.01 {
            // Under the occluder: every sample blocked.
            assert_eq!(value, 0.0, "pixel {i} at {p}");
            assert!(!result.exact[i]);
            umbra += 1;
        } else if alpha.abs() < CAP_RADIUS {
            let expected = cap_fraction_above_great_circle(alpha, CAP_RADIUS);
            let error = (value - expected).abs();
            worst = worst.max(error);
            assert!(
                error <= tolerance,
                "pixel {i} at {p}: {value} vs analytic {expected}"
            );
            penumbra += 1;
        }
    }
    println!("lit {lit}, umbra {umbra}, penumbra {penumbra}; worst error {worst:.4} (4 sigma bound {tolerance:.4})");
    assert!(lit > 1000 && umbra > 1000 && penumbra > 500);
    assert!(result.exact_pixels >= lit);
}

#[test]
fn directional_estimates_converge_with_strata() {
    let scene = ground_scene(true);
    let hard = hard_reference(&scene);
    let coarse = soft(&scene, &hard, straight_down_cap(), 8);
    let fine = soft(&scene, &hard, straight_down_cap(), 32);
    let penumbra: Vec<usize> = (0..hard.position.len())
        .filter(|&i| edge_angle(hard.position[i]).abs() < CAP_RADIUS)
        .collect();
    assert!(penumbra.len() > 500);
    let mean = |f: &dyn Fn(usize) -> f64| {
        penumbra.iter().map(|&i| f(i)).sum::<f64>() / penumbra.len() as f64
    };
    let analytic: Vec<f64> = hard
        .position
        .iter()
        .map(|p| {
            let alpha = edge_angle(*p);
            if alpha.abs() < CAP_RADIUS {
                cap_fraction_above_great_circle(alpha, CAP_RADIUS)
            } else {
                f64::NAN
            }
        })
        .collect();
    let between = mean(&|i| (coarse.visibility[i] - fine.visibility[i]).abs());
    let coarse_error = mean(&|i| (coarse.visibility[i] - analytic[i]).abs());
    let fine_error = mean(&|i| (fine.visibility[i] - analytic[i]).abs());
    println!(
        "mean |8x8 - 32x32| {between:.5}; mean error 8x8 {coarse_error:.5}, 32x32 {fine_error:.5}; \
         bounds {:.5} and {:.5}",
        coarse.standard_error_bound, fine.standard_error_bound
    );
    assert!(between < 3.0 * coarse.standard_error_bound);
    assert!(fine_error < coarse_error);
    assert!(fine_error < fine.standard_error_bound);

    // Deterministic in the seed; another seed changes the penumbra only.
    let again = soft(&scene, &hard, straight_down_cap(), 8);
    assert_eq!(again, coarse);
    let params = SoftParams {
        seed: 7,
        ..soft_params(8)
    };
    let reseeded = soft_visibility(&scene, &hard, &straight_down_cap(), &params).expect("valid");
    assert_eq!(reseeded.exact, coarse.exact);
    assert!(penumbra
        .iter()
        .any(|&i| reseeded.visibility[i] != coarse.visibility[i]));
}

#[test]
fn disk_penumbra_matches_chord_of_the_disk() {
    // A horizontal disk of radius 0.5 centred 3 units above the origin: a sample Q
    // on it is blocked when the segment from P crosses y = h at x < 0, i.e. when
    // Q.x < P.x - P.x / tau with tau = (h - P.y) / (3 - P.y): a chord of the disk.
    const RADIUS: f64 = 0.5;
    const HEIGHT: f64 = 3.0;
    let scene = ground_scene(true);
    let hard = hard_reference(&scene);
    let light = AreaLight::Disk {
        position: DVec3::new(0.0, HEIGHT, 0.0),
        radius: RADIUS,
        axis: DVec3::Y,
    };
    let result = soft(&scene, &hard, light, 16);
    check_shape(&result, &hard);
    let tolerance = 4.0 * result.standard_error_bound;
    let mut penumbra = 0;
    for (i, p) in hard.position.iter().enumerate() {
        let tau = (OCCLUDER_HEIGHT - p.y) / (HEIGHT - p.y);
        let chord = (p.x - p.x / tau) / RADIUS;
        let expected = disk_fraction_beyond(chord);
        let value = result.visibility[i];
        assert!(
            (value - expected).abs() <= tolerance,
            "pixel {i} at {p}: {value} vs analytic {expected}"
        );
        if result.exact[i] {
            assert_eq!(value, 1.0);
            assert!(chord < -1.0, "pixel {i} at {p} exact inside the penumbra");
        }
        if chord.abs() < 1.0 {
            penumbra += 1;
        }
    }
    assert!(penumbra > 500 && result.exact_pixels > 500);
}

#[test]
fn receiver_facing_away_from_the_light_is_exactly_unlit() {
    let scene = ground_scene(false);
    let hard = hard_reference(&scene);
    // Light below the ground, which is seen from above.
    let below = AreaLight::Directional {
        direction: DVec3::new(0.2, 1.0, 0.1).normalize(),
        angular_radius: 0.2,
    };
    let result = soft(&scene, &hard, below, 8);
    check_shape(&result, &hard);
    assert_eq!(result.exact_pixels, (SIZE * SIZE) as usize);
    assert!(result.visibility.iter().all(|v| *v == 0.0));

    // A light 0.05 rad above the horizon with a 0.1 rad radius: the ground's plane
    // cuts the cap, and nothing else blocks it.
    let elevation: f64 = 0.05;
    let grazing = AreaLight::Directional {
        direction: -DVec3::new(elevation.cos(), elevation.sin(), 0.0),
        angular_radius: CAP_RADIUS,
    };
    let result = soft(&scene, &hard, grazing, 16);
    check_shape(&result, &hard);
    assert_eq!(result.exact_pixels, 0);
    let expected = cap_fraction_above_great_circle(elevation, CAP_RADIUS);
    let tolerance = 4.0 * result.standard_error_bound;
    for value in &result.visibility {
        assert!(
            (value - expected).abs() <= tolerance,
            "{value} vs {expected}"
        );
    }
    let mean = result.visibility.iter().sum::<f64>() / result.visibility.len() as f64;
    assert!((mean - expected).abs() < 0.01, "{mean} vs {expected}");
}

/// Boxes and a sphere over a bumpy grid, for checking exact pixels against sampling.
fn cluttered_scene() -> RefScene {
    let mut mesh = MeshBuilder::new();
    add_heightfield(&mut mesh, (-2.0, -2.0), (2.0, 2.0), 12, |x, z| {
        0.05 * (3.0 * x).sin() * z
    });
    mesh.add_box(Vec3::new(-0.3, 0.2, -0.3), Vec3::new(0.0, 0.6, 0.1));
    mesh.add_sphere(Vec3::new(0.25, 0.3, 0.2), 0.12, 8, 12);
    RefScene::new(&mesh.into_scene("mesh"))
}

#[test]
fn exact_pixels_agree_with_sampling() {
    let scene = cluttered_scene();
    let camera = Vec3::new(0.8, 1.5, 1.6);
    let params = VisibilityParams {
        width: 48,
        height: 48,
        view_proj: Mat4::perspective_infinite_reverse_rh(1.0, 1.0, 0.05).as_dmat4()
            * Mat4::look_at_rh(camera, Vec3::ZERO, Vec3::Y).as_dmat4(),
        camera_position: camera.as_dvec3(),
        light: Light::Directional {
            direction: DVec3::NEG_Y,
        },
        tolerance: 1e-6,
        tolerance_per_distance: 0.0,
        pixel_tolerance: 1.0 / 64.0,
    };
    let hard = reference_visibility(&scene, &params);
    let soft_params = SoftParams {
        camera_position: camera.as_dvec3(),
        strata: 6,
        seed: 11,
    };
    let lights = [
        AreaLight::Directional {
            direction: DVec3::new(0.5, -1.0, 0.3).normalize(),
            angular_radius: 0.05,
        },
        AreaLight::Directional {
            direction: DVec3::new(-0.2, -1.0, -0.6).normalize(),
            angular_radius: 0.3,
        },
        AreaLight::Disk {
            position: DVec3::new(-1.0, 2.0, 0.5),
            radius: 0.3,
            axis: DVec3::new(0.4, -1.0, -0.2),
        },
        // Close to the scene, so that some receivers see it edge-on or from behind.
        AreaLight::Disk {
            position: DVec3::new(0.6, 0.25, -0.4),
            radius: 0.15,
            axis: DVec3::X,
        },
    ];
    for light in lights {
        let fast = soft_visibility_with(
            &scene,
            &hard,
            &light,
            &soft_params,
            ExactShortcuts::Enabled,
            &|| {},
        )
        .expect("valid");
        let slow = soft_visibility_with(
            &scene,
            &hard,
            &light,
            &soft_params,
            ExactShortcuts::Disabled,
            &|| {},
        )
        .expect("valid");
        assert_eq!(slow.exact_pixels, 0);
        assert!(fast.exact_pixels > 100, "{light:?}: {}", fast.exact_pixels);
        assert!(
            fast.sampled_pixels > 100,
            "{light:?}: {}",
            fast.sampled_pixels
        );
        for i in 0..fast.visibility.len() {
            // Exact pixels match sampling; sampled ones are the same computation.
            assert_eq!(
                fast.visibility[i].to_bits(),
                slow.visibility[i].to_bits(),
                "{light:?}, pixel {i} (exact: {})",
                fast.exact[i]
            );
        }
        println!(
            "{light:?}: {} exact, {} sampled",
            fast.exact_pixels, fast.sampled_pixels
        );
    }
}

#[test]
fn invalid_inputs_are_rejected() {
    let scene = ground_scene(false);
    let hard = hard_reference(&scene);
    let params = soft_params(4);
    let directional = |direction: DVec3, angular_radius: f64| AreaLight::Directional {
        direction,
        angular_radius,
    };
    let disk = |position: DVec3, radius: f64, axis: DVec3| AreaLight::Disk {
        position,
        radius,
        axis,
    };
    let invalid = [
        directional(DVec3::NEG_Y, 0.0),
        directional(DVec3::NEG_Y, -0.1),
        directional(DVec3::NEG_Y, FRAC_PI_2),
        directional(DVec3::NEG_Y, f64::NAN),
        directional(DVec3::ZERO, 0.1),
        directional(DVec3::new(f64::INFINITY, -1.0, 0.0), 0.1),
        disk(DVec3::Y, 0.0, DVec3::Y),
        disk(DVec3::Y, f64::INFINITY, DVec3::Y),
        disk(DVec3::new(f64::NAN, 1.0, 0.0), 0.5, DVec3::Y),
        disk(DVec3::Y, 0.5, DVec3::ZERO),
    ];
    for light in invalid {
        let error = soft_visibility(&scene, &hard, &light, &params).expect_err("invalid light");
        assert!(error.starts_with("soft shadows:"), "{error}");
    }
    let light = straight_down_cap();
    assert!(soft_visibility(&scene, &hard, &light, &params).is_ok());
    for strata in [0, 65_536] {
        let bad = SoftParams { strata, ..params };
        assert!(soft_visibility(&scene, &hard, &light, &bad).is_err());
    }
    let bad = SoftParams {
        camera_position: DVec3::NAN,
        ..params
    };
    assert!(soft_visibility(&scene, &hard, &light, &bad).is_err());
    let mut truncated = hard.clone();
    truncated.position.pop();
    assert!(soft_visibility(&scene, &truncated, &light, &params).is_err());
    let mut inconsistent = hard.clone();
    inconsistent.receiver[5] = 99;
    assert!(soft_visibility(&scene, &inconsistent, &light, &params).is_err());
}

#[test]
fn cone_triangle_test_is_conservative_and_tight() {
    // Against the smallest angle from the axis over a dense barycentric grid of the
    // triangle (an upper bound of the true smallest angle).
    const GRID: usize = 64;
    let mut rng = SplitMix64::new(3);
    let (mut meets, mut clear, mut loose) = (0, 0, 0);
    for case in 0..2000 {
        let apex = in_cube(&mut rng, 1.0);
        let axis = random_direction(&mut rng);
        let half_angle = rng.uniform_f64(0.01, 1.2);
        let tri = [0; 3].map(|_| apex + in_cube(&mut rng, 2.0));
        let mut smallest = f64::INFINITY;
        for i in 0..=GRID {
            for j in 0..=GRID - i {
                let (a, b) = (i as f64 / GRID as f64, j as f64 / GRID as f64);
                let p = tri[0] * (1.0 - a - b) + tri[1] * a + tri[2] * b;
                let d = p - apex;
                smallest = smallest.min(d.cross(axis).length().atan2(d.dot(axis)));
            }
        }
        let may_meet = cone_may_meet_triangle(apex, axis, half_angle, &tri);
        if !may_meet {
            assert!(smallest > half_angle, "case {case}: {tri:?} is in the cone");
            clear += 1;
        } else {
            meets += 1;
            if smallest > half_angle + 0.2 {
                loose += 1;
            }
        }
    }
    println!("{meets} may meet ({loose} far from the cone), {clear} clear");
    assert!(clear > 200 && meets > 200);
    assert!(
        loose < 20,
        "{loose} triangles far from the cone not ruled out"
    );
}
