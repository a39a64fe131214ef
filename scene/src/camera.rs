//! The perspective camera.

use glam::{Mat4, Vec3};

use crate::Aabb;

/// A camera placed at its target: it looks nowhere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("camera position and target coincide")]
pub struct CoincidentCamera;

/// Perspective camera with a reversed-Z infinite projection (Vulkan depth range `[0, 1]`,
/// near plane at depth 1, infinity at depth 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position in world space.
    pub position: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Approximate up direction.
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y_radians: f32,
    /// Distance of the near plane (positive).
    pub near: f32,
}

impl Camera {
    /// World-to-view matrix: `Mat4::look_at_rh(position, target, up)`.
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, self.up)
    }

    /// View-to-clip matrix: `Mat4::perspective_infinite_reverse_rh(fov_y_radians, aspect, near)` with clip
    /// y negated, so that view-space up is the top of a Vulkan framebuffer (whose y points down).
    pub fn proj(&self, aspect: f32) -> Mat4 {
        Mat4::from_scale(Vec3::new(1.0, -1.0, 1.0))
            * Mat4::perspective_infinite_reverse_rh(self.fov_y_radians, aspect, self.near)
    }

    /// World-to-clip matrix: `proj(aspect) * view()`.
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        self.proj(aspect) * self.view()
    }

    /// This camera moved to `position` and looking at `target` where given (the target defaults to the
    /// centre of `bounds` when only the position is given; a camera looking straight up or down takes +Z
    /// as its up).
    ///
    /// # Errors
    ///
    /// The position and the target coincide.
    pub fn placed(
        self,
        bounds: &Aabb,
        position: Option<Vec3>,
        target: Option<Vec3>,
    ) -> Result<Camera, CoincidentCamera> {
        if position.is_none() && target.is_none() {
            return Ok(self);
        }
        let position = position.unwrap_or(self.position);
        let target = target.unwrap_or(bounds.center());
        if (position - target).length() == 0.0 {
            return Err(CoincidentCamera);
        }
        let forward = (target - position).normalize();
        let up = if forward.cross(Vec3::Y).length() < 1e-3 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        Ok(Camera {
            position,
            target,
            up,
            ..self
        })
    }

    /// A camera with a 45° vertical field of view looking at the centre of `bounds` from a
    /// slanted, elevated direction, far enough that the bounding sphere fits both the vertical
    /// and the horizontal field of view for `aspect` (width / height; invalid values count as 1).
    /// The near plane is at 1% of the bounding radius, but at least 0.1 mm.
    pub fn frame(bounds: &Aabb, aspect: f32) -> Camera {
        const MARGIN: f32 = 1.05;
        let fov_y_radians = 45f32.to_radians();
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let (center, radius) = bounds.bounding_sphere();
        let half_y = fov_y_radians * 0.5;
        let half_x = (half_y.tan() * aspect).atan();
        let distance = MARGIN * radius / half_x.min(half_y).sin();
        let direction = Vec3::new(0.6, 0.45, 1.0).normalize();
        Camera {
            position: center + direction * distance,
            target: center,
            up: Vec3::Y,
            fov_y_radians,
            near: (radius * 0.01).max(1e-4),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural_default;

    #[test]
    fn placed_moves_the_camera_where_asked() {
        let bounds = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::new(1.0, 3.0, 1.0),
        };
        let camera = Camera::frame(&bounds, 1.5);
        assert_eq!(camera.placed(&bounds, None, None), Ok(camera));
        let moved = camera
            .placed(&bounds, Some(Vec3::new(-5.0, 2.0, 3.0)), None)
            .expect("placed");
        assert_eq!(
            (moved.position, moved.target, moved.up),
            (Vec3::new(-5.0, 2.0, 3.0), bounds.center(), Vec3::Y)
        );
        assert_eq!(moved.fov_y_radians, camera.fov_y_radians);
        let above = camera
            .placed(&bounds, Some(Vec3::new(0.0, 9.0, 0.0)), Some(Vec3::ZERO))
            .expect("placed");
        assert_eq!(above.up, Vec3::Z, "looking straight down");
        let target = Some(camera.position);
        assert_eq!(camera.placed(&bounds, None, target), Err(CoincidentCamera));
    }

    fn assert_frames(bounds: &Aabb, aspect: f32) {
        let camera = Camera::frame(bounds, aspect);
        let m = camera.view_proj(aspect);
        for corner in bounds.corners() {
            let clip = m * corner.extend(1.0);
            assert!(clip.w > 0.0, "corner {corner} behind the camera");
            let ndc = clip.truncate() / clip.w;
            assert!(
                ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
                "corner {corner} outside the view at aspect {aspect}: {ndc}"
            );
            assert!((0.0..=1.0).contains(&ndc.z), "depth {}", ndc.z);
        }
    }

    #[test]
    fn frame_fits_the_bounds() {
        let scene_bounds = procedural_default().bounds();
        let unit = Aabb {
            min: Vec3::new(-1e-3, 0.0, -1e-3),
            max: Vec3::new(1e-3, 5e-3, 1e-3),
        };
        let far = Aabb {
            min: Vec3::new(1000.0, -20.0, 500.0),
            max: Vec3::new(1300.0, 10.0, 505.0),
        };
        for bounds in [scene_bounds, unit, far] {
            for aspect in [0.25, 0.75, 1.0, 16.0 / 9.0, 4.0] {
                assert_frames(&bounds, aspect);
            }
        }
    }

    #[test]
    fn frame_parameters() {
        let bounds = procedural_default().bounds();
        let camera = Camera::frame(&bounds, 1.5);
        assert_eq!(camera.target, bounds.center());
        assert_eq!(camera.up, Vec3::Y);
        assert!((camera.fov_y_radians - std::f32::consts::FRAC_PI_4).abs() < 1e-6);
        assert!((camera.near - bounds.radius() * 0.01).abs() < 1e-6);
        let offset = (camera.position - camera.target).normalize();
        assert!(offset.abs_diff_eq(Vec3::new(0.6, 0.45, 1.0).normalize(), 1e-5));
        assert_eq!(camera.view_proj(1.5), camera.proj(1.5) * camera.view());
    }

    #[test]
    fn reversed_depth() {
        let camera = Camera {
            position: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            fov_y_radians: 1.0,
            near: 0.5,
        };
        let m = camera.view_proj(1.0);
        let depth = |z: f32| {
            let clip = m * Vec3::new(0.0, 0.0, z).extend(1.0);
            clip.z / clip.w
        };
        assert!((depth(-0.5) - 1.0).abs() < 1e-6);
        assert!(depth(-1000.0) > 0.0 && depth(-1000.0) < 1e-3);
    }

    #[test]
    fn degenerate_inputs_stay_finite() {
        for aspect in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let camera = Camera::frame(&Aabb::empty(), aspect);
            assert!(camera.position.is_finite());
            assert!(camera.view_proj(1.0).is_finite());
        }
    }
}
