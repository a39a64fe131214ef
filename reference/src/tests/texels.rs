//! Conservative texel sets against hand-checked cases and a brute-force oracle.

use glam::{DVec2, Mat4, Vec3, Vec4};
use scene::{MeshBuilder, SplitMix64};

use super::in_cube;
use crate::{
    conservative_texel_sets, overlaps_texel_with_margin, FaceSelection, RefScene, TexelSets,
};

const DOWN: Vec3 = Vec3::NEG_Y;

/// Light matrix mapping world (x, z) in `[0, n]^2` exactly to texel coordinates.
fn grid_matrix(n: u32) -> Mat4 {
    let s = 2.0 / n as f32;
    Mat4::from_cols(
        Vec4::new(s, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 0.0, -0.01, 0.0),
        Vec4::new(0.0, s, 0.0, 0.0),
        Vec4::new(-1.0, -1.0, 0.5, 1.0),
    )
}

/// World triangle at height 0 whose grid projection is `points` (texel space).
fn flat(points: [(f32, f32); 3]) -> [Vec3; 3] {
    points.map(|(x, z)| Vec3::new(x, 0.0, z))
}

fn scene_of(triangles: &[[Vec3; 3]]) -> RefScene {
    let mut mesh = MeshBuilder::new();
    for [a, b, c] in triangles {
        mesh.add_triangle([*a, *b, *c]);
    }
    RefScene::new(&mesh.into_scene("mesh"))
}

/// Texels `(x, y)` containing triangle `tri`.
fn texels_of(sets: &TexelSets, tri: u32) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for y in 0..sets.n {
        for x in 0..sets.n {
            if sets.texel(x, y).contains(&tri) {
                out.push((x, y));
            }
        }
    }
    out
}

fn check_csr(sets: &TexelSets, triangle_count: usize) {
    let cells = (sets.n * sets.n) as usize;
    assert_eq!(sets.offsets.len(), cells + 1);
    assert_eq!(sets.offsets[0], 0);
    assert_eq!(sets.offsets[cells] as usize, sets.triangles.len());
    assert!(sets.offsets.windows(2).all(|w| w[0] <= w[1]));
    for i in 0..cells {
        let list = &sets.triangles[sets.offsets[i] as usize..sets.offsets[i + 1] as usize];
        assert!(
            list.windows(2).all(|w| w[0] < w[1]),
            "texel {i} not strictly ascending"
        );
        assert!(list.iter().all(|t| sets.required[*t as usize]));
    }
    assert_eq!(sets.required.len(), triangle_count);
    assert_eq!(sets.light_degenerate.len(), triangle_count);
}

/// Texel-space projection, computed exactly as the reference does.
fn project(matrix: Mat4, n: u32, p: Vec3) -> DVec2 {
    let clip = matrix.as_dmat4() * p.as_dvec3().extend(1.0);
    (DVec2::new(clip.x, clip.y) / clip.w * 0.5 + 0.5) * f64::from(n)
}

/// Independent overlap oracle: a vertex in the square, a corner in the triangle,
/// or crossing edges (plain floating point; only used away from exact ties).
fn brute_overlap(q: [DVec2; 3], x: u32, y: u32) -> bool {
    let lo = DVec2::new(f64::from(x), f64::from(y));
    let hi = lo + DVec2::ONE;
    let in_square = |p: DVec2| p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y;
    if q.iter().any(|p| in_square(*p)) {
        return true;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
    if cross(q[0], q[1], q[2]) != 0.0 {
        for c in corners {
            let s = [
                cross(q[0], q[1], c),
                cross(q[1], q[2], c),
                cross(q[2], q[0], c),
            ];
            if s.iter().all(|v| *v >= 0.0) || s.iter().all(|v| *v <= 0.0) {
                return true;
            }
        }
    }
    let segments_cross = |a: DVec2, b: DVec2, c: DVec2, d: DVec2| {
        let (d1, d2) = (cross(a, b, c), cross(a, b, d));
        let (d3, d4) = (cross(c, d, a), cross(c, d, b));
        d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && !(d1 == 0.0 && d2 == 0.0)
    };
    (0..3).any(|i| {
        (0..4).any(|k| segments_cross(q[i], q[(i + 1) % 3], corners[k], corners[(k + 1) % 4]))
    })
}

/// Compares the sets with the oracle for every triangle and texel, and with
/// `overlaps_texel_with_margin`.
fn check_against_brute_force(scene: &RefScene, triangles: &[[Vec3; 3]], matrix: Mat4, n: u32) {
    let sets = conservative_texel_sets(scene, matrix.as_dmat4(), DOWN, n, FaceSelection::Both);
    check_csr(&sets, triangles.len());
    for (i, tri) in triangles.iter().enumerate() {
        let q = tri.map(|p| project(matrix, n, p));
        let id = i as u32;
        for y in 0..n {
            for x in 0..n {
                let expected = brute_overlap(q, x, y);
                assert_eq!(
                    sets.texel(x, y).contains(&id),
                    expected,
                    "triangle {i} {q:?} texel ({x}, {y})"
                );
                assert_eq!(
                    overlaps_texel_with_margin(scene, matrix.as_dmat4(), n, id, x, y, 0.0),
                    expected
                );
                if expected {
                    assert!(overlaps_texel_with_margin(
                        scene,
                        matrix.as_dmat4(),
                        n,
                        id,
                        x,
                        y,
                        0.5
                    ));
                }
            }
        }
    }
}

#[test]
fn triangle_on_texel_boundaries_touches_neighbours() {
    let n = 8;
    let tri = flat([(2.0, 2.0), (4.0, 2.0), (2.0, 4.0)]);
    let scene = scene_of(&[tri]);
    let sets = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::Both,
    );
    check_csr(&sets, 1);
    let mut expected = Vec::new();
    for y in 1..=4 {
        for x in 1..=4 {
            if x + y <= 6 {
                expected.push((x, y));
            }
        }
    }
    assert_eq!(texels_of(&sets, 0), expected);
    assert!(sets.required[0] && !sets.light_degenerate[0]);
    // A margin reaches the texel just across the hypotenuse corner.
    let matrix = grid_matrix(n);
    assert!(!overlaps_texel_with_margin(
        &scene,
        matrix.as_dmat4(),
        n,
        0,
        4,
        3,
        0.0
    ));
    assert!(overlaps_texel_with_margin(
        &scene,
        matrix.as_dmat4(),
        n,
        0,
        4,
        3,
        0.5
    ));
    assert!(!overlaps_texel_with_margin(
        &scene,
        matrix.as_dmat4(),
        n,
        0,
        6,
        6,
        0.5
    ));
}

#[test]
fn sub_texel_triangle_and_needle() {
    let n = 8;
    let small = flat([(5.2, 5.3), (5.6, 5.4), (5.3, 5.8)]);
    let needle = flat([(0.5, 0.5), (7.5, 7.25), (7.5, 7.2501)]);
    let scene = scene_of(&[small, needle]);
    let sets = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::Both,
    );
    check_csr(&sets, 2);
    assert_eq!(texels_of(&sets, 0), vec![(5, 5)]);
    let needle_texels = texels_of(&sets, 1);
    for k in 0..8 {
        assert!(needle_texels.contains(&(k, k)), "diagonal texel {k}");
    }
    assert!(!needle_texels.contains(&(7, 0)) && !needle_texels.contains(&(0, 7)));
    check_against_brute_force(&scene, &[small, needle], grid_matrix(n), n);
}

#[test]
fn partly_and_wholly_outside_triangles_are_clipped() {
    let n = 8;
    let partly = flat([(-3.0, -2.0), (3.5, 1.25), (-1.0, 6.5)]);
    let outside = flat([(20.0, 20.0), (30.0, 21.0), (25.0, 30.0)]);
    let covering = flat([(-100.0, -100.0), (300.0, -100.0), (-100.0, 300.0)]);
    let triangles = [partly, outside, covering];
    let scene = scene_of(&triangles);
    let sets = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::Both,
    );
    assert!(!texels_of(&sets, 0).is_empty());
    assert!(texels_of(&sets, 1).is_empty() && sets.required[1]);
    assert_eq!(texels_of(&sets, 2).len(), 64);
    check_against_brute_force(&scene, &triangles, grid_matrix(n), n);
}

#[test]
fn edge_on_triangle_is_binned_as_a_segment() {
    let n = 8;
    // Vertical triangle in the plane z = 1: projects onto the segment y = 1, x in [1, 3].
    let edge_on = [
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(3.0, 0.0, 1.0),
        Vec3::new(1.0, 2.0, 1.0),
    ];
    let scene = scene_of(&[edge_on]);
    let both = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::Both,
    );
    assert!(both.light_degenerate[0] && both.required[0]);
    let mut expected = Vec::new();
    for y in 0..=1 {
        for x in 0..=3 {
            expected.push((x, y));
        }
    }
    assert_eq!(texels_of(&both, 0), expected);
    // Not strictly front-facing: neither required nor listed with FrontOnly.
    let front = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::FrontOnly,
    );
    assert!(front.light_degenerate[0] && !front.required[0]);
    assert!(texels_of(&front, 0).is_empty());
}

#[test]
fn front_only_skips_back_faces_and_3d_degenerates() {
    let n = 8;
    // Clockwise in texel space = facing +y = facing the light.
    let front = flat([(1.0, 1.0), (1.5, 3.0), (3.0, 1.5)]);
    let back = flat([(1.0, 1.0), (3.0, 1.5), (1.5, 3.0)]);
    let degenerate = flat([(1.0, 1.0), (2.0, 2.0), (3.0, 3.0)]);
    let scene = scene_of(&[front, back, degenerate]);
    let both = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::Both,
    );
    let front_only = conservative_texel_sets(
        &scene,
        grid_matrix(n).as_dmat4(),
        DOWN,
        n,
        FaceSelection::FrontOnly,
    );
    check_csr(&both, 3);
    check_csr(&front_only, 3);
    assert_eq!(both.required, vec![true, true, false]);
    assert_eq!(front_only.required, vec![true, false, false]);
    assert_eq!(both.light_degenerate, vec![false, false, true]);
    assert_eq!(texels_of(&both, 0), texels_of(&both, 1));
    assert_eq!(texels_of(&front_only, 0), texels_of(&both, 0));
    assert!(texels_of(&front_only, 1).is_empty());
    assert!(texels_of(&both, 2).is_empty());
}

#[test]
fn random_triangles_match_brute_force() {
    let n = 16;
    let mut rng = SplitMix64::new(7);
    let mut triangles = Vec::new();
    for k in 0..400 {
        let center = (rng.uniform_f64(-4.0, 20.0), rng.uniform_f64(-4.0, 20.0));
        let size = [0.05, 0.5, 3.0, 12.0][k % 4];
        let mut vertex = || {
            let x = center.0 + rng.uniform_f64(-size, size);
            let z = center.1 + rng.uniform_f64(-size, size);
            (x as f32, z as f32)
        };
        let (a, b) = (vertex(), vertex());
        // Every fifth triangle is a needle.
        let c = if k % 5 == 0 {
            (b.0 + 1e-3, b.1 - 2e-3)
        } else {
            vertex()
        };
        triangles.push(flat([a, b, c]));
    }
    let scene = scene_of(&triangles);
    check_against_brute_force(&scene, &triangles, grid_matrix(n), n);
}

#[test]
fn perspective_light_matches_brute_force() {
    let n = 32;
    let matrix = Mat4::perspective_rh(70f32.to_radians(), 1.0, 0.5, 50.0)
        * Mat4::look_at_rh(Vec3::new(0.5, 10.0, 0.3), Vec3::ZERO, Vec3::Z);
    let mut rng = SplitMix64::new(8);
    let mut triangles = Vec::new();
    for _ in 0..200 {
        let center = in_cube(&mut rng, 8.0).as_vec3() * Vec3::new(1.0, 0.25, 1.0);
        let size = rng.uniform_f64(0.05, 3.0) as f32;
        triangles.push([0, 1, 2].map(|_| center + in_cube(&mut rng, 1.0).as_vec3() * size));
    }
    let scene = scene_of(&triangles);
    check_against_brute_force(&scene, &triangles, matrix, n);

    // A triangle reaching behind the light cannot be projected.
    let behind = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 12.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    ];
    let scene = scene_of(&[behind]);
    let sets = conservative_texel_sets(&scene, matrix.as_dmat4(), DOWN, n, FaceSelection::Both);
    assert!(!sets.required[0] && !sets.light_degenerate[0] && sets.triangles.is_empty());
    assert!(overlaps_texel_with_margin(
        &scene,
        matrix.as_dmat4(),
        n,
        0,
        3,
        3,
        0.0
    ));
    assert!(!overlaps_texel_with_margin(
        &scene,
        matrix.as_dmat4(),
        n,
        1,
        3,
        3,
        0.0
    ));
}

#[test]
fn texel_lookup_outside_the_grid_is_empty() {
    let scene = scene_of(&[flat([(0.0, 0.0), (8.0, 0.0), (0.0, 8.0)])]);
    let sets = conservative_texel_sets(
        &scene,
        grid_matrix(8).as_dmat4(),
        DOWN,
        8,
        FaceSelection::Both,
    );
    assert_eq!(sets.texel(0, 0), &[0]);
    assert!(sets.texel(8, 0).is_empty() && sets.texel(0, 8).is_empty());
    let empty = conservative_texel_sets(
        &scene,
        grid_matrix(8).as_dmat4(),
        DOWN,
        0,
        FaceSelection::Both,
    );
    assert_eq!(empty.offsets, vec![0]);
    assert!(empty.texel(0, 0).is_empty());
}
