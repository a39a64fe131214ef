//! The **overflow** family: entry budgets of 1K to 8K entries in a 128x128 map, which must be passed
//! without writing out of bounds, and the BVH fallback of overflowed texels against far slivers.

use glam::{DVec3, Vec3};

use super::{
    aabb, add_grid, case, circle, ground, look, rounded, with, Check, Family, Frame, HardCase,
    MapSpec, Overflow,
};
use crate::{procedural_default, Aabb, Camera, DirectionalLight, MeshBuilder, Scene, SplitMix64};

/// The cases of the `overflow` family, in table order.
pub(super) fn overflow() -> Vec<HardCase> {
    let scene = procedural_default();
    let frame = Frame {
        width: 161,
        height: 121,
    };
    let camera = Camera::frame(
        &aabb([-3.5, 0.0, -3.5], [3.5, 1.8, 3.5]),
        frame.width as f32 / frame.height as f32,
    );
    let mut cases: Vec<HardCase> = [
        ("entry budget 1K", 1024),
        ("entry budget 2K", 2048),
        ("entry budget 4K", 4096),
        ("entry budget 8K", 8192),
    ]
    .into_iter()
    .map(|(name, budget)| HardCase {
        frame,
        ..case(
            name,
            Family::Overflow,
            "The demo scene in a 128x128 map with an entry budget of 1K to 8K entries and guard \
             words: texels past the capacity; nothing may be written past it and those texels \
             walk the BVH.",
            scene.clone(),
            DirectionalLight::slanted().direction,
            Some(camera),
            MapSpec {
                guard: true,
                overflow: Overflow::Required,
                entry_budget: Some(budget),
                ..MapSpec::new(128)
            },
        )
    })
    .collect();
    let (slivers, lit) = far_slivers();
    cases.push(
        case(
            "BVH fallback vs far slivers",
            Family::Overflow,
            "A lit ground over a buried grid whose lists pass a budget of 1K entries, light straight \
             down, and 1,000 tiny slivers 60 to 100 m away, each along a line through the centre: \
             the texels past the budget walk the BVH, and no sliver may shadow the ground.",
            slivers,
            Vec3::NEG_Y,
            Some(look(Vec3::new(0.6, 1.2, 1.6), Vec3::ZERO)),
            MapSpec {
                guard: true,
                overflow: Overflow::Required,
                entry_budget: Some(1024),
                // The buried grid lies behind every ray origin: culled, its lists would stay empty.
                receiver_culling: false,
                ..MapSpec::new(128)
            },
        )
        .checking(vec![Check::Lit(lit)]),
    );
    cases
}

/// A lit ground whose central texels overflow (a grid buried just under it), and 1,000 slivers 2 to 4 cm
/// long, 60 to 100 m away, each lying along a line through the centre: under the vertical light, every
/// receiver near the centre is within millimetres of some sliver's line, where the sliver's f32 edge
/// functions round to zero. The fallback of overflowed texels (the BVH walk) tests the shadow ray against
/// every sliver whose box it meets.
fn far_slivers() -> (Scene, Aabb) {
    let mut buried = MeshBuilder::new();
    add_grid(
        &mut buried,
        DVec3::new(-0.5, -0.05, 0.5),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
        16,
        16,
    );
    let mut rng = SplitMix64::new(0x511_4e25);
    let mut slivers = MeshBuilder::new();
    for k in 0..1000 {
        let (c, s) = circle(k, 1000);
        let radial = DVec3::new(c, 0.0, s);
        let across = DVec3::new(-s, 0.0, c);
        let r = 60.0 + 40.0 * f64::from(rng.next_f32());
        let p = radial * r + DVec3::Y * (0.05 + 0.5 * f64::from(rng.next_f32()));
        slivers.add_triangle(rounded([
            p,
            p + radial * 0.02 + DVec3::Y * 0.01,
            p + radial * 0.04 + across * 1e-5,
        ]));
    }
    let scene = with(
        ground(4.0),
        [
            buried.into_scene("buried grid"),
            slivers.into_scene("far slivers"),
        ],
    );
    (scene, aabb([-0.5, -1e-3, -0.5], [0.5, 1e-3, 0.5]))
}
