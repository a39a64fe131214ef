//! Where a light reaches, for the plan's "out of reach" decision: the receivers in view (triangles not
//! entirely outside one plane of the camera frustum), and whether a triangle meets a light's range and
//! cone (conservatively: true whenever it does). Pure geometry in f64.

use glam::{DVec3, DVec4, Vec3};
use scene::{Camera, SceneFile};
use std::f64::consts::FRAC_PI_2;

/// The scene's triangles (f64) not entirely outside one plane of the camera frustum.
pub(super) fn receivers_in_view(file: &SceneFile, camera: &Camera, aspect: f32) -> Vec<[DVec3; 3]> {
    let m = camera.proj(aspect).as_dmat4() * camera.view().as_dmat4();
    let (r0, r1, r2, r3) = (m.row(0), m.row(1), m.row(2), m.row(3));
    // Inside: -w <= x <= w, -w <= y <= w, 0 <= z <= w (reversed Z: z > w is nearer than the near plane).
    let planes = [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2];
    (0..file.scene.triangle_count())
        .map(|t| file.scene.triangle(t).map(|v| v.as_dvec3()))
        .filter(|t| !planes.iter().any(|&p| outside_plane(p, t)))
        .collect()
}

/// Whether every vertex of `t` lies strictly on the negative side of the plane `p` (`dot(p, (v, 1))`).
fn outside_plane(p: DVec4, t: &[DVec3; 3]) -> bool {
    t.iter().all(|v| p.dot(v.extend(1.0)) < 0.0)
}

/// Where a spot or point light reaches: a ball of its range, within its cone.
#[derive(Debug, Clone, Copy)]
pub(super) struct Reach {
    pub(super) position: DVec3,
    pub(super) range: Option<f64>,
    pub(super) cone: Option<Cone>,
}

/// A spot light's cone.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cone {
    /// Unit axis.
    pub(super) axis: DVec3,
    /// Half-angle, at most 90°.
    pub(super) half_angle: f64,
    /// A square pyramid holding the cone (for half-angles below 90°).
    pub(super) enclosing: Option<Pyramid>,
}

impl Reach {
    /// Whether `t` may meet the reach: within the range exactly, and, for the cone, neither wholly behind
    /// the light, nor outside the cone's enclosing pyramid, nor with its bounding sphere outside the cone
    /// (conservative: true whenever `t` does meet it).
    pub(super) fn touches(&self, t: &[DVec3; 3]) -> bool {
        if self
            .range
            .is_some_and(|range| closest_point(self.position, t).distance(self.position) > range)
        {
            return false;
        }
        let Some(cone) = self.cone else {
            return true;
        };
        if t.iter().all(|v| (*v - self.position).dot(cone.axis) < 0.0) {
            return false;
        }
        if cone.enclosing.is_some_and(|p| !p.touches(t)) {
            return false;
        }
        let center = (t[0] + t[1] + t[2]) / 3.0;
        let radius = t.iter().map(|v| v.distance(center)).fold(0.0, f64::max);
        let v = center - self.position;
        let along = v.dot(cone.axis);
        let across = (v - cone.axis * along).length();
        let beyond = across.atan2(along) - cone.half_angle;
        let distance = if beyond <= 0.0 {
            0.0
        } else if beyond >= FRAC_PI_2 {
            v.length()
        } else {
            v.length() * beyond.sin()
        };
        distance <= radius
    }
}

/// The point of triangle `t` closest to `p` (Ericson, *Real-Time Collision Detection*, 5.1.5).
fn closest_point(p: DVec3, t: &[DVec3; 3]) -> DVec3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denominator = va + vb + vc;
    if denominator == 0.0 || !denominator.is_finite() {
        // A degenerate triangle: the nearest point of its edges.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(from, to)| closest_on_segment(p, from, to))
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
    }
    a + ab * (vb / denominator) + ac * (vc / denominator)
}

/// The point of the segment from `a` to `b` closest to `p`.
fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let length2 = ab.length_squared();
    if length2 == 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / length2).clamp(0.0, 1.0)
}

/// A square pyramid from `apex` along `forward`, `tan_half` wide along `right` and `up`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pyramid {
    apex: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    tan_half: f64,
}

impl Pyramid {
    /// The pyramid of a perspective view from `apex` along unit `forward` with `up_hint` (not parallel to
    /// `forward`) giving its up, as `Mat4::look_to_rh` orients it.
    pub(super) fn new(apex: Vec3, forward: Vec3, up_hint: Vec3, tan_half: f32) -> Self {
        let right = forward.cross(up_hint).normalize();
        Self {
            apex: apex.as_dvec3(),
            forward: forward.as_dvec3(),
            right: right.as_dvec3(),
            up: right.cross(forward).as_dvec3(),
            tan_half: f64::from(tan_half),
        }
    }

    /// Whether `t` is not entirely outside one of the four side planes, or behind the apex.
    pub(super) fn touches(&self, t: &[DVec3; 3]) -> bool {
        let f = self.forward * self.tan_half;
        let normals = [
            f - self.right,
            f + self.right,
            f - self.up,
            f + self.up,
            self.forward,
        ];
        !normals.iter().any(|n| {
            let plane = n.extend(-n.dot(self.apex));
            outside_plane(plane, t)
        })
    }
}

/// An up direction for a view along `forward`: +Y unless `forward` is within about 1° of ±Y, then +Z.
pub(super) fn up_hint(forward: Vec3) -> Vec3 {
    if forward.y.abs() > 1f32.to_radians().cos() {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_points_on_triangles() {
        let t = [DVec3::ZERO, DVec3::X * 2.0, DVec3::Y * 2.0];
        let cases = [
            (DVec3::new(0.5, 0.5, 3.0), DVec3::new(0.5, 0.5, 0.0)),
            (DVec3::new(-1.0, -1.0, 0.0), DVec3::ZERO),
            (DVec3::new(3.0, -1.0, 1.0), DVec3::X * 2.0),
            (DVec3::new(1.0, -2.0, 0.0), DVec3::X),
            (DVec3::new(-2.0, 1.0, 0.0), DVec3::Y),
            (DVec3::new(2.0, 2.0, 0.0), DVec3::new(1.0, 1.0, 0.0)),
        ];
        for (p, expected) in cases {
            let c = closest_point(p, &t);
            assert!(c.abs_diff_eq(expected, 1e-12), "{p}: {c}");
        }
        // Against a dense sampling of the triangle.
        let mut rng = scene::SplitMix64::new(3);
        for _ in 0..200 {
            let p = DVec3::new(
                rng.uniform_f64(-3.0, 3.0),
                rng.uniform_f64(-3.0, 3.0),
                rng.uniform_f64(-3.0, 3.0),
            );
            let d = closest_point(p, &t).distance(p);
            let mut sampled = f64::INFINITY;
            for i in 0..=100 {
                for j in 0..=(100 - i) {
                    let q = t[1] * (f64::from(i) / 100.0) + t[2] * (f64::from(j) / 100.0);
                    sampled = sampled.min(q.distance(p));
                }
            }
            assert!(
                d <= sampled + 1e-12 && sampled - d < 0.03,
                "{p}: {d} vs {sampled}"
            );
        }
        // Degenerate triangles: a point, and a segment seen from beside its middle.
        let point = [DVec3::ZERO, DVec3::ZERO, DVec3::ZERO];
        assert_eq!(closest_point(DVec3::ONE, &point), DVec3::ZERO);
        let segment = [DVec3::ZERO, DVec3::X * 4.0, DVec3::X * 2.0];
        let c = closest_point(DVec3::new(1.0, 1.0, 0.0), &segment);
        assert!(c.abs_diff_eq(DVec3::X, 1e-12), "{c}");
    }
}
