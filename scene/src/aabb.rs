//! Axis-aligned bounding boxes.

use glam::Vec3;

/// Axis-aligned box.
///
/// An [empty](Aabb::empty) box has `min = +inf` and `max = -inf`, so that extending it by any point
/// yields the degenerate box around that point. The derived quantities ([`center`](Aabb::center),
/// [`size`](Aabb::size), ...) are only meaningful for non-empty boxes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Smallest coordinate on each axis.
    pub min: Vec3,
    /// Largest coordinate on each axis.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (`min = +inf`, `max = -inf`), the identity for [`extend`](Aabb::extend).
    pub fn empty() -> Self {
        Self {
            min: Vec3::INFINITY,
            max: Vec3::NEG_INFINITY,
        }
    }

    /// Grows the box to contain `p`.
    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Centre of the box.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Extent of the box on each axis (`max - min`).
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Radius of the bounding sphere around [`center`](Aabb::center): half the diagonal.
    pub fn radius(&self) -> f32 {
        self.size().length() * 0.5
    }

    /// The eight corners; bit 0 of the index selects max x, bit 1 max y, bit 2 max z.
    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// Whether the box contains at least one point and all its coordinates are finite.
    pub(crate) fn is_valid(&self) -> bool {
        self.min.is_finite() && self.max.is_finite() && self.min.cmple(self.max).all()
    }

    /// This box if it [is valid](Aabb::is_valid) and its radius is finite, otherwise the cube
    /// `[-1, 1]^3`, so that cameras and lights built from bad bounds stay well defined.
    pub(crate) fn or_unit(self) -> Aabb {
        if self.is_valid() && self.radius().is_finite() {
            self
        } else {
            Aabb {
                min: Vec3::NEG_ONE,
                max: Vec3::ONE,
            }
        }
    }

    /// Centre and radius of the bounding sphere of [`or_unit`](Aabb::or_unit), with the radius
    /// clamped to at least 0.1 mm so that a single point still has a usable extent.
    pub(crate) fn bounding_sphere(&self) -> (Vec3, f32) {
        const MIN_RADIUS: f32 = 1e-4;
        let bounds = self.or_unit();
        (bounds.center(), bounds.radius().max(MIN_RADIUS))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extend_center_size_radius() {
        let mut b = Aabb::empty();
        assert!(!b.is_valid());
        b.extend(Vec3::new(1.0, 2.0, 3.0));
        b.extend(Vec3::new(-1.0, 0.0, 5.0));
        assert_eq!(b.min, Vec3::new(-1.0, 0.0, 3.0));
        assert_eq!(b.max, Vec3::new(1.0, 2.0, 5.0));
        assert_eq!(b.center(), Vec3::new(0.0, 1.0, 4.0));
        assert_eq!(b.size(), Vec3::splat(2.0));
        assert!((b.radius() - 3f32.sqrt()).abs() < 1e-6);
        assert_eq!(b.bounding_sphere().0, b.center());
    }

    #[test]
    fn corners_are_distinct_and_on_the_box() {
        let b = Aabb {
            min: Vec3::new(-1.0, -2.0, -3.0),
            max: Vec3::new(4.0, 5.0, 6.0),
        };
        let corners = b.corners();
        for (i, c) in corners.iter().enumerate() {
            assert!(corners[i + 1..].iter().all(|d| d != c));
            assert!((c.distance(b.center()) - b.radius()).abs() < 1e-5);
        }
    }

    #[test]
    fn degenerate_boxes_give_usable_spheres() {
        let (c, r) = Aabb::empty().bounding_sphere();
        assert_eq!((c, r), (Vec3::ZERO, 3f32.sqrt()));
        let huge = Aabb {
            min: Vec3::splat(-f32::MAX),
            max: Vec3::splat(f32::MAX),
        };
        assert_eq!(huge.or_unit().max, Vec3::ONE);
        let mut point = Aabb::empty();
        point.extend(Vec3::ONE);
        assert_eq!(point.bounding_sphere(), (Vec3::ONE, 1e-4));
    }
}
