//! The triangle-soup scene representation and whole-scene operations.

use std::path::Path;

use glam::Vec3;

use crate::{error::MEMORY_PATH, Aabb, SceneError};

/// The name of the ground plane [`Scene::with_ground_plane`] adds.
const GROUND: &str = "ground";

/// A named contiguous range of triangles (one OBJ object/group, or one procedural part).
/// A draw call.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Name from the OBJ `o`/`g` statement, or of the procedural part.
    pub name: String,
    /// Index of the first triangle (not of the first index).
    pub first_triangle: u32,
    /// Number of triangles.
    pub triangle_count: u32,
}

/// World-space triangle soup with shared vertices.
///
/// Invariants after [`validate`](Scene::validate) succeeds: there is at least one triangle, all
/// positions are finite, `indices.len() % 3 == 0`, every index is `< positions.len()`, and
/// `objects` cover `[0, triangle_count)` in order without gaps or overlaps.
/// Triangles wind counter-clockwise when seen from their front side.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// Vertex positions in metres.
    pub positions: Vec<Vec3>,
    /// Three indices into `positions` per triangle.
    pub indices: Vec<u32>,
    /// Draw ranges, in triangle order.
    pub objects: Vec<Object>,
}

impl Scene {
    /// A scene of one object named `name` holding every triangle of `indices`.
    pub fn single_object(positions: Vec<Vec3>, indices: Vec<u32>, name: &str) -> Scene {
        let triangle_count = (indices.len() / 3) as u32;
        Scene {
            positions,
            indices,
            objects: vec![Object {
                name: name.to_owned(),
                first_triangle: 0,
                triangle_count,
            }],
        }
    }

    /// Number of complete triangles (`indices.len() / 3`).
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Corner positions of triangle `i`.
    ///
    /// # Panics
    ///
    /// If `i >= triangle_count()` or the triangle references a missing vertex; call
    /// [`validate`](Scene::validate) first on scenes of unknown origin.
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        std::array::from_fn(|k| self.positions[self.indices[3 * i + k] as usize])
    }

    /// Bounds of the vertices referenced by `indices` (unreferenced vertices are ignored, as are
    /// out-of-range indices). Empty ([`Aabb::empty`]) if there are no triangles.
    pub fn bounds(&self) -> Aabb {
        let mut bounds = Aabb::empty();
        for &i in &self.indices[..3 * self.triangle_count()] {
            if let Some(&p) = self.positions.get(i as usize) {
                bounds.extend(p);
            }
        }
        bounds
    }

    /// Bounds of the vertices of the objects marked in `which` (one flag per object, in order; objects
    /// without a flag are left out). Empty ([`Aabb::empty`]) if no marked object has a triangle.
    pub fn objects_bounds(&self, which: &[bool]) -> Aabb {
        let mut bounds = Aabb::empty();
        for (object, _) in self.objects.iter().zip(which).filter(|(_, &marked)| marked) {
            let len = self.indices.len();
            let first = (object.first_triangle as usize * 3).min(len);
            let last = (first + object.triangle_count as usize * 3).min(len);
            for &i in &self.indices[first..last] {
                if let Some(&p) = self.positions.get(i as usize) {
                    bounds.extend(p);
                }
            }
        }
        bounds
    }

    /// Bounds of every object but the ground plane (an object named `"ground"`, as
    /// [`with_ground_plane`](Scene::with_ground_plane) adds it): what a camera frames. All of the scene
    /// if the ground is all there is.
    pub fn focus_bounds(&self) -> Aabb {
        let focus: Vec<bool> = self.objects.iter().map(|o| o.name != GROUND).collect();
        let bounds = self.objects_bounds(&focus);
        if bounds.is_valid() {
            bounds
        } else {
            self.bounds()
        }
    }

    /// The world-space scale of the scene's model: the bounding radius of its
    /// [`focus_bounds`](Scene::focus_bounds), at least a millimetre (the hybrid's default WSS).
    pub fn world_space_scale(&self) -> f32 {
        self.focus_bounds().radius().max(1e-3)
    }

    /// Checks the invariants listed on [`Scene`], reporting problems against the path `<memory>`.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_as(Path::new(MEMORY_PATH))
    }

    /// [`validate`](Scene::validate), reporting problems against `path`.
    pub(crate) fn validate_as(&self, path: &Path) -> Result<(), SceneError> {
        let parse_error = |message: String| SceneError::Parse {
            path: path.to_owned(),
            message,
        };
        if let Some((vertex, value)) = self.positions.iter().enumerate().find_map(|(i, p)| {
            p.to_array()
                .into_iter()
                .find(|c| !c.is_finite())
                .map(|c| (i, c))
        }) {
            return Err(SceneError::NonFinite {
                path: path.to_owned(),
                vertex,
                value,
            });
        }
        if self.triangle_count() * 3 != self.indices.len() {
            return Err(parse_error(format!(
                "{} indices do not form whole triangles",
                self.indices.len()
            )));
        }
        if let Some((position, &index)) = self
            .indices
            .iter()
            .enumerate()
            .find(|&(_, &index)| index as usize >= self.positions.len())
        {
            return Err(SceneError::IndexOutOfRange {
                path: path.to_owned(),
                triangle: position / 3,
                index,
                count: self.positions.len(),
            });
        }
        if self.indices.is_empty() {
            return Err(SceneError::Empty {
                path: path.to_owned(),
            });
        }
        let mut next = 0u64;
        for object in &self.objects {
            if u64::from(object.first_triangle) != next {
                return Err(parse_error(format!(
                    "object \"{}\" starts at triangle {} but the previous object ends at {next}",
                    object.name, object.first_triangle
                )));
            }
            next += u64::from(object.triangle_count);
        }
        let triangles = self.triangle_count() as u64;
        if next != triangles {
            return Err(parse_error(format!(
                "objects cover {next} triangles but there are {triangles}"
            )));
        }
        Ok(())
    }

    /// Appends `other`, re-basing its indices and object ranges after the existing content.
    ///
    /// Counts are stored as `u32`, so the combined scene must stay below 2^32 vertices and
    /// triangles.
    pub fn append(&mut self, other: &Scene) {
        let vertex_base = self.positions.len() as u32;
        let triangle_base = self.triangle_count() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.indices
            .extend(other.indices.iter().map(|&i| i.wrapping_add(vertex_base)));
        self.objects.extend(other.objects.iter().map(|o| Object {
            name: o.name.clone(),
            first_triangle: o.first_triangle.wrapping_add(triangle_base),
            triangle_count: o.triangle_count,
        }));
    }

    /// A copy with an extra object `"ground"`: a square of two triangles facing +Y at the lowest
    /// point of the scene, centred under it, with side `4 * max(size.x, size.z)` but at least 1 m.
    /// An empty scene gets a 1 m ground square at the origin.
    pub fn with_ground_plane(&self) -> Scene {
        let bounds = self.bounds();
        let (center, side) = if bounds.is_valid() {
            let size = bounds.size();
            let center = Vec3::new(bounds.center().x, bounds.min.y, bounds.center().z);
            (center, (4.0 * size.x.max(size.z)).max(1.0))
        } else {
            (Vec3::ZERO, 1.0)
        };
        let mut scene = self.clone();
        scene.append(&ground_square(GROUND, center, side));
        scene
    }

    /// A copy with every vertex moved by `offset`.
    pub fn translated(&self, offset: Vec3) -> Scene {
        Scene {
            positions: self.positions.iter().map(|&p| p + offset).collect(),
            ..self.clone()
        }
    }

    /// A copy scaled uniformly about the origin.
    ///
    /// A negative factor mirrors the geometry; the winding of every triangle is then reversed so
    /// that front faces stay front faces.
    pub fn scaled(&self, factor: f32) -> Scene {
        let mut indices = self.indices.clone();
        if factor < 0.0 {
            for tri in indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
        Scene {
            positions: self.positions.iter().map(|&p| p * factor).collect(),
            indices,
            objects: self.objects.clone(),
        }
    }
}

/// A one-object scene holding a horizontal square of two triangles wound counter-clockwise seen
/// from +Y, centred on `center` (at height `center.y`).
pub(crate) fn ground_square(name: &str, center: Vec3, side: f32) -> Scene {
    let h = side * 0.5;
    let corners = [(-h, -h), (-h, h), (h, h), (h, -h)];
    Scene::single_object(
        corners
            .iter()
            .map(|&(x, z)| center + Vec3::new(x, 0.0, z))
            .collect(),
        vec![0, 1, 2, 0, 2, 3],
        name,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> Scene {
        Scene {
            positions: vec![
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::splat(100.0),
            ],
            indices: vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
            objects: vec![
                Object {
                    name: "a".into(),
                    first_triangle: 0,
                    triangle_count: 1,
                },
                Object {
                    name: "b".into(),
                    first_triangle: 1,
                    triangle_count: 3,
                },
            ],
        }
    }

    fn normal(t: [Vec3; 3]) -> Vec3 {
        (t[1] - t[0]).cross(t[2] - t[0])
    }

    use crate::mesh_builder::signed_volume;

    #[test]
    fn focus_bounds_leave_the_ground_aside() {
        let model = tetrahedron();
        let grounded = model.with_ground_plane();
        assert_eq!(grounded.focus_bounds(), model.bounds());
        assert!(grounded.bounds().radius() > 2.0 * model.bounds().radius());
        assert_eq!(model.world_space_scale(), model.bounds().radius());
        let ground_only = Scene::default().with_ground_plane();
        assert_eq!(ground_only.focus_bounds(), ground_only.bounds());
    }

    #[test]
    fn basic_queries() {
        let s = tetrahedron();
        s.validate().unwrap();
        assert_eq!(s.triangle_count(), 4);
        assert_eq!(s.triangle(1), [Vec3::Y, Vec3::X, Vec3::ZERO]);
        let b = s.bounds();
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::ONE));
        assert!(signed_volume(&s) > 0.0);
    }

    #[test]
    fn bounds_of_some_objects() {
        let s = tetrahedron();
        let a = s.objects_bounds(&[true, false]);
        assert_eq!((a.min, a.max), (Vec3::ZERO, Vec3::ONE));
        let b = s.objects_bounds(&[false, true]);
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::ONE));
        assert_eq!(s.objects_bounds(&[true, true]), s.bounds());
        assert_eq!(s.objects_bounds(&[false, false]), Aabb::empty());
        let mut single = Scene::axis_box("low", Vec3::ZERO, Vec3::ONE);
        single.append(&Scene::axis_box("high", Vec3::splat(5.0), Vec3::splat(6.0)));
        let high = single.objects_bounds(&[false, true]);
        assert_eq!((high.min, high.max), (Vec3::splat(5.0), Vec3::splat(6.0)));
    }

    #[test]
    fn validate_reports_each_problem() {
        let mut s = tetrahedron();
        s.positions[3].y = f32::NAN;
        assert!(matches!(
            s.validate(),
            Err(SceneError::NonFinite { vertex: 3, .. })
        ));

        let mut s = tetrahedron();
        s.indices.push(0);
        assert!(matches!(s.validate(), Err(SceneError::Parse { .. })));

        let mut s = tetrahedron();
        s.indices[7] = 9;
        let err = s.validate().unwrap_err();
        assert!(matches!(
            err,
            SceneError::IndexOutOfRange {
                triangle: 2,
                index: 9,
                count: 5,
                ..
            }
        ));
        assert!(err.to_string().starts_with("<memory>: "));

        let mut s = tetrahedron();
        s.objects[1].first_triangle = 2;
        assert!(matches!(s.validate(), Err(SceneError::Parse { .. })));
        let mut s = tetrahedron();
        s.objects[1].triangle_count = 2;
        assert!(matches!(s.validate(), Err(SceneError::Parse { .. })));
        let mut s = tetrahedron();
        s.objects[1].triangle_count = u32::MAX;
        assert!(matches!(s.validate(), Err(SceneError::Parse { .. })));

        assert!(matches!(
            Scene::default().validate(),
            Err(SceneError::Empty { .. })
        ));
    }

    #[test]
    fn axis_box_is_closed_and_faces_outwards() {
        let b = Scene::axis_box("box", Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 3.0, 5.0));
        assert_eq!(b.triangle_count(), 12);
        assert_eq!(b.objects.len(), 1);
        b.validate().expect("valid");
        // Outward counter-clockwise faces enclose a positive volume: 2 * 3 * 3.
        assert!((signed_volume(&b) - 18.0).abs() < 1e-4);
    }

    #[test]
    fn append_rebases() {
        let mut s = tetrahedron();
        let t = tetrahedron().translated(Vec3::X * 10.0);
        s.append(&t);
        s.validate().unwrap();
        assert_eq!(s.triangle_count(), 8);
        assert_eq!(s.objects.len(), 4);
        assert_eq!(s.objects[3].first_triangle, 5);
        assert_eq!(s.triangle(5), t.triangle(1));
        assert_eq!(s.bounds().max, Vec3::new(11.0, 1.0, 1.0));
    }

    #[test]
    fn ground_plane_is_under_the_scene_and_faces_up() {
        let s = tetrahedron().translated(Vec3::new(3.0, 2.0, -1.0));
        let g = s.with_ground_plane();
        g.validate().unwrap();
        let ground = g.objects.last().unwrap();
        assert_eq!(ground.name, "ground");
        assert_eq!(ground.triangle_count, 2);
        let first = ground.first_triangle as usize;
        let mut bounds = Aabb::empty();
        for i in first..first + 2 {
            let t = g.triangle(i);
            assert!(normal(t).normalize().abs_diff_eq(Vec3::Y, 1e-6));
            t.into_iter().for_each(|p| bounds.extend(p));
        }
        assert_eq!(bounds.min.y, 2.0);
        assert_eq!(bounds.max.y, 2.0);
        assert!(bounds.center().abs_diff_eq(Vec3::new(3.5, 2.0, -0.5), 1e-6));
        assert!(bounds.size().abs_diff_eq(Vec3::new(4.0, 0.0, 4.0), 1e-6));

        let tiny = tetrahedron().scaled(0.01).with_ground_plane();
        assert_eq!(tiny.bounds().size().x, 1.0);
        let empty = Scene::default().with_ground_plane();
        empty.validate().unwrap();
        assert_eq!(empty.triangle_count(), 2);
    }

    #[test]
    fn transforms() {
        let s = tetrahedron();
        let moved = s.translated(Vec3::ONE);
        assert_eq!(moved.bounds().min, Vec3::ONE);
        let big = s.scaled(2.0);
        assert_eq!(big.bounds().max, Vec3::splat(2.0));
        assert!((signed_volume(&big) - 8.0 * signed_volume(&s)).abs() < 1e-5);
        let mirrored = s.scaled(-1.0);
        mirrored.validate().unwrap();
        assert_eq!(mirrored.bounds().min, -Vec3::ONE);
        assert!((signed_volume(&mirrored) - signed_volume(&s)).abs() < 1e-6);
    }
}
