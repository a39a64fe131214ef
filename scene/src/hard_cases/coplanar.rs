//! The **coplanar** family: overlapping coplanar faces, a decal on the ground and boxes stacked face to
//! face.

use glam::{DVec3, Vec3};

use super::{
    aabb, case, ground, look, plate, rectangle, rounded, solid_box, with, Check, Family, HardCase,
    MapSpec, Solid,
};
use crate::{DirectionalLight, MeshBuilder};

/// The cases of the `coplanar` family, in table order.
pub(super) fn coplanar() -> Vec<HardCase> {
    let light = DirectionalLight::slanted().direction;
    let mut second = MeshBuilder::new();
    // Same plane as the first plate, the other diagonal.
    second.add_quad(rounded([
        DVec3::new(0.6, 0.5, 0.5),
        DVec3::new(0.6, 0.5, -0.3),
        DVec3::new(-0.2, 0.5, -0.3),
        DVec3::new(-0.2, 0.5, 0.5),
    ]));
    let overlapping = with(
        ground(4.0),
        [
            plate("plate", [-0.6, 0.2], 0.5, [-0.5, 0.3]),
            second.into_scene("overlapping plate"),
            plate("decal", [0.8, 1.4], 0.0, [-1.4, -0.8]),
        ],
    );
    let (lower_min, lower_max) = ([-0.5, 0.0, -0.5], [0.5, 0.5, 0.5]);
    let (upper_min, upper_max) = ([-0.25, 0.5, -0.3], [0.35, 0.9, 0.2]);
    let stacked = with(
        ground(4.0),
        [
            solid_box("lower box", lower_min, lower_max),
            solid_box("upper box", upper_min, upper_max),
        ],
    );
    let steep = Vec3::new(0.8, -0.55, 0.35).normalize();
    vec![
        case(
            "overlapping coplanar plates and a decal",
            Family::Coplanar,
            "Two plates in the same plane overlapping over half their area (different diagonals), \
             and a decal quad lying exactly on the ground: no acne on the decal, no leak under \
             the plates.",
            overlapping,
            light,
            Some(look(Vec3::new(1.2, 1.6, 2.4), Vec3::new(0.3, 0.0, -0.2))),
            MapSpec::new(128),
        )
        .checking(vec![
            Check::Shadowed(Solid::Polygon(rectangle([-0.6, 0.2], 0.5, [-0.5, 0.3]))),
            Check::Shadowed(Solid::Polygon(rectangle([-0.2, 0.6], 0.5, [-0.3, 0.5]))),
            Check::Lit(aabb([0.8, -1e-3, -1.4], [1.4, 1e-3, -0.8])),
        ]),
        case(
            "boxes stacked face to face (front faces only)",
            Family::Coplanar,
            "A closed box standing on another, the upper box's bottom face coplanar with the \
             lower box's top face, the lower box's bottom coplanar with the ground: both contact \
             shadows must start at the footprints.",
            stacked,
            steep,
            Some(look(Vec3::new(2.2, 1.8, 2.4), Vec3::new(0.3, 0.3, 0.2))),
            MapSpec {
                front_faces_only: true,
                ..MapSpec::new(128)
            },
        )
        .checking(vec![
            Check::Contact(aabb(lower_min, lower_max)),
            Check::Contact(aabb(upper_min, upper_max)),
        ]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hard_cases::tests::{assert_watertight, object};

    #[test]
    fn stacked_boxes_are_watertight() {
        let cases = coplanar();
        let s = cases[1].scene.as_ref().unwrap();
        assert_watertight(&object(s, "lower box"));
        assert_watertight(&object(s, "upper box"));
    }
}
