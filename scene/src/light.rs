//! The directional light and its shadow-map projection.

use glam::{Mat4, Vec3};

use crate::Aabb;

/// Directional light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    /// Unit vector along which the light travels (from the light towards the scene).
    pub direction: Vec3,
}

impl DirectionalLight {
    /// A slanted default, about 34° from vertical: `normalize(0.68, -1.0, 0.05)`. It comes from the left of
    /// the default camera (which looks from +x+z), so shadows fall to the side where they can be seen.
    pub fn slanted() -> Self {
        Self {
            direction: Vec3::new(0.68, -1.0, 0.05).normalize(),
        }
    }

    /// A light travelling along `direction` (normalised); `None` if it has zero length or is not
    /// finite.
    pub fn new(direction: Vec3) -> Option<Self> {
        direction
            .try_normalize()
            .map(|direction| Self { direction })
    }

    /// Light view matrix: `Mat4::look_at_rh(center - direction * r * 2, center, up)` for the
    /// bounding sphere (`center`, `r`) of `bounds`, with `up = +Y` unless the direction is within
    /// about 1° of ±Y, then `+Z` ([`light_fit::directional_view`]).
    pub fn view(&self, bounds: &Aabb) -> Mat4 {
        let (center, radius) = bounds.bounding_sphere();
        light_fit::directional_view(self.unit_direction(), center, radius)
    }

    /// Orthographic light view-projection tightly enclosing the corners of `bounds` (a unit box if they
    /// are empty or not finite): their light view-space x/y range maps exactly onto clip `[-1, 1]^2`, and
    /// their depth range, widened by 1% on both sides plus a tiny margin, onto Vulkan depth `[0, 1]` (near
    /// to far). Degenerate extents (a flat scene seen edge-on, a single point) are widened by that tiny
    /// margin too. The plugin's own fit ([`light_fit::directional_view_proj`]): the matrix the plugin
    /// chooses for a sun given no matrix and the same bounds.
    pub fn view_proj(&self, bounds: &Aabb) -> Mat4 {
        let b = bounds.or_unit();
        light_fit::directional_view_proj(self.unit_direction(), b.min, b.max)
    }

    /// `direction`, normalised; straight down if it is unusable.
    fn unit_direction(&self) -> Vec3 {
        self.direction.try_normalize().unwrap_or(Vec3::NEG_Y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{procedural_default, Scene};

    fn directions() -> Vec<DirectionalLight> {
        let mut lights = vec![DirectionalLight::slanted()];
        lights.extend(
            [
                Vec3::NEG_Y,
                Vec3::Y,
                Vec3::new(0.001, -1.0, 0.0),
                Vec3::X,
                Vec3::new(0.3, -0.2, 0.9),
                Vec3::new(-1.0, -0.05, 0.2),
            ]
            .into_iter()
            .filter_map(DirectionalLight::new),
        );
        lights
    }

    /// Checks that every referenced vertex lands in clip x, y in [-1, 1] and z in [0, 1].
    fn assert_inside(scene: &Scene, light: DirectionalLight) {
        let m = light.view_proj(&scene.bounds());
        assert!(m.is_finite());
        let tolerance = 1e-5;
        for &i in &scene.indices {
            let clip = m * scene.positions[i as usize].extend(1.0);
            assert!((clip.w - 1.0).abs() < 1e-6);
            assert!(
                clip.x.abs() <= 1.0 + tolerance
                    && clip.y.abs() <= 1.0 + tolerance
                    && (0.0..=1.0).contains(&clip.z),
                "light {:?}: vertex {i} maps to {clip}",
                light.direction
            );
        }
    }

    #[test]
    fn slanted_default() {
        let d = DirectionalLight::slanted().direction;
        assert!(d.is_normalized());
        assert!(d.y < 0.0);
        let from_vertical = d.angle_between(Vec3::NEG_Y).to_degrees();
        assert!((from_vertical - 34.5).abs() < 2.0, "{from_vertical}");
    }

    #[test]
    fn new_rejects_unusable_directions() {
        assert!(DirectionalLight::new(Vec3::ZERO).is_none());
        assert!(DirectionalLight::new(Vec3::new(f32::NAN, -1.0, 0.0)).is_none());
        assert!(DirectionalLight::new(Vec3::new(0.0, f32::INFINITY, 0.0)).is_none());
        let light = DirectionalLight::new(Vec3::new(0.0, -3.0, 4.0)).unwrap();
        assert!(light.direction.abs_diff_eq(Vec3::new(0.0, -0.6, 0.8), 1e-6));
    }

    #[test]
    fn view_looks_along_the_light() {
        let bounds = procedural_default().bounds();
        for light in directions() {
            let view = light.view(&bounds);
            assert!(view.is_finite());
            let forward = view.transform_vector3(light.direction);
            assert!(forward.abs_diff_eq(Vec3::NEG_Z, 1e-5), "{forward}");
            let center = view.transform_point3(bounds.center());
            assert!((center.z + 2.0 * bounds.radius()).abs() < 1e-4);
        }
    }

    #[test]
    fn view_proj_encloses_the_procedural_scene() {
        let scene = procedural_default();
        for light in directions() {
            assert_inside(&scene, light);
            let m = light.view_proj(&scene.bounds());
            let clip = scene.bounds().corners().map(|c| m.project_point3(c));
            let max_x = clip.iter().map(|c| c.x.abs()).fold(0.0, f32::max);
            let max_y = clip.iter().map(|c| c.y.abs()).fold(0.0, f32::max);
            assert!((max_x - 1.0).abs() < 1e-5 && (max_y - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn flat_and_tiny_scenes_get_finite_projections() {
        let flat = crate::scene::ground_square("flat", Vec3::new(5.0, 1.0, -3.0), 10.0);
        let point = Scene {
            positions: vec![Vec3::splat(2.0)],
            indices: vec![0, 0, 0],
            objects: Vec::new(),
        };
        for scene in [flat, point] {
            for light in directions() {
                assert_inside(&scene, light);
            }
        }
        assert!(DirectionalLight::slanted()
            .view_proj(&crate::Aabb::empty())
            .is_finite());
    }
}
