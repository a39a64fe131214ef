//! Unit tests and the helpers they share.

mod perf;
mod soft;
mod texels;
mod visibility;
mod watertight;

use glam::{DVec3, Vec3};
use scene::SplitMix64;

/// Uniform in the cube `[-half, half)^3`.
pub(crate) fn in_cube(rng: &mut SplitMix64, half: f64) -> DVec3 {
    DVec3::new(
        rng.uniform_f64(-half, half),
        rng.uniform_f64(-half, half),
        rng.uniform_f64(-half, half),
    )
}

/// Uniformly distributed unit vector (rejection sampling in the unit ball).
pub(crate) fn random_direction(rng: &mut SplitMix64) -> DVec3 {
    loop {
        let v = in_cube(rng, 1.0);
        let len = v.length();
        if len > 0.1 && len <= 1.0 {
            return v / len;
        }
    }
}

/// Incrementally built triangle mesh.
#[derive(Default)]
pub(crate) struct MeshBuilder {
    pub(crate) positions: Vec<Vec3>,
    pub(crate) indices: Vec<u32>,
}

impl MeshBuilder {
    pub(crate) fn vertex(&mut self, p: Vec3) -> u32 {
        self.positions.push(p);
        u32::try_from(self.positions.len() - 1).expect("vertex count fits u32")
    }

    pub(crate) fn triangle(&mut self, a: u32, b: u32, c: u32) {
        self.indices.extend([a, b, c]);
    }

    /// Adds a standalone triangle.
    pub(crate) fn add_triangle(&mut self, a: Vec3, b: Vec3, c: Vec3) {
        let ids = [self.vertex(a), self.vertex(b), self.vertex(c)];
        self.triangle(ids[0], ids[1], ids[2]);
    }

    /// Adds an axis-aligned box with outward-facing (counter-clockwise) triangles.
    pub(crate) fn add_box(&mut self, min: Vec3, max: Vec3) {
        let corner = |i: u32| {
            Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        };
        let ids: Vec<u32> = (0..8).map(|i| self.vertex(corner(i))).collect();
        let faces = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        for [a, b, c, d] in faces {
            self.triangle(ids[a], ids[b], ids[c]);
            self.triangle(ids[a], ids[c], ids[d]);
        }
    }

    /// Adds a `cells x cells` grid over `[min, max]` in x/z at the height given by
    /// `height(x, z)`, with alternating diagonals, triangles facing +y.
    pub(crate) fn add_grid(
        &mut self,
        min: (f32, f32),
        max: (f32, f32),
        cells: u32,
        height: impl Fn(f32, f32) -> f32,
    ) {
        let row = cells + 1;
        let first = u32::try_from(self.positions.len()).expect("fits");
        for j in 0..row {
            for i in 0..row {
                let x = min.0 + (max.0 - min.0) * i as f32 / cells as f32;
                let z = min.1 + (max.1 - min.1) * j as f32 / cells as f32;
                self.vertex(Vec3::new(x, height(x, z), z));
            }
        }
        for j in 0..cells {
            for i in 0..cells {
                let v = |di: u32, dj: u32| first + (j + dj) * row + i + di;
                if (i + j) % 2 == 0 {
                    self.triangle(v(0, 0), v(0, 1), v(1, 1));
                    self.triangle(v(0, 0), v(1, 1), v(1, 0));
                } else {
                    self.triangle(v(0, 0), v(0, 1), v(1, 0));
                    self.triangle(v(1, 0), v(0, 1), v(1, 1));
                }
            }
        }
    }

    /// Adds a closed UV sphere.
    pub(crate) fn add_sphere(&mut self, center: Vec3, radius: f32, rings: u32, segments: u32) {
        let top = self.vertex(center + Vec3::Y * radius);
        let bottom = self.vertex(center - Vec3::Y * radius);
        let first = u32::try_from(self.positions.len()).expect("fits");
        for r in 1..rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            for s in 0..segments {
                let phi = std::f32::consts::TAU * s as f32 / segments as f32;
                let dir = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                self.vertex(center + dir * radius);
            }
        }
        let at = |r: u32, s: u32| first + (r - 1) * segments + s % segments;
        for s in 0..segments {
            self.triangle(top, at(1, s + 1), at(1, s));
            self.triangle(bottom, at(rings - 1, s), at(rings - 1, s + 1));
            for r in 1..rings - 1 {
                self.triangle(at(r, s), at(r, s + 1), at(r + 1, s + 1));
                self.triangle(at(r, s), at(r + 1, s + 1), at(r + 1, s));
            }
        }
    }

    /// The mesh as a scene with one object.
    pub(crate) fn scene(self) -> scene::Scene {
        let triangle_count = u32::try_from(self.indices.len() / 3).expect("fits");
        scene::Scene {
            positions: self.positions,
            indices: self.indices,
            objects: vec![scene::Object {
                name: "mesh".to_owned(),
                first_triangle: 0,
                triangle_count,
            }],
        }
    }
}
