//! The **shared edges** family: closed or edge-sharing blockers whose shadow rays pass exactly through
//! shared edges and vertices (a triangle fan, a grid a box built from grids, a UV sphere), light
//! straight down and a camera in the plane `x = 0`, so that a whole pixel column of receivers lies under
//! the `x = 0` edges and the centre pixel under the fan's centre vertex and the sphere's poles.

use glam::{DVec3, Vec3};

use super::{
    aabb, add_grid, add_lattice_box, add_vertex, case, circle, ground, look, rectangle, with,
    Check, Family, HardCase, MapSpec, Solid,
};
use crate::{MeshBuilder, Scene};

/// The cases of the `shared-edges` family, in table order.
pub(super) fn shared_edges() -> Vec<HardCase> {
    let down = Vec3::NEG_Y;
    let camera = Some(look(Vec3::new(0.0, 0.45, 2.5), Vec3::ZERO));
    let closed = MapSpec {
        front_faces_only: true,
        ..MapSpec::new(256)
    };

    let mut fan = MeshBuilder::new();
    let rim = add_fan_disc(&mut fan, DVec3::new(0.0, 1.0, 0.0), 1.0, 96);
    let mut plate_grid = MeshBuilder::new();
    add_grid(
        &mut plate_grid,
        DVec3::new(-1.0, 1.0, 1.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -2.0),
        32,
        32,
    );
    let mut grid_box = MeshBuilder::new();
    let (box_min, box_max) = ([-0.75, 0.75, -0.75], [0.75, 1.5, 0.75]);
    add_lattice_box(
        &mut grid_box,
        DVec3::from(box_min),
        DVec3::from(box_max),
        [8, 4, 8],
    );
    let mut sphere = MeshBuilder::new();
    let center = Vec3::new(0.0, 1.2, 0.0);
    add_uv_sphere(&mut sphere, center.as_dvec3(), 0.8, 24, 48);
    let sphere = sphere.into_scene("sphere");
    let radius = inscribed_radius(&sphere, center);

    vec![
        case(
            "fan disc (96 triangles, shared centre)",
            Family::SharedEdges,
            "A horizontal disc of 96 thin fan triangles 1 m above the ground, light straight \
             down: the receiver under the centre sends its ray through the vertex shared by all \
             96, the centre pixel column through the edges on x = 0 and the centre row through \
             the edges on z = 0.",
            with(ground(4.0), [fan.into_scene("fan")]),
            down,
            camera,
            MapSpec::new(256),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rim))]),
        case(
            "grid plate (32x32 quads)",
            Family::SharedEdges,
            "A 2 m plate of 2,048 triangles 1 m above the ground, light straight down: the centre \
             column and row of receivers lie exactly under grid edges and vertices.",
            with(ground(4.0), [plate_grid.into_scene("plate")]),
            down,
            camera,
            MapSpec::new(256),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-1.0, 1.0],
            1.0,
            [-1.0, 1.0],
        )))]),
        case(
            "closed grid box (front faces only)",
            Family::SharedEdges,
            "A floating closed box whose faces are 8x4x8 grids, bit-identical vertices on every \
             seam; only light-facing triangles are stored, so a single layer of shared edges must \
             stop every ray.",
            with(ground(4.0), [grid_box.into_scene("box")]),
            down,
            camera,
            closed,
        )
        .checking(vec![Check::Shadowed(Solid::Box(aabb(box_min, box_max)))]),
        case(
            "closed UV sphere (front faces only)",
            Family::SharedEdges,
            "A floating closed UV sphere (24 rings, 48 meridians); the centre receiver's ray \
             passes through both poles, where 48 triangles meet, and the centre column along \
             meridian edges.",
            with(ground(4.0), [sphere]),
            down,
            camera,
            closed,
        )
        .checking(vec![Check::Shadowed(Solid::Ball { center, radius })]),
    ]
}

/// Adds a closed sphere of `rings` latitude bands and `segments` meridians, poles on the vertical axis,
/// meridian 0 towards +x, wound outwards. Unlike [`MeshBuilder::add_sphere`], its vertices come from
/// [`circle`], so that vertices related by the sphere's symmetries are bit-identical mirror images.
fn add_uv_sphere(mesh: &mut MeshBuilder, center: DVec3, radius: f64, rings: u32, segments: u32) {
    let bottom = add_vertex(mesh, center - DVec3::Y * radius);
    let ring_starts: Vec<u32> = (1..rings)
        .map(|k| {
            let (c, s) = circle(i64::from(k), 2 * i64::from(rings));
            let (y, rho) = (center.y - radius * c, radius * s);
            let start = mesh.positions().len() as u32;
            for j in 0..segments {
                let (cj, sj) = circle(i64::from(j), i64::from(segments));
                add_vertex(
                    mesh,
                    DVec3::new(center.x + rho * cj, y, center.z - rho * sj),
                );
            }
            start
        })
        .collect();
    let top = add_vertex(mesh, center + DVec3::Y * radius);
    let (first, last) = (ring_starts[0], ring_starts[ring_starts.len() - 1]);
    for j in 0..segments {
        let k = (j + 1) % segments;
        mesh.connect_triangle([bottom, first + k, first + j]);
        for pair in ring_starts.windows(2) {
            let (lo, up) = (pair[0], pair[1]);
            mesh.connect_quad([lo + j, lo + k, up + k, up + j]);
        }
        mesh.connect_triangle([top, last + j, last + k]);
    }
}

/// Adds a horizontal disc of `n` fan triangles sharing the centre vertex, facing +y; rim vertex 0 towards
/// +x. Returns the rim polygon.
fn add_fan_disc(mesh: &mut MeshBuilder, center: DVec3, radius: f64, n: u32) -> Vec<Vec3> {
    let hub = add_vertex(mesh, center);
    let rim: Vec<u32> = (0..n)
        .map(|k| {
            let (c, s) = circle(i64::from(k), i64::from(n));
            add_vertex(mesh, center + DVec3::new(radius * c, 0.0, radius * s))
        })
        .collect();
    for k in 0..n as usize {
        let next = rim[(k + 1) % rim.len()];
        mesh.connect_triangle([hub, next, rim[k]]);
    }
    rim.iter().map(|&i| mesh.positions()[i as usize]).collect()
}

/// Radius of the largest ball around `center` inside the convex closed mesh `scene`: the smallest distance
/// from `center` to a triangle's plane (f64).
fn inscribed_radius(scene: &Scene, center: Vec3) -> f32 {
    let c = center.as_dvec3();
    (0..scene.triangle_count())
        .filter_map(|t| {
            let [a, b, d] = scene.triangle(t).map(|p| p.as_dvec3());
            let n = (b - a).cross(d - a).normalize_or_zero();
            (n != DVec3::ZERO).then(|| n.dot(a - c).abs())
        })
        .fold(f64::INFINITY, f64::min) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hard_cases::tests::{assert_watertight, object};
    use crate::hard_cases::Expectation;

    #[test]
    fn closed_meshes_are_watertight() {
        let cases = shared_edges();
        assert_watertight(&object(cases[2].scene.as_ref().unwrap(), "box"));
        assert_watertight(&object(cases[3].scene.as_ref().unwrap(), "sphere"));
    }

    #[test]
    fn shared_edges_lie_on_the_axes() {
        let cases = shared_edges();
        let fan = object(cases[0].scene.as_ref().unwrap(), "fan");
        let on_axis = (0..fan.triangle_count())
            .flat_map(|t| fan.triangle(t))
            .filter(|p| p.x == 0.0 || p.z == 0.0)
            .count();
        // Each of the 96 triangles has the hub; 4 rim vertices on the axes, each in 2 triangles.
        assert_eq!(on_axis, 96 + 8);
        let Expectation::Renders(checks) = &cases[3].expectation else {
            panic!()
        };
        let Check::Shadowed(Solid::Ball { radius, .. }) = checks[0] else {
            panic!()
        };
        assert!(radius > 0.79 && radius < 0.8, "{radius}");
    }
}
