//! Which frusta of a light can shade a pixel in view: the plugin records a light's frustum only if the
//! region where receivers in view can lie meets it. Pure: no GPU.
//!
//! The region is the camera frustum, within the scene's bounds when they are known and within the light's
//! range when it has one (a pixel beyond the range is not lit by the light, so its visibility does not
//! matter: the plugin gives it 1). A frustum's pipeline counts every pixel outside its frustum as lit,
//! so a frustum that does not meet the region would write 1 everywhere: skipping it changes nothing.
//!
//! The test is a linear feasibility problem in three dimensions: is the intersection of the camera's six
//! half-spaces, the box (scene bounds ∩ the cube around the range's sphere) and the light frustum's six
//! half-spaces empty? A non-empty bounded intersection has a vertex where three of the planes meet, so the
//! test solves every triple of planes and accepts when one solution satisfies every half-space within a
//! tolerance (f64, a millionth of the box's size). The tolerance errs toward keeping a frustum: a false
//! "meets" costs time, never a wrong pixel. Without a box (unlimited range and unknown bounds) the region is
//! unbounded and every frustum is kept.

use crate::light::Light;
use glam::{DMat4, DVec3, DVec4};

/// Relative tolerance of the half-space tests, in units of the box's diagonal.
const RELATIVE_TOLERANCE: f64 = 1e-6;

/// Where receivers in view can lie: the camera frustum within the scene's bounds (if known).
#[derive(Debug, Clone)]
pub struct ViewVolume {
    camera: Vec<DVec4>,
    bounds: Option<[DVec3; 2]>,
}

impl ViewVolume {
    /// The volume of a camera whose world-to-clip matrix is `view_proj` (Vulkan clip space, reversed or
    /// standard depth, finite or infinite far plane), within `bounds` (min, max) of every receiver if
    /// they are known.
    pub fn new(view_proj: DMat4, bounds: Option<[DVec3; 2]>) -> Self {
        Self {
            camera: clip_planes(view_proj),
            bounds,
        }
    }

    /// Whether the frustum of `light` may hold a receiver in view within `range` of the light's position
    /// (`None`: unlimited range, or a directional light).
    pub fn meets(&self, light: &Light, range: Option<f32>) -> bool {
        let reach = match (light.position(), range) {
            (Some(p), Some(r)) => {
                let r = DVec3::splat(f64::from(r));
                Some([p.as_dvec3() - r, p.as_dvec3() + r])
            }
            _ => None,
        };
        let [lo, hi] = match (self.bounds, reach) {
            (Some([a, b]), Some([c, d])) => [a.max(c), b.min(d)],
            (Some(b), None) | (None, Some(b)) => b,
            (None, None) => return true,
        };
        let diagonal = (hi - lo).length();
        let tolerance = RELATIVE_TOLERANCE * diagonal.max(lo.abs().max(hi.abs()).max_element());
        if lo.cmpgt(hi + DVec3::splat(tolerance)).any() {
            return false;
        }
        let mut planes = box_planes(lo, hi);
        planes.extend(&self.camera);
        // A point light's cube faces cover every direction: only its range bounds it.
        if !matches!(light, Light::Point { .. }) {
            planes.extend(clip_planes(light.view_proj().as_dmat4()));
        }
        // Quick rejection: the whole box outside one plane.
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect();
        let outside = |p: &DVec4| {
            corners
                .iter()
                .all(|c| p.truncate().dot(*c) + p.w < -tolerance)
        };
        if planes[6..].iter().any(outside) {
            return false;
        }
        feasible(&planes, tolerance)
    }
}

/// The six half-spaces `dot(plane, (x, 1)) >= 0` of Vulkan clip space (`-w <= x, y <= w`, `0 <= z <= w`)
/// in the coordinates `m` maps to clip space, with unit normals; planes whose normal vanishes (an
/// infinite far plane) are left out.
fn clip_planes(m: DMat4) -> Vec<DVec4> {
    let (r0, r1, r2, r3) = (m.row(0), m.row(1), m.row(2), m.row(3));
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2]
        .into_iter()
        .filter_map(|p| {
            let n = p.truncate().length();
            (n > 0.0 && n.is_finite()).then(|| p / n)
        })
        .collect()
}

/// The six half-spaces of the box from `lo` to `hi`.
fn box_planes(lo: DVec3, hi: DVec3) -> Vec<DVec4> {
    vec![
        DVec4::new(1.0, 0.0, 0.0, -lo.x),
        DVec4::new(-1.0, 0.0, 0.0, hi.x),
        DVec4::new(0.0, 1.0, 0.0, -lo.y),
        DVec4::new(0.0, -1.0, 0.0, hi.y),
        DVec4::new(0.0, 0.0, 1.0, -lo.z),
        DVec4::new(0.0, 0.0, -1.0, hi.z),
    ]
}

/// Whether the half-spaces (unit normals, including a bounded box) have a common point within
/// `tolerance`: some vertex where three planes meet satisfies them all.
fn feasible(planes: &[DVec4], tolerance: f64) -> bool {
    let inside = |x: DVec3| {
        planes
            .iter()
            .all(|p| p.truncate().dot(x) + p.w >= -tolerance)
    };
    let n = planes.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (planes[i], planes[j], planes[k]);
                let (na, nb, nc) = (a.truncate(), b.truncate(), c.truncate());
                let bc = nb.cross(nc);
                let det = na.dot(bc);
                if det.abs() < 1e-12 {
                    continue;
                }
                // Cramer's rule for n·x = -w of the three planes.
                let x = (bc * -a.w + nc.cross(na) * -b.w + na.cross(nb) * -c.w) / det;
                if x.is_finite() && inside(x) {
                    return true;
                }
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::point_light_faces;
    use glam::{Mat4, Vec3};

    /// A reversed-Z camera with an infinite far plane at `eye` looking at `target`.
    fn camera(eye: Vec3, target: Vec3) -> DMat4 {
        let view = Mat4::look_at_rh(eye, target, Vec3::Y);
        let proj = Mat4::perspective_infinite_reverse_rh(1.0, 16.0 / 9.0, 0.1);
        (proj * view).as_dmat4()
    }

    const ROOM: [DVec3; 2] = [DVec3::new(-10.0, 0.0, -10.0), DVec3::new(10.0, 5.0, 10.0)];

    #[test]
    fn a_camera_looking_down_minus_z_keeps_the_faces_it_sees() {
        let view = ViewVolume::new(
            camera(Vec3::new(0.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0)),
            Some(ROOM),
        );
        // A light behind the camera, near the back wall: its +Z face looks at the wall behind the camera.
        let faces = point_light_faces(Vec3::new(0.0, 2.0, 9.5), Some(3.0));
        let kept: Vec<bool> = faces.iter().map(|f| view.meets(f, Some(3.0))).collect();
        // The view is a wedge in front of the camera, narrower than 45° on each side, that starts half a
        // unit in front of the light: only the -Z face holds part of it.
        assert_eq!(kept, [false, false, false, false, false, true]);
    }

    #[test]
    fn a_light_out_of_range_of_the_view_is_culled_whole() {
        let view = ViewVolume::new(
            camera(Vec3::new(0.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0)),
            Some(ROOM),
        );
        // Behind the camera, with a range that ends before the camera's near plane reaches it.
        let position = Vec3::new(0.0, 2.0, 9.95);
        let faces = point_light_faces(position, Some(0.5));
        assert!(faces.iter().all(|f| !view.meets(f, Some(0.5))));
        // With an unlimited range the face looking into the view is kept.
        let faces = point_light_faces(position, None);
        let kept: Vec<bool> = faces.iter().map(|f| view.meets(f, None)).collect();
        assert_eq!(kept, [false, false, false, false, false, true]);
    }

    #[test]
    fn a_point_light_as_one_cube_is_culled_by_its_range_alone() {
        let view = ViewVolume::new(
            camera(Vec3::new(0.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0)),
            Some(ROOM),
        );
        let cube = |range| Light::Point {
            position: Vec3::new(0.0, 2.0, 9.95),
            range,
        };
        // Behind the camera: kept while some face meets the view, culled once its range ends before it.
        assert!(view.meets(&cube(None), None));
        assert!(view.meets(&cube(Some(3.0)), Some(3.0)));
        assert!(!view.meets(&cube(Some(0.5)), Some(0.5)));
    }

    #[test]
    fn without_a_box_every_frustum_is_kept() {
        let view = ViewVolume::new(camera(Vec3::ZERO, Vec3::NEG_Z), None);
        let faces = point_light_faces(Vec3::new(0.0, 0.0, 100.0), None);
        assert!(faces.iter().all(|f| view.meets(f, None)));
    }

    #[test]
    fn far_from_the_origin_the_test_keeps_what_it_must() {
        let offset = Vec3::new(1e4, 0.0, -1e4);
        let room = [ROOM[0] + offset.as_dvec3(), ROOM[1] + offset.as_dvec3()];
        let view = ViewVolume::new(
            camera(
                Vec3::new(0.0, 2.0, 9.0) + offset,
                Vec3::new(0.0, 2.0, 0.0) + offset,
            ),
            Some(room),
        );
        let faces = point_light_faces(Vec3::new(0.0, 2.0, 0.0) + offset, Some(20.0));
        // A light in the middle of the room the camera looks into: every face holds part of the view
        // (+Z the part between the light and the camera).
        assert!(faces.iter().all(|f| view.meets(f, Some(20.0))));
    }

    #[test]
    fn a_directional_light_is_kept_when_its_box_meets_the_view() {
        let view = ViewVolume::new(
            camera(Vec3::new(0.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0)),
            Some(ROOM),
        );
        let sun = |center: Vec3| Light::Directional {
            direction: Vec3::NEG_Y,
            view_proj: Mat4::orthographic_rh(-1.0, 1.0, -1.0, 1.0, 0.0, 20.0)
                * Mat4::look_to_rh(center, Vec3::NEG_Y, Vec3::Z),
        };
        assert!(view.meets(&sun(Vec3::new(0.0, 10.0, 0.0)), None));
        // A light box far to the side of the room holds no receiver.
        assert!(!view.meets(&sun(Vec3::new(50.0, 10.0, 0.0)), None));
    }
}
