//! Watertightness and robustness of the ray/triangle and line/segment primitives.

use glam::{DVec3, Vec3};
use scene::{MeshBuilder, SplitMix64};

use super::{add_heightfield, in_cube, random_direction};
use crate::{intersect_watertight, line_segment_distance, RefScene};

/// Every hit parameter of the line `origin + t * dir` against all triangles.
fn hits(scene: &RefScene, origin: DVec3, dir: DVec3) -> Vec<f64> {
    (0..scene.triangle_count())
        .filter_map(|i| intersect_watertight(origin, dir, &scene.triangle(i)))
        .map(|(t, bary)| {
            assert!(t.is_finite() && bary.iter().all(|b| b.is_finite()));
            t
        })
        .collect()
}

/// Closed fan around `center` (the shared vertex) with `k` triangles.
fn fan(center: Vec3, k: u32) -> MeshBuilder {
    let mut mesh = MeshBuilder::new();
    let c = mesh.vertex(center);
    let first = c + 1;
    for i in 0..k {
        let angle = std::f32::consts::TAU * i as f32 / k as f32 + 0.1;
        let radius = 1.0 + 0.3 * (i % 3) as f32;
        mesh.vertex(Vec3::new(
            angle.cos() * radius,
            0.05 * i as f32,
            angle.sin() * radius,
        ));
    }
    for i in 0..k {
        mesh.connect_triangle([c, first + i, first + (i + 1) % k]);
    }
    mesh
}

/// Tessellated closed cube `[-1, 1]^3`; seam vertices of neighbouring faces are
/// bit-identical.
fn cube(cells: u32) -> MeshBuilder {
    let mut mesh = MeshBuilder::new();
    let coord = |i: u32| -1.0 + 2.0 * i as f32 / cells as f32;
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
            let first = mesh.positions().len() as u32;
            for j in 0..=cells {
                for i in 0..=cells {
                    let mut p = Vec3::ZERO;
                    p[axis] = side;
                    p[u_axis] = coord(i);
                    p[v_axis] = coord(j);
                    mesh.vertex(p);
                }
            }
            let row = cells + 1;
            for j in 0..cells {
                for i in 0..cells {
                    let v = |di: u32, dj: u32| first + (j + dj) * row + i + di;
                    mesh.connect_triangle([v(0, 0), v(1, 0), v(1, 1)]);
                    mesh.connect_triangle([v(0, 0), v(1, 1), v(0, 1)]);
                }
            }
        }
    }
    mesh
}

/// Shared vertices and edge midpoints (exact in f64) of the interior of a mesh:
/// every vertex and every edge midpoint of the given triangles.
fn edge_and_vertex_targets(scene: &RefScene) -> Vec<DVec3> {
    let mut targets = Vec::new();
    for i in 0..scene.triangle_count() {
        let [a, b, c] = scene.triangle(i);
        targets.extend([a, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
    }
    targets
}

#[test]
fn rays_at_shared_fan_edges_and_vertex_always_hit() {
    let mut rng = SplitMix64::new(1);
    for k in [3, 5, 8, 13] {
        let scene = RefScene::new(&fan(Vec3::new(0.0, 0.3, 0.0), k).into_scene("mesh"));
        let center = scene.triangle(0)[0];
        let mut targets = vec![center];
        for i in 0..scene.triangle_count() {
            let [c, a, _] = scene.triangle(i);
            for f in [0.5, 0.25, 0.75, 0.125] {
                targets.push(c + (a - c) * f);
            }
        }
        for target in targets {
            for _ in 0..200 {
                // Within 25 degrees of vertical, so that no spoke is a silhouette.
                let side = if rng.next_f64() < 0.5 { 3.0 } else { -3.0 };
                let origin = target
                    + DVec3::new(rng.uniform_f64(-1.0, 1.0), side, rng.uniform_f64(-1.0, 1.0));
                let dir = target - origin;
                assert!(
                    !hits(&scene, origin, dir).is_empty(),
                    "ray {origin} -> {target} slipped through a fan of {k}"
                );
            }
        }
    }
}

#[test]
fn rays_at_shared_grid_edges_and_vertices_always_hit() {
    let mut rng = SplitMix64::new(2);
    for offset in [0.0f32, 1e5] {
        let mut mesh = MeshBuilder::new();
        add_heightfield(
            &mut mesh,
            (offset - 2.0, -2.0),
            (offset + 2.0, 2.0),
            8,
            |x, z| 0.37 * (x - offset) + 0.61 * z + 0.1 + 0.05 * ((x - offset) * 3.0).sin(),
        );
        let scene = RefScene::new(&mesh.into_scene("mesh"));
        let interior = |p: DVec3| (p.x - f64::from(offset)).abs() < 1.99 && p.z.abs() < 1.99;
        let targets: Vec<DVec3> = edge_and_vertex_targets(&scene)
            .into_iter()
            .filter(|p| interior(*p))
            .collect();
        assert!(targets.len() > 200);
        for target in targets {
            for _ in 0..20 {
                let side = if rng.next_f64() < 0.5 { 5.0 } else { -5.0 };
                let origin = target
                    + DVec3::new(rng.uniform_f64(-2.0, 2.0), side, rng.uniform_f64(-2.0, 2.0));
                let dir = target - origin;
                assert!(
                    !hits(&scene, origin, dir).is_empty(),
                    "ray {origin} -> {target} slipped through the grid (offset {offset})"
                );
            }
        }
    }
}

#[test]
fn lines_through_closed_meshes_hit_on_both_sides() {
    let mut rng = SplitMix64::new(3);
    let mut sphere = MeshBuilder::new();
    sphere.add_sphere(Vec3::ZERO, 1.0, 12, 16);
    for mesh in [sphere, cube(4)] {
        let scene = RefScene::new(&mesh.into_scene("mesh"));
        // Random lines through interior points.
        for _ in 0..3000 {
            let inside = in_cube(&mut rng, 0.5);
            let dir = random_direction(&mut rng);
            let ts = hits(&scene, inside, dir);
            assert!(ts.len() >= 2, "line through {inside} along {dir}: {ts:?}");
            assert!(ts.iter().any(|t| *t > 0.0) && ts.iter().any(|t| *t < 0.0));
        }
        // Rays from interior points aimed exactly at vertices and edge midpoints.
        for target in edge_and_vertex_targets(&scene) {
            for _ in 0..3 {
                let inside = in_cube(&mut rng, 0.5);
                let ts = hits(&scene, inside, target - inside);
                assert!(ts.iter().any(|t| *t > 0.0), "ray {inside} -> {target}");
                assert!(ts.iter().any(|t| *t < 0.0), "ray {inside} <- {target}");
            }
        }
    }
}

#[test]
fn nearest_hit_is_the_smallest_positive_crossing() {
    let mut rng = SplitMix64::new(5);
    let mut mesh = cube(3);
    mesh.add_sphere(Vec3::new(0.2, -0.1, 0.3), 0.4, 8, 12);
    let scene = RefScene::new(&mesh.into_scene("mesh"));
    for _ in 0..500 {
        let origin = in_cube(&mut rng, 0.9);
        let dir = random_direction(&mut rng) * rng.uniform_f64(0.5, 2.0);
        let (t, triangle) = scene.nearest_hit(origin, dir).expect("a closed cube");
        let nearest = hits(&scene, origin, dir)
            .into_iter()
            .filter(|&t| t > 0.0)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(t, nearest, "from {origin} along {dir}");
        let crossing = intersect_watertight(origin, dir, &scene.triangle(triangle));
        assert_eq!(crossing.map(|(t, _)| t), Some(nearest));
    }
    // Outside, pointing away: nothing.
    assert_eq!(scene.nearest_hit(DVec3::new(0.0, 3.0, 0.0), DVec3::Y), None);
}

#[test]
fn cube_corners_and_seams_are_watertight_along_axes_and_diagonals() {
    let scene = RefScene::new(&cube(3).into_scene("mesh"));
    // Rays from the centre straight at corners and along seams.
    for target in edge_and_vertex_targets(&scene) {
        let ts = hits(&scene, DVec3::ZERO, target);
        assert!(ts.iter().any(|t| *t > 0.0), "ray to {target}");
    }
    // Rays grazing along a face's plane are degenerate for that face, but the
    // perpendicular faces still catch them.
    let ts = hits(&scene, DVec3::new(1.0, 0.3, -5.0), DVec3::Z);
    assert!(ts.iter().any(|t| *t > 0.0));
}

#[test]
fn degenerate_triangles_give_none_and_never_nan() {
    let mut rng = SplitMix64::new(4);
    let collinear = [
        DVec3::ZERO,
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(2.0, 2.0, 2.0),
    ];
    let point = [DVec3::new(0.5, 0.5, 0.5); 3];
    let repeated = [DVec3::ZERO, DVec3::ZERO, DVec3::X];
    for tri in [collinear, point, repeated] {
        for _ in 0..2000 {
            let origin = in_cube(&mut rng, 3.0);
            let target = tri[0] + (tri[2] - tri[0]) * rng.next_f64();
            assert_eq!(intersect_watertight(origin, target - origin, &tri), None);
            assert_eq!(
                intersect_watertight(origin, random_direction(&mut rng), &tri),
                None
            );
        }
    }
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    // Ray inside the triangle's plane: degenerate as seen along the ray.
    assert_eq!(
        intersect_watertight(DVec3::new(-1.0, 0.2, 0.0), DVec3::X, &tri),
        None
    );
    // Zero and non-finite directions.
    assert_eq!(
        intersect_watertight(DVec3::new(0.2, 0.2, 1.0), DVec3::ZERO, &tri),
        None
    );
    assert_eq!(
        intersect_watertight(DVec3::new(0.2, 0.2, 1.0), DVec3::NAN, &tri),
        None
    );
    let nan_tri = [DVec3::NAN, DVec3::X, DVec3::Y];
    assert_eq!(
        intersect_watertight(DVec3::new(0.2, 0.2, 1.0), -DVec3::Z, &nan_tri),
        None
    );
    // Degenerate triangles are never usable as blockers or receivers.
    let mut mesh = MeshBuilder::new();
    mesh.add_triangle([Vec3::ZERO, Vec3::ONE, Vec3::splat(2.0)]);
    mesh.add_triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
    let scene = RefScene::new(&mesh.into_scene("mesh"));
    assert!(!scene.is_usable(0));
    assert!(scene.is_usable(1));
}

#[test]
fn hits_report_parameter_and_barycentrics() {
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let (t, bary) =
        intersect_watertight(DVec3::new(0.25, 0.5, 2.0), -DVec3::Z * 4.0, &tri).expect("hit");
    assert_eq!(t, 0.5);
    assert_eq!(bary, [0.25, 0.25, 0.5]);
    // Two-sided, and the parameter may be negative.
    let (t, _) = intersect_watertight(DVec3::new(0.25, 0.5, 2.0), DVec3::Z, &tri).expect("hit");
    assert_eq!(t, -2.0);
    // Vertices and edges are inside.
    for p in [
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::new(0.5, 0.5, 0.0),
        DVec3::new(0.5, 0.0, 0.0),
    ] {
        assert!(
            intersect_watertight(p + DVec3::Z, -DVec3::Z, &tri).is_some(),
            "{p}"
        );
    }
    assert!(intersect_watertight(DVec3::new(0.5, 0.5 + 1e-15, 1.0), -DVec3::Z, &tri).is_none());
}

#[test]
fn huge_coordinates_stay_exact() {
    let offset = DVec3::splat(1e5);
    let tri = [offset, offset + DVec3::X, offset + DVec3::Y];
    let origin = offset + DVec3::new(0.25, 0.25, 1.0);
    let (t, bary) = intersect_watertight(origin, -DVec3::Z, &tri).expect("hit");
    assert_eq!(t, 1.0);
    assert_eq!(bary, [0.5, 0.25, 0.25]);
    // Oblique rays: the hit point reproduces the target to near f64 precision.
    let mut rng = SplitMix64::new(5);
    for _ in 0..1000 {
        let (u, v) = (rng.next_f64(), rng.next_f64());
        let (u, v) = if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        let target = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
        let origin = target + random_direction(&mut rng) * 3.0;
        let dir = target - origin;
        let Some((t, [w0, w1, w2])) = intersect_watertight(origin, dir, &tri) else {
            // Only rays grazing the plane may legitimately miss after rounding.
            assert!(dir.normalize().z.abs() < 1e-6 || u < 1e-9 || v < 1e-9 || u + v > 1.0 - 1e-9);
            continue;
        };
        assert!((t - 1.0).abs() < 1e-9, "t = {t}");
        let p = tri[0] * w0 + tri[1] * w1 + tri[2] * w2;
        assert!((p - target).length() < 1e-9, "{p} vs {target}");
    }
}

#[test]
fn line_segment_distances() {
    let d = |o: DVec3, dir: DVec3, a: DVec3, b: DVec3| line_segment_distance(o, dir, a, b);
    let x = DVec3::X;
    // Perpendicular segment above the line.
    assert_eq!(
        d(
            DVec3::ZERO,
            x,
            DVec3::new(3.0, 1.0, 0.0),
            DVec3::new(3.0, 1.0, 5.0)
        ),
        1.0
    );
    // Crossing segment; the direction need not be unit.
    assert_eq!(
        d(
            DVec3::ZERO,
            x * 7.0,
            DVec3::new(2.0, -1.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0)
        ),
        0.0
    );
    // Closest point clamped to an endpoint.
    let dist = d(
        DVec3::ZERO,
        x,
        DVec3::new(0.0, 2.0, 0.0),
        DVec3::new(0.0, 3.0, 4.0),
    );
    assert!((dist - 2.0).abs() < 1e-15);
    // Skew lines: x axis and the segment along z at y = 2, passing x = 5.
    let dist = d(
        DVec3::ZERO,
        -x,
        DVec3::new(5.0, 2.0, -1.0),
        DVec3::new(5.0, 2.0, 1.0),
    );
    assert!((dist - 2.0).abs() < 1e-15);
    // Parallel segment and degenerate segment.
    assert_eq!(
        d(
            DVec3::ZERO,
            x,
            DVec3::new(-4.0, 0.0, 3.0),
            DVec3::new(9.0, 0.0, 3.0)
        ),
        3.0
    );
    assert_eq!(
        d(
            DVec3::ZERO,
            x,
            DVec3::new(4.0, 0.0, 3.0),
            DVec3::new(4.0, 0.0, 3.0)
        ),
        3.0
    );
    // Zero direction: distance from the point.
    assert_eq!(
        d(
            DVec3::ZERO,
            DVec3::ZERO,
            DVec3::new(3.0, 4.0, -1.0),
            DVec3::new(3.0, 4.0, 1.0)
        ),
        5.0
    );
    // Agrees with brute-force sampling.
    let mut rng = SplitMix64::new(6);
    for _ in 0..500 {
        let (o, dir, a, b) = (
            in_cube(&mut rng, 2.0),
            random_direction(&mut rng),
            in_cube(&mut rng, 2.0),
            in_cube(&mut rng, 2.0),
        );
        let exact = d(o, dir, a, b);
        let sampled = (0..=2000)
            .map(|k| {
                let p = a + (b - a) * (f64::from(k) / 2000.0) - o;
                (p - dir * p.dot(dir)).length()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            exact <= sampled + 1e-12 && sampled - exact < 1e-2,
            "{exact} vs {sampled}"
        );
    }
}
