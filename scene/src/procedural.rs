//! The built-in demo scene, generated deterministically in code.

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use glam::{Affine3A, EulerRot, Quat, Vec2, Vec3};

use crate::scene::ground_square;
use crate::{MeshBuilder, Scene, SplitMix64};

/// The demo's built-in scene: a collection of shadow-mapping trouble makers on a ground plane.
///
/// Objects, in order:
/// - `"ground"`: a 12 m x 12 m square at y = 0 (2 triangles),
/// - `"character"`: a 1.8 m humanoid made of closed, outward-wound parts (capsule limbs and
///   torso, sphere head and hands, box feet and pelvis) standing on the ground,
/// - `"fence"`: posts, rails and 2.5 cm slats with 7.5 cm gaps, all thin closed boxes,
/// - `"foliage"`: a bush of zero-thickness leaf polygons at random orientations, plus crossed
///   cards that intersect each other,
/// - `"sphere"`: a closed sphere resting on the ground, touching it at a single vertex.
///
/// 7,010 triangles; everything but the ground lies within 3.5 m of the origin. The output is
/// identical on every call.
pub fn procedural_default() -> Scene {
    let mut scene = ground_square("ground", Vec3::ZERO, 12.0);
    scene.append(&character().into_scene("character"));
    scene.append(&fence().into_scene("fence"));
    scene.append(&foliage().into_scene("foliage"));
    scene.append(&sphere().into_scene("sphere"));
    scene
}

fn character() -> MeshBuilder {
    let root =
        Affine3A::from_rotation_translation(Quat::from_rotation_y(0.35), Vec3::new(0.0, 0.0, 0.4));
    let mut mesh = MeshBuilder::placed(root);
    for side in [-1.0, 1.0] {
        add_centered_box(
            &mut mesh,
            Vec3::new(0.05, 0.035, 0.12),
            Vec3::new(0.1 * side, 0.035, 0.04),
        );
        add_capsule(
            &mut mesh,
            Vec3::new(0.1 * side, 0.12, 0.0),
            Vec3::new(0.1 * side, 0.86, 0.0),
            0.065,
        );
    }
    add_centered_box(
        &mut mesh,
        Vec3::new(0.16, 0.08, 0.1),
        Vec3::new(0.0, 0.93, 0.0),
    );
    mesh.add_lathe(
        &capsule_profile(0.17, 0.26),
        CAPSULE_SEGMENTS,
        Affine3A::from_scale_rotation_translation(
            Vec3::new(1.0, 1.0, 0.65),
            Quat::IDENTITY,
            Vec3::new(0.0, 1.08, 0.0),
        ),
    );
    mesh.add_lathe(
        &[
            Vec2::ZERO,
            Vec2::new(0.05, 0.0),
            Vec2::new(0.05, 0.12),
            Vec2::new(0.0, 0.12),
        ],
        CAPSULE_SEGMENTS,
        Affine3A::from_translation(Vec3::new(0.0, 1.48, 0.0)),
    );
    mesh.add_sphere(Vec3::new(0.0, 1.69, 0.01), 0.11, 14, 20);
    let shoulders = [Vec3::new(0.22, 1.43, 0.0), Vec3::new(-0.22, 1.43, 0.0)];
    let wrists = [Vec3::new(0.29, 0.92, 0.03), Vec3::new(-0.28, 1.25, 0.5)];
    for (shoulder, wrist) in shoulders.into_iter().zip(wrists) {
        add_capsule(&mut mesh, shoulder, wrist, 0.045);
        let hand = wrist + (wrist - shoulder).normalize() * 0.06;
        mesh.add_sphere(hand, 0.05, 8, 10);
    }
    mesh
}

fn fence() -> MeshBuilder {
    const HALF_LENGTH: f32 = 2.0;
    const SLAT_PITCH: f32 = 0.1;
    let root =
        Affine3A::from_rotation_translation(Quat::from_rotation_y(0.2), Vec3::new(0.3, 0.0, -1.6));
    let mut mesh = MeshBuilder::placed(root);
    for i in 0..4 {
        let x = -HALF_LENGTH + i as f32 * (2.0 * HALF_LENGTH / 3.0);
        add_centered_box(
            &mut mesh,
            Vec3::new(0.04, 0.575, 0.04),
            Vec3::new(x, 0.575, 0.0),
        );
    }
    for y in [0.25, 0.9] {
        add_centered_box(
            &mut mesh,
            Vec3::new(HALF_LENGTH, 0.02, 0.01),
            Vec3::new(0.0, y, 0.05),
        );
    }
    let slats = (2.0 * HALF_LENGTH / SLAT_PITCH) as usize;
    for i in 0..slats {
        let x = -HALF_LENGTH + (i as f32 + 0.5) * SLAT_PITCH;
        add_centered_box(
            &mut mesh,
            Vec3::new(0.0125, 0.5, 0.0075),
            Vec3::new(x, 0.55, 0.0675),
        );
    }
    mesh
}

fn foliage() -> MeshBuilder {
    const LEAVES: usize = 560;
    const TUFTS: usize = 10;
    let mut rng = SplitMix64::new(0x5eed_1eaf);
    let mut mesh = MeshBuilder::placed(Affine3A::from_translation(Vec3::new(-1.5, 0.0, 0.9)));
    for _ in 0..LEAVES {
        let offset = loop {
            let p = Vec3::new(
                rng.uniform_f32(-1.0, 1.0),
                rng.uniform_f32(-1.0, 1.0),
                rng.uniform_f32(-1.0, 1.0),
            );
            if p.length_squared() <= 1.0 {
                break p * Vec3::new(0.55, 0.45, 0.55);
            }
        };
        let orientation = Quat::from_euler(
            EulerRot::YXZ,
            rng.next_f32() * TAU,
            rng.uniform_f32(-1.0, 1.0) * 1.2,
            rng.uniform_f32(-1.0, 1.0) * PI,
        );
        let length = 0.1 + 0.08 * rng.next_f32();
        let width = length * (0.4 + 0.1 * rng.next_f32());
        let outline = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.3, -0.5),
            Vec2::new(0.7, -0.43),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.7, 0.43),
            Vec2::new(0.3, 0.5),
        ]
        .map(|q| {
            offset
                + Vec3::new(0.0, 0.75, 0.0)
                + orientation * Vec3::new(q.x * length, 0.0, q.y * width)
        });
        mesh.add_polygon(&outline);
    }
    for i in 0..TUFTS {
        let angle = i as f32 / TUFTS as f32 * TAU;
        let base = Vec3::new(angle.cos(), 0.0, angle.sin()) * (0.7 + 0.15 * rng.next_f32());
        let yaw = rng.next_f32() * PI;
        let (half_width, height) = (0.15 + 0.05 * rng.next_f32(), 0.4 + 0.2 * rng.next_f32());
        for card in 0..3 {
            let across = Quat::from_rotation_y(yaw + card as f32 * PI / 3.0) * Vec3::X * half_width;
            let up = Vec3::Y * height;
            mesh.add_polygon(&[
                base - across,
                base + across,
                base + across + up,
                base - across + up,
            ]);
        }
    }
    mesh
}

fn sphere() -> MeshBuilder {
    const RADIUS: f32 = 0.45;
    let mut mesh = MeshBuilder::new();
    mesh.add_sphere(Vec3::new(1.6, RADIUS, 1.1), RADIUS, 24, 36);
    mesh
}

/// Segments around the axis of capsules and cylinders.
const CAPSULE_SEGMENTS: u32 = 16;
/// Profile rings in each hemispherical cap of a capsule (pole excluded).
const CAPSULE_CAP_RINGS: u32 = 5;

/// Profile (radius, height) of a capsule along +Y from the centre of its bottom cap to the centre
/// of its top cap, `length` apart.
fn capsule_profile(radius: f32, length: f32) -> Vec<Vec2> {
    let cap = |from: f32, height: f32| {
        (0..=CAPSULE_CAP_RINGS).map(move |k| {
            let phi = from + FRAC_PI_2 * k as f32 / CAPSULE_CAP_RINGS as f32;
            Vec2::new(radius * phi.sin(), height - radius * phi.cos())
        })
    };
    cap(0.0, 0.0).chain(cap(FRAC_PI_2, length)).collect()
}

/// Adds a closed box of half extents `half_extents` around `center` (axis-aligned in the builder's
/// local space).
fn add_centered_box(mesh: &mut MeshBuilder, half_extents: Vec3, center: Vec3) {
    mesh.add_box(center - half_extents, center + half_extents);
}

/// Adds a closed capsule whose cap centres are `a` and `b`.
fn add_capsule(mesh: &mut MeshBuilder, a: Vec3, b: Vec3, radius: f32) {
    let axis = b - a;
    let rotation = Quat::from_rotation_arc(Vec3::Y, axis.normalize());
    mesh.add_lathe(
        &capsule_profile(radius, axis.length()),
        CAPSULE_SEGMENTS,
        Affine3A::from_rotation_translation(rotation, a),
    );
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;
    use crate::{Aabb, Object};

    fn object<'a>(scene: &'a Scene, name: &str) -> &'a Object {
        scene
            .objects
            .iter()
            .find(|o| o.name == name)
            .unwrap_or_else(|| panic!("no object {name}"))
    }

    fn triangles(object: &Object) -> std::ops::Range<usize> {
        let first = object.first_triangle as usize;
        first..first + object.triangle_count as usize
    }

    fn object_bounds(scene: &Scene, name: &str) -> Aabb {
        let mut bounds = Aabb::empty();
        for t in triangles(object(scene, name)) {
            scene.triangle(t).into_iter().for_each(|p| bounds.extend(p));
        }
        bounds
    }

    fn find(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }

    /// Asserts that object `name` is a set of closed, consistently wound surfaces: every directed
    /// edge occurs exactly once and its reverse exactly once, no triangle is degenerate, and every
    /// connected part encloses a positive volume (so it is wound outwards). Returns the number of
    /// connected parts.
    fn assert_closed(scene: &Scene, name: &str) -> usize {
        let mut directed = HashMap::<(u32, u32), u32>::new();
        let mut parent = (0..scene.positions.len()).collect::<Vec<_>>();
        let range = triangles(object(scene, name));
        for t in range.clone() {
            let [a, b, c] = [0, 1, 2].map(|k| scene.indices[3 * t + k]);
            assert!(
                a != b && b != c && c != a,
                "{name}: degenerate triangle {t}"
            );
            for (from, to) in [(a, b), (b, c), (c, a)] {
                *directed.entry((from, to)).or_default() += 1;
                let (x, y) = (
                    find(&mut parent, from as usize),
                    find(&mut parent, to as usize),
                );
                parent[x] = y;
            }
        }
        for (&(from, to), &count) in &directed {
            assert_eq!(count, 1, "{name}: edge {from}->{to} used {count} times");
            assert_eq!(
                directed.get(&(to, from)),
                Some(&1),
                "{name}: edge {from}-{to} is not shared by exactly two opposite triangles"
            );
        }
        let mut volumes = HashMap::<usize, f32>::new();
        for t in range {
            let [a, b, c] = scene.triangle(t);
            let root = find(&mut parent, scene.indices[3 * t] as usize);
            *volumes.entry(root).or_default() += a.dot(b.cross(c)) / 6.0;
        }
        for volume in volumes.values() {
            assert!(*volume > 0.0, "{name}: a part is wound inwards ({volume})");
        }
        volumes.len()
    }

    #[test]
    fn validates_with_expected_objects() {
        let scene = procedural_default();
        scene.validate().unwrap();
        let summary = scene
            .objects
            .iter()
            .map(|o| (o.name.as_str(), o.triangle_count))
            .collect::<Vec<_>>();
        assert_eq!(
            summary,
            [
                ("ground", 2),
                ("character", 2500),
                ("fence", 552),
                ("foliage", 2300),
                ("sphere", 1656),
            ]
        );
        assert!((5_000..=20_000).contains(&scene.triangle_count()));
        assert_eq!(scene, procedural_default());
    }

    #[test]
    fn closed_parts_are_closed() {
        let scene = procedural_default();
        assert_eq!(assert_closed(&scene, "character"), 12);
        assert_eq!(assert_closed(&scene, "sphere"), 1);
        assert_eq!(assert_closed(&scene, "fence"), 46);
    }

    #[test]
    fn layout() {
        let scene = procedural_default();
        for p in &scene.positions {
            assert!(p.x.abs() <= 6.0 && p.z.abs() <= 6.0 && p.y >= 0.0 && p.y < 2.0);
        }
        let ground = object_bounds(&scene, "ground");
        assert_eq!(ground.min, Vec3::new(-6.0, 0.0, -6.0));
        assert_eq!(ground.max, Vec3::new(6.0, 0.0, 6.0));
        for name in ["character", "fence", "foliage", "sphere"] {
            let b = object_bounds(&scene, name);
            assert!(
                b.min.y >= 0.0 && b.min.y < 0.1,
                "{name} does not stand on the ground"
            );
            for corner in b.corners() {
                assert!(corner.with_y(0.0).length() < 3.5, "{name} is too far out");
            }
        }
        let parts =
            ["character", "fence", "foliage", "sphere"].map(|n| (n, object_bounds(&scene, n)));
        for (i, (a, a_bounds)) in parts.iter().enumerate() {
            for (b, b_bounds) in &parts[i + 1..] {
                let apart = a_bounds.max.cmplt(b_bounds.min) | b_bounds.max.cmplt(a_bounds.min);
                assert!(apart.x || apart.z, "{a} and {b} overlap");
            }
        }
        let character = object_bounds(&scene, "character");
        assert_eq!(character.min.y, 0.0);
        assert!((character.max.y - 1.8).abs() < 0.02, "{}", character.max.y);
    }

    #[test]
    fn sphere_touches_the_ground_at_one_vertex() {
        let scene = procedural_default();
        let sphere = object(&scene, "sphere");
        let mut vertices = scene.indices[3 * triangles(sphere).start..]
            [..3 * sphere.triangle_count as usize]
            .to_vec();
        vertices.sort_unstable();
        vertices.dedup();
        let heights = vertices.iter().map(|&v| scene.positions[v as usize].y);
        assert_eq!(heights.clone().filter(|&y| y == 0.0).count(), 1);
        assert!(heights.filter(|&y| y != 0.0).all(|y| y > 1e-3));
        let center = object_bounds(&scene, "sphere").center();
        for t in triangles(sphere) {
            let [a, b, c] = scene.triangle(t);
            assert!((b - a).cross(c - a).dot((a + b + c) / 3.0 - center) > 0.0);
        }
    }

    #[test]
    fn fence_is_thin() {
        let scene = procedural_default();
        let fence = object(&scene, "fence");
        let thin_boxes = triangles(fence)
            .step_by(12)
            .filter(|&t| {
                let mut b = Aabb::empty();
                for k in t..t + 12 {
                    scene.triangle(k).into_iter().for_each(|p| b.extend(p));
                }
                let along_fence = Quat::from_rotation_y(-0.2) * b.size();
                along_fence.x.abs() < 0.05
            })
            .count();
        assert!(thin_boxes >= 40, "{thin_boxes}");
    }

    #[test]
    fn foliage_cards_are_open_and_varied() {
        let scene = procedural_default();
        let foliage = object(&scene, "foliage");
        assert!(foliage.triangle_count >= 1000);
        let normals = triangles(foliage)
            .map(|t| {
                let [a, b, c] = scene.triangle(t);
                (b - a).cross(c - a).normalize()
            })
            .collect::<Vec<_>>();
        assert!(normals.iter().all(|n| n.is_finite()));
        assert!(normals.iter().any(|n| n.y.abs() > 0.9));
        assert!(normals.iter().filter(|n| n.y.abs() < 0.3).count() > 100);
        let cards = object_bounds(&scene, "foliage");
        assert!(cards.size().min_element() > 0.5);
    }
}
