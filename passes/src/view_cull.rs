//! Which frusta of a light can change a pixel in view: the plugin records a light's frustum only if some
//! caster may shadow a receiver in view that the frustum shades. Pure: no GPU.
//!
//! A frustum's pipeline counts every pixel whose ray origin lies outside the frustum as lit, and every pixel
//! beyond the light's range may be given 1 (the light does not reach it). So a frustum may be skipped,
//! writing 1 everywhere, when no ray origin of a receiver in view, inside the frustum and within the range,
//! can have its segments to the light blocked by a caster. The region of those ray origins is known on the
//! CPU only through what bounds it: the camera frustum (widened by [`VIEW_WIDENING`] to hold every ray
//! origin, which lies within its small offset of a point the camera sees), the frustum's own side planes
//! (widened by [`FRUSTUM_WIDENING`] against the rounding of the GPU's assignment of origins to frusta;
//! none for a point light's one cube map, which covers every direction) and the box around the range's
//! sphere. Receivers are not bounded by the casters: engines leave floors, terrain or decals out of the
//! casters, and a caster outside the camera's view shadows receivers inside it.
//!
//! The test therefore has two steps:
//! 1. The region `R` of ray origins (an intersection of half-spaces) is empty: nothing to shade.
//! 2. Given the bounds of every caster and the light's size ([`Casters`]), the set `U` of points whose
//!    segments to the light may meet those bounds (the bounds swept away from the light: their shadow
//!    volume) misses `R`. For a spot or point light `U = {L + s (q - L) : q in C', s >= 1}` with `C'` the
//!    casters' box grown by the emitter's radius (a segment from `x` to a point `e` of the emitter that
//!    meets the box passes within that radius of the segment from `x` to `L`); for a directional light
//!    `U = C + K`, `K` the cone of the light's directions of travel (for a sized sun, the square cone
//!    around the disc's). `U` is convex: its half-spaces are the faces of the box that face the light and
//!    the planes through the light (or along the cone) and the box's silhouette edges.
//!
//! Both are linear feasibility problems in three dimensions. `R` never holds a line (the camera frustum is
//! pointed), so `R`, and `R ∩ U`, are empty exactly when no point where three of their planes meet
//! satisfies every half-space. The test solves every triple (f64) and accepts a point within a tolerance:
//! absolute, a ten-millionth of the scene's scale, and for the half-spaces of `U` that run along rays
//! (planes through the light or along the cone, known to within rounding) also growing with the distance
//! from the light or the box, by more than their rounding; plus the solve's own error, which grows as the
//! three planes approach a common direction. Each tolerance errs toward keeping a frustum:
//! a false "may shadow" costs time, never a wrong pixel. Quick checks decide most frusta first (a vertex
//! of `R` in `U`, a caster corner in `R`, or one plane with all of `R`, or all of `U`, strictly outside).
//! Without the casters' bounds only step 1 culls.

use crate::light::Light;
use glam::{DMat4, DVec3, DVec4};

/// The camera frustum's clip-space bounds are widened by this fraction of `w` (`|x|, |y| <= (1 + f) w`, the
/// near plane moved towards the camera alike): every ray origin of a receiver the camera sees lies inside.
/// An origin is offset from its receiver by a 64th of a pixel's footprint, a few ulps of its coordinates and
/// the depth format's precision there: far below 1% of the distance for float depth, and for fixed-point
/// depth wherever its precision is within 1% of the distance.
pub const VIEW_WIDENING: f64 = 1e-2;

/// A light frustum's side planes are widened by this fraction of `w`: the GPU assigns ray origins to frusta
/// in f32, within rounding of the exact planes.
pub const FRUSTUM_WIDENING: f64 = 1e-3;

/// Absolute tolerance of the half-space tests, in units of the scene's scale (the largest coordinate or
/// extent of the camera, the light, its range and the casters' box).
const RELATIVE_TOLERANCE: f64 = 1e-7;

/// Tolerance, per unit of distance from the light or the casters' box, of the half-spaces of the shadow
/// volume that run along its rays: their planes hold those rays to within rounding (about 1e-16 per unit).
const RAY_SLOPE: f64 = 1e-12;

/// A shadow volume whose rays spread wider than this from the light's direction (a sun of angular radius
/// near 90°), or whose light sits this close to the casters' box relative to its size, is not used to
/// cull: its half-spaces' tolerances would grow without bound.
const MAX_SLOPE: f64 = 1e-6;

/// What may shadow a receiver: the bounds of every shadow caster, and the size of the light the shadows
/// are traced for (a segment from a receiver ends anywhere on the light's emitter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Casters {
    /// World-space bounds (min, max) of every triangle that casts shadows this frame.
    pub bounds: [DVec3; 2],
    /// A directional light's angular radius (radians), or a spot or point light's emitter radius (world
    /// units); 0 for a light traced as a point or a direction.
    pub light_size: f64,
}

/// The camera's view: where the ray origins of the receivers it sees can lie.
#[derive(Debug, Clone)]
pub struct ViewVolume {
    /// The camera frustum's half-spaces, widened by [`VIEW_WIDENING`].
    camera: Vec<DVec4>,
    /// The camera's position, for the scale of the tolerances.
    eye: DVec3,
}

/// A half-space `dot(plane, (x, 1)) >= 0` tested with a tolerance that may grow with the distance from an
/// anchor point.
#[derive(Debug, Clone, Copy)]
struct HalfSpace {
    plane: DVec4,
    slack: f64,
    slope: f64,
    anchor: DVec3,
}

impl HalfSpace {
    /// A half-space with a fixed tolerance.
    fn fixed(plane: DVec4, slack: f64) -> Self {
        Self {
            plane,
            slack,
            slope: 0.0,
            anchor: DVec3::ZERO,
        }
    }

    /// The plane's value at `x`: its signed distance (unit normals), positive inside.
    fn value(&self, x: DVec3) -> f64 {
        self.plane.truncate().dot(x) + self.plane.w
    }

    /// How far outside `x` may lie and still count as inside.
    fn tolerance(&self, x: DVec3) -> f64 {
        if self.slope == 0.0 {
            self.slack
        } else {
            self.slack + self.slope * (x - self.anchor).length()
        }
    }

    /// Whether `x` lies inside, within the tolerance.
    fn holds(&self, x: DVec3) -> bool {
        self.value(x) >= -self.tolerance(x)
    }

    /// Whether `x` lies outside by more than the tolerance.
    fn excludes(&self, x: DVec3) -> bool {
        self.value(x) < -self.tolerance(x)
    }
}

impl ViewVolume {
    /// The view of a camera at `eye` whose world-to-clip matrix is `view_proj` (Vulkan clip space, reversed
    /// or standard depth, finite or infinite far plane).
    pub fn new(view_proj: DMat4, eye: DVec3) -> Self {
        let mut camera = side_planes(view_proj, VIEW_WIDENING);
        camera.extend(depth_planes(view_proj, VIEW_WIDENING));
        Self { camera, eye }
    }

    /// Whether frustum `light` may change a pixel in view: whether a receiver in view within `range` of the
    /// light (`None`: unlimited, or a directional light) lies in the frustum and, when the `casters` are
    /// known, whether some caster within their bounds may block one of its segments to the light.
    pub fn may_shadow(&self, light: &Light, range: Option<f32>, casters: Option<&Casters>) -> bool {
        let position = light.position().map(|p| p.as_dvec3());
        let reach = match (position, range) {
            (Some(p), Some(r)) => {
                let r = DVec3::splat(f64::from(r) * (1.0 + VIEW_WIDENING));
                Some([p - r, p + r])
            }
            _ => None,
        };
        // Sides of the light's frustum (a point light's one cube map covers every direction: only its
        // range bounds it).
        let sides = match light {
            Light::Point { .. } => Vec::new(),
            _ => side_planes(light.view_proj().as_dmat4(), FRUSTUM_WIDENING),
        };
        let mut planes = self.camera.clone();
        planes.extend(sides);
        if let Some([lo, hi]) = reach {
            planes.extend(box_planes(lo, hi));
        }
        let mut scale = self.eye.abs().max_element();
        for p in position.iter().chain(reach.iter().flatten()) {
            scale = scale.max(p.abs().max_element());
        }
        for p in &planes {
            scale = scale.max(p.w.abs());
        }
        if let Some(c) = casters {
            let grown = c.light_size.max(0.0);
            let [lo, hi] = c.bounds;
            scale = scale
                .max(lo.abs().max_element() + grown)
                .max(hi.abs().max_element() + grown)
                .max((hi - lo).length());
        }
        if !(scale.is_finite() && scale > 0.0) {
            return true;
        }
        let tolerance = RELATIVE_TOLERANCE * scale;
        let region: Vec<HalfSpace> = planes
            .into_iter()
            .map(|p| HalfSpace::fixed(p, tolerance))
            .collect();
        let region_vertices = vertices(&region);
        if region_vertices.is_empty() {
            return false;
        }
        let Some(casters) = casters else {
            return true;
        };
        let Some(shadow) = ShadowVolume::new(light, casters, tolerance) else {
            return true;
        };
        // A vertex of the region in the shadow volume, or a corner of the casters' box in the region: met.
        if region_vertices
            .iter()
            .any(|&v| shadow.half_spaces.iter().all(|h| h.holds(v)))
            || shadow
                .corners
                .iter()
                .any(|&c| region.iter().all(|h| h.holds(c)))
        {
            return true;
        }
        // One half-space of the shadow volume that the whole region (its vertices and its rays) leaves.
        let rays = recession_rays(&region);
        if shadow.half_spaces.iter().any(|h| {
            region_vertices.iter().all(|&v| h.excludes(v))
                && rays.iter().all(|r| h.plane.truncate().dot(*r) < -h.slope)
        }) {
            return false;
        }
        // One half-space of the region that the whole shadow volume (its corners and rays) leaves.
        if region.iter().any(|h| {
            shadow.corners.iter().all(|&c| h.excludes(c))
                && shadow.rays.iter().all(|r| h.plane.truncate().dot(*r) < 0.0)
        }) {
            return false;
        }
        let mut all = region;
        all.extend(shadow.half_spaces);
        has_vertex(&all)
    }
}

/// The points whose segments to a light may meet the casters' box, as half-spaces, with the generators
/// that span it (the box's corners and its rays away from the light) for the quick tests.
struct ShadowVolume {
    half_spaces: Vec<HalfSpace>,
    corners: [DVec3; 8],
    /// Directions in which the volume is unbounded (unit vectors): from the light through the box's
    /// corners, or the light's directions of travel.
    rays: Vec<DVec3>,
}

impl ShadowVolume {
    /// The shadow volume of `casters` for `light` (`None`: the whole space, or a volume too ill-conditioned
    /// to cull by; see [`MAX_SLOPE`]).
    fn new(light: &Light, casters: &Casters, tolerance: f64) -> Option<Self> {
        let size = casters.light_size.max(0.0);
        match light.position() {
            Some(position) => Self::of_point(position.as_dvec3(), casters.bounds, size, tolerance),
            None => Self::of_direction(
                light.direction().as_dvec3(),
                casters.bounds,
                size,
                tolerance,
            ),
        }
    }

    /// The volume behind the box `bounds`, grown by `radius`, seen from `light`: `L + s (q - L)`, `s >= 1`.
    fn of_point(light: DVec3, bounds: [DVec3; 2], radius: f64, tolerance: f64) -> Option<Self> {
        let [lo, hi] = bounds;
        if lo.cmpgt(hi).any() {
            return None;
        }
        let (lo, hi) = (lo - DVec3::splat(radius), hi + DVec3::splat(radius));
        let corners = box_corners(lo, hi);
        // The light within (or on) the box: every direction from it meets the box.
        let inside = light.cmpge(lo - tolerance).all() && light.cmple(hi + tolerance).all();
        if inside {
            return None;
        }
        let nearest = (light - light.clamp(lo, hi)).length();
        let farthest = corners
            .iter()
            .map(|c| (*c - light).length())
            .fold(0.0, f64::max);
        // Planes through the light hold the volume's rays to within their rounding, relative to the
        // farthest corner; a point x of the volume lies |x - L| / |q - L| <= |x - L| / nearest along them.
        let slope = RAY_SLOPE * farthest / nearest;
        if slope.is_nan() || slope > MAX_SLOPE {
            return None;
        }
        let mut half_spaces = Vec::new();
        // The faces that face the light: the volume lies behind them.
        for axis in 0..3 {
            let unit = DVec3::AXES[axis];
            if light[axis] > hi[axis] {
                half_spaces.push(HalfSpace::fixed((-unit).extend(hi[axis]), tolerance));
            } else if light[axis] < lo[axis] {
                half_spaces.push(HalfSpace::fixed(unit.extend(-lo[axis]), tolerance));
            }
        }
        let faces_light = |axis: usize, high: bool| {
            if high {
                light[axis] > hi[axis]
            } else {
                light[axis] < lo[axis]
            }
        };
        let centre = (lo + hi) * 0.5;
        for edge in box_edges(lo, hi) {
            // A silhouette edge: exactly one of its two faces faces the light.
            let [(first, first_high), (second, second_high)] = edge.faces;
            if faces_light(first, first_high) == faces_light(second, second_high) {
                continue;
            }
            let [a, b] = edge.ends;
            let mut n = (a - light).cross(b - light);
            if n.dot(centre - light) < 0.0 {
                n = -n;
            }
            let length = n.length();
            if !(length > 0.0 && length.is_finite()) {
                continue;
            }
            let n = n / length;
            // Every corner on its side (within rounding): a supporting plane.
            if corners
                .iter()
                .any(|c| n.dot(*c - light) < -RAY_SLOPE * farthest)
            {
                continue;
            }
            half_spaces.push(HalfSpace {
                plane: n.extend(-n.dot(light)),
                slack: tolerance,
                slope,
                anchor: light,
            });
        }
        let rays = corners.iter().map(|c| (*c - light).normalize()).collect();
        Some(Self {
            half_spaces,
            corners,
            rays,
        })
    }

    /// The box `bounds` swept along `direction` (the light's travel), or along the square cone around it
    /// that holds every direction within `angular_radius`.
    fn of_direction(
        direction: DVec3,
        bounds: [DVec3; 2],
        angular_radius: f64,
        tolerance: f64,
    ) -> Option<Self> {
        let d = direction.try_normalize()?;
        let [lo, hi] = bounds;
        if lo.cmpgt(hi).any() {
            return None;
        }
        let corners = box_corners(lo, hi);
        let rays: Vec<DVec3> = if angular_radius > 0.0 {
            // Directions d + v, v across d with |v| <= tan r: within the square |v.e1|, |v.e2| <= tan r.
            let t = angular_radius.tan();
            let e1 = d.any_orthonormal_vector();
            let e2 = d.cross(e1);
            [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0)]
                .iter()
                .map(|&(a, b)| (d + t * (a * e1 + b * e2)).normalize())
                .collect()
        } else {
            vec![d]
        };
        // A point x = c + sum t_j g_j of the volume: sum t_j <= |x - c| / cos(spread) along the rays.
        let spread = rays.iter().map(|g| g.dot(d)).fold(1.0, f64::min);
        if !(spread.is_finite() && spread * MAX_SLOPE >= RAY_SLOPE) {
            return None;
        }
        let slope = 2.0 * RAY_SLOPE / spread;
        let centre = (lo + hi) * 0.5;
        let half_diagonal = (hi - lo).length() * 0.5;
        // The facets of a box plus a cone: box faces (axes), box edges along a ray (axis x ray), corners
        // along a facet of the cone (ray x ray).
        let mut normals: Vec<DVec3> = DVec3::AXES.to_vec();
        for g in &rays {
            normals.extend(DVec3::AXES.iter().map(|a| a.cross(*g)));
        }
        for (i, g) in rays.iter().enumerate() {
            normals.extend(rays[i + 1..].iter().map(|h| g.cross(*h)));
        }
        let mut half_spaces: Vec<HalfSpace> = Vec::new();
        for n in normals.iter().filter_map(|n| n.try_normalize()) {
            for n in [n, -n] {
                // Every ray keeps x inside (within rounding), and the box lies on its positive side.
                if rays.iter().any(|g| n.dot(*g) < -RAY_SLOPE) {
                    continue;
                }
                let w = -corners
                    .iter()
                    .map(|c| n.dot(*c))
                    .fold(f64::INFINITY, f64::min);
                let plane = n.extend(w);
                if half_spaces
                    .iter()
                    .any(|h| (h.plane - plane).abs().max_element() <= tolerance)
                {
                    continue;
                }
                half_spaces.push(HalfSpace {
                    plane,
                    slack: tolerance + slope * half_diagonal,
                    slope,
                    anchor: centre,
                });
            }
        }
        Some(Self {
            half_spaces,
            corners,
            rays,
        })
    }
}

/// The eight corners of the box from `lo` to `hi`.
fn box_corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// An edge of a box: its endpoints and the two faces that meet there, each as its axis and whether it is
/// the high face of that axis.
struct BoxEdge {
    ends: [DVec3; 2],
    faces: [(usize, bool); 2],
}

/// The twelve edges of the box from `lo` to `hi`.
fn box_edges(lo: DVec3, hi: DVec3) -> Vec<BoxEdge> {
    let mut edges = Vec::with_capacity(12);
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for (high_u, high_v) in [(false, false), (true, false), (false, true), (true, true)] {
            let mut a = lo;
            a[u] = if high_u { hi[u] } else { lo[u] };
            a[v] = if high_v { hi[v] } else { lo[v] };
            let mut b = a;
            b[axis] = hi[axis];
            edges.push(BoxEdge {
                ends: [a, b],
                faces: [(u, high_u), (v, high_v)],
            });
        }
    }
    edges
}

/// The side half-spaces `dot(plane, (x, 1)) >= 0` of Vulkan clip space (`-w <= x, y <= w`) in the
/// coordinates `m` maps to clip space, each widened by `widening` times `w` (unit normals).
fn side_planes(m: DMat4, widening: f64) -> Vec<DVec4> {
    let (r0, r1, r3) = (m.row(0), m.row(1), m.row(3));
    widened([r3 + r0, r3 - r0, r3 + r1, r3 - r1], r3, widening)
}

/// The depth half-spaces of Vulkan clip space (`0 <= z <= w`), widened like [`side_planes`]; a plane whose
/// normal vanishes (an infinite far plane) is left out.
fn depth_planes(m: DMat4, widening: f64) -> Vec<DVec4> {
    let (r2, r3) = (m.row(2), m.row(3));
    widened([r2, r3 - r2], r3, widening)
}

/// `planes`, each plus `widening` times the `w` row, with unit normals; those whose normal vanishes (before
/// or after widening) are left out.
fn widened<const N: usize>(planes: [DVec4; N], w: DVec4, widening: f64) -> Vec<DVec4> {
    planes
        .into_iter()
        .filter(|p| p.truncate() != DVec3::ZERO)
        .filter_map(|p| {
            let p = p + w * widening;
            let n = p.truncate().length();
            (n > 0.0 && n.is_finite()).then(|| p / n)
        })
        .collect()
}

/// The six half-spaces of the box from `lo` to `hi`.
fn box_planes(lo: DVec3, hi: DVec3) -> [DVec4; 6] {
    [
        DVec4::new(1.0, 0.0, 0.0, -lo.x),
        DVec4::new(-1.0, 0.0, 0.0, hi.x),
        DVec4::new(0.0, 1.0, 0.0, -lo.y),
        DVec4::new(0.0, -1.0, 0.0, hi.y),
        DVec4::new(0.0, 0.0, 1.0, -lo.z),
        DVec4::new(0.0, 0.0, -1.0, hi.z),
    ]
}

/// Relative error of a solve or a cross product in f64, per unit of conditioning (a few roundings).
const SOLVE_ERROR: f64 = 1e-14;

/// Three unit normals whose determinant is below this are taken as lying in one plane (their planes meet
/// in no point, or in a line): a vertex where they meet, if any, is missed (the test then relies on
/// other triples through it).
const MIN_DETERMINANT: f64 = 1e-12;

/// The points where three of the half-spaces' planes meet and which satisfy every half-space within its
/// tolerance, widened by the error of the point's own solve (its coordinates' scale times
/// [`SOLVE_ERROR`] over the three normals' determinant): the vertices of their intersection (some vertex
/// exists when the intersection is non-empty and holds no line), and at worst some points near it.
fn vertices(half_spaces: &[HalfSpace]) -> Vec<DVec3> {
    let mut found = Vec::new();
    each_vertex(half_spaces, |x| {
        found.push(x);
        true
    });
    found
}

/// Whether the half-spaces have a vertex ([`vertices`]), stopping at the first.
fn has_vertex(half_spaces: &[HalfSpace]) -> bool {
    let mut any = false;
    each_vertex(half_spaces, |_| {
        any = true;
        false
    });
    any
}

/// Calls `visit` with each vertex of the half-spaces ([`vertices`]) while it returns true.
fn each_vertex(half_spaces: &[HalfSpace], mut visit: impl FnMut(DVec3) -> bool) {
    let n = half_spaces.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (
                    half_spaces[i].plane,
                    half_spaces[j].plane,
                    half_spaces[k].plane,
                );
                let (na, nb, nc) = (a.truncate(), b.truncate(), c.truncate());
                let bc = nb.cross(nc);
                let det = na.dot(bc);
                // Normals within rounding of one plane: parallel planes, no vertex (the error bound below
                // would be meaningless).
                if det.abs() < MIN_DETERMINANT {
                    continue;
                }
                // Cramer's rule for n.x = -w of the three planes.
                let x = (bc * -a.w + nc.cross(na) * -b.w + na.cross(nb) * -c.w) / det;
                let error = SOLVE_ERROR
                    * (x.abs().max_element() + a.w.abs().max(b.w.abs()).max(c.w.abs()))
                    / det.abs();
                if x.is_finite()
                    && half_spaces
                        .iter()
                        .all(|h| h.value(x) >= -(h.tolerance(x) + error))
                    && !visit(x)
                {
                    return;
                }
            }
        }
    }
}

/// The directions in which the intersection of the half-spaces is unbounded, as unit vectors: the edges
/// of its recession cone (where two planes' directions meet, satisfying every other plane's, within the
/// error of their cross product), and at worst some directions near them.
fn recession_rays(half_spaces: &[HalfSpace]) -> Vec<DVec3> {
    let normals: Vec<DVec3> = half_spaces.iter().map(|h| h.plane.truncate()).collect();
    let mut rays = Vec::new();
    for (i, a) in normals.iter().enumerate() {
        for b in &normals[i + 1..] {
            let cross = a.cross(*b);
            let length = cross.length();
            if !(length > 0.0 && length.is_finite()) {
                continue;
            }
            let r = cross / length;
            let error = RAY_SLOPE + SOLVE_ERROR / length;
            for r in [r, -r] {
                if normals.iter().all(|n| n.dot(r) >= -error) {
                    rays.push(r);
                }
            }
        }
    }
    rays
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{directional_light_frustum, point_light_faces, spot_light_frusta};
    use glam::{Mat4, Vec3};

    /// A reversed-Z camera with an infinite far plane at `eye` looking at `target`.
    fn camera(eye: Vec3, target: Vec3) -> ViewVolume {
        let view = Mat4::look_at_rh(eye, target, Vec3::Y);
        let proj = Mat4::perspective_infinite_reverse_rh(1.0, 16.0 / 9.0, 0.1);
        ViewVolume::new((proj * view).as_dmat4(), eye.as_dvec3())
    }

    fn casters(lo: Vec3, hi: Vec3, light_size: f64) -> Casters {
        Casters {
            bounds: [lo.as_dvec3(), hi.as_dvec3()],
            light_size,
        }
    }

    /// The camera of the tests, at (0, 2, 9) in a room looking down -Z.
    fn room_camera() -> ViewVolume {
        camera(Vec3::new(0.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0))
    }

    #[test]
    fn a_camera_looking_down_minus_z_keeps_the_faces_it_sees() {
        let view = room_camera();
        // A light behind the camera: only its -Z face holds part of the view (a wedge in front of the
        // camera, narrower than 45° on each side, that starts half a unit in front of the light).
        let faces = point_light_faces(Vec3::new(0.0, 2.0, 9.5), Some(3.0));
        let kept: Vec<bool> = faces
            .iter()
            .map(|f| view.may_shadow(f, Some(3.0), None))
            .collect();
        assert_eq!(kept, [false, false, false, false, false, true]);
    }

    #[test]
    fn a_light_out_of_range_of_the_view_is_culled_whole() {
        let view = room_camera();
        // Behind the camera, with a range that ends before the camera's near plane reaches it.
        let position = Vec3::new(0.0, 2.0, 9.95);
        let faces = point_light_faces(position, Some(0.5));
        assert!(faces.iter().all(|f| !view.may_shadow(f, Some(0.5), None)));
        // With an unlimited range the face looking into the view is kept.
        let faces = point_light_faces(position, None);
        let kept: Vec<bool> = faces
            .iter()
            .map(|f| view.may_shadow(f, None, None))
            .collect();
        assert_eq!(kept, [false, false, false, false, false, true]);
        // A point light as one cube map: culled once its range ends before the view.
        let cube = |range| Light::Point { position, range };
        assert!(view.may_shadow(&cube(None), None, None));
        assert!(view.may_shadow(&cube(Some(3.0)), Some(3.0), None));
        assert!(!view.may_shadow(&cube(Some(0.5)), Some(0.5), None));
    }

    /// The case: a low sun from behind the camera, and the only caster (a pillar) behind the camera
    /// too, out of view. Its shadow falls on a ground in view that casts nothing: the light must be kept,
    /// although the casters' bounds do not meet the view at all.
    #[test]
    fn a_caster_behind_the_camera_keeps_a_low_sun() {
        let view = camera(Vec3::new(0.0, 1.6, 0.0), Vec3::new(0.0, 0.3, -6.0));
        let pillar = casters(Vec3::new(-0.4, 0.0, 2.6), Vec3::new(0.4, 5.0, 3.4), 0.0);
        let direction = Vec3::new(0.15, -0.3, -1.0);
        let sun = directional_light_frustum(
            direction,
            [pillar.bounds[0].as_vec3(), pillar.bounds[1].as_vec3()],
        )
        .expect("fitted");
        assert!(view.may_shadow(&sun, None, Some(&pillar)));
        // A sun from the other side throws the pillar's shadow away from the view: nothing to shadow.
        let away = directional_light_frustum(
            -direction,
            [pillar.bounds[0].as_vec3(), pillar.bounds[1].as_vec3()],
        )
        .expect("fitted");
        assert!(!view.may_shadow(&away, None, Some(&pillar)));
        // Without the casters' bounds the plugin keeps what the view meets.
        assert!(view.may_shadow(&away, None, None));
    }

    #[test]
    fn a_point_light_is_culled_when_its_casters_shadow_nothing_in_view() {
        let view = room_camera();
        let lamp = Light::Point {
            position: Vec3::new(0.0, 2.0, 12.0),
            range: None,
        };
        // A wall behind the lamp (as seen from the camera): its shadow volume runs away from the view.
        let behind = casters(Vec3::new(-3.0, 0.0, 13.0), Vec3::new(3.0, 4.0, 13.5), 0.0);
        assert!(!view.may_shadow(&lamp, None, Some(&behind)));
        // A sized lamp whose emitter reaches the wall is kept (the wall's grown box holds the lamp) ...
        let sized = Casters {
            light_size: 1.2,
            ..behind
        };
        assert!(view.may_shadow(&lamp, None, Some(&sized)));
        // ... as is a hard lamp with a caster between it and the view.
        let between = casters(Vec3::new(-0.5, 1.5, 10.0), Vec3::new(0.5, 2.5, 10.5), 0.0);
        assert!(view.may_shadow(&lamp, None, Some(&between)));
        // A caster beside the lamp, behind the camera: its shadow spreads away from the lamp more slowly
        // than the view widens, and enters it far ahead (the view has no far plane) ...
        let beside = casters(Vec3::new(0.5, 0.0, 11.0), Vec3::new(0.8, 4.0, 11.3), 0.0);
        assert!(view.may_shadow(&lamp, None, Some(&beside)));
        // ... unlike one farther aside, whose shadow runs off to the side faster than the view widens.
        let aside = casters(Vec3::new(2.0, 0.0, 11.0), Vec3::new(2.5, 4.0, 11.5), 0.0);
        assert!(!view.may_shadow(&lamp, None, Some(&aside)));
    }

    #[test]
    fn a_sized_sun_keeps_the_penumbra_a_hard_sun_does_not_have() {
        // A camera looking down -Z, 1.5 m above the ground, and a sun straight down onto a block 2 to 3 m
        // high, beyond the view's left edge where it stands (at 9 to 11 m from the camera the view spans
        // |x| <= 0.98 times the distance, |y - 1.5| <= 0.55 times it).
        let view = camera(Vec3::new(0.0, 1.5, 10.0), Vec3::new(0.0, 1.5, 0.0));
        let block = casters(Vec3::new(-12.0, 2.0, -1.0), Vec3::new(-11.0, 3.0, 1.0), 0.0);
        let fit = [Vec3::new(-20.0, -1.0, -20.0), Vec3::new(20.0, 5.0, 20.0)];
        let sun = directional_light_frustum(Vec3::NEG_Y, fit).expect("fitted");
        // Its hard shadow falls straight down, outside the view at every height the view reaches there.
        assert!(!view.may_shadow(&sun, None, Some(&block)));
        // A sun of angular radius 0.3 rad widens the shadow by tan(0.3) ~ 0.31 m per metre of drop: 5 m
        // below the block its penumbra reaches 1.5 m further, into the view.
        let sized = Casters {
            light_size: 0.3,
            ..block
        };
        assert!(view.may_shadow(&sun, None, Some(&sized)));
    }

    #[test]
    fn a_directional_light_is_kept_when_its_frustum_meets_the_view() {
        let view = room_camera();
        let sun = |center: Vec3| Light::Directional {
            direction: Vec3::NEG_Y,
            view_proj: Mat4::orthographic_rh(-1.0, 1.0, -1.0, 1.0, 0.0, 20.0)
                * Mat4::look_to_rh(center, Vec3::NEG_Y, Vec3::Z),
        };
        assert!(view.may_shadow(&sun(Vec3::new(0.0, 10.0, 0.0)), None, None));
        // A light frustum far to the side of the view holds no receiver in view.
        assert!(!view.may_shadow(&sun(Vec3::new(50.0, 10.0, 0.0)), None, None));
        // Its depth range does not bound the receivers: a sun box ending above the floor still shades it.
        assert!(view.may_shadow(&sun(Vec3::new(0.0, 30.0, 0.0)), None, None));
    }

    #[test]
    fn far_from_the_origin_the_test_keeps_what_it_must() {
        let offset = Vec3::new(1e4, 0.0, -1e4);
        let view = camera(
            Vec3::new(0.0, 2.0, 9.0) + offset,
            Vec3::new(0.0, 2.0, 0.0) + offset,
        );
        let room = casters(
            Vec3::new(-10.0, 0.0, -10.0) + offset,
            Vec3::new(10.0, 5.0, 10.0) + offset,
            0.0,
        );
        let faces = point_light_faces(Vec3::new(0.0, 2.0, 0.0) + offset, Some(20.0));
        // A light in the middle of the room the camera looks into: every face holds part of the view.
        assert!(faces
            .iter()
            .all(|f| view.may_shadow(f, Some(20.0), Some(&room))));
    }

    /// Deterministic pseudo-random numbers in [0, 1) (xorshift64*).
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }

        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }

        fn point(&mut self, half: f64) -> DVec3 {
            DVec3::new(
                self.range(-half, half),
                self.range(-half, half),
                self.range(-half, half),
            )
        }
    }

    /// Whether the segment from `a` to `b` meets the box `[lo, hi]` (slab test).
    fn segment_meets_box(a: DVec3, b: DVec3, [lo, hi]: [DVec3; 2]) -> bool {
        let d = b - a;
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            if d[k] == 0.0 {
                if a[k] < lo[k] || a[k] > hi[k] {
                    return false;
                }
                continue;
            }
            let (u, v) = ((lo[k] - a[k]) / d[k], (hi[k] - a[k]) / d[k]);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        t0 <= t1
    }

    /// A unit vector within `angle` of the unit vector `axis`.
    fn within_cone(random: &mut Random, axis: DVec3, angle: f64) -> DVec3 {
        let e1 = axis.any_orthonormal_vector();
        let e2 = axis.cross(e1);
        let theta = angle * random.next().sqrt();
        let phi = std::f64::consts::TAU * random.next();
        (axis * theta.cos() + (e1 * phi.cos() + e2 * phi.sin()) * theta.sin()).normalize()
    }

    /// Random cameras, lights (point faces, cube maps, spot frusta, suns, hard and sized) and caster
    /// boxes: whenever a sampled receiver in view inside a frustum and within range has a segment to the
    /// light that meets the casters' box, the frustum is kept. Many frusta are culled all the same.
    #[test]
    fn no_frustum_whose_casters_shadow_a_receiver_in_view_is_culled() {
        let mut random = Random(0x9e37_79b9_7f4a_7c15);
        let (mut checked, mut culled, mut shadowing) = (0, 0, 0);
        for _ in 0..600 {
            // Casters around `centre`, a camera looking at a point near them or away, lights around them.
            let centre = random.point(4.0);
            let half = DVec3::new(
                random.range(0.05, 2.0),
                random.range(0.05, 2.0),
                random.range(0.05, 2.0),
            );
            let eye = centre + random.point(8.0);
            let target = if random.next() < 0.7 {
                centre + random.point(3.0)
            } else {
                eye + random.point(1.0)
            };
            let view = camera(eye.as_vec3(), target.as_vec3());
            let view_proj = Mat4::perspective_infinite_reverse_rh(1.0, 16.0 / 9.0, 0.1)
                * Mat4::look_at_rh(eye.as_vec3(), target.as_vec3(), Vec3::Y);
            let to_world = view_proj.as_dmat4().inverse();
            let size = if random.next() < 0.5 {
                0.0
            } else {
                random.range(0.01, 0.5)
            };
            let position = centre + random.point(6.0);
            let range = (random.next() < 0.5).then(|| random.range(1.0, 12.0) as f32);
            let direction = random.point(1.0).normalize();
            let lights: Vec<Light> = match (random.next() * 4.0) as u32 {
                0 => point_light_faces(position.as_vec3(), range).to_vec(),
                1 => vec![Light::Point {
                    position: position.as_vec3(),
                    range,
                }],
                2 => spot_light_frusta(position.as_vec3(), direction.as_vec3(), 1.2, range),
                _ => vec![directional_light_frustum(
                    direction.as_vec3(),
                    [Vec3::splat(-10.0), Vec3::splat(10.0)],
                )
                .expect("fitted")],
            };
            let directional = matches!(lights[0], Light::Directional { .. });
            let range = if directional { None } else { range };
            let c = Casters {
                bounds: [centre - half, centre + half],
                light_size: size,
            };
            for light in &lights {
                checked += 1;
                let kept = view.may_shadow(light, range, Some(&c));
                culled += usize::from(!kept);
                let frustum = light.view_proj().as_dmat4();
                let mut shadowed = false;
                for _ in 0..300 {
                    // A receiver seen at a random pixel and depth (reversed Z: 1 at the near plane).
                    let ndc = DVec3::new(
                        random.range(-1.0, 1.0),
                        random.range(-1.0, 1.0),
                        random.next().powi(3),
                    );
                    let p = to_world.project_point3(ndc);
                    let in_frustum = match light {
                        Light::Point { .. } => true,
                        _ => {
                            let h = frustum * p.extend(1.0);
                            h.w > 0.0 && h.x.abs() <= h.w && h.y.abs() <= h.w
                        }
                    };
                    let in_range = match (light.position(), range) {
                        (Some(l), Some(r)) => p.distance(l.as_dvec3()) <= f64::from(r),
                        _ => true,
                    };
                    if !(p.is_finite() && in_frustum && in_range) {
                        continue;
                    }
                    // Segments to the emitter's centre and to points on its sphere (or along the sun's
                    // cone): the axes, the diagonals and random ones.
                    let offsets = (0..32).map(|k| match k {
                        0 => DVec3::ZERO,
                        1..=26 => {
                            let i = k - 1 + u32::from(k > 13);
                            DVec3::new(
                                f64::from(i % 3) - 1.0,
                                f64::from(i / 3 % 3) - 1.0,
                                f64::from(i / 9) - 1.0,
                            )
                            .normalize()
                        }
                        _ => DVec3::ZERO,
                    });
                    for (k, offset) in offsets.enumerate() {
                        let end = match light.position() {
                            Some(l) => {
                                let offset = if k >= 27 {
                                    random.point(1.0).normalize_or_zero() * random.next()
                                } else {
                                    offset
                                };
                                l.as_dvec3() + offset * size
                            }
                            None => {
                                let axis = -light.direction().as_dvec3().normalize();
                                let towards = if k >= 27 {
                                    within_cone(&mut random, axis, size)
                                } else {
                                    // Towards the edge of the cone, across the axis along `offset`.
                                    let across = offset.reject_from(axis).normalize_or_zero();
                                    (axis * size.cos() + across * size.sin()).normalize()
                                };
                                p + towards * 1e4
                            }
                        };
                        if segment_meets_box(p, end, c.bounds) {
                            shadowed = true;
                        }
                    }
                    if shadowed {
                        break;
                    }
                }
                shadowing += usize::from(shadowed);
                assert!(
                    kept || !shadowed,
                    "culled {light:?} (range {range:?}) although a receiver in view is shadowed by {c:?}"
                );
            }
        }
        println!("{checked} frusta, {culled} culled, {shadowing} seen shadowing a receiver");
        assert!(
            culled * 5 > checked && shadowing * 10 > checked,
            "{culled} of {checked} culled, {shadowing} shadowing"
        );
    }
}
