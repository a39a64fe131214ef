//! The renderer's meshes: one per object of a scene (split where 16-bit indices cannot address it), in
//! object space around the object's centre, each drawn as an instance.

use crate::conventions::IndexType;
use glam::{Mat4, Vec3};
use scene::{Aabb, Scene};
use std::collections::HashMap;

/// One mesh on the CPU: positions in object space and triangle-list indices.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// The scene object it comes from.
    pub name: String,
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Triangle-list indices into `positions`.
    pub indices: Vec<u32>,
    /// The instance's object-to-world transform when the scene is at rest.
    pub rest: Mat4,
}

impl Mesh {
    /// World-space bounds of the mesh under `transform`.
    pub fn bounds(&self, transform: Mat4) -> Aabb {
        let mut b = Aabb::empty();
        for p in &self.positions {
            b.extend(transform.transform_point3(*p));
        }
        b
    }
}

/// Meshes of `scene`: one per object, translated to the object's centre; with 16-bit indices an object of
/// more than 65,536 vertices becomes several meshes.
pub fn meshes_of(scene: &Scene, index: IndexType) -> Vec<Mesh> {
    let limit = match index {
        IndexType::U16 => 1 << 16,
        IndexType::U32 => usize::MAX,
    };
    let mut meshes = Vec::new();
    for object in &scene.objects {
        let first = object.first_triangle as usize;
        let triangles = first..first + object.triangle_count as usize;
        let mut bounds = Aabb::empty();
        for t in triangles.clone() {
            for v in scene.triangle(t) {
                bounds.extend(v);
            }
        }
        let center = bounds.center();
        let mut mesh = Mesh {
            name: object.name.clone(),
            positions: Vec::new(),
            indices: Vec::new(),
            rest: Mat4::from_translation(center),
        };
        let mut remap: HashMap<u32, u32> = HashMap::new();
        for t in triangles {
            let corners = &scene.indices[t * 3..t * 3 + 3];
            let new = corners.iter().filter(|c| !remap.contains_key(c)).count();
            if mesh.positions.len() + new > limit {
                let next = Mesh {
                    name: mesh.name.clone(),
                    positions: Vec::new(),
                    indices: Vec::new(),
                    rest: mesh.rest,
                };
                meshes.push(std::mem::replace(&mut mesh, next));
                remap.clear();
            }
            for &c in corners {
                let local = *remap.entry(c).or_insert_with(|| {
                    mesh.positions.push(scene.positions[c as usize] - center);
                    (mesh.positions.len() - 1) as u32
                });
                mesh.indices.push(local);
            }
        }
        if !mesh.indices.is_empty() {
            meshes.push(mesh);
        }
    }
    meshes
}

/// The world-space scene the meshes make with `transforms` (one per mesh), as the GPU transforms them
/// (f32): for references.
pub fn world_scene(meshes: &[Mesh], transforms: &[Mat4]) -> Scene {
    let mut scene = Scene::default();
    for (m, t) in meshes.iter().zip(transforms) {
        let positions = m.positions.iter().map(|p| t.transform_point3(*p)).collect();
        scene.append(&Scene::single_object(positions, m.indices.clone(), &m.name));
    }
    scene
}
