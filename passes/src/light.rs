//! The light of a frame — directional (orthographic light frustum), spot (perspective light frustum) or
//! point (the six cube faces, built as one map) —, the frusta fitted to a light given without a matrix, and
//! the light-space constants every light-space pass derives from it, in frame coordinates.

use crate::gpu_types::GpuLight;
use crate::PassError;
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, Vec4};

/// The light whose shadows the pipeline computes. Matrices map world space to Vulkan clip space with
/// standard depth (the light's near plane at depth 0, farther points deeper; not reversed Z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Parallel light.
    Directional {
        /// Direction the light travels (normalised by the pipeline).
        direction: Vec3,
        /// Orthographic view-projection looking along `direction` and enclosing the shadow casters and
        /// receivers (world coordinates). Used by the primitive map and the shadow map alike.
        view_proj: Mat4,
    },
    /// Spot light: a point emitter with a perspective light frustum.
    Spot {
        /// Emitter position (world coordinates): shadow rays end there.
        position: Vec3,
        /// Axis of the cone (normalised by the pipeline): the direction the light points. It must agree
        /// with the view axis of `view_proj`.
        direction: Vec3,
        /// Perspective view-projection with its eye at `position`, covering the cone (world
        /// coordinates). Receivers outside it count as lit (no recorded occluder).
        view_proj: Mat4,
    },
    /// Point light: an emitter shadowed in every direction through its six cube faces
    /// ([`point_light_faces`]), built as one primitive map (`PrimitiveMapConfig::cube`): hard shadows, or
    /// area shadows of a sized emitter (its radius from the configuration), with compute binning
    /// ([`crate::ShadowConfig::shadows_point_as_cube`]). A shadow map and PCSS need one frustum each: for
    /// those the light is given as its faces, spot lights ([`point_light_faces`]), and the minimum taken.
    Point {
        /// Emitter position (world coordinates): shadow rays end there.
        position: Vec3,
        /// Range (`None`: unlimited): sets the near plane of the faces' projections.
        range: Option<f32>,
    },
}

impl Light {
    /// The light view-projection (world coordinates): a point light's +X face.
    pub fn view_proj(&self) -> Mat4 {
        match *self {
            Self::Directional { view_proj, .. } | Self::Spot { view_proj, .. } => view_proj,
            Self::Point { position, range } => point_light_faces(position, range)[0].view_proj(),
        }
    }

    /// The direction of travel (directional) or the cone axis (spot), as given; +X for a point light.
    pub fn direction(&self) -> Vec3 {
        match *self {
            Self::Directional { direction, .. } | Self::Spot { direction, .. } => direction,
            Self::Point { .. } => Vec3::X,
        }
    }

    /// The emitter position of a spot or point light.
    pub fn position(&self) -> Option<Vec3> {
        match *self {
            Self::Directional { .. } => None,
            Self::Spot { position, .. } | Self::Point { position, .. } => Some(position),
        }
    }

    /// "directional", "spot" or "point".
    pub fn kind_name(&self) -> &'static str {
        match self {
            Self::Directional { .. } => "directional",
            Self::Spot { .. } => "spot",
            Self::Point { .. } => "point",
        }
    }
}

/// Tangent of the half-angle of each cube face of a point light: a little over 45° so that every direction
/// lies strictly inside at least one face, whatever the rounding of its projection.
pub const CUBE_FACE_TAN_HALF: f32 = 1.0 + 1.0 / 256.0;

/// Widest spot cone (half-angle, radians) given one perspective frustum; wider cones are shadowed
/// through the cube faces around their axis.
pub const MAX_SINGLE_FRUSTUM_CONE: f32 = std::f32::consts::FRAC_PI_3;

/// Near plane of a perspective projection the plugin fits for a local light: this fraction of its range,
/// or [`DEFAULT_LOCAL_NEAR`] world units for a light of unlimited range. The far plane is at infinity.
pub const NEAR_FRACTION_OF_RANGE: f32 = 1.0 / 1024.0;

/// Near plane (world units) of a fitted projection for a light of unlimited range.
pub const DEFAULT_LOCAL_NEAR: f32 = 0.01;

/// The near plane of a projection fitted for a local light of `range` (`None`: unlimited).
fn fitted_near(range: Option<f32>) -> f32 {
    range.map_or(DEFAULT_LOCAL_NEAR, |r| r * NEAR_FRACTION_OF_RANGE)
}

/// The light of a perspective frustum at `position` looking along `forward` (unit), `tan_half` wide on both
/// axes, with standard depth from `near` to infinity.
fn perspective(position: Vec3, forward: Vec3, up: Vec3, tan_half: f32, near: f32) -> Light {
    let view = Mat4::look_to_rh(position, forward, up);
    Light::Spot {
        position,
        direction: forward,
        view_proj: Mat4::perspective_infinite_rh(2.0 * tan_half.atan(), 1.0, near) * view,
    }
}

/// Names of a point light's cube faces, in the order of [`point_light_faces`].
pub const POINT_FACE_NAMES: [&str; 6] = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"];

/// The name of a point light's one frustum when its faces are built as one cube map.
pub const CUBE_MAP_NAME: [&str; 1] = ["cube"];

/// Names of the faces of a spot light wider than [`MAX_SINGLE_FRUSTUM_CONE`], in the order of
/// [`spot_light_frusta`]: its axis, then the four directions across it.
pub const SPOT_FACE_NAMES: [&str; 5] = ["front", "right", "left", "up", "down"];

/// The names of a light's frusta in reports: its cube faces (`count` 6: a point light's; 5: a wide spot
/// light's), else "whole" for its one frustum.
pub fn frustum_names(count: usize) -> &'static [&'static str] {
    match count {
        6 => &POINT_FACE_NAMES,
        5 => &SPOT_FACE_NAMES,
        _ => &["whole"],
    }
}

/// The frusta that shadow a point light at `position` of `range` (`None`: unlimited): the six cube faces
/// along ±X, ±Y, ±Z, each [`CUBE_FACE_TAN_HALF`] wide, so that every direction lies inside one. A pixel
/// outside a face's frustum is lit in that face's visibility: the light's visibility is the minimum over
/// its faces.
pub fn point_light_faces(position: Vec3, range: Option<f32>) -> [Light; 6] {
    let near = fitted_near(range);
    [
        (Vec3::X, Vec3::Y),
        (Vec3::NEG_X, Vec3::Y),
        (Vec3::Y, Vec3::Z),
        (Vec3::NEG_Y, Vec3::Z),
        (Vec3::Z, Vec3::Y),
        (Vec3::NEG_Z, Vec3::Y),
    ]
    .map(|(forward, up)| perspective(position, forward, up, CUBE_FACE_TAN_HALF, near))
}

/// The frusta that shadow a spot light at `position` pointing along `direction` with a cone of half-angle
/// `outer_cone` (radians, in (0, π/2]) and `range`: one perspective frustum just wider than the cone up to
/// [`MAX_SINGLE_FRUSTUM_CONE`], else the cube faces around its axis that the cone reaches (its axis and the
/// four across it).
pub fn spot_light_frusta(
    position: Vec3,
    direction: Vec3,
    outer_cone: f32,
    range: Option<f32>,
) -> Vec<Light> {
    let axis = direction.normalize();
    let near = fitted_near(range);
    if outer_cone <= MAX_SINGLE_FRUSTUM_CONE {
        let tan_half = outer_cone.tan() * CUBE_FACE_TAN_HALF;
        return vec![perspective(
            position,
            axis,
            light_fit::up_hint(axis),
            tan_half,
            near,
        )];
    }
    let right = axis.cross(light_fit::up_hint(axis)).normalize();
    let up = right.cross(axis);
    [
        (axis, up),
        (right, up),
        (-right, up),
        (up, axis),
        (-up, axis),
    ]
    .into_iter()
    .map(|(forward, up)| perspective(position, forward, up, CUBE_FACE_TAN_HALF, near))
    .collect()
}

/// A directional light travelling along `direction`, with the orthographic frustum the plugin fits to the
/// scene's `bounds` (world-space min and max corners): their light-space x/y range maps exactly onto clip
/// `[-1, 1]²`, and their depth range, widened by 1% on both sides plus a tiny margin, onto depth `[0, 1]`
/// (near to far, standard depth). The light's view looks at the centre of the bounds' bounding sphere from
/// twice its radius away, +Y up unless the direction is within about 1° of ±Y (then +Z). Degenerate extents
/// (flat bounds seen edge-on, a single point) are widened to the tiny margin: 1e-4 of the sphere's radius
/// plus 1e-5 of the centre's largest coordinate. The construction is [`light_fit::directional_view_proj`],
/// which `scene::DirectionalLight::view_proj` calls too: a host fitting the same bounds gets the same
/// matrix. `direction` is
/// kept as given in the light (the passes normalise it in f64).
///
/// # Errors
///
/// A zero or non-finite `direction`; `bounds` that are not finite, whose min exceeds their max, or too large
/// to measure in f32.
pub fn directional_light_frustum(direction: Vec3, bounds: [Vec3; 2]) -> Result<Light, PassError> {
    let unit = direction.try_normalize().ok_or_else(|| {
        invalid(&format!(
            "a directional light's direction must be finite and non-zero to fit its frustum, got {direction}"
        ))
    })?;
    let [lo, hi] = bounds;
    if !(lo.is_finite() && hi.is_finite()) || lo.cmpgt(hi).any() {
        return Err(invalid(&format!(
            "the bounds a directional light's frustum is fitted to must be finite with min not above max, got {lo} to {hi}"
        )));
    }
    let (center, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
    if !(center.is_finite() && radius.is_finite()) {
        return Err(invalid(&format!(
            "the bounds {lo} to {hi} are too large to fit a directional light's frustum to"
        )));
    }
    Ok(Light::Directional {
        direction,
        view_proj: light_fit::directional_view_proj(unit, lo, hi),
    })
}

/// Relative tolerance of the checks that a matrix matches the light it is given for.
const MATCH_TOLERANCE: f64 = 1e-3;

/// The light in frame coordinates, validated, with what light-space passes need.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LightFrame {
    /// View-projection applied to frame coordinates.
    pub view_proj: Mat4,
    /// Its inverse.
    pub inv_view_proj: Mat4,
    /// Unit direction of travel (directional) or unit view axis (spot).
    pub direction: Vec3,
    /// Spot position in frame coordinates.
    pub position: Option<Vec3>,
    /// Linear depth (world units along the light axis) of NDC `c = (x, y, d, 1)` is
    /// `dot(lin_num, c) / dot(lin_den, c)`.
    pub lin_num: Vec4,
    /// See `lin_num`.
    pub lin_den: Vec4,
    /// View-projection of each frustum in frame coordinates: `view_proj`, or a point light's six faces.
    pub frusta: [Mat4; 6],
    /// Frusta in use in `frusta`: 1 or 6.
    pub frustum_count: usize,
}

/// `m * translation(origin)` in f64: `m` applied to coordinates relative to `origin`.
pub(crate) fn rebased(m: Mat4, origin: DVec3) -> DMat4 {
    m.as_dmat4() * DMat4::from_translation(origin)
}

fn invalid(what: &str) -> PassError {
    PassError::InvalidConfig(what.to_owned())
}

impl LightFrame {
    /// Validates `light` and moves it into the frame whose origin is `origin`.
    pub fn new(light: &Light, origin: DVec3) -> Result<Self, PassError> {
        if let Light::Point { position, range } = *light {
            return Self::point(position, range, origin);
        }
        let m = rebased(light.view_proj(), origin);
        let dir = light.direction().as_dvec3().normalize_or_zero();
        if !m.is_finite() || dir == DVec3::ZERO || !dir.is_finite() {
            return Err(invalid(
                "the light's direction and view-projection must be finite and non-zero",
            ));
        }
        let det = m.determinant();
        if det == 0.0 || !det.is_finite() {
            return Err(invalid("the light view-projection is not invertible"));
        }
        let inv = m.inverse();
        let (axis, position, a) = match light {
            Light::Directional { .. } => {
                // Orthographic along the light: travelling along `dir` changes depth only.
                let c = m * dir.extend(0.0);
                let scale = c.z.abs();
                if c.z <= 0.0
                    || c.x.abs() > MATCH_TOLERANCE * scale
                    || c.y.abs() > MATCH_TOLERANCE * scale
                    || c.w.abs() > MATCH_TOLERANCE * scale
                {
                    return Err(invalid(
                        "a directional light needs an orthographic view-projection looking along its \
                         direction with depth increasing away from the light (not reversed Z)",
                    ));
                }
                (dir, None, dir.extend(0.0))
            }
            Light::Spot { position, .. } | Light::Point { position, .. } => {
                let p = position.as_dvec3() - origin;
                if !p.is_finite() {
                    return Err(invalid("the spot light position is not finite"));
                }
                // The eye of a perspective projection maps to clip (0, 0, z, 0).
                let eye = m * p.extend(1.0);
                let off_eye = [0, 1, 3].into_iter().any(|i| {
                    let row = m.row(i);
                    eye[i].abs() > MATCH_TOLERANCE * (row.truncate().length() * (1.0 + p.length()))
                });
                let w_axis = m.row(3).truncate();
                let len = w_axis.length();
                if len == 0.0 || off_eye {
                    return Err(invalid(
                        "a spot light needs a perspective view-projection whose eye is at its position",
                    ));
                }
                let axis = w_axis / len;
                if axis.dot(dir) < 0.99 {
                    return Err(invalid(
                        "the spot light direction does not match the view axis of its view-projection",
                    ));
                }
                let depth_at = |t: f64| {
                    let c = m * (p + axis * t).extend(1.0);
                    c.z / c.w
                };
                if depth_at(2.0) <= depth_at(1.0) {
                    return Err(invalid(
                        "the spot light projection must use standard depth (near 0, far 1), not reversed Z",
                    ));
                }
                (axis, Some(p), axis.extend(-axis.dot(p)))
            }
        };
        // With X_h = inv * c and X = X_h.xyz / X_h.w: lin = dot(a, X_h) / X_h.w = dot(a.xyz, X) + a.w.
        let mut num = DVec4::ZERO;
        for i in 0..4 {
            num += inv.row(i) * a[i];
        }
        let den = inv.row(3);
        let frame = Self {
            view_proj: m.as_mat4(),
            inv_view_proj: inv.as_mat4(),
            direction: axis.as_vec3(),
            position: position.map(|p| p.as_vec3()),
            lin_num: num.as_vec4(),
            lin_den: den.as_vec4(),
            frusta: [m.as_mat4(); 6],
            frustum_count: 1,
        };
        if !frame.inv_view_proj.is_finite() || !frame.lin_num.is_finite() {
            return Err(invalid("the light view-projection is too ill-conditioned"));
        }
        Ok(frame)
    }

    /// A point light at `position` of `range`: its +X face as the light's one frustum (validated as a spot
    /// light's), and the six faces, each built in f64 around the light's position in frame coordinates.
    fn point(position: Vec3, range: Option<f32>, origin: DVec3) -> Result<Self, PassError> {
        if range.is_some_and(|r| !(r.is_finite() && r > 0.0)) {
            return Err(invalid(
                "a point light's range must be a positive finite distance",
            ));
        }
        let faces = point_light_faces(position, range);
        let mut frame = Self::new(&faces[0], origin)?;
        for (slot, face) in frame.frusta.iter_mut().zip(&faces) {
            *slot = rebased(face.view_proj(), origin).as_mat4();
        }
        frame.frustum_count = 6;
        if !frame.frusta.iter().all(Mat4::is_finite) {
            return Err(invalid("the point light's cube faces are not finite"));
        }
        Ok(frame)
    }

    /// The view-projections of the light's frusta in frame coordinates (one, or a point light's six).
    pub fn frusta(&self) -> &[Mat4] {
        &self.frusta[..self.frustum_count]
    }

    /// World size of one texel of a `size`² map: constant for a directional light, per unit of linear
    /// depth for a spot light (measured on the map's central texel, in f64).
    fn texel_world_size(&self, size: u32) -> f32 {
        let inv = self.inv_view_proj.as_dmat4();
        let at = |x: f64, y: f64| inv.project_point3(DVec3::new(x, y, 0.5));
        let step = 2.0 / f64::from(size.max(1));
        let c = at(0.0, 0.0);
        let s = 0.5 * ((at(step, 0.0) - c).length() + (at(0.0, step) - c).length());
        match self.position {
            None => s as f32,
            Some(p) => (s / (c - p.as_dvec3()).dot(self.direction.as_dvec3())) as f32,
        }
    }

    /// Shader constants for a `size`² shadow map and an emitter of `light_size` (tangent of the angular
    /// radius for a directional light, radius in world units for a spot light).
    pub fn gpu(&self, size: u32, light_size: f32) -> GpuLight {
        let (position, kind) = match self.position {
            None => (Vec4::ZERO, 0.0),
            Some(p) => (p.extend(1.0), 1.0),
        };
        GpuLight {
            view_proj: self.view_proj,
            inv_view_proj: self.inv_view_proj,
            lin_num: self.lin_num,
            lin_den: self.lin_den,
            position,
            direction: self.direction.extend(0.0),
            params: Vec4::new(self.texel_world_size(size), light_size, size as f32, kind),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn directional() -> Light {
        let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
        let view = Mat4::look_to_rh(-direction * 20.0, direction, Vec3::Y);
        Light::Directional {
            direction,
            view_proj: Mat4::orthographic_rh(-5.0, 5.0, -5.0, 5.0, 1.0, 40.0) * view,
        }
    }

    fn spot() -> Light {
        let position = Vec3::new(1.0, 6.0, 2.0);
        let direction = Vec3::new(0.0, -1.0, -0.3).normalize();
        let view = Mat4::look_to_rh(position, direction, Vec3::Y);
        Light::Spot {
            position,
            direction,
            view_proj: Mat4::perspective_rh(1.0, 1.0, 0.5, 30.0) * view,
        }
    }

    #[test]
    fn a_point_light_frame_holds_its_six_faces_in_frame_coordinates() {
        let origin = DVec3::new(1e4, 0.0, -2e3);
        let position = Vec3::new(10_003.0, 2.0, -1_998.5);
        let f = LightFrame::new(
            &Light::Point {
                position,
                range: Some(8.0),
            },
            origin,
        )
        .unwrap();
        assert_eq!(f.frusta().len(), 6);
        let p = (position.as_dvec3() - origin).as_vec3();
        assert_eq!(f.position, Some(p));
        // Each face sees the point one unit along its axis at its centre, in front of the light.
        let axes = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        for (m, axis) in f.frusta().iter().zip(axes) {
            let c = *m * (p + axis).extend(1.0);
            assert!(c.w > 0.0 && (c.x / c.w).abs() < 1e-3 && (c.y / c.w).abs() < 1e-3);
        }
        // Every direction lies strictly inside the face of its largest component.
        let d = Vec3::new(0.7, -0.7, 0.69).normalize();
        let c = f.frusta()[0] * (p + d).extend(1.0);
        assert!((c.x / c.w).abs() < 1.0 && (c.y / c.w).abs() < 1.0);
        assert!(LightFrame::new(
            &Light::Point {
                position,
                range: Some(-1.0),
            },
            origin
        )
        .is_err());
    }

    fn lin(f: &LightFrame, world: Vec3, origin: DVec3) -> f32 {
        let c = f
            .view_proj
            .project_point3((world.as_dvec3() - origin).as_vec3());
        let c = c.extend(1.0);
        f.lin_num.dot(c) / f.lin_den.dot(c)
    }

    #[test]
    fn linear_depth_is_distance_along_the_axis() {
        let origin = DVec3::new(3.0, 0.0, -1.0);
        let s = spot();
        let f = LightFrame::new(&s, origin).unwrap();
        let p = s.position().unwrap();
        for t in [0.7, 3.0, 12.0] {
            let x = p + s.direction() * t + Vec3::new(0.2, 0.0, 0.1).cross(s.direction());
            assert!((lin(&f, x, origin) - t).abs() < 1e-3 * t, "{t}");
        }
        let d = directional();
        let f = LightFrame::new(&d, origin).unwrap();
        let a = Vec3::new(0.5, 1.0, 0.0);
        let b = a + d.direction() * 2.5;
        assert!((lin(&f, b, origin) - lin(&f, a, origin) - 2.5).abs() < 1e-4);
    }

    #[test]
    fn texel_sizes() {
        let f = LightFrame::new(&directional(), DVec3::ZERO).unwrap();
        assert!((f.gpu(1000, 0.0).params.x - 0.01).abs() < 1e-6);
        let f = LightFrame::new(&spot(), DVec3::ZERO).unwrap();
        let expected = 2.0 * (0.5f32).tan() / 1000.0;
        assert!((f.gpu(1000, 0.0).params.x - expected).abs() < 1e-6);
    }

    /// Every direction projects strictly inside at least one cube face, and each face is a valid spot
    /// light of the pipeline; a narrow spot gets one frustum containing its cone, a wide one five faces.
    #[test]
    fn fitted_frusta_cover_their_lights() {
        let position = Vec3::new(1.0, 2.0, -3.0);
        let faces = point_light_faces(position, Some(10.0));
        let mut rng = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0
        };
        let inside = |light: &Light, p: Vec3| {
            let c = light.view_proj() * p.extend(1.0);
            c.w > 0.0 && c.x.abs() < c.w && c.y.abs() < c.w
        };
        for _ in 0..2000 {
            let d = Vec3::new(next(), next(), next());
            if d.length_squared() < 1e-6 {
                continue;
            }
            let p = position + d * 5.0;
            assert!(faces.iter().any(|f| inside(f, p)), "{d}");
        }
        for f in &faces {
            LightFrame::new(f, DVec3::ZERO).unwrap();
        }
        let narrow = spot_light_frusta(position, Vec3::new(0.2, -1.0, 0.1), 0.5, None);
        assert_eq!(narrow.len(), 1);
        LightFrame::new(&narrow[0], DVec3::new(4.0, 0.0, 1.0)).unwrap();
        let axis = Vec3::new(0.2, -1.0, 0.1).normalize();
        for _ in 0..500 {
            let d = (axis + Vec3::new(next(), next(), next()) * 0.45).normalize();
            if d.angle_between(axis) < 0.5 {
                assert!(inside(&narrow[0], position + d * 3.0), "{d}");
            }
        }
        let wide = spot_light_frusta(position, axis, 1.4, Some(20.0));
        assert_eq!(wide.len(), 5);
        for _ in 0..500 {
            let d = Vec3::new(next(), next(), next()).normalize();
            if d.angle_between(axis) < 1.4 {
                assert!(wide.iter().any(|f| inside(f, position + d * 3.0)), "{d}");
            }
        }
    }

    /// Directions of every kind: slanted, straight down and up (+Z up), within 1° of vertical, horizontal,
    /// grazing.
    fn sun_directions() -> [Vec3; 7] {
        [
            Vec3::new(0.68, -1.0, 0.05),
            Vec3::NEG_Y,
            Vec3::Y,
            Vec3::new(0.001, -1.0, 0.0),
            Vec3::X,
            Vec3::new(0.3, -0.2, 0.9),
            Vec3::new(-1.0, -0.05, 0.2),
        ]
    }

    /// Every corner of `bounds` in clip x, y within [-1, 1] and depth within [0, 1], up to `tolerance`
    /// (evaluated in f64); returns the largest |x| and |y|.
    fn assert_corners_inside(light: &Light, [lo, hi]: [Vec3; 2], tolerance: f64) -> (f64, f64) {
        let m = light.view_proj();
        assert!(m.is_finite(), "{light:?}");
        let (mut x, mut y) = (0.0f64, 0.0f64);
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let clip = m.as_dmat4() * corner.as_dvec3().extend(1.0);
            assert!((clip.w - 1.0).abs() < 1e-6, "orthographic: w {}", clip.w);
            assert!(
                clip.x.abs() <= 1.0 + tolerance
                    && clip.y.abs() <= 1.0 + tolerance
                    && (-tolerance..=1.0 + tolerance).contains(&clip.z),
                "{:?}: corner {corner} maps to {clip}",
                light.direction()
            );
            (x, y) = (x.max(clip.x.abs()), y.max(clip.y.abs()));
        }
        (x, y)
    }

    /// The fitted frustum encloses the bounds tightly (x and y reach ±1) in every direction, and is a valid
    /// directional light of the pipeline (orthographic along its direction), far from the origin too. (A
    /// world-space f32 matrix, computed in f32 as hosts do, resolves clip space only to about 1e-6 times
    /// the bounds' distance from the origin over their extent: the tolerance away from it.)
    #[test]
    fn a_fitted_directional_frustum_encloses_its_bounds_tightly() {
        let boxes = [
            (
                [Vec3::new(-4.0, -0.1, -4.0), Vec3::new(4.0, 2.0, 4.0)],
                1e-5,
            ),
            (
                [Vec3::new(97.0, 0.0, -200.0), Vec3::new(105.0, 7.0, -199.0)],
                1e-4,
            ),
            (
                [
                    Vec3::new(1e4 - 3.0, 0.0, -2e4),
                    Vec3::new(1e4 + 5.0, 7.0, -2e4 + 1.0),
                ],
                4e-3,
            ),
        ];
        for (bounds, tolerance) in boxes {
            for direction in sun_directions() {
                let light = directional_light_frustum(direction, bounds).expect("fitted");
                assert_eq!(light.direction(), direction, "kept as given");
                let (x, y) = assert_corners_inside(&light, bounds, tolerance);
                assert!(
                    (x - 1.0).abs() < tolerance && (y - 1.0).abs() < tolerance,
                    "{direction}: {x} {y}"
                );
                LightFrame::new(&light, (bounds[0] + bounds[1]).as_dvec3() * 0.5)
                    .expect("a valid directional light");
            }
        }
    }

    /// Flat bounds (a ground plane seen edge-on by a horizontal light) and a single point get finite,
    /// invertible frusta enclosing them.
    #[test]
    fn degenerate_bounds_get_finite_frusta() {
        let flat = [Vec3::new(0.0, 1.0, -8.0), Vec3::new(10.0, 1.0, 2.0)];
        let point = [Vec3::splat(2.0); 2];
        for bounds in [flat, point] {
            for direction in sun_directions() {
                let light = directional_light_frustum(direction, bounds).expect("fitted");
                assert_corners_inside(&light, bounds, 1e-5);
                LightFrame::new(&light, DVec3::ZERO).expect("a valid directional light");
            }
        }
    }

    #[test]
    fn a_directional_frustum_needs_a_direction_and_bounds() {
        let bounds = [Vec3::splat(-1.0), Vec3::ONE];
        for direction in [
            Vec3::ZERO,
            Vec3::new(f32::NAN, -1.0, 0.0),
            Vec3::new(0.0, f32::INFINITY, 0.0),
        ] {
            let e = directional_light_frustum(direction, bounds)
                .expect_err("refused")
                .to_string();
            assert!(e.contains("direction must be finite and non-zero"), "{e}");
        }
        for bad in [
            [Vec3::ONE, Vec3::ZERO],
            [Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE],
            [Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX)],
        ] {
            let e = directional_light_frustum(Vec3::NEG_Y, bad)
                .expect_err("refused")
                .to_string();
            assert!(e.contains("bounds"), "{e}");
        }
    }

    #[test]
    fn mismatched_lights_are_rejected() {
        let Light::Directional { view_proj, .. } = directional() else {
            unreachable!()
        };
        let wrong = Light::Directional {
            direction: Vec3::X,
            view_proj,
        };
        assert!(LightFrame::new(&wrong, DVec3::ZERO).is_err());
        let Light::Spot {
            position,
            direction,
            view_proj,
        } = spot()
        else {
            unreachable!()
        };
        let moved = Light::Spot {
            position: position + Vec3::X,
            direction,
            view_proj,
        };
        assert!(LightFrame::new(&moved, DVec3::ZERO).is_err());
        let reversed = Light::Spot {
            position,
            direction,
            view_proj: Mat4::perspective_infinite_reverse_rh(1.0, 1.0, 0.5)
                * Mat4::look_to_rh(position, direction, Vec3::Y),
        };
        assert!(LightFrame::new(&reversed, DVec3::ZERO).is_err());
        let nan = Light::Directional {
            direction: Vec3::NAN,
            view_proj,
        };
        assert!(LightFrame::new(&nan, DVec3::ZERO).is_err());
        let singular = Light::Directional {
            direction: Vec3::NEG_Y,
            view_proj: Mat4::ZERO,
        };
        assert!(LightFrame::new(&singular, DVec3::ZERO).is_err());
    }
}
