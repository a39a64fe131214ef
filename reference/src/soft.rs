//! Soft-shadow ground truth: per pixel, the fraction of an area light that is
//! visible from the receiver point, by stratified Monte Carlo over the light, with
//! pixels whose light cone is provably clear (or provably behind the receiver)
//! decided exactly without sampling.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, TAU};

use glam::DVec3;
use rayon::prelude::*;
use scene::SplitMix64;

use crate::{intersect_watertight, RefScene, VisibilityReference};

/// Shadow rays ignore hits closer to the receiver point `P` than this times
/// `1 + |P|` (the offset that keeps the receiver's neighbours from shadowing it).
pub const RELATIVE_RAY_OFFSET: f64 = 1e-9;
/// Angular margin (radians) of the exact-pixel tests: far above the rounding of
/// the angles they compare, so a pixel called exact is exact for the sampled
/// directions as computed too.
const ANGLE_MARGIN: f64 = 1e-9;
/// Below this `|det|` of the unit directions from `P` to a triangle's vertices the
/// triangle's plane passes (nearly) through `P`, and the exact cone test is not
/// trusted: the triangle then counts as meeting the cone unless its bounding sphere
/// or the receiver's tangent plane rules it out.
const MIN_DIRECTION_DETERMINANT: f64 = 1e-9;
/// Bound on the relative rounding of a dot product of a unit vector with a
/// difference of points, as a multiple of the difference's largest component.
const RELATIVE_DOT_ERROR: f64 = 1e-14;
/// Largest accepted [`SoftParams::strata`] (so that `strata²` fits `u32`).
const MAX_STRATA: u32 = 65_535;

/// An area light for soft shadows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AreaLight {
    /// A distant light whose emitter subtends a cone of half-angle
    /// `angular_radius` (radians, in `(0, π/2)`) around the direction *to* the
    /// light, `-direction`. Visibility is the visible fraction of the cone's solid
    /// angle.
    Directional {
        /// Direction the light travels (normalised internally; must be finite and
        /// non-zero).
        direction: DVec3,
        /// Half-angle of the emitter's cone in radians, in `(0, π/2)`.
        angular_radius: f64,
    },
    /// A flat disk emitter of radius `radius` centred at `position`, perpendicular
    /// to `axis`. Visibility is the visible fraction of the disk's *area* (area
    /// measure, no cosine weighting); which side of the disk emits is not modelled.
    Disk {
        /// Centre of the disk.
        position: DVec3,
        /// Radius of the disk (finite, positive).
        radius: f64,
        /// Normal of the disk's plane (normalised internally; must be finite and
        /// non-zero).
        axis: DVec3,
    },
}

/// Inputs of [`soft_visibility`] besides the scene, the hard reference and the
/// light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoftParams {
    /// World-space camera ray origin of the hard reference
    /// ([`crate::VisibilityParams::camera_position`]): receiver normals are turned
    /// to face it.
    pub camera_position: DVec3,
    /// `n`: each sampled pixel takes `n * n` stratified samples (`1 <= n <= 65535`).
    pub strata: u32,
    /// Seed of the per-pixel jitter; results are a deterministic function of it.
    pub seed: u64,
}

/// Soft visibility of every pixel; vectors are row-major with `y = 0` the top row
/// and have `width * height` entries, like [`VisibilityReference`].
#[derive(Debug, Clone, PartialEq)]
pub struct SoftReference {
    /// Framebuffer width in pixels.
    pub width: u32,
    /// Framebuffer height in pixels.
    pub height: u32,
    /// Visible fraction of the light per pixel, in `[0, 1]`; NaN where the camera
    /// ray hits nothing (the pixels whose [`VisibilityReference::position`] is NaN).
    pub visibility: Vec<f64>,
    /// Whether the pixel's value is exact (decided without sampling: exactly 1 or
    /// exactly 0). False for background and sampled pixels.
    pub exact: Vec<bool>,
    /// Number of exact pixels: light cone provably clear of every triangle but the
    /// receiver and entirely in front of the receiver (value 1), or entirely behind
    /// the receiver (value 0).
    pub exact_pixels: usize,
    /// Number of sampled pixels.
    pub sampled_pixels: usize,
    /// Samples per sampled pixel (`strata²`).
    pub samples: u32,
    /// Bound on the standard error of one sampled pixel's estimate,
    /// `0.5 / sqrt(samples)`: jittered stratification over equal-measure strata has
    /// at most the variance of independent sampling, which for a 0/1 integrand is
    /// at most `1/4 / samples`.
    pub standard_error_bound: f64,
}

/// Computes the soft-shadow ground truth of every pixel of `hard` (rayon over rows).
///
/// Per pixel with a receiver (finite [`VisibilityReference::position`] `P`, receiver
/// triangle `R`):
///
/// 1. **Normal.** `n` is the unit geometric normal of `R`, negated if
///    `n · (camera_position - P) < 0` (kept as is when the camera lies in `R`'s
///    plane).
/// 2. **Samples.** The `[0, 1)²` square is cut into `strata × strata` cells with
///    one jittered point `(u, v)` each, mapped to the light by a measure-preserving
///    map: for [`AreaLight::Directional`] `cos θ = 1 - u (1 - cos r)`, `φ = 2π v`
///    around `-direction` (uniform in solid angle); for [`AreaLight::Disk`] the
///    Shirley–Chiu concentric map onto the disk (uniform in area). The jitter comes
///    from [`scene::SplitMix64`] seeded with `seed ^ (pixel index × SplitMix64::GAMMA)`.
/// 3. **Sample visibility.** With `L` the unit direction from `P` to the sample,
///    the sample is blocked if `n · L <= 0`, or if some usable triangle other than
///    `R` is hit ([`intersect_watertight`]) by `P + s L` at `s` in `(tol, d)`, where
///    `tol = RELATIVE_RAY_OFFSET · (1 + |P|)` and `d` is infinite for a directional
///    light and the distance to the sample point for a disk. The pixel's value is
///    the fraction of unblocked samples.
/// 4. **Exact pixels.** The light's cone from `P` (half-angle `r` around
///    `-direction`; for a disk at distance `D > radius` from `P`, half-angle
///    `asin(radius / D)` around the direction to its centre, cut at distance
///    `D + radius`) is tested against the BVH conservatively (bounding spheres of
///    nodes, the receiver's tangent plane, and an exact test of the triangle's
///    cone of directions from `P`, all with margins above rounding). If the angle
///    between `n` and the cone's axis is below `90° - r` and no triangle but `R`
///    can meet the cone, the value is exactly 1; if that angle exceeds `90° + r`
///    the value is exactly 0. Neither is sampled.
///
/// Pixels without a receiver get NaN.
///
/// # Errors
///
/// Returns a message for an invalid light (non-finite values, zero direction or
/// axis, `angular_radius` outside `(0, π/2)`, `radius <= 0`), invalid `params`
/// (`strata` outside `1..=65535`, non-finite camera position), or a `hard` whose
/// vectors do not have `width * height` entries or whose receivers are
/// inconsistent with `scene` or with its positions.
pub fn soft_visibility(
    scene: &RefScene,
    hard: &VisibilityReference,
    light: &AreaLight,
    params: &SoftParams,
) -> Result<SoftReference, String> {
    soft_visibility_with_progress(scene, hard, light, params, &|| {})
}

/// [`soft_visibility`], calling `row_done` once per row it finishes (from any thread of its pool), for a
/// caller's progress display: `hard.height` calls in all.
///
/// # Errors
///
/// As [`soft_visibility`].
pub fn soft_visibility_with_progress(
    scene: &RefScene,
    hard: &VisibilityReference,
    light: &AreaLight,
    params: &SoftParams,
    row_done: &(dyn Fn() + Sync),
) -> Result<SoftReference, String> {
    soft_visibility_with(
        scene,
        hard,
        light,
        params,
        ExactShortcuts::Enabled,
        row_done,
    )
}

/// Whether [`soft_visibility_with`] decides provable pixels without sampling (the
/// disabled form lets tests check that exact pixels agree with sampling).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ExactShortcuts {
    Enabled,
    #[cfg_attr(not(test), allow(dead_code))]
    Disabled,
}

/// [`soft_visibility`] with the exact shortcuts optionally disabled.
pub(crate) fn soft_visibility_with(
    scene: &RefScene,
    hard: &VisibilityReference,
    light: &AreaLight,
    params: &SoftParams,
    shortcuts: ExactShortcuts,
    row_done: &(dyn Fn() + Sync),
) -> Result<SoftReference, String> {
    let emitter = Emitter::new(light)?;
    if !(1..=MAX_STRATA).contains(&params.strata) {
        return Err(format!(
            "soft shadows: strata must be in 1..={MAX_STRATA}, got {}",
            params.strata
        ));
    }
    if !params.camera_position.is_finite() {
        return Err(format!(
            "soft shadows: camera position {} is not finite",
            params.camera_position
        ));
    }
    check_hard_reference(scene, hard)?;

    let samples = params.strata * params.strata;
    let width = hard.width as usize;
    let rows: Vec<Vec<Outcome>> = (0..hard.height as usize)
        .into_par_iter()
        .map(|y| {
            let row = (0..width)
                .map(|x| {
                    let index = y * width + x;
                    let receiver = hard.receiver[index];
                    if receiver == u32::MAX {
                        return Outcome::Background;
                    }
                    let pixel = Receiver::new(
                        scene,
                        hard.position[index],
                        receiver as usize,
                        params.camera_position,
                    );
                    if shortcuts == ExactShortcuts::Enabled {
                        if let Some(value) = pixel.exact_value(scene, &emitter) {
                            return Outcome::Exact(value);
                        }
                    }
                    Outcome::Sampled(pixel.sampled_value(scene, &emitter, params, index))
                })
                .collect();
            row_done();
            row
        })
        .collect();

    let mut out = SoftReference {
        width: hard.width,
        height: hard.height,
        visibility: Vec::with_capacity(hard.receiver.len()),
        exact: Vec::with_capacity(hard.receiver.len()),
        exact_pixels: 0,
        sampled_pixels: 0,
        samples,
        standard_error_bound: 0.5 / f64::from(samples).sqrt(),
    };
    for outcome in rows.into_iter().flatten() {
        let (value, exact) = match outcome {
            Outcome::Background => (f64::NAN, false),
            Outcome::Exact(value) => {
                out.exact_pixels += 1;
                (value, true)
            }
            Outcome::Sampled(value) => {
                out.sampled_pixels += 1;
                (value, false)
            }
        };
        out.visibility.push(value);
        out.exact.push(exact);
    }
    Ok(out)
}

/// Checks the sizes of `hard` and that every pixel has both a finite position and
/// a receiver triangle of `scene`, or neither.
fn check_hard_reference(scene: &RefScene, hard: &VisibilityReference) -> Result<(), String> {
    let count = hard.width as usize * hard.height as usize;
    if hard.position.len() != count || hard.receiver.len() != count {
        return Err(format!(
            "soft shadows: hard reference of {}x{} pixels has {} positions and {} receivers",
            hard.width,
            hard.height,
            hard.position.len(),
            hard.receiver.len()
        ));
    }
    let mismatch = hard
        .position
        .iter()
        .zip(&hard.receiver)
        .position(|(position, &receiver)| {
            let has_receiver = receiver != u32::MAX;
            has_receiver != position.is_finite()
                || (has_receiver && receiver as usize >= scene.triangle_count())
        });
    match mismatch {
        Some(index) => Err(format!(
            "soft shadows: pixel {index} of the hard reference has position {} and receiver {}, \
             inconsistent with each other or with a scene of {} triangles",
            hard.position[index],
            hard.receiver[index],
            scene.triangle_count()
        )),
        None => Ok(()),
    }
}

/// Result of one pixel.
enum Outcome {
    Background,
    Exact(f64),
    Sampled(f64),
}

/// Orthonormal frame whose third axis is `axis`.
#[derive(Debug, Clone, Copy)]
struct Frame {
    tangent: DVec3,
    bitangent: DVec3,
    axis: DVec3,
}

impl Frame {
    fn new(axis: DVec3) -> Self {
        let (tangent, bitangent) = axis.any_orthonormal_pair();
        Self {
            tangent,
            bitangent,
            axis,
        }
    }
}

/// A validated light, ready for sampling.
#[derive(Debug, Clone, Copy)]
enum Emitter {
    /// Cone of directions of half-angle `angular_radius` around `frame.axis` (the
    /// unit direction to the light).
    Cap {
        frame: Frame,
        angular_radius: f64,
        /// `1 - cos(angular_radius)`, computed without cancellation.
        one_minus_cos: f64,
    },
    /// Disk of radius `radius` centred at `centre` in the plane spanned by
    /// `frame.tangent` and `frame.bitangent`.
    Disk {
        centre: DVec3,
        radius: f64,
        frame: Frame,
    },
}

impl Emitter {
    fn new(light: &AreaLight) -> Result<Self, String> {
        match *light {
            AreaLight::Directional {
                direction,
                angular_radius,
            } => {
                let to_light = -direction.normalize_or_zero();
                if !direction.is_finite() || to_light == DVec3::ZERO {
                    return Err(format!(
                        "soft shadows: directional light direction {direction} must be finite and non-zero"
                    ));
                }
                if !(angular_radius > 0.0 && angular_radius < FRAC_PI_2) {
                    return Err(format!(
                        "soft shadows: directional light angular radius {angular_radius} must be in (0, π/2) radians"
                    ));
                }
                let half_sine = (0.5 * angular_radius).sin();
                Ok(Self::Cap {
                    frame: Frame::new(to_light),
                    angular_radius,
                    one_minus_cos: 2.0 * half_sine * half_sine,
                })
            }
            AreaLight::Disk {
                position,
                radius,
                axis,
            } => {
                if !position.is_finite() {
                    return Err(format!(
                        "soft shadows: disk light position {position} is not finite"
                    ));
                }
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(format!(
                        "soft shadows: disk light radius {radius} must be finite and positive"
                    ));
                }
                let unit_axis = axis.normalize_or_zero();
                if !axis.is_finite() || unit_axis == DVec3::ZERO {
                    return Err(format!(
                        "soft shadows: disk light axis {axis} must be finite and non-zero"
                    ));
                }
                Ok(Self::Disk {
                    centre: position,
                    radius,
                    frame: Frame::new(unit_axis),
                })
            }
        }
    }

    /// Maps the point `(u, v)` of `[0, 1]²` to a unit direction from `origin` to
    /// the light and the distance along it to the sample (infinite for a cap). A
    /// sample at `origin` itself gives the zero direction.
    fn sample(&self, origin: DVec3, u: f64, v: f64) -> (DVec3, f64) {
        match *self {
            Self::Cap {
                frame,
                one_minus_cos: h,
                ..
            } => {
                let x = u * h; // 1 - cos θ
                let cos_theta = 1.0 - x;
                let sin_theta = (x * (2.0 - x)).max(0.0).sqrt();
                let (sin_phi, cos_phi) = (TAU * v).sin_cos();
                let dir = frame.axis * cos_theta
                    + (frame.tangent * cos_phi + frame.bitangent * sin_phi) * sin_theta;
                (dir, f64::INFINITY)
            }
            Self::Disk {
                centre,
                radius,
                frame,
            } => {
                let (x, y) = concentric_disk(u, v);
                let point = centre + (frame.tangent * x + frame.bitangent * y) * radius;
                let offset = point - origin;
                let distance = offset.length();
                (offset.normalize_or_zero(), distance)
            }
        }
    }

    /// A cone with apex `apex` that contains every sample direction, or `None`
    /// when the light is too close to `apex` to fit in one.
    fn cone(&self, apex: DVec3) -> Option<LightCone> {
        match *self {
            Self::Cap {
                frame,
                angular_radius,
                ..
            } => Some(LightCone {
                apex,
                axis: frame.axis,
                half_angle: angular_radius,
                reach: f64::INFINITY,
            }),
            Self::Disk { centre, radius, .. } => {
                let offset = centre - apex;
                let distance = offset.length();
                (distance.is_finite() && distance > radius * (1.0 + 1e-9)).then(|| LightCone {
                    apex,
                    axis: offset / distance,
                    half_angle: (radius / distance).asin(),
                    reach: distance + radius,
                })
            }
        }
    }
}

/// Shirley and Chiu's concentric map from `[0, 1]²` onto the unit disk
/// (area-preserving, so equal-area strata stay equal-area).
fn concentric_disk(u: f64, v: f64) -> (f64, f64) {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    let (sin_phi, cos_phi) = phi.sin_cos();
    (r * cos_phi, r * sin_phi)
}

/// A cone of directions from `apex`, cut at distance `reach` from it.
#[derive(Debug, Clone, Copy)]
struct LightCone {
    apex: DVec3,
    /// Unit axis.
    axis: DVec3,
    /// Half-angle in `(0, π/2)`.
    half_angle: f64,
    /// Largest distance from the apex that matters (infinite for a distant light).
    reach: f64,
}

/// Angle between two non-zero vectors, accurate near 0 and π.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// A receiver point and what its samples need.
struct Receiver {
    position: DVec3,
    triangle: usize,
    /// Unit normal facing the camera.
    normal: DVec3,
    /// Shadow-ray offset: hits at `s <= offset` are ignored.
    offset: f64,
}

impl Receiver {
    fn new(scene: &RefScene, position: DVec3, triangle: usize, camera: DVec3) -> Self {
        let [a, b, c] = scene.triangle(triangle);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let normal = if normal.dot(camera - position) < 0.0 {
            -normal
        } else {
            normal
        };
        Self {
            position,
            triangle,
            normal,
            offset: RELATIVE_RAY_OFFSET * (1.0 + position.length()),
        }
    }

    /// 1 or 0 when provable without sampling, else `None`.
    fn exact_value(&self, scene: &RefScene, emitter: &Emitter) -> Option<f64> {
        let cone = emitter.cone(self.position)?;
        let facing = angle_between(self.normal, cone.axis);
        if !facing.is_finite() || self.normal == DVec3::ZERO {
            return None;
        }
        if facing - cone.half_angle > FRAC_PI_2 + ANGLE_MARGIN {
            return Some(0.0);
        }
        let steepest = facing + cone.half_angle + ANGLE_MARGIN;
        if steepest >= FRAC_PI_2 {
            return None;
        }
        let clearance = Clearance {
            cone,
            receiver: self.triangle,
            normal: self.normal,
            // Every sample direction L has n · L >= cos(steepest), so a point x with
            // n · (x - P) <= floor lies at s <= floor / cos(steepest) = offset / 2.
            floor: 0.5 * self.offset * steepest.cos(),
        };
        let blocked = scene.any_triangle(
            |min, max| clearance.box_may_meet(min, max),
            |i| clearance.triangle_may_meet(&scene.triangle(i), i),
        );
        (!blocked).then_some(1.0)
    }

    /// The fraction of unblocked samples (rule 3 of [`soft_visibility`]).
    fn sampled_value(
        &self,
        scene: &RefScene,
        emitter: &Emitter,
        params: &SoftParams,
        pixel: usize,
    ) -> f64 {
        let mut rng = SplitMix64::new(params.seed ^ (pixel as u64).wrapping_mul(SplitMix64::GAMMA));
        let n = params.strata;
        let cell = 1.0 / f64::from(n);
        let mut visible = 0u32;
        for i in 0..n {
            for j in 0..n {
                let u = (f64::from(i) + rng.next_f64()) * cell;
                let v = (f64::from(j) + rng.next_f64()) * cell;
                let (dir, distance) = emitter.sample(self.position, u, v);
                if self.normal.dot(dir) > 0.0 && !self.occluded(scene, dir, distance) {
                    visible += 1;
                }
            }
        }
        f64::from(visible) / f64::from(n * n)
    }

    /// Whether a usable triangle other than the receiver is hit at `s` in
    /// `(offset, distance)`.
    fn occluded(&self, scene: &RefScene, dir: DVec3, distance: f64) -> bool {
        let origin = self.position;
        let mut blocked = false;
        scene.traverse(origin, dir, self.offset, distance, 0.0, |i, t_max| {
            if i == self.triangle || !scene.casts(i) {
                return;
            }
            if let Some((s, _)) = intersect_watertight(origin, dir, &scene.triangle(i)) {
                if s > self.offset && s < distance {
                    blocked = true;
                    *t_max = f64::NEG_INFINITY;
                }
            }
        });
        blocked
    }
}

/// Conservative test of whether scene geometry may block a sample inside a
/// [`LightCone`] (a `false` is a proof; a `true` is not).
struct Clearance {
    cone: LightCone,
    receiver: usize,
    normal: DVec3,
    /// Points with `normal · (x - apex)` at most this cannot be hit past the
    /// shadow-ray offset.
    floor: f64,
}

impl Clearance {
    fn box_may_meet(&self, min: DVec3, max: DVec3) -> bool {
        let apex = self.cone.apex;
        let low = min - apex;
        let high = max - apex;
        let support = (self.normal * low).max(self.normal * high).element_sum();
        let error = RELATIVE_DOT_ERROR * low.abs().max(high.abs()).max_element();
        if support + error <= self.floor {
            return false;
        }
        let centre = (min + max) * 0.5;
        let radius = 0.5 * (max - min).length() * (1.0 + 1e-12)
            + RELATIVE_DOT_ERROR * min.abs().max(max.abs()).max(apex.abs()).max_element();
        self.sphere_may_meet(centre, radius)
    }

    /// Whether the ball `(centre, radius)` may meet the cone (angle and reach).
    fn sphere_may_meet(&self, centre: DVec3, radius: f64) -> bool {
        let offset = centre - self.cone.apex;
        let distance = offset.length();
        if distance.is_nan() || distance <= radius {
            return true;
        }
        if distance - radius > self.cone.reach * (1.0 + 1e-9) {
            return false;
        }
        let angle = angle_between(self.cone.axis, offset);
        let spread = (radius / distance).asin();
        angle <= self.cone.half_angle + spread + ANGLE_MARGIN
    }

    fn triangle_may_meet(&self, tri: &[DVec3; 3], index: usize) -> bool {
        if index == self.receiver {
            return false;
        }
        let mut min = tri[0];
        let mut max = tri[0];
        for p in &tri[1..] {
            min = min.min(*p);
            max = max.max(*p);
        }
        if !self.box_may_meet(min, max) {
            return false;
        }
        let apex = self.cone.apex;
        let offsets = tri.map(|p| p - apex);
        let above = offsets
            .iter()
            .map(|d| self.normal.dot(*d) + RELATIVE_DOT_ERROR * d.abs().max_element())
            .fold(f64::NEG_INFINITY, f64::max);
        if above <= self.floor {
            return false;
        }
        self.directions_may_meet(offsets)
    }

    /// Whether the cone of directions from the apex to the triangle with vertex
    /// offsets `offsets` (from the apex) may come within the cone's half-angle of
    /// its axis. Decided only when the triangle's plane is clear of the apex.
    fn directions_may_meet(&self, offsets: [DVec3; 3]) -> bool {
        let lengths = offsets.map(DVec3::length);
        if lengths.iter().any(|l| !(l.is_finite() && *l > 0.0)) {
            return true;
        }
        let [u0, u1, u2] = [0, 1, 2].map(|k| offsets[k] / lengths[k]);
        let det = u0.dot(u1.cross(u2));
        if det.is_nan() || det.abs() < MIN_DIRECTION_DETERMINANT {
            return true;
        }
        let axis = self.cone.axis;
        // The axis is inside the simplicial cone when all its barycentric
        // coordinates have the sign of the determinant.
        let inside = [u1.cross(u2), u2.cross(u0), u0.cross(u1)]
            .iter()
            .all(|face| axis.dot(*face) * det.signum() >= 0.0);
        if inside {
            return true;
        }
        let limit = self.cone.half_angle + ANGLE_MARGIN;
        [(u0, u1), (u1, u2), (u2, u0)]
            .into_iter()
            .any(|(p, q)| angle_to_wedge(axis, p, q) <= limit)
    }
}

/// Whether [`Clearance`] lets the infinite cone `(apex, axis, half_angle)` meet
/// `tri` (no receiver, no tangent-plane floor), for tests of its rigour.
#[cfg(test)]
pub(crate) fn cone_may_meet_triangle(
    apex: DVec3,
    axis: DVec3,
    half_angle: f64,
    tri: &[DVec3; 3],
) -> bool {
    let clearance = Clearance {
        cone: LightCone {
            apex,
            axis,
            half_angle,
            reach: f64::INFINITY,
        },
        receiver: usize::MAX,
        normal: axis,
        floor: f64::NEG_INFINITY,
    };
    clearance.triangle_may_meet(tri, 0)
}

/// Angle between the unit vector `a` and the wedge `{α p + β q : α, β >= 0}` of two
/// non-parallel unit vectors.
fn angle_to_wedge(a: DVec3, p: DVec3, q: DVec3) -> f64 {
    let normal = p.cross(q).normalize();
    let height = a.dot(normal);
    let in_plane = a - normal * height;
    let between = p.cross(in_plane).dot(normal) >= 0.0 && in_plane.cross(q).dot(normal) >= 0.0;
    if between {
        height.abs().atan2(in_plane.length())
    } else {
        angle_between(a, p).min(angle_between(a, q))
    }
}
