//! Ray/triangle and line/segment primitives in `f64`.

use glam::DVec3;

use crate::exact::has_zero_area;

/// Watertight ray/triangle intersection after Woop, Benthin and Wald,
/// "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013, evaluated in `f64`
/// without epsilons and two-sided.
///
/// The triangle is translated to the ray origin and sheared so that the ray
/// becomes the +z axis (the dominant axis of `dir` becomes z). The three 2D edge
/// functions `U`, `V`, `W` are evaluated from the sheared vertices, so an edge
/// shared by two triangles is evaluated with identical (or exactly negated)
/// arithmetic in both and a ray can never slip between them.
///
/// Returns `Some((t, [u, v, w]))` when the line `origin + t * dir` crosses the
/// closed triangle (points on edges and vertices count as inside), where `t` is the
/// ray parameter (any sign; callers filter) and `u`, `v`, `w` are the barycentric
/// weights of `tri[0]`, `tri[1]`, `tri[2]` of the crossing point (summing to 1 up
/// to rounding). Returns `None` when the line misses, when the triangle is
/// degenerate as seen along the ray (determinant exactly 0), when it has exactly
/// zero area in 3D (decided with exact predicates, since rounding of the sheared
/// coordinates can make the determinant of a degenerate triangle non-zero), when
/// `dir` is zero or non-finite, or when the result would not be finite; the result
/// never contains NaN.
pub fn intersect_watertight(
    origin: DVec3,
    dir: DVec3,
    tri: &[DVec3; 3],
) -> Option<(f64, [f64; 3])> {
    let abs = dir.abs();
    let kz = if abs.x >= abs.y && abs.x >= abs.z {
        0
    } else if abs.y >= abs.z {
        1
    } else {
        2
    };
    if abs[kz] == 0.0 || !abs[kz].is_finite() {
        return None;
    }
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if dir[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let shear_x = dir[kx] / dir[kz];
    let shear_y = dir[ky] / dir[kz];
    let shear_z = 1.0 / dir[kz];

    let a = tri[0] - origin;
    let b = tri[1] - origin;
    let c = tri[2] - origin;
    let (ax, ay) = (a[kx] - shear_x * a[kz], a[ky] - shear_y * a[kz]);
    let (bx, by) = (b[kx] - shear_x * b[kz], b[ky] - shear_y * b[kz]);
    let (cx, cy) = (c[kx] - shear_x * c[kz], c[ky] - shear_y * c[kz]);

    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || has_zero_area(tri) {
        return None;
    }
    let t_scaled = u * (shear_z * a[kz]) + v * (shear_z * b[kz]) + w * (shear_z * c[kz]);
    let t = t_scaled / det;
    let bary = [u / det, v / det, w / det];
    (t.is_finite() && bary.iter().all(|x| x.is_finite())).then_some((t, bary))
}

/// Closest approach between the infinite line `origin + s * dir` and the segment
/// `[a, b]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Approach {
    /// Shortest distance between the line and the segment.
    pub distance: f64,
    /// Smallest line parameter `s` at which the distance is attained.
    pub s_min: f64,
    /// Largest line parameter `s` at which the distance is attained (differs from
    /// `s_min` only when the segment is parallel to the line).
    pub s_max: f64,
}

/// Computes the [`Approach`] of the line `origin + s * dir` to the segment `[a, b]`.
///
/// With a zero `dir` the "line" is the point `origin` and the parameters are 0.
pub(crate) fn line_segment_approach(origin: DVec3, dir: DVec3, a: DVec3, b: DVec3) -> Approach {
    let dd = dir.length_squared();
    let edge = b - a;
    let to_a = a - origin;
    if dd == 0.0 {
        let ee = edge.length_squared();
        let u = if ee > 0.0 {
            (-to_a.dot(edge) / ee).clamp(0.0, 1.0)
        } else {
            0.0
        };
        return Approach {
            distance: (to_a + edge * u).length(),
            s_min: 0.0,
            s_max: 0.0,
        };
    }
    // Components perpendicular to the line; the squared distance from the line
    // to a + u * edge is |perp(to_a) + u * perp(edge)|^2, a convex quadratic in u.
    let perp = |v: DVec3| v - dir * (v.dot(dir) / dd);
    let to_a_perp = perp(to_a);
    let edge_perp = perp(edge);
    let ee = edge_perp.length_squared();
    let length = dd.sqrt();
    let distance_of = |p: DVec3| p.cross(dir).length() / length;
    let param_of = |p: DVec3| p.dot(dir) / dd;
    if ee == 0.0 {
        // Segment parallel to the line (or a point): every point is closest.
        let (sa, sb) = (param_of(to_a), param_of(to_a + edge));
        return Approach {
            distance: distance_of(to_a),
            s_min: sa.min(sb),
            s_max: sa.max(sb),
        };
    }
    let u = (-to_a_perp.dot(edge_perp) / ee).clamp(0.0, 1.0);
    let closest = to_a + edge * u;
    let s = param_of(closest);
    Approach {
        distance: distance_of(closest),
        s_min: s,
        s_max: s,
    }
}

/// Shortest distance between the infinite line `{origin + t * dir}` and the closed
/// segment `[a, b]`. `dir` need not be unit length; a zero `dir` gives the distance
/// from the point `origin` to the segment.
pub fn line_segment_distance(origin: DVec3, dir: DVec3, a: DVec3, b: DVec3) -> f64 {
    line_segment_approach(origin, dir, a, b).distance
}
