//! Unit tests and the helpers they share.

mod perf;
mod soft;
mod texels;
mod visibility;
mod watertight;

use glam::{DVec3, Vec3};
use scene::{MeshBuilder, SplitMix64};

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

/// Adds a `cells x cells` grid over `[min, max]` in x/z at the height given by `height(x, z)`, with
/// alternating diagonals, triangles facing +y.
pub(crate) fn add_heightfield(
    mesh: &mut MeshBuilder,
    min: (f32, f32),
    max: (f32, f32),
    cells: u32,
    height: impl Fn(f32, f32) -> f32,
) {
    let row = cells + 1;
    let first = u32::try_from(mesh.positions().len()).expect("fits");
    for j in 0..row {
        for i in 0..row {
            let x = min.0 + (max.0 - min.0) * i as f32 / cells as f32;
            let z = min.1 + (max.1 - min.1) * j as f32 / cells as f32;
            mesh.vertex(Vec3::new(x, height(x, z), z));
        }
    }
    for j in 0..cells {
        for i in 0..cells {
            let v = |di: u32, dj: u32| first + (j + dj) * row + i + di;
            if (i + j) % 2 == 0 {
                mesh.connect_triangle([v(0, 0), v(0, 1), v(1, 1)]);
                mesh.connect_triangle([v(0, 0), v(1, 1), v(1, 0)]);
            } else {
                mesh.connect_triangle([v(0, 0), v(0, 1), v(1, 0)]);
                mesh.connect_triangle([v(1, 0), v(0, 1), v(1, 1)]);
            }
        }
    }
}
