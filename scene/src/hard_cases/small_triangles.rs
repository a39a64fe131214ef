//! The **small triangles** family: sub-texel, needle and zero-area triangles.

use glam::{DVec3, Vec3};

use super::{
    add_grid, case, circle, ground, look, rectangle, rounded, with, Check, Family, HardCase,
    MapSpec, Solid,
};
use crate::{DirectionalLight, MeshBuilder, SplitMix64};

/// The cases of the `small-triangles` family, in table order.
pub(super) fn small_triangles() -> Vec<HardCase> {
    let light = DirectionalLight::slanted().direction;
    let camera = Some(look(Vec3::new(0.9, 1.5, 1.9), Vec3::new(0.2, 0.25, 0.0)));
    // Ground of 4 m on a 128 map: texels of 1/32 m.
    let texel = 4.0 / 128.0;

    let mut fine = MeshBuilder::new();
    add_grid(
        &mut fine,
        DVec3::new(-0.25, 0.6, 0.25),
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -0.5),
        48,
        48,
    );

    let mut rng = SplitMix64::new(0xd057);
    let mut dust = MeshBuilder::new();
    for _ in 0..1500 {
        let c = DVec3::new(
            f64::from(rng.uniform_f32(-1.0, 1.0)) * 0.5,
            0.3 + f64::from(rng.next_f32()) * 0.5,
            f64::from(rng.uniform_f32(-1.0, 1.0)) * 0.5,
        );
        let size = texel * (0.1 + 0.3 * f64::from(rng.next_f32()));
        let mut corner = || {
            DVec3::new(
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
                f64::from(rng.uniform_f32(-1.0, 1.0)),
            ) * size
        };
        let tri = [c + corner(), c + corner(), c + corner()];
        dust.add_triangle(rounded(tri));
    }

    // Needles: a star of 64 isolated needles 1 m long and 10 µm wide, and a plate cut into 1,000 slivers
    // fanning out from one corner.
    let mut needles = MeshBuilder::new();
    for k in 0..64 {
        let (c, s) = circle(k, 64);
        let dir = DVec3::new(c, 0.0, s);
        let side = DVec3::new(-s, 0.0, c) * 5e-6;
        let hub = DVec3::new(0.0, 0.4, 0.0) + dir * 0.02;
        needles.add_triangle(rounded([
            hub - side,
            hub + dir * 0.5 + side * 0.5,
            hub + side,
        ]));
    }
    let mut slivers = MeshBuilder::new();
    let apex = DVec3::new(-0.5, 0.7, -0.5);
    let rim: Vec<DVec3> = (0..=500)
        .map(|i| DVec3::new(0.5, 0.7, -0.5 + f64::from(i) / 500.0))
        .chain((1..=500).map(|i| DVec3::new(0.5 - f64::from(i) / 500.0, 0.7, 0.5)))
        .collect();
    for pair in rim.windows(2) {
        slivers.add_triangle(rounded([apex, pair[1], pair[0]]));
    }

    // Zero-area triangles inside and next to a plate: collinear ones along its interior edges, ones with
    // repeated vertices, and points.
    let mut zero = MeshBuilder::new();
    add_grid(
        &mut zero,
        DVec3::new(-0.5, 0.6, 0.5),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
        8,
        8,
    );
    let mut degenerate = MeshBuilder::new();
    for i in 0..=8 {
        for j in 0..8 {
            let (u, v0, v1) = (
                -0.5 + f64::from(i) / 8.0,
                -0.5 + f64::from(j) / 8.0,
                -0.5 + f64::from(j + 1) / 8.0,
            );
            let (a, b) = (DVec3::new(u, 0.6, v0), DVec3::new(u, 0.6, v1));
            degenerate.add_triangle(rounded([a, b, (a + b) * 0.5]));
            degenerate.add_triangle(rounded([a, a, b]));
            let (c, d) = (DVec3::new(v0, 0.6, u), DVec3::new(v1, 0.6, u));
            degenerate.add_triangle(rounded([c, (c + d) * 0.5, d]));
            degenerate.add_triangle(rounded([c, c, c]));
        }
    }
    for k in 0..100 {
        let p = DVec3::new(
            f64::from(rng.uniform_f32(-1.0, 1.0)),
            0.2 + f64::from(rng.next_f32()),
            f64::from(rng.uniform_f32(-1.0, 1.0)),
        );
        if k % 2 == 0 {
            degenerate.add_triangle(rounded([p, p, p]));
        } else {
            degenerate.add_triangle(rounded([p, p + DVec3::X * 0.1, p + DVec3::X * 0.3]));
        }
    }

    vec![
        case(
            "sub-texel plate (4,608 triangles)",
            Family::SmallTriangles,
            "A 0.5 m plate of cells a third of a texel wide: no triangle covers a texel centre, \
             so only conservative rasterization finds them.",
            with(ground(4.0), [fine.into_scene("fine plate")]),
            light,
            camera,
            MapSpec::new(128),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-0.25, 0.25],
            0.6,
            [-0.25, 0.25],
        )))]),
        case(
            "sub-texel dust (1,500 triangles)",
            Family::SmallTriangles,
            "1,500 randomly oriented triangles 0.1 to 0.4 texels across, scattered in a 1 m box.",
            with(ground(4.0), [dust.into_scene("dust")]),
            light,
            camera,
            MapSpec::new(128),
        ),
        case(
            "needles (aspect 1e5) and slivers",
            Family::SmallTriangles,
            "64 needles 0.5 m long and 10 µm wide, and a 1 m plate cut into 1,000 slivers fanning \
             out from one corner (aspect up to 1,400).",
            with(
                ground(4.0),
                [needles.into_scene("needles"), slivers.into_scene("slivers")],
            ),
            light,
            camera,
            MapSpec::new(128),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-0.5, 0.5],
            0.7,
            [-0.5, 0.5],
        )))]),
        case(
            "zero-area triangles",
            Family::SmallTriangles,
            "An 8x8 plate with 288 zero-area triangles on its edges (collinear, repeated \
             vertices) and 100 more in the air: rejected by the ray test without NaN/Inf, never a \
             blocker.",
            with(
                ground(4.0),
                [
                    zero.into_scene("plate"),
                    degenerate.into_scene("degenerate"),
                ],
            ),
            light,
            camera,
            MapSpec::new(128),
        )
        .checking(vec![Check::Shadowed(Solid::Polygon(rectangle(
            [-0.5, 0.5],
            0.6,
            [-0.5, 0.5],
        )))]),
    ]
}
