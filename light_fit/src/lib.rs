//! The orthographic frustum a directional light is fitted to a box with, written once: the plugin fits a
//! sun given no matrix with it (`passes::directional_light_frustum`), and the CPU side that must know the
//! same matrix (`scene::DirectionalLight::view_proj`: hard cases that place geometry on its texel
//! boundaries, hosts that hand the plugin a matrix) calls the same function, so both get the same f32
//! arithmetic and the same matrix.

use glam::{Mat4, Vec3};

/// Smallest radius (world units) of the bounding sphere the frustum is fitted around, so that bounds of a
/// single point still have an extent.
pub const MIN_FIT_RADIUS: f32 = 1e-4;

/// The light's up vector: +Y, unless `forward` is within about 1° of ±Y (then +Z).
pub fn up_hint(forward: Vec3) -> Vec3 {
    if forward.y.abs() > 1f32.to_radians().cos() {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// The light's view: looking along the unit `direction` at `center` from twice `radius` away, up from
/// [`up_hint`].
pub fn directional_view(direction: Vec3, center: Vec3, radius: f32) -> Mat4 {
    Mat4::look_at_rh(
        center - direction * radius * 2.0,
        center,
        up_hint(direction),
    )
}

/// The view-projection of a directional light travelling along the unit `direction`, fitted to the box
/// `[lo, hi]` (finite, `lo <= hi`): the view of [`directional_view`] around the box's bounding sphere (its
/// radius at least [`MIN_FIT_RADIUS`]); the box's light-space x/y range maps exactly onto clip `[-1, 1]²`,
/// its depth range, widened by 1% on both sides plus a tiny margin, onto depth `[0, 1]` (near to far).
/// Degenerate extents (a flat box seen edge-on, a single point) are widened to the tiny margin: 1e-4 of the
/// radius plus 1e-5 of the centre's largest coordinate. Not finite if the box is too large to measure in
/// f32 (the callers check).
pub fn directional_view_proj(direction: Vec3, lo: Vec3, hi: Vec3) -> Mat4 {
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(MIN_FIT_RADIUS);
    let view = directional_view(direction, center, radius);
    let epsilon = radius * 1e-4 + center.abs().max_element() * 1e-5;
    let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for i in 0..8 {
        let corner = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let p = view.transform_point3(corner);
        min = min.min(p);
        max = max.max(p);
    }
    let (left, right) = at_least(min.x, max.x, epsilon);
    let (bottom, top) = at_least(min.y, max.y, epsilon);
    let (near, far) = (-max.z, -min.z);
    let margin = (far - near) * 0.01 + epsilon;
    Mat4::orthographic_rh(left, right, bottom, top, near - margin, far + margin) * view
}

/// The interval `[lo, hi]`, widened symmetrically to `min_extent` if it is narrower.
fn at_least(lo: f32, hi: f32, min_extent: f32) -> (f32, f32) {
    if hi - lo >= min_extent {
        (lo, hi)
    } else {
        let mid = (lo + hi) * 0.5;
        (mid - min_extent * 0.5, mid + min_extent * 0.5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_box_fills_clip_space_exactly_in_x_and_y_and_sits_inside_in_depth() {
        let (lo, hi) = (Vec3::new(-2.0, 0.0, -1.0), Vec3::new(3.0, 1.5, 2.0));
        for direction in [
            Vec3::new(0.68, -1.0, 0.05).normalize(),
            Vec3::NEG_Y,
            Vec3::new(0.0, -0.2, 1.0).normalize(),
        ] {
            let m = directional_view_proj(direction, lo, hi);
            let clip: Vec<Vec3> = (0..8)
                .map(|i| {
                    let c = Vec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    );
                    m.project_point3(c)
                })
                .collect();
            let max_x = clip.iter().map(|c| c.x.abs()).fold(0.0, f32::max);
            let max_y = clip.iter().map(|c| c.y.abs()).fold(0.0, f32::max);
            assert!(
                (max_x - 1.0).abs() < 1e-5 && (max_y - 1.0).abs() < 1e-5,
                "{direction}: {max_x} {max_y}"
            );
            assert!(
                clip.iter().all(|c| c.z > 0.0 && c.z < 1.0),
                "{direction}: {clip:?}"
            );
        }
    }

    #[test]
    fn a_single_point_still_gets_a_finite_frustum() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        let m = directional_view_proj(Vec3::NEG_Y, p, p);
        assert!(m.is_finite());
        assert!(m.project_point3(p).abs().max_element() <= 1.0);
    }

    #[test]
    fn up_is_z_only_near_vertical() {
        assert_eq!(up_hint(Vec3::NEG_Y), Vec3::Z);
        assert_eq!(up_hint(Vec3::new(0.68, -1.0, 0.05).normalize()), Vec3::Y);
    }
}
