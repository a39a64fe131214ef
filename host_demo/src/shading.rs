//! The demo's shading of a scene's lights: the sum over the lights of a Lambert surface lit by each with
//! its colour × intensity, its distance and cone falloff, and its visibility. Pure: no GPU.
//!
//! The falloffs are those the glTF `KHR_lights_punctual` extension recommends: inverse square with a
//! smooth window to zero at the range (`clamp(1 - (d / range)^4, 0, 1) / d²`), and for a spot light the
//! square of the linear step in `cos(angle)` from the outer cone (0) to the inner cone (1).
//! Directional intensities are illuminances (lux), spot and point intensities luminous intensities
//! (candela), so that every light gives an illuminance at the surface; the surface's radiance is
//! `albedo / π` times the sum.

use glam::Vec3;
use scene::{LightKind, SceneLight};

/// Albedo of every surface of the demo (a light grey).
pub const ALBEDO: f32 = 0.8;

/// The illuminance `light` gives a surface at `position` with unit normal `normal`, before its
/// visibility: zero facing away, beyond the range or outside the cone.
pub fn illuminance(light: &SceneLight, position: Vec3, normal: Vec3) -> Vec3 {
    let (to_light, falloff) = match light.kind {
        LightKind::Directional { direction } => (-direction, 1.0),
        LightKind::Spot {
            position: at,
            direction,
            inner_cone,
            outer_cone,
            range,
        } => {
            let (to_light, distance_falloff) = towards(at, position, range);
            let cos_outer = outer_cone.cos();
            let scale = 1.0 / (inner_cone.cos() - cos_outer).max(1e-3);
            let t = ((-to_light).dot(direction) - cos_outer) * scale;
            let cone = t.clamp(0.0, 1.0);
            (to_light, distance_falloff * cone * cone)
        }
        LightKind::Point {
            position: at,
            range,
        } => towards(at, position, range),
    };
    light.color * light.intensity * falloff * normal.dot(to_light).max(0.0)
}

/// The unit direction from `position` to a light at `at`, and the light's distance falloff.
fn towards(at: Vec3, position: Vec3, range: Option<f32>) -> (Vec3, f32) {
    let offset = at - position;
    let d2 = offset.length_squared();
    if d2 == 0.0 {
        return (Vec3::ZERO, 0.0);
    }
    let window = range.map_or(1.0, |r| (1.0 - (d2 / (r * r)).powi(2)).clamp(0.0, 1.0));
    (offset / d2.sqrt(), window / d2)
}

/// Linear radiance of every pixel: `ALBEDO / π · Σ illuminance · visibility` over `lights`, where
/// `visibility[i]` is light `i`'s visibility image. `position` and `normal` are the G-buffer's (w = 0 on
/// background, which gets `background`).
pub fn shade(
    lights: &[SceneLight],
    visibility: &[Vec<f32>],
    position: &[[f32; 4]],
    normal: &[[f32; 4]],
    background: Vec3,
) -> Vec<Vec3> {
    position
        .iter()
        .zip(normal)
        .enumerate()
        .map(|(pixel, (p, n))| {
            if n[3] == 0.0 {
                return background;
            }
            let (p, n) = (Vec3::new(p[0], p[1], p[2]), Vec3::new(n[0], n[1], n[2]));
            let sum: Vec3 = lights
                .iter()
                .zip(visibility)
                .map(|(light, v)| illuminance(light, p, n) * v[pixel])
                .sum();
            sum * (ALBEDO / std::f32::consts::PI)
        })
        .collect()
}

/// An 8-bit sRGB preview of linear radiance: Reinhard tone mapping per channel, then the sRGB curve.
pub fn tone_map(radiance: &[Vec3]) -> Vec<[u8; 4]> {
    let encode = |c: f32| {
        let x = (c / (1.0 + c)).clamp(0.0, 1.0);
        let s = if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    radiance
        .iter()
        .map(|c| [encode(c.x), encode(c.y), encode(c.z), 255])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use scene::LightSize;

    fn light(kind: LightKind) -> SceneLight {
        SceneLight {
            name: "l".into(),
            kind,
            color: Vec3::new(1.0, 0.5, 0.25),
            intensity: 4.0,
            size: LightSize::Zero,
            casts_shadows: true,
            is_static: true,
        }
    }

    #[test]
    fn lambert_with_colour_and_intensity() {
        let sun = light(LightKind::Directional {
            direction: Vec3::new(0.0, -1.0, 1.0).normalize(),
        });
        let e = illuminance(&sun, Vec3::ZERO, Vec3::Y);
        let cos = std::f32::consts::FRAC_1_SQRT_2;
        assert!(e.abs_diff_eq(Vec3::new(4.0, 2.0, 1.0) * cos, 1e-5), "{e}");
        assert_eq!(illuminance(&sun, Vec3::ZERO, Vec3::NEG_Y), Vec3::ZERO);
    }

    #[test]
    fn point_light_falls_off_with_distance_and_range() {
        let point = light(LightKind::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            range: Some(4.0),
        });
        let e = illuminance(&point, Vec3::ZERO, Vec3::Y);
        let window = 1.0 - (4.0f32 / 16.0).powi(2);
        assert!(
            e.abs_diff_eq(Vec3::new(1.0, 0.5, 0.25) * window, 1e-5),
            "{e}"
        );
        let beyond = illuminance(&point, Vec3::new(0.0, -3.0, 0.0), Vec3::Y);
        assert_eq!(beyond, Vec3::ZERO);
    }

    #[test]
    fn spot_light_cone_falloff() {
        let spot = light(LightKind::Spot {
            position: Vec3::new(0.0, 1.0, 0.0),
            direction: Vec3::NEG_Y,
            inner_cone: 0.2,
            outer_cone: 0.4,
            range: None,
        });
        let at_angle = |a: f32| {
            let p = Vec3::new(a.tan(), 0.0, 0.0);
            let e = illuminance(&spot, p, Vec3::Y);
            let d2 = p.length_squared() + 1.0;
            e.x / (4.0 * a.cos() / d2)
        };
        assert!((at_angle(0.1) - 1.0).abs() < 1e-5);
        assert!(at_angle(0.45).abs() < 1e-6);
        let half = at_angle(0.3);
        let t = (0.3f32.cos() - 0.4f32.cos()) / (0.2f32.cos() - 0.4f32.cos());
        assert!((half - t * t).abs() < 1e-4, "{half}");
    }

    #[test]
    fn shading_sums_lights_times_visibility() {
        let sun = light(LightKind::Directional {
            direction: Vec3::NEG_Y,
        });
        let lights = [sun.clone(), sun];
        let position = [[0.0, 0.0, 0.0, 1.0], [0.0; 4]];
        let normal = [[0.0, 1.0, 0.0, 1.0], [0.0; 4]];
        let sky = Vec3::new(0.1, 0.2, 0.3);
        let visibility = [vec![1.0, 1.0], vec![0.5, 1.0]];
        let radiance = shade(&lights, &visibility, &position, &normal, sky);
        let expected = Vec3::new(4.0, 2.0, 1.0) * 1.5 * ALBEDO / std::f32::consts::PI;
        assert!(radiance[0].abs_diff_eq(expected, 1e-5));
        assert_eq!(radiance[1], sky);
        let rgba = tone_map(&radiance);
        assert!(rgba[0][0] > rgba[0][1] && rgba[0][1] > rgba[0][2]);
        assert_eq!(tone_map(&[Vec3::ZERO])[0], [0, 0, 0, 255]);
    }
}
