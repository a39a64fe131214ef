//! The workspace's triangle-mesh builder.

use std::f32::consts::{PI, TAU};

use glam::{Affine3A, Vec2, Vec3};

use crate::Scene;

/// Vertex positions and triangles of one object under construction, every triangle wound
/// counter-clockwise seen from its front.
///
/// Shapes are given in the builder's local space. A builder made by [`MeshBuilder::placed`]
/// transforms every vertex by its placement; one made by [`MeshBuilder::new`] stores positions
/// exactly as given (bit for bit).
#[derive(Debug, Clone, Default)]
pub struct MeshBuilder {
    placement: Option<Affine3A>,
    positions: Vec<Vec3>,
    indices: Vec<u32>,
}

impl MeshBuilder {
    /// An empty builder storing positions as given.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty builder placing every vertex by `placement`.
    pub fn placed(placement: Affine3A) -> Self {
        Self {
            placement: Some(placement),
            ..Self::default()
        }
    }

    /// The vertices added so far (placed).
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The mesh as a scene of one object called `name`.
    pub fn into_scene(self, name: &str) -> Scene {
        Scene::single_object(self.positions, self.indices, name)
    }

    /// Adds the vertex `local` (placed) and returns its index.
    ///
    /// # Panics
    ///
    /// If the mesh already holds 2^32 vertices.
    pub fn vertex(&mut self, local: Vec3) -> u32 {
        let p = self
            .placement
            .map_or(local, |placement| placement.transform_point3(local));
        self.positions.push(p);
        u32::try_from(self.positions.len() - 1).expect("fewer than 2^32 vertices")
    }

    /// Adds the triangle of the existing vertices `a b c`.
    pub fn connect_triangle(&mut self, [a, b, c]: [u32; 3]) {
        self.indices.extend([a, b, c]);
    }

    /// Adds the quad of the existing vertices `a b c d` as the triangles `a b c` and `a c d`.
    pub fn connect_quad(&mut self, [a, b, c, d]: [u32; 4]) {
        self.indices.extend([a, b, c, a, c, d]);
    }

    /// Adds a triangle with three vertices of its own, wound as given.
    pub fn add_triangle(&mut self, corners: [Vec3; 3]) {
        self.add_polygon(&corners);
    }

    /// Adds a planar convex quad `a b c d` with four vertices of its own, as the triangles `a b c`
    /// and `a c d`.
    pub fn add_quad(&mut self, corners: [Vec3; 4]) {
        self.add_polygon(&corners);
    }

    /// Adds a planar convex polygon with vertices of its own, fan-triangulated from its first point
    /// and wound in the order given.
    pub fn add_polygon(&mut self, points: &[Vec3]) {
        let Some((&first, rest)) = points.split_first() else {
            return;
        };
        let first = self.vertex(first);
        for &p in rest {
            self.vertex(p);
        }
        for i in 2..points.len() as u32 {
            self.indices.extend([first, first + i - 1, first + i]);
        }
    }

    /// Adds the closed box from `min` to `max` (axis-aligned in local space): 8 vertices, corner
    /// `i` at `max` along x, y and z where bit 0, 1 and 2 of `i` is set; 12 triangles facing
    /// outwards, two per face in the face order +x, -x, +y, -y, +z, -z.
    pub fn add_box(&mut self, min: Vec3, max: Vec3) {
        let first = self.positions.len() as u32;
        for i in 0..8 {
            let pick = |bit: u32, axis: usize| if i & bit == 0 { min[axis] } else { max[axis] };
            self.vertex(Vec3::new(pick(1, 0), pick(2, 1), pick(4, 2)));
        }
        for face in [
            [1, 3, 7, 5],
            [0, 4, 6, 2],
            [2, 6, 7, 3],
            [0, 1, 5, 4],
            [4, 5, 7, 6],
            [0, 2, 3, 1],
        ] {
            self.connect_quad(face.map(|v| first + v));
        }
    }

    /// Adds a closed sphere of `rings` latitude bands and `segments` longitude bands, its poles
    /// single vertices on the vertical axis (a [lathe](MeshBuilder::add_lathe) of a half circle).
    pub fn add_sphere(&mut self, center: Vec3, radius: f32, rings: u32, segments: u32) {
        let profile = (0..=rings)
            .map(|k| {
                let phi = PI * k as f32 / rings as f32;
                Vec2::new(radius * phi.sin(), -radius * phi.cos())
            })
            .collect::<Vec<_>>();
        self.add_lathe(&profile, segments, Affine3A::from_translation(center));
    }

    /// Adds the closed surface of revolution of `profile` (radius, height) points around the
    /// local +Y axis, placed by `transform` (which must preserve orientation) before the builder's
    /// placement. The first and last profile points become single pole vertices on the axis; the
    /// others become rings of `segments` vertices, vertex 0 of each towards +x. Triangles face
    /// outwards. Profiles of fewer than three points add nothing.
    pub fn add_lathe(&mut self, profile: &[Vec2], segments: u32, transform: Affine3A) {
        let [bottom, rings @ .., top] = profile else {
            return;
        };
        if rings.is_empty() {
            return;
        }
        let mut point = |p: Vec3| self.vertex(transform.transform_point3(p));
        let bottom_pole = point(Vec3::new(0.0, bottom.y, 0.0));
        let ring_starts = rings
            .iter()
            .map(|ring| {
                let start = point(Vec3::new(ring.x, ring.y, 0.0));
                for j in 1..segments {
                    let theta = TAU * j as f32 / segments as f32;
                    point(Vec3::new(
                        ring.x * theta.cos(),
                        ring.y,
                        -ring.x * theta.sin(),
                    ));
                }
                start
            })
            .collect::<Vec<_>>();
        let top_pole = point(Vec3::new(0.0, top.y, 0.0));
        let (first_ring, last_ring) = (ring_starts[0], ring_starts[ring_starts.len() - 1]);
        for j in 0..segments {
            let k = (j + 1) % segments;
            self.connect_triangle([bottom_pole, first_ring + k, first_ring + j]);
            for pair in ring_starts.windows(2) {
                let (lower, upper) = (pair[0], pair[1]);
                self.connect_quad([lower + j, lower + k, upper + k, upper + j]);
            }
            self.connect_triangle([top_pole, last_ring + j, last_ring + k]);
        }
    }
}

impl Scene {
    /// An axis-aligned box from `min` to `max` as one object named `name`: 8 vertices, 12 triangles
    /// counter-clockwise seen from outside (see [`MeshBuilder::add_box`]).
    pub fn axis_box(name: &str, min: Vec3, max: Vec3) -> Scene {
        let mut mesh = MeshBuilder::new();
        mesh.add_box(min, max);
        mesh.into_scene(name)
    }
}

/// Sum of the signed volumes of the tetrahedra from the origin to every triangle (the enclosed volume
/// of a closed, outward-wound mesh), for the crate's tests.
#[cfg(test)]
pub(crate) fn signed_volume(scene: &Scene) -> f32 {
    (0..scene.triangle_count())
        .map(|i| {
            let [a, b, c] = scene.triangle(i);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;

    /// Asserts that every directed edge occurs once and its reverse once (closed, consistently
    /// wound) and that no triangle repeats a vertex.
    fn assert_closed(scene: &Scene) {
        let mut edges = HashMap::<(u32, u32), u32>::new();
        for t in scene.indices.chunks_exact(3) {
            assert!(t[0] != t[1] && t[1] != t[2] && t[2] != t[0], "{t:?}");
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *edges.entry((a, b)).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge {a}->{b} used {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "open edge {a}-{b}");
        }
    }

    #[test]
    fn box_is_closed_and_faces_outwards() {
        let mut m = MeshBuilder::new();
        m.add_box(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 3.0, 5.0));
        let b = m.into_scene("box");
        b.validate().unwrap();
        assert_eq!((b.positions.len(), b.triangle_count()), (8, 12));
        assert_closed(&b);
        assert!((signed_volume(&b) - 18.0).abs() < 1e-4);
        assert_eq!(b.positions[5], Vec3::new(1.0, 0.0, 5.0));
        // The first face is +x.
        for p in b.triangle(0).into_iter().chain(b.triangle(1)) {
            assert_eq!(p.x, 1.0);
        }
    }

    #[test]
    fn sphere_is_closed_and_faces_outwards() {
        let mut m = MeshBuilder::new();
        m.add_sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, 6, 8);
        let s = m.into_scene("sphere");
        assert_eq!(s.positions.len(), 2 + 5 * 8);
        assert_eq!(s.triangle_count(), 2 * 8 + 2 * 4 * 8);
        assert_closed(&s);
        assert!(signed_volume(&s) > 0.0);
        for p in &s.positions {
            assert!((p.distance(Vec3::new(1.0, 2.0, 3.0)) - 0.5).abs() < 1e-6);
        }
    }

    #[test]
    fn polygons_fan_from_their_first_point() {
        let mut m = MeshBuilder::new();
        let [a, b, c, d] = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0), Vec3::NEG_Z];
        m.add_triangle([a, b, c]);
        m.add_quad([a, b, c, d]);
        let s = m.into_scene("polygons");
        assert_eq!(s.positions.len(), 3 + 4);
        assert_eq!(s.indices, [0, 1, 2, 3, 4, 5, 3, 5, 6]);
        assert_eq!(s.triangle(2), [a, c, d]);
    }

    #[test]
    fn placement_moves_vertices_and_new_keeps_them_exact() {
        let mut placed = MeshBuilder::placed(Affine3A::from_translation(Vec3::Y));
        assert_eq!(placed.vertex(Vec3::X), 0);
        assert_eq!(placed.positions(), [Vec3::new(1.0, 1.0, 0.0)]);
        let mut exact = MeshBuilder::new();
        exact.vertex(Vec3::new(-0.0, 1e-30, f32::MAX));
        assert_eq!(
            exact.positions()[0].to_array().map(f32::to_bits),
            [(-0.0f32).to_bits(), 1e-30f32.to_bits(), f32::MAX.to_bits()]
        );
    }
}
