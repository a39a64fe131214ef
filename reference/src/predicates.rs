//! Conservative geometric predicates of the analytic hard-case checks: whether a shadow ray certainly
//! passes through a [`Solid`], and where the contact shadow of a box standing on a plane starts.
//!
//! "Certainly" means with a margin: a ray counts only if every parallel ray within `margin` of it
//! gives the same answer, so that a receiver position known to within `margin` can be judged.

use glam::{DVec2, DVec3};
use scene::hard_cases::Solid;
use scene::Aabb;

/// Whether the ray `p + s * l` (`s > 0`, `l` unit) certainly hits `solid`: it passes through the solid
/// shrunk by `margin`, so that every parallel ray within `margin` of it hits the solid too.
///
/// A polygon seen within about 3° of edge-on (`|cos| < 0.05` between its normal and `l`) is never
/// certainly hit, nor is a polygon of fewer than three vertices.
pub fn certainly_blocked(solid: &Solid, p: DVec3, l: DVec3, margin: f64) -> bool {
    match solid {
        Solid::Ball { center, radius } => {
            let r = f64::from(*radius) - margin;
            let oc = center.as_dvec3() - p;
            let along = oc.dot(l);
            let d2 = oc.length_squared() - along * along;
            r > 0.0 && along > 0.0 && d2 < r * r && along - (r * r - d2).sqrt() > 0.0
        }
        Solid::Box(b) => {
            let (lo, hi) = (b.min.as_dvec3() + margin, b.max.as_dvec3() - margin);
            let (mut enter, mut exit) = (0.0f64, f64::INFINITY);
            for axis in 0..3 {
                if lo[axis] > hi[axis] {
                    return false;
                }
                if l[axis] == 0.0 {
                    if p[axis] < lo[axis] || p[axis] > hi[axis] {
                        return false;
                    }
                } else {
                    let a = (lo[axis] - p[axis]) / l[axis];
                    let c = (hi[axis] - p[axis]) / l[axis];
                    enter = enter.max(a.min(c));
                    exit = exit.min(a.max(c));
                }
            }
            enter > 0.0 && enter < exit
        }
        Solid::Polygon(vertices) => {
            let v: Vec<DVec3> = vertices.iter().map(|p| p.as_dvec3()).collect();
            if v.len() < 3 {
                return false;
            }
            // Newell's normal.
            let normal = v
                .iter()
                .zip(v.iter().cycle().skip(1))
                .fold(DVec3::ZERO, |n, (a, b)| n + a.cross(*b))
                .normalize_or_zero();
            let cos = normal.dot(l);
            if cos.abs() < 0.05 {
                return false;
            }
            let s = normal.dot(v[0] - p) / cos;
            if s <= margin {
                return false;
            }
            let x = p + l * s;
            // A parallel ray moved by less than `margin` crosses the plane less than this far from x.
            let in_plane = margin * (1.0 + 1.0 / cos.abs());
            v.iter().zip(v.iter().cycle().skip(1)).all(|(a, b)| {
                let inward = normal.cross(*b - *a).normalize_or_zero();
                inward != DVec3::ZERO && (x - *a).dot(inward) >= in_plane
            })
        }
    }
}

/// Where the contact shadow of the box `b` should start for the receiver `p`, if `p` certainly lies in
/// it: `b` stands on a horizontal receiver plane at `b.min.y` (where `p` lies), and the ray `p + s * l`
/// (`s >= 0`, `l` towards an elevated light, not vertical) enters the box's footprint shrunk by
/// `margin` below the box's top lowered by `margin`. The start is the point of the receiver plane on
/// the footprint's edge where that ray enters the (unshrunk) footprint, or `p` itself when `p` lies
/// on the footprint within `margin` of its edge.
///
/// `None` when the ray misses the shrunk box, or starts inside or beyond it, when `l` points
/// downwards or straight up, or when the shrunk footprint is empty.
pub fn contact_shadow_start(b: &Aabb, p: DVec3, l: DVec3, margin: f64) -> Option<DVec3> {
    let (min, max) = (b.min.as_dvec3(), b.max.as_dvec3());
    let horizontal = DVec2::new(l.x, l.z);
    if l.y <= 0.0 || horizontal == DVec2::ZERO {
        return None;
    }
    let start = DVec2::new(p.x, p.z);
    let inner = slab_2d(
        start,
        horizontal,
        DVec2::new(min.x + margin, min.z + margin),
        DVec2::new(max.x - margin, max.z - margin),
    );
    let (enter, _) = inner.filter(|&(enter, _)| enter >= 0.0)?;
    if p.y + enter * l.y >= max.y - margin {
        return None;
    }
    let outer = slab_2d(
        start,
        horizontal,
        DVec2::new(min.x, min.z),
        DVec2::new(max.x, max.z),
    );
    let edge = outer.map_or(enter, |(e, _)| e.max(0.0));
    Some(DVec3::new(p.x + edge * l.x, p.y, p.z + edge * l.z))
}

/// Entry and exit parameters of the 2D line `start + s * dir` through the box `[lo, hi]`, if it crosses
/// it (at any `s`, also negative).
fn slab_2d(start: DVec2, dir: DVec2, lo: DVec2, hi: DVec2) -> Option<(f64, f64)> {
    let (mut enter, mut exit) = (f64::NEG_INFINITY, f64::INFINITY);
    for axis in 0..2 {
        if lo[axis] > hi[axis] {
            return None;
        }
        if dir[axis] == 0.0 {
            if start[axis] < lo[axis] || start[axis] > hi[axis] {
                return None;
            }
        } else {
            let a = (lo[axis] - start[axis]) / dir[axis];
            let b = (hi[axis] - start[axis]) / dir[axis];
            enter = enter.max(a.min(b));
            exit = exit.min(a.max(b));
        }
    }
    (enter < exit).then_some((enter, exit))
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn blocked_rays() {
        let up = DVec3::Y;
        let square = Solid::Polygon(vec![
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ]);
        assert!(certainly_blocked(&square, DVec3::ZERO, up, 0.1));
        assert!(!certainly_blocked(
            &square,
            DVec3::new(0.95, 0.0, 0.0),
            up,
            0.1
        ));
        assert!(!certainly_blocked(
            &square,
            DVec3::new(0.0, 2.0, 0.0),
            up,
            0.1
        ));
        let ball = Solid::Ball {
            center: Vec3::new(0.0, 2.0, 0.0),
            radius: 1.0,
        };
        assert!(certainly_blocked(&ball, DVec3::new(0.5, 0.0, 0.0), up, 0.1));
        assert!(!certainly_blocked(
            &ball,
            DVec3::new(0.95, 0.0, 0.0),
            up,
            0.1
        ));
        assert!(!certainly_blocked(
            &ball,
            DVec3::new(0.0, 4.0, 0.0),
            up,
            0.1
        ));
        let cube = Solid::Box(Aabb {
            min: Vec3::new(-1.0, 1.0, -1.0),
            max: Vec3::new(1.0, 2.0, 1.0),
        });
        assert!(certainly_blocked(
            &cube,
            DVec3::new(0.5, 0.0, -0.5),
            up,
            0.1
        ));
        assert!(!certainly_blocked(
            &cube,
            DVec3::new(0.95, 0.0, 0.0),
            up,
            0.1
        ));
        let slanted = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!(certainly_blocked(
            &cube,
            DVec3::new(-1.5, 0.0, 0.0),
            slanted,
            0.1
        ));
        assert!(!certainly_blocked(
            &cube,
            DVec3::new(-0.5, 2.5, 0.0),
            slanted,
            0.1
        ));
    }

    #[test]
    fn edge_on_and_degenerate_polygons_never_block() {
        let up = DVec3::Y;
        let wall = Solid::Polygon(vec![
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 2.0, 1.0),
            Vec3::new(0.0, 2.0, -1.0),
        ]);
        assert!(!certainly_blocked(&wall, DVec3::ZERO, up, 0.0));
        let segment = Solid::Polygon(vec![Vec3::new(-1.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)]);
        assert!(!certainly_blocked(&segment, DVec3::ZERO, up, 0.0));
    }

    #[test]
    fn slabs() {
        let r = slab_2d(
            DVec2::ZERO,
            DVec2::X,
            DVec2::new(1.0, -1.0),
            DVec2::new(2.0, 1.0),
        );
        assert_eq!(r, Some((1.0, 2.0)));
        assert_eq!(
            slab_2d(
                DVec2::ZERO,
                DVec2::X,
                DVec2::new(1.0, 0.5),
                DVec2::new(2.0, 1.0)
            ),
            None
        );
        // Behind the start counts too.
        assert_eq!(
            slab_2d(
                DVec2::new(3.0, 0.0),
                DVec2::X,
                DVec2::new(1.0, -1.0),
                DVec2::new(2.0, 1.0)
            ),
            Some((-2.0, -1.0))
        );
    }

    #[test]
    fn contact_shadows_start_at_the_footprint() {
        // A unit box on the ground, light from +x at 45° (rays towards +x and up).
        let b = Aabb {
            min: Vec3::new(0.0, 0.0, 0.0),
            max: Vec3::new(1.0, 1.0, 1.0),
        };
        let l = DVec3::new(1.0, 1.0, 0.0).normalize();
        // Just left of the box, inside the shadow: starts at the footprint edge x = 0.
        let start = contact_shadow_start(&b, DVec3::new(-0.2, 0.0, 0.5), l, 0.05).unwrap();
        assert!(
            start.abs_diff_eq(DVec3::new(0.0, 0.0, 0.5), 1e-12),
            "{start}"
        );
        // On the footprint within the margin of its edge: starts at the receiver itself.
        let rim = DVec3::new(0.02, 0.0, 0.5);
        assert_eq!(contact_shadow_start(&b, rim, l, 0.05), Some(rim));
        // Deeper under the box: its ray starts inside the shrunk box.
        let under = DVec3::new(0.5, 0.0, 0.5);
        assert_eq!(contact_shadow_start(&b, under, l, 0.05), None);
        // Too far out: the ray passes over the box's top lowered by the margin.
        assert_eq!(
            contact_shadow_start(&b, DVec3::new(-0.97, 0.0, 0.5), l, 0.05),
            None
        );
        // Beside the footprint, within the margin of its side: not certain.
        assert_eq!(
            contact_shadow_start(&b, DVec3::new(-0.2, 0.0, 0.97), l, 0.05),
            None
        );
        // Behind the box (the ray leaves it) and lights that are vertical or below the horizon.
        assert_eq!(
            contact_shadow_start(&b, DVec3::new(1.5, 0.0, 0.5), l, 0.05),
            None
        );
        assert_eq!(contact_shadow_start(&b, under, DVec3::Y, 0.05), None);
        assert_eq!(contact_shadow_start(&b, under, -l, 0.05), None);
    }
}
