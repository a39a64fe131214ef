//! The **scale** family: the demo scene translated by 1e3, 1e4, 1e5 and scaled by 1e-3 and 1e3, camera
//! and light following.

use glam::Vec3;

use super::{case, Check, Family, HardCase, MapSpec, Overflow, FRAME};
use crate::{procedural_default, Camera, DirectionalLight};

/// Largest number of pixels of a translated copy whose visibility may differ from the original's, for
/// translations by 1e3, 1e4 and 1e5 (0.05%, 0.15% and 0.5% of the frame). The passes work relative to the
/// scene, but the input itself is f32: at 1e5 every vertex and the camera move by up to 3.9 mm when
/// translated (0.05 px at the camera's distance), which flips pixels lying on shadow edges and silhouettes;
/// the exact answer changes with them. Measured on lavapipe: 8, 27 and 91 pixels.
const TRANSLATED_DIFFERING_PIXELS: [usize; 3] = [14, 42, 140];

/// The same for the copies scaled by 1e-3 and 1e3: their rounding is relative (6e-8, 1e-5 px), so no pixel
/// may differ. Measured on lavapipe: 0 and 0.
const SCALED_DIFFERING_PIXELS: usize = 0;

/// The cases of the `scale` family, in table order.
pub(super) fn scale() -> Vec<HardCase> {
    let base = procedural_default();
    let camera = Camera::frame(
        &base.focus_bounds(),
        FRAME.width as f32 / FRAME.height as f32,
    );
    let light = DirectionalLight::slanted().direction;
    let map = MapSpec {
        overflow: Overflow::Allowed,
        ..MapSpec::new(256)
    };
    let same = |max_differing_pixels| {
        vec![Check::SameAs {
            base: "demo scene",
            max_differing_pixels,
        }]
    };
    let description =
        "The demo scene (7,010 triangles: character, fence, foliage, sphere), camera and light \
         following the transform.";
    let mut cases = vec![case(
        "demo scene",
        Family::Scale,
        description,
        base.clone(),
        light,
        Some(camera),
        map,
    )];
    let offset = Vec3::new(1.0, 0.5, -0.75);
    for ((name, t), bound) in [
        ("translated by 1e3", 1e3),
        ("translated by 1e4", 1e4),
        ("translated by 1e5", 1e5),
    ]
    .into_iter()
    .zip(TRANSLATED_DIFFERING_PIXELS)
    {
        let o = offset * t;
        cases.push(
            case(
                name,
                Family::Scale,
                description,
                base.translated(o),
                light,
                Some(Camera {
                    position: camera.position + o,
                    target: camera.target + o,
                    ..camera
                }),
                map,
            )
            .checking(same(bound)),
        );
    }
    for (name, s) in [("scaled by 1e-3", 1e-3), ("scaled by 1e3", 1e3)] {
        cases.push(
            case(
                name,
                Family::Scale,
                description,
                base.scaled(s),
                light,
                Some(Camera {
                    position: camera.position * s,
                    target: camera.target * s,
                    near: camera.near * s,
                    ..camera
                }),
                map,
            )
            .checking(same(SCALED_DIFFERING_PIXELS)),
        );
    }
    cases
}
