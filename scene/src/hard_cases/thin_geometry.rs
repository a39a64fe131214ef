//! The **thin geometry** family: thin closed plates and zero-thickness foliage cards.

use std::f64::consts::TAU;

use glam::{DQuat, DVec3, Vec3};

use super::{
    add_lattice_box, case, ground, look, rectangle, rounded, solid_box, with, Check, Family,
    HardCase, MapSpec, Solid,
};
use crate::{DirectionalLight, MeshBuilder, SplitMix64};

/// The cases of the `thin-geometry` family, in table order.
pub(super) fn thin_geometry() -> Vec<HardCase> {
    let light = DirectionalLight::slanted().direction;
    let mut slats = MeshBuilder::new();
    for k in 0..6 {
        let x = 0.7 + 0.1 * f64::from(k);
        add_lattice_box(
            &mut slats,
            DVec3::new(x, 0.0, -0.4),
            DVec3::new(x + 0.002, 0.8, 0.4),
            [1, 1, 1],
        );
    }
    let thin = with(
        ground(4.0),
        [
            solid_box("floating plate", [-0.5, 0.6, -0.5], [0.5, 0.6001, 0.5]),
            slats.into_scene("slats"),
            solid_box("plate on the ground", [-1.2, 0.0, 0.6], [-0.6, 5e-4, 1.2]),
        ],
    );
    let mut checks = vec![Check::Shadowed(Solid::Polygon(rectangle(
        [-0.5, 0.5],
        0.60005,
        [-0.5, 0.5],
    )))];
    for k in 0..6 {
        let x = 0.701 + 0.1 * f64::from(k);
        checks.push(Check::Shadowed(Solid::Polygon(
            [(-0.4, 0.0), (0.4, 0.0), (0.4, 0.8), (-0.4, 0.8)]
                .map(|(z, y)| DVec3::new(x, y, z).as_vec3())
                .to_vec(),
        )));
    }

    let mut rng = SplitMix64::new(0xf011a6e);
    let mut cards = MeshBuilder::new();
    let mut card_checks = Vec::new();
    for k in 0..5 {
        let base = DVec3::new(
            -1.0 + 0.5 * f64::from(k),
            0.0,
            -0.6 + 0.3 * f64::from(k % 2),
        );
        let yaw = f64::from(rng.next_f32()) * std::f64::consts::PI;
        for turn in [0.0, std::f64::consts::FRAC_PI_2] {
            let across = DQuat::from_rotation_y(yaw + turn) * DVec3::X * 0.3;
            let corners = [
                base - across + DVec3::Y * 0.05,
                base + across + DVec3::Y * 0.05,
                base + across + DVec3::Y * 0.85,
                base - across + DVec3::Y * 0.85,
            ];
            cards.add_quad(rounded(corners));
            // Cards seen nearly edge-on by the light cast slivers of shadow: too thin to judge.
            let normal = (corners[1] - corners[0])
                .cross(corners[3] - corners[0])
                .normalize();
            if normal.dot(light.as_dvec3()).abs() > 0.3 {
                card_checks.push(Check::Shadowed(Solid::Polygon(
                    corners.map(|p| p.as_vec3()).to_vec(),
                )));
            }
        }
    }
    for _ in 0..300 {
        let c = DVec3::new(0.9, 0.6, 0.7)
            + DVec3::new(
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
            ) * 0.3;
        let q = DQuat::from_euler(
            glam::EulerRot::YXZ,
            f64::from(rng.next_f32()) * TAU,
            f64::from(rng.uniform_f32(-1.0, 1.0)),
            f64::from(rng.uniform_f32(-1.0, 1.0)) * 3.0,
        );
        cards.add_triangle(rounded([
            c,
            c + q * DVec3::new(0.12, 0.0, 0.03),
            c + q * DVec3::new(0.05, 0.0, 0.06),
        ]));
    }
    let foliage = with(ground(4.0), [cards.into_scene("cards and leaves")]);
    vec![
        case(
            "thin closed plates",
            Family::ThinGeometry,
            "A floating closed plate 0.1 mm thick, six 2 mm slats standing on the ground and a \
             0.5 mm plate lying on it, all thinner than the shadow ray's origin offset.",
            thin,
            light,
            Some(look(Vec3::new(1.0, 1.7, 2.6), Vec3::new(0.3, 0.2, 0.0))),
            MapSpec::new(128),
        )
        .checking(checks),
        case(
            "foliage cards",
            Family::ThinGeometry,
            "Five pairs of crossed zero-thickness cards intersecting each other, and 300 randomly \
             oriented leaf triangles, both faces stored.",
            foliage,
            light,
            Some(look(Vec3::new(0.6, 3.2, 1.8), Vec3::new(0.3, 0.0, -0.3))),
            MapSpec::new(128),
        )
        .checking(card_checks),
    ]
}
