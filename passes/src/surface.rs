//! The engine's surface as its G-buffer holds it: how its normal image encodes the normal (or that it has
//! none), in which space, and which depth marks the background. Pure: the constants the passes decode it
//! with (`engine_surface.glsl`).
//!
//! The plugin uses the normal twice: a receiver whose normal faces away from the light is in its own shadow
//! (as the engine shades it), and the ray origin moves off the surface along the normal by the bound on the
//! rebuilt point's error. A normal that is not the geometric one (a shading normal, a quantized encoding, one
//! derived from depth) tilts that move by its angle θ to the geometric normal, so the origin clears the
//! surface by cos θ of the bound: for the quantized encodings θ is below 0.5° (cos θ > 0.99996), inside the
//! bound's margin; for a shading normal that departs from the geometry, the shadow is exact for the surface
//! that normal describes, as the engine's shading is.

use glam::{Mat3, Mat4, UVec4, Vec4};
use rhi::Format;

/// How the engine's normal image encodes the surface normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NormalEncoding {
    /// xyz as stored, w = 0 on background pixels (the plugin's original contract).
    XyzCoverage,
    /// xyz as stored; background pixels are known by their depth.
    Xyz,
    /// Octahedral in the first two channels; background pixels are known by their depth.
    Octahedral,
    /// No normal image: the normal is derived from depth, from the neighbouring pixels on the same surface.
    FromDepth,
}

/// The space of the engine's normals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NormalSpace {
    /// World space.
    World,
    /// The camera's view space (`FrameInputs::view`'s rotation).
    View,
}

/// What the engine's G-buffer holds for the passes: its normal's encoding and space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SurfaceInput {
    /// The encoding.
    pub encoding: NormalEncoding,
    /// The space.
    pub space: NormalSpace,
}

impl Default for SurfaceInput {
    /// World-space xyz with coverage in w, the plugin's original contract.
    fn default() -> Self {
        Self {
            encoding: NormalEncoding::XyzCoverage,
            space: NormalSpace::World,
        }
    }
}

impl SurfaceInput {
    /// Whether a normal image of `format` can hold this encoding: xyz needs four channels, an octahedral
    /// encoding two or more; a normal derived from depth needs no image.
    pub fn accepts(&self, format: Format) -> bool {
        match self.encoding {
            NormalEncoding::XyzCoverage | NormalEncoding::Xyz => format.channels() == 4,
            NormalEncoding::Octahedral => format.channels() >= 2,
            NormalEncoding::FromDepth => true,
        }
    }

    /// The sine of the largest angle by which a normal image of `format` tilts the normal it holds in this
    /// encoding (0 for normals derived from depth): three times a channel's rounding error e, which bounds
    /// the tilt of an xyz encoding (√3 e) and of an octahedral one (2√2 e). Below it the passes let the
    /// normal derived from depth decide whether a receiver faces the light.
    pub fn normal_precision(&self, format: Format) -> f32 {
        let e = match format {
            _ if self.encoding == NormalEncoding::FromDepth => return 0.0,
            Format::Rgba32Float => f32::EPSILON / 2.0,
            Format::Rgba16Float | Format::Rg16Float => 1.0 / 2048.0,
            Format::Rg16Unorm => 1.0 / 65535.0,
            Format::Rg16Snorm => 0.5 / 32767.0,
            Format::Rgb10A2Unorm => 1.0 / 1023.0,
            _ => 1.0 / 255.0,
        };
        3.0 * e
    }

    /// The shader's mode vector for a normal image of `format`: x the encoding, y whether the channels are
    /// normalized to [0, 1] (mapped to [-1, 1]), z whether the normal is in view space.
    pub fn mode(&self, format: Format) -> UVec4 {
        let encoding = match self.encoding {
            NormalEncoding::XyzCoverage => 0,
            NormalEncoding::Xyz => 1,
            NormalEncoding::Octahedral => 2,
            NormalEncoding::FromDepth => 3,
        };
        UVec4::new(
            encoding,
            u32::from(format.is_unorm()),
            u32::from(self.space == NormalSpace::View),
            0,
        )
    }
}

/// The depth a projection gives points infinitely far along the view axis, clamped to [0, 1]: where
/// the engine's background lies (0 for reversed Z, 1 for standard Z, finite or infinite far plane).
pub fn background_depth(proj: Mat4) -> f32 {
    // z_clip = m22 z + m32 and w_clip = m23 z + m33 for view-space z; z -> -infinity.
    let (m22, m23) = (proj.z_axis.z, proj.z_axis.w);
    let limit = if m23 != 0.0 {
        m22 / m23
    } else if m22 < 0.0 {
        f32::INFINITY
    } else {
        f32::NEG_INFINITY
    };
    limit.clamp(0.0, 1.0)
}

/// The rotation from the camera's view space to world space, as a matrix with no translation.
pub fn view_to_world(view: Mat4) -> Mat4 {
    Mat4::from_mat3(Mat3::from_mat4(view).inverse())
}

/// The relative precision of a linear view-Z image of `format` (`R32_SFLOAT` or `R16_SFLOAT`: its value's
/// rounding either way), or 0 for a depth image, which holds the projection's depth.
pub fn view_z_precision(format: Format) -> f32 {
    match format {
        Format::R32Float => f32::EPSILON,
        Format::R16Float => 1.0 / 1024.0,
        _ => 0.0,
    }
}

/// The shader's surface vector: x the background depth of `proj`, y the view-Z precision of a depth image
/// of `depth_format` ([`view_z_precision`]), z the normal image's precision
/// ([`SurfaceInput::normal_precision`]).
pub fn surface_vector(proj: Mat4, depth_format: Format, normal_precision: f32) -> Vec4 {
    Vec4::new(
        background_depth(proj),
        view_z_precision(depth_format),
        normal_precision,
        0.0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn background_depth_follows_the_projection() {
        let (fov, aspect, near, far) = (1.0, 1.5, 0.1, 100.0);
        assert_eq!(
            background_depth(Mat4::perspective_infinite_reverse_rh(fov, aspect, near)),
            0.0
        );
        assert_eq!(
            background_depth(Mat4::perspective_rh(fov, aspect, far, near)),
            0.0
        );
        assert_eq!(
            background_depth(Mat4::perspective_rh(fov, aspect, near, far)),
            1.0
        );
        assert_eq!(
            background_depth(Mat4::perspective_infinite_rh(fov, aspect, near)),
            1.0
        );
        assert_eq!(
            background_depth(Mat4::orthographic_rh(-1.0, 1.0, -1.0, 1.0, near, far)),
            1.0
        );
    }

    #[test]
    fn view_z_images_say_their_precision() {
        let proj = Mat4::perspective_infinite_reverse_rh(1.0, 1.5, 0.1);
        assert_eq!(surface_vector(proj, Format::D32Float, 0.0).y, 0.0);
        assert_eq!(surface_vector(proj, Format::D24UnormS8Uint, 0.0).y, 0.0);
        assert_eq!(surface_vector(proj, Format::R32Float, 0.0).y, f32::EPSILON);
        assert_eq!(surface_vector(proj, Format::R16Float, 0.0).y, 1.0 / 1024.0);
    }

    #[test]
    fn normal_precision_follows_the_channels() {
        let xyz = SurfaceInput {
            encoding: NormalEncoding::Xyz,
            space: NormalSpace::World,
        };
        let rgba8 = xyz.normal_precision(Format::Rgba8Unorm);
        // An 8-bit channel tilts the normal by up to about 0.4°: more than a light 0.1° from grazing.
        assert!(rgba8 > 0.1f32.to_radians().sin() && rgba8 < 1.0f32.to_radians().sin());
        assert!(xyz.normal_precision(Format::Rgba32Float) < 1e-6);
        let oct = SurfaceInput {
            encoding: NormalEncoding::Octahedral,
            ..xyz
        };
        assert!(
            oct.normal_precision(Format::Rg16Unorm) < oct.normal_precision(Format::Rgb10A2Unorm)
        );
        let derived = SurfaceInput {
            encoding: NormalEncoding::FromDepth,
            ..xyz
        };
        assert_eq!(derived.normal_precision(Format::Rgba8Unorm), 0.0);
    }

    #[test]
    fn modes_and_formats() {
        let oct = SurfaceInput {
            encoding: NormalEncoding::Octahedral,
            space: NormalSpace::View,
        };
        assert_eq!(oct.mode(Format::Rg16Unorm), UVec4::new(2, 1, 1, 0));
        assert_eq!(oct.mode(Format::Rg16Snorm), UVec4::new(2, 0, 1, 0));
        assert!(oct.accepts(Format::Rg16Float) && oct.accepts(Format::Rgb10A2Unorm));
        let xyz = SurfaceInput {
            encoding: NormalEncoding::Xyz,
            space: NormalSpace::World,
        };
        assert!(xyz.accepts(Format::Rgba8Unorm) && !xyz.accepts(Format::Rg16Float));
        assert_eq!(
            SurfaceInput::default().mode(Format::Rgba32Float),
            UVec4::ZERO
        );
    }

    #[test]
    fn view_to_world_undoes_the_view_rotation() {
        let view = Mat4::look_at_rh(Vec3::new(3.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y);
        let n_world = Vec3::new(0.3, 0.8, -0.5).normalize();
        let n_view = view.transform_vector3(n_world);
        let back = view_to_world(view).transform_vector3(n_view);
        assert!(back.abs_diff_eq(n_world, 1e-6), "{back}");
    }
}
