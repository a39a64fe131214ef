//! The **frustum border** family: triangles crossing the border and the near and far planes of a light
//! matrix that covers only part of the scene (a fitted matrix encloses every vertex by construction).

use glam::{DVec3, Vec3};

use super::{
    aabb, case, ground, look, plate, rectangle, rounded, with, Check, Family, HardCase, MapSpec,
    Solid,
};
use crate::{DirectionalLight, MeshBuilder};

/// The cases of the `frustum-border` family, in table order.
pub(super) fn frustum_border() -> Vec<HardCase> {
    let light = DirectionalLight::slanted();
    let mut tilted = MeshBuilder::new();
    let tilted_corners = [
        DVec3::new(-0.8, 0.3, 0.5),
        DVec3::new(0.8, 0.3, 0.5),
        DVec3::new(0.0, 5.0, 0.9),
    ];
    tilted.add_triangle(rounded(tilted_corners));
    let mut card = MeshBuilder::new();
    let card_corners = [
        DVec3::new(-0.5, -3.0, 0.0),
        DVec3::new(-0.5, -3.0, 0.4),
        DVec3::new(-0.5, 0.8, 0.4),
        DVec3::new(-0.5, 0.8, 0.0),
    ];
    card.add_quad(rounded(card_corners));
    let scene = with(
        ground(2.0),
        [
            plate("strip along x", [-10.0, 10.0], 0.6, [-0.6, -0.1]),
            plate("strip along z", [0.2, 0.7], 0.9, [-10.0, 10.0]),
            tilted.into_scene("tilted"),
            card.into_scene("card"),
        ],
    );
    let map_box = aabb([-1.0, 0.0, -1.0], [1.0, 1.0, 1.0]);
    vec![HardCase {
        light_view_proj: Some(light.view_proj(&map_box)),
        ..case(
            "beyond the map's border and depth range",
            Family::FrustumBorder,
            "A fitted light matrix encloses every vertex, so this case replaces it by one \
             enclosing only the 2 m ground and heights 0 to 1 m: two 20 m strips cross the map's \
             border, a tilted triangle rises 4 m above its near plane and a card reaches 3 m \
             below its far plane. Receivers are all inside the map; blockers must be kept \
             wherever they overlap it.",
            scene,
            light.direction,
            Some(look(Vec3::new(0.2, 0.45, 2.6), Vec3::new(0.0, 0.0, -0.2))),
            MapSpec::new(128),
        )
        .checking(vec![
            Check::Shadowed(Solid::Polygon(rectangle([-10.0, 10.0], 0.6, [-0.6, -0.1]))),
            Check::Shadowed(Solid::Polygon(rectangle([0.2, 0.7], 0.9, [-10.0, 10.0]))),
            Check::Shadowed(Solid::Polygon(tilted_corners.map(|p| p.as_vec3()).to_vec())),
            Check::Shadowed(Solid::Polygon(card_corners.map(|p| p.as_vec3()).to_vec())),
        ])
    }]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hard_cases::tests::object;

    #[test]
    fn frustum_border_case_crosses_its_map() {
        let c = frustum_border().pop().unwrap();
        let m = c.light_view_proj.unwrap();
        let s = c.scene.unwrap();
        let clip: Vec<Vec3> = s.positions.iter().map(|&p| m.project_point3(p)).collect();
        assert!(clip.iter().any(|p| p.x.abs() > 1.0 || p.y.abs() > 1.0));
        assert!(clip.iter().any(|p| p.z < 0.0));
        assert!(clip.iter().any(|p| p.z > 1.0));
        let ground = object(&s, "ground");
        for &i in &ground.indices {
            let p = m.project_point3(ground.positions[i as usize]);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
        }
    }
}
