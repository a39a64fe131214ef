//! Exact per-pixel light visibility with ambiguity classification.

use glam::{DMat4, DVec2, DVec3, DVec4};
use rayon::prelude::*;

use crate::geometry::{intersect_watertight, line_segment_approach};
use crate::RefScene;

/// Receivers whose normal is closer than this (as a cosine) to perpendicular to the
/// light direction are [`PixelClass::Ambiguous`].
const GRAZING_COSINE: f64 = 1e-6;
/// Relative slack on the camera hit parameter when looking for nearby edges.
const HIT_SLACK: f64 = 1e-9;

/// A light source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Parallel light; `direction` is the (unit) direction the light travels, so the
    /// direction *to* the light is `-direction`.
    Directional {
        /// Direction of travel of the light.
        direction: DVec3,
    },
    /// Point light at `position`.
    Point {
        /// World-space position of the light.
        position: DVec3,
    },
    /// One sample of a spherical emitter (a sized spot or point light) as area shadows place it for each
    /// receiver `x`: the point `centre + radius (offset.x t1 + offset.y t2)` of the disc through the centre
    /// facing `x`, with `(t1, t2)` = [`disc_basis`] of the unit direction from `x` to the centre. A pixel
    /// whose direction lies within [`DISC_BASIS_POLE`] of the basis' pole is Ambiguous.
    DiscSample {
        /// The emitter's centre.
        centre: DVec3,
        /// The emitter's radius.
        radius: f64,
        /// The sample's offset on the unit disc.
        offset: DVec2,
    },
}

/// Two unit axes across the unit direction `n`: the rotation taking +Y to `n` applied to +X and +Z. It turns
/// smoothly with `n` except at `n = -Y`, where it is undefined (there it is +X and -Z).
pub fn disc_basis(n: DVec3) -> (DVec3, DVec3) {
    let a = 1.0 / (1.0 + n.y);
    if !a.is_finite() {
        return (DVec3::X, DVec3::NEG_Z);
    }
    (
        DVec3::new(1.0 - n.x * n.x * a, -n.x, -n.x * n.z * a),
        DVec3::new(-n.z * n.x * a, -n.z, 1.0 - n.z * n.z * a),
    )
}

/// Below this value of `1 + n.y`, [`disc_basis`] is too ill-conditioned for a GPU's f32 and this f64 to
/// agree on the samples' places: such pixels of a [`Light::DiscSample`] are Ambiguous.
pub const DISC_BASIS_POLE: f64 = 0.01;

/// Reference classification of one pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelClass {
    /// The camera ray hits nothing.
    Background,
    /// Exact visibility 1.
    Lit,
    /// Exact visibility 0: blocked, or the visible side of the receiver faces away
    /// from the light.
    Shadowed,
    /// Some event lies within the tolerance of a triangle edge or plane: a GPU may
    /// legitimately differ. Such pixels are counted, not compared.
    Ambiguous,
}

/// Inputs of [`reference_visibility`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VisibilityParams {
    /// Framebuffer width in pixels.
    pub width: u32,
    /// Framebuffer height in pixels.
    pub height: u32,
    /// Camera `projection * view` (reversed-Z, infinite far plane: NDC z = 1 is the
    /// near plane), composed in `f64` from the `f32` matrices given to the GPU: a
    /// product rounded to `f32` moves the rays by a sizeable fraction of a pixel once
    /// the camera is 1e4 to 1e5 units from the origin.
    pub view_proj: DMat4,
    /// World-space origin of the camera rays: the eye of `view_proj` (for a view
    /// matrix `v`, `v.inverse()` applied to the origin, in `f64`), which differs from
    /// the `f32` position the view matrix was built from by the rounding of its
    /// translation.
    pub camera_position: DVec3,
    /// The light.
    pub light: Light,
    /// Tolerance in world units for shadow-ray events and camera z-fighting.
    pub tolerance: f64,
    /// Added to `tolerance` per world unit of distance from the camera to the receiver: a fraction of the
    /// pixel footprint, which bounds how far a rasterizer's depth moves the receiver point.
    pub tolerance_per_distance: f64,
    /// Tolerance in pixels for camera rays passing near triangle edges
    /// (e.g. 1/64).
    pub pixel_tolerance: f64,
}

/// Reference visibility of every pixel; all vectors are row-major with `y = 0` the
/// top row and have `width * height` entries.
#[derive(Debug, Clone, PartialEq)]
pub struct VisibilityReference {
    /// Framebuffer width in pixels.
    pub width: u32,
    /// Framebuffer height in pixels.
    pub height: u32,
    /// Classification per pixel.
    pub class: Vec<PixelClass>,
    /// Distance from the receiver point to the nearest blocker: 0 for receivers
    /// facing away from the light, NaN when unblocked or when the nearest blocker is
    /// not certain.
    pub blocker_distance: Vec<f64>,
    /// Receiver point (camera-ray hit), NaN for pixels whose camera ray hits nothing.
    pub position: Vec<DVec3>,
    /// Receiver triangle index, `u32::MAX` for pixels whose camera ray hits nothing.
    pub receiver: Vec<u32>,
}

/// Computes the exact visibility reference of every pixel (rayon over rows).
///
/// Per pixel `(x, y)` (with `y = 0` the top row):
///
/// 1. **Camera ray.** The origin is `camera_position`; the direction is the pixel
///    centre unprojected at NDC `((x + 0.5) / W * 2 - 1, (y + 0.5) / H * 2 - 1, 1)`
///    (the near plane) through the `f64` inverse of `view_proj`, minus the origin
///    (not normalised). The nearest [`intersect_watertight`] hit with `t > 0` over
///    the BVH is the receiver triangle `R` at `P = origin + t * dir`. Without a hit
///    the pixel is [`PixelClass::Background`].
///
///    The pixel is [`PixelClass::Ambiguous`] instead if
///    (a) the camera ray passes within `pixel_tolerance` pixels of an edge of any
///    triangle (including `R`) whose plane it crosses at `t'` in
///    `(0, t * (1 + 1e-9) + tolerance / |dir|]`; distances are line-to-edge-segment
///    distances in world units compared with `t' * |dir| * pixel_angle *
///    pixel_tolerance`, where `pixel_angle = 2 tan(fov_y / 2) / H` and
///    `1 / tan(fov_y / 2)` is read from `view_proj` as the length of the xyz part of
///    its second row divided by that of its fourth row (which is `m[1][1]` of the
///    projection for a rigid view). For a triangle parallel to the ray, the edge's
///    closest-approach parameter replaces `t'`. When the camera ray hits nothing,
///    rule (a) is applied up to where the ray leaves the scene bounds, so that a ray
///    grazing a silhouette is Ambiguous (with NaN position and no receiver) rather
///    than Background; or
///    (b) another triangle is hit at `t2 > 0` with `(t2 - t) * |dir| <= tolerance`
///    (coplanar surfaces, z-fighting).
/// 2. **Receiver facing.** `n` is the unit geometric normal of `R`, flipped to face
///    the camera (`dot(n, dir) < 0`; a ray exactly in the plane is Ambiguous). `L` is
///    the unit direction to the light (`-direction`, or `normalize(position - P)`),
///    `c = dot(n, L)`. If `|c| < 1e-6` the pixel is Ambiguous; if `c < 0` it is
///    [`PixelClass::Shadowed`] with blocker distance 0.
/// 3. **Shadow ray** `P + s * L`. For a point light at distance `d`, only
///    `s < d` counts (`d = inf` for a directional light). Every usable triangle
///    `T != R` that casts shadows (every one, unless the scene was built with
///    [`RefScene::with_casters`]) whose bounding box grown by `tolerance` the ray reaches for
///    `s in [-tolerance, d + tolerance]` is examined:
///    - an *edge event* occurs when some edge of `T` is closer than `tolerance` to
///      the ray's line at a closest-approach parameter in `(-tolerance,
///      d + tolerance)`; the event's parameter is that closest-approach parameter;
///    - when the line crosses `T` ([`intersect_watertight`]) at `s`:
///      if `|s| <= tolerance` or `|s - d| <= tolerance` that is a *plane event* at
///      `s`; otherwise, if `tolerance < s < d` and `T` has no edge event, `T` is a
///      *certain blocker* at `s`.
///
///    If a certain blocker exists the pixel is Shadowed with blocker distance the
///    smallest certain `s`, replaced by NaN if an event occurred at a smaller
///    parameter (the nearest blocker is not certain). Otherwise any event makes the
///    pixel Ambiguous, and without events it is [`PixelClass::Lit`].
/// 4. Degenerate triangles (zero area in 3D, or non-finite) are ignored
///    everywhere: they never receive, block, or make anything ambiguous.
pub fn reference_visibility(scene: &RefScene, params: &VisibilityParams) -> VisibilityReference {
    reference_visibility_with_progress(scene, params, &|| {})
}

/// The classes [`reference_visibility`] gives the pixels `pixels` ((x, y), `y = 0` the top row) of `params`'
/// view, without the rest of the frame.
pub fn reference_pixel_classes(
    scene: &RefScene,
    params: &VisibilityParams,
    pixels: &[(u32, u32)],
) -> Vec<PixelClass> {
    let camera = Camera::new(params);
    pixels
        .par_iter()
        .map(|&(x, y)| shade_pixel(scene, params, &camera, x, y).class)
        .collect()
}

/// [`reference_visibility`], calling `row_done` once per row it finishes (from any thread of its pool),
/// for a caller's progress display: `params.height` calls in all.
pub fn reference_visibility_with_progress(
    scene: &RefScene,
    params: &VisibilityParams,
    row_done: &(dyn Fn() + Sync),
) -> VisibilityReference {
    let camera = Camera::new(params);
    let rows: Vec<Vec<Pixel>> = (0..params.height)
        .into_par_iter()
        .map(|y| {
            let row = (0..params.width)
                .map(|x| shade_pixel(scene, params, &camera, x, y))
                .collect();
            row_done();
            row
        })
        .collect();
    let pixels = rows.into_iter().flatten();
    let capacity = params.width as usize * params.height as usize;
    let mut out = VisibilityReference {
        width: params.width,
        height: params.height,
        class: Vec::with_capacity(capacity),
        blocker_distance: Vec::with_capacity(capacity),
        position: Vec::with_capacity(capacity),
        receiver: Vec::with_capacity(capacity),
    };
    for pixel in pixels {
        out.class.push(pixel.class);
        out.blocker_distance.push(pixel.blocker_distance);
        out.position.push(pixel.position);
        out.receiver.push(pixel.receiver);
    }
    out
}

/// Result for one pixel.
struct Pixel {
    class: PixelClass,
    blocker_distance: f64,
    position: DVec3,
    receiver: u32,
}

impl Pixel {
    fn without_receiver(class: PixelClass) -> Self {
        Self {
            class,
            blocker_distance: f64::NAN,
            position: DVec3::NAN,
            receiver: u32::MAX,
        }
    }
}

/// Camera quantities shared by all pixels.
struct Camera {
    inv_view_proj: DMat4,
    origin: DVec3,
    /// Angle subtended by one pixel (vertically) at the image centre.
    pixel_angle: f64,
}

impl Camera {
    fn new(params: &VisibilityParams) -> Self {
        let view_proj = params.view_proj;
        let focal = view_proj.row(1).truncate().length() / view_proj.row(3).truncate().length();
        let pixel_angle = 2.0 / (focal * f64::from(params.height));
        Self {
            inv_view_proj: view_proj.inverse(),
            origin: params.camera_position,
            pixel_angle: if pixel_angle.is_finite() {
                pixel_angle
            } else {
                0.0
            },
        }
    }

    /// Unnormalised direction from the camera through the near-plane point of the
    /// centre of pixel `(x, y)`.
    fn direction(&self, x: u32, y: u32, width: u32, height: u32) -> DVec3 {
        let ndc_x = (f64::from(x) + 0.5) / f64::from(width) * 2.0 - 1.0;
        let ndc_y = (f64::from(y) + 0.5) / f64::from(height) * 2.0 - 1.0;
        let near = self.inv_view_proj * DVec4::new(ndc_x, ndc_y, 1.0, 1.0);
        near.truncate() / near.w - self.origin
    }
}

fn shade_pixel(
    scene: &RefScene,
    params: &VisibilityParams,
    camera: &Camera,
    x: u32,
    y: u32,
) -> Pixel {
    let origin = camera.origin;
    // NaN and negative tolerances count as 0.
    let tolerance = params.tolerance.max(0.0);
    let dir = camera.direction(x, y, params.width, params.height);
    let dir_length = dir.length();
    if !dir.is_finite() || dir_length == 0.0 {
        return Pixel::without_receiver(PixelClass::Background);
    }
    let edge_tolerance = CameraEdgeTolerance {
        per_t: dir_length * camera.pixel_angle * params.pixel_tolerance.max(0.0),
    };
    let Some((t_hit, receiver)) = scene.nearest_hit(origin, dir) else {
        let ambiguous = scene_exit(scene, origin, dir).is_some_and(|t_exit| {
            camera_ambiguous(scene, origin, dir, None, t_exit, edge_tolerance, 0.0)
        });
        return Pixel::without_receiver(if ambiguous {
            PixelClass::Ambiguous
        } else {
            PixelClass::Background
        });
    };
    let position = origin + dir * t_hit;
    let tolerance = tolerance + t_hit * dir_length * params.tolerance_per_distance.max(0.0);
    let mut pixel = Pixel {
        class: PixelClass::Ambiguous,
        blocker_distance: f64::NAN,
        position,
        receiver: u32::try_from(receiver).unwrap_or(u32::MAX),
    };
    let t_limit = t_hit * (1.0 + HIT_SLACK) + tolerance / dir_length;
    let hit = Some((t_hit, receiver));
    if camera_ambiguous(scene, origin, dir, hit, t_limit, edge_tolerance, tolerance) {
        return pixel;
    }

    let [a, b, c] = scene.triangle(receiver);
    let mut normal = (b - a).cross(c - a).normalize_or_zero();
    let facing = normal.dot(dir);
    if facing == 0.0 {
        return pixel;
    }
    if facing > 0.0 {
        normal = -normal;
    }
    let (to_light, light_distance) = match params.light {
        Light::Directional { direction } => (-direction.normalize_or_zero(), f64::INFINITY),
        Light::Point { position: light } => {
            let offset = light - position;
            (offset.normalize_or_zero(), offset.length())
        }
        Light::DiscSample {
            centre,
            radius,
            offset,
        } => {
            let n = (centre - position).normalize_or_zero();
            if 1.0 + n.y < DISC_BASIS_POLE || n == DVec3::ZERO {
                return pixel;
            }
            let (t1, t2) = disc_basis(n);
            let to_sample = centre + radius * (offset.x * t1 + offset.y * t2) - position;
            (to_sample.normalize_or_zero(), to_sample.length())
        }
    };
    let cosine = normal.dot(to_light);
    if cosine.is_nan() || cosine.abs() < GRAZING_COSINE {
        return pixel;
    }
    if cosine < 0.0 {
        pixel.class = PixelClass::Shadowed;
        pixel.blocker_distance = 0.0;
        return pixel;
    }
    let shadow = ShadowRay {
        origin: position,
        dir: to_light,
        light_distance,
        tolerance,
        receiver,
    };
    (pixel.class, pixel.blocker_distance) = shadow.classify(scene);
    pixel
}

/// Parameter at which the ray leaves the bounds of the scene's usable triangles
/// (with a little slack), if that is ahead of the origin.
fn scene_exit(scene: &RefScene, origin: DVec3, dir: DVec3) -> Option<f64> {
    let (min, max) = scene.root_bounds()?;
    let mut exit = f64::INFINITY;
    for axis in 0..3 {
        let d = dir[axis];
        if d > 0.0 {
            exit = exit.min((max[axis] - origin[axis]) / d);
        } else if d < 0.0 {
            exit = exit.min((min[axis] - origin[axis]) / d);
        }
    }
    (exit > 0.0 && exit.is_finite()).then_some(exit * (1.0 + HIT_SLACK))
}

/// World-space edge tolerance of camera rays: `per_t * t` at ray parameter `t`.
#[derive(Clone, Copy)]
struct CameraEdgeTolerance {
    per_t: f64,
}

impl CameraEdgeTolerance {
    fn at(self, t: f64) -> f64 {
        self.per_t * t
    }
}

/// Camera-ray ambiguity, rules 1(a) and 1(b): `hit` is the nearest hit, if any;
/// planes crossed at parameters in `(0, t_limit]` are considered.
fn camera_ambiguous(
    scene: &RefScene,
    origin: DVec3,
    dir: DVec3,
    hit: Option<(f64, usize)>,
    t_limit: f64,
    edge_tolerance: CameraEdgeTolerance,
    tolerance: f64,
) -> bool {
    let dir_length = dir.length();
    let mut ambiguous = false;
    let pad = edge_tolerance.at(t_limit);
    scene.traverse(origin, dir, 0.0, t_limit, pad, |i, t_max| {
        let tri = scene.triangle(i);
        let z_fighting = hit.is_some_and(|(t_hit, receiver)| {
            i != receiver
                && intersect_watertight(origin, dir, &tri)
                    .is_some_and(|(t, _)| t > 0.0 && (t - t_hit) * dir_length <= tolerance)
        });
        if z_fighting || camera_ray_near_edge(origin, dir, &tri, t_limit, edge_tolerance) {
            ambiguous = true;
            *t_max = f64::NEG_INFINITY;
        }
    });
    ambiguous
}

/// Rule 1(a) for one triangle.
fn camera_ray_near_edge(
    origin: DVec3,
    dir: DVec3,
    tri: &[DVec3; 3],
    t_limit: f64,
    edge_tolerance: CameraEdgeTolerance,
) -> bool {
    let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    let denominator = normal.dot(dir);
    let edges = [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])];
    if denominator != 0.0 {
        let t = normal.dot(tri[0] - origin) / denominator;
        if !(t > 0.0 && t <= t_limit) {
            return false;
        }
        let limit = edge_tolerance.at(t);
        edges
            .iter()
            .any(|&(a, b)| line_segment_approach(origin, dir, a, b).distance < limit)
    } else {
        edges.iter().any(|&(a, b)| {
            let approach = line_segment_approach(origin, dir, a, b);
            let t = approach.s_max.min(t_limit);
            t > 0.0 && approach.s_min <= t_limit && approach.distance < edge_tolerance.at(t)
        })
    }
}

/// A shadow ray from a receiver point towards the light (rule 3).
struct ShadowRay {
    origin: DVec3,
    /// Unit direction to the light.
    dir: DVec3,
    /// Distance to the light (infinite for directional lights).
    light_distance: f64,
    tolerance: f64,
    receiver: usize,
}

impl ShadowRay {
    /// Classification and blocker distance of the receiver point.
    fn classify(&self, scene: &RefScene) -> (PixelClass, f64) {
        let tol = self.tolerance;
        let far = self.light_distance + tol;
        let mut certain = f64::INFINITY;
        let mut first_event = f64::INFINITY;
        scene.traverse(self.origin, self.dir, -tol, far, tol, |i, t_max| {
            if i == self.receiver || !scene.casts(i) {
                return;
            }
            let tri = scene.triangle(i);
            let edge_event = self.edge_event(&tri, far);
            if let Some(s) = edge_event {
                first_event = first_event.min(s);
            }
            if let Some((s, _)) = intersect_watertight(self.origin, self.dir, &tri) {
                if s.abs() <= tol || (s - self.light_distance).abs() <= tol {
                    first_event = first_event.min(s);
                } else if s > tol && s < self.light_distance && edge_event.is_none() {
                    certain = certain.min(s);
                    *t_max = t_max.min(s);
                }
            }
        });
        if certain.is_finite() {
            let distance = if first_event < certain {
                f64::NAN
            } else {
                certain
            };
            (PixelClass::Shadowed, distance)
        } else if first_event.is_finite() {
            (PixelClass::Ambiguous, f64::NAN)
        } else {
            (PixelClass::Lit, f64::NAN)
        }
    }

    /// Smallest parameter of an edge of `tri` passing closer than the tolerance to
    /// the ray's line, with closest approach in `(-tolerance, far)`.
    fn edge_event(&self, tri: &[DVec3; 3], far: f64) -> Option<f64> {
        let tol = self.tolerance;
        [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])]
            .into_iter()
            .map(|(a, b)| line_segment_approach(self.origin, self.dir, a, b))
            .filter(|ap| ap.distance < tol && ap.s_max > -tol && ap.s_min < far)
            .map(|ap| ap.s_min.max(-tol))
            .reduce(f64::min)
    }
}
