//! The **texel boundaries** family: triangles whose vertices are primitive-map texel corners.

use glam::{DMat4, DVec3, Vec3};

use super::{aabb, case, ground, look, rounded, with, Check, Family, HardCase, MapSpec, Solid};
use crate::{DirectionalLight, MeshBuilder, Scene};

/// The point at height `y` whose light-space projection is the corner `(i, j)` of texel grid `n`
/// (computed in f64 through the inverse of `light_view_proj`).
fn texel_corner(inverse: DMat4, n: u32, i: i64, j: i64, y: f64) -> DVec3 {
    let ndc = |k: i64| k as f64 / f64::from(n) * 2.0 - 1.0;
    let a = inverse.project_point3(DVec3::new(ndc(i), ndc(j), 0.0));
    let b = inverse.project_point3(DVec3::new(ndc(i), ndc(j), 1.0));
    a + (b - a) * ((y - a.y) / (b.y - a.y))
}

/// Map size of the texel-boundary cases.
const TEXEL_MAP: u32 = 128;

/// Height of the texel-boundary blockers.
const TEXEL_BLOCKER_HEIGHT: f64 = 0.5;

/// Blockers with every vertex on a texel corner of the map fitted to the scene (ground of 4 m, blockers
/// at [`TEXEL_BLOCKER_HEIGHT`]), and the polygon of the texel-aligned plate among them.
fn texel_blockers(light: DirectionalLight) -> (Scene, Vec<Vec3>) {
    let bounds = aabb([-2.0, 0.0, -2.0], [2.0, TEXEL_BLOCKER_HEIGHT, 2.0]);
    let inverse = light.view_proj(&bounds).as_dmat4().inverse();
    let n = TEXEL_MAP;
    let c = i64::from(n / 2);
    let p = |i: i64, j: i64| texel_corner(inverse, n, c + i, c + j, TEXEL_BLOCKER_HEIGHT);
    let mut m = MeshBuilder::new();
    // A plate of 32x32 texel-sized cells.
    for j in -16..16 {
        for i in -16..16 {
            m.add_quad(rounded([
                p(i, j),
                p(i + 1, j),
                p(i + 1, j + 1),
                p(i, j + 1),
            ]));
        }
    }
    let outline = [p(-16, -16), p(16, -16), p(16, 16), p(-16, 16)]
        .map(|p| p.as_vec3())
        .to_vec();
    // A square of 8x8 texels cut along its diagonal through texel corners.
    m.add_triangle(rounded([p(20, -4), p(28, -4), p(20, 4)]));
    m.add_triangle(rounded([p(28, -4), p(28, 4), p(20, 4)]));
    // A strip exactly one texel wide.
    m.add_quad(rounded([p(-28, -16), p(-27, -16), p(-27, 16), p(-28, 16)]));
    // Half a texel.
    m.add_triangle(rounded([p(-22, 20), p(-21, 20), p(-22, 21)]));
    // A triangle touching its neighbour texel at a single corner.
    m.add_triangle(rounded([p(20, 20), p(22, 21), p(21, 22)]));
    (with(ground(4.0), [m.into_scene("texel-aligned")]), outline)
}

/// The cases of the `texel-boundaries` family, in table order.
pub(super) fn texel_boundaries() -> Vec<HardCase> {
    let camera = Some(look(Vec3::new(0.0, 0.3, 2.5), Vec3::ZERO));
    let map = MapSpec::new(TEXEL_MAP);
    let down = DirectionalLight {
        direction: Vec3::NEG_Y,
    };
    let slanted = DirectionalLight::slanted();
    let (vertical_scene, vertical_outline) = texel_blockers(down);
    let (slanted_scene, slanted_outline) = texel_blockers(slanted);
    vec![
        case(
            "texel corners, light straight down",
            Family::TexelBoundaries,
            "Blockers whose vertices are exactly (in f32) on corners of the 128x128 map's texels: \
             a plate of texel-sized cells, a diagonal through texel corners, a strip one texel \
             wide, half a texel, a triangle touching a texel at one corner; the centre pixel \
             column's rays run along a texel boundary.",
            vertical_scene,
            down.direction,
            camera,
            map,
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(vertical_outline))]),
        case(
            "texel corners, slanted light",
            Family::TexelBoundaries,
            "The same blockers on texel corners of a slanted light's map (to f32 rounding).",
            slanted_scene,
            slanted.direction,
            camera,
            map,
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(slanted_outline))]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hard_cases::tests::object;

    #[test]
    fn texel_corners_are_exact_under_a_vertical_light() {
        let down = DirectionalLight {
            direction: Vec3::NEG_Y,
        };
        let (scene, _) = texel_blockers(down);
        let m = down.view_proj(&scene.bounds()).as_dmat4();
        assert_eq!(scene.bounds(), aabb([-2.0, 0.0, -2.0], [2.0, 0.5, 2.0]));
        let blockers = object(&scene, "texel-aligned");
        for p in blockers
            .indices
            .iter()
            .map(|&i| blockers.positions[i as usize])
        {
            let t = (m.project_point3(p.as_dvec3()).truncate() * 0.5 + 0.5) * f64::from(TEXEL_MAP);
            assert_eq!(t, t.round(), "{p} projects to {t}");
        }
        let (slanted, _) = texel_blockers(DirectionalLight::slanted());
        assert_eq!(slanted.bounds(), scene.bounds());
    }
}
