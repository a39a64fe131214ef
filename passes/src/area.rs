//! Exact soft shadows of a sized light ([`ShadowMode::Area`](crate::ShadowMode::Area)): per pixel, the
//! visible fraction of a fixed set of light samples, each tested exactly against the triangles the
//! primitive map lists for the pixel's texel.
//!
//! A directional light of angular radius `r` is the cone of directions within `r` of the direction towards
//! it. [`area_sample_directions`] spreads `N` directions over that cone, equal in solid angle (a golden-angle
//! spiral): the same directions for every pixel and every frame, so the result has no noise and is a
//! deterministic function of the input. The reference crate tests the very same directions in f64.
//!
//! The map is built as for hard shadows, with each triangle's footprint widened by the penumbra it can
//! cast: a shadow ray of direction `w` within `r` of the central direction leaves the receiver's texel
//! sideways by at most `tan(r)` per unit of depth it climbs towards the light, so a triangle whose nearest
//! point lies `h` above a texel's deepest receiver can only block rays of that texel if its footprint comes
//! within `h tan(r)` of the texel (`map_bin.glsl`).

use crate::gpu_types::AreaSamples;
use crate::PassError;
use bytemuck::Zeroable;
use glam::{DVec3, UVec4, Vec3};

/// Most light samples per pixel (the bits of the shader's sample mask).
pub const MAX_AREA_SAMPLES: u32 = 128;

/// Light samples per pixel by default.
pub const DEFAULT_AREA_SAMPLES: u32 = 64;

/// Settings of the area mode. The light's size is the one PCSS and the hybrid use
/// ([`PcssConfig::angular_radius`](crate::PcssConfig::angular_radius)): every mode shadows the same light.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AreaConfig {
    /// Light samples per pixel, in `1..=`[`MAX_AREA_SAMPLES`] (default [`DEFAULT_AREA_SAMPLES`]). Visibility
    /// takes the values `k / samples`.
    pub samples: u32,
}

impl Default for AreaConfig {
    fn default() -> Self {
        Self {
            samples: DEFAULT_AREA_SAMPLES,
        }
    }
}

impl AreaConfig {
    /// Checks the sample count, and the light's angular radius: finite, above 0 and below pi/2.
    pub fn validate(&self, angular_radius: f32) -> Result<(), PassError> {
        if !(1..=MAX_AREA_SAMPLES).contains(&self.samples) {
            return Err(PassError::InvalidConfig(format!(
                "area shadows: {} light samples per pixel; give 1..={MAX_AREA_SAMPLES}",
                self.samples
            )));
        }
        if !(angular_radius > 0.0 && angular_radius < std::f32::consts::FRAC_PI_2) {
            return Err(PassError::InvalidConfig(format!(
                "area shadows need a light of angular radius in (0, pi/2) radians, not {angular_radius}: \
                 a light of no size has hard shadows (mode hard)"
            )));
        }
        Ok(())
    }
}

/// The `samples` directions *towards* a directional light travelling along `direction` whose emitter has
/// angular radius `angular_radius`: equal-solid-angle rings (`cos θ_i = 1 - (i + 1/2)/N (1 - cos r)`) turned
/// by the golden angle, computed in f64 and rounded to f32 (the GPU and the reference use these values).
/// Every direction is unit length to f32 rounding and within `angular_radius` of `-direction`.
pub fn area_sample_directions(direction: Vec3, angular_radius: f32, samples: u32) -> Vec<Vec3> {
    let to_light = -direction.as_dvec3().normalize();
    let (e1, e2) = to_light.any_orthonormal_pair();
    let cos_r = f64::from(angular_radius).cos();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..samples)
        .map(|i| {
            let cos_t = 1.0 - (f64::from(i) + 0.5) / f64::from(samples) * (1.0 - cos_r);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let phi = golden * f64::from(i);
            let w: DVec3 = cos_t * to_light + sin_t * (phi.cos() * e1 + phi.sin() * e2);
            w.as_vec3()
        })
        .collect()
}

/// Cells per side of the grid over the samples' gnomonic coordinates ([`area_samples`]).
pub const SAMPLE_GRID: u32 = 8;

/// The area trace's sample table for `direction`, `angular_radius` and `samples`: the directions; a bound on
/// how far any of them lies from the central direction towards the light as the GPU holds it (`-direction`
/// normalised in f32), with room for the rounding of the shader's bounds; and a grid over their gnomonic
/// coordinates.
///
/// The grid: a direction `w` has gnomonic coordinates `(w.u / w.C, w.v / w.C)` in the plane of axes `u`, `v`
/// orthogonal to the centre `C`. A triangle whose vertices all lie in front (`r.C > 0` from the ray origin)
/// projects there onto the triangle of its projected vertices, so only samples inside that triangle's
/// bounding box can be hidden by it. The table lists, for every range of grid columns (and of rows), the
/// samples that may lie in it; each sample is listed in every cell within 1/1000 of the grid's extent of
/// it, so that the shader's rounding of a cell index never loses a sample.
pub fn area_samples(direction: Vec3, angular_radius: f32, samples: u32) -> AreaSamples {
    let center = (-direction).normalize();
    let dirs = area_sample_directions(direction, angular_radius, samples);
    let c = center.as_dvec3();
    let spread = dirs
        .iter()
        .map(|w| (w.as_dvec3() - c).length())
        .fold(0.0, f64::max);
    let (u, v) = c.any_orthonormal_pair();
    let (u, v) = (u.as_vec3(), v.as_vec3());
    let gnomonic: Vec<(f64, f64)> = dirs
        .iter()
        .map(|w| {
            let w = w.as_dvec3();
            let h = w.dot(c);
            (w.dot(u.as_dvec3()) / h, w.dot(v.as_dvec3()) / h)
        })
        .collect();
    let extent = gnomonic
        .iter()
        .map(|&(x, y)| x.abs().max(y.abs()))
        .fold(0.0, f64::max)
        * (1.0 + 1e-3)
        + 1e-9;
    let grid = f64::from(SAMPLE_GRID);
    let scale = grid / (2.0 * extent);
    let margin = extent * 1e-3;
    let cells = |x: f64| {
        let cell = |x: f64| ((x + extent) * scale).floor().clamp(0.0, grid - 1.0) as u32;
        (cell(x - margin), cell(x + margin))
    };
    let mut table = AreaSamples {
        center: center.extend((spread * (1.0 + 1e-4) + 1e-6) as f32),
        axis_u: u.extend(extent as f32),
        axis_v: v.extend(scale as f32),
        ..AreaSamples::zeroed()
    };
    for (i, (w, &(gu, gv))) in dirs.iter().zip(&gnomonic).enumerate() {
        table.dirs[i] = w.extend(0.0);
        let bit = |mask: &mut UVec4| mask[i / 32] |= 1 << (i % 32);
        for (ranges, (first, last)) in [
            (&mut table.u_range, cells(gu)),
            (&mut table.v_range, cells(gv)),
        ] {
            for a in 0..SAMPLE_GRID {
                for b in a..SAMPLE_GRID {
                    if a <= last && first <= b {
                        bit(&mut ranges[(a * SAMPLE_GRID + b) as usize]);
                    }
                }
            }
        }
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_lie_in_the_cone_and_cover_it_evenly() {
        let direction = Vec3::new(0.3, -1.0, 0.2);
        let r = 0.05f32;
        let dirs = area_sample_directions(direction, r, 64);
        assert_eq!(dirs.len(), 64);
        let to_light = -direction.as_dvec3().normalize();
        let mut inner = 0;
        for w in &dirs {
            let w = w.as_dvec3();
            assert!((w.length() - 1.0).abs() < 1e-6);
            let angle = w.normalize().dot(to_light).clamp(-1.0, 1.0).acos();
            assert!(angle <= f64::from(r) * (1.0 + 1e-4), "{angle}");
            // Half the solid angle lies within the cone of cos = (1 + cos r) / 2.
            if w.normalize().dot(to_light) >= (1.0 + f64::from(r).cos()) / 2.0 {
                inner += 1;
            }
        }
        assert_eq!(inner, 32);
        // Deterministic.
        assert_eq!(dirs, area_sample_directions(direction, r, 64));
    }

    #[test]
    fn the_table_bounds_the_spread_of_its_directions() {
        let t = area_samples(Vec3::NEG_Y, 0.02, 16);
        assert!(t.center.w > 0.019 && t.center.w < 0.021, "{}", t.center.w);
        assert_eq!(t.dirs[16], glam::Vec4::ZERO);
        assert!(t.dirs[15].truncate().length() > 0.99);
    }

    /// Every sample is listed in the grid ranges that hold its gnomonic coordinates, as the shader computes
    /// a cell; the whole grid lists every sample once; no range lists a sample that lies far from it.
    #[test]
    fn the_grid_lists_each_sample_in_the_cells_around_it() {
        let n = 64;
        let t = area_samples(Vec3::new(0.2, -1.0, 0.4), 0.05, n);
        let g = SAMPLE_GRID as usize;
        let all = t.u_range[g - 1];
        assert_eq!(all.x.count_ones() + all.y.count_ones(), n);
        assert_eq!(t.v_range[g - 1], all);
        let (c, u, v) = (
            t.center.truncate(),
            t.axis_u.truncate(),
            t.axis_v.truncate(),
        );
        let (extent, scale) = (t.axis_u.w, t.axis_v.w);
        let cell = |x: f32| ((x + extent) * scale).floor().clamp(0.0, g as f32 - 1.0) as usize;
        let mut narrow = 0;
        for i in 0..n as usize {
            let w = t.dirs[i].truncate();
            let (gu, gv) = (w.dot(u) / w.dot(c), w.dot(v) / w.dot(c));
            assert!(gu.abs() <= extent && gv.abs() <= extent);
            let (a, b) = (cell(gu), cell(gv));
            let listed = |m: UVec4| m[i / 32] & (1 << (i % 32)) != 0;
            assert!(listed(t.u_range[a * g + a]) && listed(t.v_range[b * g + b]));
            // Listed in at most its own cell and a neighbour.
            let cells = (0..g).filter(|&k| listed(t.u_range[k * g + k])).count();
            assert!((1..=2).contains(&cells));
            narrow += usize::from(cells == 1);
        }
        assert!(narrow > n as usize / 2);
    }

    #[test]
    fn invalid_sizes_and_counts_are_rejected() {
        let ok = AreaConfig::default();
        assert!(ok.validate(0.02).is_ok());
        for r in [
            0.0,
            -0.1,
            f32::NAN,
            f32::INFINITY,
            std::f32::consts::FRAC_PI_2,
        ] {
            let e = ok.validate(r).unwrap_err().to_string();
            assert!(e.contains("angular radius"), "{e}");
        }
        for samples in [0, MAX_AREA_SAMPLES + 1] {
            let e = AreaConfig { samples }
                .validate(0.02)
                .unwrap_err()
                .to_string();
            assert!(e.contains("light samples"), "{e}");
        }
    }
}
