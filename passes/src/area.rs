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
//!
//! A spot or point light has a spherical emitter of radius `R` around its position `P`. Each pixel takes
//! `N` points on the disc of radius `R` through `P` facing it ([`local_area_offsets`]: the same offsets on
//! the unit disc for every pixel, placed by a basis that turns smoothly with the direction to the light),
//! and counts the segments from its ray origin to them that no triangle crosses. The light's perspective
//! map (a spot light's frustum, a point light's six cube faces as one map) widens each footprint by the
//! texels a segment can move across while it climbs from the receiver to the triangle's depth
//! (`R (1/w_tri - 1/w_recv)` in the image plane, bounded in `map_bin.glsl`); triangles within
//! [`LocalAreaReach::near_radius`] of `P` are listed in every texel with receivers.

use crate::gpu_types::AreaSamples;
use crate::PassError;
use bytemuck::Zeroable;
use glam::{DVec2, DVec3, DVec4, Mat4, UVec4, Vec2, Vec3, Vec4};

pub use crate::gpu_types::MAX_AREA_SAMPLES;

/// Light samples per pixel by default.
pub const DEFAULT_AREA_SAMPLES: u32 = 64;

/// [`AreaConfig::bundle_walk_budget`] by default.
pub const DEFAULT_BUNDLE_WALK_BUDGET: u32 = 64;

/// A directional light's bundle of rays is wide when its angular bound passes this: only a wide bundle's
/// walk of the BVH may give up for its samples' own walks ([`AreaConfig::bundle_walk_budget`];
/// `WIDE_BUNDLE` in `area_trace.glsl`).
pub const WIDE_BUNDLE: f32 = 0.1;

/// A spot or point light's bundle of segments from a pixel is wide when its emitter's radius over its
/// distance passes this (`WIDE_LOCAL_BUNDLE` in `area_trace.glsl`).
pub const WIDE_LOCAL_BUNDLE: f32 = 0.05;

/// Settings of the area mode. The light's size is the one PCSS and the hybrid use
/// ([`PcssConfig::angular_radius`](crate::PcssConfig::angular_radius)): every mode shadows the same light.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AreaConfig {
    /// Light samples per pixel, in `1..=`[`MAX_AREA_SAMPLES`] (default [`DEFAULT_AREA_SAMPLES`]). Visibility
    /// takes the values `k / samples`.
    pub samples: u32,
    /// Where a pixel walks the BVH with a wide bundle of segments or rays (an emitter's radius over a
    /// twentieth of its distance, [`WIDE_LOCAL_BUNDLE`]; a directional light's angular bound over a tenth,
    /// [`WIDE_BUNDLE`]), the nodes and triangles the bundle's walk may visit per 64 samples still open,
    /// scaled by `(0.3 / width)²` (width: the radius over the distance), before each open sample walks its
    /// own segment or ray instead (default [`DEFAULT_BUNDLE_WALK_BUDGET`]). Both give the same answer bit
    /// for bit; the bundle costs less while few triangles straddle it (small lights), the samples' own
    /// walks while many do (large ones), and giving up at about the samples' walks' cost keeps a pixel
    /// within about twice the cheaper. 0: each sample's own walk at once, for every bundle; `u32::MAX`: the
    /// bundle always.
    pub bundle_walk_budget: u32,
}

impl Default for AreaConfig {
    fn default() -> Self {
        Self {
            samples: DEFAULT_AREA_SAMPLES,
            bundle_walk_budget: DEFAULT_BUNDLE_WALK_BUDGET,
        }
    }
}

impl AreaConfig {
    /// Checks the sample count, and the light's angular radius: finite, above 0 and below pi/2.
    pub fn validate(&self, angular_radius: f32) -> Result<(), PassError> {
        self.validate_samples()?;
        check_angular_radius(angular_radius)
    }

    /// Checks the sample count alone (a spot or point light's emitter has a radius, not an angular one).
    pub fn validate_samples(&self) -> Result<(), PassError> {
        if !(1..=MAX_AREA_SAMPLES).contains(&self.samples) {
            return Err(PassError::InvalidConfig(format!(
                "area shadows: {} light samples per pixel; give 1..={MAX_AREA_SAMPLES}",
                self.samples
            )));
        }
        Ok(())
    }
}

/// Checks a directional light's angular radius for area shadows: finite, above 0 and below pi/2.
pub(crate) fn check_angular_radius(angular_radius: f32) -> Result<(), PassError> {
    if !(angular_radius > 0.0 && angular_radius < std::f32::consts::FRAC_PI_2) {
        return Err(PassError::InvalidConfig(format!(
            "area shadows need a light of angular radius in (0, pi/2) radians, not {angular_radius}: \
             a light of no size has hard shadows (mode hard)"
        )));
    }
    Ok(())
}

/// The frame of a directional light travelling along `direction`: the unit direction towards it `C` and
/// two unit axes orthogonal to it, in f64 (the GPU holds them rounded to f32).
fn light_frame(direction: Vec3) -> (DVec3, DVec3, DVec3) {
    let c = -direction.as_dvec3().normalize();
    let (u, v) = c.any_orthonormal_pair();
    (c, u, v)
}

/// The sample pattern in the light's frame: sample `i` at angle `θ_i` from the centre (equal-solid-angle
/// rings, `cos θ_i = 1 - (i + 1/2)/N (1 - cos r)`), turned by `i` golden angles: `(cos θ_i, sin θ_i, φ_i)`.
fn pattern(angular_radius: f32, samples: u32) -> impl Iterator<Item = (f64, f64, f64)> {
    let cos_r = f64::from(angular_radius).cos();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..samples).map(move |i| {
        let cos_t = 1.0 - (f64::from(i) + 0.5) / f64::from(samples) * (1.0 - cos_r);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        (cos_t, sin_t, golden * f64::from(i))
    })
}

/// The `samples` directions *towards* a directional light travelling along `direction` whose emitter has
/// angular radius `angular_radius`: equal-solid-angle rings turned by the golden angle, computed in f64 and
/// rounded to f32 (the GPU and the reference use these values). Every direction is unit length to f32
/// rounding and within `angular_radius` of `-direction`.
pub fn area_sample_directions(direction: Vec3, angular_radius: f32, samples: u32) -> Vec<Vec3> {
    let (c, u, v) = light_frame(direction);
    pattern(angular_radius, samples)
        .map(|(cos_t, sin_t, phi)| (cos_t * c + sin_t * (phi.cos() * u + phi.sin() * v)).as_vec3())
        .collect()
}

/// The area trace's per-frame sample table for `direction`, `angular_radius` and `samples`: the light's
/// frame as the GPU holds it, a bound on how far any sample lies from the centre direction (with room for
/// the rounding of the shader's bounds), the extent and resolution of the edge table's offsets
/// ([`AreaEdgeTable`]), and the directions.
pub fn area_samples(direction: Vec3, angular_radius: f32, samples: u32) -> AreaSamples {
    let (c, u, v) = light_frame(direction);
    let center = c.as_vec3();
    let dirs = area_sample_directions(direction, angular_radius, samples);
    let spread = dirs
        .iter()
        .map(|w| (w.as_dvec3() - center.as_dvec3()).length())
        .fold(0.0, f64::max);
    let extent = edge_extent(angular_radius, samples);
    let mut table = AreaSamples {
        center: center.extend((spread * (1.0 + 1e-4) + 1e-6) as f32),
        axis_u: u.as_vec3().extend(extent as f32),
        axis_v: v
            .as_vec3()
            .extend((f64::from(EDGE_OFFSETS) / (2.0 * extent)) as f32),
        dirs: [Vec4::ZERO; MAX_AREA_SAMPLES as usize],
    };
    for (slot, w) in table.dirs.iter_mut().zip(&dirs) {
        *slot = w.extend(0.0);
    }
    table
}

/// The `samples` points of a spot or point light's emitter, as offsets on the unit disc: equal-area rings
/// (`radius sqrt((i + 1/2) / N)`) turned by the golden angle, computed in f64 and rounded to f32 (the GPU and
/// the reference use these values). A pixel at `x` places them on the disc of the emitter's radius `R`
/// through the light's centre `P`, facing it: `P + R (u t1 + v t2)` with `(t1, t2)` the rotation taking +Y
/// to the unit direction from `x` to `P` applied to +X and +Z (`reference::disc_basis`).
pub fn local_area_offsets(samples: u32) -> Vec<Vec2> {
    local_pattern(samples)
        .map(|(r, phi)| DVec2::new(r * phi.cos(), r * phi.sin()).as_vec2())
        .collect()
}

/// The area trace's per-frame sample table of a spot or point light: the unit-disc offsets
/// ([`local_area_offsets`]) in the directions' slots (xy), and the extent and resolution of the local edge
/// table's offsets ([`local_area_edge_table`]); the centre and axes are unused.
pub fn local_area_samples(samples: u32) -> AreaSamples {
    let extent = local_edge_extent(samples);
    let mut table = AreaSamples::zeroed();
    table.axis_u.w = extent as f32;
    table.axis_v.w = (f64::from(EDGE_OFFSETS) / (2.0 * extent)) as f32;
    for (slot, o) in table.dirs.iter_mut().zip(local_area_offsets(samples)) {
        *slot = Vec4::new(o.x, o.y, 0.0, 0.0);
    }
    table
}

/// Where a spot or point light's emitter reaches in one perspective frustum of its primitive map (area
/// shadows). A receiver `x` of the frustum sees the emitter (radius `R`, centre `P`) along segments to points
/// within `R` of `P`. A point `q` of such a segment that lies `rho >= near_radius` from `P` is within angle
/// `theta = asin(R / near_radius)` of the direction from `P` to `x`, so within `alpha + theta` of the
/// frustum's axis (`alpha`: its widest direction), and its depth key is at least
/// `|axis row| near_radius cos(alpha + theta)` = `depth_floor`. With `theta = (pi/2 - alpha) / 3`, the floor
/// is about twice the emitter's own depth extent, which keeps the per-texel widening of `map_bin.glsl`
/// bounded. Triangles nearer than `near_radius` are listed in every texel with receivers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalAreaReach {
    /// Distance from the light's centre within which a triangle goes into every texel.
    pub near_radius: f32,
    /// The depth key below which no point of a farther triangle can block a receiver of the frustum.
    pub depth_floor: f32,
}

/// The reach of an emitter of `radius` at `position` into the perspective frustum `view_proj` (both in the
/// same coordinates), or an error when the frustum is too wide (its widest direction within 3° of its plane).
pub fn local_area_reach(
    view_proj: Mat4,
    position: Vec3,
    radius: f32,
) -> Result<LocalAreaReach, PassError> {
    let m = view_proj.as_dmat4();
    let row_w = m.row(3).truncate();
    let scale = row_w.length();
    let inv = m.inverse();
    let p = position.as_dvec3();
    let axis = row_w / scale;
    let mut widest = 0.0f64;
    for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let h = inv * DVec4::new(x, y, 0.5, 1.0);
        let d = (h.truncate() / h.w - p).normalize();
        widest = widest.max(d.dot(axis).clamp(-1.0, 1.0).acos());
    }
    let alpha = widest * (1.0 + 1e-3) + 1e-4;
    let theta = (std::f64::consts::FRAC_PI_2 - alpha) / 3.0;
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(PassError::InvalidConfig(format!(
            "area shadows of a spot or point light need an emitter radius above 0 (pcss spot_radius), not \
             {radius}: a light of no size has hard shadows (mode hard)"
        )));
    }
    if !(scale.is_finite() && theta > 1f64.to_radians()) {
        return Err(PassError::InvalidConfig(format!(
            "area shadows of a spot light need a frustum narrower than 174° across its corners (this one \
             spans {:.1}°): give a narrower view_proj, or the light without one (the plugin fits it)",
            2.0 * widest.to_degrees()
        )));
    }
    let near = f64::from(radius) / theta.sin();
    Ok(LocalAreaReach {
        near_radius: (near * (1.0 + 1e-4)) as f32,
        depth_floor: (scale * near * (alpha + theta).cos() * (1.0 - 1e-4)) as f32,
    })
}

/// Directions of a triangle edge's line in the edge table (over the "diamond angle" of its normal, in
/// `[0, 4)`).
pub const EDGE_ANGLES: u32 = 64;
/// Offsets of a triangle edge's line in the edge table (over `[-extent, extent]`).
pub const EDGE_OFFSETS: u32 = 64;

/// The edge table of Schwarz and Stamminger's bitmask soft shadows, made exact. From a ray origin, the
/// samples a triangle edge's plane (normal `n`, oriented inwards) keeps are those with `n.w >= 0`; in the
/// gnomonic coordinates `g = (w.u, w.v) / (w.C)` of the light's frame that is the half-plane
/// `a g.x + b g.y + c >= 0` with `(a, b, c) = (n.u, n.v, n.C)`, a line of direction `(a, b)` and offset
/// `d = -c / |(a, b)|`. The table holds, for every cell of line directions and offsets, the samples that every
/// line of the cell keeps (`inside`) and those some line of it may keep or drop (`uncertain`); the rest are
/// dropped by every line of the cell. Each cell is widened by far more than the shader's rounding of the
/// line, and a sample counts as decided only beyond a margin that covers the rounding of the frame, of the
/// directions and of the per-sample test: the area trace takes `inside` samples as kept, drops the others,
/// and tests only the `uncertain` ones one by one, which decides every sample as the per-sample test alone
/// would. The table depends on the light's size and samples alone (the pattern is the same in every
/// light's frame); the offsets' extent is in `AreaSamples::axis_u.w`.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaEdgeTable {
    /// Light samples per pixel.
    pub samples: u32,
    /// `inside[a M + o]`: the samples every line of direction cell `a` and offset cell `o` keeps (`M` =
    /// [`EDGE_OFFSETS`]).
    pub inside: Vec<UVec4>,
    /// `uncertain[a M + o]`: the samples some line of the cell may keep or drop.
    pub uncertain: Vec<UVec4>,
}

impl AreaEdgeTable {
    /// The table as the area trace reads it: one `uvec4` a cell (inside's and uncertain's first two words)
    /// for up to 64 samples, else two (inside, uncertain).
    pub fn gpu_words(&self) -> Vec<UVec4> {
        if self.samples <= 64 {
            self.inside
                .iter()
                .zip(&self.uncertain)
                .map(|(i, u)| UVec4::new(i.x, i.y, u.x, u.y))
                .collect()
        } else {
            self.inside
                .iter()
                .zip(&self.uncertain)
                .flat_map(|(&i, &u)| [i, u])
                .collect()
        }
    }
}

/// The half-extent of the edge table's offsets: beyond every sample's gnomonic radius by the decision
/// margin.
fn edge_extent(angular_radius: f32, samples: u32) -> f64 {
    let radius = pattern(angular_radius, samples)
        .map(|(cos_t, sin_t, _)| sin_t / cos_t)
        .fold(0.0, f64::max);
    radius * (1.0 + 1e-3) + 2.0 * decision_margin(angular_radius, radius) + 1e-9
}

/// The margin beyond which the edge table calls a sample decided, in gnomonic units: the test's value is
/// the sample's signed distance to the line times `(w.C) |(a, b)|`, and the rounding of the frame, the
/// directions and the test is below 2e-6 `|n|`, with `|n| <= |(a, b)| sqrt(1 + d^2)` on the table (ten times
/// that, and twice the radius for the offset's range).
fn decision_margin(angular_radius: f32, radius: f64) -> f64 {
    let lowest = f64::from(angular_radius).cos();
    2e-5 * (1.0 + 4.0 * radius * radius).sqrt() / lowest
}

/// The angle of the direction of diamond angle `t` (any real: periodic with 4 and 2 pi).
fn diamond_to_angle(t: f64) -> f64 {
    let turns = (t / 4.0).floor();
    let r = t - 4.0 * turns;
    let (a, b) = match r {
        r if r < 1.0 => (1.0 - r, r),
        r if r < 2.0 => (1.0 - r, 2.0 - r),
        r if r < 3.0 => (r - 3.0, 2.0 - r),
        r => (r - 3.0, r - 4.0),
    };
    b.atan2(a).rem_euclid(std::f64::consts::TAU) + std::f64::consts::TAU * turns
}

/// Builds the edge table of a directional light of `angular_radius` with `samples` samples.
pub fn area_edge_table(angular_radius: f32, samples: u32) -> AreaEdgeTable {
    let points: Vec<(f64, f64)> = pattern(angular_radius, samples)
        .map(|(cos_t, sin_t, phi)| (sin_t / cos_t, phi))
        .collect();
    let radius = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let margin = decision_margin(angular_radius, radius);
    edge_table(&points, margin, edge_extent(angular_radius, samples))
}

/// The points of a spot or point light's samples on the unit disc ([`local_area_offsets`]): radius and
/// angle, in f64.
fn local_pattern(samples: u32) -> impl Iterator<Item = (f64, f64)> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..samples).map(move |i| {
        (
            ((f64::from(i) + 0.5) / f64::from(samples)).sqrt(),
            golden * f64::from(i),
        )
    })
}

/// The margin beyond which the local edge table calls a sample decided, in units of the unit disc: the
/// per-sample test `f0 + u fu + v fv` errs by a few ulps of `|f0| + |fu| + |fv|`, below 1e-6 of the line's
/// normal for the lines the table serves (offsets within a few disc radii), and the f32 offsets lie within
/// 1e-7 of the f64 points.
const LOCAL_DECISION_MARGIN: f64 = 2e-5;

/// The half-extent of the local edge table's offsets: beyond the unit disc by the decision margin.
fn local_edge_extent(samples: u32) -> f64 {
    let radius = local_pattern(samples).map(|p| p.0).fold(0.0, f64::max);
    radius * (1.0 + 1e-3) + 2.0 * LOCAL_DECISION_MARGIN + 1e-9
}

/// Builds the edge table of a spot or point light's `samples` samples on the unit disc: a condition
/// `f0 + u fu + v fv >= 0` of the area trace is the line of direction `(fu, fv)` and offset
/// `-f0 / |(fu, fv)|` in the disc's plane, as a directional light's edge is in its gnomonic plane.
pub fn local_area_edge_table(samples: u32) -> AreaEdgeTable {
    let points: Vec<(f64, f64)> = local_pattern(samples).collect();
    edge_table(&points, LOCAL_DECISION_MARGIN, local_edge_extent(samples))
}

/// The edge table of the sample `points` (radius, angle) with the decision `margin`, over offsets within
/// `extent`.
fn edge_table(points: &[(f64, f64)], margin: f64, extent: f64) -> AreaEdgeTable {
    let samples = points.len() as u32;
    // The shader's diamond angle and offset err by far less than these widenings of each cell.
    let widen_t = 1e-4;
    let widen_d = 1e-4 * extent;
    let step_t = 4.0 / f64::from(EDGE_ANGLES);
    let step_d = 2.0 * extent / f64::from(EDGE_OFFSETS);
    let tau = std::f64::consts::TAU;
    let mut inside = vec![UVec4::ZERO; (EDGE_ANGLES * EDGE_OFFSETS) as usize];
    let mut uncertain = inside.clone();
    for a in 0..EDGE_ANGLES {
        let lo = diamond_to_angle(f64::from(a) * step_t - widen_t);
        let hi = diamond_to_angle(f64::from(a + 1) * step_t + widen_t);
        // The range of g (cos(θ - φ)) over θ in [lo, hi] (an arc shorter than pi).
        let range = |(g, phi): (f64, f64)| {
            let at = |theta: f64| g * (theta - phi).cos();
            let holds = |angle: f64| (angle - lo).rem_euclid(tau) <= hi - lo;
            let top = if holds(phi) { g } else { at(lo).max(at(hi)) };
            let bottom = if holds(phi + std::f64::consts::PI) {
                -g
            } else {
                at(lo).min(at(hi))
            };
            (bottom, top)
        };
        for o in 0..EDGE_OFFSETS {
            let d_lo = if o == 0 {
                f64::NEG_INFINITY
            } else {
                -extent + f64::from(o) * step_d - widen_d
            };
            let d_hi = if o + 1 == EDGE_OFFSETS {
                f64::INFINITY
            } else {
                -extent + f64::from(o + 1) * step_d + widen_d
            };
            let cell = (a * EDGE_OFFSETS + o) as usize;
            for (i, &point) in points.iter().enumerate() {
                let (bottom, top) = range(point);
                let bit = 1 << (i % 32);
                if bottom - d_hi >= margin {
                    inside[cell][i / 32] |= bit;
                } else if top - d_lo > -margin {
                    uncertain[cell][i / 32] |= bit;
                }
            }
        }
    }
    AreaEdgeTable {
        samples,
        inside,
        uncertain,
    }
}

/// Columns (and rows) of a [`SampleBands`] table.
pub const SAMPLE_BANDS: u32 = 16;

/// The samples of every band of columns and of rows of a square grid over the samples' plane (a directional
/// light's gnomonic plane, a local light's unit disc): the BVH walk of the area trace finds the samples whose
/// points lie in a rectangle of the plane (a box's projection) with two look-ups, the samples of the band of
/// columns it spans and of the band of rows, instead of testing each sample. Each column and row holds the
/// samples within a margin of it, far above the rounding of the samples' f32 points, so that the two bands
/// hold every sample of the rectangle.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleBands {
    /// The grid's first column's (and row's) lower coordinate.
    pub lo: f32,
    /// The side of a cell.
    pub cell: f32,
    /// The samples of columns `i0..=i1` at [`band_index`]`(i0, i1)`.
    pub columns: Vec<UVec4>,
    /// The samples of rows `j0..=j1` at [`band_index`]`(j0, j1)`.
    pub rows: Vec<UVec4>,
}

/// The index of the band of columns (or rows) `i0..=i1` (`i0 <= i1 < SAMPLE_BANDS`) in a [`SampleBands`]
/// table: the bands starting at each column in turn.
pub fn band_index(i0: u32, i1: u32) -> usize {
    (i0 * SAMPLE_BANDS - i0 * i0.saturating_sub(1) / 2 + (i1 - i0)) as usize
}

impl SampleBands {
    /// Bands of `SAMPLE_BANDS` columns and rows over `[-extent, extent]^2` for the sample `points` (x, y),
    /// each column and row holding the samples within `margin` of it.
    fn new(points: &[(f64, f64)], extent: f64, margin: f64) -> Self {
        let cell = 2.0 * extent / f64::from(SAMPLE_BANDS);
        let lo = -extent;
        let line = |coordinate: fn(&(f64, f64)) -> f64| {
            let single: Vec<UVec4> = (0..SAMPLE_BANDS)
                .map(|j| {
                    let (a, b) = (lo + f64::from(j) * cell, lo + f64::from(j + 1) * cell);
                    let mut mask = UVec4::ZERO;
                    for (i, p) in points.iter().enumerate() {
                        let c = coordinate(p);
                        if c >= a - margin && c <= b + margin {
                            mask[i / 32] |= 1 << (i % 32);
                        }
                    }
                    mask
                })
                .collect();
            let mut bands = vec![UVec4::ZERO; band_index(SAMPLE_BANDS - 1, SAMPLE_BANDS - 1) + 1];
            for i0 in 0..SAMPLE_BANDS {
                let mut mask = UVec4::ZERO;
                for i1 in i0..SAMPLE_BANDS {
                    mask |= single[i1 as usize];
                    bands[band_index(i0, i1)] = mask;
                }
            }
            bands
        };
        Self {
            lo: lo as f32,
            cell: cell as f32,
            columns: line(|p| p.0),
            rows: line(|p| p.1),
        }
    }

    /// The table as the area trace reads it: a header (`lo`, `cell` as bits), the column bands, the row
    /// bands.
    pub fn gpu_words(&self) -> Vec<UVec4> {
        let header = UVec4::new(self.lo.to_bits(), self.cell.to_bits(), SAMPLE_BANDS, 0);
        std::iter::once(header)
            .chain(self.columns.iter().copied())
            .chain(self.rows.iter().copied())
            .collect()
    }

    /// The samples whose points may lie in the rectangle `[lo, hi]` (as the shader looks them up).
    pub fn samples_in(&self, lo: Vec2, hi: Vec2) -> UVec4 {
        let top = self.lo + SAMPLE_BANDS as f32 * self.cell;
        if hi.x < self.lo || hi.y < self.lo || lo.x > top || lo.y > top {
            return UVec4::ZERO;
        }
        let cell =
            |c: f32| (((c - self.lo) / self.cell).floor().max(0.0) as u32).min(SAMPLE_BANDS - 1);
        self.columns[band_index(cell(lo.x), cell(hi.x))]
            & self.rows[band_index(cell(lo.y), cell(hi.y))]
    }
}

/// The sample bands of a directional light of `angular_radius` with `samples` samples, in its gnomonic
/// plane.
pub fn area_sample_bands(angular_radius: f32, samples: u32) -> SampleBands {
    let points: Vec<(f64, f64)> = pattern(angular_radius, samples)
        .map(|(cos_t, sin_t, phi)| {
            let g = sin_t / cos_t;
            (g * phi.cos(), g * phi.sin())
        })
        .collect();
    let extent = edge_extent(angular_radius, samples);
    SampleBands::new(&points, extent, 1e-3 * extent)
}

/// The sample bands of a spot or point light's `samples` samples on the unit disc.
pub fn local_sample_bands(samples: u32) -> SampleBands {
    let points: Vec<(f64, f64)> = local_pattern(samples)
        .map(|(r, a)| (r * a.cos(), r * a.sin()))
        .collect();
    SampleBands::new(&points, local_edge_extent(samples), 1e-3)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trace's variant without the samples' own walks is chosen by [`WIDE_BUNDLE`], and the docs name
    /// both widths: the shader must call the same bundles wide.
    #[test]
    fn the_trace_calls_the_same_bundles_wide() {
        let source = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/shaders/area_trace.glsl"
        ))
        .expect("area_trace.glsl");
        for (name, width) in [
            ("WIDE_BUNDLE", WIDE_BUNDLE),
            ("WIDE_LOCAL_BUNDLE", WIDE_LOCAL_BUNDLE),
        ] {
            let value = source
                .lines()
                .find_map(|l| l.strip_prefix(&format!("const float {name} = ")))
                .and_then(|v| v.strip_suffix(';'))
                .unwrap_or_else(|| panic!("area_trace.glsl defines {name}"));
            assert_eq!(value.parse::<f32>(), Ok(width), "{name}");
        }
    }

    #[test]
    fn sample_bands_hold_every_sample_of_a_rectangle() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f32 / (1u64 << 53) as f32
        };
        for samples in [16, 64, 128] {
            let local: Vec<Vec2> = local_area_offsets(samples);
            let bands = local_sample_bands(samples);
            let r = 0.05f32;
            let directional = area_sample_bands(r, samples);
            let table = area_samples(Vec3::new(0.3, -1.0, 0.2), r, samples);
            let gnomonic: Vec<Vec2> = (0..samples as usize)
                .map(|i| {
                    let w = table.dirs[i].truncate();
                    Vec2::new(
                        w.dot(table.axis_u.truncate()),
                        w.dot(table.axis_v.truncate()),
                    ) / w.dot(table.center.truncate())
                })
                .collect();
            for (points, bands, scale) in [(&local, &bands, 1.0), (&gnomonic, &directional, r)] {
                for _ in 0..2000 {
                    let a = Vec2::new(next(), next()) * 2.4 * scale - 1.2 * scale;
                    let b = a + Vec2::new(next(), next()) * scale;
                    let mask = bands.samples_in(a, b);
                    for (i, p) in points.iter().enumerate() {
                        if p.x >= a.x && p.x <= b.x && p.y >= a.y && p.y <= b.y {
                            assert!(mask[i / 32] & (1 << (i % 32)) != 0, "sample {i} at {p}");
                        }
                    }
                }
                // A small rectangle holds few of the samples.
                let few = bands.samples_in(Vec2::splat(0.1 * scale), Vec2::splat(0.15 * scale));
                assert!(few.x.count_ones() + few.y.count_ones() + few.z.count_ones() < samples / 4);
            }
        }
    }

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
    fn local_offsets_fill_the_unit_disc_evenly() {
        let o = local_area_offsets(64);
        assert_eq!(o.len(), 64);
        assert!(o.iter().all(|p| p.length() < 1.0));
        assert_eq!(o.iter().filter(|p| p.length_squared() < 0.5).count(), 32);
        assert_eq!(local_area_samples(64).dirs[63].truncate().truncate(), o[63]);
        assert_eq!(local_area_samples(64).dirs[64], Vec4::ZERO);
    }

    /// A cube face (just over 90°) keeps its floor near twice the emitter's radius; a 176° frustum is
    /// refused.
    #[test]
    fn the_local_reach_of_a_cube_face_and_a_too_wide_frustum() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        let face = crate::light::point_light_faces(p, None)[2].view_proj();
        let r = local_area_reach(face, p, 0.1).expect("reach");
        assert!(r.near_radius > 0.4 && r.near_radius < 0.6, "{r:?}");
        assert!(r.depth_floor > 0.18 && r.depth_floor < 0.21, "{r:?}");
        let wide = Mat4::perspective_infinite_rh(176f32.to_radians(), 1.0, 0.01)
            * Mat4::look_to_rh(p, Vec3::NEG_Y, Vec3::Z);
        assert!(local_area_reach(wide, p, 0.1).is_err());
        assert!(local_area_reach(face, p, 0.0).is_err());
    }

    #[test]
    fn the_table_bounds_the_spread_of_its_directions() {
        let t = area_samples(Vec3::NEG_Y, 0.02, 16);
        assert!(t.center.w > 0.019 && t.center.w < 0.021, "{}", t.center.w);
        assert_eq!(t.dirs[16], Vec4::ZERO);
        assert!(t.dirs[15].truncate().length() > 0.99);
    }

    /// The cell words of the line `(a, b, c)` as area_trace.glsl finds them: inside and uncertain.
    fn cell_words(
        words: &[UVec4],
        t: &AreaSamples,
        n: u32,
        (a, b, c): (f32, f32, f32),
    ) -> (UVec4, UVec4) {
        let diamond = if b >= 0.0 {
            if a >= 0.0 {
                b / (a + b)
            } else {
                1.0 - a / (-a + b)
            }
        } else if a < 0.0 {
            2.0 - b / (-a - b)
        } else {
            3.0 + a / (a - b)
        };
        let k = ((diamond * (EDGE_ANGLES as f32 / 4.0)) as u32).min(EDGE_ANGLES - 1);
        let d = -c / (a * a + b * b).sqrt();
        let o = ((d + t.axis_u.w) * t.axis_v.w)
            .floor()
            .clamp(0.0, EDGE_OFFSETS as f32 - 1.0) as u32;
        let cell = (k * EDGE_OFFSETS + o) as usize;
        if n <= 64 {
            let w = words[cell];
            (UVec4::new(w.x, w.y, 0, 0), UVec4::new(w.z, w.w, 0, 0))
        } else {
            (words[2 * cell], words[2 * cell + 1])
        }
    }

    /// On 4000 random lines, each made by `line` from an angle, an offset within 1.2 times the table's
    /// extent and a scale (its table line `(a, b, c)` and the per-sample test of each sample), the table's
    /// decided samples agree with the per-sample test, and over 80% of the samples are decided.
    fn check_decisions(
        words: &[UVec4],
        t: &AreaSamples,
        n: u32,
        mut line: impl FnMut(f32, f32, f32) -> ((f32, f32, f32), Vec<bool>),
    ) {
        let mut state = 7u64;
        let mut rng = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let (mut decided, mut total) = (0usize, 0usize);
        for _ in 0..4000 {
            let angle = rng() * std::f32::consts::TAU;
            let offset = (rng() * 2.0 - 1.0) * t.axis_u.w * 1.2;
            let (abc, keeps) = line(angle, offset, rng());
            let (cell_inside, cell_uncertain) = cell_words(words, t, n, abc);
            for (i, &keeps) in keeps.iter().enumerate() {
                let bit = 1 << (i % 32);
                let inside = cell_inside[i / 32] & bit != 0;
                let uncertain = cell_uncertain[i / 32] & bit != 0;
                assert!(!(inside && uncertain));
                total += 1;
                if !uncertain {
                    decided += 1;
                    assert_eq!(inside, keeps, "{n} samples, sample {i}, line {abc:?}");
                }
            }
        }
        assert!(
            decided * 10 > total * 8,
            "{n} samples: {decided} of {total} decided"
        );
    }

    /// On random lines across the samples, the table's decided samples agree with the per-sample test on
    /// the f32 directions, and most samples are decided.
    #[test]
    fn the_edge_table_decides_as_the_per_sample_test() {
        for (r, n) in [(0.02f32, 64u32), (0.3, 128), (0.005, 16)] {
            let t = area_samples(Vec3::new(0.3, -1.0, 0.2), r, n);
            let words = area_edge_table(r, n).gpu_words();
            let (c, u, v) = (
                t.center.truncate(),
                t.axis_u.truncate(),
                t.axis_v.truncate(),
            );
            check_decisions(&words, &t, n, |angle, offset, scale| {
                let across = u * angle.cos() + v * angle.sin();
                let normal = (across - c * offset) * (0.5 + scale * 4.0);
                let keeps = (0..n as usize)
                    .map(|i| normal.dot(t.dirs[i].truncate()) >= 0.0)
                    .collect();
                ((normal.dot(u), normal.dot(v), normal.dot(c)), keeps)
            });
        }
    }

    /// On random lines across the unit disc, the local table's decided samples agree with the area
    /// trace's per-sample test `f0 + u fu + v fv >= 0` on the f32 offsets, and most samples are decided.
    #[test]
    fn the_local_edge_table_decides_as_the_per_sample_test() {
        for n in [16u32, 64, 128] {
            let t = local_area_samples(n);
            let words = local_area_edge_table(n).gpu_words();
            check_decisions(&words, &t, n, |angle, offset, scale| {
                let scale = 0.01 + scale * 100.0;
                let (fu, fv, f0) = (angle.cos() * scale, angle.sin() * scale, -offset * scale);
                let keeps = (0..n as usize)
                    .map(|i| f0 + t.dirs[i].x * fu + t.dirs[i].y * fv >= 0.0)
                    .collect();
                ((fu, fv, f0), keeps)
            });
        }
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
            let e = AreaConfig {
                samples,
                ..AreaConfig::default()
            }
            .validate(0.02)
            .unwrap_err()
            .to_string();
            assert!(e.contains("light samples"), "{e}");
        }
    }
}
