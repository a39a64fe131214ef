//! The **contact** family: a box standing on a plane under the grazing family's lights (no
//! peter-panning).

use glam::{DVec3, Vec3};

use super::grazing::GRAZING;
use super::{aabb, case, ground, look, solid_box, with, Check, Family, HardCase, MapSpec};

/// The cases of the `contact` family, in table order.
pub(super) fn contact() -> Vec<HardCase> {
    let (min, max) = ([-0.5, 0.0, -0.5], [0.5, 1.0, 0.5]);
    let scene = with(ground(24.0), [solid_box("box", min, max)]);
    let azimuth = 20f64.to_radians();
    GRAZING
        .into_iter()
        .map(|(_, _, name, degrees)| {
            let theta = degrees.to_radians();
            let travel = DVec3::new(
                theta.sin() * azimuth.cos(),
                -theta.cos(),
                theta.sin() * azimuth.sin(),
            );
            case(
                name,
                Family::Contact,
                "A 1 m box standing on a 24 m ground plane (its bottom face coplanar with the \
                 ground), lit at a grazing angle from the vertical: the contact shadow must start \
                 at the box's footprint.",
                scene.clone(),
                travel.as_vec3(),
                Some(look(Vec3::new(3.0, 1.6, 3.5), Vec3::new(0.9, 0.0, 0.5))),
                MapSpec::new(256),
            )
            .checking(vec![Check::Contact(aabb(min, max))])
        })
        .collect()
}
