//! The **grazing** family: light at 80°, 89° and 89.9° from the normal of a tilted tessellated plane and
//! of the top facet of a large tube (no acne).

use glam::{DQuat, DVec3, Vec3};

use super::{add_grid, add_vertex, case, circle, look, Check, Family, HardCase, MapSpec};
use crate::MeshBuilder;

/// `(plane case, tube case, contact case, degrees)` of the grazing angles.
pub(super) const GRAZING: [(&str, &str, &str, f64); 3] = [
    ("plane 80°", "tube 80°", "contact 80°", 80.0),
    ("plane 89°", "tube 89°", "contact 89°", 89.0),
    ("plane 89.9°", "tube 89.9°", "contact 89.9°", 89.9),
];

/// The cases of the `grazing` family, in table order.
pub(super) fn grazing() -> Vec<HardCase> {
    let mut cases = Vec::new();
    let rotation = DQuat::from_axis_angle(DVec3::new(1.0, 0.0, 0.5).normalize(), 0.35);
    let center = DVec3::new(0.0, 1.0, 0.0);
    let (normal, tangent, bitangent) = (
        rotation * DVec3::Y,
        rotation * DVec3::X,
        rotation * DVec3::Z,
    );
    let mut plane = MeshBuilder::new();
    add_grid(
        &mut plane,
        center + rotation * DVec3::new(-2.0, 0.0, 2.0),
        rotation * DVec3::new(4.0, 0.0, 0.0),
        rotation * DVec3::new(0.0, 0.0, -4.0),
        12,
        12,
    );
    let plane = plane.into_scene("tilted plane");
    let mut plane_bounds = plane.bounds();
    plane_bounds.min -= Vec3::splat(1e-3);
    plane_bounds.max += Vec3::splat(1e-3);

    let radius = 20.0;
    let mut tube = MeshBuilder::new();
    add_tube(&mut tube, DVec3::ZERO, radius, 20.0, 512);
    let tube = tube.into_scene("tube");
    let mut tube_bounds = tube.bounds();
    tube_bounds.min -= Vec3::splat(1e-2);
    tube_bounds.max += Vec3::splat(1e-2);

    for (plane_name, tube_name, _, degrees) in GRAZING {
        let theta = degrees.to_radians();
        let to_light = normal * theta.cos() + tangent * theta.sin();
        cases.push(
            case(
                plane_name,
                Family::Grazing,
                "A 4 m plane of 288 triangles, tilted so that its f32 vertices are not exactly \
             coplanar, lit at a grazing angle from its normal: every receiver on it must be lit.",
                plane.clone(),
                (-to_light).as_vec3(),
                Some(look(
                    (center + normal * 3.0 + bitangent * 3.0).as_vec3(),
                    center.as_vec3(),
                )),
                MapSpec::new(256),
            )
            .checking(vec![Check::Lit(plane_bounds)]),
        );

        // The top facet's normal is +y; light at `theta` from it, in the xy plane.
        let to_light = DVec3::new(-theta.sin(), theta.cos(), 0.0);
        let mid = (90.0 + degrees).to_radians() * 0.5;
        let target = DVec3::new(mid.cos(), mid.sin(), 0.0) * radius;
        let outward = target.normalize();
        cases.push(
            case(
                tube_name,
                Family::Grazing,
                "A convex tube of radius 20 m and 512 facets (one facing exactly up), light at a \
             grazing angle from the top facet's normal; the view holds the terminator: every \
             light-facing facet must be lit.",
                tube.clone(),
                (-to_light).as_vec3(),
                Some(look(
                    (target + outward * 6.0 + DVec3::Z * 5.0).as_vec3(),
                    target.as_vec3(),
                )),
                MapSpec::new(256),
            )
            .checking(vec![Check::Lit(tube_bounds)]),
        );
    }
    cases
}

/// Adds an open tube along z (no caps), `segments` facets wound outwards; one facet faces exactly +y.
fn add_tube(mesh: &mut MeshBuilder, center: DVec3, radius: f64, half_length: f64, segments: u32) {
    let n = i64::from(segments);
    let first = mesh.positions().len() as u32;
    for j in 0..n {
        // Vertex j at π/2 + (2j + 1)π/n: the facet between the last and the first vertex is centred on +y.
        let (c, s) = circle(n + 4 * j + 2, 4 * n);
        for z in [-half_length, half_length] {
            add_vertex(mesh, center + DVec3::new(radius * c, radius * s, z));
        }
    }
    for j in 0..segments {
        let k = (j + 1) % segments;
        let (a, d) = (first + 2 * j, first + 2 * j + 1);
        let (b, c) = (first + 2 * k, first + 2 * k + 1);
        mesh.connect_quad([a, b, c, d]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tube_has_a_facet_facing_up() {
        let mut m = MeshBuilder::new();
        add_tube(&mut m, DVec3::ZERO, 20.0, 20.0, 512);
        let s = m.into_scene("tube");
        let up = (0..s.triangle_count()).filter(|&t| {
            let [a, b, c] = s.triangle(t);
            (b - a).cross(c - a).normalize() == Vec3::Y
        });
        assert_eq!(up.count(), 2);
    }
}
